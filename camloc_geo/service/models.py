"""Pydantic models of the service's requests (query parameters and the job list body).

Scene bodies are the library's :class:`~camloc_geo.scene.Scene` (``camloc-scene/1``).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from fastapi import Path
from pydantic import BaseModel, Field

__all__ = [
    "ERROR_RESPONSES",
    "HTML_ROUTE_ERRORS",
    "CornersQuery",
    "ErrorBody",
    "ErrorDetail",
    "JobId",
    "JobList",
    "LocateQuery",
    "PointQuery",
    "ResultQuery",
    "TaskId",
    "TaskQuery",
]

_ID = r"^[0-9a-f]{32}$"

JobId = Annotated[str, Path(pattern=_ID, description="job id (32 hex digits)")]
TaskId = Annotated[str, Path(pattern=_ID, description="task id (32 hex digits)")]

Lat = Annotated[float, Field(ge=-90.0, le=90.0, description="latitude, degrees WGS 84")]
Lon = Annotated[float, Field(ge=-180.0, le=180.0, description="longitude, degrees WGS 84")]


class PointQuery(BaseModel):
    """A point and a search radius (``/v1/streets``); the radius is capped by the server."""

    lat: Lat
    lon: Lon
    radius_m: float = Field(
        default=150.0, gt=0.0, description="search radius, metres (at most CAMLOC_MAX_RADIUS_M)"
    )


class CornersQuery(PointQuery):
    """``/v1/corners``: a point, a radius, and optionally the two streets that meet."""

    streets: str | None = Field(
        default=None, max_length=200, description='"A & B": only where they meet'
    )


class LocateQuery(BaseModel):
    """``/v1/locate``."""

    max_candidates: int | None = Field(default=None, ge=1, le=100)


class ResultQuery(BaseModel):
    """``/v1/jobs/{id}/result``."""

    format: Literal["geojson", "gpkg"] = "geojson"


class TaskQuery(BaseModel):
    """``POST /v1/tasks``: how many annotations to collect, and the rough point if known."""

    annotations: int | None = Field(default=None, ge=1, le=50)
    lat: float | None = Field(default=None, ge=-90.0, le=90.0)
    lon: float | None = Field(default=None, ge=-180.0, le=180.0)
    radius_m: float = Field(default=150.0, gt=0.0, le=5_000.0)


class JobList(BaseModel):
    """A webcam list as JSON: ``{"cameras": [{"id", "title", "lat", "lon", "radius_m",
    "scene"}, ...]}``. A camera that is not an object fails alone, in the job's result."""

    cameras: list[Any]


class ErrorDetail(BaseModel):
    """What went wrong: ``type`` (``docs/service.md``), a one-line ``message``, the culprit."""

    type: str = Field(description="invalid_scene, map_data, invalid_input, not_found...")
    message: str
    field: str | None = Field(default=None, description="the field, parameter or header")


class ErrorBody(BaseModel):
    """Every error answer of the service."""

    error: ErrorDetail
    request_id: str = Field(description="also in the X-Request-ID header and the server's log")


ERROR_RESPONSES: dict[int | str, dict[str, Any]] = {
    401: {"model": ErrorBody, "description": "missing or wrong X-API-Key (CAMLOC_API_KEY)"},
    404: {"model": ErrorBody, "description": "no such job, task or path"},
    413: {"model": ErrorBody, "description": "a body or upload over the server's limits"},
    415: {"model": ErrorBody, "description": "a content type this endpoint does not take"},
    503: {"model": ErrorBody, "description": "Overpass unreachable, or the time limit"},
}
"""The error answers every route may give, declared in ``/openapi.json`` (before, only 422
was, and client generators and schema checkers saw 401/404/413/415/503 as undocumented)."""

HTML_ROUTE_ERRORS: dict[int | str, dict[str, Any]] = {
    code: {
        "description": spec["description"],
        "content": {"application/json": {"schema": {"$ref": "#/components/schemas/ErrorBody"}}},
    }
    for code, spec in ERROR_RESPONSES.items()
}
""":data:`ERROR_RESPONSES` for a route whose answer is HTML: FastAPI would declare a model's
error under the route's ``text/html``; the errors are JSON."""
