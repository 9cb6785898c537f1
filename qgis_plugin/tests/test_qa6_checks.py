"""Stop 42 qa6: what a GIS analyst met through ``qgis_process`` / ``processing.run``, each
refused before any work with a message naming the parameter (each test fails without its fix)."""

from __future__ import annotations

import pytest
from conftest import SAMPLE_OSM, SAMPLE_SCENE
from qgis.core import QgsProcessingException


def test_a_folder_given_for_one_extract_is_named(provider, tmp_path):
    # "Incorrect parameter value for OSM": a folder of extracts, as camloc:geocodelist and
    # camloc locate --osm take it, given to camloc:locate and camloc:corners
    import processing

    for alg, extra in (
        ("camloc:locate", {"SCENE": str(SAMPLE_SCENE), "CANDIDATES": str(tmp_path / "c.gpkg")}),
        (
            "camloc:corners",
            {"POINT": "-76.5935,39.2851 [EPSG:4326]", "CORNERS": str(tmp_path / "k.gpkg")},
        ),
    ):
        with pytest.raises(QgsProcessingException) as err:
            processing.run(alg, {"OSM": str(SAMPLE_OSM.parent), **extra})
        text = str(err.value)
        label = "camloc: OSM (OSM extract (empty: Overpass if allowed))"
        assert f"{label} is a folder, {SAMPLE_OSM.parent}" in text
        assert "camloc:geocodelist and camloc batch take a folder" in text
        assert not (tmp_path / "c.gpkg").exists()


def test_a_scene_that_is_a_folder_is_named(provider, tmp_path):
    import processing

    params = {
        "SCENE": str(tmp_path),
        "OSM": str(SAMPLE_OSM),
        "CANDIDATES": str(tmp_path / "c.gpkg"),
    }
    with pytest.raises(QgsProcessingException) as err:
        processing.run("camloc:locate", params)
    assert f"camloc: SCENE (Scene file (camloc-scene/1 JSON)) is a folder, {tmp_path}" in str(
        err.value
    )


@pytest.mark.parametrize("name", ["CANDIDATES", "VIEW_CONES"])
def test_an_output_in_a_missing_folder_is_refused_before_the_work(provider, tmp_path, name):
    # QGIS refused it only after the whole computation: "Could not create layer
    # /nonexistent/dir/q5.gpkg: Creation of data source failed (... unable to open database
    # file)"
    import processing

    params = {
        "SCENE": str(SAMPLE_SCENE),
        "OSM": str(SAMPLE_OSM),
        "CANDIDATES": str(tmp_path / "c.gpkg"),
        name: str(tmp_path / "nope" / "out.gpkg"),
    }
    with pytest.raises(QgsProcessingException) as err:
        processing.run("camloc:locate", params)
    text = str(err.value)
    assert f"camloc: {name} (" in text
    assert f"the folder {tmp_path / 'nope'} does not exist" in text
    assert "Creation of data source failed" not in text


def test_camloc_layers_alone_get_their_places_utm_zone(provider, tmp_path):
    # The layers are EPSG:4326 and an empty project took the first layer's CRS: a plate carree
    # drawing Helsinki (60 N) twice as wide as tall, a cone facing 45 degrees drawn at 63
    import processing
    from qgis.core import QgsProject, QgsVectorLayer

    project = QgsProject.instance()
    project.clear()
    params = {"SCENE": str(SAMPLE_SCENE), "OSM": str(SAMPLE_OSM), "CANDIDATES": "TEMPORARY_OUTPUT"}
    processing.runAndLoadResults("camloc:locate", params)
    assert project.crs().authid() == "EPSG:32618"  # Baltimore, -76.6 E: UTM zone 18 N
    project.clear()
    # a project with the analyst's own layer keeps its CRS
    own = QgsVectorLayer("Point?crs=EPSG:4326", "my cameras", "memory")
    project.addMapLayer(own)
    project.setCrs(own.crs())
    processing.runAndLoadResults("camloc:locate", params)
    assert project.crs().authid() == "EPSG:4326"
    project.clear()
