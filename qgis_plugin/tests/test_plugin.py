"""The plugin object in QGIS: set-up and tear-down, and the missing-library message."""

from __future__ import annotations

import pytest
from conftest import SAMPLE_SCENE
from qgis.core import QgsApplication, QgsProcessingException


def test_init_gui_and_unload_are_symmetric(qgis_iface, qgis_processing):
    import camloc

    reg = QgsApplication.processingRegistry()
    before = reg.providerById("camloc")
    if before is not None:
        reg.removeProvider(before)
    plugin = camloc.classFactory(qgis_iface)
    plugin.initGui()
    assert reg.providerById("camloc") is not None
    assert plugin.action is not None
    plugin.action.setChecked(True)  # opens the dock
    assert plugin.dock is not None
    assert not plugin.dock.isHidden()  # the stub main window itself is not shown
    plugin.unload()
    assert reg.providerById("camloc") is None
    assert plugin.action is None
    assert plugin.dock is None
    # and again: a reload after unload works
    plugin.initGui()
    assert reg.providerById("camloc") is not None
    plugin.unload()
    assert reg.providerById("camloc") is None


def test_processing_only_start_does_not_touch_iface(qgis_processing):
    import camloc

    reg = QgsApplication.processingRegistry()
    plugin = camloc.classFactory(None)  # what qgis_process does
    plugin.initProcessing()
    try:
        assert reg.providerById("camloc") is not None
    finally:
        reg.removeProvider(plugin.provider)


def test_missing_library_gives_a_venv_recipe_not_a_traceback(
    qgis_iface, qgis_processing, provider, monkeypatch, tmp_path
):
    import processing
    from camloc import runner

    monkeypatch.setattr(runner, "find_python", lambda refresh=False: None)
    monkeypatch.setattr(runner, "_find", lambda refresh=False: None)
    msg = runner.missing_message()
    lines = runner.install_commands()
    assert "-m venv --system-site-packages" in lines[0]
    assert "/bin/python -m pip install" in lines[1]  # into the venv, which Debian allows
    assert all(ln in msg for ln in lines)  # the whole recipe, one command a line
    assert "/usr/bin/python3 -m pip install" not in msg
    assert "camloc-geo" in msg
    assert "CAMLOC_PYTHON" in msg
    with pytest.raises(QgsProcessingException) as err:
        processing.run(
            "camloc:locate",
            {"SCENE": str(SAMPLE_SCENE), "CANDIDATES": str(tmp_path / "c.gpkg")},
        )
    assert "-m venv" in str(err.value)
    assert "Traceback" not in str(err.value)

    # the GUI start shows the same message in the message bar
    import camloc

    pushed = []
    monkeypatch.setattr(
        qgis_iface.messageBar(), "pushMessage", lambda *a, **k: pushed.append(a), raising=False
    )
    monkeypatch.setattr(
        qgis_iface.messageBar(),
        "pushWidget",
        lambda w, *a, **k: pushed.append((w.text(),)),
        raising=False,
    )
    reg = QgsApplication.processingRegistry()
    reg.removeProvider(reg.providerById("camloc"))
    plugin = camloc.classFactory(qgis_iface)
    plugin.initGui()
    try:
        # the bar shows a short line and a button for the whole recipe (never cut)
        assert any("camloc_geo" in " ".join(map(str, a)) for a in pushed)
        assert plugin.missing_dialog_text() == msg
    finally:
        plugin.unload()


def test_worker_interpreter_from_camloc_python(monkeypatch, tmp_path):
    import sys

    from camloc import runner

    monkeypatch.setenv("CAMLOC_PYTHON", str(tmp_path / "no-such-python"))
    # an unusable CAMLOC_PYTHON falls through to the next interpreter that has camloc_geo
    found = runner.find_python(refresh=True)
    assert found is not None
    monkeypatch.setenv("CAMLOC_PYTHON", sys.executable)
    assert runner.find_python(refresh=True) == sys.executable
