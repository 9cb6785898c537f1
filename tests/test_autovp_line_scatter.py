"""The long inliers' turn about their vanishing points beyond noise (a diagnosis that
``benchmarks/vp_real.py`` reports per photo, stop 39)."""

from __future__ import annotations

import math

import numpy as np

from camloc_geo import autovp


def test_line_scatter_is_the_turn_of_long_lines_beyond_their_noise() -> None:
    length_px = np.full(20, 200.0)
    turn_deg = 0.2
    res_px = np.where(np.arange(20) % 2 == 0, 1.0, -1.0) * math.radians(turn_deg) * 100.0
    # each end point also off by the detector's noise: taken out in quadrature
    noisy = np.sign(res_px) * np.hypot(res_px, autovp._CURVE_NOISE_PX)
    assert abs(autovp._line_scatter_deg(noisy, length_px) - turn_deg) < 1e-9


def test_line_scatter_counts_long_lines_only_and_needs_enough_of_them() -> None:
    length_px = np.r_[np.full(8, 100.0), np.full(30, 20.0)]
    res_px = np.r_[np.full(8, autovp._CURVE_NOISE_PX), np.full(30, 3.0)]
    assert autovp._line_scatter_deg(res_px, length_px) == 0.0
    assert math.isnan(autovp._line_scatter_deg(res_px[1:], length_px[1:]))
