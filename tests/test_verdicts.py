"""Reviewers' verdicts on the review maps: the reader (:func:`camloc_geo.maps.read_verdicts`)
and, in headless Debian Chromium with the network off, the page's verdict controls: a verdict
survives a reload, the export parses back, the badges and the phone-sized page."""

from __future__ import annotations

import csv
import io
import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from camloc_geo import maps
from camloc_geo._errors import InputError

# ------------------------------------------------------------------------------ reader


def _write_csv(path: Path, rows: list[dict[str, Any]], bom: bool = True) -> Path:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(maps.VERDICT_FIELDS), lineterminator="\r\n")
    w.writeheader()
    for r in rows:
        w.writerow(r)
    path.write_text(("\ufeff" if bom else "") + buf.getvalue(), encoding="utf-8")
    return path


ROW = {
    "camera": "cam-7",
    "rank": "2",
    "lat": "-32.0561234",
    "lon": "115.7456789",
    "verdict": "yes",
    "note": 'kerb, "the" tree',
    "reviewer": "Ana",
    "time": "2026-11-25T01:10:00.000Z",
    "page": "summary",
    "identity": "0123456789abcdef",
}


def test_read_verdicts_csv_values(tmp_path: Path) -> None:
    rows = maps.read_verdicts(
        _write_csv(tmp_path / "v.csv", [ROW, {**ROW, "camera": "x", "verdict": "no", "rank": ""}])
    )
    assert rows[0] == {
        "camera": "cam-7",
        "rank": 2,
        "lat": -32.0561234,
        "lon": 115.7456789,
        "verdict": "yes",
        "note": 'kerb, "the" tree',
        "reviewer": "Ana",
        "time": "2026-11-25T01:10:00.000Z",
        "page": "summary",
        "identity": "0123456789abcdef",
    }
    assert rows[1]["rank"] is None
    assert rows[1]["verdict"] == "no"
    assert list(rows[0]) == list(maps.VERDICT_FIELDS)


def test_read_verdicts_undoes_the_formula_guard(tmp_path: Path) -> None:
    rows = maps.read_verdicts(_write_csv(tmp_path / "v.csv", [{**ROW, "note": "'=1+1"}]))
    assert rows[0]["note"] == "=1+1"


def test_read_verdicts_geojson(tmp_path: Path) -> None:
    props = {**ROW, "rank": 3, "lat": 51.5, "lon": -0.12}
    doc = {
        "type": "FeatureCollection",
        "properties": {"format": "camloc-verdicts/1"},
        "features": [
            {"type": "Feature", "properties": props, "geometry": None},
            {"type": "Feature", "properties": {**props, "verdict": "unsure", "lat": None}},
        ],
    }
    path = tmp_path / "v.geojson"
    path.write_text(json.dumps(doc), encoding="utf-8")
    rows = maps.read_verdicts(path)
    assert [(r["rank"], r["lat"], r["lon"], r["verdict"]) for r in rows] == [
        (3, 51.5, -0.12, "yes"),
        (3, None, -0.12, "unsure"),
    ]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"verdict": "maybe"}, "line 2: verdict 'maybe' is not one of yes, no, unsure"),
        ({"rank": "two"}, "line 2: rank 'two' is not a whole number"),
        ({"lat": "abc"}, "line 2: lat 'abc' is not a number"),
        ({"lon": "190"}, "line 2: lon '190' is out of range"),
        ({"camera": ""}, "line 2: no camera id"),
    ],
)
def test_read_verdicts_names_the_bad_row(
    tmp_path: Path, change: dict[str, str], message: str
) -> None:
    path = _write_csv(tmp_path / "v.csv", [{**ROW, **change}])
    with pytest.raises(InputError, match=message):
        maps.read_verdicts(path)


def test_read_verdicts_bad_files(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="no such verdicts file"):
        maps.read_verdicts(tmp_path / "none.csv")
    other = tmp_path / "other.csv"
    other.write_text("a,b\n1,2\n", encoding="utf-8")
    with pytest.raises(InputError, match="no column camera, verdict"):
        maps.read_verdicts(other)
    broken = tmp_path / "b.geojson"
    broken.write_text("{not json", encoding="utf-8")
    with pytest.raises(InputError, match="not valid JSON"):
        maps.read_verdicts(broken)
    nofeat = tmp_path / "n.geojson"
    nofeat.write_text('{"type": "Feature"}', encoding="utf-8")
    with pytest.raises(InputError, match="no 'features' list"):
        maps.read_verdicts(nofeat)
    # session 36 QA: an empty file and a JSON list were 'not a verdicts CSV: no column ...'
    empty = tmp_path / "empty.csv"
    empty.write_text(" \n", encoding="utf-8")
    with pytest.raises(InputError, match="the verdicts file is empty"):
        maps.read_verdicts(empty)
    listed = tmp_path / "list.json"
    listed.write_text('[{"camera": "a", "verdict": "yes"}]', encoding="utf-8")
    with pytest.raises(InputError) as info:
        maps.read_verdicts(listed)
    assert str(info.value) == f"{listed}: not a verdicts GeoJSON (not a JSON object)"


# ----------------------------------------------------------------------------- browser
needs_browser = pytest.mark.skipif(
    not Path("/usr/bin/chromium").exists(), reason="Debian chromium is not installed"
)


@pytest.fixture(scope="module")
def vpages(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    from test_maps import fremantle_map, located

    out = tmp_path_factory.mktemp("verdicts")
    md = fremantle_map()
    scene, res = located(md, 0)
    _s2, res2 = located(md, 2)
    cand = maps.candidates_map(res, md, out / "candidates.html", offline=True, scene=scene)
    summary = maps.summary_map(
        [(res.scene_id, res), ("other", res2)], out / "summary.html", offline=True, map_data=md
    )
    cand2 = maps.candidates_map(res2, md, out / "candidates2.html", offline=True, overlay_top=0)
    return {
        "candidates": cand,
        "candidates2": cand2,
        "summary": summary,
        "result": res,
        "result2": res2,
    }


@pytest.fixture
def tab(browser: Any) -> Iterator[Any]:
    from test_browser_maps import _Page

    t = _Page(browser)
    yield t
    t.close()


def _open_popup(tab: Any, locator: Any) -> Any:
    tab.click_for_popup(locator)
    buttons = tab.page.locator(".leaflet-popup-content .camloc-verdict button")
    buttons.first.wait_for(timeout=30000)
    return tab.page.locator(".leaflet-popup-content .camloc-verdict")


def _close_popup(page: Any) -> None:
    page.locator(".leaflet-popup-close-button").dispatch_event("click")
    page.wait_for_function("!document.querySelector('.leaflet-popup')", timeout=30000)


def _download(page: Any, which: str) -> tuple[str, str]:
    with page.expect_download() as info:
        page.locator(f'button[data-export="{which}"]').click()
    d = info.value
    return str(d.suggested_filename), Path(d.path()).read_text(encoding="utf-8")


@pytest.mark.browser
@needs_browser
def test_candidate_verdict_survives_reload_and_exports(
    tab: Any, vpages: dict[str, Any], tmp_path: Path
) -> None:
    res = vpages["result"]
    second = res.candidates[1]
    tab.open(vpages["candidates"], ".camloc-verdicts .camloc-vcount")
    page = tab.page
    count = page.locator(".camloc-vcount")
    assert count.inner_text() == f"0 of {len(res.candidates)} candidates reviewed"
    box = _open_popup(tab, page.locator('.camloc-candidate [data-rank="2"]'))
    box.locator('button[data-verdict="yes"]').click()
    box.locator("input").fill("=the lamp post, left")
    assert page.locator(".leaflet-popup").count() == 1  # the click did not close the popup
    assert box.locator('button[data-verdict="yes"]').get_attribute("aria-pressed") == "true"
    assert count.inner_text() == f"1 of {len(res.candidates)} candidates reviewed"
    # rank 1 "not this one", then rank 2 is still the camera
    _close_popup(page)
    box1 = _open_popup(tab, page.locator('.camloc-candidate [data-rank="1"]'))
    box1.locator('button[data-verdict="no"]').click()
    assert count.inner_text() == f"2 of {len(res.candidates)} candidates reviewed"
    badges = page.evaluate(
        """() => Array.from(document.querySelectorAll('.camloc-candidate [data-verdict-mark]'))
            .map(m => [m.getAttribute('data-verdict-mark'), m.getAttribute('data-verdict'),
                       getComputedStyle(m, '::after').content,
                       m.closest('.leaflet-marker-icon').getAttribute('aria-label')])"""
    )
    marks = {k: (v, c, label) for k, v, c, label in badges}
    assert marks["2"] == ("yes", '"✓"', "candidate 2: This is the camera")
    assert marks["1"] == ("no", '"✗"', "candidate 1: Not this one")
    assert marks["3"][0] is None
    # reload: the verdicts, the note and the badges are still there
    page.reload(wait_until="load")
    page.wait_for_selector(".camloc-vcount")
    page.wait_for_function(
        "document.querySelector('.camloc-vcount').textContent.startsWith('2 of')", timeout=30000
    )
    assert (
        page.locator('.camloc-candidate [data-verdict-mark="2"]').get_attribute("data-verdict")
        == "yes"
    )
    box = _open_popup(tab, page.locator('.camloc-candidate [data-rank="2"]'))
    assert box.locator('button[data-verdict="yes"]').get_attribute("aria-pressed") == "true"
    assert box.locator("input").input_value() == "=the lamp post, left"
    _close_popup(page)
    page.locator(".camloc-verdicts input").fill("Ana Reviewer")
    name, text = _download(page, "csv")
    assert name.startswith("verdicts-fremantle-0-")
    assert name.endswith(".csv")
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    rows = maps.read_verdicts(path)
    assert [(r["camera"], r["rank"], r["verdict"]) for r in rows] == [
        ("fremantle-0", 1, "no"),
        ("fremantle-0", 2, "yes"),
    ]
    assert rows[1]["lat"] == pytest.approx(second.lat, abs=1e-7)
    assert rows[1]["lon"] == pytest.approx(second.lon, abs=1e-7)
    assert rows[1]["note"] == "=the lamp post, left"
    assert "'=the lamp post" in text  # guarded against spreadsheet formulas
    assert {r["reviewer"] for r in rows} == {"Ana Reviewer"}
    assert {r["page"] for r in rows} == {"candidates"}
    assert all(r["time"].endswith("Z") for r in rows)
    name, text = _download(page, "geojson")
    doc = json.loads(text)
    assert doc["properties"]["format"] == "camloc-verdicts/1"
    feat = doc["features"][1]
    assert feat["geometry"]["coordinates"] == pytest.approx([second.lon, second.lat], abs=1e-7)
    assert feat["properties"]["verdict"] == "yes"
    gpath = tmp_path / name
    gpath.write_text(text, encoding="utf-8")
    assert maps.read_verdicts(gpath) == rows
    assert tab.blocked == []
    assert tab.errors == []


@pytest.mark.browser
@needs_browser
def test_summary_verdicts_pick_another_rank_and_keep_apart(
    tab: Any, vpages: dict[str, Any], tmp_path: Path
) -> None:
    res, res2 = vpages["result"], vpages["result2"]
    tab.open(vpages["summary"], ".camloc-verdicts .camloc-vcount")
    page = tab.page
    count = page.locator(".camloc-vcount")
    assert count.inner_text() == "0 of 2 cameras reviewed"
    marker = page.locator(".camloc-summary-marker").nth(0)
    box = _open_popup(tab, marker)
    camera = page.locator(".leaflet-popup-content b").first.inner_text()
    picked = res if camera == res.scene_id else res2
    box.locator("select").select_option("3")
    assert count.inner_text() == "1 of 2 cameras reviewed"
    assert box.locator('button[data-verdict="yes"]').get_attribute("aria-pressed") == "false"
    page.reload(wait_until="load")
    page.wait_for_function(
        "document.querySelector('.camloc-vcount').textContent.startsWith('1 of')", timeout=30000
    )
    page.locator(".camloc-verdicts input").fill("")
    name, text = _download(page, "csv")
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    rows = maps.read_verdicts(path)
    third = picked.candidates[2]
    assert len(rows) == 1
    assert (rows[0]["camera"], rows[0]["rank"], rows[0]["verdict"]) == (camera, 3, "yes")
    assert rows[0]["lat"] == pytest.approx(third.lat, abs=1e-7)
    assert rows[0]["lon"] == pytest.approx(third.lon, abs=1e-7)
    assert rows[0]["page"] == "summary"
    assert rows[0]["reviewer"] == ""
    assert tab.blocked == []
    assert tab.errors == []


@pytest.mark.browser
@needs_browser
def test_verdicts_on_a_phone(browser: Any, vpages: dict[str, Any]) -> None:
    from test_browser_maps import ARTIFACTS, _Page

    t = _Page(browser)
    try:
        t.page.set_viewport_size({"width": 390, "height": 844})
        t.open(vpages["candidates"], ".camloc-verdicts .camloc-vcount")
        page = t.page
        ARTIFACTS.mkdir(exist_ok=True)
        # folded to its counter, top right under the layers button
        panel = page.locator(".camloc-verdicts").bounding_box()
        assert panel is not None
        assert panel["width"] <= 220
        assert panel["height"] <= 40
        assert panel["y"] < 200
        assert page.locator('button[data-export="csv"]').is_hidden()
        covered = [page.locator(".camloc-legend").bounding_box()]
        covered += [
            page.locator(f'.camloc-candidate [data-rank="{rank}"]').bounding_box()
            for rank in range(1, 5)
        ]
        for item in covered:
            assert item is not None
            assert not (
                item["x"] < panel["x"] + panel["width"]
                and panel["x"] < item["x"] + item["width"]
                and item["y"] < panel["y"] + panel["height"]
                and panel["y"] < item["y"] + item["height"]
            ), item
        page.locator(".camloc-vfold").click()
        assert page.locator('button[data-export="csv"]').is_visible()
        assert page.locator(".camloc-vfold").get_attribute("aria-expanded") == "true"
        page.screenshot(path=str(ARTIFACTS / "verdicts_phone_tools.png"))
        page.locator(".camloc-vfold").click()
        assert page.locator('button[data-export="csv"]').is_hidden()
        # keyboard only: the marker opens its popup with Enter, Tab reaches "Unsure"
        page.locator('.leaflet-marker-icon:has([data-rank="1"])').focus()
        page.keyboard.press("Enter")
        box = page.locator(".leaflet-popup-content .camloc-verdict")
        box.locator("button").first.wait_for(timeout=30000)
        box.locator('button[data-verdict="no"]').focus()
        page.keyboard.press("Tab")
        page.keyboard.press("Enter")
        assert box.locator('button[data-verdict="unsure"]').get_attribute("aria-pressed") == "true"
        popup = page.locator(".leaflet-popup-content-wrapper").bounding_box()
        assert popup is not None
        assert popup["width"] <= 390
        # the whole popup on the screen (it was placed before the controls made it taller)
        page.wait_for_timeout(400)  # Leaflet's pan animation (0.25 s)
        popup = page.locator(".leaflet-popup-content-wrapper").bounding_box()
        assert popup is not None
        assert popup["y"] >= 0
        assert popup["y"] + popup["height"] <= 844
        ARTIFACTS.mkdir(exist_ok=True)
        page.screenshot(path=str(ARTIFACTS / "verdicts_phone_popup.png"))
        _close_popup(page)
        page.wait_for_timeout(300)
        page.screenshot(path=str(ARTIFACTS / "verdicts_phone.png"))
        assert t.blocked == []
        assert t.errors == []
    finally:
        t.close()


# ------------------------------------------------------------------ summary-map --verdicts
def _gj(scene: str, ranks: list[tuple[int, float, float]]) -> dict[str, Any]:
    feats = [
        {
            "type": "Feature",
            "geometry": {"type": "Point", "coordinates": [lon, lat]},
            "properties": {
                "kind": "candidate",
                "rank": rank,
                "score": 1.0 / rank,
                "lat": lat,
                "lon": lon,
                "method": "corners",
                "heading_deg": 90.0,
            },
        }
        for rank, lat, lon in ranks
    ]
    return {"type": "FeatureCollection", "properties": {"scene": scene}, "features": feats}


def test_given_verdicts_pick_the_row_per_camera() -> None:
    fmap = maps.build_summary_map(
        [
            ("a", _gj("a", [(1, 51.5, -0.1), (2, 51.5001, -0.1001)])),
            ("b", _gj("b", [(1, 51.6, -0.2)])),
        ],
        offline=True,
        verdicts=[
            {**ROW, "camera": "a", "page": "candidates", "rank": 1, "verdict": "no"},
            {**ROW, "camera": "a", "page": "candidates", "rank": 2, "verdict": "yes"},
            {**ROW, "camera": "b", "page": "summary", "rank": 1, "verdict": "unsure"},
            {**ROW, "camera": "b", "page": "candidates", "rank": 1, "verdict": "yes"},
            {**ROW, "camera": "zzz", "page": "summary", "rank": 1, "verdict": "no"},
        ],
    )
    given = _config(fmap)["given"]
    assert {k: (v["verdict"], v.get("rank")) for k, v in given.items()} == {
        "c0": ("yes", 2),  # the review page's "yes" on rank 2 wins over its "no" on rank 1
        "c1": ("unsure", None),  # the summary page's row wins
    }
    assert _config(fmap)["items"]["c0"]["others"] == [[2, 51.5001, -0.1001, "0.500"]]


def test_summary_map_cli_verdicts(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from camloc_geo.cli import main

    gj = tmp_path / "a.geojson"
    gj.write_text(json.dumps(_gj("a", [(1, 51.5, -0.1)])), encoding="utf-8")
    good = _write_csv(
        tmp_path / "v.csv", [{**ROW, "camera": "a", "rank": "1", "lat": "", "lon": ""}]
    )
    out = tmp_path / "s.html"
    assert main(["summary-map", str(gj), "-o", str(out), "--inline", "--verdicts", str(good)]) == 0
    assert '"given": {"c0": {' in out.read_text(encoding="utf-8")
    bad = _write_csv(tmp_path / "bad.csv", [{**ROW, "verdict": "maybe"}])
    assert main(["summary-map", str(gj), "-o", str(out), "--verdicts", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert "line 2: verdict 'maybe' is not one of yes, no, unsure" in err


@pytest.mark.browser
@needs_browser
def test_summary_page_shows_given_verdicts(
    tab: Any, vpages: dict[str, Any], tmp_path: Path
) -> None:
    res, res2 = vpages["result"], vpages["result2"]
    page_path = maps.summary_map(
        [(res.scene_id, res), ("other", res2)],
        tmp_path / "given.html",
        offline=True,
        verdicts=[{**ROW, "camera": "other", "rank": 1, "verdict": "no", "note": "wrong street"}],
    )
    tab.open(page_path, ".camloc-verdicts .camloc-vcount")
    page = tab.page
    page.wait_for_function(
        "document.querySelector('.camloc-vcount').textContent === '1 of 2 cameras reviewed'",
        timeout=30000,
    )
    marks = page.evaluate(
        """() => Array.from(document.querySelectorAll('[data-verdict-mark]'))
            .map(m => m.getAttribute('data-verdict'))"""
    )
    assert sorted(str(m) for m in marks) == ["None", "no"]
    # exported again under its own reviewer and time, whoever exports
    page.locator(".camloc-verdicts input").fill("Bo")
    name, text = _download(page, "csv")
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    rows = maps.read_verdicts(path)
    assert [(r["camera"], r["verdict"], r["note"], r["reviewer"], r["time"]) for r in rows] == [
        ("other", "no", "wrong street", "Ana", ROW["time"])
    ]
    # the layer list hides and shows the cameras again: the badge comes back with them
    label = page.locator(".leaflet-control-layers label", has_text="Cameras (best candidate)")
    label.locator("input").uncheck()
    label.locator("input").check()
    page.wait_for_function(
        "document.querySelectorAll('[data-verdict-mark][data-verdict=\"no\"]').length === 1",
        timeout=30000,
    )
    assert tab.errors == []


@pytest.mark.browser
@needs_browser
@pytest.mark.parametrize(("width", "height"), [(1400, 900), (800, 600)])
def test_verdict_panel_covers_no_candidate(
    browser: Any, tmp_path: Path, width: int, height: int
) -> None:
    """The tied sample scene (12 candidates): unfolded at 800x600 the panel covered
    candidates 1 and 3; on a map under 1200x800 it opens folded to its counter."""
    from test_browser_maps import _Page

    from camloc_geo.api import locate_scene

    samples = Path(__file__).resolve().parents[1] / "sample_maps"
    tie = locate_scene(samples / "sample_scene.json", map_source=samples / "baltimore.osm.pbf")
    path = maps.candidates_map(
        tie.result,
        tie.map_data,
        tmp_path / "tied.html",
        offline=True,
        scene=tie.scene,
        overlay_top=0,
    )
    t = _Page(browser)
    try:
        t.page.set_viewport_size({"width": width, "height": height})
        t.open(path, ".camloc-verdicts .camloc-vcount")
        page = t.page
        folded = width < 1200
        assert page.locator('button[data-export="csv"]').is_visible() != folded
        panel = page.locator(".camloc-verdicts").bounding_box()
        assert panel is not None
        dots = page.locator(".camloc-candidate")
        assert dots.count() == len(tie.result.candidates)
        for i in range(dots.count()):
            d = dots.nth(i).bounding_box()
            assert d is not None
            assert not (
                d["x"] < panel["x"] + panel["width"]
                and panel["x"] < d["x"] + d["width"]
                and d["y"] < panel["y"] + panel["height"]
                and panel["y"] < d["y"] + d["height"]
            ), dots.nth(i).inner_text()
        assert t.errors == []
    finally:
        t.close()


@pytest.mark.browser
@needs_browser
def test_verdicts_kept_apart_and_back_button(tab: Any, vpages: dict[str, Any]) -> None:
    """One browser (one storage): another scene's page does not see this page's verdicts, and
    the back button brings this page back with them."""
    res2 = vpages["result2"]
    page = tab.page
    tab.open(vpages["candidates"], ".camloc-verdicts .camloc-vcount")
    box = _open_popup(tab, page.locator('.camloc-candidate [data-rank="3"]'))
    box.locator('button[data-verdict="unsure"]').click()
    assert page.locator(".camloc-vcount").inner_text().startswith("1 of ")
    tab.open(vpages["candidates2"], ".camloc-verdicts .camloc-vcount")
    page.wait_for_timeout(100)
    assert page.locator(".camloc-vcount").inner_text() == (
        f"0 of {len(res2.candidates)} candidates reviewed"
    )
    assert page.locator("[data-verdict-mark][data-verdict]").count() == 0
    tab.open(vpages["summary"], ".camloc-verdicts .camloc-vcount")
    page.wait_for_timeout(100)
    assert page.locator(".camloc-vcount").inner_text() == "0 of 2 cameras reviewed"
    page.go_back(wait_until="load")
    page.go_back(wait_until="load")
    page.wait_for_function(
        "document.querySelector('.camloc-vcount').textContent.startsWith('1 of ')",
        timeout=30000,
    )
    mark = page.locator('.camloc-candidate [data-verdict-mark="3"]')
    assert mark.get_attribute("data-verdict") == "unsure"
    assert tab.blocked == []
    assert tab.errors == []


def _config(fmap: Any) -> dict[str, Any]:
    found = re.search(r"var cfg = (\{.*?\});\n", fmap.get_root().render())
    assert found is not None
    out: dict[str, Any] = json.loads(found.group(1))
    return out


def test_page_identity_is_the_candidates(vpages: dict[str, Any]) -> None:
    """The same candidates give the same storage key (a page written again finds its
    verdicts); another scene's, or a moved candidate, another."""
    import copy

    from test_maps import fremantle_map

    res, res2 = vpages["result"], vpages["result2"]
    md = fremantle_map()
    one = _config(maps.build_candidates_map(res, md, offline=True))
    again = _config(maps.build_candidates_map(res, None, offline=True))
    other = _config(maps.build_candidates_map(res2, md, offline=True))
    assert one["identity"] == again["identity"]
    assert len(one["identity"]) == 16
    assert one["identity"] != other["identity"]
    assert one["kind"] == "candidates"
    assert one["order"] == [str(c.rank) for c in res.candidates]
    assert one["items"]["2"]["lat"] == pytest.approx(res.candidates[1].lat, abs=1e-7)
    from camloc_geo.results import candidates_geojson

    gj = candidates_geojson(res)
    moved = copy.deepcopy(gj)
    for f in moved["features"]:
        if f["properties"].get("rank") == 2 and f["properties"]["kind"] == "candidate":
            f["properties"]["lat"] += 1e-4
    base = _config(maps.build_summary_map([("a", gj)], offline=True))
    assert (
        base["identity"] == _config(maps.build_summary_map([("a", gj)], offline=True))["identity"]
    )
    assert (
        base["identity"]
        != _config(maps.build_summary_map([("a", moved)], offline=True))["identity"]
    )
    assert (
        base["identity"] != _config(maps.build_summary_map([("b", gj)], offline=True))["identity"]
    )
    assert base["noun"] == "cameras"


# ----------------------------------------------------------------- locate --map --verdicts
SAMPLES = Path(__file__).resolve().parents[1] / "sample_maps"


@pytest.fixture(scope="module")
def tied() -> Any:
    """The sample scene located on the Baltimore extract (12 candidates, 1 and 2 tied)."""
    from camloc_geo.api import locate_scene

    return locate_scene(SAMPLES / "sample_scene.json", map_source=SAMPLES / "baltimore.osm.pbf")


def _cand_row(tied: Any, rank: int, **change: Any) -> dict[str, Any]:
    c = tied.result.candidates[rank - 1]
    row = {**ROW, "camera": str(tied.result.scene_id), "rank": rank, "lat": c.lat, "lon": c.lon}
    row["page"] = "candidates"
    return {**row, **change}


def test_given_candidate_verdicts_pick_the_row_per_rank(tied: Any) -> None:
    fmap = maps.build_candidates_map(
        tied.result,
        tied.map_data,
        offline=True,
        verdicts=[
            _cand_row(tied, 1, verdict="no", note="wrong kerb"),
            _cand_row(tied, 2, verdict="unsure", page="summary"),
            _cand_row(tied, 2, verdict="yes", time="2026-11-25T01:00:00.000Z"),  # page row wins
            _cand_row(tied, 3, verdict="yes", time="2026-11-25T01:30:00.000Z"),  # latest yes
            _cand_row(tied, 4, verdict="no", lat=tied.result.candidates[3].lat + 0.001),  # moved
            _cand_row(tied, 5, verdict="no", camera="another camera"),  # not this scene: out
            {**_cand_row(tied, 7, verdict="no"), "rank": 99},  # no such rank: out
            {**_cand_row(tied, 6, verdict="unsure"), "lat": None, "lon": None},  # no position
        ],
    )
    given = _config(fmap)["given"]
    assert {k: (v["verdict"], v["note"]) for k, v in given.items()} == {
        "1": ("no", "wrong kerb"),
        "3": ("yes", ROW["note"]),
        "6": ("unsure", ROW["note"]),
    }
    assert given["3"]["reviewer"] == "Ana"
    assert given["3"]["time"] == "2026-11-25T01:30:00.000Z"
    # without verdicts the page hands in none
    assert "given" not in _config(maps.build_candidates_map(tied.result, None, offline=True))


def test_locate_map_cli_verdicts(
    tied: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from camloc_geo.cli import main

    good = _write_csv(tmp_path / "v.csv", [_cand_row(tied, 2, verdict="no", note="tree")])
    out = tmp_path / "m.html"
    scene, osm = str(SAMPLES / "sample_scene.json"), str(SAMPLES / "baltimore.osm.pbf")
    args = ["locate", scene, "--osm", osm, "-o", str(tmp_path / "c.geojson"), "--offline"]
    assert main([*args, "--map", str(out), "--verdicts", str(good)]) == 0
    found = re.search(r"var cfg = (\{.*?\});\n", out.read_text(encoding="utf-8"))
    assert found is not None
    given = json.loads(found.group(1))["given"]
    assert {k: (v["verdict"], v["note"]) for k, v in given.items()} == {"2": ("no", "tree")}
    capsys.readouterr()
    assert main([*args, "--verdicts", str(good)]) == 2
    assert "--verdicts needs --map OUT.html" in capsys.readouterr().err
    bad = _write_csv(tmp_path / "bad.csv", [{**ROW, "rank": "two"}])
    assert main([*args, "--map", str(tmp_path / "n.html"), "--verdicts", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert "line 2: rank 'two' is not a whole number" in err
    assert not (tmp_path / "n.html").exists()


@pytest.mark.browser
@needs_browser
def test_review_page_shows_given_verdicts(tab: Any, tied: Any, tmp_path: Path) -> None:
    page_path = maps.candidates_map(
        tied.result,
        tied.map_data,
        tmp_path / "given.html",
        offline=True,
        overlay_top=0,
        verdicts=[
            _cand_row(tied, 2, verdict="yes", note="the lamp post"),
            _cand_row(tied, 1, verdict="no"),
        ],
    )
    tab.open(page_path, ".camloc-verdicts .camloc-vcount")
    page = tab.page
    n = len(tied.result.candidates)
    page.wait_for_function(
        f"document.querySelector('.camloc-vcount').textContent === '2 of {n} candidates reviewed'",
        timeout=30000,
    )
    marks = page.evaluate(
        """() => Object.fromEntries(Array.from(
            document.querySelectorAll('.camloc-candidate [data-verdict-mark]'))
            .map(m => [m.getAttribute('data-verdict-mark'), m.getAttribute('data-verdict')]))"""
    )
    assert marks["1"] == "no"
    assert marks["2"] == "yes"
    assert sorted(k for k, v in marks.items() if v) == ["1", "2"]
    box = _open_popup(tab, page.locator('.camloc-candidate [data-rank="2"]'))
    assert box.locator('button[data-verdict="yes"]').get_attribute("aria-pressed") == "true"
    assert box.locator("input").input_value() == "the lamp post"
    page.screenshot(path=str(tmp_path / "given.png"))
    assert tab.blocked == []
    assert tab.errors == []


# --------------------------------------------------------------- cluster verdict badges
def _clustered_page(path: Path, verdicts: list[dict[str, Any]]) -> Path:
    """A summary page clustered as ``camloc batch --map`` writes it offline (the cluster
    plug-in inlined from its xstatic package): cameras a0-a3 7 m apart on a line, b0 and b1
    2 km off."""
    from camloc_geo.batch._run import _markercluster_assets

    near = [(f"a{i}", 51.5, -0.1 + i * 1e-4) for i in range(4)]
    far = [("b0", 51.518, -0.1), ("b1", 51.518, -0.1001)]
    items = [(name, _gj(name, [(1, lat, lon)])) for name, lat, lon in near + far]
    fmap = maps.build_summary_map(items, offline=False, tiles=None, verdicts=verdicts)
    page = fmap.get_root().render()
    js, css = _markercluster_assets()
    page = re.sub(
        r"<script\b[^>]*src=\"[^\"]*leaflet\.markercluster[^\"]*\.js\"[^>]*>\s*</script>",
        lambda _m: "<script>" + js + "</script>",
        page,
    )
    page = re.sub(
        r"<link\b[^>]*href=\"[^\"]*MarkerCluster[^\"]*\.css\"[^>]*/?>",
        lambda _m: "<style>" + css + "</style>",
        page,
    )
    page = re.sub(
        r"(L\.map\(\s*\"[^\"]+\",\s*\{)", lambda m: m.group(1) + " maxZoom: 22,", page, count=1
    )
    path.write_text(maps.inline_assets(page), encoding="utf-8")
    return path


def test_summary_clusters_use_the_verdict_icon() -> None:
    fmap = maps.build_summary_map(
        [("a", _gj("a", [(1, 51.5, -0.1)])), ("b", _gj("b", [(1, 51.6, -0.2)]))]
    )
    page = fmap.get_root().render()
    assert "options.iconCreateFunction" in page
    assert "window.camlocVerdictOf" in page
    assert "camloc-cbadge" in page


@pytest.mark.browser
@needs_browser
def test_cluster_badge_counts_the_verdicts_inside(tab: Any, tmp_path: Path) -> None:
    rows = [
        {**ROW, "camera": "a0", "rank": 1, "verdict": "yes"},
        {**ROW, "camera": "a1", "rank": 1, "verdict": "no"},
        {**ROW, "camera": "a2", "rank": 1, "verdict": "no"},
        {**ROW, "camera": "b0", "rank": 1, "verdict": "unsure"},
    ]
    path = _clustered_page(tmp_path / "clustered.html", rows)
    tab.open(path, ".camloc-verdicts .camloc-vcount")
    page = tab.page
    # session 38: at the zoom the page opens at only markers all but on top of each other
    # cluster (a0-a3, 2.3 px apart, would be pairs): two levels out, markercluster's own
    page.evaluate(
        """() => { const m = Object.keys(window).filter(k => /^map_[0-9a-f]+$/.test(k))
                   .map(k => window[k])[0]; m.setZoom(m.getZoom() - 2, {animate: false}); }"""
    )
    page.wait_for_function(
        "document.querySelector('.camloc-vcount').textContent === '4 of 6 cameras reviewed'",
        timeout=30000,
    )
    read = """() => Array.from(document.querySelectorAll('.camloc-cluster')).map(c => [
        c.querySelector('div span').textContent,
        Array.from(c.querySelectorAll('.camloc-cv')).map(b => b.textContent).join(' '),
        c.querySelector('.camloc-sr').textContent]).sort()"""
    page.wait_for_function(
        "document.querySelectorAll('.camloc-cluster .camloc-cv').length === 3", timeout=30000
    )
    assert page.evaluate(read) == [
        ["2", "?1", "2 cameras: 1 unsure, 1 not reviewed"],
        ["4", "✓1 ✗2", "4 cameras: 1 confirmed, 2 rejected, 1 not reviewed"],
    ]
    badge = page.locator(".camloc-cluster .camloc-cv-no")
    assert badge.evaluate("b => getComputedStyle(b).backgroundColor") == "rgb(176, 0, 32)"
    big = page.locator(".camloc-cluster", has_text="4 cameras")
    box, bbox = big.bounding_box(), big.locator(".camloc-cbadge").bounding_box()
    assert box is not None
    assert bbox is not None
    assert bbox["y"] >= box["y"] + box["height"] - 8  # under the bubble, not over its count
    page.screenshot(path=str(tmp_path / "clusters.png"))
    # a verdict given on a camera inside a cluster: the cluster's badge follows
    page.evaluate(
        """() => { const m = Object.keys(window).filter(k => /^map_[0-9a-f]+$/.test(k))
                   .map(k => window[k])[0]; m.setView([51.5, -0.09985], 22, {animate: false}); }"""
    )
    marker = page.locator(
        ".camloc-summary-marker:has([data-verdict-mark]):not(:has([data-verdict]))"
    )
    marker.first.wait_for(timeout=30000)
    box_v = _open_popup(tab, marker.first)
    box_v.locator('button[data-verdict="yes"]').click()
    _close_popup(page)
    page.evaluate(
        """() => { const m = Object.keys(window).filter(k => /^map_[0-9a-f]+$/.test(k))
                   .map(k => window[k])[0]; m.setView([51.509, -0.1], 14, {animate: false}); }"""
    )
    page.wait_for_function(
        "Array.from(document.querySelectorAll('.camloc-cluster .camloc-sr'))"
        ".some(s => s.textContent === '4 cameras: 2 confirmed, 2 rejected, 0 not reviewed')",
        timeout=30000,
    )
    assert tab.blocked == []
    assert tab.errors == []
