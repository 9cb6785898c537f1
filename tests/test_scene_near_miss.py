"""A misspelt scene field is named, not silently ignored (stop 41, qa3's CLI sweep).

Unknown fields are kept and ignored (other tools extend the format), so ``"camera":
{"focal": 1200}`` was calibrated with an estimated focal length and no word: exit 0, the
analyst believing the focal length known. A field whose name is close to one of the format's
now gets a warning naming both (``input_warnings``, calibrate's ``warnings``); other unknown
fields stay silent.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from camloc_geo.scene import parse_scene

SAMPLE = Path(__file__).resolve().parents[1] / "sample_maps" / "sample_scene.json"


def _scene(**edits: object) -> dict:
    data = json.loads(SAMPLE.read_text())
    for dotted, value in edits.items():
        *parents, key = dotted.split("__")
        node = data
        for p in parents:
            node = node.setdefault(p, {}) if not p.isdigit() else node[int(p)]
        node[key] = value
    return data


@pytest.mark.parametrize(
    ("edits", "said"),
    [
        (
            {"camera__focal": 1200},
            "camera.focal: not a field of camloc-scene/1, ignored; did you mean camera.focal_px?",
        ),
        (
            {"object__length": 4.2},
            "object.length: not a field of camloc-scene/1, ignored; did you mean object.length_m?",
        ),
        (
            {"priors": {"lat": 39.28, "lon": -76.59}},
            "priors: not a field of camloc-scene/1, ignored; did you mean prior?",
        ),
        (
            {"annotations__0__vp_line": {}},
            "annotations[0].vp_line: not a field of "
            "camloc-scene/1, ignored; did you mean annotations[0].vp_lines?",
        ),
    ],
)
def test_a_misspelt_field_is_named(edits: dict, said: str) -> None:
    scene = parse_scene(_scene(**edits))
    assert said in scene.input_warnings


def test_other_unknown_fields_stay_silent() -> None:
    scene = parse_scene(_scene(source_tool="labelme 5.1", camera__notes="pole 3"))
    assert not [w for w in scene.input_warnings if "not a field" in w]
    assert scene.model_extra == {"source_tool": "labelme 5.1"}


def test_calibrate_reports_it(tmp_path: Path) -> None:
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(_scene(camera__focal=1200)))
    r = subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", "calibrate", str(path)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    assert "did you mean camera.focal_px?" in r.stderr
    assert any("camera.focal_px" in w for w in json.loads(r.stdout)["warnings"])
