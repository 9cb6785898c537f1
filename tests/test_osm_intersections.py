"""Intersections and kerb corners on real OSM extracts (data/osm in this repository)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import osmnx as ox
import pytest

from camloc_geo import MapDataError
from camloc_geo.geodesy import LocalFrame, bearing_deg
from camloc_geo.osm import ARM_SAMPLE_M, Intersection, MapData, load_map

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"


def _load(name: str, lat: float, lon: float, radius_m: float = 150.0) -> MapData:
    return load_map(OSM / name, lat, lon, radius_m)


@pytest.fixture(scope="module")
def baltimore() -> MapData:
    return _load("baltimore.osm.pbf", 39.2851, -76.5940, 400.0)


def _angle_diff(a: float, b: float) -> float:
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def _perp_distance_m(x: Intersection, corner_lonlat: tuple[float, float], bearing: float) -> float:
    """Distance from a corner to the straight line through the centre with this bearing."""
    frame = LocalFrame(lat=x.lat, lon=x.lon)
    e, n = frame.enu_from_geographic(lat=corner_lonlat[1], lon=corner_lonlat[0])
    t = math.radians(bearing)
    return abs(e * math.cos(t) - n * math.sin(t))


def _assert_clockwise(x: Intersection) -> None:
    bearings = [s.bearing_deg for s in x.streets]
    assert bearings == sorted(bearings)
    assert all(0.0 <= b < 360.0 for b in bearings)
    corner_bearings = [
        bearing_deg(lat1=x.lat, lon1=x.lon, lat2=c.lat, lon2=c.lon) for c in x.corners
    ]
    assert corner_bearings == sorted(corner_bearings)
    assert [c.order for c in x.corners] == list(range(len(x.corners)))
    assert all(c.intersection_id == x.id for c in x.corners)
    names = set(x.street_names)
    assert all(set(c.streets) <= names for c in x.corners)


def _assert_kerbs_at_half_widths(x: Intersection) -> None:
    """Single-node junction: each corner is half a carriageway from both its streets."""
    by_name_bearing = list(x.streets)
    n = len(by_name_bearing)
    for i, a in enumerate(by_name_bearing):
        b = by_name_bearing[(i + 1) % n]
        gap = (b.bearing_deg - a.bearing_deg) % 360.0
        if gap >= 160.0:
            continue
        corner = min(
            (c for c in x.corners if c.streets == (a.name, b.name)),
            key=lambda c: _angle_diff(
                bearing_deg(lat1=x.lat, lon1=x.lon, lat2=c.lat, lon2=c.lon), a.bearing_deg + gap / 2
            ),
        )
        assert _perp_distance_m(x, (corner.lon, corner.lat), a.bearing_deg) == pytest.approx(
            a.width_m / 2, abs=0.05
        )
        assert _perp_distance_m(x, (corner.lon, corner.lat), b.bearing_deg) == pytest.approx(
            b.width_m / 2, abs=0.05
        )


# -- a grid: Baltimore ------------------------------------------------------------------


def test_grid_four_way_corners(baltimore: MapData) -> None:
    x = baltimore.find_intersection("Eastern Avenue & South Bond Street")
    assert x.id == "n49478228"
    assert x.kind == "junction"
    assert x.lat == pytest.approx(39.2854942)
    assert x.lon == pytest.approx(-76.5953525)
    assert [s.name for s in x.streets] == [
        "Eastern Avenue",
        "South Bond Street",
        "Eastern Avenue",
        "South Bond Street",
    ]
    assert [round(s.bearing_deg) for s in x.streets] == [86, 177, 267, 357]
    eastern = x.streets[0]
    assert eastern.highway == "primary"
    assert eastern.lanes == 2.0
    assert eastern.width_source == "lanes"
    assert eastern.width_m == pytest.approx(2 * 3.6)  # North American lane width
    assert x.streets[1].width_source == "default"
    assert len(x.corners) == 4
    assert [c.streets for c in x.corners] == [
        ("South Bond Street", "Eastern Avenue"),
        ("Eastern Avenue", "South Bond Street"),
        ("South Bond Street", "Eastern Avenue"),
        ("Eastern Avenue", "South Bond Street"),
    ]
    _assert_clockwise(x)
    _assert_kerbs_at_half_widths(x)
    # near-perpendicular crossing: successive corners are one street width apart
    d = x.corner_distances_m
    assert len(d) == 4
    widths = [x.streets[1].width_m, eastern.width_m, x.streets[3].width_m, x.streets[2].width_m]
    # corner 0 (NE) -> 1 (SE) crosses Eastern Ave, 1 -> 2 crosses Bond St...
    assert d[0] == pytest.approx(eastern.width_m, abs=0.3)
    assert d[1] == pytest.approx(x.streets[1].width_m, abs=0.3)
    assert d[2] == pytest.approx(x.streets[2].width_m, abs=0.3)
    assert d[3] == pytest.approx(x.streets[3].width_m, abs=0.3)
    assert len(widths) == 4
    enu = x.corners_enu(baltimore.frame)
    assert enu.shape == (4, 2)
    assert float(np.hypot(*(enu[0] - enu[1]))) == pytest.approx(d[0], abs=0.01)


def test_dual_carriageway_is_one_intersection(baltimore: MapData) -> None:
    x = baltimore.find_intersection("Eastern Avenue & South Broadway")
    assert x.id.startswith("c")  # consolidated from several OSM nodes
    assert len(x.osm_nodes) >= 2
    assert x.kind == "junction"
    broadway = [s for s in x.streets if s.name == "South Broadway"]
    eastern = [s for s in x.streets if s.name == "Eastern Avenue"]
    assert len(broadway) == 2
    assert len(eastern) == 2
    assert all(s.carriageways == 2 and not s.oneway for s in broadway)
    # the outer kerbs of the pair: wider than both carriageways together
    assert all(s.width_m > 20.0 for s in broadway)
    assert len(x.corners) == 4
    _assert_clockwise(x)
    d = x.corner_distances_m
    # across Eastern Avenue (narrow) and across South Broadway (wide, median included)
    assert sorted(d)[:2] == pytest.approx([eastern[0].width_m] * 2, abs=0.5)
    assert sorted(d)[2:] == pytest.approx([broadway[0].width_m] * 2, abs=1.0)


def test_bearings_agree_with_osmnx(baltimore: MapData) -> None:
    G = ox.add_edge_bearings(baltimore.graph.copy())
    checked = 0
    for x in baltimore.intersections:
        if len(x.osm_nodes) != 1:
            continue
        for s in x.streets:
            if s.carriageways != 1:
                continue
            u, v = s.edge
            if G.has_edge(u, v):
                data = next(iter(G[u][v].values()))
                osmnx_bearing = data["bearing"]
            else:
                data = next(iter(G[v][u].values()))
                osmnx_bearing = (data["bearing"] + 180.0) % 360.0
            if "geometry" in data or data["length"] < ARM_SAMPLE_M:
                continue  # curved or short edge: we measure the first 20 m on purpose
            assert _angle_diff(s.bearing_deg, osmnx_bearing) < 0.1, (x.id, s.name)
            checked += 1
    assert checked >= 20


def test_every_junction_is_clockwise_and_consistent(baltimore: MapData) -> None:
    assert len(baltimore.intersections) >= 20
    for x in baltimore.intersections:
        _assert_clockwise(x)
        assert len(x.corner_distances_m) == (len(x.corners) if len(x.corners) > 1 else 0)
        if x.kind != "junction":
            assert x.corners == ()
            assert x.warnings
        if len(x.osm_nodes) == 1 and all(s.carriageways == 1 for s in x.streets):
            _assert_kerbs_at_half_widths(x)


def test_nearest_and_name_tolerance(baltimore: MapData) -> None:
    x = baltimore.find_intersection("Eastern Avenue & South Broadway")
    assert baltimore.nearest_intersection(x.lat + 0.00005, x.lon) == x
    for query in (
        "eastern avenue & south broadway",
        "EASTERN AVE and S BROADWAY",
        "S. Broadway / Eastern Ave.",
        ["Eastern Ave", "S Broadway"],
        "Eastern Ave & Broadway",  # words of "South Broadway"
    ):
        assert baltimore.find_intersection(query).id == x.id, query


def test_streets_that_do_not_meet(baltimore: MapData) -> None:
    with pytest.raises(MapDataError) as info:
        baltimore.find_intersection("Eastern Ave & Fleet St")
    msg = str(info.value)
    assert "'Eastern Ave'" in msg
    assert "'Fleet St'" in msg
    assert "Eastern Avenue" in msg
    assert "Fleet Street" in msg
    with pytest.raises(MapDataError, match="Nowhere Road"):
        baltimore.find_intersection("Nowhere Road & Eastern Avenue")
    with pytest.raises(MapDataError, match="two street names"):
        baltimore.find_intersection("Eastern Avenue")


def test_street_bearings(baltimore: MapData) -> None:
    x = baltimore.find_intersection("Eastern Avenue & South Bond Street")
    near = dict(baltimore.street_bearings(x.lat, x.lon, radius_m=20))
    assert set(near) == {"Eastern Avenue", "South Bond Street"}
    assert near["Eastern Avenue"] == pytest.approx(86.7, abs=1.0)
    assert near["South Bond Street"] == pytest.approx(176.7, abs=1.0)
    assert all(0 <= b < 180 for b in near.values())


# -- other layouts ----------------------------------------------------------------------


def test_multi_carriageway_boulevards_taipei() -> None:
    m = _load("taipei.osm", 25.05224, 121.52256, 60)
    x = m.find_intersection("中山北路二段 & 南京東路一段")
    assert x.kind == "junction"
    assert len(x.streets) == 4
    assert [s.carriageways for s in x.streets] == [4, 2, 4, 2]
    assert len(x.corners) == 4
    _assert_clockwise(x)
    assert all(15.0 < d < 35.0 for d in x.corner_distances_m)


def test_dual_carriageway_fremantle() -> None:
    m = _load("fremantle.osm", -32.03606, 115.75579, 80)
    x = m.find_intersection("Stirling Hwy & Tydeman Rd")
    assert x.kind == "junction"
    assert any("slip road" in w for w in x.warnings)
    stirling = [s for s in x.streets if s.name == "Stirling Highway"]
    assert len(stirling) == 2
    assert all(s.carriageways == 2 and s.width_m > 20 for s in stirling)
    assert all(s.highway == "trunk" for s in stirling)
    assert len(x.corners) == 4
    _assert_clockwise(x)


def test_t_junction_old_town_heidelberg() -> None:
    m = _load("heidelberg_altstadt.osm.pbf", 49.409499, 8.704209, 60)
    x = m.find_intersection("Plöck & Theaterstr.")
    assert x.id == "n135780501"
    assert [s.name for s in x.streets] == ["Plöck", "Plöck", "Theaterstraße"]
    plock = x.streets[0]
    assert plock.width_source == "width"
    assert plock.width_m == pytest.approx(4.5)  # tagged width=4.5
    # T junction: no corner on the straight kerb opposite the stem
    assert len(x.corners) == 2
    assert all("Theaterstraße" in c.streets for c in x.corners)
    _assert_clockwise(x)
    _assert_kerbs_at_half_widths(x)
    assert x.corner_distances_m == pytest.approx([8.0, 8.0], abs=0.1)


def test_y_junction_and_roundabout_krems() -> None:
    m = _load("krems.osm.gz", 48.4043, 15.6555, 120)
    y = m.nearest_intersection(48.403791, 15.655438)
    assert y.id[1:] == "327615581"
    # Gewerbeparkstraße bends through the node; An der Schütt leaves as a residential
    # street and, opposite, as a named service street (a junction arm since issue 10)
    assert [(s.name, s.highway) for s in y.streets] == [
        ("Gewerbeparkstraße", "residential"),
        ("An der Schütt", "residential"),
        ("Gewerbeparkstraße", "residential"),
        ("An der Schütt", "service"),
    ]
    gaps = [(y.streets[(i + 1) % 4].bearing_deg - y.streets[i].bearing_deg) % 360 for i in range(4)]
    assert all(g < 160 for g in gaps)
    assert len(y.corners) == 4
    _assert_clockwise(y)
    r = m.nearest_intersection(48.404903, 15.655551)
    assert r.kind == "roundabout"
    # corners where each approach's two kerbs meet the ring's outer kerb: pairs, on a circle
    assert len(r.corners) >= 4
    assert any("outer kerb" in w for w in r.warnings)
    from test_osm_junctions import ring_of_corners

    _radius, misfit = ring_of_corners(r)
    assert misfit < 0.5


def test_five_way_paris() -> None:
    m = _load("paris_bss.osm.pbf", 48.864843, 2.353328, 50)
    x = m.find_intersection("Rue Saint-Martin & Rue de Turbigo & Rue des Gravilliers")
    assert x.id == "n398709"
    assert len(x.streets) == 5
    assert len(x.corners) == 5
    _assert_clockwise(x)
    _assert_kerbs_at_half_widths(x)
    assert len(x.corner_distances_m) == 5


def test_consolidation_matches_osmnx() -> None:
    """Our cluster centres are osmnx.consolidate_intersections' (dead_ends=True)."""
    from camloc_geo.osm._intersections import consolidate_nodes

    m = _load("paris_bss.osm.pbf", 48.8660, 2.3630, 250)
    crs = f"+proj=aeqd +lat_0={m.frame.lat0} +lon_0={m.frame.lon0} +ellps=WGS84 +units=m"
    Gp = ox.project_graph(m.graph, to_crs=crs)
    ours = consolidate_nodes(Gp, 12.0)
    Gc = ox.consolidate_intersections(Gp.copy(), tolerance=12.0, dead_ends=True)
    theirs = np.array(sorted((d["x"], d["y"]) for _n, d in Gc.nodes(data=True)))
    mine = np.array(sorted((x, y) for _m, x, y in ours))
    assert mine.shape == theirs.shape
    np.testing.assert_allclose(mine, theirs, atol=1e-6)
    merged = [members for members, _x, _y in ours if len(members) > 1]
    assert len(merged) >= 5
