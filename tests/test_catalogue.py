"""The map catalogue (:class:`camloc_geo.osm.MapCatalogue`): one rule for the map of a point."""

from __future__ import annotations

import pickle
from pathlib import Path

import pytest

from camloc_geo import MapDataError
from camloc_geo.osm import MapCatalogue, extract_bounds, extract_files, header_box
from camloc_geo.osm import _catalogue as catalogue_module

ROOT = Path(__file__).resolve().parents[1]
OSM = ROOT / "data" / "osm"
BALTIMORE = (39.2856, -76.5935)


def test_a_folder_lists_its_extracts_and_reads_each_bounds_once() -> None:
    files = extract_files(OSM)
    assert len(files) >= 10
    assert all(Path(f).is_absolute() for f in files)
    baltimore = next(f for f in files if f.endswith("baltimore.osm.pbf"))
    s, w, n, e = extract_bounds(baltimore)
    assert s <= BALTIMORE[0] <= n
    assert w <= BALTIMORE[1] <= e
    before = catalogue_module._bounds_cached.cache_info().hits
    extract_bounds(baltimore)
    assert catalogue_module._bounds_cached.cache_info().hits == before + 1


def test_bounds_come_from_the_header_box_when_there_is_one() -> None:
    path = OSM / "baltimore.osm.pbf"
    box = header_box(path)
    if box is None:
        pytest.skip("this extract has no header box")
    assert extract_bounds(path) == box


def test_the_smallest_covering_extract_serves_a_point() -> None:
    cat = MapCatalogue.from_source(OSM)
    area = cat.area_for_point(*BALTIMORE)
    assert area[0] == "file"
    assert area[1].endswith("baltimore.osm.pbf")
    assert cat.source_name(area) == "baltimore.osm.pbf"
    outside = cat.area_for_point(0.0, -30.0)  # the middle of the Atlantic
    assert outside[0] == "none"
    assert "outside every extract" in outside[1]
    with pytest.raises(MapDataError, match="outside every extract"):
        cat.map_for_point(lat=0.0, lon=-30.0)


def test_large_extracts_are_served_by_cells_and_the_network_by_cells(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(catalogue_module, "WHOLE_EXTRACT_MAX_BYTES", 1)
    cat = MapCatalogue.from_source(OSM / "baltimore.osm.pbf")
    area = cat.area_for_point(*BALTIMORE)
    assert area[0] == "cell"
    assert area[2:] == catalogue_module._cell_of(*BALTIMORE)
    assert cat.area_for_search()[0] == "none"  # too large to search a title in whole
    net = MapCatalogue.from_source(None, network=True, cache_folder="/tmp/x")
    assert net.area_for_point(*BALTIMORE) == ("net", *catalogue_module._cell_of(*BALTIMORE))
    assert MapCatalogue.from_source(None).area_for_point(*BALTIMORE)[0] == "none"


def test_a_catalogue_is_a_pure_value() -> None:
    """The same point gets the same area in every process (batch workers, the service)."""
    cat = MapCatalogue.from_source(OSM, area="balti")
    again = pickle.loads(pickle.dumps(cat))
    assert again == cat
    assert again.area_for_point(*BALTIMORE) == cat.area_for_point(*BALTIMORE)
    assert cat.area_for_search()[1].endswith("baltimore.osm.pbf")
    assert MapCatalogue.from_source(cat) is cat


def test_bad_sources_are_named() -> None:
    with pytest.raises(MapDataError, match="not found"):
        MapCatalogue.from_source(OSM / "nowhere")
    with pytest.raises(MapDataError, match="no OSM extracts"):
        MapCatalogue.from_source(ROOT / "docs")


def test_every_entry_point_takes_a_folder() -> None:
    """A folder answers as the extract covering the point does, through one loaded map."""
    from camloc_geo.api import corners_near, map_for_scene, streets_near

    by_folder = corners_near(lat=BALTIMORE[0], lon=BALTIMORE[1], radius_m=60, map_source=OSM)
    by_file = corners_near(
        lat=BALTIMORE[0], lon=BALTIMORE[1], radius_m=60, map_source=OSM / "baltimore.osm.pbf"
    )

    def ids(doc: dict) -> set[str]:
        return {
            f["properties"]["streets"][0] + "/" + f["properties"]["streets"][1]
            for f in doc["features"]
            if f["properties"]["kind"] == "intersection"
        }

    assert ids(by_folder) == ids(by_file)
    assert "Eastern Avenue/South Broadway" in ids(by_folder)
    m = streets_near(lat=BALTIMORE[0], lon=BALTIMORE[1], map_source=OSM)
    assert m is MapCatalogue.from_source(OSM).map_for_point(lat=BALTIMORE[0], lon=BALTIMORE[1])
    scene = ROOT / "sample_maps" / "sample_scene.json"
    assert map_for_scene(scene, map_source=OSM) is m
    assert map_for_scene(scene, map_source=MapCatalogue.from_source(OSM)) is m


def test_a_point_is_served_from_the_index_not_from_every_extract(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Each question read every extract's bounds (a stat and a path normalisation each):
    3000 points over a folder of 26 extracts asked 78,000 times, 0.4-2 s of a batch
    (``benchmarks/catalogue.py``). The index reads each extract once."""
    cat = MapCatalogue.from_source(OSM)
    asked: list[str] = []
    original = catalogue_module.extract_bounds

    def spy(path: str) -> tuple[float, float, float, float]:
        asked.append(str(path))
        return original(path)

    monkeypatch.setattr(catalogue_module, "extract_bounds", spy)
    monkeypatch.setattr(catalogue_module, "_INDEXES", {})
    areas = {cat.area_for_point(BALTIMORE[0] + k * 1e-6, BALTIMORE[1])[1] for k in range(3000)}
    assert len(asked) == len(cat.files)  # once each, for the index
    assert len(areas) == 1
    assert next(iter(areas)).endswith("baltimore.osm.pbf")
    assert cat.area_for_point(0.0, -30.0)[0] == "none"
    assert len(asked) == len(cat.files)


def test_the_index_follows_its_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An extract removed from the folder (or rewritten in place) no longer serves a point."""
    import os
    import shutil

    shutil.copy(OSM / "baltimore.osm.pbf", tmp_path / "a_baltimore.osm.pbf")
    cat = MapCatalogue.from_source(tmp_path)
    assert cat.area_for_point(*BALTIMORE)[0] == "file"
    (tmp_path / "a_baltimore.osm.pbf").unlink()
    assert cat.area_for_point(*BALTIMORE)[0] == "none"  # the folder changed: re-read
    # rewritten in place (the folder's time unchanged): seen at the next periodic look
    shutil.copy(OSM / "baltimore.osm.pbf", tmp_path / "a_baltimore.osm.pbf")
    cat = MapCatalogue.from_source(tmp_path)
    assert cat.area_for_point(*BALTIMORE)[0] == "file"
    folder_ns = os.stat(tmp_path).st_mtime_ns
    shutil.copy(OSM / "monaco.osm.pbf", tmp_path / "a_baltimore.osm.pbf")
    os.utime(tmp_path, ns=(folder_ns, folder_ns))
    monkeypatch.setattr(catalogue_module, "INDEX_RECHECK_S", 0.0)
    assert cat.area_for_point(*BALTIMORE)[0] == "none"
