"""The geocoder's names for the one street-name normaliser, :mod:`camloc_geo.osm._tokens`.

Names are normalised once, in the map layer (:func:`camloc_geo.osm.normalize_name` joins
:func:`name_tokens`); title geocoding reads the same tokens and the same abbreviation table.
"""

from __future__ import annotations

from camloc_geo.osm._tokens import (
    ARTICLES,
    DIRECTIONALS,
    STREET_TYPES,
    core_tokens,
    directionals_of,
    fold,
    name_tokens,
    types_of,
)

__all__ = [
    "ARTICLES",
    "DIRECTIONALS",
    "STREET_TYPES",
    "core_tokens",
    "directionals_of",
    "fold",
    "name_tokens",
    "types_of",
]
