"""Streets and buildings projected to a map's local frame, with their spatial indexes.

Computed once per :class:`~camloc_geo.osm.MapData` (lazily, under the map's lock) and shared
by every caller: absolute localisation, street bearings, synthetic scenes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from camloc_geo.geodesy import LocalFrame

if TYPE_CHECKING:
    from camloc_geo.osm._model import Building, Street

__all__ = ["LocalIndex", "building_index", "project_buildings", "project_streets", "street_index"]


@dataclass(frozen=True)
class LocalIndex:
    """Shapely geometries in the local frame, a value per geometry, and an STRtree.

    Attributes
    ----------
    geometries
        ENU metres (east, north).
    values
        One number per geometry (a street's half carriageway width; 0 for buildings).
    tree
        :class:`shapely.STRtree` over ``geometries`` (None when there are none); its
        ``query`` returns indices into ``geometries``.
    """

    geometries: tuple[Any, ...]
    values: tuple[float, ...]
    tree: Any

    @property
    def values_array(self) -> npt.NDArray[np.float64]:
        """:attr:`values` as an array (built once), to index with the tree's answers."""
        try:
            out: npt.NDArray[np.float64] = self.__dict__["_values_array"]
        except KeyError:
            out = np.asarray(self.values, dtype=np.float64)
            self.__dict__["_values_array"] = out  # a cache, not state (frozen dataclass)
        return out

    def __len__(self) -> int:
        return len(self.geometries)


def project_streets(streets: Sequence[Street], frame: LocalFrame) -> tuple[Any, ...]:
    """Street centre lines as ENU LineStrings, one per street, in order."""
    from shapely.geometry import LineString

    return tuple(
        LineString(frame.points_enu_from_geographic(np.asarray(s.geometry.coords))) for s in streets
    )


def project_buildings(buildings: Sequence[Building], frame: LocalFrame) -> tuple[Any, ...]:
    """Building footprints as ENU Polygons (exterior rings), one per building, in order."""
    from shapely.geometry import Polygon

    return tuple(
        Polygon(frame.points_enu_from_geographic(np.asarray(b.footprint.exterior.coords, float)))
        for b in buildings
    )


def street_index(streets: Sequence[Street], lines_enu: Sequence[Any]) -> LocalIndex:
    """Streets longer than 0.5 m with their half carriageway widths, and an STRtree."""
    from shapely import STRtree

    rows = [
        (line, float(st.width_m) / 2.0)
        for st, line in zip(streets, lines_enu, strict=True)
        if len(line.coords) >= 2 and line.length > 0.5
    ]
    geoms = tuple(r[0] for r in rows)
    return LocalIndex(geoms, tuple(r[1] for r in rows), STRtree(geoms) if geoms else None)


def building_index(polygons_enu: Sequence[Any]) -> LocalIndex:
    """Valid footprints larger than 1 m², and an STRtree."""
    from shapely import STRtree

    geoms = tuple(p for p in polygons_enu if p.is_valid and p.area > 1.0)
    return LocalIndex(geoms, (0.0,) * len(geoms), STRtree(geoms) if geoms else None)
