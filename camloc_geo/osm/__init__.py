"""The OpenStreetMap layer: streets, intersection kerb corners and buildings around a point.

>>> from camloc_geo.osm import load_map                      # doctest: +SKIP
>>> m = load_map("sample_maps/baltimore.osm.pbf", 39.2851, -76.5934, radius_m=200)
>>> x = m.find_intersection("Eastern Ave & S Broadway")
>>> [(c.order, c.streets) for c in x.corners], x.corner_distances_m

See :mod:`camloc_geo.osm._intersections` for how intersections and corners are modelled
and :mod:`camloc_geo.osm._widths` for carriageway widths.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from camloc_geo.osm._catalogue import (
    CELL_M,
    WHOLE_EXTRACT_MAX_BYTES,
    Area,
    MapCatalogue,
    MapCatalogueSource,
    MapPlan,
    area_map,
    extract_bounds,
    extract_files,
    map_loads,
    map_plan,
)

if TYPE_CHECKING:
    from camloc_geo.osm._intersections import (
        ARM_SAMPLE_M,
        MAX_CORNER_GAP_DEG,
        MIN_CORNER_GAP_DEG,
    )
    from camloc_geo.osm._load import EXTRACT_SUFFIXES, STREET_HIGHWAYS, clear_cache, header_box
    from camloc_geo.osm._map import DEFAULT_TOLERANCE_M, MapData, load_map
    from camloc_geo.osm._model import Building, Corner, IncidentStreet, Intersection, Street
    from camloc_geo.osm._names import normalize_name
    from camloc_geo.osm._widths import resolve_width_m

__all__ = [
    "ARM_SAMPLE_M",
    "CELL_M",
    "DEFAULT_TOLERANCE_M",
    "EXTRACT_SUFFIXES",
    "MAX_CORNER_GAP_DEG",
    "MIN_CORNER_GAP_DEG",
    "STREET_HIGHWAYS",
    "WHOLE_EXTRACT_MAX_BYTES",
    "Area",
    "Building",
    "Corner",
    "IncidentStreet",
    "Intersection",
    "MapCatalogue",
    "MapCatalogueSource",
    "MapData",
    "MapPlan",
    "Street",
    "area_map",
    "clear_cache",
    "extract_bounds",
    "extract_files",
    "header_box",
    "load_map",
    "map_loads",
    "map_plan",
    "normalize_name",
    "resolve_width_m",
]


_LAZY = {
    "ARM_SAMPLE_M": "_intersections",
    "MAX_CORNER_GAP_DEG": "_intersections",
    "MIN_CORNER_GAP_DEG": "_intersections",
    "EXTRACT_SUFFIXES": "_load",
    "STREET_HIGHWAYS": "_load",
    "clear_cache": "_load",
    "header_box": "_load",
    "DEFAULT_TOLERANCE_M": "_map",
    "MapData": "_map",
    "load_map": "_map",
    "Building": "_model",
    "Corner": "_model",
    "IncidentStreet": "_model",
    "Intersection": "_model",
    "Street": "_model",
    "normalize_name": "_names",
    "resolve_width_m": "_widths",
}
"""Names imported on first use (osmium, networkx and scipy load only when a map does)."""


def __getattr__(name: str) -> Any:
    """The map layer's names, imported on first use.

    ``intersections_geojson`` and ``streets_json`` are output shapes: they live in
    :mod:`camloc_geo.results` (the map layer never imports it).
    """
    import importlib

    if name in _LAZY:
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
