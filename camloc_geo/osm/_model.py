"""Value types of the OSM layer: streets, intersections, kerb corners and buildings.

Conventions: geographic coordinates are WGS 84, passed and stored as ``(lon, lat)`` in
geometries and GeoJSON, and named ``lat``/``lon`` in attributes. Bearings are degrees
clockwise from true north. "Clockwise" means as seen from above with north up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
import shapely
from shapely.geometry import LineString, Polygon
from shapely.geometry.polygon import orient

from camloc_geo.geodesy import LocalFrame, distance_m

if TYPE_CHECKING:
    from collections.abc import Sequence

__all__ = [
    "Building",
    "Corner",
    "IncidentStreet",
    "Intersection",
    "Street",
]

FloatArray = npt.NDArray[np.float64]

BUILDING_CORNER_MIN_TURN_DEG = 15.0
"""A footprint vertex is a building corner when the outline turns there by more than this."""


@dataclass(frozen=True)
class IncidentStreet:
    """One street leaving an intersection.

    Attributes
    ----------
    name
        The OSM ``name``; else ``ref``; else ``"unnamed <highway>"``.
    bearing_deg
        Outward bearing near the junction (over the first :data:`ARM_SAMPLE_M` metres),
        degrees clockwise from true north in [0, 360).
    highway
        The OSM ``highway`` value.
    oneway
        True for a one-way street. A dual carriageway (two one-way carriageways merged into
        one street) is not one-way.
    lanes
        Total number of lanes (over both carriageways of a dual road), or None if untagged.
    width_m
        Resolved kerb-to-kerb width used for the kerb lines, metres. For a dual carriageway
        it spans the outer kerbs of the pair (median included).
    width_source
        ``"width"``, ``"lanes"`` or ``"default"`` (see :mod:`camloc_geo.osm._widths`).
    carriageways
        1, or 2 for a dual carriageway merged from two one-way ways.
    names
        Every name of the street (osmnx keeps several where ways were merged).
    edge
        ``(u, v)`` OSM node ids of the (simplified-graph) edge the bearing was measured on,
        oriented outward; for a dual carriageway, the edge of the outbound carriageway.
    back_bearing_deg
        ``bearing_deg`` + 180 in [0, 360): the bearing towards the intersection.
    """

    name: str
    bearing_deg: float
    highway: str
    oneway: bool
    lanes: float | None
    width_m: float
    width_source: str = "default"
    carriageways: int = 1
    names: tuple[str, ...] = ()
    edge: tuple[int, int] = (0, 0)

    @property
    def back_bearing_deg(self) -> float:
        """Bearing of the street towards the intersection, [0, 360)."""
        return (self.bearing_deg + 180.0) % 360.0


@dataclass(frozen=True)
class Corner:
    """A kerb corner of an intersection.

    Attributes
    ----------
    intersection_id
        The id of its :class:`Intersection`.
    order
        Clockwise index seen from above, 0 = the corner with the smallest bearing from the
        intersection centre.
    lat, lon
        Position, degrees WGS 84.
    streets
        The two streets it lies between, in clockwise order (the street on its
        counter-clockwise side first).
    """

    intersection_id: str
    order: int
    lat: float
    lon: float
    streets: tuple[str, str]


@dataclass(frozen=True)
class Intersection:
    """A (consolidated) road intersection.

    Attributes
    ----------
    id
        ``"n<osm node id>"`` for a single OSM node, ``"c<smallest osm node id>"`` for a
        cluster of nodes consolidated into one intersection (dual carriageways, offset
        junctions).
    lat, lon
        Centre (the node, or the centroid of the consolidated nodes).
    streets
        Incident streets, sorted clockwise by outward bearing.
    corners
        Kerb corners, clockwise from above. Empty for ``"unmodelled"`` junctions (and
        roundabouts whose ring is too wide or not a circle).
    kind
        ``"junction"`` (modelled), ``"roundabout"`` or ``"unmodelled"`` (see ``warnings``).
    warnings
        Human-readable notes on what was not modelled or assumed.
    osm_nodes
        The OSM node ids grouped into this intersection.
    osm_node_lonlat
        ``(lon, lat)`` of each of ``osm_nodes``: a scene's point matches any of them.
    """

    id: str
    lat: float
    lon: float
    streets: tuple[IncidentStreet, ...]
    corners: tuple[Corner, ...]
    kind: str
    warnings: tuple[str, ...] = ()
    osm_nodes: tuple[int, ...] = ()
    osm_node_lonlat: tuple[tuple[float, float], ...] = ()

    @property
    def street_names(self) -> tuple[str, ...]:
        """Names of the incident streets, clockwise, without repeats."""
        return tuple(dict.fromkeys(s.name for s in self.streets))

    @property
    def corner_distances_m(self) -> list[float]:
        """Geodesic distance from corner i to corner i + 1 (cyclic), metres.

        The sequence the corner-matching method compares. Empty with fewer than two
        corners; with two corners it is ``[d, d]``.
        """
        if len(self.corners) < 2:
            return []
        lons = np.array([c.lon for c in self.corners])
        lats = np.array([c.lat for c in self.corners])
        dist = distance_m(lat1=lats, lon1=lons, lat2=np.roll(lats, -1), lon2=np.roll(lons, -1))
        return [float(d) for d in np.atleast_1d(dist)]

    def corners_enu(self, frame: LocalFrame) -> FloatArray:
        """Corners as an (N, 2) array of east/north metres in ``frame``."""
        if not self.corners:
            return np.zeros((0, 2), dtype=np.float64)
        return frame.points_enu_from_geographic([[c.lon, c.lat] for c in self.corners])


@dataclass(frozen=True)
class Street:
    """A street segment: one edge of the simplified street graph (both directions once).

    Attributes
    ----------
    name
        ``name``, else ``ref``, else ``"unnamed <highway>"``.
    highway, oneway, lanes, width_m
        As in :class:`IncidentStreet` (``width_m`` of this one carriageway).
    geometry
        The centre line, a LineString in (lon, lat).
    names
        All names of the merged OSM ways.
    way_ids
        OSM way ids.
    u, v
        OSM node ids at its ends.
    """

    name: str
    highway: str
    oneway: bool
    lanes: float | None
    width_m: float
    geometry: LineString
    names: tuple[str, ...] = ()
    way_ids: tuple[int, ...] = ()
    u: int = 0
    v: int = 0


@dataclass(frozen=True)
class Building:
    """A building footprint.

    Attributes
    ----------
    id
        ``"way/<id>"`` or ``"relation/<id>"``.
    name
        ``name``, else ``addr:housename``, else ``brand``, else None.
    footprint
        Outer outline, a Polygon in (lon, lat) (the largest part of a multipolygon).
    height_m
        ``height`` tag in metres, or None.
    levels
        ``building:levels``, or None.
    building
        The ``building`` tag value (``yes``, ``house``, ``church``...).
    """

    id: str
    name: str | None
    footprint: Polygon
    height_m: float | None
    levels: float | None
    building: str = "yes"

    @cached_property
    def _corner_ring(self) -> list[tuple[float, float]]:
        ring = orient(self.footprint, sign=-1.0).exterior  # clockwise seen from above
        coords = list(ring.coords)[:-1]
        if len(coords) < 3:
            return coords
        centroid = self.footprint.centroid
        frame = LocalFrame(lat=centroid.y, lon=centroid.x)
        en = frame.points_enu_from_geographic(coords)
        keep = []
        n = len(coords)
        for i in range(n):
            a = en[i] - en[i - 1]
            b = en[(i + 1) % n] - en[i]
            if np.hypot(*a) < 1e-6 or np.hypot(*b) < 1e-6:
                continue
            turn = math.degrees(abs(math.atan2(a[0] * b[1] - a[1] * b[0], float(a @ b))))
            if turn > BUILDING_CORNER_MIN_TURN_DEG:
                keep.append(i)
        if len(keep) < 3:
            keep = list(range(n))
        return [(float(coords[i][0]), float(coords[i][1])) for i in keep]

    @property
    def corners(self) -> list[tuple[float, float]]:
        """Footprint corners ``(lon, lat)``, clockwise seen from above.

        Vertices where the outline turns by less than
        :data:`BUILDING_CORNER_MIN_TURN_DEG` (digitising noise on a straight wall) are
        dropped.
        """
        return list(self._corner_ring)

    @property
    def face_midpoints(self) -> list[tuple[float, float]]:
        """Midpoints ``(lon, lat)`` of the faces between successive :attr:`corners`."""
        corners = self._corner_ring
        out: list[tuple[float, float]] = []
        for i, (lon1, lat1) in enumerate(corners):
            lon2, lat2 = corners[(i + 1) % len(corners)]
            frame = LocalFrame(lat=lat1, lon=lon1)
            e, n = frame.enu_from_geographic(lat=lat2, lon=lon2)
            lon_m, lat_m = frame.geographic_from_enu(e / 2.0, n / 2.0)
            out.append((float(lon_m), float(lat_m)))
        return out

    @property
    def centroid(self) -> tuple[float, float]:
        """Footprint centroid ``(lon, lat)``."""
        c = self.footprint.centroid
        return float(c.x), float(c.y)


def polygon_from_lonlat(coords: Sequence[tuple[float, float]]) -> Polygon | None:
    """A valid Polygon from a closed ring of (lon, lat), or None if degenerate."""
    if len(coords) < 4:
        return None
    poly = Polygon(coords)
    if not poly.is_valid:
        poly = shapely.make_valid(poly)
        if poly.geom_type != "Polygon":
            parts = [g for g in getattr(poly, "geoms", []) if g.geom_type == "Polygon"]
            if not parts:
                return None
            poly = max(parts, key=lambda g: g.area)
    if poly.is_empty or poly.area <= 0:
        return None
    return poly
