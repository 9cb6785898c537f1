"""The solvers of :mod:`camloc_geo._optimize` against ``scipy.optimize.least_squares``."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.optimize import least_squares

from camloc_geo import relative
from camloc_geo._optimize import (
    gauss_newton,
    soft_l1_cost,
    soft_l1_least_squares,
    soft_l1_least_squares_many,
    soft_l1_least_squares_many_small,
    soft_l1_least_squares_small,
)
from camloc_geo.absolute._similarity import rot2
from camloc_geo.scene import load_scene

SCENE = Path(__file__).resolve().parents[1] / "sample_maps" / "sample_scene.json"


def _curve_problem(seed: int) -> tuple[Any, Any, np.ndarray]:
    """y = a exp(b t) + c with 10 % gross outliers."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 3.0, 60)
    y = 2.0 * np.exp(-1.3 * t) + 0.5 + rng.normal(0.0, 0.02, t.size)
    bad = rng.choice(t.size, 6, replace=False)
    y[bad] += rng.normal(0.0, 1.0, 6)

    def fun(x: np.ndarray) -> np.ndarray:
        return np.asarray((x[0] * np.exp(x[1] * t) + x[2] - y) / 0.02)

    def jac(x: np.ndarray) -> np.ndarray:
        e = np.exp(x[1] * t)
        return np.column_stack([e, x[0] * t * e, np.ones_like(t)]) / 0.02

    return fun, jac, np.array([1.0, -0.5, 0.0])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_lm_soft_l1_matches_scipy_on_a_curve_with_outliers(seed: int) -> None:
    fun, jac, x0 = _curve_problem(seed)
    ours = soft_l1_least_squares(fun, jac, x0, f_scale=2.5)
    ref = least_squares(fun, x0, jac=jac, loss="soft_l1", f_scale=2.5, xtol=1e-12, ftol=1e-12)
    assert ours.success
    assert ours.cost == pytest.approx(ref.cost, rel=1e-6)
    assert ours.cost == pytest.approx(soft_l1_cost(fun(ours.x), 2.5))
    np.testing.assert_allclose(ours.x, ref.x, rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(ours.x, [2.0, -1.3, 0.5], atol=0.05)  # outliers ignored
    via = soft_l1_least_squares(fun, jac, x0, f_scale=2.5, method="scipy")
    assert via.cost == pytest.approx(ref.cost, rel=1e-6)


LOCKSTEP = [soft_l1_least_squares_many, soft_l1_least_squares_many_small]


@pytest.mark.parametrize("lockstep", LOCKSTEP)
@pytest.mark.parametrize("sigma_tol", [None, 0.1])
def test_lockstep_problems_take_the_steps_they_take_alone(
    sigma_tol: float | None, lockstep: Any
) -> None:
    problems = [_curve_problem(seed) for seed in range(4)]
    starts = [x0 + 0.3 * k for k, (_f, _j, x0) in enumerate(problems)]
    starts[3] = np.array([50.0, 8.0, -40.0])  # far off: many rejected steps
    batches: list[list[int]] = []

    def many(ids: list[int], xs: list[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray]]:
        batches.append(list(ids))
        return [(problems[i][0](x), problems[i][1](x)) for i, x in zip(ids, xs, strict=True)]

    together = lockstep(many, starts, f_scale=2.5, max_nfev=60, sigma_tol=sigma_tol)
    for (fun, jac, _x0), x0, res in zip(problems, starts, together, strict=True):

        def both(x: np.ndarray, f: Any = fun, j: Any = jac) -> tuple[np.ndarray, np.ndarray]:
            return f(x), j(x)

        alone = soft_l1_least_squares(
            fun, jac, x0, f_scale=2.5, max_nfev=60, fun_and_jac=both, sigma_tol=sigma_tol
        )
        assert res.nfev == alone.nfev
        assert res.success == alone.success
        np.testing.assert_array_equal(res.x, alone.x)
        np.testing.assert_array_equal(res.jac, alone.jac)
        assert res.cost == alone.cost
    assert batches[0] == [0, 1, 2, 3]  # the starts, in one call
    assert max(len(b) for b in batches[1:]) > 1  # trial steps shared
    assert sum(len(b) for b in batches) == sum(r.nfev for r in together)


@pytest.mark.parametrize("lockstep", LOCKSTEP)
def test_lockstep_with_a_singular_problem_matches_alone(lockstep: Any) -> None:
    # Problem 1 has a dead parameter (a zero Jacobian column): its undamped normal matrix
    # is singular, so the batched solve falls back to one system at a time.
    fun0, jac0, x0 = _curve_problem(0)

    def jac_dead(x: np.ndarray) -> np.ndarray:
        J = jac0(x)
        J[:, 2] = 0.0
        return np.asarray(J)

    problems = [(fun0, jac0), (fun0, jac_dead)]

    def many(ids: list[int], xs: list[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray]]:
        return [(problems[i][0](x), problems[i][1](x)) for i, x in zip(ids, xs, strict=True)]

    together = lockstep(many, [x0, x0], f_scale=2.5, max_nfev=40, sigma_tol=0.1)
    for (fun, jac), res in zip(problems, together, strict=True):

        def both(x: np.ndarray, f: Any = fun, j: Any = jac) -> tuple[np.ndarray, np.ndarray]:
            return f(x), j(x)

        alone = soft_l1_least_squares(
            fun, jac, x0, f_scale=2.5, max_nfev=40, fun_and_jac=both, sigma_tol=0.1
        )
        assert res.nfev == alone.nfev
        np.testing.assert_array_equal(res.x, alone.x)
    assert together[0].success
    assert np.all(np.isfinite(together[1].x))


def test_lean_lockstep_matches_lockstep_on_problems_of_two_sizes() -> None:
    # Two parameter counts in one round: the lean loop's one-stack solve does not apply and
    # it takes _solve_many's path; every problem's steps are still the lockstep loop's.
    fun0, jac0, x0 = _curve_problem(0)
    fun1, jac1, _x1 = _curve_problem(1)

    def fun_ab(x: np.ndarray) -> np.ndarray:  # c held at 0.5
        return np.asarray(fun1(np.array([x[0], x[1], 0.5])))

    def jac_ab(x: np.ndarray) -> np.ndarray:
        return np.asarray(jac1(np.array([x[0], x[1], 0.5]))[:, :2])

    problems = [(fun0, jac0), (fun_ab, jac_ab)]
    starts = [x0, np.array([1.0, -0.5])]

    def many(ids: list[int], xs: list[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray]]:
        return [(problems[i][0](x), problems[i][1](x)) for i, x in zip(ids, xs, strict=True)]

    ref = soft_l1_least_squares_many(many, starts, f_scale=2.5, max_nfev=40, sigma_tol=0.1)
    lean = soft_l1_least_squares_many_small(many, starts, f_scale=2.5, max_nfev=40, sigma_tol=0.1)
    for a, b in zip(ref, lean, strict=True):
        assert a.nfev == b.nfev > 2
        assert a.cost == b.cost
        np.testing.assert_array_equal(a.x, b.x)
        np.testing.assert_array_equal(a.jac, b.jac)
    np.testing.assert_allclose(lean[1].x, [2.0, -1.3], atol=0.1)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sigma_tol_stops_within_that_fraction_of_a_sigma(seed: int) -> None:
    """``sigma_tol`` stops once the next Gauss-Newton step is under that fraction of the
    parameters' 1-sigma: fewer evaluations, the answer within it of the full minimum."""
    fun, jac, x0 = _curve_problem(seed)
    full = soft_l1_least_squares(fun, jac, x0, f_scale=2.5, tol=1e-12)
    early = soft_l1_least_squares(fun, jac, x0, f_scale=2.5, tol=1e-12, sigma_tol=0.05)
    assert early.success
    assert early.nfev < full.nfev
    # The minimum's covariance, as the fits state it: (JᵀJ)⁻¹ s² of the weighted Jacobian.
    s2 = 2.0 * full.cost / (len(full.fun) - len(full.x))
    cov = np.linalg.inv(full.jac.T @ full.jac) * s2
    d = early.x - full.x
    assert float(d @ np.linalg.solve(cov, d)) <= (2 * 0.05) ** 2
    assert float(d @ np.linalg.solve(cov, d)) > 0.0
    # The stop's residuals and Jacobian are those of the returned x (no step after them).
    np.testing.assert_allclose(early.fun, fun(early.x))


def _assert_same_fit(a: Any, b: Any) -> None:
    assert a.nfev == b.nfev
    assert a.success == b.success
    assert a.cost == b.cost
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.fun, b.fun)
    np.testing.assert_array_equal(a.jac, b.jac)


@pytest.mark.parametrize("sigma_tol", [None, 0.1])
def test_small_loop_takes_the_loops_steps_bit_for_bit(sigma_tol: float | None) -> None:
    """soft_l1_least_squares_small is soft_l1_least_squares's lm loop, cheaper a step."""
    seen_far = 0
    for seed in range(4):
        fun, jac, x0 = _curve_problem(seed)
        for start in (x0, np.array([50.0, 8.0, -40.0])):  # near; far off (rejected steps)

            def both(x: np.ndarray, f: Any = fun, j: Any = jac) -> tuple[np.ndarray, np.ndarray]:
                return f(x), j(x)

            def clamp(x: np.ndarray) -> np.ndarray:  # a bound that binds on the far start
                return np.asarray(np.concatenate([[min(x[0], 30.0)], x[1:]]))

            for project in (None, clamp):
                kw: dict[str, Any] = {
                    "f_scale": 2.5,
                    "max_nfev": 60,
                    "sigma_tol": sigma_tol,
                    "project": project,
                }
                with np.errstate(over="ignore", invalid="ignore"):  # far off: exp overflows
                    loop = soft_l1_least_squares(fun, jac, start, fun_and_jac=both, **kw)
                    small = soft_l1_least_squares_small(both, start, **kw)
                _assert_same_fit(small, loop)
                seen_far += int(loop.nfev > 10)
    assert seen_far > 0  # the far starts did take many steps


def test_small_loop_matches_the_loop_on_the_calibration_problems() -> None:
    """Every fit of a few calibrations, replayed through soft_l1_least_squares: the same."""
    from camloc_geo.scene import parse_scene
    from camloc_geo.testing.synthetic import NoiseModel, make_scene, random_camera

    compared: list[int] = []
    original = relative._fit

    def spy(prob: Any, x0: Any, R0: Any, pp: Any, f: Any, **kw: Any) -> Any:
        res = original(prob, x0, R0, pp, f, **kw)
        if kw.get("method", "lm") != "lm":
            return res

        def both(x: np.ndarray) -> Any:
            return prob.residuals_and_jacobian(x, R0, pp, f)

        def clamp(x: np.ndarray) -> np.ndarray:
            x = x.copy()
            x[0] = float(np.clip(x[0], *prob.log_f_bounds))
            return x

        loop = soft_l1_least_squares(
            lambda x: both(x)[0],
            lambda x: both(x)[1],
            x0,
            f_scale=relative._F_SCALE,
            project=clamp if f is None else None,
            tol=kw.get("tol", 1e-10),
            max_nfev=kw.get("max_nfev", 200),
            fun_and_jac=both,
            damping=1e-4,
            sigma_tol=kw.get("sigma_tol", relative._SIGMA_TOL),
        )
        _assert_same_fit(res, loop)
        compared.append(res.nfev)
        return res

    scenes = [load_scene(SCENE)]
    for seed in (1, 2):
        rng = np.random.default_rng(seed)
        syn = make_scene(random_camera(rng), rng, noise=NoiseModel(), n_annotators=4)
        scenes.append(parse_scene(syn.scene))
    relative._fit = spy  # type: ignore[assignment]
    try:
        for scene in scenes:
            relative.calibrate(scene)
    finally:
        relative._fit = original
    assert len(compared) >= 6
    assert max(compared) >= 3  # fits that took steps


def test_lm_soft_l1_matches_scipy_on_the_calibration_problems() -> None:
    recorded: list[tuple[Any, ...]] = []
    original = relative._fit

    def spy(prob: Any, x0: Any, R0: Any, pp: Any, f: Any, **kw: Any) -> Any:
        res = original(prob, x0, R0, pp, f, **kw)
        # The same fit to the tolerances alone (no stop at a fraction of a sigma).
        full = original(prob, x0, R0, pp, f, **{**kw, "sigma_tol": None})
        sigma_tol = kw.get("sigma_tol", relative._SIGMA_TOL)
        recorded.append(
            (prob, np.array(x0, float), R0, pp, f, prob.weights.copy(), res, full, sigma_tol)
        )
        return res

    relative._fit = spy  # type: ignore[assignment]
    try:
        relative.calibrate(load_scene(SCENE))
    finally:
        relative._fit = original
    assert recorded
    assert any(rec[-1] is not None for rec in recorded)
    for prob, x0, R0, pp, f, weights, ours, full, sigma_tol in recorded:
        prob.weights = weights
        clamp = None
        if f is None:

            def clamp(x: np.ndarray, prob: Any = prob) -> np.ndarray:
                x = x.copy()
                x[0] = float(np.clip(x[0], *prob.log_f_bounds))
                return x

        def res_fun(x: np.ndarray, prob: Any = prob, R0: Any = R0, pp: Any = pp, f: Any = f) -> Any:
            return prob.residuals(x, R0, pp, f)

        def jac_fun(x: np.ndarray, prob: Any = prob, R0: Any = R0, pp: Any = pp, f: Any = f) -> Any:
            return prob.jacobian(x, R0, pp, f)

        ref = soft_l1_least_squares(
            res_fun,
            jac_fun,
            x0,
            f_scale=relative._F_SCALE,
            project=clamp,
            method="scipy",
        )
        # The home-made loop reaches scipy's minimum (or a lower one), never a worse one.
        assert full.cost <= ref.cost * (1 + 1e-4) + 1e-9
        # Stopped once the next step moves the answer by less than sigma_tol of its sigma:
        # within about half sigma_tol² of the residual variance of the minimum's cost.
        if sigma_tol is not None:
            s2 = 2.0 * ref.cost / max(len(ref.fun) - len(ref.x), 1)
            assert ours.cost <= ref.cost + sigma_tol**2 * s2 + 1e-9


def test_gauss_newton_matches_scipy_on_a_similarity_fit() -> None:
    rng = np.random.default_rng(3)
    P = rng.uniform(-10.0, 10.0, (8, 2))
    theta, T, s = 0.7, np.array([30.0, -12.0]), 1.03
    Q = s * P @ rot2(theta).T + T + rng.normal(0.0, 0.05, P.shape)

    def resid(x: np.ndarray) -> np.ndarray:
        return np.asarray((math.exp(x[3]) * P @ rot2(x[0]).T + x[1:3] - Q).ravel())

    def resid_jac(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        sc = math.exp(x[3])
        R = rot2(x[0])
        dR = np.array([[-R[1, 0], -R[0, 0]], [R[0, 0], -R[1, 0]]])
        cols = [sc * P @ dR.T, np.tile([1.0, 0.0], (len(P), 1)), np.tile([0.0, 1.0], (len(P), 1))]
        cols.append(sc * P @ R.T)
        return resid(x), np.column_stack([c.ravel() for c in cols])

    x0 = np.array([0.5, 25.0, -10.0, 0.0])
    x, J = gauss_newton(resid_jac, x0)
    ref = least_squares(resid, x0, xtol=1e-14, ftol=1e-14, gtol=1e-14)
    np.testing.assert_allclose(x, ref.x, atol=1e-8)
    assert J.shape == (16, 4)

    # The sigma stop: fewer evaluations, within sigma_tol of the minimum in the parameters'
    # own 1-sigma (whitened residuals: a noise of 0.05 is one sigma here).
    def whitened(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        calls.append(1)
        r, J = resid_jac(x)
        return r / 0.05, J / 0.05

    calls: list[int] = []
    x_full, _J = gauss_newton(whitened, x0)
    n_full = len(calls)
    calls.clear()
    x_fast, J_fast = gauss_newton(whitened, x0, sigma_tol=1e-3)
    assert len(calls) < n_full
    assert float(np.linalg.norm(J_fast @ (x_fast - x_full))) < 1e-3
    np.testing.assert_allclose(x_full, ref.x, atol=1e-8)
