"""benchmarks/vp_real.py's check of the rival frames' weights against the truth."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from test_autovp_failure_modes import street_with_rival_frame_segments

from camloc_geo import autovp
from camloc_geo.autovp import detect_vanishing_points

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
vp_real = pytest.importorskip("vp_real")


def test_rival_calibration_counts_rivals_beyond_the_own_sigma() -> None:
    """Only rivals beyond the own sigma (and 3 %) count; the expected count is the mixture's
    weight ``w / (1 + sum w)``; a rival is nearer when ``|e + d| < |e|``."""
    rows = [
        # kept +30 % (e = log 1.3); rivals: one at the truth (d = -e), one within the own
        # sigma, one further off on the wrong side
        {
            "f": 1.0,
            "focal_err": 0.3,
            "own_logf_std": 0.05,
            "rivals": [(0.5, -math.log(1.3)), (0.5, 0.02), (0.25, 0.2)],
        },
        # no rival, or no own sigma recorded (a focal length given): skipped
        {"f": 1.0, "focal_err": 0.0, "own_logf_std": 0.05, "rivals": []},
        {"f": 1.0, "focal_err": 0.0, "own_logf_std": None, "rivals": [(0.5, 0.3)]},
        {"error": "not enough structure"},
    ]
    cal = vp_real.rival_calibration(rows)
    assert cal["n_beyond_own"] == 2
    assert cal["observed_nearer"] == 1
    assert cal["expected_at_rival"] == pytest.approx((0.5 + 0.25) / 2.25)


def test_rival_recorder_sees_the_rivals_and_puts_autovp_back(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(autovp, "_F_DEFAULT_SIGMA", math.inf)
    segs, size = street_with_rival_frame_segments(16, 12, 5)
    modes, spread = autovp._rival_modes, autovp._rival_spread
    with vp_real._RivalRecorder() as rec:
        res = detect_vanishing_points(None, segments=segs, image_size=size)
    assert autovp._rival_modes is modes
    assert autovp._rival_spread is spread
    assert rec.own_logf_std is not None
    assert 0.0 < rec.own_logf_std < 0.1
    # the square frame, about 18 % below the skewed one kept, as a near tie
    assert any(w > 0.2 and -0.35 < d < -0.15 for w, d in rec.modes)
    # what the recorder saw is what went into the stated sigma
    rival = spread([(w, d, np.zeros(2)) for w, d in rec.modes], rec.own_logf_std)[0]
    assert res.focal_std_rel >= math.hypot(rec.own_logf_std, rival) - 1e-9
