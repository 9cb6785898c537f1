"""The camloc Processing provider and its algorithms, through ``processing.run`` in real QGIS."""

from __future__ import annotations

import json
import os
import shutil
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
    assert cands.featureCount() == 13
    assert res["N_CANDIDATES"] == 13
    types = _types(cands)
    assert types["rank"] in (QVariant.Int, QVariant.LongLong)
    assert types["score"] == QVariant.Double
    assert types["tie"] == QVariant.Bool
    assert types["heading_deg"] == QVariant.Double
    assert types["flags"] == QVariant.String
    assert types["ambiguous_with"] == QVariant.String
    feats = sorted(cands.getFeatures(), key=lambda f: f["rank"])
    assert [f["rank"] for f in feats] == list(range(1, 14))
    scores = [f["score"] for f in feats]
    assert scores == sorted(scores, reverse=True)
    # the sample's symmetric junction: candidates 1 and 2 tie across it (3 and 4 are their
    # near twins, 5 a same-shaped junction a block away: stop 41), and say so; 6 on score nothing
    assert [f["tie"] for f in feats[:6]] == [True] * 5 + [False]
    assert feats[0]["ambiguous_with"] == "2,4,5"
    assert feats[1]["ambiguous_with"] == "1,3,5"
    t = truth()
    dists = [
        metres_between(f.geometry().asPoint().y(), f.geometry().asPoint().x(), t["lat"], t["lon"])
        for f in feats
    ]
    assert min(dists) < 5.0
    assert dists[0] < 5.0  # the best candidate is the true position (to 5 m)
    assert _layer(res["VIEW_CONES"]).featureCount() == 13
    matched = _layer(res["MATCHED_CORNERS"])
    assert matched.featureCount() == 39
    # every layer of a camera names it: cones and matched points merged from several runs
    # (Merge vector layers, one GeoPackage per city) could not be told apart
    sid = json.loads(SAMPLE_SCENE.read_text())["id"]
    assert {f["scene"] for f in cands.getFeatures()} == {sid}
    assert {f["scene"] for f in _layer(res["VIEW_CONES"]).getFeatures()} == {sid}
    assert {f["scene"] for f in matched.getFeatures()} == {sid}
    assert _types(matched)["misfit_m"] == QVariant.Double
    inter = _layer(res["INTERSECTION"])
    kinds = sorted(f["kind"] for f in inter.getFeatures())
    assert kinds == ["corner"] * 4 + ["intersection"]
    streets = [f["streets"] for f in inter.getFeatures() if f["kind"] == "intersection"]
    assert streets == ["Eastern Avenue & South Broadway"]


def test_locate_default_style_ties_stars_best_red_unlikely_faded(provider, tmp_path):
    from camloc.layers import TIE_WORDS, apply_style
    from qgis.core import QgsRuleBasedRenderer

    res = _locate(tmp_path, MAX_CANDIDATES=3)
    layer = _layer(res["CANDIDATES"])
    assert layer.featureCount() == 3
    apply_style(layer, "candidates")
    r = layer.renderer()
    assert isinstance(r, QgsRuleBasedRenderer)
    rules = r.rootRule().children()
    assert rules[0].filterExpression() == '"tie"'
    assert "odds under 10 to 1" in rules[0].label()  # the legend explains a tie
    assert "10 to 1" in TIE_WORDS
    assert rules[-1].isElse()
    assert rules[-1].symbol().opacity() < 1.0  # the unlikely are faded
    assert len({rule.symbol().color().name() for rule in rules}) >= 4
    assert layer.labelsEnabled()
    expr = layer.labeling().settings().fieldName
    # labels beside the marker (from the symbol's bounds), not under the 7 mm tie star
    from qgis.core import QgsPalLayerSettings

    pal = layer.labeling().settings()
    assert pal.placement == QgsPalLayerSettings.OrderedPositionsAroundPoint
    assert pal.offsetType == QgsPalLayerSettings.FromSymbolBounds
    assert '"rank"' in expr
    assert '"score_text"' in expr
    widths = {c.name: c.width for c in layer.attributeTableConfig().columns()}
    assert widths["score"] >= 150  # room for 1.17461213e-15, exponent included
    scores = {f["score_text"] for f in layer.getFeatures()}
    assert all(t and len(t) <= 8 for t in scores), scores  # 0.37, 1.2e-15: never cut


def test_locate_help_states_the_core_tie_rule(provider):
    from qgis.core import QgsApplication

    text = QgsApplication.processingRegistry().algorithmById("camloc:locate").shortHelpString()
    assert "80 %" not in text
    assert "odds under 10 to 1" in text
    assert "ambiguous_with" in text


def test_locate_context_layers_of_the_map_model(provider, tmp_path):
    res = _locate(
        tmp_path,
        CONTEXT=True,
        CONTEXT_STREETS=str(tmp_path / "streets.gpkg"),
        CONTEXT_BUILDINGS=str(tmp_path / "buildings.gpkg"),
    )
    streets = _layer(res["CONTEXT_STREETS"])
    assert streets.featureCount() > 20
    names = {f["name"] for f in streets.getFeatures()}
    assert {"Eastern Avenue", "South Broadway"} <= names
    assert _layer(res["CONTEXT_BUILDINGS"]).featureCount() > 0


def test_run_and_load_results_draws_candidates_above_cones(provider, tmp_path):
    """``processing.runAndLoadResults``: Processing's own loading, then our post-processors."""
    import processing
    from qgis.core import QgsProject

    project = QgsProject.instance()
    project.clear()
    processing.runAndLoadResults(
        "camloc:locate",
        {
            "SCENE": str(SAMPLE_SCENE),
            "OSM": str(SAMPLE_OSM),
            "CANDIDATES": "TEMPORARY_OUTPUT",
            "VIEW_CONES": "TEMPORARY_OUTPUT",
            "MATCHED_CORNERS": "TEMPORARY_OUTPUT",
            "INTERSECTION": "TEMPORARY_OUTPUT",
        },
    )
    order = [n.layer().customProperty("camloc/kind") for n in project.layerTreeRoot().findLayers()]
    names = [n.layer().name() for n in project.layerTreeRoot().findLayers()]
    assert order.index("candidates") < order.index("view_cones"), (order, names)
    # each layer says which camera it is of (two runs gave two 'Camera candidates')
    sid = json.loads(SAMPLE_SCENE.read_text())["id"]
    assert f"Camera candidates ({sid})" in names, names
    assert f"View cones ({sid})" in names, names
    assert order.index("matched_corners") < order.index("view_cones"), order
    # the map draws the layer tree's order: the candidates last, on top
    drawn = project.layerTreeRoot().layerOrder()
    kinds = [lyr.customProperty("camloc/kind") for lyr in drawn]
    assert kinds.index("candidates") < kinds.index("view_cones")
    project.clear()


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


def test_corners_in_the_extent_of_one_point(provider, tmp_path):
    """The extent of a layer of one point (the best candidate a filter kept, a one-camera
    list; docs/qgis.md's model feeds locate's candidates to EXTENT) was refused, "the
    extent is empty": it is that point with RADIUS_M (session 39)."""
    import processing

    one = tmp_path / "one.geojson"
    one.write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "features": [
                    {
                        "type": "Feature",
                        "geometry": {"type": "Point", "coordinates": [-76.5935, 39.2856]},
                        "properties": {"rank": 1},
                    }
                ],
            }
        )
    )
    res = processing.run(
        "camloc:corners",
        {
            "EXTENT": str(one),
            "RADIUS_M": 60,
            "OSM": str(SAMPLE_OSM),
            "CORNERS": str(tmp_path / "corners.gpkg"),
        },
    )
    layer = _layer(res["CORNERS"])
    streets = [f["streets"] for f in layer.getFeatures() if f["kind"] == "intersection"]
    assert "Eastern Avenue & South Broadway" in streets
    for f in layer.getFeatures():
        pt = f.geometry().asPoint()
        assert metres_between(pt.y(), pt.x(), 39.2856, -76.5935) < 90  # within 60 m, + corners


def test_corners_in_the_extent_of_no_feature_says_so(provider, tmp_path):
    import processing

    none = tmp_path / "none.geojson"
    none.write_text(json.dumps({"type": "FeatureCollection", "features": []}))
    with pytest.raises(QgsProcessingException, match="the extent is empty \\(a layer without"):
        processing.run(
            "camloc:corners",
            {"EXTENT": str(none), "OSM": str(SAMPLE_OSM), "CORNERS": "TEMPORARY_OUTPUT"},
        )


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
        "cam4,Foo St & Bar Ave,,,\n"
        "cam5,N Milton Ave & E Biddle St,,,\n"
    )
    res = processing.run(
        "camloc:geocodelist",
        {
            "LIST": str(lst),
            "OSM": str(SAMPLE_OSM.parent),  # a folder of extracts, as camloc batch takes
            "CAMERAS": str(tmp_path / "cameras.gpkg"),
            "CANDIDATES": str(tmp_path / "cands.gpkg"),
        },
    )
    cams = {f["camera_id"]: f for f in _layer(res["CAMERAS"]).getFeatures()}
    assert set(cams) == {"cam1", "cam2", "cam3", "cam4", "cam5"}
    assert cams["cam1"]["status"] == "located"
    t = truth()
    pt = cams["cam1"].geometry().asPoint()
    assert metres_between(pt.y(), pt.x(), t["lat"], t["lon"]) < 5.0
    assert cams["cam2"]["status"] == "scene_error"
    assert "missing.json" in cams["cam2"]["reason"]
    assert cams["cam3"]["status"] in ("no_map", "scene_error", "no_candidates")
    assert cams["cam3"]["reason"]
    assert cams["cam4"]["status"] == "not_found"
    assert cams["cam4"]["n_candidates"] == 0
    assert cams["cam4"].geometry().isEmpty()  # not placed (GeoPackage: POINT EMPTY)
    assert cams["cam5"]["status"] == "title_only"
    # one score scale (session 41): the title's junction holds the camera's whole share, its
    # name match is match_score; a located camera's title junction holds none
    assert cams["cam5"]["score"] == 1.0
    assert 0.0 < cams["cam5"]["match_score"] <= 1.0
    cands = _layer(res["CANDIDATES"])
    assert cands.featureCount() >= 1
    assert "cam1" in {f["camera_id"] for f in cands.getFeatures()}
    cam1 = [f for f in cands.getFeatures() if f["camera_id"] == "cam1"]
    located = [f["score"] for f in cam1 if f["source"] == "locate"]
    assert sum(located) == pytest.approx(1.0)
    assert all(f["score"] == 0.0 for f in cam1 if f["source"] == "title")
    # the camera labels win over the candidates' (label priority)
    from camloc.layers import apply_style

    cam_layer, cand_layer = _layer(res["CAMERAS"]), _layer(res["CANDIDATES"])
    apply_style(cam_layer, "cameras")
    apply_style(cand_layer, "list_candidates")
    assert cam_layer.labeling().settings().priority > cand_layer.labeling().settings().priority


def test_parameter_labels_fit_the_dialog(provider):
    """Labels of 60-75 characters ("OSM extract (.osm, .osm.pbf, .osm.bz2, .osm.gz); empty:
    Overpass if allowed") widened the form past the Processing dialog as QGIS opens it
    (688 px, seen under Xvfb): the labels were cut and the file pickers' browse buttons
    hidden. Labels are short now; what they left out is the parameters' help."""
    max_chars = 48  # camloc.algorithms.LABEL_MAX_CHARS
    long = [
        (alg.id(), p.name(), p.description())
        for alg in provider.algorithms()
        for p in alg.parameterDefinitions()
        if len(p.description()) > max_chars
    ]
    assert long == []
    locate = next(a for a in provider.algorithms() if a.id() == "camloc:locate")
    radius = locate.parameterDefinition("RADIUS_M")
    if hasattr(radius, "help"):
        assert "prior radius + 200 m" in radius.help()


def test_outputs_sharing_one_geopackage_each_get_their_table(provider, tmp_path):
    # qgis_process.bin run camloc:locate --CANDIDATES=out.gpkg --VIEW_CONES=out.gpkg left
    # only the cones: QGIS wrote each plain .gpkg destination as a new file
    from osgeo import ogr

    gpkg = tmp_path / "out.gpkg"
    res = _locate(tmp_path, CANDIDATES=str(gpkg), VIEW_CONES=str(gpkg), MATCHED_CORNERS=None)
    ds = ogr.Open(str(gpkg))
    names = {ds.GetLayer(i).GetName() for i in range(ds.GetLayerCount())}
    assert {"candidates", "view_cones"} <= names
    assert ds.GetLayerByName("candidates").GetFeatureCount() == 13
    assert ds.GetLayerByName("view_cones").GetFeatureCount() == 13
    assert _layer(res["CANDIDATES"]).featureCount() == 13
    assert _layer(res["VIEW_CONES"]).wkbType() != _layer(res["CANDIDATES"]).wkbType()
    # outputs in files of their own keep QGIS's naming (the table is the file's name)
    assert Path(res["INTERSECTION"].split("|")[0]).name == "intersection.gpkg"


def test_geopackage_outputs_carry_their_style_when_opened_later(provider, tmp_path):
    # a GeoPackage written by processing.run / qgis_process opened in QGIS afterwards drew
    # plain dots without labels and a cone for every candidate: the styles were applied only
    # to layers loaded at the end of a run in the desktop
    from qgis.core import QgsRuleBasedRenderer

    res = _locate(tmp_path)
    cands = QgsVectorLayer(res["CANDIDATES"], "fresh", "ogr")  # loads the default style
    assert isinstance(cands.renderer(), QgsRuleBasedRenderer)
    assert cands.renderer().rootRule().children()[0].filterExpression() == '"tie"'
    assert cands.labelsEnabled()
    assert cands.customProperty("camloc/kind") == "candidates"
    cones = QgsVectorLayer(res["VIEW_CONES"], "fresh", "ogr")
    assert isinstance(cones.renderer(), QgsRuleBasedRenderer)
    assert cones.customProperty("camloc/kind") == "view_cones"
    # the feature tables are untouched
    assert cands.featureCount() == 13


def test_every_optional_input_says_what_empty_means(provider):
    # MAX_CANDIDATES, POINT, EXTENT, STREETS and OSM_FILE opened empty in the dialog with no
    # tooltip: nothing said what an empty field does (every candidate? no filter?)
    from qgis.core import QgsProcessingDestinationParameter

    silent = [
        f"{alg.id()}:{p.name()}"
        for alg in provider.algorithms()
        for p in alg.parameterDefinitions()
        if not isinstance(p, QgsProcessingDestinationParameter)
        and (p.defaultValue() is None or p.name() == "PAIRS")
        and not (p.help() if hasattr(p, "help") else "")
        and p.name() not in ("SCENE", "LIST")  # required, the label says it
    ]
    assert silent == []


def test_geocodelist_a_tied_camera_is_drawn_apart(provider, tmp_path):
    """Session 41 QA (the QGIS desktop): every camera was one red triangle, the sample's
    camera labelled 'a located' while its best candidate ties with one 61 m away, as
    sure-looking as the untied title-placed camera beside it."""
    import processing
    from camloc.layers import CAMERA_TIE_WORDS, apply_style
    from qgis.core import QgsExpression, QgsExpressionContext, QgsExpressionContextUtils

    lst = tmp_path / "cams.csv"
    lst.write_text(f"id,title,scene\ns1,,{SAMPLE_SCENE}\nc1,Eastern Ave & S Broadway,\n")
    res = processing.run(
        "camloc:geocodelist",
        {"LIST": str(lst), "OSM": str(SAMPLE_OSM), "CAMERAS": str(tmp_path / "cameras.gpkg")},
    )
    layer = _layer(res["CAMERAS"])
    apply_style(layer, "cameras")
    ctx = QgsExpressionContext(QgsExpressionContextUtils.globalProjectLayerScopes(layer))
    label = QgsExpression(layer.labeling().settings().fieldName)
    drawn, labels, ties = {}, {}, {}
    for f in layer.getFeatures():
        ctx.setFeature(f)
        ties[f["camera_id"]] = bool(f["tie"])
        labels[f["camera_id"]] = label.evaluate(ctx)
        for rule in layer.renderer().rootRule().children():
            if rule.isElse() or QgsExpression(rule.filterExpression()).evaluate(ctx):
                drawn[f["camera_id"]] = rule.label()
                break
    assert ties == {"s1": True, "c1": False}
    assert drawn == {"s1": CAMERA_TIE_WORDS, "c1": "camera placed"}
    assert labels == {"s1": "s1 located ≈ tie", "c1": "c1 title_only"}


def test_geocodelist_layers_loaded_name_their_list(provider, tmp_path):
    import processing
    from qgis.core import QgsProject

    lst = tmp_path / "harbour.csv"
    lst.write_text("id,title,lat,lon\ncam1,Eastern Ave & S Broadway,39.2856,-76.5935\n")
    project = QgsProject.instance()
    project.clear()
    processing.runAndLoadResults(
        "camloc:geocodelist",
        {"LIST": str(lst), "OSM": str(SAMPLE_OSM), "CAMERAS": "TEMPORARY_OUTPUT"},
    )
    names = [n.layer().name() for n in project.layerTreeRoot().findLayers()]
    assert names == ["Cameras (harbour.csv)"]
    project.clear()


def test_run_and_load_again_into_the_same_geopackage(provider, tmp_path):
    # the second run into the same output (the dialog's Run again, the file kept) failed:
    # "wrapped C/C++ object of type _Styler has been deleted" (QGIS deletes a post-processor
    # once it has run; the plugin reused it)
    import processing
    from qgis.core import QgsProject, QgsRuleBasedRenderer

    project = QgsProject.instance()
    project.clear()
    params = {
        "SCENE": str(SAMPLE_SCENE),
        "OSM": str(SAMPLE_OSM),
        "CANDIDATES": str(tmp_path / "out.gpkg"),
    }
    for _ in range(3):
        res = processing.runAndLoadResults("camloc:locate", params)
        assert res["N_CANDIDATES"] == 13
    assert any(lyr.source().startswith(str(tmp_path)) for lyr in project.mapLayers().values())
    fresh = QgsVectorLayer(res["CANDIDATES"], "fresh", "ogr")  # its default style, once more
    assert isinstance(fresh.renderer(), QgsRuleBasedRenderer)
    assert fresh.customProperty("camloc/kind") == "candidates"
    assert fresh.featureCount() == 13
    project.clear()


_LOCATE_OUTPUTS = ("CANDIDATES", "VIEW_CONES", "MATCHED_CORNERS", "INTERSECTION")


@pytest.mark.parametrize("ext", ["gpkg", "shp", "geojson"])
def test_run_and_load_into_named_files_styles_every_layer(provider, artifacts, ext):
    # runAndLoadResults (and the Toolbox dialog) into named files loaded only the last output
    # styled: each sink's parameterAsOutputLayer re-registered the earlier outputs to load,
    # dropping their post-processors: grey dots, no labels, the name without its camera
    import processing
    from qgis.core import QgsProject, QgsRuleBasedRenderer, QgsSettings

    project = QgsProject.instance()
    project.clear()
    params = {"SCENE": str(SAMPLE_SCENE), "OSM": str(SAMPLE_OSM)}
    # not under /tmp: QGIS takes a file there for a temporary layer and never names it after
    # the file, as it does the analyst's files
    tmp_path = artifacts / f"named_outputs_{ext}"
    shutil.rmtree(tmp_path, ignore_errors=True)
    tmp_path.mkdir()
    params.update({k: str(tmp_path / f"{k.lower()}.{ext}") for k in _LOCATE_OUTPUTS})
    # as on the desktop, where "Prefer output filename for layer names" is on by default: the
    # layers came up named 'candidates' (the file's name), whatever camera they were of
    settings = QgsSettings()
    key = "Processing/Configuration/PREFER_FILENAME_AS_LAYER_NAME"  # read by QGIS's C++
    before = settings.value(key)
    settings.setValue(key, True)
    try:
        res = processing.runAndLoadResults("camloc:locate", params)
    finally:
        settings.setValue(key, before) if before is not None else settings.remove(key)
    assert res["N_CANDIDATES"] == 13
    sid = json.loads(SAMPLE_SCENE.read_text())["id"]
    loaded = {lyr.customProperty("camloc/kind"): lyr for lyr in project.mapLayers().values()}
    assert set(loaded) == {"candidates", "view_cones", "matched_corners", "intersection"}
    for kind, lyr in loaded.items():
        assert lyr.source().startswith(str(tmp_path)), lyr.source()
        assert isinstance(lyr.renderer(), QgsRuleBasedRenderer), kind
        assert lyr.name().endswith(f"({sid})"), lyr.name()
    cands = loaded["candidates"]
    assert cands.featureCount() == 13
    assert cands.labelsEnabled()
    assert cands.renderer().rootRule().children()[0].filterExpression() == '"tie"'
    order = [n.layer().customProperty("camloc/kind") for n in project.layerTreeRoot().findLayers()]
    assert order.index("candidates") < order.index("view_cones"), order
    project.clear()


@pytest.mark.parametrize("size_px", [600, 800])
def test_the_intersection_keeps_its_streets_label_among_the_others(provider, tmp_path, size_px):
    # at the zoom the dock sets after a run (the candidates + 0.0006 degrees) the green
    # square's 'Eastern Avenue & South Broadway' lost to the corners' labels: not drawn
    from qgis.core import (
        QgsCoordinateReferenceSystem,
        QgsMapRendererSequentialJob,
        QgsMapSettings,
    )
    from qgis.PyQt.QtCore import QSize

    res = _locate(tmp_path)
    layers = [
        _layer(res[k]) for k in ("CANDIDATES", "MATCHED_CORNERS", "INTERSECTION", "VIEW_CONES")
    ]  # each with the default style stored in its GeoPackage
    settings = QgsMapSettings()
    settings.setLayers(layers)
    settings.setDestinationCrs(QgsCoordinateReferenceSystem("EPSG:4326"))
    extent = layers[0].extent()
    extent.grow(0.0006)
    settings.setExtent(extent)
    settings.setOutputSize(QSize(size_px, size_px))
    job = QgsMapRendererSequentialJob(settings)
    job.start()
    job.waitForFinished()
    texts = [lab.labelText for lab in job.takeLabelingResults().allLabels()]
    assert "Eastern Avenue & South Broadway" in texts, texts
    assert any(t.startswith("#1 ") for t in texts), texts


def _files_an_analyst_picks_by_mistake(tmp_path: Path) -> dict[str, tuple[Path, Path]]:
    """name: (scene, extract), one of them wrong."""
    broken = tmp_path / "broken.json"
    broken.write_text('{"format": "camloc-scene/1", "annotations": [')
    cut = tmp_path / "cut.osm.pbf"
    cut.write_bytes(SAMPLE_OSM.read_bytes()[:4000])
    notes = tmp_path / "notes.osm"
    notes.write_text("these are my notes, not OpenStreetMap\n")
    folder = tmp_path / "a folder.json"
    folder.mkdir()
    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)
    return {
        "broken.json": (broken, SAMPLE_OSM),
        "a folder.json": (folder, SAMPLE_OSM),
        "pipe.json": (fifo, SAMPLE_OSM),
        "missing.json": (tmp_path / "missing.json", SAMPLE_OSM),
        "cut.osm.pbf": (SAMPLE_SCENE, cut),
        "notes.osm": (SAMPLE_SCENE, notes),
        "the scene as extract": (SAMPLE_SCENE, SAMPLE_SCENE),
    }


class _ErrorsSaid(QgsProcessingFeedback):
    """The lines an algorithm reports as errors (the dialog's log shows them in red)."""

    def __init__(self) -> None:
        super().__init__()
        self.errors: list[str] = []

    def reportError(self, error: str, fatalError: bool = False) -> None:
        self.errors.append(error)


def test_a_wrong_file_is_one_processing_error_line_naming_it(provider, tmp_path):
    # the Toolbox dialog shows a QgsProcessingException's text in its log; any other exception
    # would be a Python traceback there. A FIFO must not block (the worker refuses it).
    import processing
    from test_dock import _Unblocker

    said = {}
    cases = _files_an_analyst_picks_by_mistake(tmp_path)
    with _Unblocker(cases["pipe.json"][0]) as unblocker:
        for name, (scene, osm) in cases.items():
            feedback = _ErrorsSaid()
            with pytest.raises(QgsProcessingException) as err:
                processing.run(
                    "camloc:locate",
                    {"SCENE": str(scene), "OSM": str(osm), "CANDIDATES": "TEMPORARY_OUTPUT"},
                    feedback=feedback,
                )
            text = " ".join([*feedback.errors, str(err.value)])
            said[name] = text
            assert "Traceback" not in text, (name, text)
            assert "camloc:" in text, (name, text)
            file_name = scene.name if osm == SAMPLE_OSM else osm.name
            assert file_name in text, (name, text)
    assert not unblocker.used  # nothing opened the FIFO
    assert len(said) == 7


@pytest.mark.parametrize(
    ("alg", "name", "value", "words"),
    [
        ("camloc:locate", "MAX_CANDIDATES", 0, "a whole number of at least 1; got 0"),
        ("camloc:locate", "MAX_CANDIDATES", "2.5", "a whole number of at least 1; got 2.5"),
        ("camloc:locate", "RADIUS_M", -5, "a number of at least 10; got -5"),
        ("camloc:corners", "RADIUS_M", "-5", "a number of at least 1; got -5"),
    ],
)
def test_a_number_out_of_range_names_the_parameter_and_its_range(
    provider, tmp_path, alg, name, value, words
):
    # QGIS's own check said only "Incorrect parameter value for MAX_CANDIDATES" (stop 41)
    import processing

    params = {
        "SCENE": str(SAMPLE_SCENE),
        "OSM": str(SAMPLE_OSM),
        "CANDIDATES": str(tmp_path / "c.gpkg"),
        "POINT": "-76.5935,39.2851 [EPSG:4326]",
        "CORNERS": str(tmp_path / "k.gpkg"),
        name: value,
    }
    with pytest.raises(QgsProcessingException) as err:
        processing.run(alg, params)
    assert f"camloc: {name} (" in str(err.value)
    assert words in str(err.value)


def test_numbers_in_range_pass_the_check(provider):
    from qgis.core import QgsApplication, QgsProcessingContext

    alg = QgsApplication.processingRegistry().createAlgorithmById("camloc:locate")
    context = QgsProcessingContext()
    base = {"SCENE": str(SAMPLE_SCENE), "OSM": str(SAMPLE_OSM), "CANDIDATES": "memory:"}
    ok, message = alg.checkParameterValues({**base, "MAX_CANDIDATES": 1, "RADIUS_M": 10}, context)
    assert ok, message
    ok, message = alg.checkParameterValues(base, context)
    assert ok, message
