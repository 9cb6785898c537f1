"""Review maps in a real browser: headless Debian Chromium driven by Playwright, network off.

Screenshots are kept under ``tests/artifacts/`` (git-ignored) for a person to look at.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from camloc_geo import maps

CHROMIUM = Path("/usr/bin/chromium")
ARTIFACTS = Path(__file__).parent / "artifacts"
LAUNCH_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--disable-sync",
]

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(not CHROMIUM.exists(), reason="Debian chromium is not installed"),
]


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=str(CHROMIUM), args=LAUNCH_ARGS)
        yield b
        b.close()


@pytest.fixture(scope="module")
def pages(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    from test_maps import fremantle_map, located

    out = tmp_path_factory.mktemp("browser")
    md = fremantle_map()
    scene, res = located(md, 0)
    _s2, res2 = located(md, 2)
    cand = maps.candidates_map(res, md, out / "candidates.html", offline=True, scene=scene)
    summary = maps.summary_map(
        [(res.scene_id, res), ("other", res2)], out / "summary.html", offline=True, map_data=md
    )
    return {"candidates": cand, "summary": summary, "result": res}


class _Page:
    """A page with every request leaving ``file:``/``data:`` aborted and recorded."""

    def __init__(self, browser: Any) -> None:
        self.context = browser.new_context(viewport={"width": 1400, "height": 900})
        self.page = self.context.new_page()
        self.blocked: list[str] = []
        self.errors: list[str] = []
        self.page.route("**/*", self._route)
        self.page.on("pageerror", lambda exc: self.errors.append(f"pageerror: {exc}"))
        self.page.on(
            "console",
            lambda msg: self.errors.append(f"console: {msg.text}") if msg.type == "error" else None,
        )

    def _route(self, route: Any) -> None:
        url = route.request.url
        if url.startswith(("file:", "data:")):
            route.continue_()
        else:
            self.blocked.append(url)
            route.abort()

    def open(self, path: Path, selector: str) -> None:
        """Load a page and wait until ``selector`` is in the DOM and the load event fired.

        How long that takes is measured by ``benchmarks/page_render.py``, not here.
        """
        self.page.goto(path.resolve().as_uri(), wait_until="load")
        self.page.wait_for_selector(selector, state="attached", timeout=5000)

    def popup_text(self) -> str:
        """Text of the open popup, once its fade-in animation has finished."""
        popup = self.page.locator(".leaflet-popup-content")
        popup.wait_for(timeout=3000)
        self.page.wait_for_function(
            "getComputedStyle(document.querySelector('.leaflet-popup')).opacity === '1'",
            timeout=3000,
        )
        return str(popup.inner_text())

    def close(self) -> None:
        self.context.close()


@pytest.fixture
def tab(browser: Any) -> Iterator[_Page]:
    t = _Page(browser)
    yield t
    t.close()


def test_candidate_map_renders_offline(tab: _Page, pages: dict[str, Any]) -> None:
    res = pages["result"]
    tab.open(pages["candidates"], ".camloc-candidate")
    page = tab.page
    assert page.locator(".leaflet-marker-icon.camloc-candidate").count() == len(res.candidates)
    assert page.locator(".camloc-legend").count() == 1
    assert page.locator(".leaflet-control-scale").count() == 1
    assert page.locator(".leaflet-control-layers").count() == 1
    assert page.locator(".leaflet-tile").count() == 0
    assert page.locator("path.leaflet-interactive").count() > 0  # vector layers drawn
    ARTIFACTS.mkdir(exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / "candidates_map.png"))
    assert tab.blocked == []
    assert tab.errors == []


def test_candidate_popup_shows_properties_and_overlay(tab: _Page, pages: dict[str, Any]) -> None:
    res = pages["result"]
    best = res.candidates[0]
    tab.open(pages["candidates"], ".camloc-candidate")
    page = tab.page
    # the best candidate is the marker labelled 1
    page.locator('.camloc-candidate [data-rank="1"]').click()
    text = tab.popup_text()
    assert "rank\t1" in text
    assert f"{best.score:.4f}" in text
    assert best.method in text
    for key in ("heading_deg", "pitch_deg", "roll_deg", "focal_px", "residual_m", "sigma_m"):
        assert key in text
    assert page.locator(".leaflet-popup-content img").count() == 1
    assert page.evaluate("document.querySelector('.leaflet-popup-content img').naturalWidth") > 0
    page.screenshot(path=str(ARTIFACTS / "candidates_map_popup.png"))
    assert tab.blocked == []
    assert tab.errors == []


def test_summary_map_renders_offline(tab: _Page, pages: dict[str, Any]) -> None:
    tab.open(pages["summary"], ".camloc-summary-marker")
    page = tab.page
    assert page.locator(".leaflet-marker-icon.camloc-summary-marker").count() == 2
    assert page.locator(".camloc-legend").count() == 1
    assert page.locator(".leaflet-control-scale").count() == 1
    page.locator(".camloc-summary-marker").first.click()
    text = tab.popup_text()
    assert "score" in text
    assert "method" in text
    assert "camera" in text
    page.screenshot(path=str(ARTIFACTS / "summary_map.png"))
    assert tab.blocked == []
    assert tab.errors == []
