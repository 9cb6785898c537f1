"""Geocode camera lists in batch: ``read_camera_list``, ``geocode_camera``, ``run_batch``.

A list (CSV or GeoJSON) gives per camera an id, a title, optionally a rough point, a street
pair and a scene file. Each camera is placed on the map of its area (loaded once per area
and process) from its title's junction and, when it has one, its located scene; results go
to a resumable journal and then to a GeoPackage (``cameras``, ``candidates``,
``view_cones``, ``errors``) and an optional summary map. See ``docs/batch.md``.
"""

from __future__ import annotations

from camloc_geo.batch._journal import journal_path
from camloc_geo.batch._run import BatchSummary, results_from_journal, run_batch
from camloc_geo.cameras import (
    COLUMN_VARIANTS,
    PLACED_STATUSES,
    CameraResult,
    CameraRow,
    geocode_camera,
    read_camera_csv,
    read_camera_list,
    row_from_mapping,
)

__all__ = [
    "COLUMN_VARIANTS",
    "PLACED_STATUSES",
    "BatchSummary",
    "CameraResult",
    "CameraRow",
    "geocode_camera",
    "journal_path",
    "read_camera_csv",
    "read_camera_list",
    "results_from_journal",
    "row_from_mapping",
    "run_batch",
]
