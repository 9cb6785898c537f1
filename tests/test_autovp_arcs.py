"""Curved outlines cut into straight pieces (issue 24): the rims of a round basin or an arch,
which the line detector cuts into short straight pieces, are left out of the vanishing-point
fit; corners, window frames and straight edges broken into collinear pieces are kept."""

from __future__ import annotations

import math

import numpy as np
import pytest

cv2 = pytest.importorskip("cv2")

from camloc_geo import autovp  # noqa: E402
from camloc_geo.autovp import detect_segments, detect_vanishing_points  # noqa: E402

SIZE = (1024, 768)
DIAG_PX = math.hypot(*SIZE)
NOISE_PX = 0.3


def cam_from_world(yaw_deg: float, pitch_deg: float) -> np.ndarray:
    """Rows: camera right, down, forward in a z-up world; pitch positive looking down."""
    ps, th = math.radians(yaw_deg), math.radians(pitch_deg)
    fwd = np.array([math.cos(ps) * math.cos(th), math.sin(ps) * math.cos(th), -math.sin(th)])
    right = np.cross(fwd, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    return np.array([right, np.cross(fwd, right), fwd])


def polyline_segments(pts: np.ndarray, gap_px: float = 1.0) -> np.ndarray:
    """Segments joining consecutive points, each end pulled in by ``gap_px / 2``."""
    a, b = pts[:-1], pts[1:]
    u = (b - a) / np.linalg.norm(b - a, axis=1)[:, None]
    return np.hstack([a + 0.5 * gap_px * u, b - 0.5 * gap_px * u])


def arc_segments(
    centre: tuple[float, float],
    radii: tuple[float, float],
    from_deg: float,
    to_deg: float,
    *,
    sagitta_px: float = 1.0,
    seed: int = 0,
    jitter_px: float = 0.2,
) -> np.ndarray:
    """An ellipse arc (axes along x and y) cut into straight pieces as a line detector cuts
    it: each piece as long as the arc strays from its chord by at most about
    ``sagitta_px`` (0.7-1.3 times that, at random)."""
    rng = np.random.default_rng(seed)
    t = np.radians(np.linspace(from_deg, to_deg, 4000))
    p = np.column_stack([centre[0] + radii[0] * np.cos(t), centre[1] + radii[1] * np.sin(t)])
    knots = [0]
    while knots[-1] < len(p) - 1:
        i, limit = knots[-1], sagitta_px * rng.uniform(0.7, 1.3)
        j = i + 2
        while j < len(p):
            u = p[j] - p[i]
            off = np.abs(u[0] * (p[i:j, 1] - p[i, 1]) - u[1] * (p[i:j, 0] - p[i, 0]))
            if off.max() / np.hypot(*u) > limit:
                break
            j += 1
        knots.append(min(j - 1, len(p) - 1))
    pts = p[knots] + rng.normal(0.0, jitter_px, (len(knots), 2))
    return polyline_segments(pts)


def test_circle_and_ellipse_arcs_are_found() -> None:
    # an arch (a half circle) and a basin's rim seen from above at a slant (an ellipse)
    arch = arc_segments((400, 300), (150, 150), 180, 360)
    rim = arc_segments((500, 550), (260, 70), 0, 180, seed=1)
    assert autovp._arc_pieces(arch, DIAG_PX, NOISE_PX).mean() >= 0.9
    # the rim's flat pieces, the ones that pose as a direction, are all found (not the
    # tight ends, which turn by 30 degrees a piece)
    flat = np.abs(rim[:, 3] - rim[:, 1]) < np.tan(np.radians(30.0)) * np.abs(rim[:, 2] - rim[:, 0])
    assert flat.sum() >= 6
    assert autovp._arc_pieces(rim, DIAG_PX, NOISE_PX)[flat].all()
    # the pieces mixed, shuffled and reversed are found all the same
    both = np.vstack([arch, rim[:, [2, 3, 0, 1]]])
    order = np.random.default_rng(3).permutation(len(both))
    arc = np.empty(len(both), bool)
    arc[order] = autovp._arc_pieces(both[order], DIAG_PX, NOISE_PX)
    apart = np.r_[
        autovp._arc_pieces(arch, DIAG_PX, NOISE_PX), autovp._arc_pieces(rim, DIAG_PX, NOISE_PX)
    ]
    assert np.array_equal(arc, apart)


def test_corners_window_frames_and_broken_straight_edges_are_kept() -> None:
    rng = np.random.default_rng(0)
    parts = []
    # window frames: rectangles in perspective (turns near 90 degrees), a grid of them
    for x0 in range(100, 900, 120):
        for y0 in range(80, 400, 110):
            quad = np.array(
                [[x0, y0], [x0 + 70, y0 + 4], [x0 + 68, y0 + 84], [x0 - 1, y0 + 80], [x0, y0]],
                float,
            )
            parts.append(polyline_segments(quad))
    # straight edges broken into collinear pieces (turns of at most half a degree)
    for y_left in (450.0, 480.0, 520.0):
        x = np.cumsum(rng.uniform(30, 60, 16)) + 50
        y = y_left + 0.15 * (x - 50) + rng.normal(0, 0.15, len(x))
        parts.append(polyline_segments(np.column_stack([x, y]), gap_px=3.0))
    # building corners near the horizon: two horizontal edges meeting at a 4-15 degree turn
    for k, turn_deg in enumerate((4.0, 8.0, 15.0)):
        a = math.radians(turn_deg)
        c = np.array([300.0 + 200 * k, 600.0])
        pts = np.array([c - [220, 0], c, c + 220 * np.array([math.cos(a), -math.sin(a)])])
        parts.append(polyline_segments(pts))
    # a roof line with a gable: two corners turning opposite ways
    parts.append(polyline_segments(np.array([[80, 700], [300, 690], [360, 650], [600, 660.0]])))
    # steps: treads and risers (90-degree turns)
    steps = [[600.0, 740.0]]
    for _ in range(5):
        steps += [[steps[-1][0], steps[-1][1] - 12], [steps[-1][0] + 60, steps[-1][1] - 12]]
    parts.append(polyline_segments(np.array(steps)))
    segs = np.vstack(parts)
    assert not autovp._arc_pieces(segs, DIAG_PX, NOISE_PX).any()


def test_straight_edges_bowed_by_a_lens_are_kept() -> None:
    # barrel distortion (division model k1 = -0.1, radius in half diagonals) bows straight
    # edges into circles of several image diagonals: the distortion fit needs those pieces
    from camloc_geo.camera import RadialDistortion, distort_points_px

    dist = RadialDistortion.for_image(-0.1, *SIZE)
    pp = (SIZE[0] / 2, SIZE[1] / 2)
    parts = []
    for y0 in (20.0, 120.0, 650.0, 748.0):
        x = np.linspace(10, 1014, 25)
        pts = distort_points_px(np.column_stack([x, np.full_like(x, y0)]), dist, pp)
        parts.append(polyline_segments(pts))
    for x0 in (15.0, 1005.0):
        y = np.linspace(10, 758, 19)
        pts = distort_points_px(np.column_stack([np.full_like(y, x0), y]), dist, pp)
        parts.append(polyline_segments(pts))
    segs = np.vstack(parts)
    assert not autovp._arc_pieces(segs, DIAG_PX, NOISE_PX).any()


def arc_tangent_at(
    point: np.ndarray, direction: np.ndarray, radius_px: float, span_deg: float = 35.0
) -> np.ndarray:
    """A circle arc touching ``direction`` at ``point``, cut into pieces of a 1 px sagitta,
    one piece centred on ``point`` (its chord is parallel to ``direction``)."""
    d = direction / np.linalg.norm(direction)
    centre = point + radius_px * np.array([-d[1], d[0]])
    a0 = math.atan2(*(point - centre)[::-1])
    step = math.sqrt(8.0 * radius_px) / radius_px  # the angle of a piece
    n = int(math.radians(span_deg) / step)
    ang = a0 + step * (np.arange(-n - 1, n + 1) + 0.5)
    return polyline_segments(centre + radius_px * np.column_stack([np.cos(ang), np.sin(ang)]))


def frontal_facade_with_arcs(
    seed: int, f_px: float = 800.0, pitch_deg: float = 8.0, n_arcs: int = 9
) -> tuple[np.ndarray, np.ndarray]:
    """A facade seen square on (its verticals and horizontals; no line runs into depth) and
    ``n_arcs`` arcs below the horizon, each with one piece that points at a made-up third
    vanishing point: a basin's rims and arches, which pose as the third direction."""
    rng = np.random.default_rng(seed)
    R = cam_from_world(0.0, pitch_deg)
    w, h = SIZE
    K = np.array([[f_px, 0, w / 2], [0, f_px, h / 2], [0, 0, 1.0]])
    lines: list[list[float]] = []
    while len(lines) < 60:
        p = np.array([15.0, rng.uniform(-8, 8), rng.uniform(-2, 8)])
        axis = np.array([0.0, 0, 1]) if len(lines) % 2 else np.array([0.0, 1, 0])
        q = p + axis * rng.uniform(1, 3)
        a, b = K @ (R @ p), K @ (R @ q)
        a, b = a[:2] / a[2], b[:2] / b[2]
        inside = np.all((a > 0) & (a < SIZE)) and np.all((b > 0) & (b < SIZE))
        if inside and np.hypot(*(a - b)) > 40:
            lines.append([*a, *b])
    # the third vanishing point of the camera with 0.7 times the focal length
    vp = np.array([w / 2, h / 2 - (0.7 * f_px) ** 2 * math.tan(math.radians(pitch_deg)) / f_px])
    arcs = []
    for _ in range(n_arcs):
        t = np.array([rng.uniform(100, 924), rng.uniform(420, 740)])
        arcs.append(arc_tangent_at(t, vp - t, rng.uniform(120, 300)))
    return np.array(lines), np.vstack(arcs)


@pytest.mark.parametrize("seed", [0, 1, 3])
def test_arc_pieces_do_not_become_a_direction(seed: int) -> None:
    f_px = 800.0
    lines, arcs = frontal_facade_with_arcs(seed, f_px)
    segs = np.vstack([lines, arcs])
    flagged = autovp._arc_pieces(segs, DIAG_PX, NOISE_PX)
    assert flagged[len(lines) :].all()
    assert not flagged[: len(lines)].any()
    # with the curves' pieces counted they make a third direction of 6 lines, and a
    # confidently wrong focal length (the test can fail)
    kept = detect_vanishing_points(None, segments=segs, image_size=SIZE, seed=0, arcs="keep")
    assert min(kept.n_lines) >= 6
    assert abs(math.log(kept.focal_px / f_px)) > max(0.1, 2 * kept.focal_std_rel)
    assert kept.confidence >= 0.5
    assert not kept.warnings
    # not counted (the default), the third direction is left out: the photo is a frontal
    # facade, whose focal length it does not fix, and says so
    res = detect_vanishing_points(None, segments=segs, image_size=SIZE, seed=0)
    assert sorted(res.n_lines)[0] == 0
    assert res.focal_source in ("prior", "bound")
    assert res.warnings
    assert res.confidence < 0.3
    assert abs(math.log(res.focal_px / f_px)) < 2 * res.focal_std_rel
    # left out of the fit: the same
    dropped = detect_vanishing_points(None, segments=segs, image_size=SIZE, seed=0, arcs="drop")
    assert sorted(dropped.n_lines)[0] == 0
    assert dropped.warnings
    assert len(dropped.segments) == len(lines)


def test_bad_arcs_option() -> None:
    lines, _ = frontal_facade_with_arcs(0)
    with pytest.raises(autovp.InputError, match="arcs"):
        detect_vanishing_points(None, segments=lines, image_size=SIZE, arcs="ignore")


def test_drawn_arcs_are_left_out_by_the_detector() -> None:
    # a drawn scene: straight edges (window frames, a long broken kerb) and drawn curves
    w, h = SIZE
    img = np.full((h, w), 230, np.uint8)
    for x0 in range(80, 900, 140):
        cv2.rectangle(img, (x0, 60), (x0 + 80, 160), 30, 3)
    cv2.line(img, (40, 700), (980, 690), 30, 3)
    cv2.line(img, (60, 200), (60, 600), 30, 3)
    curves = [((600, 430), (300, 70)), ((600, 470), (260, 55)), ((180, 330), (90, 90))]
    for c, ax in curves:
        cv2.ellipse(img, c, ax, 0.0, 0.0, 180.0, 30, 3, cv2.LINE_AA)

    def on_curve(segs: np.ndarray) -> np.ndarray:
        hit = np.zeros(len(segs), bool)
        for (cx, cy), (a, b) in curves:
            for pts in (segs[:, :2], segs[:, 2:], 0.5 * (segs[:, :2] + segs[:, 2:])):
                r = np.hypot((pts[:, 0] - cx) / a, (pts[:, 1] - cy) / b)
                hit |= (np.abs(r - 1.0) * min(a, b) < 4.0) & (pts[:, 1] > cy - 2)
        return hit

    raw = detect_segments(img)
    dropped = detect_segments(img, drop_arcs=True)
    assert on_curve(raw).sum() >= 15
    assert on_curve(dropped).sum() <= 0.25 * on_curve(raw).sum()
    # the straight edges are all there still
    assert (~on_curve(dropped)).sum() == (~on_curve(raw)).sum()
