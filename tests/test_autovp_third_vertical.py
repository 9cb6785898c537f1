"""A third horizontal direction that the vertical rules out is not a rival pairing.

Round one of stop 40 warned of a third horizontal direction whenever its pairing with one of
the frame's gave a focal length its lines fix. It fired on 9 York Urban and 12 Strecha photos,
all read right (stairs, floor joints, an oblique wing), halving their confidence. Both pairings
keep the vertical square to every horizontal direction, so the vertical vanishing point and the
horizon give the focal length on their own: where they fix it, they tell the pairings apart
(:func:`autovp._vertical_rules_out`). And a frame direction with too few lines to be kept (the
cross product of the other two) is nothing to pair with (Strecha's Herz-Jesus photos:
confidence 0.00 on right answers).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from test_autovp_third_horizontal import F_PX, SIZE, two_buildings_segments

from camloc_geo import autovp
from camloc_geo.autovp import detect_vanishing_points

_THIRD = "third horizontal direction"


def test_vertical_rules_out_a_rival_it_rejects_where_it_keeps_the_frame() -> None:
    """Rival 0.5 off in log focal, the vertical on the frame within 0.05: ruled out."""
    assert autovp._vertical_rules_out(0.0, 0.5, 0.01, 0.02, 0.05)


def test_a_loose_vertical_does_not_rule_out() -> None:
    """A level camera's vertical (sigma 0.3) cannot tell a rival 0.4 off from the frame."""
    assert not autovp._vertical_rules_out(0.0, -0.4, 0.01, -0.02, 0.3)


def test_a_vertical_that_agrees_with_neither_does_not_rule_out() -> None:
    """The vertical 3 sigmas from the frame and further from the rival: something else is
    wrong, and the warning stands (the campus photo I2_2_1: 2.7 sigmas from its frame)."""
    assert not autovp._vertical_rules_out(0.0, -1.0, 0.01, -0.45, 0.15)


def test_no_vertical_fit_does_not_rule_out() -> None:
    assert not autovp._vertical_rules_out(0.0, 0.5, 0.01, math.nan, math.inf)


def _frame_labels(segs: np.ndarray, pitch_deg: float) -> tuple[autovp._Model, autovp._Segs]:
    """The true frame (up, A, the road) of :func:`two_buildings_segments`, labelled."""
    from test_autovp_third_horizontal import _heading, cam_from_world

    R_cw = cam_from_world(0.0, pitch_deg)
    up, a_dir, c_dir = np.array([0.0, 0.0, 1.0]), _heading(45.0), _heading(-45.0)
    R = np.column_stack([R_cw @ up, R_cw @ a_dir, R_cw @ c_dir])
    scale = float(max(SIZE))
    s = autovp._prepare(segs, np.array(SIZE, dtype=float) / 2.0, scale)
    labels, score = autovp._labels(R, F_PX / scale, s, 2.0, autovp._LABEL_ANGLE_DEG)
    return autovp._Model(R=R, f_n=F_PX / scale, labels=labels, score=score), s


@pytest.mark.parametrize(("pitch_deg", "tight"), [(15.0, True), (2.0, False)])
def test_vertical_pairing_focal_is_tight_pitched_and_loose_level(
    pitch_deg: float, tight: bool
) -> None:
    """The vertical with building A gives the true focal length; within 5 % pitched 15
    degrees down (the vertical point 2600 px off), but not within 15 % for a level camera
    (2 degrees: 20000 px off), where the pairing stays the photo's to choose."""
    segs = two_buildings_segments(20.0, 24, 0, pitch_deg=pitch_deg)
    model, s = _frame_labels(segs, pitch_deg)
    logf, std = autovp._vertical_pairing_logf(
        model, 1, s, 2.0, model.f_n, autovp.FOCAL_BOUNDS_REL, None, autovp.BIAS_DEG
    )
    assert abs(logf - math.log(model.f_n)) < 2.0 * std
    if tight:
        assert std < 0.05
    else:
        assert std > 0.15


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_pitched_camera_oblique_building_is_not_warned(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Pitched 15 degrees down, building B 20 degrees off square: the frame (A, the road,
    up) is right and B's direction is a third one whose pairing with A the vertical rules
    out. Without the rule it is warned, its confidence cut."""
    segs = two_buildings_segments(20.0, 24, seed, pitch_deg=15.0)
    res = detect_vanishing_points(None, segments=segs, image_size=SIZE)
    assert abs(math.log(res.focal_px / F_PX)) < 0.02
    assert not any(_THIRD in w for w in res.warnings)
    monkeypatch.setattr(autovp, "_vertical_rules_out", lambda *a: False)
    res_without = detect_vanishing_points(None, segments=segs, image_size=SIZE)
    assert any(_THIRD in w for w in res_without.warnings)
    assert res_without.confidence < res.confidence


@pytest.mark.parametrize("seed", [0, 2])
def test_level_camera_two_buildings_still_warned(seed: int) -> None:
    """Level (2 degrees down), the vertical cannot choose: the warning stands."""
    segs = two_buildings_segments(20.0, 24, seed)
    res = detect_vanishing_points(None, segments=segs, image_size=SIZE)
    assert any(_THIRD in w for w in res.warnings)


def _strecha(name: str) -> Path:
    default = Path.home() / ".cache" / "camloc_geo" / "photos"
    root = Path(
        os.environ.get(
            "CAMLOC_STRECHA_DIR",
            str(
                Path(os.environ.get("CAMLOC_PHOTOS_DIR", str(default)))
                / "SfM_quality_evaluation"
                / "Benchmarking_Camera_Calibration_2008"
            ),
        )
    )
    path = root / name
    if not path.is_file():
        pytest.skip(f"{path} not fetched: benchmarks/fetch_real_photos.sh")
    return path


def test_strecha_stairs_photo_is_not_warned(monkeypatch: pytest.MonkeyPatch) -> None:
    """Herz-Jesus-P25 0002 (read right, -3 %): a third direction of 12 lines whose pairing
    gives -36 %, which its vertical (a 6 % sigma) rules out at 5 sigmas. Round one warned it,
    confidence 0.48; now unwarned, confidence over 0.9."""
    path = _strecha("Herz-Jesus-P25/images/0002.jpg")
    res = detect_vanishing_points(path, use_exif=False)
    assert not any(_THIRD in w for w in res.warnings)
    assert res.confidence > 0.9
    monkeypatch.setattr(autovp, "_vertical_rules_out", lambda *a: False)
    res_without = detect_vanishing_points(path, use_exif=False)
    assert any(_THIRD in w for w in res_without.warnings)
    assert res_without.confidence < 0.6


def test_strecha_no_pairing_with_a_direction_of_no_lines(monkeypatch: pytest.MonkeyPatch) -> None:
    """Herz-Jesus-P25 0003 (read right, -2 %): its frame's second horizontal direction has
    no lines (left out: the cross product of the other two). Round one paired the third
    direction with it and gave confidence 0.00 (the weaker kept direction's 0 lines); now
    nothing is paired with it."""
    path = _strecha("Herz-Jesus-P25/images/0003.jpg")
    res = detect_vanishing_points(path, use_exif=False)
    assert not any(_THIRD in w for w in res.warnings)
    assert res.confidence > 0.5
    monkeypatch.setattr(autovp, "_THIRD_PAIR_MIN_LINES", 0)
    res_without = detect_vanishing_points(path, use_exif=False)
    assert any(_THIRD in w for w in res_without.warnings)
    assert res_without.confidence < 0.05


@pytest.mark.parametrize(("n_lines", "expected"), [((20, 20, 20), 1), ((20, 20, 0), 0)])
def test_no_pairing_with_a_frame_direction_of_too_few_lines(
    n_lines: tuple[int, int, int], expected: int
) -> None:
    """A level camera (its vertical cannot choose): a third direction paired with the
    road's direction rivals the frame where the road has lines, and not where it has none
    (left out of the fit: the cross product of the other two)."""
    segs = two_buildings_segments(20.0, 24, 0)
    model, s = _frame_labels(segs, 2.0)
    third = autovp._ThirdHorizontal(14, 10, [-0.4], [0.01], [2])
    alt = autovp._rival_pairings(
        model,
        third,
        n_lines,
        0.05,
        s,
        2.0,
        model.f_n,
        autovp.FOCAL_BOUNDS_REL,
        None,
        autovp.BIAS_DEG,
    )
    assert alt == [-0.4] * expected


def test_a_pairing_the_vertical_rules_out_is_no_rival() -> None:
    """Pitched 15 degrees down, the vertical with the road's direction fixes the focal
    length within 4 %: a pairing 0.4 off in log focal is no rival; level, it is."""
    third = autovp._ThirdHorizontal(14, 10, [-0.4], [0.01], [2])
    found = []
    for pitch in (15.0, 2.0):
        model, s = _frame_labels(two_buildings_segments(20.0, 24, 0, pitch_deg=pitch), pitch)
        found.append(
            autovp._rival_pairings(
                model,
                third,
                (20, 20, 20),
                0.02,
                s,
                2.0,
                model.f_n,
                autovp.FOCAL_BOUNDS_REL,
                None,
                autovp.BIAS_DEG,
            )
        )
    assert found == [[], [-0.4]]
