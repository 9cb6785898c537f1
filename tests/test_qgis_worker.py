"""The QGIS plugin's out-of-process worker (``python -m camloc_geo.qgis_worker``), without QGIS."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from camloc_geo._errors import InputError
from camloc_geo.qgis_worker import CANDIDATE_FIELDS, candidate_rows, run_job

REPO = Path(__file__).resolve().parent.parent
SCENE = REPO / "sample_maps" / "sample_scene.json"
OSM = REPO / "sample_maps" / "baltimore.osm.pbf"


def _read(desc: dict) -> list[dict]:
    return json.loads(Path(desc["path"]).read_text())["features"]


def test_locate_job_writes_flat_typed_layers(tmp_path):
    res = run_job(
        {"task": "locate", "scene": str(SCENE), "osm": str(OSM), "out_dir": str(tmp_path)}
    )
    layers = res["layers"]
    assert {k: v["count"] for k, v in layers.items()} == {
        "candidates": 12,
        "view_cones": 12,
        "matched_corners": 36,
        "intersection": 5,
    }
    assert layers["candidates"]["fields"] == [list(f) for f in CANDIDATE_FIELDS]
    feats = _read(layers["candidates"])
    types = {"int": int, "double": float, "string": str, "bool": bool}
    for f in feats:
        for name, typ in CANDIDATE_FIELDS:
            v = f["properties"][name]
            assert v is None or type(v) is types[typ], (name, v)
    # 1 and 2 across the junction, 3 and 4 their near twins; 5 on scores nothing
    assert [f["properties"]["tie"] for f in feats[:5]] == [True, True, True, True, False]
    assert feats[1]["properties"]["ambiguous_with"] == "1,3"
    assert any("ambiguous" in w for w in res["warnings"])


def test_ties_from_the_library_are_kept_when_given():
    gj = {
        "features": [
            {
                "geometry": {"type": "Point", "coordinates": [0, 0]},
                "properties": {"kind": "candidate", "rank": r, "score": s, "ambiguous_with": a},
            }
            for r, s, a in ((1, 0.6, [3]), (2, 0.5, []), (3, 0.1, [1]))
        ]
    }
    rows = [p for _g, p in candidate_rows(gj)]
    assert [(p["tie"], p["ambiguous_with"]) for p in rows] == [
        (True, "3"),
        (False, None),
        (True, "1"),
    ]


def test_corners_job(tmp_path):
    res = run_job(
        {
            "task": "corners",
            "lat": 39.2856,
            "lon": -76.5935,
            "radius_m": 100,
            "osm": str(OSM),
            "out_dir": str(tmp_path),
        }
    )
    props = [f["properties"] for f in _read(res["layers"]["corners"])]
    inters = {p["intersection"]: p for p in props if p["kind"] == "intersection"}
    main = [i for i, p in inters.items() if p["streets"] == "Eastern Avenue & South Broadway"]
    assert len(main) == 1
    assert sum(1 for p in props if p["kind"] == "corner" and p["intersection"] == main[0]) == 4


def test_geocodelist_job_isolates_bad_rows(tmp_path):
    lst = tmp_path / "cams.geojson"
    rows = [
        {"id": "a", "scene": str(SCENE)},
        {"id": "b", "scene": "nowhere.json"},
        {"id": "c"},
    ]
    lst.write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "features": [
                    {
                        "type": "Feature",
                        "geometry": {"type": "Point", "coordinates": [-76.5935, 39.2856]},
                        "properties": r,
                    }
                    for r in rows
                ],
            }
        )
    )
    res = run_job(
        {
            "task": "geocodelist",
            "list": str(lst),
            "osm": str(OSM),
            "engine": "library",
            "out_dir": str(tmp_path),
        }
    )
    cams = {f["properties"]["camera_id"]: f for f in _read(res["layers"]["cameras"])}
    assert cams["a"]["properties"]["status"] == "ambiguous"  # the sample's symmetric junction
    assert cams["a"]["geometry"]["type"] == "Point"
    assert cams["b"]["properties"]["status"] == "error"
    assert "not found" in cams["b"]["properties"]["reason"]
    assert cams["c"]["properties"]["reason"] == "no scene file in the row"
    assert cams["c"]["geometry"] is None
    assert res["layers"]["candidates"]["count"] == 12


def test_check_scene_job_validates_and_saves_the_scene(tmp_path):
    data = json.loads(SCENE.read_text())
    out = tmp_path / "s.json"
    res = run_job({"task": "check_scene", "scene": data, "save_to": str(out)})
    assert json.loads(out.read_text()) == data
    assert res["info"]["scene"]["intersection"]["corners"] == data["intersection"]["corners"]


def test_worker_process_reports_bad_input_in_one_line_without_traceback(tmp_path):
    job = tmp_path / "job.json"
    job.write_text(json.dumps({"task": "locate", "scene": str(tmp_path / "nope.json")}))
    r = subprocess.run(
        [sys.executable, "-m", "camloc_geo.qgis_worker", str(job)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert r.returncode == 2
    last = json.loads(r.stdout.strip().splitlines()[-1])
    assert last["ok"] is False
    assert "scene file not found" in last["error"]
    assert "Traceback" not in r.stderr


@pytest.mark.parametrize(
    ("job", "message"),
    [({"task": "fly"}, "unknown task 'fly'"), ({"task": "corners"}, "missing job parameter")],
)
def test_worker_names_bad_jobs(tmp_path, job, message):
    r = subprocess.run(
        [sys.executable, "-m", "camloc_geo.qgis_worker", "-"],
        input=json.dumps({**job, "out_dir": str(tmp_path)}),
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2
    assert message in json.loads(r.stdout.strip().splitlines()[-1])["error"]


def test_probe_job():
    info = run_job({"task": "probe", "out_dir": "."})["info"]
    assert info["version"]
    assert isinstance(info["sensors"], bool)


def test_check_scene_job_rejects_a_bad_scene(tmp_path):
    data = json.loads(SCENE.read_text())
    data["intersection"]["lat"] = 39.0
    out = tmp_path / "s.json"
    with pytest.raises(InputError, match="give both lat and lon"):
        run_job({"task": "check_scene", "scene": data, "save_to": str(out)})
    assert not out.exists()


def test_geocodelist_uses_the_batch_engine_when_present(tmp_path, monkeypatch):
    import types

    import camloc_geo.qgis_worker as worker

    def geocode_camera(row, *, map_data=None, map_source=None, network=False):
        if row["id"] == "bad":
            return types.SimpleNamespace(id="bad", status="error", reason="no scene", candidates=[])
        cand = {"rank": 1, "score": 1.0, "lat": 39.28, "lon": -76.59, "sigma_m": 3.0}
        return types.SimpleNamespace(id=row["id"], status="ok", reason=None, candidates=[cand])

    fake = types.SimpleNamespace(
        read_camera_list=lambda path: iter([{"id": "a"}, {"id": "bad"}]),
        geocode_camera=geocode_camera,
    )
    monkeypatch.setattr(worker, "_batch_module", lambda: fake)
    res = run_job({"task": "geocodelist", "list": "cams.csv", "out_dir": str(tmp_path)})
    assert res["info"]["engine"] == "camloc_geo.batch"
    cams = {f["properties"]["camera_id"]: f for f in _read(res["layers"]["cameras"])}
    assert cams["a"]["properties"]["status"] == "ok"
    assert cams["a"]["geometry"]["coordinates"] == [-76.59, 39.28]
    assert cams["a"]["properties"]["tie"] is False
    assert cams["bad"]["properties"]["reason"] == "no scene"
    assert res["layers"]["candidates"]["count"] == 1
