"""camloc_geo: find where a street camera stands from one snapshot of it."""

from __future__ import annotations

from camloc_geo._errors import (
    CamlocError,
    DegenerateGeometryError,
    InputError,
    MapDataError,
    MapSourceError,
    NotEnoughStructureError,
    SceneError,
)

__version__ = "0.1.0"

__all__ = [
    "CamlocError",
    "DegenerateGeometryError",
    "InputError",
    "MapDataError",
    "MapSourceError",
    "NotEnoughStructureError",
    "SceneError",
    "__version__",
]
