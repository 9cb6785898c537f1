"""Stop 42 qa6: a walk through the real clients (a live service with httpx and schemathesis,
``camloc batch`` read back with geopandas, the annotation page in Chromium), the faults found
(each test fails without its fix)."""

from __future__ import annotations

import asyncio
from pathlib import Path

import httpx

from camloc_geo.service import create_app
from camloc_geo.service.settings import Settings


def _get(tmp_path: Path, path: str, params: dict[str, str]) -> httpx.Response:
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

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
