"""The service's dependencies: its shared state, the API key, body parsing, the thread pool.

Bodies are parsed once: JSON with NaN/Infinity refused, a scene checked against the server's
limits and validated into a :class:`~camloc_geo.scene.Scene` that the library takes as it is.
The scene endpoints that only compute (``/v1/locate``, ``/v1/calibrate``, ``/v1/maps``) send
the body's bytes to the worker, which parses and validates it there (:class:`RawScene`).
CPU work runs in worker processes or threads (:mod:`camloc_geo.service.compute`) under the
request time limit, never on the event loop.
"""

from __future__ import annotations

import asyncio
import hmac
import json
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated, Any, TypeVar

from fastapi import Depends, Header, Request

from camloc_geo import SceneError
from camloc_geo.service.compute import Compute
from camloc_geo.service.errors import TimeLimitError, UnauthorizedError, UnsupportedMediaError
from camloc_geo.service.mapstore import MapStore
from camloc_geo.service.settings import Settings
from camloc_geo.service.store import Store
from camloc_geo.service.work import check_scene_body

if TYPE_CHECKING:
    from camloc_geo.scene import Scene

__all__ = [
    "ApiKey",
    "Maps",
    "RawScene",
    "SceneBody",
    "SceneBytes",
    "ServiceSettings",
    "ServiceStore",
    "Workers",
    "content_type",
    "parse_json",
    "raw_body",
    "run_cpu",
    "scene_from_raw",
]

T = TypeVar("T")

JSON_TYPES = ("application/json",)


# The dependencies are ``async def``: FastAPI runs a plain ``def`` dependency in a thread of
# anyio's pool, a thread hop (and GIL hand-over) per dependency per request for what is an
# attribute read; on the event loop they cost microseconds.


def _state(request: Request, name: str) -> Any:
    return getattr(request.app.state, name)


async def _settings(request: Request) -> Settings:
    settings: Settings = _state(request, "settings")
    return settings


async def _maps(request: Request) -> MapStore:
    maps: MapStore = _state(request, "maps")
    return maps


async def _store(request: Request) -> Store:
    store: Store = _state(request, "store")
    return store


async def _compute(request: Request) -> Compute:
    compute: Compute = _state(request, "compute")
    return compute


ServiceSettings = Annotated[Settings, Depends(_settings)]
Maps = Annotated[MapStore, Depends(_maps)]
ServiceStore = Annotated[Store, Depends(_store)]
Workers = Annotated[Compute, Depends(_compute)]
"""The CPU pool: ``await workers.run(fn, *args)`` runs ``fn(maps, *args)`` on a worker."""


async def _require_key(
    settings: ServiceSettings,
    x_api_key: Annotated[
        str | None, Header(description="the server's key, when it has one")
    ] = None,
) -> None:
    if settings.api_key is None:
        return
    expected = settings.api_key.get_secret_value().encode()
    if x_api_key is None or not hmac.compare_digest(x_api_key.encode(), expected):
        raise UnauthorizedError("missing or wrong X-API-Key", "X-API-Key")


ApiKey = Depends(_require_key)
"""Guards a write endpoint when ``CAMLOC_API_KEY`` is set (``dependencies=[ApiKey]``)."""


def content_type(request: Request) -> str:
    """The request's media type, lower case, without parameters."""
    return request.headers.get("content-type", "").split(";")[0].strip().lower()


def unsupported_media_message(ctype: str, kinds: tuple[str, ...]) -> str:
    """The 415's words: the content type given (or none at all) and what to send.

    A body with no ``Content-Type`` was "content type 'none' not supported here", and
    ``curl --data-binary @cams.csv`` (which sends ``application/x-www-form-urlencoded``) gave
    no hint of the header to add.
    """
    send = " or ".join(kinds)
    header = " or ".join(f"-H 'Content-Type: {k}'" for k in kinds)
    if not ctype:
        return f"the request has no Content-Type header; send {send} (curl: {header})"
    text = f"content type {ctype!r} not supported here; send {send}"
    if ctype == "application/x-www-form-urlencoded":
        text += f" (curl's --data and --data-binary send {ctype} unless given {header})"
    return text


async def raw_body(request: Request, kinds: tuple[str, ...]) -> bytes:
    """The body, when its content type is one of ``kinds``.

    Raises
    ------
    UnsupportedMediaError
        Another content type (HTTP 415).
    """
    ctype = content_type(request)
    if ctype not in kinds:
        raise UnsupportedMediaError(unsupported_media_message(ctype, kinds), "content-type")
    encoding = request.headers.get("content-encoding", "").strip().lower()
    if encoding not in ("", "identity"):  # a gzip body read as JSON: "can't decode byte 0x8b"
        raise UnsupportedMediaError(
            f"content encoding {encoding!r} not supported; send the body uncompressed",
            "content-encoding",
        )
    return await request.body()


def _reject_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number JSON allows")


def parse_json(raw: bytes) -> Any:
    """Parsed JSON; NaN, Infinity, bad UTF-8 and deep nesting are a :class:`SceneError`."""
    from camloc_geo._io import NotTextError, json_text

    try:
        # (a byte-order mark dropped, as from a file Notepad saved: "Unexpected UTF-8 BOM")
        return json.loads(json_text(raw), parse_constant=_reject_constant)
    except RecursionError:
        raise SceneError("the JSON body is nested too deeply", "body") from None
    except NotTextError as exc:
        raise SceneError(f"the body is not valid JSON: it is {exc}", "body") from None
    except ValueError as exc:
        raise SceneError(f"the body is not valid JSON: {exc}", "body") from None


@dataclass(frozen=True)
class ParsedScene:
    """A scene body: the JSON as sent (to store) and the validated model (to compute with)."""

    data: dict[str, Any]
    scene: Scene


async def _scene_body(request: Request, settings: ServiceSettings) -> ParsedScene:
    from camloc_geo.api import scene_from

    raw = await raw_body(request, JSON_TYPES)

    def parse() -> ParsedScene:  # up to 2 MB of JSON: off the event loop
        data = check_scene_body(parse_json(raw), settings)
        return ParsedScene(data=data, scene=scene_from(data))

    return await run_cpu(request, parse)


SceneBody = Annotated[ParsedScene, Depends(_scene_body)]
"""A ``camloc-scene/1`` body within the server's limits, validated once."""


@dataclass(frozen=True)
class RawScene:
    """A scene body as it came (JSON bytes), for a worker to parse and validate once.

    The serving process only checks the content type: the JSON parsing, the server's limits
    and the validation all happen on the worker (:func:`scene_from_raw`), so a request's
    scene is validated once, and one ``bytes`` object is what crosses to the worker
    process (not a model of thousands of small objects to pickle and unpickle).
    """

    raw: bytes


def scene_from_raw(raw: bytes, settings: Settings) -> Scene:
    """The validated scene of a raw JSON body, within the server's limits.

    Raises
    ------
    SceneError
        Not JSON, NaN/Infinity, not an object, ``image.path`` given, or not a valid scene.
    LimitError
        Too many annotators, lines or references.
    """
    from camloc_geo.api import scene_from

    return scene_from(check_scene_body(parse_json(raw), settings))


async def _raw_scene(request: Request) -> RawScene:
    return RawScene(await raw_body(request, JSON_TYPES))


SceneBytes = Annotated[RawScene, Depends(_raw_scene)]
"""A JSON body meant as a ``camloc-scene/1`` scene, not yet parsed (see :class:`RawScene`)."""


async def run_cpu(request: Request, fn: Callable[[], T]) -> T:
    """Run ``fn`` in the app's thread pool under the request time limit (work needing no map).

    Raises
    ------
    TimeLimitError
        ``fn`` took longer than ``CAMLOC_REQUEST_TIMEOUT_S`` (HTTP 503).
    """
    executor = _state(request, "compute").executor()
    limit_s = _state(request, "settings").request_timeout_s
    loop = asyncio.get_running_loop()
    try:
        return await asyncio.wait_for(loop.run_in_executor(executor, fn), timeout=limit_s)
    except asyncio.TimeoutError:
        raise TimeLimitError(f"processing took longer than {limit_s:g} s") from None
