"""The ground footprint of a camera's view (its view cone), in the local east/north frame."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from camloc_geo.camera import Camera

__all__ = ["view_cone"]

FloatArray = npt.NDArray[np.float64]


def view_cone(cam: Camera, size: tuple[int, int], range_m: float) -> FloatArray:
    """Ground footprint of the view, clipped at ``range_m`` horizontally (ENU polygon)."""
    w, h = size
    C = cam.center_in_world
    border: list[tuple[float, float]] = []
    n = 12
    for i in range(n + 1):
        border.append((w * i / n, h))
    for i in range(n + 1):
        border.append((w, h * (1 - i / n)))
    for i in range(n + 1):
        border.append((w * (1 - i / n), 0.0))
    for i in range(n + 1):
        border.append((0.0, h * i / n))
    rays = cam.rays_in_world(np.asarray(border, dtype=float))
    pts = [C[:2].copy()]
    for r in rays:
        horiz = math.hypot(r[0], r[1])
        if horiz < 1e-9:
            continue
        if r[2] < -1e-9:
            lam = -C[2] / r[2]
            dist = lam * horiz
        else:
            dist = math.inf
        dist = min(dist, range_m)
        pts.append(C[:2] + dist * r[:2] / horiz)
    pts.append(C[:2].copy())
    return np.asarray(pts, dtype=np.float64)
