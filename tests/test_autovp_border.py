"""autovp.detect_segments: the frame's own edge (a codec's dark first row) is no scene line."""

from __future__ import annotations

import numpy as np

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
