"""A focal length that rests on two directions alone, the weaker of a few lines that no
third direction checks (issue 24: a phone photo looking up at a block over palm trees,
verticals and 8 lines of floors, +10.9 % at a stated 4.9 %, no warning)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_autovp_failure_modes import cam_from_world, facade_segments

from camloc_geo import autovp
from camloc_geo.autovp import detect_vanishing_points

F_PX = 800.0
SIZE = (1024, 768)


def verticals_and_slope_segments(
    n_slope: int, slope_deg: float, pitch_deg: float, seed: int = 0
) -> np.ndarray:
    """A facade's vertical edges (40) and ``n_slope`` parallel lines in its plane that rise
    ``slope_deg`` from the horizontal (a roof slope, a ramp's rail), no third direction;
    camera 1.6 m up, 18 m off, looking up ``-pitch_deg`` degrees."""
    rng = np.random.default_rng(seed)
    w, h = SIZE
    cam = cam_from_world(0.0, pitch_deg)
    a = math.radians(25.0)
    along = np.array([math.sin(a), -math.cos(a), 0.0])
    up = np.array([0.0, 0.0, 1.0])
    sl = math.radians(slope_deg)
    slope_dir = math.cos(sl) * along + math.sin(sl) * up
    origin = np.array([18.0, 0.0, -1.6])
    segs: list[list[float]] = []

    def add(p: np.ndarray, q: np.ndarray) -> bool:
        pc, qc = cam @ p, cam @ q
        if pc[2] < 0.5 or qc[2] < 0.5:
            return False
        a_px = F_PX * pc[:2] / pc[2] + (w / 2, h / 2)
        b_px = F_PX * qc[:2] / qc[2] + (w / 2, h / 2)
        inside = all(0 <= v[0] <= w and 0 <= v[1] <= h for v in (a_px, b_px))
        if inside and np.hypot(*(b_px - a_px)) > 25:
            segs.append([*a_px, *b_px])
            return True
        return False

    n = 0
    while n < 40:
        p = origin + along * rng.uniform(-25, 25) + up * rng.uniform(0, 40)
        n += add(p, p + up * rng.uniform(2, 10))
    n = tries = 0
    while n < n_slope and tries < 5000:
        tries += 1
        p = origin + along * rng.uniform(-25, 15) + up * rng.uniform(5, 40)
        n += add(p, p + slope_dir * rng.uniform(3, 8))
    out = np.array(segs)
    return out + rng.normal(0.0, 0.3, out.shape)


@pytest.mark.parametrize("seed", [0, 1])
def test_a_slope_posing_as_the_one_horizontal_direction_is_not_stated_sure(seed: int) -> None:
    # 10 lines rising 5 degrees, read as horizontal: the focal length comes out about 20 %
    # short (it came out 24-25 % short at a stated 5 %, 5 sigma, no warning)
    segs = verticals_and_slope_segments(10, 5.0, -30.0, seed)
    res = detect_vanishing_points(None, segments=segs, image_size=SIZE)
    assert res.n_lines[2] == 0
    assert autovp._WEAK_LINES <= res.n_lines[1] < autovp._FEW_LINES
    err = abs(math.log(res.focal_px / F_PX))
    assert err > math.log(1.1)  # still wrong: the lines cannot tell
    assert err < 2.0 * res.focal_std_rel  # but the sigma says how far it may be
    assert res.focal_std_parts["few_lines"] >= autovp._UNCHECKED_FEW_STD
    assert any("no third direction checks it" in w for w in res.warnings)
    assert res.confidence < 0.5


def test_two_directions_of_many_lines_keep_their_sigma() -> None:
    # a facade's verticals and 25 rows of windows: no direction of few lines, no new term
    segs, size = facade_segments(-20.0, n_rows=40, n_side=0)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    assert res.n_lines[2] == 0
    assert res.n_lines[1] >= autovp._FEW_LINES
    assert res.focal_std_parts["few_lines"] == 0.0
    assert res.focal_std_rel < 0.06
    assert not any("no third direction" in w for w in res.warnings)


def test_a_third_direction_checks_a_direction_of_few_lines_instead() -> None:
    # the same few rows with a side wall's courses: the pull is measured, not assumed
    segs, size = facade_segments(-20.0, n_rows=12, n_side=30)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    assert min(res.n_lines) > 0
    assert res.focal_std_parts["few_lines"] < autovp._UNCHECKED_FEW_STD
    assert not any("no third direction" in w for w in res.warnings)


def test_an_exif_prior_checks_it_instead() -> None:
    segs, size = facade_segments(-20.0, n_rows=10, n_side=0)
    res = detect_vanishing_points(
        None, segments=segs, image_size=size, focal_prior_px=F_PX, focal_prior_sigma_rel=0.05
    )
    assert res.n_lines[2] == 0
    assert res.n_lines[1] < autovp._FEW_LINES
    assert res.focal_std_parts.get("few_lines", 0.0) == 0.0
    assert not any("no third direction" in w for w in res.warnings)
    plain = detect_vanishing_points(None, segments=segs, image_size=size)
    assert plain.focal_std_parts["few_lines"] >= autovp._UNCHECKED_FEW_STD
