"""Synthetic handheld street photos with known calibration (issue 24's scene class).

A person stands on a street between two rows of facades and takes a photo down it with a
phone. Drawn with numpy and OpenCV (no other dependency), with exact truth: focal length,
principal point, gravity in the camera frame and the lens distortion.

The street (world frame: x along the street, y to its left, z up, metres):

- a road 6-12 m wide with a dashed centre line and kerbs (a lit kerb face 0.12 m high),
  pavements 1.5-4 m wide with paving joints (along and across the street, some irregular);
- a row of facades on each side, buildings 6-16 m wide and 7-22 m high, a few set back
  by up to half a metre, with storey lines (cornices), windows (a frame and a dark pane),
  doors, now and then a gable whose roof slopes are lines in no principal direction;
- with a chance, a side street: a gap in one row, with the buildings' side walls (lines
  across the street: a second finite horizontal direction when the camera turns);
- parked cars as two boxes (body and cabin) along the kerbs, turned up to 4 degrees;
- trees on the pavements (a trunk that leans up to 3 degrees, a round crown that hides the
  facades behind it) and shadows on the ground (tree crowns and one cast by the facades,
  edges in no principal direction);
- a building across the far end of the street on some photos.

The camera: 1.4-1.8 m above the ground, anywhere across the street, looking down it. Half
the photos are level cameras looking straight down the street (yaw 0-4 degrees either way,
pitch within 2 degrees: issue 24's hardest case, where only the street's vanishing point is
finite), the other half turned 4-25 degrees with a pitch from 5 degrees down to 10 up; roll
within 2 degrees, focal length 0.7-1.3 times the longer side (log-uniform), the principal point up
to 1.5 % of each side off the centre, barrel to mild pincushion distortion (division model
``k1`` in [-0.06, 0.02], radius half the image diagonal about the principal point, as
:class:`camloc_geo.camera.RadialDistortion`), Gaussian noise and a JPEG round trip
(quality 75-92). Sizes 1024x768 (half of the photos), 1024x576 (16:9), 800x600, 1280x720.

Drawn where :class:`camloc_geo.camera.Camera` projects (pixel ``(x, y)`` is the square
``[x, x + 1] x [y, y + 1]``): polygons with exact coverage
(:func:`camloc_geo.testing.traffic_render._coverage`; lines as bands 1-6 px wide with
square ends, tree crowns as 64-gons). Before session 37 everything was drawn in OpenCV's
convention (which centres pixel ``(x, y)`` at ``(x, y)``):
half a pixel right and low, fills ~0.7 px larger on every side, lines 0.2-0.5 px low.

Shortcuts (name them where the figures are quoted): painter's algorithm by distance (no
depth buffer; a car or tree is drawn whole over what lies behind it), no perspective
texture on the surfaces (flat colours with per-pixel noise), tree crowns are drawn as
image-space ellipses, no sky clutter (wires, lamps, signs), no people. Overhead wires can be
drawn over a photo afterwards (:func:`with_overhead_wires`, for tests and the wired benchmark
run).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from camloc_geo.camera import RadialDistortion, rotation_from_angles, undistort_points_px

__all__ = ["DEV_SEEDS", "HELD_OUT_SEEDS", "StreetPhoto", "render_street_photo"]

FloatArray = npt.NDArray[np.float64]

#: Seeds of the development photos (read, tuned on) and of the held-out ones (run once at
#: the end). Fixed before any result was seen.
DEV_SEEDS = range(0, 40)
HELD_OUT_SEEDS = range(5000, 5040)

_SIZES = ((1024, 768), (1024, 768), (1024, 576), (800, 600), (1280, 720))
_NEAR_M = 0.05


@dataclass(frozen=True)
class StreetPhoto:
    """One rendered street photo and its truth.

    Attributes
    ----------
    image
        ``(H, W, 3)`` BGR, 8 bits, after the JPEG round trip.
    focal_px
        True focal length, pixels.
    principal_point
        True principal point ``(cx, cy)``, pixels.
    up_in_cam
        World up in the camera frame (x right, y down, z forward).
    k1
        True division-model distortion (radius: half the image diagonal).
    yaw_deg, pitch_up_deg, roll_deg
        The camera's turn from the street's direction, its tilt above the horizon
        (positive looking up) and roll, degrees.
    height_m
        Camera height above the road, metres.
    """

    image: npt.NDArray[np.uint8]
    focal_px: float
    principal_point: tuple[float, float]
    up_in_cam: FloatArray
    k1: float
    yaw_deg: float
    pitch_up_deg: float
    roll_deg: float
    height_m: float

    @property
    def size(self) -> tuple[int, int]:
        """``(width, height)`` in pixels."""
        return int(self.image.shape[1]), int(self.image.shape[0])


class _Canvas:
    """Projects world polygons and lines into a pinhole image and draws them."""

    def __init__(
        self, R: FloatArray, C: FloatArray, f: float, pp: tuple[float, float], size: tuple[int, int]
    ) -> None:
        self.R, self.C, self.f, self.pp = R, C, f, np.asarray(pp, float)
        w, h = size
        self.img = np.zeros((h, w, 3), np.float64)

    def cam(self, pts_w: FloatArray) -> FloatArray:
        return np.asarray((np.asarray(pts_w, float) - self.C) @ self.R.T, np.float64)

    def _clip(self, pc: FloatArray) -> FloatArray:
        """Sutherland-Hodgman clip of a closed polygon (camera frame) to ``z >= near``."""
        out = []
        n = len(pc)
        for i in range(n):
            a, b = pc[i], pc[(i + 1) % n]
            ina, inb = a[2] >= _NEAR_M, b[2] >= _NEAR_M
            if ina:
                out.append(a)
            if ina != inb:
                t = (_NEAR_M - a[2]) / (b[2] - a[2])
                out.append(a + t * (b - a))
        return np.array(out) if out else np.zeros((0, 3))

    def _px(self, pc: FloatArray) -> FloatArray:
        return np.asarray(self.f * pc[:, :2] / pc[:, 2:3] + self.pp, np.float64)

    def poly(self, pts_w: Any, colour: Any) -> None:
        pc = self._clip(self.cam(np.asarray(pts_w, float)))
        if len(pc) < 3:
            return
        px = self._px(pc)
        if not np.all(np.isfinite(px)) or np.abs(px).max() > 1e6:
            return
        self._fill(px, colour)

    def _fill(self, px: FloatArray, colour: Any) -> None:
        """Blend a convex image polygon in with its exact coverage, Camera's pixel
        convention (pixel ``(x, y)`` is ``[x, x + 1] x [y, y + 1]``)."""
        from camloc_geo.testing.traffic_render import _coverage

        h, w = self.img.shape[:2]
        lo = np.clip(np.floor(px.min(axis=0)).astype(int) - 1, 0, [w, h])
        hi = np.clip(np.ceil(px.max(axis=0)).astype(int) + 1, 0, [w, h])
        if np.any(hi <= lo):
            return
        x0, y0 = int(lo[0]), int(lo[1])
        cov = _coverage(px, x0, y0, int(hi[0] - x0), int(hi[1] - y0))[..., None]
        roi = self.img[y0 : int(hi[1]), x0 : int(hi[0])]
        roi[:] = roi * (1.0 - cov) + cov * np.asarray(colour, float)

    def line(self, a_w: Any, b_w: Any, colour: Any, width_m: float) -> None:
        """A straight band ``thick`` px wide (1-6, from ``width_m`` at its nearest end)
        about the projected segment, square ends, drawn by :meth:`_fill`."""
        pc = self.cam(np.array([a_w, b_w], float))
        if pc[0, 2] < _NEAR_M and pc[1, 2] < _NEAR_M:
            return
        for i in (0, 1):
            if pc[i, 2] < _NEAR_M:
                o = pc[1 - i]
                t = (_NEAR_M - o[2]) / (pc[i, 2] - o[2])
                pc[i] = o + t * (pc[i] - o)
        px = self._px(pc)
        if not np.all(np.isfinite(px)):
            return
        z = float(pc[:, 2].min())
        thick = max(1, round(self.f * width_m / max(z, 0.5)))
        thick = min(thick, 6)
        # clip the segment to the image and a margin (Liang-Barsky)
        h, w = self.img.shape[:2]
        a, d = px[0], px[1] - px[0]
        t0, t1 = 0.0, 1.0
        for k, lim in ((0, w), (1, h)):
            for p_k, q_k in ((-d[k], a[k] + 8.0), (d[k], lim + 8.0 - a[k])):
                if abs(p_k) < 1e-12:
                    if q_k < 0:
                        return
                    continue
                r = q_k / p_k
                if p_k < 0:
                    t0 = max(t0, r)
                else:
                    t1 = min(t1, r)
        length = float(np.hypot(d[0], d[1]))
        if t1 <= t0 or length < 1e-9:
            return
        a, b = a + t0 * d, a + t1 * d
        n = np.array([-d[1], d[0]]) / length * (thick / 2)
        self._fill(np.array([a + n, b + n, b - n, a - n]), colour)

    def ellipse(self, centre_w: Any, radius_m: float, colour: Any) -> None:
        """An upright image ellipse (a 64-gon) about the projected centre, ``radius_m``
        wide and 0.85 of that high at its depth, drawn by :meth:`_fill`."""
        pc = self.cam(np.array([centre_w], float))
        if pc[0, 2] < 1.0:
            return
        px = self._px(pc)[0]
        r = self.f * radius_m / pc[0, 2]
        if r < 1 or np.abs(px).max() > 1e5:
            return
        t = np.linspace(0.0, 2.0 * np.pi, 64, endpoint=False)
        self._fill(px + np.column_stack([r * np.cos(t), 0.85 * r * np.sin(t)]), colour)


def _box(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float) -> list[FloatArray]:
    """The six faces of an axis-aligned box, each a ``(4, 3)`` array."""
    c = np.array([[x, y, z] for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)])
    faces = ((0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4), (1, 3, 7, 5))
    return [c[list(f)] for f in faces]


def _shade(colour: Any, factor: float) -> tuple[float, float, float]:
    return tuple(float(np.clip(c * factor, 0, 255)) for c in colour)  # type: ignore[return-value]


def _facade_colour(rng: np.random.Generator) -> tuple[float, float, float]:
    base = rng.choice([[200, 205, 215], [150, 170, 190], [120, 140, 170], [180, 190, 160]])
    return tuple(float(c) for c in np.clip(base + rng.normal(0, 18, 3), 40, 240))  # type: ignore[return-value]


def _draw_facade_row(
    cv: _Canvas, rng: np.random.Generator, side: int, y_face: float, x_end: float, gap: Any
) -> list[tuple[float, Any]]:
    """Facades along ``y = y_face`` (``side`` +1 left, -1 right); draw calls with distances."""
    calls: list[tuple[float, Any]] = []
    x = -30.0
    while x < x_end:
        width = float(rng.uniform(6, 16))
        if gap is not None and gap[0] < x + width and x < gap[1]:
            # a side street: the buildings' side walls, across the street
            for xs in (gap[0], gap[1]):
                height = float(rng.uniform(7, 18))
                col = _shade(_facade_colour(rng), 0.8)
                wall = np.array(
                    [
                        [xs, y_face, 0],
                        [xs, y_face + side * 25, 0],
                        [xs, y_face + side * 25, height],
                        [xs, y_face, height],
                    ]
                )
                d = float(np.linalg.norm(wall.mean(0) - cv.C))
                calls.append((d, (cv.poly, wall, col)))
                for k in range(1, int(height // 3.2) + 1):
                    zk = 3.2 * k
                    calls.append(
                        (
                            d - 0.01,
                            (
                                cv.line,
                                (xs, y_face, zk),
                                (xs, y_face + side * 25, zk),
                                _shade(col, 0.7),
                                0.12,
                            ),
                        )
                    )
            x = gap[1]
            continue
        setback = float(rng.choice([0.0, 0.0, 0.0, rng.uniform(0.1, 0.5)]))
        y = y_face + side * setback
        height = float(rng.uniform(7, 22))
        col = _facade_colour(rng)
        x0, x1 = x, x + width
        face = np.array([[x0, y, 0], [x1, y, 0], [x1, y, height], [x0, y, height]])
        d = float(np.linalg.norm(face.mean(0) - cv.C))
        items: list[tuple[Any, ...]] = [(cv.poly, face, col)]
        if setback > 0:  # the returns of a set-back facade
            for xe in (x0, x1):
                ret = np.array([[xe, y_face, 0], [xe, y, 0], [xe, y, height], [xe, y_face, height]])
                items.append((cv.poly, ret, _shade(col, 0.75)))
        if rng.random() < 0.3:  # a gable: roof slopes in the facade's plane
            top = height + float(rng.uniform(2, 5))
            tri = np.array([[x0, y, height], [x1, y, height], [(x0 + x1) / 2, y, top]])
            items.append((cv.poly, tri, _shade(col, 0.6)))
        storey = float(rng.uniform(2.9, 3.6))
        n_storeys = int(height // storey)
        line_col = _shade(col, float(rng.choice([0.6, 0.8, 1.15])))
        for k in range(1, n_storeys + 1):  # storey lines (cornices)
            zk = k * storey - 0.1
            if rng.random() < 0.7:
                items.append((cv.line, (x0, y, zk), (x1, y, zk), line_col, 0.15))
        pitch_w = float(rng.uniform(2.4, 3.6))
        win_w = float(rng.uniform(0.9, 1.5))
        win_h = float(rng.uniform(1.3, 1.9))
        pane = _shade((60, 60, 70), float(rng.uniform(0.6, 1.6)))
        frame = _shade(col, 1.2)
        n_win = max(1, int((width - 1.0) // pitch_w))
        margin = (width - n_win * pitch_w) / 2
        for k in range(n_storeys):
            zb = k * storey + (storey - win_h) * 0.55
            for j in range(n_win):
                xa = x0 + margin + j * pitch_w + (pitch_w - win_w) / 2
                if k == 0 and j == n_win // 2:  # a door
                    door = np.array(
                        [[xa, y, 0], [xa + win_w, y, 0], [xa + win_w, y, 2.2], [xa, y, 2.2]]
                    )
                    items.append((cv.poly, door, _shade(col, 0.35)))
                    continue
                if k == 0:
                    rng.random()  # (a draw kept: the seeds' photos stay as they were)
                fr = np.array(
                    [
                        [xa - 0.08, y, zb - 0.08],
                        [xa + win_w + 0.08, y, zb - 0.08],
                        [xa + win_w + 0.08, y, zb + win_h + 0.08],
                        [xa - 0.08, y, zb + win_h + 0.08],
                    ]
                )
                items.append((cv.poly, fr, frame))
                win = np.array(
                    [
                        [xa, y, zb],
                        [xa + win_w, y, zb],
                        [xa + win_w, y, zb + win_h],
                        [xa, y, zb + win_h],
                    ]
                )
                items.append((cv.poly, win, pane))
        calls.append((d, ("group", items)))
        x = x1
    return calls


def render_street_photo(seed: int, focal_rel: float | None = None) -> StreetPhoto:
    """Draw the street photo of ``seed`` (the same seed gives the same photo).

    Parameters
    ----------
    seed
        Seed of the photo's random generator.
    focal_rel
        If given, the focal length in longer sides (e.g. 0.97 for issue 24's phone),
        instead of the seed's draw; everything else stays the seed's.

    Returns
    -------
    StreetPhoto
        The photo and its truth.
    """
    import cv2

    rng = np.random.default_rng([seed, 24])
    w, h = _SIZES[int(rng.integers(len(_SIZES)))]
    long_px = max(w, h)
    f = long_px * float(math.exp(rng.uniform(math.log(0.7), math.log(1.3))))
    if focal_rel is not None:
        if not (math.isfinite(focal_rel) and 0.2 <= focal_rel <= 5.0):
            raise ValueError(f"focal_rel must be within 0.2-5 longer sides, got {focal_rel}")
        f = long_px * float(focal_rel)
    pp = (
        w / 2 + float(rng.uniform(-0.015, 0.015)) * w,
        h / 2 + float(rng.uniform(-0.015, 0.015)) * h,
    )
    k1 = float(rng.uniform(-0.06, 0.02))
    road_w = float(rng.uniform(6, 12))
    pave_w = float(rng.uniform(1.5, 4.0))
    y_face = road_w / 2 + pave_w
    cam_y = float(rng.uniform(-1, 1)) * (road_w / 2 + 0.5 * pave_w)
    on_pavement = abs(cam_y) > road_w / 2
    height = float(rng.uniform(1.4, 1.8)) + (0.12 if on_pavement else 0.0)
    # half the photos are the hard case: a level camera looking straight down the street
    level = bool(rng.random() < 0.5)
    yaw = float(rng.choice([-1, 1]) * (rng.uniform(0, 4) if level else rng.uniform(4, 25)))
    pitch_up = float(rng.uniform(-2, 2) if level else rng.uniform(-5, 10))
    roll = float(rng.uniform(-2, 2))
    # heading clockwise from +y: +x (down the street) is 90; yaw > 0 turns left
    R = rotation_from_angles(90.0 - yaw, -pitch_up, roll)
    C = np.array([0.0, cam_y, height])
    cv = _Canvas(R, C, f, pp, (w, h))

    # sky: a vertical gradient (drawn directly in the image)
    sky_top, sky_low = np.array([215.0, 170, 120]), np.array([235.0, 220, 205])
    tt = np.linspace(0, 1, h)[:, None, None]
    cv.img[:] = sky_top * (1 - tt) + sky_low * tt
    x_end = float(rng.uniform(120, 250))
    kerb_h = 0.12
    road_col = _shade((95, 95, 98), float(rng.uniform(0.8, 1.2)))
    pave_col = _shade((150, 155, 160), float(rng.uniform(0.8, 1.15)))
    cv.poly(
        [
            [-5, -road_w / 2, 0],
            [x_end, -road_w / 2, 0],
            [x_end, road_w / 2, 0],
            [-5, road_w / 2, 0],
        ],
        road_col,
    )
    for side in (1, -1):
        y0, y1 = side * road_w / 2, side * (y_face + 0.5)
        cv.poly(
            [[-5, y0, kerb_h], [x_end, y0, kerb_h], [x_end, y1, kerb_h], [-5, y1, kerb_h]], pave_col
        )
        # the kerb's face
        cv.poly(
            [[-5, y0, 0], [x_end, y0, 0], [x_end, y0, kerb_h], [-5, y0, kerb_h]],
            _shade(pave_col, 1.15),
        )
    # paving joints
    joint_col = _shade(pave_col, 0.75)
    step = float(rng.uniform(0.6, 1.5))
    for side in (1, -1):
        ya, yb = side * road_w / 2, side * y_face
        for xj in np.arange(-2.0, 40.0, step):
            skew = float(rng.normal(0, 0.05)) if rng.random() < 0.3 else 0.0
            cv.line((xj, ya, kerb_h), (xj + skew * pave_w, yb, kerb_h), joint_col, 0.02)
        for yj in np.arange(min(ya, yb) + step, max(ya, yb), step):
            cv.line((-2, yj, kerb_h), (40, yj, kerb_h), joint_col, 0.02)
    # centre line, dashed; a crossing's stripes on some photos
    mark = (225.0, 225, 225)
    for xd in np.arange(2.0, x_end, 9.0):
        cv.poly([[xd, -0.06, 0], [xd + 3, -0.06, 0], [xd + 3, 0.06, 0], [xd, 0.06, 0]], mark)
    if rng.random() < 0.35:
        xc = float(rng.uniform(10, 30))
        for yz in np.arange(-road_w / 2 + 0.3, road_w / 2 - 0.3, 1.0):
            cv.poly([[xc, yz, 0], [xc + 3, yz, 0], [xc + 3, yz + 0.5, 0], [xc, yz + 0.5, 0]], mark)
    # shadows on the ground: facades' cast shadow (slanted edge) and tree crowns
    sun_side = int(rng.choice([-1, 1]))
    slant = float(rng.uniform(0.2, 1.2))
    x_sh = float(rng.uniform(5, 40))
    sh_w = float(rng.uniform(1, road_w))
    ys = sun_side * y_face
    ground = [
        [x_sh, ys, 0.01],
        [x_end, ys, 0.01],
        [x_end, ys - sun_side * sh_w, 0.01],
        [x_sh + slant * sh_w * 3, ys - sun_side * sh_w, 0.01],
    ]
    shadow_layer = _Canvas(R, C, f, pp, (w, h))
    shadow_layer.poly(ground, (1.0, 1.0, 1.0))

    calls: list[tuple[float, Any]] = []
    for side in (1, -1):
        gap = None
        if rng.random() < 0.4:
            g0 = float(rng.uniform(15, 60))
            gap = (g0, g0 + float(rng.uniform(8, 14)))
        calls += _draw_facade_row(cv, rng, side, side * y_face, x_end, gap)
    if rng.random() < 0.5:  # a building across the far end
        hh = float(rng.uniform(10, 25))
        end = np.array(
            [
                [x_end, -y_face - 20, 0],
                [x_end, y_face + 20, 0],
                [x_end, y_face + 20, hh],
                [x_end, -y_face - 20, hh],
            ]
        )
        calls.append((1e6, (cv.poly, end, _facade_colour(rng))))
    # parked cars
    for side in (1, -1):
        xc = float(rng.uniform(3, 10))
        while xc < 80:
            if rng.random() < 0.6:
                yc = side * (road_w / 2 - 1.1)
                length, width = float(rng.uniform(3.9, 4.8)), 1.8
                turn = math.radians(float(rng.uniform(-4, 4)))
                col = _shade(
                    rng.choice(
                        [
                            [220, 220, 225],
                            [40, 40, 45],
                            [160, 160, 160],
                            [40, 40, 170],
                            [150, 80, 30],
                        ]
                    ),
                    1.0,
                )
                rot = np.array(
                    [
                        [math.cos(turn), -math.sin(turn), 0],
                        [math.sin(turn), math.cos(turn), 0],
                        [0, 0, 1],
                    ]
                )
                body = _box(-length / 2, length / 2, -width / 2, width / 2, 0.25, 0.95)
                cabin = _box(-length / 4, length / 5, -width / 2 + 0.1, width / 2 - 0.1, 0.95, 1.45)
                centre = np.array([xc, yc, 0.0])
                items: list[tuple[Any, ...]] = []
                under = np.array(
                    [
                        [-length / 2, -width / 2, 0.01],
                        [length / 2, -width / 2, 0.01],
                        [length / 2, width / 2, 0.01],
                        [-length / 2, width / 2, 0.01],
                    ]
                )
                items.append((cv.poly, under @ rot.T + centre, (30.0, 30, 32)))
                for fi, face in enumerate(body):
                    fw = face @ rot.T + centre
                    items.append((cv.poly, fw, _shade(col, 0.6 + 0.1 * fi)))
                for fi, face in enumerate(cabin):
                    fw = face @ rot.T + centre
                    items.append((cv.poly, fw, (70.0, 60, 55) if fi < 4 else _shade(col, 0.9)))
                d = float(np.linalg.norm(centre - C))
                # draw the faces nearest last within the car
                by_distance = sorted(
                    items[1:], key=lambda it: -float(np.linalg.norm(np.mean(it[1], 0) - C))
                )
                items_sorted = [items[0], *by_distance]
                calls.append((d, ("group", items_sorted)))
            xc += float(rng.uniform(5, 9))
    # trees
    n_trees = int(rng.integers(0, 7))
    tree_calls: list[tuple[float, Any]] = []
    for _ in range(n_trees):
        side = int(rng.choice([-1, 1]))
        xt = float(rng.uniform(4, 60))
        yt = side * (road_w / 2 + min(0.8, pave_w / 2))
        lean = np.radians(rng.uniform(-3, 3, 2))
        top = np.array([xt + 3 * math.sin(lean[0]), yt + 3 * math.sin(lean[1]), 3.0])
        crown_r = float(rng.uniform(1.5, 3.0))
        crown_col = _shade((50, 110, 60), float(rng.uniform(0.6, 1.2)))
        d = float(np.linalg.norm(np.array([xt, yt, 2]) - C))
        items = [
            (cv.line, (xt, yt, kerb_h), tuple(top), (40.0, 55, 70), 0.3),
            (cv.ellipse, tuple(top + np.array([0.0, 0.0, crown_r * 0.8])), crown_r, crown_col),
        ]
        tree_calls.append((d, ("group", items)))
        shadow_layer.ellipse((xt + 1.0, yt - sun_side * 1.5, 0.0), crown_r, (1.0, 1.0, 1.0))
    # the ground's shadows darken what is drawn so far (the ground)
    cv.img *= 1.0 - 0.45 * shadow_layer.img
    for _d, call in sorted(calls + tree_calls, key=lambda c: -c[0]):
        if call[0] == "group":
            for item in call[1]:
                item[0](*item[1:])
        else:
            call[0](*call[1:])

    # texture noise, lens distortion, blur, sensor noise, JPEG
    img: Any = cv.img + rng.normal(0, 3.0, cv.img.shape)
    if k1 != 0.0:
        gx, gy = np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64))
        grid = np.stack([np.ravel(gx), np.ravel(gy)], 1)
        und = undistort_points_px(grid, RadialDistortion.for_image(k1, w, h), pp)
        mx = und[:, 0].reshape(h, w).astype(np.float32)
        my = und[:, 1].reshape(h, w).astype(np.float32)
        img = cv2.remap(
            img.astype(np.float32), mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT
        )
    img = cv2.GaussianBlur(np.asarray(img, np.float32), (0, 0), 0.6)
    img = img + rng.normal(0, 2.0, img.shape)
    img8: Any = np.clip(np.rint(img), 0, 255).astype(np.uint8)
    quality = int(rng.integers(75, 93))
    ok, buf = cv2.imencode(".jpg", img8, [cv2.IMWRITE_JPEG_QUALITY, quality])
    if not ok:
        raise RuntimeError("cannot encode the rendered street photo as JPEG")
    img8 = cv2.imdecode(buf, cv2.IMREAD_COLOR)
    up = R @ np.array([0.0, 0.0, 1.0])
    return StreetPhoto(
        image=np.ascontiguousarray(img8),
        focal_px=f,
        principal_point=pp,
        up_in_cam=np.asarray(up, np.float64),
        k1=k1,
        yaw_deg=yaw,
        pitch_up_deg=pitch_up,
        roll_deg=roll,
        height_m=height,
    )


def with_overhead_wires(
    photo: StreetPhoto,
    n_wires: int = 8,
    vp_offset_rel: float = 1.5,
    y_range_px: tuple[float, float] = (20.0, 200.0),
    grey: int = 60,
    width_px: int = 2,
) -> npt.NDArray[np.uint8]:
    """The photo with overhead wires drawn across its top: thin dark lines (``width_px``
    wide, anti-aliased), horizontal in the world and in no principal direction of the
    street, so they meet on the true horizon ``vp_offset_rel`` focal lengths right of the
    principal point.

    The real street photos have them (power and tram lines: issue 24's development photo
    ``la foto.JPG``, where they posed as a principal direction); :func:`render_street_photo`
    does not draw them. Shortcut: straight (no sag), drawn over everything from the left
    edge to the right one, starting at ``y_range_px`` on the left edge, no JPEG round
    trip after them.

    Parameters
    ----------
    photo
        A rendered photo (:func:`render_street_photo`).
    n_wires
        How many wires.
    vp_offset_rel
        Where they meet on the horizon, focal lengths right of the principal point.
    y_range_px
        Their heights on the left edge, first and last (pixels).
    grey
        Their grey level.
    width_px
        Their width (pixels).

    Returns
    -------
    numpy.ndarray
        A new ``(H, W, 3)`` BGR image.
    """
    import cv2

    img = np.ascontiguousarray(photo.image.copy())
    w = img.shape[1]
    cx, cy = photo.principal_point
    up = photo.up_in_cam
    vx = cx + vp_offset_rel * photo.focal_px
    # the horizon: up . (x - cx, y - cy, f) = 0
    vy = cy - (up[0] * (vx - cx) + up[2] * photo.focal_px) / up[1]
    sub = 16  # cv2.line's fixed point: 4 fractional bits
    for k in range(n_wires):
        ya = y_range_px[0] + (y_range_px[1] - y_range_px[0]) * k / max(n_wires - 1, 1)
        yb = ya + (vy - ya) * w / vx
        # OpenCV centres pixel (x, y) at (x, y): shift from the continuous convention
        a = (round(-0.5 * sub), round((ya - 0.5) * sub))
        b = (round((w - 0.5) * sub), round((yb - 0.5) * sub))
        cv2.line(img, a, b, (grey, grey, grey), width_px, cv2.LINE_AA, shift=4)
    return img
