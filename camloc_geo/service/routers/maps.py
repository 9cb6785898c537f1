"""Map endpoints: intersections with their kerb corners, and streets, around a point."""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Any

from fastapi import APIRouter, Query
from fastapi.responses import Response

from camloc_geo.service.deps import ServiceSettings, Workers
from camloc_geo.service.errors import QueryError
from camloc_geo.service.models import CornersQuery, PointQuery

if TYPE_CHECKING:
    from camloc_geo.service.mapstore import MapStore

__all__ = ["router"]

router = APIRouter(tags=["map"])


def _check_radius(q: PointQuery, settings: ServiceSettings) -> None:
    if q.radius_m > settings.max_radius_m:
        raise QueryError(
            f"radius_m {q.radius_m:g} is over this server's limit of {settings.max_radius_m:g} m",
            "radius_m",
        )


def corners_work(maps: MapStore, q: CornersQuery) -> dict[str, Any]:
    """Corners around the query's point (runs on a worker)."""
    from camloc_geo.api import corners_within

    m = maps.map_for_point(lat=q.lat, lon=q.lon)
    return corners_within(
        lat=q.lat, lon=q.lon, radius_m=q.radius_m, map_source=m, streets=q.streets
    )


def streets_work(maps: MapStore, q: PointQuery) -> dict[str, Any]:
    """Streets around the query's point (runs on a worker)."""
    from camloc_geo.api import streets_within

    m = maps.map_for_point(lat=q.lat, lon=q.lon)
    return streets_within(lat=q.lat, lon=q.lon, radius_m=q.radius_m, map_source=m)


@router.get("/v1/corners", response_model=dict[str, Any])
async def corners(
    q: Annotated[CornersQuery, Query()], workers: Workers, settings: ServiceSettings
) -> Response:
    """Intersections and their kerb corners around a point (GeoJSON)."""
    _check_radius(q, settings)
    return await workers.run_json(corners_work, q)


@router.get("/v1/streets", response_model=dict[str, Any])
async def streets(
    q: Annotated[PointQuery, Query()], workers: Workers, settings: ServiceSettings
) -> Response:
    """Streets near a point with their bearings."""
    _check_radius(q, settings)
    return await workers.run_json(streets_work, q)
