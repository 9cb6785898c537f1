"""Write the QGIS styles ``camloc batch`` stores in its GeoPackage: run with QGIS's Python.

``/usr/bin/python3 qgis_plugin/make_batch_styles.py`` (``QT_QPA_PLATFORM=offscreen``) writes
``camloc_geo/data/qgis_styles/<name>.qml`` and ``.sld``: ``batch_cameras``,
``batch_candidates`` and ``batch_view_cones`` for ``camloc batch``'s GeoPackage, and
``job_cameras`` and ``job_candidates`` for the service's job result
(``/v1/jobs/{id}/result?format=gpkg``): the plugin's own styles (``camloc/layers.py``: the
list's candidates, its cameras, the view cones) with those layers' field names.
``camloc_geo.results.write_layer_styles`` copies them into a GeoPackage's ``layer_styles``
table, as QGIS's "Save as Default" does, so that the GeoPackage opened in QGIS looks as the
plugin's layers do; camloc_geo itself never needs QGIS. Run it again after changing a style.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
OUT = HERE.parent / "camloc_geo" / "data" / "qgis_styles"
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

_TYPES = {"int64": "int", "float64": "double", "bool": "bool", "object": "string"}


def main() -> int:
    """Write the styles; 0 on success."""
    from qgis.core import QgsApplication, QgsVectorLayer
    from qgis.PyQt.QtXml import QDomDocument

    app = QgsApplication([], False)
    app.initQgis()
    from camloc import layers as L  # noqa: N812  (the plugin's styles)

    from camloc_geo.batch import _run

    # the batch's ties: "2,4", NULL without one; the job's: JSON text, "[2, 4]" or "[]"
    batch_tie = '"ambiguous_with" IS NOT NULL'
    job_tie = "coalesce(\"ambiguous_with\", '[]') NOT IN ('', '[]')"

    # the plugin's styles themselves, given these layers' tie expressions and id column
    # (session 41: this file drew its own copies; the cones' lacked the tie's red outline)
    def cones(layer: QgsVectorLayer) -> None:
        L.style_view_cones(layer, batch_tie)

    # a tied camera: a plain column, as the SLD export can state it (not coalesce())
    def cameras(layer: QgsVectorLayer) -> None:
        L.style_cameras(layer, id_field="id", tie_expr='"tie"')

    def job_cameras_style(layer: QgsVectorLayer) -> None:
        # the job result's cameras call the tie 'ambiguous' (camloc_geo.results)
        L.style_cameras(layer, id_field="id", tie_expr='"ambiguous"')

    job_cameras = {
        "id": "object",
        "status": "object",
        "title": "object",
        "score": "float64",
        "ambiguous": "bool",
    }
    job_candidates = {
        "camera_id": "object",
        "rank": "int64",
        "score": "float64",
        "ambiguous_with": "object",
    }
    jobs = [
        ("batch_cameras", "Point", _run._CAMERA_COLUMNS, cameras),
        (
            "batch_candidates",
            "Point",
            _run._CANDIDATE_COLUMNS,
            lambda x: L.style_list_candidates(x, batch_tie),
        ),
        ("batch_view_cones", "MultiPolygon", _run._CONE_COLUMNS, cones),
        ("job_cameras", "Point", job_cameras, job_cameras_style),
        ("job_candidates", "Point", job_candidates, lambda x: L.style_list_candidates(x, job_tie)),
    ]
    OUT.mkdir(parents=True, exist_ok=True)
    for name, geometry, columns, style in jobs:
        layer = QgsVectorLayer(f"{geometry}?crs=EPSG:4326", name, "memory")
        desc = {"fields": [[c, _TYPES[t]] for c, t in columns.items()]}
        layer.dataProvider().addAttributes(L.fields_of(desc).toList())
        layer.updateFields()
        style(layer)
        doc = QDomDocument()
        error = layer.exportNamedStyle(doc)
        if error:
            print(f"{name}: {error}", file=sys.stderr)
            return 1
        (OUT / f"{name}.qml").write_text(doc.toString(1), encoding="utf-8")
        sld = QDomDocument()
        layer.exportSldStyle(sld, "")
        (OUT / f"{name}.sld").write_text(sld.toString(1), encoding="utf-8")
        print(OUT / f"{name}.qml")
    app.exitQgis()
    return 0


if __name__ == "__main__":
    sys.exit(main())
