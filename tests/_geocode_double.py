"""A tiny stand-in for ``camloc_geo.geocode`` while that package is not merged.

Installed into ``sys.modules`` by the batch tests only when the real package is missing.
It follows the interface (``parse_title``, ``geocode_title``, ``TitleMatch``) with the
osm layer's exact-ish name matching; the real package is far better at reading titles.
"""

from __future__ import annotations

import re
import sys
import types
from dataclasses import dataclass, field
from typing import Any

_COMPASS = {
    "north": 0.0,
    "northbound": 0.0,
    "nb": 0.0,
    "n": 0.0,
    "northeast": 45.0,
    "ne": 45.0,
    "east": 90.0,
    "eastbound": 90.0,
    "eb": 90.0,
    "e": 90.0,
    "southeast": 135.0,
    "se": 135.0,
    "south": 180.0,
    "southbound": 180.0,
    "sb": 180.0,
    "s": 180.0,
    "southwest": 225.0,
    "sw": 225.0,
    "west": 270.0,
    "westbound": 270.0,
    "wb": 270.0,
    "w": 270.0,
    "northwest": 315.0,
    "nw": 315.0,
}
_VIEW_RE = re.compile(
    r"\b(?:looking|facing|view(?:ing)?)\s+(north|south|east|west|northeast|northwest|southeast"
    r"|southwest|n|s|e|w|ne|nw|se|sw)\b|\b(nb|sb|eb|wb)\b",
    re.IGNORECASE,
)
_SPLIT_RE = re.compile(r"\s*(?:&|@|/|\band\b|\bat\b)\s*", re.IGNORECASE)


@dataclass
class ParsedTitle:
    raw: str
    streets: list[str] = field(default_factory=list)
    house_number: str | None = None
    camera_number: str | None = None
    view_bearing_deg: float | None = None
    compass_text: str | None = None
    notes: list[str] = field(default_factory=list)


@dataclass
class TitleMatch:
    status: str
    lat: float | None = None
    lon: float | None = None
    uncertainty_m: float | None = None
    intersection: Any = None
    names_read: list[str] = field(default_factory=list)
    names_matched: list[str] = field(default_factory=list)
    match_kinds: list[str] = field(default_factory=list)
    score: float = 0.0
    reason: str | None = None

    def to_feature(self) -> dict[str, Any]:
        return {"type": "Feature", "geometry": None, "properties": {"status": self.status}}


def parse_title(title: str) -> ParsedTitle:
    text = title or ""
    out = ParsedTitle(raw=text)
    m = _VIEW_RE.search(text)
    if m:
        word = (m.group(1) or m.group(2)).lower()
        out.view_bearing_deg = _COMPASS[word]
        out.compass_text = m.group(0)
        text = text[: m.start()] + text[m.end() :]
    text = re.sub(r"^\s*\d+\s*-\s*", "", text)
    out.streets = [p.strip(" -,") for p in _SPLIT_RE.split(text) if p.strip(" -,")]
    return out


def geocode_title(
    title: str,
    *,
    map_data: Any,
    near: tuple[float, float] | None = None,
    radius_m: float | None = None,
) -> list[TitleMatch]:
    from camloc_geo._errors import MapDataError

    parsed = parse_title(title)
    if len(parsed.streets) < 2:
        return [
            TitleMatch(
                "street" if parsed.streets else "not_found",
                names_read=parsed.streets,
                reason="one street only",
            )
        ]
    try:
        x = map_data.find_intersection(parsed.streets[:2], near=near)
    except MapDataError as exc:
        return [TitleMatch("not_found", names_read=parsed.streets, reason=str(exc))]
    if (
        near is not None
        and radius_m is not None
        and map_data._dist_from(near, x.lat, x.lon) > radius_m
    ):
        return [
            TitleMatch(
                "not_found",
                names_read=parsed.streets,
                reason=f"the junction is more than {radius_m:.0f} m from the point",
            )
        ]
    size = max(x.corner_distances_m or [10.0])
    return [
        TitleMatch(
            "junction",
            x.lat,
            x.lon,
            size,
            x,
            parsed.streets,
            list(x.street_names),
            ["exact"] * len(parsed.streets),
            1.0,
            None,
        )
    ]


def install_if_missing() -> bool:
    """Register this module as ``camloc_geo.geocode`` unless the real one exists."""
    try:
        import camloc_geo.geocode  # noqa: F401
    except ImportError:
        mod = types.ModuleType("camloc_geo.geocode")
        for name in ("ParsedTitle", "TitleMatch", "parse_title", "geocode_title"):
            setattr(mod, name, globals()[name])
        sys.modules["camloc_geo.geocode"] = mod
        return True
    return False
