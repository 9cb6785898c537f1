"""The HTTP service as a client sees it: a real uvicorn process on a loopback port, httpx."""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "sample_maps"
SCENE = json.loads((SAMPLES / "sample_scene.json").read_text())
TRUTH = json.loads((SAMPLES / "sample_scene.truth.json").read_text())


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class Server:
    """A ``camloc serve`` process; restartable on the same port and data folder."""

    def __init__(self, tmp: Path, **env: str) -> None:
        self.port = _free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        maps = tmp / "maps"
        maps.mkdir(exist_ok=True)
        if not (maps / "baltimore.osm.pbf").exists():
            shutil.copy(SAMPLES / "baltimore.osm.pbf", maps / "baltimore.osm.pbf")
        # (not PYTEST_CURRENT_TEST: a parametrized test's id can outgrow the kernel's limit on
        # an environment, and the server would fail to start with E2BIG)
        self.env = dict(
            {k: v for k, v in os.environ.items() if k != "PYTEST_CURRENT_TEST"},
            CAMLOC_MAP_DIR=str(maps),
            CAMLOC_DATA_DIR=str(tmp / "data"),
            PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""),
            **env,
        )
        self.log = tmp / f"server-{self.port}.log"
        self.proc: subprocess.Popen[bytes] | None = None

    def start(self) -> None:
        with self.log.open("ab") as fh:
            self.proc = subprocess.Popen(
                [
                    sys.executable,
                    "-m",
                    "camloc_geo.cli",
                    "serve",
                    "--port",
                    str(self.port),
                    "--log-level",
                    "warning",
                ],
                env=self.env,
                stdout=fh,
                stderr=subprocess.STDOUT,
            )
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"server exited: {self.log.read_text()[-2000:]}")
            try:
                if httpx.get(self.url + "/healthz", timeout=1.0).status_code == 200:
                    return
            except httpx.HTTPError:
                time.sleep(0.2)
        raise RuntimeError("server did not start in 60 s")

    def kill(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGKILL)
            self.proc.wait(timeout=10)

    def stop(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.kill()


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    srv = Server(tmp_path_factory.mktemp("service"))
    srv.start()
    yield srv
    srv.stop()


@pytest.fixture(scope="module")
def client(server: Server) -> Iterator[httpx.Client]:
    with httpx.Client(base_url=server.url, timeout=60.0) as c:
        yield c


def _dist_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    k = 111_320.0
    return math.hypot((lat2 - lat1) * k, (lon2 - lon1) * k * math.cos(math.radians(lat1)))


def test_healthz(client: httpx.Client) -> None:
    r = client.get("/healthz")
    assert r.status_code == 200
    assert r.json()["status"] == "ok"
    assert r.json()["extracts"] == 1
    assert len(r.headers["x-request-id"]) == 16


def test_calibrate_sample(client: httpx.Client) -> None:
    r = client.post("/v1/calibrate", json=SCENE)
    assert r.status_code == 200, r.text
    body = r.json()
    assert body["height_m"] == pytest.approx(TRUTH["height_m"], abs=1.0)
    assert body["method"] == "joint_fit"


def test_locate_sample_matches_library(client: httpx.Client) -> None:
    from camloc_geo.api import locate_scene

    r = client.post("/v1/locate", json=SCENE, params={"max_candidates": 3})
    assert r.status_code == 200, r.text
    cands = [f for f in r.json()["features"] if f["properties"]["kind"] == "candidate"]
    assert 1 <= len(cands) <= 3
    best = cands[0]["properties"]
    assert _dist_m(best["lat"], best["lon"], TRUTH["lat"], TRUTH["lon"]) < 10.0
    lib = locate_scene(SCENE, map_source=SAMPLES / "baltimore.osm.pbf").to_geojson()
    lib_best = next(f for f in lib["features"] if f["properties"]["kind"] == "candidate")
    # the service loads the whole extract (anchored elsewhere): same answer within centimetres
    assert _dist_m(best["lat"], best["lon"], *lib_best["geometry"]["coordinates"][::-1]) < 0.5


def test_corners_and_streets(client: httpx.Client) -> None:
    lat, lon = 39.28558, -76.59348
    r = client.get("/v1/corners", params={"lat": lat, "lon": lon, "radius_m": 120})
    assert r.status_code == 200, r.text
    inters = [f for f in r.json()["features"] if f["properties"]["kind"] == "intersection"]
    assert inters
    for f in inters:
        flon, flat = f["geometry"]["coordinates"]
        assert _dist_m(lat, lon, flat, flon) <= 121.0
    r = client.get("/v1/streets", params={"lat": lat, "lon": lon, "radius_m": 100})
    assert r.status_code == 200
    names = {n["name"] for n in r.json()["near"]}
    assert "Eastern Avenue" in names


def test_review_page_is_offline_html(client: httpx.Client) -> None:
    r = client.post("/v1/maps", json=SCENE)
    assert r.status_code == 200, r.text
    assert r.headers["content-type"].startswith("text/html")
    assert "L.map" in r.text or "leaflet" in r.text.lower()
    assert '<script src="http' not in r.text


@pytest.mark.parametrize(
    ("body", "ctype", "status", "field"),
    [
        (b"{not json", "application/json", 422, "body"),
        (b"[" * 100_000 + b"]" * 100_000, "application/json", 422, "body"),
        (
            b'{"format": "camloc-scene/1", "image": {"width": NaN, "height": 1}}',
            "application/json",
            422,
            "body",
        ),
        (json.dumps(SCENE).encode(), "text/plain", 415, "content-type"),
        (b"[1, 2]", "application/json", 422, "body"),
        (
            json.dumps({**SCENE, "image": {**SCENE["image"], "path": "/etc/passwd"}}).encode(),
            "application/json",
            422,
            "image.path",
        ),
        (
            json.dumps({**SCENE, "annotations": SCENE["annotations"] * 30}).encode(),
            "application/json",
            413,
            "annotations",
        ),
        (json.dumps({**SCENE, "format": "camloc-scene/9"}).encode(), "application/json", 422, None),
    ],
    ids=["not-json", "deep", "nan", "text-plain", "array", "path", "oversized", "format"],
)
def test_hostile_scene_bodies(
    client: httpx.Client, body: bytes, ctype: str, status: int, field: str | None
) -> None:
    r = client.post("/v1/locate", content=body, headers={"content-type": ctype})
    assert r.status_code == status, r.text
    err = r.json()["error"]
    assert err["message"]
    if field is not None:
        assert err["field"] == field
    assert "Traceback" not in r.text


def test_oversized_body_is_413(client: httpx.Client) -> None:
    big = b'{"x": "' + b"a" * 2_100_000 + b'"}'
    r = client.post("/v1/calibrate", content=big, headers={"content-type": "application/json"})
    assert r.status_code == 413
    assert r.json()["error"]["type"] == "limit_exceeded"


@pytest.mark.parametrize(
    "params",
    [
        {"lat": "1e308", "lon": "0"},
        {"lat": "nan", "lon": "0"},
        {"lat": "39.28", "lon": "-76.59", "radius_m": "1e9"},
        {"lat": "abc", "lon": "0"},
    ],
)
def test_bad_query_values_are_422(client: httpx.Client, params: dict[str, str]) -> None:
    r = client.get("/v1/corners", params=params)
    assert r.status_code == 422


def test_point_outside_every_extract_names_it(client: httpx.Client) -> None:
    r = client.get("/v1/corners", params={"lat": 48.85, "lon": 2.35})
    assert r.status_code == 422
    assert "no map data" in r.json()["error"]["message"]


@pytest.mark.parametrize(
    "path",
    [
        "/v1/jobs/..%2F..%2Fetc%2Fpasswd",
        "/v1/jobs/../../etc/passwd",
        "/annotate/%2e%2e%2fsecret",
        "/v1/tasks/" + "0" * 32,
    ],
)
def test_path_traversal_and_unknown_ids(client: httpx.Client, path: str) -> None:
    r = client.get(path)
    assert r.status_code in (404, 422)
    assert "root:" not in r.text


def _wait_job(client: httpx.Client, job_id: str, total: int, timeout_s: float = 90.0) -> dict:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        st = client.get(f"/v1/jobs/{job_id}").json()
        if st["status"] == "done":
            return st
        time.sleep(0.3)
    raise AssertionError(f"job not done: {st}")


def test_job_geojson_and_geopackage(client: httpx.Client, tmp_path: Path) -> None:
    cams = [
        {"id": "good", "scene": SCENE},
        {"id": "bad", "scene": {"format": "camloc-scene/1"}},
        {"id": "nothing"},
        "not an object",
    ]
    r = client.post("/v1/jobs", json={"cameras": cams})
    assert r.status_code == 202, r.text
    job = r.json()
    st = _wait_job(client, job["id"], 4)
    assert st["done"] == 4
    gj = client.get(f"/v1/jobs/{job['id']}/result").json()
    cams_out = {
        f["properties"]["id"]: f for f in gj["features"] if f["properties"]["kind"] == "camera"
    }
    assert cams_out["good"]["properties"]["status"] == "located"
    good = cams_out["good"]["properties"]
    assert _dist_m(good["lat"], good["lon"], TRUTH["lat"], TRUTH["lon"]) < 10.0
    assert cams_out["bad"]["properties"]["status"] == "scene_error"  # docs/contract.md: statuses
    assert "image" in cams_out["bad"]["properties"]["reason"]
    assert cams_out["nothing"]["properties"]["status"] == "no_evidence"
    gpkg = client.get(f"/v1/jobs/{job['id']}/result", params={"format": "gpkg"})
    assert gpkg.status_code == 200
    path = tmp_path / "job.gpkg"
    path.write_bytes(gpkg.content)
    import pyogrio

    layers = {name for name, _ in pyogrio.list_layers(path)}
    assert {"cameras", "candidates"} <= layers
    frame = pyogrio.read_dataframe(path, layer="cameras")
    assert len(frame) == 4
    assert str(frame.crs).endswith("4326")


def test_job_from_csv(client: httpx.Client) -> None:
    csv_text = "id,title,latitude,lng\nc1,Eastern Ave & S Broadway,39.2856,-76.5935\n"
    r = client.post("/v1/jobs", content=csv_text.encode(), headers={"content-type": "text/csv"})
    assert r.status_code == 202, r.text
    st = _wait_job(client, r.json()["id"], 1)
    assert st["done"] == 1
    assert "warnings" not in r.json()
    # one id on two rows: accepted, as camloc batch accepts it, and named (it went unsaid)
    twice = csv_text + "c1,Eastern Ave & S Bond St,39.2853,-76.5957\n"
    r = client.post("/v1/jobs", content=twice.encode(), headers={"content-type": "text/csv"})
    assert r.status_code == 202, r.text
    assert r.json()["warnings"] == [
        "the list: 1 camera id(s) used on more than one row: 'c1' on rows 1, 2; each row is "
        "geocoded and kept (rows tell them apart), but anything joining on id will mix them "
        "up: give each camera its own id"
    ]
    # ... and the result does tell them apart: each camera feature has its row, each
    # candidate its camera's (the warning said so, but no feature had a row: the two c1
    # cameras and their candidates could not be told apart; found through httpx on a
    # real camloc serve with the sweep's 40-webcam list)
    job_id = r.json()["id"]
    _wait_job(client, job_id, 2)
    feats = client.get(f"/v1/jobs/{job_id}/result").json()["features"]
    cams = [f["properties"] for f in feats if f["properties"]["kind"] == "camera"]
    assert [(c["id"], c["row"]) for c in cams] == [("c1", 1), ("c1", 2)]
    cands = [f["properties"] for f in feats if f["properties"]["kind"] == "candidate"]
    assert sorted({c["camera_row"] for c in cands}) == [1, 2]


def test_job_survives_server_kill(tmp_path: Path) -> None:
    srv = Server(tmp_path)
    srv.start()
    n = 12
    try:
        with httpx.Client(base_url=srv.url, timeout=60.0) as c:
            job = c.post(
                "/v1/jobs", json={"cameras": [{"id": f"cam{i}", "scene": SCENE} for i in range(n)]}
            ).json()
            time.sleep(1.0)
        srv.kill()
        srv.start()
        with httpx.Client(base_url=srv.url, timeout=60.0) as c:
            st = _wait_job(c, job["id"], n, timeout_s=120)
            assert st["done"] == n
            gj = c.get(f"/v1/jobs/{job['id']}/result").json()
        ids = [f["properties"]["id"] for f in gj["features"] if f["properties"]["kind"] == "camera"]
        assert sorted(ids) == sorted(f"cam{i}" for i in range(n))  # each exactly once
    finally:
        srv.stop()


def test_api_key_guards_writes(tmp_path: Path) -> None:
    srv = Server(tmp_path, CAMLOC_API_KEY="s3cret")
    srv.start()
    try:
        with httpx.Client(base_url=srv.url, timeout=60.0) as c:
            assert c.post("/v1/calibrate", json=SCENE).status_code == 401
            wrong = c.post("/v1/calibrate", json=SCENE, headers={"X-API-Key": "nope"})
            assert wrong.status_code == 401
            ok = c.post("/v1/calibrate", json=SCENE, headers={"X-API-Key": "s3cret"})
            assert ok.status_code == 200
            assert c.get("/healthz").status_code == 200
    finally:
        srv.stop()


def _png(width: int, height: int) -> bytes:
    import cv2
    import numpy as np

    ok, buf = cv2.imencode(".png", np.full((height, width, 3), 128, np.uint8))
    assert ok
    return bytes(buf.tobytes())


def test_crowd_task_collects_and_locates(client: httpx.Client) -> None:
    w, h = SCENE["image"]["width"], SCENE["image"]["height"]
    prior = SCENE["prior"]
    r = client.post(
        "/v1/tasks",
        content=_png(w, h),
        headers={"content-type": "image/png"},
        params={"annotations": 2, "lat": prior["lat"], "lon": prior["lon"]},
    )
    assert r.status_code == 201, r.text
    task = r.json()
    wrong = {**SCENE, "image": {"width": w + 1, "height": h}}
    bad = client.post(f"/v1/tasks/{task['id']}/annotations", json=wrong)
    assert bad.status_code == 422
    assert bad.json()["error"]["field"] == "image"
    for i, ann in enumerate(SCENE["annotations"][:2]):
        one = {**SCENE, "annotations": [ann]}
        r = client.post(f"/v1/tasks/{task['id']}/annotations", json=one)
        assert r.status_code == 200, r.text
        assert r.json()["annotations"] == i + 1
        if i == 0:  # no map before the task is located: said in the service's error shape
            early = client.get(f"/v1/tasks/{task['id']}/map")
            assert early.status_code == 404
            assert early.json()["error"]["message"] == (
                f"task {task['id']} has no map: it is collecting (1 of 2 annotations)"
            )
            assert "map_url" not in client.get(f"/v1/tasks/{task['id']}").json()
    st = client.get(f"/v1/tasks/{task['id']}").json()
    assert st["status"] == "located", st
    # the task's review page: there was none (a client had to POST the merged scene to
    # /v1/maps itself)
    assert st["map_url"] == f"/v1/tasks/{task['id']}/map"
    page = client.get(st["map_url"])
    assert page.status_code == 200, page.text
    assert page.headers["content-type"].startswith("text/html")
    assert "camloc-candidate" in page.text
    cands = [
        f for f in st["result"]["candidates"]["features"] if f["properties"]["kind"] == "candidate"
    ]
    assert (
        _dist_m(
            cands[0]["properties"]["lat"], cands[0]["properties"]["lon"], TRUTH["lat"], TRUTH["lon"]
        )
        < 15.0
    )
    late = client.post(f"/v1/tasks/{task['id']}/annotations", json=SCENE)
    assert late.status_code == 422
    # the page of the full task says so before any work (it was served as if open)
    full = client.get(f"/annotate/{task['id']}").text
    assert "This task has all its 2 annotations already: it takes no more work." in full
    # session 40: and where the answer is (the page named none)
    assert f"The camera's candidates: /v1/tasks/{task['id']}/map" in full


def test_crowd_task_no_map_can_serve_is_refused(client: httpx.Client) -> None:
    w, h = SCENE["image"]["width"], SCENE["image"]["height"]
    r = client.post(
        "/v1/tasks",
        content=_png(w, h),
        headers={"content-type": "image/png"},
        params={"lat": 48.85, "lon": 2.35},
    )
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["type"] == "map_data"
    assert "lat=48.850000, lon=2.350000" in err["message"]


def test_docs_work_offline(client: httpx.Client) -> None:
    page = client.get("/docs")
    assert page.status_code == 200
    assert "SwaggerUIBundle" in page.text
    assert "cdn." not in page.text
    assert "//fonts." not in page.text
    srcs = re.findall(r'(?:src|href)="([^"]+)"', page.text)
    assert len(srcs) >= 2
    assert all(s.startswith("/") for s in srcs), srcs
    for src in srcs:
        asset = client.get(src)
        assert asset.status_code == 200, src
        assert len(asset.content) > 1_000
    redoc = client.get("/redoc")
    assert redoc.status_code == 200
    assert "cdn." not in redoc.text
    assert "fonts.googleapis" not in redoc.text


def test_task_upload_limits(client: httpx.Client) -> None:
    r = client.post("/v1/tasks", content=b"GIF89a....", headers={"content-type": "image/png"})
    assert r.status_code == 422
    assert "JPEG, PNG or WebP" in r.json()["error"]["message"]
    r = client.post("/v1/tasks", content=b"x", headers={"content-type": "application/pdf"})
    assert r.status_code == 415


def test_schemathesis_finds_no_server_error(server: Server, tmp_path: Path) -> None:
    """A bounded fuzz run against the live OpenAPI schema: no 5xx anywhere."""
    exe = shutil.which("schemathesis") or shutil.which("st")
    assert exe, "schemathesis is a test dependency"
    proc = subprocess.run(
        [
            exe,
            "run",
            f"{server.url}/openapi.json",
            "--checks",
            "not_a_server_error",
            "--max-examples",
            "10",
            "--seed",
            "1",
            "--request-timeout",
            "30",
            "--no-color",
            "--phases",
            "coverage,fuzzing",
        ],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]
    assert "/v1/locate" in proc.stdout  # the scene endpoints were exercised
    tested = re.search(r"Tested: (\d+)", proc.stdout)
    assert tested is not None, proc.stdout[-2000:]
    assert int(tested.group(1)) >= 17  # 14 before the 3 /v1/verdicts operations
