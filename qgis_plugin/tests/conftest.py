"""Fixtures for the plugin tests in real QGIS (pytest-qgis, headless)."""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
PLUGIN_ROOT = HERE.parent
REPO = PLUGIN_ROOT.parent
SAMPLE_SCENE = REPO / "sample_maps" / "sample_scene.json"
SAMPLE_TRUTH = REPO / "sample_maps" / "sample_scene.truth.json"
SAMPLE_OSM = REPO / "sample_maps" / "baltimore.osm.pbf"
ARTIFACTS = REPO / "tests" / "artifacts" / "qgis"

# The plugin package ``camloc`` lives in qgis_plugin/; the worker runs in this interpreter,
# which has camloc_geo (outside QGIS's process the wheels are fine).
if str(PLUGIN_ROOT) not in sys.path:
    sys.path.insert(0, str(PLUGIN_ROOT))
os.environ.setdefault("CAMLOC_PYTHON", sys.executable)


def metres_between(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Great-circle distance (m)."""
    p1, p2 = math.radians(lat1), math.radians(lat2)
    dp, dl = p2 - p1, math.radians(lon2 - lon1)
    a = math.sin(dp / 2) ** 2 + math.cos(p1) * math.cos(p2) * math.sin(dl / 2) ** 2
    return 2 * 6371008.8 * math.asin(math.sqrt(a))


def truth() -> dict:
    return json.loads(SAMPLE_TRUTH.read_text())


@pytest.fixture(scope="session")
def artifacts() -> Path:
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    return ARTIFACTS


@pytest.fixture
def provider(qgis_processing):
    """The camloc provider registered in the Processing registry."""
    from camloc.provider import CamlocProvider
    from qgis.core import QgsApplication

    reg = QgsApplication.processingRegistry()
    prov = reg.providerById("camloc")
    added = None
    if prov is None:
        added = CamlocProvider()
        assert reg.addProvider(added)
        prov = added
    yield prov
    if added is not None and reg.providerById("camloc") is not None:
        reg.removeProvider(reg.providerById("camloc"))


def chain_model(options: bool = True):
    """A model as the designer builds it: camloc:locate's candidates feed camloc:corners (its
    extent) and native:extractbyattribute (rank = 1); outputs ``locate:candidates``,
    ``corners:corners``, ``best:best``; inputs ``scene`` and ``osm``.

    ``options=False`` leaves camloc's options with a default (the yes/no ``NETWORK`` and
    ``CONTEXT``, corners' ``RADIUS_M``) unset, as a model written in Python or saved before an
    option existed does."""
    from qgis.core import (
        QgsProcessingModelAlgorithm,
        QgsProcessingModelChildAlgorithm,
        QgsProcessingModelChildParameterSource,
        QgsProcessingModelOutput,
        QgsProcessingModelParameter,
        QgsProcessingParameterFile,
    )

    src = QgsProcessingModelChildParameterSource
    model = QgsProcessingModelAlgorithm("camloc chain", "camloc tests")
    for name in ("scene", "osm"):
        model.addModelParameter(
            QgsProcessingParameterFile(name, name), QgsProcessingModelParameter(name)
        )

    def child(alg_id, child_id, sources, output, model_output):
        c = QgsProcessingModelChildAlgorithm(alg_id)
        c.setChildId(child_id)
        for param, source in sources.items():
            c.addParameterSources(param, [source])
        out = QgsProcessingModelOutput(model_output, model_output)
        out.setChildId(child_id)
        out.setChildOutputName(output)
        c.setModelOutputs({model_output: out})
        model.addChildAlgorithm(c)

    locate_options = {"NETWORK": src.fromStaticValue(False), "CONTEXT": src.fromStaticValue(False)}
    corners_options = {
        "RADIUS_M": src.fromStaticValue(150.0),
        "NETWORK": src.fromStaticValue(False),
    }
    child(
        "camloc:locate",
        "locate",
        {
            "SCENE": src.fromModelParameter("scene"),
            "OSM": src.fromModelParameter("osm"),
            **(locate_options if options else {}),
        },
        "CANDIDATES",
        "candidates",
    )
    child(
        "camloc:corners",
        "corners",
        {
            "EXTENT": src.fromChildOutput("locate", "CANDIDATES"),
            "OSM": src.fromModelParameter("osm"),
            **(corners_options if options else {}),
        },
        "CORNERS",
        "corners",
    )
    child(
        "native:extractbyattribute",
        "best",
        {
            "INPUT": src.fromChildOutput("locate", "CANDIDATES"),
            "FIELD": src.fromStaticValue("rank"),
            "OPERATOR": src.fromStaticValue(0),
            "VALUE": src.fromStaticValue("1"),
        },
        "OUTPUT",
        "best",
    )
    model.updateDestinationParameters()
    return model
