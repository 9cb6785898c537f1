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
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from camloc_geo._optimize import soft_l1_cost, soft_l1_least_squares
from camloc_geo.absolute._evidence import Evidence
from camloc_geo.absolute._model import Candidate, LocateSettings, Observation
from camloc_geo.absolute._refine import _matched_points, _street_bearing_prior
from camloc_geo.absolute._similarity import Similarity2D
from camloc_geo.camera import Camera

if TYPE_CHECKING:
    from camloc_geo.relative import CalibrationResult, JointState

__all__ = ["MAX_ANNOTATION_COST_RISE", "MIN_MATCHED_POINTS", "bundle_adjust"]

FloatArray = npt.NDArray[np.float64]

MAX_ANNOTATION_COST_RISE = 30.0
"""Largest rise of the annotations' chi-square the map may force (in squared sigmas)."""

MIN_MATCHED_POINTS = 3
"""Fewer matched map points add no redundancy beyond the similarity's four parameters: two
points fit any camera exactly, and the bundle would only wander along the flat valley of
the similarity's rotation (measured: it moved two-corner candidates by up to 8 m)."""

_F_SCALE = 2.5


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
    state = calibration.joint_state
    if state is None:
        return cand
    obs_q = _matched_points(cand, ev)
    if len(obs_q) < MIN_MATCHED_POINTS:
        return cand
    prob = state.problem
    saved_weights = prob.weights
    prob.weights = state.weights
    try:
        return _bundle(cand, state, obs_q, ev, settings, image_size)
    except (ValueError, np.linalg.LinAlgError, FloatingPointError):
        return cand
    finally:
        prob.weights = saved_weights


def _bundle(
    cand: Candidate,
    state: JointState,
    obs_q: list[tuple[Observation, FloatArray]],
    ev: Evidence,
    settings: LocateSettings,
    image_size: tuple[int, int],
) -> Candidate:
    prob = state.problem
    pixels = np.array([o.pixel for o, _q in obs_q], dtype=float)
    q_en = np.array([q for _o, q in obs_q], dtype=float)
    sigma_map = np.array([o.sigma_map_m for o, _q in obs_q], dtype=float)
    sigma_click = settings.sigma_pixel_rel * math.hypot(*image_size)
    s_sigma = max(settings.scale_sigma_rel, 1e-6)
    street_brg = _street_bearing_prior(cand, ev, settings)
    n_cam = len(state.x)
    M, origin = state.internal_from_output, state.internal_origin

    def map_residuals_batch(Z: FloatArray) -> FloatArray:
        """The map rows of a batch of parameter vectors ``(P, n)`` → ``(P, m)``: each matched
        map point's pixel residual (u then v, over its sigma), the scale prior, then the
        street-bearing prior when there is one."""
        f, pp, R, C = prob._unpack_batch(
            Z[:, :n_cam], state.rotation0, state.principal_point, state.focal_px
        )
        theta, tx, ty, ls = Z[:, n_cam], Z[:, n_cam + 1], Z[:, n_cam + 2], Z[:, n_cam + 3]
        s = np.exp(ls)
        cos_t, sin_t = np.cos(theta), np.sin(theta)
        dx = q_en[None, :, 0] - tx[:, None]  # (P, n)
        dy = q_en[None, :, 1] - ty[:, None]
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
        sig = np.sqrt(sigma_click**2 + (fc * sigma_map[None, :] / depth) ** 2)
        parts = [(u - pixels[:, 0]) / sig, (v - pixels[:, 1]) / sig, (ls / s_sigma)[:, None]]
        if street_brg is not None:
            car_brg = (90.0 - np.degrees(theta)) % 180.0
            diff = (car_brg - street_brg + 90.0) % 180.0 - 90.0
            parts.append((diff / settings.bearing_sigma_deg)[:, None])
        return np.concatenate(parts, axis=1)

    def residuals_and_jacobian(z: FloatArray) -> tuple[FloatArray, FloatArray]:
        # One batched evaluation each: the annotations depend on the camera only, so their
        # rows come from the joint fit's own batched residuals and Jacobian; the few map rows
        # from one batch of forward differences whose first row is the residual itself.
        r_ann, J_ann = prob.residuals_and_jacobian(
            z[:n_cam], state.rotation0, state.principal_point, state.focal_px
        )
        h = 1e-6 * np.maximum(1.0, np.abs(z))
        Mb = map_residuals_batch(np.vstack([z, z + np.diag(h)]))
        n_ann = J_ann.shape[0]
        J = np.zeros((n_ann + Mb.shape[1], len(z)))
        J[:n_ann, :n_cam] = J_ann
        J[n_ann:] = ((Mb[1:] - Mb[0]) / h[:, None]).T
        return np.concatenate([r_ann, Mb[0]]), J

    # The similarity is expressed from the calibration's output frame; the start is the
    # candidate's (refined) one.
    sim0 = cand.enu_from_world
    z0 = np.concatenate(
        [state.x, [sim0.rotation_rad, *np.asarray(sim0.translation_m), math.log(sim0.scale)]]
    )
    r0, J0 = residuals_and_jacobian(z0)  # its costs are needed after the fit too
    start = [(r0, J0)]

    def fun_and_jac(z: FloatArray) -> tuple[FloatArray, FloatArray]:
        if start and np.array_equal(z, z0):
            return start.pop()  # the fit's first evaluation, at the start
        return residuals_and_jacobian(z)

    def residuals(z: FloatArray) -> FloatArray:
        return residuals_and_jacobian(z)[0]

    def jacobian(z: FloatArray) -> FloatArray:
        return residuals_and_jacobian(z)[1]

    # Every trial step is evaluated with its Jacobian (one batched call: most steps are
    # accepted, and an accepted one then needs no second call).
    res = soft_l1_least_squares(
        residuals, jacobian, z0, f_scale=_F_SCALE, max_nfev=200, fun_and_jac=fun_and_jac
    )
    if not res.success or not np.all(np.isfinite(res.x)):
        return cand

    def robust(r: FloatArray) -> float:  # in squared sigmas, like a chi-square
        return 2.0 * soft_l1_cost(r, _F_SCALE)

    n_ann = len(r0) - (2 * len(pixels) + 1 + (street_brg is not None))
    ann0, ann1 = robust(r0[:n_ann]), robust(res.fun[:n_ann])
    map0, map1 = robust(r0[n_ann:]), robust(res.fun[n_ann:])
    if ann1 - ann0 > MAX_ANNOTATION_COST_RISE and map0 - map1 < ann1 - ann0:
        return cand
    lo, hi = prob.f_bounds
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
        sigma_m=_position_sigma(res, state, n_cam),
        refined=True,
    )


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
