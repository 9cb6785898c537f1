"""Session 40 QA on a live service: ``GET /v1/corners?streets=`` with fewer than two names.

``streets=Eastern Ave`` (or ``" & "``) was a 422 ``map_data`` with no field, "give at least two
street names", as if the map were at fault; it is the query's: 422 ``invalid_input`` naming
``streets``, before any map is read.
"""

from __future__ import annotations

import asyncio
from pathlib import Path

import httpx
import pytest

from camloc_geo.service import create_app
from camloc_geo.service.settings import Settings


def _get(tmp_path: Path, params: dict[str, str]) -> httpx.Response:
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.get("/v1/corners", params=params)

    try:
        return asyncio.run(run())
    finally:
        app.state.compute.shutdown()


@pytest.mark.parametrize("streets", ["Eastern Ave", " & ", "Eastern Ave &"])
def test_one_street_name_is_the_querys_fault(tmp_path: Path, streets: str) -> None:
    r = _get(tmp_path, {"lat": "39.2855", "lon": "-76.5935", "streets": streets})
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["type"] == "invalid_input"
    assert err["field"] == "streets"
    assert "give two street names" in err["message"]


def test_the_root_address_says_what_the_service_is(tmp_path: Path) -> None:
    """``GET /`` in a browser was a 404 "Not Found" JSON; it is a page linking the API's
    description and health."""
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> tuple[httpx.Response, httpx.Response]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.get("/"), await client.head("/")

    try:
        page, head = asyncio.run(run())
    finally:
        app.state.compute.shutdown()
    assert page.status_code == 200
    assert page.headers["content-type"].startswith("text/html")
    for link in ('href="/docs"', 'href="/redoc"', 'href="/openapi.json"', 'href="/healthz"'):
        assert link in page.text
    assert head.status_code == 200
    assert head.content == b""


def test_a_job_maps_title_camera_shows_its_uncertainty() -> None:
    """A title-placed camera's candidate states ``uncertainty_m`` (20 m); the job map's popup
    read ``sigma_m`` and showed "—" (as ``camloc batch --map``'s page does not)."""
    from camloc_geo.service.routers.jobs import job_summary_page

    cand = {
        "type": "Feature",
        "geometry": {"type": "Point", "coordinates": [-76.5937, 39.2892]},
        "properties": {
            "rank": 1,
            "source": "title",
            "score": 0.94,
            "lat": 39.2892,
            "lon": -76.5937,
            "uncertainty_m": 20.213,
            "method": "title:junction",
            "kind": "candidate",
        },
    }
    camera = {
        "id": "c1",
        "title": "E Pratt St & S Broadway",
        "status": "title_only",
        "lat": 39.2892,
        "lon": -76.5937,
        "uncertainty_m": 20.213,
        "candidates": [cand],
    }
    page = job_summary_page([camera])
    assert "<th>sigma_m</th><td>20.21 m</td>" in page


def test_a_missing_map_is_said_in_the_servers_words(tmp_path: Path) -> None:
    """A server without map data answered a scene "no map: give --osm EXTRACT_OR_FOLDER or
    allow --network", options a client of the service does not have; a job's camera said
    "give --osm EXTRACT_OR_FOLDER" in its reason. Both name the server's map folder now."""
    import json

    from camloc_geo.service.work import process_camera

    scene = (Path(__file__).resolve().parents[1] / "sample_maps" / "sample_scene.json").read_text()
    settings = Settings(data_dir=tmp_path / "d", workers=0, map_dir=None, network=False)
    app = create_app(settings)

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.post("/v1/locate", json=json.loads(scene))

    try:
        r = asyncio.run(run())
        maps = app.state.maps
    finally:
        app.state.compute.shutdown()
    assert r.status_code == 422, r.text
    message = r.json()["error"]["message"]
    assert "this server has no map data there (its operator adds extracts to CAMLOC_MAP_DIR)" in (
        message
    )
    assert "--osm" not in message
    res = process_camera({"id": "c1", "title": "Eastern Ave & S Broadway"}, maps, settings)
    assert "--osm" not in str(res)
    assert "CAMLOC_MAP_DIR" in str(res)


def test_a_running_jobs_map_counts_the_cameras_not_done_yet() -> None:
    """A job's map opened while it ran said "0 of 0 cameras on the map" (only finished
    cameras were counted): it counts the pending ones and says to reload later."""
    from camloc_geo.service.routers.jobs import job_summary_page

    page = job_summary_page([], pending=3)
    assert "<title>camloc summary: 0 of 3 cameras on the map</title>" in page
    assert "3 cameras not done yet (the job is still running): reload the page later" in page
    done = job_summary_page([])
    assert "not done yet" not in done


def test_a_failed_tasks_page_says_why(tmp_path: Path) -> None:
    """The annotation page of a task whose located merge failed said only that it takes no
    more work; it says why it could not be located now."""
    import io

    from PIL import Image

    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))
    buf = io.BytesIO()
    Image.new("RGB", (64, 48), (90, 90, 90)).save(buf, format="PNG")
    store = app.state.store
    task_id = store.create_task(
        image=buf.getvalue(),
        image_type="png",
        width=64,
        height=48,
        needed=1,
        base_scene={"format": "camloc-scene/1", "id": "t", "image": {"width": 64, "height": 48}},
    )
    store.set_task_result(task_id, "failed", {"reason": "the annotators marked different cars"})

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.get(f"/annotate/{task_id}")

    try:
        page = asyncio.run(run())
    finally:
        app.state.compute.shutdown()
    assert page.status_code == 200, page.text
    assert "It could not be located: the annotators marked different cars" in page.text
