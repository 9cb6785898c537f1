"""Where :func:`camloc_geo.testing.synthetic.make_located_scene` puts the car.

The benchmarks' junction cameras (``benchmarks/absolute.py``, ``absolute_slips.py``,
``unseen_cities.py``) stand on the scene maker's placement: a car outside every carriageway
is flagged "car off street" by :func:`camloc_geo.absolute.locate` even when the answer is
right, so the placement must keep it on the road.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from camloc_geo.osm import MapData, load_map
from camloc_geo.testing.synthetic import LocatedScene, NoiseModel, make_located_scene

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"


@pytest.fixture(scope="module")
def baltimore() -> MapData:
    return load_map(OSM / "baltimore.osm.pbf", 39.2851, -76.5934, radius_m=300)


def _car_side_midpoint_enu(ls: LocatedScene, length_m: float = 4.6) -> np.ndarray:
    """The midpoint of the car's long side nearest the camera, ENU metres.

    The scene's world frame has its origin at the car's nearest ground corner and its x
    axis along the car; ``p_enu = world_to_enu @ p_world + origin_enu``.
    """
    world_to_enu = ls.camera_enu.cam_from_world_rotation.T @ ls.camera_world.cam_from_world_rotation
    origin_enu = ls.camera_enu.center_in_world - world_to_enu @ ls.camera_world.center_in_world
    return np.asarray(origin_enu + world_to_enu @ np.array([length_m / 2, 0.0, 0.0]))


def _beyond_nearest_carriageway_m(m: MapData, xy: np.ndarray) -> float:
    """How far ``xy`` stands beyond the kerb of its nearest carriageway (negative: on it)."""
    from shapely.geometry import Point

    pt = Point(float(xy[0]), float(xy[1]))
    idx = m.street_index
    return min(g.distance(pt) - hw for g, hw in zip(idx.geometries, idx.values, strict=True))


def test_cars_at_dual_carriageways_stand_in_a_carriageway(baltimore: MapData) -> None:
    # Baltimore's dual-carriageway junctions: a car follows one of the two carriageways,
    # within that carriageway's half width. Merged, street.width_m spans both and the
    # median; a car placed by it stood up to 7 m outside any carriageway (3 of these 32).
    duals = [i for i in baltimore.intersections if any(s.carriageways > 1 for s in i.streets)]
    assert len(duals) >= 3
    beyond = []
    for inter in duals[:4]:
        for seed in range(8):
            ls = make_located_scene(
                baltimore, inter, np.random.default_rng(seed), noise=NoiseModel.exact()
            )
            assert ls is not None
            beyond.append(_beyond_nearest_carriageway_m(baltimore, _car_side_midpoint_enu(ls)))
    # the side's midpoint is within 0.9 m of the centre, at most half_width - 1 m out
    assert max(beyond) < 0.0, sorted(beyond)[-3:]


def test_cars_at_single_carriageways_stand_in_their_street(baltimore: MapData) -> None:
    singles = [i for i in baltimore.intersections if all(s.carriageways == 1 for s in i.streets)]
    beyond = []
    for inter in singles[:6]:
        for seed in range(3):
            ls = make_located_scene(
                baltimore, inter, np.random.default_rng(seed), noise=NoiseModel.exact()
            )
            if ls is not None:
                beyond.append(_beyond_nearest_carriageway_m(baltimore, _car_side_midpoint_enu(ls)))
    assert len(beyond) >= 12
    assert max(beyond) < 0.0, sorted(beyond)[-3:]


def test_cars_at_a_wide_median_stand_in_a_carriageway() -> None:
    # Moscow's Academician Korolev Street: two carriageways 23 m apart, each 11 m from the
    # merged axis; the car is placed on one of them (none was placed with a 10 m reach).
    m = load_map(OSM / "moscow_ostankino.osm.gz", 55.8215, 37.6038, radius_m=300)
    inter, _ = m.match_intersection(lat=55.8214925, lon=37.6037556, max_distance_m=15)
    assert inter is not None
    assert min(s.carriageways for s in inter.streets) == 2
    beyond = []
    for seed in range(4):
        ls = make_located_scene(m, inter, np.random.default_rng(seed), noise=NoiseModel.exact())
        assert ls is not None
        beyond.append(_beyond_nearest_carriageway_m(m, _car_side_midpoint_enu(ls)))
    assert max(beyond) < 0.0, beyond
