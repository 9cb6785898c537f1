"""The HTTP service: ``create_app(settings)`` assembles the routers over the library API.

Routes live in :mod:`camloc_geo.service.routers` (one router per area), errors and their
status table in :mod:`camloc_geo.service.errors`, body parsing and the API key in
:mod:`camloc_geo.service.deps`. Nothing is built at import.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager

from fastapi import FastAPI
from fastapi.routing import APIRoute

from camloc_geo import __version__
from camloc_geo.service.compute import Compute
from camloc_geo.service.errors import ERROR_STATUS, install_error_handlers
from camloc_geo.service.fastpath import SceneFastPath
from camloc_geo.service.mapstore import MapStore
from camloc_geo.service.middleware import HeadAsGet, RequestLimits, VerdictCors
from camloc_geo.service.models import ERROR_RESPONSES
from camloc_geo.service.routers import ROUTERS
from camloc_geo.service.routers.jobs import JobRunner
from camloc_geo.service.routers.meta import install_docs
from camloc_geo.service.routers.scenes import FAST_ROUTES
from camloc_geo.service.settings import Settings
from camloc_geo.service.store import Store
from camloc_geo.service.verdicts import VerdictStore

__all__ = ["ERROR_STATUS", "create_app"]

DESCRIPTION = (
    "Find where a street camera stands from one snapshot. Map data comes from the server's "
    "configuration only. Errors: 4xx with `error.type`, `error.message` and `error.field` "
    "naming what is wrong."
)


def create_app(settings: Settings | None = None) -> FastAPI:
    """Build the service.

    Parameters
    ----------
    settings
        Configuration (default: from ``CAMLOC_*`` environment variables).
    """
    settings = settings or Settings()
    maps, store = MapStore(settings), Store(settings.data_dir)
    compute = Compute(settings, maps)
    runner = JobRunner(store, compute, settings)

    @asynccontextmanager
    async def lifespan(_app: FastAPI) -> AsyncIterator[None]:
        compute.start()
        runner.start()
        try:
            yield
        finally:
            runner.stop()
            compute.shutdown()

    app = FastAPI(
        title="camloc",
        version=__version__,
        description=DESCRIPTION,
        lifespan=lifespan,
        docs_url=None,
        redoc_url=None,
    )
    app.state.settings, app.state.maps, app.state.store = settings, maps, store
    app.state.compute = compute
    app.state.verdicts = VerdictStore(
        settings.verdict_dir or settings.data_dir, max_rows=settings.max_verdicts
    )
    for router in ROUTERS:
        app.include_router(router, responses=ERROR_RESPONSES)
    # every route's methods by path, for a 405's Allow (Starlette names the first route's only)
    app.state.route_methods = [
        (route.path_regex, frozenset(route.methods))
        for router in ROUTERS
        for route in router.routes
        if isinstance(route, APIRoute) and route.methods
    ]
    install_error_handlers(app)
    install_docs(app)
    # (the last added is the outermost: a request's id and body limit come first)
    app.add_middleware(SceneFastPath, compute=compute, settings=settings, routes=FAST_ROUTES)
    app.add_middleware(HeadAsGet)  # HEAD on every GET path (after the id and the limits)
    app.add_middleware(
        RequestLimits,
        max_bytes=settings.max_request_bytes,
        upload_paths=("/v1/tasks",),
        max_upload_bytes=settings.max_upload_bytes,
    )
    if settings.cors_origin_list:  # pages of other origins share verdicts (--verdict-url)
        app.add_middleware(VerdictCors, origins=settings.cors_origin_list)
    return app
