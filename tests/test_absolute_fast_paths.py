"""The shortcuts that keep :func:`camloc_geo.absolute.locate` fast compute what the plain
functions compute: the placement memo (carried observations, precisions, street angles),
the sigma points' camera centres, the batched position sigmas, the one-call ground
observation, and the refinement's lockstep fits."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camloc_geo.absolute import LocateSettings, _pipeline, _refine, _scoring
from camloc_geo.absolute._evidence import Evidence, gather_evidence, ground_observation
from camloc_geo.absolute._model import LocateResult
from camloc_geo.absolute._similarity import Similarity2D
from camloc_geo.camera import Camera
from camloc_geo.osm import MapData, load_map
from camloc_geo.relative import CalibrationResult, calibrate
from camloc_geo.scene import Scene, parse_scene
from camloc_geo.testing.synthetic import make_located_scene

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"


@pytest.fixture(scope="module")
def baltimore() -> MapData:
    return load_map(OSM / "baltimore.osm.pbf", 39.2851, -76.5934, radius_m=300)


@pytest.fixture(scope="module")
def located(baltimore: MapData) -> list[tuple[Scene, CalibrationResult]]:
    """Scenes with corners and two references at three junctions, calibrated."""
    junctions = [i for i in baltimore.intersections if i.kind == "junction" and len(i.corners) >= 3]
    rng = np.random.default_rng(5)
    out = []
    for inter in junctions[:3]:
        ls = make_located_scene(baltimore, inter, rng, min_corners=2, n_references=2)
        assert ls is not None
        scene = parse_scene(ls.scene)
        out.append((scene, calibrate(scene)))
    return out


def _evidence(scene: Scene, cal: CalibrationResult, m: MapData) -> tuple[Evidence, Any]:
    settings = LocateSettings()
    frame = _pipeline.frame_anchor(scene, m)
    result = LocateResult([], frame, cal, [], image_size=scene.image_size)
    return gather_evidence(scene, m, cal.camera, settings, result), result


def _placements(ev: Evidence) -> list[Similarity2D]:
    rng = np.random.default_rng(11)
    return [
        Similarity2D(float(rng.uniform(-math.pi, math.pi)), rng.normal(0, 20, 2), s)
        for s in rng.uniform(0.8, 1.2, 12)
    ]


def test_placement_memo_gives_mahal_and_precision(
    located: list[tuple[Scene, CalibrationResult]], baltimore: MapData
) -> None:
    for scene, cal in located:
        ev, _result = _evidence(scene, cal, baltimore)
        obs = ev.observations
        assert len(obs) >= 3
        for sim in _placements(ev):
            here = _scoring.placement(ev, sim)
            assert _scoring.placement(ev, sim) is here  # remembered
            for o in obs:
                p, prec = here.carried(o)
                want = _scoring.obs_precision(o, sim.rotation, sim.scale)
                np.testing.assert_allclose(prec, want, rtol=1e-12, atol=0.0)
                np.testing.assert_allclose(p, sim.apply(o.world_xy), rtol=1e-13, atol=1e-12)
                q = np.array([3.0, -7.0])
                _r, m2 = here.misfit(o, q)
                assert m2 == pytest.approx(_scoring.mahal(o, q, sim), rel=1e-12)


def test_street_angles_are_remembered_and_unchanged(
    located: list[tuple[Scene, CalibrationResult]], baltimore: MapData
) -> None:
    scene, cal = located[0]
    ev, _result = _evidence(scene, cal, baltimore)
    assert ev.street_tree is not None
    sims = _placements(ev)
    fresh = _scoring._street_angles(sims, ev)
    assert any(a is not None for a in fresh)
    first = _scoring.street_angles_under_car(sims, ev)
    again = _scoring.street_angles_under_car(list(reversed(sims)), ev)
    assert first == fresh
    assert again == list(reversed(fresh))
    # one at a time, as the batch
    assert [_scoring._street_angles([s], ev)[0] for s in sims] == fresh


def test_sigma_points_are_the_moved_cameras_centres(
    located: list[tuple[Scene, CalibrationResult]],
) -> None:
    _scene, cal = located[0]
    world_cam: Camera = cal.camera
    sim = Similarity2D(0.7, np.array([12.0, -30.0]), 1.05)
    points = _pipeline._sigma_points(sim, 4.0, world_cam)
    assert len(points) == 4
    step = math.sqrt(3.0) * 4.0 / math.sqrt(2.0)
    for (centre, moved), shift in zip(
        points, ((step, 0.0), (-step, 0.0), (0.0, step), (0.0, -step)), strict=True
    ):
        want = moved.camera(world_cam).center_in_world
        np.testing.assert_allclose(centre, want, rtol=0.0, atol=1e-9)
        np.testing.assert_array_equal(moved.translation_m, sim.translation_m + np.array(shift))
        assert (moved.rotation_rad, moved.scale) == (sim.rotation_rad, sim.scale)


def test_batched_position_sigmas_are_the_single_ones(
    located: list[tuple[Scene, CalibrationResult]], baltimore: MapData
) -> None:
    for scene, cal in located:
        result = _pipeline.locate(scene, baltimore, calibration=cal)
        cands = result.candidates
        assert len(cands) >= 2
        evs = [c.evidence for c in cands]
        world_cam = cal.camera
        settings = LocateSettings()
        many = _refine.position_sigmas_m(cands, world_cam, evs, settings)
        one = [
            _refine.position_sigma_m(c, world_cam, e, settings)
            for c, e in zip(cands, evs, strict=True)
        ]
        assert many == one
        assert all(s is not None and s > 0 for s in many)
        # against the refinement's own whitened Jacobian at the candidate's similarity
        for c, e, sigma in zip(cands, evs, many, strict=True):
            problem = _refine._similarity_problem(c, e, settings)
            assert problem is not None
            resid_jac, x0 = problem
            _r, J = resid_jac(x0)
            plain = _refine._position_sigma_m(J, c.enu_from_world, world_cam)
            assert plain is not None
            assert sigma == pytest.approx(plain, rel=1e-9)


def test_ground_observation_matches_one_cast_per_pixel(
    located: list[tuple[Scene, CalibrationResult]],
) -> None:
    scene, cal = located[0]
    cam = cal.camera
    width, height = scene.image_size
    diag = math.hypot(width, height)
    settings = LocateSettings()
    for px in ([0.3 * width, 0.8 * height], [0.7 * width, 0.95 * height]):
        obs = ground_observation(cam, px, "corner", "c", 1.0, settings, diag)
        p = np.asarray(px, float)
        J = np.empty((2, 2))
        for j in range(2):
            d = np.zeros(2)
            d[j] = 0.5
            J[:, j] = cam.ground_from_pixels(p + d)[:2] - cam.ground_from_pixels(p - d)[:2]
        g = cam.ground_from_pixels(p)
        np.testing.assert_array_equal(obs.world_xy, g[:2])
        cov = (settings.sigma_pixel_rel * diag) ** 2 * (J @ J.T)
        foot = cam.center_in_world[:2]
        rng = float(np.linalg.norm(g[:2] - foot)) + float(np.linalg.norm(foot))
        cov = cov + (settings.scale_sigma_rel * 0.5 * rng) ** 2 * np.eye(2)
        np.testing.assert_allclose(obs.cov_world, cov, rtol=1e-12, atol=0.0)


def _plain_residuals(obs_q: list[Any], L: np.ndarray, x: np.ndarray, s_sigma: float) -> np.ndarray:
    """The refinement's whitened point and scale residuals, written out plainly."""
    theta, tx, ty, ls = x
    s = math.exp(ls)
    R = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    rows = []
    for (o, q), Lk in zip(obs_q, L, strict=True):
        rows.append(Lk.T @ (s * R @ o.world_xy + np.array([tx, ty]) - q))
    return np.concatenate([np.ravel(rows), [ls / s_sigma]])


def test_refinement_residuals_and_jacobian(
    located: list[tuple[Scene, CalibrationResult]], baltimore: MapData
) -> None:
    settings = LocateSettings()
    for scene, cal in located:
        result = _pipeline.locate(scene, baltimore, calibration=cal)
        cand = result.candidates[0]
        ev = cand.evidence
        assert ev is not None
        obs_q = _refine._matched_points(cand, ev)
        brg = _refine._street_bearing_prior(cand, ev, settings)
        resid_jac = _refine._residuals(obs_q, cand.enu_from_world, settings, brg, ev)
        here = _scoring.placement(ev, cand.enu_from_world)
        L = np.linalg.cholesky(np.stack([here.carried(o)[1] for o, _q in obs_q]))
        x0 = np.array([cand.theta_rad, *cand.translation_en, math.log(cand.scale)])
        for dx in (np.zeros(4), np.array([0.05, 2.0, -1.0, 0.03])):
            x = x0 + dx
            r, J = resid_jac(x)
            n_pts = 2 * len(obs_q) + 1
            want = _plain_residuals(obs_q, L, x, max(settings.scale_sigma_rel, 1e-6))
            np.testing.assert_allclose(r[:n_pts], want, rtol=1e-9, atol=1e-9)
            assert len(r) == n_pts + (brg is not None)
            # the Jacobian against central differences
            for j in range(4):
                h = np.zeros(4)
                h[j] = 1e-6
                fd = (resid_jac(x + h)[0] - resid_jac(x - h)[0]) / 2e-6
                np.testing.assert_allclose(J[:, j], fd, rtol=1e-5, atol=1e-6)


def test_candidate_angles_are_the_cameras_to_the_bit() -> None:
    from camloc_geo.camera import rotation_from_rotvec
    from camloc_geo.results import _angles_deg

    rng = np.random.default_rng(2)
    rotations = [rotation_from_rotvec(v) for v in rng.normal(0.0, 1.5, (500, 3))]
    rotations.append(np.diag([1.0, -1.0, -1.0]))  # looking straight down: no heading
    rotations.append(np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]]))  # level, north
    for R in rotations:
        cam = Camera(1000.0, (640.0, 360.0), R, np.array([0.0, 0.0, -5.0]))
        assert _angles_deg(cam) == cam.angles_deg


def test_merge_on_floats_is_the_merge_on_arrays(
    located: list[tuple[Scene, CalibrationResult]],
    baltimore: MapData,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import copy
    from dataclasses import replace

    scene, cal = located[0]
    base = _pipeline.locate(scene, baltimore, calibration=cal).candidates[0]
    rng = np.random.default_rng(8)
    cands = []
    for k in range(60):
        sim = Similarity2D(
            base.enu_from_world.rotation_rad + float(rng.choice([0.0, 0.05, 1.0, 3.0])),
            np.asarray(base.translation_en) + rng.normal(0.0, 6.0, 2),
            base.scale,
        )
        c = replace(base, enu_from_world=sim, camera=sim.camera(cal.camera), merged=1)
        c.log_likelihood = float(rng.normal(0.0, 3.0)) - 0.01 * k
        cands.append(c)
    settings = LocateSettings()
    on_floats = _pipeline.normalise_and_merge(copy.deepcopy(cands), settings)
    monkeypatch.setattr(_pipeline, "_MERGE_LOOP_MAX", -1)
    on_arrays = _pipeline.normalise_and_merge(copy.deepcopy(cands), settings)
    assert 3 < len(on_floats) < len(cands)
    assert [(c.score, c.merged, c.log_likelihood) for c in on_floats] == [
        (c.score, c.merged, c.log_likelihood) for c in on_arrays
    ]


def test_bundle_position_sigmas_batched_are_the_single_ones(
    located: list[tuple[Scene, CalibrationResult]],
    baltimore: MapData,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from camloc_geo.absolute import _bundle

    seen: list[tuple[list[float | None], list[float | None]]] = []
    batched = _bundle._position_sigmas

    def both(results: Any, state: Any, n_cam: int) -> list[float | None]:
        got = batched(results, state, n_cam)
        seen.append((got, [_bundle._position_sigma(r, state, n_cam) for r in results]))
        return got

    monkeypatch.setattr(_bundle, "_position_sigmas", both)
    for scene, cal in located:
        _pipeline.locate(scene, baltimore, calibration=cal)
    assert any(len(got) >= 2 for got, _one in seen)
    for got, one in seen:
        assert got == one


def test_a_result_keeps_no_placement_memo(
    located: list[tuple[Scene, CalibrationResult]], baltimore: MapData
) -> None:
    scene, cal = located[0]
    result = _pipeline.locate(scene, baltimore, calibration=cal)
    evs = {id(c.evidence): c.evidence for c in result.candidates if c.evidence is not None}
    assert evs
    for ev in evs.values():
        assert ev.placement_memo == {}
        assert ev.observation_table is None
