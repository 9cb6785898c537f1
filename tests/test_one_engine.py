"""One camera, one answer: the same multi-city list through ``camloc batch`` and an HTTP job.

Both front ends call the library's camera-list engine (:func:`camloc_geo.api.locate_camera`)
and choose maps through one :class:`~camloc_geo.osm.MapCatalogue` over the same folder of
extracts, so every camera must be placed (or not) alike, at the same point (within 1 m).
"""

from __future__ import annotations

import csv
import json
import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import httpx
import pytest
from test_service import Server, _wait_job

from camloc_geo.cameras import PLACED_STATUSES
from camloc_geo.testing.camera_list import make_camera_list

ROOT = Path(__file__).resolve().parents[1]
OSM = ROOT / "data" / "osm"
CITIES = ("baltimore.osm.pbf", "helsinki.osm.pbf", "heidelberg_altstadt.osm.pbf")

pytest.importorskip("fastapi")
pytest.importorskip("uvicorn")
pyogrio = pytest.importorskip("pyogrio")


def _dist_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    from camloc_geo.geodesy import distance_m

    return float(distance_m(lat1=lat1, lon1=lon1, lat2=lat2, lon2=lon2))


@pytest.fixture(scope="module")
def case(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    base = tmp_path_factory.mktemp("one_engine")
    maps = base / "maps"
    maps.mkdir()
    for name in CITIES:
        os.symlink(OSM / name, maps / name)
    lst = make_camera_list(
        base / "list",
        [OSM / name for name in CITIES],
        12,
        seed=11,
        scene_fraction=0.5,
        point_fraction=0.75,
        bad_rows=("unknown_streets", "far_point"),
    )
    return {"base": base, "maps": maps, "list": lst}


def _batch_results(case: dict[str, Any]) -> dict[str, dict[str, Any]]:
    out = case["base"] / "batch.gpkg"
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "camloc_geo.cli",
            "batch",
            str(case["list"]),
            "--osm",
            str(case["maps"]),
            "-o",
            str(out),
            "--workers",
            "1",
            "--no-progress",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    frame = pyogrio.read_dataframe(out, layer="cameras")
    return {
        str(r["id"]): {"status": r["status"], "lat": r["lat"], "lon": r["lon"]}
        for _, r in frame.iterrows()
    }


def _job_cameras(case: dict[str, Any]) -> list[dict[str, Any]]:
    """The list's rows as a job's cameras, each scene inline (never a server path)."""
    cams = []
    with open(case["list"], newline="", encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            cam: dict[str, Any] = {k: v for k, v in row.items() if v and k != "scene"}
            if row.get("scene"):
                scene = json.loads((case["list"].parent / row["scene"]).read_text())
                scene.get("image", {}).pop("path", None)
                cam["scene"] = scene
            cams.append(cam)
    return cams


def _job_results(case: dict[str, Any]) -> dict[str, dict[str, Any]]:
    srv = Server(case["base"] / "srv")
    srv.env["CAMLOC_MAP_DIR"] = str(case["maps"])
    srv.start()
    try:
        with httpx.Client(base_url=srv.url, timeout=60.0) as client:
            cams = _job_cameras(case)
            r = client.post("/v1/jobs", json={"cameras": cams})
            assert r.status_code == 202, r.text
            job = r.json()
            _wait_job(client, job["id"], len(cams), timeout_s=300.0)
            gj = client.get(f"/v1/jobs/{job['id']}/result").json()
    finally:
        srv.stop()
    return {
        str(f["properties"]["id"]): f["properties"]
        for f in gj["features"]
        if f["properties"]["kind"] == "camera"
    }


def test_batch_and_http_job_give_one_answer(case: dict[str, Any]) -> None:
    (case["base"] / "srv").mkdir()
    batch = _batch_results(case)
    job = _job_results(case)
    assert set(batch) == set(job)
    placed = 0
    for cam_id, b in batch.items():
        j = job[cam_id]
        b_placed = b["status"] in PLACED_STATUSES
        assert b_placed == (j["status"] in PLACED_STATUSES), (cam_id, b, j)
        assert b["status"] == j["status"], (cam_id, b["status"], j["status"])
        if b_placed:
            placed += 1
            assert not math.isnan(b["lat"])
            assert _dist_m(b["lat"], b["lon"], j["lat"], j["lon"]) < 1.0, (cam_id, b, j)
    assert placed >= 8  # the check compares placed cameras, not only failures


def test_old_status_words_are_accepted_on_input() -> None:
    from camloc_geo.cameras import STATUSES, CameraResult, normalize_status

    assert normalize_status("no_candidate") == "no_candidates"
    assert normalize_status("located") == "located"
    old = CameraResult(row=1, id="c1", status="no_candidates").to_dict()
    old["status"] = "no_candidate"  # a journal or job stored before the one vocabulary
    assert CameraResult.from_dict(old).status == "no_candidates"
    assert "no_candidate" not in STATUSES


def test_a_job_camera_is_a_list_row() -> None:
    """The service's camera dicts are read with the list's column aliases; scene paths refused."""
    from camloc_geo.cameras import row_from_mapping

    row = row_from_mapping(
        {"ID": "c7", "name": "Eastern Ave & S Broadway", "latitude": "39.2856", "lng": -76.5935},
        1,
        scene_paths=False,
    )
    assert (row.id, row.title, row.lat, row.lon) == (
        "c7",
        "Eastern Ave & S Broadway",
        39.2856,
        -76.5935,
    )
    bad = row_from_mapping({"id": "c8", "scene": "/etc/passwd"}, 1, scene_paths=False)
    assert bad.scene is None
    assert not bad.has_scene
    assert any("inline" in p for p in bad.problems)
    inline = row_from_mapping({"id": "c9", "scene": {"format": "camloc-scene/1"}}, 1)
    assert inline.has_scene
    assert inline.scene_data == {"format": "camloc-scene/1"}
