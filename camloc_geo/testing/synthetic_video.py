"""Synthetic traffic videos for the virtual radar: a textured ground and moving cuboids.

A known camera (the same one whose annotated scene :func:`camloc_geo.testing.synthetic.make_scene`
produces, so the scene calibrates to it) watches a textured ground plane (blurred random
noise at several scales, lane markings) with the scene's parked reference car at the world
origin, and vehicles (cuboids with windows and wheels, shaded per face) driving along
straight lines at constant known speeds. Frames get Gaussian sensor noise and are written
with :class:`cv2.VideoWriter` (MJPG in ``.avi`` by default).

Optionally, hard shadows on the ground (``shadow=``). Shortcuts: no lighting changes, no
lens distortion, rigid boxes.
Used by ``tests/test_radar.py`` and ``benchmarks/radar.py``; videos go to temporary
directories, never into the repository.
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
from camloc_geo.testing.synthetic import NoiseModel, make_scene

__all__ = [
    "SyntheticVehicle",
    "SyntheticVideo",
    "render_video",
    "traffic_camera",
    "vehicle_boxes",
]

FloatArray = npt.NDArray[np.float64]

_SKY = (200, 190, 170)
_FACES = ((0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))


@dataclass(frozen=True)
class SyntheticVehicle:
    """A cuboid driving straight at constant speed on the ground ``z = 0``.

    Parameters
    ----------
    start_xy_m
        World position of the vehicle's footprint centre at ``t = start_s``.
    direction_deg
        Direction of travel in the world frame, degrees counter-clockwise from +x.
    speed_kmh
        Constant speed.
    start_s
        Time at which it is at ``start_xy_m`` (it moves before and after too).
    size_m
        Length, width, height.
    colour
        BGR body colour.
    """

    start_xy_m: tuple[float, float]
    direction_deg: float
    speed_kmh: float
    start_s: float = 0.0
    size_m: tuple[float, float, float] = (4.5, 1.8, 1.5)
    colour: tuple[int, int, int] = (40, 40, 180)

    def centre_at(self, t_s: float) -> FloatArray:
        """Footprint centre at time ``t_s``, metres."""
        a = math.radians(self.direction_deg)
        d = self.speed_kmh / 3.6 * (t_s - self.start_s)
        return np.array(
            [self.start_xy_m[0] + d * math.cos(a), self.start_xy_m[1] + d * math.sin(a)]
        )

    def corners_at(self, t_s: float) -> FloatArray:
        """The 8 corners ``(8, 3)``: bottom 0-3 counter-clockwise, then top 4-7."""
        length, width, height = self.size_m
        a = math.radians(self.direction_deg)
        fwd = np.array([math.cos(a), math.sin(a)])
        left = np.array([-fwd[1], fwd[0]])
        c = self.centre_at(t_s)
        foot = [
            c + s * length / 2 * fwd + q * width / 2 * left
            for s, q in ((1, -1), (1, 1), (-1, 1), (-1, -1))
        ]
        bottom = np.array([[p[0], p[1], 0.0] for p in foot])
        top = bottom + np.array([0.0, 0.0, height])
        return np.vstack([bottom, top])


@dataclass
class SyntheticVideo:
    """A rendered video and its truth."""

    path: Path
    camera: Camera
    scene: dict[str, Any]
    fps: float
    n_frames: int
    image_size: tuple[int, int]
    vehicles: list[SyntheticVehicle]
    boxes: dict[int, dict[int, tuple[float, float, float, float]]] = field(default_factory=dict)
    """Per vehicle index, per frame: the image box of a vehicle wholly in view."""


def traffic_camera(
    height_m: float = 7.0,
    distance_m: float = 18.0,
    *,
    azimuth_deg: float = 235.0,
    image_size: tuple[int, int] = (640, 360),
    hfov_deg: float = 70.0,
    roll_deg: float = 1.0,
) -> Camera:
    """A camera on a pole looking at the reference car at the origin and the road in front.

    The camera stands ``distance_m`` (horizontally) from the origin at ``azimuth_deg``
    (counter-clockwise from +x), ``height_m`` above the ground, aimed at ``(6, -3, 0)``.
    """
    w, h = image_size
    f = (w / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)
    az = math.radians(azimuth_deg)
    centre = np.array([distance_m * math.cos(az), distance_m * math.sin(az), height_m])
    fwd = np.array([6.0, -3.0, 0.0]) - centre
    heading = math.degrees(math.atan2(fwd[0], fwd[1]))
    pitch = math.degrees(math.atan2(-fwd[2], math.hypot(fwd[0], fwd[1])))
    R = rotation_from_angles(heading, pitch, roll_deg)
    return Camera.from_center(f, (w / 2.0, h / 2.0), R, centre)


def _ground_texture(
    rng: np.random.Generator, extent_m: tuple[float, float, float, float], m_per_px: float
) -> tuple[npt.NDArray[np.uint8], FloatArray]:
    """A BGR texture of the ground and its ``world_from_texture`` 3×3 homography."""
    import cv2

    x0, x1, y0, y1 = extent_m
    tw, th = int((x1 - x0) / m_per_px), int((y1 - y0) / m_per_px)
    tex = np.full((th, tw), 95.0, np.float32)
    for cell_px, amp in ((2, 22.0), (6, 18.0), (25, 14.0), (90, 10.0)):
        small = rng.normal(0.0, amp, (th // cell_px + 2, tw // cell_px + 2)).astype(np.float32)
        tex += cv2.resize(small, (tw, th), interpolation=cv2.INTER_CUBIC)[:th, :tw]
    world_from_tex = np.array([[m_per_px, 0.0, x0], [0.0, m_per_px, y0], [0.0, 0.0, 1.0]])
    # Dashed lane markings along x at y = -6 (centre line), solid edges at y = -2 and -10.
    for y_m, dash in ((-6.0, True), (-2.0, False), (-10.0, False)):
        row = int((y_m - y0) / m_per_px)
        half = max(1, int(0.07 / m_per_px))
        for xs in np.arange(x0, x1, 6.0 if dash else x1 - x0):
            c0 = int((xs - x0) / m_per_px)
            c1 = int((xs + (3.0 if dash else x1 - x0) - x0) / m_per_px)
            tex[row - half : row + half + 1, c0:c1] = 230.0
    tex = np.clip(tex, 0, 255).astype(np.uint8)
    bgr = cv2.merge([tex, tex, (tex.astype(np.int16) * 9 // 10).astype(np.uint8)])
    return np.asarray(bgr, np.uint8), world_from_tex


def _background(
    camera: Camera, image_size: tuple[int, int], rng: np.random.Generator
) -> npt.NDArray[np.uint8]:
    import cv2

    w, h = image_size
    tex, world_from_tex = _ground_texture(rng, (-60.0, 80.0, -60.0, 40.0), 0.03)
    R, t = camera.cam_from_world_rotation, camera.cam_from_world_translation
    img_from_ground = camera.img_from_cam @ np.column_stack([R[:, 0], R[:, 1], t])
    # OpenCV indexes pixels by their centres, Camera puts the first one's at 0.5 (session 37)
    cv_from_img = np.array([[1.0, 0.0, -0.5], [0.0, 1.0, -0.5], [0.0, 0.0, 1.0]])
    tex_centres = np.array([[1.0, 0.0, 0.5], [0.0, 1.0, 0.5], [0.0, 0.0, 1.0]])
    img_from_tex = cv_from_img @ img_from_ground @ world_from_tex @ tex_centres
    img = cv2.warpPerspective(tex, img_from_tex, (w, h), flags=cv2.INTER_AREA, borderValue=_SKY)
    # Pixels at or above the horizon (and the far haze) are sky.
    a, b, c = camera.horizon_line()
    uu, vv = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    img[(a * uu + b * vv + c) < 3.0] = _SKY
    return np.asarray(img, np.uint8)


def _draw_shadow(
    img: npt.NDArray[np.uint8], camera: Camera, corners: FloatArray, shadow: tuple[float, float]
) -> None:
    """Darken the ground under a cuboid's shadow (sun direction: ``shadow`` m per m height)."""
    from camloc_geo.testing.traffic_render import _darken

    top = corners[4:]
    cast = top[:, :2] + np.outer(top[:, 2], shadow)
    ground = np.vstack([corners[:4, :2], cast])
    px = camera.project(np.column_stack([ground, np.zeros(len(ground))]))
    if not np.all(np.isfinite(px)):
        return
    _darken(img, px, 0.5)


def _draw_vehicle(
    img: npt.NDArray[np.uint8], camera: Camera, corners: FloatArray, colour: tuple[int, int, int]
) -> bool:
    """Draw a cuboid (back faces culled); False when part of it is behind the camera.

    Drawn in :class:`~camloc_geo.camera.Camera`'s pixel convention with exact coverage
    (:func:`camloc_geo.testing.traffic_render._coverage`); before session 37 OpenCV's
    anti-aliased fill drew it half a pixel right of and below its projection, 0.7 px larger.
    """
    from camloc_geo.testing.traffic_render import _Layer

    R, t = camera.cam_from_world_rotation, camera.cam_from_world_translation
    if np.any((corners @ R.T + t)[:, 2] < 0.5):
        return False
    px = camera.project(corners)
    centre = corners.mean(axis=0)
    eye = camera.center_in_world
    base = np.array(colour, float)
    polygons: list[tuple[FloatArray, FloatArray]] = []
    decals: list[tuple[FloatArray, FloatArray]] = []  # on the side faces
    for face in _FACES:
        q = corners[list(face)]
        fc = q.mean(axis=0)
        normal = fc - centre
        if normal @ (eye - fc) <= 0:
            continue
        shade = 0.55 + 0.45 * abs(normal[2]) / (np.linalg.norm(normal) + 1e-9)
        polygons.append((px[list(face)], base * shade))
        if abs(normal[2]) < 1e-6:
            # A window in the upper part of each side face and two dark wheels at the bottom.
            p0, p1, _p2, p3 = q  # bottom a, bottom b, top b, top a (see _FACES order)
            win = [
                p0 + 0.15 * (p1 - p0) + 0.55 * (p3 - p0),
                p0 + 0.85 * (p1 - p0) + 0.55 * (p3 - p0),
            ]
            win += [win[1] + 0.3 * (p3 - p0), win[0] + 0.3 * (p3 - p0)]
            decals.append((camera.project(np.array(win)), np.array([70.0, 60.0, 50.0])))
            for s in (0.15, 0.7):
                wh = [p0 + s * (p1 - p0), p0 + (s + 0.15) * (p1 - p0)]
                wh += [wh[1] + 0.3 * (p3 - p0), wh[0] + 0.3 * (p3 - p0)]
                decals.append((camera.project(np.array(wh)), np.array([25.0, 25.0, 25.0])))
    if polygons:
        _Layer(polygons, (img.shape[1], img.shape[0]), decals).paint(img)
    return True


def vehicle_boxes(
    camera: Camera,
    vehicles: list[SyntheticVehicle],
    fps: float,
    n_frames: int,
    image_size: tuple[int, int],
    margin_px: float = 1.0,
) -> dict[int, dict[int, tuple[float, float, float, float]]]:
    """Exact image boxes ``(x1, y1, x2, y2)`` of each vehicle in the frames it is wholly in."""
    w, h = image_size
    out: dict[int, dict[int, tuple[float, float, float, float]]] = {}
    R, t = camera.cam_from_world_rotation, camera.cam_from_world_translation
    for k, veh in enumerate(vehicles):
        per: dict[int, tuple[float, float, float, float]] = {}
        for i in range(n_frames):
            corners = veh.corners_at(i / fps)
            if np.any((corners @ R.T + t)[:, 2] < 0.5):
                continue
            px = camera.project(corners)
            lo, hi = px.min(axis=0), px.max(axis=0)
            if (
                lo[0] >= margin_px
                and lo[1] >= margin_px
                and hi[0] <= w - margin_px
                and (hi[1] <= h - margin_px)
            ):
                per[i] = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
        out[k] = per
    return out


def render_video(
    path: str | Path,
    camera: Camera,
    vehicles: list[SyntheticVehicle],
    *,
    image_size: tuple[int, int] = (640, 360),
    fps: float = 25.0,
    duration_s: float = 3.0,
    seed: int = 0,
    noise_sigma: float = 2.0,
    fourcc: str = "MJPG",
    parked_car: bool = True,
    shadow: tuple[float, float] | None = None,
) -> SyntheticVideo:
    """Render and write a synthetic traffic video; returns its truth and the scene.

    Parameters
    ----------
    path
        Output file (``.avi`` for MJPG).
    camera
        The camera; its annotated scene (noise-free, 3 annotators) is returned too.
    vehicles
        Moving vehicles.
    image_size, fps, duration_s
        Frame size (width, height), frame rate and length.
    seed
        Texture and noise seed.
    noise_sigma
        Per-pixel Gaussian sensor noise, grey levels.
    fourcc
        Codec; MJPG is available in every OpenCV build.
    parked_car
        Draw the scene's reference car (the preset sedan at the world origin).
    shadow
        Cast hard shadows on the ground (50 % darker): the horizontal displacement of a
        point's shadow per metre of its height, ``(dx, dy)`` in the world frame. None: no sun.

    Raises
    ------
    RuntimeError
        OpenCV cannot open a writer for ``path`` with ``fourcc``.
    """

    rng = np.random.default_rng(seed)
    w, h = image_size
    syn = make_scene(
        camera,
        np.random.default_rng(seed),
        noise=NoiseModel.exact(),
        n_annotators=3,
        image_size=image_size,
    )
    background = _background(camera, image_size, rng)
    if parked_car:
        sedan = PRESETS["sedan"]
        parked = SyntheticVehicle(
            (sedan.length_m / 2, sedan.width_m / 2),
            0.0,
            0.0,
            size_m=(sedan.length_m, sedan.width_m, sedan.height_m),
            colour=(150, 150, 150),
        )
        if shadow is not None:
            _draw_shadow(background, camera, parked.corners_at(0.0), shadow)
        _draw_vehicle(background, camera, parked.corners_at(0.0), parked.colour)
    n_frames = round(duration_s * fps)
    path = Path(path)
    eye = camera.center_in_world[:2]

    def frame_at(t_s: float) -> npt.NDArray[np.uint8]:
        frame = background.copy()
        order = sorted(
            range(len(vehicles)),
            key=lambda k: -float(np.linalg.norm(vehicles[k].centre_at(t_s) - eye)),
        )
        if shadow is not None:
            for k in order:
                _draw_shadow(frame, camera, vehicles[k].corners_at(t_s), shadow)
        for k in order:
            _draw_vehicle(frame, camera, vehicles[k].corners_at(t_s), vehicles[k].colour)
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
    boxes = vehicle_boxes(camera, vehicles, fps, n_frames, image_size)
    return SyntheticVideo(path, camera, syn.scene, fps, n_frames, image_size, vehicles, boxes)
