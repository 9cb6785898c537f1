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
  dimension), while the scene only states the preset;
- (located scenes) the car's axis is ``car_yaw_deg`` (Gaussian) off its street's bearing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from camloc_geo.camera import Camera, clip_segment_to_image, rotation_from_angles
from camloc_geo.objects import PRESETS, ObjectSize

__all__ = [
    "LocatedScene",
    "NoiseModel",
    "SyntheticScene",
    "make_located_scene",
    "make_scene",
    "random_camera",
]

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
    car_yaw_deg: float = 2.0

    @classmethod
    def exact(cls) -> NoiseModel:
        """No noise at all (and a car exactly parallel to its street)."""
        return cls(0.0, 0.0, 0.0, 0.0, 0.0, car_yaw_deg=0.0)


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
    pp = (
        w / 2.0 + rng.uniform(-pp_offset_px, pp_offset_px),
        h / 2.0 + rng.uniform(-pp_offset_px, pp_offset_px),
    )
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


def _visible_segment(
    cam: Camera, a: FloatArray, b: FloatArray, size: tuple[int, int]
) -> FloatArray | None:
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
    clipped = clip_segment_to_image(pa, pb, size[0], size[1], 0.0)
    return None if clipped is None else clipped.ravel()


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
        car = [
            (np.array([x, 0, z]), np.array([x, W, z]))
            for x, z in ((0, 0.3), (0, H * 0.8), (L, 0.3))
        ]
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
    preset: ObjectSize = PRESETS["sedan"],
    noise: NoiseModel | None = None,
    n_annotators: int = 5,
    image_size: tuple[int, int] = (1920, 1080),
    width_sign: float = 1.0,
    give_focal: bool = False,
    scene_id: str = "synthetic",
    true_size: ObjectSize | None = None,
) -> SyntheticScene:
    """Annotate a synthetic camera's view of a car at the world origin.

    Returns
    -------
    SyntheticScene
        The scene as a ``camloc-scene/1`` dict (sizes stated as ``preset``) and the truth.
    """
    noise = noise or NoiseModel()
    w, h = image_size
    true = true_size or ObjectSize(
        *(
            d * (1.0 + rng.normal(0.0, noise.size_rel))
            for d in (preset.length_m, preset.width_m, preset.height_m)
        )
    )
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
                if (
                    seg is None
                    or math.hypot(seg[2] - seg[0], seg[3] - seg[1]) < noise.min_segment_px
                ):
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
        "object": {
            "length_m": preset.length_m,
            "width_m": preset.width_m,
            "height_m": preset.height_m,
        },
        "annotations": annotations,
    }
    if give_focal:
        scene["camera"] = {
            "focal_px": camera.focal_px,
            "principal_point": list(camera.principal_point),
        }
    return SyntheticScene(scene, camera, true, ws, wrong)


@dataclass
class LocatedScene:
    """A synthetic scene placed at a real intersection, with its truth in the local frame."""

    scene: dict[str, Any]
    camera_enu: Camera
    camera_world: Camera
    lat: float
    lon: float
    intersection_id: str
    visible_corner_orders: list[int]


def make_located_scene(
    map_data: Any,
    intersection: Any,
    rng: np.random.Generator,
    *,
    noise: NoiseModel | None = None,
    corner_sigma_m: float = 1.5,
    n_annotators: int = 5,
    image_size: tuple[int, int] = (1920, 1080),
    n_references: int = 0,
    min_corners: int = 1,
    max_corners: int = 4,
    give_streets: bool = False,
    max_tries: int = 300,
    n_landmarks: int = 0,
    landmark_kind: str = "building_corner",
    landmark_sigma_m: float = 1.0,
    state_preset: bool = False,
) -> LocatedScene | None:
    """A camera near a real intersection of ``map_data`` looking at a car and kerb corners.

    The car stands in a lane of one of the intersection's streets, parallel to it (at a dual
    carriageway in one of its two carriageways, within that carriageway's half width); the
    camera, 2.5-14 m high, 12-45 m from the intersection centre, looks towards it. The
    real kerb corners differ from the map's by ``corner_sigma_m`` (the map model's error);
    their pixels (with click noise) are listed clockwise on screen. Returns None when no
    placement shows the car and ``min_corners`` corners within ``max_tries``.

    ``n_references`` ground pixels near the car get their lat/lon, off by 0.5 m per axis.
    ``n_landmarks`` visible ground points of named buildings (``landmark_kind``:
    ``building_corner`` or ``face_midpoint`` of the map's footprint, the real one off by
    ``landmark_sigma_m``; in view, below the horizon, not hidden by a building, within 80 m)
    are listed by name; a placement without them is rejected (None when none has them).

    The car is a sedan drawn ``noise.size_rel`` off the preset per dimension. By default the
    scene states the preset's numbers (``object.length_m`` ...), which ``calibrate`` takes
    as the car's known size (no size term in its sigmas: the scene then claims more than it
    knows); ``state_preset`` states ``{"preset": "sedan"}`` instead, as a user who does not
    know the car would (``benchmarks/relative.py``'s scenes do).
    """
    noise = noise or NoiseModel()
    frame = map_data.frame
    w, h = image_size
    centre = np.array(frame.enu_from_geographic(lat=intersection.lat, lon=intersection.lon), float)
    map_corners = np.array(
        [frame.enu_from_geographic(lat=c.lat, lon=c.lon) for c in intersection.corners], float
    ).reshape(-1, 2)
    if len(map_corners) == 0:
        return None
    real_corners = map_corners + rng.normal(0.0, corner_sigma_m / math.sqrt(2), map_corners.shape)
    preset = ObjectSize(4.6, 1.8, 1.45)
    buildings = _buildings_enu(map_data, centre, 120.0)
    marks = _landmark_points(map_data, centre, landmark_kind, 90.0) if n_landmarks else []
    if n_landmarks and not marks:
        return None
    lines = _street_lines_enu(map_data, centre, 80.0)
    for _ in range(max_tries):
        street = intersection.streets[int(rng.integers(len(intersection.streets)))]
        b = math.radians(street.bearing_deg)
        along = np.array([math.sin(b), math.cos(b)])
        right = np.array([along[1], -along[0]])
        dist = float(rng.uniform(8.0, 25.0))
        # In a lane of the street's real centre line (it may bend), parallel to it there: of
        # a dual carriageway, the nearer carriageway's line, within that carriageway's half
        # width (the intersection's street.width_m spans both and the median).
        reach_m = max(10.0, street.width_m / 2) if street.carriageways > 1 else 10.0
        on_line = _along_street(lines, street.name, centre + dist * along, along, max_m=reach_m)
        half_width_m = (
            on_line[2] if on_line is not None else street.width_m / 2 / street.carriageways
        )
        if on_line is None and street.carriageways > 1:
            continue  # the merged centre line runs in the median
        lateral = float(rng.uniform(1.2, max(1.5, half_width_m - 1.0))) * rng.choice([-1.0, 1.0])
        car_centre = centre + dist * along + lateral * right
        if on_line is not None:
            base, along, _ = on_line
            right = np.array([along[1], -along[0]])
            car_centre = base + lateral * right
            on_line = _along_street(lines, street.name, car_centre, along)
            if on_line is not None:
                along = on_line[1]
        car_dir = along * rng.choice([-1.0, 1.0])
        yaw = math.radians(rng.normal(0.0, noise.car_yaw_deg)) if noise.car_yaw_deg > 0 else 0.0
        car_dir = (
            np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]]) @ car_dir
        )
        car_side = np.array([-car_dir[1], car_dir[0]])
        az = rng.uniform(0, 2 * math.pi)
        cam_xy = centre + rng.uniform(12.0, 45.0) * np.array([math.cos(az), math.sin(az)])
        cam_h = float(rng.uniform(2.5, 14.0))
        if _inside_any(buildings, cam_xy, 0.5):
            continue
        target = 0.5 * (centre + car_centre) + rng.normal(0, 3.0, 2)
        fwd = np.array([*(target - cam_xy), -cam_h])
        heading = math.degrees(math.atan2(fwd[0], fwd[1]))
        pitch = math.degrees(math.atan2(-fwd[2], math.hypot(fwd[0], fwd[1])))
        hfov = math.radians(rng.uniform(45.0, 95.0))
        f = (w / 2.0) / math.tan(hfov / 2.0)
        R = rotation_from_angles(heading, pitch, float(rng.uniform(-3, 3)))
        cam_enu = Camera.from_center(f, (w / 2.0, h / 2.0), R, [*cam_xy, cam_h])
        true = ObjectSize(
            *(
                d * (1.0 + rng.normal(0.0, noise.size_rel))
                for d in (preset.length_m, preset.width_m, preset.height_m)
            )
        )
        half_l, half_w = true.length_m / 2, true.width_m / 2
        ground = [
            car_centre + sl * half_l * car_dir + sw * half_w * car_side
            for sl in (-1, 1)
            for sw in (-1, 1)
        ]
        dists = [np.linalg.norm(g - cam_xy) for g in ground]
        o = ground[int(np.argmin(dists))]
        x_dir = car_dir if np.dot(car_centre - o, car_dir) > 0 else -car_dir
        z = np.array([0.0, 0.0, 1.0])
        x3 = np.array([*x_dir, 0.0])
        y3 = np.cross(z, x3)
        ws = 1.0 if np.dot(car_centre - o, y3[:2]) > 0 else -1.0
        # world -> enu: p_enu = Rw p_world + o
        Rw = np.column_stack([x3, y3, z])
        box = np.array(
            [
                [x, y, zz]
                for x in (0, true.length_m)
                for y in (0, ws * true.width_m)
                for zz in (0, true.height_m)
            ]
        )
        box_enu = box @ Rw.T + np.array([*o, 0.0])
        pix = cam_enu.project(box_enu)
        if (
            not np.all(np.isfinite(pix))
            or np.any(pix < 5)
            or np.any(pix[:, 0] > w - 5)
            or np.any(pix[:, 1] > h - 5)
        ):
            continue
        if np.ptp(pix[:, 0]) < 60 or _axes_degenerate(pix[0], pix[4], pix[2], pix[1]):
            continue
        corner_pix = cam_enu.project(np.column_stack([real_corners, np.zeros(len(real_corners))]))
        horizon = cam_enu.horizon_line()
        vis = [
            i
            for i, p in enumerate(corner_pix)
            if np.all(np.isfinite(p))
            and 10 <= p[0] <= w - 10
            and 10 <= p[1] <= h - 10
            and horizon @ np.array([p[0], p[1], 1.0]) > 20
        ]
        vis = [i for i in vis if not _blocked(buildings, cam_xy, real_corners[i])]
        if len(vis) < min_corners or _blocked(buildings, cam_xy, car_centre):
            continue
        seen_marks = []
        if n_landmarks:
            for name, q in marks:
                p = cam_enu.project([*q, 0.0])
                if (
                    np.all(np.isfinite(p))
                    and 10 <= p[0] <= w - 10
                    and 10 <= p[1] <= h - 10
                    and horizon @ np.array([p[0], p[1], 1.0]) > 20
                    and np.linalg.norm(q - cam_xy) < 80.0
                    and not _blocked(buildings, cam_xy, q)
                ):
                    seen_marks.append((name, q))
            if len(seen_marks) < n_landmarks:
                continue
        vis = (
            vis[:max_corners]
            if len(vis) <= max_corners
            else sorted(rng.choice(vis, max_corners, replace=False).tolist())
        )
        # Clockwise on screen = map order. All corners seen: the list may start anywhere.
        # Part of them: a person lists the visible arc clockwise from its first corner, so
        # the list starts after the widest gap (two corners are not listed the long way round).
        if len(vis) < len(real_corners):
            nc = len(real_corners)
            gaps = [(vis[(i + 1) % len(vis)] - vis[i]) % nc or nc for i in range(len(vis))]
            start = (int(np.argmax(gaps)) + 1) % len(vis)
        else:
            start = int(rng.integers(len(vis)))
        vis = vis[start:] + vis[:start]
        R_world = cam_enu.cam_from_world_rotation @ Rw
        C_world = Rw.T @ (cam_enu.center_in_world - np.array([*o, 0.0]))
        cam_world = Camera.from_center(f, (w / 2.0, h / 2.0), R_world, C_world)
        syn = make_scene(
            cam_world,
            rng,
            preset=preset,
            noise=replace_size(noise),
            n_annotators=n_annotators,
            image_size=image_size,
            width_sign=ws,
            true_size=true,
        )
        if any(
            len(a["vp_lines"][k]) < 2
            for a in syn.scene["annotations"]
            for k in ("length", "width", "height")
        ):
            continue
        scene = syn.scene
        if state_preset:
            scene["object"] = {"preset": "sedan"}
        lon, lat = frame.geographic_from_enu(float(cam_xy[0]), float(cam_xy[1]))
        clicks = corner_pix[vis] + rng.normal(0.0, noise.point_px, (len(vis), 2))
        scene["intersection"] = {"corners": np.clip(clicks, 0, [w, h]).tolist()}
        if give_streets:
            scene["intersection"]["streets"] = sorted({s.name for s in intersection.streets})[:2]
        else:
            scene["intersection"]["lat"] = intersection.lat
            scene["intersection"]["lon"] = intersection.lon
        plon, plat = frame.geographic_from_enu(
            float(centre[0] + rng.normal(0, 20)), float(centre[1] + rng.normal(0, 20))
        )
        scene["prior"] = {"lat": float(plat), "lon": float(plon), "radius_m": 150.0}
        refs = []
        for _k in range(n_references):
            for _t in range(50):
                q = car_centre + rng.normal(0, 12.0, 2)
                p = cam_enu.project([*q, 0.0])
                if (
                    np.all(np.isfinite(p))
                    and 5 < p[0] < w - 5
                    and 5 < p[1] < h - 5
                    and horizon @ np.array([*p, 1.0]) > 20
                ):
                    qlon, qlat = frame.geographic_from_enu(
                        float(q[0] + rng.normal(0, 0.5)), float(q[1] + rng.normal(0, 0.5))
                    )
                    pp = p + rng.normal(0.0, noise.point_px, 2)
                    refs.append(
                        {
                            "pixel": np.clip(pp, 0, [w, h]).tolist(),
                            "lat": float(qlat),
                            "lon": float(qlon),
                        }
                    )
                    break
        if refs:
            scene["references"] = refs
        if n_landmarks:
            pick = rng.choice(len(seen_marks), n_landmarks, replace=False)
            lms = []
            for j in sorted(int(v) for v in pick):
                name, q = seen_marks[j]
                real = q + rng.normal(0.0, landmark_sigma_m / math.sqrt(2), 2)
                p = cam_enu.project([*real, 0.0]) + rng.normal(0.0, noise.point_px, 2)
                lms.append(
                    {"pixel": np.clip(p, 0, [w, h]).tolist(), "kind": landmark_kind, "name": name}
                )
            scene["landmarks"] = lms
        return LocatedScene(
            scene,
            cam_enu,
            cam_world,
            float(lat),
            float(lon),
            intersection.id,
            [intersection.corners[i].order for i in vis],
        )
    return None


def _projected(map_data: Any, name: str) -> tuple[Any, ...]:
    """The map's streets or buildings in its local frame (``MapData.streets_enu`` ...)."""
    return tuple(getattr(map_data, name, ()))


def _street_lines_enu(
    map_data: Any, centre: FloatArray, radius_m: float
) -> list[tuple[str, Any, float]]:
    """Street centre lines (ENU LineStrings) passing within ``radius_m`` of ``centre``.

    Each with its name and its carriageway's half width, metres (``Street.width_m`` / 2:
    one carriageway of a dual road).
    """
    from shapely.geometry import Point

    around = Point(float(centre[0]), float(centre[1]))
    out = []
    streets = getattr(map_data, "streets", [])
    for st, line in zip(streets, _projected(map_data, "streets_enu"), strict=True):
        if line.length > 1.0 and line.distance(around) < radius_m:
            out.append((st.name, line, float(st.width_m) / 2.0))
    return out


def _along_street(
    lines: list[tuple[str, Any, float]],
    name: str,
    point: FloatArray,
    along: FloatArray,
    max_m: float = 10.0,
) -> tuple[FloatArray, FloatArray, float] | None:
    """The nearest point of the named street's centre line, its direction and half width.

    The direction is the chord over ±5 m (as :mod:`camloc_geo.absolute` measures a street
    under the car), oriented like ``along``; the half width (metres) is that centre line's
    own carriageway's. None when the street is not within ``max_m`` metres (a dual
    carriageway's merged axis runs down its median: its carriageways lie within half its
    outer width).
    """
    from shapely.geometry import Point

    pt = Point(float(point[0]), float(point[1]))
    near = [(line.distance(pt), line, hw) for n, line, hw in lines if n == name]
    near = [x for x in near if x[0] < max_m]
    if not near:
        return None
    _, line, half_width_m = min(near, key=lambda x: x[0])
    s = line.project(pt)
    a = line.interpolate(max(0.0, s - 5.0))
    b = line.interpolate(min(line.length, s + 5.0))
    d = np.array([b.x - a.x, b.y - a.y])
    if np.linalg.norm(d) < 1e-6:
        return None
    d = d / np.linalg.norm(d)
    if float(d @ along) < 0:
        d = -d
    p = line.interpolate(s)
    return np.array([p.x, p.y]), d, float(half_width_m)


def _landmark_points(
    map_data: Any, centre: FloatArray, kind: str, radius_m: float
) -> list[tuple[str, FloatArray]]:
    """Corners or face midpoints (ENU) of the named buildings near ``centre``.

    Only names that find the same building from the map's point are kept (a name shared by
    several buildings would be found elsewhere).
    """
    out = []
    for b in getattr(map_data, "buildings", []):
        if not b.name:
            continue
        lon, lat = b.centroid
        c = np.array(map_data.frame.enu_from_geographic(lat=lat, lon=lon), float)
        if np.linalg.norm(c - centre) > radius_m:
            continue
        try:
            if map_data.find_building(b.name).id != b.id:
                continue
        except ValueError:
            continue
        pts = b.corners if kind == "building_corner" else b.face_midpoints
        for q in map_data.frame.points_enu_from_geographic(np.asarray(pts, float)):
            out.append((b.name, q))
    return out


def _axes_degenerate(
    origin: FloatArray,
    length: FloatArray,
    width: FloatArray,
    height: FloatArray,
    min_px: float = 15.0,
    min_angle_deg: float = 5.0,
) -> bool:
    """True when two of the car's edges from the origin corner (nearly) coincide on screen.

    Such a view (the camera looking straight along the car) cannot be annotated, and
    :func:`camloc_geo.relative.calibrate` rightly rejects it.
    """
    steps = [np.asarray(p, float) - np.asarray(origin, float) for p in (length, width, height)]
    if min(float(np.linalg.norm(s)) for s in steps) < min_px:
        return True
    for i in range(3):
        for j in range(i + 1, 3):
            a, b = steps[i], steps[j]
            sin = abs(a[0] * b[1] - a[1] * b[0]) / (np.linalg.norm(a) * np.linalg.norm(b))
            if sin < math.sin(math.radians(min_angle_deg)):
                return True
    return False


def _buildings_enu(map_data: Any, centre: FloatArray, radius_m: float) -> list[Any]:
    from shapely.geometry import Point

    out = []
    around = Point(float(centre[0]), float(centre[1])).buffer(radius_m)
    for poly in _projected(map_data, "buildings_enu"):
        if poly.is_valid and poly.intersects(around):
            out.append(poly)
    return out


def _inside_any(polys: list[Any], xy: FloatArray, depth_m: float) -> bool:
    from shapely.geometry import Point

    pt = Point(float(xy[0]), float(xy[1]))
    return any(p.contains(pt) and p.exterior.distance(pt) > depth_m for p in polys)


def _blocked(polys: list[Any], a: FloatArray, b: FloatArray) -> bool:
    from shapely.geometry import LineString

    line = LineString([(float(a[0]), float(a[1])), (float(b[0]), float(b[1]))])
    return any(line.intersects(p) and line.intersection(p).length > 1.0 for p in polys)


def replace_size(noise: NoiseModel) -> NoiseModel:
    """The noise model without the size term (the caller already drew the true size)."""
    from dataclasses import replace

    return replace(noise, size_rel=0.0)
