"""Stop 42 qa7: the review page in Chromium (``camloc locate ... --map``), the faults found
(each test fails without its fix)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from conftest import CHROMIUM

from camloc_geo import maps

REPO = Path(__file__).resolve().parents[1]
needs_browser = pytest.mark.skipif(not CHROMIUM.exists(), reason="Debian chromium is not installed")

_DOTS = """() => Array.from(document.querySelectorAll('.camloc-candidate'))
    .filter(e => e.offsetWidth > 0)
    .map(e => { const r = e.getBoundingClientRect();
        const d = e.querySelector('.camloc-dot');
        const top = document.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2);
        return {rank: d.getAttribute('data-rank'), x: r.left + r.width / 2,
                y: r.top + r.height / 2, r: r.width / 2, moved: e.getAttribute('data-moved-px'),
                seen: !!top && e.contains(top)}; })"""


@pytest.fixture(scope="module")
def sample_page(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from camloc_geo.api import locate_scene

    out = locate_scene(
        REPO / "sample_maps" / "sample_scene.json",
        map_source=REPO / "sample_maps" / "baltimore.osm.pbf",
    )
    path = tmp_path_factory.mktemp("apart") / "review.html"
    return maps.candidates_map(out.result, out.map_data, path, offline=True, scene=out.scene)


def _covered(dots: list[dict[str, Any]]) -> list[str]:
    out = []
    for i, a in enumerate(dots):
        for b in dots[i + 1 :]:
            d = ((a["x"] - b["x"]) ** 2 + (a["y"] - b["y"]) ** 2) ** 0.5
            if d < 0.8 * (a["r"] + b["r"]):
                out.append(f"{a['rank']} and {b['rank']} ({d:.0f} px apart)")
    return out


@pytest.mark.browser
@needs_browser
def test_candidates_metres_apart_are_all_seen_at_the_opening_zoom(
    browser: Any, sample_page: Path
) -> None:
    """The bundled sample's rank 3 (tied with 2, 4 and 5) stands 3.4 m from rank 1: at the
    review page's opening zoom its disc lay under rank 1's, and rank 4's under rank 2's; a
    reviewer saw neither, and could click neither (only a hover over the sliver raised it).
    Each disc is now drawn clear of the better ones, joined to its point by a leader."""
    context = browser.new_context(viewport={"width": 1280, "height": 800})
    page = context.new_page()
    page.route(
        "**/*",
        lambda r: r.continue_() if r.request.url.startswith(("file:", "data:")) else r.abort(),
    )
    try:
        page.goto(sample_page.resolve().as_uri(), wait_until="load")
        page.wait_for_selector(".camloc-candidate", timeout=30000)
        page.wait_for_timeout(800)  # the opening fit's zoom
        dots = page.evaluate(_DOTS)
        assert len(dots) >= 10
        assert _covered(dots) == []
        by_rank = {d["rank"]: d for d in dots}
        assert by_rank["1"]["moved"] is None  # the best stays on its point
        assert by_rank["3"]["moved"] is not None
        assert all(d["seen"] for d in dots[:5]), [d for d in dots if not d["seen"]]
        # zoomed in to where they stand clear, every disc is on its own point again
        for _ in range(4):
            page.locator(".leaflet-control-zoom-in").click()
            page.wait_for_timeout(500)
        near = page.evaluate(_DOTS)
        one = {d["rank"]: d for d in near}["1"]
        assert one["moved"] is None
        assert page.locator(".camloc-leader").count() <= len(dots)
    finally:
        context.close()
