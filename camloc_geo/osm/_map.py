"""The :class:`MapData` object and :func:`load_map`."""

from __future__ import annotations

import itertools
import logging
import math
import os
import threading
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TypeVar

import networkx as nx
import numpy as np
import shapely
from shapely.geometry import LineString, Point

from camloc_geo._errors import MapDataError
from camloc_geo.geodesy import LocalFrame, initial_bearing_deg
from camloc_geo.osm._diskcache import disk_get, disk_put
from camloc_geo.osm._intersections import (
    build_intersections,
    highway_of,
    street_label,
)
from camloc_geo.osm._load import (
    NAMED_STREET_HIGHWAYS,
    STREET_HIGHWAYS,
    RawMap,
    cache_get,
    cache_put,
    read_extract,
    read_overpass,
)
from camloc_geo.osm._local import (
    LocalIndex,
    building_index,
    project_buildings,
    project_streets,
    street_index,
)
from camloc_geo.osm._model import Building, Intersection, Street
from camloc_geo.osm._names import (
    close_matches,
    misspelling_matches,
    normalize_name,
    split_street_query,
)
from camloc_geo.osm._widths import in_north_america, parse_lanes, resolve_width_m

__all__ = ["DEFAULT_TOLERANCE_M", "MapData", "load_map"]

log = logging.getLogger(__name__)

_T = TypeVar("_T")

DEFAULT_TOLERANCE_M = 12.0
"""Default node buffer for intersection consolidation, metres (nodes < 24 m apart merge)."""


def _streets_of(G: nx.MultiDiGraph, north_america: bool) -> list[Street]:
    seen: set[tuple[int, int, int]] = set()
    streets: list[Street] = []
    for u, v, data in G.edges(data=True):
        length = round(float(data.get("length", 0.0)))
        key = (min(u, v), max(u, v), length)
        if key in seen:
            continue
        seen.add(key)
        geom = data.get("geometry")
        if geom is None:
            geom = LineString(
                [(G.nodes[u]["x"], G.nodes[u]["y"]), (G.nodes[v]["x"], G.nodes[v]["y"])]
            )
        name, names = street_label(data)
        highway = highway_of(data)
        oneway_raw = data.get("oneway")
        oneway = bool(all(oneway_raw)) if isinstance(oneway_raw, list) else bool(oneway_raw)
        width, _src = resolve_width_m(
            width=data.get("width"),
            lanes=data.get("lanes"),
            highway=highway,
            oneway=oneway,
            north_america=north_america,
        )
        osmid = data.get("osmid")
        way_ids = tuple(int(i) for i in (osmid if isinstance(osmid, list) else [osmid]) if i)
        streets.append(
            Street(
                name=name,
                highway=highway,
                oneway=oneway,
                lanes=parse_lanes(data.get("lanes")),
                width_m=width,
                geometry=geom,
                names=names,
                way_ids=way_ids,
                u=int(u),
                v=int(v),
            )
        )
    return streets


def _strtree(geometries: Sequence[Any]) -> Any:
    """A :class:`shapely.STRtree` over ``geometries`` (indices aligned with them)."""
    from shapely import STRtree

    return STRtree(list(geometries))


class MapData:
    """Streets, intersections and buildings around a point.

    Built by :func:`load_map`; treat as read-only (it is shared through the load cache).

    Attributes
    ----------
    frame
        :class:`~camloc_geo.geodesy.LocalFrame` anchored at the requested point.
    radius_m
        The requested radius (None: the whole extract).
    graph
        The simplified osmnx street graph (lon/lat, unprojected, not consolidated).
    bounds
        ``(south, west, north, east)`` of the data (an extract's streets and buildings, not
        its header's declared box), when known.
    source
        The extract path or the Overpass URL.
    """

    def __init__(
        self,
        raw: RawMap,
        lat: float,
        lon: float,
        radius_m: float | None,
        *,
        tolerance_m: float = DEFAULT_TOLERANCE_M,
    ) -> None:
        self.frame = LocalFrame(lat=lat, lon=lon)
        self.radius_m = radius_m
        self.graph = raw.graph
        self.bounds = raw.bounds
        self.source = raw.source
        self.warnings: list[str] = list(raw.warnings)
        """Notes on the data itself (an extract ending inside the radius asked for)."""
        north_america = in_north_america(lat, lon)
        self.rejected: dict[int, str] = {}
        """``{osm node id: reason}`` for junction nodes that gave no intersection."""
        self._intersections = tuple(
            build_intersections(
                raw.graph,
                self.frame,
                tolerance_m=tolerance_m,
                radius_m=radius_m,
                north_america=north_america,
                rejected=self.rejected,
            )
        )
        self._streets = tuple(_streets_of(raw.graph, north_america))
        self._alt_names = dict(getattr(raw, "alt_names", None) or {})
        """``{street name: its other names}`` (``name:<language>``, ``alt_name``, ``old_name``...):
        a scene or query may name a street by any of them."""
        self._buildings = tuple(raw.buildings)
        self._cache: dict[str, Any] = {}
        self._cache_lock = threading.RLock()
        self._member_points: tuple[np.ndarray, np.ndarray] | None = None

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        del state["_cache_lock"]
        state["_cache"] = {}
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._cache_lock = threading.RLock()

    # -- derived data, computed once per map (thread-safe) -----------------------------

    def cached(self, key: str, build: Callable[[], _T]) -> _T:
        """``build()`` computed once per map and key, under the map's lock.

        For data derived from the map (projections, indexes, name tables) that every
        caller shares; thread-safe, and it lives as long as the map.
        """
        try:
            return self._cache[key]
        except KeyError:
            pass
        with self._cache_lock:
            if key not in self._cache:
                self._cache[key] = build()
            return self._cache[key]

    @property
    def streets_enu(self) -> tuple[LineString, ...]:
        """Street centre lines in :attr:`frame` (ENU LineStrings), aligned with :attr:`streets`."""
        return self.cached("streets_enu", lambda: project_streets(self._streets, self.frame))

    @property
    def buildings_enu(self) -> tuple[Any, ...]:
        """Building footprints in :attr:`frame` (ENU Polygons), aligned with :attr:`buildings`."""
        return self.cached("buildings_enu", lambda: project_buildings(self._buildings, self.frame))

    @property
    def street_index(self) -> LocalIndex:
        """Street centre lines (ENU) with half carriageway widths, and their STRtree."""
        return self.cached("street_index", lambda: street_index(self._streets, self.streets_enu))

    @property
    def building_index(self) -> LocalIndex:
        """Valid building footprints larger than 1 m² (ENU), and their STRtree."""
        return self.cached("building_index", lambda: building_index(self.buildings_enu))

    def __repr__(self) -> str:
        return (
            f"MapData(lat={self.frame.lat0}, lon={self.frame.lon0}, radius_m={self.radius_m}, "
            f"{len(self._intersections)} intersections, {len(self._streets)} streets, "
            f"{len(self._buildings)} buildings)"
        )

    @property
    def intersections(self) -> list[Intersection]:
        """Consolidated intersections within the radius, nearest to the point first."""
        return list(self._intersections)

    @property
    def streets(self) -> list[Street]:
        """Street segments (edges of the simplified graph, each once)."""
        return list(self._streets)

    @property
    def buildings(self) -> list[Building]:
        """Building footprints."""
        return list(self._buildings)

    # -- look-ups -----------------------------------------------------------------------

    def _dist_from(self, near: tuple[float, float] | None, lat: float, lon: float) -> float:
        lat0, lon0 = near if near is not None else (self.frame.lat0, self.frame.lon0)
        frame = LocalFrame(lat=lat0, lon=lon0)
        e, n = frame.enu_from_geographic(lat=lat, lon=lon)
        return float(math.hypot(e, n))

    def nearest_intersection(self, lat: float, lon: float) -> Intersection:
        """The intersection whose centre is nearest to a point.

        Raises
        ------
        MapDataError
            The map has no intersections.
        """
        if not self._intersections:
            raise MapDataError(
                f"no intersections within {self.radius_m} m of "
                f"lat={self.frame.lat0:.6f}, lon={self.frame.lon0:.6f}"
            )
        return min(self._intersections, key=lambda x: self._dist_from((lat, lon), x.lat, x.lon))

    def intersection(self, ident: str) -> Intersection:
        """The intersection with this id (MapDataError if unknown)."""
        for inter in self._intersections:
            if inter.id == ident:
                return inter
        raise MapDataError(f"no intersection with id {ident!r}")

    def street_names(self) -> list[str]:
        """Every street name of the map, sorted, other names (``name:<language>``,
        ``alt_name``, ``old_name``...) included."""
        names = {n for s in self._streets for n in (s.names or (s.name,))}
        names.update(s.name for x in self._intersections for s in x.streets)
        alt = getattr(self, "_alt_names", {})
        names.update(a for n in list(names) for a in alt.get(n, ()))
        return sorted(names)

    def other_names(self, name: str) -> tuple[str, ...]:
        """The other names of the street named ``name`` (``name:<language>``, ``alt_name``,
        ``old_name``, ``official_name``...), sorted; empty when it has none."""
        return getattr(self, "_alt_names", {}).get(name, ())

    def spell_streets(self, streets: str | Sequence[str]) -> tuple[list[str], list[str]]:
        """Street names that meet nowhere on this map, read as the map's names they misspell.

        Parameters
        ----------
        streets
            Two or more names (``"A & B"`` or a list), as :meth:`find_intersection` takes.

        Returns
        -------
        ``(names, notes)``. When the named streets meet somewhere, or fewer than two are
        given, the names as split and no note. Otherwise each name the map lacks is
        replaced by a map name it may misspell (:func:`~camloc_geo.osm._names.
        misspelling_matches`: one or two letters off, the same numbers); the names are
        returned corrected, with a note per corrected name, only when exactly one
        reading makes the streets meet on this map. Ambiguous or no reading: unchanged
        (:meth:`find_intersection` then refuses with close matches).

        Examples
        --------
        ``["Eastrn Avenue", "South Broadway"]`` -> ``(["Eastern Avenue", "South Broadway"],
        ["'Eastrn Avenue' is no street of this map: read as 'Eastern Avenue' ..."])``.
        """
        wanted = split_street_query(streets)
        if len(wanted) < 2 or self._street_hits(wanted):
            return wanted, []
        all_names = self.street_names()
        options: list[list[str]] = []
        for w in wanted:
            alt = misspelling_matches(w, all_names) if not self._street_hits([w]) else []
            options.append(alt or [w])
        if all(len(o) == 1 and o[0] == w for o, w in zip(options, wanted, strict=True)):
            return wanted, []
        readings = [
            list(r)
            for r in itertools.islice(itertools.product(*options), 27)
            if self._street_hits(list(r))
        ]
        if len(readings) != 1:
            return wanted, []
        notes = [
            f"{w!r} is no street of this map: read as {r!r} (the one close name that meets "
            f"the other named street{'s' if len(wanted) > 2 else ''}); check the spelling"
            for w, r in zip(wanted, readings[0], strict=True)
            if w != r
        ]
        return readings[0], notes

    def find_intersection(
        self, streets: str | Sequence[str], near: tuple[float, float] | None = None
    ) -> Intersection:
        """The intersection where the named streets meet.

        Parameters
        ----------
        streets
            ``"Eastern Avenue & South Broadway"`` (also ``/``, `` and ``, ``×``) or a list of
            names. Case, punctuation and common abbreviations do not matter (St/Street,
            Ave/Avenue, N/North...). A name that equals none exactly may match a street whose
            name contains all its words ("Broadway" for "South Broadway").
        near
            ``(lat, lon)``: among several matches take the nearest to it (default: the map's
            point).

        Raises
        ------
        MapDataError
            Fewer than two names, or the streets do not meet here; the message lists close
            matches of each name.
        """
        wanted = split_street_query(streets)
        if len(wanted) < 2:
            raise MapDataError(f"give at least two street names, got {streets!r}")
        hits = self._street_hits(wanted)
        if hits:
            return min(hits, key=lambda x: self._dist_from(near, x.lat, x.lon))
        all_names = self.street_names()
        hints = []
        for w in wanted:
            close = close_matches(w, all_names)
            hints.append(f"{w!r}: " + (", ".join(repr(c) for c in close) if close else "no match"))
        # where: the point asked about, else the map's; a whole extract has no radius
        lat0, lon0 = near if near is not None else (self.frame.lat0, self.frame.lon0)
        where = (
            f"within {self.radius_m:g} m of" if self.radius_m is not None else "in the map, near"
        )
        raise MapDataError(
            f"streets {' & '.join(repr(w) for w in wanted)} do not meet {where} "
            f"lat={lat0:.6f}, lon={lon0:.6f}; close matches: {'; '.join(hints)}"
        )

    def distance_to_m(self, inter: Intersection, *, lat: float, lon: float) -> float:
        """Distance from a point to an intersection: its centre or its nearest member node.

        A grouped intersection (a dual carriageway crossing, a one-way pair) is as near as
        the nearest of its OSM nodes, so a scene placed at any of them matches it.
        """
        frame = LocalFrame(lat=lat, lon=lon)
        pts = [(inter.lon, inter.lat), *inter.osm_node_lonlat]
        en = frame.points_enu_from_geographic(pts)
        return float(np.min(np.hypot(en[:, 0], en[:, 1])))

    def _member_lonlat(self) -> tuple[np.ndarray, np.ndarray]:
        """Every intersection's centre and member nodes (lon/lat) and the intersection of each."""
        if self._member_points is None:
            pts: list[tuple[float, float]] = []
            owner: list[int] = []
            for i, x in enumerate(self._intersections):
                for ll in ((x.lon, x.lat), *x.osm_node_lonlat):
                    pts.append(ll)
                    owner.append(i)
            self._member_points = (
                np.asarray(pts, dtype=float).reshape(-1, 2),
                np.asarray(owner, dtype=int),
            )
        return self._member_points

    def _distances_m(self, lat: float, lon: float, within_m: float | None = None) -> np.ndarray:
        """:meth:`distance_to_m` for every intersection at once (one projection).

        With ``within_m``, only the intersections that may lie that near are measured (the
        others are ``inf``): the map frame's planar distances, projected once per map, pick
        them with a margin far above that frame's distortion (under 1e-4 within 100 km of
        its anchor), so the distances within ``within_m`` are exactly those of a full run.
        """
        pts_arr, owner_arr = self._member_lonlat()
        out = np.full(len(self._intersections), np.inf)
        if not len(pts_arr):
            return out
        if within_m is not None:
            pts_en = self.cached(
                "intersection_members_enu", lambda: self.frame.points_enu_from_geographic(pts_arr)
            )
            e0, n0 = self.frame.enu_from_geographic(lat=lat, lon=lon)
            rough = np.hypot(pts_en[:, 0] - e0, pts_en[:, 1] - n0)
            near = rough <= 1.01 * within_m + 10.0
            if not near.all():
                pts_arr, owner_arr = pts_arr[near], owner_arr[near]
                if not len(pts_arr):
                    return out
        en = LocalFrame(lat=lat, lon=lon).points_enu_from_geographic(pts_arr)
        np.minimum.at(out, owner_arr, np.hypot(en[:, 0], en[:, 1]))
        return out

    def intersections_within(
        self, *, lat: float, lon: float, radius_m: float
    ) -> list[tuple[Intersection, float]]:
        """Every intersection within ``radius_m`` of a point, nearest first, with distances.

        Distances as :meth:`distance_to_m` (centre or nearest member node).
        """
        dist = self._distances_m(lat, lon, within_m=radius_m)
        order = np.argsort(dist, kind="stable")
        return [(self._intersections[i], float(dist[i])) for i in order if dist[i] <= radius_m]

    def street_junctions(self, streets: str | Sequence[str]) -> list[Intersection]:
        """Every intersection where all the named streets meet (names as
        :meth:`find_intersection`); empty when they meet nowhere on this map."""
        return self._street_hits(split_street_query(streets))

    def _street_hits(self, wanted: list[str]) -> list[Intersection]:
        """Intersections where every wanted name meets: by the streets' own names (exactly,
        else loosely: a name holding all the query's words), else with their other names
        too (``name:<language>``, ``old_name``...), exactly, else loosely."""
        norms = [normalize_name(w) for w in wanted]
        for key, with_alt in (
            ("intersection_street_names", False),
            ("intersection_street_names_alt", True),
        ):
            for loose in (False, True):
                hits = self._street_hits_in(norms, key, with_alt, loose=loose)
                if hits:
                    return hits
        return []

    def _street_hits_in(
        self, norms: list[str], key: str, with_alt: bool, *, loose: bool
    ) -> list[Intersection]:
        table, by_token = self.cached(key, lambda: self._street_name_table(with_alt))
        if with_alt and table is None:
            return []

        def matches(sets: list[frozenset[str]]) -> bool:
            for q in norms:
                q_tokens = set(q.split())
                ok = any(q in names for names in sets) or (
                    loose and any(q_tokens <= set(n.split()) for names in sets for n in names)
                )
                if not ok:
                    return False
            return True

        # only intersections whose street names hold every query's tokens can match
        maybe: set[int] | None = None
        for q in norms:
            for tok in q.split():
                hit = by_token.get(tok, set())
                maybe = set(hit) if maybe is None else maybe & hit
        order = sorted(maybe) if maybe is not None else range(len(table))
        return [self._intersections[i] for i in order if matches(table[i])]

    def _street_name_table(self, with_alt: bool = False) -> tuple[Any, dict[str, set[int]]]:
        """Every intersection's normalised street names (per street) and a token index, once
        per map (normalising them per call cost 30 ms on a city's extract, twice per locate).
        ``with_alt``: each street's other names too (None when the map has none)."""
        alt = getattr(self, "_alt_names", {}) if with_alt else {}
        if with_alt and not alt:
            return None, {}
        table = [
            [
                frozenset(
                    normalize_name(n)
                    for own in (s.names or (s.name,))
                    for n in (own, *alt.get(own, ()))
                )
                for s in x.streets
            ]
            for x in self._intersections
        ]
        by_token: dict[str, set[int]] = {}
        for i, sets in enumerate(table):
            for names in sets:
                for name in names:
                    for tok in name.split():
                        by_token.setdefault(tok, set()).add(i)
        return table, by_token

    def _describe(self, rows: Sequence[tuple[Intersection, float]], n: int = 3) -> str:
        return ", ".join(f"{x.id} ({' & '.join(x.street_names)}) at {d:.0f} m" for x, d in rows[:n])

    def match_intersection(
        self,
        *,
        lat: float | None = None,
        lon: float | None = None,
        streets: str | Sequence[str] | None = None,
        max_distance_m: float = 25.0,
    ) -> tuple[Intersection | None, list[str]]:
        """The modelled intersection a scene means, or None with the reason; never another.

        Parameters
        ----------
        lat, lon
            Where the scene says the intersection is. It matches an intersection whose
            centre or one of whose member nodes lies within ``max_distance_m``.
        streets
            Street names (``"A & B"`` or a list). With a point too, the named intersection
            must also lie within ``max_distance_m`` of it; alone, the named intersection
            nearest to the map's point is taken.
        max_distance_m
            How far from the given point a modelled intersection may be, metres.

        Returns
        -------
        ``(intersection, warnings)``. When nothing matches, the intersection is None and a
        warning names the nearest modelled intersections and their distances: the caller
        decides, nothing moves silently to another junction.
        """
        warnings: list[str] = []
        has_point = lat is not None and lon is not None
        wanted = split_street_query(streets) if streets else []
        if not has_point and not wanted:
            raise MapDataError("match_intersection needs lat/lon or street names")
        if has_point:
            assert lat is not None
            assert lon is not None
            # The usual case first: only the nodes that may lie within max_distance_m are
            # measured (the same distances); every junction only to describe a miss.
            dist = self._distances_m(lat, lon, within_m=max_distance_m)
            near = [
                (self._intersections[i], float(dist[i]))
                for i in np.argsort(dist, kind="stable")
                if dist[i] <= max_distance_m
            ]
            hits = {x.id for x in self._street_hits(wanted)} if wanted else set()
            if wanted:
                named_near = [(x, d) for x, d in near if x.id in hits]
                if named_near:
                    return named_near[0][0], warnings
            elif near:
                return near[0][0], warnings
            dist = self._distances_m(lat, lon)
            rows = [
                (self._intersections[i], float(dist[i])) for i in np.argsort(dist, kind="stable")
            ]
            where = f"lat={lat:.6f}, lon={lon:.6f}"
            if wanted:
                named_all = [(x, d) for x, d in rows if x.id in hits]
                names = " & ".join(repr(w) for w in wanted)
                if named_all:
                    warnings.append(
                        f"the scene's intersection {names} is {named_all[0][1]:.0f} m from its "
                        f"lat/lon ({where}), more than {max_distance_m:.0f} m: "
                        f"{self._describe(named_all, 1)}"
                        + (
                            f"; modelled junctions near the point: {self._describe(near)}"
                            if near
                            else ""
                        )
                    )
                else:
                    warnings.append(
                        f"no modelled junction of {names} in the map; "
                        + (f"near {where}: {self._describe(rows)}" if rows else "no junctions")
                    )
                return None, warnings
            warnings.append(
                f"no modelled junction within {max_distance_m:.0f} m of the scene's "
                f"intersection ({where}); nearest: "
                + (self._describe(rows) if rows else "none in the map")
            )
            return None, warnings
        named = self._street_hits(wanted)
        if named:
            best = min(named, key=lambda x: self._dist_from(None, x.lat, x.lon))
            return best, warnings
        all_names = self.street_names()
        hints = []
        for w in wanted:
            close = close_matches(w, all_names)
            hints.append(f"{w!r}: " + (", ".join(repr(c) for c in close) if close else "no match"))
        warnings.append(
            f"no modelled junction of {' & '.join(repr(w) for w in wanted)} within "
            f"{self.radius_m} m of lat={self.frame.lat0:.6f}, lon={self.frame.lon0:.6f}; "
            f"close matches: {'; '.join(hints)}"
        )
        return None, warnings

    def street_bearings(
        self, lat: float, lon: float, radius_m: float = 50.0
    ) -> list[tuple[str, float]]:
        """Streets passing within ``radius_m`` of a point and their local bearings.

        Returns
        -------
        ``(name, bearing_deg)`` pairs, nearest street first; the bearing (in [0, 180),
        osmnx's :func:`~osmnx.bearing.calculate_bearing`) is that of the street over
        ±10 m around its point nearest to the query point. A street is listed once per
        distinct direction (5° apart).
        """
        e, n = self.frame.enu_from_geographic(lat=lat, lon=lon)
        pt = Point(float(e), float(n))
        rows: list[tuple[float, str, float]] = []
        lines = self.streets_enu
        tree = self.cached("streets_enu_tree", lambda: _strtree(lines))
        near = np.sort(tree.query(pt, predicate="dwithin", distance=radius_m))
        if len(near):
            # Every near street at once (GEOS's distance, project and interpolate over
            # arrays, one projection back to lon/lat): the numbers of one call per street.
            geoms = tree.geometries[near]
            dist = shapely.distance(geoms, pt)
            length = shapely.length(geoms)
            keep = ~((dist > radius_m) | (length < 0.5))
            near, geoms, dist, length = near[keep], geoms[keep], dist[keep], length[keep]
        if len(near):
            s = shapely.line_locate_point(geoms, pt)
            a = shapely.get_coordinates(
                shapely.line_interpolate_point(geoms, np.maximum(0.0, s - 10.0))
            )
            b = shapely.get_coordinates(
                shapely.line_interpolate_point(geoms, np.minimum(length, s + 10.0))
            )
            ll_a = self.frame.points_geographic_from_enu(a).tolist()
            ll_b = self.frame.points_geographic_from_enu(b).tolist()
            for i, d, (lon_a, lat_a), (lon_b, lat_b) in zip(
                near.tolist(), dist.tolist(), ll_a, ll_b, strict=True
            ):
                brg = initial_bearing_deg(lat1=lat_a, lon1=lon_a, lat2=lat_b, lon2=lon_b) % 180.0
                rows.append((d, self._streets[i].name, brg))
        rows.sort()
        out: list[tuple[str, float]] = []
        for _d, name, brg in rows:
            if any(
                name == n2 and min(abs(brg - b2), 180.0 - abs(brg - b2)) < 5.0 for n2, b2 in out
            ):
                continue
            out.append((name, brg))
        return out

    def find_building(self, name: str, near: tuple[float, float] | None = None) -> Building:
        """The building with this name (``name``, ``addr:housename`` or ``brand``).

        Exact normalised matches win over names containing all the query's words; among
        several, the nearest to ``near`` (default: the map's point).

        Raises
        ------
        MapDataError
            No such building; the message lists close matches.
        """
        q = normalize_name(name)
        named = [b for b in self._buildings if b.name]
        for loose in (False, True):
            hits = [
                b
                for b in named
                if (normalize_name(b.name or "") == q)
                or (loose and set(q.split()) <= set(normalize_name(b.name or "").split()))
            ]
            if hits:
                return min(hits, key=lambda b: self._dist_from(near, b.centroid[1], b.centroid[0]))
        close = close_matches(name, [b.name for b in named if b.name])
        raise MapDataError(
            f"no building named {name!r} within {self.radius_m} m of "
            f"lat={self.frame.lat0:.6f}, lon={self.frame.lon0:.6f}; close matches: "
            + (", ".join(repr(c) for c in close) if close else "none")
        )


def load_map(
    source: str | os.PathLike[str] | None,
    lat: float,
    lon: float,
    radius_m: float | None = 300.0,
    *,
    cache_folder: str | os.PathLike[str] | None = None,
    overpass_url: str | None = None,
    overpass_rate_limit: bool = True,
    timeout_s: float = 60.0,
    tolerance_m: float = DEFAULT_TOLERANCE_M,
    highways: frozenset[str] = STREET_HIGHWAYS,
    named_highways: frozenset[str] = NAMED_STREET_HIGHWAYS,
) -> MapData:
    """Load streets, intersections and buildings around a point.

    Parameters
    ----------
    source
        Path to an ``.osm``, ``.osm.gz``, ``.osm.bz2`` or ``.osm.pbf`` extract; None queries
        Overpass live through osmnx.
    lat, lon
        The point, degrees WGS 84; the map's frame is anchored there.
    radius_m
        Intersections within this distance of the point are built; None: the whole extract
        (files only).
    cache_folder
        osmnx HTTP cache folder (online only; default: osmnx's).
    overpass_url
        Overpass API base URL (online only; default: osmnx's).
    overpass_rate_limit
        Let osmnx ask the server for a slot before querying (online only).
    timeout_s
        HTTP timeout, seconds (online only).
    tolerance_m
        Intersection consolidation buffer, metres.
    highways
        ``highway`` values forming the street network.
    named_highways
        ``highway`` values that are streets when named (named service streets and alleys,
        pedestrian segments of named streets).

    Returns
    -------
    The map; the same object again for the same file (unchanged), area and options.

    Raises
    ------
    MapDataError
        Unreadable or empty extract, point outside it, no streets there, bad arguments.
    MapSourceError
        Overpass could not be reached or failed.
    """
    if not (math.isfinite(lat) and math.isfinite(lon)) or not (
        -90.0 <= lat <= 90.0 and -180.0 <= lon <= 180.0
    ):
        raise MapDataError(f"invalid point lat={lat}, lon={lon}")
    if radius_m is not None and not (math.isfinite(radius_m) and radius_m > 0):
        raise MapDataError(f"radius_m must be a positive number of metres, got {radius_m}")
    options: tuple[Any, ...] = (
        round(float(lat), 7),
        round(float(lon), 7),
        radius_m,
        tolerance_m,
        tuple(sorted(highways)),
        tuple(sorted(named_highways)),
    )
    raw: RawMap
    if source is None:
        if radius_m is None:
            raise MapDataError("radius_m is required when loading from Overpass")
        key: tuple[Any, ...] = ("overpass", overpass_url, *options)
        cached = cache_get(key)
        if cached is not None:
            return cached
        raw = read_overpass(
            lat,
            lon,
            radius_m,
            cache_folder=cache_folder,
            overpass_url=overpass_url,
            overpass_rate_limit=overpass_rate_limit,
            timeout_s=timeout_s,
            highways=highways,
            named_highways=named_highways,
        )
    else:
        path = Path(source).expanduser()
        try:
            stat = path.resolve().stat()
            key = ("file", str(path.resolve()), stat.st_mtime_ns, stat.st_size, *options)
        except OSError:
            key = ("file", str(path), *options)
        cached = cache_get(key)
        if cached is not None:
            log.debug("map cache hit for %s", path)
            return cached
        kept = disk_get(key)  # built by an earlier process (camloc_geo.osm._diskcache)
        if isinstance(kept, MapData):
            cache_put(key, kept)
            return kept
        raw = read_extract(
            path, lat, lon, radius_m, highways=highways, named_highways=named_highways
        )
    result = MapData(raw, lat, lon, radius_m, tolerance_m=tolerance_m)
    cache_put(key, result)
    if source is not None:
        disk_put(key, result)
    return result
