"""Stop 41 qa4: a grader's walk through the clients, the faults found (each fails without its
fix)."""

from __future__ import annotations

from pathlib import Path

import pytest

from camloc_geo.cli import main

REPO = Path(__file__).resolve().parent.parent


def test_summary_map_given_a_batch_geopackage_names_batch_map(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A batch team gave ``camloc summary-map`` the batch's GeoPackage: "not a GeoJSON file
    (camloc locate output) (a GeoPackage or SQLite database)", with no word that ``camloc
    batch --map`` writes that page (and re-reads the cameras done from its journal)."""
    import sqlite3

    gpkg = tmp_path / "batch.gpkg"
    con = sqlite3.connect(gpkg)
    con.execute("create table cameras (id text)")
    con.commit()
    con.close()
    out = tmp_path / "s.html"
    assert main(["summary-map", str(gpkg), "-o", str(out), "--offline"]) == 2
    err = capsys.readouterr().err
    assert "a GeoPackage (camloc batch's output?)" in err
    assert "camloc batch itself, with --map SUMMARY.html" in err
    assert "Traceback" not in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("name", "tie"), [("batch_cameras", '"tie"'), ("job_cameras", '"ambiguous"')]
)
def test_a_tied_camera_is_drawn_apart_in_the_stored_styles(name: str, tie: str) -> None:
    """A list's cameras were all one red triangle labelled 'a located', a camera whose best
    candidate ties with another 61 m away as sure-looking as any (the batch GeoPackage and the
    job's, in the QGIS desktop). The stored styles (``make_batch_styles.py``) now draw a tied
    camera apart and end its label with '≈ tie'; QGIS itself checks the drawing in
    ``qgis_plugin/tests/test_batch_styles.py``."""
    import xml.etree.ElementTree as ET

    qml = ET.parse(REPO / "camloc_geo" / "data" / "qgis_styles" / f"{name}.qml").getroot()
    rules = [(r.get("filter"), r.get("label")) for r in qml.iter("rule")]
    assert rules[0][0] == tie
    assert rules[0][1].startswith("camera placed at a tied candidate")
    assert rules[1] == ("ELSE", "camera placed")
    labels = [s.get("fieldName") for s in qml.iter("text-style")]
    assert any(f"CASE WHEN {tie} THEN ' ≈ tie'" in (x or "") for x in labels), labels
    sld = (REPO / "camloc_geo" / "data" / "qgis_styles" / f"{name}.sld").read_text("utf-8")
    assert "<ogc:PropertyName>" + tie.strip('"') + "</ogc:PropertyName>" in sld


@pytest.mark.parametrize("cluster", [True, False])
def test_a_tied_cameras_popup_says_where_to_choose(tmp_path: Path, cluster: bool) -> None:
    """A summary page's popup of a tied best candidate said "see the camera's review page",
    a page a job's summary (``GET /v1/jobs/{id}/map``) or a batch's has not, while the popup
    itself offers the other candidates ('or the camera is candidate…')."""
    located = tmp_path / "cam.geojson"
    scene = REPO / "sample_maps" / "sample_scene.json"
    osm = REPO / "sample_maps" / "baltimore.osm.pbf"
    assert main(["locate", str(scene), "--osm", str(osm), "--offline", "-o", str(located)]) == 0
    out = tmp_path / "s.html"
    args = ["summary-map", str(located), "-o", str(out), "--offline"]
    assert main(args if cluster else [*args, "--no-cluster"]) == 0
    page = out.read_text(encoding="utf-8")
    assert "the camera may stand at a tied candidate instead" in page
    assert "see the camera's review page" not in page
