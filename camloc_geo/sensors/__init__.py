"""Virtual sensors on a calibrated camera: the scale and the clinometer (radar, guide below).

Once :func:`camloc_geo.relative.calibrate` has found the camera in the car's metric world
frame (ground plane ``z = 0``), pixels on the ground become points in metres:

- :func:`ground_distance` (virtual scale): length of the path through clicked ground pixels;
- :func:`point_height` (virtual clinometer): height of a point vertically above a ground point.

Uncertainty model (``sigma_m``)
-------------------------------
Monte Carlo with a fixed seed (reproducible): ``n_samples`` draws of

- the camera centre, perturbed per axis by ``calibration.position_sigma_m`` (zero when the
  calibration has none);
- the orientation, turned by a small random rotation ``exp([ε]×)`` on the left of
  ``cam_from_world_rotation``, ``ε`` drawn per camera axis (x right, y down, z optical) with
  ``calibration.rotation_sigma_deg`` (none when the calibration has none);
- the focal length, perturbed by ``calibration.focal_sigma_px`` when known;
- the principal point, perturbed by ``calibration.principal_point_sigma_px`` when known;
- every clicked pixel, perturbed by ``click_sigma_px`` (default 1.5 px) per coordinate.

The camera's parameters are drawn together, with the correlations of the calibration's
``parameter_covariance`` at the reported sigmas: a principal point off centre and the tilt
it trades against nearly cancel on the ground, as they do in the fit. Without a covariance
they are drawn independently. ``sigma_m`` is the standard deviation of the measurement over
the draws. Draws in which a pixel's ray misses the ground are dropped; if more than half
are dropped the measurement is refused.

The virtual radar (vehicle speeds from video) is :mod:`camloc_geo.sensors.radar`; the
virtual guide (people seen by the camera matched to GPS traces) is
:mod:`camloc_geo.sensors.guide`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, SupportsFloat, SupportsIndex

import numpy as np
import numpy.typing as npt

from camloc_geo._errors import InputError

if TYPE_CHECKING:
    from camloc_geo.relative import CalibrationResult

__all__ = ["Measurement", "ground_distance", "point_height"]

FloatArray = npt.NDArray[np.float64]

_HORIZON_EPS = 1e-9
_SEED = 20261123


@dataclass(frozen=True)
class Measurement:
    """A length measured with the calibrated camera.

    Attributes
    ----------
    quantity
        ``"distance"`` (virtual scale) or ``"height"`` (virtual clinometer).
    value_m
        The measurement with the calibrated camera, metres.
    sigma_m
        1-sigma uncertainty, metres (model in the module docstring).
    n_samples
        Monte Carlo draws that reached the ground.
    warnings
        What makes the sigma doubtful: draws lost beyond the horizon (their distance is
        unbounded, so the spread of the others is a lower bound).
    """

    quantity: str
    value_m: float
    sigma_m: float
    n_samples: int
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: ``{"distance_m"|"height_m": ..., "sigma_m": ..., "n_samples": ...}``,
        and ``"warnings"`` when there are any."""
        out: dict[str, Any] = {
            f"{self.quantity}_m": self.value_m,
            "sigma_m": self.sigma_m,
            "n_samples": self.n_samples,
        }
        if self.warnings:
            out["warnings"] = list(self.warnings)
        return out


def _pixels(pixels_px: npt.ArrayLike, what: str) -> FloatArray:
    try:
        px = np.asarray(pixels_px, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{what}: pixels must be numbers (u, v)") from exc
    if px.ndim == 1:
        px = px.reshape(1, -1)
    if px.ndim != 2 or px.shape[1] != 2:
        raise InputError(f"{what}: pixels must be (u, v) pairs, got shape {px.shape}")
    if not np.all(np.isfinite(px)):
        raise InputError(f"{what}: pixels must be finite numbers")
    return px


def _check_in_view(pixels: FloatArray, calibration: object, what: str) -> None:
    """Refuse a pixel more than one image size outside the image (``--ground 1e308,2 3,4``
    measured 762 m ± 50 km). The image is taken as twice the principal point, which is its
    centre unless the scene gave another."""
    cx, cy = (float(c) for c in calibration.camera.principal_point)  # type: ignore[attr-defined]
    width, height = 2.0 * cx, 2.0 * cy
    if not (width > 0 and height > 0):
        return
    for u, v in pixels:
        if not (-width <= u <= 2.0 * width and -height <= v <= 2.0 * height):
            raise InputError(
                f"{what}: pixel ({u:g}, {v:g}) is far outside the {width:g}x{height:g} image "
                "(more than one image size beyond its edge)"
            )


def _options(
    calibration: object, click_sigma_px: object, n_samples: object, seed: object
) -> tuple[float, int, int]:
    """Checked ``(click_sigma_px, n_samples, seed)``; an :class:`InputError` naming a bad one."""
    import math
    import operator

    if not hasattr(calibration, "camera"):
        raise InputError(
            "calibration must be a CalibrationResult (from calibrate_scene), not "
            f"{type(calibration).__name__}"
        )
    try:
        sigma = float(click_sigma_px)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        sigma = math.nan
    if isinstance(click_sigma_px, bool) or not (math.isfinite(sigma) and sigma >= 0):
        raise InputError(
            f"click_sigma_px must be a finite number of pixels >= 0, got {click_sigma_px!r}"
        )
    whole: list[int] = []
    for name, value, least in (("n_samples", n_samples, 2), ("seed", seed, 0)):
        try:
            k = operator.index(value)  # type: ignore[arg-type]
        except TypeError:
            k = -1
        if isinstance(value, bool) or k < least:
            raise InputError(f"{name} must be a whole number >= {least}, got {value!r}")
        whole.append(k)
    return sigma, whole[0], whole[1]


def _rays(
    pixels: FloatArray, focal: FloatArray, pp: tuple[float, float], R: FloatArray
) -> FloatArray:
    """World viewing directions (not normalised) of pixels ``(S, N, 2)`` for focals ``(S,)``.

    ``R`` is one ``cam_from_world`` rotation ``(3, 3)`` or one per draw ``(S, 3, 3)``.
    """
    f = focal[:, None]
    d_cam = np.stack(
        [(pixels[..., 0] - pp[0]) / f, (pixels[..., 1] - pp[1]) / f, np.ones(pixels.shape[:2])],
        axis=-1,
    )
    if R.ndim == 3:
        return np.asarray(np.einsum("snj,sjk->snk", d_cam, R), dtype=np.float64)
    return np.asarray(d_cam @ R, dtype=np.float64)  # Rᵀ applied to each row


def _ground(centres: FloatArray, rays: FloatArray) -> FloatArray:
    """Ground points ``(S, N, 3)``; NaN where a ray does not reach ``z = 0`` in front."""
    dz = rays[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = -centres[:, None, 2] / dz
    bad = ~np.isfinite(lam) | (lam <= 0) | (np.abs(dz) < _HORIZON_EPS)
    lam = np.where(bad, np.nan, lam)
    return np.asarray(centres[:, None, :] + lam[..., None] * rays, dtype=np.float64)


def _draws(
    calibration: CalibrationResult,
    pixels: FloatArray,
    n_samples: int,
    click_sigma_px: float,
    seed: int,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Centres ``(S+1, 3)``, focals ``(S+1,)`` and pixels ``(S+1, N, 2)``; row 0 nominal.

    The rotation is not drawn: see :func:`_draws_posed`.
    """
    centres, focals, _rotations, px = _draws_posed(
        calibration, pixels, n_samples, click_sigma_px, seed, principal_point=False
    )
    return centres, focals, px


def _draws_posed(
    calibration: CalibrationResult,
    pixels: FloatArray,
    n_samples: int,
    click_sigma_px: float,
    seed: int,
    principal_point: bool = True,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Centres ``(S+1, 3)``, focals ``(S+1,)``, ``cam_from_world`` rotations ``(S+1, 3, 3)``
    and pixels ``(S+1, N, 2)``; row 0 nominal (model in the module docstring).

    A drawn principal point ``pp + δ`` is applied as the pixels moved by ``−δ`` (the rays
    through ``u − pp − δ`` are the same), so callers keep casting through the camera's
    principal point; ``principal_point=False`` leaves it out.
    """
    from scipy.spatial.transform import Rotation

    cam = calibration.camera
    rng = np.random.default_rng(seed)
    sig_c = calibration.position_sigma_m
    sig_c = np.zeros(3) if sig_c is None else np.nan_to_num(np.asarray(sig_c, float).reshape(3))
    sig_f = calibration.focal_sigma_px
    sig_f = 0.0 if sig_f is None or not np.isfinite(sig_f) else float(sig_f)
    sig_r = getattr(calibration, "rotation_sigma_deg", None)
    sig_rad = (
        np.zeros(3)
        if sig_r is None
        else np.radians(np.nan_to_num(np.asarray(sig_r, float).reshape(3)))
    )
    sig_pp_in = getattr(calibration, "principal_point_sigma_px", None)
    sig_pp = (
        np.zeros(2)
        if sig_pp_in is None or not principal_point
        else np.nan_to_num(np.asarray(sig_pp_in, float).reshape(2))
    )
    corr = _correlation(getattr(calibration, "parameter_covariance", None))
    R = cam.cam_from_world_rotation
    rotations = np.broadcast_to(R, (n_samples + 1, 3, 3)).copy()
    d_pp = np.zeros((n_samples, 2))
    if corr is not None:
        # Drawn together: the fit's correlations (e.g. a principal point off centre against
        # the tilt it trades with) at the reported sigmas (which include the jackknife).
        z = rng.normal(0.0, 1.0, (n_samples, 9)) @ corr.T
        scale = np.concatenate([[sig_f], sig_pp, sig_rad, sig_c])
        d = z * scale
        centres = cam.center_in_world + d[:, 6:9]
        focals = cam.focal_px + d[:, 0]
        d_pp = d[:, 1:3]
        eps = d[:, 3:6]
        px = pixels[None] + rng.normal(0.0, click_sigma_px, (n_samples, *pixels.shape))
    else:
        centres = cam.center_in_world + rng.normal(0.0, 1.0, (n_samples, 3)) * sig_c
        focals = cam.focal_px + rng.normal(0.0, sig_f, n_samples)
        px = pixels[None] + rng.normal(0.0, click_sigma_px, (n_samples, *pixels.shape))
        eps = rng.normal(0.0, 1.0, (n_samples, 3)) * sig_rad if sig_r is not None else None
    focals = np.clip(focals, 0.1 * cam.focal_px, None)
    px = px - d_pp[:, None, :]
    if eps is not None:
        rotations[1:] = Rotation.from_rotvec(eps).as_matrix() @ R
    return (
        np.vstack([cam.center_in_world[None], centres]),
        np.concatenate([[cam.focal_px], focals]),
        rotations,
        np.concatenate([pixels[None], px]),
    )


def _correlation(cov: Any) -> FloatArray | None:
    """A square root ``L`` (``L Lᵀ`` = the correlation matrix) of a ``(9, 9)`` covariance.

    Entries of zero variance get an uncorrelated unit draw (scaled to zero by their sigma).
    None when there is no usable covariance.
    """
    if cov is None:
        return None
    c = np.asarray(cov, dtype=np.float64)
    if c.shape != (9, 9) or not np.all(np.isfinite(c)):
        return None
    sd = np.sqrt(np.clip(np.diag(c), 0.0, None))
    ok = sd > 0.0
    inv = np.where(ok, 1.0 / np.where(ok, sd, 1.0), 0.0)
    rho = c * inv[:, None] * inv[None, :]
    rho[~ok, :] = 0.0
    rho[:, ~ok] = 0.0
    rho[np.diag_indices(9)] = 1.0
    vals, vecs = np.linalg.eigh(0.5 * (rho + rho.T))
    return np.asarray(vecs * np.sqrt(np.clip(vals, 0.0, None)), dtype=np.float64)


def _check_ground(points: FloatArray, pixels: FloatArray) -> None:
    bad = ~np.all(np.isfinite(points), axis=-1)
    if np.any(bad):
        u, v = pixels[int(np.argmax(bad))]
        raise InputError(
            f"pixel ({u:g}, {v:g}) is at or above the horizon: its ray never meets the ground"
        )


def _summary(quantity: str, values: FloatArray) -> Measurement:
    nominal = float(values[0])
    draws = values[1:]
    ok = draws[np.isfinite(draws)]
    if len(ok) < max(2, len(draws) // 2):
        raise InputError(
            f"the {quantity} is too close to the horizon to measure: most perturbed cameras "
            "see the clicked pixels above it"
        )
    warnings: tuple[str, ...] = ()
    if len(ok) < len(draws):
        warnings = (
            f"{len(draws) - len(ok)} of {len(draws)} perturbed cameras see the clicked pixels "
            f"at or above the horizon: the {quantity} may be far larger than stated, and "
            "sigma_m (the spread of the other draws) is a lower bound",
        )
    return Measurement(quantity, nominal, float(np.std(ok, ddof=1)), len(ok), warnings)


def ground_distance(
    calibration: CalibrationResult,
    pixels_px: npt.ArrayLike,
    *,
    click_sigma_px: SupportsFloat = 1.5,
    n_samples: SupportsIndex = 400,
    seed: SupportsIndex = _SEED,
) -> Measurement:
    """Virtual scale: length of the path through clicked ground pixels.

    Parameters
    ----------
    calibration
        The calibrated camera (:class:`camloc_geo.relative.CalibrationResult`).
    pixels_px
        ``(N, 2)`` image pixels of points on the ground, ``N >= 2``, in path order.
    click_sigma_px
        Standard deviation of a click, pixels per coordinate.
    n_samples, seed
        Monte Carlo draws for ``sigma_m`` and their seed.

    Returns
    -------
    Measurement
        ``quantity="distance"``: the summed length of the ground segments, metres.

    Raises
    ------
    InputError
        Fewer than two pixels, a pixel not finite or more than one image size outside the
        image, or a pixel at or above the horizon (named in the message); a
        ``calibration`` that is not one, ``click_sigma_px`` < 0, ``n_samples`` < 2, a
        ``seed`` that is not a whole number >= 0.
    """
    click_sigma_px, n_samples, seed = _options(calibration, click_sigma_px, n_samples, seed)
    pixels = _pixels(pixels_px, "ground")
    if len(pixels) < 2:
        raise InputError("ground: give at least two pixels")
    _check_in_view(pixels, calibration, "ground")
    cam = calibration.camera
    centres, focals, rotations, px = _draws_posed(
        calibration, pixels, n_samples, click_sigma_px, seed
    )
    rays = _rays(px, focals, cam.principal_point, rotations)
    points = _ground(centres, rays)
    _check_ground(points[0], pixels)
    lengths = np.linalg.norm(np.diff(points[..., :2], axis=1), axis=-1).sum(axis=1)
    return _summary("distance", lengths)


def point_height(
    calibration: CalibrationResult,
    base_px: npt.ArrayLike,
    top_px: npt.ArrayLike,
    *,
    click_sigma_px: SupportsFloat = 1.5,
    n_samples: SupportsIndex = 400,
    seed: SupportsIndex = _SEED,
) -> Measurement:
    """Virtual clinometer: height of a point vertically above a ground point.

    The base pixel is cast onto the ground; the top pixel's ray is intersected (least squares)
    with the vertical line through that ground point.

    Parameters
    ----------
    calibration
        The calibrated camera.
    base_px
        ``(u, v)`` where the vertical meets the ground (e.g. the foot of a building's face).
    top_px
        ``(u, v)`` of the point above it (e.g. the roof edge).
    click_sigma_px, n_samples, seed
        As in :func:`ground_distance`.

    Returns
    -------
    Measurement
        ``quantity="height"``, metres above the ground.

    Raises
    ------
    InputError
        The base pixel is at or above the horizon, or the top pixel is below its base; a
        pixel not finite or more than one image size outside the image; a
        ``calibration`` that is not one, ``click_sigma_px`` < 0, ``n_samples`` < 2, a
        ``seed`` that is not a whole number >= 0.
    """
    click_sigma_px, n_samples, seed = _options(calibration, click_sigma_px, n_samples, seed)
    base = _pixels(base_px, "height base")
    top = _pixels(top_px, "height top")
    if len(base) != 1 or len(top) != 1:
        raise InputError("height: give one base pixel and one top pixel")
    _check_in_view(base, calibration, "height base")
    _check_in_view(top, calibration, "height top")
    pixels = np.vstack([base, top])
    cam = calibration.camera
    centres, focals, rotations, px = _draws_posed(
        calibration, pixels, n_samples, click_sigma_px, seed
    )
    rays = _rays(px, focals, cam.principal_point, rotations)
    foot = _ground(centres, rays[:, :1])[:, 0]
    _check_ground(foot[:1], base)
    d = rays[:, 1]
    w_xy = centres[:, :2] - foot[:, :2]
    d_xy2 = np.einsum("ij,ij->i", d[:, :2], d[:, :2])
    with np.errstate(divide="ignore", invalid="ignore"):
        s = -np.einsum("ij,ij->i", w_xy, d[:, :2]) / d_xy2
    heights = centres[:, 2] + s * d[:, 2]
    heights = np.where((d_xy2 > _HORIZON_EPS) & (s > 0), heights, np.nan)
    if not np.isfinite(heights[0]):
        raise InputError(
            f"top pixel ({top[0, 0]:g}, {top[0, 1]:g}) is straight along the vertical through "
            "the camera or behind it: no height"
        )
    if heights[0] < 0.0:
        raise InputError(
            f"top pixel ({top[0, 0]:g}, {top[0, 1]:g}) is below its base pixel "
            f"({base[0, 0]:g}, {base[0, 1]:g}): the point would be underground"
        )
    return _summary("height", heights)
