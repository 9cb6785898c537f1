"""Synthetic cameras and annotated scenes with a documented annotation noise model.

Used by the tests and the benchmarks; also handy to check a pipeline end to end.

Noise model (:class:`NoiseModel`), per annotator:

- every clicked axis pixel is off by isotropic Gaussian noise of ``point_px``;
- every drawn segment's endpoints are off by ``line_px``; segments are 2 to 4 per axis,
  taken from the car's own edges (short: often 20-80 px) and from longer scene lines
  parallel to the axes (lane markings and kerbs along the length, stop lines and crossings
  along the width, building edges and poles along the height), clipped to the image;
- with probability ``wrong_corner_prob`` an annotator marks the wrong ground corner of the
  car (the far end of the length edge), with the edges that start from that corner;
- with probability ``sloppy_prob`` an annotator is sloppy: 4× the pixel noise;
- the car's true size differs from the preset by ``size_rel`` (relative, Gaussian, per
  dimension), while the scene only states the preset.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from camloc_geo.camera import Camera, rotation_from_angles
from camloc_geo.objects import ObjectSize

__all__ = ["NoiseModel", "SyntheticScene", "make_scene", "random_camera"]

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class NoiseModel:
    """Annotation noise; see the module docstring. ``NoiseModel.exact()`` is noise-free."""

    point_px: float = 2.0
    line_px: float = 1.0
    wrong_corner_prob: float = 0.1
    sloppy_prob: float = 0.1
    size_rel: float = 0.05
    min_segment_px: float = 25.0

    @classmethod
    def exact(cls) -> NoiseModel:
        """No noise at all."""
        return cls(0.0, 0.0, 0.0, 0.0, 0.0)


@dataclass
class SyntheticScene:
    """A generated scene and its truth."""

    scene: dict[str, Any]
    camera: Camera
    true_size: ObjectSize
    width_sign: float
    wrong_corner: list[bool]


def random_camera(
    rng: np.random.Generator,
    *,
    image_size: tuple[int, int] = (1920, 1080),
    height_m: tuple[float, float] = (2.0, 15.0),
    distance_m: tuple[float, float] = (8.0, 40.0),
    focal_px: tuple[float, float] | None = None,
    roll_deg: float = 4.0,
    pp_offset_px: float = 0.0,
    width_sign: float = 1.0,
) -> Camera:
    """A camera looking at a car at the world origin from the side of its nearest corner.

    The camera stands in the quadrant x < 0 and ``y·width_sign < 0``, so the corner at the
    origin is the one nearest to it; it looks roughly at the car's centre with some jitter.
    """
    w, h = image_size
    if focal_px is None:
        # Horizontal fields of view from 30° to 90°.
        hfov = math.radians(rng.uniform(30.0, 90.0))
        f = (w / 2.0) / math.tan(hfov / 2.0)
    else:
        f = float(rng.uniform(*focal_px))
    pp = (w / 2.0 + rng.uniform(-pp_offset_px, pp_offset_px), h / 2.0 + rng.uniform(-pp_offset_px, pp_offset_px))
    cam_h = float(rng.uniform(*height_m))
    dist = float(rng.uniform(*distance_m))
    az = math.radians(rng.uniform(200.0, 250.0))  # direction from the car to the camera
    cx, cy = dist * math.cos(az), width_sign * dist * math.sin(az)
    if cy * width_sign > 0:
        cy = -cy
    center = np.array([cx, cy, cam_h])
    target = np.array([2.0, width_sign * 0.9, 0.5]) + rng.normal(0.0, 1.0, 3) * [2.0, 2.0, 0.3]
    fwd = target - center
    heading = math.degrees(math.atan2(fwd[0], fwd[1]))
    pitch = math.degrees(math.atan2(-fwd[2], math.hypot(fwd[0], fwd[1])))
    R = rotation_from_angles(heading, pitch, float(rng.uniform(-roll_deg, roll_deg)))
    return Camera.from_center(f, pp, R, center)


def _clip_segment(p: FloatArray, q: FloatArray, w: int, h: int) -> FloatArray | None:
    """Clip a 2-D segment to the image rectangle (Liang-Barsky)."""
    t0, t1 = 0.0, 1.0
    d = q - p
    for pk, qk in ((-d[0], p[0]), (d[0], w - p[0]), (-d[1], p[1]), (d[1], h - p[1])):
        if pk == 0:
            if qk < 0:
                return None
            continue
        r = qk / pk
        if pk < 0:
            t0 = max(t0, r)
        else:
            t1 = min(t1, r)
        if t0 > t1:
            return None
    return np.array([*(p + t0 * d), *(p + t1 * d)])


def _visible_segment(cam: Camera, a: FloatArray, b: FloatArray, size: tuple[int, int]) -> FloatArray | None:
    """Project a 3-D segment (clipped to the front of the camera and to the image)."""
    R, t = cam.cam_from_world_rotation, cam.cam_from_world_translation
    za, zb = (R @ a + t)[2], (R @ b + t)[2]
    near = 0.5
    if za < near and zb < near:
        return None
    if za < near:
        a = a + (b - a) * (near - za) / (zb - za)
    elif zb < near:
        b = b + (a - b) * (near - zb) / (za - zb)
    pa, pb = cam.project(a), cam.project(b)
    return _clip_segment(pa, pb, size[0], size[1])


def _scene_lines(
    rng: np.random.Generator, axis: int, size: ObjectSize, ws: float
) -> list[tuple[FloatArray, FloatArray]]:
    """Candidate 3-D segments parallel to a world axis: car edges, then scene lines."""
    L, W, H = size.length_m, ws * size.width_m, size.height_m
    car: list[tuple[FloatArray, FloatArray]]
    scene: list[tuple[FloatArray, FloatArray]] = []
    if axis == 0:
        car = [(np.array([0, 0, z]), np.array([L, 0, z])) for z in (0.3, H * 0.8)]
        car.append((np.array([0, W, 0.3]), np.array([L, W, 0.3])))
        for _ in range(4):  # lane lines / kerbs along the street
            y = float(rng.uniform(-12, 12))
            x0 = float(rng.uniform(-30, 10))
            scene.append((np.array([x0, y, 0.0]), np.array([x0 + rng.uniform(8, 40), y, 0.0])))
    elif axis == 1:
        car = [(np.array([x, 0, z]), np.array([x, W, z])) for x, z in ((0, 0.3), (0, H * 0.8), (L, 0.3))]
        for _ in range(4):  # stop lines, crossings
            x = float(rng.uniform(-20, 25))
            y0 = float(rng.uniform(-12, 0))
            scene.append((np.array([x, y0, 0.0]), np.array([x, y0 + rng.uniform(4, 14), 0.0])))
    else:
        car = [(np.array([x, y, 0.2]), np.array([x, y, H])) for x, y in ((0, 0), (L, 0), (0, W))]
        for _ in range(4):  # building edges, poles
            x, y = float(rng.uniform(-25, 30)), float(rng.uniform(-20, 20))
            scene.append((np.array([x, y, 0.0]), np.array([x, y, rng.uniform(3, 15)])))
    order = list(rng.permutation(len(car)))
    return [car[i] for i in order] + scene


def make_scene(
    camera: Camera,
    rng: np.random.Generator,
    *,
    preset: ObjectSize = ObjectSize(4.6, 1.8, 1.45),
    noise: NoiseModel | None = None,
    n_annotators: int = 5,
    image_size: tuple[int, int] = (1920, 1080),
    width_sign: float = 1.0,
    give_focal: bool = False,
    scene_id: str = "synthetic",
) -> SyntheticScene:
    """Annotate a synthetic camera's view of a car at the world origin.

    Returns
    -------
    SyntheticScene
        The scene as a ``camloc-scene/1`` dict (sizes stated as ``preset``) and the truth.
    """
    noise = noise or NoiseModel()
    w, h = image_size
    true = ObjectSize(*(d * (1.0 + rng.normal(0.0, noise.size_rel)) for d in
                        (preset.length_m, preset.width_m, preset.height_m)))
    ws = width_sign
    L, W, H = true.length_m, ws * true.width_m, true.height_m
    annotations = []
    wrong = []
    for a in range(n_annotators):
        sloppy = rng.random() < noise.sloppy_prob
        k = 4.0 if sloppy else 1.0
        is_wrong = rng.random() < noise.wrong_corner_prob
        wrong.append(bool(is_wrong))
        if is_wrong:
            pts = np.array([[L, 0, 0], [0, 0, 0], [L, W, 0], [L, 0, H]], float)
        else:
            pts = np.array([[0, 0, 0], [L, 0, 0], [0, W, 0], [0, 0, H]], float)
        pix = camera.project(pts) + rng.normal(0.0, noise.point_px * k, (4, 2))
        pix[:, 0] = np.clip(pix[:, 0], 0.0, w)
        pix[:, 1] = np.clip(pix[:, 1], 0.0, h)
        vp_lines: dict[str, list[list[float]]] = {}
        for axis, name in enumerate(("length", "width", "height")):
            want = int(rng.integers(2, 5))
            got: list[list[float]] = []
            for p, q in _scene_lines(rng, axis, true, ws):
                seg = _visible_segment(camera, p, q, image_size)
                if seg is None or math.hypot(seg[2] - seg[0], seg[3] - seg[1]) < noise.min_segment_px:
                    continue
                seg = seg + rng.normal(0.0, noise.line_px * k, 4)
                seg[[0, 2]] = np.clip(seg[[0, 2]], 0.0, w)
                seg[[1, 3]] = np.clip(seg[[1, 3]], 0.0, h)
                got.append([float(v) for v in seg])
                if len(got) >= want:
                    break
            vp_lines[name] = got
        annotations.append(
            {
                "annotator": f"w{a + 1}",
                "axes": {
                    "origin": pix[0].tolist(),
                    "length": pix[1].tolist(),
                    "width": pix[2].tolist(),
                    "height": pix[3].tolist(),
                },
                "vp_lines": vp_lines,
            }
        )
    scene: dict[str, Any] = {
        "format": "camloc-scene/1",
        "id": scene_id,
        "image": {"width": w, "height": h},
        "object": {"length_m": preset.length_m, "width_m": preset.width_m, "height_m": preset.height_m},
        "annotations": annotations,
    }
    if give_focal:
        scene["camera"] = {"focal_px": camera.focal_px, "principal_point": list(camera.principal_point)}
    return SyntheticScene(scene, camera, true, ws, wrong)
