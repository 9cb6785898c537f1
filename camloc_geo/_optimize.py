"""Nonlinear least squares: the one module every fit in the package goes through.

Two problems, two solvers, both typed and tested against
:func:`scipy.optimize.least_squares` on the same problems (``tests/test_optimize.py``):

:func:`soft_l1_least_squares`
    Robust (soft-L1) least squares, the relative pose's joint fit. ``method="lm"`` is a
    small Levenberg-Marquardt loop on iteratively reweighted residuals; ``method="scipy"``
    calls ``least_squares(loss="soft_l1")``. Both minimise the same cost
    ``0.5 Σ 2 f² (√(1 + r²/f²) − 1)`` and return the same :class:`LeastSquaresResult`.
    The loop stays because it earns its place, modestly: on 40 calibration fits
    (``benchmarks/optimize.py``) it reaches the same minimum (median relative cost
    difference 3e-10) 1.35x faster per fit (median) and 2.3x faster in total, with no
    trust-region bookkeeping on a 7-9 parameter problem.
:func:`soft_l1_least_squares_small`
    The ``lm`` loop of :func:`soft_l1_least_squares` for a few parameters whose residuals
    and Jacobian come from one call (the relative pose's joint fit): exactly its steps
    (tested bit for bit), with fewer array operations a step (its cost is numpy's per-call
    overhead on 7-10 parameters).
:func:`soft_l1_least_squares_many`
    The ``lm`` loop for several independent problems in lockstep (the absolute bundle
    adjustment of the leading candidates): each takes exactly the steps it takes alone
    (tested bit for bit), their evaluations are made in one call per round.
:func:`soft_l1_least_squares_many_small`
    The lockstep loop of :func:`soft_l1_least_squares_many`, step for step (tested bit for
    bit), with :func:`soft_l1_least_squares_small`'s leaner bookkeeping (the bundle).
:func:`gauss_newton`
    Plain Gauss-Newton for nearly linear problems with an analytic Jacobian (the absolute
    refinement of ``enu_from_world``): a handful of steps, stopping when the cost stops
    falling.

scipy is imported only inside :func:`soft_l1_least_squares` with ``method="scipy"``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

__all__ = [
    "LeastSquaresResult",
    "gauss_newton",
    "soft_l1_cost",
    "soft_l1_least_squares",
    "soft_l1_least_squares_many",
    "soft_l1_least_squares_many_small",
    "soft_l1_least_squares_small",
]

FloatArray = npt.NDArray[np.float64]
Residuals = Callable[[FloatArray], FloatArray]
ResidualsAndJacobian = Callable[[FloatArray], tuple[FloatArray, FloatArray]]
ManyResidualsAndJacobians = Callable[
    [list[int], list[FloatArray]], list[tuple[FloatArray, FloatArray]]
]


@dataclass(frozen=True)
class LeastSquaresResult:
    """The fields of :func:`scipy.optimize.least_squares`'s result that callers use.

    Attributes
    ----------
    x
        The solution.
    cost
        The robust cost at ``x``, ``0.5 Σ ρ(r²)`` (scipy's definition).
    fun
        The residuals at ``x``.
    jac
        The robustly weighted Jacobian at ``x``: ``jacᵀ jac`` is the Gauss-Newton Hessian
        of the cost (as scipy returns it).
    success
        Converged (tolerance met, or no descent direction left).
    nfev
        Residual evaluations (each Jacobian counts as one: it is one batched evaluation).
    """

    x: FloatArray
    cost: float
    fun: FloatArray
    jac: FloatArray
    success: bool
    nfev: int


def soft_l1_cost(r: FloatArray, f_scale: float) -> float:
    """``0.5 Σ 2 f² (√(1 + r²/f²) − 1)``: scipy's soft-L1 cost of residuals ``r``."""
    c2 = f_scale**2
    return float(0.5 * np.sum(2.0 * c2 * (np.sqrt(1.0 + r * r / c2) - 1.0)))


def soft_l1_least_squares(
    fun: Residuals,
    jac: Residuals,
    x0: npt.ArrayLike,
    *,
    f_scale: float,
    project: Callable[[FloatArray], FloatArray] | None = None,
    method: Literal["lm", "scipy"] = "lm",
    tol: float = 1e-10,
    max_nfev: int = 200,
    fun_and_jac: ResidualsAndJacobian | None = None,
    damping: float = 1e-3,
    sigma_tol: float | None = None,
) -> LeastSquaresResult:
    """Minimise the soft-L1 cost of ``fun(x)`` from ``x0``.

    Parameters
    ----------
    fun, jac
        Residuals ``(m,)`` and their Jacobian ``(m, n)`` at ``x``.
    f_scale
        Soft margin between inlier and outlier residuals (scipy's ``f_scale``).
    project
        Maps a trial ``x`` back into the feasible set (``lm`` only; e.g. clamps a focal
        length). None: unconstrained.
    method
        ``lm``: the Levenberg-Marquardt loop; ``scipy``: ``least_squares(loss="soft_l1")``.
    tol, max_nfev
        Relative tolerance on the gradient, step and cost decrease; evaluation budget.
    fun_and_jac
        Optional (``lm`` only): the residuals and the Jacobian at ``x`` from one call. Each
        trial step is then evaluated with its Jacobian at once (worth it where a batched
        finite-difference Jacobian costs little more than the residuals alone: most steps
        are accepted, and an accepted step then needs no second call).
    damping
        ``lm``: the initial Levenberg-Marquardt damping (relative to the normal equations'
        diagonal); smaller suits a start already near the minimum.
    sigma_tol
        ``lm``: also stop once the fit no longer moves the answer: when the undamped
        Gauss-Newton step from ``x`` is shorter than ``sigma_tol`` of the parameters' own
        1-sigma (its Newton decrement ``gᵀ A⁻¹ g`` below ``sigma_tol² s²``, ``s²`` the
        residual variance factor ``2 cost / (m − n)``, at least 1e-12). ``x`` is returned
        as it is (with its residuals and Jacobian, no further evaluation): within
        ``sigma_tol`` sigma of the minimum. None: the tolerances alone.
    """
    x = np.asarray(x0, dtype=np.float64).copy()
    if project is not None:
        x = project(x)
    if method == "scipy":
        return _scipy_soft_l1(fun, jac, x, f_scale=f_scale, tol=tol, max_nfev=max_nfev)
    return _lm_soft_l1(
        fun,
        jac,
        x,
        f_scale=f_scale,
        project=project,
        tol=tol,
        max_nfev=max_nfev,
        fun_and_jac=fun_and_jac,
        damping=damping,
        sigma_tol=sigma_tol,
    )


def _scipy_soft_l1(
    fun: Residuals, jac: Residuals, x: FloatArray, *, f_scale: float, tol: float, max_nfev: int
) -> LeastSquaresResult:
    from scipy.optimize import least_squares

    res = least_squares(
        fun,
        x,
        jac=jac,
        loss="soft_l1",
        f_scale=f_scale,
        method="trf",
        x_scale="jac",
        ftol=tol,
        xtol=tol,
        gtol=tol,
        max_nfev=max_nfev,
    )
    return LeastSquaresResult(
        x=np.asarray(res.x, dtype=np.float64),
        cost=float(res.cost),
        fun=np.asarray(res.fun, dtype=np.float64),
        jac=np.asarray(res.jac, dtype=np.float64),
        success=bool(res.success),
        nfev=int(res.nfev),
    )


def _lm_soft_l1(
    fun: Residuals,
    jac: Residuals,
    x: FloatArray,
    *,
    f_scale: float,
    project: Callable[[FloatArray], FloatArray] | None,
    tol: float,
    max_nfev: int,
    fun_and_jac: ResidualsAndJacobian | None = None,
    damping: float = 1e-3,
    sigma_tol: float | None = None,
) -> LeastSquaresResult:
    """Levenberg-Marquardt on soft-L1 reweighted residuals (IRLS weights per step)."""
    c2 = f_scale**2
    if fun_and_jac is not None:
        r, J = fun_and_jac(x)
    else:
        r = fun(x)
        J = jac(x)
    cost = soft_l1_cost(r, f_scale)
    lam = damping
    nfev = 1
    success = False
    while nfev < max_nfev:
        w = 1.0 / np.sqrt(1.0 + r * r / c2)  # soft-L1 IRLS weights
        Jw = J * w[:, None]
        A = J.T @ Jw
        g = Jw.T @ r
        if np.max(np.abs(g)) * max(1.0, float(np.max(np.abs(x)))) < tol * max(cost, 1e-300):
            success = True
            break
        diag = np.diag(A).copy()
        diag[diag <= 0] = 1e-12
        try:
            if sigma_tol is None:
                dx = -np.linalg.solve(A + lam * np.diag(diag), g)
            else:
                # The damped step and the undamped Gauss-Newton step in one call.
                both = np.linalg.solve(
                    np.stack([A + lam * np.diag(diag), A]), np.stack([g, g])[:, :, None]
                )[:, :, 0]
                if _within_sigma(float(g @ both[1]), cost, len(r), len(g), sigma_tol):
                    success = True
                    break
                dx = -both[0]
        except np.linalg.LinAlgError:
            lam *= 10.0
            if lam > 1e12:
                break
            continue
        x_new = x + dx
        if project is not None:
            x_new = project(x_new)
        J_new: FloatArray | None = None
        if fun_and_jac is not None:
            r_new, J_new = fun_and_jac(x_new)
        else:
            r_new = fun(x_new)
        nfev += 1
        cost_new = soft_l1_cost(r_new, f_scale)
        if cost_new <= cost:
            step_small = np.max(np.abs(dx)) <= tol * (1e-3 + float(np.max(np.abs(x))))
            gain_small = cost - cost_new <= tol * max(cost, 1e-300)
            x, r, cost = x_new, r_new, cost_new
            lam = max(lam * 0.3, 1e-12)
            J = J_new if J_new is not None else jac(x)
            if step_small or gain_small:
                success = True
                break
        else:
            lam *= 10.0
            if lam > 1e12:
                success = True  # no descent direction left: at a (local) minimum
                break
    w = 1.0 / np.sqrt(1.0 + r * r / c2)
    return LeastSquaresResult(
        x=x, cost=cost, fun=r, jac=J * np.sqrt(w)[:, None], success=success, nfev=nfev
    )


def soft_l1_least_squares_small(
    fun_and_jac: ResidualsAndJacobian,
    x0: npt.ArrayLike,
    *,
    f_scale: float,
    project: Callable[[FloatArray], FloatArray] | None = None,
    tol: float = 1e-10,
    max_nfev: int = 200,
    damping: float = 1e-3,
    sigma_tol: float | None = None,
    stop: Callable[[float, FloatArray, FloatArray], bool] | None = None,
) -> LeastSquaresResult:
    """:func:`soft_l1_least_squares` (``method="lm"``, with ``fun_and_jac``), step for step.

    The same iterations, tests and arithmetic, so the same result bit for bit; only the
    bookkeeping of a step takes fewer numpy calls: the damped and the undamped normal
    equations are written into one preallocated stack, the soft-L1 weights come from the
    square roots the cost already took. Worth it where a step's array operations, not its
    evaluation, are the cost (7-10 parameters, ~100 residuals).

    Parameters
    ----------
    fun_and_jac
        The residuals ``(m,)`` and their Jacobian ``(m, n)`` at ``x`` from one call.
    x0, f_scale, project, tol, max_nfev, damping, sigma_tol
        As :func:`soft_l1_least_squares`.
    stop
        Called at each step's start with the cost, the normal matrix ``Jᵀ W J`` and the
        gradient ``Jᵀ W r`` at ``x``; True ends the fit there (``success`` False), for a
        caller that needs only to know whether the cost gets below some level.
    """
    x = np.asarray(x0, dtype=np.float64).copy()
    if project is not None:
        x = project(x)
    c2 = f_scale**2
    r, J = fun_and_jac(x)
    root = np.sqrt(1.0 + r * r / c2)  # soft-L1: cost 0.5 Σ 2c² (root - 1), IRLS weight 1/root
    cost = float(0.5 * np.sum(2.0 * c2 * (root - 1.0)))
    lam = damping
    nfev = 1
    success = False
    n = len(x)
    stack = np.empty((2, n, n))  # the damped and the undamped normal equations
    flat_damped = stack.reshape(2, n * n)[0]  # a view: its diagonal is every (n + 1)th
    rhs = np.empty((2, n, 1))
    while nfev < max_nfev:
        w = 1.0 / root
        Jw = J * w[:, None]
        A = J.T @ Jw
        g = Jw.T @ r
        if stop is not None and stop(cost, A, g):
            break
        if np.max(np.abs(g)) * max(1.0, float(np.max(np.abs(x)))) < tol * max(cost, 1e-300):
            success = True
            break
        diag = A.diagonal().copy()
        diag[diag <= 0] = 1e-12
        try:
            if sigma_tol is None:
                dx = -np.linalg.solve(A + lam * np.diag(diag), g)
            else:
                stack[0] = A
                stack[1] = A
                flat_damped[:: n + 1] += lam * diag  # A + lam·diag(diag), as the loop
                rhs[:, :, 0] = g
                both = np.linalg.solve(stack, rhs)[:, :, 0]
                if _within_sigma(float(g @ both[1]), cost, len(r), len(g), sigma_tol):
                    success = True
                    break
                dx = -both[0]
        except np.linalg.LinAlgError:
            lam *= 10.0
            if lam > 1e12:
                break
            continue
        x_new = x + dx
        if project is not None:
            x_new = project(x_new)
        r_new, J_new = fun_and_jac(x_new)
        nfev += 1
        root_new = np.sqrt(1.0 + r_new * r_new / c2)
        cost_new = float(0.5 * np.sum(2.0 * c2 * (root_new - 1.0)))
        if cost_new <= cost:
            step_small = np.max(np.abs(dx)) <= tol * (1e-3 + float(np.max(np.abs(x))))
            gain_small = cost - cost_new <= tol * max(cost, 1e-300)
            x, r, cost, J, root = x_new, r_new, cost_new, J_new, root_new
            lam = max(lam * 0.3, 1e-12)
            if step_small or gain_small:
                success = True
                break
        else:
            lam *= 10.0
            if lam > 1e12:
                success = True  # no descent direction left: at a (local) minimum
                break
    w = 1.0 / root
    return LeastSquaresResult(
        x=x, cost=cost, fun=r, jac=J * np.sqrt(w)[:, None], success=success, nfev=nfev
    )


def soft_l1_least_squares_many(
    fun_and_jac_many: ManyResidualsAndJacobians,
    x0s: list[FloatArray],
    *,
    f_scale: float,
    tol: float = 1e-10,
    max_nfev: int = 200,
    damping: float = 1e-3,
    sigma_tol: float | None = None,
) -> list[LeastSquaresResult]:
    """Several independent problems through the ``lm`` loop of :func:`soft_l1_least_squares`
    in lockstep, their trial steps evaluated together.

    Each problem takes exactly the steps, the damping and the stopping decisions it would
    take alone (``soft_l1_least_squares(..., fun_and_jac=...)``, unprojected); only the
    evaluations are shared: ``fun_and_jac_many(ids, xs)`` gives the residuals and the
    Jacobian of problem ``ids[k]`` at ``xs[k]`` for every ``k`` in one call, so that a caller
    can batch its finite differences over all of them (small problems cost mostly per call).
    The first call holds every problem at its start. ``sigma_tol``: each problem stops as
    :func:`soft_l1_least_squares` with the same ``sigma_tol`` would (within that fraction of
    its own 1-sigma of the minimum); None (the default): the tolerances alone.
    """
    xs = [np.asarray(x0, dtype=np.float64).copy() for x0 in x0s]
    n = len(xs)
    c2 = f_scale**2
    first = fun_and_jac_many(list(range(n)), xs)
    rs = [r for r, _J in first]
    Js = [J for _r, J in first]
    costs = [soft_l1_cost(r, f_scale) for r in rs]
    lams = [damping] * n
    nfevs = [1] * n
    successes = [False] * n
    active = list(range(n))
    while active:
        trial_ids: list[int] = []
        trial_xs: list[FloatArray] = []
        trial_dxs: list[FloatArray] = []
        still: list[int] = []
        # The normal equations of every problem still going, then all their solves in one
        # batched call (LAPACK solves each matrix on its own: the same bits as one by one).
        pending: list[tuple[int, FloatArray, FloatArray, FloatArray]] = []
        for i in active:
            if nfevs[i] >= max_nfev:
                continue
            r, J, x = rs[i], Js[i], xs[i]
            w = 1.0 / np.sqrt(1.0 + r * r / c2)  # soft-L1 IRLS weights
            Jw = J * w[:, None]
            A = J.T @ Jw
            g = Jw.T @ r
            if float(np.abs(g).max()) * max(1.0, float(np.abs(x).max())) < tol * max(
                costs[i], 1e-300
            ):
                successes[i] = True
                continue
            diag = A.diagonal().copy()
            diag[diag <= 0] = 1e-12
            pending.append((i, A + lams[i] * np.diag(diag), A, g))
        solved = _solve_many(pending, with_gauss_newton=sigma_tol is not None)
        for (i, _A_damped, _A, g), sol in zip(pending, solved, strict=True):
            if sol is None:
                lams[i] *= 10.0
                if lams[i] <= 1e12:
                    still.append(i)  # retried next round with the same residuals
                continue
            if sigma_tol is not None and _within_sigma(
                float(g @ sol[1]), costs[i], len(rs[i]), len(g), sigma_tol
            ):
                successes[i] = True
                continue
            dx = np.asarray(-sol[0], np.float64)
            trial_ids.append(i)
            trial_xs.append(xs[i] + dx)
            trial_dxs.append(dx)
        evaluated = fun_and_jac_many(trial_ids, trial_xs) if trial_ids else []
        for i, x_new, dx, (r_new, J_new) in zip(
            trial_ids, trial_xs, trial_dxs, evaluated, strict=True
        ):
            nfevs[i] += 1
            cost_new = soft_l1_cost(r_new, f_scale)
            if cost_new <= costs[i]:
                x = xs[i]
                step_small = float(np.abs(dx).max()) <= tol * (1e-3 + float(np.abs(x).max()))
                gain_small = costs[i] - cost_new <= tol * max(costs[i], 1e-300)
                xs[i], rs[i], costs[i], Js[i] = x_new, r_new, cost_new, J_new
                lams[i] = max(lams[i] * 0.3, 1e-12)
                if step_small or gain_small:
                    successes[i] = True
                    continue
            else:
                lams[i] *= 10.0
                if lams[i] > 1e12:
                    successes[i] = True  # no descent direction left: at a (local) minimum
                    continue
            still.append(i)
        active = sorted(still)
    out = []
    for i in range(n):
        w = 1.0 / np.sqrt(1.0 + rs[i] * rs[i] / c2)
        out.append(
            LeastSquaresResult(
                x=xs[i],
                cost=costs[i],
                fun=rs[i],
                jac=Js[i] * np.sqrt(w)[:, None],
                success=successes[i],
                nfev=nfevs[i],
            )
        )
    return out


def soft_l1_least_squares_many_small(
    fun_and_jac_many: ManyResidualsAndJacobians,
    x0s: list[FloatArray],
    *,
    f_scale: float,
    tol: float = 1e-10,
    max_nfev: int = 200,
    damping: float = 1e-3,
    sigma_tol: float | None = None,
) -> list[LeastSquaresResult]:
    """:func:`soft_l1_least_squares_many`, step for step, with fewer array operations a step.

    The same iterations, tests and arithmetic, so the same results bit for bit (tested);
    only a round's bookkeeping is leaner, as :func:`soft_l1_least_squares_small`'s: the
    soft-L1 weights come from the square roots the cost already took, and the damped and
    undamped normal equations of every problem go straight into one preallocated stack for
    the round's single batched solve (problems of one size; otherwise, or when a system is
    singular, :func:`_solve_many`'s path). Worth it where the problems are small (10-15
    parameters, ~100 residuals) and the step's numpy calls, not its evaluation, cost.

    Parameters
    ----------
    fun_and_jac_many, x0s, f_scale, tol, max_nfev, damping, sigma_tol
        As :func:`soft_l1_least_squares_many`.
    """
    xs = [np.asarray(x0, dtype=np.float64).copy() for x0 in x0s]
    n = len(xs)
    c2 = f_scale**2
    first = fun_and_jac_many(list(range(n)), xs)
    rs = [r for r, _J in first]
    Js = [J for _r, J in first]
    # soft-L1: cost 0.5 Σ 2c² (root - 1), IRLS weight 1/root (soft_l1_cost's arithmetic)
    roots = [np.sqrt(1.0 + r * r / c2) for r in rs]
    costs = [float(0.5 * np.sum(2.0 * c2 * (root - 1.0))) for root in roots]
    lams = [damping] * n
    nfevs = [1] * n
    successes = [False] * n
    active = list(range(n))
    k_sys = 2 if sigma_tol is not None else 1
    sizes = {len(x) for x in xs}
    n_par = len(xs[0]) if len(sizes) == 1 else 0
    while active:
        trial_ids: list[int] = []
        trial_xs: list[FloatArray] = []
        trial_dxs: list[FloatArray] = []
        still: list[int] = []
        systems: list[tuple[int, FloatArray, FloatArray, FloatArray]] = []
        for i in active:
            if nfevs[i] >= max_nfev:
                continue
            r, J, x = rs[i], Js[i], xs[i]
            Jw = J * (1.0 / roots[i])[:, None]
            A = J.T @ Jw
            g = Jw.T @ r
            if float(np.abs(g).max()) * max(1.0, float(np.abs(x).max())) < tol * max(
                costs[i], 1e-300
            ):
                successes[i] = True
                continue
            diag = A.diagonal().copy()
            diag[diag <= 0] = 1e-12
            systems.append((i, A, g, diag))
        solved: list[FloatArray | None] = []
        if systems and n_par:
            # The round's systems in one stack, damped (and undamped) per problem, as
            # _solve_many stacks them: A + lam·diag(diag) is A with lam·diag added to its
            # diagonal (every (n + 1)th element of the flattened matrix).
            m = len(systems)
            mats = np.empty((m * k_sys, n_par, n_par))
            rhs = np.empty((m * k_sys, n_par, 1))
            flat = mats.reshape(m * k_sys, n_par * n_par)
            for j, (i, A, g, diag) in enumerate(systems):
                mats[k_sys * j] = A
                flat[k_sys * j, :: n_par + 1] += lams[i] * diag
                rhs[k_sys * j, :, 0] = g
                if k_sys == 2:
                    mats[2 * j + 1] = A
                    rhs[2 * j + 1, :, 0] = g
            try:
                sols = np.asarray(np.linalg.solve(mats, rhs)[:, :, 0], np.float64)
            except np.linalg.LinAlgError:
                pass  # some system is singular: _solve_many tells which
            else:
                solved = [sols[k_sys * j : k_sys * (j + 1)] for j in range(m)]
        if systems and not solved:
            pending = [(i, A + lams[i] * np.diag(diag), A, g) for i, A, g, diag in systems]
            solved = _solve_many(pending, with_gauss_newton=sigma_tol is not None)
        for (i, _A, g, _diag), sol in zip(systems, solved, strict=True):
            if sol is None:
                lams[i] *= 10.0
                if lams[i] <= 1e12:
                    still.append(i)  # retried next round with the same residuals
                continue
            if sigma_tol is not None and _within_sigma(
                float(g @ sol[1]), costs[i], len(rs[i]), len(g), sigma_tol
            ):
                successes[i] = True
                continue
            dx = np.asarray(-sol[0], np.float64)
            trial_ids.append(i)
            trial_xs.append(xs[i] + dx)
            trial_dxs.append(dx)
        evaluated = fun_and_jac_many(trial_ids, trial_xs) if trial_ids else []
        for i, x_new, dx, (r_new, J_new) in zip(
            trial_ids, trial_xs, trial_dxs, evaluated, strict=True
        ):
            nfevs[i] += 1
            root_new = np.sqrt(1.0 + r_new * r_new / c2)
            cost_new = float(0.5 * np.sum(2.0 * c2 * (root_new - 1.0)))
            if cost_new <= costs[i]:
                x = xs[i]
                step_small = float(np.abs(dx).max()) <= tol * (1e-3 + float(np.abs(x).max()))
                gain_small = costs[i] - cost_new <= tol * max(costs[i], 1e-300)
                xs[i], rs[i], costs[i], Js[i], roots[i] = x_new, r_new, cost_new, J_new, root_new
                lams[i] = max(lams[i] * 0.3, 1e-12)
                if step_small or gain_small:
                    successes[i] = True
                    continue
            else:
                lams[i] *= 10.0
                if lams[i] > 1e12:
                    successes[i] = True  # no descent direction left: at a (local) minimum
                    continue
            still.append(i)
        active = sorted(still)
    return [
        LeastSquaresResult(
            x=xs[i],
            cost=costs[i],
            fun=rs[i],
            jac=Js[i] * np.sqrt(1.0 / roots[i])[:, None],
            success=successes[i],
            nfev=nfevs[i],
        )
        for i in range(n)
    ]


def _solve_many(
    pending: list[tuple[int, FloatArray, FloatArray, FloatArray]], *, with_gauss_newton: bool
) -> list[FloatArray | None]:
    """For each ``(i, A_damped, A, g)``: ``A_damped⁻¹ g`` (and ``A⁻¹ g`` with
    ``with_gauss_newton``) stacked, or None where a matrix is singular; one batched solve
    when every system has the same size and none is singular."""
    if not pending:
        return []

    def one(A_damped: FloatArray, A: FloatArray, g: FloatArray) -> FloatArray | None:
        try:
            if not with_gauss_newton:
                return np.asarray(np.linalg.solve(A_damped, g)[None, :], np.float64)
            both = np.linalg.solve(np.stack([A_damped, A]), np.stack([g, g])[:, :, None])
            return np.asarray(both[:, :, 0], np.float64)
        except np.linalg.LinAlgError:
            return None

    if len({g.shape for _i, _Ad, _A, g in pending}) == 1:
        mats = [m for _i, Ad, A, _g in pending for m in ((Ad, A) if with_gauss_newton else (Ad,))]
        k = 2 if with_gauss_newton else 1
        rhs = [g for _i, _Ad, _A, g in pending for _ in range(k)]
        try:
            sols = np.asarray(
                np.linalg.solve(np.stack(mats), np.stack(rhs)[:, :, None])[:, :, 0], np.float64
            )
        except np.linalg.LinAlgError:
            pass  # some system is singular: one by one, to tell which
        else:
            return [sols[j * k : (j + 1) * k] for j in range(len(pending))]
    return [one(Ad, A, g) for _i, Ad, A, g in pending]


def _within_sigma(decrement: float, cost: float, m: int, n: int, sigma_tol: float) -> bool:
    """A Gauss-Newton step of Newton decrement ``gᵀ A⁻¹ g`` is under ``sigma_tol`` of the
    parameters' 1-sigma (``A⁻¹ s²``, ``s² = 2 cost / (m − n)``, at least 1e-12)."""
    s2 = max(2.0 * cost / max(m - n, 1), 1e-12)
    return bool(np.isfinite(decrement) and 0.0 <= decrement <= sigma_tol * sigma_tol * s2)


def gauss_newton(
    resid_jac: ResidualsAndJacobian,
    x0: npt.ArrayLike,
    *,
    max_iter: int = 8,
    sigma_tol: float | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Gauss-Newton from ``x0``; the solution and the Jacobian there.

    For nearly linear problems: each step solves the linearised problem by least squares
    and is taken only if the squared residual does not grow; stops on a step below 1e-10.

    Parameters
    ----------
    resid_jac
        Residuals ``(m,)`` and their Jacobian ``(m, n)`` at ``x``.
    x0
        The start.
    max_iter
        Most steps taken.
    sigma_tol
        For whitened residuals (unit variance): also stop after a step whose length in the
        parameters' own 1-sigma (``‖J dx‖``, the Newton decrement's root) is under
        ``sigma_tol``; the next step would be smaller still (Gauss-Newton converges at
        least linearly here), so ``x`` is within about ``sigma_tol`` sigma of the minimum.
        None (the default): the 1e-10 step rule alone.
    """
    x = np.asarray(x0, dtype=np.float64)
    r, J = resid_jac(x)
    for _ in range(max_iter):
        try:
            dx = -np.linalg.lstsq(J, r, rcond=None)[0]
        except np.linalg.LinAlgError:
            break
        x_new = x + dx
        r_new, J_new = resid_jac(x_new)
        if float(r_new @ r_new) > float(r @ r) * (1 + 1e-12):
            break
        small = sigma_tol is not None and float(np.linalg.norm(J @ dx)) < sigma_tol
        x, r, J = x_new, r_new, J_new
        if np.max(np.abs(dx)) < 1e-10 or small:
            break
    return x, J
