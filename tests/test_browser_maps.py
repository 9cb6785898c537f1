"""Review maps in a real browser: headless Debian Chromium driven by Playwright, network off.

Screenshots are kept under ``tests/artifacts/`` (git-ignored) for a person to look at.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import CHROMIUM

from camloc_geo import maps

ARTIFACTS = Path(__file__).parent / "artifacts"

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(not CHROMIUM.exists(), reason="Debian chromium is not installed"),
]


@pytest.fixture(scope="module")
def pages(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    from test_maps import fremantle_map, located

    out = tmp_path_factory.mktemp("browser")
    md = fremantle_map()
    scene, res = located(md, 0)
    _s2, res2 = located(md, 2)
    cand = maps.candidates_map(res, md, out / "candidates.html", offline=True, scene=scene)
    from camloc_geo.api import locate_scene

    samples = Path(__file__).resolve().parents[1] / "sample_maps"
    tie = locate_scene(samples / "sample_scene.json", map_source=samples / "baltimore.osm.pbf")
    assert tie.result.candidates[0].ambiguous_with == [2, 4, 5]
    tied = maps.candidates_map(
        tie.result, tie.map_data, out / "tied.html", offline=True, scene=tie.scene
    )
    summary = maps.summary_map(
        [(res.scene_id, res), ("other", res2)], out / "summary.html", offline=True, map_data=md
    )
    return {
        "candidates": cand,
        "summary": summary,
        "result": res,
        "tied": tied,
        "tied_result": tie.result,
    }


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
        self.page.wait_for_selector(selector, state="attached", timeout=30000)

    def click_for_popup(self, locator: Any) -> None:
        """Click a marker to open its popup; click once more if no popup came.

        Rarely (about 1 run in 10 under a loaded CI, never in 30 quiet runs) the first click
        on a freshly loaded map opened no popup within 3 s; the cause was not pinned down
        (a click Leaflet swallows while the page settles is the likely one). What the popup
        shows is asserted as before.
        """
        locator.click()
        try:
            self.page.locator(".leaflet-popup-content").wait_for(timeout=3000)
        except Exception:  # playwright's TimeoutError
            # (a second click on a marker whose popup is open would close it: only if none)
            if self.page.locator(".leaflet-popup-content").count() == 0:
                locator.click()

    def popup_text(self) -> str:
        """Text of the open popup, once its fade-in animation has finished."""
        popup = self.page.locator(".leaflet-popup-content")
        popup.wait_for(timeout=30000)
        self.page.wait_for_function(
            "getComputedStyle(document.querySelector('.leaflet-popup')).opacity === '1'",
            timeout=30000,
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
    tab.click_for_popup(page.locator('.camloc-candidate [data-rank="1"]'))
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
    tab.click_for_popup(page.locator(".camloc-summary-marker").first)
    text = tab.popup_text()
    assert "score" in text
    assert "method" in text
    assert "camera" in text
    page.screenshot(path=str(ARTIFACTS / "summary_map.png"))
    assert tab.blocked == []
    assert tab.errors == []


def _box(page: Any, selector: str) -> dict[str, float]:
    box = page.locator(selector).first.bounding_box()
    assert box is not None, selector
    return dict(box)


def _overlap(a: dict[str, float], b: dict[str, float]) -> bool:
    return (
        a["x"] < b["x"] + b["width"]
        and b["x"] < a["x"] + a["width"]
        and a["y"] < b["y"] + b["height"]
        and b["y"] < a["y"] + a["height"]
    )


def test_tied_candidates_are_marked_and_explained(
    tab: _Page, pages: dict[str, Any], tmp_path: Path
) -> None:
    res = pages["tied_result"]
    tab.open(pages["tied"], ".camloc-candidate")
    page = tab.page
    banner = page.locator(".camloc-banner")
    assert banner.count() == 1
    assert banner.is_visible()
    text = banner.inner_text()
    assert "Ambiguous: candidates 1, 2, 3, 4 and 5 all fit the evidence" in text
    assert "symmetric junction" in text
    assert "view_hint" in text
    # the two tied markers: different fill colours, both in the dashed ring with the badge
    fills = page.evaluate(
        """() => [1, 2, 5].map(r => getComputedStyle(
            document.querySelector(`.camloc-candidate [data-rank="${r}"]`)).backgroundColor)"""
    )
    assert fills[0] == "rgb(0, 114, 178)"  # Okabe-Ito blue
    assert fills[1] == "rgb(230, 159, 0)"  # Okabe-Ito orange
    assert len(set(fills)) == 3
    for rank in (1, 2):
        ring = page.locator(f'.camloc-tied:has([data-rank="{rank}"])')
        assert ring.count() == 1
        assert ring.locator(".camloc-badge").is_visible()
        style = page.evaluate(
            """r => getComputedStyle(document.querySelector(
                `.camloc-tied:has([data-rank="${r}"])`), "::before").borderTopStyle""",
            rank,
        )
        assert style == "dashed"
        # the page is fitted so that the banner hides neither tied candidate
        assert not _overlap(_box(page, f'[data-rank="{rank}"]'), _box(page, ".camloc-banner"))
    assert page.locator('.camloc-tied:has([data-rank="6"])').count() == 0  # negligible score
    ARTIFACTS.mkdir(exist_ok=True)
    shot = tmp_path / "tied_map.png"
    page.screenshot(path=str(shot))
    page.screenshot(path=str(ARTIFACTS / "tied_map.png"))
    assert shot.stat().st_size > 10_000
    # a tied candidate's popup names the other and why; the banner folds to its headline
    tab.click_for_popup(page.locator('.camloc-candidate [data-rank="2"]'))
    popup = tab.popup_text()
    assert "Tied with candidates 1 (score" in popup
    assert f"{res.candidates[0].score:.3f}" in popup
    assert "symmetric junction" in popup
    assert banner.locator("h4").is_visible()
    assert not banner.locator(".camloc-banner-body").is_visible()
    page.screenshot(path=str(ARTIFACTS / "tied_map_popup.png"))
    page.locator(".leaflet-popup-close-button").click()
    page.wait_for_function(
        "!document.querySelector('.camloc-banner').classList.contains('folded')", timeout=30000
    )
    assert banner.locator(".camloc-banner-body").is_visible()
    assert tab.blocked == []
    assert tab.errors == []


def test_summary_map_rings_a_tied_camera(tab: _Page, pages: dict[str, Any], tmp_path: Path) -> None:
    tie = pages["tied_result"]
    out = maps.summary_map(
        [("tied-cam", tie), ("clear-cam", pages["result"])], tmp_path / "s.html", offline=True
    )
    tab.open(out, ".camloc-summary-marker")
    page = tab.page
    assert page.locator(".camloc-summary-marker").count() == 2
    assert page.locator(".camloc-summary-marker .camloc-tied-arrow").count() == 1
    tab.click_for_popup(page.locator(".camloc-summary-marker .camloc-tied-arrow"))
    text = tab.popup_text()
    assert "tied with candidates 2, 4 and 5" in text
    assert "odds under 10 to 1" in text
    assert "tied-cam" in text
    assert tab.blocked == []
    assert tab.errors == []


def test_tie_banner_hides_no_tied_candidate_on_a_small_screen(
    browser: Any, pages: dict[str, Any]
) -> None:
    """At 1024x640 (a small laptop) the banner's whole explanation was about 270 px high and
    covered candidates 2 and 4, the rivals it tells of; there it now opens folded to its
    headline, and a click on the headline unfolds it (and folds it again)."""
    t = _Page(browser)
    try:
        t.page.set_viewport_size({"width": 1024, "height": 640})
        t.open(pages["tied"], ".camloc-candidate")
        page = t.page
        banner = page.locator(".camloc-banner")
        assert banner.locator("h4").is_visible()
        assert not banner.locator(".camloc-banner-body").is_visible()
        for rank in (1, 2, 3, 4):
            box = _box(page, f'.camloc-candidate [data-rank="{rank}"]')
            assert not _overlap(box, _box(page, ".camloc-banner")), rank
        ARTIFACTS.mkdir(exist_ok=True)
        page.screenshot(path=str(ARTIFACTS / "tied_map_small.png"))
        banner.locator("h4").click()
        assert banner.locator(".camloc-banner-body").is_visible()
        assert "view_hint" in banner.inner_text()
        banner.locator("h4").click()
        assert not banner.locator(".camloc-banner-body").is_visible()
        assert t.blocked == []
        assert t.errors == []
    finally:
        t.close()


def test_phone_sees_the_candidates_not_the_controls(browser: Any, pages: dict[str, Any]) -> None:
    """On a 390x844 phone the review page's layer list (12 lines, always open) and its
    legend (20 lines) covered the map: candidates 1, 3 and most others were under them
    (Chromium screenshot of camloc locate --map on the sample scene). Below 720 px the
    layer list opens folded to Leaflet's layers button, the legend to its heading, the tie
    banner sits at the bottom; each opens on a tap."""
    t = _Page(browser)
    try:
        t.page.set_viewport_size({"width": 390, "height": 844})
        t.open(pages["tied"], ".camloc-candidate")
        page = t.page
        page.wait_for_selector(".camloc-legend.folded", timeout=30000)
        layers = page.locator(".leaflet-control-layers")
        assert "leaflet-control-layers-expanded" not in (layers.get_attribute("class") or "")
        legend = _box(page, ".camloc-legend")
        assert legend["height"] < 40
        covers = [_box(page, ".camloc-legend"), _box(page, ".leaflet-control-layers")]
        covers.append(_box(page, ".camloc-banner"))
        for rank in (1, 2, 3, 4):
            box = _box(page, f'.camloc-candidate [data-rank="{rank}"]')
            assert not any(_overlap(box, c) for c in covers), rank
        ARTIFACTS.mkdir(exist_ok=True)
        page.screenshot(path=str(ARTIFACTS / "tied_map_phone.png"))
        page.locator(".leaflet-control-layers-toggle").click()
        assert "leaflet-control-layers-expanded" in (layers.get_attribute("class") or "")
        assert page.get_by_text("Buildings").is_visible()
        page.locator(".camloc-legend h4").click()
        assert _box(page, ".camloc-legend")["height"] > 200
        assert t.blocked == []
        assert t.errors == []
    finally:
        t.close()


def test_phone_popup_is_not_under_the_title_box(browser: Any, pages: dict[str, Any]) -> None:
    """On a 390x844 phone an open popup fills the width and the title box (scene id,
    candidates, calibration) drew over its first rows: rank, score, lat and lon were
    unreadable (Chromium screenshot of the verdicts' phone test). The top controls step
    aside while a popup is open and come back when it closes."""
    t = _Page(browser)
    try:
        t.page.set_viewport_size({"width": 390, "height": 844})
        t.open(pages["candidates"], ".camloc-candidate")
        page = t.page
        page.wait_for_selector(".camloc-legend.folded", timeout=30000)
        assert page.locator(".camloc-title").is_visible()
        t.click_for_popup(page.locator('.camloc-candidate [data-rank="1"]'))
        t.popup_text()
        popup = _box(page, ".leaflet-popup-content-wrapper")
        shown = [
            _box(page, sel)
            for sel in (".camloc-title", ".leaflet-control-zoom")
            if page.locator(sel).is_visible()
        ]
        assert not any(_overlap(popup, c) for c in shown)
        ARTIFACTS.mkdir(exist_ok=True)
        page.screenshot(path=str(ARTIFACTS / "candidates_map_phone_popup.png"))
        page.locator(".leaflet-popup-close-button").click()
        page.wait_for_selector(".leaflet-popup", state="detached", timeout=30000)
        assert page.locator(".camloc-title").is_visible()
        assert t.blocked == []
        assert t.errors == []
    finally:
        t.close()


def test_long_scene_id_wraps_beside_the_banner(
    browser: Any, pages: dict[str, Any], tmp_path: Path
) -> None:
    """A scene id of 270 characters with HTML in it (a scraped webcam title, through
    POST /v1/maps): escaped, but one unbroken line across the whole page, under the tie
    banner and the layer list (Chromium at 1280x800). The title box now wraps at 290 px,
    beside the banner."""
    long_id = "<img src=x onerror=alert(1)> Cam 3 - Main St / 5th Ave " + "x" * 200
    from camloc_geo.api import locate_scene

    samples = Path(__file__).resolve().parents[1] / "sample_maps"
    tie = locate_scene(samples / "sample_scene.json", map_source=samples / "baltimore.osm.pbf")
    tie.result.scene_id = long_id
    page_path = maps.candidates_map(
        tie.result, tie.map_data, tmp_path / "long.html", offline=True, scene=tie.scene
    )
    t = _Page(browser)
    try:
        t.page.set_viewport_size({"width": 1280, "height": 800})
        t.open(page_path, ".camloc-candidate")
        page = t.page
        title = _box(page, ".camloc-title")
        assert title["width"] <= 320
        assert not _overlap(title, _box(page, ".camloc-banner"))
        assert "onerror=alert(1)" in page.locator(".camloc-title").inner_text()
        assert page.locator(".camloc-title img").count() == 0
        assert t.blocked == []
        assert t.errors == []
    finally:
        t.close()
