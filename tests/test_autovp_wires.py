"""Overhead wires are not lines of the street (issue 24 item 2, stop 39 round two).

Power and tram lines hang over real streets: long, thin, nearly straight and horizontal,
they meet on the horizon in no principal direction of the street. On the development photo
``la foto.JPG`` (grafital) they posed as a horizontal direction: +51 % at a stated 17 %.
``_thin_lines`` finds thin lines (a ridge of the grey levels with like sides), ``_sky_wires``
those of them above the skyline (the top of the vertical lines around them) and the thin
lines on the same image line; where a direction of the frame leans on them the photo is
read again without them.
"""

from __future__ import annotations

import numpy as np
import pytest

from camloc_geo import autovp
from camloc_geo.testing import street_photo_render as spr


def _canvas(h: int = 200, w: int = 400, grey: int = 200) -> np.ndarray:
    return np.full((h, w), grey, dtype=np.uint8)


def test_a_thin_dark_line_is_thin_and_a_step_edge_is_not() -> None:
    img = _canvas()
    import cv2

    # a 2 px dark line (a wire) across uniform sky; a step edge lower down (a roof line)
    cv2.line(img, (20, 60), (380, 80), 60, 2, cv2.LINE_AA)
    img[140:, :] = 90
    segs = np.array(
        [
            [20.5, 60.0, 380.5, 80.0],  # on the wire's upper edge, as LSD would put it
            [20.5, 62.0, 380.5, 82.0],  # on its lower edge
            [20.0, 140.0, 380.0, 140.0],  # the step
        ]
    )
    thin = autovp._thin_lines(img, segs)
    assert thin.tolist() == [True, True, False]


def test_a_wide_band_is_not_thin() -> None:
    img = _canvas()
    img[60:72, :] = 60  # a 12 px band: two step edges, not a wire
    segs = np.array([[10.0, 60.0, 390.0, 60.0], [10.0, 72.0, 390.0, 72.0]])
    assert not np.any(autovp._thin_lines(img, segs))


def test_a_wire_runs_above_the_skyline_and_a_facade_line_below_it() -> None:
    # verticals (label 0) topping out at y = 100 between x = 0 and 400
    vert = np.array([[x, 100.0, x, 300.0] for x in range(0, 401, 50)], float)
    segs = np.vstack(
        [
            vert,
            [[0.0, 40.0, 400.0, 60.0]],  # above them: a wire
            [[0.0, 150.0, 400.0, 160.0]],  # below their tops: a line on the facades
            [[500.0, 65.0, 700.0, 75.0]],  # the first wire's line, off the verticals
        ]
    )
    labels = np.r_[np.zeros(len(vert), int), 1, 1, 1]
    thin = np.ones(len(segs), dtype=bool)
    wires = autovp._sky_wires(segs, thin, labels, 0, (800.0, 400.0), merge_px=8.0)
    assert wires[len(vert) :].tolist() == [True, False, True]
    assert not np.any(wires[: len(vert)])
    # not thin: not a wire, wherever it lies
    thin[len(vert)] = False
    wires = autovp._sky_wires(segs, thin, labels, 0, (800.0, 400.0), merge_px=8.0)
    assert not wires[len(vert)]


def test_a_thin_line_under_a_step_edge_is_not_a_wire() -> None:
    # a ceiling's joint above the walls' verticals, under a lamp's edge (a step, not thin):
    # not the sky
    vert = np.array([[x, 100.0, x, 300.0] for x in range(0, 401, 50)], float)
    segs = np.vstack(
        [
            vert,
            [[0.0, 40.0, 400.0, 60.0]],  # the joint
            [[0.0, 10.0, 400.0, 30.0]],  # the lamp's edge above it
        ]
    )
    labels = np.r_[np.zeros(len(vert), int), 1, 1]
    thin = np.r_[np.zeros(len(vert), bool), True, False]
    wires = autovp._sky_wires(segs, thin, labels, 0, (800.0, 400.0), merge_px=8.0)
    assert not np.any(wires)
    # with a thin line above it instead (another wire), both are wires
    thin[-1] = True
    wires = autovp._sky_wires(segs, thin, labels, 0, (800.0, 400.0), merge_px=8.0)
    assert wires[len(vert) :].tolist() == [True, True]


def test_wire_directions_need_enough_wire_lines_and_share() -> None:
    segs = np.array([[0.0, 10.0 * i, 300.0, 10.0 * i + 5.0] for i in range(9)], float)
    labels = np.ones(9, dtype=np.int64)
    wires = np.zeros(9, dtype=bool)
    wires[:2] = True  # two wire lines: too few
    assert autovp._wire_directions(segs, labels, wires, 4.0) == []
    wires[:3] = True  # three of nine: a third
    assert autovp._wire_directions(segs, labels, wires, 4.0) == [1]
    labels[3:] = 2  # direction 2 has none
    assert autovp._wire_directions(segs, labels, wires, 4.0) == [1]


@pytest.mark.parametrize("seed", [1, 2, 8])
def test_wires_over_a_street_photo_do_not_pose_as_a_direction(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    # seed 8: two of the wires cross facades only (nowhere in the sky); read again without
    # the sky's wires alone, they made a direction with car edges (+62 % at a stated 9 %,
    # no warning): the thin lines of a direction that leans on wires go too
    photo = spr.render_street_photo(seed)
    img = spr.with_overhead_wires(photo)
    res = autovp.detect_vanishing_points(img)
    err = res.focal_px / photo.focal_px - 1.0
    assert abs(err) < 0.05, err
    assert abs(err) < 2.0 * res.focal_std_rel
    # without the wires' check the wires make a direction of the frame: far off
    monkeypatch.setattr(autovp, "_WIRE_MIN_LINES", 10**6)
    res_without = autovp.detect_vanishing_points(img)
    assert abs(res_without.focal_px / photo.focal_px - 1.0) > 0.15


def test_a_street_photo_without_wires_is_not_read_again(monkeypatch: pytest.MonkeyPatch) -> None:
    photo = spr.render_street_photo(1)
    res = autovp.detect_vanishing_points(photo.image)
    monkeypatch.setattr(autovp, "_WIRE_MIN_LINES", 10**6)
    res_without = autovp.detect_vanishing_points(photo.image)
    assert res.focal_px == res_without.focal_px
    assert np.array_equal(res.labels, res_without.labels)
