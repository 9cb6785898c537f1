"""Health, and the API's description: ``/openapi.json`` with the scene schema, and ``/docs``
and ``/redoc`` whose assets are served by the server itself (they work offline).

Swagger UI and ReDoc come from the ``fastapi-offline`` package; without it the pages fall back
to FastAPI's (which load their assets from a CDN).
"""

from __future__ import annotations

import logging
from importlib import resources
from pathlib import Path
from typing import Any

from fastapi import APIRouter, FastAPI, Request
from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html
from fastapi.openapi.utils import get_openapi
from fastapi.responses import HTMLResponse, Response
from fastapi.staticfiles import StaticFiles

from camloc_geo import __version__
from camloc_geo.service.deps import Maps

__all__ = ["install_docs", "router"]

log = logging.getLogger(__name__)

router = APIRouter(tags=["meta"])

ASSETS = "/docs/assets"
REDOC_JS = "/docs/redoc.js"
"""ReDoc's script as served (:func:`_redoc_bundle`): outside the static mount."""

REDOC_CSP = "img-src 'self' data: blob:"
"""The ``/redoc`` page's Content-Security-Policy: images from the server only."""

FAVICON_SVG = (
    b'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 16 16">'
    b'<circle cx="8" cy="8" r="7" fill="#1f6feb"/><circle cx="8" cy="8" r="3" fill="#fff"/>'
    b"</svg>"
)
"""The service's icon (a lens), at ``/favicon.ico``: browsers ask for it on every served page
and logged a 404 in the console without it."""


@router.get("/healthz")
async def healthz(maps: Maps) -> dict[str, Any]:
    """Liveness: the version and how many extracts are configured."""
    return {"status": "ok", "version": __version__, "extracts": len(maps.extracts)}


@router.get("/favicon.ico", include_in_schema=False)
async def favicon() -> Response:
    """A tiny SVG icon, so a browser's console stays clean on the served pages."""
    return Response(
        FAVICON_SVG, media_type="image/svg+xml", headers={"Cache-Control": "public, max-age=86400"}
    )


_INDEX_HTML = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>camloc service {version}</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<link rel="icon" href="/favicon.ico">
<style>body {{ font: 15px/1.5 sans-serif; margin: 2em auto; max-width: 40em; padding: 0 1em; }}
</style></head><body>
<h1>camloc service {version}</h1>
<p>Finds where a street camera stands from one snapshot. This address serves an HTTP API:</p>
<ul>
<li><a href="/docs">/docs</a>: the API, to try in the browser (Swagger UI)</li>
<li><a href="/redoc">/redoc</a>: the API, to read (ReDoc)</li>
<li><a href="/openapi.json">/openapi.json</a>: the API's description, for clients</li>
<li><a href="/healthz">/healthz</a>: health, the version and the extracts configured</li>
<li><a href="/v1/verdicts">/v1/verdicts</a>: the pages reviewers gave verdicts on</li>
</ul></body></html>
"""


@router.get("/", include_in_schema=False, response_class=HTMLResponse)
async def index() -> HTMLResponse:
    """The service's address opened in a browser: what it is and where its API is described
    (it was a 404 "Not Found" JSON)."""
    return HTMLResponse(_INDEX_HTML.format(version=__version__))


@router.head("/healthz", include_in_schema=False)
async def healthz_head(maps: Maps) -> dict[str, Any]:
    """``HEAD /healthz`` (``curl -I``, load balancers' probes) answers as ``GET`` without a
    body; it was a 405."""
    return await healthz(maps)


REDOC_LOGO = b"https://cdn.redoc.ly/redoc/logo-mini.svg"
"""Where ReDoc's bundle draws its maker's logo from (no option turns it off)."""


def _redoc_bundle(path: Path) -> bytes:
    """ReDoc's script with its logo taken from this server (the service's icon): the offline
    ``/redoc`` page made one request to another site, cdn.redoc.ly, which failed offline
    (a console error) and told that site who reads the docs."""
    return path.read_bytes().replace(REDOC_LOGO, b"/favicon.ico")


def _assets_dir() -> Path | None:
    try:
        folder = Path(str(resources.files("fastapi_offline") / "static"))
    except ModuleNotFoundError:
        return None
    return folder if (folder / "swagger-ui-bundle.js").is_file() else None


def _scene_schemas() -> dict[str, Any]:
    from camloc_geo.scene import Scene

    schema = Scene.model_json_schema(ref_template="#/components/schemas/{model}")
    defs = schema.pop("$defs", {})
    schema.get("properties", {}).pop("base_dir", None)
    defs["Scene"] = schema
    return dict(defs)


def install_docs(app: FastAPI) -> None:
    """``/openapi.json`` (built once, with the ``Scene`` schema), ``/docs`` and ``/redoc``.

    Build the app with ``docs_url=None, redoc_url=None``.
    """

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            schema = get_openapi(
                title=app.title, version=app.version, description=app.description, routes=app.routes
            )
            schema.setdefault("components", {}).setdefault("schemas", {}).update(_scene_schemas())
            app.openapi_schema = schema
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
    folder = _assets_dir()
    if folder is None:
        log.warning("fastapi-offline is not installed: /docs loads Swagger UI from a CDN")
        swagger: dict[str, Any] = {}
        redoc: dict[str, Any] = {}
    else:
        app.mount(ASSETS, StaticFiles(directory=folder), name="docs-assets")
        swagger = {
            "swagger_js_url": f"{ASSETS}/swagger-ui-bundle.js",
            "swagger_css_url": f"{ASSETS}/swagger-ui.css",
            "swagger_favicon_url": f"{ASSETS}/favicon.png",
        }
        redoc = {
            "redoc_js_url": REDOC_JS,
            "redoc_favicon_url": f"{ASSETS}/favicon.png",
            "with_google_fonts": False,
        }

    async def docs(request: Request) -> HTMLResponse:
        return get_swagger_ui_html(
            openapi_url="/openapi.json", title=f"{app.title} - API", **swagger
        )

    async def redoc_page(request: Request) -> HTMLResponse:
        page = get_redoc_html(openapi_url="/openapi.json", title=f"{app.title} - API", **redoc)
        if folder is not None:  # images from this server only (see _redoc_bundle)
            page.headers["Content-Security-Policy"] = REDOC_CSP
        return page

    bundle: list[bytes] = []

    async def redoc_js() -> Response:
        if folder is None:
            return Response(status_code=404)
        if not bundle:
            bundle.append(_redoc_bundle(folder / "redoc.standalone.js"))
        return Response(
            bundle[0],
            media_type="text/javascript; charset=utf-8",
            headers={"Cache-Control": "public, max-age=86400"},
        )

    app.add_api_route(REDOC_JS, redoc_js, include_in_schema=False)

    app.add_api_route("/docs", docs, include_in_schema=False)
    app.add_api_route("/redoc", redoc_page, include_in_schema=False)
