"""The camera-list engine: reading a list, and placing each camera from its evidence.

A list (CSV or GeoJSON, :func:`read_camera_list`) gives per camera an id, a title, optionally
a rough point, a street pair and a scene. :func:`geocode_camera` places one camera: its
title's junction, its prior, its located scene, on the map its point falls in
(:class:`camloc_geo.osm.MapCatalogue`). The result (:class:`CameraResult`) says ``status``
in one vocabulary (``docs/contract.md``). ``camloc batch``, the service's jobs and QGIS's
``camloc:geocodelist`` are calls to it; nothing per camera is computed anywhere else.
"""

from __future__ import annotations

from camloc_geo.cameras._camera import (
    PLACED_STATUSES,
    RETRY_STATUSES,
    STATUS_ALIASES,
    STATUSES,
    CameraResult,
    geocode_camera,
    normalize_status,
)
from camloc_geo.cameras._list import (
    COLUMN_VARIANTS,
    CameraRow,
    binary_list_kind,
    parse_coordinate,
    read_camera_csv,
    read_camera_list,
    row_from_mapping,
)

__all__ = [
    "COLUMN_VARIANTS",
    "PLACED_STATUSES",
    "RETRY_STATUSES",
    "STATUSES",
    "STATUS_ALIASES",
    "CameraResult",
    "CameraRow",
    "binary_list_kind",
    "geocode_camera",
    "normalize_status",
    "parse_coordinate",
    "read_camera_csv",
    "read_camera_list",
    "row_from_mapping",
]
