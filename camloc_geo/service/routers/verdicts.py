"""Verdict endpoints: reviewers of one page share their verdicts through the service.

Reads are open; with ``CAMLOC_API_KEY`` set, a change (``POST``) needs ``X-API-Key`` like the
other write endpoints (the served pages ask the reviewer for it once, on the first 401): the
pages served by the service post here; see docs/service.md, "Verdicts".
"""

from __future__ import annotations

from datetime import datetime, timezone
from typing import Annotated, Any

from fastapi import APIRouter, Depends, Query, Request
from fastapi.responses import JSONResponse, Response
from starlette.concurrency import run_in_threadpool

from camloc_geo.service.deps import ApiKey, content_type, unsupported_media_message
from camloc_geo.service.errors import UnsupportedMediaError
from camloc_geo.service.models import VerdictIdentity, VerdictPage, VerdictPost, VerdictsQuery
from camloc_geo.service.verdicts import VerdictStore, export_csv, export_geojson

__all__ = ["VERDICTS_PATH", "router"]

VERDICTS_PATH = "/v1/verdicts"
"""Where a page served by the service sends its verdicts (``<path>/<page>/<identity>``)."""

router = APIRouter(tags=["verdicts"])


async def _verdicts(request: Request) -> VerdictStore:
    store: VerdictStore = request.app.state.verdicts
    return store


Verdicts = Annotated[VerdictStore, Depends(_verdicts)]


@router.get(VERDICTS_PATH)
async def list_pages(
    store: Verdicts,
    limit: Annotated[int, Query(ge=1, le=10_000, description="at most this many pages")] = 1000,
) -> dict[str, Any]:
    """The pages that have verdicts, latest change first."""
    return {"pages": await run_in_threadpool(store.pages, limit)}


_EXPORT_DOC: dict[int | str, dict[str, Any]] = {
    200: {
        "description": "the page's verdicts (format=json), or its export (csv, geojson)",
        "content": {
            "application/json": {},
            "text/csv": {"schema": {"type": "string"}},
            "application/geo+json": {},
        },
    }
}


@router.get(VERDICTS_PATH + "/{page}/{identity}", response_model=None, responses=_EXPORT_DOC)
async def page_verdicts(
    page: VerdictPage,
    identity: VerdictIdentity,
    store: Verdicts,
    q: Annotated[VerdictsQuery, Query()],
) -> Response:
    """A page's verdicts (none yet: an empty ``items``); ``format=csv`` or ``geojson``: the
    export the page itself writes, which ``camloc summary-map --verdicts`` and ``camloc
    locate --map ... --verdicts`` read."""
    doc = await run_in_threadpool(store.page, page, identity)
    if q.format == "json":
        return JSONResponse(doc)
    name = f"verdicts-{page}-{identity[:8]}"
    if q.format == "csv":
        return Response(
            export_csv(doc),
            media_type="text/csv; charset=utf-8",
            headers={"Content-Disposition": f'attachment; filename="{name}.csv"'},
        )
    return JSONResponse(
        export_geojson(doc),
        media_type="application/geo+json",
        headers={"Content-Disposition": f'attachment; filename="{name}.geojson"'},
    )


async def _json_body(request: Request) -> None:
    """A verdicts post is JSON: another content type is a 415 naming it, as for the other
    write endpoints (a CSV body was a 422 "Input should be a valid dictionary")."""
    ctype = content_type(request)
    if ctype != "application/json" and not ctype.endswith("+json"):
        raise UnsupportedMediaError(
            unsupported_media_message(ctype, ("application/json",)), "content-type"
        )


@router.post(VERDICTS_PATH + "/{page}/{identity}", dependencies=[ApiKey, Depends(_json_body)])
async def post_verdicts(
    page: VerdictPage, identity: VerdictIdentity, body: VerdictPost, store: Verdicts
) -> dict[str, Any]:
    """Add or change verdicts on a page: each item replaces the stored one of its key unless
    that one is newer. Answers the page's verdicts after the change, the keys taken, and
    ``warnings``: one per item taken with a verdict but no ``camera`` (kept; an export row
    without a camera cannot be matched to one, so ``--verdicts`` leaves it out).
    With ``CAMLOC_API_KEY`` set: ``X-API-Key`` is needed (401 without it)."""
    now = datetime.now(timezone.utc)
    items = {key: item.stored(now) for key, item in body.items.items()}
    # (in the thread pool: SQLite may wait up to 30 s for another process's lock, which
    # blocked every other request of the event loop)
    doc, taken = await run_in_threadpool(store.merge, page, identity, items)
    return {**doc, "taken": taken, "warnings": no_camera_warnings(items, taken)}


def no_camera_warnings(items: dict[str, dict[str, Any]], taken: list[str]) -> list[str]:
    """One line per taken item that has a verdict but no ``camera``, naming its key.

    Such an item was taken without a word, and ``camloc summary-map --verdicts`` then failed
    on the whole export ("no camera id"); the export is read without it now, and the poster
    is told here.
    """
    out = []
    for key in taken:
        it = items[key]
        if it.get("verdict") is not None and not str(it.get("camera") or "").strip():
            out.append(
                f"item {key!r}: no camera: kept, but the export's row of it names no camera, "
                "so --verdicts leaves it out (send 'camera', the camera's id on the page)"
            )
    return out
