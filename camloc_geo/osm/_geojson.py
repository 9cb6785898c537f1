"""GeoJSON / JSON views of intersections and streets (for the command line and tools)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from camloc_geo.osm._model import Intersection

if TYPE_CHECKING:
    from camloc_geo.osm._map import MapData

__all__ = ["intersections_geojson", "streets_json"]

ATTRIBUTION = "© OpenStreetMap contributors, ODbL 1.0"


def _street_props(inter: Intersection) -> list[dict[str, Any]]:
    return [
        {
            "name": s.name,
            "bearing_deg": round(s.bearing_deg, 3),
            "back_bearing_deg": round(s.back_bearing_deg, 3),
            "highway": s.highway,
            "oneway": s.oneway,
            "lanes": s.lanes,
            "width_m": round(s.width_m, 2),
            "width_source": s.width_source,
            "carriageways": s.carriageways,
        }
        for s in inter.streets
    ]


def intersections_geojson(intersections: Iterable[Intersection]) -> dict[str, Any]:
    """A FeatureCollection of intersections (``kind: "intersection"``) and their corners.

    Intersection properties: ``id``, ``streets`` (names, clockwise), ``kind_detail``
    (``junction``/``roundabout``/``unmodelled``), ``warnings``, ``incident_streets``
    (bearing, highway, width... per street), ``corner_distances_m``. Corner properties:
    ``intersection`` (the id), ``order`` (clockwise from above, from 0), ``streets`` (the
    two streets it lies between). Coordinates are ``[lon, lat]``.
    """
    features: list[dict[str, Any]] = []
    for inter in intersections:
        features.append(
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [inter.lon, inter.lat]},
                "properties": {
                    "kind": "intersection",
                    "id": inter.id,
                    "streets": list(inter.street_names),
                    "kind_detail": inter.kind,
                    "warnings": list(inter.warnings),
                    "incident_streets": _street_props(inter),
                    "corner_distances_m": [round(d, 3) for d in inter.corner_distances_m],
                    "osm_nodes": list(inter.osm_nodes),
                },
            }
        )
        for corner in inter.corners:
            features.append(
                {
                    "type": "Feature",
                    "geometry": {"type": "Point", "coordinates": [corner.lon, corner.lat]},
                    "properties": {
                        "kind": "corner",
                        "intersection": corner.intersection_id,
                        "order": corner.order,
                        "streets": list(corner.streets),
                    },
                }
            )
    return {"type": "FeatureCollection", "attribution": ATTRIBUTION, "features": features}


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
