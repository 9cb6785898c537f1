"""The 2-D similarity that carries the car's world frame onto the map's local frame."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from camloc_geo.camera import Camera

__all__ = ["Similarity2D", "rot2", "similarity_fit", "theta_for_bearing"]

FloatArray = npt.NDArray[np.float64]


def rot2(theta_rad: float) -> FloatArray:
    """2×2 rotation matrix, anticlockwise by ``theta_rad``."""
    c, s = math.cos(theta_rad), math.sin(theta_rad)
    return np.array([[c, -s], [s, c]])


def theta_for_bearing(bearing_deg: float) -> float:
    """Rotation carrying the world x axis onto a bearing (clockwise from north)."""
    return math.radians(90.0 - bearing_deg)


@dataclass(frozen=True)
class Similarity2D:
    """``p_target = scale · R(rotation_rad) · p_source + translation_m`` in the ground plane.

    Named target-from-source, e.g. ``enu_from_world``: the car's world frame (x along the
    car, z up) to the map's local east/north frame. Composable (``a.compose(b)`` applies
    ``b`` first) and invertible.

    Examples
    --------
    >>> enu_from_world = Similarity2D(math.pi / 2, np.array([10.0, 0.0]), 2.0)
    >>> enu_from_world.apply(np.array([1.0, 0.0])).round(9).tolist()
    [10.0, 2.0]
    >>> enu_from_world.inverse().apply(np.array([10.0, 2.0])).round(9).tolist()
    [1.0, 0.0]
    """

    rotation_rad: float
    translation_m: FloatArray = field(default_factory=lambda: np.zeros(2))
    scale: float = 1.0

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Similarity2D):
            return NotImplemented
        return (
            self.rotation_rad == other.rotation_rad
            and self.scale == other.scale
            and bool(np.array_equal(self.translation_m, other.translation_m))
        )

    def __hash__(self) -> int:
        return hash((self.rotation_rad, self.scale, tuple(np.asarray(self.translation_m))))

    @classmethod
    def identity(cls) -> Similarity2D:
        """The identity transform."""
        return cls(0.0, np.zeros(2), 1.0)

    @property
    def rotation(self) -> FloatArray:
        """The 2×2 rotation matrix (without the scale)."""
        return rot2(self.rotation_rad)

    @property
    def heading_deg(self) -> float:
        """Bearing (clockwise from north, [0, 360)) of the source frame's x axis."""
        return (90.0 - math.degrees(self.rotation_rad)) % 360.0

    def apply(self, points: npt.ArrayLike) -> FloatArray:
        """Transform one point ``(2,)`` or points ``(N, 2)``."""
        p = np.asarray(points, dtype=np.float64)
        if p.ndim == 1:
            return np.asarray(self.scale * self.rotation @ p + self.translation_m)
        return np.asarray(self.scale * p @ self.rotation.T + self.translation_m)

    def inverse(self) -> Similarity2D:
        """The transform back: ``inverse().apply(apply(p)) == p``."""
        inv_scale = 1.0 / self.scale
        back = rot2(-self.rotation_rad)
        return Similarity2D(
            -self.rotation_rad, -inv_scale * back @ np.asarray(self.translation_m), inv_scale
        )

    def compose(self, other: Similarity2D) -> Similarity2D:
        """``self ∘ other``: apply ``other`` first, then ``self``.

        ``a_from_c = a_from_b.compose(b_from_c)``.
        """
        return Similarity2D(
            self.rotation_rad + other.rotation_rad,
            self.apply(np.asarray(other.translation_m)),
            self.scale * other.scale,
        )

    def camera(self, camera_in_source: Camera) -> Camera:
        """A camera posed in the source frame, posed in the target frame (z kept, scaled)."""
        c, s = math.cos(self.rotation_rad), math.sin(self.rotation_rad)
        Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])  # rot2 in the xy block
        R = camera_in_source.cam_from_world_rotation @ Rz.T
        T = self.translation_m
        C = self.scale * Rz @ camera_in_source.center_in_world + np.array([T[0], T[1], 0.0])
        return Camera.from_center(camera_in_source.focal_px, camera_in_source.principal_point, R, C)


def similarity_fit(
    source: FloatArray, target: FloatArray, weights: FloatArray, scale_sigma: float
) -> Similarity2D:
    """Weighted 2-D similarity ``target_from_source`` with the scale regularised towards 1.

    Closed-form weighted Procrustes gives the rigid solution; the scale is the
    precision-weighted combination of the data's scale and the prior s = 1.
    """
    w = weights / weights.sum()
    mw = (w[:, None] * source).sum(axis=0)
    me = (w[:, None] * target).sum(axis=0)
    a = source - mw
    b = target - me
    sxx = float((w * (a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1])).sum())
    sxy = float((w * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])).sum())
    theta = math.atan2(sxy, sxx)
    var_a = float((w * (a**2).sum(axis=1)).sum())
    if var_a > 1e-12 and scale_sigma > 0:
        s_data = math.hypot(sxx, sxy) / var_a
        # Information of the data about s: sum(weights * |a|^2) in units of the weights.
        info = float((weights * (a**2).sum(axis=1)).sum())
        prior_info = 1.0 / scale_sigma**2
        s = (info * s_data + prior_info * 1.0) / (info + prior_info)
    else:
        s = 1.0
    T = me - s * rot2(theta) @ mw
    return Similarity2D(theta, T, s)
