"""Session 38 QA: ``/openapi.json`` declares the GeoPackage answer of a job's result.

``GET /v1/jobs/{id}/result?format=gpkg`` answers ``application/geopackage+sqlite3`` but the
description listed only ``application/json`` for its 200 (a schemathesis run's stateful
phase: "ST105 Undocumented Content-Type").
"""

from __future__ import annotations

from pathlib import Path

from camloc_geo.service import create_app
from camloc_geo.service.settings import Settings


def test_job_result_declares_both_media_types(tmp_path: Path) -> None:
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))
    try:
        spec = app.openapi()
    finally:
        app.state.compute.shutdown()
    ok = spec["paths"]["/v1/jobs/{job_id}/result"]["get"]["responses"]["200"]["content"]
    assert set(ok) == {"application/json", "application/geopackage+sqlite3"}
    assert ok["application/geopackage+sqlite3"]["schema"]["format"] == "binary"
