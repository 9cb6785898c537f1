"""The later stages of :func:`camloc_geo.absolute.locate`: every junction of a prior-only scene,
the cues inside the ranking, and the bundle adjustment of the leaders."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camloc_geo.absolute import LocateSettings, apply_cues, locate
from camloc_geo.geodesy import distance_m
from camloc_geo.osm import MapData, load_map
from camloc_geo.relative import calibrate
from camloc_geo.results import candidates_geojson
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import LocatedScene, NoiseModel, make_located_scene

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"


@pytest.fixture(scope="module")
def baltimore() -> MapData:
    return load_map(OSM / "baltimore.osm.pbf", 39.2851, -76.5934, radius_m=300)


def _junctions(m: MapData) -> list[Any]:
    return [i for i in m.intersections if i.kind == "junction" and len(i.corners) >= 3]


def _err_m(c: Any, ls: LocatedScene) -> float:
    return float(distance_m(lat1=c.lat, lon1=c.lon, lat2=ls.lat, lon2=ls.lon))


def test_prior_only_keeps_every_junction_within_the_prior(baltimore: MapData) -> None:
    """The prior's centre is the neighbouring junction: the true one must still be found."""
    js = _junctions(baltimore)
    true_j = js[0]
    neighbour = min(
        (k for k in js if k.id != true_j.id),
        key=lambda k: distance_m(lat1=true_j.lat, lon1=true_j.lon, lat2=k.lat, lon2=k.lon),
    )
    ls = make_located_scene(
        baltimore,
        true_j,
        np.random.default_rng(3),
        noise=NoiseModel.exact(),
        corner_sigma_m=0.0,
        min_corners=3,
        max_corners=4,
    )
    assert ls is not None
    scene = json.loads(json.dumps(ls.scene))
    scene["intersection"] = {"corners": scene["intersection"]["corners"]}
    scene["prior"] = {"lat": neighbour.lat, "lon": neighbour.lon, "radius_m": 150.0}
    result = locate(parse_scene(scene), baltimore)
    errs = [_err_m(c, ls) for c in result.candidates]
    assert min(errs) < 0.1
    ids = {c.intersection_id for c in result.candidates}
    assert true_j.id in ids
    assert neighbour.id in ids
    assert len(ids) >= 3
    best = min(range(len(errs)), key=errs.__getitem__)
    assert result.candidates[best].intersection_id == true_j.id
    assert any("junctions with kerb corners within 150 m" in w for w in result.warnings)
    assert result.intersection is not None
    assert result.intersection.id == result.candidates[0].intersection_id
    gj = candidates_geojson(result)
    cand_props = [f["properties"] for f in gj["features"] if f["properties"]["kind"] == "candidate"]
    assert {p["intersection"] for p in cand_props} == ids


def test_stated_intersection_point_is_the_only_junction(baltimore: MapData) -> None:
    js = _junctions(baltimore)
    ls = make_located_scene(
        baltimore, js[0], np.random.default_rng(3), noise=NoiseModel.exact(), corner_sigma_m=0.0
    )
    assert ls is not None
    result = locate(parse_scene(ls.scene), baltimore)
    assert {c.intersection_id for c in result.candidates} == {js[0].id}
    assert not any("junctions with kerb corners" in w for w in result.warnings)


def test_cues_are_part_of_the_ranking(baltimore: MapData) -> None:
    """A view hint pointing at the true heading ranks the true candidate first, inside locate;
    apply_cues afterwards changes nothing."""
    js = _junctions(baltimore)
    ls = make_located_scene(
        baltimore, js[0], np.random.default_rng(3), noise=NoiseModel.exact(), corner_sigma_m=0.0
    )
    assert ls is not None
    scene = json.loads(json.dumps(ls.scene))
    heading = ls.camera_enu.angles_deg[0]
    scene["view_hint"] = {"bearing_deg": round(heading % 360.0, 1), "tolerance_deg": 20.0}
    sc = parse_scene(scene)
    result = locate(sc, baltimore)
    assert result.cues_applied
    assert _err_m(result.candidates[0], ls) < 0.1
    assert any(f.kind.value == "cue" for f in result.candidates[0].flags)
    scores = [c.score for c in result.candidates]
    apply_cues(result, sc, baltimore)
    assert [c.score for c in result.candidates] == scores


def test_bundle_adjustment_helps_where_the_relative_pose_is_off(baltimore: MapData) -> None:
    """Crowd-noisy annotations and four references: re-fitting the camera with the map
    lowers the mean and the worst error of the top candidate over twelve scenes."""
    js = _junctions(baltimore)
    plain, bundled = [], []
    for seed in range(12):
        ls = make_located_scene(
            baltimore,
            js[seed % len(js)],
            np.random.default_rng(seed),
            noise=NoiseModel(),
            corner_sigma_m=0.0,
            n_references=4,
            min_corners=3,
            max_corners=4,
        )
        assert ls is not None
        scene = json.loads(json.dumps(ls.scene))
        scene.pop("intersection", None)
        sc = parse_scene(scene)
        cal = calibrate(sc)
        assert cal.joint_state is not None
        for ba, out in ((False, plain), (True, bundled)):
            res = locate(sc, baltimore, calibration=cal, settings=LocateSettings(bundle_adjust=ba))
            out.append(_err_m(res.candidates[0], ls))
            if ba:
                assert res.candidates[0].sigma_m is not None
                assert res.candidates[0].sigma_m > 0.0
    assert np.mean(bundled) < 0.9 * np.mean(plain), (plain, bundled)
    assert max(bundled) < max(plain), (plain, bundled)


def test_two_corners_also_try_the_car_along_a_street() -> None:
    """Two corners close together fix the rotation poorly: street-aligned alternatives
    within the rotation's window of the fitted rotation are proposed too (none for
    far-off streets)."""
    import math

    from camloc_geo.absolute._hypotheses import _street_aligned
    from camloc_geo.absolute._similarity import Similarity2D, theta_for_bearing

    world = np.array([[0.0, 0.0], [6.0, 0.0]])
    fitted = Similarity2D(theta_for_bearing(100.0), np.zeros(2), 1.0)
    enu = fitted.apply(world)
    hyps = _street_aligned(world, enu, fitted, [90.0, 10.0], 0.0, (0, 1), math.radians(30.0))
    assert len(hyps) == 1  # 90° (10° off) kept, 270° and 10°/190° too far
    # A loose rotation (a 100° window) also tries 10° and 190° (90° off) but not 270°.
    loose = _street_aligned(world, enu, fitted, [90.0, 10.0], 0.0, (0, 1), math.radians(100.0))
    assert sorted(round(h.enu_from_world.heading_deg) % 360 for h in loose) == [10, 90, 190]
    h = hyps[0]
    assert math.isclose(h.enu_from_world.heading_deg, 90.0, abs_tol=1e-9)
    # the corners' centroid is matched exactly
    assert np.allclose(h.enu_from_world.apply(world).mean(axis=0), enu.mean(axis=0))
    assert h.corner_assignment == (0, 1)


def test_two_corner_rotation_window_widens_with_a_short_baseline() -> None:
    """Three sigmas of the two-corner rotation, never under 30°: corners a narrow side
    street apart (5 m, each uncertain by 2 m) leave it loose by nearly 90°; corners 20 m
    apart known to 0.5 m keep the 30° floor."""
    import math

    from camloc_geo.absolute._hypotheses import _rotation_window_rad

    narrow = _rotation_window_rad(np.array([[0.0, 0.0], [5.0, 0.0]]), np.array([0.25, 0.25]))
    assert math.degrees(narrow) == pytest.approx(3 * math.degrees(math.atan2(math.sqrt(8), 5)))
    assert math.degrees(narrow) > 85.0
    wide = _rotation_window_rad(np.array([[0.0, 0.0], [20.0, 0.0]]), np.array([4.0, 4.0]))
    assert math.degrees(wide) == pytest.approx(30.0)
    same = _rotation_window_rad(np.array([[1.0, 1.0], [1.0, 1.0]]), np.array([1.0, 1.0]))
    assert same == pytest.approx(math.pi)


def test_plausibility_is_averaged_over_the_position_uncertainty(baltimore: MapData) -> None:
    """A candidate put 3 m inside a building is penalised at its estimate; with a position
    sigma of 15 m (capped at 8) the averaged plausibility is far milder (part of the Gaussian
    stands outside the footprint), and with a negligible sigma it is the estimate's."""
    import math
    from dataclasses import replace

    from shapely.geometry import Point

    from camloc_geo.absolute._model import FlagKind
    from camloc_geo.absolute._pipeline import SIGMA_POINT_CAP_M, _expected_plausibility
    from camloc_geo.absolute._scoring import plausibility

    js = _junctions(baltimore)
    ls = make_located_scene(
        baltimore, js[0], np.random.default_rng(3), noise=NoiseModel.exact(), corner_sigma_m=0.0
    )
    assert ls is not None
    sc = parse_scene(ls.scene)
    cal = calibrate(sc)
    res = locate(sc, baltimore, calibration=cal)
    cand = res.candidates[0]
    ev = cand.evidence
    assert ev is not None
    assert ev.buildings is not None
    centre = cand.camera.center_in_world[:2]
    # A point 3 m inside the nearest footprint from which a step of the capped sigma points
    # (√3 · 8 / √2 ≈ 9.8 m) east, west, north or south leaves every footprint.
    step = math.sqrt(3.0) * SIGMA_POINT_CAP_M / math.sqrt(2.0)
    polys = ev.buildings.geometries
    inner = None
    for poly in sorted(polys, key=lambda p: p.distance(Point(*centre))):
        ring = poly.buffer(-3.0)
        if ring.is_empty or ring.geom_type != "Polygon":
            continue
        for x, y in list(ring.exterior.coords)[:-1]:
            shifted = [
                Point(x + dx, y + dy) for dx, dy in ((step, 0), (-step, 0), (0, step), (0, -step))
            ]
            if any(not any(q.contains(sp) for q in polys) for sp in shifted):
                inner = np.array([x, y])
                break
        if inner is not None:
            break
    assert inner is not None
    sim = cand.enu_from_world
    moved = replace(sim, translation_m=np.asarray(sim.translation_m) + (inner - centre))
    cam = moved.camera(cal.camera)
    assert np.allclose(cam.center_in_world[:2], inner)
    settings = LocateSettings()
    p0, flags = plausibility(cam, moved, ev, settings, cand.matches)
    assert FlagKind.INSIDE_BUILDING in {f.kind for f in flags}
    inside = replace(cand, enu_from_world=moved, camera=cam)
    tiny = _expected_plausibility(p0, inside, 1e-3, cal.camera, ev, settings, cand.matches)
    assert tiny == pytest.approx(p0, rel=1e-6)
    wide = _expected_plausibility(p0, inside, 15.0, cal.camera, ev, settings, cand.matches)
    assert 1.5 * p0 < wide <= 1.0


def test_bundle_stopped_within_a_tenth_sigma_keeps_the_full_fits_answer(
    baltimore: MapData, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The bundle's ``sigma_tol`` stop (3 % of a sigma) moves no leader by more than a
    tenth of its sigma from the fully converged bundle, and keeps the ranking."""
    from camloc_geo.absolute import _bundle

    js = _junctions(baltimore)
    for seed in range(6):
        ls = make_located_scene(
            baltimore,
            js[seed % len(js)],
            np.random.default_rng(100 + seed),
            noise=NoiseModel(),
            corner_sigma_m=0.0,
            n_references=4,
            min_corners=3,
            max_corners=4,
        )
        assert ls is not None
        scene = json.loads(json.dumps(ls.scene))
        scene.pop("intersection", None)
        sc = parse_scene(scene)
        cal = calibrate(sc)
        early = locate(sc, baltimore, calibration=cal).candidates
        monkeypatch.setattr(_bundle, "_SIGMA_TOL", None)
        full = locate(sc, baltimore, calibration=cal).candidates
        monkeypatch.undo()
        assert [c.intersection_id for c in early] == [c.intersection_id for c in full]
        for a, b in zip(early[:3], full[:3], strict=True):
            moved = float(distance_m(lat1=a.lat, lon1=a.lon, lat2=b.lat, lon2=b.lon))
            assert b.sigma_m is None or moved <= 0.1 * b.sigma_m, (seed, moved, b.sigma_m)
