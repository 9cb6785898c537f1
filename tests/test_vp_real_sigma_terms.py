"""benchmarks/vp_real.py: which term decides the focal sigma, and the vertical lines' bias."""

from __future__ import annotations

import math
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
vp_real = pytest.importorskip("vp_real")


def _vertical_segments(vp_xy: tuple[float, float], turn_deg: float, lean_deg: float) -> np.ndarray:
    """Segments 100 px long at x = 100..700, aimed at ``vp_xy``, each turned by
    ``turn_deg`` plus ``lean_deg`` on the right of x = 400 and minus it on the left."""
    segs = []
    for x in np.linspace(100.0, 700.0, 8):
        mid = np.array([x, 300.0])
        to_vp = np.array(vp_xy) - mid
        to_vp /= np.linalg.norm(to_vp)
        a = math.radians(turn_deg + (lean_deg if x > 400.0 else -lean_deg))
        # turned counter-clockwise in the image's (x right, y down) frame by -a, so that
        # the signed angle from the segment to the line to the VP is +a
        c, s = math.cos(-a), math.sin(-a)
        d = np.array([c * to_vp[0] - s * to_vp[1], s * to_vp[0] + c * to_vp[1]])
        segs.append([*(mid - 50.0 * d), *(mid + 50.0 * d)])
    return np.array(segs)


def _res(segs: np.ndarray) -> SimpleNamespace:
    return SimpleNamespace(
        segments=segs,
        labels=np.zeros(len(segs), dtype=np.int64),
        distortion=0.0,
        image_size=(800, 600),
        principal_point=(400.0, 300.0),
    )


def test_vertical_bias_reads_the_turn_and_the_lean() -> None:
    f, pp = 800.0, (400.0, 300.0)
    up = np.array([0.0, -0.8, 0.6])  # looking up: the vertical VP above the photo
    vp = (f * up[0] / up[2] + pp[0], f * up[1] / up[2] + pp[1])
    truth = {"f": f, "pp": pp, "up": up}
    turn, conv = vp_real.vertical_bias_deg(_res(_vertical_segments(vp, 0.0, 0.0)), truth)
    assert turn == pytest.approx(0.0, abs=1e-9)
    assert conv == pytest.approx(0.0, abs=1e-9)
    turn, conv = vp_real.vertical_bias_deg(_res(_vertical_segments(vp, 0.4, 0.0)), truth)
    assert turn == pytest.approx(0.4, abs=1e-6)
    assert conv == pytest.approx(0.0, abs=1e-6)
    turn, conv = vp_real.vertical_bias_deg(_res(_vertical_segments(vp, 0.0, 0.25)), truth)
    assert abs(turn) < 1e-6
    assert abs(conv) == pytest.approx(0.25, abs=1e-6)
    assert vp_real.vertical_bias_deg(_res(_vertical_segments(vp, 0.0, 0.0)), {"up": None}) is None


def test_sigma_terms_names_the_largest_term() -> None:
    parts = [
        {"least_squares": 0.01, "jackknife": 0.03, "systematic": 0.02, "principal_point": 0.0},
        {"least_squares": 0.01, "jackknife": 0.0, "systematic": 0.05, "principal_point": 0.01},
        {"least_squares": 0.01, "jackknife": 0.0, "systematic": 0.04, "principal_point": 0.0},
    ]
    rows = [{"focal_std_parts": p} for p in parts] + [{"focal_std_parts": {}}]
    got = vp_real.sigma_terms(rows)
    assert got["n"] == 3
    assert got["decides"] == {"statistical": 1, "systematic": 2, "principal_point": 0}
    assert got["median"]["statistical"] == pytest.approx(0.01)
    assert got["median"]["systematic"] == pytest.approx(0.04)
    share = got["share_of_variance"]
    assert share["systematic"] == pytest.approx(0.0045 / (0.0045 + 0.0011 + 0.0001))
    assert vp_real.sigma_terms([{"focal_std_parts": {}}]) is None
