"""Pydantic models of the service's requests (query parameters and the job list body).

Scene bodies are the library's :class:`~camloc_geo.scene.Scene` (``camloc-scene/1``).
"""

from __future__ import annotations

from datetime import datetime, timedelta, timezone
from typing import Annotated, Any, Literal

from fastapi import Path
from pydantic import BaseModel, ConfigDict, Field, StringConstraints, field_validator

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
    "VerdictIdentity",
    "VerdictItem",
    "VerdictPage",
    "VerdictPost",
    "VerdictsQuery",
    "utc_text",
]

_ID = r"^[0-9a-f]{32}$"

JobId = Annotated[str, Path(pattern=_ID, description="job id (32 hex digits)")]
TaskId = Annotated[str, Path(pattern=_ID, description="task id (32 hex digits)")]

VerdictPage = Annotated[
    Literal["candidates", "summary"],
    Path(description="the page's kind: candidates (a review page) or summary"),
]
VerdictIdentity = Annotated[
    str,
    Path(
        pattern=r"^[0-9a-f]{16}$",
        description="the page's identity (16 hex digits, in its exports and localStorage key)",
    ),
]
VERDICT_KEY = r"^c?[0-9]{1,6}$"
"""A candidate's key on its page: its rank (review page) or ``c<index>`` (summary page)."""
MAX_VERDICTS_PER_POST = 10_000
"""Most items in one ``POST /v1/verdicts/...`` (a summary page has one per camera)."""
_FUTURE_SLACK = timedelta(minutes=5)

# allow_inf_nan=False: lat=nan was refused "should be less than or equal to 90"; it now says
# it is not a finite number
Lat = Annotated[
    float, Field(ge=-90.0, le=90.0, allow_inf_nan=False, description="latitude, degrees WGS 84")
]
Lon = Annotated[
    float,
    Field(ge=-180.0, le=180.0, allow_inf_nan=False, description="longitude, degrees WGS 84"),
]


class PointQuery(BaseModel):
    """A point and a search radius (``/v1/streets``); the radius is capped by the server."""

    lat: Lat
    lon: Lon
    radius_m: float = Field(
        default=150.0,
        gt=0.0,
        allow_inf_nan=False,
        description="search radius, metres (at most CAMLOC_MAX_RADIUS_M)",
    )


class CornersQuery(PointQuery):
    """``/v1/corners``: a point, a radius, and optionally the two streets that meet."""

    streets: str | None = Field(
        default=None, max_length=200, description='"A & B": only where they meet'
    )

    @field_validator("streets")
    @classmethod
    def _two_streets(cls, value: str | None) -> str | None:
        """Fewer than two names is the query's fault: 422 ``invalid_input`` naming
        ``streets`` (it was ``map_data`` with no field, as if the map were wrong)."""
        from camloc_geo.osm._names import split_street_query

        if value is not None and value.strip():
            names = [n for n in split_street_query(value) if n]
            if len(names) < 2:
                raise ValueError(f'give two street names, as "A & B" (got {value!r})')
        return value


class LocateQuery(BaseModel):
    """``/v1/locate``."""

    max_candidates: int | None = Field(default=None, ge=1, le=100)


class ResultQuery(BaseModel):
    """``/v1/jobs/{id}/result``."""

    format: Literal["geojson", "gpkg"] = "geojson"


class TaskQuery(BaseModel):
    """``POST /v1/tasks``: how many annotations to collect, and the rough point if known."""

    annotations: int | None = Field(default=None, ge=1, le=50)
    lat: float | None = Field(default=None, ge=-90.0, le=90.0, allow_inf_nan=False)
    lon: float | None = Field(default=None, ge=-180.0, le=180.0, allow_inf_nan=False)
    radius_m: float = Field(default=150.0, gt=0.0, le=5_000.0, allow_inf_nan=False)


class JobList(BaseModel):
    """A webcam list as JSON: ``{"cameras": [{"id", "title", "lat", "lon", "radius_m",
    "scene"}, ...]}``. A camera that is not an object fails alone, in the job's result."""

    cameras: list[Any]


def utc_text(when: datetime) -> str:
    """``2026-11-25T01:10:00.000Z``: the pages' form of a time (UTC, milliseconds), which
    sorts as text. A time without a zone is taken as UTC.

    Raises
    ------
    ValueError
        A time that cannot be told in UTC (year 1 with a zone east of Greenwich).
    """
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    try:
        utc = when.astimezone(timezone.utc)
    except OverflowError:
        raise ValueError("the time is out of range") from None
    return utc.isoformat(timespec="milliseconds").replace("+00:00", "Z")


def _encodable(text: str) -> str:
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raise ValueError("the text is not valid Unicode (a lone surrogate)") from None
    return text


class VerdictItem(BaseModel):
    """One reviewer's verdict on one candidate (or camera): as a page keeps it."""

    model_config = ConfigDict(extra="forbid")

    verdict: Literal["yes", "no", "unsure"] | None = Field(
        default=None, description="yes (this is the camera / confirm), no, unsure; null: withdrawn"
    )
    rank: int | None = Field(
        default=None, ge=1, le=100_000, description="summary page: the candidate picked"
    )
    note: str = Field(default="", max_length=200, description="the reviewer's note")
    reviewer: str = Field(default="", max_length=80, description="the reviewer's name")
    camera: str = Field(default="", max_length=300, description="the camera's id on the page")
    lat: float | None = Field(
        default=None, ge=-90.0, le=90.0, allow_inf_nan=False, description="the chosen candidate"
    )
    lon: float | None = Field(
        default=None, ge=-180.0, le=180.0, allow_inf_nan=False, description="its longitude"
    )
    time: datetime | None = Field(
        default=None,
        description="when it was given (ISO 8601; default: now); the latest wins",
    )

    @field_validator("note", "reviewer", "camera")
    @classmethod
    def _text(cls, value: str) -> str:
        return _encodable(value)

    def stored(self, now: datetime) -> dict[str, Any]:
        """The row to store: ``time`` as :func:`utc_text`, a future one (past a few minutes
        of clock slack) taken as ``now``."""
        when = self.time or now
        if when.tzinfo is None:
            when = when.replace(tzinfo=timezone.utc)
        text = utc_text(when)
        if text > utc_text(now + _FUTURE_SLACK):
            text = utc_text(now)
        return {
            "verdict": self.verdict,
            "rank": self.rank,
            "note": self.note,
            "reviewer": self.reviewer,
            "time": text,
            "camera": self.camera,
            "lat": self.lat,
            "lon": self.lon,
        }


class VerdictPost(BaseModel):
    """``POST /v1/verdicts/{page}/{identity}``: ``{"items": {key: verdict}}``."""

    model_config = ConfigDict(extra="forbid")

    items: dict[Annotated[str, StringConstraints(pattern=VERDICT_KEY)], VerdictItem] = Field(
        max_length=MAX_VERDICTS_PER_POST,
        description='key: the candidate\'s rank ("3", review page) or "c<index>" (summary page)',
    )


class VerdictsQuery(BaseModel):
    """``GET /v1/verdicts/{page}/{identity}``: as JSON (the page's items), or as the page's
    own export (CSV or GeoJSON, read by ``camloc_geo.maps.read_verdicts``)."""

    format: Literal["json", "csv", "geojson"] = "json"


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
