"""Consolidated intersections, their incident streets and kerb corners.

Method
------
1. The simplified street graph (osmnx) is projected to the map's local azimuthal
   equidistant frame and its nodes are consolidated as
   :func:`osmnx.consolidate_intersections` does (``tolerance_m`` buffer per node: nodes
   closer than twice that and connected inside the cluster are one intersection, e.g. the
   four nodes of a dual carriageway crossing), see :func:`consolidate_nodes`.
2. Each edge leaving a cluster is an *arm*. Its direction is measured near the junction:
   from the node where it leaves the cluster to the point :data:`ARM_SAMPLE_M` metres
   along it (continuing through nodes where only a tag changes), with
   :func:`osmnx.bearing.calculate_bearing`. For a straight edge this is osmnx's own edge
   bearing (:func:`osmnx.add_edge_bearings`). Slip roads (``*_link``) are ignored. Parallel
   carriageways of one road (same name, at least one one-way, bearings within
   :data:`DUAL_MAX_ANGLE_DEG`: dual carriageways, frontage roads) are merged into one street
   whose kerbs are the outermost kerbs of the group. An unnamed piece takes the name of the
   street it continues into.
3. Each street's kerbs are its centre line, straight along the arm's direction, offset by
   half the carriageway width (:mod:`camloc_geo.osm._widths`). The kerb corner between two
   angularly adjacent streets is where the clockwise-side kerb of the first meets the
   counter-clockwise-side kerb of the next.

Which gaps get a corner (consistency matters more than anything for sequence matching):

- a gap between adjacent streets of :data:`MAX_CORNER_GAP_DEG` or more has no corner: the
  kerb runs on (nearly) straight, so the side of a T junction opposite the stem has no
  corner. A T has 2 corners, a crossing 4, a Y 3, a five-way junction 5;
- a gap under :data:`MIN_CORNER_GAP_DEG` (two streets leaving almost together: a fork's
  gore, a tunnel under a street, a slip road peeling off) has no corner either: the kerbs
  meet far out in a thin wedge nobody would click. The junction's other corners stay (a
  warning names the pair);
- parallel kerb lines, a corner farther than :data:`MAX_CORNER_DISTANCE_M` from the
  centre, more than :data:`MAX_STREETS` streets, or no corner left at all make the junction
  ``"unmodelled"``: no corners at all, and a warning saying why;
- a median opening (a dual carriageway whose two carriageways are joined by a short
  connector inside the junction, no side street) has the four corners of the median noses:
  where each carriageway's inner kerb meets the connector's kerbs
  (:func:`_median_opening_corners`);
- roundabouts (``junction=roundabout|circular`` on a street at the cluster) are
  ``"roundabout"``; their corners are where each approach's two kerbs meet the ring's outer
  kerb (:func:`_roundabout_corners`; none for rings over :data:`MAX_RING_RADIUS_M`).
  Mini-roundabouts (a node tag) are ordinary junctions.
- Nodes joining fewer than three streets (after merging carriageways and dropping slip
  roads) are not intersections.

Corners are ordered by their bearing from the intersection centre (clockwise seen from
above, 0 = smallest bearing) and labelled with the two streets they lie between.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any

import networkx as nx
import numpy as np
import shapely
from shapely.geometry import LineString

from camloc_geo.geodesy import LocalFrame, bearing_deg, initial_bearing_deg
from camloc_geo.osm._model import Corner, IncidentStreet, Intersection
from camloc_geo.osm._names import normalize_name
from camloc_geo.osm._widths import _first, parse_lanes, resolve_width_m

__all__ = [
    "ARM_SAMPLE_M",
    "DUAL_MAX_ANGLE_DEG",
    "GROUP_DIVIDED_M",
    "GROUP_NEAR_M",
    "MAX_CORNER_DISTANCE_M",
    "MAX_CORNER_GAP_DEG",
    "MAX_GROUP_SPAN_M",
    "MAX_STREETS",
    "MIN_CORNER_GAP_DEG",
    "build_intersections",
    "consolidate_nodes",
    "group_junction_nodes",
    "junction_nodes",
    "street_label",
]

log = logging.getLogger(__name__)

ARM_SAMPLE_M = 20.0
"""Length of street near the junction whose direction gives a street's bearing, metres."""
DUAL_MAX_ANGLE_DEG = 35.0
"""Two opposite one-way carriageways of one name closer than this in bearing are one street."""
MIN_CORNER_GAP_DEG = 15.0
"""Adjacent streets closer than this in bearing have no kerb corner between them."""
MAX_RING_NODES = 200
"""A roundabout's ring is followed through at most this many nodes."""
MAX_RING_RADIUS_M = 60.0
"""Rings wider than this (gyratories, squares around a park) get no ring corners: each place
where a street meets such a ring is modelled as an ordinary junction of the two (the ring is
nearly straight over a junction's extent)."""
WIDE_RING_REASON = "a wide ring"
MIN_MEDIAN_M = 0.5
"""A median opening's corners need a median at least this wide between the carriageways."""
MAX_CORNER_GAP_DEG = 160.0
"""Adjacent streets this far apart or more have no kerb corner between them."""
MAX_CORNER_DISTANCE_M = 40.0
"""A kerb corner farther than this from the centre means the junction is unmodelled."""
MAX_GORE_DISTANCE_M = 80.0
"""A gore's nose (where the facing kerbs of two streets forking less than
:data:`MIN_CORNER_GAP_DEG` apart meet) farther than this along them is not modelled."""
MAX_STREETS = 6
"""Junctions with more streets are unmodelled."""

GROUP_NEAR_M = 12.0
"""Junction nodes joined by a street piece shorter than this are one junction."""
GROUP_DIVIDED_M = 32.0
"""Junction nodes joined by a piece this short that crosses (or is) a one-way carriageway
(dual carriageway, one-way pair) are one junction."""
MAX_GROUP_SPAN_M = 45.0
"""A grouped junction never spans more than this (no chains of junctions)."""

_ROUNDABOUT = {"roundabout", "circular"}


def street_label(data: dict[str, Any]) -> tuple[str, tuple[str, ...]]:
    """A street's display name and all its names from osmnx edge data.

    ``name``; else ``ref``; else ``"unnamed <highway>"``.
    """
    raw = data.get("name")
    names: list[str] = []
    for value in raw if isinstance(raw, list) else [raw]:
        if isinstance(value, str) and value.strip():
            names.extend(v.strip() for v in value.split(";") if v.strip())
    if not names:
        ref = _first(data.get("ref"))
        if isinstance(ref, str) and ref.strip():
            names = [ref.strip()]
    if not names:
        return f"unnamed {highway_of(data)}", ()
    names = list(dict.fromkeys(names))
    return names[0], tuple(names)


def highway_of(data: dict[str, Any]) -> str:
    """The ``highway`` value of osmnx edge data (the first one of a merged edge)."""
    value = _first(data.get("highway"))
    return str(value) if value else "road"


def _is_oneway(data: dict[str, Any]) -> bool:
    value = data.get("oneway")
    if isinstance(value, list):
        return bool(all(value))
    return bool(value)


@dataclass
class _Arm:
    coords: np.ndarray  # (N, 2) ENU, outward from the intersection
    origin: np.ndarray  # (2,)
    direction: np.ndarray  # (2,) unit
    bearing: float
    flow: str  # "both" | "out" | "in"
    data: dict[str, Any]
    name: str
    names: tuple[str, ...]
    highway: str
    width_m: float
    width_source: str
    lanes: float | None
    edge: tuple[int, int]


@dataclass
class _Street:
    name: str
    names: tuple[str, ...]
    highway: str
    oneway: bool
    lanes: float | None
    width_m: float
    width_source: str
    carriageways: int
    origin: np.ndarray
    direction: np.ndarray
    s_left: float  # signed offsets along the right normal: left kerb (negative)
    s_right: float  # right kerb (positive)
    bearing: float
    edge: tuple[int, int]
    coords: np.ndarray | None = None  # (N, 2) ENU centre line outward (single carriageways)


def _right_normal(d: np.ndarray) -> np.ndarray:
    return np.array([d[1], -d[0]])


def _bearing_enu(frame: LocalFrame, p0: np.ndarray, p1: np.ndarray) -> float:
    (lon0, lon1), (lat0, lat1) = frame.geographic_from_enu(
        np.array([p0[0], p1[0]]), np.array([p0[1], p1[1]])
    )
    return initial_bearing_deg(lat1=lat0, lon1=lon0, lat2=lat1, lon2=lon1)


def project_graph_enu(G: nx.MultiDiGraph, frame: LocalFrame) -> nx.MultiDiGraph:
    """A copy of a lon/lat graph with node ``x``/``y`` and edge geometries in the frame's metres.

    What :func:`osmnx.project_graph` to the frame's azimuthal equidistant CRS gives, without
    the round trip through GeoDataFrames (a quarter of a second per map).
    """
    Gp = G.copy()
    nodes = list(Gp.nodes)
    if nodes:
        lonlat = np.array([[Gp.nodes[n]["x"], Gp.nodes[n]["y"]] for n in nodes], dtype=float)
        en = frame.points_enu_from_geographic(lonlat)
        for n, (x, y) in zip(nodes, en.tolist(), strict=True):
            Gp.nodes[n]["x"] = x
            Gp.nodes[n]["y"] = y
    edges = [d for _u, _v, d in Gp.edges(data=True) if d.get("geometry") is not None]
    if edges:
        geoms = shapely.transform(
            np.array([d["geometry"] for d in edges], dtype=object),
            frame.points_enu_from_geographic,
        )
        for d, g in zip(edges, geoms, strict=True):
            d["geometry"] = g
    Gp.graph["crs"] = (
        f"+proj=aeqd +lat_0={frame.lat0:.10f} +lon_0={frame.lon0:.10f} "
        "+x_0=0 +y_0=0 +ellps=WGS84 +units=m"
    )
    return Gp


def _angle_diff(a: float, b: float) -> float:
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def _extend_arm(
    G: nx.MultiDiGraph, edge: tuple[Any, Any], coords: list[tuple[float, float]]
) -> list[tuple[float, float]]:
    """Extend an arm shorter than :data:`ARM_SAMPLE_M` along plain continuations.

    Graph nodes where only a tag changes (lanes, name...) split a street into short edges;
    the direction near the junction is still measured over :data:`ARM_SAMPLE_M` metres.
    """
    length = LineString(coords).length
    prev, cur = edge
    for _ in range(6):
        if length >= ARM_SAMPLE_M or cur not in G:
            break
        nbrs = (set(G.successors(cur)) | set(G.predecessors(cur))) - {prev, cur}
        if len(nbrs) != 1:
            break
        nxt = nbrs.pop()
        forward = G.get_edge_data(cur, nxt)
        data = next(iter((forward or G.get_edge_data(nxt, cur)).values()))
        if "geometry" in data:
            more = list(data["geometry"].coords)
            if not forward:
                more = more[::-1]
        else:
            more = [(G.nodes[cur]["x"], G.nodes[cur]["y"]), (G.nodes[nxt]["x"], G.nodes[nxt]["y"])]
        coords = coords + more[1:]
        length = LineString(coords).length
        prev, cur = cur, nxt
    return coords


def _continued_label(
    G: nx.MultiDiGraph, edge: tuple[Any, Any], data: dict[str, Any], max_steps: int = 4
) -> tuple[str, tuple[str, ...]]:
    """The arm's label; an unnamed piece takes the name of the street it continues into.

    Short unnamed pieces (bridges, split ways) at a junction would otherwise label the whole
    arm "unnamed ...". Only plain continuations are followed (nodes joining exactly two
    streets), at most ``max_steps`` edges.
    """
    name, names = street_label(data)
    if names or G is None:
        return name, names
    prev, cur = edge
    for _ in range(max_steps):
        if cur not in G:
            break
        nbrs = (set(G.successors(cur)) | set(G.predecessors(cur))) - {prev, cur}
        if len(nbrs) != 1:
            break
        nxt = nbrs.pop()
        edata = G.get_edge_data(cur, nxt) or G.get_edge_data(nxt, cur)
        nxt_data = next(iter(edata.values()))
        n2, names2 = street_label(nxt_data)
        if names2:
            return n2, names2
        prev, cur = cur, nxt
    return name, names


def _make_arm(
    coords: list[tuple[float, float]],
    flow: str,
    data: dict[str, Any],
    edge: tuple[int, int],
    frame: LocalFrame,
    north_america: bool,
    G: nx.MultiDiGraph | None = None,
) -> _Arm | None:
    line = LineString(coords)
    if line.length < 0.5:
        return None
    p0 = np.asarray(coords[0], dtype=float)
    p1_pt = line.interpolate(min(ARM_SAMPLE_M, line.length))
    p1 = np.array([p1_pt.x, p1_pt.y])
    vec = p1 - p0
    norm = float(np.hypot(*vec))
    if norm < 1e-3:
        return None
    name, names = _continued_label(G, edge, data) if G is not None else street_label(data)
    highway = highway_of(data)
    oneway = flow != "both"
    width, source = resolve_width_m(
        width=data.get("width"),
        lanes=data.get("lanes"),
        highway=highway,
        oneway=oneway,
        north_america=north_america,
    )
    return _Arm(
        coords=np.asarray(coords, dtype=float),
        origin=p0,
        direction=vec / norm,
        bearing=_bearing_enu(frame, p0, p1),
        flow=flow,
        data=data,
        name=name,
        names=names,
        highway=highway,
        width_m=width,
        width_source=source,
        lanes=parse_lanes(data.get("lanes")),
        edge=edge,
    )


def consolidate_nodes(
    Gp: nx.MultiDiGraph, tolerance_m: float
) -> list[tuple[list[Any], float, float]]:
    """Clusters of nearby, connected nodes: the nodes of one intersection.

    The same clusters as :func:`osmnx.consolidate_intersections` (``dead_ends=True``):
    nodes buffered by ``tolerance_m`` whose buffers overlap form a cluster (their centroid
    is the centroid of the buffers' union), then a cluster whose nodes are not connected
    inside it is split into its weakly connected parts (centroid: mean of the nodes). It
    skips osmnx's graph rebuild, whose per-edge pandas look-ups dominate the run time on
    whole extracts; the equivalence is checked by the test suite.

    Returns
    -------
    ``(nodes, x, y)`` per cluster, in projected coordinates.
    """
    nodes = list(Gp.nodes)
    if not nodes:
        return []
    xs = np.array([Gp.nodes[n]["x"] for n in nodes], dtype=float)
    ys = np.array([Gp.nodes[n]["y"] for n in nodes], dtype=float)
    points = shapely.points(xs, ys)
    tree = shapely.STRtree(points)
    # overlapping buffers of radius r <=> centres closer than 2 r
    pairs = tree.query(points, predicate="dwithin", distance=2.0 * tolerance_m)
    from scipy.sparse import coo_matrix  # scipy.sparse: imported on first use
    from scipy.sparse.csgraph import connected_components

    n = len(nodes)
    adj = coo_matrix((np.ones(pairs.shape[1]), (pairs[0], pairs[1])), shape=(n, n))
    _count, labels = connected_components(adj, directed=False)
    groups: dict[int, list[int]] = {}
    for i, lab in enumerate(labels.tolist()):
        groups.setdefault(lab, []).append(i)
    clusters: list[tuple[list[Any], float, float]] = []
    for members in groups.values():
        if len(members) == 1:
            i = members[0]
            clusters.append(([nodes[i]], float(xs[i]), float(ys[i])))
            continue
        member_nodes = [nodes[i] for i in members]
        parts = list(nx.weakly_connected_components(Gp.subgraph(member_nodes)))
        if len(parts) == 1:
            union = shapely.union_all(shapely.buffer(points[members], tolerance_m, quad_segs=16))
            c = union.centroid
            clusters.append((member_nodes, float(c.x), float(c.y)))
            continue
        index = {nodes[i]: i for i in members}
        for part in parts:
            idx = [index[p] for p in part]
            clusters.append(
                ([nodes[i] for i in sorted(idx)], float(xs[idx].mean()), float(ys[idx].mean()))
            )
    return clusters


def junction_nodes(G: nx.MultiDiGraph) -> list[Any]:
    """Nodes where three or more street edges meet: osmnx's own street count.

    :func:`osmnx.stats.count_streets_per_node` counts each physical street piece once
    whatever its direction, parallel pieces between the same two nodes separately (two
    streets leaving a node towards the same next node still make a junction).
    """
    counts = count_streets_per_node(G)
    return [node for node in G.nodes if counts.get(node, 0) >= 3]


def count_streets_per_node(G: nx.MultiDiGraph) -> dict[Any, int]:
    """osmnx's ``stats.count_streets_per_node`` (same steps), without importing osmnx."""
    import itertools
    from collections import Counter

    Gu = G.to_undirected(reciprocal=False, as_view=True)
    self_loops = set(nx.selfloop_edges(Gu))
    edges = [e for e in Gu.edges(keys=False) if e not in self_loops] + list(self_loops)
    counts = Counter(itertools.chain.from_iterable(edges))
    return {node: counts[node] for node in G.nodes}


def group_junction_nodes(
    Gp: nx.MultiDiGraph,
    nodes: list[Any],
    *,
    near_m: float = GROUP_NEAR_M,
    divided_m: float = GROUP_DIVIDED_M,
    max_span_m: float = MAX_GROUP_SPAN_M,
) -> list[tuple[list[Any], float, float]]:
    """Group junction nodes a person at the corner sees as one junction.

    Two junction nodes are grouped when one street piece joins them and it is shorter than
    ``near_m`` (one junction drawn as two nodes), or shorter than ``divided_m`` and it is a
    one-way carriageway or crosses one (the nodes of a dual carriageway or a one-way pair).
    Pieces are taken shortest first and a group never grows wider than ``max_span_m``, so
    junctions along a street never chain into one.

    Returns
    -------
    ``(nodes, x, y)`` per group in the projected coordinates of ``Gp``; the centre is the mean
    of the member nodes.
    """
    index = {n: i for i, n in enumerate(nodes)}
    xy = np.array([[Gp.nodes[n]["x"], Gp.nodes[n]["y"]] for n in nodes], dtype=float)
    oneway_at: dict[Any, int] = {}
    for n in nodes:
        count = 0
        for u, v, data in list(Gp.out_edges(n, data=True)) + list(Gp.in_edges(n, data=True)):
            if u != v and _is_oneway(data):
                count += 1
        oneway_at[n] = count
    pairs: list[tuple[float, int, int]] = []
    for u, v, data in Gp.edges(data=True):
        if u == v or u not in index or v not in index:
            continue
        length = float(data.get("length") or LineString(_edge_coords(Gp, u, v, data)).length)
        divided = _is_oneway(data) or (oneway_at[u] >= 2 and oneway_at[v] >= 2)
        if length < near_m or (length < divided_m and divided):
            pairs.append((length, index[u], index[v]))
    pairs.sort()
    parent = list(range(len(nodes)))
    members: dict[int, list[int]] = {i: [i] for i in range(len(nodes))}

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for _length, i, j in pairs:
        ri, rj = find(i), find(j)
        if ri == rj:
            continue
        both = members[ri] + members[rj]
        pts = xy[both]
        span = float(np.max(np.hypot(*(pts[:, None, :] - pts[None, :, :]).T)))
        if span > max_span_m:
            continue
        parent[rj] = ri
        members[ri] = both
        del members[rj]
    out = []
    for group in members.values():
        ids = [nodes[i] for i in sorted(group)]
        c = xy[group].mean(axis=0)
        out.append((ids, float(c[0]), float(c[1])))
    return out


def _edge_coords(G: nx.MultiDiGraph, u: Any, v: Any, data: dict[str, Any]) -> list[Any]:
    geom = data.get("geometry")
    if geom is not None:
        return list(geom.coords)
    return [(G.nodes[u]["x"], G.nodes[u]["y"]), (G.nodes[v]["x"], G.nodes[v]["y"])]


def _arms_of(
    Gp: nx.MultiDiGraph,
    members: list[Any],
    frame: LocalFrame,
    north_america: bool,
) -> tuple[list[_Arm], list[str]]:
    """The streets leaving a cluster of nodes, one arm per street (both directions once)."""
    inside = set(members)
    found: dict[tuple[Any, ...], tuple[list[tuple[float, float]], set[str], dict[str, Any], Any]]
    found = {}
    warnings: list[str] = []
    for node in members:
        for u, v, data in Gp.out_edges(node, data=True):
            if u == v:
                # a loop (a street leaving and coming back to the node): two arms
                coords = _edge_coords(Gp, u, v, data)
                if len(coords) < 3:
                    continue
                for way, flow in ((coords, "out"), (coords[::-1], "in")):
                    key = (u, v, tuple(np.round(np.asarray(way), 2).ravel().tolist()))
                    entry = found.setdefault(key, (way, set(), data, (u, v)))
                    entry[1].add(flow)
                continue
            if v in inside:
                continue
            coords = _edge_coords(Gp, u, v, data)
            key = (u, v, tuple(np.round(np.asarray(coords), 2).ravel().tolist()))
            entry = found.setdefault(key, (coords, set(), data, (u, v)))
            entry[1].add("out")
        for u, v, data in Gp.in_edges(node, data=True):
            if u == v or u in inside:
                continue
            coords = _edge_coords(Gp, u, v, data)[::-1]
            key = (v, u, tuple(np.round(np.asarray(coords), 2).ravel().tolist()))
            entry = found.setdefault(key, (coords, set(), data, (v, u)))
            entry[1].add("in")
    arms: list[_Arm] = []
    for coords_found, flows, data, edge in found.values():
        coords = _extend_arm(Gp, edge, coords_found)
        flow = "both" if len(flows) == 2 or not _is_oneway(data) else next(iter(flows))
        arm = _make_arm(coords, flow, data, edge, frame, north_america, Gp)
        if arm is not None:
            arms.append(arm)
    return arms, list(dict.fromkeys(warnings))


def _name_key(arm: _Arm) -> str:
    return normalize_name(arm.name) if arm.names else f"~{arm.highway}"


def _single_street(arm: _Arm) -> _Street:
    half = arm.width_m / 2.0
    return _Street(
        name=arm.name,
        names=arm.names,
        highway=arm.highway,
        oneway=arm.flow != "both",
        lanes=arm.lanes,
        width_m=arm.width_m,
        width_source=arm.width_source,
        carriageways=1,
        origin=arm.origin,
        direction=arm.direction,
        s_left=-half,
        s_right=half,
        bearing=arm.bearing,
        edge=arm.edge,
        coords=arm.coords,
    )


def _merged_street(group: list[_Arm], frame: LocalFrame) -> _Street:
    """One street from several parallel carriageways: kerbs are the outermost ones."""
    d = np.sum([arm.direction for arm in group], axis=0)
    d = d / float(np.hypot(*d))
    r = _right_normal(d)
    origin = np.mean([arm.origin for arm in group], axis=0)
    offs = [float((arm.origin - origin) @ r) for arm in group]
    s_right = max(off + arm.width_m / 2.0 for off, arm in zip(offs, group, strict=True))
    s_left = min(off - arm.width_m / 2.0 for off, arm in zip(offs, group, strict=True))
    lanes_each = [arm.lanes for arm in group]
    lanes = None
    if all(n is not None for n in lanes_each):
        lanes = float(sum(n for n in lanes_each if n is not None))
    sources = {arm.width_source for arm in group}
    out_arms = [arm for arm in group if arm.flow in ("out", "both")] or group
    flows = {arm.flow for arm in group}
    return _Street(
        name=group[0].name,
        names=tuple(dict.fromkeys(n for arm in group for n in arm.names)),
        highway=group[0].highway,
        oneway=flows in ({"out"}, {"in"}),
        lanes=lanes,
        width_m=s_right - s_left,
        width_source=sources.pop() if len(sources) == 1 else "mixed",
        carriageways=len(group),
        origin=origin,
        direction=d,
        s_left=s_left,
        s_right=s_right,
        bearing=_bearing_enu(frame, origin, origin + ARM_SAMPLE_M * d),
        edge=out_arms[0].edge,
    )


def _group_streets(arms: list[_Arm], frame: LocalFrame) -> list[_Street]:
    """Merge parallel carriageways of one road; one street per remaining arm.

    Arms with the same name (or both unnamed of the same ``highway``), bearings within
    :data:`DUAL_MAX_ANGLE_DEG` and at least one of them one-way are carriageways of one
    road (dual carriageways, frontage roads): they are merged transitively.
    """
    parent = list(range(len(arms)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i, a in enumerate(arms):
        for j in range(i + 1, len(arms)):
            b = arms[j]
            if a.flow == "both" and b.flow == "both":
                continue
            if _name_key(a) != _name_key(b):
                continue
            if _angle_diff(a.bearing, b.bearing) <= DUAL_MAX_ANGLE_DEG:
                parent[find(i)] = find(j)
    groups: dict[int, list[_Arm]] = {}
    for i, arm in enumerate(arms):
        groups.setdefault(find(i), []).append(arm)
    streets = [
        _single_street(g[0]) if len(g) == 1 else _merged_street(g, frame) for g in groups.values()
    ]
    streets.sort(key=lambda s: s.bearing)
    return streets


def _kerb_corner(a: _Street, b: _Street) -> np.ndarray | None:
    """Where a's right (clockwise-side) kerb line meets b's left kerb line; None if parallel.

    The kerb lines are straight and extended both ways, so arms of a consolidated cluster
    that start at different nodes still meet near the cluster centre.
    """
    ra, rb = _right_normal(a.direction), _right_normal(b.direction)
    pa = a.origin + a.s_right * ra
    t = _line_meet(pa, a.direction, b.origin + b.s_left * rb, b.direction)
    return None if t is None else np.asarray(pa + t * a.direction, dtype=float)


def _line_meet(pa: np.ndarray, da: np.ndarray, pb: np.ndarray, db: np.ndarray) -> float | None:
    """``t`` where the line ``pa + t da`` meets ``pb + u db``; None if they are parallel.

    Cramer's rule on the 2 x 2 system.
    """
    dax, day = float(da[0]), float(da[1])
    dbx, dby = float(db[0]), float(db[1])
    det = -dax * dby + day * dbx
    if abs(det) < 1e-9:
        return None
    rx, ry = float(pb[0] - pa[0]), float(pb[1] - pa[1])
    return (-rx * dby + ry * dbx) / det


def _is_roundabout(G: nx.MultiDiGraph, osm_nodes: list[Any]) -> bool:
    for n in osm_nodes:
        if n not in G:
            continue
        for _u, _v, data in list(G.out_edges(n, data=True)) + list(G.in_edges(n, data=True)):
            if _is_ring_edge(data):
                return True
    return False


def _model_corners(
    streets: list[_Street], centre: np.ndarray, notes: list[str] | None = None
) -> tuple[list[tuple[np.ndarray, _Street, _Street]], str | None]:
    """Kerb corners between adjacent streets, or the reason the junction is unmodelled.

    ``notes`` (if given) receives one line per pair of streets too close in bearing to have
    a corner between them.
    """
    if len(streets) > MAX_STREETS:
        return [], f"{len(streets)} streets meet (more than {MAX_STREETS})"
    corners: list[tuple[np.ndarray, _Street, _Street]] = []
    sharp: list[str] = []
    noses: list[str] = []
    n = len(streets)
    for i in range(n):
        a, b = streets[i], streets[(i + 1) % n]
        gap = (b.bearing - a.bearing) % 360.0
        if gap >= MAX_CORNER_GAP_DEG:
            continue
        if gap < MIN_CORNER_GAP_DEG:
            nose = _gore_nose(a, b)
            if nose is None:
                sharp.append(f"{a.name!r} and {b.name!r} (only {gap:.0f}° apart")
            else:
                corners.append((nose, a, b))
                noses.append(
                    f"the corner between {a.name!r} and {b.name!r} (only {gap:.0f}° apart) is "
                    f"their gore's nose, {float(np.hypot(*(nose - centre))):.0f} m out"
                )
            continue
        point = _kerb_corner(a, b)
        if point is None:
            return [], f"the kerbs of {a.name!r} and {b.name!r} do not meet"
        dist = float(np.hypot(*(point - centre)))
        if dist > MAX_CORNER_DISTANCE_M:
            return [], f"the kerbs of {a.name!r} and {b.name!r} meet {dist:.0f} m from the centre"
        corners.append((point, a, b))
    if not corners:
        return [], (
            "; ".join(f"{pair})" for pair in sharp) if sharp else "no two streets meet at an angle"
        )
    if notes is not None:
        notes += [f"no kerb corner between {pair}: a fork's gore)" for pair in sharp]
        notes += noses
    return corners, None


def _gore_nose(a: _Street, b: _Street) -> np.ndarray | None:
    """The nose of the gore between two streets forking at a sharp angle, or None.

    Streets leaving a node a few degrees apart (a carriageway splitting, a slip road
    leaving a motorway) have no corner at the node: their facing kerbs (a's right, b's left)
    run side by side and meet only where the carriageways have drawn apart by their half
    widths, tens of metres out, at the tip of the island or the painted gore. The kerbs
    are the centre lines' offset curves along their real geometry (a straight extension
    of the first bearing would put a curving slip road's nose far off); the meeting
    nearest the node, within :data:`MAX_GORE_DISTANCE_M`, is the nose.
    """
    if a.coords is None or b.coords is None or len(a.coords) < 2 or len(b.coords) < 2:
        return None
    from shapely.geometry import LineString, Point

    kerb_a = LineString(a.coords).offset_curve(-a.s_right)  # shapely: positive is left
    kerb_b = LineString(b.coords).offset_curve(-b.s_left)
    meet = kerb_a.intersection(kerb_b)
    if meet.is_empty:
        return None
    points = [g for g in getattr(meet, "geoms", [meet]) if isinstance(g, Point)]
    origin = Point(float(a.coords[0][0]), float(a.coords[0][1]))
    points = [p for p in points if p.distance(origin) <= MAX_GORE_DISTANCE_M]
    if not points:
        return None
    nearest = min(points, key=origin.distance)
    return np.array([nearest.x, nearest.y], dtype=float)


def _is_ring_edge(data: dict[str, Any]) -> bool:
    junction = data.get("junction")
    values = junction if isinstance(junction, list) else [junction]
    return any(str(j) in _ROUNDABOUT for j in values if j)


def _roundabout_corners(
    Gp: nx.MultiDiGraph, members: list[Any], arms: list[_Arm], north_america: bool
) -> tuple[list[tuple[np.ndarray, _Street, _Street]], str | None]:
    """Kerb corners of a roundabout: where each approach's kerbs meet the ring's outer kerb.

    The ring is followed from the group's nodes along ``junction=roundabout|circular``
    edges; a circle fitted to its geometry (algebraic least squares) gives the centre and
    the radius of its centre line, and half the ring's carriageway width (one-way) gives
    the outer kerb. Each approach (an arm that is not part of the ring) has two kerb lines,
    straight along its first metres; each meets the outer kerb circle where the approach
    flares into the ring. Returns the corners, or ``[]`` and the reason.
    """
    ring_data: dict[str, Any] | None = None
    seen: set[Any] = set()
    todo = [n for n in members if n in Gp]
    points: list[tuple[float, float]] = []
    while todo and len(seen) < MAX_RING_NODES:
        n = todo.pop()
        if n in seen:
            continue
        seen.add(n)
        for u, v, data in list(Gp.out_edges(n, data=True)) + list(Gp.in_edges(n, data=True)):
            if not _is_ring_edge(data):
                continue
            ring_data = ring_data or data
            points += [tuple(p) for p in _edge_coords(Gp, u, v, data)]
            todo += [w for w in (u, v) if w not in seen]
    if ring_data is None or len(points) < 4:
        return [], "no ring geometry"
    xy = np.unique(np.asarray(points, dtype=float), axis=0)
    if len(xy) < 4:
        return [], "no ring geometry"
    # Kasa circle fit: x^2 + y^2 + D x + E y + F = 0
    A = np.column_stack([xy[:, 0], xy[:, 1], np.ones(len(xy))])
    b = -(xy[:, 0] ** 2 + xy[:, 1] ** 2)
    (D, E, F), *_ = np.linalg.lstsq(A, b, rcond=None)
    centre = np.array([-D / 2.0, -E / 2.0])
    radius_sq = float(centre @ centre - F)
    if radius_sq <= 0.0:
        return [], "the ring is not a circle"
    radius = math.sqrt(radius_sq)
    spread = np.abs(np.hypot(*(xy - centre).T) - radius)
    if float(np.median(spread)) > 0.25 * radius + 2.0:
        return [], f"a ring of {radius:.0f} m radius (or no circle)"
    if radius > MAX_RING_RADIUS_M:
        return [], f"{WIDE_RING_REASON} of {radius:.0f} m radius"
    ring_name, ring_names = street_label(ring_data)
    ring_width, ring_source = resolve_width_m(
        width=ring_data.get("width"),
        lanes=ring_data.get("lanes"),
        highway=highway_of(ring_data),
        oneway=True,
        north_america=north_america,
    )
    outer = radius + ring_width / 2.0
    ring = _Street(
        name=ring_name,
        names=ring_names,
        highway=highway_of(ring_data),
        oneway=True,
        lanes=parse_lanes(ring_data.get("lanes")),
        width_m=ring_width,
        width_source=ring_source,
        carriageways=1,
        origin=centre,
        direction=np.array([1.0, 0.0]),
        s_left=-ring_width / 2.0,
        s_right=ring_width / 2.0,
        bearing=0.0,
        edge=(0, 0),
    )
    out: list[tuple[np.ndarray, _Street, _Street]] = []
    owner: list[int] = []
    for k, arm in enumerate(arms):
        if _is_ring_edge(arm.data):
            continue
        street = _single_street(arm)
        r = _right_normal(arm.direction)
        for s_kerb, pair in (
            (arm.width_m / 2.0, (street, ring)),
            (-arm.width_m / 2.0, (ring, street)),
        ):
            p = arm.origin + s_kerb * r - centre
            # |p + t d| = outer, the root nearest the arm's start (t >= 0 leaves the ring)
            pd = float(p @ arm.direction)
            disc = pd * pd - float(p @ p) + outer * outer
            if disc < 0.0:
                continue
            roots = [-pd + math.sqrt(disc), -pd - math.sqrt(disc)]
            t = min(roots, key=abs)
            if abs(t) > outer + MAX_CORNER_DISTANCE_M:
                continue
            out.append((np.asarray(centre + p + t * arm.direction, dtype=float), *pair))
            owner.append(k)
    # Around the ring, an approach's two corners are neighbours; approaches whose corners
    # interleave (arms that curve into each other near the ring) are left out.
    angles = [math.atan2(float(q[1] - centre[1]), float(q[0] - centre[0])) for q, _a, _b in out]
    order = sorted(range(len(out)), key=lambda i: angles[i])
    seq = [owner[i] for i in order]
    bad = {
        k
        for k in set(seq)
        if seq.count(k) == 2
        and (j := [i for i, o in enumerate(seq) if o == k])[1] - j[0] not in (1, len(seq) - 1)
    }
    out = [c for c, k in zip(out, owner, strict=True) if k not in bad]
    if not out:
        return [], "no approach meets the ring"
    return out, None


def _median_opening_corners(
    Gp: nx.MultiDiGraph,
    members: list[Any],
    arms: list[_Arm],
    streets: list[_Street],
    north_america: bool,
) -> list[tuple[np.ndarray, _Street, _Street]]:
    """The median noses of a median opening, or ``[]`` if the group is not one.

    A median opening is a group of nodes whose arms make one straight dual carriageway
    (two opposite streets, at least one of them of two carriageways) joined by connector
    pieces inside the group. Its kerb corners are where the inner kerb of each carriageway
    (the median's edge) meets either kerb of a connector: four per connector, the corners a
    camera sees at the two ends of the gap in the median.
    """
    if len(streets) != 2 or max(s.carriageways for s in streets) < 2:
        return []
    a, b = streets
    if _angle_diff(a.bearing, (b.bearing + 180.0) % 360.0) > DUAL_MAX_ANGLE_DEG:
        return []
    d = a.direction
    r = _right_normal(d)
    # the carriageways: arms of either side, as lateral offsets (in a's frame) and widths
    lanes = sorted(
        (float((arm.origin - a.origin) @ r), arm.width_m)
        for arm in arms
        if min(_angle_diff(arm.bearing, a.bearing), _angle_diff(arm.bearing, b.bearing))
        <= DUAL_MAX_ANGLE_DEG
    )
    carriageways: list[tuple[float, float]] = []
    for off, width in lanes:  # the arms of one carriageway on both sides: one entry
        if carriageways and abs(off - carriageways[-1][0]) < 1.0:
            continue
        carriageways.append((off, width))
    if len(carriageways) != 2:
        return []
    (o1, w1), (o2, w2) = carriageways
    s1, s2 = o1 + w1 / 2.0, o2 - w2 / 2.0  # the median's two edges
    if s2 - s1 < MIN_MEDIAN_M:
        return []
    inside = set(members)
    seen: set[frozenset[Any]] = set()
    out: list[tuple[np.ndarray, _Street, _Street]] = []
    for u in members:
        for _u, v, data in Gp.out_edges(u, data=True):
            if v not in inside or v == u or frozenset((u, v)) in seen:
                continue
            seen.add(frozenset((u, v)))
            pu = np.array([Gp.nodes[u]["x"], Gp.nodes[u]["y"]], dtype=float)
            pv = np.array([Gp.nodes[v]["x"], Gp.nodes[v]["y"]], dtype=float)
            along = pv - pu
            if float(np.hypot(*along)) < 1.0:
                continue
            c = along / float(np.hypot(*along))
            if abs(float(c @ d)) > math.cos(math.radians(MIN_CORNER_GAP_DEG)):
                continue  # a piece along the carriageway, not across the median
            name, names = street_label(data)
            highway = highway_of(data)
            width, source = resolve_width_m(
                width=data.get("width"),
                lanes=data.get("lanes"),
                highway=highway,
                oneway=_is_oneway(data),
                north_america=north_america,
            )
            mid = (pu + pv) / 2.0
            conn = _Street(
                name=name,
                names=names,
                highway=highway,
                oneway=_is_oneway(data),
                lanes=parse_lanes(data.get("lanes")),
                width_m=width,
                width_source=source,
                carriageways=1,
                origin=mid,
                direction=c,
                s_left=-width / 2.0,
                s_right=width / 2.0,
                bearing=0.0,
                edge=(int(u), int(v)),
            )
            rc = _right_normal(c)
            for s_med in (s1, s2):
                base = a.origin + s_med * r
                for s_conn in (conn.s_left, conn.s_right):
                    t = _line_meet(base, d, mid + s_conn * rc, c)
                    if t is None:  # never: the connector crosses d by MIN_CORNER_GAP_DEG or more
                        continue
                    side = a if t >= 0.0 else b
                    out.append((np.asarray(base + t * d, dtype=float), side, conn))
    return out


def build_intersections(
    G: nx.MultiDiGraph,
    frame: LocalFrame,
    *,
    tolerance_m: float = GROUP_NEAR_M,
    radius_m: float | None = None,
    north_america: bool = False,
    rejected: dict[int, str] | None = None,
) -> list[Intersection]:
    """Intersections of an unprojected osmnx street graph.

    Parameters
    ----------
    G
        Simplified osmnx graph in lon/lat (``x``/``y`` node attributes).
    frame
        The map's local frame; the graph is projected to its azimuthal equidistant CRS.
    tolerance_m
        Junction nodes joined by a street piece shorter than this are one intersection
        (see :func:`group_junction_nodes`), metres.
    radius_m
        Keep intersections whose centre is within this distance of the frame's anchor;
        None keeps all.
    north_america
        Apply US/Canada width conventions.
    rejected
        If given, filled with ``{osm node id: reason}`` for junction nodes that gave no
        intersection (diagnostics for benchmarks).

    Returns
    -------
    Intersections (kind ``junction``, ``roundabout`` or ``unmodelled``), nearest first.
    """
    if G.number_of_edges() == 0:
        return []
    Gp = project_graph_enu(G, frame)
    out: list[tuple[float, Intersection]] = []
    groups = group_junction_nodes(
        Gp, junction_nodes(Gp), near_m=tolerance_m, divided_m=max(GROUP_DIVIDED_M, tolerance_m)
    )
    queue = list(groups)
    while queue:
        members, cx, cy = queue.pop(0)
        centre = np.array([cx, cy], dtype=float)
        dist_centre = float(np.hypot(*centre))
        if radius_m is not None and dist_centre > radius_m:
            continue
        arms, warnings = _arms_of(Gp, members, frame, north_america)
        links = [a for a in arms if a.highway.endswith("_link")]
        plain = [a for a in arms if not a.highway.endswith("_link")]
        streets = _group_streets(plain, frame)
        if len(streets) >= 3:
            if links:
                warnings.append(f"{len(links)} slip road(s) ignored")
        else:
            # a slip road joining a street, a carriageway splitting, a fork: every arm counts
            streets = _group_streets(arms, frame)
            if len(streets) < 3:
                streets = sorted((_single_street(a) for a in arms), key=lambda s: s.bearing)
        if len(streets) < 3 and len(members) > 1:
            # a group that leaves fewer than three streets is no junction as a whole (a
            # one-way loop with a short cut-through, Harrisburg's Beacon Drive): its nodes
            # are taken one by one
            queue[:0] = [([n], float(Gp.nodes[n]["x"]), float(Gp.nodes[n]["y"])) for n in members]
            continue
        if len(streets) < 3:
            if rejected is not None:
                for node in members:
                    rejected[int(node)] = f"{len(arms)} street arm(s) leave the node group"
            continue
        osm_nodes = [int(x) for x in members]
        ident = f"n{osm_nodes[0]}" if len(osm_nodes) == 1 else f"c{min(osm_nodes)}"
        member_lonlat = tuple((float(G.nodes[n]["x"]), float(G.nodes[n]["y"])) for n in members)
        lon, lat = frame.geographic_from_enu(centre[0], centre[1])
        kind = "junction"
        modelled: list[tuple[np.ndarray, _Street, _Street]] = []
        if _is_roundabout(Gp, osm_nodes):
            kind = "roundabout"
            modelled, reason = _roundabout_corners(Gp, members, arms, north_america)
            wide = reason is not None and reason.startswith(WIDE_RING_REASON)
            own: list[str] = []
            if wide:
                # Großer Stern, Place de l'Étoile: where a street meets a ring this wide, the
                # ring is a street like any other over the junction's extent
                modelled, plain_reason = _model_corners(streets, centre, own)
                if plain_reason:
                    modelled = []
            if wide and modelled:
                kind = "junction"
                warnings += own
                warnings.append(
                    f"on the ring of a roundabout ({reason}): modelled as an ordinary junction "
                    "of the ring and the street(s) meeting it"
                )
            else:
                warnings.append(
                    f"roundabout: kerb corners not modelled ({reason})"
                    if reason
                    else "roundabout: the corners are where each approach's kerbs meet the "
                    "ring's outer kerb"
                )
        else:
            modelled, reason = _model_corners(streets, centre, warnings)
            if reason and len(members) > 1:
                road = _group_streets(plain, frame)
                modelled = _median_opening_corners(Gp, members, arms, road, north_america)
                if modelled:
                    reason = None
                    streets = road  # one road of two carriageways each way
                    warnings.append(
                        "median opening: the corners are the noses of the median either side "
                        "of the gap"
                    )
            if reason:
                kind = "unmodelled"
                warnings.append(f"unmodelled junction: {reason}")
        corner_rows = []
        for point, a, b in modelled:
            clon, clat = frame.geographic_from_enu(point[0], point[1])
            corner_rows.append(
                (
                    bearing_deg(
                        lat1=float(lat), lon1=float(lon), lat2=float(clat), lon2=float(clon)
                    ),
                    clat,
                    clon,
                    a,
                    b,
                )
            )
        corner_rows.sort(key=lambda row: row[0])
        corners = tuple(
            Corner(
                intersection_id=ident,
                order=k,
                lat=float(clat),
                lon=float(clon),
                streets=(a.name, b.name),
            )
            for k, (_b, clat, clon, a, b) in enumerate(corner_rows)
        )
        incident = tuple(
            IncidentStreet(
                name=s.name,
                bearing_deg=round(s.bearing, 9) % 360.0,
                highway=s.highway,
                oneway=s.oneway,
                lanes=s.lanes,
                width_m=round(s.width_m, 6),
                width_source=s.width_source,
                carriageways=s.carriageways,
                names=s.names,
                edge=(int(s.edge[0]), int(s.edge[1])),
            )
            for s in streets
        )
        out.append(
            (
                dist_centre,
                Intersection(
                    id=ident,
                    lat=float(lat),
                    lon=float(lon),
                    streets=incident,
                    corners=corners,
                    kind=kind,
                    warnings=tuple(dict.fromkeys(warnings)),
                    osm_nodes=tuple(osm_nodes),
                    osm_node_lonlat=member_lonlat,
                ),
            )
        )
    out.sort(key=lambda row: row[0])
    log.debug("%d intersections built", len(out))
    return [row[1] for row in out]
