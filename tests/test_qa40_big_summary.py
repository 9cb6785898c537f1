"""Session 40 QA: a 3000-camera job map was 8 MB and took 10.6 s to build.

Each camera was a folium marker with its own icon, tooltip and popup HTML, rendered through a
Jinja template of its own. A page of more than ``SUMMARY_DATA_MARKERS`` cameras now carries
its markers as one compact data array (texts many cameras share kept once), and the browser
makes the markers, icons, tooltips and popups from it (a popup's HTML when it opens). The
page stays offline (Leaflet and markercluster inlined), and its popups, verdict controls and
the clusters' verdict counts work as on a small page (checked in Chromium here).
"""

from __future__ import annotations

import random
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import CHROMIUM, LAUNCH_ARGS

from camloc_geo import maps


def _items(n: int, seed: int = 40) -> list[tuple[str, dict[str, Any]]]:
    rng = random.Random(seed)
    out = []
    for i in range(n):
        lat = 39.28 + rng.uniform(-0.03, 0.03)
        lon = -76.6 + rng.uniform(-0.03, 0.03)
        feats = []
        for rank in (1, 2, 3):
            props = {
                "kind": "candidate",
                "rank": rank,
                "lat": lat,
                "lon": lon + rank * 1e-4,
                "score": rng.random() / rank,
                "method": "corners (located)" if i % 3 else "title (title_only)",
                "heading_deg": rng.uniform(0, 360) if i % 4 else None,
                "height_m": 6.0,
                "sigma_m": 4.0 + i % 7,
                "flags": ["located"] + (["tie"] if i % 17 == 0 else []),
                "ambiguous_with": [2] if (i % 17 == 0 and rank == 1) else [],
            }
            geom = {"type": "Point", "coordinates": [props["lon"], lat]}
            feats.append({"type": "Feature", "geometry": geom, "properties": props})
        reason = "junction of the map's model <b>" if i % 5 == 0 else None
        out.append(
            (
                f"cam-{i:05d}",
                {"type": "FeatureCollection", "features": feats, "properties": {"reason": reason}},
            )
        )
    return out


def test_a_3000_camera_page_is_small_and_carries_no_marker_html() -> None:
    page = maps.summary_page(_items(3000))
    size_mb = len(page.encode("utf-8")) / 1e6
    assert size_mb < 2.0, size_mb  # 7.96 MB before
    assert page.count("L.marker(") == 1  # the data's one loop, not a marker each
    assert "cam-02999" in page
    assert page.count("cam-02999") <= 2  # the data and the verdicts' list, once each
    assert page.count("junction of the map") == 1  # a shared reason is kept once
    assert not re.search(r"<script[^>]+src=\"https?:", page)  # offline: nothing from a CDN


def test_a_small_page_keeps_its_markers_as_before() -> None:
    small = maps.summary_page(_items(maps.SUMMARY_DATA_MARKERS))
    assert "CamlocDataMarkers" not in small
    assert small.count("L.marker(") > 100


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    if not CHROMIUM.exists():
        pytest.skip("Debian chromium is not installed")
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=str(CHROMIUM), args=LAUNCH_ARGS)
        yield b
        b.close()


def _open(browser: Any, path: Path) -> tuple[Any, Any, list[str]]:
    context = browser.new_context(viewport={"width": 1200, "height": 800})
    page = context.new_page()
    said: list[str] = []
    page.on("pageerror", lambda exc: said.append(f"pageerror: {exc}"))

    def route(r: Any) -> None:
        if r.request.url.startswith(("file:", "data:")):
            r.continue_()
        else:
            said.append("request: " + r.request.url)
            r.abort()

    page.route("**/*", route)
    page.goto(path.resolve().as_uri(), wait_until="load")
    return context, page, said


def _popup_of(page: Any, camera: str) -> str:
    """Open ``camera``'s popup (zoomed to it, the clusters spread) and return its text."""
    page.wait_for_selector(".camloc-summary-marker, .marker-cluster", state="attached")
    page.evaluate("() => Object.values(window).find((v) => v instanceof L.Map).closePopup()")
    page.wait_for_function("!document.querySelector('.leaflet-popup')")
    page.evaluate(
        """(cam) => {
            var group = Object.values(window).find((v) => v && v.zoomToShowLayer);
            var m = group.getLayers().find((l) => l.getTooltip() &&
                String(l.getTooltip().getContent()).includes(cam + " ("));
            group.zoomToShowLayer(m, () => m.openPopup());
        }""",
        camera,
    )
    page.wait_for_selector(".leaflet-popup .camloc-verdict button", timeout=30000)
    return str(page.locator(".leaflet-popup-content").inner_text())


@pytest.mark.browser
def test_a_large_page_works_in_chromium(browser: Any, tmp_path: Path) -> None:
    items = _items(maps.SUMMARY_DATA_MARKERS + 100)
    big = tmp_path / "big.html"
    big.write_text(maps.summary_page(items), encoding="utf-8")
    small = tmp_path / "small.html"
    small.write_text(maps.summary_page(items[:2] + items[17:18]), encoding="utf-8")
    context, page, said = _open(browser, small)
    want = [_popup_of(page, "cam-00000"), _popup_of(page, "cam-00017")]
    context.close()
    context, page, said = _open(browser, big)
    page.wait_for_selector(".marker-cluster", state="attached", timeout=30000)
    assert page.locator(".camloc-summary-marker").count() < 50  # clustered at first sight
    got = _popup_of(page, "cam-00000")
    assert got == want[0]  # the same popup as a small page's, verdict controls included
    assert "reason\tjunction of the map's model <b>" in got  # escaped, shown as typed
    page.locator(".leaflet-popup button.v-yes").click()
    page.wait_for_function(
        'document.querySelectorAll(\'[data-verdict-mark="c0"][data-verdict="yes"]\').length'
    )
    assert page.locator(".camloc-vcount").inner_text() == "1 of 400 cameras reviewed"
    tied = _popup_of(page, "cam-00017")
    assert tied == want[1]
    assert "the evidence does not favour the best candidate firmly" in tied
    page.evaluate(
        "() => { var m = Object.values(window).find((v) => v instanceof L.Map);"
        " m.closePopup(); m.setZoom(12, {animate: false}); }"
    )
    page.wait_for_selector(".camloc-cv-yes", state="attached", timeout=30000)
    assert page.locator(".camloc-cv-yes").all_inner_texts() == ["✓1"]  # the cluster counts it
    assert said == []  # no script error, no request leaving the page
    context.close()


def test_the_basemap_asks_the_catalogue_once_per_distinct_point(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A job's title-placed cameras share their junction's point: 3000 cameras at a few
    junctions asked the catalogue for each camera's area 3000 times (2 s of a 3000-camera
    job map); each distinct point is asked once now, and the counts are the same."""
    from camloc_geo.osm import MapCatalogue

    baltimore = Path(__file__).resolve().parents[1] / "sample_maps" / "baltimore.osm.pbf"
    asked: list[tuple[float, float]] = []
    original = MapCatalogue.area_for_point

    def spy(self: Any, lat: float, lon: float, **kw: Any) -> Any:
        asked.append((lat, lon))
        return original(self, lat, lon, **kw)

    monkeypatch.setattr(MapCatalogue, "area_for_point", spy)
    points = [(39.2855, -76.5935)] * 1000 + [(39.2905, -76.5937)] * 999 + [(0.0, 0.0)] * 7
    maps_data, unserved = maps.basemap_maps(points, baltimore)
    assert sorted(set(asked)) == sorted(set(points))
    assert len(asked) == 3
    assert len(maps_data) == 1
    assert unserved == 7
