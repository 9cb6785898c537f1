"""Pydantic models of the service's requests (query parameters and the job list body).

Scene bodies are the library's :class:`~camloc_geo.scene.Scene` (``camloc-scene/1``).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from fastapi import Path
from pydantic import BaseModel, Field

__all__ = [
    "CornersQuery",
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
