"""Session 38 QA: a camera whose scene cannot be read has no point, nor a point's sigma.

``camloc batch`` (and a job, QGIS ``camloc:geocodelist``) gave a ``scene_error`` camera with
a good title a NULL point but the title junction's ``uncertainty_m`` (21 m): a GIS layer
showed a 1-sigma of 21 m for a camera it did not place. The title's junction stays in the
candidates layer with its own uncertainty.
"""

from __future__ import annotations

from pathlib import Path

import pyogrio

from camloc_geo.batch import run_batch

REPO = Path(__file__).resolve().parents[1]
OSM = REPO / "sample_maps" / "baltimore.osm.pbf"


def test_scene_error_camera_has_no_uncertainty(tmp_path: Path) -> None:
    (tmp_path / "broken.json").write_text("{", encoding="utf-8")
    lst = tmp_path / "cams.csv"
    lst.write_text(
        "id,title,lat,lon,scene\nc1,Eastern Ave & S Broadway,39.2856,-76.5935,broken.json\n",
        encoding="utf-8",
    )
    out = tmp_path / "out.gpkg"
    run_batch(lst, out_gpkg=out, map_source=OSM, progress=False, workers=1)
    cam = pyogrio.read_dataframe(out, layer="cameras").iloc[0]
    assert cam["status"] == "scene_error"
    assert cam.geometry is None
    assert cam["uncertainty_m"] != cam["uncertainty_m"]  # NULL (NaN)
    cands = pyogrio.read_dataframe(out, layer="candidates")
    assert len(cands) == 1
    assert cands.iloc[0]["source"] == "title"
    assert 5.0 < cands.iloc[0]["uncertainty_m"] < 100.0
