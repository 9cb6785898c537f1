"""The ground footprint of a camera's view (its view cone), in the local east/north frame."""

from __future__ import annotations

import functools
import math

import numpy as np
import numpy.typing as npt

from camloc_geo.camera import Camera

__all__ = ["view_cone"]

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
