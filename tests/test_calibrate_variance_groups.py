"""The fit's covariance with one residual variance factor per row group (stop 39, an option).

``CalibrationSettings.variance_groups``: the segments, the car's corner clicks and its
edge-end clicks each get their own factor, the estimator staying the fit's (the sandwich).
Off by default (benchmarks/README.md, stop 39).
"""

from __future__ import annotations

import numpy as np

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
