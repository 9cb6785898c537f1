"""The synthetic handheld street photos (camloc_geo.testing.street_photo_render)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from camloc_geo.autovp import detect_vanishing_points, pitch_roll_from_up
from camloc_geo.camera import Camera, rotation_from_angles
from camloc_geo.testing.street_photo_render import (
    DEV_SEEDS,
    HELD_OUT_SEEDS,
    render_street_photo,
)


def test_seed_ranges_do_not_overlap() -> None:
    assert set(DEV_SEEDS).isdisjoint(HELD_OUT_SEEDS)
    assert len(DEV_SEEDS) == len(HELD_OUT_SEEDS) == 40


def test_same_seed_same_photo_and_other_seed_another() -> None:
    a, b, c = render_street_photo(3), render_street_photo(3), render_street_photo(4)
    assert np.array_equal(a.image, b.image)
    assert a.focal_px == b.focal_px
    assert a.image.shape != c.image.shape or not np.array_equal(a.image, c.image)


@pytest.mark.parametrize("seed", [0, 1, 2, 5, 36])
def test_truth_is_in_the_stated_ranges(seed: int) -> None:
    ph = render_street_photo(seed)
    w, h = ph.size
    assert ph.image.shape == (h, w, 3)
    assert ph.image.dtype == np.uint8
    assert (w, h) in {(1024, 768), (1024, 576), (800, 600), (1280, 720)}
    assert 0.7 <= ph.focal_px / max(w, h) <= 1.3
    assert abs(ph.principal_point[0] - w / 2) <= 0.015 * w + 1e-9
    assert abs(ph.principal_point[1] - h / 2) <= 0.015 * h + 1e-9
    assert -0.06 <= ph.k1 <= 0.02
    assert 1.4 <= ph.height_m <= 1.8 + 0.12
    # gravity in the camera frame agrees with the stated pitch (positive up) and roll
    pitch_down, roll = pitch_roll_from_up(ph.up_in_cam)
    assert pitch_down == pytest.approx(-ph.pitch_up_deg, abs=1e-9)
    assert roll == pytest.approx(ph.roll_deg, abs=1e-9)
    assert abs(ph.yaw_deg) <= 25.0
    assert -5.0 <= ph.pitch_up_deg <= 10.0


def test_half_the_photos_are_level_cameras_down_the_street() -> None:
    level = [
        abs(ph.yaw_deg) < 4.0 and abs(ph.pitch_up_deg) < 2.0
        for ph in (render_street_photo(s) for s in range(12))
    ]
    assert 3 <= sum(level) <= 9


def test_a_turned_camera_is_calibrated_from_its_photo() -> None:
    # seed 1: turned 6 degrees, looking up 9.5: three finite vanishing points
    ph = render_street_photo(1)
    res = detect_vanishing_points(ph.image, seed=0, use_exif=False)
    err = math.log(res.focal_px / ph.focal_px)
    assert abs(err) < 0.05
    assert abs(err) < 2 * res.focal_std_rel
    assert abs(res.pitch_deg + ph.pitch_up_deg) < 1.5
    assert res.distortion == pytest.approx(ph.k1, abs=0.02)


def test_focal_rel_sets_the_focal_length_and_keeps_the_rest() -> None:
    a, b = render_street_photo(7), render_street_photo(7, focal_rel=0.97)
    assert b.focal_px == pytest.approx(0.97 * max(b.size))
    assert a.size == b.size
    assert a.principal_point == b.principal_point
    assert a.yaw_deg == b.yaw_deg
    assert a.k1 == b.k1
    with pytest.raises(ValueError, match="focal_rel"):
        render_street_photo(7, focal_rel=float("nan"))


def _canvas_and_camera() -> tuple[Any, Camera]:
    """A turned, tilted, rolled camera 1.6 m up on a street, off-centre principal point."""
    from camloc_geo.testing.street_photo_render import _Canvas

    R = rotation_from_angles(90.0 - 12.0, -4.0, 1.5)
    C = np.array([0.0, -1.0, 1.6])
    f, pp, size = 820.0, (515.3, 380.7), (1024, 768)
    return _Canvas(R, C, f, pp, size), Camera.from_center(f, pp, R, C)


def test_storey_line_is_drawn_where_the_camera_projects() -> None:
    # A storey line on the left facade (y = 8 m, 6 m up), white on black: in each column its
    # drawn centre (intensity-weighted, pixel (x, y) centred at (x + 0.5, y + 0.5)) lies on
    # Camera.project's line. OpenCV's line drew it 0.2-0.5 px low (session 37).
    cv, camera = _canvas_and_camera()
    a, b = np.array([12.0, 8.0, 6.0]), np.array([40.0, 8.0, 6.0])
    cv.line(a, b, (255.0, 255.0, 255.0), 0.15)
    ua, ub = camera.project(np.array([a, b]))
    lum = cv.img[..., 0]
    errs, us = [], []
    for x in range(int(min(ua[0], ub[0])) + 10, int(max(ua[0], ub[0])) - 10, 7):
        u = x + 0.5
        us.append(u)
        v = ua[1] + (u - ua[0]) * (ub[1] - ua[1]) / (ub[0] - ua[0])
        y0, y1 = int(v) - 12, int(v) + 13
        col = lum[y0:y1, x]
        centre = float(np.sum((np.arange(y0, y1) + 0.5) * col) / np.sum(col))
        errs.append(centre - v)
    assert len(errs) >= 20
    # every column within 0.3 px (0.03 measured; OpenCV's LINE_AA wobbled by up to 0.35 px
    # even shifted into Camera's convention), and the line fitted through them within 0.1 px
    assert np.max(np.abs(errs)) < 0.3
    slope, offset = np.polyfit(us, errs, 1)
    assert np.max(np.abs(slope * np.array([us[0], us[-1]]) + offset)) < 0.1


def test_facade_edges_are_drawn_where_the_camera_projects() -> None:
    # A facade (x 14-30 m, y = 8 m, 0-5 m up), white on black: in each column the drawn
    # span (covered length and centre) gives its top and bottom edges, within 0.3 px of
    # Camera.project's. OpenCV's anti-aliased fill grew it ~0.7 px a side, 0.5 px low.
    cv, camera = _canvas_and_camera()
    face = np.array([[14.0, 8.0, 0.0], [30.0, 8.0, 0.0], [30.0, 8.0, 5.0], [14.0, 8.0, 5.0]])
    cv.poly(face, (255.0, 255.0, 255.0))
    p = camera.project(face)
    cov = cv.img[..., 0] / 255.0
    errs = []
    for x in range(int(p[:, 0].min()) + 3, int(p[:, 0].max()) - 3, 5):
        u = x + 0.5
        top = p[3, 1] + (u - p[3, 0]) * (p[2, 1] - p[3, 1]) / (p[2, 0] - p[3, 0])
        bottom = p[0, 1] + (u - p[0, 0]) * (p[1, 1] - p[0, 1]) / (p[1, 0] - p[0, 0])
        col = cov[:, x]
        length = float(col.sum())
        centre = float(np.sum((np.arange(len(col)) + 0.5) * col) / length)
        errs += [centre - length / 2 - top, centre + length / 2 - bottom]
    assert len(errs) >= 40
    assert np.max(np.abs(errs)) < 0.3


def test_tree_crown_is_centred_where_the_camera_projects() -> None:
    # A crown (radius 2 m, 20 m ahead), white on black: its drawn centroid within 0.05 px of
    # Camera.project's centre (OpenCV's ellipse had it truncated to whole pixels, 0.5 px low
    # and right), its area that of the ellipse within 1 %.
    cv, camera = _canvas_and_camera()
    centre_w = np.array([20.0, 2.0, 4.0])
    cv.ellipse(centre_w, 2.0, (255.0, 255.0, 255.0))
    cov = cv.img[..., 0] / 255.0
    uv = camera.project(centre_w[None])[0]
    r_px = (
        camera.focal_px
        * 2.0
        / float((camera.cam_from_world_rotation @ centre_w + camera.cam_from_world_translation)[2])
    )
    yy, xx = np.mgrid[0 : cov.shape[0], 0 : cov.shape[1]]
    area = float(cov.sum())
    assert abs(float(np.sum((xx + 0.5) * cov)) / area - uv[0]) < 0.05
    assert abs(float(np.sum((yy + 0.5) * cov)) / area - uv[1]) < 0.05
    assert area == pytest.approx(math.pi * 0.85 * r_px**2, rel=0.01)
