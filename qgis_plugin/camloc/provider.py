"""The ``camloc`` Processing provider."""

from __future__ import annotations

import os

from qgis.core import QgsMessageLog, QgsProcessingProvider
from qgis.PyQt.QtGui import QIcon

from . import runner
from .algorithms import CornersAlgorithm, GeocodeListAlgorithm, LocateAlgorithm, MeasureAlgorithm

ICON = os.path.join(os.path.dirname(__file__), "icon.png")


class CamlocProvider(QgsProcessingProvider):
    """Provider ``camloc``: locate, corners, geocodelist (measure with camloc_geo.sensors)."""

    def __init__(self) -> None:
        super().__init__()
        self.capabilities: dict = {}

    def id(self) -> str:
        return "camloc"

    def name(self) -> str:
        return "camloc"

    def longName(self) -> str:
        return "camloc: where a street camera stands"

    def icon(self) -> QIcon:
        return QIcon(ICON)

    def loadAlgorithms(self) -> None:
        self.addAlgorithm(LocateAlgorithm())
        self.addAlgorithm(CornersAlgorithm())
        self.addAlgorithm(GeocodeListAlgorithm())
        self.capabilities = runner.probe()
        if not self.capabilities:
            QgsMessageLog.logMessage(runner.missing_message(), "camloc")
        elif self.capabilities.get("sensors"):
            self.addAlgorithm(MeasureAlgorithm())
        else:
            QgsMessageLog.logMessage(
                "camloc:measure is not available: the installed camloc_geo has no virtual "
                "sensors (camloc_geo.sensors)",
                "camloc",
            )
