"""The map catalogue: which map serves a point, for every front end.

A :class:`MapCatalogue` knows where maps come from: extract files (one file or a folder,
each extract's bounds read once, from its header box or one scan of its nodes, and kept in an
index the catalogue asks per point, rebuilt when the extracts' folder changes), Overpass
through osmnx and its cache (``network=True``), or nothing. One rule chooses the map for a
point (:meth:`MapCatalogue.area_for_point`):

- the smallest extract whose bounds cover the point;
  - an extract up to :data:`WHOLE_EXTRACT_MAX_BYTES` is one ``("file", PATH)`` area, its map
    anchored at the centre of its bounds, shared by every camera it covers;
  - a larger one is split into squares of :data:`CELL_M` metres, ``("cell", PATH, I, J)``,
    each map anchored at its cell's centre;
- no extract covers it and the network is allowed: the Overpass cell ``("net", I, J)``;
- otherwise ``("none", REASON)``.

Without a point, a title is searched in each (whole) extract: ``("search", PATHS)``
(:meth:`MapCatalogue.area_for_search`).

Maps are kept in a per-process dictionary (:meth:`MapCatalogue.map_for_area`), so a worker
parses an area's extract once however many cameras it serves. Areas are pure values: the
same point gets the same area, and so the same map anchored at the same point, in every
process and every front end (CLI, batch, service, geocoder, QGIS), which keeps their answers
identical.
"""

from __future__ import annotations

import logging
import math
import os
import threading
import time
from collections import OrderedDict
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

from camloc_geo._errors import InputError, MapDataError

if TYPE_CHECKING:
    from camloc_geo.osm._map import MapData

__all__ = [
    "CELL_M",
    "WHOLE_EXTRACT_MAX_BYTES",
    "Area",
    "MapCatalogue",
    "MapPlan",
    "area_map",
    "clear_maps",
    "extract_bounds",
    "extract_files",
    "map_loads",
    "map_plan",
]

log = logging.getLogger(__name__)

WHOLE_EXTRACT_MAX_BYTES = 48 * 1024 * 1024
"""Extracts up to this size are loaded whole (one map for every camera they cover)."""

CELL_M = 2000.0
"""Side of the square cells larger extracts and Overpass are split into (metres)."""

_CELL_MARGIN_M = 400.0
_MAX_MAPS = 32
_DEG_LAT_M = 111_320.0

Area = tuple[Any, ...]
"""A unit of map loading: ``("file", PATH)``, ``("cell", PATH, I, J)``, ``("net", I, J)``,
``("search", PATHS)`` or ``("none", REASON)``."""


def extract_files(source: str | os.PathLike[str]) -> tuple[str, ...]:
    """The extract itself, or every extract in a folder (absolute paths, sorted by name).

    Raises
    ------
    MapDataError
        The path does not exist, or the folder holds no extract.
    """
    from camloc_geo.osm._load import EXTRACT_SUFFIXES

    path = Path(source).expanduser()
    if path.is_file():
        return (str(path.absolute()),)
    if path.is_dir():
        files = sorted(
            str(p.absolute())
            for p in path.iterdir()
            if p.is_file() and p.name.lower().endswith(EXTRACT_SUFFIXES)
        )
        if not files:
            raise MapDataError(
                f"no OSM extracts (.osm, .osm.pbf, .osm.gz, .osm.bz2) in the folder {path}"
            )
        return tuple(files)
    raise MapDataError(f"OSM extract or folder not found: {path}")


@lru_cache(maxsize=256)
def _bounds_cached(path: str, mtime_ns: int) -> tuple[float, float, float, float]:
    import osmium

    from camloc_geo.osm._load import _check_extract_path, header_box

    _check_extract_path(Path(path))
    box = header_box(Path(path))
    if box is not None:
        return box
    s, w, n, e = math.inf, math.inf, -math.inf, -math.inf
    try:
        for node in osmium.FileProcessor(path, osmium.osm.NODE):
            if not isinstance(node, osmium.osm.Node):
                continue
            loc = node.location
            if loc.valid():
                s, n = min(s, loc.lat), max(n, loc.lat)
                w, e = min(w, loc.lon), max(e, loc.lon)
    except (RuntimeError, OSError, ValueError) as exc:
        raise MapDataError(f"cannot read OSM extract {Path(path).name}: {exc}") from exc
    if not math.isfinite(s):
        raise MapDataError(f"OSM extract {Path(path).name} holds no located nodes")
    return s, w, n, e


def extract_bounds(path: str | os.PathLike[str]) -> tuple[float, float, float, float]:
    """``(south, west, north, east)`` of an extract: its header box, else one scan of its nodes.

    Read once per file and modification time.

    Raises
    ------
    MapDataError
        The file is missing, unreadable or holds no located node.
    """
    p = str(Path(path).expanduser().absolute())
    try:
        mtime = os.stat(p).st_mtime_ns
    except OSError:
        mtime = 0
    return _bounds_cached(p, mtime)


def _cell_of(lat: float, lon: float) -> tuple[int, int]:
    d = CELL_M / _DEG_LAT_M
    return math.floor(lat / d), math.floor(lon / d)


def _cell_centre(i: int, j: int) -> tuple[float, float]:
    d = CELL_M / _DEG_LAT_M
    return (i + 0.5) * d, (j + 0.5) * d


INDEX_RECHECK_S = 2.0
"""How often (seconds) a catalogue's index re-stats each of its extracts (an extract rewritten
in place, which leaves its folder's modification time alone); files added, removed or
renamed change the folder's, which every question checks."""


@dataclass(frozen=True)
class _IndexEntry:
    path: str
    south: float
    west: float
    north: float
    east: float


@dataclass(frozen=True)
class _ExtractIndex:
    """A catalogue's extracts, read once: bounds smallest first, and their sizes.

    ``folders`` is the signature of the extracts' folders (their modification times) and
    ``files`` that of the extracts themselves (modification time and size), taken when the
    index was built; ``checked`` the :func:`time.monotonic` of the last look at ``files``.
    """

    folders: tuple[int, ...]
    files: tuple[tuple[int, int], ...]
    checked: float
    entries: tuple[_IndexEntry, ...]
    sizes: dict[str, int]

    def whole(self, path: str) -> bool:
        """Is the extract loaded whole (up to :data:`WHOLE_EXTRACT_MAX_BYTES`; unknown: yes)."""
        size = self.sizes.get(path, -1)
        return size < 0 or size <= WHOLE_EXTRACT_MAX_BYTES


_INDEXES: dict[tuple[str, ...], _ExtractIndex] = {}
_INDEX_LOCK = threading.Lock()
_MAX_INDEXES = 64


def _stat_sig(path: str) -> tuple[int, int]:
    try:
        st = os.stat(path)
    except OSError:
        return (-1, -1)
    return (st.st_mtime_ns, st.st_size)


@lru_cache(maxsize=_MAX_INDEXES)
def _folders_of(files: tuple[str, ...]) -> tuple[str, ...]:
    return tuple(sorted({os.path.dirname(f) for f in files}))


def _build_index(files: tuple[str, ...], folders: tuple[int, ...]) -> _ExtractIndex:
    sigs = tuple(_stat_sig(f) for f in files)
    rows: list[tuple[float, str, _IndexEntry]] = []
    for f in files:
        try:
            s, w, n, e = extract_bounds(f)
        except MapDataError as exc:  # said once per change of the folder, not per point
            log.warning("%s", exc)
            continue
        rows.append(((n - s) * (e - w), f, _IndexEntry(f, s, w, n, e)))
    rows.sort(key=lambda r: (r[0], r[1]))
    sizes = {f: sig[1] for f, sig in zip(files, sigs, strict=True)}
    return _ExtractIndex(folders, sigs, time.monotonic(), tuple(r[2] for r in rows), sizes)


def _extract_index(files: tuple[str, ...]) -> _ExtractIndex:
    """The index of a catalogue's extracts, built once and kept per process.

    Rebuilt when a folder holding them changes (a file added, removed or renamed: one stat
    per folder per question), or when an extract's modification time or size changed (looked
    at every :data:`INDEX_RECHECK_S` seconds). Before session 41 every question stat-ed and
    normalised every extract's path: 128 µs a point over ``data/osm``'s 26 extracts, about
    0.4-2 s for a 3000-camera list (``benchmarks/catalogue.py``).
    """
    folders = tuple(_stat_sig(d)[0] for d in _folders_of(files))
    index = _INDEXES.get(files)
    if index is not None and index.folders == folders:
        if time.monotonic() - index.checked < INDEX_RECHECK_S:
            return index
        if tuple(_stat_sig(f) for f in files) == index.files:
            fresh = _ExtractIndex(
                index.folders, index.files, time.monotonic(), index.entries, index.sizes
            )
            with _INDEX_LOCK:
                _INDEXES[files] = fresh
            return fresh
    index = _build_index(files, folders)
    with _INDEX_LOCK:
        if len(_INDEXES) >= _MAX_INDEXES and files not in _INDEXES:
            _INDEXES.pop(next(iter(_INDEXES)))
        _INDEXES[files] = index
    return index


@dataclass(frozen=True)
class MapCatalogue:
    """Where maps come from: extract files, Overpass, or nothing (a pure, picklable value).

    Build one with :meth:`from_source`. Attributes
    ----------
    files
        Absolute paths of the extracts (one file, or a folder's extracts).
    network
        May Overpass be queried for a point no extract covers.
    area_filter
        Only extracts whose file name contains this (a city's name) serve titles without a point.
    cache_folder, overpass_url
        osmnx's HTTP cache folder and the Overpass endpoint (online only; default osmnx's).
    """

    files: tuple[str, ...] = ()
    network: bool = False
    area_filter: str | None = None
    cache_folder: str | None = None
    overpass_url: str | None = None

    @classmethod
    def from_source(
        cls,
        source: MapCatalogueSource,
        *,
        network: bool = False,
        area: str | None = None,
        cache_folder: str | os.PathLike[str] | None = None,
        overpass_url: str | None = None,
    ) -> MapCatalogue:
        """The catalogue of an extract, a folder of extracts, or the network.

        Parameters
        ----------
        source
            An extract, a folder of extracts, a catalogue (returned as is) or None (Overpass
            when ``network``; with an extract or folder the network is never used).
        area
            Keep only the extracts whose name contains it (titles without a point).

        Raises
        ------
        MapDataError
            The extract or folder does not exist or holds no extract.
        InputError
            No extract's name contains ``area``.
        """
        if isinstance(source, MapCatalogue):
            return source
        folder = None if cache_folder is None else str(cache_folder)
        if source is None:
            return cls(
                network=bool(network),
                area_filter=area,
                cache_folder=folder,
                overpass_url=overpass_url,
            )
        files = extract_files(source)
        if area and not any(area.strip().lower() in Path(f).name.lower() for f in files):
            raise InputError(f"--area {area!r}: no extract's name contains it")
        return cls(files=files, area_filter=area, cache_folder=folder, overpass_url=overpass_url)

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

    def covering(self, lat: float, lon: float, *, name: str | None = None) -> list[str]:
        """The extracts whose bounds cover a point, smallest first (``name`` preferred).

        Reads the catalogue's index (:func:`_extract_index`: every extract's bounds and size
        read once, re-read when its folder changes), not every extract's file per point.
        """
        entries = _extract_index(self.files).entries
        wanted = self._named(name) if name else ()
        if wanted:
            keep = set(wanted)
            chosen = [x for x in entries if x.path in keep]
        else:
            chosen = list(entries)
        return [x.path for x in chosen if x.south <= lat <= x.north and x.west <= lon <= x.east]

    def area_for_point(self, lat: float, lon: float, *, name: str | None = None) -> Area:
        """The area whose map serves a point (the module's one rule)."""
        if self.files:
            covering = self.covering(lat, lon, name=name)
            if not covering:
                names = ", ".join(Path(f).name for f in self.files[:5])
                more = " ..." if len(self.files) > 5 else ""
                return (
                    "none",
                    f"lat={lat:.6f}, lon={lon:.6f} is outside every extract ({names}{more})",
                )
            f = covering[0]
            if _extract_index(self.files).whole(f):
                return ("file", f)
            return ("cell", f, *_cell_of(lat, lon))
        if self.network:
            return ("net", *_cell_of(lat, lon))
        return ("none", "no map: give --osm EXTRACT_OR_FOLDER or allow --network")

    def area_for_search(self, name: str | None = None) -> Area:
        """The area in which a title without a point is searched (whole extracts only)."""
        if not self.files:
            return (
                "none",
                "no point to load the map around (no lat/lon) and no extract to search the "
                "title in: give --osm EXTRACT_OR_FOLDER",
            )
        name = name or self.area_filter
        files = self._named(name)
        if not files:
            return ("none", f"no extract's name contains the area {name!r}")
        whole = tuple(f for f in files if self._whole(f))
        if not whole:
            return (
                "none",
                "no point given and the extract is too large to search whole: give lat/lon",
            )
        if len(whole) == 1:
            return ("file", whole[0])
        return ("search", whole)

    def area_of(self, row: Any) -> Area:
        """The area of a camera (anything with ``lat``, ``lon``, ``has_point`` and ``area``)."""
        if getattr(row, "has_point", False):
            return self.area_for_point(float(row.lat), float(row.lon), name=row.area)
        return self.area_for_search(getattr(row, "area", None))

    def map_for_area(self, area: Area) -> MapData:
        """The map of an area, loaded once per process (thread-safe).

        Raises
        ------
        MapDataError, MapSourceError
            No map for the area, an unreadable extract, or Overpass failed.
        """
        if area[0] == "none":
            raise MapDataError(str(area[1]))
        if area[0] == "net":
            return area_map(area, cache_folder=self.cache_folder, overpass_url=self.overpass_url)
        return area_map(area)

    def map_for_point(self, *, lat: float, lon: float) -> MapData:
        """The map serving a point.

        Raises
        ------
        MapDataError
            No extract covers the point and the network is off; an unreadable extract.
        MapSourceError
            Overpass failed.
        """
        return self.map_for_area(self.area_for_point(lat, lon))

    def source_name(self, area: Area) -> str | None:
        """What a result names as its map: the extract's file name, ``overpass`` or None."""
        if area[0] == "net":
            return "overpass"
        if area[0] in ("file", "cell"):
            return os.path.basename(str(area[1]))
        return None


MapCatalogueSource = str | os.PathLike[str] | MapCatalogue | None
"""What every front end accepts as a map source: an extract, a folder, a catalogue, or None."""

MapPlan = MapCatalogue
"""The old name of :class:`MapCatalogue` (batch)."""


def map_plan(
    map_source: MapCatalogueSource, *, network: bool = False, area: str | None = None
) -> MapCatalogue:
    """The :class:`MapCatalogue` of an extract, a folder of extracts, or the network.

    Raises
    ------
    MapDataError
        The extract or folder does not exist or holds no extract.
    """
    return MapCatalogue.from_source(map_source, network=network, area=area)


_MAPS: OrderedDict[tuple[Any, ...], Any] = OrderedDict()
_MAPS_LOCK = threading.Lock()
_LOAD_LOCKS: dict[tuple[Any, ...], threading.Lock] = {}
_LOADS = [0]


def map_loads() -> int:
    """How many maps :func:`area_map` has loaded in this process so far (or forgotten).

    A long-running process (the service's workers) compares it between requests to learn
    that its set of maps changed, e.g. to move them out of the garbage collector's way.
    """
    return _LOADS[0]


def area_map(
    area: Area, *, cache_folder: str | None = None, overpass_url: str | None = None
) -> MapData:
    """The map of an area, loaded once per process (thread-safe).

    Raises
    ------
    MapDataError, MapSourceError
        The extract is unreadable or Overpass failed.
    """
    key = (*area, cache_folder, overpass_url) if area[0] == "net" else tuple(area)
    with _MAPS_LOCK:
        if key in _MAPS:
            _MAPS.move_to_end(key)
            return _MAPS[key]
        lock = _LOAD_LOCKS.setdefault(key, threading.Lock())
    with lock:
        with _MAPS_LOCK:
            if key in _MAPS:
                return _MAPS[key]
        m = _load_area(area, cache_folder, overpass_url)
        with _MAPS_LOCK:
            _MAPS[key] = m
            _LOADS[0] += 1
            while len(_MAPS) > _MAX_MAPS:
                _MAPS.popitem(last=False)
        return m


def _load_area(area: Area, cache_folder: str | None, overpass_url: str | None) -> MapData:
    from camloc_geo.osm._map import load_map

    kind = area[0]
    radius = CELL_M * math.sqrt(0.5) + _CELL_MARGIN_M
    if kind == "file":
        s, w, n, e = extract_bounds(area[1])
        return load_map(area[1], (s + n) / 2.0, (w + e) / 2.0, radius_m=None)
    if kind == "cell":
        lat, lon = _cell_centre(area[2], area[3])
        return load_map(area[1], lat, lon, radius_m=radius)
    if kind == "net":
        lat, lon = _cell_centre(area[1], area[2])
        return load_map(
            None, lat, lon, radius_m=radius, cache_folder=cache_folder, overpass_url=overpass_url
        )
    raise MapDataError(f"no map for area {area[0]!r}")


def clear_maps() -> None:
    """Forget the maps of this process."""
    with _MAPS_LOCK:
        _MAPS.clear()
        _LOADS[0] += 1
