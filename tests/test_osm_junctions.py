"""Junction kinds the model must cover (issue 10), on snippets of the real extracts in data/osm.

Each test loads a small radius around one real junction and asserts the intersection (its
streets, its kind) and its kerb corners: how many, and where (half a carriageway from each
of the two streets they lie between, at the distance the two streets' angle gives).
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from camloc_geo import MapDataError
from camloc_geo.geodesy import LocalFrame, bearing_deg, distance_m
from camloc_geo.osm import Intersection, MapData, load_map

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"


def _load(name: str, lat: float, lon: float, radius_m: float = 80.0) -> MapData:
    return load_map(OSM / name, lat, lon, radius_m)


def _junction_at(name: str, lat: float, lon: float) -> Intersection:
    """The intersection an extract's map (80 m around the point) matches at the point."""
    x, _ = _load(name, lat, lon).match_intersection(lat=lat, lon=lon)
    assert x is not None
    return x


def _offset_m(x: Intersection, lon: float, lat: float, bearing: float) -> float:
    """Signed distance of a point from the line through the centre with this bearing."""
    e, n = LocalFrame(lat=x.lat, lon=x.lon).enu_from_geographic(lat=lat, lon=lon)
    t = math.radians(bearing)
    return float(e * math.cos(t) - n * math.sin(t))


def _assert_corners_on_kerbs(x: Intersection) -> None:
    """Every corner lies half a carriageway from both its streets, clockwise between them."""
    streets = list(x.streets)
    expected = []
    for i, a in enumerate(streets):
        b = streets[(i + 1) % len(streets)]
        gap = (b.bearing_deg - a.bearing_deg) % 360.0
        if 15.0 <= gap < 160.0:  # a sharper fork's corner is its gore's nose, far out
            expected.append((a, b, gap))
    noses = sum("gore's nose" in w for w in x.warnings)
    assert len(x.corners) == len(expected) + noses
    for a, b, gap in expected:
        mid = (a.bearing_deg + gap / 2.0) % 360.0
        corner = min(
            (c for c in x.corners if c.streets == (a.name, b.name)),
            key=lambda c: abs(
                (bearing_deg(lat1=x.lat, lon1=x.lon, lat2=c.lat, lon2=c.lon) - mid + 180.0) % 360.0
                - 180.0
            ),
        )
        assert abs(_offset_m(x, corner.lon, corner.lat, a.bearing_deg)) == pytest.approx(
            a.width_m / 2.0, abs=0.3
        )
        assert abs(_offset_m(x, corner.lon, corner.lat, b.bearing_deg)) == pytest.approx(
            b.width_m / 2.0, abs=0.3
        )
        if a.width_m == b.width_m:  # on the bisector, w/2 / sin(gap/2) from the centre
            e, n = LocalFrame(lat=x.lat, lon=x.lon).enu_from_geographic(
                lat=corner.lat, lon=corner.lon
            )
            d = math.hypot(e, n)
            assert d == pytest.approx(a.width_m / 2.0 / math.sin(math.radians(gap / 2)), abs=0.5)


def ring_of_corners(x: Intersection) -> tuple[float, float]:
    """The circle through an intersection's corners (algebraic least squares, in metres):
    its radius and the largest corner's distance off it."""
    import numpy as np

    frame = LocalFrame(lat=x.lat, lon=x.lon)
    xy = np.array([frame.enu_from_geographic(lat=c.lat, lon=c.lon) for c in x.corners], float)
    a = np.column_stack([xy[:, 0], xy[:, 1], np.ones(len(xy))])
    (d, e, f), *_ = np.linalg.lstsq(a, -(xy**2).sum(axis=1), rcond=None)
    centre = np.array([-d / 2.0, -e / 2.0])
    radius = float(np.sqrt(centre @ centre - f))
    return radius, float(np.abs(np.hypot(*(xy - centre).T) - radius).max())


def _names(x: Intersection) -> list[str]:
    return [s.name for s in x.streets]


def test_plain_t_junction_kotka() -> None:
    """Karhinkatu / Kosselinkatu: two streets leave the node towards the same next node."""
    m = _load("kotka.osm.pbf", 60.5233823, 26.9485972)
    x, warnings = m.match_intersection(lat=60.5233823, lon=26.9485972)
    assert warnings == []
    assert x is not None
    assert x.id == "n876232641"
    assert x.kind == "junction"
    assert _names(x) == ["Karhinkatu", "Karhinkatu", "Kosselinkatu"]
    assert len(x.corners) == 2  # a T: the straight side has no corner
    _assert_corners_on_kerbs(x)
    by_name, _ = m.match_intersection(
        streets="Karhinkatu & Kosselinkatu", lat=60.52338, lon=26.94860
    )
    assert by_name is x


def test_street_meeting_one_carriageway_berlin() -> None:
    """Littenstraße meets the one-way carriageway of Grunerstraße: a T with two corners."""
    m = _load("berlin_alexanderplatz.osm.pbf", 52.5191873, 13.4125554)
    x, warnings = m.match_intersection(streets="Littenstraße & Grunerstraße")
    assert warnings == []
    assert x is not None
    assert x.id == "n2933657337"
    assert _names(x) == ["Grunerstraße", "Littenstraße", "Grunerstraße"]
    assert [s.oneway for s in x.streets] == [True, False, True]
    assert len(x.corners) == 2
    _assert_corners_on_kerbs(x)
    assert {c.streets for c in x.corners} == {
        ("Grunerstraße", "Littenstraße"),
        ("Littenstraße", "Grunerstraße"),
    }


def test_one_way_boulevard_paris() -> None:
    """Rue de Turbigo leaves the one-way Boulevard de Sébastopol."""
    m = _load("paris_bss.osm.pbf", 48.8644209, 2.3515281)
    x, warnings = m.match_intersection(
        lat=48.8644209, lon=2.3515281, streets=["Rue de Turbigo", "Boulevard de Sébastopol"]
    )
    assert warnings == []
    assert x is not None
    assert x.id == "n398708"
    assert _names(x) == ["Boulevard de Sébastopol", "Rue de Turbigo", "Boulevard de Sébastopol"]
    assert len(x.corners) == 2
    _assert_corners_on_kerbs(x)


def test_link_road_baltimore() -> None:
    """Fallsway / East Lexington Street with a trunk link: the link is the third arm."""
    m = _load("baltimore.osm.pbf", 39.2918302, -76.6070481)
    x, warnings = m.match_intersection(streets="Fallsway & East Lexington Street")
    assert warnings == []
    assert x is not None
    assert x.id == "n49484576"
    assert [s.highway for s in x.streets] == ["residential", "trunk_link", "secondary"]
    assert len(x.corners) == 2
    _assert_corners_on_kerbs(x)
    assert ("Fallsway", "East Lexington Street") in {c.streets for c in x.corners}


def test_living_street_alley_paris() -> None:
    """Rue Sainte-Croix de la Bretonnerie: highway=living_street, service=alley."""
    m = _load("paris_bss.osm.pbf", 48.8584984, 2.355264)
    x, warnings = m.match_intersection(
        streets="Rue Sainte-Croix de la Bretonnerie & Rue des Archives"
    )
    assert warnings == []
    assert x is not None
    assert x.id == "n26401417"
    assert _names(x) == [
        "Rue des Archives",
        "Rue Sainte-Croix de la Bretonnerie",
        "Rue des Archives",
        "Rue Sainte-Croix de la Bretonnerie",
    ]
    assert {s.highway for s in x.streets} == {"residential", "living_street"}
    assert len(x.corners) == 4
    _assert_corners_on_kerbs(x)


def test_same_name_fork_kotka() -> None:
    """Suurniitynkatu forks into three arms of the same name: a Y with three corners."""
    m = _load("kotka.osm.pbf", 60.5256613, 26.9416883)
    x, warnings = m.match_intersection(lat=60.5256613, lon=26.9416883)
    assert warnings == []
    assert x is not None
    assert x.id == "n773542103"
    assert _names(x) == ["Suurniitynkatu"] * 3
    assert len(x.corners) == 3
    _assert_corners_on_kerbs(x)


def test_named_service_street_is_an_arm_krems() -> None:
    """A named highway=service street is a junction arm (issue 18)."""
    x = _junction_at("krems.osm.gz", 48.403791, 15.655438)
    assert ("An der Schütt", "service") in {(s.name, s.highway) for s in x.streets}
    assert len(x.corners) == 4


def test_pedestrian_segments_are_arms_heidelberg() -> None:
    """Pedestrian segments of named streets meet in junctions (Marktplatz)."""
    x = _junction_at("heidelberg_altstadt.osm.pbf", 49.4122891, 8.710133)
    assert x.id == "n324700898"
    assert [s.highway for s in x.streets] == ["pedestrian"] * 3
    assert len(x.corners) == 2


def test_dual_carriageway_grouped_with_member_nodes_fremantle() -> None:
    """A grouped intersection keeps its nodes: a point at any member node matches it."""
    m = _load("fremantle.osm", -32.0363, 115.7553, 120)
    grouped = [x for x in m.intersections if len(x.osm_nodes) > 1]
    assert grouped
    for x in grouped:
        assert len(x.osm_node_lonlat) == len(x.osm_nodes)
        frame = LocalFrame(lat=x.lat, lon=x.lon)
        span = max(
            math.dist(
                frame.enu_from_geographic(lon=p[0], lat=p[1]),
                frame.enu_from_geographic(lon=q[0], lat=q[1]),
            )
            for p in x.osm_node_lonlat
            for q in x.osm_node_lonlat
        )
        assert span <= 45.0
        for lon, lat in x.osm_node_lonlat:
            hit, warnings = m.match_intersection(lat=lat, lon=lon)
            assert hit is x
            assert warnings == []


# -- the intersection the user meant ------------------------------------------------------


def test_no_junction_near_the_point_warns_and_names_the_nearest() -> None:
    m = _load("kotka.osm.pbf", 60.5233823, 26.9485972, 150)
    # 60 m north of the T junction, along Kosselinkatu: no junction within 25 m
    lon, lat = LocalFrame(lat=60.5233823, lon=26.9485972).geographic_from_enu(-30.0, 55.0)
    x, warnings = m.match_intersection(lat=float(lat), lon=float(lon))
    assert x is None
    assert len(warnings) == 1
    assert "no modelled junction within 25 m" in warnings[0]
    assert "n876232641 (Karhinkatu & Kosselinkatu) at" in warnings[0]


def test_named_junction_far_from_the_point_is_not_taken() -> None:
    m = _load("kotka.osm.pbf", 60.5233823, 26.9485972, 400)
    # the other Karhinkatu / Kosselinkatu junction, 250 m away, is not moved to silently
    x, warnings = m.match_intersection(
        lat=60.5251717, lon=26.9461103, streets="Karhinkatu & Kosselinkatu", max_distance_m=25.0
    )
    assert x is not None
    assert x.id == "n876232723"
    x, warnings = m.match_intersection(
        lat=60.5240, lon=26.9470, streets="Karhinkatu & Kosselinkatu"
    )
    assert x is None
    assert "more than 25 m" in warnings[0]
    x, warnings = m.match_intersection(
        lat=60.5233823, lon=26.9485972, streets="Nowhere & Karhinkatu"
    )
    assert x is None
    assert "no modelled junction of 'Nowhere' & 'Karhinkatu'" in warnings[0]


def test_prior_keeps_every_junction_within_its_radius() -> None:
    m = _load("kotka.osm.pbf", 60.5233823, 26.9485972, 300)
    rows = m.intersections_within(lat=60.5233823, lon=26.9485972, radius_m=200)
    assert rows[0][0].id == "n876232641"
    assert rows[0][1] == pytest.approx(0.0, abs=0.01)
    dists = [d for _x, d in rows]
    assert dists == sorted(dists)
    assert all(d <= 200 for d in dists)
    assert len(rows) >= 3


# -- extract bounds -------------------------------------------------------------------------


def test_junction_beyond_the_declared_box_loads() -> None:
    """West Oakland's header box ends south of 9th Street; the ways it holds go beyond."""
    m = _load("West-Oakland.osm.bz2", 37.8095784, -122.300788, 60)
    x, warnings = m.match_intersection(lat=37.8095784, lon=-122.300788)
    assert warnings == []
    assert x is not None
    assert set(x.street_names) == {"Wood Street", "9th Street"}


def test_thin_map_warns_point_outside_data_refused() -> None:
    m = _load("kotka.osm.pbf", 60.5205, 26.95, 300)
    assert any("ends" in w and "to the south" in w for w in m.warnings)
    inside = _load("kotka.osm.pbf", 60.53, 26.95, 100)
    assert inside.warnings == []
    with pytest.raises(MapDataError, match="outside the extract"):
        _load("kotka.osm.pbf", 60.60, 26.95, 100)


def test_median_opening_has_the_median_noses_moscow() -> None:
    """A gap in the median of a dual carriageway (Ogorodny proezd): four median-nose corners.

    osmnx's graph counts both carriageway nodes as junctions; a camera there sees the two
    ends of the median island either side of the gap, on the carriageways' inner kerbs.
    """
    m = _load("moscow_ostankino.osm.gz", 55.8146, 37.60083)
    x, warnings = m.match_intersection(lat=55.8146, lon=37.60083)
    assert warnings == []
    assert x is not None
    assert x.kind == "junction"
    assert len(x.osm_nodes) == 2
    assert [(s.name, s.carriageways) for s in x.streets] == [("Огородный проезд", 2)] * 2
    assert any("median opening" in w for w in x.warnings)
    assert len(x.corners) == 4
    road = x.streets[0]
    frame = LocalFrame(lat=x.lat, lon=x.lon)
    t = math.radians(road.bearing_deg)
    along = []
    for c in x.corners:
        # inside the road (between its outer kerbs), off its centre line: on the median
        lateral = _offset_m(x, c.lon, c.lat, road.bearing_deg)
        assert 0.2 < abs(lateral) < road.width_m / 2.0 - 2.0
        e, n = frame.enu_from_geographic(lat=c.lat, lon=c.lon)
        along.append(float(e * math.sin(t) + n * math.cos(t)))
    # two corners at each end of the gap, the ends a connector's width (5-12 m) apart
    along.sort()
    assert along[1] - along[0] < 1.0
    assert along[3] - along[2] < 1.0
    assert 5.0 < along[2] - along[1] < 12.0


def test_sharp_fork_keeps_the_other_corners_monaco() -> None:
    """Two streets leaving 14° apart have no corner at the node: their corner is the nose of
    the gore between them, 37 m out where their facing kerbs meet; the others stay."""
    x = _junction_at("monaco.osm.pbf", 43.7398998, 7.423849)
    assert x.kind == "junction"
    assert any("gore's nose" in w for w in x.warnings)
    assert len(x.corners) == 3
    _assert_corners_on_kerbs(x)
    nose = next(
        c
        for c in x.corners
        if c.streets == ("Boulevard Princesse Charlotte", "Avenue Saint-Michel")
    )
    assert 30.0 < distance_m(lat1=x.lat, lon1=x.lon, lat2=nose.lat, lon2=nose.lon) < 45.0
    assert 52.0 < bearing_deg(lat1=x.lat, lon1=x.lon, lat2=nose.lat, lon2=nose.lon) < 66.0


@pytest.mark.parametrize(
    ("name", "lat", "lon", "a", "b", "out_m"),
    [
        # a two-way street splitting into two one-way carriageways 10° apart
        ("kotka.osm.pbf", 60.5332685, 26.9542466, 0, 1, (35.0, 47.0)),
        # a slip road leaving a motorway 6° apart
        ("kotka.osm.pbf", 60.528707, 26.9565551, 0, 1, (50.0, 65.0)),
    ],
)
def test_a_carriageway_split_or_diverge_has_its_gore_nose(
    name: str, lat: float, lon: float, a: int, b: int, out_m: tuple[float, float]
) -> None:
    """Streets forking a few degrees apart meet at no corner by the node; the one corner such
    a junction has is the nose of the gore, where a's right kerb meets b's left kerb (half a
    carriageway right of a, tens of metres out between the two)."""
    x = _junction_at(name, lat, lon)
    assert x.kind == "junction"
    assert len(x.corners) == 1
    assert any("gore's nose" in w for w in x.warnings)
    sa, sb = x.streets[a], x.streets[b]
    nose = x.corners[0]
    assert nose.streets == (sa.name, sb.name)
    d = distance_m(lat1=x.lat, lon1=x.lon, lat2=nose.lat, lon2=nose.lon)
    assert out_m[0] < d < out_m[1]
    brg = bearing_deg(lat1=x.lat, lon1=x.lon, lat2=nose.lat, lon2=nose.lon)
    assert sa.bearing_deg - 2.0 < brg < sb.bearing_deg + 2.0
    assert _offset_m(x, nose.lon, nose.lat, sa.bearing_deg) == pytest.approx(
        sa.width_m / 2.0, abs=0.3
    )
    assert _offset_m(x, nose.lon, nose.lat, sb.bearing_deg) < 0.0  # left of b


def test_roundabout_corners_on_the_ring_paris() -> None:
    """Place Olympe de Gouges: each approach's two kerbs meet the ring's outer kerb.

    The corners lie on one circle (the outer kerb) and come in pairs, one pair per approach;
    approaches that curve into each other near the ring (Rue de Franche-Comté and Rue
    Béranger here) are left out rather than given interleaved corners.
    """
    x = _junction_at("paris_bss.osm.pbf", 48.864697, 2.3646324)
    assert x.kind == "roundabout"
    assert any("outer kerb" in w for w in x.warnings)
    assert len(x.corners) == 6
    radius, misfit = ring_of_corners(x)
    assert 5.0 < radius < 15.0
    assert misfit < 0.5
    # one pair per approach, the ring's name on the other side of each corner
    approaches = [next(n for n in c.streets if n != "Place Olympe de Gouges") for c in x.corners]
    assert (
        approaches
        == ["Rue Charlot", "Rue Charlot", "Rue de Turenne", "Rue de Turenne"] + ["Rue Charlot"] * 2
    )
    assert all("Place Olympe de Gouges" in c.streets for c in x.corners)
