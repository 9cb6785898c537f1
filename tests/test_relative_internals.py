"""The joint problem's remembered evaluations and vectorised sensitivities (issue 26)."""

from __future__ import annotations

from typing import Any

import numpy as np

from camloc_geo.relative import (
    _F_SCALE,
    _ground_corner_evidence,
    _ground_corner_sensitivity,
    calibrate,
)
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import NoiseModel, make_scene, random_camera


def _state(seed: int = 4) -> Any:
    rng = np.random.default_rng(seed)
    syn = make_scene(random_camera(rng), rng, noise=NoiseModel(), n_annotators=4)
    state = calibrate(parse_scene(syn.scene)).joint_state
    assert state is not None
    return state


def _fresh(prob: Any, x: np.ndarray, args: tuple[Any, ...]) -> tuple[np.ndarray, np.ndarray]:
    prob._memo.clear()
    r, J = prob.residuals_and_jacobian(x, *args)
    return r.copy(), J.copy()


def test_remembered_evaluations_match_fresh_ones_and_follow_the_state() -> None:
    state = _state()
    prob = state.problem
    args = (state.rotation0, state.principal_point, state.focal_px)
    x = np.asarray(state.x, dtype=float)
    prob.weights = state.weights
    r1, J1 = prob.residuals_and_jacobian(x, *args)
    r2, J2 = prob.residuals_and_jacobian(x.copy(), *args)
    assert r2 is r1  # remembered
    assert J2 is J1
    np.testing.assert_array_equal(prob.residuals(x, *args), r1)
    fresh_r, fresh_J = _fresh(prob, x, args)
    np.testing.assert_array_equal(fresh_r, r1)
    np.testing.assert_array_equal(fresh_J, J1)
    # other weights, another point, other corners: not the remembered answer
    prob.weights = np.ones(prob.n_annotators) * 0.5
    r3 = prob.residuals(x, *args)
    assert not np.allclose(r3, r1)
    np.testing.assert_allclose(r3, _fresh(prob, x, args)[0])
    x_moved = x + 1e-3
    assert not np.allclose(prob.residuals(x_moved, *args), r3)
    saved = prob.corners.copy()
    prob.set_corners((saved + 1) % 4)
    assert not np.allclose(prob.residuals(x, *args), r3)
    prob.set_corners(saved)
    prob.weights = state.weights


def test_unweighted_residuals_are_the_residuals_at_weight_one() -> None:
    state = _state(5)
    prob = state.problem
    args = (state.rotation0, state.principal_point, state.focal_px)
    x = np.asarray(state.x, dtype=float)
    prob.weights = np.array([1.0, 0.3, 0.8, 0.05])[: prob.n_annotators]
    prob.residuals_and_jacobian(x, *args)  # remembered at these weights
    from_memory = prob.unweighted_residuals(x, *args)
    saved = prob.weights
    prob.weights = np.ones(prob.n_annotators)
    prob._memo.clear()
    n_rows = len(prob.segments) + 2 * len(prob.pt_pix)
    direct = prob.residuals(x, *args)[:n_rows]
    prob.weights = saved
    np.testing.assert_allclose(from_memory, direct, rtol=1e-12, atol=1e-12)


def test_the_vectorised_ground_corner_columns_equal_the_loop() -> None:
    state = _state(6)
    prob = state.problem
    args = (state.rotation0, state.principal_point, state.focal_px)
    x = np.asarray(state.x, dtype=float)
    prob.weights = state.weights
    D = _ground_corner_sensitivity(prob, x, *args)
    assert D is not None
    # the loop it replaced: per annotator, per edge, per click one column of -H⁻¹ Jᵀ W dr
    r, J = _fresh(prob, x, args)
    w = 1.0 / np.sqrt(1.0 + (r / _F_SCALE) ** 2)
    JW = J * w[:, None]
    H = J.T @ JW
    n_seg, n_pt = len(prob.segments), len(prob.pt_pix)
    clicks = prob.pt_pix.reshape(-1, 4, 2)
    cols = []
    for a in range(len(clicks)):
        for end in (1, 2):
            step = prob.ground_corner_sigma_rel * (clicks[a, end] - clicks[a, 0])
            for j in range(4 * a, 4 * a + 4):
                ju, jv = JW[n_seg + j], JW[n_seg + n_pt + j]
                cols.append(-prob._pt_scale[j] * (step[0] * ju + step[1] * jv))
    ref = -_ground_corner_evidence(prob, r) * np.linalg.solve(H, np.column_stack(cols))
    # the same columns in another order: the consider covariance D Dᵀ is the same
    assert D.shape == ref.shape == (len(x), 8 * len(clicks))
    scale = float(np.abs(ref @ ref.T).max())
    np.testing.assert_allclose(D @ D.T, ref @ ref.T, rtol=1e-9, atol=1e-9 * scale)


def test_residuals_of_a_batch_unpacked_with_another_equal_the_batch_alone() -> None:
    # The bundle unpacks its annotation and map batches in one call and takes the
    # annotation rows from the slice (relative._ROTVEC_SCALAR_MAX: both batches large).
    state = _state(6)
    prob = state.problem
    args = (state.rotation0, state.principal_point, state.focal_px)
    x = np.asarray(state.x, dtype=float)
    rng = np.random.default_rng(0)
    X = x + 1e-3 * rng.standard_normal((15, len(x)))
    other = x + 1e-2 * rng.standard_normal((20, len(x)))
    f, pp, R, C = prob._unpack_batch(np.concatenate([X, other]), *args)
    pp_x = pp[:15] if len(pp) > 1 else pp
    got = prob.residuals_of_unpacked(f[:15], pp_x, R[:15], C[:15], *args[1:])
    alone = prob.residuals_batch(X, *args)
    assert got.shape == alone.shape == (15, len(prob.residuals(x, *args)))
    np.testing.assert_array_equal(got, alone)
    assert not np.allclose(got[0], got[1])  # the rows are the batch's own


def test_rotation_jackknife_is_not_counted_twice() -> None:
    """The fit's rotation covariance and the annotators' leave-one-out spread estimate the
    same sampling spread: the stated sigma is the larger per axis, as for the position and
    the focal length (old code: their root-sum-square, 0.61° on x and 0.87° on y; crowd
    rotation 1σ coverage 87 / 87 / 90 %)."""
    from types import SimpleNamespace

    from camloc_geo.relative import _add_jackknife_spread

    result = SimpleNamespace(
        focal_sigma_px=10.0,
        position_sigma_m=np.array([1.0, 1.0, 1.0]),
        rotation_sigma_deg=np.array([0.5, 0.1, 0.3]),
    )
    # leave-one-out turns of ±0.2° about x, ±0.5° about y, none about z: jackknife sigmas
    # sqrt((m - 1) / m · Σ d²) with m = 4: 0.35° on x, 0.87° on y, 0 on z
    a, b = np.radians(0.2), np.radians(0.5)
    turns = [np.array([a, b, 0.0]), np.array([-a, -b, 0.0])] * 2
    centres = [np.zeros(3)] * 4
    _add_jackknife_spread(result, centres, turns, [1000.0] * 4)  # type: ignore[arg-type]
    np.testing.assert_allclose(result.rotation_sigma_fit_deg, [0.5, 0.1, 0.3])
    np.testing.assert_allclose(result.rotation_sigma_deg, [0.5, np.sqrt(0.75), 0.3], rtol=1e-9)
