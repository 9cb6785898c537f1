"""A second traffic-video generator: two-box cars and vans with ground clearance and shadows.

Independent of the virtual radar's own model (:mod:`camloc_geo.sensors.radar` fits a
cuboid standing on the ground), so tests and benchmarks built on these videos do not share
the radar's assumptions. Each vehicle is

- a **body**: a box from ``clearance_m`` (0.2 m by default) above the road up to the
  waistline, full length and width;
- a **cabin** on it: narrower and shorter than the body, its roof shorter still (slanted
  windscreens), glass all round and a roof in the body's colour; a van's cabin is nearly
  as long and as wide as its body;
- four dark **wheels** (octagons in vertical planes at the track width, inside the body's
  sides) that touch the road: the ground contact is *below* the body's lower edge;
- a dark **contact shadow** under the body and, with a sun, a hard **cast shadow**.

Faces are shaded by a sun (Lambert plus ambient light), colours vary (white, black, silver,
red, blue, and a grey as dark as the road: the hard case for background subtraction).
A pole camera 6-9 m up watches a straight street (lanes along world x, the annotated
reference car parked at the origin); the scene is that camera's annotation by 3
annotators with 1 px clicks, each also drawing one or two of the painted lane lines
(:func:`camloc_geo.testing.road_lines.street_scene`), so it calibrates to the camera up to
that noise.

Truth per frame: the image box of each vehicle wholly in view, and the world positions of
its wheel contacts. Shortcuts: painter's algorithm per vehicle (no mutual occlusion of
interpenetrating parts), no motion blur, no lens distortion.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from camloc_geo.camera import Camera, rotation_from_angles
from camloc_geo.objects import PRESETS
from camloc_geo.testing._video import write_video
from camloc_geo.testing.road_lines import street_scene

__all__ = [
    "COLOURS",
    "SHAPES",
    "RenderedVideo",
    "Shape",
    "StreetVehicle",
    "random_street",
    "render_street",
    "street_camera",
    "street_photo",
]

FloatArray = npt.NDArray[np.float64]
Box = tuple[float, float, float, float]

_SKY = (205, 195, 180)
_TYRE = (22.0, 22.0, 24.0)
_ROAD_GREY = 92.0
_SUN = np.array([0.45, -0.55, 0.70])  # direction towards the sun (world), normalised below
_SUN = _SUN / np.linalg.norm(_SUN)

COLOURS: dict[str, tuple[int, int, int]] = {  # BGR
    "white": (225, 228, 230),
    "black": (30, 30, 32),
    "silver": (165, 165, 160),
    "road_grey": (100, 98, 92),
    "red": (40, 40, 175),
    "blue": (150, 70, 30),
    "green": (60, 120, 50),
    "yellow": (40, 185, 215),
}
"""Body colours; ``road_grey`` differs from the asphalt by about 10 levels."""


@dataclass(frozen=True)
class Shape:
    """A vehicle's dimensions, metres.

    Attributes
    ----------
    length_m, width_m, height_m
        Overall size (body length and width; roof height above the road).
    waist_m
        Height of the body's top (where the cabin starts) above the road.
    cabin_length, cabin_width
        Cabin base as fractions of the body's length and width.
    roof_length
        Roof length as a fraction of the cabin base's length.
    cabin_offset
        Cabin centre's shift backwards along the body, as a fraction of its length.
    clearance_m
        Height of the body's lower edge above the road.
    wheel_radius_m, wheelbase, track
        Wheel radius; axle spacing and wheel spacing as fractions of length and width.
    """

    length_m: float
    width_m: float
    height_m: float
    waist_m: float
    cabin_length: float
    cabin_width: float
    roof_length: float
    cabin_offset: float
    clearance_m: float = 0.2
    wheel_radius_m: float = 0.32
    wheelbase: float = 0.62
    track: float = 0.94


SHAPES: dict[str, Shape] = {
    "sedan": Shape(4.6, 1.8, 1.45, 0.85, 0.50, 0.86, 0.62, 0.05),
    "hatchback": Shape(4.0, 1.75, 1.5, 0.9, 0.58, 0.88, 0.72, 0.12),
    "suv": Shape(4.7, 1.9, 1.75, 1.05, 0.62, 0.90, 0.80, 0.08, clearance_m=0.25),
    "van": Shape(5.2, 2.0, 2.3, 1.1, 0.86, 0.96, 0.92, 0.04, 0.22, 0.34),
    "cuboid": Shape(4.5, 1.8, 1.5, 1.5, 1.0, 1.0, 1.0, 0.0, 0.0, 0.3),
}
"""Vehicle shapes: three two-box cars, a van, and the radar's own cuboid on the road."""


@dataclass(frozen=True)
class StreetVehicle:
    """A vehicle driving straight at constant speed.

    Parameters
    ----------
    start_xy_m
        World position of the footprint centre at ``t = start_s``.
    direction_deg
        Direction of travel, degrees counter-clockwise from world +x.
    speed_kmh
        Constant speed.
    start_s
        Time at which it is at ``start_xy_m``.
    shape
        Its shape (:data:`SHAPES`).
    colour
        BGR body colour.
    """

    start_xy_m: tuple[float, float]
    direction_deg: float
    speed_kmh: float
    start_s: float = 0.0
    shape: Shape = SHAPES["sedan"]
    colour: tuple[int, int, int] = COLOURS["red"]

    def centre_at(self, t_s: float) -> FloatArray:
        """Footprint centre at time ``t_s``, metres."""
        a = math.radians(self.direction_deg)
        d = self.speed_kmh / 3.6 * (t_s - self.start_s)
        return np.array(
            [self.start_xy_m[0] + d * math.cos(a), self.start_xy_m[1] + d * math.sin(a)]
        )

    def _frame(self, t_s: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        a = math.radians(self.direction_deg)
        fwd = np.array([math.cos(a), math.sin(a), 0.0])
        left = np.array([-fwd[1], fwd[0], 0.0])
        c = self.centre_at(t_s)
        return np.array([c[0], c[1], 0.0]), fwd, left

    def parts_at(self, t_s: float) -> dict[str, Any]:
        """World geometry at ``t_s``: ``body`` and ``cabin`` (8 corners each, bottom 0-3 then
        top 4-7, counter-clockwise from front right), ``wheels`` (4 octagons ``(8, 3)``) and
        ``contacts`` (the 4 wheel contacts on the road, ``(4, 3)``)."""
        s = self.shape
        o, fwd, left = self._frame(t_s)

        def box(
            length: float, width: float, z0: float, z1: float, top_len: float, shift: float
        ) -> FloatArray:
            pts = []
            for z, ln in ((z0, length), (z1, top_len)):
                for q, p in ((1, -1), (1, 1), (-1, 1), (-1, -1)):
                    pts.append(
                        o + (q * ln / 2 - shift) * fwd + p * width / 2 * left + [0.0, 0.0, z]
                    )
            return np.array(pts)

        body = box(s.length_m, s.width_m, s.clearance_m, s.waist_m, s.length_m, 0.0)
        cl = s.cabin_length * s.length_m
        cabin = box(
            cl,
            s.cabin_width * s.width_m,
            s.waist_m,
            s.height_m,
            cl * s.roof_length,
            s.cabin_offset * s.length_m,
        )
        r = s.wheel_radius_m
        wheels, contacts = [], []
        ang = np.linspace(0.0, 2 * math.pi, 8, endpoint=False) + math.pi / 8
        rv = r / math.cos(math.pi / 8)  # the octagon's flat bottom edge on the road
        for q in (1, -1):
            for p in (1, -1):
                hub = (
                    o + q * s.wheelbase * s.length_m / 2 * fwd + p * s.track * s.width_m / 2 * left
                )
                wheels.append(
                    np.array(
                        [
                            hub + rv * math.cos(b) * fwd + [0.0, 0.0, r + rv * math.sin(b)]
                            for b in ang
                        ]
                    )
                )
                contacts.append(hub.copy())
        return {
            "body": body,
            "cabin": cabin if s.height_m > s.waist_m + 1e-6 else None,
            "wheels": wheels,
            "contacts": np.array(contacts),
        }

    def points_at(self, t_s: float) -> FloatArray:
        """Every vertex of the vehicle at ``t_s`` ``(N, 3)`` (its image box is theirs)."""
        p = self.parts_at(t_s)
        out = [p["body"], *p["wheels"]]
        if p["cabin"] is not None:
            out.append(p["cabin"])
        return np.vstack(out)


@dataclass
class RenderedVideo:
    """A rendered street video and its truth."""

    path: Path
    camera: Camera
    scene: dict[str, Any]
    fps: float
    n_frames: int
    image_size: tuple[int, int]
    vehicles: list[StreetVehicle]
    boxes: dict[int, dict[int, Box]] = field(default_factory=dict)
    """Per vehicle index, per frame: the image box of a vehicle wholly in view."""
    contacts_world_m: dict[int, dict[int, FloatArray]] = field(default_factory=dict)
    """Per vehicle index, per frame in ``boxes``: its 4 wheel contacts ``(4, 2)``, metres."""


def street_camera(
    height_m: float = 7.5,
    *,
    image_size: tuple[int, int] = (960, 540),
    hfov_deg: float = 65.0,
    setback_m: float = 16.0,
    along_m: float = -8.0,
    aim_xy_m: tuple[float, float] = (8.0, -5.0),
    roll_deg: float = 0.5,
) -> Camera:
    """A pole camera beside the street, ``setback_m`` from the parked reference car.

    The camera stands at ``(along_m, -setback_m)`` (the street runs along x at
    ``y = -2 ... -12``), ``height_m`` up, aimed at ``aim_xy_m`` on the road.
    """
    w, h = image_size
    f = (w / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)
    centre = np.array([along_m, -setback_m, height_m])
    fwd = np.array([aim_xy_m[0], aim_xy_m[1], 0.0]) - centre
    heading = math.degrees(math.atan2(fwd[0], fwd[1]))
    pitch = math.degrees(math.atan2(-fwd[2], math.hypot(fwd[0], fwd[1])))
    R = rotation_from_angles(heading, pitch, roll_deg)
    return Camera.from_center(f, (w / 2.0, h / 2.0), R, centre)


# --------------------------------------------------------------------------- drawing
def _texture(rng: np.random.Generator, m_per_px: float) -> tuple[Any, FloatArray]:
    """Asphalt with lane markings and kerbs; returns the BGR texture and world_from_texture."""
    import cv2

    x0, x1, y0, y1 = -90.0, 110.0, -60.0, 40.0
    tw, th = int((x1 - x0) / m_per_px), int((y1 - y0) / m_per_px)
    tex = np.full((th, tw), _ROAD_GREY, np.float32)
    for cell_px, amp in ((2, 9.0), (7, 7.0), (30, 6.0), (120, 6.0)):
        small = rng.normal(0.0, amp, (th // cell_px + 2, tw // cell_px + 2)).astype(np.float32)
        tex += cv2.resize(small, (tw, th), interpolation=cv2.INTER_CUBIC)[:th, :tw]

    def row(y_m: float) -> int:
        return int((y_m - y0) / m_per_px)

    # pavements (lighter) beyond the kerbs at y = -1.5 and y = -12.5
    tex[: row(-12.5)] += 35.0
    tex[row(-1.5) :] += 35.0
    half = max(1, int(0.07 / m_per_px))
    for y_m, dash in ((-7.0, True), (-4.25, True), (-9.75, True), (-1.8, False), (-12.2, False)):
        r = row(y_m)
        for xs in np.arange(x0, x1, 6.0 if dash else x1 - x0):
            c0 = int((xs - x0) / m_per_px)
            c1 = int((xs + (3.0 if dash else x1 - x0) - x0) / m_per_px)
            tex[r - half : r + half + 1, c0:c1] = 225.0
    tex = np.clip(tex, 0, 255).astype(np.uint8)
    bgr = cv2.merge([tex, tex, (tex.astype(np.int16) * 24 // 25).astype(np.uint8)])
    world_from_tex = np.array([[m_per_px, 0.0, x0], [0.0, m_per_px, y0], [0.0, 0.0, 1.0]])
    return np.asarray(bgr, np.uint8), world_from_tex


def _background(
    camera: Camera, image_size: tuple[int, int], rng: np.random.Generator, m_per_px: float
) -> Any:
    import cv2

    w, h = image_size
    tex, world_from_tex = _texture(rng, m_per_px)
    R, t = camera.cam_from_world_rotation, camera.cam_from_world_translation
    img_from_ground = camera.img_from_cam @ np.column_stack([R[:, 0], R[:, 1], t])
    # OpenCV indexes pixels by their centres; Camera puts the first pixel's centre at 0.5
    # (both in the image and in the texture, whose pixel c covers world x0 + [c, c + 1] m/px)
    cv_from_img = np.array([[1.0, 0.0, -0.5], [0.0, 1.0, -0.5], [0.0, 0.0, 1.0]])
    tex_centres = np.array([[1.0, 0.0, 0.5], [0.0, 1.0, 0.5], [0.0, 0.0, 1.0]])
    img = cv2.warpPerspective(
        tex,
        cv_from_img @ img_from_ground @ world_from_tex @ tex_centres,
        (w, h),
        flags=cv2.INTER_AREA,
        borderValue=_SKY,
    )
    a, b, c = camera.horizon_line()
    uu, vv = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    img[(a * uu + b * vv + c) < 3.0] = _SKY
    return np.asarray(img, np.uint8)


def _coverage(px: FloatArray, x0: int, y0: int, w: int, h: int) -> FloatArray:
    """How much of each pixel of the window ``[x0, x0 + w) x [y0, y0 + h)`` the convex hull
    of ``px`` covers, 0-1 ``(h, w)``.

    In :class:`~camloc_geo.camera.Camera`'s convention: pixel ``(x, y)`` is the unit square
    ``[x, x + 1] x [y, y + 1]``, its centre at ``(x + 0.5, y + 0.5)``. Each edge covers a
    pixel by ``clip(0.5 + d)`` for the signed distance ``d`` (px) of its centre inside the
    edge's line (exact for edges along the pixel grid, unbiased for slanted ones), the
    polygon by the product over its edges; a polygon thinner than a pixel (its summed
    coverage above its area) is scaled down to its area. So a drawn edge stands where the
    camera projects it (within a few hundredths of a pixel) and a polygon keeps its area;
    OpenCV's anti-aliased fill put every edge half a pixel right of and below its
    projection and grew it by about 0.7 px on every side (before session 37).
    """
    import cv2

    out = np.zeros((h, w))
    hull = cv2.convexHull(np.asarray(px, np.float32)).reshape(-1, 2).astype(np.float64)
    if len(hull) < 3 or w <= 0 or h <= 0:
        return out
    x, y = hull[:, 0], hull[:, 1]
    area2 = float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    if abs(area2) < 1e-9:
        return out
    lo = np.maximum(np.floor(hull.min(axis=0)).astype(int) - 1, [x0, y0])
    hi = np.minimum(np.ceil(hull.max(axis=0)).astype(int) + 1, [x0 + w, y0 + h])
    if np.any(hi <= lo):
        return out
    uu, vv = np.meshgrid(np.arange(lo[0], hi[0]) + 0.5, np.arange(lo[1], hi[1]) + 0.5)
    cov = np.ones(uu.shape)
    sign = 1.0 if area2 > 0 else -1.0
    for a, b in zip(hull, np.roll(hull, -1, axis=0), strict=True):
        e = b - a
        n = sign * np.array([-e[1], e[0]]) / (np.hypot(e[0], e[1]) + 1e-12)  # inward
        cov *= np.clip(0.5 + (uu - a[0]) * n[0] + (vv - a[1]) * n[1], 0.0, 1.0)
    total = float(cov.sum())
    if total > abs(area2) / 2 / 0.95:  # thinner than a pixel: keep its area
        cov *= abs(area2) / 2 / total
    out[lo[1] - y0 : hi[1] - y0, lo[0] - x0 : hi[0] - x0] = cov
    return out


class _Layer:
    """A vehicle drawn apart, then laid over the frame at once (painter's order inside it).

    Colours blend face over face; the layer's opacity adds the faces' coverages (capped at
    1), so two faces sharing an edge cover its pixels wholly (blending them over each other
    would let the background show through the seam by up to a quarter).
    """

    def __init__(
        self,
        polygons: list[tuple[FloatArray, FloatArray]],
        size: tuple[int, int],
        decals: list[tuple[FloatArray, FloatArray]] | None = None,
    ):
        """``polygons``: ``(image polygon, BGR)`` in painter's order; ``decals``: painted on
        them afterwards (windows, wheels drawn on a face), colour only: where a decal's edge
        lies on its face's edge it must not add to the layer's opacity."""
        w, h = size
        allpx = np.vstack([p for p, _ in polygons])
        lo = np.clip(np.floor(allpx.min(axis=0)).astype(int) - 1, 0, [w, h])
        hi = np.clip(np.ceil(allpx.max(axis=0)).astype(int) + 1, 0, [w, h])
        self.x0, self.y0 = int(lo[0]), int(lo[1])
        self.w, self.h = int(hi[0] - lo[0]), int(hi[1] - lo[1])
        self.colour = np.zeros((self.h, self.w, 3))
        self.over = np.zeros((self.h, self.w))
        self.alpha = np.zeros((self.h, self.w))
        for px, colour in polygons:
            c = _coverage(px, self.x0, self.y0, self.w, self.h)
            self.colour = self.colour * (1.0 - c[..., None]) + c[..., None] * colour
            self.over = self.over * (1.0 - c) + c
            self.alpha = np.minimum(1.0, self.alpha + c)
        for px, colour in decals or []:
            c = _coverage(px, self.x0, self.y0, self.w, self.h) * (self.over > 0)
            self.colour = (
                self.colour * (1.0 - c[..., None]) + c[..., None] * colour * self.over[..., None]
            )

    def paint(self, img: Any) -> None:
        """Lay the layer over ``img`` (BGR uint8, in place)."""
        if self.w <= 0 or self.h <= 0:
            return
        roi = img[self.y0 : self.y0 + self.h, self.x0 : self.x0 + self.w]
        colour = self.colour / np.maximum(self.over, 1e-9)[..., None]
        a = self.alpha[..., None]
        roi[:] = np.clip(roi * (1.0 - a) + colour * a + 0.5, 0, 255).astype(np.uint8)


def _darken(img: Any, px: FloatArray, factor: float) -> None:
    h, w = img.shape[:2]
    lo = np.clip(np.floor(px.min(axis=0)).astype(int) - 1, 0, [w, h])
    hi = np.clip(np.ceil(px.max(axis=0)).astype(int) + 1, 0, [w, h])
    if np.any(hi <= lo):
        return
    a = _coverage(px, int(lo[0]), int(lo[1]), int(hi[0] - lo[0]), int(hi[1] - lo[1]))
    roi = img[lo[1] : hi[1], lo[0] : hi[0]]
    roi[:] = (roi * (1.0 - (1.0 - factor) * a[..., None]) + 0.5).astype(np.uint8)


_FACES = ((0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))


def _shade(normal: FloatArray) -> float:
    n = normal / (np.linalg.norm(normal) + 1e-12)
    return 0.5 + 0.5 * max(0.0, float(n @ _SUN))


def _box_faces(
    camera: Camera, corners: FloatArray, colour: FloatArray, glass: bool
) -> list[tuple[FloatArray, FloatArray]]:
    """The visible faces of a box: ``(image polygon, shaded BGR colour)`` each."""
    out = []
    eye = camera.center_in_world
    centre = corners.mean(axis=0)
    px = camera.project(corners)
    for k, face in enumerate(_FACES):
        q = corners[list(face)]
        fc = q.mean(axis=0)
        normal = np.cross(q[1] - q[0], q[3] - q[0])
        if normal @ (fc - centre) < 0:
            normal = -normal
        if k == 0 or normal @ (eye - fc) <= 0:  # the bottom is never seen from above
            continue
        side = k >= 2
        base = np.array([55.0, 48.0, 42.0]) if glass and side else colour
        out.append((px[list(face)], base * _shade(normal)))
    return out


def _draw(img: Any, camera: Camera, veh: StreetVehicle, t_s: float, sun: bool) -> None:
    parts = veh.parts_at(t_s)
    body, cabin = parts["body"], parts["cabin"]
    pts = veh.points_at(t_s)
    R, t = camera.cam_from_world_rotation, camera.cam_from_world_translation
    if np.any((pts @ R.T + t)[:, 2] < 0.5):
        return
    # contact shadow under the body (ambient occlusion), then the sun's cast shadow
    foot = body[:4].copy()
    foot[:, 2] = 0.0
    centre = foot.mean(axis=0)
    _darken(img, camera.project(centre + 1.04 * (foot - centre)), 0.45)
    if sun:
        cast = pts[:, :2] - np.outer(pts[:, 2], _SUN[:2] / _SUN[2])
        _darken(img, camera.project(np.column_stack([cast, np.zeros(len(cast))])), 0.55)
    colour = np.array(veh.colour, float)
    # wheels on the far side are behind the body; those on the near side show in their
    # arches (drawn over the body's side) down to the road
    eye = camera.center_in_world
    near = [
        (w[:, :2].mean(axis=0) - centre[:2]) @ (eye[:2] - centre[:2]) > 0 for w in parts["wheels"]
    ]
    tyre = np.array(_TYRE)
    polygons = [
        (camera.project(wheel), tyre)
        for wheel, n in zip(parts["wheels"], near, strict=True)
        if not n
    ]
    polygons += _box_faces(camera, body, colour, glass=False)
    polygons += [
        (camera.project(wheel), tyre) for wheel, n in zip(parts["wheels"], near, strict=True) if n
    ]
    if cabin is not None:
        polygons += _box_faces(camera, cabin, colour, glass=True)
    _Layer(polygons, (img.shape[1], img.shape[0])).paint(img)


def _truth(
    camera: Camera, vehicles: list[StreetVehicle], fps: float, n_frames: int, size: tuple[int, int]
) -> tuple[dict[int, dict[int, Box]], dict[int, dict[int, FloatArray]]]:
    w, h = size
    R, t = camera.cam_from_world_rotation, camera.cam_from_world_translation
    boxes: dict[int, dict[int, Box]] = {}
    contacts: dict[int, dict[int, FloatArray]] = {}
    for k, veh in enumerate(vehicles):
        boxes[k], contacts[k] = {}, {}
        for i in range(n_frames):
            pts = veh.points_at(i / fps)
            if np.any((pts @ R.T + t)[:, 2] < 0.5):
                continue
            px = camera.project(pts)
            lo, hi = px.min(axis=0), px.max(axis=0)
            if lo[0] >= 1 and lo[1] >= 1 and hi[0] <= w - 1 and hi[1] <= h - 1:
                boxes[k][i] = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
                contacts[k][i] = veh.parts_at(i / fps)["contacts"][:, :2]
    return boxes, contacts


def render_street(
    path: str | Path,
    camera: Camera,
    vehicles: list[StreetVehicle],
    *,
    fps: float = 20.0,
    duration_s: float = 20.0,
    seed: int = 0,
    noise_sigma: float = 2.0,
    sun: bool = True,
    annotation_px: float = 1.0,
    fourcc: str = "MJPG",
    texture_m_per_px: float = 0.025,
    photo: bool = False,
) -> RenderedVideo:
    """Render a street video (MJPG ``.avi``) and return it with its truth and annotated scene.

    With ``photo``, the scene's ``image.path`` is the street's background frame
    (:func:`street_photo`), written beside the video as a PNG of the same name: the photo a
    radar user can take from the video, whose painted lines ``calibrate`` adds to the
    annotators' (``CalibrationSettings.photo_lines``).

    Parameters
    ----------
    path
        Output file.
    camera
        The camera (:func:`street_camera`); the frame size is its principal point's double.
    vehicles
        The traffic.
    fps, duration_s
        Frame rate and length.
    seed
        Seed of the asphalt texture, the sensor noise and the annotators' clicks.
    noise_sigma
        Gaussian sensor noise, grey levels.
    sun
        Cast hard shadows (besides the contact shadows, always drawn).
    annotation_px
        Click noise of the scene's 3 annotators (1 px by default; 0: exact).
    fourcc
        Codec; MJPG is available in every OpenCV build.
    texture_m_per_px
        Resolution of the asphalt texture (coarser: faster, for small test videos).
    photo
        Write the background frame and name it in the scene (default False: no
        ``image.path``, the scene the radar benchmarks calibrate).

    Raises
    ------
    RuntimeError
        OpenCV cannot open a writer for ``path``.
    """

    size = (round(2 * camera.principal_point[0]), round(2 * camera.principal_point[1]))
    w, h = size
    rng = np.random.default_rng(seed)
    # The parked car's clicks and the painted lane lines, as 3 annotators draw them.
    scene = street_scene(camera, seed, click_px=annotation_px, image_size=size).scene
    background = _street_background(camera, size, rng, texture_m_per_px, sun)
    n_frames = round(duration_s * fps)
    path = Path(path)
    eye = camera.center_in_world[:2]

    def frame_at(t_s: float) -> npt.NDArray[np.uint8]:
        frame = background.copy()
        order = sorted(vehicles, key=lambda v: -float(np.linalg.norm(v.centre_at(t_s) - eye)))
        for veh in order:
            _draw(frame, camera, veh, t_s, sun)
        return frame

    write_video(
        path,
        frame_at,
        fps=fps,
        n_frames=n_frames,
        size=(w, h),
        fourcc=fourcc,
        noise_sigma=noise_sigma,
    )
    boxes, contacts = _truth(camera, vehicles, fps, n_frames, size)
    if photo:
        scene["image"]["path"] = str(
            _write_photo(path.with_suffix(".png"), _noisy(background, seed, noise_sigma))
        )
    return RenderedVideo(path, camera, scene, fps, n_frames, size, vehicles, boxes, contacts)


def _street_background(
    camera: Camera,
    size: tuple[int, int],
    rng: np.random.Generator,
    texture_m_per_px: float,
    sun: bool,
) -> Any:
    """The street without traffic: asphalt, markings and the parked reference sedan."""
    background = _background(camera, size, rng, texture_m_per_px)
    ref = PRESETS["sedan"]
    parked = StreetVehicle(
        (ref.length_m / 2, ref.width_m / 2),
        0.0,
        0.0,
        shape=SHAPES["sedan"],
        colour=COLOURS["silver"],
    )
    _draw(background, camera, parked, 0.0, sun)
    return background


def _noisy(image: Any, seed: int, noise_sigma: float) -> npt.NDArray[np.uint8]:
    """``image`` with one draw of Gaussian sensor noise (its own generator: ``seed + 13``)."""
    noise = np.random.default_rng(seed + 13).normal(0.0, noise_sigma, np.shape(image))
    return np.asarray(np.clip(np.asarray(image, float) + noise, 0, 255), np.uint8)


def _write_photo(path: Path, image: npt.NDArray[np.uint8]) -> Path:
    import cv2

    if not cv2.imwrite(str(path), image):
        raise RuntimeError(f"cannot write the street photo {path}")
    return path.resolve()


def street_photo(
    camera: Camera,
    seed: int,
    path: str | Path,
    *,
    noise_sigma: float = 2.0,
    sun: bool = True,
    texture_m_per_px: float = 0.025,
) -> Path:
    """Write the background frame :func:`render_street` gives its scene, without a video.

    The street as ``render_street(..., seed=seed)`` draws it before any traffic (asphalt
    texture, painted lines, kerbs, the parked reference sedan and its shadows) with one draw
    of the sensor noise: the photo a radar user takes from the video (a frame without
    passing cars) and names as the scene's ``image.path``.

    Parameters
    ----------
    camera
        The camera (the frame size is its principal point's double).
    seed
        ``render_street``'s seed (the texture and the noise).
    path
        The PNG to write.
    noise_sigma, sun, texture_m_per_px
        As :func:`render_street`.

    Returns
    -------
    Path
        The absolute path written.

    Raises
    ------
    RuntimeError
        OpenCV cannot write ``path``.
    """
    size = (round(2 * camera.principal_point[0]), round(2 * camera.principal_point[1]))
    rng = np.random.default_rng(seed)
    background = _street_background(camera, size, rng, texture_m_per_px, sun)
    return _write_photo(Path(path), _noisy(background, seed, noise_sigma))


def random_street(
    rng: np.random.Generator,
    *,
    n_vehicles: int = 10,
    duration_s: float = 20.0,
    image_size: tuple[int, int] = (960, 540),
    shapes: tuple[str, ...] = ("sedan", "hatchback", "suv", "van"),
    colours: tuple[str, ...] = tuple(COLOURS),
    speed_kmh: tuple[float, float] = (20.0, 70.0),
) -> tuple[Camera, list[StreetVehicle]]:
    """A random pole camera (6-9 m up) and traffic on the street in both directions.

    Vehicles cross the camera's view one after another (evenly spread over the video,
    alternating directions, lanes at ``y = -3, -5.5`` eastbound and ``-8.5, -11``
    westbound); each passes ``x = 8`` (the middle of the view) at its time.
    """
    ref = PRESETS["sedan"]
    car = np.array(
        [[x, y, z] for x in (0.0, ref.length_m) for y in (0.0, ref.width_m) for z in (0.0, 1.4)]
    )
    w, h = image_size
    for _ in range(200):  # the annotated reference car must be in view, off the borders
        cam = street_camera(
            float(rng.uniform(6.0, 9.0)),
            image_size=image_size,
            hfov_deg=float(rng.uniform(55.0, 70.0)),
            setback_m=float(rng.uniform(14.0, 19.0)),
            along_m=float(rng.uniform(-14.0, -7.0)),
            aim_xy_m=(float(rng.uniform(5.0, 11.0)), -6.0),
            roll_deg=float(rng.uniform(-1.5, 1.5)),
        )
        px = cam.project(car)
        if px[:, 0].min() > 0.05 * w and px[:, 1].max() < 0.95 * h:
            break
    vehicles = []
    for k in range(n_vehicles):
        east = k % 2 == 0
        lane = float(rng.choice([-3.0, -5.5] if east else [-8.5, -11.0]))
        t_mid = (k + 0.5) * duration_s / n_vehicles + float(rng.uniform(-0.3, 0.3))
        vehicles.append(
            StreetVehicle(
                (8.0, lane),
                0.0 if east else 180.0,
                float(rng.uniform(*speed_kmh)),
                start_s=t_mid,
                shape=SHAPES[str(rng.choice(list(shapes)))],
                colour=COLOURS[str(rng.choice(list(colours)))],
            )
        )
    return cam, vehicles
