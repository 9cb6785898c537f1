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


def test_a_list_run_without_any_map_says_so_once(tmp_path: Path) -> None:
    """``camloc batch`` (and QGIS's geocodelist) without an extract and with the network off
    ended every camera no_map, exit 0, with the reason only per camera in the GeoPackage
    (session 41 QA): the run now says it once, in the summary's warnings (stderr, the
    Processing log)."""
    from camloc_geo.batch import run_batch

    lst = tmp_path / "cams.csv"
    lst.write_text("id,title,lat,lon\na,Eastern Ave & Broadway,39.2857,-76.5933\n", "utf-8")
    summary = run_batch(lst, out_gpkg=tmp_path / "o.gpkg", progress=False, workers=1)
    assert summary.statuses == {"no_map": 1}
    said = [w for w in summary.warnings if "this run had no map" in w]
    assert said == [
        "1 camera(s) no_map: this run had no map (no extract, the network off): give --osm "
        "EXTRACT_OR_FOLDER or allow --network"
    ]
    # with an extract: no such warning
    osm = REPO / "sample_maps" / "baltimore.osm.pbf"
    again = run_batch(lst, out_gpkg=tmp_path / "p.gpkg", map_source=osm, progress=False, workers=1)
    assert not [w for w in again.warnings if "no map" in w]


def test_a_geojson_list_without_a_feature_is_named_as_geojson(tmp_path: Path) -> None:
    """It said "no row under its header", a CSV's words, of a GeoJSON list."""
    from camloc_geo import InputError
    from camloc_geo.batch import run_batch

    lst = tmp_path / "cams.geojson"
    lst.write_text('\ufeff {"type": "FeatureCollection", "features": []}', "utf-8")
    with pytest.raises(
        InputError, match=r"holds no camera \(no feature in its FeatureCollection\)"
    ):
        run_batch(lst, out_gpkg=tmp_path / "o.gpkg", progress=False, workers=1)
    csv = tmp_path / "cams.csv"
    csv.write_text("id,title\n", "utf-8")
    with pytest.raises(InputError, match=r"no row under its header"):
        run_batch(csv, out_gpkg=tmp_path / "c.gpkg", progress=False, workers=1)
