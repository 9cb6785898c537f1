"""Stop 41 QA (qa5): on the bundled sample's review page (``camloc locate ... --map``) the map
corner's label "m0" and the matched scene corner's "2" overlapped at the opening zoom: a map
corner's label stood below its point and a scene corner's above the next one, 31 px lower.
Corner labels now point away from the junction and then take the first place clear of the
candidates, the corner points and each other (``camloc_geo.maps._LabelsClear``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from conftest import CHROMIUM

from camloc_geo import maps

REPO = Path(__file__).resolve().parents[1]
needs_browser = pytest.mark.skipif(not CHROMIUM.exists(), reason="Debian chromium is not installed")

_BOXES = """() => Array.from(document.querySelectorAll(
        '.camloc-corner-label, .camloc-candidate .camloc-dot'))
    .filter(e => e.offsetWidth > 0)
    .map(e => { const r = e.getBoundingClientRect();
        return {t: e.innerText.trim(), label: !e.classList.contains('camloc-dot'),
                x: r.left, y: r.top, w: r.width, h: r.height}; })"""


@pytest.fixture(scope="module")
def sample_page(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from camloc_geo.api import locate_scene

    out = locate_scene(
        REPO / "sample_maps" / "sample_scene.json",
        map_source=REPO / "sample_maps" / "baltimore.osm.pbf",
    )
    path = tmp_path_factory.mktemp("labels") / "review.html"
    return maps.candidates_map(out.result, out.map_data, path, offline=True, scene=out.scene)


def _overlaps(boxes: list[dict[str, Any]]) -> list[str]:
    """Pairs of a corner label and another label or a candidate's disc that overlap."""
    found = []
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            if not (a["label"] or b["label"]):
                continue  # two candidates: their own layout
            w = min(a["x"] + a["w"], b["x"] + b["w"]) - max(a["x"], b["x"])
            h = min(a["y"] + a["h"], b["y"] + b["h"]) - max(a["y"], b["y"])
            if w > 0.5 and h > 0.5:
                found.append(f"{a['t']!r} and {b['t']!r} ({w:.0f}x{h:.0f} px)")
    return found


@pytest.mark.browser
@needs_browser
@pytest.mark.parametrize("size", [(1400, 900), (1024, 640)])
def test_corner_labels_clear_of_each_other_and_the_candidates(
    browser: Any, sample_page: Path, size: tuple[int, int]
) -> None:
    context = browser.new_context(viewport={"width": size[0], "height": size[1]})
    page = context.new_page()
    page.route(
        "**/*",
        lambda r: r.continue_() if r.request.url.startswith(("file:", "data:")) else r.abort(),
    )
    try:
        page.goto(sample_page.resolve().as_uri(), wait_until="load")
        page.wait_for_selector(".camloc-corner-label", timeout=30000)
        page.wait_for_timeout(800)  # the opening fit's zoom
        boxes = page.evaluate(_BOXES)
        texts = {b["t"] for b in boxes if b["label"]}
        assert {"m0", "m1", "m2", "m3", "0", "1", "2"} <= texts
        assert _overlaps(boxes) == []
        page.locator(".leaflet-control-zoom-in").click()  # and a step closer
        page.wait_for_timeout(800)
        assert _overlaps(page.evaluate(_BOXES)) == []
    finally:
        context.close()
