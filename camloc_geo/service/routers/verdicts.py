"""Verdict endpoints: reviewers of one page share their verdicts through the service.

Open like the annotation pages' submissions (a reviewer's browser has no API key): the
pages served by the service post here; see docs/service.md, "Verdicts".
"""

from __future__ import annotations

from datetime import datetime, timezone
from typing import Annotated, Any

from fastapi import APIRouter, Depends, Query, Request

from camloc_geo.service.models import VerdictIdentity, VerdictPage, VerdictPost
from camloc_geo.service.verdicts import VerdictStore

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
    return {"pages": store.pages(limit)}


@router.get(VERDICTS_PATH + "/{page}/{identity}")
async def page_verdicts(
    page: VerdictPage, identity: VerdictIdentity, store: Verdicts
) -> dict[str, Any]:
    """A page's verdicts (none yet: an empty ``items``)."""
    return store.page(page, identity)


@router.post(VERDICTS_PATH + "/{page}/{identity}")
async def post_verdicts(
    page: VerdictPage, identity: VerdictIdentity, body: VerdictPost, store: Verdicts
) -> dict[str, Any]:
    """Add or change verdicts on a page: each item replaces the stored one of its key unless
    that one is newer. Answers the page's verdicts after the change and the keys taken."""
    now = datetime.now(timezone.utc)
    items = {key: item.stored(now) for key, item in body.items.items()}
    doc, taken = store.merge(page, identity, items)
    return {**doc, "taken": taken}
