"""Chords of curved outlines are not lines of the scene (issue 24, stop 39).

A line detector cuts a ring, a dome or a basin's rim into short straight pieces; near where
the curve runs along a vanishing direction they point at that vanishing point. On exifr's
``broken1.jpg`` (the Palace of Culture, Warsaw) the rotunda's rings posed as both horizontal
directions: -17.5 % at a stated 2.9 %, confidence 0.84. ``_curve_pieces`` finds them by
what a curve is: each piece is continued at both its ends by another piece turned the same
way by a few degrees (a straight edge cut in pieces continues straight, a corner turns by
more).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camloc_geo import autovp


def _polyline_pieces(pts_px: np.ndarray, step: int, gap_px: float = 1.0) -> np.ndarray:
    """Cut a polyline into straight pieces of ``step`` vertices, ``gap_px`` apart."""
    segs = []
    for i in range(0, len(pts_px) - step, step):
        a, b = pts_px[i].astype(float), pts_px[i + step].astype(float)
        u = (b - a) / np.linalg.norm(b - a)
        segs.append(np.r_[a + 0.5 * gap_px * u, b - 0.5 * gap_px * u])
    return np.array(segs)


def _ellipse_arc_px(
    centre_px: tuple[float, float], a_px: float, b_px: float, t0_deg: float, t1_deg: float
) -> np.ndarray:
    t = np.radians(np.linspace(t0_deg, t1_deg, 400))
    return np.c_[centre_px[0] + a_px * np.cos(t), centre_px[1] + b_px * np.sin(t)]


def test_chords_of_a_flat_ring_are_found() -> None:
    # the front of a rotunda's ring seen from below: a flat ellipse, cut into 40-60 px pieces
    arc = _ellipse_arc_px((512.0, 500.0), 400.0, 60.0, 20.0, 160.0)
    segs = _polyline_pieces(arc, 20)
    flags = autovp._curve_pieces(segs, 0.25, 6.0)
    assert len(segs) >= 15
    # every piece but possibly the two at the ends of the run
    assert flags.sum() >= len(segs) - 2


def test_a_straight_edge_cut_in_pieces_is_not_a_curve() -> None:
    rng = np.random.default_rng(0)
    x = np.linspace(100.0, 900.0, 400)
    line = np.c_[x, 300.0 + 0.12 * (x - 100.0)]
    segs = _polyline_pieces(line, 20)
    segs = segs + rng.normal(0.0, 0.25, segs.shape)
    assert not autovp._curve_pieces(segs, 0.25, 6.0).any()


@pytest.mark.parametrize("turn_deg", [30.0, 60.0, 90.0])
def test_corners_and_window_frames_are_not_curves(turn_deg: float) -> None:
    # a polygon turning by turn_deg at each corner (a window frame at 90 degrees), each
    # side one piece: every piece is bent the same way at both ends, by more than a curve's
    segs = []
    p, ang = np.array([200.0, 200.0]), 0.0
    for _ in range(int(360 / turn_deg)):
        q = p + 80.0 * np.array([math.cos(ang), math.sin(ang)])
        segs.append(np.r_[p, q])
        p, ang = q, ang + math.radians(turn_deg)
    assert not autovp._curve_pieces(np.array(segs), 0.25, 6.0).any()


def test_a_kinked_edge_is_not_a_curve() -> None:
    # two straight edges meeting at 12 degrees (a facade's cornice and the next facade's),
    # each cut into pieces: only the two pieces at the kink are bent, each at one end
    x = np.linspace(0.0, 300.0, 200)
    left = np.c_[100.0 + x, 400.0 + 0.0 * x]
    a = math.radians(12.0)
    right = np.c_[400.0 + x * math.cos(a), 400.0 + x * math.sin(a)]
    segs = np.vstack([_polyline_pieces(left, 40), _polyline_pieces(right, 40)])
    assert not autovp._curve_pieces(segs, 0.25, 6.0).any()


def test_the_pieces_of_a_ring_drawn_in_an_image_are_found() -> None:
    # A rotunda's ring drawn as a band: the detector's chords of its edges are found and
    # told from the straight lines of a window grid beside it.
    cv2 = pytest.importorskip("cv2")
    img = np.full((768, 1024), 200, np.uint8)
    outer = _ellipse_arc_px((512.0, 420.0), 430.0, 70.0, 15.0, 165.0)
    inner = _ellipse_arc_px((512.0, 440.0), 430.0, 70.0, 15.0, 165.0)[::-1]
    cv2.fillPoly(img, [np.round(np.r_[outer, inner] * 16).astype(np.int32)], 80, cv2.LINE_AA, 4)
    # a facade's window grid beside it, so that the photo has its directions
    for x in range(60, 960, 60):
        cv2.line(img, (x * 16, 560 * 16), (x * 16, 740 * 16), 60, 2, cv2.LINE_AA, 4)
    for y in range(570, 740, 30):
        cv2.line(img, (40 * 16, y * 16), (980 * 16, (y + 25) * 16), 60, 2, cv2.LINE_AA, 4)
    segs, curve = autovp._detect_segments(img)
    mid_y = 0.5 * (segs[:, 1] + segs[:, 3])
    on_ring = mid_y < 545.0
    assert on_ring.sum() >= 8
    # the ring's pieces are found as chords of a curve, the grid's lines are not
    assert curve[on_ring].mean() >= 0.6
    assert curve[~on_ring].mean() <= 0.05


def _rotunda_photo(pitch_deg: float, f_px: float = 800.0) -> np.ndarray:
    """A rotunda 45 m off (radius 20 m), its cornices drawn as bands and its columns as
    lines, seen from 1.6 m up looking up ``-pitch_deg``: the cornices' chords are its only
    horizontal lines."""
    cv2 = pytest.importorskip("cv2")
    w, h = 1024, 768
    th = math.radians(pitch_deg)
    fwd = np.array([math.cos(th), 0.0, -math.sin(th)])
    right = np.cross(fwd, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    cam_from_world = np.array([right, np.cross(fwd, right), fwd])
    img = np.full((h, w), 200, np.uint8)
    centre = np.array([45.0, 0.0, -1.6])

    def project_px(pts_world: np.ndarray) -> np.ndarray:
        pc = pts_world @ cam_from_world.T
        return np.c_[f_px * pc[:, 0] / pc[:, 2] + w / 2, f_px * pc[:, 1] / pc[:, 2] + h / 2]

    az = np.radians(np.linspace(100.0, 260.0, 400))  # the half facing the camera
    rings_m = (3.0, 3.6, 9.0, 9.6, 14.0, 14.5)
    for z in rings_m:
        low = centre + np.c_[20.0 * np.cos(az), 20.0 * np.sin(az), np.full(len(az), z)]
        band = np.r_[project_px(low), project_px(low + np.array([0.0, 0.0, 0.6]))[::-1]]
        cv2.fillPoly(img, [np.round(band * 16).astype(np.int32)], 90, cv2.LINE_AA, 4)
    spans_m = [(0.0, 2.7), (4.5, 8.7), (10.5, 13.7)]
    for a in np.radians(np.arange(104.0, 258.0, 7.0)):
        foot = centre + np.array([20.0 * math.cos(a), 20.0 * math.sin(a), 0.0])
        for z0, z1 in spans_m:
            ends = project_px(np.array([foot + np.array([0.0, 0.0, z]) for z in (z0, z1)]))
            p, q = np.round(ends * 16).astype(np.int32)
            cv2.line(img, (int(p[0]), int(p[1])), (int(q[0]), int(q[1])), 60, 2, cv2.LINE_AA, 4)
    rng = np.random.default_rng(0)
    return np.clip(img + rng.normal(0.0, 2.0, img.shape), 0, 255).astype(np.uint8)


def _chords_in(result: autovp.AutoVPResult, segs: np.ndarray, chords: np.ndarray) -> np.ndarray:
    keys = {tuple(np.round(s, 6)) for s in segs[chords]}
    return np.array([tuple(np.round(s, 6)) in keys for s in result.segments])


@pytest.mark.parametrize("pitch_deg", [-10.0, -20.0])
def test_a_direction_made_of_a_rotundas_rings_is_read_again_without_them(
    pitch_deg: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    img = _rotunda_photo(pitch_deg)
    segs, chords = autovp._detect_segments(img)
    assert chords.sum() >= 20
    # now (the default): the photo is read again without them, and still says it does
    # not fix the focal length
    res = autovp.detect_vanishing_points(img)
    assert not _chords_in(res, segs, chords).any()
    assert res.warnings
    # before: a horizontal direction was mostly the rings' chords
    monkeypatch.setattr(autovp, "_CURVE_MODE", "keep")
    kept = autovp.detect_vanishing_points(img)
    in_kept = _chords_in(kept, segs, chords)
    horizontal = kept.labels >= 1
    assert np.count_nonzero(in_kept & horizontal) >= 0.5 * np.count_nonzero(horizontal)
    assert res.focal_std_rel >= 0.2


def test_rings_that_leave_too_little_without_them_are_said_to_decide() -> None:
    # at 15 degrees up, without the chords fewer than two directions are left: the
    # reading with them stands, said to rest on pieces of curves
    res = autovp.detect_vanishing_points(_rotunda_photo(-15.0))
    assert any("pieces of curves" in w_ for w_ in res.warnings)
    assert res.focal_std_rel >= 0.2
    assert res.confidence < 0.5


def test_curve_directions_needs_enough_chords_and_share() -> None:
    labels = np.array([0] * 20 + [1] * 10 + [2] * 30)
    chords = np.zeros(60, dtype=bool)
    chords[20:22] = True  # two chords of 10: too few
    chords[30:35] = True  # five of 30: a share under 15 %... 16.7 %: counted
    assert autovp._curve_directions(labels, chords) == [2]
    chords[22] = True  # three of 10
    assert autovp._curve_directions(labels, chords) == [1, 2]
    chords[30:35] = False
    chords[30:33] = True  # three of 30: 10 %
    assert autovp._curve_directions(labels, chords) == [1]


def test_read_again_with_a_given_distortion_and_annotated_axes() -> None:
    # the chords stay aligned with the segments when a given k1 undistorts them and
    # annotated axes are fitted with them
    img = _rotunda_photo(-20.0)
    segs, chords = autovp._detect_segments(img)
    axes = [((100.0, 700.0), (100.0, 600.0)), ((100.0, 700.0), (300.0, 705.0))]
    res = autovp.detect_vanishing_points(img, distortion_k1=-0.02)
    assert not _chords_in(res, segs, chords).any()
    assert res.distortion == -0.02
    # with the axes the chords are needed for a second direction: the reading with them
    # stands, said to rest on curves (the axes are the result's first segments)
    res = autovp.detect_vanishing_points(img, distortion_k1=-0.02, axes_hint=axes)
    assert len(res.segments) == len(segs) + len(axes)
    assert _chords_in(res, segs, chords)[len(axes) :].sum() == chords.sum()
    assert any("pieces of curves" in w_ for w_ in res.warnings)
    assert res.focal_std_rel >= 0.2
