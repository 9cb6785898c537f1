"""Session 38 QA: QGIS ``camloc:measure`` passes on the calibration's warnings.

The worker's measure task answered ``"warnings": []`` whatever the calibration said, so the
Processing log gave a measurement resting on a scene whose photo is missing, or on an
annotator left out, without a warning (``camloc:locate`` gives them).
"""

from __future__ import annotations

import json
from pathlib import Path

from camloc_geo.qgis.worker import run_job

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "sample_maps" / "sample_scene.json"


def test_measure_job_gives_the_calibration_warnings(tmp_path: Path) -> None:
    data = json.loads(SCENE.read_text(encoding="utf-8"))
    data["image"]["path"] = "no-such-photo.jpg"
    data["annotations"][1]["axes"]["origin"] = [1e308, 500]  # one annotator left out
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(data), encoding="utf-8")
    out = tmp_path / "out"
    out.mkdir()
    pairs = [{"kind": "distance", "a": [1241, 631], "b": [1345, 531]}]
    res = run_job({"task": "measure", "scene": str(scene), "pairs": pairs, "out_dir": str(out)})
    warnings = res["warnings"]
    assert any("no-such-photo.jpg" in w for w in warnings), warnings
    assert any("'w2'" in w and "left out" in w for w in warnings), warnings


def test_measure_job_gives_a_pair_near_the_horizon_its_warning(tmp_path: Path) -> None:
    """A pair whose draws are partly lost beyond the horizon: its sigma is a lower bound, and
    the Processing log says so for that pair."""
    from camloc_geo._errors import InputError
    from camloc_geo.api import calibrate_scene
    from camloc_geo.sensors import ground_distance

    cal = calibrate_scene(SCENE)
    near = [1241.0, 631.0]
    far_px = None
    for v in range(0, 1080, 2):
        try:
            m = ground_distance(cal, [near, [960.0, float(v)]])
        except InputError:
            continue
        if m.n_samples < 400:
            far_px = [960.0, float(v)]
            break
    assert far_px is not None
    out = tmp_path / "out"
    out.mkdir()
    pairs = [
        {"kind": "distance", "a": [1241, 631], "b": [1345, 531]},
        {"kind": "distance", "a": near, "b": far_px},
    ]
    res = run_job({"task": "measure", "scene": str(SCENE), "pairs": pairs, "out_dir": str(out)})
    said = [w for w in res["warnings"] if w.startswith("PAIRS item")]
    assert len(said) == 1, res["warnings"]
    assert said[0].startswith("PAIRS item 1: ")
    assert "lower bound" in said[0]
