"""A rough intersection lat/lon (webcam listings give "a rough point"): no junction within
25 m of it, so the junctions around it are searched (``benchmarks/absolute_slips.py``'s
``intersection_latlon_off``). Noise-free annotations at real Baltimore junctions."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camloc_geo import MapDataError
from camloc_geo.absolute import LocateResult, locate
from camloc_geo.absolute._evidence import LATLON_SEARCH_M, latlon_search
from camloc_geo.geodesy import LocalFrame, distance_m
from camloc_geo.osm import MapData, load_map
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import LocatedScene, NoiseModel, make_located_scene

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"


@pytest.fixture(scope="module")
def baltimore() -> MapData:
    return load_map(OSM / "baltimore.osm.pbf", 39.2851, -76.5934, radius_m=300)


def _located(m: MapData, inter_id: str, seed: int) -> LocatedScene:
    ls = make_located_scene(
        m,
        m.intersection(inter_id),
        np.random.default_rng(seed),
        noise=NoiseModel.exact(),
        corner_sigma_m=0.0,
        min_corners=2,
    )
    assert ls is not None
    return ls


def _errors(res: LocateResult, ls: LocatedScene) -> list[float]:
    return [
        float(distance_m(lat1=c.lat, lon1=c.lon, lat2=ls.lat, lon2=ls.lon)) for c in res.candidates
    ]


def _moved(scene: dict[str, Any], east_m: float, north_m: float) -> dict[str, Any]:
    """The scene with its intersection lat/lon moved ``east_m``, ``north_m``."""
    out = json.loads(json.dumps(scene))
    it = out["intersection"]
    lon, lat = LocalFrame(lat=it["lat"], lon=it["lon"]).geographic_from_enu(east_m, north_m)
    it["lat"], it["lon"] = float(lat), float(lon)
    return out


@pytest.mark.parametrize(
    ("inter_id", "seed", "east_m", "north_m"),
    [
        ("c49531205", 9, 0.0, 60.0),  # Aliceanna Street & South Broadway, 60 m north
        ("n49494688", 4, -45.0, -40.0),  # Aliceanna & South Bethel, 60 m south-west
    ],
)
def test_rough_intersection_point_searches_the_junctions_around_it(
    baltimore: MapData, inter_id: str, seed: int, east_m: float, north_m: float
) -> None:
    # Old code: MapDataError "no modelled junction matches the scene's intersection".
    # Now the junctions with kerb corners within 200 m are tried, and the warning names the
    # junction the best candidate stands at and its distance from the stated point.
    ls = _located(baltimore, inter_id, seed)
    scene = _moved(ls.scene, east_m, north_m)
    it = scene["intersection"]
    assert not baltimore.intersections_within(lat=it["lat"], lon=it["lon"], radius_m=25.0)
    res = locate(parse_scene(scene), baltimore)
    errs = _errors(res, ls)
    assert min(errs) < 1.0
    assert errs[0] < 1.0 or res.candidates[0].ambiguous_with  # right, or a tie named
    assert len({c.intersection_id for c in res.candidates}) > 1  # several junctions tried
    warned = [w for w in res.warnings if "were matched at the" in w]
    assert len(warned) == 1
    if errs[0] < 1.0:
        d = baltimore.distance_to_m(baltimore.intersection(inter_id), lat=it["lat"], lon=it["lon"])
        assert f"junction {inter_id} " in warned[0]
        assert f"{d:.0f} m from the stated point" in warned[0]
        assert abs(d - math.hypot(east_m, north_m)) < 15.0
        assert res.intersection is not None
        assert res.intersection.id == inter_id


def test_exact_intersection_point_searches_nothing(baltimore: MapData) -> None:
    # The clean scene: one junction, no search, no search warning.
    ls = _located(baltimore, "c49531205", 9)
    res = locate(parse_scene(ls.scene), baltimore)
    assert _errors(res, ls)[0] < 1.0
    assert {c.intersection_id for c in res.candidates} == {"c49531205"}
    assert not [w for w in res.warnings if "were matched at the" in w]


def test_point_farther_than_the_search_radius_is_refused_naming_the_nearest(
    baltimore: MapData,
) -> None:
    ls = _located(baltimore, "c49531205", 9)
    scene = _moved(ls.scene, 0.0, -600.0)  # in the harbour, no junction within 200 m
    it = scene["intersection"]
    assert not latlon_search(baltimore, it["lat"], it["lon"], None)
    with pytest.raises(MapDataError) as exc:
        locate(parse_scene(scene), baltimore)
    text = str(exc.value)
    assert "no modelled junction within 25 m" in text
    assert f"none with kerb corners within {LATLON_SEARCH_M:.0f} m" in text
    assert "nearest: " in text
    assert " at " in text


def test_search_odds_fall_with_distance(baltimore: MapData) -> None:
    x = baltimore.intersection("c49531205")
    lon, lat = LocalFrame(lat=x.lat, lon=x.lon).geographic_from_enu(0.0, 60.0)
    found = latlon_search(baltimore, float(lat), float(lon), None)
    assert 2 <= len(found) <= 8
    assert found[0][2] == 0.0
    dists = [d for _x, d, _lp in found]
    priors = [lp for _x, _d, lp in found]
    assert dists == sorted(dists)
    assert priors == sorted(priors, reverse=True)
    assert all(d <= LATLON_SEARCH_M for d in dists)
    assert priors[-1] < priors[0] - 0.3
    # with street names, a junction where they do not meet is at odds 0.2 more
    named = latlon_search(baltimore, float(lat), float(lon), ["Aliceanna Street", "Broadway"])
    assert named[0][0].id == "c49531205"
    others = {x.id: lp for x, _d, lp in found}
    for y, _d, lp in named[1:]:
        assert lp == pytest.approx(others[y.id] - others["c49531205"] + math.log(0.2))


def test_tie_across_searched_junctions_says_why(baltimore: MapData) -> None:
    # Aliceanna & South Bethel, the point 60 m south-west: its candidates tie with those of
    # n49489908 (and a third junction's); the tie names the junction search, not a
    # symmetric junction.
    ls = _located(baltimore, "n49494688", 4)
    res = locate(parse_scene(_moved(ls.scene, -45.0, -40.0)), baltimore)
    tie = next(t for t in res.ties if 1 in t.ranks)
    ids = {res.candidates[r - 1].intersection_id for r in tie.ranks}
    assert {"n49494688", "n49489908"} <= ids
    assert tie.why.startswith("the junctions around the scene's intersection lat/lon")
    # a tie within one junction keeps the usual reason
    ls = _located(baltimore, "c49531205", 9)
    res = locate(parse_scene(_moved(ls.scene, 0.0, 60.0)), baltimore)
    tie = next(t for t in res.ties if 1 in t.ranks)
    assert {res.candidates[r - 1].intersection_id for r in tie.ranks} == {"c49531205"}
    assert tie.why.startswith("a symmetric junction cannot tell them apart")


def test_rough_point_with_street_names_prefers_the_named_junction(baltimore: MapData) -> None:
    # Aliceanna Street & South Broadway, its point 90 m east and its streets named. Old code:
    # MapDataError ("the scene's intersection ... is 90 m from its lat/lon, more than 25 m").
    # Now the search keeps the named junction at even odds and the others at 0.2 more.
    ls = _located(baltimore, "c49531205", 9)
    scene = _moved(ls.scene, 90.0, 0.0)
    scene["intersection"]["streets"] = ["Aliceanna Street", "South Broadway"]
    res = locate(parse_scene(scene), baltimore)
    errs = _errors(res, ls)
    assert errs[0] < 1.0
    assert res.candidates[0].intersection_id == "c49531205"
    warned = [w for w in res.warnings if "were matched at the" in w]
    assert len(warned) == 1
    assert "junction c49531205 (Aliceanna Street & South Broadway)" in warned[0]


@pytest.mark.parametrize(
    ("inter_id", "seed", "stated_id"),
    [
        ("c49489906", 1, "n49489907"),  # the stated point at a junction 114 m away
        ("n998949631", 1, "c49493751"),  # 65 m away
    ],
)
def test_rough_point_at_a_junction_that_fits_badly_tries_the_junctions_around_it(
    baltimore: MapData, inter_id: str, seed: int, stated_id: str
) -> None:
    # The stated lat/lon is another junction's (a rough point that lands within 25 m of the
    # wrong junction). Old code took it at its word: every candidate stood at that junction,
    # none within 15 m of the camera. That junction fits the image badly (its best candidate
    # is implausible on the map), so the junctions within 200 m are tried too, and the
    # warning names the one the answer stands at.
    ls = _located(baltimore, inter_id, seed)
    scene = json.loads(json.dumps(ls.scene))
    stated = baltimore.intersection(stated_id)
    scene["intersection"]["lat"], scene["intersection"]["lon"] = stated.lat, stated.lon
    res = locate(parse_scene(scene), baltimore)
    errs = _errors(res, ls)
    assert errs[0] < 1.0
    assert res.candidates[0].intersection_id == inter_id
    assert res.intersection is not None
    assert res.intersection.id == inter_id
    warned = [w for w in res.warnings if "fits the image badly" in w]
    assert len(warned) == 1
    d = baltimore.distance_to_m(baltimore.intersection(inter_id), lat=stated.lat, lon=stated.lon)
    assert f"{stated_id} (" in warned[0]
    assert f"stands at junction {inter_id} " in warned[0]
    assert f"{d:.0f} m from the stated point" in warned[0]
    assert not [w for w in res.warnings if w.startswith("corners: the scene lists")]


def test_stated_junction_that_fits_well_is_taken_at_its_word(baltimore: MapData) -> None:
    # A clean scene's junction fits: its neighbours are not tried (no candidate elsewhere,
    # no junction warning), however well they would fit.
    from camloc_geo.absolute._pipeline import fits_badly

    ls = _located(baltimore, "c49531205", 9)
    res = locate(parse_scene(ls.scene), baltimore)
    assert not fits_badly(res.candidates)
    assert {c.intersection_id for c in res.candidates} == {"c49531205"}
    assert not [w for w in res.warnings if "fits the image badly" in w]
    assert fits_badly([])
