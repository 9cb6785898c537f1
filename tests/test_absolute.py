"""Absolute localisation (:mod:`camloc_geo.absolute`) on real OSM extracts.

Synthetic cameras stand at real intersections
(:func:`camloc_geo.testing.synthetic.make_located_scene`);
noise-free annotations must give the true position exactly, and the candidate list must keep
the contract of ``../docs/contract.md``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camloc_geo._errors import InputError, MapDataError, SceneError
from camloc_geo.absolute import LocateResult, LocateSettings, locate
from camloc_geo.geodesy import distance_m
from camloc_geo.osm import MapData, load_map
from camloc_geo.relative import calibrate
from camloc_geo.results import candidates_geojson
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import LocatedScene, NoiseModel, make_located_scene

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"


# (extract, lat, lon): a row-house grid, two old towns, a hilly town with irregular streets.
PLACES = {
    "baltimore": ("baltimore.osm.pbf", 39.2851, -76.5934),
    "heidelberg": ("heidelberg_altstadt.osm.pbf", 49.4120, 8.7080),
    "krems": ("krems.osm.gz", 48.4095, 15.6100),
    "monaco": ("monaco.osm.pbf", 43.7384, 7.4246),
}
EXACT = 0.1  # metres


@pytest.fixture(scope="module")
def maps() -> dict[str, MapData]:
    out = {}
    for key, (name, lat, lon) in PLACES.items():
        out[key] = load_map(OSM / name, lat, lon, radius_m=300)
    return out


def junctions(m: MapData) -> list[Any]:
    return [i for i in m.intersections if i.kind == "junction" and len(i.corners) >= 3]


def exact_located(m: MapData, inter: Any, seed: int, **kw: Any) -> LocatedScene:
    kw.setdefault("min_corners", 2)
    ls = make_located_scene(
        m, inter, np.random.default_rng(seed), noise=NoiseModel.exact(), corner_sigma_m=0.0, **kw
    )
    assert ls is not None, f"no placement at {inter.id}"
    return ls


def errors_m(result: LocateResult, ls: LocatedScene) -> list[float]:
    return [
        float(distance_m(lat1=c.lat, lon1=c.lon, lat2=ls.lat, lon2=ls.lon))
        for c in result.candidates
    ]


def car_bearing_deg(ls: LocatedScene) -> float:
    """Bearing of the car's length axis (the world x axis) in the local frame."""
    cam_from_enu = ls.camera_enu.cam_from_world_rotation
    enu_from_world = cam_from_enu.T @ ls.camera_world.cam_from_world_rotation
    x = enu_from_world[:, 0]
    return math.degrees(math.atan2(x[0], x[1])) % 360.0


def ground_refs(
    m: MapData, ls: LocatedScene, pixels: list[tuple[float, float]]
) -> list[dict[str, Any]]:
    """Exact references: the true ground points under the given pixels."""
    g = ls.camera_enu.ground_from_pixels(np.asarray(pixels, dtype=float))
    assert np.all(np.isfinite(g))
    refs = []
    for px, p in zip(pixels, g, strict=True):
        lon, lat = m.frame.geographic_from_enu(float(p[0]), float(p[1]))
        refs.append({"pixel": list(px), "lat": float(lat), "lon": float(lon)})
    return refs


def check_contract(result: LocateResult) -> None:
    cands = result.candidates
    assert cands
    assert sum(c.score for c in cands) == pytest.approx(1.0, abs=1e-9)
    assert [c.rank for c in cands] == list(range(1, len(cands) + 1))
    scores = [c.score for c in cands]
    assert scores == sorted(scores, reverse=True)
    assert all(0.0 <= s <= 1.0 for s in scores)


# ------------------------------------------------------------------ noise-free corners
@pytest.mark.parametrize("place", list(PLACES))
def test_exact_corners_found_at_real_intersections(maps: dict[str, MapData], place: str) -> None:
    m = maps[place]
    js = junctions(m)[:3]
    assert js, f"no junction with three or more corners in {place}"
    for k, inter in enumerate(js):
        ls = exact_located(m, inter, seed=10 + k)
        result = locate(parse_scene(ls.scene), m)
        check_contract(result)
        errs = errors_m(result, ls)
        best = int(np.argmin(errs))
        assert errs[best] < EXACT, (inter.id, errs)
        true = result.candidates[best]
        assert true.method == "corners"
        assert true.residual_m < 0.05
        heading, _pitch, _roll = ls.camera_enu.angles_deg
        assert (true.heading_deg - heading + 180.0) % 360.0 - 180.0 == pytest.approx(0.0, abs=0.05)
        assert true.camera.height_m == pytest.approx(ls.camera_enu.height_m, abs=0.05)
        top = result.candidates[0]
        if errs[0] > EXACT:
            # Only an exact symmetric twin may outrank the truth (it fits as well and its
            # score differs only through the map plausibility factors), or a street-aligned
            # pose that misfits within the corners' noise: either way rank 1 names the truth
            # as tied.
            assert true.rank in top.ambiguous_with, (inter.id, errs[0], top.ambiguous_with)
            if top.residual_m >= 0.05:
                assert top.residual_m < LocateSettings().sigma_corner_m, (inter.id, top.residual_m)
            else:
                assert true.score > 0.5 * top.score, (inter.id, true.score, top.score)


@pytest.mark.parametrize(
    ("place", "inter_id"),
    [("baltimore", "n49471343"), ("krems", "n271438768"), ("monaco", None)],
)
def test_exact_corners_top_candidate_at_asymmetric_junctions(
    maps: dict[str, MapData], place: str, inter_id: str | None
) -> None:
    """All corners visible at a junction whose corner distances have no symmetry."""
    m = maps[place]
    if inter_id is None:
        inter = max(junctions(m), key=lambda i: _asymmetry(i.corner_distances_m))
    else:
        inter = m.intersection(inter_id)
    assert _asymmetry(inter.corner_distances_m) > 2.0
    n = len(inter.corners)
    ls = exact_located(m, inter, seed=3, min_corners=n, max_corners=n)
    result = locate(parse_scene(ls.scene), m)
    errs = errors_m(result, ls)
    assert errs[0] < EXACT, (inter.id, errs)
    assert result.candidates[0].score > 0.5


def _asymmetry(d: list[float]) -> float:
    a = np.asarray(d)
    return float(min(np.abs(a - np.roll(a, s)).max() for s in range(1, len(a))))


# ------------------------------------------------------------------------ references
def test_two_references_unique_and_exact(maps: dict[str, MapData]) -> None:
    m = maps["baltimore"]
    ls = exact_located(m, junctions(m)[0], seed=5)
    scene = dict(ls.scene)
    del scene["intersection"]
    scene["references"] = ground_refs(m, ls, [(400.0, 1000.0), (1500.0, 950.0)])
    result = locate(parse_scene(scene), m)
    check_contract(result)
    assert result.methods_tried == ["two_references"]
    assert len(result.candidates) == 1
    c = result.candidates[0]
    assert c.method == "two_references"
    assert errors_m(result, ls)[0] < EXACT
    assert c.residual_m < 0.01
    assert c.sigma_m is not None
    assert c.sigma_m > 0.0


def test_two_references_without_map(maps: dict[str, MapData]) -> None:
    m = maps["krems"]
    ls = exact_located(m, junctions(m)[0], seed=6)
    scene = dict(ls.scene)
    del scene["intersection"]
    scene["references"] = ground_refs(m, ls, [(300.0, 900.0), (1600.0, 1000.0)])
    result = locate(parse_scene(scene))
    assert len(result.candidates) == 1
    assert errors_m(result, ls)[0] < EXACT


def test_three_references_one_wrong_flags_the_worst(maps: dict[str, MapData]) -> None:
    m = maps["baltimore"]
    ls = exact_located(m, junctions(m)[1], seed=7)
    scene = dict(ls.scene)
    del scene["intersection"]
    refs = ground_refs(m, ls, [(300.0, 1000.0), (1600.0, 1000.0), (960.0, 800.0)])
    e, n = m.frame.enu_from_geographic(lat=refs[1]["lat"], lon=refs[1]["lon"])
    refs[1]["lon"], refs[1]["lat"] = (float(v) for v in m.frame.geographic_from_enu(e + 20.0, n))
    scene["references"] = refs
    result = locate(parse_scene(scene), m)
    check_contract(result)
    assert {c.method for c in result.candidates} == {"two_references"}
    # The joint fit spreads the 20 m error over all three (its largest residual may be at
    # another point); leaving each out in turn names the wrong one, and the fit of the
    # other two, exact, comes first.
    warning = next(w for w in result.warnings if w.startswith("references[1]"))
    assert "20.0 m" in warning
    c = result.candidates[0]
    assert "worst_reference:references[1]" in c.flags
    assert "poor_fit" not in c.flags
    assert errors_m(result, ls)[0] < EXACT
    misfits = {mt["label"]: mt["misfit_m"] for mt in c.matches if mt["kind"] == "reference"}
    assert misfits["references[1]"] == pytest.approx(20.0, abs=0.5)
    assert misfits["references[0]"] < EXACT
    assert misfits["references[2]"] < EXACT


def test_three_exact_references_flag_nothing_far(maps: dict[str, MapData]) -> None:
    m = maps["baltimore"]
    ls = exact_located(m, junctions(m)[1], seed=7)
    scene = dict(ls.scene)
    del scene["intersection"]
    scene["references"] = ground_refs(m, ls, [(300.0, 1000.0), (1600.0, 1000.0), (960.0, 800.0)])
    result = locate(parse_scene(scene), m)
    c = result.candidates[0]
    assert errors_m(result, ls)[0] < EXACT
    assert c.residual_m < 0.01
    assert any(w.endswith("0.0 m from where they put it") for w in result.warnings)


def test_one_reference_with_street_bearing_gives_two_candidates(maps: dict[str, MapData]) -> None:
    m = maps["heidelberg"]
    ls = exact_located(m, junctions(m)[0], seed=8)
    scene = dict(ls.scene)
    del scene["intersection"]
    scene["references"] = ground_refs(m, ls, [(900.0, 950.0)])
    scene["street_bearing_deg"] = (car_bearing_deg(ls) + 180.0) % 360.0  # either direction
    result = locate(parse_scene(scene), m)
    check_contract(result)
    assert result.methods_tried == ["one_reference"]
    assert len(result.candidates) == 2
    assert {c.method for c in result.candidates} == {"one_reference"}
    errs = errors_m(result, ls)
    assert min(errs) < EXACT
    # The other is the car turned end for end about the reference point.
    assert max(errs) > 1.0


def test_one_reference_with_map_bearings(maps: dict[str, MapData]) -> None:
    """Without a stated bearing the streets near the reference give them: two per direction."""
    m = maps["baltimore"]
    inter = junctions(m)[0]
    ls = exact_located(m, inter, seed=9)
    scene = dict(ls.scene)
    del scene["intersection"]
    scene["references"] = ground_refs(m, ls, [(900.0, 950.0)])
    result = locate(parse_scene(scene), m)
    check_contract(result)
    ref = scene["references"][0]
    n_bearings = len({round(b) % 180 for _n, b in m.street_bearings(ref["lat"], ref["lon"], 25.0)})
    assert 2 <= len(result.candidates) <= 2 * n_bearings
    # The synthetic car is parallel to its street within a couple of degrees.
    assert min(errors_m(result, ls)) < 3.0


# -------------------------------------------------------------------------- output
def test_geojson_contract(maps: dict[str, MapData]) -> None:
    m = maps["krems"]
    ls = exact_located(m, junctions(m)[0], seed=11)
    result = locate(parse_scene(ls.scene), m)
    doc = json.loads(json.dumps(candidates_geojson(result), allow_nan=False))
    assert doc["type"] == "FeatureCollection"
    cands = [f for f in doc["features"] if f["properties"]["kind"] == "candidate"]
    cones = [f for f in doc["features"] if f["properties"]["kind"] == "view_cone"]
    assert len(cands) == len(result.candidates)
    required = {
        "kind",
        "rank",
        "score",
        "lat",
        "lon",
        "height_m",
        "heading_deg",
        "pitch_deg",
        "roll_deg",
        "focal_px",
        "method",
        "residual_m",
    }
    for f, c in zip(cands, result.candidates, strict=True):
        p = f["properties"]
        assert required <= set(p), required - set(p)
        assert f["geometry"]["type"] == "Point"
        assert f["geometry"]["coordinates"] == [p["lon"], p["lat"]]
        assert p["lon"] == pytest.approx(c.lon)
        assert p["lat"] == pytest.approx(c.lat)
        assert 0.0 <= p["heading_deg"] < 360.0
        assert p["method"] in {"two_references", "one_reference", "corners", "landmark"}
    assert [f["properties"]["rank"] for f in cands] == list(range(1, len(cands) + 1))
    assert sum(f["properties"]["score"] for f in cands) == pytest.approx(1.0)
    # [lon, lat] order: Krems is at 15.6° E, 48.4° N.
    lon, lat = cands[0]["geometry"]["coordinates"]
    assert 15.5 < lon < 15.7
    assert 48.3 < lat < 48.5
    assert len(cones) == len(cands)
    for cone, cand in zip(cones, cands, strict=True):
        assert cone["geometry"]["type"] == "Polygon"
        ring = cone["geometry"]["coordinates"][0]
        assert len(ring) >= 4
        assert ring[0] == ring[-1]
        (lon1, lat1), (lon2, lat2) = ring[0], cand["geometry"]["coordinates"]
        assert distance_m(lat1=lat1, lon1=lon1, lat2=lat2, lon2=lon2) < 0.01
        assert cone["properties"]["rank"] == cand["properties"]["rank"]
    kinds = {f["properties"]["kind"] for f in doc["features"]}
    assert {"intersection", "corner"} <= kinds


# ------------------------------------------------------------------------- bad input
def test_no_geographic_evidence_gives_reason(maps: dict[str, MapData]) -> None:
    m = maps["baltimore"]
    ls = exact_located(m, junctions(m)[0], seed=12)
    scene = dict(ls.scene)
    del scene["intersection"]
    result = locate(parse_scene(scene), m)
    assert result.candidates == []
    assert result.reason is not None
    assert "no geographic evidence" in result.reason
    del scene["prior"]
    with pytest.raises(SceneError, match="prior"):
        locate(parse_scene(scene))


def test_corners_without_map_is_an_error(maps: dict[str, MapData]) -> None:
    m = maps["baltimore"]
    ls = exact_located(m, junctions(m)[0], seed=13)
    with pytest.raises(MapDataError, match="no map"):
        locate(parse_scene(ls.scene))


def test_duplicate_corner_pixels_are_an_error(maps: dict[str, MapData]) -> None:
    m = maps["krems"]
    inter = junctions(m)[0]
    ls = exact_located(m, inter, seed=14)
    scene = dict(ls.scene)
    px = scene["intersection"]["corners"][0]
    scene["intersection"] = {**scene["intersection"], "corners": [px] * (len(inter.corners) + 1)}
    with pytest.raises(SceneError, match=r"intersection\.corners\[1\].*same pixel"):
        locate(parse_scene(scene), m)


def test_corners_that_no_assignment_fits(maps: dict[str, MapData]) -> None:
    """Corners seen at a wide junction, the scene naming a small one: nothing fits."""
    m = maps["baltimore"]
    wide, small = m.intersection("c49531205"), m.intersection("n49493753")
    assert min(wide.corner_distances_m) > 2 * max(small.corner_distances_m)
    ls = exact_located(m, wide, seed=15, min_corners=4)
    scene = dict(ls.scene)
    scene["intersection"] = {
        "corners": scene["intersection"]["corners"],
        "lat": small.lat,
        "lon": small.lon,
    }
    result = locate(parse_scene(scene), m)
    assert result.candidates == []
    assert result.reason is not None
    assert result.reason.startswith("no hypothesis fits the corners evidence")
    # The right junction fits.
    assert errors_m(locate(parse_scene(ls.scene), m), ls)[0] < EXACT


def test_references_far_from_the_prior(maps: dict[str, MapData]) -> None:
    m = maps["baltimore"]
    ls = exact_located(m, junctions(m)[0], seed=16)
    scene = dict(ls.scene)
    del scene["intersection"]
    scene["references"] = ground_refs(m, ls, [(400.0, 1000.0), (1500.0, 950.0)])
    # The listed location is 5 km north of where the references are.
    scene["prior"] = {**scene["prior"], "lat": scene["prior"]["lat"] + 0.045, "radius_m": 100.0}
    result = locate(parse_scene(scene), m)
    assert result.candidates == []
    assert result.reason is not None
    assert "prior" in result.reason


def test_unknown_streets_name_the_streets(maps: dict[str, MapData]) -> None:
    m = maps["baltimore"]
    ls = exact_located(m, junctions(m)[0], seed=17)
    scene = dict(ls.scene)
    scene["intersection"] = {
        "corners": scene["intersection"]["corners"],
        "streets": ["Nowhere Lane", "Imaginary Street"],
    }
    with pytest.raises(MapDataError, match="Nowhere Lane") as info:
        locate(parse_scene(scene), m)
    assert isinstance(info.value, InputError)
    assert "Imaginary Street" in str(info.value)


def test_corner_above_the_horizon_is_ignored_with_a_warning(maps: dict[str, MapData]) -> None:
    m = maps["krems"]
    ls = exact_located(m, junctions(m)[0], seed=18, min_corners=3)
    scene = dict(ls.scene)
    corners = [*scene["intersection"]["corners"]]
    hx = ls.camera_enu.horizon_line()
    sky = [960.0, 1.0]
    assert hx @ [*sky, 1.0] < 0
    corners[0] = sky
    scene["intersection"] = {**scene["intersection"], "corners": corners}
    result = locate(parse_scene(scene), m)
    assert any("horizon" in w for w in result.warnings)
    assert result.candidates


def test_precomputed_calibration_is_reused(maps: dict[str, MapData]) -> None:
    m = maps["baltimore"]
    ls = exact_located(m, junctions(m)[2], seed=19)
    scene = parse_scene(ls.scene)
    cal = calibrate(scene)
    a = locate(scene, m, calibration=cal)
    b = locate(scene, m)
    assert a.calibration is cal
    got = np.array([(c.lat, c.lon) for c in a.candidates])
    want = np.array([(c.lat, c.lon) for c in b.candidates])
    assert got.shape == want.shape
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)


# ------------------------------------------------------------------------- generator
def test_located_scenes_can_be_calibrated(maps: dict[str, MapData]) -> None:
    """The generator never looks straight along the car (collinear edges on screen)."""
    m = maps["krems"]
    for k, inter in enumerate(junctions(m)[:3]):
        ls = exact_located(m, inter, seed=10 + k)
        cal = calibrate(parse_scene(ls.scene))
        assert cal.camera.focal_px == pytest.approx(ls.camera_world.focal_px, rel=1e-6)


def test_located_scenes_list_a_partial_view_as_its_clockwise_arc(maps: dict[str, MapData]) -> None:
    """Two of four corners seen are listed the short way round, as a person would."""
    m = maps["baltimore"]
    for k, inter in enumerate(junctions(m)[:6]):
        n = len(inter.corners)
        for seed in range(3):
            ls = exact_located(m, inter, seed=100 * k + seed, max_corners=n - 1)
            vis = ls.visible_corner_orders
            steps = [(vis[(i + 1) % len(vis)] - vis[i]) % n for i in range(len(vis))]
            # The wrap-around step (last back to first) crosses the unseen corners.
            assert steps[-1] == max(steps), (inter.id, vis)


# ------------------------------------------------------------------------- landmarks
def landmark_scene(m: MapData, inter_id: str, n: int, kind: str) -> LocatedScene:
    ls = make_located_scene(
        m,
        m.intersection(inter_id),
        np.random.default_rng(1),
        noise=NoiseModel.exact(),
        corner_sigma_m=0.0,
        landmark_sigma_m=0.0,
        n_landmarks=n,
        landmark_kind=kind,
    )
    assert ls is not None
    del ls.scene["intersection"]
    return ls


@pytest.mark.parametrize("kind", ["building_corner", "face_midpoint"])
def test_two_landmarks_exact(maps: dict[str, MapData], kind: str) -> None:
    m = maps["baltimore"]
    ls = landmark_scene(m, "c49471330", 2, kind)
    assert all(lm["kind"] == kind for lm in ls.scene["landmarks"])
    result = locate(parse_scene(ls.scene), m)
    check_contract(result)
    assert result.methods_tried == ["landmark"]
    errs = errors_m(result, ls)
    assert errs[0] < EXACT
    assert result.candidates[0].method == "landmark"


def test_one_landmark_uses_the_streets_along_the_building(maps: dict[str, MapData]) -> None:
    """The car's street runs along a side of the building, not past its centre."""
    m = maps["baltimore"]
    ls = landmark_scene(m, "c49471330", 1, "building_corner")
    result = locate(parse_scene(ls.scene), m)
    check_contract(result)
    # The synthetic car is parallel to its street within a couple of degrees.
    assert min(errors_m(result, ls)) < 3.0


def test_unknown_landmark_names_the_building(maps: dict[str, MapData]) -> None:
    m = maps["baltimore"]
    ls = landmark_scene(m, "c49471330", 1, "building_corner")
    ls.scene["landmarks"][0]["name"] = "Nonexistent Cathedral"
    with pytest.raises(MapDataError, match="Nonexistent Cathedral"):
        locate(parse_scene(ls.scene), m)


def test_one_landmark_with_stated_bearing_gives_two_candidates_per_point(
    maps: dict[str, MapData],
) -> None:
    """A landmark given by lat/lon (no map): like one reference, two candidates."""
    m = maps["baltimore"]
    ls = landmark_scene(m, "c49471330", 1, "building_corner")
    px = ls.scene["landmarks"][0]["pixel"]
    g = ls.camera_enu.ground_from_pixels(np.asarray([px], dtype=float))[0]
    lon, lat = m.frame.geographic_from_enu(float(g[0]), float(g[1]))
    ls.scene["landmarks"] = [
        {"pixel": px, "kind": "building_corner", "lat": float(lat), "lon": float(lon)}
    ]
    ls.scene["street_bearing_deg"] = car_bearing_deg(ls)
    result = locate(parse_scene(ls.scene))
    check_contract(result)
    assert len(result.candidates) == 2
    assert min(errors_m(result, ls)) < EXACT


@pytest.mark.parametrize("seed", [2, 4])
def test_street_prior_does_not_move_an_exact_fit(seed: int) -> None:
    """At Stirling Hwy x Tydeman Rd the true car is judged across its street (a divided
    highway's carriageway lines): the refinement must not pull the exact corner fit onto
    the street prior (it moved it by 4-7 m)."""
    m = load_map(OSM / "fremantle.osm", -32.036172, 115.755714, radius_m=250)
    inter = next(i for i in m.intersections if i.kind == "junction" and len(i.corners) >= 4)
    ls = exact_located(m, inter, seed=seed, min_corners=3)
    result = locate(parse_scene(ls.scene), m)
    assert errors_m(result, ls)[0] < EXACT
    assert result.candidates[0].residual_m < 0.05


def test_more_visible_corners_than_the_map_models(maps: dict[str, MapData]) -> None:
    """A listed corner the map has no counterpart for is left unmatched, not fatal."""
    found = 0
    pairs = [(maps[k], i) for k in ("heidelberg", "krems") for i in junctions(maps[k])[:4]]
    for seed, (m, inter) in enumerate(pairs):
        ls = make_located_scene(
            m,
            inter,
            np.random.default_rng(seed),
            noise=NoiseModel.exact(),
            corner_sigma_m=0.0,
            min_corners=len(inter.corners),
        )
        if ls is None or len(ls.scene["intersection"]["corners"]) != len(inter.corners):
            continue
        corners = ls.scene["intersection"]["corners"]
        bogus = ((np.array(corners[0]) + np.array(corners[1])) / 2 + [0.0, 40.0]).tolist()
        ls.scene["intersection"]["corners"] = [corners[0], bogus, *corners[1:]]
        result = locate(parse_scene(ls.scene), m)
        check_contract(result)
        assert any("unmatched" in w for w in result.warnings)
        d = errors_m(result, ls)
        best = result.candidates[int(np.argmin(d))]
        assert min(d) < EXACT
        assert "unmatched:intersection.corners[1]" in best.flags
        assert all(mt["label"] != "intersection.corners[1]" for mt in best.matches)
        found += 1
    assert found >= 2


def test_one_reference_widens_the_street_search(maps: dict[str, MapData]) -> None:
    """No street within the search radius of the reference: widen it and say so."""
    from camloc_geo.absolute import LocateSettings

    m = maps["baltimore"]
    ls = exact_located(m, junctions(m)[1], seed=23)
    w, h = ls.scene["image"]["width"], ls.scene["image"]["height"]
    scene = dict(ls.scene)
    scene.pop("intersection")
    scene["references"] = ground_refs(m, ls, [(w / 2, h * 0.9)])
    ref = scene["references"][0]
    # The reference's distance to the nearest street: search half as far, so only the
    # widened search finds it.
    dist = next(
        r for r in np.geomspace(0.05, 500.0, 400) if m.street_bearings(ref["lat"], ref["lon"], r)
    )
    settings = LocateSettings(street_search_m=0.5 * dist)
    result = locate(parse_scene(scene), m, settings=settings)
    assert result.candidates
    assert any("street bearings" in x and "used those within" in x for x in result.warnings)
    assert min(errors_m(result, ls)) < 1.0


def test_evidence_above_the_calibrated_horizon_is_explained(maps: dict[str, MapData]) -> None:
    m = maps["baltimore"]
    ls = exact_located(m, junctions(m)[1], seed=23)
    scene_obj = parse_scene(ls.scene)
    cal = calibrate(scene_obj)
    line = cal.camera.horizon_line()  # > 0 below the horizon
    w = ls.scene["image"]["width"]
    above = [(x, y) for x in (5.0, w / 2, w - 5.0) for y in (1.0, 3.0) if line @ [x, y, 1.0] < 0]
    if len(above) < 2:
        pytest.skip("the horizon of this camera is above the image")
    scene = dict(ls.scene)
    scene.pop("intersection")
    scene["references"] = [{"pixel": list(px), "lat": ls.lat, "lon": ls.lon} for px in above[:2]]
    result = locate(parse_scene(scene), m, calibration=cal)
    assert result.candidates == []
    assert result.reason is not None
    assert "above the calibrated camera's horizon" in result.reason


def test_intersection_point_matching_no_junction_is_searched_around_with_a_warning() -> None:
    """A scene's intersection 42 m from the nearest modelled junction: the junctions within
    200 m are searched and the warning names the one the answer stands at (it used to be
    refused); nothing moves silently to another junction."""
    import json

    from camloc_geo.api import locate_scene

    root = Path(__file__).resolve().parents[1] / "sample_maps"
    scene = json.loads((root / "sample_scene.json").read_text())
    scene["intersection"]["lat"] = 39.28698  # 42 m from Bank Street & South Broadway
    scene["intersection"]["lon"] = -76.59348
    scene["intersection"].pop("streets", None)
    res = locate_scene(scene, map_source=root / "baltimore.osm.pbf").result
    assert res.candidates
    warned = [w for w in res.warnings if "were matched at the" in w]
    assert len(warned) == 1
    top = res.candidates[0].intersection_id
    assert f"junction {top} " in warned[0]
    assert "Bank Street & South Broadway), 42 m from the stated point" in warned[0]


def test_intersection_point_far_from_every_junction_is_refused_naming_the_nearest() -> None:
    """A scene's intersection farther than the 200 m search from any junction with kerb
    corners is refused, naming the nearest junctions."""
    import json

    from camloc_geo.api import locate_scene

    root = Path(__file__).resolve().parents[1] / "sample_maps"
    scene = json.loads((root / "sample_scene.json").read_text())
    scene["intersection"]["lat"] = 39.2795  # in the harbour, 630 m south
    scene["intersection"]["lon"] = -76.59348
    scene["intersection"].pop("streets", None)
    with pytest.raises(
        MapDataError, match=r"no modelled junction matches.*nearest.*none with kerb corners"
    ):
        locate_scene(scene, map_source=root / "baltimore.osm.pbf")
