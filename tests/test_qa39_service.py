"""Session 39 QA: the service through an HTTP client.

- ``OPTIONS`` (or ``PUT``, ``DELETE``) on ``/v1/verdicts/{page}/{identity}`` was a 405 with
  ``Allow: GET``, though the path takes ``POST`` too: Starlette names the methods of the
  first route matching the path only. ``DELETE /healthz`` said ``Allow: GET`` (it takes
  ``HEAD``).
"""

from __future__ import annotations

import asyncio
import re
from pathlib import Path

import httpx
import pytest

from camloc_geo.service import create_app
from camloc_geo.service.settings import Settings

PAGE = "/v1/verdicts/summary/0123456789abcdef"


def _calls(tmp_path: Path, calls: list[tuple[str, str]]) -> list[httpx.Response]:
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> list[httpx.Response]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return [await client.request(method, url) for method, url in calls]

    try:
        return asyncio.run(run())
    finally:
        app.state.compute.shutdown()


@pytest.mark.parametrize(
    ("method", "url", "allow"),
    [
        ("OPTIONS", PAGE, "GET, HEAD, POST"),
        ("PUT", PAGE, "GET, HEAD, POST"),
        ("DELETE", PAGE, "GET, HEAD, POST"),
        ("DELETE", "/healthz", "GET, HEAD"),
        ("OPTIONS", "/v1/verdicts", "GET, HEAD"),
        ("GET", "/v1/locate", "POST"),
        ("OPTIONS", "/v1/jobs/abc", "GET, HEAD"),
    ],
)
def test_a_405_names_every_method_the_path_takes(
    tmp_path: Path, method: str, url: str, allow: str
) -> None:
    (r,) = _calls(tmp_path, [(method, url)])
    assert r.status_code == 405, r.text
    assert r.headers["allow"] == allow
    err = r.json()["error"]
    assert err["type"] == "method_not_allowed"
    assert err["message"] == f"method {method} not allowed here; allowed: {allow}"


def test_redoc_draws_no_image_from_another_site(tmp_path: Path) -> None:
    """ReDoc's bundle loads its maker's logo from https://cdn.redoc.ly: the offline docs
    page made a request to another site (Chromium: net::ERR_NAME_NOT_RESOLVED offline)."""
    pytest.importorskip("fastapi_offline")
    (r,) = _calls(tmp_path, [("GET", "/redoc")])
    assert r.status_code == 200
    assert r.headers["content-security-policy"] == "img-src 'self' data: blob:"
    assert "cdn.redoc.ly" not in r.text
    (script,) = [s for s in re.findall(r'<script src="([^"]+)"', r.text) if "redoc" in s]
    (js,) = _calls(tmp_path / "js", [("GET", script)])
    assert js.status_code == 200
    assert len(js.content) > 500_000  # the whole bundle
    assert b"https://cdn.redoc.ly" not in js.content
    assert b'src:"/favicon.ico"' in js.content


@pytest.mark.parametrize("url", ["/v1/verdicts", PAGE, "/docs", "/openapi.json", "/favicon.ico"])
def test_head_answers_as_get_without_a_body(tmp_path: Path, url: str) -> None:
    """``curl -I`` (link checkers, uptime probes) got a 405 from every page but /healthz."""
    head, get = _calls(tmp_path, [("HEAD", url), ("GET", url)])
    assert get.status_code == 200, get.text
    assert head.status_code == 200
    assert head.content == b""
    assert head.headers["content-type"] == get.headers["content-type"]
    assert head.headers["content-length"] == get.headers["content-length"]
    assert "x-request-id" in head.headers


def test_head_of_a_missing_job_is_its_404(tmp_path: Path) -> None:
    (r,) = _calls(tmp_path, [("HEAD", "/v1/jobs/" + "0" * 32 + "/map")])
    assert r.status_code == 404
    assert r.content == b""
