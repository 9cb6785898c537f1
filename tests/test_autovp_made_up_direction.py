"""A vanishing direction made up of tangent pieces of curves (issue 24, session 35).

A frontal scene fixes its focal length through its third direction alone. Where that
direction is the near-straight stretches of round things (a basin's rim, steps, an arch:
Lund 4-fountain DSC_0492, +121 % at a stated 8.9 % before), its lines meet wherever the
curves' tangents do, and the focal length with them. Synthetic segments: a facade seen
nearly square-on (8 degrees off; its horizontal and vertical vanishing points far off) and
16 short arcs, each drawn as three pieces bent 8-14 degrees at their joints, whose middle
pieces all point at the vanishing point the third direction would have at 1.5 times the
focal length. Before the curve test (``autovp._curve_direction``) every seed read +20-23 %
at a stated 7-9 %, confidence 0.63-0.66, no warning: confidently wrong.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camloc_geo import autovp
from camloc_geo.autovp import detect_vanishing_points

F_PX = 1000.0
SIZE = (1280, 960)
YAW_DEG = 8.0  # the facade's turn from square-on: its vanishing point lies 7 f off


def cam_from_world(yaw_deg: float, pitch_deg: float) -> np.ndarray:
    """Rows: camera right, down, forward in a z-up world; pitch positive looking down."""
    ps, th = math.radians(yaw_deg), math.radians(pitch_deg)
    fwd = np.array([math.cos(ps) * math.cos(th), math.sin(ps) * math.cos(th), -math.sin(th)])
    right = np.cross(fwd, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    return np.array([right, np.cross(fwd, right), fwd])


def frontal_scene_with_arcs(
    seed: int, *, n_arcs: int = 16, focal_factor: float = 1.5, straight: bool = False
) -> np.ndarray:
    """Segments (N x 4, px) of a facade seen ``YAW_DEG`` off square, and ``n_arcs`` arcs.

    The arcs' middle pieces point at the vanishing point the third direction would have at
    ``focal_factor`` times the true focal length; with ``straight`` the arcs' end pieces
    continue them straight (edges cut in three, no curve).
    """
    rng = np.random.default_rng(seed)
    w, h = SIZE
    c = np.array([w / 2, h / 2])
    R = cam_from_world(YAW_DEG, 2.0)
    segs: list[list[float]] = []

    def add_world(p: np.ndarray, q: np.ndarray) -> None:
        pc, qc = R @ p, R @ q
        if pc[2] < 0.5 or qc[2] < 0.5:
            return
        a = F_PX * pc[:2] / pc[2] + c
        b = F_PX * qc[:2] / qc[2] + c
        if all(0 <= v[0] <= w and 0 <= v[1] <= h for v in (a, b)) and np.hypot(*(b - a)) > 30:
            segs.append([*(a + rng.normal(0, 0.3, 2)), *(b + rng.normal(0, 0.3, 2))])

    along = np.array([0.0, 1.0, 0.0])  # the facade runs along world y, 20 m ahead (x)
    up = np.array([0.0, 0.0, 1.0])
    for _ in range(60):
        p = np.array([20.0, rng.uniform(-12, 12), rng.uniform(-1.5, 14)])
        add_world(p, p + up * rng.uniform(1.5, 5))
    for _ in range(50):
        p = np.array([20.0, rng.uniform(-12, 9), rng.uniform(-1.5, 14)])
        add_world(p, p + along * rng.uniform(1.5, 4))
    # where the third direction (world x) would meet at focal_factor times the focal length:
    # the far facade point stays, the near one moves so that -(v1 - c).(v3 - c) = f'^2
    d1, d3 = R @ along, R @ np.array([1.0, 0.0, 0.0])
    f_fake = focal_factor * F_PX
    v1 = f_fake * d1[:2] / d1[2]
    v3 = F_PX * d3[:2] / d3[2]
    t = -(f_fake**2) / float(v1 @ v3)
    vp_fake = c + t * v3
    for _ in range(n_arcs):
        mid = np.array([rng.uniform(0.1 * w, 0.9 * w), rng.uniform(0.1 * h, 0.95 * h)])
        u = vp_fake - mid
        u /= np.linalg.norm(u)
        half = 0.5 * rng.uniform(70, 120)
        a, b = mid - half * u, mid + half * u
        segs.append([*a, *b])
        bend = 0.0 if straight else math.radians(rng.uniform(8, 14))
        for end, sign in ((b, 1.0), (a, -1.0)):
            ang = math.atan2(sign * u[1], sign * u[0]) + bend  # the curve turns steadily
            q = end + rng.uniform(40, 60) * np.array([math.cos(ang), math.sin(ang)])
            segs.append([*end, *q])
    return np.asarray(segs, dtype=float)


def _confidently_wrong(res: autovp.AutoVPResult) -> bool:
    err = abs(math.log(res.focal_px / F_PX))
    return (
        err > math.log(1.1)
        and err > 2 * res.focal_std_rel
        and not res.warnings
        and res.confidence >= 0.5
    )


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_direction_of_curve_pieces_leaves_the_focal_length_loose(seed: int) -> None:
    segs = frontal_scene_with_arcs(seed)
    res = detect_vanishing_points(None, segments=segs, image_size=SIZE, seed=0)
    err = math.log(res.focal_px / F_PX)
    # the stated sigma covers the error (before: +20-23 % at a stated 7-9 %, no warning)
    assert abs(err) < 2 * res.focal_std_rel, (res.focal_px, res.focal_std_rel)
    assert res.focal_std_rel > 0.1
    assert not _confidently_wrong(res)
    assert any("pieces of" in w for w in res.warnings), res.warnings


def test_straight_edges_cut_in_pieces_are_not_taken_for_a_curve() -> None:
    """The same scene with the arcs' pieces continuing each other straight: three pieces of
    one edge, not a curve; the third direction stands (the focal length it gives is
    whatever it gives: the test is only that the curve test leaves it alone)."""
    segs = frontal_scene_with_arcs(0, straight=True)
    res = detect_vanishing_points(None, segments=segs, image_size=SIZE, seed=0)
    assert not any("pieces of" in w for w in res.warnings), res.warnings


def test_curve_share_counts_pieces_continued_by_a_bent_piece() -> None:
    straight = np.array([[0.0, 0.0, 50.0, 0.0], [50.0, 0.0, 100.0, 0.0], [0, 40, 60, 40.0]])
    bent = np.array(
        [[0.0, 0.0, 50.0, 0.0], [50.0, 0.0, 99.2, 8.7], [0, 40, 60, 40.0]]  # 10 degrees
    )
    sel = np.array([True, False, True])
    assert autovp._curve_share(straight, sel) == 0.0
    assert autovp._curve_share(bent, sel) == pytest.approx(0.5)
