"""The service's middleware (plain ASGI): a request id, the body size limits, and CORS for
the verdict endpoints when ``CAMLOC_CORS_ORIGINS`` names origins.

Plain ASGI rather than ``@app.middleware("http")``: no extra task and no response copy per
request. A body over its limit is refused from ``Content-Length`` before it is read, and a
body without one is cut off while it streams in.
"""

from __future__ import annotations

import json
import uuid
from typing import Any

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from camloc_geo.service.work import LimitError

__all__ = ["HeadAsGet", "RequestLimits", "VerdictCors"]


class HeadAsGet:
    """``HEAD`` answered as ``GET`` without its body, on every path that takes ``GET``.

    FastAPI's routes take only the methods they name: ``curl -I``, link checkers and
    uptime probes got a 405 from every page (``/v1/jobs/{id}/map``, ``/docs``,
    ``/v1/verdicts``...) but ``/healthz``. The headers (``Content-Length`` included) are
    the ``GET``'s, as HTTP asks.

    Parameters
    ----------
    app
        The wrapped ASGI app.
    """

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or scope["method"] != "HEAD":
            await self.app(scope, receive, send)
            return

        async def headers_only(message: Message) -> None:
            if message["type"] == "http.response.body":
                if not message.get("more_body", False):
                    await send({"type": "http.response.body", "body": b""})
                return
            await send(message)

        await self.app({**scope, "method": "GET"}, receive, headers_only)


class VerdictCors:
    """CORS for the verdict endpoints only, for the configured origins only.

    A review page written by ``camloc locate --map ... --verdict-url`` (opened from a file:
    origin ``null``, or from another web server) reads and changes its verdicts here; every
    other path answers as without CORS. A preflight from another origin is refused (400),
    and the answers to its requests carry no ``Access-Control-Allow-Origin``.

    Parameters
    ----------
    app
        The wrapped ASGI app.
    origins
        The allowed origins (``https://host[:port]``, or ``null``).
    paths
        The path prefixes CORS applies to.
    """

    def __init__(
        self, app: ASGIApp, *, origins: list[str], paths: tuple[str, ...] = ("/v1/verdicts",)
    ) -> None:
        from starlette.middleware.cors import CORSMiddleware

        self.app = app
        self.paths = paths
        self.cors = CORSMiddleware(
            app,
            allow_origins=list(origins),
            allow_methods=["GET", "POST"],
            allow_headers=["Content-Type", "X-API-Key"],
            expose_headers=["X-Request-ID"],
            max_age=600,
        )

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        path = scope.get("path", "") if scope["type"] == "http" else ""
        if any(path == p or path.startswith(p + "/") for p in self.paths):
            await self.cors(scope, receive, send)
        else:
            await self.app(scope, receive, send)


class RequestLimits:
    """Give every request an id (``X-Request-ID``) and refuse bodies over their limit.

    Parameters
    ----------
    app
        The wrapped ASGI app.
    max_bytes
        Largest body (bytes).
    upload_paths, max_upload_bytes
        Paths that take uploads, and their larger limit.
    """

    def __init__(
        self,
        app: ASGIApp,
        *,
        max_bytes: int,
        upload_paths: tuple[str, ...] = (),
        max_upload_bytes: int = 0,
    ) -> None:
        self.app = app
        self.max_bytes = max_bytes
        self.upload_paths = upload_paths
        self.max_upload_bytes = max_upload_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        rid = uuid.uuid4().hex[:16]
        scope.setdefault("state", {})["request_id"] = rid
        header = (b"x-request-id", rid.encode())
        limit = self.max_upload_bytes if scope["path"] in self.upload_paths else self.max_bytes
        length = dict(scope["headers"]).get(b"content-length")
        if length is not None:
            try:
                too_big = int(length) > limit
            except ValueError:
                await _answer(send, 400, "bad_request", "invalid Content-Length header", None, rid)
                return
            if too_big:
                msg = f"request body over {limit} bytes"
                await _answer(send, 413, "limit_exceeded", msg, "body", rid)
                return

        received = 0

        async def counted() -> Message:
            nonlocal received
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > limit:
                    raise LimitError(f"request body over {limit} bytes", "body")
            return message

        async def send_with_id(message: Message) -> None:
            if message["type"] == "http.response.start":
                message["headers"] = [*message.get("headers", []), header]
            await send(message)

        await self.app(scope, counted, send_with_id)


async def _answer(
    send: Send, status: int, kind: str, message: str, field: str | None, rid: str
) -> None:
    error: dict[str, Any] = {"type": kind, "message": message}
    if field:
        error["field"] = field
    body = json.dumps({"error": error, "request_id": rid}).encode()
    await send(
        {
            "type": "http.response.start",
            "status": status,
            "headers": [
                (b"content-type", b"application/json"),
                (b"content-length", str(len(body)).encode()),
                (b"x-request-id", rid.encode()),
            ],
        }
    )
    await send({"type": "http.response.body", "body": body})
