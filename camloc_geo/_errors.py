"""Exceptions raised by camloc_geo.

Every error caused by the caller's input subclasses :class:`InputError`, itself a
``ValueError``: the command line maps those to exit status 2 with a one-line message.
Anything else is a failure of ours or of the environment (exit status 1).
"""

from __future__ import annotations

__all__ = [
    "CamlocError",
    "DegenerateGeometryError",
    "InputError",
    "MapDataError",
    "MapSourceError",
    "NotEnoughStructureError",
    "SceneError",
]


class CamlocError(Exception):
    """Base class of every error camloc_geo raises on purpose."""


class InputError(CamlocError, ValueError):
    """The caller's input is wrong; the message names what is wrong."""


class SceneError(InputError):
    """A scene file or scene object breaks the contract of ``camloc-scene/1``.

    Parameters
    ----------
    message
        What is wrong.
    field
        Dotted path of the offending field (``annotations[0].axes.origin``), if known.
    """

    def __init__(self, message: str, field: str | None = None) -> None:
        self.field = field
        super().__init__(f"{field}: {message}" if field else message)


class DegenerateGeometryError(InputError):
    """The geometry cannot determine what is asked (parallel lines, collinear axes...)."""


class NotEnoughStructureError(InputError):
    """An image or an annotation set has too little structure to answer confidently."""


class MapDataError(InputError):
    """Map data is missing, unreadable, or does not contain what was asked for."""


class MapSourceError(CamlocError, RuntimeError):
    """A map source (Overpass server, network) failed; not the caller's fault."""
