"""camloc_geo.geocode from Python: bad input is the package's error; an area in one map of many."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from camloc_geo._errors import InputError, MapDataError
from camloc_geo.geocode import geocode_title, geocode_title_in_maps, whole_map
from camloc_geo.osm import MapData

REPO = Path(__file__).resolve().parents[1]
OSM_DIR = REPO / "data" / "osm"


@pytest.fixture(scope="module")
def baltimore() -> MapData:
    return whole_map(REPO / "sample_maps" / "baltimore.osm.pbf")


@pytest.fixture(scope="module")
def krems() -> MapData:
    return whole_map(REPO / "data" / "osm" / "krems.osm.gz")


def test_area_found_in_the_second_map_of_a_folder(baltimore: MapData, krems: MapData) -> None:
    """An area named in one extract only: the first extract's 'not a named place' (an
    InputError, not caught) sank the whole search."""
    best = geocode_title_in_maps("Eastern & Broadway", [krems, baltimore], area="Patterson Park")
    assert best[0].status == "junction"
    assert best[0].lat == pytest.approx(39.2856, abs=2e-3)
    with pytest.raises(MapDataError, match="'Nowhere Park' is not a named place of any map"):
        geocode_title_in_maps("Eastern & Broadway", [krems, baltimore], area="Nowhere Park")


CASES: list[tuple[str, Callable[[MapData], Any], type[Exception], str]] = [
    (
        "map None",
        lambda m: geocode_title("A & B", map_data=None),  # type: ignore[arg-type]
        MapDataError,
        "map_data must be a MapData",
    ),
    (
        "map path",
        lambda m: geocode_title("A & B", map_data="x.osm"),  # type: ignore[arg-type]
        MapDataError,
        "not str",
    ),
    (
        "near short",
        lambda m: geocode_title("A & B", map_data=m, near=(1.0,)),  # type: ignore[arg-type]
        InputError,
        "near must be (lat, lon)",
    ),
    (
        "near text",
        lambda m: geocode_title("A & B", map_data=m, near=("a", "b")),  # type: ignore[arg-type]
        InputError,
        "near must be (lat, lon)",
    ),
    (
        "radius text",
        lambda m: geocode_title("A & B", map_data=m, radius_m="far"),  # type: ignore[arg-type]
        InputError,
        "radius_m must be a positive number",
    ),
    (
        "no maps",
        lambda m: geocode_title_in_maps("A & B", []),
        MapDataError,
        "no maps to search",
    ),
    (
        "maps a path",
        lambda m: geocode_title_in_maps("A & B", "maps/"),  # type: ignore[arg-type]
        MapDataError,
        "maps must be a list of MapData",
    ),
    (
        "maps of paths",
        lambda m: geocode_title_in_maps("A & B", [m, "x.osm"]),  # type: ignore[list-item]
        MapDataError,
        "maps[1] must be a MapData",
    ),
    (
        "whole_map int",
        lambda m: whole_map(5),  # type: ignore[arg-type]
        MapDataError,
        "must be a str or a Path",
    ),
]


@pytest.mark.parametrize(
    ("call", "error", "words"), [c[1:] for c in CASES], ids=[c[0] for c in CASES]
)
def test_bad_input_is_named(
    baltimore: MapData, call: Callable[[MapData], Any], error: type[Exception], words: str
) -> None:
    """Before: AttributeError 'source', IndexError, ValueError, TypeError."""
    with pytest.raises(error) as info:
        call(baltimore)
    assert words in str(info.value)


def test_title_match_repr_is_short(baltimore: MapData) -> None:
    """repr() printed the whole Intersection (streets, corners, nodes) and the parsed title:
    2,335 characters for one junction; the fields stay, repr leaves those three out."""
    best = geocode_title("Eastern Ave & S Broadway", map_data=baltimore)[0]
    text = repr(best)
    assert len(text) < 600
    assert text.startswith("TitleMatch(status='junction', lat=39.28557975, lon=-76.59348405")
    assert "Corner(" not in text
    assert best.intersection is not None
    assert best.intersection.id == "c49537218"


def test_an_extract_copied_into_the_folder_after_a_first_look_is_found(tmp_path: Path) -> None:
    """The folder's plan was cached on its name alone, for good: a camera outside every
    extract stayed 'no_map' after the extract covering it was copied in."""
    import shutil

    from camloc_geo.cameras import CameraRow, geocode_camera

    shutil.copy(OSM_DIR / "monaco.osm.pbf", tmp_path)
    row = CameraRow(row=1, id="c", title="Eastern Ave & S Broadway", lat=39.2851, lon=-76.5934)
    assert geocode_camera(row, map_source=tmp_path).status == "no_map"
    shutil.copy(OSM_DIR / "baltimore.osm.pbf", tmp_path)
    assert geocode_camera(row, map_source=tmp_path).status != "no_map"
