"""The analyst's dock: a scripted annotation, the map pick, run, save; screenshots."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import HERE, SAMPLE_OSM, SAMPLE_SCENE, metres_between, truth
from qgis.core import (
    QgsCoordinateReferenceSystem,
    QgsCoordinateTransform,
    QgsMapRendererSequentialJob,
    QgsMapSettings,
    QgsPointXY,
    QgsProject,
    QgsVectorLayer,
)
from qgis.PyQt.QtCore import QPointF, QSize, Qt
from qgis.PyQt.QtGui import QColor, QImage, QPainter, QPen, QPolygonF
from qgis.PyQt.QtTest import QTest

EXPECTED = HERE / "data" / "expected_scene.json"
PICK = (39.2856, -76.5935)  # lat, lon of the intersection clicked on the map


def _snapshot(path: Path) -> Path:
    """A 1920x1080 drawing of the sample's street: road, kerbs and the car's box."""
    scene = json.loads(SAMPLE_SCENE.read_text())
    img = QImage(1920, 1080, QImage.Format_RGB32)
    img.fill(QColor("#9db7c9"))
    p = QPainter(img)
    p.setRenderHint(QPainter.Antialiasing)
    p.setBrush(QColor("#6e6e6e"))
    p.setPen(Qt.NoPen)
    p.drawPolygon(
        QPolygonF([QPointF(0, 430), QPointF(1920, 480), QPointF(1920, 1080), QPointF(0, 1080)])
    )
    corners = scene["intersection"]["corners"]
    p.setPen(QPen(QColor("#e0e0e0"), 5))
    for x, y in corners:
        p.drawLine(QPointF(x - 120, y + 10), QPointF(x + 120, y - 10))
    ann = scene["annotations"][0]
    p.setPen(QPen(QColor("#202020"), 3))
    p.setBrush(QColor("#b22222"))
    ax = ann["axes"]
    o, ln, w, h = (QPointF(*ax[k]) for k in ("origin", "length", "width", "height"))
    p.drawPolygon(QPolygonF([o, ln, ln + (w - o), w]))
    up = h - o
    p.drawPolygon(QPolygonF([o + up, ln + up, ln + (w - o) + up, w + up]))
    for a in (o, ln, w, ln + (w - o)):
        p.drawLine(a, a + up)
    p.end()
    assert img.save(str(path))
    return path


@pytest.fixture
def dock(qgis_iface, qgis_new_project, provider):
    from camloc.dock import CamlocDock

    d = CamlocDock(qgis_iface)
    d.resize(480, 820)
    d.show()
    yield d
    d.close()
    d.deleteLater()


def _annotate(dock) -> None:
    """The analyst's clicks, replayed through the image view's click signal."""
    ann = json.loads(SAMPLE_SCENE.read_text())["annotations"][0]
    click = dock.view.clicked.emit
    dock.set_step("origin")
    for key in ("origin", "length", "width", "height"):
        click(*ann["axes"][key])
    assert dock.annotation.step == "lines_length"  # the point steps advance by themselves
    for axis in ("length", "width", "height"):
        dock.set_step(f"lines_{axis}")
        for x1, y1, x2, y2 in ann["vp_lines"][axis]:
            click(x1, y1)
            click(x2, y2)
    dock.set_step("corners")
    for x, y in json.loads(SAMPLE_SCENE.read_text())["intersection"]["corners"]:
        click(x, y)


def _pick_on_canvas(dock, qgis_iface) -> None:
    """Pick the intersection with the map tool on a canvas in Web Mercator."""
    canvas = qgis_iface.mapCanvas()
    merc = QgsCoordinateReferenceSystem("EPSG:3857")
    canvas.setDestinationCrs(merc)
    xf = QgsCoordinateTransform(
        QgsCoordinateReferenceSystem("EPSG:4326"), merc, QgsProject.instance()
    )
    pt = xf.transform(QgsPointXY(PICK[1], PICK[0]))
    dock.pick_button.setChecked(True)
    assert canvas.mapTool() is dock.map_tool
    dock.map_tool.canvasClicked.emit(pt, Qt.LeftButton)
    assert not dock.pick_button.isChecked()


def test_dock_mouse_click_lands_on_the_image_pixel(dock, tmp_path):
    assert dock.open_snapshot(str(_snapshot(tmp_path / "snapshot.png")))
    dock.set_step("origin")
    target = QPointF(1363.4, 592.9)
    QTest.mouseClick(
        dock.view.viewport(), Qt.LeftButton, Qt.NoModifier, dock.view.mapFromScene(target)
    )
    x, y = dock.annotation.axes["origin"]
    scale = 1920 / dock.view.viewport().width()
    assert abs(x - target.x()) <= 2 * scale
    assert abs(y - target.y()) <= 2 * scale


def test_dock_scripted_annotation_saves_the_expected_scene(dock, qgis_iface, tmp_path, artifacts):
    assert dock.open_snapshot(str(_snapshot(tmp_path / "snapshot.png")))
    assert dock.annotation.problems()
    _annotate(dock)
    _pick_on_canvas(dock, qgis_iface)
    dock.streets_edit.setText("Eastern Avenue & South Broadway")
    assert dock.annotation.problems() == []
    out = tmp_path / "scene.json"
    assert dock.save_scene(str(out)), dock.status.text()
    assert json.loads(out.read_text()) == json.loads(EXPECTED.read_text())
    dock.grab().save(str(artifacts / "dock.png"))


def test_dock_refuses_to_save_an_invalid_scene(dock, tmp_path):
    assert dock.open_snapshot(str(_snapshot(tmp_path / "snapshot.png")))
    out = tmp_path / "scene.json"
    dock.annotation.set_location(lat=39.2856, lon=-76.5935)
    dock.annotation.radius_m = 0.0  # the library's check names the field
    assert not dock.save_scene(str(out))
    assert "prior.radius_m" in dock.status.text()
    assert not out.exists()


def test_dock_run_adds_candidate_layers_in_any_project_crs(dock, qgis_iface, tmp_path, artifacts):
    assert dock.open_snapshot(str(_snapshot(tmp_path / "snapshot.png")))
    _annotate(dock)
    _pick_on_canvas(dock, qgis_iface)
    dock.osm_edit.setText(str(SAMPLE_OSM))
    layers = dock.run()
    assert [lyr.name() for lyr in layers] == [
        "camloc view cones",
        "camloc intersection",
        "camloc matched corners",
        "camloc candidates",
    ]
    project = QgsProject.instance()
    assert all(project.mapLayer(lyr.id()) is not None for lyr in layers)
    cands = layers[-1]
    assert cands.crs().authid() == "EPSG:4326"
    assert cands.featureCount() >= 2
    t = truth()
    best = min(
        metres_between(f.geometry().asPoint().y(), f.geometry().asPoint().x(), t["lat"], t["lon"])
        for f in cands.getFeatures()
    )
    # one annotator (the sample's w1) instead of three: 14 m, as the library gives for this
    # scene (the three-annotator sample is within 5 m, see test_algorithms)
    assert best < 20.0
    assert "candidate(s)" in dock.status.text()
    # the canvas (Web Mercator) shows the candidates with their styles, over the OSM streets
    streets = QgsVectorLayer(f"{SAMPLE_OSM}|layername=lines", "OSM streets", "ogr")
    assert streets.isValid()
    settings = QgsMapSettings()
    settings.setDestinationCrs(QgsCoordinateReferenceSystem("EPSG:3857"))
    settings.setOutputSize(QSize(1000, 800))
    settings.setBackgroundColor(QColor("white"))
    settings.setLayers([*reversed(layers), streets])
    ext = qgis_iface.mapCanvas().extent()  # the dock zoomed the canvas to the candidates
    to_canvas = QgsCoordinateTransform(cands.crs(), settings.destinationCrs(), project)
    assert ext.contains(to_canvas.transform(QgsPointXY(t["lon"], t["lat"])))
    ext = to_canvas.transformBoundingBox(layers[0].extent())
    ext.scale(1.3)
    settings.setExtent(ext)
    job = QgsMapRendererSequentialJob(settings)
    job.start()
    job.waitForFinished()
    image = job.renderedImage()
    assert image.save(str(artifacts / "canvas.png"))
    dock.grab().save(str(artifacts / "dock_after_run.png"))
