"""camloc's algorithms in Processing's batch dialog (one run per row) and in a model."""

from __future__ import annotations

import json

import pytest
from conftest import SAMPLE_OSM, SAMPLE_SCENE, chain_model
from qgis.core import QgsProject, QgsRuleBasedRenderer, QgsVectorLayer


def _scene_copy(tmp_path, scene_id: str):
    scene = json.loads(SAMPLE_SCENE.read_text())
    scene["id"] = scene_id
    if isinstance(scene.get("image"), str) and not scene["image"].startswith("/"):
        scene["image"] = str(SAMPLE_SCENE.parent / scene["image"])
    path = tmp_path / f"{scene_id}.json"
    path.write_text(json.dumps(scene))
    return path


def test_batch_rows_load_styled_layers_named_after_their_scene(provider, tmp_path):
    # what BatchAlgorithmDialog.runAlgorithm does (QGIS 3.22): one algorithm, a fresh context
    # per row, outputs per row, then handleAlgorithmResults with the row's parameters
    from processing.gui.Postprocessing import handleAlgorithmResults
    from processing.tools import dataobjects
    from qgis.core import (
        QgsApplication,
        QgsProcessingFeedback,
        QgsProcessingOutputLayerDefinition,
    )

    project = QgsProject.instance()
    project.clear()
    alg = QgsApplication.processingRegistry().createAlgorithmById("camloc:locate")
    rows = [SAMPLE_SCENE, _scene_copy(tmp_path, "second-camera")]
    ids = [json.loads(p.read_text())["id"] for p in rows]
    feedback = QgsProcessingFeedback()
    for i, scene in enumerate(rows):
        params = {"SCENE": str(scene), "OSM": str(SAMPLE_OSM)}
        for out in ("CANDIDATES", "VIEW_CONES"):
            dest = str(tmp_path / f"row{i}_{out.lower()}.gpkg")
            params[out] = QgsProcessingOutputLayerDefinition(dest, project)
        # the batch panel's cells left empty: an output definition with an empty destination
        # (BatchPanel.parametersForRow); each row failed "Could not create destination layer
        # for MATCHED_CORNERS: invalid value"
        for out in ("MATCHED_CORNERS", "INTERSECTION", "CONTEXT_STREETS", "CONTEXT_BUILDINGS"):
            params[out] = QgsProcessingOutputLayerDefinition("", project)
        params = alg.preprocessParameters(params)
        context = dataobjects.createContext(feedback)
        results, ok = alg.run(params, context, feedback)
        assert ok, results
        assert results["N_CANDIDATES"] == 13
        assert "MATCHED_CORNERS" not in results
        assert handleAlgorithmResults(alg, context, feedback, False, params)
    layers = {lyr.name(): lyr for lyr in project.mapLayers().values()}
    assert sorted(layers) == sorted(
        f"{what} ({sid})" for sid in ids for what in ("Camera candidates", "View cones")
    )
    for i, sid in enumerate(ids):
        cands = layers[f"Camera candidates ({sid})"]
        assert cands.source().startswith(str(tmp_path / f"row{i}_candidates.gpkg"))
        assert cands.featureCount() == 13
        assert {f["scene"] for f in cands.getFeatures()} == {sid}
        assert isinstance(cands.renderer(), QgsRuleBasedRenderer)
        assert cands.labelsEnabled()
        cones = layers[f"View cones ({sid})"]
        assert cones.customProperty("camloc/kind") == "view_cones"
        assert isinstance(cones.renderer(), QgsRuleBasedRenderer)
    project.clear()


def test_model_locate_feeds_corners_and_a_native_filter(provider, tmp_path):
    import processing

    model = chain_model()
    res = processing.run(
        model,
        {
            "scene": str(SAMPLE_SCENE),
            "osm": str(SAMPLE_OSM),
            "locate:candidates": str(tmp_path / "candidates.gpkg"),
            "corners:corners": str(tmp_path / "corners.gpkg"),
            "best:best": str(tmp_path / "best.gpkg"),
        },
    )
    cands = QgsVectorLayer(res["locate:candidates"], "c", "ogr")
    assert cands.featureCount() == 13
    # the GeoPackage a child wrote carries camloc's default style
    assert isinstance(cands.renderer(), QgsRuleBasedRenderer)
    best = list(QgsVectorLayer(res["best:best"], "b", "ogr").getFeatures())
    first = [f for f in cands.getFeatures() if f["rank"] == 1]
    assert len(best) == 1
    assert len(first) == 1
    assert best[0]["lat"] == first[0]["lat"]
    assert best[0]["lon"] == first[0]["lon"]
    corners = QgsVectorLayer(res["corners:corners"], "k", "ogr")
    kinds = [f["kind"] for f in corners.getFeatures()]
    assert kinds.count("intersection") >= 1
    streets = " ".join(str(f["streets"]) for f in corners.getFeatures())
    assert "Eastern Avenue" in streets
    assert "South Broadway" in streets
    assert isinstance(corners.renderer(), QgsRuleBasedRenderer)


def test_model_outputs_loaded_keep_the_model_names_and_camloc_styles(provider, tmp_path):
    # a model's output is named by its author ('candidates'): the styler named it
    # 'Camera candidates (scene)' over it; it still styles it
    import processing

    project = QgsProject.instance()
    project.clear()
    processing.runAndLoadResults(
        chain_model(),
        {
            "scene": str(SAMPLE_SCENE),
            "osm": str(SAMPLE_OSM),
            "locate:candidates": "TEMPORARY_OUTPUT",
            "corners:corners": str(tmp_path / "corners.gpkg"),
            "best:best": "TEMPORARY_OUTPUT",
        },
    )
    layers = {lyr.name(): lyr for lyr in project.mapLayers().values()}
    assert sorted(layers) == ["best", "candidates", "corners"]
    assert layers["candidates"].customProperty("camloc/kind") == "candidates"
    assert isinstance(layers["candidates"].renderer(), QgsRuleBasedRenderer)
    assert layers["candidates"].featureCount() == 13
    assert layers["corners"].customProperty("camloc/kind") == "corners"
    assert layers["best"].featureCount() == 1
    project.clear()


def test_model_with_camloc_options_left_unset_validates_and_runs(provider, tmp_path):
    # QGIS 3.22 refused such a model: "Parameter NETWORK is mandatory", "Parameter CONTEXT is
    # mandatory" (every non-optional parameter without a source, whatever its default)
    import processing

    model = chain_model(options=False)
    assert model.validate() == (True, [])
    for child in ("locate", "corners"):
        assert model.validateChildAlgorithm(child) == (True, [])
    res = processing.run(
        model,
        {
            "scene": str(SAMPLE_SCENE),
            "osm": str(SAMPLE_OSM),
            "locate:candidates": str(tmp_path / "candidates.gpkg"),
            "corners:corners": str(tmp_path / "corners.gpkg"),
            "best:best": str(tmp_path / "best.gpkg"),
        },
    )
    assert QgsVectorLayer(res["locate:candidates"], "c", "ogr").featureCount() == 13
    assert QgsVectorLayer(res["best:best"], "b", "ogr").featureCount() == 1
    corners = QgsVectorLayer(res["corners:corners"], "k", "ogr")
    assert [f["kind"] for f in corners.getFeatures()].count("intersection") >= 1


def test_unset_options_read_as_their_defaults(provider):
    from qgis.core import QgsProcessingContext, QgsProcessingParameterDefinition

    context = QgsProcessingContext()
    for alg in provider.algorithms():
        for name, default in (("NETWORK", False), ("CONTEXT", False), ("RADIUS_M", 150.0)):
            param = alg.parameterDefinition(name)
            if param is None or param.defaultValue() is None:
                continue
            assert param.flags() & QgsProcessingParameterDefinition.FlagOptional, (alg.id(), name)
            assert param.defaultValue() == default
            if param.type() == "boolean":
                assert alg.parameterAsBool({}, name, context) is False
            else:
                assert alg.parameterAsDouble({}, name, context) == default


@pytest.mark.parametrize("alg_id", ["camloc:locate", "camloc:corners", "camloc:geocodelist"])
def test_the_designers_child_dialog_left_as_it_opens_gives_a_valid_child(
    provider, qgis_iface, alg_id
):
    # the graphical modeler's path: add the algorithm, set only its required input, press OK
    from processing.modeler.ModelerParametersDialog import ModelerParametersDialog
    from qgis.core import (
        QgsApplication,
        QgsProcessingModelAlgorithm,
        QgsProcessingModelChildParameterSource,
        QgsProcessingModelParameter,
        QgsProcessingParameterFile,
    )

    model = QgsProcessingModelAlgorithm("designer", "camloc tests")
    model.addModelParameter(
        QgsProcessingParameterFile("input", "input"), QgsProcessingModelParameter("input")
    )
    alg = QgsApplication.processingRegistry().algorithmById(alg_id)
    dlg = ModelerParametersDialog(alg, model)
    wrappers = dlg.widget.widget.wrappers
    required = {"camloc:locate": "SCENE", "camloc:geocodelist": "LIST"}.get(alg_id)
    if required:
        wrappers[required].setWidgetValue(
            QgsProcessingModelChildParameterSource.fromModelParameter("input")
        )
    child = dlg.createAlgorithm()
    model.addChildAlgorithm(child)
    assert model.validateChildAlgorithm(child.childId()) == (True, [])
    dlg.deleteLater()
