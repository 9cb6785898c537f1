"""Stop 42 qa6: the annotation page driven as a crowd worker drives it (Chromium, Playwright),
the faults found (each test fails without its fix)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from annotate_synthetic import located_case, render_snapshot
from conftest import CHROMIUM

from camloc_geo.cli import main

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(not CHROMIUM.exists(), reason="Debian chromium is not installed"),
]


@pytest.fixture(scope="module")
def case(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    out = tmp_path_factory.mktemp("qa6")
    ls = located_case()
    snap = out / "snapshot.jpg"
    snap.write_bytes(render_snapshot(ls))
    page = out / "page.html"
    assert main(["annotate", str(snap), "-o", str(page)]) == 0
    return {"page": page, "axes": ls.scene["annotations"][0]["axes"]}


@pytest.fixture
def tab(browser: Any) -> Iterator[Any]:
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.route(
        "**/*",
        lambda r: r.continue_() if r.request.url.startswith(("file:", "data:")) else r.abort(),
    )
    yield page
    assert errors == []
    context.close()


def _screen(page: Any, x: float, y: float) -> tuple[float, float]:
    sx, sy = page.evaluate(f"camloc.screenFromImage({float(x)!r}, {float(y)!r})")
    return float(sx), float(sy)


def _zoom_on(page: Any, x: float, y: float) -> None:
    page.mouse.move(*_screen(page, x, y))
    for _ in range(3):
        page.mouse.wheel(0, -300)
    page.wait_for_timeout(50)


@pytest.mark.parametrize(
    "order",
    [
        ("height", "origin", "width", "length"),  # the top first
        ("length", "width", "height", "origin"),  # the ground corner last
    ],
)
def test_car_points_in_the_wrong_order_are_named_at_once(
    tab: Any, case: dict[str, Any], order: tuple[str, ...]
) -> None:
    """A crowd worker (on a phone) tapped the car's top first, then its ground corner (a real
    York Urban photo): the page took the top as the ground corner, moved on to the lines by
    itself and said nothing until lines were drawn, and then only "Wrong corner? The length
    end ..." (``calibrate`` then refused the scene: "the camera is 1.1 m below the
    ground"). The page now stays on the car and names the order over the photo."""
    page = tab
    page.goto(case["page"].resolve().as_uri(), wait_until="load")
    page.wait_for_selector("body[data-ready]", state="attached", timeout=30000)
    axes = case["axes"]
    _zoom_on(page, *axes["origin"])
    for k in order:
        page.mouse.click(*_screen(page, *axes[k]))
    assert page.evaluate("camloc.step()") == 0  # stays on the car
    assert page.evaluate("camloc.analysis().topBelow") is True
    alerts = page.inner_text("#alerts")
    assert "Points in the wrong order? The top (point 4) is not above point 1" in alerts
    assert "Wrong corner?" not in alerts
    assert page.inner_text("#step-missing").startswith("The four points are placed, but the top")
    assert "done" not in (page.locator("#steps li").first.get_attribute("class") or "")
    # put right (undo the four, tap them in order): the check goes and the page moves on
    for _ in range(4):
        page.click("#btn-undo")
    for k in ("origin", "length", "width", "height"):
        page.mouse.click(*_screen(page, *axes[k]))
    assert page.evaluate("camloc.step()") == 1
    assert page.evaluate("camloc.analysis().topBelow") is False
    assert "done" in (page.locator("#steps li").first.get_attribute("class") or "")
    assert "wrong order" not in page.inner_text("#checks-body")


def test_the_summary_title_box_leaves_the_map_to_the_cameras(browser: Any, tmp_path: Any) -> None:
    """A batch summary (``camloc batch --map``) with four cameras not placed: its title box
    ran across the window over the top of the map (1248 px of a 1280-px window on a 12-camera
    list; 613 px here), and a cluster zoomed into lay under it (a click on it was taken by the
    box). The box now wraps at 560 px."""
    from camloc_geo import maps

    located = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [24.9452, 60.1706]},
                "properties": {
                    "kind": "candidate",
                    "rank": 1,
                    "score": 0.9,
                    "method": "corners",
                    "lat": 60.1706,
                    "lon": 24.9452,
                },
            }
        ],
    }
    missing = [
        (
            name,
            {
                "type": "FeatureCollection",
                "features": [],
                "properties": {"reason": f"not_found: '{title}' is neither a street nor a place"},
            },
        )
        for name, title in [
            ("mos-1", "ул. Академика Королёва / Останкинская ул."),
            ("bad-1", "Mikonkatu / Kaisaniemenkatu"),
            ("bad-2", "Some camera on the corner of the market square"),
            ("bad-3", "Obere Landstraße & Untere Landstraße looking north"),
        ]
    ]
    page_path = maps.summary_map([("hel-1", located), *missing], tmp_path / "s.html", offline=True)
    context = browser.new_context(viewport={"width": 1280, "height": 800})
    try:
        page = context.new_page()
        page.route(
            "**/*",
            lambda r: r.continue_() if r.request.url.startswith(("file:", "data:")) else r.abort(),
        )
        page.goto(page_path.resolve().as_uri(), wait_until="load")
        page.wait_for_selector(".camloc-summary-title", state="attached", timeout=30000)
        box = page.locator(".camloc-summary-title").bounding_box()
        assert box is not None
        assert box["width"] <= 560 + 1, box
        assert "4 without candidates" in page.inner_text(".camloc-summary-title")
    finally:
        context.close()


def test_a_tap_that_selects_a_car_point_says_to_zoom_in(browser: Any, case: dict[str, Any]) -> None:
    """On a 390x844 phone the whole photo shows the car some 30 px long: a crowd worker's tap
    for the third car point, 4 px from the second, selected the second instead, and nothing
    said why no point came. The page now says so, and to zoom in."""
    context = browser.new_context(
        viewport={"width": 390, "height": 844}, has_touch=True, is_mobile=True
    )
    try:
        page = context.new_page()
        page.route(
            "**/*",
            lambda r: r.continue_() if r.request.url.startswith(("file:", "data:")) else r.abort(),
        )
        page.goto(case["page"].resolve().as_uri(), wait_until="load")
        page.wait_for_selector("body[data-ready]", state="attached", timeout=30000)
        box = page.locator("#canvas").bounding_box()
        axes = case["axes"]
        taps = [axes["origin"], axes["length"]]
        for x, y in taps:
            sx, sy = _screen(page, x, y)
            page.tap("#canvas", position={"x": sx - box["x"], "y": sy - box["y"]})
        lx, ly = _screen(page, *axes["length"])
        page.tap("#canvas", position={"x": lx + 3 - box["x"], "y": ly - 2 - box["y"]})
        state = page.evaluate("camloc.state()")["axes"]
        assert state["width"] is None  # no third point placed
        banner = page.inner_text("#banner")
        assert banner.startswith("That tap selected point 2 (length), 4 px away, instead of")
        assert "placing point 3: zoom in (+, or pinch)" in banner
    finally:
        context.close()
