"""Map data for the service: the server's :class:`~camloc_geo.osm.MapCatalogue`.

Only the server's configuration names map sources: a folder of extracts and, optionally,
Overpass around a point. Which map serves a point is the catalogue's one rule, the same as
``camloc batch`` and every other front end; maps are loaded once per area and shared.
"""

from __future__ import annotations

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
        from camloc_geo.osm import MapCatalogue, extract_files

        self._settings = settings
        files: tuple[str, ...] = ()
        if settings.map_dir is not None:
            folder = Path(settings.map_dir)
            if not folder.is_dir():
                raise MapDataError(f"CAMLOC_MAP_DIR {folder} is not a folder")
            try:
                files = extract_files(folder)
            except MapDataError:
                files = ()  # an empty folder: no extract, the network may still serve
        self.catalogue: MapCatalogue = MapCatalogue(
            files=files,
            network=bool(settings.network),
            cache_folder=None if settings.cache_folder is None else str(settings.cache_folder),
            overpass_url=settings.overpass_url,
        )
        self.extracts: list[Path] = [Path(f) for f in files]

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
        area = self.catalogue.area_for_point(lat, lon)
        if area[0] == "none":
            raise MapDataError(
                f"no map data configured on this server covers lat={lat:.6f}, lon={lon:.6f}"
            )
        return self.catalogue.map_for_area(area)


def distance_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Geodesic distance in metres (:func:`camloc_geo.geodesy.distance_m`, positional)."""
    from camloc_geo import geodesy

    return float(geodesy.distance_m(lat1=lat1, lon1=lon1, lat2=lat2, lon2=lon2))
