"""GeoJSON / JSON views of intersections and streets (for the command line and tools)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from camloc_geo.osm._model import Intersection
from camloc_geo.results import ATTRIBUTION, corners_collection, to_json

if TYPE_CHECKING:
    from camloc_geo.osm._map import MapData

__all__ = ["intersections_geojson", "streets_json"]


def intersections_geojson(intersections: Iterable[Intersection]) -> dict[str, Any]:
    """A FeatureCollection of intersections (``kind: "intersection"``) and their corners.

    Intersection properties: ``id``, ``streets`` (names, clockwise), ``kind_detail``
    (``junction``/``roundabout``/``unmodelled``; also as ``intersection_kind``, the same
    value), ``warnings``, ``incident_streets`` (bearing, highway, width... per street),
    ``corner_distances_m``. Corner properties: ``intersection`` (the id), ``order``
    (clockwise from above, from 0), ``streets`` (the two streets it lies between).
    Coordinates are ``[lon, lat]``. The typed model is
    :class:`camloc_geo.results.CornersCollection`.
    """
    doc: dict[str, Any] = to_json(corners_collection(intersections))
    return doc


def streets_json(m: MapData, lat: float, lon: float, radius_m: float) -> dict[str, Any]:
    """Streets near a point with their bearings, and every street segment of the map."""
    near = [
        {"name": n, "bearing_deg": round(b, 3)} for n, b in m.street_bearings(lat, lon, radius_m)
    ]
    seen: dict[str, dict[str, Any]] = {}
    for s in m.streets:
        entry = seen.setdefault(
            s.name,
            {"name": s.name, "highway": s.highway, "oneway": s.oneway, "segments": 0, "ways": []},
        )
        entry["segments"] += 1
        entry["ways"] = sorted(set(entry["ways"]) | set(s.way_ids))
    return {
        "lat": lat,
        "lon": lon,
        "radius_m": radius_m,
        "near": near,
        "streets": sorted(seen.values(), key=lambda e: e["name"]),
        "attribution": ATTRIBUTION,
    }
