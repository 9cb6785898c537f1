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
