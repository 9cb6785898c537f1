"""benchmarks/vp_real.py --prior-at-truth: the default focal prior centred on the truth."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
vp_real = pytest.importorskip("vp_real")

from camloc_geo import NotEnoughStructureError, autovp  # noqa: E402


def _record_priors(monkeypatch: pytest.MonkeyPatch) -> list[tuple[float, float, float]]:
    """Replace the benchmark's ``detect_vanishing_points`` by one that records the default
    prior's centre and sigma (for a 4:3 frame) and the wide prior's centre while it runs."""
    seen: list[tuple[float, float, float]] = []

    def fake(*args: Any, **kwargs: Any) -> Any:
        centre, sigma = autovp._default_focal_prior(1000.0, 750.0)
        seen.append((centre, sigma, autovp._F_PRIOR_REL))
        raise NotEnoughStructureError("recorded")

    monkeypatch.setattr(vp_real, "detect_vanishing_points", fake)
    return seen


def _truth(f_px: float) -> dict[str, Any]:
    return {
        "set": "s",
        "name": "s/a",
        "f": f_px,
        "up": None,
        "path": np.zeros((750, 1000), np.uint8),
        "size": (1000, 750),
    }


def test_prior_at_truth_centres_the_default_prior_and_keeps_its_sigma(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    seen = _record_priors(monkeypatch)
    default = autovp._default_focal_prior(1000.0, 750.0)
    rows = vp_real.run([_truth(720.0)], use_exif=False, prior_at_truth=True)
    assert rows[0]["error"] == "recorded"
    assert seen[0][0] == pytest.approx(0.72)  # centred on 720 px / 1000 px
    assert seen[0][1] == pytest.approx(default[1])  # the same sigma
    assert seen[0][2] == pytest.approx(0.72)
    # and put back afterwards
    assert autovp._default_focal_prior(1000.0, 750.0) == default
    assert autovp._F_PRIOR_REL == 1.0


def test_plain_run_keeps_the_default_prior(monkeypatch: pytest.MonkeyPatch) -> None:
    seen = _record_priors(monkeypatch)
    vp_real.run([_truth(720.0)], use_exif=False)
    assert seen[0][0] == pytest.approx(1.0)
    assert seen[0][2] == pytest.approx(1.0)


def test_prior_at_truth_is_its_own_labelled_run() -> None:
    assert "SIMULATION" in vp_real.PRIOR_AT_TRUTH_RUN
    assert vp_real.PRIOR_AT_TRUTH_RUN != "no EXIF"


def test_main_reports_the_simulation_as_its_own_run_and_bars(tmp_path: Path) -> None:
    import json

    out = tmp_path / "out"
    argv = ["--sets", "street-synth-dev", "--synth-photos", "1", "--prior-at-truth"]
    assert vp_real.main([*argv, "--no-exif-kept", "--out", str(out)]) == 0
    doc = json.loads((out / "vp_real.json").read_text(encoding="utf-8"))
    assert set(doc["per_image"]) == {"no EXIF", vp_real.PRIOR_AT_TRUTH_RUN}
    sim = doc["summary"][vp_real.PRIOR_AT_TRUTH_RUN]["street-synth"]
    bars = doc["summary"][vp_real.SIM_BARS]["street-synth"]
    assert bars["stripped_within_10pct"]["value"] == sim["share_focal_within_10pct"]
    assert bars["kept_within_10pct"]["met"] is None  # the simulation is EXIF-stripped only
    assert "street-synth" in doc["summary"]["issue 24 bars"]  # the headline's, apart
