"""Session 37 QA: faults found driving the ``camloc`` command line as a user."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BALTIMORE = REPO / "sample_maps" / "baltimore.osm.pbf"


def _camloc(args: list[str | bytes], cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(REPO), "LC_ALL": "C.UTF-8"}
    cmd: list[str | bytes] = [sys.executable, "-m", "camloc_geo.cli", *args]
    return subprocess.run(
        cmd, capture_output=True, text=True, errors="replace", timeout=600, cwd=cwd, env=env
    )


def test_geocode_title_not_utf8_to_file(tmp_path: Path) -> None:
    """A title typed in a Windows-1252 terminal (``\\xe9`` for é) was read into a lone
    surrogate: ``-o`` then failed with ``UnicodeEncodeError`` (exit 1) after the work. It is
    read as Windows-1252 with a warning, and the file is valid UTF-8 JSON."""
    out = tmp_path / "g.geojson"
    title = b"Eastern Ave \xe9& S Broadway"
    proc = _camloc(["geocode", "--osm", str(BALTIMORE), title, "-o", str(out)], tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "title 1 is not UTF-8 text: read as Windows-1252" in proc.stderr
    features = json.loads(out.read_text(encoding="utf-8"))["features"]
    assert features[0]["properties"]["title"] == "Eastern Ave \u00e9& S Broadway"
    assert features[0]["properties"]["status"] == "junction"
