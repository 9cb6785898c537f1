"""The analyst's dock: annotate a snapshot, pick the intersection, run in the background.

Two ways to annotate, one scene:

- **In the browser** (recommended): *Annotate in browser…* opens the library's annotation page
  (``camloc_geo.web``, the page of ``camloc annotate``: zoom, pan, undo, moving points, guided
  steps, live focal length) served from QGIS; its *Submit* hands the scene back to the dock.
- **In the dock**: the same steps, clicked on the snapshot here (wheel zooms, right or middle
  drag pans, *1:1* shows full resolution).

Preset, search radius and viewing direction are set here for either. *Run* locates the camera
in a QgsTask (progress, *Cancel*; the GUI stays responsive) and writes the layers into a
GeoPackage the analyst picks (default: ``camloc_results.gpkg`` beside the project).
"""

from __future__ import annotations

import json
import os
import traceback
from typing import Any

from qgis.core import (
    Qgis,
    QgsApplication,
    QgsCoordinateTransform,
    QgsExpression,
    QgsMessageLog,
    QgsProject,
    QgsTask,
    QgsVectorLayer,
)
from qgis.gui import QgsMapToolEmitPoint
from qgis.PyQt.QtCore import QObject, QPointF, QRectF, Qt, QUrl, pyqtSignal
from qgis.PyQt.QtGui import QBrush, QColor, QDesktopServices, QPainter, QPen, QPixmap
from qgis.PyQt.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDockWidget,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QGraphicsItem,
    QGraphicsScene,
    QGraphicsView,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListWidget,
    QProgressBar,
    QPushButton,
    QScrollArea,
    QSizePolicy,
    QVBoxLayout,
    QWidget,
)

from .annotation import GUIDANCE, STEPS, Annotation
from .imagefile import SnapshotError, check_regular_file, read_snapshot
from .layers import (
    DRAW_ORDER,
    apply_style,
    extent_with_room,
    label_room_px,
    style_qml,
    use_local_crs,
    wgs84,
    write_gpkg_layer,
    write_gpkg_styles,
)
from .runner import WorkerCanceledError, WorkerError, run_worker

AXIS_COLOURS = {
    "origin": "#ffffff",
    "length": "#e41a1c",
    "width": "#377eb8",
    "height": "#4daf4a",
    "corners": "#ff7f00",
}
PRESETS = ["sedan", "bus", "hatchback", "minivan", "pickup", "suv", "taxi_ny", "van"]
"""The library's object presets (``camloc_geo.objects.PRESETS``; the worker's probe wins)."""
LAYER_TITLES = {
    "candidates": "Camera candidates",
    "matched_corners": "Matched map points",
    "intersection": "Intersection and kerb corners",
    "view_cones": "View cones (leading candidates)",
    "context_buildings": "Map model: buildings",
    "context_streets": "Map model: streets",
}
"""The dock's names for its result layers, capitalised as the Processing outputs' names (the
dock's 'camera candidates' sat beside the Toolbox's 'Camera candidates (...)')."""
RESULTS_NAME = "camloc_results.gpkg"
MARKER_PX = 6.0
"""Click markers' radius on screen (pixels, at any zoom)."""


MAX_SCENE_BYTES = 10_000_000
"""Largest scene file loaded (bytes): ``camloc_geo._limits.MAX_SCENE_BYTES``, copied because the
plugin does not import camloc_geo (keep the two equal)."""


STALE_PROPERTY = "camloc/stale"
"""Custom property of a result group and its layers left from a run before one that failed."""
STALE_PREFIX = "stale · "
"""What a stale layer's name starts with."""
STALE_OPACITY = 0.35
"""A stale layer's opacity (drawn faded under the analyst's next results)."""


def stale_name(group: str) -> str:
    """The name of result group ``group`` once a later run of its camera failed."""
    suffix = " (stale: a later run failed)"
    return group if group.endswith(suffix) else group + suffix


def _mark_labels_stale(layer: Any) -> None:
    """A stale layer's labels say so and are drawn faded.

    A layer's opacity does not reach its labels: the stale candidates' '#1 0.37 (tie with
    #2, #4)' stood on the map as a fresh run's (seen in the desktop under Xvfb, session 41).
    Each label starts with :data:`STALE_PREFIX` (a feature without a label keeps none) and
    its text takes :data:`STALE_OPACITY`.
    """
    from qgis.core import QgsPalLayerSettings, QgsVectorLayerSimpleLabeling

    if not isinstance(layer, QgsVectorLayer) or not layer.labelsEnabled():
        return
    labeling = layer.labeling()
    if not isinstance(labeling, QgsVectorLayerSimpleLabeling):
        return
    pal = QgsPalLayerSettings(labeling.settings())
    text = pal.fieldName if pal.isExpression else QgsExpression.quotedColumnRef(pal.fieldName)
    if not text:
        return
    # '||' keeps a NULL label NULL (concat() would label every feature 'stale · ')
    pal.fieldName = f"'{STALE_PREFIX}' || ({text})"
    pal.isExpression = True
    fmt = pal.format()
    fmt.setOpacity(STALE_OPACITY)
    pal.setFormat(fmt)
    layer.setLabeling(QgsVectorLayerSimpleLabeling(pal))


def _sentence(text: str) -> str:
    """``text`` ended as a sentence (a full stop added where it ends without one)."""
    text = text.rstrip()
    return text if not text or text[-1] in ".!?" else text + "."


def _output_problem(path: str, what: str) -> str | None:
    """Why ``path`` cannot be written as a ``what`` (one line), or None.

    An existing FIFO, device or folder is refused before anything opens it (writing to a FIFO
    blocks until someone reads it).
    """
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        return f"cannot write the {what} {path}: its folder is missing or not writable"
    if os.path.lexists(path):
        problem = check_regular_file(path, what)
        if problem:
            return problem
        if not os.access(path, os.W_OK):
            return f"cannot write the {what} {path}: the file is read-only"
    return None


def _path_from(target: str, folder: str) -> str:
    """``target`` as a scene file in ``folder`` names it: relative when it can be, with ``/``."""
    target = os.path.abspath(target)
    try:
        rel = os.path.relpath(target, os.path.abspath(folder or "."))
    except ValueError:  # another drive (Windows): only an absolute path reaches it
        return target
    return rel.replace(os.sep, "/")


def _same_file(a: str | None, b: str | None) -> bool:
    """Whether two paths name one file (either may not exist yet)."""
    if not a or not b:
        return False
    try:
        if os.path.exists(a) and os.path.exists(b):
            return os.path.samefile(a, b)
    except OSError:
        return False
    return os.path.abspath(a) == os.path.abspath(b)


def _extract_problem(osm: str) -> str | None:
    """Why ``osm`` is not an OSM extract or a folder of extracts (one line), or None."""
    if os.path.isdir(osm):
        return None
    problem = check_regular_file(osm, "OSM extract")
    if problem:
        return problem
    if os.path.getsize(osm) == 0:
        return f"the OSM extract {osm} is empty (0 bytes)"
    return None


def _json_text(raw: bytes) -> str:
    """A scene file's text: UTF-8, a byte-order mark dropped (Notepad and PowerShell write
    one: it was "Expecting value: line 1 column 1"), or UTF-16 with its mark; as the
    library's ``camloc_geo._io.json_text`` reads it (the plugin does not import the library).
    A file that is no text raises ``ValueError`` saying so."""
    import codecs

    try:
        if raw.startswith(codecs.BOM_UTF8):
            return raw[len(codecs.BOM_UTF8) :].decode("utf-8")
        if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
            return raw.decode("utf-16")
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        if raw.startswith(b"SQLite format 3\x00"):
            raise ValueError("it is a GeoPackage or SQLite database, not a scene") from None
        raise ValueError(
            f"it is not UTF-8 text (byte 0x{raw[exc.start : exc.start + 1].hex()} at position "
            f"{exc.start}), not a scene"
        ) from None


class ImageView(QGraphicsView):
    """The snapshot; emits image pixel coordinates of left clicks; zooms and pans.

    Overlays (click markers) are the view's own items: replacing the image removes them
    first, so no item is ever removed twice (the crash of issue 27).
    """

    clicked = pyqtSignal(float, float)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setScene(QGraphicsScene(self))
        self.setRenderHint(QPainter.Antialiasing)
        self.setRenderHint(QPainter.SmoothPixmapTransform)
        self.setTransformationAnchor(QGraphicsView.AnchorUnderMouse)
        self.setMinimumHeight(260)
        self._pixmap_item: Any = None
        self._overlays: list[QGraphicsItem] = []
        self._fitted = True
        self._pan_from: Any = None

    # --- image and overlays -------------------------------------------------------------
    def set_pixmap(self, pixmap: QPixmap) -> None:
        self.clear_overlays()
        if self._pixmap_item is not None:
            self.scene().removeItem(self._pixmap_item)
        self._pixmap_item = self.scene().addPixmap(pixmap)
        self._pixmap_item.setZValue(-1)
        self._pixmap_item.setTransformationMode(Qt.SmoothTransformation)
        self.scene().setSceneRect(QRectF(pixmap.rect()))
        self.fit()

    def has_image(self) -> bool:
        return self._pixmap_item is not None

    EMPTY_TEXT = (
        "No snapshot open.\nOpen snapshot… to annotate a photo; Load scene… for a saved scene "
        "(its marks show once its photo is open)."
    )

    def paintEvent(self, event: Any) -> None:
        """The view; with no snapshot, a line saying so (it was a blank white box)."""
        super().paintEvent(event)
        if self._pixmap_item is None:
            painter = QPainter(self.viewport())
            painter.setPen(QColor("#6b6b6b"))
            box = self.viewport().rect().adjusted(16, 16, -16, -16)
            painter.drawText(box, int(Qt.AlignCenter | Qt.TextWordWrap), self.EMPTY_TEXT)
            painter.end()

    def clear_overlays(self) -> None:
        """Remove the click markers (each once)."""
        sc = self.scene()
        for item in self._overlays:
            if item.scene() is sc:
                sc.removeItem(item)
        self._overlays = []

    def add_overlay(self, item: QGraphicsItem) -> QGraphicsItem:
        self._overlays.append(item)
        return item

    def overlay_count(self) -> int:
        return len(self._overlays)

    # --- zoom and pan ---------------------------------------------------------------------
    def fit(self) -> None:
        """The whole image in the view."""
        if self._pixmap_item is not None:
            self.fitInView(self.scene().sceneRect(), Qt.KeepAspectRatio)
        self._fitted = True

    def actual_size(self) -> None:
        """One image pixel per screen pixel (full resolution)."""
        self.resetTransform()
        self._fitted = False

    def zoom(self, factor: float) -> None:
        scale = self.transform().m11() * factor
        if 0.02 <= scale <= 40.0:
            self.scale(factor, factor)
            self._fitted = False

    def zoom_level(self) -> float:
        """Screen pixels per image pixel."""
        return float(self.transform().m11())

    def wheelEvent(self, event: Any) -> None:
        steps = event.angleDelta().y() / 120.0
        if steps:
            self.zoom(1.25**steps)
        event.accept()

    def resizeEvent(self, event: Any) -> None:
        super().resizeEvent(event)
        if self._fitted:
            self.fit()

    def mousePressEvent(self, event: Any) -> None:
        pan = event.button() in (Qt.RightButton, Qt.MiddleButton) or (
            event.button() == Qt.LeftButton and event.modifiers() & Qt.ControlModifier
        )
        if pan:
            self._pan_from = event.pos()
            self.setCursor(Qt.ClosedHandCursor)
            event.accept()
            return
        if event.button() == Qt.LeftButton and self._pixmap_item is not None:
            p = self.mapToScene(event.pos())
            self.clicked.emit(p.x(), p.y())
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event: Any) -> None:
        if self._pan_from is not None:
            d = event.pos() - self._pan_from
            self._pan_from = event.pos()
            self.horizontalScrollBar().setValue(self.horizontalScrollBar().value() - d.x())
            self.verticalScrollBar().setValue(self.verticalScrollBar().value() - d.y())
            event.accept()
            return
        super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event: Any) -> None:
        if self._pan_from is not None:
            self._pan_from = None
            self.unsetCursor()
            event.accept()
            return
        super().mouseReleaseEvent(event)


class LocateTask(QgsTask):
    """Locate a scene in the worker and write its layers into a GeoPackage (off the GUI)."""

    def __init__(self, job: dict[str, Any], gpkg: str, prefix: str) -> None:
        super().__init__("camloc: locate the camera", QgsTask.CanCancel)
        self.job = job
        self.gpkg = gpkg
        self.prefix = prefix
        self.uris: dict[str, str] = {}
        self.shapes: dict[str, dict[str, Any]] = {}  # kind -> its fields and geometry
        self.error: str | None = None
        self.warnings: list[str] = []
        self.info: dict[str, Any] = {}
        self.message = ""
        self.on_done: Any = None

    def run(self) -> bool:
        def progress(pct: float, message: str) -> None:
            self.message = message
            self.setProgress(0.9 * pct)

        try:
            res = run_worker(self.job, progress=progress, canceled=self.isCanceled)
            for kind in DRAW_ORDER:
                desc = res["layers"].get(kind)
                if desc is not None:
                    self.uris[kind] = write_gpkg_layer(self.gpkg, f"{self.prefix}_{kind}", desc)
                    self.shapes[kind] = {"fields": desc["fields"], "geometry": desc["geometry"]}
            self.warnings = [str(w) for w in res.get("warnings") or []]
            self.info = dict(res.get("info") or {})
        except WorkerCanceledError:
            self.error = "canceled"
            return False
        except (WorkerError, OSError) as exc:
            self.error = str(exc)
            return False
        except Exception as exc:  # an exception out of a task would be a Python error
            self.error = _unexpected(exc)
            return False
        self.setProgress(100)
        return True

    def finished(self, ok: bool) -> None:
        if self.on_done is not None:
            self.on_done(self, ok)


def _unexpected(exc: BaseException) -> str:
    """One line for an error the plugin did not foresee in a background task; its traceback
    goes to the message log (tab camloc), not to a Python error dialog."""
    QgsMessageLog.logMessage(traceback.format_exc(), "camloc", Qgis.Critical)
    return f"unexpected error ({type(exc).__name__}: {exc}); details in the message log, tab camloc"


class WorkerTask(QgsTask):
    """Any worker job in the background; ``on_done(task, ok)`` on the GUI thread."""

    def __init__(self, title: str, job: dict[str, Any]) -> None:
        super().__init__(title, QgsTask.CanCancel)
        self.job = job
        self.result: dict[str, Any] = {}
        self.error: str | None = None
        self.on_done: Any = None

    def run(self) -> bool:
        try:
            self.result = run_worker(
                self.job, progress=lambda p, _m: self.setProgress(p), canceled=self.isCanceled
            )
        except WorkerError as exc:
            self.error = str(exc)
            return False
        except Exception as exc:  # as LocateTask.run
            self.error = _unexpected(exc)
            return False
        return True

    def finished(self, ok: bool) -> None:
        if self.on_done is not None:
            self.on_done(self, ok)


class _SceneInbox(QObject):
    """Carries a scene from the page server's thread to the GUI thread."""

    received = pyqtSignal(dict)


def _number(value: Any) -> float | None:
    """``value`` as a float, None for NULL or text."""
    try:
        out = float(value)
    except (TypeError, ValueError):
        return None
    return out if out == out else None  # NaN is no number to show


def candidate_line(feat: Any) -> str:
    """One candidate as the dock lists it: ``#1  0.37  ★ tie with #2, #4 · 9.6 m up, facing
    334° (NNW)``."""
    score = feat["score_text"] if feat["score_text"] not in (None, "") else feat["score"]
    line = f"#{feat['rank']}  {score}"
    if feat["tie"] and feat["tie"] not in ("0", "false"):
        others = [p.strip() for p in str(feat["ambiguous_with"] or "").split(",") if p.strip()]
        line += "  ★ tie" + (" with " + ", ".join(f"#{o}" for o in others) if others else "")
    bits = []
    height = _number(feat["height_m"])
    if height is not None:
        bits.append(f"{height:.1f} m up")
    heading = _number(feat["heading_deg"])
    if heading is not None:
        points = [
            "N",
            "NNE",
            "NE",
            "ENE",
            "E",
            "ESE",
            "SE",
            "SSE",
            "S",
            "SSW",
            "SW",
            "WSW",
            "W",
            "WNW",
            "NW",
            "NNW",
        ]
        bits.append(f"facing {heading % 360:.0f}° ({points[round(heading % 360 / 22.5) % 16]})")
    return line + (" · " + ", ".join(bits) if bits else "")


class CamlocDock(QDockWidget):
    """Annotate a snapshot for camloc and locate the camera."""

    def __init__(self, iface: Any = None, parent: QWidget | None = None) -> None:
        super().__init__("camloc: locate a camera", parent)
        self.setObjectName("CamlocDock")
        self.iface = iface
        self.annotation = Annotation()
        self.image_file: str | None = None
        self.image_size: tuple[int, int] | None = None
        """The open snapshot's displayed width and height (EXIF orientation applied)."""
        self.result_layers: list[QgsVectorLayer] = []
        self._result_key: tuple[str, str] | None = None  # (GeoPackage, table prefix) shown
        self._restore: tuple[str, dict[str, str]] | None = None  # (group, uris) to put back
        self._restore_extent: Any = None  # the canvas's extent at that Run
        self._qml: dict[tuple[str, str], str] = {}  # (kind, fields and geometry) -> style
        self._result_group = ""
        self._result_uris: dict[str, str] = {}
        self.map_tool: QgsMapToolEmitPoint | None = None
        self._previous_tool = None
        self.task: QgsTask | None = None
        self._loading = False
        self.page_task: WorkerTask | None = None
        self.page_server: Any = None
        self._ready_note = False
        """A complete scene was just loaded: the guidance says so until a step is picked."""
        self.inbox = _SceneInbox()
        self.inbox.received.connect(self.receive_scene)
        self._build()
        self.steps.setCurrentRow(0)
        self._show_guidance()

    # --- layout ---------------------------------------------------------------------------
    def _build(self) -> None:
        self.view = ImageView()
        body = QWidget()
        lay = QVBoxLayout(body)
        row = QHBoxLayout()
        self.open_button = QPushButton("Open snapshot…")
        self.open_button.clicked.connect(self._open_dialog)
        self.browser_button = QPushButton("Annotate in browser…")
        self.browser_button.setToolTip(
            "The camloc annotation page (zoom, pan, undo, moving points, live focal length); "
            "its Submit sends the scene back here"
        )
        self.browser_button.clicked.connect(self.annotate_in_browser)
        self.load_button = QPushButton("Load scene…")
        self.load_button.clicked.connect(self._load_dialog)
        row.addWidget(self.open_button)
        row.addWidget(self.load_button)
        lay.addLayout(row)
        self.browser_button.setText("Annotate in browser (zoom, checks)…")
        lay.addWidget(self.browser_button)
        self.guidance = QLabel()
        self.guidance.setWordWrap(True)
        # wrapped labels take the dock's width; a long word (a path, a URL) never widens it
        self.guidance.setSizePolicy(QSizePolicy.Ignored, QSizePolicy.Preferred)
        self.guidance.setStyleSheet("QLabel { background: #fff8d6; padding: 4px; }")
        lay.addWidget(self.guidance)
        self.steps = QListWidget()
        self.steps.setWordWrap(True)
        for _key, label, _kind in STEPS:
            self.steps.addItem(label)
        self.steps.setMinimumHeight(self.steps.sizeHintForRow(0) * len(STEPS) + 8)
        self.steps.currentRowChanged.connect(self._step_changed)
        lay.addWidget(self.steps)
        zoom = QHBoxLayout()
        for text, slot in (
            ("Fit", lambda: self.view.fit()),
            ("1:1", lambda: self.view.actual_size()),
            ("−", lambda: self.view.zoom(1 / 1.25)),
            ("+", lambda: self.view.zoom(1.25)),
        ):
            b = QPushButton(text)
            b.setMaximumWidth(48)
            b.clicked.connect(slot)
            zoom.addWidget(b)
        zoom.addStretch(1)
        self.undo_button = QPushButton("Undo")
        self.undo_button.clicked.connect(self.undo)
        zoom.addWidget(self.undo_button)
        lay.addLayout(zoom)
        self.view.clicked.connect(self.image_clicked)
        lay.addWidget(self.view, 1)

        form = QFormLayout()
        self.preset_combo = QComboBox()
        self.preset_combo.addItems(PRESETS)
        self.preset_combo.setToolTip("the annotated car's size class (camloc_geo.objects)")
        form.addRow("Car preset", self.preset_combo)
        self.radius_spin = QDoubleSpinBox()
        self.radius_spin.setRange(10.0, 5000.0)
        self.radius_spin.setDecimals(0)
        self.radius_spin.setSingleStep(50.0)
        self.radius_spin.setSuffix(" m")
        self.radius_spin.setValue(150.0)
        self.radius_spin.setToolTip("how far from the picked point the camera may stand")
        form.addRow("Search radius", self.radius_spin)
        self.hint_edit = QLineEdit()
        self.hint_edit.setPlaceholderText("e.g. looking north, NB, facing SW, or 270 (degrees)")
        self.hint_edit.setToolTip("the camera's viewing direction: decides between tied places")
        form.addRow("Viewing direction", self.hint_edit)
        pick = QHBoxLayout()
        self.pick_button = QPushButton("Pick on map")
        self.pick_button.setCheckable(True)
        self.pick_button.toggled.connect(self._pick_toggled)
        self.streets_edit = QLineEdit()
        self.streets_edit.setPlaceholderText("or its streets: A & B")
        pick.addWidget(self.pick_button)
        pick.addWidget(self.streets_edit)
        form.addRow("Intersection", pick)
        osm = QHBoxLayout()
        self.osm_edit = QLineEdit()
        self.osm_edit.setPlaceholderText("OSM extract or folder (empty: Overpass)")
        osm_button = QPushButton("…")
        osm_button.setMaximumWidth(30)
        osm_button.clicked.connect(self._osm_dialog)
        osm.addWidget(self.osm_edit)
        osm.addWidget(osm_button)
        form.addRow("Map", osm)
        out = QHBoxLayout()
        self.gpkg_edit = QLineEdit()
        self.gpkg_edit.setPlaceholderText(f"{RESULTS_NAME} beside the project")
        gpkg_button = QPushButton("…")
        gpkg_button.setMaximumWidth(30)
        gpkg_button.clicked.connect(self._gpkg_dialog)
        out.addWidget(self.gpkg_edit)
        out.addWidget(gpkg_button)
        form.addRow("Results", out)
        # a check box's text never wraps: at 47 characters ("Also load the map model's
        # streets and buildings") it made the form 452 px wide, wider than the dock at 420 px,
        # and, with no horizontal scroll bar, cut the guidance and the Undo button
        self.context_check = QCheckBox("Also load the map's streets, buildings")
        self.context_check.setToolTip(
            "Also load the map model's streets (as wide as the model thinks) and buildings as "
            "layers, to check the map the candidates were matched on."
        )
        form.addRow(self.context_check)
        lay.addLayout(form)
        row4 = QHBoxLayout()
        self.run_button = QPushButton("Run")
        self.run_button.clicked.connect(self.run)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.setEnabled(False)
        self.cancel_button.clicked.connect(self.cancel)
        self.save_button = QPushButton("Save scene…")
        self.save_button.clicked.connect(self._save_dialog)
        for b in (self.run_button, self.cancel_button, self.save_button):
            row4.addWidget(b)
        # Run, its progress and the status line stay below the scrolled part, always in sight:
        # inside it they fell below the fold of a 1000-pixel-high screen, so the analyst had
        # to scroll to find Run and to read the result.
        footer = QWidget()
        foot = QVBoxLayout(footer)
        foot.setContentsMargins(lay.contentsMargins())
        foot.addLayout(row4)
        self.progress = QProgressBar()
        self.progress.setRange(0, 100)
        self.progress.setVisible(False)
        foot.addWidget(self.progress)
        self.status = QLabel(
            "Open a snapshot, then annotate it here or in the browser (Annotate in browser…)."
        )
        self.status.setWordWrap(True)
        self.status.setSizePolicy(QSizePolicy.Ignored, QSizePolicy.Preferred)
        self.status.setTextInteractionFlags(Qt.TextSelectableByMouse)
        foot.addWidget(self.status)
        # the candidates of the last run, best first: the analyst read them only from map
        # labels (the leading ones) or the attribute table; a click shows one on the map
        self.candidate_list = QListWidget()
        self.candidate_list.setToolTip(
            "The last run's candidates, best first (★: a tie). Click one to select it on the "
            "map and centre the map on it."
        )
        self.candidate_list.setVisible(False)
        # five rows in sight (sizeHintForRow is -1 while the list is empty: the list came up
        # 3 px high, a line under the status)
        rows_px = (self.candidate_list.fontMetrics().height() + 4) * 5 + 8
        self.candidate_list.setMinimumHeight(rows_px)
        self.candidate_list.setMaximumHeight(rows_px)
        self.candidate_list.currentRowChanged.connect(self.show_candidate)
        foot.addWidget(self.candidate_list)
        scroll = QScrollArea()
        scroll.setWidgetResizable(True)
        scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)  # wrap, never cut
        scroll.setFrameShape(QScrollArea.NoFrame)
        self.setMinimumWidth(380)
        scroll.setWidget(body)
        outer = QWidget()
        whole = QVBoxLayout(outer)
        whole.setContentsMargins(0, 0, 0, 0)
        whole.setSpacing(0)
        whole.addWidget(scroll, 1)
        whole.addWidget(footer)
        self.setWidget(outer)

    # --- snapshot and clicks ---------------------------------------------------------------
    def _open_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(
            self, "Open snapshot", "", "Images (*.png *.jpg *.jpeg *.webp *.bmp *.tif);;All (*.*)"
        )
        if path:
            self.open_snapshot(path)

    def open_snapshot(self, path: str) -> bool:
        """Show the image and start a new annotation for it (any number of times).

        The image is read as viewers show it (EXIF orientation applied), so the scene's
        ``image.width``/``height`` are the grid calibrate, the browser page and ``camloc vp``
        use. A FIFO or device, an empty, truncated or non-image file, or an image over
        ``MAX_IMAGE_PIXELS`` is refused with one status line (False); the open snapshot and
        its annotation stay as they were.
        """
        try:
            image, turned = read_snapshot(path)
        except SnapshotError as exc:
            self.refuse(str(exc))
            return False
        pix = QPixmap.fromImage(image)
        if pix.isNull():  # out of memory for the pixmap
            self.refuse(f"cannot show the image {path}: not enough memory for it")
            return False
        self._stop_page()
        scene_id = os.path.splitext(os.path.basename(path))[0]
        self.annotation = Annotation(image.width(), image.height(), scene_id=scene_id)
        self._ready_note = False
        self.annotation.image_path = os.path.basename(path)
        self.image_file = os.path.abspath(path)
        self.image_size = (image.width(), image.height())
        self.view.set_pixmap(pix)
        self.steps.blockSignals(True)
        self.steps.setCurrentRow(0)
        self.steps.blockSignals(False)
        self.redraw()
        self._show_guidance()
        upright = " (turned upright, as its EXIF orientation says)" if turned else ""
        self.set_status(
            f"{image.width()}×{image.height()} px{upright}. Annotate here, or in the browser "
            "with its zoom and checks (Annotate in browser…)."
        )
        return True

    def _step_changed(self, row: int) -> None:
        self._ready_note = False  # the analyst picked a step: its own guidance from now on
        if 0 <= row < len(STEPS):
            self.annotation.set_step(STEPS[row][0])
            self.redraw()
            self._show_guidance()

    def _show_guidance(self) -> None:
        if not self.view.has_image() and self._ready_note:
            # a complete scene loaded without its snapshot (the bundled sample names none): the
            # guidance said "Start: open a snapshot" beside "Run when ready" and eight ticks
            self.guidance.setText(
                "<b>Everything needed is marked: Run</b> (at the bottom of the dock).<br>The "
                "snapshot is not open (the scene names none, or it was not found beside the "
                "scene): Open snapshot… to see or change the marks."
            )
            return
        if not self.view.has_image():
            self.guidance.setText(
                "<b>Start:</b> open a snapshot. The steps below mark the car (its corner and "
                "edges), lines along its axes and the intersection's kerb corners."
            )
            return
        if self._ready_note:
            # a complete scene just loaded: step 1's "click the corner of the car" read as
            # if nothing were marked yet
            self.guidance.setText(
                "<b>Everything needed is marked: Run</b> (at the bottom of the dock).<br>To "
                "add lines or corners, or to redo a point, pick its step below."
            )
            return
        row = [s[0] for s in STEPS].index(self.annotation.step)
        self.guidance.setText(f"<b>{STEPS[row][1]}</b><br>{GUIDANCE[self.annotation.step]}")

    def set_step(self, key: str) -> None:
        """Select a step by key (``origin``, ``lines_length``, ``corners``...)."""
        self.steps.setCurrentRow([s[0] for s in STEPS].index(key))

    def image_clicked(self, x: float, y: float) -> None:
        """A click on the snapshot at image pixel ``(x, y)``."""
        if not self.view.has_image():
            self.set_status("Open a snapshot first.")
            return
        self._ready_note = False
        what = self.annotation.click(x, y)
        self._sync_step_row()
        self.redraw()
        self._show_guidance()
        row = [s[0] for s in STEPS].index(self.annotation.step)
        self.set_status(f"{what} at ({x:.1f}, {y:.1f}). Next: {STEPS[row][1]}")

    def _sync_step_row(self) -> None:
        row = [s[0] for s in STEPS].index(self.annotation.step)
        if row != self.steps.currentRow():
            self.steps.blockSignals(True)
            self.steps.setCurrentRow(row)
            self.steps.blockSignals(False)

    def undo(self) -> None:
        self.annotation.undo()
        self._sync_step_row()
        self.redraw()
        self._show_guidance()

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
        """Draw the annotation over the image: markers a fixed size on screen at any zoom."""
        self._update_step_labels()
        view = self.view
        view.clear_overlays()
        if not view.has_image():
            return
        sc = view.scene()
        a = self.annotation

        def pen(colour: str, width: float = 2.5) -> QPen:
            p = QPen(QColor(colour))
            p.setWidthF(width)
            p.setCosmetic(True)  # screen pixels, whatever the zoom
            return p

        def dot(x: float, y: float, fill: str, r: float = MARKER_PX) -> None:
            item = sc.addEllipse(-r, -r, 2 * r, 2 * r, pen("#000000", 1.5), QBrush(QColor(fill)))
            item.setPos(x, y)
            item.setFlag(QGraphicsItem.ItemIgnoresTransformations)
            view.add_overlay(item)

        if "origin" in a.axes:
            ox, oy = a.axes["origin"]
            for axis in ("length", "width", "height"):
                if axis in a.axes:
                    x, y = a.axes[axis]
                    view.add_overlay(sc.addLine(ox, oy, x, y, pen(AXIS_COLOURS[axis], 3.0)))
        for axis, segs in a.lines.items():
            p = pen(AXIS_COLOURS[axis])
            p.setStyle(Qt.DashLine)
            for x1, y1, x2, y2 in segs:
                view.add_overlay(sc.addLine(x1, y1, x2, y2, p))
        for key, (x, y) in a.axes.items():
            dot(x, y, AXIS_COLOURS[key])
        if a.pending is not None:
            dot(a.pending[0], a.pending[1], "#ffff00")
        for i, (x, y) in enumerate(a.corners):
            dot(x, y, AXIS_COLOURS["corners"], MARKER_PX * 1.3)
            t = sc.addSimpleText(str(i))
            t.setBrush(QBrush(QColor("#ffffff")))
            t.setPen(pen("#000000", 0.8))
            f = t.font()
            f.setPointSize(12)
            f.setBold(True)
            t.setFont(f)
            t.setFlag(QGraphicsItem.ItemIgnoresTransformations)
            t.setPos(QPointF(x, y))
            view.add_overlay(t)

    # --- the annotation page in the browser -----------------------------------------------
    def annotate_in_browser(self) -> bool:
        """Open the library's annotation page for the snapshot; its Submit comes back here."""
        if not self.image_file:
            self.set_status("Open a snapshot first: the page annotates that image.")
            return False
        if self.page_task is not None:
            self.set_status("The annotation page is being prepared…")
            return False
        from .browser import PageServer

        self._stop_page()
        self.page_server = PageServer(self._scene_from_page)
        a = self.annotation
        job: dict[str, Any] = {
            "task": "annotation_page",
            "image": self.image_file,
            "submit_url": self.page_server.submit_url,
            "title": f"camloc: annotate {os.path.basename(self.image_file)}",
        }
        if a.lat is not None and a.lon is not None:
            job.update({"lat": a.lat, "lon": a.lon, "radius_m": self.radius_spin.value()})
            osm = self.osm_edit.text().strip()
            if osm and os.path.isfile(osm):
                job["osm"] = osm
            if self.streets_edit.text().strip():
                job["streets"] = self.streets_edit.text().strip()
        if a.axes or a.corners or a.base:
            job["scene"] = self.scene()  # continue from what was clicked here
        task = WorkerTask("camloc: prepare the annotation page", job)
        task.on_done = self._page_ready
        self.page_task = task
        QgsApplication.taskManager().addTask(task)
        self.set_status("Preparing the annotation page…")
        return True

    def _page_ready(self, task: WorkerTask, ok: bool) -> None:
        self.page_task = None
        if self.page_server is None:
            return
        if not ok:
            self.refuse(f"annotation page: {task.error or 'canceled'}")
            self._stop_page()
            return
        self.page_server.html = task.result["info"]["html"]
        QDesktopServices.openUrl(QUrl(self.page_server.url))
        self.set_status(
            "The annotation page is open in your browser. Annotate there and press Submit: "
            "the scene comes back here by itself."
        )
        self.status.setToolTip(self.page_server.url)

    def _scene_from_page(self, scene: dict[str, Any]) -> str | None:
        """On the page server's thread: validate with the library, then hand to the GUI."""
        try:
            run_worker({"task": "check_scene", "scene": scene})
        except WorkerError as exc:
            return str(exc)
        self.inbox.received.emit(scene)
        return None

    def receive_scene(self, scene: dict[str, Any]) -> None:
        """Take a scene (from the page or a file) as the dock's annotation."""
        self.annotation = Annotation.from_scene(scene)
        if self.image_file and not self.annotation.image_path:
            self.annotation.image_path = os.path.basename(self.image_file)
        self._ready_note = not self.annotation.problems()
        self._settings_from_annotation()
        self._sync_step_row()
        self.redraw()
        self._show_guidance()
        anns = len(scene.get("annotations") or [])
        corners = len((scene.get("intersection") or {}).get("corners") or [])
        missing = self.annotation.problems()
        self.set_status(
            f"Scene received: {anns} car annotation(s), {corners} kerb corner(s). "
            + ("Run when ready." if not missing else "Still to do: " + "; ".join(missing))
            + self._grid_warning()
        )

    def _grid_warning(self) -> str:
        """A warning when the scene's image size is not the open snapshot's displayed size."""
        if self.image_size is None:
            return ""
        shown = self.image_size
        scene = (self.annotation.width, self.annotation.height)
        if scene == shown or not all(scene):
            return ""
        if scene == shown[::-1]:
            return (
                f" Warning: the scene is {scene[0]}×{scene[1]} px, the snapshot shown upright "
                f"{shown[0]}×{shown[1]}: it was annotated turned a quarter (its stored grid, "
                "EXIF orientation ignored); annotate it again."
            )
        return (
            f" Warning: the scene is {scene[0]}×{scene[1]} px but the open snapshot is "
            f"{shown[0]}×{shown[1]}: is it the scene's image?"
        )

    def _settings_from_annotation(self) -> None:
        a = self.annotation
        if self.preset_combo.findText(a.preset) < 0:
            self.preset_combo.addItem(a.preset)
        self.preset_combo.setCurrentText(a.preset)
        self.radius_spin.setValue(a.radius_m)
        self.hint_edit.setText(a.view_hint)
        self.streets_edit.setText(" & ".join(a.streets))

    def _stop_page(self) -> None:
        if self.page_server is not None:
            self.page_server.stop()
            self.page_server = None

    def _load_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Load scene", "", "camloc scenes (*.json)")
        if path:
            self.load_scene(path)

    def load_scene(self, path: str) -> bool:
        """Load a scene file (for example one saved by the annotation page)."""
        problem = check_regular_file(path, "scene")  # a FIFO would block QGIS on open()
        if problem:
            self.refuse(problem)
            return False
        try:
            if os.path.getsize(path) > MAX_SCENE_BYTES:
                raise ValueError(
                    f"{os.path.getsize(path) / 1e6:.0f} MB, more than the "
                    f"{MAX_SCENE_BYTES / 1e6:g} MB a scene may be"
                )
            with open(path, "rb") as fh:
                scene = json.loads(_json_text(fh.read()))
            if not isinstance(scene, dict):
                raise ValueError("not a JSON object")
        except (OSError, ValueError, RecursionError) as exc:
            self.refuse(f"cannot read the scene {path}: {exc}")
            return False
        name = os.path.basename(path)
        # the library's own check, at load (it used to come only at Run or Save): the analyst
        # hears at once what is wrong with the file
        invalid = self._scene_problem(scene)
        try:
            Annotation.from_scene(scene)  # a wrong shape ("annotations": 5) cannot be shown
        except (AttributeError, KeyError, TypeError, ValueError, IndexError) as exc:
            self.refuse(f"cannot load the scene {name}: {invalid or exc}")
            return False
        image = (scene.get("image") or {}).get("path")
        refused = ""
        if isinstance(image, str) and image and not self.image_file:
            candidate = os.path.join(os.path.dirname(path), image)
            if os.path.lexists(candidate) and not self.open_snapshot(candidate):
                refused = self.status.text()
        self.receive_scene(scene)
        if invalid:  # one line: what is wrong comes first, it is what Run and Save will refuse
            self.set_status(
                f"Scene {name} loaded, but it is not valid: {invalid}. Fix it (here or in the "
                "file) before Run or Save."
            )
        if refused:  # say why its image is not shown
            self.set_status(f"{self.status.text()} Its image was not opened: {refused}")
        return True

    def _scene_problem(self, scene: dict[str, Any]) -> str | None:
        """What the library finds wrong with a scene (its first problems, one line), or None.

        None too when the worker cannot say (no Python with camloc_geo): Run says that.
        """
        from qgis.PyQt.QtWidgets import QApplication

        QApplication.setOverrideCursor(Qt.WaitCursor)
        try:
            run_worker({"task": "check_scene", "scene": scene})
        except WorkerError as exc:
            if exc.kind not in ("SceneError", "InputError"):
                return None
            return " ".join(str(exc).split())
        finally:
            QApplication.restoreOverrideCursor()
        return None

    # --- map pick --------------------------------------------------------------------------
    def _pick_toggled(self, on: bool) -> None:
        if self.iface is None:
            return
        canvas = self.iface.mapCanvas()
        if on:
            if self.map_tool is not None:
                return
            self._previous_tool = canvas.mapTool()
            self.map_tool = QgsMapToolEmitPoint(canvas)
            self.map_tool.canvasClicked.connect(self._canvas_clicked)
            canvas.setMapTool(self.map_tool)
            self.set_status("Click the intersection on the map.")
        elif self.map_tool is not None:
            tool, self.map_tool = self.map_tool, None
            canvas.unsetMapTool(tool)
            if self._previous_tool is not None:
                canvas.setMapTool(self._previous_tool)
            self._previous_tool = None

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
        """The current scene dict, with the dock's preset, radius, direction and streets."""
        a = self.annotation
        text = self.streets_edit.text().strip()
        a.streets = [s.strip() for s in text.replace("/", "&").split("&") if s.strip()]
        a.preset = self.preset_combo.currentText() or a.preset
        a.radius_m = float(self.radius_spin.value())
        a.view_hint = self.hint_edit.text().strip()
        return a.to_scene()

    def save_scene(self, path: str) -> bool:
        """Validate the scene with the library and write it; False (status says why) if invalid."""
        problem = _output_problem(path, "scene file")
        if problem is None and _same_file(path, self.image_file):
            # the library would have written the scene over the photo
            problem = f"{path} is the open snapshot; give the scene its own .json file"
        if problem is None and _same_file(path, self.osm_edit.text().strip()):
            problem = f"{path} is the map extract; give the scene its own .json file"
        if problem:
            self.refuse(f"not saved: {problem}")
            return False
        scene = self.scene()
        if self.image_file:  # the scene names its photo from its own folder, where it is saved
            scene["image"]["path"] = _path_from(self.image_file, os.path.dirname(path))
        try:
            run_worker({"task": "check_scene", "scene": scene, "save_to": path})
        except WorkerError as exc:
            self.refuse(f"not saved: {exc}")
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

    def _gpkg_dialog(self) -> None:
        path, _ = QFileDialog.getSaveFileName(
            self,
            "Results GeoPackage",
            self.results_path(),
            "GeoPackage (*.gpkg)",
            options=QFileDialog.DontConfirmOverwrite,  # layers are added to an existing file
        )
        if path:
            self.gpkg_edit.setText(path if path.endswith(".gpkg") else path + ".gpkg")

    def results_path(self) -> str:
        """The GeoPackage results go to: the one chosen, else beside the project (or image)."""
        chosen = self.gpkg_edit.text().strip()
        if chosen:
            return chosen
        folder = QgsProject.instance().absolutePath()
        if not folder and self.image_file:
            folder = os.path.dirname(self.image_file)
        return os.path.join(folder or os.path.expanduser("~"), RESULTS_NAME)

    def run(self) -> QgsTask | None:
        """Locate the camera in the background; the layers load when the task ends.

        Returns the task (None when the scene is not ready or a run is going on).
        """
        if self.task is not None or self._loading:
            self.set_status("A run is going on: wait for it or Cancel it.")
            return None
        problems = self.annotation.problems()
        if problems:
            self.refuse("Not ready: " + "; ".join(problems))
            return None
        osm = self.osm_edit.text().strip()
        gpkg = self.results_path()
        problem = _output_problem(gpkg, "GeoPackage")
        for other, what in ((self.image_file, "the open snapshot"), (osm, "the map extract")):
            if problem is None and _same_file(gpkg, other):
                problem = f"{gpkg} is {what}"  # found only after the run, as an OGR error
        if problem:
            self.refuse(f"cannot write results: {problem}; pick another GeoPackage")
            return None
        if osm:
            problem = _extract_problem(osm)
            if problem:
                self.refuse(problem)
                return None
        prefix = "".join(c if c.isalnum() else "_" for c in self.annotation.scene_id) or "scene"
        self._fill_candidates(None)
        self._restore = None
        if self._result_key == (os.path.abspath(gpkg), prefix):
            # their GeoPackage tables are about to be replaced; put back if the run fails
            self._restore = (self._result_group, dict(self._result_uris))
            # and the map where the analyst left it: put back into a project left empty, QGIS
            # zoomed to the layers' full extent (the cones; seen in the desktop check)
            self._restore_extent = (
                self.iface.mapCanvas().extent() if self.iface is not None else None
            )
            self._remove_results()
        else:
            # another camera's (or GeoPackage's) layers: they stay in the project as they are
            self.result_layers = []
        self._result_key = None
        scene = self.scene()
        if self.image_file:
            # the worker runs in a folder of its own, where the bare file name the scene
            # holds names no file
            scene["image"]["path"] = os.path.abspath(self.image_file)
        job = {
            "task": "locate",
            "scene": scene,
            "osm": osm or None,
            "network": not osm,
            "context": self.context_check.isChecked(),
        }
        task = LocateTask(job, gpkg, prefix)
        task.on_done = self._run_done
        task.progressChanged.connect(self._task_progress)
        self.task = task
        self.run_button.setEnabled(False)
        self.cancel_button.setEnabled(True)
        self.progress.setValue(0)
        self.progress.setVisible(True)
        self.set_status(
            "Locating the camera…" + ("" if osm else " (downloading the map from Overpass)")
        )
        QgsApplication.taskManager().addTask(task)
        return task

    def cancel(self) -> None:
        """Cancel the run (the worker process is stopped)."""
        task = self.task
        if task is not None:
            # said before cancel(): a task canceled before it started ends inside cancel()
            # (its finished(False) runs at once), and "Canceling…" stayed after "Canceled."
            self.set_status("Canceling…")
            task.cancel()

    def _task_progress(self, value: float) -> None:
        self.progress.setValue(int(value))
        task = self.task
        if isinstance(task, LocateTask) and task.message:
            self.status.setText(f"Locating the camera… {task.message}")

    def _run_done(self, task: LocateTask, ok: bool) -> None:
        self.task = None
        self.run_button.setEnabled(True)
        self.cancel_button.setEnabled(False)
        self.progress.setVisible(False)
        if not ok:
            restore, self._restore = self._restore, None
            canceled = task.error in (None, "canceled")
            group = f"camloc: {self.annotation.scene_id}"
            if restore is not None:  # the tables were not replaced: the last results come back
                group = restore[0]
                self._load_layers(
                    restore[0], restore[1], None, self._restore_extent, stale=not canceled
                )
                self._result_key = (os.path.abspath(task.gpkg), task.prefix)
            if canceled:
                kept = " The map keeps the last run's layers." if restore is not None else ""
                self.set_status("Canceled." + kept)
                return
            # one line, whatever the library wrote, ended as a sentence before what follows
            # ('unexpected EOF The layers on the map...' ran the two together)
            line = _sentence(" ".join(str(task.error).split()))
            # the last run's layers of this camera (put back, or of another GeoPackage) are
            # marked stale: shown unmarked, they were taken for this run's answer
            marked = self._mark_stale(group) if restore is None else stale_name(group)
            if marked:
                about = f" The layers on the map are the last run's, marked stale ('{marked}')."
            else:
                about = " No layer on the map is this run's."
            self.set_status(f"camloc: {line}{about}")
            # QGIS's message bar too: the run may have been started long ago, the dock hidden
            if self.iface is not None:
                self.iface.messageBar().pushMessage(
                    "camloc", f"the camera was not located: {line}{about}", Qgis.Critical, 15
                )
            return
        self._load_results(task)

    def _load_results(self, task: LocateTask) -> None:
        """Store the layers' default styles in the GeoPackage, load the layers, then report
        and zoom."""
        self._restore = None
        self._result_key = (os.path.abspath(task.gpkg), task.prefix)
        self._store_styles(task)
        self._load_layers(f"camloc: {self.annotation.scene_id}", task.uris, task)

    def _store_styles(self, task: LocateTask) -> None:
        """The default style of each table the run wrote, into the GeoPackage's
        ``layer_styles`` (Layer › Add Layer, the Browser and another project then draw them
        styled), before any of them is opened (see :func:`layers.write_gpkg_styles`). A
        failure is logged; the layers are styled in the project anyway."""
        styles = {}
        for kind, shape in task.shapes.items():
            key = (kind, json.dumps(shape, sort_keys=True))
            if key not in self._qml:
                self._qml[key] = style_qml(kind, shape)
            if self._qml[key]:
                styles[f"{task.prefix}_{kind}"] = (kind, self._qml[key])
        error = write_gpkg_styles(task.gpkg, styles)
        if error:
            QgsMessageLog.logMessage(f"the styles were not stored: {error}", "camloc", Qgis.Warning)

    def _load_layers(
        self,
        name: str,
        uris: dict[str, str],
        task: LocateTask | None,
        extent: Any = None,
        stale: bool = False,
    ) -> None:
        """Load layers one per event-loop turn (each turn a few tens of ms, so the GUI never
        stalls for the whole batch) into the group ``name``, candidates on top; then report
        ``task`` (None: layers put back after a failed run, nothing to report) or set the
        canvas back to ``extent`` (a QgsRectangle, None: left as it is). ``stale``: the
        layers are a failed run's predecessors, marked so (:meth:`_mark_stale`)."""
        from qgis.PyQt.QtCore import QTimer

        root = QgsProject.instance().layerTreeRoot()
        group = root.findGroup(name) or root.insertGroup(0, name)
        self._result_group = name
        self._result_uris = dict(uris)
        todo = [k for k in DRAW_ORDER if k in uris]  # top to bottom
        self.result_layers = []
        self._loading = True

        def next_layer() -> None:
            if not todo:
                self._loading = False
                if stale:
                    self._mark_stale(name)
                if task is not None:
                    # a project of camloc layers alone: its place's UTM zone, not a stretched
                    # EPSG:4326 (before the canvas zooms to the candidates)
                    canvas = self.iface.mapCanvas() if self.iface is not None else None
                    drawn = canvas.mapSettings().destinationCrs() if canvas is not None else None
                    plate_carree = (
                        drawn is None or not drawn.isValid() or drawn.authid() == "EPSG:4326"
                    )
                    if plate_carree and use_local_crs(QgsProject.instance()) and canvas is not None:
                        canvas.setDestinationCrs(QgsProject.instance().crs())
                    self._report(task)
                elif extent is not None and self.iface is not None:
                    canvas = self.iface.mapCanvas()
                    canvas.setExtent(extent)
                    canvas.refresh()
                    # after QGIS's own zoom to the first layers of an empty project
                    QTimer.singleShot(0, lambda: (canvas.setExtent(extent), canvas.refresh()))
                return
            kind = todo.pop(0)
            opts = QgsVectorLayer.LayerOptions(False, False)  # no default style, no extent scan
            layer = QgsVectorLayer(uris[kind], LAYER_TITLES.get(kind, kind), "ogr", opts)
            if layer.isValid():
                apply_style(layer, kind)
                QgsProject.instance().addMapLayer(layer, False)
                group.addLayer(layer)
                self.result_layers.append(layer)
            QTimer.singleShot(0, next_layer)

        next_layer()

    def _report(self, task: LocateTask) -> None:
        from qgis.PyQt.QtCore import QTimer

        kinds = {lyr.customProperty("camloc/kind"): lyr for lyr in self.result_layers}
        cands = kinds.get("candidates")
        n = cands.featureCount() if cands is not None else 0
        tied = cands is not None and any(f["tie"] for f in cands.getFeatures())
        # the file's name: a whole path is one word too long to wrap, and cut the rest off
        msg = f"{n} candidate(s) in {os.path.basename(task.gpkg)}; best first."
        if tied:  # the library's tie, from the data (never from warning text)
            msg += " ★ marks a tie: add a viewing direction or a landmark to decide."
        if not n and task.info.get("reason"):
            msg = f"No candidate: {task.info['reason']}"
        self.set_status(msg)
        self.status.setToolTip(task.gpkg)
        self._fill_candidates(cands)
        if self.iface is not None and cands is not None and n:
            canvas = self.iface.mapCanvas()
            project = QgsProject.instance()
            xform = QgsCoordinateTransform(wgs84(), canvas.mapSettings().destinationCrs(), project)
            ext84 = cands.extent()
            ext84.grow(0.0002)  # degrees (the layer is EPSG:4326): about 20 m around them
            # room beside them for the leading candidates' labels: at a fixed 60 m the canvas
            # beside the dock (460 px) cut '#4 0.05 (tie with #1, #3)' at its left edge
            ext = extent_with_room(
                xform.transformBoundingBox(ext84),
                canvas.width(),
                canvas.height(),
                label_room_px(cands, canvas.mapSettings().outputDpi()),
            )
            canvas.setExtent(ext)
            canvas.refresh()
            # the first layers of an empty project make QGIS zoom to their full extent once
            # the event loop runs: zoom again after that
            QTimer.singleShot(0, lambda: (canvas.setExtent(ext), canvas.refresh()))

    def _fill_candidates(self, cands: QgsVectorLayer | None) -> None:
        """List ``cands`` best first (None: empty and hidden)."""
        self.candidate_list.blockSignals(True)
        self.candidate_list.clear()
        self._candidate_fids: list[int] = []
        feats = sorted(cands.getFeatures(), key=lambda f: f["rank"]) if cands is not None else []
        for f in feats:
            self.candidate_list.addItem(candidate_line(f))
            self._candidate_fids.append(f.id())
        self._candidate_layer = cands
        self.candidate_list.setCurrentRow(-1)
        self.candidate_list.blockSignals(False)
        self.candidate_list.setVisible(bool(feats))

    def show_candidate(self, row: int) -> None:
        """Select the candidate of list row ``row`` on its layer and centre the map on it."""
        layer = getattr(self, "_candidate_layer", None)
        if layer is None or not 0 <= row < len(self._candidate_fids):
            return
        try:
            feat = layer.getFeature(self._candidate_fids[row])
            layer.selectByIds([feat.id()])
        except RuntimeError:  # the layer was removed with its project
            return
        if self.iface is None or not feat.hasGeometry():
            return
        canvas = self.iface.mapCanvas()
        xform = QgsCoordinateTransform(
            layer.crs(), canvas.mapSettings().destinationCrs(), QgsProject.instance()
        )
        canvas.setCenter(xform.transform(feat.geometry().asPoint()))
        canvas.refresh()

    def wait(self, timeout_s: float = 120.0) -> bool:
        """Process events until the run (and the page task) ends; True if it did in time."""
        import time

        from qgis.PyQt.QtCore import QCoreApplication

        t0 = time.monotonic()

        def busy() -> bool:
            return self.task is not None or self.page_task is not None or self._loading

        while busy() and time.monotonic() - t0 < timeout_s:
            QCoreApplication.processEvents()
            time.sleep(0.01)
        return not busy()

    def _remove_results(self) -> None:
        project = QgsProject.instance()
        root = project.layerTreeRoot()
        emptied = []
        for old in self.result_layers:
            try:
                layer_id = old.id()
            except RuntimeError:  # deleted with the project
                continue
            node = root.findLayer(layer_id)
            if node is not None and node.parent() is not None:
                emptied.append(node.parent())
            if project.mapLayer(layer_id) is not None:
                project.removeMapLayer(layer_id)
        self.result_layers = []
        for group in emptied:  # a stale group emptied: the new run makes its own
            try:
                if group.customProperty(STALE_PROPERTY) and not group.children():
                    parent = group.parent()
                    if parent is not None:
                        parent.removeChildNode(group)
            except RuntimeError:
                continue

    def _mark_stale(self, name: str) -> str | None:
        """Mark the result group ``name`` and its layers stale (a run of its camera failed):
        the group's and the layers' names say so and the layers are drawn faded. Returns the
        group's new name (None: no such group, or it holds no layer)."""
        root = QgsProject.instance().layerTreeRoot()
        group = root.findGroup(name)
        if group is None:
            group = root.findGroup(stale_name(name))
        if group is None or not group.findLayers():
            return None
        new = stale_name(name)
        group.setName(new)
        group.setCustomProperty(STALE_PROPERTY, True)
        for node in group.findLayers():
            layer = node.layer()
            if layer is None or layer.customProperty(STALE_PROPERTY):
                continue
            layer.setCustomProperty(STALE_PROPERTY, True)
            layer.setName(f"{STALE_PREFIX}{layer.name()}")
            layer.setOpacity(STALE_OPACITY)
            _mark_labels_stale(layer)
            layer.triggerRepaint()
        return new

    def refuse(self, text: str) -> None:
        """Say why an action was refused: the status line, and QGIS's message bar (a warning,
        10 s; the analyst may be looking at the map, not at the dock)."""
        self.set_status(text)
        if self.iface is not None:
            line = " ".join(text.split())
            self.iface.messageBar().pushMessage("camloc", line, Qgis.Warning, 10)

    def set_status(self, text: str) -> None:
        self.status.setText(text)
        self.status.setToolTip("")
        self._fit_status()

    def _fit_status(self) -> None:
        """Give the status line the height of all its wrapped lines (the footer kept one)."""
        width = self.status.width()
        if width > 0:
            self.status.setMinimumHeight(self.status.heightForWidth(width))

    def resizeEvent(self, event: Any) -> None:
        super().resizeEvent(event)
        self._fit_status()

    def shutdown(self) -> None:
        """Stop what runs in the background (the plugin calls this on unload)."""
        self.pick_button.setChecked(False)
        if self.task is not None:
            self.task.on_done = None
            self.task.cancel()
            self.task = None
        self._stop_page()

    def closeEvent(self, event: Any) -> None:
        self.pick_button.setChecked(False)
        self._stop_page()
        super().closeEvent(event)
