"""Session 38 QA: list rows that give only a scene, and an HTTP job row's own problems.

- A camera given only a scene (``id,scene``, or an HTTP job camera with its scene inline and
  no title or point) was located with one extract (``--osm city.osm.pbf``) but ended
  ``no_evidence`` ("no point, no title and no street pair") with a folder of extracts
  (``--osm data/osm/``, the README's form, and always in the service): with no point of its
  own it was searched by title in every extract. Its map is now chosen at its scene's
  intersection (or prior) point.
- ``POST /v1/jobs`` lost a row's problems (``lat 'abc' is not a number``) before the camera
  was placed: the job keeps the parsed row, from which the bad value is gone; the reason
  now ends with them, as ``camloc batch``'s does.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pyogrio
import pytest

from camloc_geo.batch import run_batch
from camloc_geo.cameras import CameraRow

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "sample_maps" / "sample_scene.json"
BALTIMORE = REPO / "sample_maps" / "baltimore.osm.pbf"


@pytest.fixture
def maps(tmp_path: Path) -> Path:
    folder = tmp_path / "maps"
    folder.mkdir()
    (folder / BALTIMORE.name).symlink_to(BALTIMORE)
    # a second extract: with one, every camera is in it
    (folder / "frederiksted.osm.pbf").symlink_to(REPO / "data" / "osm" / "frederiksted.osm.pbf")
    return folder


def test_scene_point_is_the_intersection_then_the_prior(tmp_path: Path) -> None:
    from camloc_geo.cameras._list import area_row, scene_point

    data: dict[str, Any] = json.loads(SCENE.read_text(encoding="utf-8"))
    row = CameraRow(row=1, id="a", scene_data=data)
    assert scene_point(row) == (39.2856, -76.5935)  # the sample's prior
    data2 = {**data, "intersection": {**data["intersection"], "lat": 39.28, "lon": -76.59}}
    assert scene_point(CameraRow(row=1, id="a", scene_data=data2)) == (39.28, -76.59)
    moved = area_row(CameraRow(row=1, id="a", scene_data=data2))
    assert (moved.lat, moved.lon) == (39.28, -76.59)
    # a row's own point wins; a scene naming no valid point leaves the row as it is
    own = CameraRow(row=1, id="a", lat=1.0, lon=2.0, scene_data=data2)
    assert area_row(own) is own
    bad = {**data, "prior": {"lat": float("nan"), "lon": 5}, "intersection": {"lat": 95}}
    assert scene_point(CameraRow(row=1, id="a", scene_data=bad)) is None
    broken = tmp_path / "broken.json"
    broken.write_text("{", encoding="utf-8")
    assert scene_point(CameraRow(row=1, id="a", scene=str(broken))) is None
    assert scene_point(CameraRow(row=1, id="a", scene=str(SCENE))) == (39.2856, -76.5935)


def test_batch_locates_a_scene_only_row_with_a_folder_of_extracts(
    tmp_path: Path, maps: Path
) -> None:
    shutil.copy(SCENE, tmp_path / "scene.json")
    lst = tmp_path / "cams.csv"
    lst.write_text("id,scene\nd1,scene.json\nd2,missing.json\n", encoding="utf-8")
    out = tmp_path / "out.gpkg"
    run_batch(lst, out_gpkg=out, map_source=maps, progress=False, workers=1)
    cams = pyogrio.read_dataframe(out, layer="cameras").set_index("id")
    assert cams.loc["d1", "status"] == "located"
    assert cams.loc["d1", "extract"] == BALTIMORE.name
    assert cams.loc["d1", "lat"] == pytest.approx(39.2854, abs=0.001)
    assert cams.loc["d1", "lon"] == pytest.approx(-76.5933, abs=0.001)
    # a scene that cannot be read still says so
    assert cams.loc["d2", "status"] == "scene_error"


def test_job_camera_with_only_an_inline_scene_is_located(tmp_path: Path, maps: Path) -> None:
    from camloc_geo.service.mapstore import MapStore
    from camloc_geo.service.routers.jobs import camera_records
    from camloc_geo.service.settings import Settings
    from camloc_geo.service.work import process_camera

    settings = Settings(map_dir=maps, network=False, data_dir=tmp_path / "data")
    scene = json.loads(SCENE.read_text(encoding="utf-8"))
    body = json.dumps({"cameras": [{"id": "d", "scene": scene}]}).encode()
    (scene_cam,) = camera_records(body, "application/json", 10)
    located = process_camera(scene_cam, MapStore(settings), settings)
    assert located["status"] == "located", located["reason"]


def test_job_row_problems_survive_the_stored_list(tmp_path: Path, maps: Path) -> None:
    from camloc_geo.service.mapstore import MapStore
    from camloc_geo.service.routers.jobs import camera_records
    from camloc_geo.service.settings import Settings
    from camloc_geo.service.work import process_camera

    settings = Settings(map_dir=maps, network=False, data_dir=tmp_path / "data")
    store = MapStore(settings)
    body = json.dumps(
        {
            "cameras": [
                {"id": "c", "title": "Eastern Ave & S Broadway", "lat": "abc", "lon": -76.59},
                {"id": "e", "title": "Nowhere & Fake", "lat": 95, "lon": -76.59},
            ]
        }
    ).encode()
    bad_lat, off_earth = camera_records(body, "application/json", 10)
    placed = process_camera(bad_lat, store, settings)
    assert placed["status"] == "title_only"
    assert placed["reason"].count("list row: lat 'abc' is not a number") == 1
    missed = process_camera(off_earth, store, settings)
    assert missed["status"] == "not_found"
    assert "lat=95.0, lon=-76.59 is not a point on Earth" in missed["reason"]
    csv_cam = camera_records(
        b"id,title,lat,lon\nc,Eastern Ave & S Broadway,abc,-76.59\n", "text/csv", 10
    )[0]
    assert "lat 'abc' is not a number" in process_camera(csv_cam, store, settings)["reason"]
