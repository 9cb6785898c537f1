"""Session 39 QA: ``POST /v1/jobs`` with a GeoJSON camera list.

``camloc batch`` reads a GeoJSON list (a QGIS or GDAL export: properties as columns, a Point
as the camera's point); the service, whose lists are documented as read by batch's reader,
refused it: 422 'the body must be {"cameras": [...]}'.
"""

from __future__ import annotations

import asyncio
import json
from pathlib import Path

import httpx

from camloc_geo.service import create_app
from camloc_geo.service.routers.jobs import camera_records
from camloc_geo.service.settings import Settings

SCENE = Path(__file__).resolve().parents[1] / "sample_maps" / "sample_scene.json"


def _feature(props: dict[str, object], geometry: object = None, **extra: object) -> dict:
    return {"type": "Feature", "geometry": geometry, "properties": props, **extra}


def _collection() -> dict:
    return {
        "type": "FeatureCollection",
        "features": [
            _feature(
                {"title": "Eastern Ave & S Broadway"},
                {"type": "Point", "coordinates": [-76.5935, 39.2856]},
                id="c1",
            ),
            _feature(
                {"id": "c2", "title": "Fleet St & S Broadway"},
                {"type": "Point", "coordinates": [360000.0, 4350000.0]},
            ),
            _feature({"id": "c3", "scene": json.loads(SCENE.read_text(encoding="utf-8"))}),
            _feature({"id": "c4", "title": "Thames St & S Broadway", "scene": "/etc/cam.json"}),
        ],
    }


def test_a_geojson_list_is_read_as_camloc_batch_reads_it() -> None:
    raw = json.dumps(_collection()).encode()
    cams = camera_records(raw, "application/json", 10)
    assert [c["id"] for c in cams] == ["c1", "c2", "c3", "c4"]
    assert (cams[0]["lat"], cams[0]["lon"]) == (39.2856, -76.5935)
    assert "lat" not in cams[1]
    assert "projected coordinates" in " ".join(cams[1]["problems"])
    assert cams[2]["scene"]["id"] == "baltimore-eastern-broadway"  # inline scene kept
    assert "scene" not in cams[3]  # a server file is never named by a client
    assert "a scene must be given inline" in " ".join(cams[3]["problems"])


def test_a_geojson_list_is_a_job(tmp_path: Path) -> None:
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.post(
                "/v1/jobs",
                content=json.dumps(_collection()).encode(),
                headers={"content-type": "application/json"},
            )

    try:
        r = asyncio.run(run())
    finally:
        app.state.compute.shutdown()
    assert r.status_code == 202, r.text
    assert r.json()["total"] == 4
