"""Session 38 QA: ``camloc measure`` says each warning of the scene once.

The scene was read twice (once to check the pixels against the image, once to calibrate),
so a scene whose photo is missing printed its ``image.path`` warning twice on stderr.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "sample_maps" / "sample_scene.json"


@pytest.mark.parametrize(
    ("args", "key", "value"),
    [
        (["--ground", "1241,631", "1345,531"], "distance_m", 5.022726907964511),
        (["--height", "1035,503", "1040,128"], "height_m", 6.3768511894346185),
    ],
)
def test_a_missing_photo_is_warned_once(
    tmp_path: Path, args: list[str], key: str, value: float
) -> None:
    data = json.loads(SCENE.read_text(encoding="utf-8"))
    data["image"]["path"] = "no-such-photo.jpg"
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(data), encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    res = subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", "measure", str(scene), *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert res.returncode == 0, res.stderr
    warnings = [ln for ln in res.stderr.splitlines() if "no-such-photo.jpg" in ln]
    assert len(warnings) == 1, res.stderr
    assert json.loads(res.stdout)[key] == pytest.approx(value, rel=1e-6)
