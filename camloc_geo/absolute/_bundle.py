"""Stage 7, bundle adjustment: the camera re-fitted with the annotations and the map together.

The relative pose (:func:`camloc_geo.relative.calibrate`) is fitted to the annotations
alone, and :func:`~camloc_geo.absolute._refine.refine` then fits only the car-to-map
similarity ``enu_from_world``, keeping that pose. When the vanishing lines determine the
focal length poorly (a vanishing point near infinity), a focal length off by 20-50 %
distorts every ground point, and no similarity can undo it.

Here, for each leading candidate, one robust least-squares problem holds

- every annotator's vanishing-line and car-corner residuals of the joint fit (with the
  annotators' final robust weights), and
- every map point the candidate matched (references, kerb corners, landmarks) as a pixel
  residual: the map point, carried into the car's world frame by ``enu_from_world``'s
  inverse, projected with the camera, against the clicked pixel; its sigma is the click
  noise and the map's uncertainty seen at the point's depth,
- the scale prior of ``enu_from_world`` and, when the car stands along a street, the
  street-bearing prior of the refinement,

over the focal length (unless given), the camera's rotation and centre, and the
similarity: a soft-L1 Levenberg-Marquardt fit (the joint fit's own optimiser,
:func:`camloc_geo._optimize.soft_l1_least_squares`, which keeps ``scipy.optimize``'s
import out of ``locate``). The candidate
keeps its rank and score (those compare hypotheses on the same evidence); its camera,
position and ``sigma_m`` become the bundle's. A bundle that does not converge, or moves the
annotations' fit by more than a chi-square jump of :data:`MAX_ANNOTATION_COST_RISE` while
explaining the map no better, is dropped and the candidate kept as it was.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from camloc_geo._optimize import (
    LeastSquaresResult,
    soft_l1_cost,
    soft_l1_least_squares_many_small,
)
from camloc_geo.absolute._evidence import Evidence
from camloc_geo.absolute._model import Candidate, LocateSettings, Observation
from camloc_geo.absolute._refine import _matched_points, _street_bearing_prior
from camloc_geo.absolute._similarity import Similarity2D
from camloc_geo.camera import Camera
from camloc_geo.relative import _ROTVEC_SCALAR_MAX

if TYPE_CHECKING:
    from camloc_geo.relative import CalibrationResult, JointState

__all__ = [
    "MAX_ANNOTATION_COST_RISE",
    "MIN_MATCHED_POINTS",
    "bundle_adjust",
    "bundle_adjust_many",
]

FloatArray = npt.NDArray[np.float64]

MAX_ANNOTATION_COST_RISE = 30.0
"""Largest rise of the annotations' chi-square the map may force (in squared sigmas)."""

MIN_MATCHED_POINTS = 3
"""Fewer matched map points add no redundancy beyond the similarity's four parameters: two
points fit any camera exactly, and the bundle would only wander along the flat valley of
the similarity's rotation (measured: it moved two-corner candidates by up to 8 m)."""

_F_SCALE = 2.5

_SIGMA_TOL = 0.03
"""The bundle stops once its next Gauss-Newton step is under this fraction of the fit's own
1-sigma (``soft_l1_least_squares``'s ``sigma_tol``). Measured on ``benchmarks/absolute.py
--n 40`` against the fully converged bundle: the top candidates move by at most 6 cm (0.012
sigma), every hit rate and rank is the same and the medians within 5 mm; 0.1 saved another
0.5 ms but moved medians by up to 6 cm."""


def _cam_parts(
    state: JointState, x_cam: FloatArray
) -> tuple[float, tuple[float, float], FloatArray, FloatArray]:
    """Focal length, principal point, rotation and centre in the calibration's output frame."""
    f, pp, R, C = state.problem.unpack(
        x_cam, state.rotation0, state.principal_point, state.focal_px
    )
    M, origin = state.internal_from_output, state.internal_origin
    return f, pp, R @ M, M.T @ (C - origin)


def bundle_adjust(
    cand: Candidate,
    calibration: CalibrationResult,
    ev: Evidence,
    settings: LocateSettings,
    image_size: tuple[int, int],
) -> Candidate:
    """The candidate with its camera re-fitted to the annotations and its matched map points.

    Parameters
    ----------
    cand
        A scored (and refined) candidate; its matches say which map point each pixel is.
    calibration
        The relative pose; without its joint fit's state (``joint_state``) nothing changes.
    ev
        The evidence the candidate was scored on.
    settings
        The noise model (click noise, scale prior, bearing prior).
    image_size
        ``(width, height)``, pixels.

    Returns
    -------
    Candidate
        A copy with ``camera``, ``enu_from_world`` and ``sigma_m`` from the bundle, or
        ``cand`` itself when there is no joint state, fewer than :data:`MIN_MATCHED_POINTS`
        matched map points, or the bundle is not trustworthy.
    """
    return bundle_adjust_many([cand], calibration, [ev], settings, image_size)[0]


def bundle_adjust_many(
    cands: list[Candidate],
    calibration: CalibrationResult,
    evs: list[Evidence],
    settings: LocateSettings,
    image_size: tuple[int, int],
) -> list[Candidate]:
    """:func:`bundle_adjust` of several candidates (each with its evidence), fitted together.

    Each candidate's fit is its own (the same steps and answer as alone,
    :func:`camloc_geo._optimize.soft_l1_least_squares_many`); their residuals and
    finite-difference Jacobians are evaluated in one batch per step, which costs about what
    one candidate's did.
    """
    out = list(cands)
    state = calibration.joint_state
    if state is None:
        return out
    problems: list[_Problem] = []
    for i, (cand, ev) in enumerate(zip(cands, evs, strict=True)):
        obs_q = _matched_points(cand, ev)
        if len(obs_q) >= MIN_MATCHED_POINTS:
            problems.append(_Problem.of(i, cand, ev, obs_q, settings, state))
    if not problems:
        return out
    prob = state.problem
    saved_weights = prob.weights
    prob.weights = state.weights
    try:
        try:
            fitted = _bundle_many(problems, state, settings, image_size)
        except (ValueError, np.linalg.LinAlgError, FloatingPointError):
            fitted = []
            for p in problems:  # one at a time: a failing candidate keeps its place
                try:
                    fitted += _bundle_many([p], state, settings, image_size)
                except (ValueError, np.linalg.LinAlgError, FloatingPointError):
                    fitted.append(p.cand)
    finally:
        prob.weights = saved_weights
    for p, c in zip(problems, fitted, strict=True):
        out[p.index] = c
    return out


@dataclass(frozen=True)
class _Problem:
    """One candidate's bundle: its matched pixels and map points, priors and start."""

    index: int
    cand: Candidate
    pixels: FloatArray  # (n, 2)
    q_en: FloatArray  # (n, 2) matched map points, local east/north
    sigma_map: FloatArray  # (n,)
    street_brg: float | None
    z0: FloatArray

    @classmethod
    def of(
        cls,
        index: int,
        cand: Candidate,
        ev: Evidence,
        obs_q: list[tuple[Observation, FloatArray]],
        settings: LocateSettings,
        state: JointState,
    ) -> _Problem:
        # The similarity is expressed from the calibration's output frame; the start is the
        # candidate's (refined) one.
        sim0 = cand.enu_from_world
        return cls(
            index=index,
            cand=cand,
            pixels=np.array([o.pixel for o, _q in obs_q], dtype=float),
            q_en=np.array([q for _o, q in obs_q], dtype=float),
            sigma_map=np.array([o.sigma_map_m for o, _q in obs_q], dtype=float),
            street_brg=_street_bearing_prior(cand, ev, settings),
            z0=np.concatenate(
                [
                    state.x,
                    [sim0.rotation_rad, *np.asarray(sim0.translation_m), math.log(sim0.scale)],
                ]
            ),
        )

    @property
    def n_map_rows(self) -> int:
        """Pixel rows (u, then v, per point), the scale prior, the bearing prior if any."""
        return 2 * len(self.pixels) + 1 + (self.street_brg is not None)


def _bundle_many(
    problems: list[_Problem],
    state: JointState,
    settings: LocateSettings,
    image_size: tuple[int, int],
) -> list[Candidate]:
    prob = state.problem
    sigma_click = settings.sigma_pixel_rel * math.hypot(*image_size)
    s_sigma = max(settings.scale_sigma_rel, 1e-6)
    n_cam = len(state.x)
    M, origin = state.internal_from_output, state.internal_origin
    # The problems' map points padded to one length, so that all rows go in one batch.
    n_max = max(len(p.pixels) for p in problems)
    Q = np.zeros((len(problems), n_max, 2))
    PX = np.zeros((len(problems), n_max, 2))
    SM = np.zeros((len(problems), n_max))
    BRG = np.zeros(len(problems))  # no bearing prior: a column left out (columns())
    for k, p in enumerate(problems):
        n = len(p.pixels)
        Q[k, :n], PX[k, :n], SM[k, :n] = p.q_en, p.pixels, p.sigma_map
        if p.street_brg is not None:
            BRG[k] = p.street_brg

    def map_rows(
        Z: FloatArray,
        owner: npt.NDArray[np.int64],
        cam: tuple[FloatArray, FloatArray, FloatArray, FloatArray],
    ) -> FloatArray:
        """The map rows of parameter vectors ``Z`` ``(P, n)``, row ``p`` of problem
        ``owner[p]``: each matched map point's pixel residual over its sigma (u, padded to
        ``n_max``, then v), the scale prior, then the street-bearing prior (a column left
        unused by a problem without one). ``cam``: ``Z``'s camera parts unpacked
        (``_unpack_batch``)."""
        f, pp, R, C = cam
        theta, tx, ty, ls = Z[:, n_cam], Z[:, n_cam + 1], Z[:, n_cam + 2], Z[:, n_cam + 3]
        q_en, pixels, sigma_map = Q[owner], PX[owner], SM[owner]
        s = np.exp(ls)
        cos_t, sin_t = np.cos(theta), np.sin(theta)
        dx = q_en[:, :, 0] - tx[:, None]  # (P, n)
        dy = q_en[:, :, 1] - ty[:, None]
        # rot2(θ)ᵀ applied to each row, over the scale
        px = (dx * cos_t[:, None] + dy * sin_t[:, None]) / s[:, None]
        py = (-dx * sin_t[:, None] + dy * cos_t[:, None]) / s[:, None]
        p_out = np.stack([px, py, np.zeros_like(px)], axis=2)  # (P, n, 3)
        p_int = p_out @ M.T + origin
        pc = np.einsum("pij,pnj->pni", R, p_int - C[:, None, :])
        depth = np.maximum(pc[:, :, 2], 0.05)
        fc = f[:, None]
        u = pc[:, :, 0] / depth * fc + pp[:, 0:1]
        v = pc[:, :, 1] / depth * fc + pp[:, 1:2]
        sig = np.sqrt(sigma_click**2 + (fc * sigma_map / depth) ** 2)
        car_brg = (90.0 - np.degrees(theta)) % 180.0
        diff = (car_brg - BRG[owner] + 90.0) % 180.0 - 90.0
        parts = [
            (u - pixels[:, :, 0]) / sig,
            (v - pixels[:, :, 1]) / sig,
            (ls / s_sigma)[:, None],
            (diff / settings.bearing_sigma_deg)[:, None],
        ]
        return np.concatenate(parts, axis=1)

    def columns(p: _Problem) -> npt.NDArray[np.int64]:
        n = len(p.pixels)
        cols = [*range(n), *range(n_max, n_max + n), 2 * n_max]
        if p.street_brg is not None:
            cols.append(2 * n_max + 1)
        return np.asarray(cols, dtype=np.int64)

    cols = [columns(p) for p in problems]
    n_z = n_cam + 4

    def fun_and_jac_many(
        ids: list[int], zs: list[FloatArray]
    ) -> list[tuple[FloatArray, FloatArray]]:
        # The annotations depend on the camera only: their rows and forward-difference
        # Jacobian as the joint fit's own (steps of 1e-7 relative), every problem in one
        # batch; the map rows likewise (steps of 1e-6), one batch whose first row per problem
        # is the residual itself.
        zs_all = np.stack(zs)  # (k, n_z)
        H_ann = 1e-7 * np.maximum(1.0, np.abs(zs_all[:, :n_cam]))
        h_ann = list(H_ann)
        X = _forward_rows(zs_all[:, :n_cam], H_ann)
        H_map = 1e-6 * np.maximum(1.0, np.abs(zs_all))
        h_map = list(H_map)
        Z = _forward_rows(zs_all, H_map)
        args = (state.rotation0, state.principal_point, state.focal_px)
        n_x = len(X)
        if n_x > _ROTVEC_SCALAR_MAX and len(Z) > _ROTVEC_SCALAR_MAX:
            # Both batches' cameras unpacked in one call: row by row, the same bits as
            # apart while both batches take _rotvec_matrices' array formula (its small
            # batches go through Python floats, which can differ in the last bit).
            f, pp, R, C = prob._unpack_batch(np.concatenate([X, Z[:, :n_cam]]), *args)
            pp_x, pp_z = (pp[:n_x], pp[n_x:]) if len(pp) > 1 else (pp, pp)
            Rb = prob.residuals_of_unpacked(f[:n_x], pp_x, R[:n_x], C[:n_x], *args[1:])
            cam_z = (f[n_x:], pp_z, R[n_x:], C[n_x:])
        else:
            Rb = prob.residuals_batch(X, *args)
            cam_z = prob._unpack_batch(Z[:, :n_cam], *args)
        owner = np.repeat(np.asarray(ids, dtype=np.int64), n_z + 1)
        Mb_all = map_rows(Z, owner, cam_z)
        out = []
        for k, i in enumerate(ids):
            ra = Rb[k * (n_cam + 1) : (k + 1) * (n_cam + 1)]
            r_ann = np.asarray(ra[0], dtype=np.float64)
            J_ann = np.asarray(((ra[1:] - ra[0]) / h_ann[k][:, None]).T, dtype=np.float64)
            Mb = Mb_all[k * (n_z + 1) : (k + 1) * (n_z + 1)][:, cols[i]]
            n_ann = J_ann.shape[0]
            J = np.zeros((n_ann + Mb.shape[1], n_z))
            J[:n_ann, :n_cam] = J_ann
            J[n_ann:] = ((Mb[1:] - Mb[0]) / h_map[k][:, None]).T
            out.append((np.concatenate([r_ann, Mb[0]]), J))
        return out

    starts: list[FloatArray] = []

    def recorded(ids: list[int], zs: list[FloatArray]) -> list[tuple[FloatArray, FloatArray]]:
        got = fun_and_jac_many(ids, zs)
        if not starts:  # the first call: every problem at its start; kept for the costs
            starts.extend(r for r, _J in got)
        return got

    results = soft_l1_least_squares_many_small(
        recorded, [p.z0 for p in problems], f_scale=_F_SCALE, max_nfev=200, sigma_tol=_SIGMA_TOL
    )
    sigmas = _position_sigmas(results, state, n_cam)
    return [
        _accept(p, res, r0, state, n_cam, sigma)
        for p, res, r0, sigma in zip(problems, results, starts, sigmas, strict=True)
    ]


def _forward_rows(zs: FloatArray, hs: FloatArray) -> FloatArray:
    """Each parameter vector ``zs[k]`` then it moved by ``hs[k, j]`` along each parameter
    ``j``, stacked: ``(k (n + 1), n)``, the rows of ``np.vstack([z, z + np.diag(h)])`` per
    vector (the same additions), built in three array operations."""
    k, n = zs.shape
    steps = np.zeros((k, n + 1, n))
    idx = np.arange(n)
    steps[:, idx + 1, idx] = hs
    rows = zs[:, None, :] + steps
    rows[:, 0, :] = zs  # the vector itself, untouched (as vstack's first row)
    return np.asarray(rows.reshape(k * (n + 1), n), dtype=np.float64)


def _accept(
    p: _Problem,
    res: LeastSquaresResult,
    r0: FloatArray,
    state: JointState,
    n_cam: int,
    sigma_m: float | None,
) -> Candidate:
    """The candidate as the bundle left it, or as it was when the bundle is not trustworthy."""
    cand = p.cand
    if not res.success or not np.all(np.isfinite(res.x)):
        return cand

    def robust(r: FloatArray) -> float:  # in squared sigmas, like a chi-square
        return 2.0 * soft_l1_cost(r, _F_SCALE)

    n_ann = len(r0) - p.n_map_rows
    ann0, ann1 = robust(r0[:n_ann]), robust(res.fun[:n_ann])
    map0, map1 = robust(r0[n_ann:]), robust(res.fun[n_ann:])
    if ann1 - ann0 > MAX_ANNOTATION_COST_RISE and map0 - map1 < ann1 - ann0:
        return cand
    lo, hi = state.problem.f_bounds
    f, pp, R_out, C_out = _cam_parts(state, res.x[:n_cam])
    if not lo * 1.001 < f < hi / 1.001 or C_out[2] <= 0.0:
        return cand
    theta, tx, ty, ls = res.x[n_cam:]
    sim = Similarity2D(float(theta), np.array([tx, ty]), math.exp(float(ls)))
    world_cam = Camera.from_center(f, pp, R_out, C_out)
    camera = sim.camera(world_cam)
    return replace(
        cand,
        enu_from_world=sim,
        camera=camera,
        sigma_m=sigma_m,
        refined=True,
    )


def _position_sigmas(
    results: list[LeastSquaresResult], state: JointState, n_cam: int
) -> list[float | None]:
    """:func:`_position_sigma` of each fit, the covariances' pseudo-inverses in one batched
    call and the position's finite differences in one evaluation (LAPACK per matrix; the
    position depends on the camera centre and the similarity only, elementwise): the same
    bits as one fit at a time."""
    if len(results) < 2 or len({np.shape(r.x) for r in results}) != 1:
        return [_position_sigma(r, state, n_cam) for r in results]
    s2s = []
    for res in results:
        fun, z = np.asarray(res.fun), np.asarray(res.x)
        dof = max(len(fun) - len(z), 1)
        s2s.append(max(float(fun @ fun) / dof, 1.0))
    try:
        covs = np.linalg.pinv(np.stack([r.jac.T @ r.jac for r in results]))
    except np.linalg.LinAlgError:
        return [_position_sigma(r, state, n_cam) for r in results]
    Jps = _position_jacobians([np.asarray(r.x) for r in results], state, n_cam)
    out: list[float | None] = []
    for cov, s2, Jp in zip(covs, s2s, Jps, strict=True):
        cov_p = Jp @ (cov * s2) @ Jp.T
        tr = float(np.trace(cov_p))
        out.append(math.sqrt(tr) if math.isfinite(tr) and tr >= 0.0 else None)
    return out


def _position_jacobians(zs: list[FloatArray], state: JointState, n_cam: int) -> list[FloatArray]:
    """The finite-difference Jacobians ``(2, n)`` of the camera's (east, north) at each
    parameter vector (steps of 1e-6 relative), all in one evaluation."""
    hs = [1e-6 * np.maximum(1.0, np.abs(z)) for z in zs]
    Z = np.vstack([np.vstack([z, z + np.diag(h)]) for z, h in zip(zs, hs, strict=True)])
    prob = state.problem
    _f, _pp, _R, C = prob._unpack_batch(
        Z[:, :n_cam], state.rotation0, state.principal_point, state.focal_px
    )
    C_out = (C - state.internal_origin) @ state.internal_from_output
    theta, tx, ty, s = Z[:, n_cam], Z[:, n_cam + 1], Z[:, n_cam + 2], np.exp(Z[:, n_cam + 3])
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    east = s * (cos_t * C_out[:, 0] - sin_t * C_out[:, 1]) + tx
    north = s * (sin_t * C_out[:, 0] + cos_t * C_out[:, 1]) + ty
    out = []
    n_z = len(zs[0]) + 1
    for k, h in enumerate(hs):
        e, n = east[k * n_z : (k + 1) * n_z], north[k * n_z : (k + 1) * n_z]
        out.append(np.stack([(e[1:] - e[0]) / h, (n[1:] - n[0]) / h]))
    return out


def _position_sigma(res: object, state: JointState, n_cam: int) -> float | None:
    """1-sigma horizontal position uncertainty (m) from the bundle's covariance."""
    J = np.asarray(res.jac)  # type: ignore[attr-defined]
    fun = np.asarray(res.fun)  # type: ignore[attr-defined]
    z = np.asarray(res.x)  # type: ignore[attr-defined]
    dof = max(len(fun) - len(z), 1)
    s2 = max(float(fun @ fun) / dof, 1.0)
    try:
        cov = np.linalg.pinv(J.T @ J) * s2
    except np.linalg.LinAlgError:
        return None

    # The position (east, north) at z and at z moved along each parameter, in one batch:
    # s · rot2(θ) · C_out[:2] + t, with C_out the camera centre in the output frame.
    h = 1e-6 * np.maximum(1.0, np.abs(z))
    Z = np.vstack([z, z + np.diag(h)])
    prob = state.problem
    _f, _pp, _R, C = prob._unpack_batch(
        Z[:, :n_cam], state.rotation0, state.principal_point, state.focal_px
    )
    C_out = (C - state.internal_origin) @ state.internal_from_output
    theta, tx, ty, s = Z[:, n_cam], Z[:, n_cam + 1], Z[:, n_cam + 2], np.exp(Z[:, n_cam + 3])
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    east = s * (cos_t * C_out[:, 0] - sin_t * C_out[:, 1]) + tx
    north = s * (sin_t * C_out[:, 0] + cos_t * C_out[:, 1]) + ty
    Jp = np.stack([(east[1:] - east[0]) / h, (north[1:] - north[0]) / h])
    cov_p = Jp @ cov @ Jp.T
    tr = float(np.trace(cov_p))
    return math.sqrt(tr) if math.isfinite(tr) and tr >= 0.0 else None
