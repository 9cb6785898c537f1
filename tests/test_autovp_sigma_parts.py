"""autovp: the terms of the focal sigma (``focal_std_parts``) add up to ``focal_std_rel``."""

from __future__ import annotations

import math

import numpy as np
import pytest

from camloc_geo.autovp import detect_vanishing_points
from tests.test_autovp import cam_from_world, render_scene

_TERMS = {
    "least_squares",
    "jackknife",
    "systematic",
    "split_horizon",
    "few_lines",
    "principal_point",
    "rival",
    "distortion",
}


def _total(parts: dict[str, float]) -> float:
    stat = max(parts["least_squares"], parts["jackknife"])
    rest = (parts[k] for k in _TERMS - {"least_squares", "jackknife"})
    return math.sqrt(stat**2 + sum(v**2 for v in rest))


def test_parts_add_up_to_the_stated_sigma() -> None:
    img = render_scene(cam_from_world(30.0, 12.0, 4.0), 700.0)
    res = detect_vanishing_points(img)
    assert res.focal_source == "estimated"
    parts = res.focal_std_parts
    assert set(parts) == _TERMS
    assert all(v >= 0.0 and math.isfinite(v) for v in parts.values())
    # three finite vanishing points: a tight sigma, the default prior stays out
    assert res.focal_std_rel < 0.10
    assert _total(parts) == pytest.approx(res.focal_std_rel, rel=1e-9)
    # the systematic term is the 0.3 degree turn: it moves with bias_deg, the rest not
    half = detect_vanishing_points(img, bias_deg=0.15).focal_std_parts
    assert half["systematic"] == pytest.approx(0.5 * parts["systematic"], rel=0.1)
    assert half["least_squares"] == pytest.approx(parts["least_squares"], rel=1e-6)
    assert 0.0 < res.line_residual_rms_px < 1.5


def test_no_parts_when_the_focal_length_is_given() -> None:
    img = render_scene(cam_from_world(30.0, 12.0, 4.0), 700.0)
    res = detect_vanishing_points(img, focal_px=700.0)
    assert res.focal_std_parts == {}
    assert np.isnan(res.line_residual_rms_px)
