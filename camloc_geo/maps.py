"""Review maps (Leaflet, via folium): candidate maps for one scene and summary maps.

A reviewer decides from the candidate map which candidate position is right:

- candidates are numbered by rank and each rank has its own colour (:data:`RANK_PALETTE`,
  Okabe–Ito, colour-blind safe: rank 1 blue, 2 orange, 3 green...), sized by rank, the best
  drawn on top with a heavy outline; their popups list every property of the candidate
  GeoJSON (:func:`camloc_geo.results.candidates_geojson`) and show the image overlay
  (:mod:`camloc_geo.overlay`) of the leading candidates; the legend lists each rank's colour
  and score;
- candidates that tie (non-empty ``ambiguous_with``) wear a dashed ring and an "≈" badge;
  a banner at the top of the page says which candidates tie, how close their scores are,
  why (the result's ``ambiguous`` warning, their flags) and what evidence would decide;
  each tied candidate's popup names the ranks it ties with;
- view cones (60 m) of the three best candidates are shown in their candidate's colour, the
  others' in a hidden layer;
- the intersection's kerb corners are shown with their map order (``m0``, ``m1``... clockwise
  from above); for each leading candidate a layer numbers the map corners with the index of
  the scene corner matched to them (``intersection.corners[i]``) and joins them to the
  camera position;
- the streets (centre lines and modelled carriageways) and buildings near the scene are
  vector layers; a layer control, a legend and a scale bar complete the page.

The summary map colours each camera's best candidate by score (:data:`SCORE_SCALE`); a camera
whose best candidate is tied gets a dashed ring and an "≈" badge, and its popup says which
candidate it is tied with.

Pages without tiles draw the OpenStreetMap streets (names on hover) and buildings as an
inlined vector basemap (:func:`basemap_features`): the review page within its disc, the
summary pages within :data:`SUMMARY_BASEMAP_RADIUS_M` of each camera; capped at
:data:`BASEMAP_MAX_ROADS` and :data:`BASEMAP_MAX_BUILDINGS` features, nearest first (the page
says so when capped), with OSM's attribution in the map's corner. A clustered summary page
clusters only markers all but on top of each other (:data:`CLUSTER_NEAR_PX`) at the zoom it
opens at and closer; both pages open fitted clear of the boxes over the map.

Offline pages (``offline=True``) are one self-contained HTML file: Leaflet's JS and CSS
and jQuery (which folium's popups use) are inlined from the ``xstatic-leaflet`` and
``xstatic-jquery`` packages, Leaflet's images become data URIs, every other asset folium
references (bootstrap, font-awesome, awesome-markers) is dropped, markers are DivIcons, and
there is no tile layer: the page makes no request at all. Online pages use folium's CDN links
and may add a tile basemap (OpenStreetMap by default, with its attribution).
"""

from __future__ import annotations

import base64
import html
import logging
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import folium
import numpy as np
import numpy.typing as npt
import shapely
import shapely.affinity
import shapely.prepared
from branca.element import Figure, MacroElement
from jinja2 import Template
from shapely.geometry import LineString, Point, Polygon

from camloc_geo import overlay as _overlay
from camloc_geo.results import ATTRIBUTION, TIE_DISTANCE_M, TIE_SCORE_RATIO

if TYPE_CHECKING:
    from camloc_geo.absolute import LocateResult
    from camloc_geo.geodesy import LocalFrame
    from camloc_geo.osm import MapData
    from camloc_geo.scene import Scene

__all__ = [
    "BASEMAP_MAX_AREAS",
    "BASEMAP_MAX_BUILDINGS",
    "BASEMAP_MAX_ROADS",
    "CLUSTER_NEAR_PX",
    "CLUSTER_OPEN_MAX_MARKERS",
    "CLUSTER_STREET_ZOOM",
    "MAX_PAGE_BYTES",
    "RANK_OTHER",
    "RANK_PALETTE",
    "SCORE_SCALE",
    "SUMMARY_BASEMAP_RADIUS_M",
    "VERDICTS",
    "VERDICT_FIELDS",
    "Basemap",
    "basemap_features",
    "basemap_maps",
    "build_candidates_map",
    "build_summary_map",
    "candidates_map",
    "inline_assets",
    "leaflet_assets",
    "rank_colour",
    "rank_style",
    "read_verdicts",
    "score_colour",
    "summary_map",
    "summary_page",
]

log = logging.getLogger(__name__)

MAX_PAGE_BYTES = 1_500_000
"""Size budget of a one-scene page (offline pages embed their overlays within it)."""

SCORE_SCALE: tuple[tuple[float, str, str], ...] = (
    (0.5, "#800026", "≥ 0.5"),
    (0.2, "#e31a1c", "0.2 – 0.5"),
    (0.05, "#fd8d3c", "0.05 – 0.2"),
    (0.01, "#fed976", "0.01 – 0.05"),
    (0.0, "#ffffcc", "< 0.01"),
)
"""Score bins (lower bound, fill colour, legend text), best first (ColorBrewer YlOrRd)."""

RANK_PALETTE: tuple[str, ...] = (
    "#0072B2",  # blue
    "#E69F00",  # orange
    "#009E73",  # bluish green
    "#CC79A7",  # reddish purple
    "#56B4E9",  # sky blue
    "#D55E00",  # vermillion
    "#F0E442",  # yellow
    "#000000",  # black
)
"""Colour of candidate ranks 1, 2, ... 8 on the one-scene page: the Okabe–Ito palette
(Okabe & Ito 2008, "Color Universal Design"), told apart under the common colour-vision
deficiencies. Neighbouring ranks never share a colour."""

RANK_OTHER = "#999999"
"""Colour of ranks beyond :data:`RANK_PALETTE` (grey)."""

TIE_CHOICE_WORDS = (
    "the camera may stand at a tied candidate instead: choose it under 'or the camera is "
    "candidate…' below (its review page, camloc locate --map, draws them all)"
)
"""A summary page's popup of a tied best candidate: what to do. It said "see the camera's
review page", a page a job's summary (``GET /v1/jobs/{id}/map``) or a batch's has not
(session 41 QA), while the popup itself offers the choice."""

TIE_RING = "#111111"
"""Colour of the dashed ring and the "≈" badge of a tied candidate."""

OSM_ATTRIBUTION = ATTRIBUTION
_OSM_TILES_ATTR = (
    '&copy; <a href="https://www.openstreetmap.org/copyright">OpenStreetMap</a> contributors, ODbL'
)
"""OSM's credit in the map's attribution line: the OSM tile layer's and the vector
basemap's (one text, so Leaflet shows it once when both are on a page)."""

_STYLE: dict[str, Any] = {
    "building": {"color": "#8d6e63", "weight": 1, "fillColor": "#d7ccc8", "fillOpacity": 0.7},
    "carriageway": {"color": "#616161", "weight": 1.2, "fillColor": "#ffffff", "fillOpacity": 0.9},
    "centre": {"color": "#9e9e9e", "weight": 1.5, "dashArray": "6 4"},
    "corner": "#1565c0",
    "match": "#6a1b9a",
    "prior": "#00897b",
}
_OVERLAY_TOP = 5
_MATCH_LAYERS = 5
_CONES_SHOWN = 3
_BANNER_FOLDED_PX = 60  # the banner folded to its headline while a popup is open
BANNER_FOLD_BELOW_PX = (1200, 800)
"""A map narrower or lower than this (pixels) opens with the banner folded to its headline."""
SMALL_SCREEN_PX = 720
"""A map narrower than this (a phone) opens with its layer list folded to Leaflet's layers
button and its legend folded to its heading: unfolded, the two covered the whole map of a
390x844 phone, the candidates under them."""


# ----------------------------------------------------------------------------- styling
def score_colour(score: float) -> str:
    """Fill colour of a score on :data:`SCORE_SCALE`."""
    s = float(score) if score is not None and math.isfinite(score) else 0.0
    for lower, colour, _text in SCORE_SCALE:
        if s >= lower:
            return colour
    return SCORE_SCALE[-1][1]


def rank_colour(rank: int) -> str:
    """Colour of a candidate rank on the one-scene page (:data:`RANK_PALETTE`)."""
    r = int(rank)
    return RANK_PALETTE[r - 1] if 1 <= r <= len(RANK_PALETTE) else RANK_OTHER


def rank_style(rank: int) -> tuple[int, float, int]:
    """``(diameter_px, outline_px, z_index_offset)`` of a candidate marker of a rank."""
    if rank <= 1:
        return 34, 3.5, 10_000
    if rank <= 3:
        return 26, 2.0, 5_000 - rank
    return 20, 1.2, 1_000 - min(rank, 999)


def _text_colour(fill: str) -> str:
    r, g, b = (int(fill[i : i + 2], 16) for i in (1, 3, 5))
    return "#000" if 0.299 * r + 0.587 * g + 0.114 * b > 150 else "#fff"


def _fmt(value: Any, unit: str = "", digits: int = 2) -> str:
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        if not math.isfinite(value):
            return "—"
        return f"{value:.{digits}f}{unit}"
    if isinstance(value, (list, tuple)):
        return ", ".join(str(v) for v in value) if value else "none"
    return f"{value}{unit}"


def _score_text(value: Any, digits: int = 3) -> str:
    """A score as people read it: ``0.375``, then ``1.1e-15`` where three decimals would say
    ``0.000`` (a tiny score is not a zero one; QGIS's ``score_text`` does the same)."""
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        return "—"
    if value == 0 or abs(value) >= 0.5 * 10.0**-digits:
        return f"{value:.{digits}f}"
    return f"{value:.1e}"


# ------------------------------------------------------------------------ map elements
class _Control(MacroElement):
    """A Leaflet control holding static HTML (legend, title)."""

    _template = Template(
        """
{% macro header(this, kwargs) %}
<style>{{ this.css }}</style>
{% endmacro %}
{% macro script(this, kwargs) %}
var {{ this.get_name() }} = L.control({position: {{ this.position|tojson }}});
{{ this.get_name() }}.onAdd = function (map) {
    var div = L.DomUtil.create("div", {{ this.css_class|tojson }});
    div.innerHTML = {{ this.html|tojson }};
    L.DomEvent.disableClickPropagation(div);
    L.DomEvent.disableScrollPropagation(div);
    return div;
};
{{ this.get_name() }}.addTo({{ this._parent.get_name() }});
{% endmacro %}
"""
    )

    def __init__(self, html_text: str, *, position: str, css_class: str, css: str = "") -> None:
        super().__init__()
        self._name = "CamlocControl"
        self.html = html_text
        self.position = position
        self.css_class = css_class
        self.css = css


class _SmallScreenFolds(MacroElement):
    """On a map narrower than :data:`SMALL_SCREEN_PX`: the layer list folded to its button
    (a tap opens it, a tap on the map folds it), the legend to its heading (a tap on it
    unfolds or folds it), and the top controls hidden while a popup is open (it fills the
    screen's width; they covered its first rows)."""

    _template = Template(
        """
{% macro script(this, kwargs) %}
setTimeout(function () {  // after every control of the page is on the map
    var map = {{ this._parent.get_name() }};
    if (map.getSize().x >= {{ this.below }}) { return; }
    var box = map.getContainer();
    var layers = box.querySelector(".leaflet-control-layers");
    if (layers) {
        L.DomUtil.removeClass(layers, "leaflet-control-layers-expanded");
        var button = layers.querySelector(".leaflet-control-layers-toggle");
        if (button) {
            button.title = "layers";
            L.DomEvent.on(button, "click", function (e) {
                L.DomEvent.preventDefault(e);
                L.DomUtil.addClass(layers, "leaflet-control-layers-expanded");
            });
        }
        map.on("click", function () {
            L.DomUtil.removeClass(layers, "leaflet-control-layers-expanded");
        });
    }
    // the popup fills a phone's width: the top controls (title box, zoom, layers, the
    // verdicts' counter) drew over its first rows; they step aside while it is open
    map.on("popupopen", function () { L.DomUtil.addClass(box, "camloc-popup-open"); });
    map.on("popupclose", function () { L.DomUtil.removeClass(box, "camloc-popup-open"); });
    var legend = box.querySelector(".camloc-legend");
    if (legend) {
        L.DomUtil.addClass(legend, "folded");
        var head = legend.querySelector("h4");
        if (head) {
            head.title = "tap to show or hide the legend";
            L.DomEvent.on(head, "click", function () {
                var fold = !L.DomUtil.hasClass(legend, "folded");
                (fold ? L.DomUtil.addClass : L.DomUtil.removeClass)(legend, "folded");
            });
        }
    }
}, 0);
{% endmacro %}
"""
    )

    def __init__(self) -> None:
        super().__init__()
        self._name = "CamlocSmallScreen"
        self.below = SMALL_SCREEN_PX


class _Banner(MacroElement):
    """A box at the top centre of the map (over the tiles, under nothing)."""

    _template = Template(
        """
{% macro script(this, kwargs) %}
(function () {
    var div = L.DomUtil.create(
        "div", {{ this.css_class|tojson }}, {{ this._parent.get_name() }}.getContainer());
    div.innerHTML = {{ this.html|tojson }};
    L.DomEvent.disableClickPropagation(div);
    L.DomEvent.disableScrollPropagation(div);
    var map = {{ this._parent.get_name() }};
    // on a small screen (a laptop's 1024x640) the whole explanation covered the tied
    // candidates it is about: there it starts folded to its headline; a click on the
    // headline folds or unfolds it anywhere
    var size = map.getSize();
    var folded = size.y < {{ this.fold_below[1] }} || size.x < {{ this.fold_below[0] }};
    function show() {
        if (folded) { L.DomUtil.addClass(div, "folded"); }
        else { L.DomUtil.removeClass(div, "folded"); }
    }
    var head = div.querySelector("h4");
    if (head) {
        head.title = "click to show or hide the explanation";
        L.DomEvent.on(head, "click", function () { folded = !folded; show(); });
    }
    show();
    // an open popup would be under the banner: fold it to its headline meanwhile
    map.on("popupopen", function () { L.DomUtil.addClass(div, "folded"); });
    map.on("popupclose", show);
})();
{% endmacro %}
"""
    )

    def __init__(self, html_text: str, *, css_class: str) -> None:
        super().__init__()
        self._name = "CamlocBanner"
        self.html = html_text
        self.css_class = css_class
        self.fold_below = BANNER_FOLD_BELOW_PX


_PAGE_CSS = """
.camloc-legend, .camloc-title { background: rgba(255,255,255,0.93); padding: 6px 9px;
  border-radius: 5px; box-shadow: 0 1px 5px rgba(0,0,0,0.4); font: 12px/1.35 sans-serif;
  color: #222; }
.camloc-legend { max-width: 260px; }
.camloc-summary-title { max-height: 40vh; overflow-y: auto; box-sizing: border-box;
  max-width: min(560px, calc(100vw - 20px)); }
.camloc-title { overflow-wrap: anywhere; }
.camloc-title:not(.camloc-summary-title) { max-width: min(290px, calc(100vw - 80px)); }
.camloc-more summary { cursor: pointer; color: #124; }
.leaflet-control-layers-expanded { font: 12px/1.4 sans-serif; padding: 4px 8px; }
.leaflet-container { font-family: sans-serif; }
.camloc-legend h4, .camloc-title h4 { margin: 0 0 4px; font-size: 13px; }
.camloc-legend .sw { display: inline-block; width: 14px; height: 14px; border-radius: 50%;
  border: 1px solid #333; vertical-align: middle; margin-right: 5px; }
.camloc-legend .ln { display: inline-block; width: 18px; height: 0; vertical-align: middle;
  margin-right: 5px; border-top: 3px solid #333; }
.camloc-legend .bx { display: inline-block; width: 14px; height: 10px; vertical-align: middle;
  margin-right: 5px; border: 1px solid #333; }
.camloc-legend small { color: #555; }
.camloc-candidate, .camloc-summary-marker { background: transparent; border: none; }
.camloc-dot { box-sizing: border-box; border-radius: 50%; border-style: solid; border-color: #111;
  display: flex; align-items: center; justify-content: center; font: bold 12px sans-serif;
  box-shadow: 0 1px 4px rgba(0,0,0,0.5); width: 100%; height: 100%; }
.camloc-corner-label { background: transparent; border: none; }
.camloc-corner-label div { font: bold 11px sans-serif; color: #fff; border-radius: 8px;
  padding: 0 4px; text-align: center; white-space: nowrap; border: 1px solid #fff; }
.camloc-popup { font: 12px/1.3 sans-serif; }
.camloc-popup table { border-collapse: collapse; }
.camloc-popup td, .camloc-popup th { padding: 1px 6px 1px 0; text-align: left;
  vertical-align: top; }
.camloc-popup img { display: block; width: 460px; margin-top: 6px;
  border: 1px solid #999; }
.camloc-tied { position: relative; width: 100%; height: 100%; }
.camloc-tied::before { content: ""; position: absolute; inset: -6px; border-radius: 50%;
  border: 2.5px dashed #111; background: rgba(255,255,255,0.55); }
.camloc-tied .camloc-dot { position: relative; }
.camloc-tied-arrow { position: relative; width: 100%; height: 100%; }
.camloc-tied-arrow svg { display: block; }
.camloc-badge { position: absolute; top: -11px; right: -11px; width: 16px; height: 16px;
  border-radius: 50%; background: #fff; color: #111; border: 1.5px solid #111;
  font: bold 13px/14px sans-serif; text-align: center; box-sizing: border-box; }
.camloc-banner { position: absolute; top: 10px; left: 50%; transform: translateX(-50%);
  z-index: 1000; max-width: min(640px, calc(100% - 640px)); min-width: 320px;
  background: #fff8e1; border: 2px solid #b26a00; border-radius: 6px; padding: 7px 11px;
  box-shadow: 0 2px 7px rgba(0,0,0,0.45); font: 12.5px/1.4 sans-serif; color: #222; }
.camloc-legend.folded { max-height: 1.45em; overflow: hidden; }
.camloc-popup-open .leaflet-top .leaflet-control { visibility: hidden; }
@media (max-width: 719px) {
  .leaflet-control-attribution { font-size: 10px; max-width: calc(100vw - 110px);
    white-space: normal; text-align: right; }
  .camloc-banner { top: auto; bottom: 100px; min-width: 0; max-width: calc(100% - 40px);
    width: calc(100% - 40px); }
  .leaflet-popup-content { max-width: calc(100vw - 70px) !important; max-height: 62vh;
    overflow-y: auto; }
  .camloc-popup img { width: 100%; }
}
.camloc-legend.folded h4 { cursor: pointer; }
.camloc-legend.folded h4::after { content: " \\25B8"; font-weight: normal; color: #555; }
.camloc-banner.folded .camloc-banner-body { display: none; }
.camloc-banner.folded h4 { margin: 0; }
.camloc-banner h4 { cursor: pointer; }
.camloc-banner.folded h4::after { content: " \\25B8 why, and what decides"; font-weight: normal;
  font-size: 11.5px; color: #555; }
.camloc-banner.minor { background: rgba(255,255,255,0.93); border-color: #777; }
.camloc-banner h4 { margin: 0 0 3px; font-size: 14px; color: #7a3e00; }
.camloc-banner.minor h4 { color: #333; font-size: 12.5px; }
.camloc-banner ul { margin: 3px 0 0; padding-left: 18px; }
.camloc-banner code, .camloc-popup code { background: #eee; padding: 0 2px; }
.camloc-tie { background: #fff8e1; border-left: 3px solid #b26a00; padding: 3px 6px;
  margin: 3px 0 5px; }
"""


def _tie_swatch(fill: str) -> str:
    """A legend swatch of a tied marker: dashed ring and "≈"."""
    return (
        f'<span class="sw" style="background:{fill};border:2px dashed {TIE_RING};'
        'text-align:center;font:bold 10px/10px sans-serif">≈</span>'
    )


def _legend_html(
    *,
    scene_id: str | None,
    has_corners: bool,
    has_prior: bool,
    summary: bool,
    cands: Sequence[Mapping[str, Any]] = (),
    any_tie: bool = False,
) -> str:
    rows = []
    title = "Camera positions" if summary else "Candidate camera positions"
    rows.append(f"<h4>{html.escape(title)}</h4>")
    if summary:
        rows.append("<small>best candidate per camera; arrow = heading</small><br>")
        rows.append("<b>score</b><br>")
        for _lower, colour, text in SCORE_SCALE:
            rows.append(
                f'<span class="sw" style="background:{colour}"></span>{html.escape(text)}<br>'
            )
        if any_tie:
            rows.append(
                _tie_swatch("#fff") + "best candidate tied with another (see its popup)<br>"
            )
    else:
        rows.append(
            "<small>number = rank (1 = most likely); larger = better; "
            "colour = rank (Okabe–Ito)</small><br>"
        )
        rows.append("<b>rank: score</b><br>")
        shown = [p for p in cands if isinstance(p.get("rank"), int)][: len(RANK_PALETTE)]
        for p in shown:
            rank = int(p["rank"])
            ties = _ties_of(p)
            swatch = (
                _tie_swatch(rank_colour(rank))
                if ties
                else f'<span class="sw" style="background:{rank_colour(rank)}"></span>'
            )
            tie = f" ≈ tied with {_and(ties)}" if ties else ""
            rows.append(
                f'{swatch}<span data-legend-rank="{rank}">{rank}: '
                f"{_score_text(p.get('score'))}{html.escape(tie)}</span><br>"
            )
        if len(cands) > len(RANK_PALETTE):
            rows.append(
                f'<span class="sw" style="background:{RANK_OTHER}"></span>'
                f"ranks {len(RANK_PALETTE) + 1}–{len(cands)}<br>"
            )
        if any_tie:
            rows.append(_tie_swatch("#fff") + "dashed ring, ≈: tied (see the banner)<br>")
        rows.append(
            f'<span class="bx" style="background:{rank_colour(1)};opacity:.45"></span>'
            "view cone (60 m), in its candidate's colour<br>"
        )
        if has_corners:
            rows.append(
                f'<span class="sw" style="background:{_STYLE["corner"]}"></span>'
                "map kerb corner m<i>j</i> (clockwise)<br>"
            )
            rows.append(
                f'<span class="sw" style="background:{_STYLE["match"]}"></span>'
                "scene corner <i>i</i> matched here<br>"
            )
        rows.append(
            f'<span class="bx" style="background:{_STYLE["carriageway"]["fillColor"]}"></span>'
            "carriageway (modelled width)<br>"
        )
        rows.append(
            f'<span class="ln" style="border-top:2px dashed {_STYLE["centre"]["color"]}"></span>'
            "street centre line<br>"
        )
        rows.append(
            f'<span class="bx" style="background:{_STYLE["building"]["fillColor"]}"></span>'
            "building<br>"
        )
        if has_prior:
            rows.append(
                f'<span class="ln" style="border-top:2px dashed {_STYLE["prior"]}"></span>'
                "prior area<br>"
            )
    rows.append(f"<small>{html.escape(OSM_ATTRIBUTION)}</small>")
    return "".join(rows)


# -------------------------------------------------------------------------------- ties
_TIE_RULE = (
    f"the weaker scores at least {TIE_SCORE_RATIO:g} of the stronger (the evidence favours one "
    f"by less than {1 / TIE_SCORE_RATIO:g} to 1), yet they stand more than {TIE_DISTANCE_M:g} m "
    "apart: the "
    "evidence cannot tell them apart firmly (typically a symmetric junction seen with two corners)"
)
_COMPASS: tuple[str, ...] = ("N", "NNE", "NE", "ENE", "E", "ESE", "SE", "SSE")
_COMPASS += ("S", "SSW", "SW", "WSW", "W", "WNW", "NW", "NNW")


def _compass(bearing_deg: Any) -> str | None:
    """``"NNW (335°)"`` for a bearing; None when there is none."""
    if not isinstance(bearing_deg, (int, float)) or not math.isfinite(bearing_deg):
        return None
    b = float(bearing_deg) % 360.0
    return f"{_COMPASS[int((b + 11.25) // 22.5) % 16]} ({b:.0f}°)"


def _distance_m(a: Mapping[str, Any], b: Mapping[str, Any]) -> float:
    """Ground distance between two candidates' lat/lon, metres (:func:`geodesy.distance_m`)."""
    from camloc_geo.geodesy import distance_m

    return float(
        distance_m(
            lat1=float(a["lat"]), lon1=float(a["lon"]), lat2=float(b["lat"]), lon2=float(b["lon"])
        )
    )


def _ties_of(props: Mapping[str, Any]) -> list[int]:
    """The ranks a candidate ties with (its ``ambiguous_with``; tolerant of odd input)."""
    raw = props.get("ambiguous_with") or []
    if isinstance(raw, (int, str)):
        raw = [raw]
    out = []
    for r in raw if isinstance(raw, (list, tuple)) else []:
        try:
            out.append(int(r))
        except (TypeError, ValueError):
            continue
    return sorted(set(out) - {props.get("rank")})


def _tie_groups(cands: Sequence[Mapping[str, Any]]) -> list[list[int]]:
    """Ranks that tie, as connected groups of two or more, ordered by their best rank."""
    ranks = {int(p["rank"]) for p in cands if isinstance(p.get("rank"), int)}
    parent = {r: r for r in ranks}

    def root(r: int) -> int:
        while parent[r] != r:
            r = parent[r]
        return r

    for p in cands:
        if not isinstance(p.get("rank"), int):
            continue
        for other in _ties_of(p):
            if other in parent:
                a, b = root(int(p["rank"])), root(other)
                parent[max(a, b)] = min(a, b)
    groups: dict[int, list[int]] = {}
    for r in sorted(ranks):
        groups.setdefault(root(r), []).append(r)
    return sorted((g for g in groups.values() if len(g) >= 2), key=lambda g: g[0])


def _and(items: Sequence[Any]) -> str:
    """``"1 and 2"``, ``"1, 2 and 3"``."""
    words = [str(i) for i in items]
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def _tie_reason(group: Sequence[int], collection: Mapping[str, Any], *, short: bool = False) -> str:
    """Why these ranks tie: the result's tie naming them (its ``ties`` data), else the rule.

    ``short``: only the explanation (what would decide), without the odds the banner already
    says. Escaped HTML.
    """
    for tie in collection.get("ties") or []:
        ranks = tie.get("ranks") if isinstance(tie, Mapping) else None
        if isinstance(ranks, list) and set(group[:2]) <= set(ranks):
            text = str(tie.get("why" if short else "text") or "")
            if text:
                return html.escape(text.rstrip(". "))
    return html.escape(_TIE_RULE)


def _flags_text(group: Sequence[int], by_rank: Mapping[int, Mapping[str, Any]]) -> str:
    flagged = [(r, list(by_rank[r].get("flags") or [])) for r in group]
    if not any(f for _r, f in flagged):
        return "none (the map finds nothing implausible about any of them)"
    return "; ".join(
        f"{r}: {html.escape(', '.join(str(x) for x in f)) if f else 'none'}" for r, f in flagged
    )


def _tie_hints(group: Sequence[int], by_rank: Mapping[int, Any], scene: Scene | None) -> str:
    """What evidence would break a tie, one HTML sentence (cues the scene lacks first)."""
    looks = [c for c in (_compass(by_rank[r].get("heading_deg")) for r in group) if c]
    items = []
    given = []
    if scene is None or scene.view_hint is None:
        sectors = list({c.split(" ", 1)[0]: c for c in reversed(looks)}.values())[::-1]
        which = f": does it look {' or '.join(sectors)}?" if len(sectors) >= 2 else ""
        items.append(f"<code>view_hint</code> (the camera's direction{html.escape(which)})")
    else:
        given.append("view_hint")
    if scene is None or scene.object.street is None:
        items.append("<code>object.street</code> (the car's street)")
    else:
        given.append("object.street")
    if scene is None or scene.object.front is None:
        items.append("<code>object.front</code> (the car's front; decides on a one-way street)")
    else:
        given.append("object.front")
    items.append(
        "a reference pixel with its lat/lon, a landmark, another kerb corner or a tighter "
        "<code>prior</code>"
    )
    head = "<b>To break the tie</b>, add to the scene "
    if given:
        head = (
            f"The scene's {html.escape(_and(given))} did not decide. <b>To break the tie</b>, add "
        )
    return head + ", ".join(items[:-1]) + (", or " if len(items) > 1 else "") + items[-1] + "."


def _tie_banner(
    collection: Mapping[str, Any], cands: Sequence[Mapping[str, Any]], scene: Scene | None
) -> tuple[str, str] | None:
    """``(html, css_class)`` of the page's tie banner; None when no candidates tie."""
    groups = _tie_groups(cands)
    if not groups:
        return None
    by_rank = {int(p["rank"]): p for p in cands if isinstance(p.get("rank"), int)}
    main = groups[0] if groups[0][0] == 1 else None
    rest = [g for g in groups if g is not main]
    parts = []
    if main is not None:
        scores = [float(by_rank[r].get("score") or 0.0) for r in main]
        ratio = min(scores) / max(scores) if max(scores) > 0 else 1.0
        gap = max(_distance_m(by_rank[a], by_rank[b]) for a in main for b in main if a < b)
        looks = [c for c in (_compass(by_rank[r].get("heading_deg")) for r in main) if c]
        parts.append(
            f"<h4>≈ Ambiguous: candidates {_and(main)} "
            f"{'all' if len(main) > 2 else 'both'} fit the evidence "
            f"(score ratio {ratio:.2f}; tied: odds under {1 / TIE_SCORE_RATIO:g} to 1)</h4>"
            f"Scores {' vs '.join(f'{x:.3f}' for x in scores)}, {gap:.0f} m apart"
            + (f", looking {html.escape(' vs '.join(looks))}" if looks else "")
            + f". Flags: {_flags_text(main, by_rank)}. Check "
            + ("them all" if len(main) > 2 else "both")
            + " before choosing rank 1.<br>"
            f"<b>Why:</b> {_tie_reason(main, collection, short=True)}.<br>"
            + _tie_hints(main, by_rank, scene)
        )
        css = "camloc-banner"
    else:
        parts.append(
            f"<h4>≈ Candidates {_and(rest[0])} tie with each other</h4>"
            f"The best candidate (rank 1) is not tied. <b>Why:</b> {html.escape(_TIE_RULE)}."
        )
        rest = rest[1:]
        css = "camloc-banner minor"
    if rest:
        shown = ", ".join(" ≈ ".join(str(r) for r in g) for g in rest[:6])
        top = max(float(by_rank[r].get("score") or 0.0) for g in rest for r in g)
        parts.append(
            f"<br><small>Also tied: {shown}{' …' if len(rest) > 6 else ''} "
            f"(scores at most {top:.3f}).</small>"
        )
    head, body = "".join(parts).split("</h4>", 1)
    return f'{head}</h4><div class="camloc-banner-body">{body}</div>', css


def _tie_note(
    props: Mapping[str, Any],
    by_rank: Mapping[int, Mapping[str, Any]],
    collection: Mapping[str, Any],
) -> str:
    """The popup's line on a tied candidate: whom it ties with and why (empty if untied)."""
    others = [r for r in _ties_of(props) if r in by_rank]
    if not others:
        return ""
    rank = int(props.get("rank", 0))
    score = float(props.get("score") or 0.0)
    bits = []
    for r in others:
        o = by_rank[r]
        s = float(o.get("score") or 0.0)
        ratio = min(s, score) / max(s, score) if max(s, score) > 0 else 1.0
        look = _compass(o.get("heading_deg"))
        bits.append(
            f"<b>{r}</b> (score {s:.3f}, ratio {ratio:.2f}, {_distance_m(props, o):.0f} m away"
            + (f", looking {look}" if look else "")
            + ")"
        )
    word = "candidate" if len(others) == 1 else "candidates"
    return (
        f'<div class="camloc-tie">≈ <b>Tied with {word}</b> {_and(bits)}.'
        f"<br>Why: {_tie_reason(sorted([rank, *others]), collection)}."
        "</div>"
    )


# ----------------------------------------------------------------------- vector basemap
BASEMAP_MAX_ROADS = 1500
"""At most this many street pieces are drawn on one page's vector basemap (nearest the
cameras first; the page says so when more were in reach)."""
BASEMAP_MAX_BUILDINGS = 1500
"""At most this many building outlines are drawn on one page's vector basemap (nearest
first; the page says so when more were in reach)."""
SUMMARY_BASEMAP_RADIUS_M = 250.0
"""A summary page's vector basemap covers this many metres around each camera."""

_ROAD_WEIGHT = {
    "motorway": 9,
    "trunk": 9,
    "primary": 8,
    "secondary": 8,
    "tertiary": 7,
    "residential": 6,
    "unclassified": 6,
    "living_street": 5,
    "service": 4,
}
_BASEMAP_ROAD = {"color": "#ffffff", "opacity": 1.0, "lineCap": "round", "lineJoin": "round"}
_BASEMAP_CASING = {"color": "#9a9a92", "opacity": 1.0, "lineCap": "round", "lineJoin": "round"}
_BASEMAP_BACKGROUND = "#efeee9"
_BASEMAP_FULL_ZOOM = 18
_BASEMAP_BUILDING = {"color": "#a1887f", "weight": 1, "fillColor": "#e4dcd6", "fillOpacity": 0.8}


@dataclass(frozen=True)
class Basemap:
    """The OSM streets and buildings a page draws under its markers (lon/lat GeoJSON).

    Attributes
    ----------
    roads, buildings
        GeoJSON features, nearest the page's points first, at most the caps.
    roads_in_reach, buildings_in_reach
        How many were inside the clip before the caps.
    """

    roads: list[dict[str, Any]]
    buildings: list[dict[str, Any]]
    roads_in_reach: int
    buildings_in_reach: int

    @property
    def capped(self) -> bool:
        """More features were in reach than are drawn."""
        roads_left = self.roads_in_reach > len(self.roads)
        return roads_left or self.buildings_in_reach > len(self.buildings)

    @property
    def empty(self) -> bool:
        """Nothing to draw."""
        return not self.roads and not self.buildings


def _lonlat_geojson(geom: Any) -> dict[str, Any] | None:
    """A clipped shapely geometry in lon/lat → a GeoJSON geometry (lines or polygons only),
    coordinates rounded to 6 decimals (about 0.1 m)."""
    if geom.is_empty:
        return None
    lines: list[Any] = []
    polys: list[Any] = []
    for g in getattr(geom, "geoms", [geom]):
        if g.is_empty:
            continue
        if isinstance(g, LineString) and len(g.coords) >= 2:
            lines.append([list(c[:2]) for c in g.coords])
        elif isinstance(g, Polygon):
            polys.append(
                [[list(c[:2]) for c in g.exterior.coords]]
                + [[list(c[:2]) for c in r.coords] for r in g.interiors]
            )
        elif hasattr(g, "geoms"):
            sub = _lonlat_geojson(g)
            if sub is not None and sub["type"] == "MultiLineString":
                lines.extend(sub["coordinates"])
            elif sub is not None:
                polys.extend(sub["coordinates"])
    if polys:
        return {"type": "MultiPolygon", "coordinates": _round_coords(polys)}
    if lines:
        return {"type": "MultiLineString", "coordinates": _round_coords(lines)}
    return None


_SIMPLIFY_DEG = 3e-6
"""Outlines are simplified to about 0.3 m (degrees) before they are written: a page's
basemap is for telling a street from a building, not for surveying."""


def _simplified(geom: Any) -> Any:
    return geom.simplify(_SIMPLIFY_DEG, preserve_topology=True) if not geom.is_empty else geom


def _unit_vectors(lonlat: npt.ArrayLike) -> np.ndarray:
    """(lon, lat) degrees → unit vectors (N, 3): their chord distance times the earth's
    radius is the distance apart in metres, for points a few km apart or closer."""
    arr = np.radians(np.asarray(lonlat, dtype=float).reshape(-1, 2))
    cos_lat = np.cos(arr[:, 1])
    return np.column_stack(
        [cos_lat * np.cos(arr[:, 0]), cos_lat * np.sin(arr[:, 0]), np.sin(arr[:, 1])]
    )


def _nearest_m(near_lonlat: np.ndarray, refs_lonlat: list[tuple[float, float]]) -> np.ndarray:
    """Metres from each reference point to the nearest of ``near_lonlat`` (a k-d tree: a
    batch's page has up to 50,000 cameras)."""
    if not refs_lonlat:
        return np.zeros(0)
    from scipy.spatial import cKDTree

    dist, _idx = cKDTree(_unit_vectors(near_lonlat)).query(_unit_vectors(refs_lonlat))
    return np.asarray(dist, dtype=float) * 6_371_008.8


def basemap_features(
    maps_data: Sequence[MapData],
    clip_lonlat: Any,
    near_lonlat: npt.ArrayLike,
    *,
    max_roads: int | None = None,
    max_buildings: int | None = None,
) -> Basemap:
    """The streets and buildings of some maps inside a clip area, nearest some points first.

    Parameters
    ----------
    maps_data
        The maps (a street piece or building in two of them is drawn once: by its geometry,
        by its OSM id).
    clip_lonlat
        A shapely geometry in (lon, lat) degrees: features are cut to it.
    near_lonlat
        ``(N, 2)`` (lon, lat) of the page's points (cameras, candidates): the features
        nearest them are kept first when a cap is reached.
    max_roads, max_buildings
        Caps on the features kept (>= 0); default :data:`BASEMAP_MAX_ROADS` and
        :data:`BASEMAP_MAX_BUILDINGS`.

    Returns
    -------
    Basemap
        The features kept and how many were in reach.
    """
    near = np.asarray(near_lonlat, dtype=float).reshape(-1, 2)
    if near.shape[0] == 0:
        c = clip_lonlat.centroid
        near = np.array([[c.x, c.y]])
    prepared = shapely.prepared.prep(clip_lonlat)
    roads: list[tuple[tuple[float, float], dict[str, Any]]] = []
    buildings: list[tuple[tuple[float, float], dict[str, Any]]] = []
    seen_roads: set[Any] = set()
    seen_buildings: set[str] = set()
    for md in maps_data:
        for st in md.streets:
            key = st.geometry.wkb  # one piece of street in two maps: drawn once
            if key in seen_roads or not prepared.intersects(st.geometry):
                continue
            seen_roads.add(key)
            geom = _lonlat_geojson(_simplified(st.geometry.intersection(clip_lonlat)))
            if geom is None:
                continue
            mid = st.geometry.interpolate(0.5, normalized=True)
            roads.append(
                (
                    (mid.x, mid.y),
                    {
                        "type": "Feature",
                        "geometry": geom,
                        "properties": {
                            "name": st.name or "(unnamed)",
                            "highway": st.highway,
                            "width_m": round(float(st.width_m), 1),
                        },
                    },
                )
            )
        for b in md.buildings:
            if b.id in seen_buildings or not prepared.intersects(b.footprint):
                continue
            seen_buildings.add(b.id)
            geom = _lonlat_geojson(_simplified(b.footprint.intersection(clip_lonlat)))
            if geom is None:
                continue
            c = b.footprint.centroid
            h = _overlay.building_height_m(b)
            buildings.append(
                (
                    (c.x, c.y),
                    {
                        "type": "Feature",
                        "geometry": geom,
                        "properties": {
                            "name": b.name or "(building)",
                            "building": b.building,
                            "height_m": "unknown" if h is None else f"{h:.0f}",
                        },
                    },
                )
            )
    road_m = _nearest_m(near, [ref for ref, _f in roads])
    building_m = _nearest_m(near, [ref for ref, _f in buildings])
    roads = [roads[k] for k in np.argsort(road_m, kind="stable")]
    buildings = [buildings[k] for k in np.argsort(building_m, kind="stable")]
    n_roads = BASEMAP_MAX_ROADS if max_roads is None else max(int(max_roads), 0)
    n_buildings = BASEMAP_MAX_BUILDINGS if max_buildings is None else max(int(max_buildings), 0)
    return Basemap(
        roads=[f for _d, f in roads[:n_roads]],
        buildings=[f for _d, f in buildings[:n_buildings]],
        roads_in_reach=len(roads),
        buildings_in_reach=len(buildings),
    )


BASEMAP_MAX_AREAS = 8
"""A summary page's basemap loads the maps of at most this many extract areas (the ones
serving the most cameras); cameras elsewhere have no streets drawn under them."""


def basemap_maps(
    points_latlon: Iterable[tuple[float, float]], source: Any
) -> tuple[list[MapData], int]:
    """The maps of the extract areas serving some cameras, for a summary page's basemap.

    Only extracts are read, never the network (a page is built from what is on disk): the
    catalogue's rule picks each camera's area (:class:`camloc_geo.osm.MapCatalogue`), and
    the maps of at most :data:`BASEMAP_MAX_AREAS` areas (those serving the most cameras)
    are loaded, once per process. An area whose map cannot be read is skipped (logged).

    Parameters
    ----------
    points_latlon
        The cameras' ``(lat, lon)``, degrees.
    source
        A :class:`~camloc_geo.osm.MapCatalogue`, an extract or a folder of extracts, or None.

    Returns
    -------
    list of MapData, int
        The maps, and how many cameras no loaded map serves.
    """
    from camloc_geo._errors import MapDataError, MapSourceError
    from camloc_geo.osm import MapCatalogue, area_map

    if source is None:
        return [], 0
    catalogue = MapCatalogue.from_source(source)
    served: dict[tuple[Any, ...], int] = {}
    unserved = 0
    # each distinct point once (a job's title-placed cameras share their junction's point:
    # 3000 cameras at 10 junctions asked the catalogue 3000 times, 0.7 ms each)
    counts: dict[tuple[float, float], int] = {}
    for lat, lon in points_latlon:
        key = (float(lat), float(lon))
        counts[key] = counts.get(key, 0) + 1
    for (lat, lon), n in counts.items():
        area = catalogue.area_for_point(lat, lon) if catalogue.files else ("none",)
        if area[0] in ("file", "cell"):
            served[tuple(area)] = served.get(tuple(area), 0) + n
        else:
            unserved += n
    maps_data = []
    ranked = sorted(served.items(), key=lambda kv: -kv[1])
    for area, n in ranked[:BASEMAP_MAX_AREAS]:
        try:
            maps_data.append(area_map(area))
        except (MapDataError, MapSourceError, OSError) as exc:  # a page without its streets
            log.warning("basemap: the map of %s could not be read: %s", area[1], exc)
            unserved += n
    unserved += sum(n for _a, n in ranked[BASEMAP_MAX_AREAS:])
    return maps_data, unserved


def _discs_lonlat(points_latlon: Sequence[tuple[float, float]], radius_m: float) -> Any:
    """The union of discs of ``radius_m`` around (lat, lon) points, in (lon, lat) degrees."""
    parts = []
    for lat, lon in points_latlon:
        k = math.cos(math.radians(lat))
        disc = Point(0.0, 0.0).buffer(radius_m / 111_320.0, quad_segs=8)
        parts.append(
            shapely.affinity.affine_transform(disc, [1.0 / max(k, 1e-6), 0.0, 0.0, 1.0, lon, lat])
        )
    return shapely.union_all(parts) if parts else Polygon()


def _basemap_note(bm: Basemap) -> str:
    """The page's line saying the basemap was capped (empty when it was not)."""
    if not bm.capped:
        return ""
    parts = []
    if bm.roads_in_reach > len(bm.roads):
        parts.append(f"{len(bm.roads)} of {bm.roads_in_reach} street pieces")
    if bm.buildings_in_reach > len(bm.buildings):
        parts.append(f"{len(bm.buildings)} of {bm.buildings_in_reach} buildings")
    return (
        '<small class="camloc-basemap-capped" style="display:block">basemap capped: '
        + html.escape(" and ".join(parts))
        + " drawn, nearest first</small>"
    )


class _OsmAttribution(MacroElement):
    """OpenStreetMap's attribution in the map's attribution control (bottom right)."""

    _template = Template(
        """
{% macro script(this, kwargs) %}
{{ this._parent.get_name() }}.attributionControl.addAttribution({{ this.text|tojson }});
{% endmacro %}
"""
    )

    def __init__(self) -> None:
        super().__init__()
        self._name = "CamlocOsmAttribution"
        self.text = _OSM_TILES_ATTR


class _StreetCasing(MacroElement):
    """The white streets' grey casing, made in the page from the streets' own layer (the
    features are not written twice), and both scaled with the zoom: from
    :data:`_BASEMAP_FULL_ZOOM` on at their full width (a class's width in pixels), thinner
    farther out, and below zoom 15 thin grey lines without casing (at a city's zoom the
    wide white streets merged into blobs)."""

    _template = Template(
        """
{% macro script(this, kwargs) %}
(function () {
    var map = {{ this._parent.get_name() }};
    var group = {{ this.group }}, streets = {{ this.streets }};
    var widths = {{ this.widths|tojson }};
    function width(f) { return widths[f.properties.highway] || {{ this.default_width }}; }
    var casing = L.geoJSON(streets.toGeoJSON(), {interactive: false,
                                                 style: {{ this.casing|tojson }}});
    group.addLayer(casing);
    casing.bringToBack();
    function restyle() {
        var z = map.getZoom();
        var k = Math.min(1.25, Math.max(0.2, Math.pow(2, (z - {{ this.full_zoom }}) / 2)));
        var far = z < 15;
        streets.setStyle(function (f) {
            return {weight: Math.max(1, width(f) * k), color: far ? "#bdbab0" : "#ffffff"};
        });
        casing.setStyle(function (f) {
            return {weight: Math.max(1, width(f) * k) + 2, opacity: far ? 0 : 1};
        });
    }
    map.on("zoomend", restyle);
    restyle();
})();
{% endmacro %}
"""
    )

    def __init__(self, group: Any, streets: Any) -> None:
        super().__init__()
        self._name = "CamlocStreetCasing"
        self.group = group.get_name()
        self.streets = streets.get_name()
        self.widths = _ROAD_WEIGHT
        self.default_width = 4
        self.casing = _BASEMAP_CASING
        self.full_zoom = _BASEMAP_FULL_ZOOM


def _draw_basemap(
    fmap: folium.Map, bm: Basemap, *, road_style: Mapping[str, Any] | None = None
) -> None:
    """The basemap's layers (streets with their names on hover, building outlines) and OSM's
    attribution; nothing when it is empty. ``road_style``: one style for every street
    (the candidates map's dashed centre lines over its carriageways); default white streets
    in a grey casing, wider by class."""
    if bm.empty:
        return
    if bm.buildings:
        folium.GeoJson(
            {"type": "FeatureCollection", "features": bm.buildings},
            name="Buildings",
            style_function=lambda _f: _STYLE["building"] if road_style else _BASEMAP_BUILDING,
            tooltip=folium.GeoJsonTooltip(
                fields=["name", "building", "height_m"], aliases=["name", "building", "height (m)"]
            ),
        ).add_to(fmap)
    if bm.roads:
        roads = {"type": "FeatureCollection", "features": bm.roads}
        tooltip = folium.GeoJsonTooltip(
            fields=["name", "highway", "width_m"],
            aliases=["street", "highway", "width (m)"],
            sticky=True,
        )
        if road_style:
            folium.GeoJson(
                roads,
                name="Street centre lines",
                style_function=lambda _f: dict(road_style),
                tooltip=tooltip,
            ).add_to(fmap)
        else:

            def weight(f: Mapping[str, Any]) -> int:
                return _ROAD_WEIGHT.get(str(f["properties"].get("highway")), 4)

            group = folium.FeatureGroup(name="Streets (OpenStreetMap)", show=True)
            streets = folium.GeoJson(
                roads,
                style_function=lambda f: {**_BASEMAP_ROAD, "weight": weight(f)},
                tooltip=tooltip,
            )
            streets.add_to(group)
            group.add_to(fmap)
            _StreetCasing(group, streets).add_to(fmap)
    _OsmAttribution().add_to(fmap)


# ---------------------------------------------------------------------------- geometry
def _round_coords(coords: Any, nd: int = 6) -> Any:
    if isinstance(coords, (list, tuple)):
        if coords and isinstance(coords[0], (int, float)):
            return [round(float(v), nd) for v in coords]
        return [_round_coords(c, nd) for c in coords]
    return coords


def _geom_lonlat(geom_en: Any, frame: Any) -> Any:
    """A shapely geometry in frame metres → GeoJSON geometry dict in lon/lat (6 decimals)."""

    def conv(coords: Any) -> list[list[float]]:
        arr = np.asarray(coords, dtype=float)[:, :2]
        out: list[list[float]] = frame.points_geographic_from_enu(arr).tolist()
        return out

    def one(g: Any) -> dict[str, Any] | None:
        if g.is_empty:
            return None
        if isinstance(g, Polygon):
            return {
                "type": "Polygon",
                "coordinates": [conv(g.exterior.coords)] + [conv(r.coords) for r in g.interiors],
            }
        if isinstance(g, LineString):
            return {"type": "LineString", "coordinates": conv(g.coords)}
        return None

    parts = [one(g) for g in getattr(geom_en, "geoms", [geom_en])]
    polys = [p["coordinates"] for p in parts if p and p["type"] == "Polygon"]
    lines = [p["coordinates"] for p in parts if p and p["type"] == "LineString"]
    if polys:
        return {"type": "MultiPolygon", "coordinates": _round_coords(polys)}
    if lines:
        return {"type": "MultiLineString", "coordinates": _round_coords(lines)}
    return None


def _focus(result: LocateResult, candidates: list[dict[str, Any]]) -> tuple[np.ndarray, float]:
    """Centre (east, north in result.frame) and radius of the area the reviewer needs."""
    frame = result.frame
    pts = []
    inter = result.intersection
    if inter is not None:
        pts.append(frame.enu_from_geographic(lat=inter.lat, lon=inter.lon))
    for c in candidates[:8]:
        pts.append(
            frame.enu_from_geographic(lat=c["properties"]["lat"], lon=c["properties"]["lon"])
        )
    if not pts:
        return np.zeros(2), 150.0
    arr = np.asarray(pts, dtype=float)
    centre = arr[0] if inter is not None else arr.mean(axis=0)
    radius = float(np.max(np.linalg.norm(arr - centre, axis=1))) + 90.0
    return centre, float(min(max(radius, 120.0), 350.0))


def _map_layers(
    fmap: folium.Map,
    map_data: MapData,
    frame: LocalFrame,
    centre: np.ndarray,
    radius: float,
    near_lonlat: npt.ArrayLike,
) -> Basemap:
    """Carriageways, street centre lines and buildings within ``radius`` of ``centre`` (the
    centre lines and buildings capped at :data:`BASEMAP_MAX_ROADS` and
    :data:`BASEMAP_MAX_BUILDINGS`, nearest ``near_lonlat`` first)."""
    disc = Point(float(centre[0]), float(centre[1])).buffer(radius, quad_segs=16)
    carriage = _overlay.carriageways_enu(map_data.streets, frame, centre, radius)
    geom = _geom_lonlat(carriage, frame)
    if geom is not None:
        folium.GeoJson(
            {"type": "Feature", "geometry": geom, "properties": {"kind": "carriageway"}},
            name="Carriageways (modelled width)",
            style_function=lambda _f: _STYLE["carriageway"],
            interactive=False,
        ).add_to(fmap)
    clip = Polygon(frame.points_geographic_from_enu(np.asarray(disc.exterior.coords)))
    bm = basemap_features(
        [map_data],
        clip,
        near_lonlat,
        max_roads=BASEMAP_MAX_ROADS,
        max_buildings=BASEMAP_MAX_BUILDINGS,
    )
    _draw_basemap(fmap, bm, road_style=_STYLE["centre"])
    return bm


def _candidate_popup(
    props: Mapping[str, Any],
    image_src: str | None,
    image_link: str | None,
    tie_note: str = "",
    verdict_key: str | None = None,
) -> str:
    rows = [
        ("rank", _fmt(props.get("rank"))),
        ("score", _score_text(props.get("score"), digits=4)),
        ("method", html.escape(str(props.get("method")))),
        ("lat", _fmt(props.get("lat"), "°", 7)),
        ("lon", _fmt(props.get("lon"), "°", 7)),
        ("height_m", _fmt(props.get("height_m"), " m")),
        ("heading_deg", _fmt(props.get("heading_deg"), "°", 1)),
        ("pitch_deg", _fmt(props.get("pitch_deg"), "°", 1)),
        ("roll_deg", _fmt(props.get("roll_deg"), "°", 1)),
        ("focal_px", _fmt(props.get("focal_px"), " px", 1)),
        ("residual_m", _fmt(props.get("residual_m"), " m")),
        ("sigma_m", _fmt(props.get("sigma_m"), " m")),
        ("flags", html.escape(_fmt(list(props.get("flags") or [])))),
        ("ambiguous_with", html.escape(_fmt(_ties_of(props)))),
    ]
    shown = {
        "kind",
        "rank",
        "score",
        "method",
        "lat",
        "lon",
        "height_m",
        "heading_deg",
        "pitch_deg",
        "roll_deg",
        "focal_px",
        "residual_m",
        "sigma_m",
        "flags",
        "matches",
        "ambiguous_with",
    }
    for key, value in props.items():
        if key not in shown:
            digits = 3 if key == "scale" else 2
            rows.append((html.escape(str(key)), html.escape(_fmt(value, digits=digits))))
    body = "".join(f"<tr><th>{k}</th><td>{v}</td></tr>" for k, v in rows)
    parts = [
        f'<div class="camloc-popup"><b>Candidate {int(props.get("rank", 0))}</b>',
        tie_note,
        f"<table>{body}</table>",
    ]
    if verdict_key is not None:
        parts.append(_verdict_box(verdict_key))
    matches = props.get("matches") or []
    if matches:
        mrows = []
        for m in matches:
            target = m.get("map_corner") or _fmt(m.get("map_lonlat"), digits=6)
            mrows.append(
                f"<tr><td>{html.escape(str(m.get('label')))}</td><td>→ {html.escape(str(target))}"
                f"</td><td>{_fmt(m.get('misfit_m'), ' m')}</td></tr>"
            )
        parts.append("<b>matches</b> (scene → map, misfit)<table>" + "".join(mrows) + "</table>")
    if image_src:
        img = f'<img src="{image_src}" alt="overlay of candidate {int(props.get("rank", 0))}">'
        if image_link:
            img = f'<a href="{html.escape(image_link)}" target="_blank">{img}</a>'
        parts.append(img)
    parts.append("</div>")
    return "".join(parts)


def _dot_icon(
    label: str,
    fill: str,
    size: int,
    outline: float,
    css_class: str,
    tied_with: Sequence[int] = (),
    verdict_key: str | None = None,
) -> folium.DivIcon:
    """A numbered disc; a tied one sits in a dashed ring with an "≈" badge; with a
    ``verdict_key``, wrapped to wear the reviewer's verdict badge."""
    text = _text_colour(fill)
    inner = (
        f'<div class="camloc-dot" data-rank="{html.escape(label)}" data-fill="{fill}" '
        f'style="background:{fill};color:{text};border-width:{outline}px">'
        f"{html.escape(label)}</div>"
    )
    if tied_with:
        ties = ",".join(str(int(r)) for r in tied_with)
        inner = (
            f'<div class="camloc-tied" data-tied-with="{ties}">{inner}'
            '<span class="camloc-badge">≈</span></div>'
        )
    if verdict_key is not None:
        inner = _vmark(verdict_key, inner)
    return folium.DivIcon(
        html=inner, icon_size=(size, size), icon_anchor=(size // 2, size // 2), class_name=css_class
    )


_LABEL_W_PX, _LABEL_H_PX, _LABEL_GAP_PX = 34, 16, 4
"""A corner label's box and its gap from its point and from the label stacked beside it."""


def _outward(lat: float, lon: float, centre: tuple[float, float] | None) -> tuple[bool, bool]:
    """``(right, down)``: the side of ``centre`` (lat, lon) a point lies on, on screen; its
    labels go that way, away from the junction (no centre: right and down)."""
    if centre is None:
        return True, True
    return lon >= centre[1], lat < centre[0]


def _corner_icon(
    text: str, colour: str, *, right: bool = True, down: bool = True, tier: int = 0
) -> folium.DivIcon:
    """A small label beside its point, on the side ``right``/``down`` says; ``tier`` 1 is the
    second label of one point (a matched scene corner's over a map corner's), stacked further
    out.

    The labels of a junction's corners point away from its centre (:func:`_outward`): a map
    corner's label below its point and a scene corner's above the next point overlapped where
    two corners stood close, "m0" over "2" on the bundled sample's review page (stop 41).
    """
    inner = f'<div style="background:{colour}">{html.escape(text)}</div>'
    step = _LABEL_H_PX + _LABEL_GAP_PX // 2
    x_px = _LABEL_GAP_PX if right else -_LABEL_GAP_PX - _LABEL_W_PX
    y_px = _LABEL_GAP_PX + tier * step if down else -_LABEL_GAP_PX - _LABEL_H_PX - tier * step
    return folium.DivIcon(
        html=inner,
        icon_size=(_LABEL_W_PX, _LABEL_H_PX),
        icon_anchor=(-x_px, -y_px),
        class_name="camloc-corner-label",
    )


def _set_page_title(fmap: folium.Map, title: str) -> None:
    """The page's ``<title>`` (the browser tab, bookmarks, a screen reader's first words),
    escaped: scene ids are the user's text."""
    fmap.get_root().title = html.escape(title)  # type: ignore[attr-defined]


def _new_map(offline: bool, tiles: str | None, location: Sequence[float]) -> folium.Map:
    fmap = folium.Map(
        location=list(location),
        zoom_start=18,
        tiles=None,
        control_scale=True,
        max_zoom=22,
        prefer_canvas=False,
    )
    if not offline and tiles:
        if tiles == "OpenStreetMap":
            folium.TileLayer(
                "OpenStreetMap",
                name="OpenStreetMap",
                attr=_OSM_TILES_ATTR,
                max_zoom=22,
                max_native_zoom=19,
            ).add_to(fmap)
        else:
            folium.TileLayer(tiles, name="Basemap", max_zoom=22, max_native_zoom=19).add_to(fmap)
    root = fmap.get_root()
    assert isinstance(root, Figure)
    root.header.add_child(
        folium.Element(
            "<style>"
            + _PAGE_CSS
            + (
                f".leaflet-container.leaflet-container {{ background: {_BASEMAP_BACKGROUND}; }}"
                if offline or not tiles
                else ""
            )
            + "</style>"
        ),
        name="camloc_css",
    )
    return fmap


# ------------------------------------------------------------------------ candidate map
def _left_out_html(cal: Mapping[str, Any], collection: Mapping[str, Any]) -> str:
    """The title's line naming the annotators the calibration left out, and why (the
    calibration's own warnings about them, at most two); empty when none was."""
    left = [str(a) for a in cal.get("outlier_annotators") or []]
    if not left:
        return ""
    why = [
        str(w)
        for w in collection.get("warnings") or []
        if any(f"annotator {a!r}" in str(w) for a in left)
    ][:2]
    text = f"left out: annotator{'s' if len(left) > 1 else ''} " + ", ".join(left)
    return (
        '<small class="camloc-left-out" '
        'style="display:block;max-width:300px;white-space:normal"><b>'
        + html.escape(text)
        + "</b>"
        + "".join(f"<br>{html.escape(w)}" for w in why)
        + "</small>"
    )


def build_candidates_map(
    result: LocateResult,
    map_data: MapData | None,
    *,
    scene: Scene | None = None,
    offline: bool = False,
    tiles: str | None = "OpenStreetMap",
    overlay_images: Mapping[int, str] | None = None,
    overlay_links: Mapping[int, str] | None = None,
    verdicts: Sequence[Mapping[str, Any]] | None = None,
    verdict_service: str | None = None,
) -> folium.Map:
    """The review map of one scene's candidates, as a :class:`folium.Map`.

    Parameters
    ----------
    result
        A :func:`camloc_geo.absolute.locate` result.
    map_data
        The map the result was computed with (streets and buildings layers); may be None.
    scene
        The scene (its prior is drawn); optional.
    offline
        No tile layer (the assets are inlined only when saving, see :func:`candidates_map`).
    tiles
        folium tile name or URL template for online pages; None for none.
    overlay_images
        ``rank → img src`` (a data URI or a relative path) shown in the candidate's popup.
    overlay_links
        ``rank → href`` of the full-size overlay (the thumbnail links to it).
    verdicts
        Rows of :func:`read_verdicts`: those of this scene shown again on its candidates (a
        browser that has verdicts of its own for this page keeps those; see
        docs/candidates.md).
    verdict_service
        Path (or URL) of a camloc service's verdicts endpoint (``/v1/verdicts``): the page,
        when opened over HTTP(S), shares its verdicts there (docs/service.md, "Verdicts");
        opened from a file it keeps them in the browser only. None: never.

    Returns
    -------
    folium.Map
        With layers, layer control, legend and scale bar.
    """
    from camloc_geo.results import candidates_geojson

    gj = candidates_geojson(result)
    feats = gj["features"]
    cands = [f for f in feats if f["properties"]["kind"] == "candidate"]
    cones = [f for f in feats if f["properties"]["kind"] == "view_cone"]
    corners = [f for f in feats if f["properties"]["kind"] == "corner"]
    frame = result.frame
    centre_en, radius = _focus(result, cands)
    lon0, lat0 = frame.geographic_from_enu(float(centre_en[0]), float(centre_en[1]))
    fmap = _new_map(offline, None if offline else tiles, (float(lat0), float(lon0)))
    scene_name = (gj.get("properties") or {}).get("scene")
    _set_page_title(fmap, f"camloc review: {scene_name}" if scene_name else "camloc review")

    basemap_note = ""
    if map_data is not None:
        near = [[f["properties"]["lon"], f["properties"]["lat"]] for f in cands[:8]]
        if result.intersection is not None:
            near.append([result.intersection.lon, result.intersection.lat])
        bm = _map_layers(fmap, map_data, result.frame, centre_en, radius, near)
        basemap_note = _basemap_note(bm)

    if scene is not None and scene.prior is not None and scene.prior.radius_m:
        fg_prior = folium.FeatureGroup(name="Prior area", show=True)
        folium.Circle(
            [scene.prior.lat, scene.prior.lon],
            radius=float(scene.prior.radius_m),
            color=_STYLE["prior"],
            weight=1.5,
            dash_array="8 6",
            fill=False,
            interactive=False,
        ).add_to(fg_prior)
        fg_prior.add_to(fmap)

    # View cones: the best few shown, the others available.
    fg_cones = folium.FeatureGroup(name=f"View cones (top {_CONES_SHOWN})", show=True)
    fg_cones_rest = folium.FeatureGroup(name="View cones (other candidates)", show=False)
    for cone in sorted(cones, key=lambda f: -f["properties"]["rank"]):
        rank = int(cone["properties"]["rank"])
        score = float(cone["properties"]["score"])
        colour = rank_colour(rank)
        style = {
            "color": colour,
            "weight": 2.5 if rank == 1 else 1.0,
            "fillColor": colour,
            "fillOpacity": 0.06 + 0.16 * min(score, 1.0),
            "opacity": 0.9,
        }
        folium.GeoJson(
            {
                "type": "Feature",
                "geometry": {
                    "type": "Polygon",
                    "coordinates": _round_coords(cone["geometry"]["coordinates"]),
                },
                "properties": {"rank": rank},
            },
            style_function=lambda _f, s=style: s,
            interactive=False,
        ).add_to(fg_cones if rank <= _CONES_SHOWN else fg_cones_rest)
    fg_cones.add_to(fmap)
    if len(cones) > _CONES_SHOWN:
        fg_cones_rest.add_to(fmap)

    # Map kerb corners, in map order; their labels (and the scene corners' matched to them)
    # point away from the junction's centre
    centre = (
        (
            sum(f["geometry"]["coordinates"][1] for f in corners) / len(corners),
            sum(f["geometry"]["coordinates"][0] for f in corners) / len(corners),
        )
        if corners
        else None
    )
    corner_points = {
        (round(f["geometry"]["coordinates"][0], 7), round(f["geometry"]["coordinates"][1], 7))
        for f in corners
    }
    if corners:
        fg_corners = folium.FeatureGroup(name="Map kerb corners (m = clockwise order)", show=True)
        for f in corners:
            p = f["properties"]
            lon, lat = f["geometry"]["coordinates"]
            tip = html.escape(
                f"map corner {p['order']} of {p['intersection']}: "
                + " / ".join(p.get("streets") or [])
            )
            folium.CircleMarker(
                [lat, lon],
                radius=4,
                color="#fff",
                weight=1.5,
                fill=True,
                fill_color=_STYLE["corner"],
                fill_opacity=1.0,
                tooltip=tip,
            ).add_to(fg_corners)
            right, down = _outward(lat, lon, centre)
            folium.Marker(
                [lat, lon],
                icon=_corner_icon(f"m{p['order']}", _STYLE["corner"], right=right, down=down),
                tooltip=tip,
            ).add_to(fg_corners)
        fg_corners.add_to(fmap)

    # Matches of the leading candidates: scene index on the matched map point.
    for f in cands[:_MATCH_LAYERS]:
        p = f["properties"]
        matches = p.get("matches") or []
        if not matches:
            continue
        rank = int(p["rank"])
        fg = folium.FeatureGroup(name=f"Scene points → map, candidate {rank}", show=rank == 1)
        for m in matches:
            mlon, mlat = m["map_lonlat"]
            label = str(m.get("label", ""))
            idx = label.rsplit("[", 1)[-1].rstrip("]")
            text = (
                idx if m["kind"] == "corner" else ("R" if m["kind"] == "reference" else "L") + idx
            )
            folium.PolyLine(
                [[p["lat"], p["lon"]], [mlat, mlon]],
                color=_STYLE["match"],
                weight=1.2,
                opacity=0.7,
                dash_array="3 4",
                interactive=False,
            ).add_to(fg)
            right, down = _outward(mlat, mlon, centre)
            # on a map corner: stacked beyond its "m" label; elsewhere (a reference, a
            # landmark) beside the point
            on_corner = (round(mlon, 7), round(mlat, 7)) in corner_points
            folium.Marker(
                [mlat, mlon],
                icon=_corner_icon(
                    text, _STYLE["match"], right=right, down=down, tier=1 if on_corner else 0
                ),
                tooltip=html.escape(
                    f"candidate {rank}: {label} → "
                    f"{m.get('map_corner', 'map point')}, misfit "
                    f"{_fmt(m.get('misfit_m'), ' m')}"
                ),
            ).add_to(fg)
        fg.add_to(fmap)

    # Candidates last (on top), best drawn above the others.
    fg_cands = folium.FeatureGroup(name="Candidates", show=True)
    collection = gj["properties"]
    cand_props = [f["properties"] for f in cands]
    by_rank = {int(p["rank"]): p for p in cand_props}
    banner = _tie_banner(collection, cand_props, scene)
    for f in sorted(cands, key=lambda f: -f["properties"]["rank"]):
        p = f["properties"]
        rank = int(p["rank"])
        size, outline, z = rank_style(rank)
        img = (overlay_images or {}).get(rank)
        link = (overlay_links or {}).get(rank)
        ties = [r for r in _ties_of(p) if r in by_rank]
        note = _tie_note(p, by_rank, collection)
        popup = folium.Popup(
            _candidate_popup(p, img, link, note, verdict_key=str(rank)),
            max_width=500 if img else 360,
            auto_pan_padding_top_left=[10, 10 if banner is None else _BANNER_FOLDED_PX],
        )
        tip = f"#{rank} score {_score_text(p['score'])} ({html.escape(str(p['method']))})"
        if ties:
            tip += f" ≈ tied with {_and(ties)}"
        folium.Marker(
            [p["lat"], p["lon"]],
            icon=_dot_icon(
                str(rank),
                rank_colour(rank),
                size,
                outline,
                "camloc-candidate",
                tied_with=ties,
                verdict_key=str(rank),
            ),
            popup=popup,
            tooltip=tip,
            z_index_offset=z,
            # a candidate under a better one (3.4 m apart at the sample's junction: rank 3
            # under rank 1) comes on top while the mouse is on what shows of it
            rise_on_hover=True,
            rise_offset=20_000,
        ).add_to(fg_cands)
    fg_cands.add_to(fmap)
    scene_name = str(result.scene_id)
    v_items = {
        str(p["rank"]): {
            "camera": scene_name,
            "rank": int(p["rank"]),
            "lat": _num(p.get("lat"), 7),
            "lon": _num(p.get("lon"), 7),
            "label": f"candidate {int(p['rank'])}",
        }
        for p in cand_props
    }
    v_identity = [
        scene_name,
        [
            [it["rank"], it["lat"], it["lon"], _num(p.get("score"), 6)]
            for it, p in zip(v_items.values(), cand_props, strict=True)
        ],
    ]
    if cand_props:
        config = _verdict_config("candidates", v_items, v_identity, scene_name)
        config["service"] = verdict_service
        if verdicts:
            config["given"] = _given_candidate_verdicts(scene_name, v_items, verdicts)
        _Verdicts(config).add_to(fmap)

    folium.LayerControl(collapsed=False, position="topright").add_to(fmap)
    _SmallScreenFolds().add_to(fmap)
    _Control(
        _legend_html(
            scene_id=result.scene_id,
            has_corners=bool(corners),
            has_prior=scene is not None and scene.prior is not None,
            summary=False,
            cands=cand_props,
            any_tie=bool(_tie_groups(cand_props)),
        ),
        position="bottomleft",
        css_class="camloc-legend",
    ).add_to(fmap)
    if banner is not None:
        _Banner(banner[0], css_class=banner[1]).add_to(fmap)
    cal = gj["properties"]["calibration"]
    title = (
        f"<h4>{html.escape(str(result.scene_id))}</h4>"
        f"{len(cands)} candidate(s); methods tried: "
        f"{html.escape(', '.join(result.methods_tried) or 'none')}"
        f"<br><small>calibration: f = {_fmt(cal['focal_px'], ' px', 0)}, h = "
        f"{_fmt(cal['height_m'], ' m', 1)} ({html.escape(str(cal['method']))})</small>"
    )
    title += _left_out_html(cal, collection)
    title += basemap_note
    if not cands:
        why = str(result.reason or "").strip() or "the locate result gives no reason"
        title += f"<br><b>no candidates</b>: {html.escape(why)}"
    _Control(title, position="topleft", css_class="camloc-title").add_to(fmap)

    if len(cands) >= 2:
        _CandidatesApart().add_to(fmap)  # before the labels: they keep clear of the discs
    if corners or any(f["properties"].get("matches") for f in cands[:_MATCH_LAYERS]):
        _LabelsClear().add_to(fmap)  # before the fit: its zoom places the labels
    pts = [[f["properties"]["lat"], f["properties"]["lon"]] for f in cands[:6]]
    for f in corners:
        pts.append([f["geometry"]["coordinates"][1], f["geometry"]["coordinates"][0]])
    if len(pts) >= 2:
        arr = np.asarray(pts)
        _FitClear([arr.min(axis=0).tolist(), arr.max(axis=0).tolist()]).add_to(fmap)
    return fmap


def _overlay_sources(
    result: LocateResult,
    map_data: MapData | None,
    scene: Scene | None,
    out_path: Path,
    overlay_dir: str | None,
    embed: bool,
    top: int,
) -> tuple[dict[int, Any], dict[int, str]]:
    """Overlay images of the leading candidates; written to ``overlay_dir`` when given."""
    images: dict[int, Any] = {}
    links: dict[int, str] = {}
    background = None
    if scene is not None:
        background = _overlay._read_background(scene, result.image_size)
    for c in result.candidates[:top]:
        path = None
        if overlay_dir is not None:
            path = Path(overlay_dir) / f"{_safe(result.scene_id)}_rank{c.rank}.png"
        img = _overlay.candidate_overlay(
            result, c, map_data, scene=scene, path=path, background=background
        )
        images[c.rank] = img
        if path is not None:
            links[c.rank] = _relative(path, out_path.parent)
    return images, links


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name) or "scene"


def _relative(path: Path, start: Path) -> str:
    import os

    return Path(os.path.relpath(path.resolve(), start.resolve())).as_posix()


def _render(fmap: folium.Map, offline: bool) -> str:
    page = fmap.get_root().render()
    return inline_assets(page) if offline else page


def candidates_map(
    result: LocateResult,
    map_data: MapData | None,
    path: str | Path,
    *,
    offline: bool = False,
    scene: Scene | None = None,
    overlay_dir: str | None = None,
    tiles: str | None = "OpenStreetMap",
    overlay_top: int = _OVERLAY_TOP,
    thumbnail_width: int = 480,
    max_bytes: int = MAX_PAGE_BYTES,
    verdicts: Sequence[Mapping[str, Any]] | None = None,
    verdict_service: str | None = None,
) -> Path:
    """Write the review map of one scene's candidates as an HTML page.

    Parameters
    ----------
    result
        A :func:`camloc_geo.absolute.locate` result.
    map_data
        The map used (None when the scene needed none).
    path
        Output HTML file.
    offline
        One self-contained file making no request (no tiles; Leaflet, jQuery and the overlays
        inlined). Otherwise folium's CDN links and a tile basemap.
    scene
        The scene: its snapshot is the overlays' background and its prior is drawn.
    overlay_dir
        Write the full-size overlay PNGs of the leading candidates here; online pages then
        show them by relative link. Offline pages (or online pages without a folder) embed
        base64 PNG thumbnails.
    tiles
        Basemap for online pages (folium tile name or URL template; None for none).
    overlay_top
        How many leading candidates get an overlay.
    thumbnail_width
        Width of embedded thumbnails, pixels (reduced, and the number of embedded overlays
        cut, until the page fits ``max_bytes``).
    max_bytes
        Size budget of a page with embedded overlays.
    verdicts
        Rows of :func:`read_verdicts` shown again on the page (see
        :func:`build_candidates_map`).
    verdict_service
        The service's verdicts endpoint the page shares its verdicts with when opened over
        HTTP (see :func:`build_candidates_map`).

    Returns
    -------
    Path
        The page written.
    """
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    embed = offline or overlay_dir is None
    images, links = (
        ({}, {})
        if overlay_top <= 0
        else _overlay_sources(result, map_data, scene, out, overlay_dir, embed, overlay_top)
    )
    if not embed:
        fmap = build_candidates_map(
            result,
            map_data,
            scene=scene,
            offline=offline,
            tiles=tiles,
            overlay_images=links,
            overlay_links=links,
            verdicts=verdicts,
            verdict_service=verdict_service,
        )
        page = _render(fmap, offline)
    else:
        width = thumbnail_width
        ranks = sorted(images)
        while True:
            srcs = {
                r: "data:image/png;base64,"
                + base64.b64encode(_overlay.encode_png(images[r], max_width=width)).decode("ascii")
                for r in ranks
            }
            fmap = build_candidates_map(
                result,
                map_data,
                scene=scene,
                offline=offline,
                tiles=tiles,
                overlay_images=srcs,
                overlay_links=links,
                verdicts=verdicts,
                verdict_service=verdict_service,
            )
            page = _render(fmap, offline)
            size = len(page.encode("utf-8"))
            if size <= max_bytes or not ranks:
                break
            if width > 240:
                width = int(width * 0.8)
            else:
                ranks = ranks[:-1]
            log.info(
                "page %d bytes > %d: overlays at %d px for %d candidates",
                size,
                max_bytes,
                width,
                len(ranks),
            )
    from camloc_geo._io import write_text_atomic

    write_text_atomic(out, page)
    log.info("wrote %s (%d bytes)", out, len(page.encode("utf-8")))
    return out


# --------------------------------------------------------------------------- summary map
def _best_feature(
    item: Any, others: list[list[Any]] | None = None
) -> tuple[dict[str, Any] | None, str | None]:
    """The best candidate feature of a GeoJSON dict or LocateResult, and the scene's reason;
    ``others`` (when given) receives ``[rank, lat, lon, score text]`` of the other candidates
    (at most 8, by rank) for the summary page's "pick another candidate"."""
    if isinstance(item, Mapping):
        gj = item
    else:
        from camloc_geo.results import candidates_geojson

        gj = candidates_geojson(item, view_cones=False)
    cands = [
        f for f in gj.get("features", []) if f.get("properties", {}).get("kind") == "candidate"
    ]
    reason = (gj.get("properties") or {}).get("reason")
    if not cands:
        return None, reason
    cands = sorted(cands, key=lambda f: _rank_of(f["properties"]))
    if others is not None:
        for f in cands[1:9]:
            q = f["properties"]
            lat, lon = _num(q.get("lat"), 7), _num(q.get("lon"), 7)
            if isinstance(q.get("rank"), int) and lat is not None and lon is not None:
                others.append([int(q["rank"]), lat, lon, _score_text(q.get("score"))])
    return cands[0], reason


def _rank_of(props: Mapping[str, Any]) -> int:
    rank = props.get("rank")
    return rank if isinstance(rank, int) and not isinstance(rank, bool) else 1 << 30


def _arrow_icon(
    heading: float | None,
    fill: str,
    css_class: str,
    tied: bool = False,
    verdict_key: str | None = None,
) -> folium.DivIcon:
    """A heading arrow (a dot without heading); a tied camera's in a dashed ring with "≈"."""
    if heading is None or not math.isfinite(heading):
        shape = '<circle r="6" />'
    else:
        shape = f'<path transform="rotate({heading:.1f})" d="M0,-11 L6,6 L0,2 L-6,6 Z" />'
    ring = ""
    size = 26
    if tied:
        size = 36
        ring = (
            f'<circle r="16" fill="rgba(255,255,255,0.7)" stroke="{TIE_RING}" '
            'stroke-width="2.5" stroke-dasharray="5 3" />'
        )
    h = size // 2
    svg = (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}" '
        f'viewBox="-{h} -{h} {size} {size}">{ring}'
        f'<g fill="{fill}" stroke="#111" stroke-width="1.5">{shape}</g></svg>'
    )
    if tied:
        svg = (
            f'<div class="camloc-tied-arrow" data-tied="1">{svg}'
            '<span class="camloc-badge">≈</span></div>'
        )
    if verdict_key is not None:
        svg = _vmark(verdict_key, svg)
    return folium.DivIcon(
        html=svg, icon_size=(size, size), icon_anchor=(h, h), class_name=css_class
    )


_PLACED_ONLY = {
    "title_only": "at the junction its title names",
    "street_only": "on the street its title names",
    # a camera two places fit equally, drawn at the first in its dashed ring: it was
    # counted "located" on the service's job page (qa7)
    "ambiguous": "two places fit equally: drawn at the first, dashed; see its popup",
}


def _summary_heading(rows: Sequence[tuple[str, Mapping[str, Any]]]) -> str:
    """ "N camera(s) located", or, for a batch whose points are not all located scenes (their
    status leads their ``flags``), how many of each: a title's junction is not a location."""
    statuses: dict[str, int] = {}
    for _s, f in rows:
        flags = f["properties"].get("flags") or []
        status = flags[0] if flags and flags[0] in (*_PLACED_ONLY, "located") else "located"
        statuses[status] = statuses.get(status, 0) + 1
    if set(statuses) <= {"located"}:
        return f"<h4>{len(rows)} camera(s) located</h4>"
    parts = [f"{statuses['located']} located"] if statuses.get("located") else []
    parts += [f"{statuses[k]} {k} ({why})" for k, why in _PLACED_ONLY.items() if k in statuses]
    return f"<h4>{len(rows)} camera(s) on the map</h4>" + html.escape(", ".join(parts)) + "<br>"


def _summary_tie(props: Mapping[str, Any], reason: str | None) -> str | None:
    """How a camera's best candidate is tied, for its popup; None when it is not."""
    others = _ties_of(props)
    if others:
        word = "candidate" if len(others) == 1 else "candidates"
        return f"tied with {word} {_and(others)}"
    if "tie" in [str(f) for f in props.get("flags") or []]:
        return "tied with another candidate" + (f": {reason}" if reason else "")
    return None


_STATUS_PREFIX = re.compile(r"^([a-z][a-z_]*): ")


MISSING_LABEL_CHARS = 60
"""A camera's name in the summary's list of cameras not on the map is cut here (the whole
name and reason on hover): one scraped title of 300 characters filled the heading box."""
MISSING_LISTED = 500
"""At most this many cameras not on the map are named on the page (the rest are counted; the
GeoPackage's ``cameras`` layer has them all)."""


def _missing_label(scene_id: Any, reason: Any) -> str:
    m = _STATUS_PREFIX.match(str(reason or ""))
    status = m.group(1) if m else None
    name = " ".join(str(scene_id).split())
    short = name if len(name) <= MISSING_LABEL_CHARS else name[: MISSING_LABEL_CHARS - 1] + "…"
    hover = name + ": " + str(reason or "") if short != name else str(reason or "")
    label = html.escape(short) + (f" ({status})" if status else "")
    return f'<span title="{html.escape(hover)}">{label}</span>'


def _missing_html(missing: Sequence[tuple[str, Any]], shown: int = 10) -> str:
    """The summary heading's line of cameras not on the map: counted by status (a batch
    camera's reason starts with it: ``scene_error: scene broken.json: ...``), each named with
    its status, the whole reason on hover. It listed bare names, so a broken scene, a title
    not found and a camera without evidence read alike. The first ``shown`` are named in the
    line, the others (up to :data:`MISSING_LISTED`) under a fold: they were left out ("…")."""
    statuses: dict[str, int] = {}
    names = [_missing_label(scene_id, reason) for scene_id, reason in missing[:shown]]
    for _scene_id, reason in missing:
        m = _STATUS_PREFIX.match(str(reason or ""))
        if m:
            statuses[m.group(1)] = statuses.get(m.group(1), 0) + 1
    counted = ", ".join(f"{n} {st}" for st, n in sorted(statuses.items(), key=lambda kv: -kv[1]))
    text = (
        f"{len(missing)} without candidates"
        + (f" ({html.escape(counted)})" if counted else "")
        + ": "
        + ", ".join(names)
    )
    rest = missing[shown:MISSING_LISTED]
    if rest:
        more = ", ".join(_missing_label(scene_id, reason) for scene_id, reason in rest)
        unlisted = len(missing) - shown - len(rest)
        tail = (
            f", and {unlisted} more (the GeoPackage's cameras layer has them all)"
            if unlisted
            else ""
        )
        text += (
            f'<details class="camloc-more"><summary>and {len(missing) - shown} more</summary>'
            f"{more}{tail}</details>"
        )
    return text


def build_summary_map(
    items: Iterable[tuple[str, Any]],
    *,
    offline: bool = False,
    tiles: str | None = "OpenStreetMap",
    cluster: bool = True,
    map_data: MapData | Sequence[MapData] | None = None,
    verdicts: Sequence[Mapping[str, Any]] | None = None,
    verdict_service: str | None = None,
    tiles_attribution: str | None = None,
    pending: int = 0,
) -> folium.Map:
    """A map of many cameras: the best candidate of each, as a :class:`folium.Map`.

    Parameters
    ----------
    items
        ``(scene_id, candidates)`` pairs; ``candidates`` is a candidate GeoJSON dict
        (:func:`camloc_geo.results.candidates_geojson`) or a ``LocateResult``.
    offline
        No tiles and no clustering plugin (its script would come from a CDN): plain markers.
    tiles
        Basemap for online pages.
    cluster
        Cluster markers (online pages only; ``leaflet.markercluster`` from its CDN).
    map_data
        A map, or several (the areas of a batch), to draw under the cameras as a light
        vector basemap: their streets (names on hover) and building outlines within
        :data:`SUMMARY_BASEMAP_RADIUS_M` of each camera, at most :data:`BASEMAP_MAX_ROADS`
        and :data:`BASEMAP_MAX_BUILDINGS` of them (nearest the cameras first; the page says
        so when capped), with OpenStreetMap's attribution: the only context a page without
        tiles has.
    verdicts
        Rows of :func:`read_verdicts`: shown again on the page (a browser that has verdicts
        of its own for this page keeps those; see docs/candidates.md).
    verdict_service
        A camloc service's verdicts endpoint, shared when the page is opened over HTTP (see
        :func:`build_candidates_map`).
    tiles_attribution
        With ``tiles`` a tile URL template (``https://.../{z}/{x}/{y}.png``): its attribution
        (plain text), the layer named "Basemap". Without it ``tiles`` is taken as before.
    pending
        Cameras not done yet (a running job's): counted in the page's title and said in its
        title box (an unfinished job's page said "0 of 0 cameras on the map").
    """
    rows: list[tuple[str, dict[str, Any]]] = []
    missing = []
    reasons: dict[int, str | None] = {}
    alternatives: dict[int, list[list[Any]]] = {}
    for scene_id, item in items:
        others: list[list[Any]] = []
        best, reason = _best_feature(item, others)
        if best is None:
            missing.append((scene_id, reason))
        else:
            reasons[len(rows)] = reason
            alternatives[len(rows)] = others
            rows.append((scene_id, best))
    ties = {i: _summary_tie(f["properties"], reasons[i]) for i, (_s, f) in enumerate(rows)}
    if rows:
        lats = np.array([f["properties"]["lat"] for _s, f in rows])
        lons = np.array([f["properties"]["lon"] for _s, f in rows])
        location = (float(lats.mean()), float(lons.mean()))
    else:
        location = (0.0, 0.0)
    if tiles_attribution is not None and tiles and not offline:
        fmap = _new_map(offline, None, location)
        folium.TileLayer(
            tiles,
            name="Basemap",
            attr=html.escape(tiles_attribution),
            max_zoom=22,
            max_native_zoom=19,
        ).add_to(fmap)
    else:
        fmap = _new_map(offline, None if offline else tiles, location)
    n_cameras = len(rows) + len(missing) + max(0, int(pending))
    _set_page_title(
        fmap,
        f"camloc summary: {len(rows)} of {n_cameras} camera{'s' * (n_cameras != 1)} on the map",
    )
    basemap_note = ""
    if map_data is not None and rows:
        maps_data: list[MapData] = list(map_data) if isinstance(map_data, Sequence) else [map_data]
        cams = [(float(f["properties"]["lat"]), float(f["properties"]["lon"])) for _s, f in rows]
        bm = basemap_features(
            maps_data,
            _discs_lonlat(cams, SUMMARY_BASEMAP_RADIUS_M),
            [(lon, lat) for lat, lon in cams],
        )
        _draw_basemap(fmap, bm)
        basemap_note = _basemap_note(bm)
    parent: Any
    if cluster and not offline:
        from folium.plugins import MarkerCluster

        parent = MarkerCluster(
            name="Cameras (best candidate)", icon_create_function=_CLUSTER_ICON_JS
        )
    else:
        parent = folium.FeatureGroup(name="Cameras (best candidate)")
    order = sorted(range(len(rows)), key=lambda i: rows[i][1]["properties"].get("score", 0.0))
    compact = len(rows) > SUMMARY_DATA_MARKERS
    data_rows: list[list[Any]] = []
    words = _Words()  # texts many cameras share (colours, methods, flags, reasons), once each
    for i in order:
        scene_id, f = rows[i]
        p = f["properties"]
        tie = ties[i]
        fields = _summary_fields(scene_id, p)
        why = " ".join(str(reasons[i] or "").split())
        # what placed the camera and what was wrong (a camloc batch camera: "junction of
        # the map's model; list row: lat 'abc' is not a number", "...; 933 km from the
        # point given"): the popup showed the numbers only
        short = (why if len(why) <= 300 else why[:299] + "…") or None
        if compact:
            data_rows.append(
                [
                    i,
                    str(scene_id),
                    round(float(p["lat"]), 7),
                    round(float(p["lon"]), 7),
                    _finite(p.get("heading_deg")),
                    tie,
                    _finite(p.get("score")),
                    words.of(score_colour(p.get("score", 0.0))),
                    words.of(fields[2][1]),  # the method
                    p.get("rank") if isinstance(p.get("rank"), int) else None,
                    _finite(p.get("height_m")),
                    _finite(p.get("residual_m")),
                    _finite(p.get("sigma_m")),
                    words.of(fields[-1][1]),  # the flags
                    None if short is None else words.of(short),
                ]
            )
            continue
        body = "".join(f"<tr><th>{k}</th><td>{html.escape(v)}</td></tr>" for k, v in fields)
        if short:
            body += f"<tr><th>reason</th><td>{html.escape(short)}</td></tr>"
        note = ""
        if tie:
            note = (
                f'<div class="camloc-tie">≈ <b>{html.escape(tie)}</b>: the evidence does not '
                "favour the best candidate firmly (odds under "
                f"{1 / TIE_SCORE_RATIO:g} to 1): {html.escape(TIE_CHOICE_WORDS)}</div>"
            )
        popup = folium.Popup(
            f'<div class="camloc-popup"><b>{html.escape(str(scene_id))}</b>{note}'
            f"<table>{body}</table>{_verdict_box(f'c{i}')}</div>",
            max_width=320,
        )
        folium.Marker(
            [p["lat"], p["lon"]],
            popup=popup,
            icon=_arrow_icon(
                p.get("heading_deg"),
                score_colour(p.get("score", 0.0)),
                "camloc-summary-marker",
                tied=tie is not None,
                verdict_key=f"c{i}",
            ),
            tooltip=f"{html.escape(str(scene_id))} ({p.get('score', 0.0):.2f})"
            + (f" ≈ {html.escape(tie)}" if tie else ""),
            rise_on_hover=True,  # a camera drawn under another comes on top under the mouse
        ).add_to(parent)
    parent.add_to(fmap)
    if compact:
        _DataMarkers(parent, data_rows, words.texts).add_to(fmap)
    v_items = {}
    for i, (scene_id, f) in enumerate(rows):
        p = f["properties"]
        v_items[f"c{i}"] = {
            "camera": str(scene_id),
            "rank": p.get("rank") if isinstance(p.get("rank"), int) else None,
            "lat": _num(p.get("lat"), 7),
            "lon": _num(p.get("lon"), 7),
            "label": f"camera {scene_id}",
            "others": alternatives[i],
        }
        if compact:  # the page's script says "camera <id>" itself
            del v_items[f"c{i}"]["label"]
    if v_items:
        v_identity = [
            [it["camera"], it["rank"], it["lat"], it["lon"], it["others"]]
            for it in v_items.values()
        ]
        config = _verdict_config("summary", v_items, v_identity, "summary")
        config["service"] = verdict_service
        if verdicts:
            config["given"] = _given_verdicts(v_items, verdicts)
        _Verdicts(config).add_to(fmap)
    folium.LayerControl(collapsed=False, position="topright").add_to(fmap)
    _SmallScreenFolds().add_to(fmap)
    _Control(
        _legend_html(
            scene_id=None,
            has_corners=False,
            has_prior=False,
            summary=True,
            any_tie=any(t is not None for t in ties.values()),
        ),
        position="bottomleft",
        css_class="camloc-legend",
    ).add_to(fmap)
    title = _summary_heading(rows)
    n_tied = sum(t is not None for t in ties.values())
    if n_tied:
        title += f"≈ {n_tied} with a tied best candidate (dashed ring)<br>"
    if missing:
        title += _missing_html(missing)
    if pending > 0:
        title += (
            f"⏳ {int(pending)} camera{'s' * (pending != 1)} not done yet (the job is still "
            "running): reload the page later<br>"
        )
    title += basemap_note
    _Control(title, position="topleft", css_class="camloc-title camloc-summary-title").add_to(fmap)
    bounds = (
        [[float(lats.min()), float(lons.min())], [float(lats.max()), float(lons.max())]]
        if len(rows) >= 2
        else None
    )
    if isinstance(parent, folium.FeatureGroup) or not rows:
        if bounds is not None:
            _FitClear(bounds, max_zoom=18).add_to(fmap)
    else:
        _OpenUnclustered(parent, bounds).add_to(fmap)
    return fmap


SUMMARY_DATA_MARKERS = 300
"""A summary page of more cameras than this carries its markers as one compact data array
that the browser turns into markers, icons, tooltips and popups (a popup's HTML made only
when it opens), instead of one folium marker each with its icon and popup HTML: a 3000-camera
job map was 8 MB and took 10.6 s to build (session 40)."""


def _summary_fields(scene_id: Any, p: Mapping[str, Any]) -> list[tuple[str, str]]:
    """A summary popup's rows as ``(label, plain text)``, in order (escaped where drawn)."""
    return [
        ("camera", str(scene_id)),
        ("score", _score_text(p.get("score"))),
        ("method", str(p.get("method"))),
        ("rank", _fmt(p.get("rank"))),
        ("lat", _fmt(p.get("lat"), "°", 7)),
        ("lon", _fmt(p.get("lon"), "°", 7)),
        ("height_m", _fmt(p.get("height_m"), " m")),
        ("heading_deg", _fmt(p.get("heading_deg"), "°", 1)),
        ("residual_m", _fmt(p.get("residual_m"), " m")),
        ("sigma_m", _fmt(p.get("sigma_m"), " m")),
        ("flags", _fmt(list(p.get("flags") or []))),
    ]


def _finite(value: Any) -> float | None:
    """A number as the page's data carries it (None when missing or not finite)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value)


class _Words:
    """Texts shared by many rows of a page's data, each kept once; a row holds its index."""

    def __init__(self) -> None:
        self.texts: list[str] = []
        self._at: dict[str, int] = {}

    def of(self, text: str) -> int:
        """The index of ``text`` (added if new)."""
        at = self._at.get(text)
        if at is None:
            at = self._at[text] = len(self.texts)
            self.texts.append(text)
        return at


class _DataMarkers(MacroElement):
    """A large summary page's markers, made in the browser from one compact array.

    Each row: ``[index, camera, lat, lon, heading, tie text, score, colour, method, rank,
    height_m, residual_m, sigma_m, flags, reason]``, the colour, method, flags and reason as
    indices into ``words`` (texts many cameras share, once each); missing numbers null. The
    icons are :func:`_arrow_icon`'s (the same HTML, so the verdict badges and the clusters'
    counts find them), the tooltips and popups :func:`build_summary_map`'s, a popup made when
    it opens; the markers go into the group in one ``addLayers`` call (markercluster's bulk
    path).
    """

    _template = Template(
        """
{% macro script(this, kwargs) %}
(function () {
    var group = {{ this.group }};
    var words = {{ this.words|tojson }};
    var rows = {{ this.rows|tojson }};
    var ring = {{ this.ring|tojson }}, odds = {{ this.odds|tojson }};
    var tieChoice = {{ this.tie_choice|tojson }};
    function esc(x) {
        return String(x).replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;")
            .replace(/"/g, "&quot;").replace(/'/g, "&#x27;");
    }
    function num(x, digits, unit) {  // as the Python side's _fmt
        return x === null ? "\u2014" : x.toFixed(digits) + unit;
    }
    function score(x) {  // as _score_text: 0.375, or 1.1e-15 where 0.000 would show
        if (x === null) { return "\u2014"; }
        return (x === 0 || Math.abs(x) >= 0.0005) ? x.toFixed(3) : x.toExponential(1);
    }
    function icon(r) {
        var heading = r[4], tied = r[5] !== null, size = tied ? 36 : 26, h = size / 2;
        var shape = heading === null ? '<circle r="6" />'
            : '<path transform="rotate(' + heading.toFixed(1) +
              ')" d="M0,-11 L6,6 L0,2 L-6,6 Z" />';
        var svg = '<svg xmlns="http://www.w3.org/2000/svg" width="' + size + '" height="' +
            size + '" viewBox="-' + h + ' -' + h + ' ' + size + ' ' + size + '">' +
            (tied ? '<circle r="16" fill="rgba(255,255,255,0.7)" stroke="' + ring +
                    '" stroke-width="2.5" stroke-dasharray="5 3" />' : '') +
            '<g fill="' + words[r[7]] + '" stroke="#111" stroke-width="1.5">' + shape +
            '</g></svg>';
        if (tied) {
            svg = '<div class="camloc-tied-arrow" data-tied="1">' + svg +
                '<span class="camloc-badge">\u2248</span></div>';
        }
        svg = '<div class="camloc-vmark" data-verdict-mark="c' + r[0] + '">' + svg + '</div>';
        return L.divIcon({html: svg, iconSize: [size, size], iconAnchor: [h, h],
                          className: "camloc-summary-marker"});
    }
    function popup(r) {
        var fields = [
            ["camera", r[1]], ["score", score(r[6])], ["method", words[r[8]]],
            ["rank", r[9] === null ? "\u2014" : String(r[9])],
            ["lat", num(r[2], 7, "\u00b0")], ["lon", num(r[3], 7, "\u00b0")],
            ["height_m", num(r[10], 2, " m")], ["heading_deg", num(r[4], 1, "\u00b0")],
            ["residual_m", num(r[11], 2, " m")], ["sigma_m", num(r[12], 2, " m")],
            ["flags", words[r[13]]]
        ];
        if (r[14] !== null) { fields.push(["reason", words[r[14]]]); }
        var body = fields.map(function (f) {
            return "<tr><th>" + f[0] + "</th><td>" + esc(f[1]) + "</td></tr>";
        }).join("");
        var note = r[5] === null ? "" : '<div class="camloc-tie">\u2248 <b>' + esc(r[5]) +
            "</b>: the evidence does not favour the best candidate firmly (odds under " +
            odds + " to 1): " + tieChoice + "</div>";
        return '<div class="camloc-popup"><b>' + esc(r[1]) + "</b>" + note + "<table>" +
            body + '</table><div class="camloc-verdict" data-verdict-key="c' + r[0] +
            '"></div></div>';
    }
    var markers = rows.map(function (r) {
        var m = L.marker([r[2], r[3]], {icon: icon(r), riseOnHover: true});
        m.bindTooltip(esc(r[1]) + " (" + (r[6] || 0).toFixed(2) + ")" +
                      (r[5] === null ? "" : " \u2248 " + esc(r[5])), {sticky: true});
        var content = null;  // made at the first opening, then kept: the verdict controls
        // drawn into it stay when Leaflet updates the popup (made anew, they went)
        m.bindPopup(function () {
            if (content === null) {
                content = document.createElement("div");
                content.innerHTML = popup(r);
            }
            return content;
        }, {maxWidth: 320});
        return m;
    });
    if (typeof group.addLayers === "function") { group.addLayers(markers); }
    else { markers.forEach(function (m) { group.addLayer(m); }); }
})();
{% endmacro %}
"""
    )

    def __init__(self, group: Any, rows: list[list[Any]], words: list[str]) -> None:
        super().__init__()
        self._name = "CamlocDataMarkers"
        self.group = group.get_name()
        self.rows = rows
        self.words = words
        self.ring = TIE_RING
        self.odds = f"{1 / TIE_SCORE_RATIO:g}"
        self.tie_choice = html.escape(TIE_CHOICE_WORDS)


_FIT_CLEAR_JS = """
function camlocFitClear(map, bounds, maxZoom, beforeFit) {
    // fit the markers into the part of the map no box covers: a box along the top or the
    // bottom (title, banner, scale, the verdicts' counter) pads that edge, a tall one
    // (a long legend or layer list) pads its side; on a phone the legend and the layer list
    // are folded (SmallScreenFolds), so they count folded
    var size = map.getSize();
    var box = map.getContainer().getBoundingClientRect();
    var small = size.x < SMALL_PX;
    var pad = {l: 30, t: 30, r: 30, b: 30};
    var boxes = map.getContainer().querySelectorAll(".leaflet-control, .camloc-banner");
    Array.prototype.forEach.call(boxes, function (el) {
        var r = el.getBoundingClientRect();
        if (!r.width || !r.height) { return; }
        var x0 = r.left - box.left, y0 = r.top - box.top;
        var x1 = x0 + r.width, y1 = y0 + r.height;
        if (small && el.classList.contains("camloc-legend")) { y0 = Math.max(y0, y1 - 30); }
        if (small && el.classList.contains("leaflet-control-layers")) {
            y1 = Math.min(y1, y0 + 50);
            x0 = Math.max(x0, x1 - 50);
        }
        if (y1 - y0 > 0.35 * size.y) {
            if (x0 < size.x / 2) { pad.l = Math.max(pad.l, x1 + 10); }
            else { pad.r = Math.max(pad.r, size.x - x0 + 10); }
        } else if (y0 < size.y / 2) { pad.t = Math.max(pad.t, y1 + 10); }
        else { pad.b = Math.max(pad.b, size.y - y0 + 10); }
    });
    // at least 40 % of the map's width and height stay for the markers
    if (pad.l + pad.r > 0.6 * size.x) {
        var kx = 0.6 * size.x / (pad.l + pad.r); pad.l *= kx; pad.r *= kx;
    }
    if (pad.t + pad.b > 0.6 * size.y) {
        var ky = 0.6 * size.y / (pad.t + pad.b); pad.t *= ky; pad.b *= ky;
    }
    var options = {paddingTopLeft: [pad.l, pad.t], paddingBottomRight: [pad.r, pad.b],
                   animate: false};
    if (maxZoom) { options.maxZoom = maxZoom; }
    if (beforeFit) {  // the zoom fitBounds will choose (Leaflet's own rule)
        var zoom = map.getBoundsZoom(L.latLngBounds(bounds), false,
                                     L.point(pad.l + pad.r, pad.t + pad.b));
        beforeFit(maxZoom ? Math.min(maxZoom, zoom) : zoom);
    }
    map.fitBounds(bounds, options);
    map.getContainer().setAttribute("data-camloc-fit-padding",
        [pad.l, pad.t, pad.r, pad.b].map(Math.round).join(" "));
}
""".replace("SMALL_PX", str(SMALL_SCREEN_PX))
"""A page's first view: its markers fitted clear of the boxes over the map (a legend at the
bottom left covered the candidates there)."""


_LABELS_CLEAR_JS = """
function camlocLabelsClear(map, W, H, G) {
    // Each corner label (a map corner's "m0", a matched scene corner's "2") takes the first
    // of its places (its own side of the junction first, then the other sides, then stacked
    // further out) that covers no candidate marker, no corner point and no label placed
    // before it; none clear: the least covered. Redone at every zoom and layer toggle.
    function overlap(a, b) {
        var w = Math.min(a.x + a.w, b.x + b.w) - Math.max(a.x, b.x);
        var h = Math.min(a.y + a.h, b.y + b.h) - Math.max(a.y, b.y);
        return w > 0 && h > 0 ? w * h : 0;
    }
    function place() {
        var box = map.getContainer().getBoundingClientRect(), taken = [], labels = [];
        document.querySelectorAll(".camloc-candidate").forEach(function (e) {
            if (!e.offsetWidth) { return; }
            var r = e.getBoundingClientRect();
            taken.push({x: r.left - box.left, y: r.top - box.top, w: r.width, h: r.height});
        });
        map.eachLayer(function (l) {
            var o = l.options && l.options.icon && l.options.icon.options;
            if (l._icon && o && o.className === "camloc-corner-label") { labels.push(l); }
        });
        labels.forEach(function (l) {  // the corner points
            var p = map.latLngToContainerPoint(l.getLatLng());
            taken.push({x: p.x - G, y: p.y - G, w: 2 * G, h: 2 * G});
        });
        labels.sort(function (a, b) {  // map corners' labels (next to the point) first
            return Math.abs(a.options.icon.options.iconAnchor[1]) -
                Math.abs(b.options.icon.options.iconAnchor[1]);
        });
        labels.forEach(function (l) {
            var p = map.latLngToContainerPoint(l.getLatLng());
            var a = l.options.icon.options.iconAnchor, x0 = -a[0], y0 = -a[1];
            var right = x0 >= 0, down = y0 >= 0, tier0 = Math.abs(y0) > G + H ? 1 : 0;
            var places = [], best = null, bestCost = Infinity;
            var xs = [right ? G : -G - W, right ? -G - W : G, -W / 2];  // beside, centred
            for (var tier = tier0; tier < tier0 + 4; tier++) {
                [down, !down].forEach(function (d) {
                    xs.forEach(function (x) {
                        places.push([x, d ? G + tier * (H + 2) : -G - H - tier * (H + 2)]);
                    });
                });
            }
            places.forEach(function (o) {
                if (bestCost === 0) { return; }
                var r = {x: p.x + o[0], y: p.y + o[1], w: W, h: H}, cost = 0;
                taken.forEach(function (t) { cost += overlap(r, t); });
                if (cost < bestCost) { bestCost = cost; best = o; }
            });
            l._icon.style.marginLeft = best[0] + "px";
            l._icon.style.marginTop = best[1] + "px";
            taken.push({x: p.x + best[0], y: p.y + best[1], w: W, h: H});
        });
    }
    map.on("zoomend overlayadd overlayremove", place);
    map.whenReady(function () { setTimeout(place, 0); });
}
"""


_CANDIDATES_APART_JS = """
function camlocCandidatesApart(map, G) {
    // Candidate discs that would cover each other at this zoom (3 m apart at a junction:
    // rank 3 hidden under rank 1 at the opening zoom) are drawn apart: by rank, each takes
    // the first place, on rings around its point, that covers no disc placed before it, and
    // a thin leader joins it to its point. Redone at every zoom and layer toggle; at a zoom
    // where they stand clear, every disc is on its point.
    var leaders = L.layerGroup().addTo(map);
    function place() {
        leaders.clearLayers();
        var ms = [];
        map.eachLayer(function (l) {
            var o = l.options && l.options.icon && l.options.icon.options;
            if (!(l._icon && o && o.className === "camloc-candidate")) { return; }
            if (l._camlocMargin === undefined) {
                l._camlocMargin = [parseFloat(l._icon.style.marginLeft) || 0,
                                   parseFloat(l._icon.style.marginTop) || 0];
            }
            l._icon.style.marginLeft = l._camlocMargin[0] + "px";
            l._icon.style.marginTop = l._camlocMargin[1] + "px";
            var d = l._icon.querySelector(".camloc-dot");
            if (!l._icon.offsetWidth || !d) { return; }
            ms.push({l: l, rank: parseInt(d.getAttribute("data-rank"), 10) || 0,
                     r: Math.max(l._icon.offsetWidth, l._icon.offsetHeight) / 2});
        });
        ms.sort(function (a, b) { return a.rank - b.rank; });
        var placed = [];
        ms.forEach(function (m) {
            var p = map.latLngToContainerPoint(m.l.getLatLng()), best = null;
            function clear(x, y) {
                return placed.every(function (q) {
                    return Math.hypot(x - q.x, y - q.y) >= m.r + q.r + G;
                });
            }
            if (clear(p.x, p.y)) { best = [0, 0]; }
            var away = 0;
            placed.forEach(function (q) {  // start the search away from the nearest disc
                if (Math.hypot(p.x - q.x, p.y - q.y) < m.r + q.r + G) {
                    away = Math.atan2(p.y - q.y, p.x - q.x) || Math.atan2(q.r, -q.r);
                }
            });
            for (var ring = 1; !best && ring <= 8; ring++) {
                var dist = ring * (m.r + G);
                for (var k = 0; k < 12 && !best; k++) {
                    var a = away + (k % 2 ? 1 : -1) * Math.ceil(k / 2) * Math.PI / 6;
                    var x = p.x + dist * Math.cos(a), y = p.y + dist * Math.sin(a);
                    if (clear(x, y)) { best = [x - p.x, y - p.y]; }
                }
            }
            best = best || [0, 0];
            placed.push({x: p.x + best[0], y: p.y + best[1], r: m.r});
            if (best[0] || best[1]) {
                m.l._icon.style.marginLeft = (m.l._camlocMargin[0] + best[0]) + "px";
                m.l._icon.style.marginTop = (m.l._camlocMargin[1] + best[1]) + "px";
                m.l._icon.setAttribute("data-moved-px", Math.round(Math.hypot(best[0], best[1])));
                L.polyline([m.l.getLatLng(), map.containerPointToLatLng(
                    [p.x + best[0], p.y + best[1]])],
                    {color: "#111", weight: 1.5, opacity: 0.8, interactive: false,
                     className: "camloc-leader"}).addTo(leaders);
                L.circleMarker(m.l.getLatLng(), {radius: 2.5, color: "#111", weight: 1,
                    fillOpacity: 1, interactive: false}).addTo(leaders);
            } else {
                m.l._icon.removeAttribute("data-moved-px");
            }
        });
    }
    map.on("zoomend overlayadd overlayremove", place);
    map.whenReady(function () { setTimeout(place, 0); });
}
"""


class _CandidatesApart(MacroElement):
    """Candidate discs drawn clear of each other at every zoom, each joined to its point by
    a leader (:data:`_CANDIDATES_APART_JS`); added after the markers, before the labels.

    The sample's rank 3 stood 3.4 m from rank 1 and was hidden under it at the opening zoom
    (only a hover raised it): a reviewer could not see or click a tied candidate (qa7).
    """

    _template = Template(
        """
{% macro script(this, kwargs) %}
(function () {
    {{ this.js }}
    camlocCandidatesApart({{ this._parent.get_name() }}, {{ this.g }});
})();
{% endmacro %}
"""
    )

    def __init__(self) -> None:
        super().__init__()
        self._name = "CamlocCandidatesApart"
        self.js = _CANDIDATES_APART_JS
        self.g = 2


class _LabelsClear(MacroElement):
    """Corner labels placed clear of the candidates and of each other
    (:data:`_LABELS_CLEAR_JS`); added after the markers.

    The labels' own places (:func:`_corner_icon`) are fixed offsets, and at the bundled
    sample's opening zoom "m0" and a matched scene corner's "2" overlapped (stop 41).
    """

    _template = Template(
        """
{% macro script(this, kwargs) %}
(function () {
    {{ this.js }}
    camlocLabelsClear({{ this._parent.get_name() }}, {{ this.w }}, {{ this.h }}, {{ this.g }});
})();
{% endmacro %}
"""
    )

    def __init__(self) -> None:
        super().__init__()
        self._name = "CamlocLabelsClear"
        self.js = _LABELS_CLEAR_JS
        self.w, self.h, self.g = _LABEL_W_PX, _LABEL_H_PX, _LABEL_GAP_PX


class _FitClear(MacroElement):
    """Fit the map to ``bounds`` clear of its boxes (:data:`_FIT_CLEAR_JS`); added last."""

    _template = Template(
        """
{% macro script(this, kwargs) %}
(function () {
    {{ this.js }}
    camlocFitClear({{ this._parent.get_name() }}, {{ this.bounds|tojson }},
                   {{ this.max_zoom|tojson }});
})();
{% endmacro %}
"""
    )

    def __init__(self, bounds: list[list[float]], max_zoom: int | None = None) -> None:
        super().__init__()
        self._name = "CamlocFitClear"
        self.js = _FIT_CLEAR_JS
        self.bounds = bounds
        self.max_zoom = max_zoom


CLUSTER_NEAR_PX = 4
"""At the zoom a clustered summary page opens at, and closer, only cameras whose markers
stand within this many pixels of each other (all but on top of each other: two cameras
placed at one junction's point) share a cluster, which a click spreads out (markercluster's
spiderfy); zoomed out farther, markercluster's own 80 px clusters. Cameras tens of metres
apart are never hidden in a cluster at the opening zoom: a reviewer sees each marker (a page
of more than :data:`CLUSTER_OPEN_MAX_MARKERS` cameras: from :data:`CLUSTER_STREET_ZOOM`)."""

CLUSTER_OPEN_MAX_MARKERS = 300
"""A summary page with more cameras than this opens clustered as markercluster clusters
(80 px) and drops to :data:`CLUSTER_NEAR_PX` only from :data:`CLUSTER_STREET_ZOOM` on: a
city's thousands of cameras as single markers at a city's zoom would be slow and cover
each other."""

CLUSTER_STREET_ZOOM = 16
"""The zoom (about 2 m a pixel) from which a large summary page clusters only markers all
but on top of each other."""


class _OpenUnclustered(MacroElement):
    """Fit a clustered summary page to its cameras (no animation), then cluster only markers
    all but on top of each other (:data:`CLUSTER_NEAR_PX`) at that zoom and closer (a large
    page: from :data:`CLUSTER_STREET_ZOOM`)."""

    _template = Template(
        """
{% macro script(this, kwargs) %}
(function () {
    {{ this.js }}
    var map = {{ this._parent.get_name() }};
    var group = {{ this.group }};
    function recluster(open) {  // before the view moves: the group then shows the new view
        var markers = group.getLayers();
        var from = markers.length <= {{ this.max_markers }} ? open
            : Math.max(open, {{ this.street_zoom }});
        group.options.maxClusterRadius = function (zoom) {
            return zoom >= from ? {{ this.near_px }} : 80;
        };
        group.clearLayers();  // clustered again under the new radius
        group.addLayers(markers);
        map.getContainer().setAttribute("data-camloc-open-zoom", String(open));
        map.getContainer().setAttribute("data-camloc-unclustered-from", String(from));
    }
    {% if this.bounds %}
    camlocFitClear(map, {{ this.bounds|tojson }}, 18, recluster);
    {% else %}
    recluster(map.getZoom());
    {% endif %}
})();
{% endmacro %}
"""
    )

    def __init__(self, group: Any, bounds: list[list[float]] | None) -> None:
        super().__init__()
        self._name = "CamlocOpenUnclustered"
        self.group = group.get_name()
        self.bounds = bounds
        self.near_px = CLUSTER_NEAR_PX
        self.js = _FIT_CLEAR_JS
        self.max_markers = CLUSTER_OPEN_MAX_MARKERS
        self.street_zoom = CLUSTER_STREET_ZOOM


@lru_cache(maxsize=1)
def markercluster_assets() -> tuple[str, str]:
    """Leaflet.markercluster's JS and CSS (its two stylesheets) from the xstatic package."""
    import xstatic.pkg.leaflet_markercluster as xmc

    base = Path(xmc.BASE_DIR)
    js = (base / "leaflet.markercluster.js").read_text(encoding="utf-8")
    js = re.sub(r"//# sourceMappingURL=\S+", "", js)
    css = (base / "MarkerCluster.css").read_text(encoding="utf-8") + (
        base / "MarkerCluster.Default.css"
    ).read_text(encoding="utf-8")
    if "</script" in js.lower() or "</style" in css.lower():
        raise ValueError("leaflet.markercluster cannot be inlined")
    return js, css


def summary_page(
    items: Iterable[tuple[str, Any]],
    *,
    tiles: str | None = None,
    tiles_attribution: str | None = None,
    verdict_service: str | None = None,
    verdicts: Sequence[Mapping[str, Any]] | None = None,
    map_source: Any = None,
    pending: int = 0,
) -> str:
    """The summary page as one self-contained HTML text, with clusters.

    Leaflet, jQuery and Leaflet.markercluster are inlined (no CDN), so the markers are
    clustered with the verdict counts under each cluster (as ``camloc batch --map``'s page);
    a basemap only when ``tiles`` is given: then its tiles are the page's only requests
    (besides ``verdict_service``'s, opened over HTTP).

    Parameters
    ----------
    items, verdicts, verdict_service
        As :func:`build_summary_map`.
    tiles
        A tile URL template (``https://tiles.example.org/{z}/{x}/{y}.png``), or None: no
        basemap, the page makes no request of its own.
    tiles_attribution
        The basemap's attribution (plain text; default ``basemap: <host>``).
    map_source
        Without ``tiles``: the extracts (a :class:`~camloc_geo.osm.MapCatalogue`, an extract
        or a folder) whose streets and buildings around the cameras are drawn as a light
        vector basemap, inlined (:func:`basemap_maps`, :func:`build_summary_map`'s
        ``map_data``); never the network. None: no basemap.
    pending
        Cameras not done yet, as :func:`build_summary_map`'s.

    Returns
    -------
    str
        The page.
    """
    items = list(items)
    map_data: list[MapData] | None = None
    if map_source is not None and not tiles:
        points = []
        for _scene_id, item in items:
            best, _reason = _best_feature(item)
            if best is not None:
                points.append((float(best["properties"]["lat"]), float(best["properties"]["lon"])))
        map_data, unserved = basemap_maps(points, map_source)
        if unserved:
            log.info("basemap: %d camera(s) outside the extracts' areas loaded", unserved)
    attribution = None
    if tiles:
        from urllib.parse import urlsplit

        attribution = tiles_attribution or f"basemap: {urlsplit(tiles).hostname or tiles}"
    fmap = build_summary_map(
        items,
        offline=False,
        tiles=tiles or None,
        tiles_attribution=attribution,
        cluster=True,
        map_data=map_data or None,
        verdicts=verdicts,
        verdict_service=verdict_service,
        pending=pending,
    )
    page = fmap.get_root().render()
    page = re.sub(
        r"<script\b[^>]*src=\"[^\"]*leaflet\.markercluster[^\"]*\.js\"[^>]*>\s*</script>",
        lambda _m: "<!--camloc:markercluster_js-->",
        page,
    )
    page = re.sub(
        r"<link\b[^>]*href=\"[^\"]*MarkerCluster[^\"]*\.css\"[^>]*/?>",
        lambda _m: "<!--camloc:markercluster_css-->",
        page,
    )
    if not tiles:  # without a tile layer the map has no maxZoom, which the clusters need
        page = re.sub(
            r"(L\.map\(\s*\"[^\"]+\",\s*\{)", lambda m: m.group(1) + " maxZoom: 22,", page, count=1
        )
    page = inline_assets(page, tiles=bool(tiles))
    js, css = markercluster_assets()
    page = page.replace("<!--camloc:markercluster_css-->", "<style>" + css + "</style>", 1)
    page = page.replace("<!--camloc:markercluster_css-->", "")
    page = page.replace("<!--camloc:markercluster_js-->", "<script>" + js + "</script>", 1)
    return page.replace("<!--camloc:markercluster_js-->", "")


def summary_map(
    items: Iterable[tuple[str, Any]],
    path: str | Path,
    *,
    offline: bool = False,
    tiles: str | None = "OpenStreetMap",
    cluster: bool = True,
    map_data: MapData | None = None,
    verdicts: Sequence[Mapping[str, Any]] | None = None,
    verdict_service: str | None = None,
) -> Path:
    """Write the summary map of many cameras; see :func:`build_summary_map`.

    Returns
    -------
    Path
        The page written.
    """
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fmap = build_summary_map(
        items,
        offline=offline,
        tiles=tiles,
        cluster=cluster,
        map_data=map_data,
        verdicts=verdicts,
        verdict_service=verdict_service,
    )
    page = _render(fmap, offline)
    from camloc_geo._io import write_text_atomic

    write_text_atomic(out, page)
    log.info("wrote %s (%d bytes)", out, len(page.encode("utf-8")))
    return out


# ----------------------------------------------------------------------------- verdicts
VERDICTS: tuple[str, ...] = ("yes", "no", "unsure")
"""A reviewer's verdict on a candidate (on the summary page: on a camera's chosen candidate):
``yes`` (this is the camera; on the summary page "confirm"), ``no`` (not this one; "reject"),
``unsure``."""

VERDICT_FIELDS: tuple[str, ...] = (
    "camera",
    "rank",
    "lat",
    "lon",
    "verdict",
    "note",
    "reviewer",
    "time",
    "page",
    "identity",
)
"""Columns of an exported verdicts CSV (and properties of its GeoJSON's features), in order."""

VERDICT_NOTE_CHARS = 200
"""Longest note a reviewer can type into a verdict control."""

_VERDICT_STORE = "camloc-verdicts/v1/"

_VERDICT_CSS = """
.camloc-vmark { position: relative; width: 100%; height: 100%; }
.camloc-vmark[data-verdict]::after { position: absolute; bottom: -9px; left: -9px; width: 17px;
  height: 17px; border-radius: 50%; border: 1.5px solid #fff; box-sizing: border-box;
  font: bold 12px/14px sans-serif; text-align: center; color: #fff;
  box-shadow: 0 0 0 1px #111; }
.camloc-vmark[data-verdict="yes"]::after { content: "\\2713"; background: #1b7f3b; }
.camloc-vmark[data-verdict="no"]::after { content: "\\2717"; background: #b00020; }
.camloc-vmark[data-verdict="unsure"]::after { content: "?"; background: #555; }
.camloc-verdict { margin: 6px 0 5px; border-top: 1px solid #ccc; padding-top: 5px; }
.camloc-verdict .camloc-vbtns { display: flex; flex-wrap: wrap; gap: 4px; }
.camloc-verdict button, .camloc-verdicts button { font: 12px sans-serif; padding: 3px 7px;
  border: 1px solid #777; border-radius: 4px; background: #f5f5f5; cursor: pointer;
  min-height: 28px; }
.camloc-verdict button[aria-pressed="true"] { color: #fff; border-color: #111; }
.camloc-verdict button.v-yes[aria-pressed="true"] { background: #1b7f3b; }
.camloc-verdict button.v-no[aria-pressed="true"] { background: #b00020; }
.camloc-verdict button.v-unsure[aria-pressed="true"] { background: #555; }
.camloc-verdict input, .camloc-verdict select, .camloc-verdicts input { font: 12px sans-serif;
  margin-top: 4px; box-sizing: border-box; max-width: 100%; }
.camloc-verdict input { width: 100%; }
.camloc-verdicts { background: rgba(255,255,255,0.95); padding: 5px 8px; border-radius: 5px;
  box-shadow: 0 1px 5px rgba(0,0,0,0.4); font: 12px/1.35 sans-serif; color: #222;
  max-width: min(300px, calc(100vw - 30px)); box-sizing: border-box; }
.camloc-verdicts .camloc-vhead { display: flex; align-items: center; gap: 6px; }
.camloc-verdicts .camloc-vcount { font-weight: bold; }
.camloc-verdicts button.camloc-vfold { min-height: 0; padding: 0 5px; margin-left: auto; }
.camloc-verdicts.folded .camloc-vtools, .camloc-verdicts.folded .camloc-vwarn { display: none; }
.camloc-verdicts .camloc-vtools { display: flex; flex-wrap: wrap; gap: 4px; margin-top: 3px;
  align-items: center; }
.camloc-verdicts input { width: 8em; margin: 0; }
.camloc-verdicts .camloc-vwarn { color: #b00020; display: block; }
.camloc-verdicts .camloc-vshare { flex-basis: 100%; color: #1b5e20; }
.camloc-verdicts .camloc-vkey { flex-basis: 100%; margin: 2px 0 0; }
.camloc-verdicts .camloc-vkey[hidden] { display: none; }
.camloc-verdicts .camloc-vkey span { display: block; }
.camloc-verdicts .camloc-vkey input { width: 12em; margin-right: 4px; }
.camloc-cluster .camloc-cbadge { position: absolute; top: 34px; left: 50%;
  transform: translateX(-50%); display: flex; gap: 1px; white-space: nowrap;
  pointer-events: none; }
.camloc-cluster .camloc-cv { font: bold 11px/14px sans-serif; color: #fff; padding: 0 3px;
  border-radius: 7px; border: 1px solid #fff; box-shadow: 0 0 0 1px #111; }
.camloc-cluster .camloc-cv-yes { background: #1b7f3b; }
.camloc-cluster .camloc-cv-no { background: #b00020; }
.camloc-cluster .camloc-cv-unsure { background: #555; }
.camloc-sr { position: absolute; width: 1px; height: 1px; overflow: hidden;
  clip: rect(0 0 0 0); white-space: nowrap; }
.camloc-verdicts .camloc-vshare.bad { color: #b00020; }
"""


_CLUSTER_ICON_JS = """
function (cluster) {
    // Leaflet.markercluster's own icon (its CSS classes and size steps) with the verdicts
    // inside the cluster counted under it: "✓2 ✗1 ?1" (the page's verdicts script tells a
    // camera's verdict through window.camlocVerdictOf; before it runs, none)
    var n = cluster.getChildCount();
    var size = n < 10 ? "small" : (n < 100 ? "medium" : "large");
    var of = window.camlocVerdictOf;
    var counts = {yes: 0, no: 0, unsure: 0};
    if (typeof of === "function") {
        cluster.getAllChildMarkers().forEach(function (m) {
            var o = m.options.icon && m.options.icon.options;
            var key = /data-verdict-mark="([^"]*)"/.exec((o && o.html) || "");
            var v = key ? of(key[1]) : null;
            if (v && counts.hasOwnProperty(v)) { counts[v]++; }
        });
    }
    var sym = {yes: "\\u2713", no: "\\u2717", unsure: "?"};
    var words = {yes: "confirmed", no: "rejected", unsure: "unsure"};
    var badge = "", said = [];
    ["yes", "no", "unsure"].forEach(function (v) {
        if (counts[v]) {
            badge += '<span class="camloc-cv camloc-cv-' + v + '" data-verdict="' + v + '">' +
                sym[v] + counts[v] + "</span>";
            said.push(counts[v] + " " + words[v]);
        }
    });
    var left = n - counts.yes - counts.no - counts.unsure;
    var label = n + " cameras: " + (said.length ? said.join(", ") + ", " + left +
        " not reviewed" : "none reviewed");
    return L.divIcon({
        html: '<div><span>' + n + '</span></div>' +
            (badge ? '<span class="camloc-cbadge" aria-hidden="true">' + badge + '</span>' : '') +
            '<span class="camloc-sr">' + label + '</span>',
        className: "marker-cluster marker-cluster-" + size + " camloc-cluster",
        iconSize: new L.Point(40, 40)
    });
}
"""
"""The summary page's cluster icon: markercluster's own, with a badge counting the verdicts
of the cameras inside (and the counts as text for screen readers)."""


class _Verdicts(MacroElement):
    """The reviewer's verdicts: a control in each popup's ``.camloc-verdict`` placeholder, a
    badge on marked markers, a counter, the reviewer's name and the export buttons, all kept
    in the browser's localStorage under the page's kind and identity (see docs/candidates.md).
    """

    _template = Template(
        """
{% macro header(this, kwargs) %}
<style>{{ this.css }}</style>
{% endmacro %}
{% macro script(this, kwargs) %}
(function () {
    var cfg = {{ this.config|tojson }};
    var map = {{ this._parent.get_name() }};
    var KEY = {{ this.store|tojson }} + cfg.kind + "/" + cfg.identity;
    var WHO = {{ this.store|tojson }} + "reviewer";
    // the service's API key, when it wants one for changes: asked once (on the first 401),
    // kept for this tab's session only (sessionStorage), sent as X-API-Key
    var APIKEY = {{ this.store|tojson }} + "service-key";
    var SYM = {yes: "\\u2713", no: "\\u2717", unsure: "?"};
    var LABEL = cfg.labels;
    var store = null;
    try { store = window.localStorage; store.getItem(WHO); } catch (e) { store = null; }
    var state = {items: {}};
    // served by a camloc service (over HTTP, cfg.service a path): verdicts shared there too,
    // from a file none; a page pointed at a service (cfg.service a URL, --verdict-url): there,
    // from a file too (the service allows the page's origin: CAMLOC_CORS_ORIGINS)
    var remote = null;
    var elsewhere = !!cfg.service && /^https?:\\/\\//i.test(cfg.service);
    if (cfg.service && (elsewhere || /^https?:$/.test(window.location.protocol))) {
        remote = cfg.service.replace(/\\/+$/, "") + "/" + cfg.kind + "/" + cfg.identity;
    }
    function load() {
        state = {items: {}};
        if (!store) { return; }
        try {
            var s = JSON.parse(store.getItem(KEY) || "null");
            if (s && typeof s.items === "object" && s.items) { state = s; }
        } catch (e) { state = {items: {}}; }
    }
    function save() {
        if (!store) { return; }
        try { store.setItem(KEY, JSON.stringify(state)); } catch (e) { warn("not saved: " + e); }
    }
    function reviewer() {
        try { return (store && store.getItem(WHO)) || ""; } catch (e) { return ""; }
    }
    function labelOf(it) {  // a large summary page's items carry no label (its camera's)
        return it.label || ("camera " + it.camera);
    }
    function el(tag, cls, text) {
        var e = document.createElement(tag);
        if (cls) { e.className = cls; }
        if (text !== undefined) { e.textContent = text; }
        return e;
    }
    function mark(k) {
        var v = state.items[k] && state.items[k].verdict;
        var it = cfg.items[k];
        document.querySelectorAll('[data-verdict-mark="' + k + '"]').forEach(function (m) {
            if (v) { m.setAttribute("data-verdict", v); }
            else { m.removeAttribute("data-verdict"); }
            var icon = m.closest(".leaflet-marker-icon") || m;
            icon.setAttribute("aria-label", labelOf(it) + (v ? ": " + LABEL[v] : ": not reviewed"));
        });
    }
    var count, warnBox;
    function warn(text) { if (warnBox) { warnBox.textContent = text; } }
    window.camlocVerdictOf = function (k) {
        return (state.items[k] && state.items[k].verdict) || null;
    };
    var reclusterTimer = null;
    function reclusters() {  // the cluster icons count the verdicts inside: made again
        if (reclusterTimer !== null) { return; }
        reclusterTimer = setTimeout(function () {
            reclusterTimer = null;
            map.eachLayer(function (l) {
                if (typeof l.refreshClusters === "function") { l.refreshClusters(); }
            });
        }, 0);
    }
    function counted() {
        reclusters();
        var n = 0;
        cfg.order.forEach(function (k) { if (state.items[k] && state.items[k].verdict) { n++; } });
        if (count) {
            count.textContent = n + " of " + cfg.order.length + " " + cfg.noun + " reviewed";
        }
    }
    function set(k, verdict, rank) {
        var changed = [k];
        var v = state.items[k] || {};
        var same = v.verdict === verdict && (rank === null || v.rank === rank);
        if (same) { delete v.verdict; delete v.rank; }
        else { v.verdict = verdict; if (rank !== null) { v.rank = rank; } else { delete v.rank; } }
        v.time = new Date().toISOString();
        delete v.reviewer;  // a handed-in verdict changed here is this reviewer's
        state.items[k] = v;
        if (cfg.kind === "candidates" && v.verdict === "yes") {
            // one candidate is the camera: a "yes" on another is withdrawn
            cfg.order.forEach(function (o) {
                var w = state.items[o];
                if (o !== k && w && w.verdict === "yes") {
                    delete w.verdict;
                    w.time = v.time;
                    mark(o);
                    changed.push(o);
                }
            });
        }
        save(); mark(k); counted(); share(changed);
    }
    // ---- sharing with the service (remote): the latest time of a key wins
    var shareBox = null, noteTimer = null;
    function shared(text, bad) {
        if (!shareBox) { return; }
        shareBox.textContent = text;
        shareBox.className = "camloc-vshare" + (bad ? " bad" : "");
    }
    function wire(k) {  // an item as the service keeps it: with the export's camera and point
        var v = state.items[k] || {}, it = cfg.items[k];
        var c = v.verdict ? chosen(k) : {rank: it.rank, lat: it.lat, lon: it.lon};
        return {verdict: v.verdict || null,
                rank: cfg.kind === "summary" ? (v.rank || it.rank || null) : null,
                note: (v.note || "").slice(0, cfg.note_chars),
                reviewer: (typeof v.reviewer === "string" ? v.reviewer : reviewer()).slice(0, 80),
                camera: String(it.camera).slice(0, 300),
                lat: typeof c.lat === "number" ? c.lat : null,
                lon: typeof c.lon === "number" ? c.lon : null,
                time: v.time || null};
    }
    function failed(what) {
        return function (e) {
            var hint = "";
            if (elsewhere && /fetch|network/i.test(String(e))) {  // CORS refusals say no more
                hint = "; is the service up, and this page's origin (" +
                    window.location.origin + ") in its CAMLOC_CORS_ORIGINS?";
            }
            shared("not shared with the service (" + what + ": " + e + hint + ")", true);
        };
    }
    function answer(r) {
        if (r.ok) { return r.json(); }
        function refused(text) {
            var e = new Error(text);
            e.status = r.status;
            throw e;
        }
        return r.json().then(function (b) {
            refused((b && b.error && b.error.message) || ("HTTP " + r.status));
        }, function () { refused("HTTP " + r.status); });
    }
    var keyBox = null, keyInput = null, keyText = null, keyHost = null, panelDiv = null;
    function apiKey() {
        try { return window.sessionStorage.getItem(APIKEY) || ""; } catch (e) { return ""; }
    }
    function askKey(message, hadKey) {  // a change refused for its key: say so, ask for it
        try { window.sessionStorage.removeItem(APIKEY); } catch (e) { /* no storage */ }
        shared("not shared with the service: the change was refused (401: " + message +
               "); kept in this browser only", true);
        if (!keyHost) { return; }
        if (!keyBox) { makeKeyBox(); }
        keyText.textContent = hadKey
            ? "The service refused that key. Enter its API key again:"
            : "The service needs its API key for changes. Enter it (asked once a session):";
        keyBox.hidden = false;
        if (panelDiv) {  // a folded panel would hide the question
            L.DomUtil.removeClass(panelDiv, "folded");
        }
    }
    function makeKeyBox() {
        keyBox = el("form", "camloc-vkey");
        var keyLabel = el("label");
        keyText = el("span");
        keyInput = el("input");
        keyInput.type = "password";
        keyInput.autocomplete = "off";
        keyInput.setAttribute("aria-label", "the service's API key");
        keyLabel.appendChild(keyText);
        keyLabel.appendChild(keyInput);
        keyBox.appendChild(keyLabel);
        var keySend = el("button", "camloc-vkeysend", "Send");
        keySend.type = "submit";
        keyBox.appendChild(keySend);
        keyBox.addEventListener("submit", function (ev) {
            ev.preventDefault();
            var key = keyInput.value.trim();
            if (!key) { return; }
            try { window.sessionStorage.setItem(APIKEY, key); } catch (e) { /* none */ }
            keyInput.value = "";
            keyBox.hidden = true;
            pull();  // reads the service's and sends this browser's newer verdicts
        });
        L.DomEvent.on(keyInput, "keydown keypress keyup", L.DomEvent.stopPropagation);
        keyHost.appendChild(keyBox);
    }
    function sending(hadKey) {
        return function (e) {
            if (e && e.status === 401) { askKey(e.message, hadKey); return; }
            failed("sending")(e && e.message ? e.message : e);
        };
    }
    function share(keys) {
        if (!remote || !keys.length) { return; }
        var body = {items: {}};
        keys.forEach(function (k) { if (cfg.items[k]) { body.items[k] = wire(k); } });
        shared("sharing\u2026", false);
        var headers = {"Content-Type": "application/json"}, key = apiKey();
        if (key) { headers["X-API-Key"] = key; }
        fetch(remote, {method: "POST", headers: headers,
                       body: JSON.stringify(body), credentials: "same-origin"})
            .then(answer).then(function (doc) { adopt(doc, false); }, sending(!!key));
    }
    function adopt(doc, pushBack) {
        // the service's items newer than this browser's are taken; this browser's newer
        // ones (given offline, or handed in with the page) are sent
        var server = (doc && doc.items) || {}, newer = [];
        Object.keys(server).forEach(function (k) {
            var s = server[k], v = state.items[k];
            if (!cfg.items[k] || !s) { return; }
            if (!v || !v.time || (s.time && s.time > v.time)) {
                var w = {time: s.time || "", note: s.note || "", reviewer: s.reviewer || ""};
                if (s.verdict) { w.verdict = s.verdict; }
                if (s.verdict && s.rank) { w.rank = s.rank; }
                state.items[k] = w;
            }
        });
        if (cfg.kind === "candidates") {  // one candidate is the camera: the latest "yes"
            var yes = cfg.order.filter(function (k) {
                return state.items[k] && state.items[k].verdict === "yes";
            });
            yes.sort(function (a, b) {
                return (state.items[a].time || "") < (state.items[b].time || "") ? 1 : -1;
            });
            yes.slice(1).forEach(function (k) {
                delete state.items[k].verdict;
                state.items[k].time = state.items[yes[0]].time;
            });
        }
        cfg.order.forEach(function (k) {
            var v = state.items[k], s = server[k];
            // (the same verdict, rank and note there is not sent again: a clock ahead of the
            // server's, whose times the server takes as its now, sent it on every reading)
            if (!v || !v.time) { return; }
            var w = wire(k);
            var same = s && (s.verdict || null) === w.verdict &&
                (s.rank || null) === w.rank && (s.note || "") === w.note;
            if (!same && (!s || !s.time || v.time > s.time)) { newer.push(k); }
        });
        save(); cfg.order.forEach(mark); counted(); rerender();
        var n = 0;
        Object.keys(server).forEach(function (k) { if (server[k] && server[k].verdict) { n++; } });
        shared("shared with the service (" + n + " there)", false);
        if (pushBack && newer.length) { share(newer); }
    }
    function pull() {
        if (!remote) { return; }
        fetch(remote, {credentials: "same-origin", cache: "no-store"})
            .then(answer).then(function (doc) { adopt(doc, true); }, function (e) {
                failed("reading")(e && e.message ? e.message : e);
            });
    }
    function rerender() {  // an open popup's controls follow a verdict that came in
        document.querySelectorAll(".leaflet-popup .camloc-verdict[data-verdict-key]")
            .forEach(function (box) {
                if (box.contains(document.activeElement) &&
                    document.activeElement.tagName === "INPUT") { return; }
                render(box, box.getAttribute("data-verdict-key"));
            });
    }
    function render(box, k) {
        var it = cfg.items[k];
        if (!it) { return; }
        box.textContent = "";
        var buttons = [], pick = null;
        function sync() {  // the controls' states from the stored verdict, in place (a click
            // target taken out of the page made Leaflet take the click for the map's)
            var v = state.items[k] || {};
            buttons.forEach(function (b) {
                var val = b.getAttribute("data-verdict");
                var on = v.verdict === val && (val !== "yes" || !v.rank || v.rank === it.rank);
                b.setAttribute("aria-pressed", on ? "true" : "false");
            });
            if (pick) {
                var other = v.verdict === "yes" && v.rank && v.rank !== it.rank;
                pick.value = other ? String(v.rank) : "";
            }
        }
        var group = el("div", "camloc-vbtns");
        group.setAttribute("role", "group");
        group.setAttribute("aria-label", "verdict on " + labelOf(it));
        cfg.verdicts.forEach(function (val) {
            var b = el("button", "v-" + val, SYM[val] + " " + LABEL[val]);
            b.type = "button";
            b.setAttribute("data-verdict", val);
            b.addEventListener("click", function () {
                set(k, val, val === "yes" && cfg.kind === "summary" ? it.rank : null);
                sync();
            });
            buttons.push(b);
            group.appendChild(b);
        });
        box.appendChild(group);
        if (it.others && it.others.length) {
            pick = el("select");
            pick.setAttribute("aria-label", "or pick another candidate of " + it.camera);
            pick.appendChild(el("option", "", "or the camera is candidate\\u2026"));
            pick.options[0].value = "";
            it.others.forEach(function (o) {
                var opt = el("option", "", "rank " + o[0] + " (score " + o[3] + ")");
                opt.value = String(o[0]);
                pick.appendChild(opt);
            });
            pick.addEventListener("change", function () {
                if (pick.value) { set(k, "yes", parseInt(pick.value, 10)); }
                sync();
            });
            box.appendChild(pick);
        }
        var note = el("input");
        note.type = "text";
        note.maxLength = cfg.note_chars;
        note.placeholder = "note (optional)";
        note.setAttribute("aria-label", "note on " + labelOf(it));
        note.value = (state.items[k] || {}).note || "";
        note.addEventListener("input", function () {
            var w = state.items[k] || {};
            w.note = note.value;
            w.time = new Date().toISOString();
            delete w.reviewer;
            state.items[k] = w;
            save();
            if (noteTimer !== null) { clearTimeout(noteTimer); }
            noteTimer = setTimeout(function () { noteTimer = null; share([k]); }, 600);
        });
        L.DomEvent.on(note, "keydown keypress keyup", L.DomEvent.stopPropagation);
        box.appendChild(note);
        sync();
    }
    map.on("popupopen", function (e) {
        var root = e.popup.getElement();
        if (!root) { return; }
        var boxes = root.querySelectorAll(".camloc-verdict[data-verdict-key]");
        boxes.forEach(function (box) { render(box, box.getAttribute("data-verdict-key")); });
        // the popup grew by the controls after Leaflet placed it: place and pan it again
        if (boxes.length) { e.popup.update(); }
    });
    function chosen(k) {
        var it = cfg.items[k], v = state.items[k];
        var rank = (v.verdict === "yes" && v.rank) ? v.rank : it.rank;
        var lat = it.lat, lon = it.lon;
        (it.others || []).forEach(function (o) { if (o[0] === rank) { lat = o[1]; lon = o[2]; } });
        return {rank: rank, lat: lat, lon: lon};
    }
    function rows() {
        var who = reviewer();
        var out = [];
        cfg.order.forEach(function (k) {
            var v = state.items[k];
            if (!v || !v.verdict) { return; }
            var it = cfg.items[k], c = chosen(k);
            out.push({camera: it.camera, rank: c.rank, lat: c.lat, lon: c.lon,
                      verdict: v.verdict, note: v.note || "",
                      reviewer: typeof v.reviewer === "string" ? v.reviewer : who,
                      time: v.time || "",
                      page: cfg.kind, identity: cfg.identity});
        });
        return out;
    }
    function cell(x) {
        var s = x === null || x === undefined ? "" : String(x);
        if (/^[=+\\-@\\t\\r]/.test(s) && typeof x === "string") { s = "'" + s; }
        return /[",\\r\\n]/.test(s) ? '"' + s.replace(/"/g, '""') + '"' : s;
    }
    function csv() {
        var lines = [cfg.fields.join(",")];
        rows().forEach(function (r) {
            lines.push(cfg.fields.map(function (f) { return cell(r[f]); }).join(","));
        });
        return "\\ufeff" + lines.join("\\r\\n") + "\\r\\n";
    }
    function geojson() {
        return JSON.stringify({
            type: "FeatureCollection",
            properties: {format: "camloc-verdicts/1", page: cfg.kind, identity: cfg.identity,
                         exported: new Date().toISOString()},
            features: rows().map(function (r) {
                return {type: "Feature", properties: r,
                        geometry: (typeof r.lat === "number" && typeof r.lon === "number")
                            ? {type: "Point", coordinates: [r.lon, r.lat]} : null};
            })
        }, null, 1);
    }
    function download(name, text, type) {
        var url = URL.createObjectURL(new Blob([text], {type: type}));
        var a = el("a");
        a.href = url;
        a.download = name;
        document.body.appendChild(a);
        a.click();
        setTimeout(function () { URL.revokeObjectURL(url); a.remove(); }, 2000);
    }
    // a phone's map (narrower than {{ this.small }} px): top right, under the layers button
    // (at the bottom right it covered the legend and candidates); a map smaller than
    // {{ this.fold_below[0] }}x{{ this.fold_below[1] }} px: folded to its counter (unfolded,
    // it covered candidates 1 and 3 of the tied test scene at 800x600)
    var size = map.getSize();
    var small = size.x < {{ this.small }};
    var folded = small || size.x < {{ this.fold_below[0] }} || size.y < {{ this.fold_below[1] }};
    var panel = L.control({position: small ? "topright" : "bottomright"});
    panel.onAdd = function () {
        var div = L.DomUtil.create("div", "camloc-verdicts" + (folded ? " folded" : ""));
        panelDiv = div;
        div.setAttribute("role", "region");
        div.setAttribute("aria-label", "verdicts");
        var head = el("div", "camloc-vhead");
        count = el("span", "camloc-vcount");
        count.setAttribute("aria-live", "polite");
        head.appendChild(count);
        var fold = el("button", "camloc-vfold", folded ? "\u25b8" : "\u25be");
        fold.type = "button";
        fold.setAttribute("aria-expanded", folded ? "false" : "true");
        fold.setAttribute("aria-label", "show or hide the export tools");
        fold.addEventListener("click", function () {
            var open = L.DomUtil.hasClass(div, "folded");
            (open ? L.DomUtil.removeClass : L.DomUtil.addClass)(div, "folded");
            fold.textContent = open ? "\u25be" : "\u25b8";
            fold.setAttribute("aria-expanded", open ? "true" : "false");
        });
        head.appendChild(fold);
        div.appendChild(head);
        var tools = el("div", "camloc-vtools");
        var who = el("input");
        who.type = "text";
        who.maxLength = 80;
        who.placeholder = "your name";
        who.setAttribute("aria-label", "reviewer's name (in the export)");
        who.value = reviewer();
        who.addEventListener("input", function () {
            try { if (store) { store.setItem(WHO, who.value); } } catch (e) { warn("not saved"); }
        });
        L.DomEvent.on(who, "keydown keypress keyup", L.DomEvent.stopPropagation);
        tools.appendChild(who);
        tools.appendChild(el("span", "", "Export"));
        [["CSV", "text/csv", csv], ["GeoJSON", "application/geo+json", geojson]].forEach(
            function (f) {
                var b = el("button", "camloc-vexport", f[0]);
                b.type = "button";
                b.setAttribute("data-export", f[0].toLowerCase());
                b.setAttribute("aria-label", "export the verdicts as " + f[0]);
                b.title = "download the verdicts as " + f[0] + " (nothing leaves this page)";
                b.addEventListener("click", function () {
                    download(cfg.file + (f[0] === "CSV" ? ".csv" : ".geojson"), f[2](), f[1]);
                });
                tools.appendChild(b);
            });
        if (remote) {
            shareBox = el("small", "camloc-vshare", "sharing\u2026");
            shareBox.setAttribute("aria-live", "polite");
            tools.appendChild(shareBox);
            keyHost = tools;  // the key field is made on the first refusal
        }
        div.appendChild(tools);
        warnBox = el("small", "camloc-vwarn");
        div.appendChild(warnBox);
        if (!store) { warn("verdicts are not kept: this browser gives the page no storage"); }
        L.DomEvent.disableClickPropagation(div);
        L.DomEvent.disableScrollPropagation(div);
        return div;
    };
    panel.addTo(map);
    function refresh() { load(); seed(); cfg.order.forEach(mark); counted(); pull(); }
    function seed() {  // verdicts handed in with the page (--verdicts FILE), once
        if (!cfg.given || state.seeded) { return; }
        var hasYes = cfg.kind === "candidates" && cfg.order.some(function (k) {
            return state.items[k] && state.items[k].verdict === "yes";
        });
        Object.keys(cfg.given).forEach(function (k) {
            var g = cfg.given[k];
            // one candidate is the camera: a handed-in "yes" does not add a second one
            if (hasYes && g.verdict === "yes") { return; }
            if (!state.items[k] && cfg.items[k]) { state.items[k] = g; }
        });
        state.seeded = true;
        save();
    }
    setTimeout(refresh, 0);  // after the markers are on the map
    // a marker's icon is made anew when its layer is shown again (layer list, clusters)
    var again = null;
    map.on("layeradd", function () {
        if (again === null) {
            again = setTimeout(function () { again = null; cfg.order.forEach(mark); }, 0);
        }
    });
    window.addEventListener("pageshow", refresh);  // back button (a page from the bfcache)
    window.addEventListener("storage", function (e) { if (e.key === KEY) { refresh(); } });
    if (remote) {  // the other reviewers' verdicts: on coming back to the page, and every 30 s
        window.addEventListener("focus", pull);
        setInterval(function () {
            if (document.visibilityState !== "hidden") { pull(); }
        }, 30000);
    }
})();
{% endmacro %}
"""
    )

    def __init__(self, config: Mapping[str, Any]) -> None:
        super().__init__()
        self._name = "CamlocVerdicts"
        self.config = dict(config)
        self.css = _VERDICT_CSS
        self.store = _VERDICT_STORE
        self.small = SMALL_SCREEN_PX
        self.fold_below = BANNER_FOLD_BELOW_PX


def _page_identity(parts: Any) -> str:
    """16 hex digits of the SHA-256 of the page's cameras and candidates: two pages share
    stored verdicts only when they show the same candidates of the same cameras."""
    import hashlib
    import json

    blob = json.dumps(parts, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(blob.encode("utf-8")).hexdigest()[:16]


def _verdict_labels(kind: str) -> dict[str, str]:
    if kind == "summary":
        return {"yes": "Confirm", "no": "Reject", "unsure": "Unsure"}
    return {"yes": "This is the camera", "no": "Not this one", "unsure": "Unsure"}


def _num(value: Any, nd: int) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return round(float(value), nd) if math.isfinite(value) else None


def _verdict_config(
    kind: str, items: Mapping[str, Mapping[str, Any]], identity_parts: Any, file_stem: str
) -> dict[str, Any]:
    identity = _page_identity([kind, identity_parts])
    return {
        "kind": kind,
        "identity": identity,
        "items": dict(items),
        "order": list(items),
        "labels": _verdict_labels(kind),
        "verdicts": list(VERDICTS),
        "fields": list(VERDICT_FIELDS),
        "noun": "cameras" if kind == "summary" else "candidates",
        "note_chars": VERDICT_NOTE_CHARS,
        "file": f"verdicts-{_safe(file_stem)[:60]}-{identity[:8]}",
    }


def _given_verdicts(
    items: Mapping[str, Mapping[str, Any]], verdicts: Sequence[Mapping[str, Any]]
) -> dict[str, dict[str, Any]]:
    """The summary page's stored form (key ``c<i>``) of exported verdict rows: a summary
    page's row of the camera first, else a review page's "yes" on one of its candidates,
    else its row on the camera's best candidate; the last such row of a camera wins. Rows
    of cameras not on the page, or choosing a rank the page does not have, are left out
    (counted in a warning)."""
    by_camera: dict[str, list[tuple[str, Mapping[str, Any]]]] = {}
    for key, it in items.items():
        by_camera.setdefault(str(it["camera"]), []).append((key, it))
    given: dict[str, tuple[int, dict[str, Any]]] = {}
    unused = 0
    for row in verdicts:
        placed = False
        for key, it in by_camera.get(str(row.get("camera")), []):
            ranks = {it["rank"], *(o[0] for o in it.get("others") or [])}
            rank = row.get("rank")
            if row.get("page") == "summary":
                level = 3
            elif row.get("verdict") == "yes" and rank in ranks:
                level = 2
            elif rank == it["rank"]:
                level = 1
            else:
                continue
            if row.get("verdict") == "yes" and rank not in ranks:
                continue
            item = {"verdict": row.get("verdict"), "note": row.get("note") or ""}
            item["time"] = row.get("time") or ""
            item["reviewer"] = row.get("reviewer") or ""
            if row.get("verdict") == "yes" and rank is not None:
                item["rank"] = rank
            if level >= given.get(key, (0, {}))[0]:
                given[key] = (level, item)
            placed = True
        unused += not placed
    if unused:
        log.warning("%d verdict row(s) name no camera or candidate of this page: left out", unused)
    return {key: item for key, (_level, item) in given.items()}


_GIVEN_MOVED_M = 30.0
"""A handed-in verdict on a review page's candidate is left out when its position (as
exported) lies farther than this from the candidate of the same rank on the page: the scene
was located again and the ranks moved."""


def _given_candidate_verdicts(
    scene_name: str,
    items: Mapping[str, Mapping[str, Any]],
    verdicts: Sequence[Mapping[str, Any]],
) -> dict[str, dict[str, Any]]:
    """The review page's stored form (key ``str(rank)``) of exported verdict rows of its
    camera: a review page's row of a candidate first, else a summary page's row naming the
    candidate's rank (its "confirm" is "this is the camera"); the last such row wins. Rows of
    other cameras, of ranks the page does not have, or whose position is more than
    :data:`_GIVEN_MOVED_M` from the page's candidate are left out (counted in a warning). At
    most one candidate keeps "yes" (the latest by time)."""
    given: dict[str, tuple[int, dict[str, Any]]] = {}
    unused = moved = 0
    for row in verdicts:
        rank = row.get("rank")
        key = str(rank)
        it = items.get(key)
        if str(row.get("camera")) != scene_name or rank is None or it is None:
            unused += 1
            continue
        lat, lon = row.get("lat"), row.get("lon")
        if (
            lat is not None
            and lon is not None
            and it.get("lat") is not None
            and it.get("lon") is not None
            and _distance_m({"lat": lat, "lon": lon}, it) > _GIVEN_MOVED_M
        ):
            moved += 1
            continue
        level = 2 if row.get("page") == "candidates" else 1
        item = {
            "verdict": row.get("verdict"),
            "note": row.get("note") or "",
            "time": row.get("time") or "",
            "reviewer": row.get("reviewer") or "",
        }
        if level >= given.get(key, (0, {}))[0]:
            given[key] = (level, item)
    out = {key: item for key, (_level, item) in given.items()}
    yes = [k for k, v in out.items() if v["verdict"] == "yes"]
    if len(yes) > 1:  # one candidate is the camera: the latest "yes" stays
        keep = max(yes, key=lambda k: str(out[k]["time"]))
        for k in yes:
            if k != keep:
                del out[k]
        log.warning(
            "verdicts: %d candidates of %s given 'yes': kept candidate %s (the latest)",
            len(yes),
            scene_name,
            keep,
        )
    if unused:
        log.warning(
            "%d verdict row(s) name another camera or a rank not on this page: left out", unused
        )
    if moved:
        log.warning(
            "%d verdict row(s) lie more than %.0f m from this page's candidate of their rank "
            "(the scene was located again): left out",
            moved,
            _GIVEN_MOVED_M,
        )
    return out


def _verdict_box(key: str) -> str:
    """The popup's placeholder the page's script fills with the verdict control."""
    return f'<div class="camloc-verdict" data-verdict-key="{html.escape(key)}"></div>'


def _vmark(key: str, inner: str) -> str:
    """A marker's HTML wrapped so that its verdict badge can be drawn on it."""
    return f'<div class="camloc-vmark" data-verdict-mark="{html.escape(key)}">{inner}</div>'


def read_verdicts(path: str | Path) -> list[dict[str, Any]]:
    """Read the verdicts a reviewer exported from a review or summary page.

    Parameters
    ----------
    path
        The exported ``.csv`` or ``.geojson`` (see docs/candidates.md, "Verdicts").

    Returns
    -------
    list of dict
        One row per reviewed candidate or camera, keys :data:`VERDICT_FIELDS`: ``camera``,
        ``note``, ``reviewer``, ``time``, ``page``, ``identity`` as ``str``, ``verdict`` one of
        :data:`VERDICTS`, ``rank`` an ``int`` (or None), ``lat``/``lon`` floats in degrees (or
        None).

    Raises
    ------
    InputError
        The file is missing, is neither an exported CSV nor GeoJSON, lacks a column, or a row
        has a verdict, rank or position that is not one (the message names the row), or no
        row names a camera.

    Notes
    -----
    A row without a camera id (a service export of an item posted without ``camera``) is left
    out with a warning naming its line or feature; the other rows are read. One such row sank
    the whole file ("line 3: no camera id", exit 2) though the service had taken it.
    """
    import csv
    import json

    from camloc_geo._errors import InputError

    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise InputError(f"{p}: no such verdicts file") from None
    except UnicodeDecodeError:
        from camloc_geo.cameras import binary_list_kind

        with open(p, "rb") as fh:
            kind = binary_list_kind(fh.read(4096)) or "not UTF-8 text"
        raise InputError(
            f"{p}: not a verdicts file ({kind}): give the .csv or .geojson a review or "
            "summary page exported (its Export button)"
        ) from None
    except OSError as exc:
        raise InputError(f"{p}: cannot read the verdicts file: {exc}") from None
    raw: list[tuple[str, Mapping[str, Any]]] = []
    if not text.strip():
        raise InputError(
            f"{p}: the verdicts file is empty (export the page's verdicts as CSV or GeoJSON)"
        )
    if text.lstrip().startswith(("{", "[")):
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InputError(f"{p}: not valid JSON: {exc}") from None
        feats = data.get("features") if isinstance(data, dict) else None
        if not isinstance(feats, list):
            what = "no 'features' list" if isinstance(data, dict) else "not a JSON object"
            raise InputError(f"{p}: not a verdicts GeoJSON ({what})")
        for i, f in enumerate(feats):
            props = f.get("properties") if isinstance(f, dict) else None
            if not isinstance(props, dict):
                raise InputError(f"{p}: features[{i}] has no properties")
            raw.append((f"features[{i}]", props))
    else:
        reader = csv.DictReader(text.splitlines())
        missing = [f for f in ("camera", "verdict") if f not in (reader.fieldnames or [])]
        if missing:
            # (it listed the export's columns as "columns: camera, ...", which read as the
            # file's own: a camera list was "no column camera, verdict (columns: camera, ...")
            found = ", ".join(str(c) for c in (reader.fieldnames or [])[:12]) or "none"
            raise InputError(
                f"{p}: not a verdicts CSV: no column {', '.join(missing)} (its columns: "
                f"{found[:200]}; a page's export has {', '.join(VERDICT_FIELDS)})"
            )
        for i, row in enumerate(reader, start=2):
            raw.append((f"line {i}", row))
    rows, no_camera = [], []
    for where, r in raw:
        if not _unformula(r.get("camera")).strip():
            no_camera.append(where)
            continue
        rows.append(_verdict_row(p, where, r))
    if no_camera:
        named = ", ".join(no_camera[:10]) + (" ..." if len(no_camera) > 10 else "")
        if not rows:
            raise InputError(
                f"{p}: {named}: no camera id, in any row: a verdict row names its camera "
                "(a page's export does; an item posted to the service without 'camera' "
                "has none)"
            )
        log.warning(
            "%s: %d verdict row(s) without a camera id left out (%s); the other %d read",
            p,
            len(no_camera),
            named,
            len(rows),
        )
    return rows


def _unformula(value: Any) -> str:
    """A text cell as typed: the export's "'" guard before = + - @ removed."""
    s = "" if value is None else str(value)
    return s[1:] if len(s) >= 2 and s[0] == "'" and s[1] in "=+-@\t\r" else s


def _verdict_row(path: Path, where: str, row: Mapping[str, Any]) -> dict[str, Any]:
    from camloc_geo._errors import InputError

    verdict = str(row.get("verdict") or "").strip()
    if verdict not in VERDICTS:
        raise InputError(
            f"{path}: {where}: verdict {verdict!r} is not one of {', '.join(VERDICTS)}"
        )
    camera = _unformula(row.get("camera"))
    if not camera:
        raise InputError(f"{path}: {where}: no camera id")
    out: dict[str, Any] = {"camera": camera, "verdict": verdict}
    rank = row.get("rank")
    if rank in (None, ""):
        out["rank"] = None
    else:
        try:
            out["rank"] = int(str(rank))
        except ValueError:
            raise InputError(f"{path}: {where}: rank {rank!r} is not a whole number") from None
    for key, bound in (("lat", 90.0), ("lon", 180.0)):
        value = row.get(key)
        if value in (None, ""):
            out[key] = None
            continue
        try:
            num = float(value)
        except (TypeError, ValueError):
            raise InputError(f"{path}: {where}: {key} {value!r} is not a number") from None
        if not (math.isfinite(num) and -bound <= num <= bound):
            raise InputError(f"{path}: {where}: {key} {value!r} is out of range")
        out[key] = num
    for key in ("note", "reviewer", "time", "page", "identity"):
        out[key] = _unformula(row.get(key))
    return {k: out[k] for k in VERDICT_FIELDS}


# ------------------------------------------------------------------------------ offline
@lru_cache(maxsize=1)
def leaflet_assets() -> dict[str, str]:
    """Leaflet JS/CSS (images as data URIs) and jQuery from the xstatic packages."""
    import xstatic.pkg.jquery as xjquery
    import xstatic.pkg.leaflet as xleaflet

    lbase = Path(xleaflet.BASE_DIR)
    css = (lbase / "leaflet.css").read_text(encoding="utf-8")

    def data_uri(match: re.Match[str]) -> str:
        name = match.group(1)
        blob = (lbase / "images" / name).read_bytes()
        return "url(data:image/png;base64," + base64.b64encode(blob).decode("ascii") + ")"

    css = re.sub(r"url\(images/([A-Za-z0-9_.-]+\.png)\)", data_uri, css)
    css = css.replace("url(#default#VML)", "none")
    js = (lbase / "leaflet.js").read_text(encoding="utf-8")
    js = re.sub(r"//# sourceMappingURL=\S+", "", js)
    jq = (Path(xjquery.BASE_DIR) / "jquery.min.js").read_text(encoding="utf-8")
    jq = re.sub(r"//# sourceMappingURL=\S+", "", jq)
    for name, text in (("leaflet.js", js), ("jquery.min.js", jq)):
        if "</script" in text.lower():
            raise ValueError(f"{name} contains '</script' and cannot be inlined")
    return {"leaflet_js": js, "leaflet_css": css, "jquery_js": jq}


_SCRIPT_SRC = re.compile(r"<script\b[^>]*\bsrc=\"([^\"]+)\"[^>]*>\s*</script>", re.IGNORECASE)
_CSS_LINK = re.compile(r"<link\b[^>]*\bhref=\"([^\"]+)\"[^>]*/?>", re.IGNORECASE)


def inline_assets(page: str, *, tiles: bool = False) -> str:
    """Make a folium page self-contained: inline Leaflet and jQuery, drop other remote assets.

    Parameters
    ----------
    page
        HTML rendered by folium.
    tiles
        Keep the page's tile layers (a basemap configured on purpose, :func:`summary_page`):
        its tiles are then the page's only remote requests. Default: a tile layer is an error.

    Returns
    -------
    The page with Leaflet's and jQuery's ``<script src>``/``<link>`` replaced by inline copies
    from the xstatic packages and every other external script or stylesheet removed.

    Raises
    ------
    ValueError
        When a remote resource reference is left (a tile layer, an ``<img>`` from the web).
    """
    assets = leaflet_assets()

    placeholders = {
        "leaflet_js": "<!--camloc:leaflet_js-->",
        "jquery_js": "<!--camloc:jquery_js-->",
        "leaflet_css": "<!--camloc:leaflet_css-->",
    }

    def script(match: re.Match[str]) -> str:
        url = match.group(1)
        name = url.rsplit("/", 1)[-1].lower()
        if re.fullmatch(r"leaflet(-src)?\.js", name):
            return placeholders["leaflet_js"]
        if re.fullmatch(r"jquery(-[\d.]+)?(\.min)?\.js", name):
            return placeholders["jquery_js"]
        log.debug("offline page: dropped script %s", url)
        return ""

    def link(match: re.Match[str]) -> str:
        url = match.group(1)
        if "stylesheet" not in match.group(0).lower():
            return match.group(0)
        if url.rsplit("/", 1)[-1].lower() == "leaflet.css":
            return placeholders["leaflet_css"]
        log.debug("offline page: dropped stylesheet %s", url)
        return ""

    out = _SCRIPT_SRC.sub(script, page)
    out = _CSS_LINK.sub(link, out)
    leftovers = re.findall(
        r"""<(?:script|img|link|iframe|source|video|audio)\b[^>]*\b(?:src|href)=["']?"""
        r"""(?:https?:)?//[^"'\s>]+""",
        out,
        flags=re.IGNORECASE,
    )
    leftovers += re.findall(r"url\(\s*[\"']?(?:https?:)?//[^)]*\)", out, flags=re.IGNORECASE)
    if not tiles and re.search(r"L\.tileLayer\(", out):
        leftovers.append("L.tileLayer(...)")
    if leftovers:
        raise ValueError(f"offline page still references remote resources: {leftovers[:3]}")
    out = out.replace(
        placeholders["leaflet_css"], "<style>" + assets["leaflet_css"] + "</style>", 1
    )
    for key in ("leaflet_js", "jquery_js"):
        out = out.replace(placeholders[key], "<script>" + assets[key] + "</script>", 1)
    return out
