"""The QGIS desktop, driven as an analyst would, with screenshots: a script for ``qgis --code``.

The suite runs it (test_desktop.py, under Xvfb, a fresh profile, a time limit); by hand::

    CAMLOC_PYTHON=$PWD/.venv-qgis/bin/python \\
    xvfb-run -a -s "-screen 0 1400x900x24" qgis --nologo --noversioncheck \\
        --profiles-path /tmp/camloc-profile --code qgis_plugin/tests/desktop_check.py

It runs, on the bundled sample: camloc:locate from the Toolbox's code path
(``processing.runAndLoadResults``) into named GeoPackages, the Toolbox's algorithm dialog (a
background task) into named shapefiles, the Processing batch dialog with two scenes (outputs per
row, optional outputs left empty, layers loaded), and the dock (Load scene…, Run; then Run on a
cut extract, and a Run canceled at once). Each step writes the loaded layers (name, renderer,
camloc kind, features, the candidates' ranks), the labels the canvas drew (text, layer, inside
the visible map or cut by its edge), where the canvas sits in the window's screenshot, the
message bar's lines and the message log's Python errors and camloc messages to ``summary.json`` in
``$CAMLOC_DESKTOP_OUT`` (default ``tests/artifacts/qgis/desktop``), with screenshots
(``*.png``) beside it. QGIS exits with the project cleared first (``QgsApplication.exit()``
with layers still loaded crashed QGIS 3.22 in its own teardown:
``QgisApp::setMapStyleDockLayer`` on a destroyed widget); a watchdog ends it after
``$CAMLOC_DESKTOP_WATCHDOG_S`` seconds (default 240) with ``error`` in the summary.
"""

from __future__ import annotations

import json
import os
import sys
import traceback
from pathlib import Path
from typing import Any

from qgis.core import QgsApplication, QgsProject
from qgis.PyQt.QtCore import QPoint, QTimer
from qgis.PyQt.QtWidgets import QTextEdit
from qgis.utils import iface

REPO = Path(os.environ.get("CAMLOC_REPO", Path.cwd()))
SCENE = REPO / "sample_maps" / "sample_scene.json"
OSM = REPO / "sample_maps" / "baltimore.osm.pbf"
OUT = Path(os.environ.get("CAMLOC_DESKTOP_OUT", REPO / "tests" / "artifacts" / "qgis" / "desktop"))
OUT.mkdir(parents=True, exist_ok=True)
sys.path.insert(0, str(REPO / "qgis_plugin"))
summary: dict[str, Any] = {}
state: dict[str, Any] = {}


def _layers() -> list[dict[str, Any]]:
    """The layers in the legend, top first."""
    out = []
    for node in QgsProject.instance().layerTreeRoot().findLayers():
        lyr = node.layer()
        row = {
            "name": lyr.name(),
            "renderer": type(lyr.renderer()).__name__,
            "kind": lyr.customProperty("camloc/kind"),
            "features": lyr.featureCount(),
            "labels": lyr.labelsEnabled(),
        }
        if row["kind"] == "candidates":
            feats = list(lyr.getFeatures())
            row["ranks"] = [f["rank"] for f in feats]
            row["tie_ranks"] = sorted(f["rank"] for f in feats if f["tie"])
        out.append(row)
    return out


def _labels() -> list[dict[str, Any]]:
    """The labels of the canvas's last render: text, layer and whether the visible map holds
    the whole of it (False: cut by the canvas's edge)."""
    canvas = iface.mapCanvas()
    results = canvas.labelingResults()
    if results is None or not hasattr(results, "allLabels"):
        return []
    extent = canvas.mapSettings().visibleExtent()
    names = {lid: lyr.name() for lid, lyr in QgsProject.instance().mapLayers().items()}
    return [
        {
            "layer": names.get(lp.layerID, lp.layerID),
            "text": lp.labelText,
            "inside": extent.contains(lp.labelRect),
            "unplaced": lp.isUnplaced,
        }
        for lp in results.allLabels()
    ]


def _shot(name: str) -> None:
    canvas = iface.mapCanvas()
    canvas.saveAsImage(str(OUT / f"{name}_canvas.png"))
    iface.mainWindow().grab().save(str(OUT / f"{name}_window.png"))
    corner = canvas.mapTo(iface.mainWindow(), QPoint(0, 0))
    summary.setdefault("canvas", {})[name] = {
        "rect": [corner.x(), corner.y(), canvas.width(), canvas.height()],
        "labels": _labels(),
    }


def _zoom_to_candidates() -> None:
    """As the dock zooms after a run: the candidates with room for their labels."""
    from camloc.layers import extent_with_room, label_room_px
    from qgis.core import QgsCoordinateTransform

    canvas = iface.mapCanvas()
    for lyr in QgsProject.instance().mapLayers().values():
        if lyr.customProperty("camloc/kind") == "candidates":
            ext = lyr.extent()
            ext.grow(0.0002)
            # the canvas may be in the place's UTM zone (camloc.layers.use_local_crs)
            xform = QgsCoordinateTransform(
                lyr.crs(), canvas.mapSettings().destinationCrs(), QgsProject.instance()
            )
            ext = xform.transformBoundingBox(ext)
            room = label_room_px(lyr, canvas.mapSettings().outputDpi())
            canvas.setExtent(extent_with_room(ext, canvas.width(), canvas.height(), room))
            canvas.refresh()
            return


def step_toolbox() -> None:
    import processing
    from processing.core.Processing import Processing

    Processing.initialize()
    import camloc

    plugin = camloc.classFactory(iface)
    plugin.initProcessing()
    plugin.initGui()
    state["plugin"] = plugin
    outs = ("CANDIDATES", "VIEW_CONES", "MATCHED_CORNERS", "INTERSECTION")
    params = {"SCENE": str(SCENE), "OSM": str(OSM)}
    params.update({k: str(OUT / f"toolbox_{k.lower()}.gpkg") for k in outs})
    processing.runAndLoadResults("camloc:locate", params)
    summary["toolbox"] = _layers()

    def zoomed() -> None:  # after QGIS's own zoom to its first layers
        _zoom_to_candidates()
        _after_render(lambda: (_shot("toolbox"), step_dialog()))

    QTimer.singleShot(300, guarded(zoomed))


def step_dialog() -> None:
    """The Toolbox's own dialog (its run is a background task) into named shapefiles."""
    from processing.gui.AlgorithmDialog import AlgorithmDialog

    QgsProject.instance().clear()
    alg = QgsApplication.processingRegistry().createAlgorithmById("camloc:locate")
    dlg = AlgorithmDialog(alg, parent=iface.mainWindow())
    state["dialog"] = dlg
    dlg.show()
    outs = ("CANDIDATES", "VIEW_CONES", "MATCHED_CORNERS", "INTERSECTION")
    params = {"SCENE": str(SCENE), "OSM": str(OSM)}
    params.update({k: str(OUT / f"dialog_{k.lower()}.shp") for k in outs})
    dlg.setParameters(params)
    dlg.resize(900, 640)
    dlg.grab().save(str(OUT / "dialog_parameters.png"))  # the form as the analyst fills it

    def finished(ok: bool, results: dict[str, Any]) -> None:
        summary["dialog_shp"] = {"ok": ok, "layers": _layers()}
        dlg.algorithmFinished.disconnect(finished)
        QTimer.singleShot(
            1500, lambda: (dlg.grab().save(str(OUT / "dialog.png")), guarded(cancel_run)())
        )

    def cancel_run() -> None:
        """Run again into other files and press Cancel at once, as for a long run."""
        QgsProject.instance().clear()
        again = {"SCENE": str(SCENE), "OSM": str(OSM)}
        again.update({k: str(OUT / f"dialog_canceled_{k.lower()}.gpkg") for k in outs})
        dlg.setParameters(again)
        dlg.algorithmFinished.connect(canceled)
        dlg.runAlgorithm()
        state["cancel_enabled"] = dlg.cancelButton().isEnabled()
        dlg.cancelButton().click()

    def canceled(ok: bool, results: dict[str, Any]) -> None:
        summary["dialog_canceled"] = {
            "ok": ok,
            "cancel_enabled": state.get("cancel_enabled"),
            "layers": _layers(),
            "files": sorted(p.name for p in OUT.glob("dialog_canceled_*")),
            "log": _dialog_log(dlg),
        }
        QTimer.singleShot(
            1000,
            lambda: (dlg.grab().save(str(OUT / "dialog_canceled.png")), guarded(step_batch)()),
        )

    dlg.algorithmFinished.connect(finished)
    dlg.runAlgorithm()


def _dialog_log(dlg: Any) -> str | None:
    """The text of a Processing dialog's log (the text box that lists the input parameters)."""
    for box in dlg.findChildren(QTextEdit):
        if "Input parameters" in box.toPlainText():
            return box.toPlainText()
    return None


def step_batch() -> None:
    from processing.gui.BatchAlgorithmDialog import BatchAlgorithmDialog
    from processing.tools import dataobjects

    if "dialog" in state:
        state["dialog"].close()
    QgsProject.instance().clear()
    second = json.loads(SCENE.read_text())
    second["id"] = "second-camera"
    (OUT / "second-camera.json").write_text(json.dumps(second))
    alg = QgsApplication.processingRegistry().createAlgorithmById("camloc:locate")
    dlg = BatchAlgorithmDialog(alg, parent=iface.mainWindow())
    state["batch"] = dlg
    dlg.resize(1300, 500)
    dlg.show()
    panel = dlg.mainWidget()
    scenes = [SCENE, OUT / "second-camera.json"]
    while panel.batchRowCount() < len(scenes):
        panel.addRow()
    context = dataobjects.createContext()
    col = panel.parameter_to_column
    for row, scene in enumerate(scenes):
        panel.wrappers[row][col["SCENE"]].setParameterValue(str(scene), context)
        panel.wrappers[row][col["OSM"]].setParameterValue(str(OSM), context)
        for out in ("CANDIDATES", "VIEW_CONES"):  # the other outputs left empty
            cell = panel.tblParameters.cellWidget(row + 1, col[out])
            cell.setValue(str(OUT / f"batch_row{row}_{out.lower()}.gpkg"))
    panel.checkLoadLayersOnCompletion.setChecked(True)
    dlg.runAlgorithm()
    summary["batch"] = _layers()
    QTimer.singleShot(300, _zoom_to_candidates)
    QTimer.singleShot(
        1500, lambda: (dlg.grab().save(str(OUT / "batch_dialog.png")), guarded(step_dock)())
    )


def step_dock() -> None:
    state["batch"].close()
    QgsProject.instance().clear()
    plugin = state["plugin"]
    plugin.action.setChecked(True)
    dock = plugin.dock
    dock.load_scene(str(SCENE))
    dock.osm_edit.setText(str(OSM))
    dock.gpkg_edit.setText(str(OUT / "dock_results.gpkg"))
    dock.run()

    def poll(n: list[int] = [0]) -> None:  # noqa: B006 - a counter kept between calls
        n[0] += 1
        if (dock.task is not None or dock._loading) and n[0] < 240:
            QTimer.singleShot(500, poll)
            return
        QTimer.singleShot(2500, guarded(finish))

    QTimer.singleShot(500, poll)


def finish() -> None:
    dock = state["plugin"].dock
    summary["dock"] = {
        "status": dock.status.text(),
        "guidance": dock.guidance.text(),
        "candidates": [
            dock.candidate_list.item(i).text() for i in range(dock.candidate_list.count())
        ],
        "layers": _layers(),
        "extent": _extent(),
    }

    def shots() -> None:
        _shot("dock")
        dock.grab().save(str(OUT / "dock.png"))
        iface.layerTreeView().grab().save(str(OUT / "dock_legend.png"))
        step_dock_errors()

    _after_render(shots)


def _after_render(then: Any) -> None:
    """Refresh the canvas and call ``then`` once it has drawn (its labels known): a fixed
    wait took the screenshot before the labels on a busy machine."""
    canvas = iface.mapCanvas()
    fired: list[bool] = []

    def drawn() -> None:
        if fired:
            return
        fired.append(True)
        canvas.mapCanvasRefreshed.disconnect(drawn)
        QTimer.singleShot(300, guarded(then))

    canvas.mapCanvasRefreshed.connect(drawn)
    canvas.refresh()


def _extent() -> list[float]:
    """The canvas's extent, [xmin, ymin, xmax, ymax] in the project's CRS."""
    ext = iface.mapCanvas().extent()
    return [ext.xMinimum(), ext.yMinimum(), ext.xMaximum(), ext.yMaximum()]


def _bar() -> list[str]:
    """The message bar's items, 'title: text', newest last."""
    out = []
    for item in iface.messageBar().items():
        out.append(f"{item.title()}: {item.text()}")
    return out


def _when_idle(then: Any) -> None:
    """Call ``then`` once the dock's run and its layer loading have ended (at most 120 s)."""
    dock = state["plugin"].dock

    def poll(n: list[int] = [0]) -> None:  # noqa: B006 - a counter kept between calls
        n[0] += 1
        if (dock.task is not None or dock._loading) and n[0] < 240:
            QTimer.singleShot(500, poll)
            return
        QTimer.singleShot(500, guarded(then))

    QTimer.singleShot(300, poll)


def step_dock_errors() -> None:
    """What the analyst sees when the extract is broken, and when a run is canceled: the
    message bar's line (no Python error), the last results kept."""
    dock = state["plugin"].dock
    cut = OUT / "cut.osm.pbf"
    cut.write_bytes(OSM.read_bytes()[:4000])
    iface.messageBar().clearWidgets()
    dock.osm_edit.setText(str(cut))
    dock.run()

    def broken_done() -> None:
        summary["dock_broken_extract"] = {
            "status": dock.status.text(),
            "bar": _bar(),
            "layers": _layers(),
            "extent": _extent(),
        }
        iface.mainWindow().grab().save(str(OUT / "dock_error_window.png"))
        iface.messageBar().clearWidgets()
        dock.osm_edit.setText(str(OSM))
        dock.run()
        dock.cancel()  # at once: the worker is stopped
        _when_idle(canceled)

    def canceled() -> None:
        summary["dock_canceled"] = {
            "status": dock.status.text(),
            "layers": _layers(),
            "extent": _extent(),
        }
        done()

    _when_idle(broken_done)


def done() -> None:
    if summary.get("done"):
        return
    summary["done"] = True
    (OUT / "summary.json").write_text(json.dumps(summary, indent=1, ensure_ascii=False))
    QgsProject.instance().clear()  # before exit: see the module's docstring
    QTimer.singleShot(300, QgsApplication.exit)


def guarded(step: Any) -> Any:
    def run() -> None:
        try:
            step()
        except Exception:
            summary["error"] = traceback.format_exc()
            done()

    return run


def _log(message: str, tag: str, level: Any) -> None:
    if tag in ("Python error", "Python warning", "camloc") or "Traceback" in message:
        summary.setdefault("log", []).append({"tag": tag, "message": message})


QgsApplication.messageLog().messageReceived.connect(_log)


def start() -> None:
    # the window as large as the screen (Xvfb has no window manager to maximise it): the
    # canvas beside the dock as an analyst's screen shows it
    screen = QgsApplication.primaryScreen()
    if screen is not None:
        iface.mainWindow().setGeometry(screen.availableGeometry())
    step_toolbox()


def watchdog() -> None:
    if not summary.get("done"):
        summary["error"] = f"watchdog: the steps did not end within {WATCHDOG_S} s"
        done()


WATCHDOG_S = float(os.environ.get("CAMLOC_DESKTOP_WATCHDOG_S", "240"))
QTimer.singleShot(int(WATCHDOG_S * 1000), watchdog)
QTimer.singleShot(500, guarded(start))
