"""Service fixes of QA sweep 37b: query values that are not finite numbers are named so, and
the served pages leave a browser's console clean (``/favicon.ico``)."""

from __future__ import annotations

import asyncio
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from test_service import Server

from camloc_geo.service import create_app
from camloc_geo.service.settings import Settings

needs_browser = pytest.mark.skipif(
    not Path("/usr/bin/chromium").exists(), reason="Debian chromium is not installed"
)


def _answers(tmp_path: Path, requests: list[tuple[str, str]]) -> list[httpx.Response]:
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> list[httpx.Response]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return [await client.request(method, url) for method, url in requests]

    try:
        return asyncio.run(run())
    finally:
        app.state.compute.shutdown()


@pytest.mark.parametrize(
    ("method", "url", "field", "value"),
    [
        ("GET", "/v1/streets?lat=nan&lon=-76.59", "lat", "nan"),
        ("GET", "/v1/corners?lat=39.28&lon=inf", "lon", "inf"),
        ("GET", "/v1/streets?lat=39.28&lon=-76.59&radius_m=nan", "radius_m", "nan"),
        ("POST", "/v1/tasks?lat=nan&lon=-76.59", "lat", "nan"),
    ],
)
def test_query_value_not_finite_is_named(
    tmp_path: Path, method: str, url: str, field: str, value: str
) -> None:
    (r,) = _answers(tmp_path, [(method, url)])
    assert r.status_code == 422
    error = r.json()["error"]
    assert error["type"] == "invalid_input"
    assert error["field"] == field
    assert error["message"] == f"{field}: Input should be a finite number (got '{value}')"
    assert "less than or equal" not in error["message"]


def test_out_of_range_still_says_the_range(tmp_path: Path) -> None:
    (r,) = _answers(tmp_path, [("GET", "/v1/streets?lat=100&lon=1")])
    assert r.status_code == 422
    assert "less than or equal to 90" in r.json()["error"]["message"]


def test_favicon_is_served(tmp_path: Path) -> None:
    (r,) = _answers(tmp_path, [("GET", "/favicon.ico")])
    assert r.status_code == 200
    assert r.headers["content-type"] == "image/svg+xml"
    assert r.content.startswith(b"<svg")
    assert r.content.endswith(b"</svg>")


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    srv = Server(tmp_path_factory.mktemp("qa37b-service"))
    srv.start()
    yield srv
    srv.stop()


@pytest.mark.browser
@needs_browser
def test_served_page_console_is_clean(server: Server, browser: Any) -> None:
    """Chromium logged "Failed to load resource: ... 404" for /favicon.ico on every served
    page; the job's summary page now opens with no console error and no failed request."""
    with httpx.Client(base_url=server.url, timeout=60.0) as client:
        r = client.post("/v1/jobs", json={"cameras": [{"id": "nothing"}]})
        assert r.status_code == 202, r.text
        job = r.json()["id"]
        deadline = time.monotonic() + 90
        while client.get(f"/v1/jobs/{job}").json()["status"] != "done":
            assert time.monotonic() < deadline, "job not done"
            time.sleep(0.3)
    context = browser.new_context()
    errors: list[str] = []
    failed: list[str] = []
    outside: list[str] = []
    try:
        page = context.new_page()
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda exc: errors.append(f"pageerror: {exc}"))
        page.on("response", lambda resp: failed.append(resp.url) if resp.status >= 400 else None)

        # no page.route: Playwright's routing keeps Chromium from asking for the favicon
        page.on(
            "request",
            lambda req: (
                None if req.url.startswith((server.url, "data:")) else outside.append(req.url)
            ),
        )
        page.goto(f"{server.url}/v1/jobs/{job}/map", wait_until="load")
        # Chromium asks for /favicon.ico after the load, past Playwright's request events
        # (only its console error shows it)
        page.wait_for_timeout(2000)
    finally:
        context.close()
    assert outside == []  # the page asks nothing of the internet
    assert failed == []
    assert errors == []
