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
