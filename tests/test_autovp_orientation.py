"""Honest pitch and roll sigmas (issue 24 item 4): a horizon that rests on a handful of
lines across a road, with no vertical line, must not look sure; a frame the lines fix
well keeps its sigma."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_autovp_failure_modes import cam_from_world, facade_segments, lane_marking_segments

from camloc_geo.autovp import detect_vanishing_points


def highway_segments(
    *,
    pitch_deg: float = 15.0,
    yaw_deg: float = 10.0,
    n_across: int = 4,
    across_tilt_deg: float = 6.0,
    seed: int = 0,
    f_px: float = 1000.0,
    size: tuple[int, int] = (1280, 720),
    height_m: float = 8.0,
    n_poles: int = 0,
) -> np.ndarray:
    """A traffic camera ``height_m`` up over a highway along +x, looking down ``pitch_deg``
    and ``yaw_deg`` off it, not rolled: 60 lane markings and kerbs along the road, no
    vertical line, and ``n_across`` short lines across it that are not quite of the ground
    (a car's edges, a guard rail on a ramp: turned ``across_tilt_deg`` out of the ground
    plane about the road's direction), and ``n_poles`` poles beside the road (the only
    vertical lines)."""
    rng = np.random.default_rng(seed)
    w, h = size
    R = cam_from_world(yaw_deg, pitch_deg)
    centre = np.array([0.0, 0.0, height_m])
    t = math.radians(across_tilt_deg)
    across = np.array([0.0, math.cos(t), math.sin(t)])
    pairs = [
        *[
            (np.array([x, y, 0.0]), np.array([x + rng.uniform(3, 9), y, 0.0]))
            for x, y in zip(rng.uniform(15, 80, 60), rng.uniform(-8, 8, 60), strict=True)
        ],
        *[
            (p, p + across * rng.uniform(1.5, 2.5))
            for p in (
                np.array([x, y, 0.5])
                for x, y in zip(
                    rng.uniform(15, 35, n_across), rng.uniform(-6, 3, n_across), strict=True
                )
            )
        ],
        *[
            (np.array([x, y, 0.0]), np.array([x, y, rng.uniform(4, 7)]))
            for x, y in zip(
                rng.uniform(15, 50, n_poles), rng.choice([-9.0, 9.0], n_poles), strict=True
            )
        ],
    ]
    segs = []
    for p, q in pairs:
        pc, qc = R @ (p - centre), R @ (q - centre)
        if pc[2] < 0.5 or qc[2] < 0.5:
            continue
        a, b = f_px * pc[:2] / pc[2] + (w / 2, h / 2), f_px * qc[:2] / qc[2] + (w / 2, h / 2)
        if all(0 <= v[0] <= w and 0 <= v[1] <= h for v in (a, b)) and np.hypot(*(b - a)) > 20:
            segs.append([*a, *b])
    return np.array(segs) + rng.normal(0.0, 0.3, (len(segs), 4))


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("given_focal", [False, True])
def test_horizon_on_a_few_lines_across_a_road_states_its_roll_sigma(
    seed: int, given_focal: bool
) -> None:
    """No vertical line, and the horizon resting on 4 short lines across the road that are
    not of the ground: the roll is off by degrees. Its stated sigma must cover that, and a
    warning must say what the horizon rests on. (Before, the stated roll sigma was a
    fraction of a degree: BrnoCompSpeed's traffic cameras were off by 17-27 degrees at
    0.3-1.6.)"""
    segs = highway_segments(seed=seed)
    res = detect_vanishing_points(
        None, segments=segs, image_size=(1280, 720), focal_px=1000.0 if given_focal else None
    )
    assert res.n_lines[0] < 3  # nothing vertical
    roll_err = abs(res.roll_deg)  # the camera is not rolled
    pitch_err = abs(res.pitch_deg - 15.0)
    assert roll_err > 1.0  # the few lines do tilt the horizon
    assert roll_err <= 2.0 * res.roll_std_deg
    assert pitch_err <= 2.0 * res.pitch_std_deg
    assert any("horizon rests on" in w for w in res.warnings)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_horizon_on_a_few_poles_states_its_roll_sigma(seed: int) -> None:
    """The same highway with 6 lines across it that are not of the ground and 4 poles:
    the frame rests on a handful of lines (the lines across, or the poles). Its roll is off
    by up to 2 degrees; the stated sigma covers that within 2 sigma (before: 0.8-1.0
    degrees, 2.2-2.3 sigma off on seeds 2 and 3)."""
    segs = highway_segments(seed=seed, n_across=6, n_poles=4)
    res = detect_vanishing_points(None, segments=segs, image_size=(1280, 720))
    assert abs(res.roll_deg) <= 2.0 * res.roll_std_deg
    assert abs(res.pitch_deg - 15.0) <= 2.0 * res.pitch_std_deg


@pytest.mark.parametrize(
    ("scene", "pitch_std_deg", "roll_std_deg"),
    [("street", 1.1788, 0.6215), ("facade-up", 1.1625, 0.3429), ("facade-down", 1.1896, 0.3176)],
)
def test_well_fixed_frame_keeps_its_tilt_sigma(
    scene: str, pitch_std_deg: float, roll_std_deg: float
) -> None:
    """Frames the lines fix (a street camera over lane markings, stop lines and poles; a
    facade with its side wall, 12-29 lines a direction): no consider term, no warning, and
    the stated pitch and roll sigmas are what they were before the jackknife and the
    consider term (the figures pinned here), and cover the error."""
    if scene == "street":
        segs, size, pitch_true = (
            lane_marking_segments(30.0, 10.0, n_poles=30, seed=0),
            (1024, 768),
            30.0,
        )
    else:
        pitch_true = -10.0 if scene == "facade-up" else 10.0
        segs, size = facade_segments(pitch_true, n_side=40)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    assert not any("horizon rests on" in w for w in res.warnings)
    assert res.pitch_std_deg == pytest.approx(pitch_std_deg, rel=0.02)
    assert res.roll_std_deg == pytest.approx(roll_std_deg, rel=0.02)
    assert abs(res.pitch_deg - pitch_true) <= 2.0 * res.pitch_std_deg
    assert abs(res.roll_deg) <= 2.0 * res.roll_std_deg
