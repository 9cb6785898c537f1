"""The live (Overpass via osmnx) path, against a local HTTP server: never the internet."""

from __future__ import annotations

import http.server
import json
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import ClassVar
from urllib.parse import unquote_plus

import osmnx as ox
import pytest

from camloc_geo import MapDataError, MapSourceError
from camloc_geo.osm import clear_cache, load_map

DATA = Path(__file__).resolve().parent / "data" / "overpass"
LAT, LON = 39.28549, -76.59535  # Eastern Avenue & South Bond Street, Baltimore


class _Handler(http.server.BaseHTTPRequestHandler):
    responses: ClassVar[dict[str, bytes]] = {}
    queries: ClassVar[list[str]] = []

    def do_POST(self) -> None:
        length = int(self.headers.get("Content-Length", "0"))
        body = self.rfile.read(length).decode("utf-8", "replace")
        type(self).queries.append(body)
        key = "streets" if "highway" in body else "buildings"
        payload = type(self).responses[key]
        self.send_response(200)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(payload)))
        self.end_headers()
        self.wfile.write(payload)

    do_GET = do_POST  # noqa: N815

    def log_message(self, format: str, *args: object) -> None:
        pass


@pytest.fixture
def overpass_server() -> Iterator[tuple[str, type[_Handler]]]:
    handler = type("Handler", (_Handler,), {"queries": []})
    handler.responses = {
        "streets": (DATA / "baltimore_streets.json").read_bytes(),
        "buildings": (DATA / "baltimore_buildings.json").read_bytes(),
    }
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/api", handler
    finally:
        server.shutdown()
        server.server_close()
        thread.join(5)


def _settings_snapshot() -> dict[str, object]:
    keys = ("overpass_url", "cache_folder", "use_cache", "overpass_rate_limit", "requests_timeout")
    return {k: getattr(ox.settings, k) for k in keys}


def test_online_load_uses_server_cache_and_restores_settings(
    overpass_server: tuple[str, type[_Handler]], tmp_path: Path
) -> None:
    url, handler = overpass_server
    before = _settings_snapshot()
    clear_cache()
    m = load_map(
        None,
        LAT,
        LON,
        radius_m=100,
        cache_folder=tmp_path / "cache",
        overpass_url=url,
        overpass_rate_limit=False,
        timeout_s=5,
    )
    assert _settings_snapshot() == before
    # streets (one query per filter: the street highways, named service/pedestrian), buildings
    assert len(handler.queries) == 3
    decoded = [unquote_plus(q) for q in handler.queries]
    assert any("residential" in q for q in decoded)
    assert any('["name"]' in q and "service" in q for q in decoded)
    x = m.find_intersection("Eastern Ave & S Bond St")
    assert x.kind == "junction"
    assert len(x.corners) == 4
    assert {s.name for s in x.streets} == {"Eastern Avenue", "South Bond Street"}
    assert len(m.buildings) >= 2
    assert all(b.id.startswith("way/") for b in m.buildings)
    assert list((tmp_path / "cache").iterdir())  # osmnx HTTP cache written

    # same area again: in-process cache, no request
    assert load_map(None, LAT, LON, radius_m=100, overpass_url=url) is m
    assert len(handler.queries) == 3

    # new process state: osmnx's HTTP cache answers, still no request
    clear_cache()
    m2 = load_map(
        None,
        LAT,
        LON,
        radius_m=100,
        cache_folder=tmp_path / "cache",
        overpass_url=url,
        overpass_rate_limit=False,
        timeout_s=5,  # part of the query text, hence of osmnx's cache key
    )
    assert len(handler.queries) == 3
    assert m2.find_intersection("Eastern Avenue & South Bond Street").id == x.id
    clear_cache()


def test_online_matches_offline_extract(
    overpass_server: tuple[str, type[_Handler]], tmp_path: Path
) -> None:
    extract = Path(__file__).resolve().parents[1] / "data" / "osm" / "baltimore.osm.pbf"
    url, _handler = overpass_server
    clear_cache()
    online = load_map(
        None, LAT, LON, 60, cache_folder=tmp_path, overpass_url=url, overpass_rate_limit=False
    )
    offline = load_map(extract, LAT, LON, 60)
    a = online.find_intersection("Eastern Ave & S Bond St")
    b = offline.find_intersection("Eastern Ave & S Bond St")
    assert a.id == b.id
    assert [c.streets for c in a.corners] == [c.streets for c in b.corners]
    for ca, cb in zip(a.corners, b.corners, strict=True):
        assert ca.lat == pytest.approx(cb.lat, abs=1e-7)
        assert ca.lon == pytest.approx(cb.lon, abs=1e-7)
    clear_cache()


def test_network_error_is_map_source_error(tmp_path: Path) -> None:
    clear_cache()
    before = _settings_snapshot()
    with pytest.raises(MapSourceError, match="Overpass"):
        load_map(
            None,
            LAT,
            LON,
            100,
            cache_folder=tmp_path,
            overpass_url="http://127.0.0.1:9/api",
            overpass_rate_limit=False,
            timeout_s=2,
        )
    assert _settings_snapshot() == before


def test_empty_response_is_map_data_error(
    overpass_server: tuple[str, type[_Handler]], tmp_path: Path
) -> None:
    url, handler = overpass_server
    handler.responses = {k: json.dumps({"elements": []}).encode() for k in ("streets", "buildings")}
    clear_cache()
    with pytest.raises(MapDataError, match="no streets"):
        load_map(
            None,
            10.0,
            10.0,
            100,
            cache_folder=tmp_path,
            overpass_url=url,
            overpass_rate_limit=False,
        )


def test_non_json_answer_is_map_source_error(
    overpass_server: tuple[str, type[_Handler]], tmp_path: Path
) -> None:
    url, handler = overpass_server
    handler.responses = dict.fromkeys(("streets", "buildings"), b"<html>rate limited</html>")
    clear_cache()
    with pytest.raises(MapSourceError, match="Overpass"):
        load_map(
            None,
            11.0,
            11.0,
            100,
            cache_folder=tmp_path,
            overpass_url=url,
            overpass_rate_limit=False,
        )
