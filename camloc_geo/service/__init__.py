"""camloc as an HTTP service (FastAPI): ``create_app(settings)`` and its settings.

Start it with ``camloc serve`` or any ASGI server::

    CAMLOC_WORKERS=2 uvicorn --factory camloc_geo.service:app_from_env

(``CAMLOC_WORKERS``: worker processes for the CPU work; 0, the default, computes in threads.)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fastapi import FastAPI

    from camloc_geo.service.settings import Settings

__all__ = ["Settings", "app_from_env", "create_app"]


def create_app(settings: Settings | None = None) -> FastAPI:
    """Build the service app (see :func:`camloc_geo.service.app.create_app`)."""
    from camloc_geo.service.app import create_app as _create

    return _create(settings)


def app_from_env() -> FastAPI:
    """The app configured from ``CAMLOC_*`` environment variables (a uvicorn factory)."""
    from camloc_geo.service.settings import Settings

    return create_app(Settings())


def __getattr__(name: str) -> Any:
    if name == "Settings":
        from camloc_geo.service.settings import Settings

        return Settings
    raise AttributeError(name)
