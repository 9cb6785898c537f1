"""The plugin object: Processing provider, dock widget and menu entry, set up and torn down."""

from __future__ import annotations

import os
from typing import Any

from qgis.core import Qgis, QgsApplication
from qgis.PyQt.QtCore import Qt
from qgis.PyQt.QtGui import QIcon
from qgis.PyQt.QtWidgets import QAction

from . import runner
from .provider import CamlocProvider

ICON = os.path.join(os.path.dirname(__file__), "icon.png")
MENU = "&camloc"


class CamlocPlugin:
    """``initProcessing`` adds the provider; ``initGui`` adds the dock; ``unload`` undoes both."""

    def __init__(self, iface: Any) -> None:
        self.iface = iface  # None under qgis_process: touched only in initGui
        self.provider: CamlocProvider | None = None
        self.action: QAction | None = None
        self.dock: Any = None

    def initProcessing(self) -> None:
        if self.provider is None:
            self.provider = CamlocProvider()
            QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self) -> None:
        self.initProcessing()
        self.action = QAction(QIcon(ICON), "Locate a camera (camloc)…", self.iface.mainWindow())
        self.action.setCheckable(True)
        self.action.toggled.connect(self._toggle_dock)
        self.iface.addPluginToMenu(MENU, self.action)
        self.iface.addToolBarIcon(self.action)
        if runner.find_python() is None:
            self._warn_missing()

    def missing_dialog_text(self) -> str:
        """The whole install recipe, as the dialog behind the message bar shows it."""
        return runner.missing_message()

    def _warn_missing(self) -> None:
        """A one-line warning with a button opening the whole recipe (the bar cuts text)."""
        bar = self.iface.messageBar()
        text = "the camloc_geo library is missing: the plugin needs a Python that has it."
        try:
            from qgis.PyQt.QtWidgets import QPushButton

            widget = bar.createMessage("camloc", text)
            button = QPushButton("How to install…", widget)
            button.clicked.connect(self._show_missing)
            widget.layout().addWidget(button)
            bar.pushWidget(widget, Qgis.Warning)
        except (AttributeError, TypeError):  # a stub interface (tests)
            bar.pushMessage("camloc", text, level=Qgis.Warning, duration=0)

    def _show_missing(self) -> None:
        from qgis.PyQt.QtWidgets import QMessageBox

        box = QMessageBox(self.iface.mainWindow())
        box.setWindowTitle("camloc: install camloc_geo")
        box.setIcon(QMessageBox.Information)
        box.setText(self.missing_dialog_text())
        box.setTextInteractionFlags(Qt.TextSelectableByMouse)
        box.exec_()

    def _toggle_dock(self, on: bool) -> None:
        if on and self.dock is None:
            from .dock import CamlocDock

            self.dock = CamlocDock(self.iface, self.iface.mainWindow())
            self.iface.addDockWidget(Qt.RightDockWidgetArea, self.dock)
            self.dock.visibilityChanged.connect(self._dock_visibility)
        if self.dock is not None:
            self.dock.setVisible(on)

    def _dock_visibility(self, visible: bool) -> None:
        if self.action is not None and self.action.isChecked() != visible:
            self.action.setChecked(visible)

    def unload(self) -> None:
        if self.dock is not None:
            self.dock.shutdown()
            self.iface.removeDockWidget(self.dock)
            self.dock.deleteLater()
            self.dock = None
        if self.action is not None:
            self.iface.removePluginMenu(MENU, self.action)
            self.iface.removeToolBarIcon(self.action)
            self.action = None
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
