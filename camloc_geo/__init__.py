"""camloc_geo: find where a street camera stands from one snapshot of it."""

from __future__ import annotations

from typing import TYPE_CHECKING

from camloc_geo._errors import (
    CamlocError,
    DegenerateGeometryError,
    InputError,
    MapDataError,
    MapSourceError,
    NotEnoughStructureError,
    SceneError,
)

if TYPE_CHECKING:  # the real signatures for type checkers; imported lazily at run time
    from camloc_geo.api import (
        calibrate_scene,
        corners_near,
        locate_scene,
        map_for_scene,
        streets_near,
    )

__version__ = "0.1.0"

_API = ("calibrate_scene", "corners_near", "locate_scene", "map_for_scene", "streets_near")


def __getattr__(name: str) -> object:
    """The API entry points, imported on first use (keeps ``import camloc_geo`` light)."""
    if name in _API:
        from camloc_geo import api

        return getattr(api, name)
    raise AttributeError(f"module 'camloc_geo' has no attribute {name!r}")


def __dir__() -> list[str]:
    """The module's names with the lazy entry points (tab completion in a notebook)."""
    return sorted(set(globals()) | set(_API))


__all__ = [
    "CamlocError",
    "DegenerateGeometryError",
    "InputError",
    "MapDataError",
    "MapSourceError",
    "NotEnoughStructureError",
    "SceneError",
    "__version__",
    "calibrate_scene",
    "corners_near",
    "locate_scene",
    "map_for_scene",
    "streets_near",
]
