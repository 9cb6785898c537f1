"""The ground footprint of a camera's view (its view cone), in the local east/north frame."""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from camloc_geo.camera import Camera, undistort_points_px

__all__ = ["view_cone", "view_cones"]

FloatArray = npt.NDArray[np.float64]


@functools.lru_cache(maxsize=64)
def _border_px(size: tuple[int, int], n: int) -> FloatArray:
    """The image border, clockwise from the bottom-left corner, ``n`` steps per side.

    Cached per image size (every candidate of a scene draws the same border); read-only.
    """
    w, h = size
    border: list[tuple[float, float]] = []
    for i in range(n + 1):
        border.append((w * i / n, h))
    for i in range(n + 1):
        border.append((w, h * (1 - i / n)))
    for i in range(n + 1):
        border.append((w * (1 - i / n), 0.0))
    for i in range(n + 1):
        border.append((0.0, h * i / n))
    out = np.asarray(border, dtype=float)
    out.flags.writeable = False
    return out


def view_cone(cam: Camera, size: tuple[int, int], range_m: float) -> FloatArray:
    """Ground footprint of the view, clipped at ``range_m`` horizontally (ENU polygon).

    The camera centre, then where each ray through the image border (12 steps per side)
    meets the ground, or the point ``range_m`` away along it (a ray above the horizon, or a
    ground point farther), then the centre again.
    """
    C = cam.center_in_world
    rays = cam.rays_in_world(_border_px((size[0], size[1]), 12))
    horiz = np.array([math.hypot(x, y) for x, y in rays[:, :2].tolist()])
    keep = horiz >= 1e-9  # rays straight down or up have no direction on the ground
    rays, horiz = rays[keep], horiz[keep]
    down = rays[:, 2] < -1e-9
    dist = np.full(len(rays), math.inf)
    dist[down] = -C[2] / rays[down, 2] * horiz[down]
    dist = np.minimum(dist, range_m)
    pts = C[:2] + dist[:, None] * rays[:, :2] / horiz[:, None]
    return np.asarray(np.vstack([C[:2], pts, C[:2]]), dtype=np.float64)


def view_cones(cams: Sequence[Camera], size: tuple[int, int], range_m: float) -> list[FloatArray]:
    """:func:`view_cone` of every camera in ``cams`` (one image ``size``), in one computation.

    The same numbers, bit for bit, as one :func:`view_cone` call per camera: the rays of all
    cameras are cast in one batched matrix product and clipped together.
    """
    if not cams:
        return []
    px = _border_px((size[0], size[1]), 12)
    n_cam, n_ray = len(cams), len(px)
    if all(c.distortion is None or c.distortion.k1 == 0.0 for c in cams):
        hom = np.broadcast_to(np.column_stack([px, np.ones(n_ray)]), (n_cam, n_ray, 3))
    else:
        hom = np.stack(
            [
                np.column_stack(
                    [undistort_points_px(px, c.distortion, c.principal_point), np.ones(n_ray)]
                )
                for c in cams
            ]
        )
    img_to_cam_T = np.stack([c.cam_from_img.T for c in cams])  # as Camera.rays_in_world
    R = np.stack([c.cam_from_world_rotation for c in cams])
    centers = np.stack([c.center_in_world for c in cams])
    rays = np.matmul(np.matmul(hom, img_to_cam_T), R)
    rays /= np.linalg.norm(rays, axis=2, keepdims=True)
    # math.hypot, as view_cone takes it (np.hypot differs in the last bit on some rays)
    xs, ys = rays[:, :, 0].ravel().tolist(), rays[:, :, 1].ravel().tolist()
    horiz = np.array(list(map(math.hypot, xs, ys))).reshape(n_cam, n_ray)
    keep = horiz >= 1e-9  # rays straight down or up have no direction on the ground
    down = keep & (rays[:, :, 2] < -1e-9)
    dist = np.full((n_cam, n_ray), math.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        dist[down] = (-centers[:, 2:3] / rays[:, :, 2] * horiz)[down]
    dist = np.minimum(dist, range_m)
    safe = np.where(keep, horiz, 1.0)
    pts = centers[:, None, :2] + dist[:, :, None] * rays[:, :, :2] / safe[:, :, None]
    out: list[FloatArray] = []
    for i in range(n_cam):
        ring = np.empty((int(keep[i].sum()) + 2, 2))
        ring[0] = ring[-1] = centers[i, :2]
        ring[1:-1] = pts[i][keep[i]]
        out.append(ring)
    return out
