"""Image overlays: the map drawn into the snapshot with a candidate's pose.

A reviewer sees at a glance whether a candidate pose fits the picture: the map's kerbs
(street centre lines offset by half their modelled width, merged where carriageways meet),
street centre lines and building outlines are projected into the image with the candidate's
camera, together with the annotated pixels and the map points they were matched to.

Conventions
-----------
- Geometry is built in the :class:`~camloc_geo.geodesy.LocalFrame` of the
  :class:`~camloc_geo.absolute.LocateResult` (east, north, up metres), the frame the
  candidate cameras are posed in; the map's own frame is never mixed in.
- 3-D polylines are clipped against the camera's near plane (``z_cam >= near_m``) *before*
  projection, so a line passing behind the camera never wraps around the image. Ground
  features (z = 0) are additionally cut where they would reach the horizon: every drawn
  ground pixel is strictly below the horizon line.
- Pixels are continuous image coordinates (``[0.5, 0.5]`` is the centre of the top-left
  pixel, as in the scene contract); drawing converts them to OpenCV's integer-centred
  coordinates with sub-pixel precision.
- Images are BGR ``uint8`` arrays (OpenCV).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import cv2
import numpy as np
import numpy.typing as npt
import shapely
from shapely.geometry import LineString, MultiLineString, Point, Polygon

from camloc_geo.camera import Camera, clip_segment_to_image
from camloc_geo.geodesy import LocalFrame

if TYPE_CHECKING:
    from camloc_geo.absolute import Candidate, LocateResult
    from camloc_geo.osm import MapData
    from camloc_geo.scene import Scene

__all__ = [
    "OverlayFeatures",
    "candidate_overlay",
    "carriageways_enu",
    "clip_polyline_near",
    "encode_png",
    "map_features_enu",
    "overlay_points",
    "project_ground_points",
    "project_polyline",
    "render_overlay",
    "thumbnail",
]

log = logging.getLogger(__name__)
FloatArray = npt.NDArray[np.float64]
ImageArray = npt.NDArray[np.uint8]

DEFAULT_LEVEL_HEIGHT_M = 3.0
"""Storey height used for a roofline when a building only has ``building:levels``."""

#: BGR colours of the overlay (kept in one place: the legend drawn in the image uses them).
COLOURS: dict[str, tuple[int, int, int]] = {
    "kerb": (0, 215, 255),  # amber
    "centre": (255, 190, 80),  # light blue
    "building": (255, 80, 255),  # magenta
    "roof": (200, 150, 255),  # pink
    "horizon": (160, 160, 160),
    "annotated": (60, 230, 60),  # green
    "projected": (40, 40, 255),  # red
    "map_corner": (255, 140, 30),  # blue
    "text": (255, 255, 255),
}

_BLANK_BGR = (48, 44, 40)
_HORIZON_MARGIN_PX = 1.0


# --------------------------------------------------------------------------- geometry
def clip_polyline_near(
    camera: Camera, points_in_world: npt.ArrayLike, *, near_m: float = 0.5
) -> list[FloatArray]:
    """Pieces of a 3-D polyline in front of the camera's near plane.

    Parameters
    ----------
    camera
        The camera (its ``cam_from_world`` pose defines the near plane).
    points_in_world
        ``(N, 3)`` vertices, metres.
    near_m
        Distance of the near plane in front of the camera centre, metres (> 0).

    Returns
    -------
    list of (M, 3) arrays
        The runs of the polyline with ``z_cam >= near_m``; a segment that crosses the plane
        is cut at the plane. Empty when nothing is in front.
    """
    pts = np.asarray(points_in_world, dtype=np.float64).reshape(-1, 3)
    if len(pts) == 0:
        return []
    R, t = camera.cam_from_world_rotation, camera.cam_from_world_translation
    z = pts @ R[2] + t[2]
    pieces: list[FloatArray] = []
    run: list[FloatArray] = []
    if z[0] >= near_m:
        run.append(pts[0])
    for i in range(1, len(pts)):
        a, b = pts[i - 1], pts[i]
        za, zb = z[i - 1], z[i]
        a_in, b_in = za >= near_m, zb >= near_m
        if a_in and b_in:
            run.append(b)
        elif a_in and not b_in:
            run.append(a + (b - a) * (za - near_m) / (za - zb))
            pieces.append(np.asarray(run))
            run = []
        elif b_in and not a_in:
            run = [a + (b - a) * (near_m - za) / (zb - za), b]
    if len(run) >= 2:
        pieces.append(np.asarray(run))
    return [p for p in pieces if len(p) >= 2]


def project_polyline(
    camera: Camera,
    points_in_world: npt.ArrayLike,
    *,
    near_m: float = 0.5,
    below_horizon: bool = False,
) -> list[FloatArray]:
    """Project a 3-D polyline into the image, clipped against the near plane first.

    Parameters
    ----------
    camera
        The camera.
    points_in_world
        ``(N, 3)`` vertices, metres.
    near_m
        Near plane distance, metres.
    below_horizon
        True for ground features: cut the pieces where they reach the horizon line too
        (numerically, a ground point in front of a camera above the ground is always below
        the horizon; this guards against a camera at or below the ground).

    Returns
    -------
    list of (M, 2) arrays
        Pixel polylines, every vertex finite.
    """
    out: list[FloatArray] = []
    horizon = camera.horizon_line() if below_horizon else None
    for piece in clip_polyline_near(camera, points_in_world, near_m=near_m):
        px = np.asarray(camera.project(piece), dtype=np.float64).reshape(-1, 2)
        ok = np.all(np.isfinite(px), axis=1)
        if horizon is not None:
            side = px @ horizon[:2] + horizon[2]
            ok &= side > _HORIZON_MARGIN_PX
        # Keep runs of valid vertices.
        start = None
        for i, good in enumerate([*ok.tolist(), False]):
            if good and start is None:
                start = i
            elif not good and start is not None:
                if i - start >= 2:
                    out.append(px[start:i])
                start = None
    return out


def project_ground_points(camera: Camera, points_en: npt.ArrayLike) -> FloatArray:
    """Pixels of ground points ``(N, 2)`` east/north (z = 0); NaN rows behind the camera."""
    en = np.asarray(points_en, dtype=np.float64).reshape(-1, 2)
    pts = np.column_stack([en, np.zeros(len(en))])
    return np.asarray(camera.project(pts), dtype=np.float64).reshape(-1, 2)


def carriageways_enu(
    streets: Sequence[Any], frame: LocalFrame, centre_en: npt.ArrayLike, radius_m: float
) -> Any:
    """Union of the streets' modelled carriageways near a point, in ``frame`` metres.

    Each street centre line is buffered by half its ``width_m``; the union's boundary is the
    modelled kerb line, merged across intersections.

    Returns
    -------
    shapely geometry
        A (Multi)Polygon in east/north metres, clipped to the disc; empty when no street is near.
    """
    c = np.asarray(centre_en, dtype=float).reshape(2)
    disc = Point(float(c[0]), float(c[1])).buffer(radius_m, quad_segs=16)
    parts = []
    for st in streets:
        line = _line_enu(st.geometry, frame)
        if line is None or not line.intersects(disc):
            continue
        parts.append(line.buffer(max(float(st.width_m), 1.0) / 2.0, quad_segs=4))
    if not parts:
        return Polygon()
    return shapely.union_all(parts).intersection(disc)


def _line_enu(geom: Any, frame: LocalFrame) -> LineString | None:
    coords = np.asarray(geom.coords, dtype=float)
    if len(coords) < 2:
        return None
    return LineString(frame.points_enu_from_geographic(coords[:, :2]))


def _lines_of(geom: Any) -> list[FloatArray]:
    """Coordinate arrays of every line in a (multi)line geometry."""
    if geom.is_empty:
        return []
    if isinstance(geom, LineString):
        return [np.asarray(geom.coords, dtype=float)]
    if isinstance(geom, MultiLineString) or hasattr(geom, "geoms"):
        out: list[FloatArray] = []
        for g in geom.geoms:
            out.extend(_lines_of(g))
        return out
    return []


@dataclass
class OverlayFeatures:
    """Map features in a local frame, ready to project.

    Attributes
    ----------
    kerbs, centre_lines
        Lists of ``(N, 3)`` ground polylines (z = 0), metres.
    building_ground
        Closed ``(N, 3)`` footprint rings at z = 0.
    building_roofs
        ``(ring at roof height, height)`` for buildings with a known height.
    """

    kerbs: list[FloatArray] = field(default_factory=list)
    centre_lines: list[FloatArray] = field(default_factory=list)
    building_ground: list[FloatArray] = field(default_factory=list)
    building_roofs: list[tuple[FloatArray, float]] = field(default_factory=list)


def _with_z(xy: FloatArray, z: float = 0.0) -> FloatArray:
    return np.column_stack([xy[:, :2], np.full(len(xy), z)])


def building_height_m(building: Any) -> float | None:
    """A building's height from ``height`` or ``building:levels``, else None."""
    h = getattr(building, "height_m", None)
    if h is not None and math.isfinite(h) and h > 0:
        return float(h)
    lv = getattr(building, "levels", None)
    if lv is not None and math.isfinite(lv) and lv > 0:
        return float(lv) * DEFAULT_LEVEL_HEIGHT_M
    return None


def map_features_enu(
    map_data: MapData | None,
    frame: LocalFrame,
    centre_en: npt.ArrayLike,
    *,
    radius_m: float = 150.0,
    roofs: bool = True,
) -> OverlayFeatures:
    """Kerbs, centre lines and building outlines within ``radius_m`` of a point.

    Parameters
    ----------
    map_data
        The map (None gives no features).
    frame
        The frame to express them in (the result's frame, where the cameras live).
    centre_en
        Centre of the disc, east/north metres (usually the camera position).
    radius_m
        Features are clipped to this disc.
    roofs
        Also give the roof outline of buildings with a known height (or levels).
    """
    feats = OverlayFeatures()
    if map_data is None:
        return feats
    c = np.asarray(centre_en, dtype=float).reshape(2)
    disc = Point(float(c[0]), float(c[1])).buffer(radius_m, quad_segs=16)
    for geom in _lines_of(carriageways_enu(map_data.streets, frame, c, radius_m).boundary):
        clipped = LineString(geom).intersection(disc.buffer(-0.01))
        feats.kerbs.extend(_with_z(a) for a in _lines_of(clipped) if len(a) >= 2)
    for st in map_data.streets:
        line = _line_enu(st.geometry, frame)
        if line is None or not line.intersects(disc):
            continue
        feats.centre_lines.extend(
            _with_z(a) for a in _lines_of(line.intersection(disc)) if len(a) >= 2
        )
    for b in map_data.buildings:
        ring = np.asarray(b.footprint.exterior.coords, dtype=float)
        en = frame.points_enu_from_geographic(ring[:, :2])
        poly = Polygon(en)
        if not poly.intersects(disc):
            continue
        feats.building_ground.append(_with_z(en))
        h = building_height_m(b) if roofs else None
        if h is not None:
            feats.building_roofs.append((_with_z(en, h), h))
    return feats


# ---------------------------------------------------------------------------- drawing
def _to_cv(px: FloatArray, shift: int) -> npt.NDArray[np.int32]:
    """Continuous pixels to OpenCV fixed-point coordinates (pixel k's centre is k + 0.5)."""
    return np.round((px - 0.5) * (1 << shift)).astype(np.int32)


def _draw_polyline(
    img: ImageArray,
    px: FloatArray,
    colour: tuple[int, int, int],
    thickness: int,
    *,
    dashed: bool = False,
) -> None:
    h, w = img.shape[:2]
    shift = 4
    for i in range(1, len(px)):
        seg = clip_segment_to_image(px[i - 1], px[i], float(w), float(h), 4.0)
        if seg is None:
            continue
        if dashed:
            length = float(np.linalg.norm(seg[1] - seg[0]))
            step = max(8.0, 4.0 * thickness)
            n = max(1, int(length // step))
            for k in range(0, n, 2):
                a = seg[0] + (seg[1] - seg[0]) * (k / n)
                b = seg[0] + (seg[1] - seg[0]) * (min(k + 1, n) / n)
                ia, ib = _to_cv(a, shift), _to_cv(b, shift)
                cv2.line(
                    img,
                    (int(ia[0]), int(ia[1])),
                    (int(ib[0]), int(ib[1])),
                    colour,
                    thickness,
                    cv2.LINE_AA,
                    shift,
                )
            continue
        ia, ib = _to_cv(seg[0], shift), _to_cv(seg[1], shift)
        cv2.line(
            img,
            (int(ia[0]), int(ia[1])),
            (int(ib[0]), int(ib[1])),
            colour,
            thickness,
            cv2.LINE_AA,
            shift,
        )


def _label(
    img: ImageArray, text: str, at: FloatArray, colour: tuple[int, int, int], scale: float
) -> None:
    x, y = round(float(at[0])), round(float(at[1]))
    thick = max(1, round(scale * 2))
    cv2.putText(
        img, text, (x, y), cv2.FONT_HERSHEY_SIMPLEX, scale, (0, 0, 0), thick + 2, cv2.LINE_AA
    )
    cv2.putText(img, text, (x, y), cv2.FONT_HERSHEY_SIMPLEX, scale, colour, thick, cv2.LINE_AA)


def _horizon_segment(camera: Camera, w: int, h: int) -> FloatArray | None:
    a, b, c = camera.horizon_line()
    if abs(b) > abs(a):
        p, q = np.array([0.0, -(c) / b]), np.array([float(w), -(c + a * w) / b])
    else:
        p, q = np.array([-(c) / a, 0.0]), np.array([-(c + b * h) / a, float(h)])
    return clip_segment_to_image(p, q, float(w), float(h), 0.0)


@dataclass
class OverlayPoint:
    """An annotated pixel and the projection of the map point it was matched to."""

    kind: str
    label: str
    annotated_px: FloatArray
    projected_px: FloatArray
    map_label: str


def overlay_points(candidate: Candidate, result: LocateResult) -> list[OverlayPoint]:
    """The candidate's matches: annotated pixels and their matched map points, projected.

    Parameters
    ----------
    candidate
        A candidate of ``result`` (its camera is posed in ``result.frame``).
    result
        The locate result.

    Returns
    -------
    list of OverlayPoint
        One per match (references, corners, landmarks); ``projected_px`` is NaN for a map
        point behind the camera.
    """
    out: list[OverlayPoint] = []
    for m in candidate.matches:
        en = np.asarray(m["map_en"], dtype=float).reshape(1, 2)
        proj = project_ground_points(candidate.camera, en)[0]
        label = str(m.get("label", m["kind"]))
        if m["kind"] == "corner":
            short = label.rsplit("[", 1)[-1].rstrip("]")
            map_label = f"m{m.get('order', '?')}"
        elif m["kind"] == "reference":
            short = "R" + label.rsplit("[", 1)[-1].rstrip("]")
            map_label = short
        else:
            short = "L" + label.rsplit("[", 1)[-1].rstrip("]")
            map_label = short
        out.append(
            OverlayPoint(m["kind"], short, np.asarray(m["pixel"], dtype=float), proj, map_label)
        )
    return out


def render_overlay(
    camera: Camera,
    image_size: tuple[int, int],
    features: OverlayFeatures,
    *,
    background: ImageArray | None = None,
    points: Sequence[OverlayPoint] = (),
    map_corners: Sequence[tuple[str, FloatArray]] = (),
    title: str | None = None,
) -> ImageArray:
    """Draw map features and matched points into an image.

    Parameters
    ----------
    camera
        The pose to project with (same frame as ``features``).
    image_size
        ``(width, height)`` of the snapshot; the overlay has this size.
    features
        What to draw (:func:`map_features_enu`).
    background
        The snapshot (BGR), resized to ``image_size`` if needed; a dark blank canvas when None.
    points
        Annotated pixels with their matched map points (:func:`overlay_points`).
    map_corners
        ``(label, pixel)`` of the intersection's kerb corners (all of them, matched or not);
        non-finite pixels are skipped.
    title
        A caption drawn in the top-left corner.

    Returns
    -------
    The BGR image.
    """
    w, h = int(image_size[0]), int(image_size[1])
    if background is None:
        img = np.empty((h, w, 3), dtype=np.uint8)
        img[:] = _BLANK_BGR
    else:
        bg = background if background.ndim == 3 else cv2.cvtColor(background, cv2.COLOR_GRAY2BGR)
        if bg.shape[1] != w or bg.shape[0] != h:
            bg = cv2.resize(bg, (w, h), interpolation=cv2.INTER_AREA)
        # Dim the photo a little so the lines stand out.
        img = np.asarray(cv2.convertScaleAbs(bg[:, :, :3], alpha=0.75, beta=0.0), dtype=np.uint8)
    unit = max(1.0, w / 640.0)
    thick = max(2, round(unit * 1.3))
    hz = _horizon_segment(camera, w, h)
    if hz is not None:
        _draw_polyline(img, hz, COLOURS["horizon"], max(1, thick // 2), dashed=True)
    for ring in features.building_ground:
        for px in project_polyline(camera, ring, below_horizon=True):
            _draw_polyline(img, px, COLOURS["building"], thick)
    for roof, _hgt in features.building_roofs:
        for px in project_polyline(camera, roof):
            _draw_polyline(img, px, COLOURS["roof"], max(1, thick - 1))
        for v in roof[:-1]:
            edge = np.array([[v[0], v[1], 0.0], v])
            for px in project_polyline(camera, edge):
                _draw_polyline(img, px, COLOURS["roof"], max(1, thick - 1))
    for line in features.centre_lines:
        for px in project_polyline(camera, line, below_horizon=True):
            _draw_polyline(img, px, COLOURS["centre"], max(1, thick - 1), dashed=True)
    for line in features.kerbs:
        for px in project_polyline(camera, line, below_horizon=True):
            _draw_polyline(img, px, COLOURS["kerb"], thick)
    scale = 0.45 * unit
    r = round(6 * unit)
    matched = {p.map_label for p in points}
    for label, px in map_corners:
        if not np.all(np.isfinite(px)) or not (-r <= px[0] <= w + r and -r <= px[1] <= h + r):
            continue
        ic = _to_cv(np.asarray(px, dtype=float), 0)
        cv2.circle(
            img, (int(ic[0]), int(ic[1])), max(2, r // 2), COLOURS["map_corner"], -1, cv2.LINE_AA
        )
        if label not in matched:
            _label(img, label, px + np.array([-3.5 * r, 2.2 * r]), COLOURS["map_corner"], scale)
    for p in points:
        a = p.annotated_px
        q = p.projected_px
        if np.all(np.isfinite(q)):
            _draw_polyline(img, np.array([a, q]), COLOURS["projected"], max(1, thick - 1))
            iq = _to_cv(q, 0)
            cv2.drawMarker(
                img,
                (int(iq[0]), int(iq[1])),
                COLOURS["projected"],
                cv2.MARKER_TILTED_CROSS,
                2 * r,
                thick,
                cv2.LINE_AA,
            )
            _label(img, p.map_label, q + np.array([r, 2.2 * r]), COLOURS["projected"], scale)
        ia = _to_cv(a, 0)
        cv2.circle(img, (int(ia[0]), int(ia[1])), r, COLOURS["annotated"], thick, cv2.LINE_AA)
        _label(img, p.label, a + np.array([r + 2, -r]), COLOURS["annotated"], scale * 1.2)
    _draw_key(img, unit, title)
    return img


def _draw_key(img: ImageArray, unit: float, title: str | None) -> None:
    rows = [
        ("kerb", "kerbs (modelled)"),
        ("centre", "street centre lines"),
        ("building", "buildings (ground)"),
        ("roof", "roofline (known height)"),
        ("annotated", "annotated pixel (scene index)"),
        ("projected", "matched map point (m = map corner)"),
        ("map_corner", "map kerb corner (clockwise order)"),
    ]
    scale = 0.42 * unit
    line_h = round(18 * unit)
    x0, y0 = int(8 * unit), int(8 * unit)
    n = len(rows) + (1 if title else 0)
    box_w = int(300 * unit)
    sub = img[y0 : y0 + n * line_h + int(8 * unit), x0 : x0 + box_w]
    sub[:] = (sub.astype(np.float32) * 0.35).astype(np.uint8)
    y = y0 + line_h
    if title:
        _label(img, title, np.array([x0 + 6 * unit, y - 4 * unit]), COLOURS["text"], scale)
        y += line_h
    for key, text in rows:
        cv2.line(
            img,
            (int(x0 + 6 * unit), int(y - 8 * unit)),
            (int(x0 + 30 * unit), int(y - 8 * unit)),
            COLOURS[key],
            max(2, int(unit * 1.3)),
            cv2.LINE_AA,
        )
        _label(img, text, np.array([x0 + 38 * unit, y - 4 * unit]), COLOURS["text"], scale)
        y += line_h


def _read_background(scene: Scene | None, image_size: tuple[int, int]) -> ImageArray | None:
    if scene is None:
        return None
    path = scene.image_file()
    if path is None:
        return None
    if not Path(path).is_file():
        log.warning("scene image %s not found: overlay on a blank canvas", path)
        return None
    img = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if img is None:
        log.warning("cannot read scene image %s: overlay on a blank canvas", path)
        return None
    return np.asarray(img, dtype=np.uint8)


def candidate_overlay(
    result: LocateResult,
    candidate: Candidate,
    map_data: MapData | None,
    *,
    scene: Scene | None = None,
    path: str | Path | None = None,
    radius_m: float = 150.0,
    features: OverlayFeatures | None = None,
    background: ImageArray | None = None,
) -> ImageArray:
    """The overlay image of one candidate, optionally written as PNG.

    Parameters
    ----------
    result
        The locate result (frame, image size).
    candidate
        One of its candidates.
    map_data
        The map (kerbs, centre lines, buildings); None draws only the matched points.
    scene
        The scene, for its snapshot (``scene.image_file()``); blank canvas without one.
    path
        Write the PNG here (folders are created).
    radius_m
        Map features within this distance of the candidate are drawn.
    features, background
        Precomputed features / snapshot (skips the map clipping / image reading).

    Returns
    -------
    The BGR overlay at the image size.
    """
    size = result.image_size
    if size[0] <= 0 or size[1] <= 0:
        size = scene.image_size if scene is not None else (1920, 1080)
    if features is None:
        features = map_features_enu(map_data, result.frame, candidate.east_north, radius_m=radius_m)
    if background is None:
        background = _read_background(scene, size)
    title = (
        f"{result.scene_id}: rank {candidate.rank}, score {candidate.score:.3f}, {candidate.method}"
    )
    corners: list[tuple[str, FloatArray]] = []
    if result.intersection is not None and result.intersection.corners:
        en = result.intersection.corners_enu(result.frame)
        px = project_ground_points(candidate.camera, en)
        corners = [(f"m{c.order}", px[i]) for i, c in enumerate(result.intersection.corners)]
    img = render_overlay(
        candidate.camera,
        size,
        features,
        background=background,
        points=overlay_points(candidate, result),
        map_corners=corners,
        title=title,
    )
    if path is not None:
        p = Path(path)
        from camloc_geo._io import atomic_path

        p.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(p) as tmp:
            if not cv2.imwrite(str(tmp), img):
                raise OSError(f"cannot write overlay PNG {p}")
    return img


def thumbnail(img: ImageArray, max_width: int) -> ImageArray:
    """Downscale (area interpolation) to at most ``max_width`` pixels wide."""
    h, w = img.shape[:2]
    if w <= max_width:
        return img
    nh = max(1, round(h * max_width / w))
    return np.asarray(
        cv2.resize(img, (max_width, nh), interpolation=cv2.INTER_AREA), dtype=np.uint8
    )


def encode_png(img: ImageArray, *, max_width: int | None = None) -> bytes:
    """PNG bytes of an image, downscaled to ``max_width`` first when given."""
    if max_width is not None:
        img = thumbnail(img, max_width)
    ok, buf = cv2.imencode(".png", img, [cv2.IMWRITE_PNG_COMPRESSION, 9])
    if not ok:
        raise ValueError("PNG encoding failed")
    return bytes(buf.tobytes())
