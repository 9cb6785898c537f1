"""Session 38 QA findings in the review pages (found by the client sweep, fixed on main).

- Review and summary pages had an empty ``<title>`` (a browser tab read the file name).
- ``--verdicts cams.gpkg`` said "'utf-8' codec can't decode byte 0xd8 ...".
- ``camloc summary-map`` given only empty FeatureCollections exited 0 with no word.
"""

from __future__ import annotations

import json
import re
from dataclasses import replace
from pathlib import Path

import pytest
from test_maps import fremantle_map, located

from camloc_geo import maps
from camloc_geo._errors import InputError
from camloc_geo.cli import main
from camloc_geo.results import candidates_geojson


def _title(page: str) -> str:
    m = re.search(r"<title>(.*?)</title>", page, flags=re.DOTALL)
    assert m is not None, "the page has no <title>"
    return m.group(1)


def test_pages_have_a_title_with_the_scene_escaped(tmp_path: Path) -> None:
    fremantle = fremantle_map()
    _scene, res = located(fremantle, 0)
    res = replace(res, scene_id="cam <b>7</b>")
    page = maps.candidates_map(res, fremantle, tmp_path / "r.html", offline=True)
    assert _title(page.read_text(encoding="utf-8")) == "camloc review: cam &lt;b&gt;7&lt;/b&gt;"
    empty = {"type": "FeatureCollection", "features": [], "properties": {"reason": "x"}}
    items = [("a", candidates_geojson(res)), ("b", empty)]
    out = maps.summary_map(items, tmp_path / "s.html", offline=True)
    assert _title(out.read_text(encoding="utf-8")) == "camloc summary: 1 of 2 cameras on the map"


def test_verdicts_that_are_a_geopackage_are_named(tmp_path: Path) -> None:
    gpkg = tmp_path / "cams.gpkg"
    gpkg.write_bytes(b"SQLite format 3\x00" + bytes(range(256)) * 20)
    with pytest.raises(InputError) as err:
        maps.read_verdicts(gpkg)
    msg = str(err.value)
    assert "GeoPackage" in msg or "SQLite" in msg
    assert "codec" not in msg
    assert "Export" in msg


def test_summary_map_of_empty_inputs_warns(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    empty = tmp_path / "e.geojson"
    empty.write_text(json.dumps({"type": "FeatureCollection", "features": []}), encoding="utf-8")
    out = tmp_path / "s.html"
    assert main(["summary-map", str(empty), "-o", str(out), "--offline"]) == 0
    assert "no camera in the inputs has a candidate" in caplog.text
    assert out.is_file()
