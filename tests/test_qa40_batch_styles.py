"""Session 40 QA: the batch GeoPackage carried no QGIS styles.

Opened in QGIS it drew every layer in one random colour: ties, ranks and cameras alike. It now
holds QGIS's ``layer_styles`` table with the plugin's styles (QML and SLD) for ``cameras``,
``candidates`` and ``view_cones``, each the layer's default, which QGIS applies when the layer
is opened (checked in QGIS by qgis_plugin/tests/test_batch_styles.py). So does the service's
job result (``/v1/jobs/{id}/result?format=gpkg``), with the styles of its own columns.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pyogrio
import pytest

from camloc_geo.batch import run_batch
from camloc_geo.batch._run import STYLED_LAYERS

REPO = Path(__file__).resolve().parents[1]
BALTIMORE = REPO / "sample_maps" / "baltimore.osm.pbf"


@pytest.fixture(scope="module")
def gpkg(tmp_path_factory: pytest.TempPathFactory) -> Path:
    tmp = tmp_path_factory.mktemp("styles")
    lst = tmp / "cams.csv"
    lst.write_text(
        "id,title\nc1,Eastern Ave & S Broadway\nc2,Nowhere Rd & Fake St\n", encoding="utf-8"
    )
    out = tmp / "cams.gpkg"
    run_batch(lst, out_gpkg=out, map_source=BALTIMORE, progress=False, workers=1)
    return out


def test_the_geopackage_holds_a_default_style_for_each_drawn_layer(gpkg: Path) -> None:
    layers = dict(pyogrio.list_layers(gpkg))
    assert layers["layer_styles"] is None  # an attribute table, as QGIS makes it
    styles = pyogrio.read_dataframe(gpkg, layer="layer_styles")
    assert sorted(styles["f_table_name"]) == sorted(STYLED_LAYERS)
    assert styles["useAsDefault"].tolist() == [True] * len(STYLED_LAYERS)
    assert set(styles["styleName"]) == {"camloc"}
    for _i, row in styles.iterrows():
        name = row["f_table_name"]
        info = pyogrio.read_info(gpkg, layer=name)
        assert row["f_geometry_column"] == info["geometry_name"]
        qml = ET.fromstring(row["styleQML"].split("\n", 1)[1])  # after the DOCTYPE line
        assert qml.tag == "qgis"
        renderer = qml.find("renderer-v2")
        assert renderer is not None
        assert renderer.get("type") == "RuleRenderer"
        ET.fromstring(row["styleSLD"])  # well-formed SLD beside it
        # every field a rule or a label reads is a field of the layer
        used = _fields_read(row["styleQML"])
        assert used, name
        assert used <= set(info["fields"]), (name, used - set(info["fields"]))
    cands = styles.set_index("f_table_name").loc["candidates", "styleQML"]
    assert "ambiguous_with" in cands  # ties drawn as stars, from the batch's own column


def _fields_read(qml_text: str) -> set[str]:
    qml = ET.fromstring(qml_text.split("\n", 1)[1])
    texts = [r.get("filter") or "" for r in qml.iter("rule")]
    texts += [s.get("fieldName") or "" for s in qml.iter("text-style")]
    texts += [o.get("value") or "" for o in qml.iter("Option") if o.get("name") == "expression"]
    return {m for t in texts for m in re.findall(r'"([A-Za-z_]+)"', t)}


def test_a_service_job_geopackage_is_styled_too(tmp_path: Path) -> None:
    from camloc_geo.results import job_result_geojson, job_result_geopackage

    title_only = {
        "id": "t1",
        "row": 1,
        "status": "title_only",
        "lat": 39.2855,
        "lon": -76.5935,
        "candidates": [
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [-76.5935, 39.2855]},
                "properties": {"kind": "candidate", "rank": 1, "score": 0.5},
            }
        ],
    }
    path = tmp_path / "job.gpkg"
    path.write_bytes(job_result_geopackage(job_result_geojson("j", [title_only])))
    styles = pyogrio.read_dataframe(path, layer="layer_styles").set_index("f_table_name")
    assert sorted(styles.index) == ["cameras", "candidates"]
    for name in ("cameras", "candidates"):
        fields = set(pyogrio.read_info(path, layer=name)["fields"])
        assert _fields_read(styles.loc[name, "styleQML"]) <= fields, name
    cands = pyogrio.read_dataframe(path, layer="candidates")
    assert cands["ambiguous_with"].isna().all()  # the column the style reads, empty


def test_the_layers_read_as_before(gpkg: Path) -> None:
    cams = pyogrio.read_dataframe(gpkg, layer="cameras")
    assert cams["id"].tolist() == ["c1", "c2"]
