"""The camloc Processing provider and its algorithms, through ``processing.run`` in real QGIS."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import SAMPLE_OSM, SAMPLE_SCENE, metres_between, truth
from qgis.core import (
    QgsProcessingException,
    QgsProcessingFeedback,
    QgsVectorLayer,
)
from qgis.PyQt.QtCore import QVariant


def _layer(path: str) -> QgsVectorLayer:
    layer = QgsVectorLayer(path, Path(path).stem, "ogr")
    assert layer.isValid(), path
    return layer


def _types(layer: QgsVectorLayer) -> dict[str, int]:
    return {f.name(): f.type() for f in layer.fields()}


def _locate(tmp_path: Path, scene: Path = SAMPLE_SCENE, **extra):
    import processing

    params = {
        "SCENE": str(scene),
        "OSM": str(SAMPLE_OSM),
        "CANDIDATES": str(tmp_path / "candidates.gpkg"),
        "VIEW_CONES": str(tmp_path / "view_cones.gpkg"),
        "MATCHED_CORNERS": str(tmp_path / "matched.gpkg"),
        "INTERSECTION": str(tmp_path / "intersection.gpkg"),
        **extra,
    }
    return processing.run("camloc:locate", params)


def test_provider_loads_with_its_algorithms(provider):
    from qgis.core import QgsApplication

    ids = {a.id() for a in provider.algorithms()}
    assert {"camloc:locate", "camloc:corners", "camloc:geocodelist"} <= ids
    assert provider.capabilities.get("version") is not None
    # camloc:measure is registered only when camloc_geo has the virtual sensors
    assert ("camloc:measure" in ids) == bool(provider.capabilities.get("sensors"))
    reg = QgsApplication.processingRegistry()
    assert reg.algorithmById("camloc:locate") is not None
    alg = reg.algorithmById("camloc:locate")
    names = [p.name() for p in alg.parameterDefinitions()]
    assert names[:2] == ["SCENE", "OSM"]
    assert {"CANDIDATES", "VIEW_CONES", "MATCHED_CORNERS", "INTERSECTION"} <= set(names)


def test_locate_layers_counts_types_and_accuracy(provider, tmp_path):
    res = _locate(tmp_path)
    cands = _layer(res["CANDIDATES"])
    assert cands.crs().authid() == "EPSG:4326"
    assert cands.featureCount() == 12
    assert res["N_CANDIDATES"] == 12
    types = _types(cands)
    assert types["rank"] in (QVariant.Int, QVariant.LongLong)
    assert types["score"] == QVariant.Double
    assert types["tie"] == QVariant.Bool
    assert types["heading_deg"] == QVariant.Double
    assert types["flags"] == QVariant.String
    assert types["ambiguous_with"] == QVariant.String
    feats = sorted(cands.getFeatures(), key=lambda f: f["rank"])
    assert [f["rank"] for f in feats] == list(range(1, 13))
    scores = [f["score"] for f in feats]
    assert scores == sorted(scores, reverse=True)
    # the sample's symmetric junction: candidates 1 and 2 tie across it (3 and 4 are their
    # near twins), and say so; 5 on score nothing
    assert [f["tie"] for f in feats[:5]] == [True, True, True, True, False]
    assert feats[0]["ambiguous_with"] == "2,4"
    assert feats[1]["ambiguous_with"] == "1,3"
    t = truth()
    dists = [
        metres_between(f.geometry().asPoint().y(), f.geometry().asPoint().x(), t["lat"], t["lon"])
        for f in feats
    ]
    assert min(dists) < 5.0
    assert dists[0] < 5.0  # the best candidate is the true position (to 5 m)
    assert _layer(res["VIEW_CONES"]).featureCount() == 12
    matched = _layer(res["MATCHED_CORNERS"])
    assert matched.featureCount() == 36
    assert _types(matched)["misfit_m"] == QVariant.Double
    inter = _layer(res["INTERSECTION"])
    kinds = sorted(f["kind"] for f in inter.getFeatures())
    assert kinds == ["corner"] * 4 + ["intersection"]
    streets = [f["streets"] for f in inter.getFeatures() if f["kind"] == "intersection"]
    assert streets == ["Eastern Avenue & South Broadway"]


def test_locate_default_style_colours_by_score_labels_rank_marks_ties(provider, tmp_path):
    from camloc.layers import apply_style
    from qgis.core import QgsGraduatedSymbolRenderer, QgsSymbolLayer

    res = _locate(tmp_path, MAX_CANDIDATES=3)
    layer = _layer(res["CANDIDATES"])
    assert layer.featureCount() == 3
    apply_style(layer, "candidates")
    r = layer.renderer()
    assert isinstance(r, QgsGraduatedSymbolRenderer)
    assert r.classAttribute() == "score"
    ranges = r.ranges()  # keep the copies alive while their symbols are read
    symbols = [rng.symbol() for rng in ranges]
    colours = {sym.color().name() for sym in symbols}
    assert len(colours) == len(ranges) >= 3
    props = symbols[0].symbolLayer(0).dataDefinedProperties()
    shape = props.property(QgsSymbolLayer.PropertyName).expressionString()
    assert '"tie"' in shape
    assert "star" in shape
    assert layer.labelsEnabled()
    assert '"rank"' in layer.labeling().settings().fieldName


def test_locate_bad_scene_is_a_processing_error_naming_the_problem(provider, tmp_path):
    bad = tmp_path / "bad.json"
    data = json.loads(SAMPLE_SCENE.read_text())
    del data["annotations"][0]["axes"]["origin"]
    bad.write_text(json.dumps(data))
    with pytest.raises(QgsProcessingException) as err:
        _locate(tmp_path, scene=bad)
    assert "annotations[0].axes.origin" in str(err.value)
    assert "Traceback" not in str(err.value)


def test_locate_without_map_and_network_says_give_an_extract(provider, tmp_path):
    with pytest.raises(QgsProcessingException, match="network is off"):
        _locate(tmp_path, OSM=None, NETWORK=False)


def test_locate_cancel_stops_the_worker(provider, tmp_path):
    import processing

    fb = QgsProcessingFeedback()
    fb.cancel()
    res = processing.run(
        "camloc:locate",
        {
            "SCENE": str(SAMPLE_SCENE),
            "OSM": str(SAMPLE_OSM),
            "CANDIDATES": str(tmp_path / "c.gpkg"),
        },
        feedback=fb,
    )
    assert "CANDIDATES" not in res or not Path(tmp_path / "c.gpkg").exists()


def test_progress_reaches_feedback(provider, tmp_path):
    import processing

    seen: list[float] = []
    fb = QgsProcessingFeedback()
    fb.progressChanged.connect(seen.append)
    processing.run(
        "camloc:locate",
        {"SCENE": str(SAMPLE_SCENE), "OSM": str(SAMPLE_OSM), "CANDIDATES": "TEMPORARY_OUTPUT"},
        feedback=fb,
    )
    assert seen
    assert max(seen) >= 80


def test_corners_around_a_point_in_another_crs(provider, tmp_path):
    import processing
    from qgis.core import (
        QgsCoordinateReferenceSystem,
        QgsCoordinateTransform,
        QgsPointXY,
        QgsProject,
    )

    xf = QgsCoordinateTransform(
        QgsCoordinateReferenceSystem("EPSG:4326"),
        QgsCoordinateReferenceSystem("EPSG:3857"),
        QgsProject.instance(),
    )
    p = xf.transform(QgsPointXY(-76.5935, 39.2856))
    res = processing.run(
        "camloc:corners",
        {
            "POINT": f"{p.x()},{p.y()} [EPSG:3857]",
            "RADIUS_M": 100,
            "OSM": str(SAMPLE_OSM),
            "CORNERS": str(tmp_path / "corners.gpkg"),
        },
    )
    layer = _layer(res["CORNERS"])
    assert layer.crs().authid() == "EPSG:4326"
    assert _types(layer)["order"] in (QVariant.Int, QVariant.LongLong)
    feats = list(layer.getFeatures())
    main = [
        f["intersection"]
        for f in feats
        if f["kind"] == "intersection" and f["streets"] == "Eastern Avenue & South Broadway"
    ]
    assert len(main) == 1
    orders = sorted(
        f["order"] for f in feats if f["kind"] == "corner" and f["intersection"] == main[0]
    )
    assert orders == [0, 1, 2, 3]
    for f in layer.getFeatures():
        pt = f.geometry().asPoint()
        assert (
            metres_between(pt.y(), pt.x(), 39.2856, -76.5935) < 130
        )  # corners of junctions within 100 m


def test_corners_in_a_canvas_extent(provider, tmp_path):
    import processing

    res = processing.run(
        "camloc:corners",
        {
            "EXTENT": "-76.5950,-76.5920,39.2845,39.2865 [EPSG:4326]",
            "OSM": str(SAMPLE_OSM),
            "CORNERS": str(tmp_path / "corners.gpkg"),
        },
    )
    layer = _layer(res["CORNERS"])
    n_inter = sum(1 for f in layer.getFeatures() if f["kind"] == "intersection")
    assert n_inter >= 2


def test_corners_needs_a_point_or_an_extent(provider):
    # (a test of its own: a layer kept alive by an exception's frames until QGIS exits
    # crashes the interpreter at exit)
    import processing

    with pytest.raises(QgsProcessingException, match="give a point"):
        processing.run("camloc:corners", {"OSM": str(SAMPLE_OSM), "CORNERS": "TEMPORARY_OUTPUT"})


def test_geocodelist_one_row_per_camera_with_status(provider, tmp_path):
    import processing

    far = json.loads(SAMPLE_SCENE.read_text())
    far["prior"] = {"lat": 52.52, "lon": 13.41, "radius_m": 150}
    (tmp_path / "far.json").write_text(json.dumps(far))
    lst = tmp_path / "cams.csv"
    lst.write_text(
        "id,title,latitude,lng,scene\n"
        f"cam1,Eastern Ave & S Broadway looking north,39.2856,-76.5935,{SAMPLE_SCENE}\n"
        "cam2,no snapshot,39.2856,-76.5935,missing.json\n"
        "cam3,far away,52.52,13.41,far.json\n"
    )
    res = processing.run(
        "camloc:geocodelist",
        {
            "LIST": str(lst),
            "OSM": str(SAMPLE_OSM),
            "CAMERAS": str(tmp_path / "cameras.gpkg"),
            "CANDIDATES": str(tmp_path / "cands.gpkg"),
        },
    )
    cams = {f["camera_id"]: f for f in _layer(res["CAMERAS"]).getFeatures()}
    assert set(cams) == {"cam1", "cam2", "cam3"}
    assert cams["cam1"]["status"] in ("ok", "ambiguous")
    t = truth()
    pt = cams["cam1"].geometry().asPoint()
    assert metres_between(pt.y(), pt.x(), t["lat"], t["lon"]) < 5.0
    assert cams["cam2"]["status"] == "error"
    assert "not found" in cams["cam2"]["reason"]
    assert cams["cam3"]["status"] in ("error", "not_found")
    assert cams["cam3"]["reason"]
    cands = _layer(res["CANDIDATES"])
    assert cands.featureCount() >= 1
    assert "cam1" in {f["camera_id"] for f in cands.getFeatures()}
