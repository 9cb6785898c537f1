"""autovp on street-level frames: the frame's own edge, the default focal prior of wide crops."""

from __future__ import annotations

import numpy as np
import pytest

from camloc_geo.autovp import _along_border, detect_segments


def _frame_with_dark_first_row() -> np.ndarray:
    rng = np.random.default_rng(3)
    img = np.clip(rng.normal(130.0, 4.0, (360, 640)), 0, 255).astype(np.uint8)
    img[0, 200:] = 60  # a dark first row over most of the width (seen on dash-camera frames)
    img[:, -1] = 200  # a bright last column
    img[150:154, 100:500] = 30  # a scene line, well inside the frame
    img[60:300, 320:323] = 30  # and another
    return img


def test_segments_along_the_frame_edge_are_dropped() -> None:
    img = _frame_with_dark_first_row()
    h, w = img.shape
    kept = detect_segments(img)
    raw = detect_segments(img, trim_borders=False)
    on_edge = _along_border(raw, (0, 0, w, h), 2.5)
    assert on_edge.any()  # the detector does see the edge ...
    assert not _along_border(kept, (0, 0, w, h), 2.5).any()  # ... and it is left out
    # the scene lines stay
    horiz = kept[np.abs(kept[:, 1] - kept[:, 3]) < 2]
    assert np.any((np.abs(horiz[:, 1] - 152) < 4) & (np.abs(horiz[:, 0] - horiz[:, 2]) > 150))
    vert = kept[np.abs(kept[:, 0] - kept[:, 2]) < 2]
    assert np.any((np.abs(vert[:, 0] - 321.5) < 4) & (np.abs(vert[:, 1] - vert[:, 3]) > 100))


def test_along_border_needs_both_end_points_on_the_same_side() -> None:
    box = (0, 0, 640, 360)
    segs = np.array(
        [
            [10.0, 1.0, 600.0, 1.5],  # along the top
            [639.0, 10.0, 639.5, 300.0],  # along the right side
            [1.0, 1.0, 300.0, 200.0],  # starts in a corner, runs inside
            [10.0, 5.0, 600.0, 5.0],  # 5 px in: a scene line
            [0.5, 100.0, 639.5, 100.0],  # from side to side
        ]
    )
    assert _along_border(segs, box, 2.5).tolist() == [True, True, False, False, False]


def test_default_focal_prior_is_unchanged_for_common_sensor_shapes() -> None:
    from camloc_geo.autovp import _F_DEFAULT_SIGMA, _F_PRIOR_REL, _default_focal_prior

    for w, h in [(640, 480), (3072, 2048), (1280, 720), (720, 1280), (1000, 1000)]:
        assert _default_focal_prior(w, h) == (_F_PRIOR_REL, _F_DEFAULT_SIGMA)


def test_default_focal_prior_of_a_wide_crop_lies_between_its_two_readings() -> None:
    import math

    from camloc_geo.autovp import _F_DEFAULT_SIGMA, _default_focal_prior

    # KITTI's 1242x375: the longer side kept (1.0) or a wide-angle camera whose shorter
    # side spans a 16:9 frame's (16/9 * 375 / 1242 = 0.537); KITTI's own is 0.58
    centre, sigma = _default_focal_prior(1242, 375)
    assert centre == pytest.approx(math.sqrt(16.0 / 9.0 * 375 / 1242))
    assert 0.70 < centre < 0.76
    assert sigma > _F_DEFAULT_SIGMA
    assert abs(math.log(0.581 / centre)) < 1.0 * sigma  # KITTI's truth within 1 sigma
    assert abs(math.log(1.0 / centre)) < 1.0 * sigma  # and so is a cut band's
    assert _default_focal_prior(375, 1242) == (centre, sigma)  # portrait alike
