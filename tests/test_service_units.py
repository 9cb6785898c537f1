"""The service's pieces without a server: list bodies, settings, and the library functions
the service calls (corner and street radius filters, crowd merge, job result shapes)."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from camloc_geo import SceneError

if TYPE_CHECKING:
    from camloc_geo.osm import MapData

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "sample_maps"
SCENE = json.loads((SAMPLES / "sample_scene.json").read_text())

pytest.importorskip("fastapi")


@pytest.fixture(scope="module")
def whole_map() -> MapData:  # the whole extract, as the service loads it
    from camloc_geo.osm import load_map

    return load_map(SAMPLES / "baltimore.osm.pbf", 39.2856, -76.5935, radius_m=None)


def test_corners_within_keeps_only_the_radius(whole_map: MapData) -> None:
    from camloc_geo.api import corners_near, corners_within
    from camloc_geo.geodesy import distance_m

    lat, lon = 39.28558, -76.59348
    near = corners_within(lat=lat, lon=lon, radius_m=120, map_source=whole_map)
    # corners_near keeps to the radius itself on a map loaded wider (one rule, in the API)
    assert corners_near(lat=lat, lon=lon, radius_m=120, map_source=whole_map) == near
    inters = [f for f in near["features"] if f["properties"]["kind"] == "intersection"]
    assert 0 < len(inters) < len(whole_map.intersections)
    kept = {f["properties"]["id"] for f in inters}
    for f in inters:
        flon, flat = f["geometry"]["coordinates"]
        assert distance_m(lat1=lat, lon1=lon, lat2=flat, lon2=flon) <= 120.0
    corners = [f for f in near["features"] if f["properties"]["kind"] == "corner"]
    assert corners
    assert all(f["properties"]["intersection"] in kept for f in corners)


def test_corners_within_streets_keeps_to_the_radius(whole_map: MapData) -> None:
    """``streets`` on a whole map (the service's ``/v1/corners?streets=``) answered with a
    junction 2.3 km outside ``radius_m`` and, for names not in the map, said they "do not
    meet within None m" of the map's centre instead of the point asked about."""
    from camloc_geo import MapDataError
    from camloc_geo.api import corners_within

    lat, lon = 39.28558, -76.59348
    milton = "N Milton Ave & E Biddle St"
    near = corners_within(
        lat=lat, lon=lon, radius_m=100, map_source=whole_map, streets="Eastern Ave & S Broadway"
    )
    assert near["features"][0]["properties"]["streets"] == ["Eastern Avenue", "South Broadway"]
    with pytest.raises(MapDataError) as far:
        corners_within(lat=lat, lon=lon, radius_m=100, map_source=whole_map, streets=milton)
    msg = str(far.value)
    assert "do not meet within 100 m of lat=39.285580, lon=-76.593480" in msg
    assert "lat=39.304766, lon=-76.582644" in msg  # where they do meet, 2.3 km away
    wider = corners_within(lat=lat, lon=lon, radius_m=2500, map_source=whole_map, streets=milton)
    assert wider["features"][0]["properties"]["kind"] == "intersection"
    with pytest.raises(MapDataError) as none:
        corners_within(lat=lat, lon=lon, radius_m=100, map_source=whole_map, streets="Foo & Bar")
    msg = str(none.value)
    assert "None" not in msg
    assert "lat=39.285580, lon=-76.593480" in msg
    assert "'Foo': no match" in msg


def test_intersections_within_measures_exactly_what_a_full_scan_does(whole_map: MapData) -> None:
    # intersections_within measures only the nodes near the point (picked in the map's
    # frame); every intersection within the radius, and its distance, as a scan of all.
    import numpy as np

    xs = whole_map.intersections
    for k, radius in ((0, 150.0), (len(xs) // 2, 400.0), (len(xs) - 1, 60.0)):
        lat, lon = xs[k].lat + 3e-4, xs[k].lon - 2e-4
        got = whole_map.intersections_within(lat=lat, lon=lon, radius_m=radius)
        every = whole_map._distances_m(lat, lon)  # every node projected: the full scan
        want = [(xs[i], float(every[i])) for i in np.argsort(every, kind="stable")]
        want = [(x, d) for x, d in want if d <= radius]
        assert [x.id for x, _d in got] == [x.id for x, _d in want]
        assert [d for _x, d in got] == [d for _x, d in want]
        assert len(got) >= 1
        near = got[0][0]
        assert got[0][1] == pytest.approx(whole_map.distance_to_m(near, lat=lat, lon=lon))


def test_streets_within_lists_only_near_streets(whole_map: MapData) -> None:
    from camloc_geo.api import streets_within

    out = streets_within(lat=39.28558, lon=-76.59348, radius_m=100, map_source=whole_map)
    near = {n["name"] for n in out["near"]}
    assert "Eastern Avenue" in near
    assert {s["name"] for s in out["streets"]} == near


def test_crowd_scene_takes_the_task_prior_only_when_none_given() -> None:
    from camloc_geo.api import crowd_scene

    one, two = ({**SCENE, "annotations": [a]} for a in SCENE["annotations"][:2])
    no_prior = [{k: v for k, v in s.items() if k != "prior"} for s in (one, two)]
    prior = {"lat": 39.0, "lon": -76.0, "radius_m": 80.0}
    merged = crowd_scene(no_prior, prior=prior)
    assert merged["prior"] == prior
    assert len(merged["annotations"]) == 2
    assert crowd_scene([one, two], prior=prior)["prior"]["lat"] == SCENE["prior"]["lat"]
    with pytest.raises(SceneError):
        crowd_scene([])


def test_job_result_geojson_shapes() -> None:
    from camloc_geo.results import job_result_geojson

    cand = {
        "type": "Feature",
        "geometry": {"type": "Point", "coordinates": [1.0, 2.0]},
        "properties": {"kind": "candidate", "rank": 1},
    }
    gj = job_result_geojson(
        "j1",
        [
            {"id": "a", "status": "located", "lat": 2.0, "lon": 1.0, "candidates": [cand]},
            {"id": "b", "status": "failed", "reason": "bad"},
        ],
    )
    kinds = [(f["properties"]["kind"], f["properties"].get("id")) for f in gj["features"]]
    assert kinds == [("camera", "a"), ("candidate", None), ("camera", "b")]
    assert gj["features"][0]["geometry"]["coordinates"] == [1.0, 2.0]
    assert gj["features"][1]["properties"]["camera_id"] == "a"
    assert gj["features"][2]["geometry"] is None
    assert gj["properties"]["job"] == "j1"


def test_camera_records_read_like_camloc_batch() -> None:
    from camloc_geo.service.routers.jobs import camera_records

    text = "Camera_ID;Name;Latitude;Lng\nc1;Eastern Ave & S Broadway;39.2856;-76.5935\n;x;abc;1\n"
    rows = camera_records(text.encode(), "text/csv", 10)
    assert rows[0] == {
        "id": "c1",
        "title": "Eastern Ave & S Broadway",
        "lat": 39.2856,
        "lon": -76.5935,
    }
    assert rows[1]["id"] == "row-2"
    assert "lat" not in rows[1]
    assert any("not a number" in p for p in rows[1]["problems"])
    body = {"cameras": [{"id": "j", "latitude": "39.2", "lon": -76.5, "scene": SCENE}, 5]}
    got = camera_records(json.dumps(body).encode(), "application/json", 10)
    assert got[0]["lat"] == 39.2
    assert got[0]["scene"] == SCENE
    assert got[1] == 5
    assert len(camera_records(("id\n" + "x\n" * 50).encode(), "text/csv", 3)) == 4
    with pytest.raises(SceneError, match="scene"):
        camera_records(b"id,scene\nc,/etc/passwd\n", "text/csv", 10)
    with pytest.raises(SceneError, match="cameras"):
        camera_records(b'{"cams": []}', "application/json", 10)


def test_data_dir_defaults_to_the_users_data_folder(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    from camloc_geo.service.settings import Settings

    monkeypatch.delenv("CAMLOC_DATA_DIR", raising=False)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "xdg"))
    monkeypatch.chdir(tmp_path)
    data_dir = Settings().data_dir
    assert data_dir == tmp_path / "xdg" / "camloc" / "service"
    monkeypatch.setenv("CAMLOC_DATA_DIR", str(tmp_path / "mine"))
    assert Settings().data_dir == tmp_path / "mine"


def test_worker_processes_answer_like_threads(tmp_path: Path) -> None:
    import asyncio
    import shutil

    from camloc_geo import MapDataError
    from camloc_geo.service.compute import Compute
    from camloc_geo.service.mapstore import MapStore
    from camloc_geo.service.models import PointQuery
    from camloc_geo.service.routers.crowd import servable_work
    from camloc_geo.service.routers.maps import streets_work
    from camloc_geo.service.settings import Settings

    (tmp_path / "maps").mkdir()
    shutil.copy(SAMPLES / "baltimore.osm.pbf", tmp_path / "maps")
    q = PointQuery(lat=39.28558, lon=-76.59348, radius_m=100)
    answers = {}
    for workers in (0, 1):
        settings = Settings(
            map_dir=tmp_path / "maps",
            data_dir=tmp_path / "d",
            workers=workers,
            request_timeout_s=600.0,  # a busy machine: starting the worker and loading the map
        )
        compute = Compute(settings, MapStore(settings))
        compute.start()
        try:
            answers[workers] = asyncio.run(compute.run(streets_work, q))
            with pytest.raises(MapDataError, match=r"lat=48\.850000"):
                asyncio.run(compute.run(servable_work, False, (48.85, 2.35)))
        finally:
            compute.shutdown()
    assert answers[1] == answers[0]
    assert "Eastern Avenue" in {n["name"] for n in answers[1]["near"]}


def test_a_worker_freezes_its_maps_once_per_map_change(monkeypatch: pytest.MonkeyPatch) -> None:
    import gc

    from camloc_geo.osm import _catalogue
    from camloc_geo.service import compute

    calls: list[str] = []

    def collect(*_a: object) -> int:
        calls.append("collect")
        return 0

    monkeypatch.setattr(gc, "freeze", lambda: calls.append("freeze"))
    monkeypatch.setattr(gc, "unfreeze", lambda: calls.append("unfreeze"))
    monkeypatch.setattr(gc, "collect", collect)
    monkeypatch.setattr(compute, "_frozen_at_loads", -1)
    compute._freeze_maps()
    assert calls == ["unfreeze", "collect", "freeze"]
    compute._freeze_maps()  # no map loaded since: nothing to do
    assert calls == ["unfreeze", "collect", "freeze"]
    monkeypatch.setattr(_catalogue, "_LOADS", [_catalogue._LOADS[0] + 1])  # a map loaded
    compute._freeze_maps()
    assert calls == ["unfreeze", "collect", "freeze"] * 2


@pytest.mark.parametrize(
    ("body", "kind", "field"),
    [
        (b'{"format": "camloc-scene/1", "image": {"width": NaN}}', "SceneError", "body"),
        (
            json.dumps({**SCENE, "image": {**SCENE["image"], "path": "/x"}}).encode(),
            "SceneError",
            "image.path",
        ),
        (
            json.dumps({**SCENE, "annotations": SCENE["annotations"] * 30}).encode(),
            "LimitError",
            "annotations",
        ),
    ],
    ids=["nan", "path", "oversized"],
)
def test_raw_scene_errors_cross_to_the_serving_process(body: bytes, kind: str, field: str) -> None:
    # a worker parses the raw body; its error is pickled back and must keep type and field
    import pickle

    from camloc_geo import InputError
    from camloc_geo.service.deps import scene_from_raw
    from camloc_geo.service.settings import Settings

    with pytest.raises(InputError) as info:
        scene_from_raw(body, Settings())
    back = pickle.loads(pickle.dumps(info.value))
    assert type(back).__name__ == kind
    assert back.field == field
    assert str(back) == str(info.value)


def test_raw_scene_is_the_scene_parsed_in_process() -> None:
    from camloc_geo.scene import parse_scene
    from camloc_geo.service.deps import scene_from_raw
    from camloc_geo.service.settings import Settings

    raw = json.dumps(SCENE).encode()
    assert scene_from_raw(raw, Settings()) == parse_scene(SCENE)


def _serve_args(*argv: str) -> Any:
    import argparse

    from camloc_geo.cli import serve

    parser = argparse.ArgumentParser()
    serve.register(parser.add_subparsers())
    return parser.parse_args(["serve", *argv])


def test_serve_hands_its_loop_parser_and_access_log_to_uvicorn(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import uvicorn

    from camloc_geo.cli import serve

    seen: dict[str, Any] = {}
    monkeypatch.setattr(uvicorn, "run", lambda app, **kw: seen.update(kw, app=app))
    monkeypatch.setattr(serve, "_check_listen", lambda host, port: None)  # port 8000 may be busy
    monkeypatch.setenv("CAMLOC_WORKERS", "0")  # restored after the test (run sets it)
    assert serve.run(_serve_args("--workers", "2")) == 0
    assert (seen["loop"], seen["http"], seen["access_log"]) == ("auto", "auto", True)
    assert os.environ["CAMLOC_WORKERS"] == "2"
    args = _serve_args("--loop", "asyncio", "--http", "h11", "--no-access-log")
    assert serve.run(args) == 0
    assert (seen["loop"], seen["http"], seen["access_log"]) == ("asyncio", "h11", False)


def test_serve_refuses_a_busy_port_in_one_line(monkeypatch: pytest.MonkeyPatch) -> None:
    """A port another server holds was found by uvicorn after the application started,
    among its INFO lines, with its own exit status 3; it is now exit 2 before starting."""
    import socket

    import uvicorn

    from camloc_geo._errors import InputError
    from camloc_geo.cli import serve

    started: list[Any] = []
    monkeypatch.setattr(uvicorn, "run", lambda app, **kw: started.append(kw))
    monkeypatch.setenv("CAMLOC_WORKERS", "0")
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        with pytest.raises(InputError, match=rf"--port {port}: cannot listen on .*in use"):
            serve.run(_serve_args("--host", "127.0.0.1", "--port", str(port)))
    assert started == []

    def stops(app: str, **kw: Any) -> None:
        raise SystemExit(3)

    monkeypatch.setattr(uvicorn, "run", stops)
    monkeypatch.setattr(serve, "_check_listen", lambda host, port: None)
    with pytest.raises(RuntimeError, match="uvicorn status 3"):
        serve.run(_serve_args("--port", str(port)))


@pytest.mark.parametrize(("option", "module"), [("--loop", "uvloop"), ("--http", "httptools")])
def test_serve_names_a_missing_speed_up(
    monkeypatch: pytest.MonkeyPatch, option: str, module: str
) -> None:
    from camloc_geo._errors import InputError
    from camloc_geo.cli import serve

    monkeypatch.setattr(serve, "_importable", lambda name: name != module)
    with pytest.raises(InputError, match=rf"{option} {module}: {module} is not installed"):
        serve.run(_serve_args(option, module))


@pytest.mark.parametrize(
    ("query", "expected"),
    [
        (b"", (True, None)),
        (b"max_candidates=5", (True, 5)),
        (b"other=1&max_candidates=100", (True, 100)),
        (b"other=x", (True, None)),
        (b"max_candidates=0", (False, None)),
        (b"max_candidates=101", (False, None)),
        (b"max_candidates=abc", (False, None)),
        (b"max_candidates=-3", (False, None)),
        (b"max_candidates=5.0", (False, None)),
        (b"max_candidates=", (False, None)),
        (b"max_candidates=%D9%A3", (False, None)),  # an Arabic-Indic 3: FastAPI's to judge
        (b"max_candidates=2&max_candidates=3", (False, None)),
    ],
)
def test_fast_path_takes_only_plain_queries(query: bytes, expected: tuple[bool, Any]) -> None:
    from camloc_geo.service.fastpath import max_candidates_of

    assert max_candidates_of(query) == expected


def test_fast_path_answers_exactly_as_the_fastapi_routes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the same requests to the app with and without the fast path: same status, same body
    import asyncio
    import shutil

    import httpx
    from pydantic import SecretStr

    from camloc_geo.service import app as app_module
    from camloc_geo.service import create_app, fastpath
    from camloc_geo.service.settings import Settings

    (tmp_path / "maps").mkdir()
    shutil.copy(SAMPLES / "baltimore.osm.pbf", tmp_path / "maps")
    settings = Settings(
        map_dir=tmp_path / "maps", data_dir=tmp_path / "d", api_key=SecretStr("k\u00e9y"), workers=0
    )
    plain: list[bool] = []
    real_plain = fastpath.SceneFastPath._plain

    def spy(self: Any, scope: Any) -> tuple[bool, int | None]:
        out = real_plain(self, scope)
        plain.append(out[0])
        return out

    monkeypatch.setattr(fastpath.SceneFastPath, "_plain", spy)
    body = json.dumps(SCENE).encode()
    key = "k\u00e9y".encode("latin-1")  # how HTTP headers carry it (FastAPI reads Latin-1)
    json_key = {"content-type": "application/json", "x-api-key": key}
    requests: list[tuple[str, str, bytes, dict[str, Any]]] = [
        ("/v1/locate", "", body, json_key),
        ("/v1/locate", "max_candidates=2", body, json_key),
        ("/v1/calibrate", "", body, {**json_key, "content-type": "Application/JSON; charset=x"}),
        ("/v1/locate", "", b'{"format": "camloc-scene/1", "image": {"width": NaN}}', json_key),
        ("/v1/locate", "", json.dumps([1]).encode(), json_key),
        ("/v1/calibrate", "", json.dumps({**SCENE, "annotations": []}).encode(), json_key),
        # FastAPI's to judge
        ("/v1/locate", "max_candidates=0", body, json_key),
        ("/v1/locate", "max_candidates=abc", body, json_key),
        ("/v1/locate", "", body, {**json_key, "x-api-key": b"wrong"}),
        ("/v1/locate", "", body, {"content-type": "application/json"}),
        ("/v1/calibrate", "", body, {**json_key, "content-type": "text/plain"}),
    ]

    def drop_id(r: httpx.Response) -> Any:
        data = r.json()
        if isinstance(data, dict):
            data.pop("request_id", None)
            if "error" in data and data["error"].get("type") == "internal":
                data["error"].pop("message")
        return r.status_code, r.headers["content-type"], data

    async def answers(fast: bool) -> list[Any]:
        if not fast:
            monkeypatch.setattr(app_module, "FAST_ROUTES", {})
        app = create_app(settings)
        transport = httpx.ASGITransport(app=app)
        out = []
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            for path, query, content, headers in requests:
                url = f"{path}?{query}" if query else path
                r = await client.post(url, content=content, headers=headers)
                out.append(drop_id(r))
        app.state.compute.shutdown()
        return out

    with_fast = asyncio.run(answers(True))
    assert plain == [True] * 6 + [False] * 5
    plain.clear()
    without = asyncio.run(answers(False))
    assert plain == []
    assert [a[0] for a in with_fast] == [200, 200, 200, 422, 422, 422, 422, 422, 401, 401, 415]
    assert with_fast == without
    assert len(with_fast[1][2]["features"]) < len(with_fast[0][2]["features"])


def test_fast_path_cuts_off_a_body_without_length_over_the_limit(tmp_path: Path) -> None:
    import asyncio
    from collections.abc import AsyncIterator

    import httpx

    from camloc_geo.service import create_app
    from camloc_geo.service.settings import Settings

    app = create_app(Settings(data_dir=tmp_path / "d", max_request_bytes=1_000, workers=0))

    async def chunks() -> AsyncIterator[bytes]:  # no Content-Length: streamed
        for _ in range(4):
            yield b" " * 400

    async def post() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.post(
                "/v1/locate", content=chunks(), headers={"content-type": "application/json"}
            )

    r = asyncio.run(post())
    app.state.compute.shutdown()
    assert r.status_code == 413
    assert r.json()["error"] == {
        "type": "limit_exceeded",
        "message": "request body over 1000 bytes",
        "field": "body",
    }
    assert r.json()["request_id"] == r.headers["x-request-id"]


def test_fastapi_refusals_come_in_the_service_error_shape(tmp_path: Path) -> None:
    """A bad query or path value, an unknown path and a wrong method answered
    ``{"detail": ...}`` only; every error is now ``{"error": {...}, "request_id"}`` as
    docs/service.md says, with FastAPI's ``detail`` kept for the clients that read it."""
    import asyncio

    import httpx

    from camloc_geo.service import create_app
    from camloc_geo.service.settings import Settings

    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def calls() -> list[httpx.Response]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return [
                await client.get("/v1/corners", params={"lat": "95", "lon": "0"}),
                await client.post("/v1/locate?max_candidates=0", json=SCENE),
                await client.get("/v1/jobs/zzz"),
                await client.get("/v1/nope"),
                await client.get("/v1/locate"),
            ]

    lat, cands, job, nope, method = asyncio.run(calls())
    app.state.compute.shutdown()
    assert lat.status_code == 422
    body = lat.json()
    assert body["error"]["type"] == "invalid_input"
    assert body["error"]["field"] == "lat"
    assert body["error"]["message"] == "lat: Input should be less than or equal to 90 (got '95')"
    assert body["request_id"] == lat.headers["x-request-id"]
    assert body["detail"][0]["loc"] == ["query", "lat"]  # FastAPI's own, kept
    assert (cands.status_code, cands.json()["error"]["field"]) == (422, "max_candidates")
    assert (job.status_code, job.json()["error"]["field"]) == (422, "job_id")
    assert nope.status_code == 404
    assert nope.json()["error"] == {"type": "not_found", "message": "Not Found"}
    assert nope.json()["detail"] == "Not Found"
    assert method.status_code == 405
    assert method.json()["error"]["type"] == "method_not_allowed"
    assert "allow" in {k.lower() for k in method.headers}


def test_openapi_declares_the_error_answers(tmp_path: Path) -> None:
    """/openapi.json listed 200 and 422 only: a 401, 404, 413, 415 or 503 was undocumented
    (schemathesis' status-code conformance check failed on every route)."""
    from camloc_geo.service import create_app
    from camloc_geo.service.settings import Settings

    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))
    spec = app.openapi()
    app.state.compute.shutdown()
    for path, item in spec["paths"].items():
        for method, op in item.items():
            assert {"401", "404", "413", "415", "503"} <= set(op["responses"]), (method, path)
    error = spec["paths"]["/v1/locate"]["post"]["responses"]["415"]["content"]
    assert error["application/json"]["schema"] == {"$ref": "#/components/schemas/ErrorBody"}
    # an HTML route's errors are JSON too (FastAPI would have put them under text/html)
    html_error = spec["paths"]["/v1/maps"]["post"]["responses"]["415"]["content"]
    assert set(html_error) == {"application/json"}
    assert set(spec["paths"]["/annotate/{task_id}"]["get"]["responses"]["404"]["content"]) == {
        "application/json"
    }
    body = spec["components"]["schemas"]["ErrorBody"]
    assert body["required"] == ["error", "request_id"]
    assert set(spec["components"]["schemas"]["ErrorDetail"]["properties"]) == {
        "type",
        "message",
        "field",
    }


def test_healthz_answers_head(tmp_path: Path) -> None:
    """``curl -I /healthz`` (a load balancer's probe) was a 405; it is a 200 without a body."""
    import asyncio

    import httpx

    from camloc_geo.service import create_app
    from camloc_geo.service.settings import Settings

    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def calls() -> tuple[httpx.Response, httpx.Response]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.head("/healthz"), await client.get("/healthz")

    head, get = asyncio.run(calls())
    app.state.compute.shutdown()
    assert head.status_code == 200
    assert head.content == b""
    assert get.json()["status"] == "ok"
    assert set(app.openapi()["paths"]["/healthz"]) == {"get"}


def test_a_compressed_body_is_refused_by_name(tmp_path: Path) -> None:
    """A gzip body (``Content-Encoding: gzip``) was read as JSON: "the body is not valid JSON:
    'utf-8' codec can't decode byte 0x8b"; it is now a 415 naming the encoding, on the fast
    path's routes too."""
    import asyncio
    import gzip

    import httpx

    from camloc_geo.service import create_app
    from camloc_geo.service.settings import Settings

    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))
    body = gzip.compress(json.dumps(SCENE).encode())
    headers = {"content-type": "application/json", "content-encoding": "gzip"}

    async def calls() -> list[httpx.Response]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return [
                await client.post(path, content=body, headers=headers)
                for path in ("/v1/locate", "/v1/calibrate", "/v1/jobs")
            ]

    answers = asyncio.run(calls())
    app.state.compute.shutdown()
    for r in answers:
        assert r.status_code == 415
        assert r.json()["error"] == {
            "type": "unsupported_media_type",
            "message": "content encoding 'gzip' not supported; send the body uncompressed",
            "field": "content-encoding",
        }


def test_a_resubmitted_annotation_is_not_a_second_annotator(tmp_path: Path) -> None:
    """The same scene posted twice to a task (a retry after a lost answer, a double click on
    Submit) counted as two annotators, and completed a two-annotator task with one person's
    work; the repeat now gets the state back with ``duplicate: true`` and counts nothing."""
    import asyncio

    import cv2
    import httpx
    import numpy as np

    from camloc_geo.service import create_app
    from camloc_geo.service.settings import Settings

    maps = tmp_path / "maps"
    maps.mkdir()
    (maps / "baltimore.osm.pbf").symlink_to(SAMPLES / "baltimore.osm.pbf")
    app = create_app(Settings(data_dir=tmp_path / "d", map_dir=maps, workers=0))
    photo = cv2.imencode(".png", np.full((1080, 1920, 3), 128, np.uint8))[1].tobytes()
    one = json.loads(json.dumps(SCENE))
    one["annotations"] = one["annotations"][:1]
    other = json.loads(json.dumps(SCENE))
    other["annotations"] = other["annotations"][1:2]

    async def calls() -> list[httpx.Response]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            task = await client.post(
                "/v1/tasks?annotations=2", content=photo, headers={"content-type": "image/png"}
            )
            url = f"/v1/tasks/{task.json()['id']}"
            return [
                task,
                await client.post(f"{url}/annotations", json=one),
                await client.post(f"{url}/annotations", json=one),
                await client.get(url),
                await client.post(f"{url}/annotations", json=other),
            ]

    task, first, again, state, second = asyncio.run(calls())
    app.state.compute.shutdown()
    assert task.status_code == 201
    assert first.json() == {"annotations": 1, "needed": 2, "status": "collecting"}
    assert again.status_code == 200
    assert again.json() == {
        "annotations": 1,
        "needed": 2,
        "status": "collecting",
        "duplicate": True,
    }
    assert (state.json()["annotations"], state.json()["status"]) == (1, "collecting")
    assert second.json()["annotations"] == 2  # a second person's work still completes it
    assert "duplicate" not in second.json()


def test_job_geopackage_of_a_job_with_nothing_done_is_a_geopackage(tmp_path: Path) -> None:
    """``/v1/jobs/{id}/result?format=gpkg`` before any camera was done answered 200 with 0
    bytes (no GeoPackage: QGIS cannot open it); both layers are now always there."""
    import pyogrio

    from camloc_geo.results import job_result_geopackage

    empty = tmp_path / "empty.gpkg"
    empty.write_bytes(job_result_geopackage({"type": "FeatureCollection", "features": []}))
    layers = dict(pyogrio.list_layers(empty))
    assert layers == {"cameras": "Point", "candidates": "Point", "layer_styles": None}
    assert len(pyogrio.read_dataframe(empty, layer="cameras")) == 0


def test_job_geopackage_types_null_numbers_as_numbers(tmp_path: Path) -> None:
    """A job of title-only cameras has no heading or height anywhere: heading_deg and
    height_m were String fields of the GeoPackage (ogrinfo: 'heading_deg (String) =
    (null)'), so QGIS sorted and styled them as text; they are Real now."""
    import pyogrio

    from camloc_geo.results import job_result_geojson, job_result_geopackage

    gj = job_result_geojson(
        "j1",
        [
            {
                "id": "a",
                "row": 1,
                "status": "title_only",
                "lat": 2.0,
                "lon": 1.0,
                "heading_deg": None,
                "height_m": None,
                "reason": "junction",
            },
        ],
    )
    path = tmp_path / "job.gpkg"
    path.write_bytes(job_result_geopackage(gj))
    info = pyogrio.read_info(path, layer="cameras")
    types = dict(zip(info["fields"], info["dtypes"], strict=True))
    assert types["heading_deg"] == "float64"
    assert types["height_m"] == "float64"
    assert types["reason"] == "object"
