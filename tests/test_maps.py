"""Review maps: offline pages are self-contained, popups carry every property, size budget."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from camloc_geo import maps
from camloc_geo.absolute import LocateResult, locate
from camloc_geo.cli import main
from camloc_geo.osm import MapData, load_map
from camloc_geo.results import candidates_geojson
from camloc_geo.scene import Scene, parse_scene
from camloc_geo.testing.synthetic import NoiseModel, make_located_scene

SAMPLES = Path(__file__).resolve().parents[1] / "sample_maps"
FREMANTLE = (-32.036172, 115.755714)
CONTRACT = (
    "rank",
    "score",
    "lat",
    "lon",
    "height_m",
    "heading_deg",
    "pitch_deg",
    "roll_deg",
    "focal_px",
    "method",
    "residual_m",
)
REMOTE = re.compile(
    r"""<(?:script|img|link|iframe)\b[^>]*\b(?:src|href)=["']?(?:https?:)?//""", re.IGNORECASE
)


def fremantle_map() -> MapData:
    """The Fremantle sample extract around Stirling Hwy × Tydeman Rd."""
    return load_map(SAMPLES / "fremantle.osm", *FREMANTLE, radius_m=250)


def located(map_data: MapData, seed: int, **kwargs: Any) -> tuple[Scene, LocateResult]:
    """A synthetic scene at the extract's main junction and its locate result."""
    inter = next(i for i in map_data.intersections if i.kind == "junction" and len(i.corners) >= 4)
    kwargs.setdefault("min_corners", 3)
    ls = make_located_scene(map_data, inter, np.random.default_rng(seed), **kwargs)
    assert ls is not None
    ls.scene["id"] = f"fremantle-{seed}"
    scene = parse_scene(ls.scene)
    return scene, locate(scene, map_data)


def div_icons(page: str, class_name: str) -> list[str]:
    """Inner HTML of the page's Leaflet DivIcons of a class."""
    found = re.findall(r"L\.divIcon\((\{.*?\})\s*\)", page, flags=re.DOTALL)
    icons = [json.loads(re.sub(r",\s*\}$", "}", m)) for m in found]
    return [i["html"] for i in icons if i.get("className") == class_name]


def remote_references(page: str) -> list[str]:
    """Remote resource references left outside the inlined scripts."""
    outside = re.sub(r"<script>.*?</script>", "", page, flags=re.DOTALL)
    return REMOTE.findall(outside) + re.findall(r"L\.tileLayer\(", outside)


@pytest.fixture(scope="module")
def fremantle() -> MapData:
    return fremantle_map()


@pytest.fixture(scope="module")
def scene_result(fremantle: MapData) -> tuple[Scene, LocateResult]:
    return located(fremantle, 0)


@pytest.fixture(scope="module")
def offline_page(
    tmp_path_factory: pytest.TempPathFactory,
    fremantle: MapData,
    scene_result: tuple[Scene, LocateResult],
) -> str:
    scene, res = scene_result
    out = tmp_path_factory.mktemp("maps") / "scene.html"
    maps.candidates_map(res, fremantle, out, offline=True, scene=scene)
    return out.read_text(encoding="utf-8")


def test_offline_page_is_self_contained(offline_page: str) -> None:
    assert remote_references(offline_page) == []
    assert "<script>" in offline_page
    assert "L.map(" in offline_page  # folium's map script
    assert "window.L" in offline_page or "leaflet" in offline_page.lower()  # Leaflet inlined
    assert "jQuery" in offline_page
    assert "bootstrap" not in offline_page.lower()
    assert "awesome-markers" not in offline_page.lower()
    assert "url(images/" not in offline_page  # Leaflet's images are data URIs


def test_offline_page_fits_the_size_budget(offline_page: str) -> None:
    assert len(offline_page.encode("utf-8")) < 1_500_000


def test_one_marker_per_candidate_and_every_property_in_popups(
    offline_page: str, scene_result: tuple[Scene, LocateResult]
) -> None:
    _scene, res = scene_result
    n = len(res.candidates)
    assert n >= 2
    assert len(div_icons(offline_page, "camloc-candidate")) == n
    gj = candidates_geojson(res)
    best = gj["features"][0]["properties"]
    for key in (*CONTRACT, "sigma_m", "flags", "scale", "merged", "refined"):
        assert f"<th>{key}</th>" in offline_page, key
    assert f"<td>{best['lat']:.7f}°</td>" in offline_page
    assert "data:image/png;base64," in offline_page  # overlay thumbnails embedded
    assert "camloc-legend" in offline_page
    assert "L.control.scale" in offline_page
    assert "L.control.layers" in offline_page


def test_scene_corner_numbers_label_the_matched_map_corners(
    offline_page: str, scene_result: tuple[Scene, LocateResult]
) -> None:
    _scene, res = scene_result
    best = res.candidates[0]
    assert res.intersection is not None
    labels = [re.sub(r"<[^>]+>", "", h) for h in div_icons(offline_page, "camloc-corner-label")]
    assert best.matches
    for i, m in enumerate(best.matches):
        assert m["label"] == f"intersection.corners[{i}]"
        assert str(i) in labels  # the scene's index labels the matched map corner
    for corner in res.intersection.corners:
        assert f"m{corner.order}" in labels


def test_online_page_has_osm_tiles_and_links_overlays(
    tmp_path: Path, fremantle: MapData, scene_result: tuple[Scene, LocateResult]
) -> None:
    scene, res = scene_result
    out = tmp_path / "html" / "online.html"
    maps.candidates_map(res, fremantle, out, scene=scene, overlay_dir=str(tmp_path / "png"))
    page = out.read_text(encoding="utf-8")
    assert "tile.openstreetmap.org" in page
    assert "openstreetmap.org/copyright" in page  # tile attribution
    pngs = sorted((tmp_path / "png").glob("*.png"))
    assert len(pngs) == min(5, len(res.candidates))
    assert f'src="../png/{pngs[0].name}"' in page
    assert "base64" not in page
    img = cv2.imread(str(pngs[0]))
    assert img is not None
    assert img.shape[:2] == (1080, 1920)


def test_page_without_map_data(tmp_path: Path, fremantle: MapData) -> None:
    inter = next(i for i in fremantle.intersections if i.kind == "junction")
    ls = make_located_scene(
        fremantle,
        inter,
        np.random.default_rng(4),
        n_references=2,
        noise=NoiseModel.exact(),
        corner_sigma_m=0.0,
    )
    assert ls is not None
    del ls.scene["intersection"]
    scene = parse_scene(ls.scene)
    res = locate(scene, None)
    assert res.candidates
    out = maps.candidates_map(res, None, tmp_path / "refs.html", offline=True, scene=scene)
    page = out.read_text(encoding="utf-8")
    assert remote_references(page) == []
    assert len(div_icons(page, "camloc-candidate")) == len(res.candidates)


def test_size_budget_shrinks_photo_overlays(tmp_path: Path, fremantle: MapData) -> None:
    scene, _res = located(fremantle, 1)
    noise = np.random.default_rng(0).integers(0, 255, (1080, 1920, 3), dtype=np.uint8)
    cv2.imwrite(str(tmp_path / "snap.png"), noise)  # incompressible "photo"
    data = scene.model_dump(mode="json", exclude_none=True)
    data["image"]["path"] = "snap.png"
    scene = parse_scene(data, base_dir=tmp_path)
    res = locate(scene, fremantle)
    out = maps.candidates_map(res, fremantle, tmp_path / "photo.html", offline=True, scene=scene)
    size = out.stat().st_size
    assert size < maps.MAX_PAGE_BYTES
    assert "data:image/png;base64," in out.read_text(encoding="utf-8")


def test_inline_assets_refuses_remote_leftovers() -> None:
    page = (
        '<html><head><script src="https://cdn.jsdelivr.net/npm/leaflet@1.9.3/dist/leaflet.js">'
        '</script></head><body><img src="https://example.org/x.png"></body></html>'
    )
    with pytest.raises(ValueError, match="remote"):
        maps.inline_assets(page)
    ok = maps.inline_assets(page.replace('<img src="https://example.org/x.png">', ""))
    assert "cdn.jsdelivr" not in ok


def test_score_scale_is_ordered() -> None:
    scores = [0.9, 0.3, 0.1, 0.02, 0.001]
    colours = [maps.score_colour(s) for s in scores]
    assert colours == [c for _l, c, _t in maps.SCORE_SCALE]
    sizes = [maps.rank_style(r)[0] for r in (1, 2, 5)]
    assert sizes == sorted(sizes, reverse=True)
    z = [maps.rank_style(r)[2] for r in (1, 2, 3, 4, 40)]
    assert z == sorted(z, reverse=True)


def test_summary_map_best_candidate_per_camera(
    tmp_path: Path, fremantle: MapData, scene_result: tuple[Scene, LocateResult]
) -> None:
    _scene, res0 = scene_result
    _s1, res1 = located(fremantle, 2)
    empty = {"type": "FeatureCollection", "features": [], "properties": {"reason": "no evidence"}}
    items = [("cam-a", candidates_geojson(res0)), ("cam-b", res1), ("cam-c", empty)]
    out = maps.summary_map(items, tmp_path / "summary.html", offline=True)
    page = out.read_text(encoding="utf-8")
    assert remote_references(page) == []
    assert len(div_icons(page, "camloc-summary-marker")) == 2
    assert "cam-a" in page
    assert "cam-b" in page
    assert "1 without candidates: " in page
    assert 'no evidence\\"\\u003ecam-c\\u003c/span\\u003e' in page  # the name, its reason on hover
    online = maps.summary_map(items, tmp_path / "summary_online.html").read_text(encoding="utf-8")
    assert "markercluster" in online.lower()


def test_cli_locate_writes_offline_map(tmp_path: Path, fremantle: MapData) -> None:
    inter = next(i for i in fremantle.intersections if i.kind == "junction" and len(i.corners) >= 4)
    ls = make_located_scene(fremantle, inter, np.random.default_rng(7), min_corners=3)
    assert ls is not None
    scene_file = tmp_path / "scene.json"
    scene_file.write_text(json.dumps(ls.scene), encoding="utf-8")
    out = tmp_path / "map.html"
    (tmp_path / "ov").mkdir()  # output folders are never created by the command line
    rc = main(
        [
            "locate",
            str(scene_file),
            "--osm",
            str(SAMPLES / "fremantle.osm"),
            "--offline",
            "--map",
            str(out),
            "--overlays",
            str(tmp_path / "ov"),
            "-o",
            str(tmp_path / "c.geojson"),
        ]
    )
    assert rc == 0
    page = out.read_text(encoding="utf-8")
    assert remote_references(page) == []
    n = sum(
        f["properties"]["kind"] == "candidate"
        for f in json.loads((tmp_path / "c.geojson").read_text())["features"]
    )
    assert len(div_icons(page, "camloc-candidate")) == n
    assert list((tmp_path / "ov").glob("*.png"))


def test_cli_summary_map(
    tmp_path: Path, fremantle: MapData, scene_result: tuple[Scene, LocateResult]
) -> None:
    _scene, res = scene_result
    a = tmp_path / "a.geojson"
    a.write_text(json.dumps(candidates_geojson(res)), encoding="utf-8")
    empty = tmp_path / "b.geojson"
    empty.write_text(json.dumps({"type": "FeatureCollection", "features": []}), encoding="utf-8")
    out = tmp_path / "s.html"
    rc = main(
        [
            "summary-map",
            str(a),
            str(empty),
            "-o",
            str(out),
            "--offline",
            "--osm",
            str(SAMPLES / "fremantle.osm"),
        ]
    )
    assert rc == 0
    page = out.read_text(encoding="utf-8")
    assert remote_references(page) == []
    assert len(div_icons(page, "camloc-summary-marker")) == 1
    assert res.scene_id in page
    assert "1 without candidates: " in page
    assert "\\u003eb\\u003c/span\\u003e" in page
    assert "Buildings" in page


def test_cli_summary_map_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.geojson"
    bad.write_text("[1, 2]", encoding="utf-8")
    assert main(["summary-map", str(bad), "-o", str(tmp_path / "x.html")]) == 2
    err = capsys.readouterr().err
    assert "not a GeoJSON FeatureCollection" in err
    assert "Traceback" not in err


def test_page_without_candidates_says_why(
    tmp_path: Path, fremantle: MapData, scene_result: tuple[Scene, LocateResult]
) -> None:
    from dataclasses import replace

    scene, res = scene_result
    empty = replace(res, candidates=[], reason="every candidate misfits")
    page = maps.candidates_map(empty, fremantle, tmp_path / "none.html", offline=True, scene=scene)
    text = page.read_text(encoding="utf-8")
    assert div_icons(text, "camloc-candidate") == []
    assert "no candidates" in text
    assert "every candidate misfits" in text


# ------------------------------------------------------------------------------- ties
BALTIMORE_SCENE = SAMPLES / "sample_scene.json"  # a symmetric junction seen with 3 corners


@pytest.fixture(scope="module")
def tied() -> Any:
    """The sample scene at Eastern Ave × S Broadway: candidates 1 and 2 tie, 60 m apart."""
    from camloc_geo.api import locate_scene

    out = locate_scene(BALTIMORE_SCENE, map_source=SAMPLES / "baltimore.osm.pbf")
    res = out.result
    # 1 and 2 face each other across the junction; 3 and 4 are their near twins (odds 2-8 to 1);
    # 5 stands at a same-shaped junction a block away where only one named street meets (stop 41)
    assert res.candidates[0].ambiguous_with == [2, 4, 5]
    assert res.candidates[1].ambiguous_with == [1, 3, 5]
    assert res.candidates[4].rival == "neighbour junction"
    assert any(w.startswith("ambiguous: candidates 1 and 2") for w in res.warnings)
    return out


def test_ties_are_data_decided_in_the_core(tied: Any) -> None:
    """The tie is a field of the result and of its GeoJSON, not only words in a warning."""
    res = tied.result
    assert res.leaders_tie
    assert [t.ranks for t in res.ties] == [[1, 2, 3, 4, 5]]
    assert f"ambiguous: {res.ties[0].text}" in res.warnings
    doc = tied.to_geojson()
    assert doc["properties"]["ties"][0]["ranks"] == [1, 2, 3, 4, 5]
    assert "symmetric junction" in doc["properties"]["ties"][0]["why"]
    # the rival joins the leaders' tie without taking over its reason (stop 41)
    assert "and candidate 5, at a junction where only some" in doc["properties"]["ties"][0]["why"]


@pytest.fixture(scope="module")
def tied_page(tmp_path_factory: pytest.TempPathFactory, tied: Any) -> str:
    out = tmp_path_factory.mktemp("ties") / "tie.html"
    maps.candidates_map(tied.result, tied.map_data, out, offline=True, scene=tied.scene)
    return out.read_text(encoding="utf-8")


def candidate_icon(page: str, rank: int) -> str:
    """The DivIcon HTML of the candidate marker labelled ``rank``."""
    found = [h for h in div_icons(page, "camloc-candidate") if f'data-rank="{rank}"' in h]
    assert len(found) == 1, rank
    return found[0]


def banner_html(page: str) -> str | None:
    """The tie banner's HTML (the JSON string the page's script puts into it), if any."""
    m = re.search(
        r'L\.DomUtil\.create\(\s*"div",\s*"(camloc-banner[^"]*)",'
        r'.*?div\.innerHTML = ("(?:[^"\\]|\\.)*");',
        page,
        flags=re.DOTALL,
    )
    return None if m is None else f"{m.group(1)}|{json.loads(m.group(2))}"


def popup_of(page: str, rank: int) -> str:
    """The popup HTML of candidate ``rank`` (folium puts it in a div of its own)."""
    starts = [m.start() for m in re.finditer(r"<b>Candidate \d+</b>", page)]
    for s in starts:
        if page.startswith(f"<b>Candidate {rank}</b>", s):
            end = page.find("</table>", s)
            return page[s:end]
    raise AssertionError(f"no popup of candidate {rank}")


def test_rank_colours_are_distinct_okabe_ito() -> None:
    colours = [maps.rank_colour(r) for r in range(1, 9)]
    assert len(set(colours)) == 8
    assert colours[0] == "#0072B2"  # blue
    assert colours[1] == "#E69F00"  # orange
    assert maps.rank_colour(9) == maps.rank_colour(40) == maps.RANK_OTHER
    assert maps.RANK_OTHER not in colours


def test_tied_candidates_differ_in_colour_and_wear_the_tie_ring(tied_page: str, tied: Any) -> None:
    one, two, five = (candidate_icon(tied_page, r) for r in (1, 2, 6))
    assert f"background:{maps.rank_colour(1)}" in one
    assert f"background:{maps.rank_colour(2)}" in two
    assert maps.rank_colour(1) != maps.rank_colour(2)
    assert 'class="camloc-tied" data-tied-with="2,4,5"' in one
    assert 'class="camloc-tied" data-tied-with="1,3,5"' in two
    assert "camloc-badge" in one
    assert "camloc-badge" in two
    assert tied.result.candidates[5].ambiguous_with == []  # rank 6: a negligible score
    assert "camloc-tied" not in five
    assert "camloc-badge" not in five
    # the view cones of ranks 1 and 2 are drawn in their candidate's colour
    for rank in (1, 2):
        colour = maps.rank_colour(rank)
        assert f'return {{"color": "{colour}", "fillColor": "{colour}"' in tied_page, rank
    assert remote_references(tied_page) == []


def test_tie_banner_says_which_why_and_what_decides(tied_page: str, tied: Any) -> None:
    banner = banner_html(tied_page)
    assert banner is not None
    css, text = banner.split("|", 1)
    assert css == "camloc-banner"
    # 1 and 2 across the junction, each with a near twin (3 beside 1, 4 beside 2): one group
    assert "Ambiguous: candidates 1, 2, 3, 4 and 5 all fit the evidence" in text
    scores = [c.score for c in tied.result.candidates[:5]]
    assert f"score ratio {min(scores) / max(scores):.2f}" in text
    assert " vs ".join(f"{s:.3f}" for s in scores) in text
    # why: the engine's own warning, and the candidates' (empty) flags
    assert "a symmetric junction cannot tell them apart" in text
    assert "Flags: none" in text
    # the sample scene has no view hint, street or front: each is suggested, with the two
    # viewing directions the hint would have to choose between
    scene = tied.scene
    assert scene.view_hint is None
    assert scene.object.street is None
    assert "<code>view_hint</code>" in text
    assert "<code>object.street</code>" in text
    assert "<code>object.front</code>" in text
    from camloc_geo.maps import _compass

    c1, c2 = tied.result.candidates[:2]
    hint = text.split("does it look", 1)[1]  # the directions the hint chooses between
    assert _compass(c1.heading_deg % 360) in hint
    assert _compass(c2.heading_deg % 360) in hint
    assert _compass(c1.heading_deg % 360) != _compass(c2.heading_deg % 360)
    # candidates of negligible score tie with nobody (no "also tied" line, no rings)
    assert "Also tied" not in text
    assert all(not c.ambiguous_with for c in tied.result.candidates[5:])


def test_tied_popups_name_the_ranks_and_why(tied_page: str, tied: Any) -> None:
    from camloc_geo.geodesy import distance_m
    from camloc_geo.maps import _compass

    c1, c2 = tied.result.candidates[:2]
    gap = distance_m(lat1=c1.lat, lon1=c1.lon, lat2=c2.lat, lon2=c2.lon)
    assert 40.0 < gap < 80.0  # the two sides of the junction
    two = popup_of(tied_page, 2)
    assert f"Tied with candidates</b> <b>1</b> (score {c1.score:.3f}" in two
    assert f"{gap:.0f} m away, looking {_compass(c1.heading_deg % 360)}" in two
    assert "a symmetric junction cannot tell them apart" in two
    assert "<tr><th>ambiguous_with</th><td>1, 3, 5</td></tr>" in two
    five = popup_of(tied_page, 6)
    assert "Tied with" not in five
    assert "<tr><th>ambiguous_with</th><td>none</td></tr>" in five


def test_banner_exactly_when_candidates_tie(tied: Any, offline_page: str) -> None:
    import copy

    res = copy.deepcopy(tied.result)
    # only lower ranks tie: a quieter banner that says the best is not tied
    for c in res.candidates:
        c.ambiguous_with = []
    res.candidates[4].ambiguous_with = [6]  # set by hand: the engine ties no negligible ones
    res.candidates[5].ambiguous_with = [5]
    res.warnings = []
    page = maps.build_candidates_map(res, None, offline=True).get_root().render()
    banner = banner_html(page)
    assert banner is not None
    assert banner.startswith("camloc-banner minor|")
    assert "Candidates 5 and 6 tie with each other" in banner
    assert "The best candidate (rank 1) is not tied" in banner
    assert "camloc-tied" not in candidate_icon(page, 1)
    # no tie at all: no banner, no ring
    for c in res.candidates:
        c.ambiguous_with = []
    page = maps.build_candidates_map(res, None, offline=True).get_root().render()
    assert banner_html(page) is None
    assert not any("camloc-tied" in h for h in div_icons(page, "camloc-candidate"))
    # and the Fremantle page has a banner exactly when its result has ties
    assert (banner_html(offline_page) is not None) == bool(
        re.search(r'data-tied-with="\d', offline_page)
    )


def test_banner_hints_follow_the_scene_cues(tied: Any) -> None:
    from camloc_geo.scene import ViewHint

    scene = tied.scene.model_copy(
        update={
            "view_hint": ViewHint(bearing_deg=90.0, tolerance_deg=20.0),
            "object": tied.scene.object.model_copy(update={"street": "Eastern Avenue"}),
        }
    )
    page = maps.build_candidates_map(tied.result, None, scene=scene, offline=True)
    text = banner_html(page.get_root().render())
    assert text is not None
    assert "The scene's view_hint and object.street did not decide" in text
    assert "<code>view_hint</code>" not in text
    assert "<code>object.front</code>" in text


def test_summary_map_marks_a_tied_best_candidate(tmp_path: Path, tied: Any) -> None:
    import copy

    gj = candidates_geojson(tied.result)
    clear = copy.deepcopy(gj)
    for f in clear["features"]:
        if f["properties"].get("kind") == "candidate":
            f["properties"]["ambiguous_with"] = []
    batch_row = {  # a batch journal row: a tie flag, no ambiguous_with
        "features": [
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [-76.59, 39.28]},
                "properties": {
                    "kind": "candidate",
                    "rank": 1,
                    "lat": 39.28,
                    "lon": -76.59,
                    "score": 0.5,
                    "method": "title (ambiguous)",
                    "flags": ["ambiguous", "tie"],
                },
            }
        ],
        "properties": {"reason": "two places match the title equally well"},
    }
    items = [("cam-tied", gj), ("cam-clear", clear), ("cam-title", batch_row)]
    page = maps.summary_map(items, tmp_path / "s.html", offline=True).read_text(encoding="utf-8")
    assert remote_references(page) == []
    icons = div_icons(page, "camloc-summary-marker")
    assert len(icons) == 3
    assert sum("camloc-tied-arrow" in h and "stroke-dasharray" in h for h in icons) == 2
    assert "≈ <b>tied with candidates 2, 4 and 5</b>" in page
    assert "tied with another candidate: two places match the title equally well" in page
    assert "cam-tied (0.36) ≈ tied with candidates 2, 4 and 5" in page  # tooltip
    assert "2 with a tied best candidate" in page
    assert "cam-clear (0.36)" in page
    assert "cam-clear (0.36) ≈" not in page


def test_summary_map_heading_tells_located_from_title_only(tmp_path: Path, tied: Any) -> None:
    """A batch summary with a title-only camera said "3 camera(s) located" although batch
    reported 2 located and 1 title_only; the heading now counts each."""

    def batch_row(status: str) -> dict[str, Any]:
        props = {"kind": "candidate", "rank": 1, "lat": 39.28, "lon": -76.59, "score": 0.5}
        props.update(method=f"title ({status})", flags=[status])
        feature = {"type": "Feature", "geometry": {"type": "Point", "coordinates": [-76.59, 39.28]}}
        return {"features": [{**feature, "properties": props}], "properties": {"reason": None}}

    gj = candidates_geojson(tied.result)
    statuses = (("a", "located"), ("b", "located"), ("c", "title_only"))
    items = [(cam, batch_row(status)) for cam, status in statuses]
    page = maps.summary_map(items, tmp_path / "s.html", offline=True).read_text(encoding="utf-8")
    assert "3 camera(s) on the map" in page
    assert "2 located, 1 title_only (at the junction its title names)" in page
    assert "camera(s) located" not in page
    plain = maps.summary_map([("cam", gj)], tmp_path / "p.html", offline=True)
    assert "1 camera(s) located" in plain.read_text(encoding="utf-8")


def test_tiny_scores_are_not_printed_as_zero(tied_page: str, tied: Any) -> None:
    """The legend said "5: 0.000" for a score of 1.1e-15 (and the popup 0.0000): a tiny
    score read as an impossible one. It is now written as 1.1e-15; the leaders keep 0.375."""
    # the legend sits in a script string: <, > and quotes are escaped there
    page = tied_page.replace("\\u003c", "<").replace("\\u003e", ">").replace('\\"', '"')
    score5 = tied.result.candidates[5].score
    assert 0 < score5 < 1e-6
    assert f'data-legend-rank="6">6: {score5:.1e}' in page
    assert 'data-legend-rank="6">6: 0.000' not in page
    score1 = tied.result.candidates[0].score
    assert f'data-legend-rank="1">1: {score1:.3f}' in page
    assert f"#6 score {score5:.1e}" in page  # the marker's tooltip


def test_review_map_names_the_annotators_left_out(
    tmp_path: Path, fremantle: MapData, scene_result: tuple[Scene, LocateResult]
) -> None:
    """A crowd task whose annotator drew every line on the wrong axis: its result says the
    annotator was left out, but the review page (POST /v1/maps on the task's merged scene)
    showed only the candidates, as if all three annotators had agreed."""
    import copy

    scene, res = scene_result
    page = tmp_path / "plain.html"
    maps.candidates_map(res, fremantle, page, offline=True, scene=scene)
    assert "left out" not in page.read_text(encoding="utf-8")
    bad = copy.deepcopy(res)
    why = (
        "annotator 'w2' (annotations[2]) left out: vp_lines.length: 3 of 3 segments disagree "
        "with everybody else's (drawn for another axis?)"
    )
    bad.calibration.outlier_annotators = ["w2"]
    bad.calibration.warnings = [*bad.calibration.warnings, why]
    page = tmp_path / "left_out.html"
    maps.candidates_map(bad, fremantle, page, offline=True, scene=scene)
    text = page.read_text(encoding="utf-8")
    # the title control's HTML, as the page's script holds it (JSON-escaped)
    assert "\\u003cb\\u003eleft out: annotator w2\\u003c/b\\u003e" in text
    assert "(annotations[2]) left out: vp_lines.length: 3 of 3 segments disagree" in text


def test_summary_map_says_why_cameras_are_not_on_it(tmp_path: Path) -> None:
    """camloc batch --map listed the cameras without a point by bare name ("4 without
    candidates: c1 Eastern Ave & S Broadway, c4 ..."): a broken scene, a title not in the
    map and a camera without evidence read alike. They are now counted by status and each
    named with it, the whole reason on hover."""

    def empty(reason: str) -> dict[str, Any]:
        return {"type": "FeatureCollection", "features": [], "properties": {"reason": reason}}

    items = [
        ("c1 Eastern", empty("scene_error: scene broken.json: image.height: required")),
        ("c4 Eastern", empty("scene_error: scene garbage.json: malformed JSON")),
        ("c6 Nowhere", empty("not_found: 'Nowhere St' is not a street name of this map")),
    ]
    page = maps.summary_map(items, tmp_path / "s.html", offline=True).read_text(encoding="utf-8")
    assert "3 without candidates (2 scene_error, 1 not_found): " in page
    assert "c1 Eastern (scene_error)\\u003c/span\\u003e" in page
    assert "c6 Nowhere (not_found)" in page
    assert "scene broken.json: image.height: required" in page


def test_summary_map_names_every_camera_not_on_it_briefly(tmp_path: Path) -> None:
    """The sweep's 40-webcam list: 12 cameras without a point, of which the page named 10 and
    an ellipsis (two cameras nowhere on the page), and one scraped title of 300 characters
    filled the heading box (a third of a phone's screen). Names are now cut at 60 characters
    (the whole name and reason on hover) and the cameras past the first 10 are under a fold."""

    def empty(reason: str) -> dict[str, Any]:
        return {"type": "FeatureCollection", "features": [], "properties": {"reason": reason}}

    long_title = "html-01 <b>Cam</b> & E Monument St " + "very long description " * 12
    items = [(long_title, empty("not_found: 'Cam' is not a street name of this map"))]
    items += [(f"c{k} Nowhere St", empty("not_found: no such street")) for k in range(11)]
    page = maps.summary_map(items, tmp_path / "s.html", offline=True).read_text(encoding="utf-8")
    assert "12 without candidates (12 not_found): " in page
    label = maps._missing_label(long_title, "not_found: x")
    shown = label.split(">", 1)[1].rsplit("<", 1)[0]
    assert shown.endswith("description ve\u2026 (not_found)")
    assert len(shown) < 90
    assert "\\u003cb\\u003e" not in page.split("without candidates")[1][:400]
    assert "and 2 more\\u003c/summary\\u003e" in page
    assert "c9 Nowhere St (not_found)" in page
    assert "c10 Nowhere St (not_found)" in page
    assert "camloc-summary-title" in page


def test_review_map_without_candidates_never_says_none(tmp_path: Path) -> None:
    """A result without candidates and without a reason (one read back from a file) gave
    the title 'no candidates: None'."""
    import copy

    md = fremantle_map()
    scene, res = located(md, 0)
    empty = copy.copy(res)
    empty.candidates = []
    empty.reason = None
    page = maps.candidates_map(empty, md, tmp_path / "e.html", offline=True, scene=scene)
    text = page.read_text(encoding="utf-8")
    assert "no candidates\\u003c/b\\u003e: the locate result gives no reason" in text
    assert "\\u003c/b\\u003e: None" not in text


def test_summary_popup_shows_the_camera_reason(tmp_path: Path) -> None:
    """A camloc batch camera placed at its title's junction despite a bad list row
    ("junction of the map's model; list row: lat 'abc' is not a number") showed score,
    method and sigma in its popup but not that warning: the reason is now a popup row."""
    item = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [13.415, 52.5208]},
                "properties": {
                    "kind": "candidate",
                    "rank": 1,
                    "lat": 52.5208,
                    "lon": 13.415,
                    "score": 1.0,
                    "method": "title (title_only)",
                },
            }
        ],
        "properties": {
            "reason": "junction of the map's model; list row: lat 'abc' is not a number"
        },
    }
    page = maps.summary_map([("badlat <i>x</i>", item)], tmp_path / "s.html", offline=True)
    text = page.read_text(encoding="utf-8")
    assert (
        "<tr><th>reason</th><td>junction of the map&#x27;s model; list row: lat &#x27;abc&#x27;"
        " is not a number</td></tr>" in text
    )
