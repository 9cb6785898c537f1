"""The name index of a map: every OSM name of its streets, junctions, addresses, landmarks.

Built once per :class:`~camloc_geo.osm.MapData` by :func:`index_for` and cached on the map
object (thread-safe). Sources:

- the map's street graph (``name``, else ``ref``, as the loader keeps them) and its
  junction model (each incident street of each intersection);
- when the map was read from a file, one more pass over the extract with pyosmium
  (about 0.1 s for a city-centre extract) for what the loader does not keep: every name
  tag of every ``highway`` way (``name``, ``alt_name``, ``old_name``, ``official_name``,
  ``short_name``, ``loc_name``, ``ref``, ``name:*``...), the geometry of named ways the
  street graph leaves out (``service``, ``pedestrian``, ``footway``...: the geometric
  junction fallback needs them), ``addr:*`` addresses, and named features (landmarks).
  When the map was loaded with a radius, only what lies within it (plus a margin) is kept.
"""

from __future__ import annotations

import logging
import math
import re
import threading
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from shapely.geometry import LineString

from camloc_geo.geocode._normalize import core_tokens, fold, name_tokens

if TYPE_CHECKING:
    from camloc_geo.osm import Intersection, MapData

__all__ = ["NAME_TAG_RE", "GeocodeIndex", "Landmark", "index_for"]

log = logging.getLogger(__name__)

NAME_TAG_RE = re.compile(
    r"^(?:name|alt_name|old_name|official_name|short_name|loc_name|reg_name|nat_name|int_name"
    r"|name_\d|ref|alt_ref|old_ref|official_ref)(?::.*)?$"
)
"""OSM keys whose values name a street or feature (``name:*`` and the like included)."""

INDEX_MARGIN_M = 300.0
"""With a map loaded around a point, file features this far beyond its radius are kept."""

_ATTR = "_camloc_geocode_index"
_LOCK = threading.Lock()
_LANDMARK_SKIP_KEYS = ("highway", "route", "boundary", "type")


def names_from_tags(tags: dict[str, str]) -> list[str]:
    """Every name in the name tags of an OSM object (values split at ``;``), ``name`` first."""
    out: list[str] = []
    keys = sorted((k for k in tags if NAME_TAG_RE.match(k)), key=lambda k: (k != "name", k))
    for key in keys:
        for value in tags[key].split(";"):
            value = value.strip()
            if value and value not in out:
                out.append(value)
    return out


@dataclass(frozen=True)
class Landmark:
    """A named OSM feature (or ``addr:*`` address) with a point."""

    name: str
    lat: float
    lon: float
    kind: str  # e.g. "amenity=townhall", "place=suburb", "address"
    osm_id: str


@dataclass
class GeocodeIndex:
    """Normalised names -> streets, junctions, addresses and landmarks of one map."""

    displays: dict[tuple[str, ...], list[str]] = field(default_factory=lambda: defaultdict(list))
    by_core: dict[tuple[str, ...], set[tuple[str, ...]]] = field(
        default_factory=lambda: defaultdict(set)
    )
    junctions: dict[tuple[str, ...], list[tuple[int, int]]] = field(
        default_factory=lambda: defaultdict(list)
    )
    lines: dict[tuple[str, ...], list[LineString]] = field(
        default_factory=lambda: defaultdict(list)
    )
    addresses: dict[tuple[tuple[str, ...], str], list[Landmark]] = field(
        default_factory=lambda: defaultdict(list)
    )
    landmarks: dict[tuple[str, ...], list[Landmark]] = field(
        default_factory=lambda: defaultdict(list)
    )
    landmark_core: dict[tuple[str, ...], set[tuple[str, ...]]] = field(
        default_factory=lambda: defaultdict(set)
    )
    vocab: list[str] = field(default_factory=list)
    vocab_set: frozenset[str] = frozenset()
    core_choices: list[str] = field(default_factory=list)
    full_choices: list[str] = field(default_factory=list)
    compact_choices: list[str] = field(default_factory=list)
    compact_full: dict[str, tuple[str, ...]] = field(default_factory=dict)
    landmark_choices: list[str] = field(default_factory=list)
    intersections: list[Intersection] = field(default_factory=list)
    cache: dict[Any, Any] = field(default_factory=dict)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def add_street_name(self, name: str) -> tuple[str, ...]:
        toks = name_tokens(name)
        if not toks:
            return toks
        shown = self.displays[toks]
        if name not in shown:
            shown.append(name)
        self.by_core[core_tokens(toks)].add(toks)
        return toks

    def add_landmark(self, mark: Landmark) -> None:
        toks = name_tokens(mark.name)
        if not toks:
            return
        self.landmarks[toks].append(mark)
        self.landmark_core[core_tokens(toks)].add(toks)

    def finish(self) -> None:
        vocab = {t for core in self.by_core for t in core}
        self.vocab = sorted(vocab)
        self.vocab_set = frozenset(vocab)
        self.core_choices = [" ".join(c) for c in self.by_core]
        self.full_choices = [" ".join(f) for f in self.displays]
        self.compact_full = {"".join(f): f for f in self.displays}
        self.compact_choices = list(self.compact_full)
        self.landmark_choices = [" ".join(f) for f in self.landmarks]

    def display(self, toks: tuple[str, ...]) -> str:
        shown = self.displays.get(toks)
        return shown[0] if shown else " ".join(toks)


def _way_ids_of_edge(map_data: MapData, u: int, v: int) -> list[int]:
    G = map_data.graph
    out: list[int] = []
    for a, b in ((u, v), (v, u)):
        data = G.get_edge_data(a, b)
        if not data:
            continue
        for edge in data.values():
            osmid = edge.get("osmid")
            for i in osmid if isinstance(osmid, list) else [osmid]:
                if i is not None:
                    out.append(int(i))
    return out


def _within(map_data: MapData) -> Any:
    if map_data.radius_m is None:
        return lambda lat, lon: True
    lat0, lon0 = map_data.frame.lat0, map_data.frame.lon0
    limit = map_data.radius_m + INDEX_MARGIN_M
    kx = 111_320.0 * math.cos(math.radians(lat0))

    def inside(lat: float, lon: float) -> bool:
        return math.hypot((lon - lon0) * kx, (lat - lat0) * 110_574.0) <= limit

    return inside


@dataclass
class _FileScan:
    way_names: dict[int, list[str]] = field(default_factory=dict)
    extra_lines: list[tuple[list[str], LineString]] = field(default_factory=list)
    addresses: list[tuple[str, str, Landmark]] = field(default_factory=list)
    landmarks: list[Landmark] = field(default_factory=list)


def _scan_file(path: Path, map_data: MapData) -> _FileScan:
    """What the street loader does not keep: all names, minor ways, addresses, features."""
    import osmium

    scan = _FileScan()
    inside = _within(map_data)
    graph_ways: set[int] = set()
    for _u, _v, data in map_data.graph.edges(data=True):
        osmid = data.get("osmid")
        for i in osmid if isinstance(osmid, list) else [osmid]:
            if i is not None:
                graph_ways.add(int(i))
    processor = (
        osmium.FileProcessor(str(path), osmium.osm.NODE | osmium.osm.WAY)
        .with_locations()
        .with_filter(osmium.filter.EmptyTagFilter())
    )
    for obj in processor:
        tags = dict(obj.tags)
        names = names_from_tags(tags)
        housenumber = tags.get("addr:housenumber")
        if not names and not housenumber:
            continue
        is_way = isinstance(obj, osmium.osm.Way)
        if isinstance(obj, osmium.osm.Way):
            # located nodes only: ways crossing the extract's edge keep their inside part
            pts = [(nd.lon, nd.lat) for nd in obj.nodes if nd.location.valid()]
            if len(pts) < 2:
                continue
            xs = [p[0] for p in pts]
            ys = [p[1] for p in pts]
            if not any(inside(y, x) for x, y in pts):
                continue
            lon = sum(xs) / len(xs)
            lat = sum(ys) / len(ys)
            osm_id = f"way/{obj.id}"
        elif isinstance(obj, osmium.osm.Node):
            loc = obj.location
            if not loc.valid():
                continue
            lat, lon = loc.lat, loc.lon
            if not inside(lat, lon):
                continue
            osm_id = f"node/{obj.id}"
        else:
            continue
        highway = tags.get("highway")
        if is_way and highway and names and tags.get("area") != "yes":
            scan.way_names[obj.id] = names
            if obj.id not in graph_ways:
                # minor ways (service, pedestrian...) and ways the loader could not place
                scan.extra_lines.append((names, LineString(pts)))
            continue
        if housenumber and tags.get("addr:street"):
            mark = Landmark(
                name=f"{housenumber} {tags['addr:street']}",
                lat=lat,
                lon=lon,
                kind="address",
                osm_id=osm_id,
            )
            for number in re.split(r"[;,]", housenumber):
                scan.addresses.append((tags["addr:street"], number.strip(), mark))
        if names and not any(k in tags for k in _LANDMARK_SKIP_KEYS if k != "highway"):
            key = next(
                (
                    k
                    for k in (
                        "amenity",
                        "tourism",
                        "historic",
                        "leisure",
                        "shop",
                        "place",
                        "railway",
                        "public_transport",
                        "building",
                        "man_made",
                        "office",
                        "highway",
                    )
                    if k in tags
                ),
                None,
            )
            kind = f"{key}={tags[key]}" if key else "feature"
            for name in names:
                scan.landmarks.append(Landmark(name, lat, lon, kind, osm_id))
    return scan


def _build(map_data: MapData) -> GeocodeIndex:
    index = GeocodeIndex()
    scan = _FileScan()
    source = Path(map_data.source) if map_data.source else None
    if source is not None and source.is_file():
        try:
            scan = _scan_file(source, map_data)
        except (RuntimeError, OSError, ValueError) as exc:  # the loader read it; be lenient
            log.warning("names beyond the street graph not read from %s: %s", source, exc)
    for street in map_data.streets:
        names = list(street.names or (() if street.name.startswith("unnamed ") else (street.name,)))
        for wid in street.way_ids:
            for extra in scan.way_names.get(wid, ()):
                if extra not in names:
                    names.append(extra)
        for name in names:
            toks = index.add_street_name(name)
            if toks:
                index.lines[toks].append(street.geometry)
    for names, line in scan.extra_lines:
        for name in names:
            toks = index.add_street_name(name)
            if toks:
                index.lines[toks].append(line)
    index.intersections = map_data.intersections
    for i, inter in enumerate(index.intersections):
        for j, inc in enumerate(inter.streets):
            names = list(inc.names)
            for wid in _way_ids_of_edge(map_data, *inc.edge):
                for extra in scan.way_names.get(wid, ()):
                    if extra not in names:
                        names.append(extra)
            seen: set[tuple[str, ...]] = set()
            for name in names:
                toks = index.add_street_name(name)
                if toks and toks not in seen:
                    seen.add(toks)
                    index.junctions[toks].append((i, j))
    for street_name, number, mark in scan.addresses:
        index.addresses[(name_tokens(street_name), fold(number).replace(" ", ""))].append(mark)
    for mark in scan.landmarks:
        index.add_landmark(mark)
    index.finish()
    return index


def index_for(map_data: MapData) -> GeocodeIndex:
    """The name index of a map, built on first use and cached on the map object."""
    index: GeocodeIndex | None = getattr(map_data, _ATTR, None)
    if index is not None:
        return index
    with _LOCK:
        index = getattr(map_data, _ATTR, None)
        if index is None:
            index = _build(map_data)
            setattr(map_data, _ATTR, index)
    return index
