"""Stage 5, refinement: one least-squares fit of ``enu_from_world`` to all matched evidence."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from camloc_geo._optimize import gauss_newton
from camloc_geo.absolute._evidence import Evidence
from camloc_geo.absolute._model import Candidate, LocateSettings, Observation
from camloc_geo.absolute._scoring import (
    OUTLIER_M2,
    obs_precision,
    placement,
    street_angle_under_car,
)
from camloc_geo.absolute._similarity import Similarity2D
from camloc_geo.camera import Camera, undistort_points_px

if TYPE_CHECKING:
    from camloc_geo.relative import CalibrationResult

FloatArray = npt.NDArray[np.float64]
ResidualJacobian = Callable[[FloatArray], tuple[FloatArray, FloatArray]]

_SIGMA_TOL = 1e-3
"""The refinement stops after a Gauss-Newton step under this fraction of the fit's 1-sigma
(:func:`camloc_geo._optimize.gauss_newton`'s ``sigma_tol``; the residuals are whitened).
The steps shrink about 30-fold each (measured on ``benchmarks/locate_profile.py``), so the
answer moves by about 3e-5 sigma against the 1e-10 step rule, in 4 evaluations instead of
8-9."""


def _matched_points(cand: Candidate, ev: Evidence) -> list[tuple[Observation, FloatArray]]:
    """The candidate's inlier observations and their matched map points.

    Points beyond the likelihood's cap are outliers to this hypothesis (they add a
    constant): leave them out, or one wrong reference drags the fit back onto itself.
    """
    obs_q: list[tuple[Observation, FloatArray]] = list(ev.refs)
    by_label = {m.label: m for m in cand.matches}
    for o in ev.corners:
        if o.label in by_label:
            obs_q.append((o, np.asarray(by_label[o.label].map_en)))
    for o, _pts in ev.landmarks:
        if o.label in by_label:
            obs_q.append((o, np.asarray(by_label[o.label].map_en)))
    inliers = [
        (o, q)
        for o, q in obs_q
        if (by_label[o.label].mahalanobis2 if o.label in by_label else 0.0) <= OUTLIER_M2
    ]
    return inliers if len(inliers) >= 2 else obs_q


def _street_bearing_prior(cand: Candidate, ev: Evidence, settings: LocateSettings) -> float | None:
    """The bearing of the street under the car, when the car (nearly) lies along it.

    The street prior only pulls a candidate that already (nearly) meets it: one whose car
    is flagged off the street or across it is the evidence's, not the prior's, to move.
    """
    if ev.street_tree is None:
        return None
    diff0 = street_angle_under_car(cand.enu_from_world, ev)
    if diff0 is not None and abs(diff0) <= 2.5 * settings.bearing_sigma_deg:
        return ((90.0 - math.degrees(cand.theta_rad)) - diff0) % 180.0
    return None


_LOG_SCALE_MAX = 5.0
"""The log scale :func:`_residuals` evaluates at most (a scale of 148: 100 scale sigmas)."""


def _residuals(
    obs_q: list[tuple[Observation, FloatArray]],
    start: Similarity2D,
    settings: LocateSettings,
    street_brg: float | None,
    ev: Evidence | None = None,
) -> ResidualJacobian:
    """Whitened residuals and Jacobian in x = (θ, tx, ty, ln s).

    ``ev``: the evidence the observations come from, whose memo of the start
    (:func:`~camloc_geo.absolute._scoring.placement`) has their precisions there.
    """
    # Whitening at the starting similarity (the rotation and scale change little here).
    if ev is None:
        R20 = start.rotation
        precisions = [obs_precision(o, R20, start.scale) for o, _q in obs_q]
    else:
        here = placement(ev, start)
        precisions = [here.carried(o)[1] for o, _q in obs_q]
    L = np.linalg.cholesky(np.stack(precisions))  # each matrix's own factor
    P = np.array([o.world_xy for o, _q in obs_q], dtype=np.float64)
    Q = np.array([q for _o, q in obs_q], dtype=np.float64)
    s_sigma = max(settings.scale_sigma_rel, 1e-6)

    n = len(obs_q)
    m = 2 * n + 1 + (street_brg is not None)
    # The residual of point k is L_kᵀ (s R(θ) p_k + t − q_k), with R(θ) p = cos θ p + sin θ p⊥
    # (p⊥ = p turned by 90°): whitened once, every term is a fixed vector times a scalar of
    # x, flattened (u, v per point) like the residuals.
    P_perp = np.stack([-P[:, 1], P[:, 0]], axis=1)
    U = np.einsum("nji,nj->ni", L, P).ravel()  # L_kᵀ p_k
    V = np.einsum("nji,nj->ni", L, P_perp).ravel()  # L_kᵀ p⊥_k
    W = np.einsum("nji,nj->ni", L, Q).ravel()  # L_kᵀ q_k
    T_east, T_north = L[:, 0, :].ravel(), L[:, 1, :].ravel()  # L_kᵀ e_x, L_kᵀ e_y
    J_const = np.zeros((m, 4))
    J_const[: 2 * n, 1] = T_east  # the translation's columns do not change
    J_const[: 2 * n, 2] = T_north
    J_const[2 * n] = [0.0, 0.0, 0.0, 1.0 / s_sigma]
    if street_brg is not None:
        J_const[2 * n + 1] = [-math.degrees(1.0) / settings.bearing_sigma_deg, 0, 0, 0]

    def resid_jac(x: FloatArray) -> tuple[FloatArray, FloatArray]:
        theta, tx, ty, ls = (float(v) for v in x)
        # A wild step (one matched point, a far start) may ask for any scale: exp() of it
        # overflowed. Clamped, the scale prior's residual (ls / s_sigma, unclamped) makes
        # the step costlier than the start, and Gauss-Newton refuses it.
        s = math.exp(min(max(ls, -_LOG_SCALE_MAX), _LOG_SCALE_MAX))
        a, b = s * math.cos(theta), s * math.sin(theta)
        turned = a * U + b * V  # L_kᵀ s R(θ) p_k: also the log scale's column
        r = np.empty(m)
        r[: 2 * n] = turned + tx * T_east + ty * T_north - W
        r[2 * n] = ls / s_sigma
        J = J_const.copy()
        J[: 2 * n, 0] = a * V - b * U  # ∂/∂θ
        J[: 2 * n, 3] = turned
        if street_brg is not None:
            # The car is parallel to the street it stands on, within bearing_sigma_deg (the
            # street found under the car at the start; the refinement moves it little).
            car_brg = (90.0 - math.degrees(theta)) % 180.0
            diff = (car_brg - street_brg + 90.0) % 180.0 - 90.0
            r[2 * n + 1] = diff / settings.bearing_sigma_deg
        return r, J

    return resid_jac


def _position_sigma_m(
    J: FloatArray, enu_from_world: Similarity2D, world_cam: Camera
) -> float | None:
    """1-sigma position uncertainty of the camera, propagated from the fit's covariance."""
    return _propagated_sigma(
        J.T @ J, _position_jacobian(enu_from_world, world_cam.center_in_world[:2])
    )


def _similarity_problem(
    cand: Candidate, ev: Evidence, settings: LocateSettings
) -> tuple[ResidualJacobian, FloatArray] | None:
    """The least-squares problem of ``enu_from_world`` for a candidate's matched evidence
    (residuals and Jacobian in ``(θ, tx, ty, ln s)``) and its start, None with no match."""
    obs_q = _matched_points(cand, ev)
    if not obs_q:
        return None
    street_brg = _street_bearing_prior(cand, ev, settings)
    resid_jac = _residuals(obs_q, cand.enu_from_world, settings, street_brg, ev)
    x0 = np.array([cand.theta_rad, *cand.translation_en, math.log(cand.scale)])
    return resid_jac, x0


def position_sigma_m(
    cand: Candidate, world_cam: Camera, ev: Evidence, settings: LocateSettings
) -> float | None:
    """1-sigma position uncertainty of a candidate as it stands (no refinement): the
    covariance of the least-squares fit of ``enu_from_world`` to its matched evidence,
    linearised at the candidate's own similarity."""
    return position_sigmas_m([cand], world_cam, [ev], settings)[0]


def _normal_matrix_at_start(
    cand: Candidate, ev: Evidence, settings: LocateSettings
) -> FloatArray | None:
    """``JᵀJ`` of the refinement's problem at the candidate's own similarity, None with no
    match: ``Σ_k D_kᵀ Λ_k D_k`` over the matched points (``D_k`` the point's ENU position's
    Jacobian in (θ, tx, ty, ln s), ``Λ_k`` its precision) plus the scale prior's and the
    bearing prior's rows; the refinement's whitened ``J`` gives the same matrix up to
    rounding (``Λ = L Lᵀ``), without its Cholesky factors and closure."""
    parts = _normal_parts(cand, ev, settings)
    return None if parts is None else parts[3]


def _normal_parts(
    cand: Candidate, ev: Evidence, settings: LocateSettings
) -> tuple[list[tuple[Observation, FloatArray]], FloatArray, FloatArray, FloatArray] | None:
    """The parts of :func:`_normal_matrix_at_start`: the matched points, their Jacobians
    ``D`` ``(n, 2, 4)``, precisions ``(n, 2, 2)`` and ``JᵀJ`` ``(4, 4)``; None with no match."""
    obs_q = _matched_points(cand, ev)
    if not obs_q:
        return None
    street_brg = _street_bearing_prior(cand, ev, settings)
    sim = cand.enu_from_world
    here = placement(ev, sim)
    prec = np.stack([here.carried(o)[1] for o, _q in obs_q])  # (n, 2, 2)
    P = np.array([o.world_xy for o, _q in obs_q], dtype=np.float64)
    s, theta = float(sim.scale), float(sim.rotation_rad)
    a, b = s * math.cos(theta), s * math.sin(theta)
    px, py = P[:, 0], P[:, 1]
    D = np.zeros((len(obs_q), 2, 4))
    D[:, 0, 0] = -b * px - a * py  # ∂/∂θ of s R(θ) p: s (−sin p + cos p⊥)
    D[:, 1, 0] = a * px - b * py
    D[:, 0, 1] = 1.0  # ∂/∂tx, ∂/∂ty
    D[:, 1, 2] = 1.0
    D[:, 0, 3] = a * px - b * py  # ∂/∂ln s: s R(θ) p
    D[:, 1, 3] = b * px + a * py
    JtJ = np.einsum("nia,nij,njb->ab", D, prec, D)
    JtJ[3, 3] += (1.0 / max(settings.scale_sigma_rel, 1e-6)) ** 2
    if street_brg is not None:
        JtJ[0, 0] += (math.degrees(1.0) / settings.bearing_sigma_deg) ** 2
    return obs_q, D, prec, np.asarray(JtJ, dtype=np.float64)


def position_sigmas_m(
    cands: Sequence[Candidate],
    world_cam: Camera,
    evs: Sequence[Evidence],
    settings: LocateSettings,
) -> list[float | None]:
    """:func:`position_sigma_m` of several candidates (each on its evidence): the
    covariances' pseudo-inverses and their propagation in one batched call each (LAPACK
    and the matrix products per matrix: the same bits as one at a time)."""
    out: list[float | None] = [None] * len(cands)
    rows: list[tuple[int, FloatArray, FloatArray]] = []  # (index, JᵀJ, Jp)
    Cw = world_cam.center_in_world[:2]
    for k, (cand, ev) in enumerate(zip(cands, evs, strict=True)):
        JtJ = _normal_matrix_at_start(cand, ev, settings)
        if JtJ is not None:
            rows.append((k, JtJ, _position_jacobian(cand.enu_from_world, Cw)))
    for (k, _JtJ, _Jp), sigma in zip(rows, _propagated_sigmas(rows), strict=True):
        out[k] = sigma
    return out


def _propagated_sigmas(rows: list[tuple[int, FloatArray, FloatArray]]) -> list[float | None]:
    """:func:`_propagated_sigma` of each ``(index, JᵀJ, Jp)``: the pseudo-inverses and the
    propagation in one batched call each (LAPACK and the products per matrix: the same bits
    as one at a time); one at a time when the batch fails, a failing one None."""
    if not rows:
        return []
    try:
        cov = np.linalg.pinv(np.stack([JtJ for _k, JtJ, _Jp in rows]))
    except np.linalg.LinAlgError:
        return [_propagated_sigma(JtJ, Jp) for _k, JtJ, Jp in rows]
    Jp = np.stack([Jp for _k, _JtJ, Jp in rows])
    cov_p = Jp @ cov @ Jp.transpose(0, 2, 1)
    return [float(math.sqrt(max(tr, 0.0))) for tr in (cov_p[:, 0, 0] + cov_p[:, 1, 1]).tolist()]


def _position_jacobian(enu_from_world: Similarity2D, Cw: FloatArray) -> FloatArray:
    """Jacobian ``(2, 4)`` of the camera's ENU position w.r.t. (θ, tx, ty, ln s), with
    ``Cw`` the camera centre's (x, y) in the world frame."""
    theta, s = float(enu_from_world.rotation_rad), float(enu_from_world.scale)
    c, sn = math.cos(theta), math.sin(theta)
    cx, cy = float(Cw[0]), float(Cw[1])
    # s dR(θ) C and s R(θ) C, with dR = ∂R/∂θ, on floats
    return np.array(
        [
            [(s * -sn) * cx + (s * -c) * cy, 1.0, 0.0, (s * c) * cx + (s * -sn) * cy],
            [(s * c) * cx + (s * -sn) * cy, 0.0, 1.0, (s * sn) * cx + (s * c) * cy],
        ]
    )


def _propagated_sigma(JtJ: FloatArray, Jp: FloatArray) -> float | None:
    """The position sigma from the normal matrix and the position's Jacobian."""
    try:
        cov = np.linalg.pinv(JtJ)
    except np.linalg.LinAlgError:
        return None
    cov_p = Jp @ cov @ Jp.T
    return float(math.sqrt(max(np.trace(cov_p), 0.0)))


def refine(cand: Candidate, world_cam: Camera, ev: Evidence, settings: LocateSettings) -> Candidate:
    """Refine ``enu_from_world`` and so the camera's position against all matched evidence.

    The world-frame pose of the camera is kept from the relative fit (its own uncertainty
    enters through the observation covariances); the car-to-map similarity is fitted by
    least squares on the Mahalanobis residuals of every matched point plus the scale prior,
    and its covariance is propagated to the camera position.
    """
    return refine_many([cand], world_cam, [ev], settings)[0]


def refine_many(
    cands: Sequence[Candidate],
    world_cam: Camera,
    evs: Sequence[Evidence],
    settings: LocateSettings,
) -> list[Candidate]:
    """:func:`refine` of several candidates (each on its evidence): each its own fit, their
    position sigmas in one batch (:func:`_propagated_sigmas`, the same bits)."""
    out = list(cands)
    fitted: list[tuple[int, Similarity2D]] = []
    rows: list[tuple[int, FloatArray, FloatArray]] = []  # (index, JᵀJ, Jp)
    Cw = world_cam.center_in_world[:2]
    for k, (cand, ev) in enumerate(zip(cands, evs, strict=True)):
        problem = _similarity_problem(cand, ev, settings)
        if problem is None:
            continue
        resid_jac, x0 = problem
        x, J = gauss_newton(resid_jac, x0, sigma_tol=_SIGMA_TOL)
        if not np.all(np.isfinite(x)) or abs(float(x[3])) > _LOG_SCALE_MAX:
            continue  # the fit ran away (a reference thousands of km off): kept unrefined
        theta, tx, ty, ls = x
        sim = Similarity2D(float(theta), np.array([tx, ty]), math.exp(ls))
        fitted.append((k, sim))
        rows.append((k, J.T @ J, _position_jacobian(sim, Cw)))
    for (k, sim), sigma in zip(fitted, _propagated_sigmas(rows), strict=True):
        out[k] = replace(
            cands[k],
            enu_from_world=sim,
            camera=sim.camera(world_cam),
            sigma_m=sigma,
            refined=True,
        )
    return out


CALIBRATION_PARAMETERS = (0, 1, 2, 3, 4, 5, 8)
"""The rows of ``CalibrationResult.parameter_covariance`` that move a placement: focal length,
principal point x, y, the rotation about the camera's three axes and the centre's height.
The centre's x and y carry the camera and every ground point it casts together, so the
similarity to the map absorbs them."""


def calibration_covariance(cal: CalibrationResult) -> FloatArray | None:
    """The calibration's covariance ``(7, 7)`` over :data:`CALIBRATION_PARAMETERS`, each
    marginal widened to the stated sigma where that is larger, None when it states none.

    ``parameter_covariance`` is the fit's alone (before the annotators' jackknife); the stated
    ``focal_sigma_px``, ``rotation_sigma_deg`` and ``position_sigma_m`` include the jackknife.
    Each row and column is scaled by ``max(1, stated / fitted)``: the marginals become the
    stated sigmas and the fit's correlations are kept. Without a joint covariance, the stated
    sigmas alone (uncorrelated).
    """
    stated = np.zeros(7)
    if cal.focal_sigma_px is not None:
        stated[0] = float(cal.focal_sigma_px)
    if cal.principal_point_sigma_px is not None:
        stated[1:3] = np.asarray(cal.principal_point_sigma_px, dtype=float)[:2]
    if cal.rotation_sigma_deg is not None:
        stated[3:6] = np.radians(np.asarray(cal.rotation_sigma_deg, dtype=float)[:3])
    if cal.position_sigma_m is not None:
        stated[6] = float(np.asarray(cal.position_sigma_m, dtype=float)[2])
    stated = np.where(np.isfinite(stated), stated, 0.0)
    cov_full = cal.parameter_covariance
    if cov_full is None or np.shape(cov_full) != (9, 9) or not np.all(np.isfinite(cov_full)):
        cov = np.diag(stated**2)
    else:
        idx = np.array(CALIBRATION_PARAMETERS)
        cov = np.asarray(cov_full, dtype=float)[np.ix_(idx, idx)]
        fitted = np.sqrt(np.clip(np.diag(cov), 0.0, None))
        widen = np.where(fitted > 0.0, np.maximum(1.0, stated / np.where(fitted > 0, fitted, 1)), 0)
        cov = widen[:, None] * cov * widen[None, :]
        # a stated sigma where the fit has none (a held parameter): uncorrelated
        held = fitted <= 0.0
        cov[held, held] = stated[held] ** 2
    if not np.any(cov):
        return None
    return np.asarray(0.5 * (cov + cov.T), dtype=np.float64)


def _rotations(rotvecs: FloatArray) -> FloatArray:
    """Rotation matrices ``(m, 3, 3)`` of rotation vectors ``(m, 3)`` (radians), Rodrigues'
    formula at once (:func:`camloc_geo.camera.rotation_from_rotvec` of each)."""
    theta = np.linalg.norm(rotvecs, axis=1)
    safe = np.where(theta > 1e-12, theta, 1.0)
    k = rotvecs / safe[:, None]
    K = np.zeros((len(rotvecs), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = k[:, 2], -k[:, 1], k[:, 0]
    sin = np.where(theta > 1e-12, np.sin(theta), 0.0)[:, None, None]
    cos1 = np.where(theta > 1e-12, 1.0 - np.cos(theta), 0.0)[:, None, None]
    return np.asarray(np.eye(3)[None] + sin * K + cos1 * (K @ K), dtype=np.float64)


def _calibration_sigma_points(
    cam: Camera, cov: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The calibration's sigma points: the camera moved by ``±`` each column of a square root
    of ``cov`` (:data:`CALIBRATION_PARAMETERS`), those with a positive focal length and
    height kept, as arrays: focal lengths ``(m,)``, principal points ``(m, 2)``,
    ``cam_from_world`` rotations ``(m, 3, 3)`` and centres ``(m, 3)``."""
    lam, vec = np.linalg.eigh(cov)
    steps = [math.sqrt(float(lam[k])) * vec[:, k] for k in range(len(lam)) if lam[k] > 0.0]
    deltas = np.array([sign * d for d in steps for sign in (1.0, -1.0)]).reshape(-1, 7)
    return _moved_cameras(cam, deltas)


def _moved_cameras(
    cam: Camera, deltas: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The camera moved by each row of ``deltas`` ``(m, 7)`` (:data:`CALIBRATION_PARAMETERS`),
    those with a positive focal length and height kept, as the arrays of
    :func:`_calibration_sigma_points`."""
    f = float(cam.focal_px) + deltas[:, 0]
    C = np.asarray(cam.center_in_world, dtype=float)[None, :] + np.outer(deltas[:, 6], [0, 0, 1])
    ok = (f > 0.0) & (C[:, 2] > 0.0)
    R0 = np.asarray(cam.cam_from_world_rotation, dtype=float)
    R = _rotations(deltas[ok, 3:6]) @ R0
    pp = np.asarray(cam.principal_point, dtype=float)[None, :] + deltas[ok, 1:3]
    return f[ok], pp, R, C[ok]


def _cast(
    pixels: FloatArray, f: FloatArray, pp: FloatArray, R: FloatArray, C: FloatArray
) -> FloatArray:
    """Pinhole pixels ``(n, 2)`` cast onto the ground ``z = 0`` through ``m`` cameras at once
    (the arrays of :func:`_calibration_sigma_points`): ``(m, n, 2)``, NaN where a ray does
    not reach the ground in front of its camera."""
    d = np.empty((len(f), len(pixels), 3))
    d[:, :, :2] = (pixels[None, :, :] - pp[:, None, :]) / f[:, None, None]
    d[:, :, 2] = 1.0
    rays = np.einsum("mji,mnj->mni", R, d)  # Rᵀ of each camera on each direction
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -C[:, None, 2] / rays[:, :, 2]
    t = np.where(t > 0.0, t, np.nan)
    return np.asarray(C[:, None, :2] + t[:, :, None] * rays[:, :, :2], dtype=np.float64)


def calibration_sigmas_m(
    cands: Sequence[Candidate],
    cal: CalibrationResult,
    evs: Sequence[Evidence],
    settings: LocateSettings,
) -> list[float | None]:
    """How far each candidate's camera moves with the calibration (1-sigma, metres).

    The refinement fits ``enu_from_world`` with the calibrated camera held: its sigma
    (:func:`refine`) carries the clicks' and the map's noise, not the calibration's. With
    two references the camera is fixed by the two pixels and the calibration's rays, so a
    focal length 30 % off moves it by tens of metres while the fit stays exact. Here the
    calibration's covariance (:func:`calibration_covariance`) is carried through the same
    fit by its sigma points (the unscented transform without a centre term: each of the
    seven directions ``±`` one square-root column): the matched pixels are cast again through
    each moved camera (exactly: the casting is where a focal length far off bends the
    answer), and the similarity's least-squares fit, linearised at the candidate's (its
    normal matrix, :func:`_normal_matrix_at_start`), moves with the cast points. A lens
    distortion is undone at the calibrated principal point for every sigma point. A sigma
    point that casts a matched pixel above the horizon counts as the farthest of the
    others, doubled.

    Returns the 1-sigma (root of the trace of the position covariance) per candidate, None
    where it cannot be computed (no match, no calibration covariance).
    """
    out: list[float | None] = [None] * len(cands)
    cov = calibration_covariance(cal)
    if cov is None:
        return out
    cam0 = cal.camera
    f, pp, R, C = _calibration_sigma_points(cam0, cov)
    if not len(f):
        return out
    for k, (cand, ev) in enumerate(zip(cands, evs, strict=True)):
        d2 = _squared_moves(cand, ev, settings, cam0, (f, pp, R, C))
        if d2 is None:
            continue
        lost = ~np.isfinite(d2)
        far = 4.0 * float(np.max(d2[~lost])) if np.any(~lost) else 0.0
        out[k] = math.sqrt(0.5 * float(np.sum(np.where(lost, far, d2))))
    return out


def _squared_moves(
    cand: Candidate,
    ev: Evidence,
    settings: LocateSettings,
    cam0: Camera,
    moved_cams: tuple[FloatArray, FloatArray, FloatArray, FloatArray],
) -> FloatArray | None:
    """How far (squared, metres²) the candidate's camera moves on the map with each moved
    camera (the arrays of :func:`_moved_cameras`): the matched pixels cast again through it
    exactly, the similarity's fit linearised at the candidate. ``inf`` where a moved camera
    casts a matched pixel above its horizon; None where nothing can be computed."""
    parts = _normal_parts(cand, ev, settings)
    if parts is None:
        return None
    obs_q, D, prec, JtJ = parts
    pixels = np.array([o.pixel for o, _q in obs_q], dtype=float)
    if cam0.distortion is not None:
        pixels = undistort_points_px(pixels, cam0.distortion, cam0.principal_point)
    R0 = np.asarray(cam0.cam_from_world_rotation, dtype=float)
    base = (
        np.array([float(cam0.focal_px)]),
        np.asarray(cam0.principal_point, dtype=float)[None, :],
        R0[None, :, :],
        np.asarray(cam0.center_in_world, dtype=float)[None, :],
    )
    g0 = _cast(pixels, *base)[0]
    if not np.all(np.isfinite(g0)):
        return None
    moved = _cast(pixels, *moved_cams) - g0[None]  # (m, n, 2) in the world frame
    sim = cand.enu_from_world
    A = sim.scale * sim.rotation  # a world displacement in ENU
    de = np.einsum("ij,mnj->mni", A, np.nan_to_num(moved))
    # the fit's step that absorbs them: JᵀJ Δx = -Σ D_kᵀ Λ_k δe_k
    grad = np.einsum("nia,nij,mnj->ma", D, prec, de)
    try:
        dx = -np.linalg.solve(JtJ, grad.T).T
    except np.linalg.LinAlgError:
        dx = -(np.linalg.pinv(JtJ) @ grad.T).T
    Jp = _position_jacobian(sim, cam0.center_in_world[:2])
    dpos = dx @ Jp.T  # (m, 2); the centre's own height moves no horizontal position
    d2 = np.einsum("mi,mi->m", dpos, dpos)
    lost = ~np.all(np.isfinite(moved), axis=(1, 2)) | ~np.isfinite(d2)
    return np.asarray(np.where(lost, np.inf, d2), dtype=np.float64)


def focal_moves_m(
    cand: Candidate,
    cal: CalibrationResult,
    ev: Evidence,
    settings: LocateSettings,
    k_sigma: float = 2.0,
) -> tuple[float, float] | None:
    """How far the candidate's camera moves on the map when the calibration's focal length
    is ``k_sigma`` sigmas shorter and longer (metres; ``inf`` where a matched pixel would
    cast above the horizon), the other parameters moved with it along the covariance's
    regression on the focal length (:func:`calibration_covariance`), the matched pixels cast
    exactly (the camera moves faster than linearly with a focal length far off: the
    1-sigma of :func:`calibration_sigmas_m` understates a 2-sigma focal length's move).

    None where it cannot be computed (no focal sigma, no match).
    """
    cov = calibration_covariance(cal)
    if cov is None or cov[0, 0] <= 0.0:
        return None
    step = k_sigma * cov[:, 0] / math.sqrt(float(cov[0, 0]))
    cam0 = cal.camera
    out = []
    for delta in (-step, step):
        moved = _moved_cameras(cam0, delta[None, :])
        if not len(moved[0]):  # a focal length or height at or below zero: no camera
            out.append(math.inf)
            continue
        d2 = _squared_moves(cand, ev, settings, cam0, moved)
        if d2 is None:
            return None
        out.append(math.sqrt(float(d2[0])))
    return (out[0], out[1])
