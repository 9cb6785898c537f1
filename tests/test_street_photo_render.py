"""The synthetic handheld street photos (camloc_geo.testing.street_photo_render)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from camloc_geo.autovp import detect_vanishing_points, pitch_roll_from_up
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
