"""Loading extracts: formats, clipping, the in-process cache, buildings and bad input."""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

import osmnx as ox
import pytest
from shapely.geometry import Point

from camloc_geo import MapDataError
from camloc_geo.osm import _map as _map_module
from camloc_geo.osm import clear_cache, load_map

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"


AGUAS = (21.8700, -102.2720)


def test_pbf_and_bz2_xml_give_the_same_map() -> None:
    a = load_map(OSM / "aguascalientes.osm.pbf", *AGUAS, 150)
    b = load_map(OSM / "aguascalientes.osm.bz2", *AGUAS, 150)
    assert len(a.intersections) >= 5
    assert [x.id for x in a.intersections] == [x.id for x in b.intersections]
    for xa, xb in zip(a.intersections, b.intersections, strict=True):
        assert [(c.lat, c.lon, c.streets) for c in xa.corners] == [
            (c.lat, c.lon, c.streets) for c in xb.corners
        ]
    assert len(a.streets) == len(b.streets)


@pytest.mark.parametrize(
    ("name", "lat", "lon"),
    [
        ("krems.osm.gz", 48.4093, 15.6137),
        ("taipei.osm", 25.05224, 121.52256),
        ("West-Oakland.osm.bz2", 37.8076, -122.3004),
        ("moscow_ostankino.osm.gz", 55.81315, 37.59419),
    ],
)
def test_each_format_loads(name: str, lat: float, lon: float) -> None:
    m = load_map(OSM / name, lat, lon, 200)
    assert len(m.intersections) >= 2
    assert any(len(x.corners) == 4 for x in m.intersections)
    assert m.frame.lat0 == lat
    # only intersections within the radius, nearest first
    dists = [m._dist_from(None, x.lat, x.lon) for x in m.intersections]
    assert dists == sorted(dists)
    assert dists[-1] <= 200.0


def test_clip_keeps_whole_streets_but_only_nearby_intersections() -> None:
    small = load_map(OSM / "helsinki.osm.pbf", 60.1699, 24.9384, 80)
    big = load_map(OSM / "helsinki.osm.pbf", 60.1699, 24.9384, 300)
    assert 0 < len(small.intersections) < len(big.intersections)
    big_by_id = {x.id: x for x in big.intersections}
    for x in small.intersections:  # clipping does not change a nearby intersection
        assert x.id in big_by_id
        assert x.corners == big_by_id[x.id].corners


def test_same_area_is_not_parsed_twice(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    src = tmp_path / "oakland.osm.bz2"
    shutil.copy(OSM / "West-Oakland.osm.bz2", src)
    clear_cache()
    first = load_map(src, 37.8076, -122.3004, 150)
    reads: list[Path] = []
    real_read = _map_module.read_extract

    def counting_read(path: Path, *args: Any, **kwargs: Any) -> Any:
        reads.append(path)
        return real_read(path, *args, **kwargs)

    monkeypatch.setattr(_map_module, "read_extract", counting_read)
    again = load_map(str(src), 37.8076, -122.3004, 150.0)
    assert again is first
    assert reads == []  # served from the cache: the file is not read again
    assert load_map(src, 37.8076, -122.3004, 100) is not first  # another area
    stat = src.stat()
    os.utime(src, ns=(stat.st_atime_ns, stat.st_mtime_ns + 2_000_000_000))
    assert load_map(src, 37.8076, -122.3004, 150) is not first  # file changed
    assert len(reads) == 2  # the other area and the changed file were read
    clear_cache()


def test_osmnx_settings_untouched() -> None:
    before = (ox.settings.use_cache, ox.settings.log_console, ox.settings.overpass_url)
    load_map(OSM / "bristol_whitelion.osm.pbf", 51.45544, -2.59523, 100)
    assert (ox.settings.use_cache, ox.settings.log_console, ox.settings.overpass_url) == before


# -- buildings --------------------------------------------------------------------------


def test_buildings_named_with_corners_and_faces() -> None:
    m = load_map(OSM / "bristol_whitelion.osm.pbf", 51.45544, -2.59523, 150)
    assert len(m.buildings) >= 40
    b = m.find_building("the white lion")
    assert b.name == "The White Lion"
    assert b.id.startswith("way/")
    assert b.building == "commercial"
    corners = b.corners
    assert len(corners) == 4
    # clockwise seen from above: negative signed area in (lon, lat)
    area2 = sum(
        x1 * y2 - x2 * y1
        for (x1, y1), (x2, y2) in zip(corners, corners[1:] + corners[:1], strict=True)
    )
    assert area2 < 0
    faces = b.face_midpoints
    assert len(faces) == len(corners)
    for lon, lat in faces:
        assert b.footprint.exterior.distance(Point(lon, lat)) < 1e-7
    levels = m.find_building("Saint Lawrence House")
    assert levels.levels == 12.0
    with pytest.raises(MapDataError, match="White Lyon"):
        m.find_building("White Lyon Pub")


def test_building_name_fallbacks() -> None:
    m = load_map(OSM / "baltimore.osm.pbf", 39.2851, -76.5934, 300)
    market = m.find_building("Broadway Market", near=(39.2856, -76.5934))
    assert market.name == "Broadway Market"
    assert market.footprint.is_valid


# -- bad input --------------------------------------------------------------------------


def test_missing_file() -> None:
    with pytest.raises(MapDataError, match="not found"):
        load_map(OSM / "nope.osm.pbf", 39.0, -76.0)


@pytest.mark.parametrize("name", ["empty.osm.pbf", "empty.osm"])
def test_empty_file(tmp_path: Path, name: str) -> None:
    (tmp_path / name).write_bytes(b"")
    with pytest.raises(MapDataError, match="empty"):
        load_map(tmp_path / name, 39.0, -76.0)


@pytest.mark.parametrize(
    ("name", "content"),
    [
        ("junk.osm.pbf", b"\x00\x01this is not a pbf" * 10),
        ("junk.osm", b"<osm><node id='1' lat='x'"),
        ("junk.osm.gz", b"not gzip at all"),
        ("nothing.osm", b"<?xml version='1.0'?><osm version='0.6'></osm>"),
    ],
)
def test_unreadable_or_empty_extract(tmp_path: Path, name: str, content: bytes) -> None:
    (tmp_path / name).write_bytes(content)
    with pytest.raises(MapDataError, match=name.split(".")[0]):
        load_map(tmp_path / name, 39.0, -76.0)


@pytest.mark.parametrize("lat", ["999", "abc"])
def test_a_node_off_the_globe_is_a_map_error(tmp_path: Path, lat: str) -> None:
    """``<node lat="999">`` (or ``"abc"``) inside a street: osmium's InvalidLocationError was
    not caught, so ``camloc corners`` ended "failed: InvalidLocationError ...", exit 1 (found
    by the session-39 client sweep); it is a MapDataError naming the file, exit 2."""
    xml = (
        "<?xml version='1.0'?><osm version='0.6'>"
        f"<node id='1' lat='{lat}' lon='-76.0'/><node id='2' lat='39.001' lon='-76.0'/>"
        "<way id='5'><nd ref='1'/><nd ref='2'/><tag k='highway' v='residential'/></way>"
        "</osm>"
    )
    (tmp_path / "bad.osm").write_text(xml)
    with pytest.raises(MapDataError, match=r"bad\.osm: a node"):
        load_map(tmp_path / "bad.osm", 39.0, -76.0)


def test_unsupported_suffix(tmp_path: Path) -> None:
    (tmp_path / "map.txt").write_text("hello")
    with pytest.raises(MapDataError, match="unsupported"):
        load_map(tmp_path / "map.txt", 39.0, -76.0)


def test_point_outside_extract() -> None:
    with pytest.raises(MapDataError, match="outside the extract"):
        load_map(OSM / "baltimore.osm.pbf", 48.85, 2.35)


def test_no_streets_near_point() -> None:
    # inside the extract's box, over the harbour water
    with pytest.raises(MapDataError, match="no streets within 50 m"):
        load_map(OSM / "baltimore.osm.pbf", 39.2720, -76.5790, 50)


@pytest.mark.parametrize(
    ("lat", "lon", "radius"), [(91.0, 0.0, 100.0), (float("nan"), 0.0, 100.0), (39.0, -76.0, -5.0)]
)
def test_bad_arguments(lat: float, lon: float, radius: float) -> None:
    with pytest.raises(MapDataError):
        load_map(OSM / "baltimore.osm.pbf", lat, lon, radius)


def _buildings_only(path: Path) -> Path:
    nodes = [(1, 48.0, 11.0), (2, 48.0, 11.0005), (3, 48.0004, 11.0005), (4, 48.0004, 11.0)]
    xml = ['<?xml version="1.0" encoding="UTF-8"?>', '<osm version="0.6">']
    xml += [f'<node id="{i}" lat="{la}" lon="{lo}" version="1"/>' for i, la, lo in nodes]
    xml.append('<way id="10" version="1">')
    xml += [f'<nd ref="{i}"/>' for i in (1, 2, 3, 4, 1)]
    xml += ['<tag k="building" v="yes"/>', "</way>", "</osm>"]
    path.write_text("\n".join(xml), encoding="utf-8")
    return path


@pytest.mark.parametrize("radius_m", [1e9, 5000.0])
def test_an_extract_of_buildings_alone_says_so_whatever_the_radius(
    radius_m: float, tmp_path: Path
) -> None:
    # before: "no streets within 1000000000 m of ..." (the radius was not what was wrong)
    osm = _buildings_only(tmp_path / "buildings.osm")
    with pytest.raises(MapDataError, match=r"buildings\.osm holds buildings but no streets"):
        load_map(osm, 48.0002, 11.00025, radius_m)
