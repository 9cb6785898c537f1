"""The fit's covariance with one residual variance factor per row group (stop 39, an option).

``CalibrationSettings.variance_groups``: the segments, the car's corner clicks and its
edge-end clicks each get their own factor, the estimator staying the fit's (the sandwich).
Off by default (benchmarks/README.md, stop 39).
"""

from __future__ import annotations

import numpy as np
import pytest

import camloc_geo.relative as rel
from camloc_geo.relative import CalibrationSettings, calibrate
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import NoiseModel, make_scene, random_camera


def _scene(seed: int) -> dict:  # type: ignore[type-arg]
    rng = np.random.default_rng(seed)
    cam = random_camera(rng)
    syn = make_scene(cam, rng, noise=NoiseModel(sloppy_prob=0.0), n_annotators=5)
    syn.scene["object"] = {"preset": "sedan"}
    return syn.scene


def _state_and_jac(seed: int, groups: bool):  # type: ignore[no-untyped-def]
    res = calibrate(parse_scene(_scene(seed)), CalibrationSettings(variance_groups=groups))
    state = res.joint_state
    assert state is not None
    prob = state.problem
    prob.weights = state.weights
    r, J = prob.residuals_and_jacobian(
        state.x, state.rotation0, state.principal_point, state.focal_px
    )
    return res, prob, r, J


def test_off_is_the_pooled_factor_and_on_is_the_sandwich() -> None:
    _res, prob, r, J = _state_and_jac(3, groups=False)
    inv = rel._sym_inverse(J.T @ J)
    pooled = rel._fit_covariance(prob, r, J, inv)
    dof = len(r) - len(inv)
    s2 = 2.0 * rel.soft_l1_cost(r, rel._F_SCALE) / dof
    np.testing.assert_allclose(pooled, inv * s2, rtol=1e-12)
    prob.variance_groups = True
    grouped = rel._fit_covariance(prob, r, J, inv)
    # The crowd's lines fit better, relative to their assumed noise, than its clicks do: the
    # lines' factor is the smaller, and the focal length (the lines decide it) is tighter.
    n_seg, n_pt = len(prob.segments), len(prob.pt_pix)
    seg_ms = float(np.mean(r[:n_seg] ** 2))
    click_ms = float(np.mean(r[n_seg : n_seg + 2 * n_pt] ** 2))
    assert seg_ms < 0.6 * click_ms
    assert grouped[0, 0] < pooled[0, 0]


def test_groups_without_redundancy_keep_the_pooled_factor(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """A group's own factor needs its redundancy; below it the row keeps the pooled factor,
    and with every row pooled the sandwich is the pooled covariance (to round-off)."""
    _res, prob, r, J = _state_and_jac(3, groups=True)
    inv = rel._sym_inverse(J.T @ J)
    grouped = rel._fit_covariance(prob, r, J, inv)
    monkeypatch.setattr(rel, "_VARIANCE_GROUP_MIN_REDUNDANCY", 1e9)
    pooled_rows = rel._fit_covariance(prob, r, J, inv)
    prob.variance_groups = False
    pooled = rel._fit_covariance(prob, r, J, inv)
    np.testing.assert_allclose(pooled_rows, pooled, rtol=1e-9, atol=1e-15)
    assert not np.allclose(grouped, pooled, rtol=1e-3)


def test_the_option_moves_no_camera() -> None:
    a = calibrate(parse_scene(_scene(5)))
    b = calibrate(parse_scene(_scene(5)), CalibrationSettings(variance_groups=True))
    np.testing.assert_array_equal(a.camera.center_in_world, b.camera.center_in_world)
    assert a.camera.focal_px == b.camera.focal_px
    assert a.focal_sigma_px is not None
    assert b.focal_sigma_px is not None
    assert a.focal_sigma_px != b.focal_sigma_px


def test_a_group_without_its_own_factor_pools_every_row() -> None:
    """One annotator: its clicks have too little redundancy for a factor of their own, so
    every row keeps the pooled factor (stop 42). Before, the segments alone got their own,
    and the clicks' misfit, the only sign of one annotator's leaning line, left the lines'
    quantities (the hand-annotated street car ``today``, hand-b alone: 2.2 sigmas off)."""
    rng = np.random.default_rng(11)
    cam = random_camera(rng)
    syn = make_scene(cam, rng, noise=NoiseModel(sloppy_prob=0.0), n_annotators=1)
    syn.scene["object"] = {"preset": "sedan"}
    res = calibrate(parse_scene(syn.scene), CalibrationSettings(variance_groups=True))
    state = res.joint_state
    assert state is not None
    prob = state.problem
    prob.weights = state.weights
    r, J = prob.residuals_and_jacobian(
        state.x, state.rotation0, state.principal_point, state.focal_px
    )
    inv = rel._sym_inverse(J.T @ J)
    s2_row = rel._variance_factors(prob, r, J, inv)
    pooled = rel._variance_factors(prob, r, J, inv, pooled=True)
    np.testing.assert_array_equal(s2_row, np.full(len(r), pooled))
    np.testing.assert_allclose(
        rel._fit_covariance(prob, r, J, inv), inv * pooled, rtol=1e-12, atol=0.0
    )


def test_a_box_that_is_not_the_stated_car_keeps_the_pooled_factor() -> None:
    """A van annotated as a sedan (its clicked box disagrees with the stated proportions): the
    clicks' misfit is the model's, and every row shares it. With per-group factors alone it
    widened only what the clicks decide, and the camera fell outside 2 sigmas
    (``tests/test_crowd_slips.py``'s van, seed 2)."""
    from camloc_geo.objects import PRESETS

    rng = np.random.default_rng(2)
    cam = random_camera(rng)
    syn = make_scene(
        cam,
        rng,
        noise=NoiseModel(wrong_corner_prob=0.0, sloppy_prob=0.0),
        n_annotators=4,
        true_size=PRESETS["van"],
    )
    syn.scene["object"] = {"preset": "sedan"}
    scene = parse_scene(syn.scene)
    grouped = calibrate(scene, CalibrationSettings(variance_groups=True))
    pooled = calibrate(scene, CalibrationSettings(variance_groups=False))
    props = grouped.object_proportions
    assert props is not None
    assert props["disagrees"] is True
    np.testing.assert_allclose(grouped.position_sigma_m, pooled.position_sigma_m, rtol=1e-9)
    assert grouped.focal_sigma_px == pytest.approx(pooled.focal_sigma_px, rel=1e-9)
    err = np.linalg.norm(grouped.camera.center_in_world - syn.camera.center_in_world)
    assert grouped.position_sigma_m is not None
    assert err <= 2.0 * np.linalg.norm(grouped.position_sigma_m)
