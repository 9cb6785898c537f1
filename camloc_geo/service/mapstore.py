"""Map data for the service: the server's :class:`~camloc_geo.osm.MapCatalogue`.

Only the server's configuration names map sources: a folder of extracts and, optionally,
Overpass around a point. Which map serves a point is the catalogue's one rule, the same as
``camloc batch`` and every other front end; maps are loaded once per area and shared.
"""

from __future__ import annotations

import os
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from camloc_geo._errors import MapDataError

if TYPE_CHECKING:
    from camloc_geo.osm import MapCatalogue, MapData
    from camloc_geo.service.settings import Settings

__all__ = ["MapStore", "distance_m"]


class MapStore:
    """The maps a service instance uses: a thin adapter over its catalogue (thread-safe)."""

    def __init__(self, settings: Settings) -> None:
        self._settings = settings
        self._folder: Path | None = None
        if settings.map_dir is not None:
            folder = Path(settings.map_dir)
            if not folder.is_dir():
                raise MapDataError(f"CAMLOC_MAP_DIR {folder} is not a folder")
            self._folder = folder
        self._lock = threading.Lock()
        self._folder_ns: int | None = None
        self._catalogue = self._listed()

    def _listed(self) -> MapCatalogue:
        """The catalogue of the folder's extracts as they are now."""
        from camloc_geo.osm import MapCatalogue, extract_files

        files: tuple[str, ...] = ()
        if self._folder is not None:
            try:
                self._folder_ns = os.stat(self._folder).st_mtime_ns
            except OSError:
                self._folder_ns = None
            try:
                files = extract_files(self._folder)
            except MapDataError:
                files = ()  # an empty folder: no extract, the network may still serve
        settings = self._settings
        return MapCatalogue(
            files=files,
            network=bool(settings.network),
            cache_folder=None if settings.cache_folder is None else str(settings.cache_folder),
            overpass_url=settings.overpass_url,
        )

    @property
    def catalogue(self) -> MapCatalogue:
        """The catalogue of ``CAMLOC_MAP_DIR``'s extracts, listed again when the folder changes.

        The extracts were listed once, at start-up: one copied in later (as the service's
        "its operator adds extracts to CAMLOC_MAP_DIR" asks) served nothing until a restart
        (stop 41, qa3). One stat of the folder per request.
        """
        if self._folder is not None:
            try:
                ns: int | None = os.stat(self._folder).st_mtime_ns
            except OSError:
                ns = self._folder_ns
            if ns != self._folder_ns:
                with self._lock:
                    if ns != self._folder_ns:
                        self._catalogue = self._listed()
        return self._catalogue

    @property
    def extracts(self) -> list[Path]:
        """The extracts the service's map data comes from (``CAMLOC_MAP_DIR``'s, as now)."""
        return [Path(f) for f in self.catalogue.files]

    @property
    def settings(self) -> Settings:
        """The server's settings (a worker checks a raw scene body against their limits)."""
        return self._settings

    def map_for_point(self, *, lat: float, lon: float) -> MapData:
        """The map serving a point (the catalogue's rule).

        Raises
        ------
        MapDataError
            No configured extract covers the point and the network is off.
        MapSourceError
            Overpass failed.
        """
        catalogue = self.catalogue
        area = catalogue.area_for_point(lat, lon)
        if area[0] == "none":
            raise MapDataError(
                f"no map data configured on this server covers lat={lat:.6f}, lon={lon:.6f}"
                + self._swapped_hint(catalogue, lat, lon)
            )
        return catalogue.map_for_area(area)

    @staticmethod
    def _swapped_hint(catalogue: MapCatalogue, lat: float, lon: float) -> str:
        """A hint when the point, outside every extract, lies in one with lat and lon swapped
        (``?lat=24.9455&lon=60.1699`` for Helsinki was only "no map data ... covers", where
        ``camloc batch`` names the swap)."""
        if not -90.0 <= lon <= 90.0 or not catalogue.files:
            return ""
        try:
            covering = catalogue.covering(lon, lat)
        except Exception:  # a hint only
            return ""
        if not covering:
            return ""
        return (
            f"; with lat and lon swapped, lat={lon:.6f}, lon={lat:.6f} lies in a map (in "
            f"{Path(covering[0]).name}): are lat and lon the other way round?"
        )


def distance_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Geodesic distance in metres (:func:`camloc_geo.geodesy.distance_m`, positional)."""
    from camloc_geo import geodesy

    return float(geodesy.distance_m(lat1=lat1, lon1=lon1, lat2=lat2, lon2=lon2))
