"""Loading OSM data around a point: local extracts (pyosmium) or live Overpass (osmnx).

Offline, the extract (PBF or XML, plain/gzip/bzip2) is read once with pyosmium, keeping
only the street ways (:data:`STREET_HIGHWAYS`) and building ways that have a node within
``radius_m + CLIP_MARGIN_M`` of the point; ways are kept whole, so every street through a
kept intersection is complete. Each way's geometry is built in C++ (WKB) and its nodes are
only visited in Python when it is kept. The street graph is built from the ways by
:mod:`camloc_geo.osm._graph`, which follows :func:`osmnx.graph_from_xml` and
:func:`osmnx.simplify_graph` (nodes kept where name, highway, lanes, width or junction
change) without importing osmnx.
Buildings are closed ``building=*`` ways (multipolygon building relations are skipped
offline; online, osmnx returns them and the largest polygon is kept).

Online, :func:`osmnx.graph_from_point` (same highway filter, as an Overpass
``custom_filter``) and :func:`osmnx.features_from_point` query Overpass with osmnx's HTTP
cache. osmnx settings are changed only inside :func:`osmnx_settings`, which restores them.

Loaded maps are cached in process (least recently used, :data:`_CACHE_SIZE` maps), keyed by
file path, modification time and size, the point, the radius and the options (or the
Overpass URL), so the same area is not parsed twice.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import threading
from collections import OrderedDict
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import networkx as nx
import numpy as np
import osmium
import shapely

from camloc_geo._errors import MapDataError, MapSourceError
from camloc_geo.geodesy import GEOD
from camloc_geo.osm._graph import alt_names_by_name, graph_from_ways, simplify_graph
from camloc_geo.osm._model import Building, polygon_from_lonlat
from camloc_geo.osm._widths import parse_lanes, parse_width_m

__all__ = [
    "CLIP_MARGIN_M",
    "EXTRACT_SUFFIXES",
    "NAMED_STREET_HIGHWAYS",
    "STREET_HIGHWAYS",
    "RawMap",
    "clear_cache",
    "header_box",
    "osmnx_settings",
    "read_extract",
    "read_overpass",
]

log = logging.getLogger(__name__)

STREET_HIGHWAYS: frozenset[str] = frozenset(
    {
        "motorway",
        "trunk",
        "primary",
        "secondary",
        "tertiary",
        "unclassified",
        "residential",
        "living_street",
        "road",
        "busway",
        "motorway_link",
        "trunk_link",
        "primary_link",
        "secondary_link",
        "tertiary_link",
    }
)
"""``highway`` values that form the street network (no service roads, paths or footways)."""

NAMED_STREET_HIGHWAYS: frozenset[str] = frozenset({"service", "pedestrian"})
"""``highway`` values that are streets when they carry a ``name`` (and are not areas): named
service streets and alleys (row-house streets, ``service=alley``) and pedestrian segments of
named streets, so their junctions exist and they are junction arms."""

CLIP_MARGIN_M = 60.0
"""Data is kept this far beyond the requested radius so edge clusters are complete."""

EXTRACT_SUFFIXES = (".osm", ".osm.gz", ".osm.bz2", ".osm.pbf", ".pbf", ".xml", ".osm.xml")

_BUILDING_KEYS = ("name", "addr:housename", "brand", "height", "building:levels", "building")


@dataclass
class RawMap:
    """What a source yields before intersections are built."""

    graph: nx.MultiDiGraph
    buildings: list[Building] = field(default_factory=list)
    bounds: tuple[float, float, float, float] | None = None  # (south, west, north, east)
    source: str = ""
    warnings: list[str] = field(default_factory=list)
    alt_names: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """``{street name: its other names}`` (``name:<language>``, ``alt_name``, ``old_name``...)."""


_SETTINGS_LOCK = threading.RLock()


def _osmnx() -> Any:
    """osmnx, imported on first use (half a second: it pulls in geopandas and matplotlib)."""
    import osmnx

    return osmnx


@contextlib.contextmanager
def osmnx_settings(**values: Any) -> Iterator[None]:
    """Set ``osmnx.settings`` attributes for the duration of a block, then restore them.

    Values that are None are left alone.
    """
    ox = _osmnx()
    saved: dict[str, Any] = {}
    with _SETTINGS_LOCK:
        try:
            for key, value in values.items():
                if value is None:
                    continue
                saved[key] = getattr(ox.settings, key)
                setattr(ox.settings, key, value)
            yield
        finally:
            for key, value in saved.items():
                setattr(ox.settings, key, value)


def _clip_box(lat: float, lon: float, radius_m: float) -> tuple[float, float, float, float]:
    """(south, west, north, east) of the box enclosing a circle, degrees."""
    _lon, north, _ = GEOD.fwd(lon, lat, 0.0, radius_m)
    _lon, south, _ = GEOD.fwd(lon, lat, 180.0, radius_m)
    east, _lat, _ = GEOD.fwd(lon, lat, 90.0, radius_m)
    west, _lat, _ = GEOD.fwd(lon, lat, 270.0, radius_m)
    return float(south), float(west), float(north), float(east)


def _num(value: str | None) -> float | None:
    if value is None:
        return None
    return parse_lanes(value) if value else None


def _building_from_tags(ident: str, tags: dict[str, str], poly: Any) -> Building:
    name = tags.get("name") or tags.get("addr:housename") or tags.get("brand") or None
    return Building(
        id=ident,
        name=name,
        footprint=poly,
        height_m=parse_width_m(tags.get("height"), max_m=1000.0),
        levels=_num(tags.get("building:levels")),
        building=tags.get("building") or "yes",
    )


def _check_extract_path(path: Path) -> None:
    if not path.exists():
        raise MapDataError(f"OSM extract not found: {path}")
    if not path.is_file():
        raise MapDataError(f"OSM extract is not a file: {path}")
    name = path.name.lower()
    if not name.endswith(EXTRACT_SUFFIXES):
        raise MapDataError(
            f"unsupported OSM extract {path.name!r}: expected .osm, .osm.gz, .osm.bz2 or .osm.pbf"
        )
    if path.stat().st_size == 0:
        raise MapDataError(f"OSM extract is empty: {path}")


def header_box(path: Path) -> tuple[float, float, float, float] | None:
    """``(south, west, north, east)`` declared in the extract's header, or None.

    Only a hint (clipped extracts hold data beyond it): choosing which extract of a folder
    covers a point; the map itself uses the data's own extent.
    """
    try:
        reader = osmium.io.Reader(str(path), osmium.osm.NOTHING)
        try:
            box = reader.header().box()
        finally:
            reader.close()
    except RuntimeError:
        return None
    if not box.valid():
        return None
    return (box.bottom_left.lat, box.bottom_left.lon, box.top_right.lat, box.top_right.lon)


_WKB_LINESTRING_LE = "0102000000"
"""Hex WKB header of a little-endian 2-D linestring without SRID (pyosmium's output)."""


def _linestring_xy(wkb_hex: str) -> np.ndarray:
    """``(N, 2)`` lon/lat of pyosmium's hex WKB linestring.

    The doubles are read straight from the WKB (byte order, type and point count take
    9 bytes): the same values ``shapely.get_coordinates(shapely.from_wkb(...))`` gives, at a
    third of the cost per way (the way loop is most of an extract's load time). Any other
    WKB flavour goes through shapely.
    """
    if wkb_hex.startswith(_WKB_LINESTRING_LE):
        return np.frombuffer(bytes.fromhex(wkb_hex), dtype="<f8", offset=9).reshape(-1, 2)
    return np.asarray(shapely.get_coordinates(shapely.from_wkb(wkb_hex)), dtype=float)


def read_extract(
    path: Path,
    lat: float,
    lon: float,
    radius_m: float | None,
    *,
    highways: frozenset[str] = STREET_HIGHWAYS,
    named_highways: frozenset[str] = NAMED_STREET_HIGHWAYS,
) -> RawMap:
    """Read the streets and buildings of an extract around a point.

    Parameters
    ----------
    path
        ``.osm``, ``.osm.gz``, ``.osm.bz2`` or ``.osm.pbf`` file.
    lat, lon
        The point, degrees.
    radius_m
        Keep ways with a node within ``radius_m + CLIP_MARGIN_M``; None keeps everything.
    highways
        ``highway`` values to keep as streets.
    named_highways
        ``highway`` values kept as streets when the way has a ``name`` and is not an area.

    Raises
    ------
    MapDataError
        Unreadable or empty extract, point outside the data it holds, or no streets near
        the point.
    """
    _check_extract_path(path)
    box = None if radius_m is None else _clip_box(lat, lon, radius_m + CLIP_MARGIN_M)
    street_ways: list[tuple[int, dict[str, str], list[tuple[int, float, float]]]] = []
    buildings: list[Building] = []
    s_min, w_min, n_max, e_max = math.inf, math.inf, -math.inf, -math.inf
    n_ways = 0
    wkb_factory = osmium.geom.WKBFactory()
    try:
        processor = (
            osmium.FileProcessor(str(path), osmium.osm.NODE | osmium.osm.WAY)
            .with_locations()
            .with_filter(osmium.filter.EntityFilter(osmium.osm.WAY))
            .with_filter(osmium.filter.KeyFilter("highway", "building"))
        )
        for way in processor:
            if not isinstance(way, osmium.osm.Way):
                continue
            n_ways += 1
            highway = way.tags.get("highway")
            is_street = highway in highways or (
                highway in named_highways and "name" in way.tags and way.tags.get("area") != "yes"
            )
            is_building = "building" in way.tags and not is_street
            if not (is_street or is_building):
                continue
            # one C++ call builds the geometry (WKB); nodes are visited in Python only if kept
            try:
                xy = _linestring_xy(wkb_factory.create_linestring(way))
            except (osmium.InvalidLocationError, RuntimeError, ValueError):
                # a way clipped at the extract's edge: keep the part the extract holds
                part = [
                    (nd.location.lon, nd.location.lat) for nd in way.nodes if nd.location.valid()
                ]
                if len(part) < 2:
                    continue
                xy = np.asarray(part, dtype=float)
            xs, ys = xy[:, 0], xy[:, 1]
            (x0, y0), (x1, y1) = xy.min(axis=0).tolist(), xy.max(axis=0).tolist()
            s_min, n_max = min(s_min, y0), max(n_max, y1)
            w_min, e_max = min(w_min, x0), max(e_max, x1)
            if box is not None and (
                y1 < box[0]
                or y0 > box[2]
                or x1 < box[1]
                or x0 > box[3]
                or not np.any((box[0] <= ys) & (ys <= box[2]) & (box[1] <= xs) & (xs <= box[3]))
            ):
                continue
            nodes = [
                (nd.ref, nd.location.lat, nd.location.lon)
                for nd in way.nodes
                if nd.location.valid()
            ]
            if len(nodes) < 2:
                continue
            if is_street:
                street_ways.append((way.id, dict(way.tags), nodes))
            elif way.is_closed() and len(nodes) >= 4:
                poly = polygon_from_lonlat([(x, y) for _r, y, x in nodes])
                if poly is not None:
                    tags = {k: way.tags[k] for k in _BUILDING_KEYS if k in way.tags}
                    buildings.append(_building_from_tags(f"way/{way.id}", tags, poly))
    except RuntimeError as exc:  # osmium's parse errors
        raise MapDataError(f"cannot read OSM extract {path.name}: {exc}") from exc
    except osmium.InvalidLocationError as exc:  # <node lat="999"> or lat="abc"
        raise MapDataError(
            f"cannot read OSM extract {path.name}: a node's coordinates are not a location ({exc})"
        ) from exc
    except (OSError, EOFError, ValueError) as exc:
        raise MapDataError(f"cannot read OSM extract {path.name}: {exc}") from exc

    if n_ways == 0 or not math.isfinite(s_min):
        raise MapDataError(f"OSM extract {path.name} holds no streets or buildings")
    # the data's own extent, not the header's declared box: clipped extracts hold whole
    # ways a few metres beyond it, and a box may declare more than the data covers
    bounds = (s_min, w_min, n_max, e_max)
    inside = bounds[0] <= lat <= bounds[2] and bounds[1] <= lon <= bounds[3]
    if radius_m is not None and not inside:
        raise MapDataError(
            f"point lat={lat:.6f}, lon={lon:.6f} is outside the extract {path.name} "
            f"(its streets and buildings cover lat {bounds[0]:.5f}..{bounds[2]:.5f}, "
            f"lon {bounds[1]:.5f}..{bounds[3]:.5f})"
        )
    warnings = []
    if radius_m is not None:
        edges = _edge_distances_m(lat, lon, bounds)
        thin = {side: d for side, d in edges.items() if d < radius_m}
        if thin:
            sides = ", ".join(f"{d:.0f} m to the {side}" for side, d in thin.items())
            warnings.append(
                f"the extract {path.name} ends {sides} of lat={lat:.6f}, lon={lon:.6f}, "
                f"inside the {radius_m:.0f} m asked for: junctions beyond are missing"
            )
    if not street_ways:
        if radius_m is None or radius_m >= max(_edge_distances_m(lat, lon, bounds).values()) * 2:
            # the whole extract was searched: its size, not the radius, says it
            raise MapDataError(f"OSM extract {path.name} holds buildings but no streets")
        raise MapDataError(
            f"no streets within {radius_m:.0f} m of lat={lat:.6f}, lon={lon:.6f} in {path.name}"
        )
    graph = _graph_from_ways(street_ways)
    return RawMap(
        graph=graph,
        buildings=buildings,
        bounds=bounds,
        source=str(path),
        warnings=warnings,
        alt_names=alt_names_by_name(street_ways),
    )


def _edge_distances_m(
    lat: float, lon: float, bounds: tuple[float, float, float, float]
) -> dict[str, float]:
    """Distance from a point inside a box to each of its sides, metres."""
    south, west, north, east = bounds
    out = {}
    for side, (lon2, lat2) in {
        "south": (lon, south),
        "north": (lon, north),
        "west": (west, lat),
        "east": (east, lat),
    }.items():
        _a, _b, dist = GEOD.inv(lon, lat, lon2, lat2)
        out[side] = float(dist)
    return out


def _graph_from_ways(
    ways: list[tuple[int, dict[str, str], list[tuple[int, float, float]]]],
) -> nx.MultiDiGraph:
    """The simplified street graph of the ways (osmnx's, built without importing osmnx)."""
    return simplify(graph_from_ways(ways))


SIMPLIFY_EDGE_ATTRS_DIFFER = ("name", "highway", "lanes", "width", "junction")
"""Graph nodes where these tags change are kept, so every simplified edge has one value of
each (osmnx would otherwise merge them into lists in arbitrary order)."""


def simplify(graph: nx.MultiDiGraph) -> nx.MultiDiGraph:
    """osmnx's simplification keeping nodes where :data:`SIMPLIFY_EDGE_ATTRS_DIFFER` change."""
    return simplify_graph(graph, edge_attrs_differ=SIMPLIFY_EDGE_ATTRS_DIFFER)


def overpass_filter(
    highways: frozenset[str], named_highways: frozenset[str] = frozenset()
) -> list[str]:
    """The osmnx ``custom_filter`` (a union of filters) selecting the street ways."""
    alternatives = "|".join(sorted(highways))
    filters = [f'["highway"~"^({alternatives})$"]["area"!~"yes"]']
    if named_highways:
        named = "|".join(sorted(named_highways))
        filters.append(f'["highway"~"^({named})$"]["name"]["area"!~"yes"]')
    return filters


CONNECT_TIMEOUT_S = 5.0
"""How long to wait for the Overpass server to accept a connection, seconds."""

_OFFLINE_HINT = "give --osm EXTRACT (a local OSM extract) to work without the network"


def probe_server(url: str, timeout_s: float) -> str | None:
    """None when a TCP connection to the URL's host opens within ``timeout_s``.

    Otherwise why not: ``"timeout"``, ``"connection refused"``, ``"unknown host"``...
    """
    import socket
    from urllib.parse import urlsplit

    parts = urlsplit(url)
    host = parts.hostname
    if not host:
        return "no host in the URL"
    try:
        port = parts.port or (443 if parts.scheme == "https" else 80)
    except ValueError:
        return "bad port in the URL"
    try:
        with socket.create_connection((host, port), timeout=timeout_s):
            return None
    except TimeoutError:
        return "timeout"
    except socket.gaierror:
        return "unknown host"
    except ConnectionRefusedError:
        return "connection refused"
    except OSError as exc:
        return exc.strerror or type(exc).__name__


def read_overpass(
    lat: float,
    lon: float,
    radius_m: float,
    *,
    cache_folder: str | os.PathLike[str] | None = None,
    overpass_url: str | None = None,
    overpass_rate_limit: bool = True,
    timeout_s: float = 60.0,
    highways: frozenset[str] = STREET_HIGHWAYS,
    connect_timeout_s: float = CONNECT_TIMEOUT_S,
    named_highways: frozenset[str] = NAMED_STREET_HIGHWAYS,
) -> RawMap:
    """Query streets and buildings around a point from Overpass through osmnx.

    The server is first probed with a TCP connection of ``connect_timeout_s``: when it does
    not answer in time the call fails at once (osmnx would otherwise wait its rate-limit
    pause, 60 s, then the full HTTP timeout). When the connection is refused or the name
    does not resolve, osmnx still runs without its rate-limit query, so answers in its HTTP
    cache are served and anything else fails immediately.

    Raises
    ------
    MapSourceError
        The server could not be reached or answered with an error.
    MapDataError
        The server returned no streets there.
    """
    settings: dict[str, Any] = {
        "use_cache": True,
        "overpass_rate_limit": overpass_rate_limit,
        "requests_timeout": timeout_s,
        "log_console": False,
    }
    if cache_folder is not None:
        settings["cache_folder"] = str(cache_folder)
    if overpass_url is not None:
        settings["overpass_url"] = overpass_url.rstrip("/")
    where = f"lat={lat:.6f}, lon={lon:.6f}"
    import requests

    ox = _osmnx()
    url = overpass_url or ox.settings.overpass_url
    problem = probe_server(url, connect_timeout_s)
    if problem == "timeout":
        raise MapSourceError(
            f"cannot reach the Overpass server {url} (no answer in {connect_timeout_s:g} s): "
            f"{_OFFLINE_HINT}"
        )
    if problem is not None:
        settings["overpass_rate_limit"] = False
    try:
        with osmnx_settings(**settings):
            graph = ox.graph_from_point(
                (lat, lon),
                dist=radius_m + CLIP_MARGIN_M,
                dist_type="bbox",
                simplify=False,
                retain_all=True,
                truncate_by_edge=True,
                custom_filter=overpass_filter(highways, named_highways),
            )
            graph = simplify(graph)
            try:
                features = ox.features_from_point(
                    (lat, lon), tags={"building": True}, dist=radius_m
                )
            except ox._errors.InsufficientResponseError:
                features = None
    except ox._errors.InsufficientResponseError as exc:
        if "responded" in str(exc):  # osmnx: the reply was not JSON (an error page)
            raise MapSourceError(
                f"unreadable answer from the Overpass server for {where}: {exc}"
            ) from exc
        raise MapDataError(
            f"Overpass returned no streets within {radius_m:.0f} m of {where}"
        ) from exc
    except ox._errors.ResponseStatusCodeError as exc:
        raise MapSourceError(f"Overpass server error for {where}: {exc}") from exc
    except requests.exceptions.RequestException as exc:
        raise MapSourceError(
            f"cannot reach the Overpass server {url} ({problem or type(exc).__name__}): "
            f"{_OFFLINE_HINT}"
        ) from exc
    except ValueError as exc:  # a reply that is not Overpass JSON
        raise MapSourceError(
            f"unreadable answer from the Overpass server for {where}: {exc}"
        ) from exc
    buildings: list[Building] = []
    if features is not None and len(features):
        for idx, row in features.iterrows():
            geom = row.geometry
            if geom is None or geom.geom_type not in ("Polygon", "MultiPolygon"):
                continue
            if geom.geom_type == "MultiPolygon":
                geom = max(geom.geoms, key=lambda g: g.area)
            tags = {
                k: str(row[k])
                for k in _BUILDING_KEYS
                if k in row.index and isinstance(row[k], str) and row[k]
            }
            element, osm_id = idx if isinstance(idx, tuple) else ("way", idx)
            buildings.append(_building_from_tags(f"{element}/{osm_id}", tags, geom))
    return RawMap(graph=graph, buildings=buildings, source=overpass_url or "overpass")


_CACHE: OrderedDict[tuple[Any, ...], Any] = OrderedDict()
_CACHE_SIZE = 16
_CACHE_LOCK = threading.Lock()


def cache_get(key: tuple[Any, ...]) -> Any:
    """Cached value for a key (moved to most recent), or None."""
    with _CACHE_LOCK:
        value = _CACHE.get(key)
        if value is not None:
            _CACHE.move_to_end(key)
        return value


def cache_put(key: tuple[Any, ...], value: Any) -> None:
    """Store a value, evicting the least recently used beyond the cache size."""
    with _CACHE_LOCK:
        _CACHE[key] = value
        _CACHE.move_to_end(key)
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.popitem(last=False)


def clear_cache() -> None:
    """Forget every map loaded in this process."""
    with _CACHE_LOCK:
        _CACHE.clear()
