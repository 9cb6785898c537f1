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
