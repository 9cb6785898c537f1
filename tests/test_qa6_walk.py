"""Stop 42 qa6: a walk through the real clients (a live service with httpx and schemathesis,
``camloc batch`` read back with geopandas, the annotation page in Chromium), the faults found
(each test fails without its fix)."""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import Any

import httpx
import pytest

from camloc_geo.service import create_app
from camloc_geo.service.settings import Settings

REPO = Path(__file__).resolve().parent.parent


def _get(
    tmp_path: Path, path: str, params: dict[str, str], map_dir: Path | None = None
) -> httpx.Response:
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0, map_dir=map_dir))

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.get(path, params=params)

    try:
        return asyncio.run(run())
    finally:
        app.state.compute.shutdown()


def test_a_refused_street_pair_is_quoted_once(tmp_path: Path) -> None:
    """``GET /v1/corners?streets=Mikonkatu`` (schemathesis, then by hand) answered
    "streets: Value error, give two street names, as "A & B" (got 'Mikonkatu') (got
    'Mikonkatu')": pydantic's prefix, and the value quoted twice."""
    r = _get(tmp_path, "/v1/corners", {"lat": "60.17", "lon": "24.945", "streets": "Mikonkatu"})
    assert r.status_code == 422, r.text
    msg = r.json()["error"]["message"]
    assert msg == "streets: give two street names, as \"A & B\" (got 'Mikonkatu')"


def test_a_long_bad_value_is_quoted_short(tmp_path: Path) -> None:
    """A 5000-character ``streets`` was quoted whole in the one-line message (10 kB answer)."""
    r = _get(tmp_path, "/v1/corners", {"lat": "60.17", "lon": "24.945", "streets": "x" * 5000})
    assert r.status_code == 422, r.text
    msg = r.json()["error"]["message"]
    assert msg.startswith("streets: String should have at most 200 characters (got 'xxx")
    assert len(msg) < 200, msg
    assert msg.endswith("...')")


@pytest.mark.parametrize(
    ("lat", "lon", "want"),
    [
        ("60.1697 N", "24.9455 E", (60.1697, 24.9455)),
        ("N 60.1697", "E24.9455", (60.1697, 24.9455)),
        ("60.1697°", "24.9455°", (60.1697, 24.9455)),
        ("39°17'8.2\"N", "76°35'36.6\"W", (39.285611, -76.5935)),
        ("39° 17.137' N", "76° 35.61' W", (39.285617, -76.5935)),
        ("33°51′54″S", "151°12′36″E", (-33.865, 151.21)),
        ("60,1697 N", "24,9455 E", (60.1697, 24.9455)),
    ],
)
def test_a_list_point_written_with_hemisphere_letters_is_read(
    lat: str, lon: str, want: tuple[float, float]
) -> None:
    """A webcam list copied from a map site (``60.1697 N``, ``76°35'36.6"W``): every such
    point was "lat '60.1697 N' is not a number", the camera searched by its title alone
    (``camloc batch``, ``POST /v1/jobs``, QGIS ``camloc:geocodelist``, ``camloc geocode
    --list``)."""
    from camloc_geo.cameras._list import row_from_mapping
    from camloc_geo.cli.geocode import _point_of

    row = row_from_mapping({"id": "c", "title": "A & B", "lat": lat, "lon": lon}, 1)
    assert not row.problems, row.problems
    assert (row.lat, row.lon) == pytest.approx(want, abs=1e-5)
    point, problem = _point_of(lat, lon)
    assert problem is None
    assert point == pytest.approx(want, abs=1e-5)


@pytest.mark.parametrize(
    ("lat", "lon", "words"),
    [
        ("24.9455 E", "60.1697 N", "is a longitude (E/W), not a latitude: are the list's lat"),
        ("60.1697", "-24.9 W", "has both a sign and the hemisphere W"),
        ("60°75'N", "24.9", "has minutes or seconds of 60 or more"),
        ("N 60.1 N", "24.9", "has two hemisphere letters"),
        ("sixty", "24.9", "is not a number"),
    ],
)
def test_a_coordinate_near_a_written_one_says_what_is_wrong(lat: str, lon: str, words: str) -> None:
    from camloc_geo.cameras._list import row_from_mapping

    row = row_from_mapping({"id": "c", "title": "A & B", "lat": lat, "lon": lon}, 1)
    assert row.lat is None
    assert row.lon is None
    assert any(words in p for p in row.problems), row.problems


@pytest.mark.parametrize("path", ["/v1/corners", "/v1/streets"])
def test_a_swapped_point_is_named_by_the_service(tmp_path: Path, path: str) -> None:
    """``GET /v1/corners?lat=24.9455&lon=60.1699`` (Helsinki, lat and lon the other way
    round) answered only "no map data configured on this server covers lat=24.945500,
    lon=60.169900", where ``camloc batch`` names the swap."""
    import shutil

    maps = tmp_path / "maps"
    maps.mkdir()
    shutil.copy(REPO / "data" / "osm" / "helsinki.osm.pbf", maps)
    r = _get(tmp_path, path, {"lat": "24.9455", "lon": "60.1699"}, map_dir=maps)
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["type"] == "map_data"
    assert err["message"] == (
        "no map data configured on this server covers lat=24.945500, lon=60.169900; with lat "
        "and lon swapped, lat=60.169900, lon=24.945500 lies in a map (in helsinki.osm.pbf): "
        "are lat and lon the other way round?"
    )
    # a point in no map either way is answered as before
    r = _get(tmp_path, path, {"lat": "10.0", "lon": "20.0"}, map_dir=maps)
    assert r.json()["error"]["message"] == (
        "no map data configured on this server covers lat=10.000000, lon=20.000000"
    )


def _page_config(html: str) -> dict[str, Any]:
    import json
    import re

    m = re.search(r'<script id="camloc-config" type="application/json">(.*?)</script>', html, re.S)
    assert m is not None
    return dict(json.loads(m.group(1)))


def test_a_crowd_tasks_page_shows_its_junction(tmp_path: Path) -> None:
    """``POST /v1/tasks?lat=&lon=`` at a junction the server's maps hold: its page
    (``GET /annotate/{task}``) had no map, where ``camloc annotate --osm --lat --lon`` shows
    the junction with its kerb corners numbered. Annotators were asked for the corners
    "clockwise" with nothing to see them on, and the scene they sent named no junction."""
    import json
    import shutil

    import cv2
    import numpy as np

    scene = json.loads((REPO / "sample_maps" / "sample_scene.json").read_text())
    maps = tmp_path / "maps"
    maps.mkdir()
    shutil.copy(REPO / "sample_maps" / "baltimore.osm.pbf", maps)
    w, h = scene["image"]["width"], scene["image"]["height"]
    ok, buf = cv2.imencode(".png", np.full((h, w, 3), 128, np.uint8))
    assert ok
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0, map_dir=maps))

    async def run() -> tuple[dict[str, Any], dict[str, Any]]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            pages = []
            for params in (
                {
                    "annotations": "1",
                    "lat": str(scene["prior"]["lat"]),
                    "lon": str(scene["prior"]["lon"]),
                },
                {"annotations": "1"},
            ):
                r = await client.post(
                    "/v1/tasks",
                    content=bytes(buf.tobytes()),
                    headers={"content-type": "image/png"},
                    params=params,
                )
                assert r.status_code == 201, r.text
                page = await client.get(r.json()["annotate_url"])
                assert page.status_code == 200, page.text
                pages.append(_page_config(page.text))
            return pages[0], pages[1]

    try:
        with_point, without = asyncio.run(run())
    finally:
        app.state.compute.shutdown()
    feats = with_point["corners"]["features"]
    kinds = [f["properties"]["kind"] for f in feats]
    assert kinds[0] == "intersection"
    assert len(feats[0]["properties"]["streets"]) >= 2
    # the junction nearest the task's point, as camloc annotate --osm --lat --lon draws it
    assert kinds.count("corner") >= 2
    assert "street" in kinds
    assert without["corners"] is None  # no point: no map, as before


def test_a_scheduler_address_where_nothing_answers_says_so(tmp_path: Path) -> None:
    """``camloc batch --scheduler tcp://127.0.0.1:9999`` with no scheduler there ended after
    30 s with "failed: OSError: Timed out trying to connect to tcp://127.0.0.1:9999 after 30
    s" and no word of what to do."""
    import socket

    dask = pytest.importorskip("dask")
    pytest.importorskip("distributed")
    from camloc_geo.batch import run_batch

    with socket.socket() as s:  # a port where nothing listens
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    cams = tmp_path / "cams.csv"
    cams.write_text("id,title\nc1,A & B\n", encoding="utf-8")
    with (
        dask.config.set({"distributed.comm.timeouts.connect": "1s"}),
        pytest.raises(OSError, match=r"no Dask scheduler answered at tcp://127\.0\.0\.1:") as err,
    ):
        run_batch(
            cams,
            out_gpkg=tmp_path / "out.gpkg",
            scheduler=f"tcp://127.0.0.1:{port}",
            progress=False,
        )
    assert "leave --scheduler out to run on local processes" in str(err.value)


def test_a_body_without_a_content_type_is_named_as_such(tmp_path: Path) -> None:
    """A CSV list posted with no Content-Type (httpx's ``content=``) was "content type 'none'
    not supported here", and ``curl --data-binary @cams.csv`` (form-urlencoded) gave no hint of
    the header to add."""
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> list[httpx.Response]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            body = b"id,title\nc1,A & B\n"
            return [
                await client.post("/v1/jobs", content=body),
                await client.post(
                    "/v1/jobs",
                    content=body,
                    headers={"content-type": "application/x-www-form-urlencoded"},
                ),
            ]

    try:
        none, form = asyncio.run(run())
    finally:
        app.state.compute.shutdown()
    assert none.status_code == 415
    assert none.json()["error"]["message"] == (
        "the request has no Content-Type header; send application/json or text/csv (curl: "
        "-H 'Content-Type: application/json' or -H 'Content-Type: text/csv')"
    )
    assert form.status_code == 415
    assert form.json()["error"]["message"].endswith(
        "(curl's --data and --data-binary send application/x-www-form-urlencoded unless given "
        "-H 'Content-Type: application/json' or -H 'Content-Type: text/csv')"
    )


@pytest.mark.parametrize(
    ("command", "osm", "where"),
    [
        ("corners", "helsinki.osm.pbf", "the extract"),
        ("streets", "helsinki.osm.pbf", "the extract"),
        ("corners", "", "helsinki.osm.pbf"),
    ],
)
def test_swapped_lat_lon_on_the_command_line_are_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, osm: str, where: str
) -> None:
    """``camloc corners --lat 24.9455 --lon 60.1699 --osm helsinki.osm.pbf`` (lon first, as
    GeoJSON writes it): "outside the extract" with no word that the other way round it is
    inside, as ``camloc batch``, the service and QGIS say."""
    import shutil

    from camloc_geo.cli import main

    maps = tmp_path / "maps"
    maps.mkdir()
    shutil.copy(REPO / "data" / "osm" / "helsinki.osm.pbf", maps)
    shutil.copy(REPO / "sample_maps" / "fremantle.osm", maps)
    source = maps / osm if osm else maps
    assert main([command, "--lat", "24.9455", "--lon", "60.1699", "--osm", str(source)]) == 2
    err = capsys.readouterr().err
    assert err.rstrip().endswith(
        f"; with --lat and --lon swapped (--lat 60.1699 --lon 24.9455) the point lies in "
        f"{where}: are they the other way round?"
    ), err
    # a point in no map either way: no hint
    assert main([command, "--lat", "10", "--lon", "20", "--osm", str(source)]) == 2
    assert "swapped" not in capsys.readouterr().err


def test_a_verdict_key_of_the_wrong_shape_is_explained(tmp_path: Path) -> None:
    """``POST /v1/verdicts/candidates/{identity}`` with an item key ``x`` (schemathesis): the
    answer quoted a regular expression, "items.x.[key]: String should match pattern
    '^c?[0-9]{1,6}$' (got 'x')"."""
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.post(
                "/v1/verdicts/candidates/0123456789abcdef",
                json={"items": {"rank1": {"verdict": "yes"}}},
            )

    try:
        r = asyncio.run(run())
    finally:
        app.state.compute.shutdown()
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["message"] == (
        "items: 'rank1' is not a key of the page's items: a candidate's rank on a review page "
        "('1', '2', ...) or 'c' and a camera's index on a summary page ('c0', 'c1', ...), as its "
        "export gives them"
    )
    assert err["field"] == "items.rank1.[key]"  # as before


def test_a_crowd_page_whose_junction_is_slow_comes_without_its_map(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The junction map of a task's page is looked up under the request's time limit; past
    it (a large extract read cold), the page comes as before, without the map, not a 503."""
    import time

    import cv2
    import numpy as np

    from camloc_geo.service.routers import crowd

    def slow(maps: Any, lat: float, lon: float) -> None:
        time.sleep(1.0)

    monkeypatch.setattr(crowd, "junction_work", slow)
    ok, buf = cv2.imencode(".png", np.full((64, 64, 3), 128, np.uint8))
    assert ok
    # network on: the task is accepted without an extract (the slow lookup stands in for one)
    app = create_app(
        Settings(data_dir=tmp_path / "d", workers=0, network=True, request_timeout_s=0.2)
    )

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            r = await client.post(
                "/v1/tasks",
                content=bytes(buf.tobytes()),
                headers={"content-type": "image/png"},
                params={"annotations": "1", "lat": "60.17", "lon": "24.945"},
            )
            assert r.status_code == 201, r.text
            return await client.get(r.json()["annotate_url"])

    try:
        page = asyncio.run(run())
    finally:
        app.state.compute.shutdown()
    assert page.status_code == 200, page.text
    assert _page_config(page.text)["corners"] is None
