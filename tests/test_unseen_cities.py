"""What broke on the held-out city extracts (``benchmarks/unseen_cities.py``), pinned.

- Berlin's Großer Stern (a ring of 71 m radius): every place a street meets the ring was a
  ``roundabout`` without kerb corners, so no camera there could be located by its corners.
  Now each is an ordinary junction of the ring and the street.
- Harrisburg PA: "2nd Alley & 2nd Avenue" (the two never meet) was placed, ``ambiguous``, at
  seven junctions of 2nd Alley and *South 2nd Street*: a map name of the same core with
  another street type stood in for a 2nd Avenue the map has.
"""

from __future__ import annotations

from pathlib import Path

import pytest

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"


@pytest.fixture(scope="module")
def grosser_stern():  # type: ignore[no-untyped-def]
    from camloc_geo.osm import load_map

    return load_map(OSM / "berlin_siegessaeule.osm.gz", 52.5145, 13.3502, 500.0)


def test_wide_roundabout_ring_meets_streets_at_ordinary_junctions(grosser_stern) -> None:  # type: ignore[no-untyped-def]
    on_ring = [x for x in grosser_stern.intersections if "Großer Stern" in x.street_names]
    assert len(on_ring) >= 8
    for x in on_ring:
        assert x.kind == "junction", (x.id, x.warnings)
        assert len(x.corners) >= 2
        assert any("a wide ring of 71 m radius" in w for w in x.warnings)
        # corners lie between the ring and a street meeting it, 5-35 m from the node
        assert sum("Großer Stern" in c.streets for c in x.corners) >= 2
        assert all(5.0 < d < 35.0 for d in x.corner_distances_m)


def test_wide_ring_junction_hofjaegerallee(grosser_stern) -> None:  # type: ignore[no-untyped-def]
    x = grosser_stern.nearest_intersection(52.51394, 13.35057)
    assert x.id == "n3366747780"
    assert sorted(x.street_names) == ["Großer Stern", "Hofjägerallee"]
    # a T: two corners, one either side of Hofjägerallee, 10 m from the node
    assert [c.streets for c in x.corners] == [
        ("Großer Stern", "Hofjägerallee"),
        ("Hofjägerallee", "Großer Stern"),
    ]
    assert x.corner_distances_m == pytest.approx([10.0, 10.0], abs=0.1)


def test_small_roundabouts_keep_their_ring_corners() -> None:
    """Rings under 60 m radius are still one roundabout with corners on the outer kerb."""
    from camloc_geo.osm import load_map

    m = load_map(OSM / "andorra.osm.pbf", 42.5075, 1.5300, 1500.0)
    rings = [x for x in m.intersections if x.kind == "roundabout"]
    assert rings
    assert any(x.corners and any("outer kerb" in w for w in x.warnings) for x in rings), [
        x.warnings for x in rings
    ]


@pytest.fixture(scope="module")
def harrisburg():  # type: ignore[no-untyped-def]
    from camloc_geo.geocode import whole_map

    return whole_map(OSM / "harrisburg.osm.pbf")


def test_a_street_type_the_map_has_is_not_swapped_for_another(harrisburg) -> None:  # type: ignore[no-untyped-def]
    from camloc_geo.geocode import geocode_title

    found = geocode_title("2nd Alley & 2nd Avenue", map_data=harrisburg)
    assert [f.status for f in found] == ["not_found"]
    assert found[0].names_matched == ["2nd Alley", "2nd Avenue"]
    assert "do not meet" in (found[0].reason or "")


def test_type_left_out_or_matching_still_places(harrisburg) -> None:  # type: ignore[no-untyped-def]
    from camloc_geo.geocode import geocode_title

    # the N/S half left out, the same street type: still South 2nd Street
    best = geocode_title("2nd Street & Paxton Street", map_data=harrisburg)[0]
    assert best.placed
    assert best.lat == pytest.approx(40.2086, abs=0.001)
    assert best.lon == pytest.approx(-76.7894, abs=0.001)


def test_group_leaving_two_streets_is_split_into_its_nodes() -> None:
    """Harrisburg's Beacon Drive: a one-way loop with a 25 m unnamed cut-through.

    The two nodes the cut-through joins were grouped (a short piece across a one-way
    carriageway) into one junction that only two arms leave, and dropped: osmnx's two
    junctions there had no camloc intersection within 100 m. Each node is now a junction.
    """
    from camloc_geo.osm import load_map

    m = load_map(OSM / "harrisburg.osm.pbf", 40.30777, -76.82923, 150.0)
    by_node = {x.osm_nodes: x for x in m.intersections}
    for node in (2374400296, 2374400298):
        x = by_node[(node,)]
        assert x.kind == "junction"
        assert len(x.streets) == 3
        assert len(x.corners) >= 2
        assert all(5.0 < d < 12.0 for d in x.corner_distances_m)
