"""The batch GeoPackage's view cones use the plugin's one cone style, tie rule included.

``qgis_plugin/make_batch_styles.py`` drew the cones with its own copy of
``layers.style_view_cones`` without the tie's red outline, and chose the "leading" cones by
a score ratio within the camera instead of the core's tie rule (the cones table had no tie
column). The cones now carry their candidate's ``ambiguous_with`` and the stored style is the
plugin's, given that column (stop 41). QGIS itself checks the drawing in
``qgis_plugin/tests/test_batch_styles.py``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pyogrio
import pytest

from camloc_geo.batch import run_batch

REPO = Path(__file__).resolve().parents[1]
STYLES = REPO / "camloc_geo" / "data" / "qgis_styles"
TIE = '"ambiguous_with" IS NOT NULL'


@pytest.fixture(scope="module")
def gpkg(tmp_path_factory: pytest.TempPathFactory) -> Path:
    tmp = tmp_path_factory.mktemp("cones")
    lst = tmp / "cams.csv"
    scene = REPO / "sample_maps" / "sample_scene.json"
    lst.write_text(f"id,title,scene\ns1,,{scene}\n", encoding="utf-8")
    out = tmp / "cams.gpkg"
    run_batch(
        lst,
        out_gpkg=out,
        map_source=REPO / "sample_maps" / "baltimore.osm.pbf",
        progress=False,
        workers=1,
    )
    return out


def test_a_cone_carries_its_candidates_ties(gpkg: Path) -> None:
    cands = pyogrio.read_dataframe(gpkg, layer="candidates", read_geometry=False)
    cones = pyogrio.read_dataframe(gpkg, layer="view_cones", read_geometry=False)

    def text(v: object) -> str | None:
        return v if isinstance(v, str) else None  # NULL reads as NaN

    ties = {
        (r.source, r.rank): text(r.ambiguous_with)
        for r in cands.itertuples()
        if r.source == "locate"
    }
    assert sorted(k[1] for k, t in ties.items() if t) == [1, 2, 3, 4, 5]  # the sample's tie
    assert len(cones) == len(ties)
    for r in cones.itertuples():
        assert text(r.ambiguous_with) == ties[(r.source, r.rank)], r.rank


def test_the_stored_cone_style_is_the_plugins_with_the_tie_rule() -> None:
    qml = ET.fromstring((STYLES / "batch_view_cones.qml").read_text().split("\n", 1)[1])
    rules = list(qml.iter("rule"))
    assert len(rules) == 1
    assert rules[0].get("filter") == f'"rank" = 1 OR ({TIE}) OR coalesce("score", 0) >= 0.05'
    expressions = [
        o.get("value") or "" for o in qml.iter("Option") if o.get("name") == "expression"
    ]
    stroke = [e for e in expressions if "#d7191c" in e]
    assert stroke == [f"CASE WHEN {TIE} THEN '#d7191c' ELSE color_rgba(180, 120, 0, 160) END"]
    # the SLD can say the rule now (it drew every cone: no "a camera's best" in SLD)
    sld = (STYLES / "batch_view_cones.sld").read_text()
    assert "ambiguous_with" in sld


def test_the_style_tool_has_no_copy_of_the_plugins_styles() -> None:
    tool = (REPO / "qgis_plugin" / "make_batch_styles.py").read_text()
    for copied in ("color_rgba(", "_marker(", "_rules("):
        assert copied not in tool, copied
    assert "L.style_view_cones(layer, batch_tie)" in tool
