"""Map endpoints: intersections with their kerb corners, and streets, around a point."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Query, Request
from fastapi.responses import JSONResponse

from camloc_geo.service.deps import Maps, ServiceSettings, run_cpu
from camloc_geo.service.errors import QueryError
from camloc_geo.service.models import CornersQuery, PointQuery

__all__ = ["router"]

router = APIRouter(tags=["map"])


def _check_radius(q: PointQuery, settings: ServiceSettings) -> None:
    if q.radius_m > settings.max_radius_m:
        raise QueryError(
            f"radius_m {q.radius_m:g} is over this server's limit of {settings.max_radius_m:g} m",
            "radius_m",
        )


@router.get("/v1/corners")
async def corners(
    request: Request, q: Annotated[CornersQuery, Query()], maps: Maps, settings: ServiceSettings
) -> JSONResponse:
    """Intersections and their kerb corners around a point (GeoJSON)."""
    _check_radius(q, settings)

    def work() -> dict[str, Any]:
        from camloc_geo.api import corners_within

        m = maps.map_for_point(lat=q.lat, lon=q.lon)
        return corners_within(
            lat=q.lat, lon=q.lon, radius_m=q.radius_m, map_source=m, streets=q.streets
        )

    return JSONResponse(await run_cpu(request, work))


@router.get("/v1/streets")
async def streets(
    request: Request, q: Annotated[PointQuery, Query()], maps: Maps, settings: ServiceSettings
) -> JSONResponse:
    """Streets near a point with their bearings."""
    _check_radius(q, settings)

    def work() -> dict[str, Any]:
        from camloc_geo.api import streets_within

        m = maps.map_for_point(lat=q.lat, lon=q.lon)
        return streets_within(lat=q.lat, lon=q.lon, radius_m=q.radius_m, map_source=m)

    return JSONResponse(await run_cpu(request, work))
