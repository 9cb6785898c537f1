"""The QGIS plugin's out-of-process worker (``python -m camloc_geo.qgis.worker``), without QGIS."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from camloc_geo import InputError
from camloc_geo.qgis.worker import (
    CANDIDATE_FIELDS,
    candidate_rows,
    run_job,
    score_text,
    user_words,
)

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
        "candidates": 13,
        "view_cones": 13,
        "matched_corners": 39,
        "intersection": 5,
    }
    assert layers["candidates"]["fields"] == [list(f) for f in CANDIDATE_FIELDS]
    feats = _read(layers["candidates"])
    types = {"int": int, "double": float, "string": str, "bool": bool}
    for f in feats:
        for name, typ in CANDIDATE_FIELDS:
            v = f["properties"][name]
            assert v is None or type(v) is types[typ], (name, v)
    # 1 and 2 across the junction, 3 and 4 their near twins, 5 a same-shaped junction a block
    # away (stop 41); 6 on scores nothing
    assert [f["properties"]["tie"] for f in feats[:6]] == [True] * 5 + [False]
    assert feats[1]["properties"]["ambiguous_with"] == "1,3,5"
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


def _camera_list(tmp_path: Path) -> Path:
    lst = tmp_path / "cams.geojson"
    rows = [
        {"id": "a", "scene": str(SCENE)},
        {"id": "b", "scene": "nowhere.json"},
        {"id": "c"},
        {"id": "d", "title": "N Milton Ave & E Biddle St"},
        {"id": "e", "title": "Foo St & Bar Ave"},
        {"id": "f", "title": "Main St"},
    ]
    lst.write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "features": [
                    {
                        "type": "Feature",
                        "geometry": (
                            {"type": "Point", "coordinates": [-76.5935, 39.2856]}
                            if r["id"] in "abc"
                            else None
                        ),
                        "properties": r,
                    }
                    for r in rows
                ],
            }
        )
    )
    return lst


def test_geocodelist_job_isolates_bad_rows(tmp_path):
    lst = _camera_list(tmp_path)
    res = run_job(
        {"task": "geocodelist", "list": str(lst), "osm": str(OSM), "out_dir": str(tmp_path)}
    )
    assert res["info"]["engine"] == "camloc_geo.batch"
    cams = {f["properties"]["camera_id"]: f for f in _read(res["layers"]["cameras"])}
    assert cams["a"]["properties"]["status"] == "located"
    assert cams["a"]["properties"]["tie"] is True  # the sample's symmetric junction
    assert cams["a"]["geometry"]["type"] == "Point"
    assert cams["b"]["properties"]["status"] == "scene_error"
    assert "nowhere.json" in cams["b"]["properties"]["reason"]
    assert cams["c"]["properties"]["status"] == "no_evidence"
    assert cams["c"]["geometry"] is None
    assert cams["d"]["properties"]["status"] == "title_only"
    assert cams["e"]["properties"]["status"] == "not_found"  # no landmark stands in
    assert cams["e"]["geometry"] is None
    assert cams["f"]["properties"]["status"] == "not_found"
    assert cams["f"]["properties"]["n_candidates"] == 0
    assert cams["a"]["properties"]["n_candidates"] >= 2
    assert res["layers"]["candidates"]["count"] >= 13
    # one score scale (stop 41): a title-only camera's junction holds the whole share, its
    # name match in match_score; a located camera's candidates share 1
    d = cams["d"]["properties"]
    assert d["score"] == 1.0
    assert 0.0 < d["match_score"] <= 1.0
    cands = [f["properties"] for f in _read(res["layers"]["candidates"])]
    located = [c for c in cands if c["camera_id"] == "a" and c["source"] == "locate"]
    assert sum(c["score"] for c in located) == pytest.approx(1.0)
    assert all(c["match_score"] is None for c in located)


def test_geocodelist_names_duplicate_camera_ids(tmp_path):
    """camloc:geocodelist said nothing of a list with one id on two rows (camloc batch now
    warns on stderr): the worker's warnings carry the line, which Processing shows."""
    lst = tmp_path / "cams.csv"
    lst.write_text("id,title\ncam1,A & B\ncam2,C & D\ncam1,E & F\n", encoding="utf-8")
    res = run_job({"task": "geocodelist", "list": str(lst), "out_dir": str(tmp_path)})
    # (no map given: since session 41 the run says so too, a line of its own)
    dups = [w for w in res["warnings"] if "this run had no map" not in w]
    assert len(dups) == 1
    assert "1 camera id(s) used on more than one row: 'cam1' on rows 1, 3" in dups[0]
    clean = tmp_path / "clean.csv"
    clean.write_text("id,title\ncam1,A & B\n", encoding="utf-8")
    res = run_job({"task": "geocodelist", "list": str(clean), "out_dir": str(tmp_path / "c")})
    assert [w for w in res["warnings"] if "this run had no map" not in w] == []
    assert any("this run had no map" in w for w in res["warnings"])


def test_geocodelist_gives_the_answers_of_camloc_batch(tmp_path):
    """The same list through ``camloc_geo.batch.run_batch`` (``camloc batch``) and the worker."""
    from camloc_geo.batch import results_from_journal, run_batch

    lst = _camera_list(tmp_path)
    run_batch(lst, out_gpkg=tmp_path / "b.gpkg", map_source=OSM.parent, progress=False, workers=1)
    batch = {r.id: r for r in results_from_journal(tmp_path / "b.gpkg")}
    (tmp_path / "w").mkdir()
    res = run_job(
        {
            "task": "geocodelist",
            "list": str(lst),
            "osm": str(OSM.parent),  # a folder of extracts, as camloc batch --osm takes
            "out_dir": str(tmp_path / "w"),
        }
    )
    cams = {f["properties"]["camera_id"]: f["properties"] for f in _read(res["layers"]["cameras"])}
    assert set(cams) == set(batch)
    for cam_id, r in batch.items():
        p = cams[cam_id]
        assert (p["status"], p["lat"], p["lon"], p["tie"]) == (r.status, r.lat, r.lon, r.tie)
        assert p["n_candidates"] == r.n_candidates


def test_geocodelist_names_a_missing_list_or_map(tmp_path):
    with pytest.raises(InputError, match="camera list not found"):
        run_job({"task": "geocodelist", "list": str(tmp_path / "no.csv"), "out_dir": "."})
    lst = _camera_list(tmp_path)
    with pytest.raises(InputError, match="OSM extract or folder not found"):
        run_job({"task": "geocodelist", "list": str(lst), "osm": str(tmp_path / "nope")})


def test_scores_and_labels_read_as_people_write_them():
    assert [score_text(s) for s in (0.3712, 0.045, 0.0021, 1.17461213e-15, 0.0, None)] == [
        "0.37",
        "0.04",
        "0.0021",
        "1.2e-15",
        "0",
        None,
    ]
    assert user_words("intersection.corners[0]") == "your kerb corner 0"
    assert user_words("occluded:references[2]") == "occluded your reference point 2"
    assert user_words("landmarks[1]") == "your landmark 1"


def test_ties_never_come_from_close_scores():
    """No ``ambiguous_with``, no tie, however close the scores (the rule is the core's)."""
    gj = {
        "features": [
            {
                "geometry": {"type": "Point", "coordinates": [0, 0]},
                "properties": {"kind": "candidate", "rank": r, "score": s},
            }
            for r, s in ((1, 0.37), (2, 0.36), (3, 0.045))
        ]
    }
    assert [p["tie"] for _g, p in candidate_rows(gj)] == [False, False, False]


def test_old_module_path_still_runs(tmp_path):
    r = subprocess.run(
        [sys.executable, "-m", "camloc_geo.qgis_worker", "-"],
        input=json.dumps({"task": "probe", "out_dir": str(tmp_path)}),
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout.strip().splitlines()[-1])["info"]
    assert info["tie_score_ratio"] == 0.1
    assert "sedan" in info["presets"]


def test_worker_imports_no_private_core_module():
    import ast

    src = (REPO / "camloc_geo" / "qgis" / "worker.py").read_text()
    mods = [
        n.module if isinstance(n, ast.ImportFrom) else a.name
        for n in ast.walk(ast.parse(src))
        if isinstance(n, (ast.Import, ast.ImportFrom))
        for a in (n.names if isinstance(n, ast.Import) else [n])
    ]
    private = [m for m in mods if m and m.startswith("camloc_geo")]
    assert [m for m in private if any(p.startswith("_") for p in m.split("."))] == []
    assert "camloc_geo.batch" in private  # the camera-list engine of camloc batch


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
        [sys.executable, "-m", "camloc_geo.qgis.worker", str(job)],
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
        [sys.executable, "-m", "camloc_geo.qgis.worker", "-"],
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


def test_annotation_page_job_serves_the_library_page_in_crowd_mode(tmp_path):
    from PIL import Image

    img = tmp_path / "snap.png"
    Image.new("RGB", (640, 360), (120, 120, 120)).save(img)
    res = run_job(
        {
            "task": "annotation_page",
            "image": str(img),
            "submit_url": "http://127.0.0.1:5/camloc/t/scene",
            "lat": 39.2856,
            "lon": -76.5935,
            "osm": str(OSM),
            "out_dir": str(tmp_path),
        }
    )
    page = res["info"]["html"]
    assert '"mode":"crowd"' in page
    assert "http://127.0.0.1:5" in page  # the page may post to the plugin's server only
    assert '"prior":{"lat":39.2856' in page
    assert "Eastern Avenue" in page  # the junction's map from the extract
    with pytest.raises(InputError):
        run_job({"task": "annotation_page", "image": str(tmp_path / "no.png"), "submit_url": "x"})


def test_locate_context_layers_are_the_map_model(tmp_path):
    res = run_job(
        {
            "task": "locate",
            "scene": str(SCENE),
            "osm": str(OSM),
            "context": True,
            "out_dir": str(tmp_path),
        }
    )
    streets = _read(res["layers"]["context_streets"])
    assert {"Eastern Avenue", "South Broadway"} <= {f["properties"]["name"] for f in streets}
    assert all(f["geometry"]["type"] in ("LineString", "MultiLineString") for f in streets)
    assert res["layers"]["context_buildings"]["count"] > 0
    matched = _read(res["layers"]["matched_corners"])
    assert {f["properties"]["what"] for f in matched} >= {"your kerb corner 0"}


def test_geocodelist_agrees_with_camloc_batch_on_a_multi_city_list(tmp_path):
    """Issue 25's check for QGIS: a synthetic list over three cities, one folder of extracts,
    through ``camloc batch`` (the CLI, in its own process) and the worker's geocodelist."""
    import os

    pyogrio = pytest.importorskip("pyogrio")
    from camloc_geo.testing.camera_list import make_camera_list

    maps = tmp_path / "maps"
    maps.mkdir()
    osm = REPO / "data" / "osm"
    for name in ("baltimore.osm.pbf", "helsinki.osm.pbf", "heidelberg_altstadt.osm.pbf"):
        os.symlink(osm / name, maps / name)
    lst = make_camera_list(
        tmp_path / "list",
        sorted(maps.iterdir()),
        9,
        seed=5,
        scene_fraction=0.5,
        point_fraction=0.6,
        bad_rows=("unknown_streets", "far_point"),
    )
    out = tmp_path / "batch.gpkg"
    env = {**os.environ, "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "camloc_geo.cli",
            "batch",
            str(lst),
            "--osm",
            str(maps),
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
    cli = {
        str(r["id"]): (r["status"], r["lat"], r["lon"])
        for _, r in pyogrio.read_dataframe(out, layer="cameras").iterrows()
    }
    (tmp_path / "w").mkdir()
    res = run_job(
        {"task": "geocodelist", "list": str(lst), "osm": str(maps), "out_dir": str(tmp_path / "w")}
    )
    qgis = {
        f["properties"]["camera_id"]: (
            f["properties"]["status"],
            f["properties"]["lat"],
            f["properties"]["lon"],
        )
        for f in _read(res["layers"]["cameras"])
    }
    assert set(qgis) == set(cli)
    assert len(cli) == 11
    placed = 0
    for cam_id, (status, lat, lon) in cli.items():
        q_status, q_lat, q_lon = qgis[cam_id]
        assert q_status == status, cam_id
        if lat is None or lat != lat:  # not placed (NaN in the GeoPackage)
            assert q_lat is None, cam_id
            continue
        placed += 1
        assert abs(q_lat - lat) < 1e-5, cam_id  # about 1 m
        assert abs(q_lon - lon) < 1e-5, cam_id
    assert placed >= 6


def test_measure_job_gives_the_library_values(tmp_path):
    """camloc:measure's rows carry the measured metres (was: value_m null in every row)."""
    from camloc_geo.api import calibrate_scene
    from camloc_geo.sensors import ground_distance, point_height

    pairs = [
        {"kind": "distance", "a": [1241, 631], "b": [1345, 531]},
        {"kind": "height", "a": [1035, 503], "b": [1040, 128]},
    ]
    res = run_job(
        {"task": "measure", "scene": str(SCENE), "pairs": pairs, "out_dir": str(tmp_path)}
    )
    rows = [f["properties"] for f in _read(res["layers"]["measurements"])]
    cal = calibrate_scene(SCENE)
    dist = ground_distance(cal, [[1241, 631], [1345, 531]])
    height = point_height(cal, [1035, 503], [1040, 128])
    assert [r["kind"] for r in rows] == ["distance", "height"]
    assert rows[0]["value_m"] == pytest.approx(dist.value_m, rel=1e-9)
    assert rows[1]["value_m"] == pytest.approx(height.value_m, rel=1e-9)
    assert rows[0]["sigma_m"] == pytest.approx(dist.sigma_m, rel=1e-9)
    assert 5.0 < rows[0]["value_m"] < 40.0
    assert 2.0 < rows[1]["value_m"] < 30.0


@pytest.mark.parametrize(
    ("pairs", "message"),
    [
        ([{"kind": "distance", "a": [1241, 631]}], "PAIRS item 0: 'b' must be a pixel [x, y]"),
        ([{"kind": "area", "a": [1, 2], "b": [3, 4]}], "kind 'area' is not one of"),
        ([{"a": [1, 2], "b": [3, "x"]}], "PAIRS item 0: 'b' must be a pixel"),
        ([[1, 2, 3, 4]], "PAIRS item 0: must be an object"),
        ({"a": [1, 2]}, "PAIRS must be a JSON list"),
        # session 40: an empty PAIRS wrote an empty table without a word
        ([], "PAIRS has no pair: nothing to measure"),
        # a pixel the library refuses: which item (it named none)
        (
            [{"a": [1, 2], "b": [3, 4]}, {"a": [1e308, 631], "b": [1345, 531]}],
            "PAIRS item 1: ground: pixel (1e+308, 631) is far outside",
        ),
        (None, "PAIRS has no pair: nothing to measure"),
    ],
)
def test_measure_job_names_a_bad_pair(tmp_path, pairs, message):
    """A bad PAIRS item is named (was: "missing job parameter 'b'", or an unknown kind
    silently measured as a distance)."""
    with pytest.raises(InputError) as info:
        run_job({"task": "measure", "scene": str(SCENE), "pairs": pairs, "out_dir": str(tmp_path)})
    assert message in str(info.value)


def test_worker_errors_name_the_processing_parameters_not_cli_options(tmp_path):
    """camloc:locate without OSM (the network off) said "give --osm EXTRACT
    (map_source=...)": options the Processing dialog does not have. It names OSM and NETWORK
    now (session 40, found through qgis_process.bin)."""
    r = subprocess.run(
        [sys.executable, "-m", "camloc_geo.qgis.worker", "-"],
        input=json.dumps({"task": "locate", "scene": str(SCENE), "out_dir": str(tmp_path)}),
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2
    error = json.loads(r.stdout.strip().splitlines()[-1])["error"]
    assert "give OSM (an OSM extract) or allow Overpass (NETWORK)" in error
    assert "--osm" not in error
    assert "map_source" not in error


def test_geocodelist_reasons_name_the_processing_parameters(tmp_path):
    """A camera with no map (no OSM, the network off) had the reason "... give --osm
    EXTRACT_OR_FOLDER" in the QGIS layer; it names the OSM parameter now."""
    lst = tmp_path / "cams.csv"
    lst.write_text("id,title\ncam1,Eastern Ave & S Broadway\n", encoding="utf-8")
    res = run_job({"task": "geocodelist", "list": str(lst), "out_dir": str(tmp_path)})
    (cam,) = _read(res["layers"]["cameras"])
    reason = cam["properties"]["reason"]
    assert cam["properties"]["status"] == "no_map"
    assert "give OSM (an extract or a folder of them)" in reason
    assert "--osm" not in reason


def test_a_corners_point_given_lat_first_is_named_swapped(tmp_path):
    """``qgis_process run camloc:corners --POINT="39.2857,-76.5933 [EPSG:4326]"`` (lat first)
    reached the worker as lat -76.59, lon 39.29: refused as outside the extract, with no word
    that the two were swapped (session 41 QA, qgis_process.bin)."""
    from camloc_geo import MapDataError

    job = {"task": "corners", "radius_m": 100, "osm": str(OSM), "out_dir": str(tmp_path)}
    with pytest.raises(MapDataError) as err:
        run_job({**job, "lat": -76.5935, "lon": 39.2856})
    text = str(err.value)
    assert "is outside the extract baltimore.osm.pbf" in text
    assert "latitude and longitude swapped?" in text
    assert "'-76.593500,39.285600 [EPSG:4326]' is lat=39.285600, lon=-76.593500" in text
    # a point outside the extract either way gets no such hint
    with pytest.raises(MapDataError) as err:
        run_job({**job, "lat": 10.0, "lon": 20.0})
    assert "is outside the extract" in str(err.value)
    assert "swapped" not in str(err.value)


def test_swapped_point_hint_reads_the_librarys_bounds():
    from camloc_geo.qgis.worker import swapped_point_hint

    msg = (
        "point lat=-76.593300, lon=39.285700 is outside the extract b.osm.pbf (its streets "
        "and buildings cover lat 39.24602..39.31428, lon -76.61390..-76.51758)"
    )
    assert swapped_point_hint(msg, -76.5933, 39.2857) is not None
    assert swapped_point_hint(msg, 39.2857, -76.7) is None
    assert swapped_point_hint("cannot read OSM extract b.osm.pbf", -76.5933, 39.2857) is None
