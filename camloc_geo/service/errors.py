"""The service's errors: one status table, and the handlers that answer with JSON.

Every error reaches the client as ``{"error": {"type", "message", "field"}, "request_id"}``.
Library errors and the service's own map to a status through :data:`ERROR_STATUS`; anything
else is a 500 logged with its request id, whose details never reach the client.
"""

from __future__ import annotations

import logging
from typing import Any

from fastapi import FastAPI, Request
from fastapi.responses import JSONResponse

from camloc_geo import (
    CamlocError,
    DegenerateGeometryError,
    InputError,
    MapDataError,
    MapSourceError,
    NotEnoughStructureError,
    SceneError,
)
from camloc_geo.service.work import LimitError

__all__ = [
    "ERROR_STATUS",
    "LimitError",
    "NotFoundError",
    "QueryError",
    "ServiceError",
    "TimeLimitError",
    "UnauthorizedError",
    "UnsupportedMediaError",
    "error_response",
    "error_response_for",
    "install_error_handlers",
]

log = logging.getLogger("camloc_geo.service")


class ServiceError(Exception):
    """An error of the HTTP layer itself (not of the library); ``field`` names the culprit."""

    def __init__(self, message: str, field: str | None = None) -> None:
        super().__init__(message)
        self.field = field


class UnsupportedMediaError(ServiceError):
    """The body's content type is not one this endpoint takes."""


class NotFoundError(ServiceError):
    """No job or task with this id."""


class UnauthorizedError(ServiceError):
    """The ``X-API-Key`` header is missing or wrong."""


class TimeLimitError(ServiceError):
    """Processing took longer than ``CAMLOC_REQUEST_TIMEOUT_S``."""


class QueryError(ServiceError):
    """A query parameter is outside what this server accepts."""


ERROR_STATUS: tuple[tuple[type[BaseException], int, str], ...] = (
    (UnauthorizedError, 401, "unauthorized"),
    (NotFoundError, 404, "not_found"),
    (UnsupportedMediaError, 415, "unsupported_media_type"),
    (TimeLimitError, 503, "time_limit"),
    (QueryError, 422, "invalid_input"),
    (LimitError, 413, "limit_exceeded"),
    (SceneError, 422, "invalid_scene"),
    (NotEnoughStructureError, 422, "not_enough_structure"),
    (DegenerateGeometryError, 422, "degenerate_geometry"),
    (MapDataError, 422, "map_data"),
    (InputError, 422, "invalid_input"),
    (MapSourceError, 503, "map_source_unavailable"),
)
"""Exception → HTTP status and error type; the first matching row wins."""


def request_id(request: Request) -> str:
    """The id the middleware gave this request (``-`` before it ran)."""
    return str(getattr(request.state, "request_id", "-"))


def error_response(
    status: int, kind: str, message: str, field: str | None, rid: str
) -> JSONResponse:
    """The JSON error answer."""
    body: dict[str, Any] = {"error": {"type": kind, "message": message}, "request_id": rid}
    if field:
        body["error"]["field"] = field
    return JSONResponse(body, status_code=status)


def error_response_for(exc: BaseException, rid: str) -> JSONResponse:
    """The answer to an exception: its row of :data:`ERROR_STATUS`, or a logged 500."""
    for cls, status, kind in ERROR_STATUS:
        if isinstance(exc, cls):
            if status >= 500:
                log.warning("request %s: %s", rid, exc)
            message = " ".join(str(exc).split())
            return error_response(status, kind, message, getattr(exc, "field", None), rid)
    log.error("request %s failed", rid, exc_info=exc)
    return error_response(500, "internal", f"internal error (request id {rid})", None, rid)


async def _known(request: Request, exc: Exception) -> JSONResponse:
    return error_response_for(exc, request_id(request))


async def _unexpected(request: Request, exc: Exception) -> JSONResponse:
    rid = request_id(request)
    log.error("request %s failed", rid, exc_info=exc)
    return error_response(500, "internal", f"internal error (request id {rid})", None, rid)


def install_error_handlers(app: FastAPI) -> None:
    """Answer library and service errors through :data:`ERROR_STATUS`, the rest with a 500."""
    app.add_exception_handler(CamlocError, _known)
    app.add_exception_handler(ServiceError, _known)
    app.add_exception_handler(Exception, _unexpected)
