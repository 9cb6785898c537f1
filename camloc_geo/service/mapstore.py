"""Map data for the service: loaded once per extract, shared by every request.

Only the server's configuration names map sources: a folder of extracts (each loaded whole,
once, on first need) and, optionally, Overpass around a point (cached per ~1 km cell).
"""

from __future__ import annotations

import logging
import math
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from camloc_geo._errors import MapDataError

if TYPE_CHECKING:
    from camloc_geo.osm import MapData
    from camloc_geo.service.settings import Settings

__all__ = ["EXTRACT_SUFFIXES", "MapStore"]

log = logging.getLogger(__name__)

EXTRACT_SUFFIXES = (".osm", ".osm.gz", ".osm.bz2", ".osm.pbf")
_CELL_DEG = 0.01  # Overpass maps are shared within cells of about 1 km
_OVERPASS_RADIUS_M = 1_200.0


class MapStore:
    """The maps a service instance uses; thread-safe, each extract parsed at most once."""

    def __init__(self, settings: Settings) -> None:
        self._settings = settings
        self._lock = threading.Lock()
        self._loading: dict[str, threading.Lock] = {}
        self._maps: dict[str, MapData | MapDataError] = {}
        self._bounds: dict[Path, tuple[float, float, float, float]] = {}
        self.extracts: list[Path] = []
        if settings.map_dir is not None:
            folder = Path(settings.map_dir)
            if not folder.is_dir():
                raise MapDataError(f"CAMLOC_MAP_DIR {folder} is not a folder")
            self.extracts = sorted(
                p for p in folder.iterdir() if p.is_file() and p.name.endswith(EXTRACT_SUFFIXES)
            )

    def _load(self, key: str, loader: object) -> MapData | MapDataError:
        with self._lock:
            if key in self._maps:
                return self._maps[key]
            lock = self._loading.setdefault(key, threading.Lock())
        with lock:
            with self._lock:
                if key in self._maps:
                    return self._maps[key]
            try:
                value: MapData | MapDataError = loader()  # type: ignore[operator]
            except MapDataError as exc:
                log.warning("map %s unusable: %s", key, exc)
                value = exc
            with self._lock:
                self._maps[key] = value
            return value

    def _extract_map(self, path: Path) -> MapData | MapDataError:
        def load() -> MapData:
            from camloc_geo.osm import load_map

            south, west, north, east = extract_bounds(path)
            self._bounds[path] = (south, west, north, east)
            return load_map(path, (south + north) / 2, (west + east) / 2, radius_m=None)

        return self._load(f"file:{path}", load)

    def map_for_point(self, *, lat: float, lon: float) -> MapData:
        """The map covering a point.

        Raises
        ------
        MapDataError
            No configured extract covers the point and the network is off.
        """
        for path in self.extracts:
            m = self._extract_map(path)
            if isinstance(m, MapDataError) or path not in self._bounds:
                continue
            south, west, north, east = self._bounds[path]
            if south <= lat <= north and west <= lon <= east:
                return m
        if self._settings.network:
            clat = round(lat / _CELL_DEG) * _CELL_DEG
            clon = round(lon / _CELL_DEG) * _CELL_DEG

            def load() -> MapData:
                from camloc_geo.osm import load_map

                return load_map(
                    None,
                    clat,
                    clon,
                    _OVERPASS_RADIUS_M,
                    cache_folder=self._settings.cache_folder,
                    overpass_url=self._settings.overpass_url,
                )

            got = self._load(f"overpass:{clat:.2f},{clon:.2f}", load)
            if isinstance(got, MapDataError):
                raise got
            return got
        raise MapDataError(
            f"no map data configured on this server covers lat={lat:.6f}, lon={lon:.6f}"
        )


def distance_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Great-circle distance in metres (haversine; for filtering, not for results)."""
    p1, p2 = math.radians(lat1), math.radians(lat2)
    dp, dl = p2 - p1, math.radians(lon2 - lon1)
    a = math.sin(dp / 2) ** 2 + math.cos(p1) * math.cos(p2) * math.sin(dl / 2) ** 2
    return 2 * 6_371_008.8 * math.asin(min(1.0, math.sqrt(a)))


def extract_bounds(path: Path) -> tuple[float, float, float, float]:
    """``(south, west, north, east)`` of an extract's nodes (its data, not its header box)."""
    import osmium

    south = west = math.inf
    north = east = -math.inf
    try:
        for obj in osmium.FileProcessor(str(path), osmium.osm.NODE):
            if not isinstance(obj, osmium.osm.Node):
                continue
            node = obj
            if not node.location.valid():
                continue
            lat, lon = node.location.lat, node.location.lon
            south, north = min(south, lat), max(north, lat)
            west, east = min(west, lon), max(east, lon)
    except RuntimeError as exc:
        raise MapDataError(f"cannot read OSM extract {path.name}: {exc}") from exc
    if not math.isfinite(south):
        raise MapDataError(f"OSM extract {path.name} holds no nodes")
    return south, west, north, east
