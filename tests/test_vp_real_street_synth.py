"""benchmarks/vp_real.py: the synthetic street photos' set (street-synth)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
vp_real = pytest.importorskip("vp_real")


def test_street_synth_rows_carry_the_renderers_truth() -> None:
    from camloc_geo.testing.street_photo_render import render_street_photo

    rows = vp_real.load_street_synth(("dev", "held-out"), 1, focal_rel=0.97)
    assert [r["name"] for r in rows] == ["street-synth/seed0", "street-synth/seed5000"]
    assert [r["half"] for r in rows] == ["dev", "held-out"]
    for r, seed in zip(rows, (0, 5000), strict=True):
        ph = render_street_photo(seed, 0.97)
        assert r["set"] == "street-synth"
        assert np.array_equal(r["path"], ph.image)
        assert r["f"] == pytest.approx(0.97 * max(r["size"]))
        assert r["pp"] == ph.principal_point
        assert r["up"][1] < 0  # up points to the image's top
        assert np.allclose(np.abs(r["up"]), np.abs(ph.up_in_cam))


def test_issue24_bars_are_judged_on_street_synth() -> None:
    rows = [
        {"set": "street-synth", "name": f"s{i}", "f_true": 1000.0, "has_horizon_truth": False}
        for i in range(4)
    ]
    for i, r in enumerate(rows):
        err = 0.02 if i < 3 else 0.30  # 3 of 4 within 10 %, one off and confident
        r.update(
            f=1000.0 * (1 + err),
            focal_err=err,
            focal_std_rel=0.05,
            confidence=0.9,
            warnings=[],
            time_s=0.0,
        )
    bars = vp_real.issue24_bars(vp_real.summarise(rows), None)
    assert bars["stripped_within_10pct"]["value"] == pytest.approx(0.75)
    assert bars["stripped_within_10pct"]["met"] is True
    assert bars["stripped_confidently_wrong_share"]["value"] == pytest.approx(0.25)
    assert bars["stripped_confidently_wrong_share"]["met"] is False
