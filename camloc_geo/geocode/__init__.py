"""Geocoding webcam titles: the junction, street, address or landmark a title names.

Example::

    from camloc_geo.osm import load_map
    from camloc_geo.geocode import geocode_title

    m = load_map("data/osm/baltimore.osm.pbf", 39.2826, -76.5685, radius_m=None)
    best = geocode_title("625 - Milton & E Biddle St", map_data=m)[0]
    best.status, best.names_matched, (best.lat, best.lon)

See :mod:`camloc_geo.geocode._parse` (reading titles), :mod:`camloc_geo.geocode._normalize`
(street-name normalisation) and :mod:`camloc_geo.geocode._geocode` (matching).
"""

from __future__ import annotations

from camloc_geo.geocode._geocode import (
    FUZZY_MIN_RATIO,
    STATUSES,
    NameHit,
    TitleMatch,
    geocode_title,
    match_name,
)
from camloc_geo.geocode._index import GeocodeIndex, index_for
from camloc_geo.geocode._maps import extract_paths, geocode_title_in_maps, whole_map
from camloc_geo.geocode._normalize import core_tokens, name_tokens
from camloc_geo.geocode._parse import ParsedTitle, parse_compass_words, parse_title

__all__ = [
    "FUZZY_MIN_RATIO",
    "STATUSES",
    "GeocodeIndex",
    "NameHit",
    "ParsedTitle",
    "TitleMatch",
    "core_tokens",
    "extract_paths",
    "geocode_title",
    "geocode_title_in_maps",
    "index_for",
    "match_name",
    "name_tokens",
    "parse_compass_words",
    "parse_title",
    "whole_map",
]
