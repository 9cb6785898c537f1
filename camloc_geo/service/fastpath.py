"""The scene endpoints' ordinary requests, answered without FastAPI's routing and dependencies.

``POST /v1/locate`` and ``POST /v1/calibrate`` are the service's hot path: the serving
process only has to hand the body's bytes to a worker and send the JSON bytes it returns.
Through FastAPI that costs more CPU than the parsing itself: matching the route, solving
five dependencies (the API key, the settings, the body, the pool, the query model) and
validating a query model, per request (1.2 ms of the serving process's 1.8 ms, measured).

This plain ASGI layer answers a request whose every part is plainly in order — the exact
path, ``Content-Type: application/json``, the right ``X-API-Key`` (when the server has one),
and no ``max_candidates`` or one plain integer in its range — with the same worker call and
the same bytes as the FastAPI route. Anything else (a wrong key, another content type, an odd
query) goes on to FastAPI unchanged, so every refusal is the FastAPI route's own answer; the
routes stay declared there, and ``/openapi.json`` is the same.
"""

from __future__ import annotations

import hmac
import logging
from collections.abc import Callable
from typing import Any
from urllib.parse import parse_qsl

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from camloc_geo.service.compute import Compute
from camloc_geo.service.errors import error_response_for
from camloc_geo.service.settings import Settings

__all__ = ["SceneFastPath", "WorkCall", "max_candidates_of"]

WorkCall = Callable[[bytes, "int | None"], tuple[Callable[..., Any], tuple[Any, ...]]]
"""``(raw body, max_candidates) -> (fn, args)``: an endpoint's call on a worker."""

log = logging.getLogger(__name__)

MAX_CANDIDATES = (1, 100)
"""``max_candidates``'s range (as :class:`~camloc_geo.service.models.LocateQuery` has it)."""


def max_candidates_of(query_string: bytes) -> tuple[bool, int | None]:
    """``(plain, value)`` of a ``/v1/locate`` query string.

    ``plain`` is False when FastAPI should judge it: ``max_candidates`` given twice, or not
    a plain decimal integer within :data:`MAX_CANDIDATES`. Other parameters are ignored, as
    FastAPI ignores them.
    """
    if not query_string:
        return True, None
    try:
        pairs = parse_qsl(query_string.decode("latin-1"), keep_blank_values=True)
    except ValueError:
        return False, None
    values = [v for k, v in pairs if k == "max_candidates"]
    if not values:
        return True, None
    if len(values) > 1 or not values[0].isascii() or not values[0].isdigit():
        return False, None
    n = int(values[0])
    lo, hi = MAX_CANDIDATES
    return (True, n) if lo <= n <= hi else (False, None)


class SceneFastPath:
    """ASGI middleware: the plain requests of the scene endpoints, straight to the workers.

    Parameters
    ----------
    app
        The FastAPI app (gets every request this layer does not answer).
    compute
        The service's CPU pool.
    settings
        The server's settings (its API key).
    routes
        ``path -> work(raw body, max_candidates) -> (fn, args)``: the worker call of each
        endpoint (:data:`camloc_geo.service.routers.scenes.FAST_ROUTES`).
    """

    def __init__(
        self,
        app: ASGIApp,
        *,
        compute: Compute,
        settings: Settings,
        routes: dict[str, WorkCall],
    ) -> None:
        self.app, self.compute, self.routes = app, compute, routes
        key = settings.api_key
        self.key = None if key is None else key.get_secret_value().encode()

    def _key_ok(self, key: bytes | None) -> bool:
        if self.key is None:
            return True
        # the header as the FastAPI route compares it: decoded Latin-1, encoded UTF-8
        return key is not None and hmac.compare_digest(key.decode("latin-1").encode(), self.key)

    def _plain(self, scope: Scope) -> tuple[bool, int | None]:
        content_type = key = None  # the first of each, as Starlette's headers give them
        for name, value in scope["headers"]:
            if name == b"content-type" and content_type is None:
                content_type = value
            elif name == b"x-api-key" and key is None:
                key = value
            elif name == b"content-encoding" and value.strip().lower() not in (b"", b"identity"):
                return False, None  # refused by the route (415), in its words
        if content_type is None:
            return False, None
        if content_type.split(b";", 1)[0].strip().lower() != b"application/json":
            return False, None
        if not self._key_ok(key):
            return False, None
        if scope["path"] == "/v1/locate":
            return max_candidates_of(scope.get("query_string", b""))
        return True, None

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        route = self.routes.get(scope["path"]) if scope["type"] == "http" else None
        if route is None or scope["method"] != "POST":
            await self.app(scope, receive, send)
            return
        plain, max_candidates = self._plain(scope)
        if not plain:
            await self.app(scope, receive, send)
            return
        try:
            chunks: list[bytes] = []
            while True:
                message: Message = await receive()
                if message["type"] == "http.disconnect":
                    return
                chunks.append(message.get("body", b""))
                if not message.get("more_body", False):
                    break
            fn, args = route(b"".join(chunks), max_candidates)
            body: bytes = await self.compute.run_bytes(fn, *args)
        except Exception as exc:  # the same answer as the FastAPI route's error handlers
            rid = str(scope.get("state", {}).get("request_id", "-"))
            await error_response_for(exc, rid)(scope, receive, send)
            return
        await send(
            {
                "type": "http.response.start",
                "status": 200,
                "headers": [
                    (b"content-length", str(len(body)).encode()),
                    (b"content-type", b"application/json"),
                ],
            }
        )
        await send({"type": "http.response.body", "body": body})
