"""Frames and the pinhole camera model.

Conventions (written down once, used everywhere; see ``docs/contract.md``):

image
    Continuous pixel coordinates ``[x, y]``: origin at the top-left corner of the image,
    x right, y down. The centre of the top-left pixel is ``[0.5, 0.5]``; the image centre
    is ``[width / 2, height / 2]``.
camera
    x right, y down, z forward along the optical axis. ``img_from_cam`` is the intrinsic
    matrix ``K = [[f, 0, cx], [0, f, cy], [0, 0, 1]]`` (square pixels, no skew).
world
    The scene's metric frame, metres: origin at the annotated ground corner of the reference
    object, x along its length, z up, y = z × x (right-handed). The ground is z = 0.
pose
    ``cam_from_world = [R | t]``: ``points_in_cam = R @ points_in_world + t``. The camera
    centre in the world frame is ``-Rᵀ t``.
angles
    Headings are degrees clockwise from north (in the world frame, "north" is +y and "east"
    is +x, so the world-frame heading is measured clockwise from +y). Pitch is the optical
    axis' angle below the horizon (positive = looking down). Roll is the rotation about the
    optical axis: with ``f`` the optical axis, ``r`` the camera x axis (image right),
    ``r0 = normalize(f × up)`` and ``d0 = f × r0``, ``roll = atan2(r·d0, r·r0)``; positive when
    the image's right side tilts downward, i.e. the scene appears rotated anticlockwise.

Pixels that look at or above the horizon have no ground point. Every function that casts
pixels onto the ground takes ``above_horizon="nan"`` (NaN rows, the default for batches) or
``"error"`` (raise :class:`~camloc_geo.DegenerateGeometryError`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from camloc_geo._errors import DegenerateGeometryError, InputError

__all__ = [
    "Camera",
    "RadialDistortion",
    "angles_from_rotation",
    "clip_segment_to_image",
    "distort_points_px",
    "project_to_rotation",
    "rotation_from_angles",
    "rotation_from_rotvec",
    "rotvec_from_rotation",
    "undistort_points_px",
]

FloatArray = npt.NDArray[np.float64]
HorizonPolicy = Literal["nan", "error"]

_UP = np.array([0.0, 0.0, 1.0])
# Minimum cosine between a viewing ray and the ground (below the horizon) to count as a ground hit.
_GROUND_EPS = 1e-9
_ROTATION_TOL = 1e-4  # a rotation rounded to 5-6 decimals (JSON written by hand) passes


def _float(value: object, name: str) -> float:
    """``value`` as a Python float (numpy scalars too), or an :class:`InputError` naming it."""
    if isinstance(value, bool):
        raise InputError(f"{name} must be a number, got {value!r}")
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None


def _rows(values: npt.ArrayLike, width: int, name: str) -> FloatArray:
    """``values`` as floats whose last axis has ``width`` numbers, or an :class:`InputError`."""
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers, got {values!r}") from None
    if arr.ndim == 0 or arr.shape[-1] != width:
        raise InputError(f"{name} must be ({width},) or (N, {width}), got shape {arr.shape}")
    return arr


@dataclass(frozen=True)
class RadialDistortion:
    """One-parameter radial lens distortion, the division model.

    A distorted pixel ``p_d`` (as in the photo) and its undistorted (pinhole) pixel
    ``p_u`` satisfy::

        p_u = c + (p_d - c) / (1 + k1 * r_d**2),   r_d = |p_d - c| / radius_px

    with ``c`` the principal point and ``radius_px`` half the image diagonal, so that
    ``k1`` does not depend on the image's size: ``k1 < 0`` is barrel distortion (wide-angle
    lenses; straight lines bow outwards), ``k1 > 0`` pincushion. ``k1 = -0.1`` moves a
    corner of the photo outwards by about 11 % of its distance to the centre.

    Attributes
    ----------
    k1
        The coefficient (dimensionless).
    radius_px
        Half the image diagonal, pixels.
    """

    k1: float
    radius_px: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "k1", _float(self.k1, "distortion k1"))
        object.__setattr__(self, "radius_px", _float(self.radius_px, "distortion radius_px"))
        if not math.isfinite(self.k1) or abs(self.k1) >= 1.0:
            raise DegenerateGeometryError(
                f"distortion k1 must be finite and in (-1, 1), got {self.k1}"
            )
        if not (math.isfinite(self.radius_px) and self.radius_px > 0):
            raise DegenerateGeometryError(
                f"distortion radius must be positive, got {self.radius_px}"
            )

    @classmethod
    def for_image(cls, k1: float, width_px: float, height_px: float) -> RadialDistortion:
        """The distortion ``k1`` of a ``width_px`` x ``height_px`` image."""
        return cls(float(k1), 0.5 * math.hypot(width_px, height_px))


def undistort_points_px(
    points_px: npt.ArrayLike,
    distortion: RadialDistortion | None,
    principal_point: tuple[float, float],
) -> FloatArray:
    """Pinhole pixels of ``(2,)`` or ``(N, 2)`` pixels of a distorted photo.

    ``distortion`` None or ``k1 == 0`` returns the points unchanged (as floats). A point
    the model maps through infinity (``1 + k1 r**2 <= 0``, far outside the photo) is NaN.
    """
    p = np.asarray(points_px, dtype=np.float64)
    if distortion is None or distortion.k1 == 0.0:
        return p.copy()
    c = np.asarray(principal_point, dtype=np.float64)
    d = p - c
    r2 = np.sum(d * d, axis=-1, keepdims=True) / distortion.radius_px**2
    den = 1.0 + distortion.k1 * r2
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(den > 0, c + d / den, np.nan)
    return np.asarray(out, dtype=np.float64)


def distort_points_px(
    points_px: npt.ArrayLike,
    distortion: RadialDistortion | None,
    principal_point: tuple[float, float],
) -> FloatArray:
    """Pixels in the distorted photo of ``(2,)`` or ``(N, 2)`` pinhole pixels.

    The inverse of :func:`undistort_points_px`: ``r_d`` solves
    ``k1 r_u r_d**2 - r_d + r_u = 0`` (the root that tends to ``r_u`` as ``k1 -> 0``).
    Points with no solution (``4 k1 r_u**2 > 1``, far outside a pincushion photo) are NaN.
    """
    p = np.asarray(points_px, dtype=np.float64)
    if distortion is None or distortion.k1 == 0.0:
        return p.copy()
    c = np.asarray(principal_point, dtype=np.float64)
    d = (p - c) / distortion.radius_px
    ru = np.sqrt(np.sum(d * d, axis=-1, keepdims=True))
    k = distortion.k1
    disc = 1.0 - 4.0 * k * ru * ru
    with np.errstate(divide="ignore", invalid="ignore"):
        # r_d / r_u = 2 / (1 + sqrt(disc)), stable for small k and r_u = 0
        ratio = np.where(disc >= 0, 2.0 / (1.0 + np.sqrt(np.maximum(disc, 0.0))), np.nan)
    return np.asarray(c + (p - c) * ratio, dtype=np.float64)


def project_to_rotation(matrix: npt.ArrayLike) -> FloatArray:
    """Nearest proper rotation (Frobenius norm) to a 3×3 matrix, by SVD with det = +1.

    Parameters
    ----------
    matrix
        A 3×3 matrix, roughly a rotation.

    Returns
    -------
    The closest matrix ``R`` with ``RᵀR = I`` and ``det R = +1``.
    """
    m = np.asarray(matrix, dtype=float).reshape(3, 3)
    if not np.all(np.isfinite(m)):
        raise DegenerateGeometryError("rotation estimate is not finite")
    u, _s, vt = np.linalg.svd(m)
    d = np.sign(np.linalg.det(u @ vt)) or 1.0
    return np.asarray(u @ np.diag([1.0, 1.0, d]) @ vt, dtype=np.float64)


def rotation_from_rotvec(rotvec: npt.ArrayLike) -> FloatArray:
    """Rotation matrix of a rotation vector (axis times angle in radians), Rodrigues' formula.

    The same as ``scipy.spatial.transform.Rotation.from_rotvec(v).as_matrix()``, without
    importing scipy.spatial (a quarter of a second) on the calibration's path.
    """
    w = np.asarray(rotvec, dtype=float).reshape(3)
    theta2 = float(w @ w)
    if theta2 < 1e-12:  # sin θ / θ and (1 - cos θ) / θ² by their Taylor series
        a, b = 1.0 - theta2 / 6.0, 0.5 - theta2 / 24.0
    else:
        theta = math.sqrt(theta2)
        a, b = math.sin(theta) / theta, (1.0 - math.cos(theta)) / theta2
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    return np.asarray(np.eye(3) + a * K + b * (K @ K), dtype=np.float64)


def rotvec_from_rotation(matrix: npt.ArrayLike) -> FloatArray:
    """Rotation vector (axis times angle in radians, angle in [0, π]) of a rotation matrix.

    Through the unit quaternion (Shepperd's choice of its largest component, stable at every
    angle, π included); the same as ``Rotation.from_matrix(R).as_rotvec()``.
    """
    R = np.asarray(matrix, dtype=float).reshape(3, 3)
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    k = int(np.argmax([tr, R[0, 0], R[1, 1], R[2, 2]]))
    if k == 0:
        w = 0.5 * math.sqrt(max(1.0 + tr, 0.0))
        q = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / (4.0 * w)
    else:
        i = k - 1
        j, m = (i + 1) % 3, (i + 2) % 3
        qi = 0.5 * math.sqrt(max(1.0 + 2.0 * R[i, i] - tr, 0.0))
        q = np.empty(3)
        q[i] = qi
        q[j] = (R[i, j] + R[j, i]) / (4.0 * qi)
        q[m] = (R[i, m] + R[m, i]) / (4.0 * qi)
        w = (R[m, j] - R[j, m]) / (4.0 * qi)
    if w < 0.0:
        q, w = -q, -w
    n = float(np.linalg.norm(q))
    scale = 2.0 * math.atan2(n, w) / n if n > 1e-12 else 2.0 / max(w, 1e-300)
    return np.asarray(q * scale, dtype=np.float64)


def rotation_from_angles(heading_deg: float, pitch_deg: float, roll_deg: float) -> FloatArray:
    """``cam_from_world`` rotation of a camera with the given heading, pitch and roll.

    The world frame here is z up with heading measured clockwise from +y ("north")
    towards +x ("east"); use it with an ENU frame (x east, y north, z up).

    Parameters
    ----------
    heading_deg
        Bearing of the optical axis projected on the ground, clockwise from +y.
    pitch_deg
        Angle of the optical axis below the horizon (positive = looking down).
    roll_deg
        Rotation about the optical axis, positive when image-right tilts downward.

    Returns
    -------
    The 3×3 rotation ``R`` with ``points_in_cam = R @ points_in_world + t``.
    """
    h, p, r = np.radians([heading_deg, pitch_deg, roll_deg])
    forward = np.array([math.sin(h) * math.cos(p), math.cos(h) * math.cos(p), -math.sin(p)])
    right0 = np.array([math.cos(h), -math.sin(h), 0.0])  # forward × up, normalised
    down0 = np.cross(forward, right0)
    right = math.cos(r) * right0 + math.sin(r) * down0
    down = np.cross(forward, right)
    world_from_cam = np.column_stack([right, down, forward])
    return np.asarray(world_from_cam.T, dtype=np.float64)


def angles_from_rotation(cam_from_world_rotation: npt.ArrayLike) -> tuple[float, float, float]:
    """Heading, pitch and roll (degrees) of a ``cam_from_world`` rotation; z is up.

    Heading is clockwise from +y in [0, 360); it is undefined (returned as 0) for a camera
    looking straight down or up, where roll absorbs the rotation.
    """
    R = np.asarray(cam_from_world_rotation, dtype=float).reshape(3, 3)
    right = R[0]  # rows of R = camera axes in the world
    f0, f1, f2 = R[2].tolist()  # the forward axis, as Python floats (cheaper than numpy's)
    z = -f2
    if z > 1.0:  # np.clip(z, -1, 1) on a Python float, NaN kept
        z = 1.0
    elif z < -1.0:
        z = -1.0
    pitch = math.degrees(math.asin(z))
    horiz = math.hypot(f0, f1)
    if horiz < 1e-12:
        heading = 0.0
        r0, r1, r2 = 1.0, 0.0, 0.0
    else:
        heading = math.degrees(math.atan2(f0, f1)) % 360.0
        r0, r1, r2 = f1 / horiz, -f0 / horiz, 0.0 / horiz
    right0 = np.array([r0, r1, r2])
    # np.cross(forward, right0), written out (the same products and differences)
    down0 = np.array([f1 * r2 - f2 * r1, f2 * r0 - f0 * r2, f0 * r1 - f1 * r0])
    roll = math.degrees(math.atan2(float(right @ down0), float(right @ right0)))
    return heading, pitch, roll


@dataclass(frozen=True)
class Camera:
    """A pinhole camera: intrinsics and the ``cam_from_world`` pose.

    Parameters
    ----------
    focal_px
        Focal length in pixels (square pixels).
    principal_point
        ``(cx, cy)`` in image pixels.
    cam_from_world_rotation
        ``R``, a proper 3×3 rotation.
    cam_from_world_translation
        ``t``, metres: the world origin in the camera frame.
    distortion
        Optional radial lens distortion (:class:`RadialDistortion`): :meth:`project`
        returns pixels of the distorted photo and :meth:`rays_in_world` takes them. The
        matrices (``img_from_cam``, ``horizon_line``, ...) are those of the pinhole camera:
        undistort pixels with :func:`undistort_points_px` before using them.
    """

    focal_px: float
    principal_point: tuple[float, float]
    cam_from_world_rotation: FloatArray
    cam_from_world_translation: FloatArray
    distortion: RadialDistortion | None = None

    def __post_init__(self) -> None:
        # Built ~30 times a locate and more in calibrate: the checks cost a few microseconds
        # (Python floats for the 3x3 products, not numpy's allclose and det: 47 -> 17 us).
        focal_px = _float(self.focal_px, "focal_px")
        if not (math.isfinite(focal_px) and focal_px > 0):
            raise DegenerateGeometryError(f"focal_px must be positive, got {self.focal_px}")
        R = _rows(self.cam_from_world_rotation, 3, "cam_from_world_rotation")
        t = _rows(self.cam_from_world_translation, 3, "cam_from_world_translation")
        if R.shape != (3, 3):
            raise InputError(f"cam_from_world_rotation must be 3x3, got shape {R.shape}")
        if t.size != 3:
            raise InputError(f"cam_from_world_translation must be 3 numbers, got shape {t.shape}")
        t = t.reshape(3)
        (a, b, c), (d, e, f), (g, h, i) = R.tolist()
        tx, ty, tz = t.tolist()
        if not all(math.isfinite(v) for v in (a, b, c, d, e, f, g, h, i, tx, ty, tz)):
            raise DegenerateGeometryError("camera pose is not finite")
        gram_off = (  # R Rᵀ - I, entry by entry
            a * a + b * b + c * c - 1.0,
            d * d + e * e + f * f - 1.0,
            g * g + h * h + i * i - 1.0,
            a * d + b * e + c * f,
            a * g + b * h + c * i,
            d * g + e * h + f * i,
        )
        det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
        if max(abs(v) for v in gram_off) > _ROTATION_TOL or not det > 0.0:
            raise DegenerateGeometryError(
                "cam_from_world_rotation is not a proper rotation (R Rᵀ = I, det R = +1): "
                "use project_to_rotation() for a nearly orthonormal matrix"
            )
        pp_in = self.principal_point
        try:
            px, py = pp_in
            pp = (_float(px, "principal_point x"), _float(py, "principal_point y"))
        except (TypeError, ValueError, InputError):
            raise InputError(f"principal_point must be two finite numbers, got {pp_in!r}") from None
        if not (math.isfinite(pp[0]) and math.isfinite(pp[1])):
            raise InputError(f"principal_point must be two finite numbers, got {pp_in!r}")
        object.__setattr__(self, "focal_px", focal_px)
        object.__setattr__(self, "cam_from_world_rotation", R)
        object.__setattr__(self, "cam_from_world_translation", t)
        object.__setattr__(self, "principal_point", pp)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Camera):
            return NotImplemented
        return (
            self.focal_px == other.focal_px
            and self.principal_point == other.principal_point
            and bool(np.array_equal(self.cam_from_world_rotation, other.cam_from_world_rotation))
            and self.distortion == other.distortion
            and bool(
                np.array_equal(self.cam_from_world_translation, other.cam_from_world_translation)
            )
        )

    def __hash__(self) -> int:
        return hash(
            (
                self.focal_px,
                self.principal_point,
                self.cam_from_world_rotation.tobytes(),
                self.cam_from_world_translation.tobytes(),
            )
        )

    # ----------------------------------------------------------------- factories
    @classmethod
    def from_center(
        cls,
        focal_px: float,
        principal_point: tuple[float, float],
        cam_from_world_rotation: npt.ArrayLike,
        center_in_world: npt.ArrayLike,
    ) -> Camera:
        """Build a camera from its centre in the world frame instead of ``t``."""
        R = _rows(cam_from_world_rotation, 3, "cam_from_world_rotation")
        c = _rows(center_in_world, 3, "center_in_world")
        if R.shape != (3, 3) or c.shape != (3,):
            raise InputError(
                f"cam_from_world_rotation must be 3x3 and center_in_world 3 numbers, got shapes "
                f"{R.shape} and {c.shape}"
            )
        return cls(focal_px, principal_point, R, -R @ c)

    # ---------------------------------------------------------------- properties
    @property
    def img_from_cam(self) -> FloatArray:
        """The intrinsic matrix ``K``."""
        cx, cy = self.principal_point
        f = self.focal_px
        return np.array([[f, 0.0, cx], [0.0, f, cy], [0.0, 0.0, 1.0]])

    @property
    def cam_from_img(self) -> FloatArray:
        """``K⁻¹``: pixels (homogeneous) to viewing rays in the camera frame."""
        cx, cy = self.principal_point
        f = self.focal_px
        return np.array([[1.0 / f, 0.0, -cx / f], [0.0, 1.0 / f, -cy / f], [0.0, 0.0, 1.0]])

    @property
    def cam_from_world(self) -> FloatArray:
        """The 3×4 matrix ``[R | t]``."""
        return np.column_stack([self.cam_from_world_rotation, self.cam_from_world_translation])

    @property
    def img_from_world(self) -> FloatArray:
        """The 3×4 projection matrix ``K [R | t]``."""
        return self.img_from_cam @ self.cam_from_world

    @property
    def center_in_world(self) -> FloatArray:
        """Camera centre in the world frame, ``-Rᵀ t``."""
        R = self.cam_from_world_rotation
        return np.asarray(-R.T @ self.cam_from_world_translation, dtype=np.float64)

    @property
    def height_m(self) -> float:
        """Height of the camera centre above the ground plane z = 0."""
        return float(self.center_in_world[2])

    @property
    def angles_deg(self) -> tuple[float, float, float]:
        """``(heading, pitch, roll)`` in degrees; see the module conventions."""
        return angles_from_rotation(self.cam_from_world_rotation)

    def horizon_line(self) -> FloatArray:
        """The horizon as a homogeneous image line ``(a, b, c)``, ``a x + b y + c = 0``.

        Scaled so that ``a x + b y + c > 0`` below the horizon (on the ground side).
        """
        # Image of the plane through the camera centre parallel to the ground: K⁻ᵀ R up.
        line = self.cam_from_img.T @ (self.cam_from_world_rotation @ _UP)
        # Ground pixels have rays with negative world z: flip so that ground is positive.
        return np.asarray(-line / np.linalg.norm(line[:2]), dtype=np.float64)

    # ------------------------------------------------------------------ mappings
    def project(self, points_in_world: npt.ArrayLike) -> FloatArray:
        """Project world points to pixels.

        Parameters
        ----------
        points_in_world
            ``(3,)`` or ``(N, 3)`` metres.

        Returns
        -------
        ``(2,)`` or ``(N, 2)`` pixels; NaN rows for points at or behind the camera plane.
        """
        pts = _rows(points_in_world, 3, "points_in_world")
        single = pts.ndim == 1
        pts = pts.reshape(-1, 3)
        points_in_cam = pts @ self.cam_from_world_rotation.T + self.cam_from_world_translation
        z = points_in_cam[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            uv = points_in_cam[:, :2] / z[:, None]
        uv = uv * self.focal_px + np.asarray(self.principal_point)
        uv[z <= 1e-12] = np.nan
        if self.distortion is not None:
            uv = distort_points_px(uv, self.distortion, self.principal_point)
        return uv[0] if single else uv

    def rays_in_world(self, pixels: npt.ArrayLike) -> FloatArray:
        """Unit viewing directions, in the world frame, of ``(2,)`` or ``(N, 2)`` pixels."""
        px = _rows(pixels, 2, "pixels")
        single = px.ndim == 1
        px = px.reshape(-1, 2)
        if self.distortion is not None:
            px = undistort_points_px(px, self.distortion, self.principal_point)
        rays_in_cam = np.column_stack([px, np.ones(len(px))]) @ self.cam_from_img.T
        rays = rays_in_cam @ self.cam_from_world_rotation  # Rᵀ applied to each row
        rays /= np.linalg.norm(rays, axis=1, keepdims=True)
        return rays[0] if single else rays

    def ground_from_pixels(
        self,
        pixels: npt.ArrayLike,
        *,
        ground_z_m: float = 0.0,
        above_horizon: HorizonPolicy = "nan",
    ) -> FloatArray:
        """Cast pixels onto the horizontal plane ``z = ground_z_m``.

        Parameters
        ----------
        pixels
            ``(2,)`` or ``(N, 2)`` image pixels.
        ground_z_m
            Height of the plane, metres (0 = the ground).
        above_horizon
            ``"nan"``: pixels whose ray does not reach the plane in front of the camera give
            NaN rows; ``"error"``: raise :class:`DegenerateGeometryError` naming them.

        Returns
        -------
        ``(3,)`` or ``(N, 3)`` world points with z = ``ground_z_m``.
        """
        px = _rows(pixels, 2, "pixels")
        single = px.ndim == 1
        rays = self.rays_in_world(px.reshape(-1, 2)).reshape(-1, 3)
        center = self.center_in_world
        dz = ground_z_m - center[2]
        with np.errstate(divide="ignore", invalid="ignore"):
            lam = dz / rays[:, 2]
        bad = ~np.isfinite(lam) | (lam <= 0) | (np.abs(rays[:, 2]) < _GROUND_EPS)
        if np.any(bad) and above_horizon == "error":
            first = np.asarray(px.reshape(-1, 2)[bad][0]).tolist()
            raise DegenerateGeometryError(
                f"pixel {first} is at or above the horizon: its ray never meets the plane "
                f"z = {ground_z_m} m in front of the camera"
            )
        lam = np.where(bad, np.nan, lam)  # inf x 0 would warn for rays exactly on the horizon
        points = center + lam[:, None] * rays
        return points[0] if single else points

    def height_on_vertical(
        self,
        foot_pixel: npt.ArrayLike,
        top_pixel: npt.ArrayLike,
        *,
        above_horizon: HorizonPolicy = "error",
    ) -> float:
        """Height of a point on the vertical line standing on a ground pixel.

        The foot pixel is cast onto the ground; the top pixel's ray is intersected (in the
        least-squares sense) with the vertical line through that ground point. This is the
        paper's virtual clinometer.

        Returns
        -------
        Height above the ground, metres.
        """
        foot = self.ground_from_pixels(np.asarray(foot_pixel, float), above_horizon=above_horizon)
        if not np.all(np.isfinite(foot)):
            return math.nan
        return float(self.point_on_vertical(foot[:2], top_pixel)[2])

    def point_on_vertical(self, ground_xy: npt.ArrayLike, pixel: npt.ArrayLike) -> FloatArray:
        """World point on the vertical line through ``ground_xy`` closest to a pixel's ray."""
        c = self.center_in_world
        d = self.rays_in_world(np.asarray(pixel, float))
        g = np.array([*np.asarray(ground_xy, float)[:2], 0.0])
        # Closest points between the ray c + s d and the line g + h z.
        A = np.array([[d @ d, -(d @ _UP)], [d @ _UP, -(_UP @ _UP)]])
        b = np.array([(g - c) @ d, (g - c) @ _UP])
        try:
            _s, h = np.linalg.solve(A, b)
        except np.linalg.LinAlgError as exc:
            raise DegenerateGeometryError("the pixel's ray is parallel to the vertical") from exc
        return np.asarray(g + h * _UP, dtype=np.float64)

    def to_dict(self) -> dict[str, object]:
        """JSON-ready description (lists of floats)."""
        heading, pitch, roll = self.angles_deg
        return {
            "focal_px": self.focal_px,
            "principal_point": list(self.principal_point),
            "cam_from_world": self.cam_from_world.tolist(),
            "camera_in_world": self.center_in_world.tolist(),
            "height_m": self.height_m,
            "heading_deg": heading,
            "pitch_deg": pitch,
            "roll_deg": roll,
        }


def clip_segment_to_image(
    p: FloatArray, q: FloatArray, w: float, h: float, m: float = 0.0
) -> FloatArray | None:
    """Clip a 2-D segment to ``[-m, w + m] × [-m, h + m]`` (shapely's ``clip_by_rect``).

    Returns the clipped segment as a (2, 2) array of endpoints, in the direction from ``p``
    to ``q``, or None when it misses the rectangle (or only touches it at a point).
    """
    import shapely
    from shapely.geometry import LineString

    a = np.asarray(p, dtype=np.float64)
    b = np.asarray(q, dtype=np.float64)
    lo, hi = (-m, -m), (w + m, h + m)
    if np.array_equal(a, b):
        inside = lo[0] <= a[0] <= hi[0] and lo[1] <= a[1] <= hi[1]
        return np.array([a, b]) if inside else None
    clipped = shapely.clip_by_rect(LineString([a, b]), lo[0], lo[1], hi[0], hi[1])
    if clipped.is_empty or clipped.geom_type != "LineString":
        return None
    coords = np.asarray(clipped.coords, dtype=np.float64)
    ends = np.array([coords[0], coords[-1]])
    d = b - a
    if float((ends[1] - ends[0]) @ d) < 0:  # keep the direction p → q
        ends = ends[::-1]
    return ends
