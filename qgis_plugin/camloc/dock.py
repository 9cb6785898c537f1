"""The analyst's dock: annotate a snapshot, pick the intersection, run, save the scene."""

from __future__ import annotations

import json
import os
import tempfile
from typing import Any

from qgis.core import (
    QgsCoordinateTransform,
    QgsProject,
    QgsVectorLayer,
)
from qgis.gui import QgsMapToolEmitPoint
from qgis.PyQt.QtCore import QPointF, QRectF, Qt, pyqtSignal
from qgis.PyQt.QtGui import QBrush, QColor, QPainter, QPen, QPixmap
from qgis.PyQt.QtWidgets import (
    QApplication,
    QDockWidget,
    QFileDialog,
    QGraphicsScene,
    QGraphicsView,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListWidget,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from .annotation import STEPS, Annotation
from .layers import apply_style, wgs84
from .runner import WorkerError, run_worker

AXIS_COLOURS = {
    "origin": "#ffffff",
    "length": "#e41a1c",
    "width": "#377eb8",
    "height": "#4daf4a",
    "corners": "#ff7f00",
}


class ImageView(QGraphicsView):
    """The snapshot; emits image pixel coordinates of left clicks."""

    clicked = pyqtSignal(float, float)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setScene(QGraphicsScene(self))
        self.setRenderHint(QPainter.Antialiasing)
        self.setMinimumHeight(220)
        self._pixmap_item = None

    def set_pixmap(self, pixmap: QPixmap) -> None:
        self.scene().clear()
        self._pixmap_item = self.scene().addPixmap(pixmap)
        self.scene().setSceneRect(QRectF(pixmap.rect()))
        self.fit()

    def fit(self) -> None:
        if self._pixmap_item is not None:
            self.fitInView(self.scene().sceneRect(), Qt.KeepAspectRatio)

    def resizeEvent(self, event):
        super().resizeEvent(event)
        self.fit()

    def mousePressEvent(self, event):
        if event.button() == Qt.LeftButton and self._pixmap_item is not None:
            p = self.mapToScene(event.pos())
            self.clicked.emit(p.x(), p.y())
        super().mousePressEvent(event)


class CamlocDock(QDockWidget):
    """Annotate a snapshot for camloc and locate the camera."""

    def __init__(self, iface: Any = None, parent: QWidget | None = None) -> None:
        super().__init__("camloc: locate a camera", parent)
        self.setObjectName("CamlocDock")
        self.iface = iface
        self.annotation = Annotation()
        self.overlays: list[Any] = []
        self.result_layers: list[QgsVectorLayer] = []
        self.map_tool: QgsMapToolEmitPoint | None = None
        self._previous_tool = None

        body = QWidget(self)
        lay = QVBoxLayout(body)
        row = QHBoxLayout()
        self.open_button = QPushButton("Open snapshot…")
        self.open_button.clicked.connect(self._open_dialog)
        self.undo_button = QPushButton("Undo")
        self.undo_button.clicked.connect(self.undo)
        row.addWidget(self.open_button)
        row.addWidget(self.undo_button)
        lay.addLayout(row)
        self.steps = QListWidget()
        for _key, label, _kind in STEPS:
            self.steps.addItem(label)
        self.steps.setFixedHeight(self.steps.sizeHintForRow(0) * len(STEPS) + 8)
        self.steps.currentRowChanged.connect(self._step_changed)
        lay.addWidget(self.steps)
        self.view = ImageView()
        self.view.clicked.connect(self.image_clicked)
        lay.addWidget(self.view, 1)
        row2 = QHBoxLayout()
        self.pick_button = QPushButton("Pick intersection on map")
        self.pick_button.setCheckable(True)
        self.pick_button.toggled.connect(self._pick_toggled)
        self.streets_edit = QLineEdit()
        self.streets_edit.setPlaceholderText("streets (optional): A & B")
        row2.addWidget(self.pick_button)
        row2.addWidget(self.streets_edit)
        lay.addLayout(row2)
        row3 = QHBoxLayout()
        self.osm_edit = QLineEdit()
        self.osm_edit.setPlaceholderText("OSM extract (empty: Overpass)")
        osm_button = QPushButton("…")
        osm_button.setMaximumWidth(30)
        osm_button.clicked.connect(self._osm_dialog)
        row3.addWidget(self.osm_edit)
        row3.addWidget(osm_button)
        lay.addLayout(row3)
        row4 = QHBoxLayout()
        self.run_button = QPushButton("Run")
        self.run_button.clicked.connect(self.run)
        self.save_button = QPushButton("Save scene…")
        self.save_button.clicked.connect(self._save_dialog)
        row4.addWidget(self.run_button)
        row4.addWidget(self.save_button)
        lay.addLayout(row4)
        self.status = QLabel("Open a snapshot to start.")
        self.status.setWordWrap(True)
        lay.addWidget(self.status)
        self.setWidget(body)
        self.steps.setCurrentRow(0)

    # --- snapshot and clicks ---------------------------------------------------------------
    def _open_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(
            self, "Open snapshot", "", "Images (*.png *.jpg *.jpeg *.bmp *.tif);;All files (*.*)"
        )
        if path:
            self.open_snapshot(path)

    def open_snapshot(self, path: str) -> bool:
        """Show the image and start a new annotation for it."""
        pix = QPixmap(path)
        if pix.isNull():
            self.set_status(f"cannot read the image {path}")
            return False
        scene_id = os.path.splitext(os.path.basename(path))[0]
        self.annotation = Annotation(pix.width(), pix.height(), scene_id=scene_id)
        self.annotation.image_path = os.path.basename(path)
        self.view.set_pixmap(pix)
        self.steps.setCurrentRow(0)
        self.redraw()
        self.set_status(f"{pix.width()}×{pix.height()} px. {STEPS[0][1]}")
        return True

    def _step_changed(self, row: int) -> None:
        if 0 <= row < len(STEPS):
            self.annotation.set_step(STEPS[row][0])
            self.redraw()

    def set_step(self, key: str) -> None:
        """Select a step by key (``origin``, ``lines_length``, ``corners``...)."""
        self.steps.setCurrentRow([s[0] for s in STEPS].index(key))

    def image_clicked(self, x: float, y: float) -> None:
        """A click on the snapshot at image pixel ``(x, y)``."""
        what = self.annotation.click(x, y)
        row = [s[0] for s in STEPS].index(self.annotation.step)
        if row != self.steps.currentRow():
            self.steps.blockSignals(True)
            self.steps.setCurrentRow(row)
            self.steps.blockSignals(False)
        self.redraw()
        self.set_status(f"{what} at ({x:.1f}, {y:.1f}). {STEPS[row][1]}")

    def undo(self) -> None:
        self.annotation.undo()
        self.steps.blockSignals(True)
        self.steps.setCurrentRow([s[0] for s in STEPS].index(self.annotation.step))
        self.steps.blockSignals(False)
        self.redraw()

    def _update_step_labels(self) -> None:
        a = self.annotation
        for row, (key, label, kind) in enumerate(STEPS):
            if kind == "point":
                extra = "  ✓" if key in a.axes else ""
            elif kind == "line":
                n = len(a.lines[key.split("_", 1)[1]])
                extra = f"  ({n})" if n else ""
            else:
                extra = f"  ({len(a.corners)})" if a.corners else ""
            self.steps.item(row).setText(label + extra)

    def redraw(self) -> None:
        """Draw the annotation over the image."""
        self._update_step_labels()
        sc = self.view.scene()
        for item in self.overlays:
            sc.removeItem(item)
        self.overlays = []
        a = self.annotation
        width = max(2.0, a.width / 600.0)
        r = width * 3

        def pen(colour: str) -> QPen:
            p = QPen(QColor(colour))
            p.setWidthF(width)
            return p

        if "origin" in a.axes:
            ox, oy = a.axes["origin"]
            for axis in ("length", "width", "height"):
                if axis in a.axes:
                    x, y = a.axes[axis]
                    self.overlays.append(sc.addLine(ox, oy, x, y, pen(AXIS_COLOURS[axis])))
        for key, (x, y) in a.axes.items():
            self.overlays.append(
                sc.addEllipse(
                    x - r, y - r, 2 * r, 2 * r, pen("#000000"), QBrush(QColor(AXIS_COLOURS[key]))
                )
            )
        for axis, segs in a.lines.items():
            p = pen(AXIS_COLOURS[axis])
            p.setStyle(Qt.DashLine)
            for x1, y1, x2, y2 in segs:
                self.overlays.append(sc.addLine(x1, y1, x2, y2, p))
        if a.pending is not None:
            x, y = a.pending
            self.overlays.append(sc.addEllipse(x - r, y - r, 2 * r, 2 * r, pen("#ffff00")))
        for i, (x, y) in enumerate(a.corners):
            self.overlays.append(
                sc.addEllipse(
                    x - 1.5 * r,
                    y - 1.5 * r,
                    3 * r,
                    3 * r,
                    pen("#000000"),
                    QBrush(QColor(AXIS_COLOURS["corners"])),
                )
            )
            t = sc.addSimpleText(str(i))
            t.setBrush(QBrush(QColor("#ffffff")))
            t.setScale(max(1.0, a.width / 400.0))
            t.setPos(QPointF(x + 2 * r, y - 4 * r))
            self.overlays.append(t)

    # --- map pick --------------------------------------------------------------------------
    def _pick_toggled(self, on: bool) -> None:
        if self.iface is None:
            return
        canvas = self.iface.mapCanvas()
        if on:
            self._previous_tool = canvas.mapTool()
            self.map_tool = QgsMapToolEmitPoint(canvas)
            self.map_tool.canvasClicked.connect(self._canvas_clicked)
            canvas.setMapTool(self.map_tool)
            self.set_status("Click the intersection on the map.")
        elif self.map_tool is not None:
            canvas.unsetMapTool(self.map_tool)
            if self._previous_tool is not None:
                canvas.setMapTool(self._previous_tool)
            self.map_tool = None

    def _canvas_clicked(self, point: Any, button: Any = None) -> None:
        crs = self.iface.mapCanvas().mapSettings().destinationCrs() if self.iface else None
        self.pick_location(point, crs)
        self.pick_button.setChecked(False)

    def pick_location(self, point: Any, crs: Any = None) -> tuple[float, float]:
        """Set the intersection from a map point in ``crs`` (default: the project's CRS)."""
        crs = crs or QgsProject.instance().crs()
        xform = QgsCoordinateTransform(crs, wgs84(), QgsProject.instance())
        p = xform.transform(point)
        self.annotation.set_location(lat=p.y(), lon=p.x())
        self.set_status(f"intersection at {p.y():.6f}, {p.x():.6f}")
        return p.y(), p.x()

    # --- scene, run, save ------------------------------------------------------------------
    def scene(self) -> dict[str, Any]:
        """The current scene dict (streets from the text box)."""
        text = self.streets_edit.text().strip()
        self.annotation.streets = [
            s.strip() for s in text.replace("/", "&").split("&") if s.strip()
        ]
        return self.annotation.to_scene()

    def save_scene(self, path: str) -> bool:
        """Validate the scene with the library and write it; False (status says why) if invalid."""
        try:
            run_worker({"task": "check_scene", "scene": self.scene(), "save_to": path})
        except WorkerError as exc:
            self.set_status(f"not saved: {exc}")
            return False
        self.set_status(f"saved {path}")
        return True

    def _save_dialog(self) -> None:
        path, _ = QFileDialog.getSaveFileName(
            self, "Save scene", f"{self.annotation.scene_id}.json", "camloc scenes (*.json)"
        )
        if path:
            self.save_scene(path)

    def _osm_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(
            self, "OSM extract", "", "OSM extracts (*.osm *.pbf *.bz2 *.gz);;All files (*.*)"
        )
        if path:
            self.osm_edit.setText(path)

    def run(self) -> list[QgsVectorLayer]:
        """Locate the camera (``camloc:locate``) and add the candidate layers to the project."""
        problems = self.annotation.problems()
        if problems:
            self.set_status("Not ready: " + "; ".join(problems))
            return []
        import processing

        folder = tempfile.mkdtemp(prefix="camloc_dock_")
        scene_path = os.path.join(folder, f"{self.annotation.scene_id}.json")
        with open(scene_path, "w", encoding="utf-8") as fh:
            json.dump(self.scene(), fh, indent=1)
        outputs = {
            "CANDIDATES": os.path.join(folder, "candidates.gpkg"),
            "VIEW_CONES": os.path.join(folder, "view_cones.gpkg"),
            "MATCHED_CORNERS": os.path.join(folder, "matched_corners.gpkg"),
            "INTERSECTION": os.path.join(folder, "intersection.gpkg"),
        }
        params = {
            "SCENE": scene_path,
            "OSM": self.osm_edit.text().strip() or None,
            "NETWORK": not self.osm_edit.text().strip(),
            **outputs,
        }
        QApplication.setOverrideCursor(Qt.WaitCursor)
        try:
            res = processing.run("camloc:locate", params)
        except Exception as exc:  # QgsProcessingException: the library's message
            self.set_status(str(exc).strip().splitlines()[0] if str(exc).strip() else repr(exc))
            return []
        finally:
            QApplication.restoreOverrideCursor()
        project = QgsProject.instance()
        for old in self.result_layers:
            if project.mapLayer(old.id()) is not None:
                project.removeMapLayer(old.id())
        self.result_layers = []
        for key, kind, title in (
            ("VIEW_CONES", "view_cones", "camloc view cones"),
            ("INTERSECTION", "intersection", "camloc intersection"),
            ("MATCHED_CORNERS", "matched_corners", "camloc matched corners"),
            ("CANDIDATES", "candidates", "camloc candidates"),
        ):
            if key not in res:
                continue
            layer = QgsVectorLayer(res[key], title, "ogr")
            if not layer.isValid():
                continue
            apply_style(layer, kind)
            project.addMapLayer(layer)
            self.result_layers.append(layer)
        n = self.result_layers[-1].featureCount() if self.result_layers else 0
        self.set_status(f"{n} candidate(s); best first, ties drawn as stars.")
        if self.iface is not None and self.result_layers:
            canvas = self.iface.mapCanvas()
            xform = QgsCoordinateTransform(wgs84(), canvas.mapSettings().destinationCrs(), project)
            ext = xform.transformBoundingBox(self.result_layers[-1].extent())
            ext.scale(2.0)
            canvas.setExtent(ext)
            canvas.refresh()
        return self.result_layers

    def set_status(self, text: str) -> None:
        self.status.setText(text)

    def closeEvent(self, event):
        self.pick_button.setChecked(False)
        super().closeEvent(event)
