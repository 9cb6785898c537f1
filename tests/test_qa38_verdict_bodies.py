"""Session 38 QA: ``POST /v1/verdicts/...`` bodies that are not JSON.

- A GeoPackage (binary) posted as ``application/json`` was a 400 ``http_error`` "There was
  an error parsing the body", a status the service documents for nothing; bad input is 422
  naming ``body``.
- A body that is no valid JSON (``\\xff\\xfe{}``) was 422 with the field ``"0"`` (the
  position FastAPI put in its location), message "0: JSON decode error".
- A CSV body was 422 "request: Input should be a valid dictionary"; another content type is
  415 naming ``content-type``, as on every other write endpoint.
"""

from __future__ import annotations

import asyncio
from pathlib import Path

import httpx
import pytest

from camloc_geo.service import create_app
from camloc_geo.service.settings import Settings

URL = "/v1/verdicts/summary/0123456789abcdef"


def _post(tmp_path: Path, body: bytes, ctype: str) -> httpx.Response:
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.post(URL, content=body, headers={"content-type": ctype})

    try:
        return asyncio.run(run())
    finally:
        app.state.compute.shutdown()


@pytest.mark.parametrize(
    "body",
    [
        b"SQLite format 3\x00\x10\x00\x01\x01\x00@  \xd8\x9b\x00\x00\xff",
        b"\xff\xfe{}",
        b'{"items": ',
    ],
)
def test_a_body_that_is_no_json_is_a_422_naming_body(tmp_path: Path, body: bytes) -> None:
    r = _post(tmp_path, body, "application/json")
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["field"] == "body"
    assert err["message"].startswith("body: the body is not valid JSON")


def test_another_content_type_is_a_415(tmp_path: Path) -> None:
    r = _post(tmp_path, b"camera,verdict\nc1,yes\n", "text/csv")
    assert r.status_code == 415, r.text
    assert r.json()["error"]["field"] == "content-type"


def test_a_json_post_still_lands(tmp_path: Path) -> None:
    r = _post(tmp_path, b'{"items": {"c1": {"verdict": "yes"}}}', "application/json")
    assert r.status_code == 200, r.text
    assert r.json()["taken"] == ["c1"]
