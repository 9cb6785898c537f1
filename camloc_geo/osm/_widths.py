"""Carriageway widths of OSM highways: tags first, documented defaults otherwise.

The kerb-to-kerb width of one carriageway is resolved in this order:

1. ``width`` tag (metres; ``"7 m"``, ``"7,5"``, feet ``"24'"`` / ``"24 ft"`` and feet+inches
   ``24'6"`` are understood);
2. ``lanes`` × lane width: 3.25 m per lane (the middle of the usual 3.0-3.5 m), 3.6 m
   (12 ft) in North America (US/Canada, recognised by coordinates) where the AASHTO
   standard lane is wider;
3. a default per ``highway`` type for a two-way street (:data:`DEFAULT_WIDTH_M`, including a
   typical parking strip for residential streets), scaled by 0.6 for one-way streets
   (a one-way street is usually a single lane plus parking), never under 3.0 m. In North
   America the defaults are scaled by :data:`NORTH_AMERICA_SCALE` (wider lanes, kerbside
   parking on both sides).

Narrow old-town streets in Europe are usually narrower than these defaults; that is
accepted (the corners then sit up to ~1-2 m too far from the centre line). Tag the
``width`` in OSM where it matters.
"""

from __future__ import annotations

import math
import re
from typing import Any

__all__ = [
    "DEFAULT_WIDTH_M",
    "LANE_WIDTH_M",
    "NORTH_AMERICA_LANE_WIDTH_M",
    "NORTH_AMERICA_SCALE",
    "in_north_america",
    "parse_lanes",
    "parse_width_m",
    "resolve_width_m",
]

LANE_WIDTH_M = 3.25
"""Lane width used with the ``lanes`` tag outside North America, metres."""

NORTH_AMERICA_LANE_WIDTH_M = 3.6
"""Lane width used with the ``lanes`` tag in the US and Canada (12 ft), metres."""

NORTH_AMERICA_SCALE = 1.2
"""Factor applied to :data:`DEFAULT_WIDTH_M` in the US and Canada."""

ONEWAY_SCALE = 0.6
MIN_WIDTH_M = 3.0

DEFAULT_WIDTH_M: dict[str, float] = {
    "motorway": 14.0,
    "trunk": 13.0,
    "primary": 11.0,
    "secondary": 10.0,
    "tertiary": 9.0,
    "unclassified": 7.0,
    "residential": 8.0,
    "living_street": 5.5,
    "service": 5.0,
    "motorway_link": 6.0,
    "trunk_link": 6.0,
    "primary_link": 6.0,
    "secondary_link": 6.0,
    "tertiary_link": 6.0,
    "road": 7.0,
    "busway": 7.0,
    "pedestrian": 6.0,
}
"""Default kerb-to-kerb width of a two-way carriageway per ``highway`` value, metres."""

_FALLBACK_WIDTH_M = 7.0
_NUMBER_RE = re.compile(r"[-+]?\d+(?:[.,]\d+)?")
_FEET_INCHES_RE = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*'\s*(?:(\d+(?:\.\d+)?)\s*\")?\s*$")


def _first(value: Any) -> Any:
    """osmnx merges tags of simplified edges into lists: take the first usable value."""
    if isinstance(value, (list, tuple)):
        for item in value:
            if item is not None and not (isinstance(item, float) and math.isnan(item)):
                return item
        return None
    if isinstance(value, float) and math.isnan(value):
        return None
    return value


def parse_width_m(value: Any, *, max_m: float = 100.0) -> float | None:
    """Parse an OSM ``width`` (or ``height``) value to metres, or None if absent or bad.

    Values outside (0.5, ``max_m``] are rejected as tagging errors.

    Examples
    --------
    >>> parse_width_m("7.5"), parse_width_m("7,5 m"), parse_width_m("24'"), parse_width_m("x")
    (7.5, 7.5, 7.3152, None)
    """
    value = _first(value)
    if value is None:
        return None
    if isinstance(value, (int, float)):
        width = float(value)
    else:
        text = str(value).strip().lower()
        feet = _FEET_INCHES_RE.match(text)
        if feet:
            width = float(feet.group(1)) * 0.3048 + float(feet.group(2) or 0.0) * 0.0254
        else:
            num = _NUMBER_RE.search(text)
            if not num:
                return None
            width = float(num.group(0).replace(",", "."))
            if "ft" in text or "feet" in text:
                width *= 0.3048
            elif "cm" in text:
                width /= 100.0
    if not math.isfinite(width) or width <= 0.5 or width > max_m:
        return None
    return round(width, 6)


def parse_lanes(value: Any) -> float | None:
    """Parse an OSM ``lanes`` value (``"2"``, ``"2;3"`` takes the first), or None."""
    value = _first(value)
    if value is None:
        return None
    num = _NUMBER_RE.search(str(value))
    if not num:
        return None
    lanes = float(num.group(0).replace(",", "."))
    return lanes if 0 < lanes < 20 else None


def in_north_america(lat: float, lon: float) -> bool:
    """Rough test for the US/Canada (where wider lane conventions apply)."""
    return 24.0 <= lat <= 72.0 and -170.0 <= lon <= -52.0


def resolve_width_m(
    *,
    width: Any,
    lanes: Any,
    highway: str,
    oneway: bool,
    north_america: bool = False,
) -> tuple[float, str]:
    """Carriageway width of one way and where it came from.

    Parameters
    ----------
    width, lanes
        The raw ``width`` and ``lanes`` tag values (or None).
    highway
        The ``highway`` value.
    oneway
        Whether the way is one-way (one carriageway of a dual road is one-way).
    north_america
        Use the US/Canada conventions.

    Returns
    -------
    width_m, source
        The width in metres and ``"width"``, ``"lanes"`` or ``"default"``.
    """
    tagged = parse_width_m(width)
    if tagged is not None:
        return tagged, "width"
    n_lanes = parse_lanes(lanes)
    if n_lanes is not None:
        lane_w = NORTH_AMERICA_LANE_WIDTH_M if north_america else LANE_WIDTH_M
        return max(MIN_WIDTH_M, n_lanes * lane_w), "lanes"
    base = DEFAULT_WIDTH_M.get(highway, _FALLBACK_WIDTH_M)
    if north_america:
        base *= NORTH_AMERICA_SCALE
    if oneway:
        base *= ONEWAY_SCALE
    return max(MIN_WIDTH_M, round(base, 6)), "default"
