"""Stop 42 qa7: a second walk through the real clients (an HTTP client against the service,
``camloc batch`` and its GeoPackage, the pages in Chromium), the faults found (each test fails
without its fix)."""

from __future__ import annotations

import asyncio
import json
import shutil
from pathlib import Path
from typing import Any

import httpx
import pytest

from camloc_geo.service import create_app
from camloc_geo.service.settings import Settings

REPO = Path(__file__).resolve().parent.parent


def test_a_crowd_task_located_nowhere_says_why(tmp_path: Path) -> None:
    """A crowd task whose merged scene the server's maps cannot place (its prior in a city no
    configured extract covers, no junction) was ``located`` with an empty FeatureCollection;
    a client polling ``GET /v1/tasks/{id}`` for ``located`` found a ``map_url`` and nothing
    said there was no answer (the reason lay in ``result.candidates.properties``), and the
    annotation page linked "The camera's candidates" to an empty map. The status stays
    ``located`` (a new value would break the pollers); ``n_candidates`` and ``reason`` say it."""
    import cv2
    import numpy as np

    scene = json.loads((REPO / "sample_maps" / "sample_scene.json").read_text())
    scene["prior"] = {"lat": 60.17, "lon": 24.94, "radius_m": 150}  # Helsinki: no map here
    scene.pop("intersection", None)
    maps = tmp_path / "maps"
    maps.mkdir()
    shutil.copy(REPO / "sample_maps" / "baltimore.osm.pbf", maps)
    w, h = scene["image"]["width"], scene["image"]["height"]
    ok, buf = cv2.imencode(".png", np.full((h, w, 3), 128, np.uint8))
    assert ok
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0, map_dir=maps))

    async def run() -> tuple[dict[str, Any], dict[str, Any], str]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            r = await client.post(
                "/v1/tasks",
                content=bytes(buf.tobytes()),
                headers={"content-type": "image/png"},
                params={"annotations": "1"},
            )
            assert r.status_code == 201, r.text
            task = r.json()
            sub = await client.post(f"/v1/tasks/{task['id']}/annotations", json=scene)
            assert sub.status_code == 200, sub.text
            status = await client.get(task["status_url"])
            assert status.status_code == 200, status.text
            page = await client.get(task["annotate_url"])
            assert page.status_code == 200, page.text
            return sub.json(), status.json(), page.text

    try:
        submitted, status, page = asyncio.run(run())
    finally:
        app.state.compute.shutdown()
    assert status["status"] == "located"  # unchanged: pollers keep working
    assert status["n_candidates"] == 0
    assert status["reason"].startswith("no geographic evidence"), status
    assert submitted["status"] == "located"
    assert submitted["reason"] == status["reason"]
    assert "located with no candidate: no geographic evidence" in page
    assert "The camera's candidates:" not in page


def test_a_title_found_in_no_extract_of_a_folder_names_where_its_miss_is(tmp_path: Path) -> None:
    """``camloc batch`` (and ``camloc geocode --osm FOLDER``) searching a title without a point
    in a folder of extracts said "'Nowhere' is not a street name of this map (closest: Willow
    Street, ...)": the most telling miss of the 35 extracts, West Oakland's, as if it were the
    only map; a reader looked for the Krems camera among Oakland's streets."""
    from camloc_geo.batch import geocode_camera
    from camloc_geo.cameras import row_from_mapping
    from camloc_geo.geocode._maps import geocode_title_in_maps, whole_map

    folder = tmp_path / "osm"
    folder.mkdir()
    for name in ("baltimore.osm.pbf", "krems.osm.gz"):
        shutil.copy(REPO / "data" / "osm" / name, folder)
    row = row_from_mapping({"id": "x", "title": "Nowhere & Nothing"}, 1)
    res = geocode_camera(row, map_source=str(folder))
    assert res.status == "not_found"
    assert res.reason.startswith("found in none of the 2 extracts searched; the nearest miss is in")
    assert "this map (closest:" in res.reason  # the miss's own words follow, its extract named
    maps = [whole_map(folder / n) for n in ("baltimore.osm.pbf", "krems.osm.gz")]
    got = geocode_title_in_maps("Nowhere & Nothing", maps)
    assert got[0].status == "not_found"
    assert got[0].reason.startswith("found in none of the 2 extracts searched; the nearest miss")
    # one extract: its own words, as before
    one = geocode_title_in_maps("Nowhere & Nothing", maps[1:])
    assert one[0].reason.startswith("'Nowhere' is not a street name of this map")


def test_a_camera_whose_title_meets_twice_says_why_it_is_ambiguous() -> None:
    """Leeds, "Mabgate & Regent Street" with the list's point 13 m from one of the two
    places those streets meet (79 m apart, both inside the point's radius): the camera was
    ``ambiguous`` with the reason "junction of the map's model, at the nodes the two streets
    share", which names one place and no doubt (``camloc batch``, ``POST /v1/jobs``)."""
    from camloc_geo.batch import geocode_camera
    from camloc_geo.cameras import row_from_mapping

    row = row_from_mapping(
        {"id": "L2", "title": "Mabgate & Regent Street", "lat": "53.7994", "lon": "-1.5347"}, 1
    )
    res = geocode_camera(row, map_source=str(REPO / "data" / "osm" / "leeds_centre.osm.gz"))
    assert res.status == "ambiguous"
    assert res.n_candidates == 2
    assert res.reason.startswith(
        "2 places fit the title equally well (Mabgate & Regent Street), up to 79 m apart; "
        "from the list's point 13 m, 91 m: a radius_m holding one alone"
    ), res.reason
    assert res.reason.endswith("junction of the map's model, at the nodes the two streets share")


_LEEDS_LIST = (
    "id;title;lat;lon\n"
    "L1;Regent St / New York Rd looking N;53,8001;-1,5344\n"
    "L2;Mabgate & Regent Street;53.7994;-1.5347\n"
)


def _heading(page: str) -> str:
    """The summary page's heading box, its markup unescaped."""
    text = page.replace("\\u003c", "<").replace("\\u003e", ">")
    start = text.index("camera(s) on the map")
    return text[start : start + 400]


def test_an_ambiguous_camera_is_counted_as_such_on_the_job_page(tmp_path: Path) -> None:
    """``POST /v1/jobs`` then ``GET /v1/jobs/{id}/map`` (a live ``camloc serve``, by hand):
    Leeds' "Mabgate & Regent Street" (ambiguous between two junctions) was drawn at its first
    place with no ring and the heading said "1 located" in a job where no camera was
    located. The job's cameras as the service computes them, and its page."""
    from camloc_geo.service.mapstore import MapStore
    from camloc_geo.service.routers.jobs import job_summary_page
    from camloc_geo.service.work import process_camera

    maps_dir = tmp_path / "maps"
    maps_dir.mkdir()
    shutil.copy(REPO / "data" / "osm" / "leeds_centre.osm.gz", maps_dir)
    settings = Settings(data_dir=tmp_path / "d", workers=0, map_dir=maps_dir)
    maps = MapStore(settings)
    cams = [
        {"id": "L1", "title": "Regent St / New York Rd looking N", "lat": 53.8001, "lon": -1.5344},
        {"id": "L2", "title": "Mabgate & Regent Street", "lat": 53.7994, "lon": -1.5347},
    ]
    results = [process_camera(c, maps, settings) for c in cams]
    assert [r["status"] for r in results] == ["title_only", "ambiguous"]
    head = _heading(job_summary_page(results))
    assert "located" not in head.split("<br>")[0], head
    assert "1 ambiguous (two places fit equally" in head, head
    assert "1 with a tied best candidate" in head, head


def test_an_ambiguous_camera_is_drawn_on_the_batch_page(tmp_path: Path) -> None:
    """``camloc batch --map``: the same camera, with its two candidates in the GeoPackage,
    was listed "1 without candidates (1 ambiguous)" and not drawn; the job page drew it (two
    clients, two answers). Both now draw it at its first place in a dashed ring."""
    from camloc_geo.batch import run_batch

    lst = tmp_path / "cams.csv"
    lst.write_text(_LEEDS_LIST, encoding="utf-8")
    run_batch(
        lst,
        out_gpkg=tmp_path / "cams.gpkg",
        map_source=str(REPO / "data" / "osm" / "leeds_centre.osm.gz"),
        summary_map=tmp_path / "summary.html",
        progress=False,
        workers=1,
    )
    page = (tmp_path / "summary.html").read_text(encoding="utf-8")
    head = _heading(page)
    assert head.startswith("camera(s) on the map"), head
    assert "1 ambiguous (two places fit equally" in head, head
    assert "without candidates" not in head, head
    # its popup says "choose it under 'or the camera is candidate…'": the list is there (a
    # tied camera of this page had none, the job page's had), its second place to pick
    assert '"others": [[2, 53.7999831, -1.5337234, "0.500"]]' in page


def test_a_csv_list_sent_as_json_says_to_send_it_as_csv(tmp_path: Path) -> None:
    """``curl -H 'Content-Type: application/json' --data-binary @cams.csv .../v1/jobs`` (the
    header kept from the JSON call before): "body: the body is not valid JSON: Expecting value:
    line 1 column 1 (char 0)", which says nothing of what to change."""
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.post(
                "/v1/jobs", content=_LEEDS_LIST, headers={"content-type": "application/json"}
            )

    try:
        r = asyncio.run(run())
    finally:
        app.state.compute.shutdown()
    assert r.status_code == 422, r.text
    msg = r.json()["error"]["message"]
    assert msg.startswith("body: the body is not valid JSON: Expecting value"), msg
    assert msg.endswith(
        "it looks like a CSV list (its first row 'id;title;lat;lon'): send it with the header "
        "Content-Type: text/csv"
    ), msg


@pytest.mark.parametrize(
    ("extract", "kind"),
    [
        ("sample_maps/baltimore.osm.pbf", "an OSM extract (.osm.pbf)"),
        ("data/osm/krems.osm.gz", "a gzip-compressed file (an .osm.gz extract?)"),
        ("data/osm/West-Oakland.osm.bz2", "a bzip2-compressed file (an .osm.bz2 extract?)"),
    ],
)
def test_an_extract_given_as_the_scene_or_the_list_is_named(extract: str, kind: str) -> None:
    """``camloc locate EXTRACT --osm SCENE`` (the two swapped) said "it is not UTF-8 text
    (byte 0x95 at position 16)"; ``camloc batch EXTRACT ...`` said the list "is not a text
    file (it holds NUL bytes)" and to export the cameras from QGIS (a .osm.bz2 was read as
    Windows-1252 text)."""
    from camloc_geo import InputError
    from camloc_geo.batch import read_camera_list
    from camloc_geo.scene import load_scene

    path = REPO / extract
    with pytest.raises(InputError) as scene_err:
        load_scene(path)
    assert f"it is {kind}; a scene is camloc-scene/1 JSON text" in str(scene_err.value)
    with pytest.raises(InputError) as list_err:
        list(read_camera_list(path))
    assert str(list_err.value) == (
        f"the camera list {path.name} is {kind}, not a CSV or GeoJSON list of cameras: give "
        "the extract (or its folder) after --osm and the camera list first"
    )


def _dock_annotation() -> Any:
    """The QGIS dock's scene model (``qgis_plugin/camloc/annotation.py``: plain Python, no
    QGIS import), loaded from its file."""
    import importlib.util

    path = REPO / "qgis_plugin" / "camloc" / "annotation.py"
    spec = importlib.util.spec_from_file_location("camloc_dock_annotation", path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.Annotation


def test_the_dock_locates_a_loaded_scene_as_camloc_locate_does() -> None:
    """QGIS dock, *Load scene…* the bundled sample, *Run* (``desktop_check.py`` under Xvfb):
    12 candidates, "#1 tie with #2, #4", where ``camloc locate`` on the same file gives 13,
    #1 tied with 2, 4 and 5, and warns of candidate 5 at a cross street a block away. The
    dock wrote the scene's prior point into ``intersection.lat/lon``, which pins the search to
    the junction nearest that point; the scene gave none."""
    from camloc_geo.api import locate_scene

    scene = json.loads((REPO / "sample_maps" / "sample_scene.json").read_text())
    assert "lat" not in scene["intersection"]
    dock = _dock_annotation().from_scene(scene)
    sent = dock.to_scene()
    assert "lat" not in sent["intersection"]
    assert "lon" not in sent["intersection"]
    assert sent["prior"]["lat"] == scene["prior"]["lat"]
    osm = REPO / "sample_maps" / "baltimore.osm.pbf"
    cli = locate_scene(scene, map_source=osm).to_geojson()["features"]
    got = locate_scene(sent, map_source=osm).to_geojson()["features"]
    assert len(got) == len(cli)
    assert [f["properties"]["score"] for f in got[:5]] == pytest.approx(
        [f["properties"]["score"] for f in cli[:5]], rel=1e-9
    )
    # a junction picked on the map is still sent as the junction's point
    dock.set_location(lat=39.28556, lon=-76.59349)
    picked = dock.to_scene()["intersection"]
    assert (picked["lat"], picked["lon"]) == (39.28556, -76.59349)


def test_geocode_best_says_when_it_left_out_a_match_as_good(tmp_path: Path) -> None:
    """``camloc geocode --list cams.csv --osm leeds_centre.osm.gz --best``: "Mabgate & Regent
    Street" came out a plain ``junction`` at one of the two places those streets meet (79 m
    apart, equal scores); the other was dropped without a word, the answer looked sure."""
    from camloc_geo.cli import main

    lst = tmp_path / "cams.csv"
    lst.write_text(_LEEDS_LIST, encoding="utf-8")
    out = tmp_path / "out.geojson"
    osm = REPO / "data" / "osm" / "leeds_centre.osm.gz"
    assert main(["geocode", "--list", str(lst), "--osm", str(osm), "--best", "-o", str(out)]) == 0
    by_id = {
        f["properties"]["id"]: f["properties"]
        for f in json.loads(out.read_text(encoding="utf-8"))["features"]
    }
    assert by_id["L2"]["status"] == "junction"  # unchanged
    assert by_id["L2"]["reason"].endswith(
        "; --best left out 1 match of the same score, up to 79 m away (without --best all are "
        "listed)"
    )
    assert "--best left out" not in by_id["L1"]["reason"]  # one place: as before


def test_geocode_names_a_list_point_with_lat_and_lon_swapped() -> None:
    """``camloc geocode --list`` with a row ``-1.5337;53.7991`` (lat and lon the other way
    round): "7,971 km from the point given (-1.53370,53.79910): is it this camera's point?",
    where ``camloc batch`` names the swap; the swapped point lies 2 m from the match."""
    from camloc_geo.geocode._maps import geocode_title_in_maps, whole_map

    m = whole_map(REPO / "data" / "osm" / "leeds_centre.osm.gz")
    got = geocode_title_in_maps("Quarry Hill at Playhouse Sq", [m], near=(-1.5337, 53.7991))
    assert got[0].status == "junction"
    assert got[0].reason.endswith(
        "With lat and lon swapped it lies 2 m from this match: are the list's lat and lon "
        "columns the other way round?"
    ), got[0].reason
    far = geocode_title_in_maps("Quarry Hill at Playhouse Sq", [m], near=(53.70, -1.60))
    assert "swapped" not in far[0].reason  # far, but not swapped: as before
