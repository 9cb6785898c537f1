"""Session 39 QA: the service through an HTTP client.

- ``OPTIONS`` (or ``PUT``, ``DELETE``) on ``/v1/verdicts/{page}/{identity}`` was a 405 with
  ``Allow: GET``, though the path takes ``POST`` too: Starlette names the methods of the
  first route matching the path only. ``DELETE /healthz`` said ``Allow: GET`` (it takes
  ``HEAD``).
"""

from __future__ import annotations

import asyncio
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
        ("OPTIONS", PAGE, "GET, POST"),
        ("PUT", PAGE, "GET, POST"),
        ("DELETE", PAGE, "GET, POST"),
        ("DELETE", "/healthz", "GET, HEAD"),
        ("OPTIONS", "/v1/verdicts", "GET"),
        ("GET", "/v1/locate", "POST"),
        ("OPTIONS", "/v1/jobs/abc", "GET"),
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
