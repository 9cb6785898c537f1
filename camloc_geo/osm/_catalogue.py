"""Which map each camera uses: areas, and the maps loaded once per area and process.

An *area* is the unit of map loading and of work partitioning:

- ``("file", PATH)``: a whole extract (files up to :data:`WHOLE_EXTRACT_MAX_BYTES`), its map
  anchored at the centre of the extract's bounds, shared by every camera it covers;
- ``("cell", PATH, I, J)``: a square of :data:`CELL_M` metres of a larger extract, or
  ``("net", I, J)`` of Overpass (``network=True``), its map anchored at the cell's centre;
- ``("search", PATHS)``: cameras without a point, whose titles are searched in each extract;
- ``("none", REASON)``: no map can serve the camera (outside every extract, network off).

Maps are kept in a per-process dictionary (:func:`area_map`), so a worker parses an area's
extract once however many chunks of cameras it processes there. Areas are pure values: the
same camera gets the same area, and so the same map anchored at the same point, in every
process, which keeps local and Dask results identical.
"""

from __future__ import annotations

import logging
import math
import os
import threading
from collections import OrderedDict
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

from camloc_geo._errors import InputError, MapDataError

if TYPE_CHECKING:
    from camloc_geo.cameras._list import CameraRow
    from camloc_geo.osm import MapData

__all__ = ["CELL_M", "WHOLE_EXTRACT_MAX_BYTES", "Area", "MapPlan", "area_map", "map_plan"]

log = logging.getLogger(__name__)

WHOLE_EXTRACT_MAX_BYTES = 48 * 1024 * 1024
"""Extracts up to this size are loaded whole (one map for every camera they cover)."""

CELL_M = 2000.0
"""Side of the square cells larger extracts and Overpass are split into (metres)."""

_CELL_MARGIN_M = 400.0
_MAX_MAPS = 32

Area = tuple[Any, ...]


def _extract_files(source: Path) -> tuple[str, ...]:
    from camloc_geo.osm._load import EXTRACT_SUFFIXES

    if source.is_file():
        return (str(source.absolute()),)
    if source.is_dir():
        files = sorted(
            str(p.absolute())
            for p in source.iterdir()
            if p.is_file() and p.name.lower().endswith(EXTRACT_SUFFIXES)
        )
        if not files:
            raise MapDataError(
                f"no OSM extracts (.osm, .osm.pbf, .osm.gz, .osm.bz2) in the folder {source}"
            )
        return tuple(files)
    raise MapDataError(f"OSM extract or folder not found: {source}")


@lru_cache(maxsize=256)
def extract_bounds(path: str, mtime_ns: int = 0) -> tuple[float, float, float, float]:
    """``(south, west, north, east)`` of an extract: its header, else one scan of its nodes."""
    import osmium

    from camloc_geo.osm._load import _header_box

    box = _header_box(Path(path))
    if box is not None:
        return box
    s, w, n, e = math.inf, math.inf, -math.inf, -math.inf
    try:
        for node in osmium.FileProcessor(path, osmium.osm.NODE):
            loc = node.location  # type: ignore[union-attr]
            if loc.valid():
                s, n = min(s, loc.lat), max(n, loc.lat)
                w, e = min(w, loc.lon), max(e, loc.lon)
    except (RuntimeError, OSError, ValueError) as exc:
        raise MapDataError(f"cannot read OSM extract {Path(path).name}: {exc}") from exc
    if not math.isfinite(s):
        raise MapDataError(f"OSM extract {Path(path).name} holds no located nodes")
    return s, w, n, e


def _bounds(path: str) -> tuple[float, float, float, float]:
    try:
        mtime = os.stat(path).st_mtime_ns
    except OSError:
        mtime = 0
    return extract_bounds(path, mtime)


def _cell_of(lat: float, lon: float) -> tuple[int, int]:
    dlat = CELL_M / 111_320.0
    return math.floor(lat / dlat), math.floor(lon / dlat)


def _cell_centre(i: int, j: int) -> tuple[float, float]:
    dlat = CELL_M / 111_320.0
    return (i + 0.5) * dlat, (j + 0.5) * dlat


@dataclass(frozen=True)
class MapPlan:
    """Where maps come from for a batch: extract files, or Overpass, or nothing."""

    files: tuple[str, ...] = ()
    network: bool = False
    area_filter: str | None = None

    def _whole(self, path: str) -> bool:
        try:
            return os.path.getsize(path) <= WHOLE_EXTRACT_MAX_BYTES
        except OSError:
            return True

    def _named(self, name: str | None) -> tuple[str, ...]:
        if not name:
            return self.files
        key = name.strip().lower()
        return tuple(f for f in self.files if key in Path(f).name.lower())

    def area_of(self, row: CameraRow) -> Area:
        """The area a camera belongs to (a pure function of the row and the plan)."""
        if row.has_point:
            assert row.lat is not None
            assert row.lon is not None
            if self.files:
                covering = []
                for f in self._named(row.area) or self.files:
                    try:
                        s, w, n, e = _bounds(f)
                    except MapDataError as exc:
                        log.warning("%s", exc)
                        continue
                    if s <= row.lat <= n and w <= row.lon <= e:
                        covering.append(((n - s) * (e - w), f))
                if not covering:
                    names = ", ".join(Path(f).name for f in self.files[:5])
                    more = " ..." if len(self.files) > 5 else ""
                    return (
                        "none",
                        f"lat={row.lat:.6f}, lon={row.lon:.6f} is outside every extract "
                        f"({names}{more})",
                    )
                f = min(covering)[1]  # the smallest extract covering the point
                if self._whole(f):
                    return ("file", f)
                return ("cell", f, *_cell_of(row.lat, row.lon))
            if self.network:
                return ("net", *_cell_of(row.lat, row.lon))
            return ("none", "no map: give --osm EXTRACT_OR_FOLDER or allow --network")
        if not self.files:
            return (
                "none",
                "no point to load the map around (no lat/lon) and no extract to search the "
                "title in: give --osm EXTRACT_OR_FOLDER",
            )
        name = row.area or self.area_filter
        files = self._named(name)
        if not files:
            return ("none", f"no extract's name contains the area {name!r}")
        big = [f for f in files if not self._whole(f)]
        if big and len(big) == len(files):
            return (
                "none",
                "no point given and the extract is too large to search whole: give lat/lon",
            )
        files = tuple(f for f in files if self._whole(f))
        if len(files) == 1:
            return ("file", files[0])
        return ("search", files)


def map_plan(
    map_source: str | os.PathLike[str] | None, *, network: bool = False, area: str | None = None
) -> MapPlan:
    """The :class:`MapPlan` of an extract, a folder of extracts, or the network.

    Raises
    ------
    MapDataError
        The extract or folder does not exist or holds no extract.
    """
    if map_source is None:
        return MapPlan(network=bool(network), area_filter=area)
    files = _extract_files(Path(map_source).expanduser())
    if area and not any(area.strip().lower() in Path(f).name.lower() for f in files):
        raise InputError(f"--area {area!r}: no extract's name contains it")
    return MapPlan(files=files, network=False, area_filter=area)


_MAPS: OrderedDict[Area, Any] = OrderedDict()
_MAPS_LOCK = threading.Lock()
_LOAD_LOCKS: dict[Area, threading.Lock] = {}


def area_map(area: Area) -> MapData:
    """The map of an area, loaded once per process (thread-safe).

    Raises
    ------
    MapDataError, MapSourceError
        The extract is unreadable or Overpass failed.
    """
    with _MAPS_LOCK:
        if area in _MAPS:
            _MAPS.move_to_end(area)
            return _MAPS[area]
        lock = _LOAD_LOCKS.setdefault(area, threading.Lock())
    with lock:
        with _MAPS_LOCK:
            if area in _MAPS:
                return _MAPS[area]
        m = _load_area(area)
        with _MAPS_LOCK:
            _MAPS[area] = m
            while len(_MAPS) > _MAX_MAPS:
                _MAPS.popitem(last=False)
        return m


def _load_area(area: Area) -> MapData:
    from camloc_geo.osm import load_map

    kind = area[0]
    radius = CELL_M * math.sqrt(0.5) + _CELL_MARGIN_M
    if kind == "file":
        s, w, n, e = _bounds(area[1])
        return load_map(area[1], (s + n) / 2.0, (w + e) / 2.0, radius_m=None)
    if kind == "cell":
        lat, lon = _cell_centre(area[2], area[3])
        return load_map(area[1], lat, lon, radius_m=radius)
    if kind == "net":
        lat, lon = _cell_centre(area[1], area[2])
        return load_map(None, lat, lon, radius_m=radius)
    raise MapDataError(f"no map for area {area[0]!r}")


def clear_maps() -> None:
    """Forget the maps of this process."""
    with _MAPS_LOCK:
        _MAPS.clear()
