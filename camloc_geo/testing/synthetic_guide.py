"""Synthetic people and GPS traces for the virtual guide's tests and benchmark.

People walk on the ground (``z = 0``) in a camera's view (turning back at the image's edge),
their foot pixels are projected with click noise; those with a phone log a GPS trace with
time-correlated noise (first-order autoregressive, ``gps_correlation_s``) over a slightly
longer time than they are seen. Distractor phones walk nearby without being tracked.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from camloc_geo.absolute._similarity import Similarity2D
from camloc_geo.camera import Camera
from camloc_geo.geodesy import LocalFrame
from camloc_geo.sensors.guide import GpsTrace, PixelTrack

__all__ = ["GuideData", "make_guide_data"]

FloatArray = npt.NDArray[np.float64]


@dataclass
class GuideData:
    """Tracks, traces and the truth (``truth[track id]`` = its trace id or None)."""

    tracks: list[PixelTrack]
    traces: list[GpsTrace]
    truth: dict[str, str | None]
    enu_from_world: Similarity2D
    frame: LocalFrame
    start_s: float


def _in_view(cam: Camera, xy: FloatArray, size: tuple[int, int], margin: float) -> bool:
    px = cam.project(np.array([xy[0], xy[1], 0.0]))
    if not np.all(np.isfinite(px)):
        return False
    w, h = size
    # foot pixel well below the horizon and inside the image
    return bool(margin <= px[0] <= w - margin and 0.3 * h <= px[1] <= h - margin)


def _walk(
    rng: np.random.Generator,
    start: FloatArray,
    times: FloatArray,
    ok: Callable[[FloatArray], bool],
) -> FloatArray:
    speed = float(rng.uniform(0.8, 1.6))
    heading = float(rng.uniform(0, 2 * math.pi))
    pos = [start.copy()]
    dt = float(times[1] - times[0]) if len(times) > 1 else 1.0
    for _ in times[1:]:
        for _try in range(20):
            heading += float(rng.normal(0.0, math.radians(15.0) * math.sqrt(dt)))
            nxt = pos[-1] + speed * dt * np.array([math.cos(heading), math.sin(heading)])
            if ok(nxt):
                break
            heading += math.pi + float(rng.normal(0.0, 0.5))
        else:
            nxt = pos[-1].copy()
        pos.append(nxt)
    return np.asarray(pos, dtype=np.float64)


def _gps_noise(
    rng: np.random.Generator, n: int, dt: float, sigma_m: float, correlation_s: float
) -> FloatArray:
    a = math.exp(-dt / correlation_s) if correlation_s > 0 else 0.0
    e = np.zeros((n, 2))
    e[0] = rng.normal(0.0, sigma_m, 2)
    for k in range(1, n):
        e[k] = a * e[k - 1] + math.sqrt(1 - a * a) * rng.normal(0.0, sigma_m, 2)
    return e


def make_guide_data(
    camera: Camera,
    rng: np.random.Generator,
    *,
    n_people: int = 4,
    n_without_phone: int = 0,
    n_distractors: int = 2,
    gps_sigma_m: float = 4.0,
    gps_correlation_s: float = 10.0,
    click_sigma_px: float = 2.0,
    duration_s: float = 40.0,
    fps: float = 5.0,
    gps_period_s: float = 1.0,
    image_size: tuple[int, int] = (1920, 1080),
    start_s: float = 1_767_225_600.0,
    enu_from_world: Similarity2D | None = None,
    frame: LocalFrame | None = None,
) -> GuideData:
    """People seen by ``camera`` (car world frame) and GPS traces in ``frame``.

    The first ``n_people - n_without_phone`` people carry a phone; ``n_distractors`` more
    phones walk 15-60 m from the view's centre, unseen. Each person is seen from a random
    time in the first quarter for 60-100 % of the rest; phones log from 5 s before to 5 s
    after. ``enu_from_world`` defaults to a random rotation and offset (scale 1), ``frame``
    to an anchor in Paris.
    """
    w, h = image_size
    frame = frame or LocalFrame(lat=48.8530, lon=2.3499)
    if enu_from_world is None:
        enu_from_world = Similarity2D(
            float(rng.uniform(-math.pi, math.pi)), rng.uniform(-50, 50, 2), 1.0
        )
    centre_px = np.array([w / 2, 0.75 * h])
    view_centre = camera.ground_from_pixels(centre_px)[:2]
    times = start_s + np.arange(0.0, duration_s + 1e-9, 1.0 / fps)
    cam_xy = camera.center_in_world[:2]

    def visible(xy: FloatArray) -> bool:
        return _in_view(camera, xy, image_size, 20.0) and bool(np.linalg.norm(xy - cam_xy) < 45.0)

    tracks: list[PixelTrack] = []
    traces: list[GpsTrace] = []
    truth: dict[str, str | None] = {}
    n_phone = n_people - n_without_phone

    def gps_of(gid: str, path_world: FloatArray, sel: npt.NDArray[np.bool_]) -> GpsTrace:
        step = max(1, round(gps_period_s * fps))
        idx = np.flatnonzero(sel)[::step]
        en = enu_from_world.apply(path_world[idx])
        en = en + _gps_noise(rng, len(idx), gps_period_s, gps_sigma_m, gps_correlation_s)
        return GpsTrace(gid, times[idx], frame.points_geographic_from_enu(en))

    for p in range(n_people):
        for _ in range(500):
            u, v = rng.uniform(0.1 * w, 0.9 * w), rng.uniform(0.45 * h, 0.95 * h)
            start = camera.ground_from_pixels(np.array([u, v]))[:2]
            if np.all(np.isfinite(start)) and visible(start):
                break
        path = _walk(rng, start, times, visible)
        a = float(rng.uniform(0.0, 0.25 * duration_s))
        b = a + float(rng.uniform(0.6, 1.0)) * (duration_s - a)
        rel = times - start_s
        seen = (rel >= a) & (rel <= b)
        px = camera.project(np.column_stack([path[seen], np.zeros(int(seen.sum()))]))
        px = px + rng.normal(0.0, click_sigma_px, px.shape)
        tid = f"person{p + 1}"
        tracks.append(PixelTrack(tid, times[seen], px))
        if p < n_phone:
            gid = f"phone{p + 1}"
            traces.append(gps_of(gid, path, (rel >= a - 5.0) & (rel <= b + 5.0)))
            truth[tid] = gid
        else:
            truth[tid] = None
    for d in range(n_distractors):
        ang = float(rng.uniform(0, 2 * math.pi))
        start = view_centre + float(rng.uniform(15.0, 60.0)) * np.array(
            [math.cos(ang), math.sin(ang)]
        )
        path = _walk(rng, start, times, lambda xy: True)
        traces.append(gps_of(f"other{d + 1}", path, np.ones(len(times), dtype=bool)))
    order = rng.permutation(len(traces))
    return GuideData(
        tracks, [traces[k] for k in order], truth, enu_from_world, frame, float(start_s)
    )
