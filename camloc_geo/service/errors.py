"""The service's errors: one status table, and the handlers that answer with JSON.

Every error reaches the client as ``{"error": {"type", "message", "field"}, "request_id"}``.
Library errors and the service's own map to a status through :data:`ERROR_STATUS`; anything
else is a 500 logged with its request id, whose details never reach the client.
"""

from __future__ import annotations

import logging
import math
from typing import Any

from fastapi import FastAPI, Request
from fastapi.encoders import jsonable_encoder
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException

from camloc_geo import (
    CamlocError,
    DegenerateGeometryError,
    InputError,
    MapDataError,
    MapSourceError,
    NotEnoughStructureError,
    SceneError,
)
from camloc_geo.service.verdicts import VerdictStoreError
from camloc_geo.service.work import LimitError, server_words

__all__ = [
    "ERROR_STATUS",
    "LimitError",
    "NotFoundError",
    "QueryError",
    "ServiceError",
    "TimeLimitError",
    "UnauthorizedError",
    "UnsupportedMediaError",
    "WorkerLostError",
    "error_body",
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


class WorkerLostError(ServiceError):
    """The worker process computing the request stopped (killed, out of memory); the
    server starts another: the same request may be sent again."""


ERROR_STATUS: tuple[tuple[type[BaseException], int, str], ...] = (
    (UnauthorizedError, 401, "unauthorized"),
    (NotFoundError, 404, "not_found"),
    (UnsupportedMediaError, 415, "unsupported_media_type"),
    (TimeLimitError, 503, "time_limit"),
    (WorkerLostError, 503, "worker_lost"),
    (QueryError, 422, "invalid_input"),
    (LimitError, 413, "limit_exceeded"),
    (SceneError, 422, "invalid_scene"),
    (NotEnoughStructureError, 422, "not_enough_structure"),
    (DegenerateGeometryError, 422, "degenerate_geometry"),
    (MapDataError, 422, "map_data"),
    (InputError, 422, "invalid_input"),
    (MapSourceError, 503, "map_source_unavailable"),
    (VerdictStoreError, 503, "verdicts_unavailable"),
)
"""Exception → HTTP status and error type; the first matching row wins."""


def request_id(request: Request) -> str:
    """The id the middleware gave this request (``-`` before it ran)."""
    return str(getattr(request.state, "request_id", "-"))


def error_body(kind: str, message: str, field: str | None, rid: str) -> dict[str, Any]:
    """``{"error": {"type", "message", "field"?}, "request_id"}``."""
    body: dict[str, Any] = {"error": {"type": kind, "message": message}, "request_id": rid}
    if field:
        body["error"]["field"] = field
    return body


def error_response(
    status: int, kind: str, message: str, field: str | None, rid: str
) -> JSONResponse:
    """The JSON error answer."""
    return JSONResponse(error_body(kind, message, field, rid), status_code=status)


def error_response_for(exc: BaseException, rid: str) -> JSONResponse:
    """The answer to an exception: its row of :data:`ERROR_STATUS`, or a logged 500."""
    for cls, status, kind in ERROR_STATUS:
        if isinstance(exc, cls):
            if status >= 500:
                log.warning("request %s: %s", rid, exc)
            message = server_words(" ".join(str(exc).split()))
            return error_response(status, kind, message, getattr(exc, "field", None), rid)
    log.error("request %s failed", rid, exc_info=exc)
    return error_response(500, "internal", f"internal error (request id {rid})", None, rid)


async def _known(request: Request, exc: Exception) -> JSONResponse:
    return error_response_for(exc, request_id(request))


async def _unexpected(request: Request, exc: Exception) -> JSONResponse:
    rid = request_id(request)
    log.error("request %s failed", rid, exc_info=exc)
    return error_response(500, "internal", f"internal error (request id {rid})", None, rid)


_ID_WORDS = {
    r"^[0-9a-f]{32}$": (
        "an id of this service (32 hex digits, 0-9 and a-f, as the POST that made it answered)"
    ),
    r"^[0-9a-f]{16}$": "a page identity (16 hex digits, 0-9 and a-f, as the review page shows it)",
    r"^c?[0-9]{1,6}$": (
        "a key of the page's items: a candidate's rank on a review page ('1', '2', ...) or "
        "'c' and a camera's index on a summary page ('c0', 'c1', ...), as its export gives them"
    ),
}
"""What the service's id patterns mean, for a refused path value (stop 41, qa3)."""


_ECHO_CHARS = 80
"""Longest input quoted back in a validation message (a 200-character query value was
quoted whole, twice)."""


def _validation_message(errors: list[dict[str, Any]]) -> tuple[str, str | None]:
    """One line for FastAPI's validation errors (``lat: Input should be ... (got 95)``) and
    the field of the first."""
    parts = []
    field = None
    for err in errors:
        if err.get("type") == "json_invalid":  # the body is no JSON: its loc is a position
            field = field or "body"
            ctx = err.get("ctx") or {}
            why = f": {ctx['error']}" if isinstance(ctx, dict) and ctx.get("error") else ""
            parts.append(f"body: the body is not valid JSON{why}")
            continue
        loc = [str(x) for x in err.get("loc", ()) if x not in ("query", "path", "body", "header")]
        name = ".".join(loc) or "request"
        field = field or name
        got = err.get("input")
        if isinstance(got, str) and len(got) > _ECHO_CHARS:
            got = got[:_ECHO_CHARS] + "..."
        got_text = f" (got {got!r})" if isinstance(got, (str, int, float)) else ""
        pattern = (
            (err.get("ctx") or {}).get("pattern") if isinstance(err.get("ctx"), dict) else None
        )
        if err.get("type") == "string_pattern_mismatch" and pattern in _ID_WORDS:
            # "String should match pattern '^[0-9a-f]{32}$'" named a regular expression
            if loc and loc[-1] == "[key]":  # a mapping's key: "items.x.[key]" named it twice
                name = ".".join(loc[:-2]) or name  # (the field stays as it was)
            parts.append(f"{name}: {got!r} is not {_ID_WORDS[pattern]}")
            continue
        msg = str(err.get("msg", "invalid"))
        if err.get("type") == "value_error":
            # our own validators' words ("give two street names, as "A & B" (got 'X')"):
            # pydantic's "Value error, " prefix dropped, and the value not quoted twice
            msg = msg.removeprefix("Value error, ")
            if "(got " in msg:
                got_text = ""
        parts.append(f"{name}: {msg}{got_text}")
    return "; ".join(parts) or "invalid request", field


def _json_safe(value: Any) -> Any:
    """``value`` as JSON can carry it: a lone surrogate (``"\\ud800"`` in a JSON body) and a
    NaN or infinity (``NaN`` is read by FastAPI's JSON parser) echoed back in a validation
    error's ``input`` made the answer fail to encode, a 500 instead of the 422. Strings are
    made valid UTF-8 (``?`` for a surrogate), such numbers their text (``"nan"``)."""
    if isinstance(value, str):
        return value.encode("utf-8", "replace").decode("utf-8")
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, list):
        return [_json_safe(v) for v in value]
    if isinstance(value, dict):
        return {_json_safe(k): _json_safe(v) for k, v in value.items()}
    return value


_HTTP_KINDS = {404: "not_found", 405: "method_not_allowed", 401: "unauthorized"}


async def _invalid_request(request: Request, exc: Exception) -> JSONResponse:
    """A query or path value FastAPI refused: the service's error shape, FastAPI's ``detail``
    kept alongside for clients that read it (before, only ``{"detail": [...]}``)."""
    errors = _json_safe(jsonable_encoder(getattr(exc, "errors", list)()))
    message, field = _validation_message(errors)
    body = error_body("invalid_input", message, field, request_id(request))
    body["detail"] = errors
    return JSONResponse(body, status_code=422)


async def _http_error(request: Request, exc: Exception) -> JSONResponse:
    """Starlette's 404 (no such path), 405 (wrong method) and the like, in the service's
    shape, ``detail`` kept."""
    status = int(getattr(exc, "status_code", 500))
    detail = getattr(exc, "detail", None)
    if status == 400 and detail == "There was an error parsing the body":
        # FastAPI's answer to a JSON body that is no text (a GeoPackage, UTF-16 without a
        # mark): bad input, 422 naming the body, as every other body the service refuses
        body = error_body(
            "invalid_input",
            "body: the body is not valid JSON (not UTF-8 text)",
            "body",
            request_id(request),
        )
        body["detail"] = detail
        return JSONResponse(body, status_code=422)
    kind = _HTTP_KINDS.get(status, "http_error")
    message = str(detail) if detail else kind.replace("_", " ")
    body = error_body(kind, message, None, request_id(request))
    body["detail"] = detail
    headers = dict(getattr(exc, "headers", None) or {})
    if status == 405:
        allowed = allowed_methods(request.app, request.scope.get("path", ""))
        if allowed:
            # (Starlette names the first matching route's methods only: OPTIONS or PUT on
            # /v1/verdicts/{page}/{identity} said "Allow: GET", though it takes POST)
            headers["Allow"] = ", ".join(allowed)
            body["error"]["message"] = f"method {request.method} not allowed here; allowed: " + (
                ", ".join(allowed)
            )
    return JSONResponse(body, status_code=status, headers=headers or None)


_METHOD_ORDER = ("GET", "HEAD", "POST", "PUT", "PATCH", "DELETE", "OPTIONS")


def allowed_methods(app: FastAPI, path: str) -> list[str]:
    """The methods some route of ``app`` takes at ``path`` (every route, not the first).

    Parameters
    ----------
    app
        The service; its routes are read from ``app.state.route_methods``, a list of
        ``(path regex, methods)`` that :func:`camloc_geo.service.app.create_app` sets.
    path
        The request's path.

    Returns
    -------
    list of str
        The methods in the usual order (``GET, HEAD, POST, ...``); empty when no route matches.
    """
    methods: set[str] = set()
    for regex, route_methods in getattr(app.state, "route_methods", ()):
        if regex.match(path):
            methods |= set(route_methods)
    if "GET" in methods:  # (HeadAsGet answers HEAD wherever GET is taken)
        methods.add("HEAD")
    known = [m for m in _METHOD_ORDER if m in methods]
    return known + sorted(methods - set(known))


def install_error_handlers(app: FastAPI) -> None:
    """Answer library and service errors through :data:`ERROR_STATUS`, the rest with a 500;
    FastAPI's own refusals (validation, unknown path, wrong method) in the same shape."""
    app.add_exception_handler(CamlocError, _known)
    app.add_exception_handler(ServiceError, _known)
    app.add_exception_handler(RequestValidationError, _invalid_request)
    app.add_exception_handler(StarletteHTTPException, _http_error)
    app.add_exception_handler(Exception, _unexpected)
