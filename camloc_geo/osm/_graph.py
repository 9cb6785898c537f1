"""The street graph of a local extract, built without importing osmnx.

osmnx's :func:`osmnx.graph_from_xml` and :func:`osmnx.simplify_graph` make the same graph,
but importing osmnx costs half a second (it pulls in geopandas, pandas and matplotlib), more
than reading and modelling a whole neighbourhood. These functions follow osmnx 2.x step by
step (same node and edge order, attributes, lengths and simplification rules; osmnx is MIT
licensed), so that a map read from an extract is the map osmnx would give, and the graph
that Overpass returns through osmnx is simplified by the same code.

The graph is an unprojected :class:`networkx.MultiDiGraph`: nodes carry ``x`` (longitude)
and ``y`` (latitude); edges carry ``osmid``, the useful way tags, ``oneway``, ``reversed``,
``length`` (metres, great circle) and, once simplified, ``geometry`` (lon/lat LineString).
"""

from __future__ import annotations

import itertools
import logging
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from typing import Any

import networkx as nx
from shapely.geometry import LineString

from camloc_geo.geodesy import great_circle_m

__all__ = [
    "ALT_NAME_TAGS",
    "USEFUL_TAGS_WAY",
    "alt_names_by_name",
    "alt_names_of",
    "graph_from_ways",
    "simplify_graph",
]

log = logging.getLogger(__name__)

USEFUL_TAGS_WAY = (
    "access",
    "area",
    "bridge",
    "est_width",
    "highway",
    "junction",
    "landuse",
    "lanes",
    "maxspeed",
    "name",
    "oneway",
    "ref",
    "service",
    "tunnel",
    "width",
)
"""Way tags kept as edge attributes (osmnx's ``settings.useful_tags_way``)."""

ALT_NAME_TAGS = ("alt_name", "old_name", "official_name", "int_name", "loc_name", "short_name")
"""Way tags whose values are other names of a street (also every ``name:<language>``)."""

_LANG_NAME_RE = re.compile(r"^name:[a-z]{2,3}(?:[-_][A-Za-z]{2,8})?$")


def alt_names_of(tags: Mapping[str, str]) -> str | None:
    """A way's other names (:data:`ALT_NAME_TAGS`, ``name:<language>``), ``;``-joined and
    sorted, or None. Not kept on the graph (osmnx keeps none of them): the map keeps them
    by street name (:attr:`RawMap.alt_names <camloc_geo.osm._load.RawMap>`)."""
    found = {
        v.strip()
        for k, value in tags.items()
        if k in ALT_NAME_TAGS or _LANG_NAME_RE.match(k)
        for v in str(value).split(";")
        if v.strip()
    }
    return ";".join(sorted(found)) if found else None


_ONEWAY_VALUES = {"yes", "true", "1", "-1", "reverse", "T", "F"}
_REVERSED_VALUES = {"-1", "reverse", "T"}


def graph_from_ways(
    ways: Sequence[tuple[int, dict[str, str], Sequence[tuple[int, float, float]]]],
) -> nx.MultiDiGraph:
    """The unsimplified directed street graph of OSM ways.

    What ``osmnx.graph_from_xml(path, bidirectional=False, simplify=False, retain_all=True)``
    gives for an OSM XML file holding these ways and their nodes (coordinates at the
    file's 7 decimals).

    Parameters
    ----------
    ways
        ``(way_id, tags, [(node_id, lat, lon), ...])`` in file order.
    """
    nodes: dict[int, dict[str, float]] = {}
    for _way_id, _tags, refs in ways:
        for ref, lat, lon in refs:
            nodes[ref] = {"y": float(f"{lat:.7f}"), "x": float(f"{lon:.7f}")}
    G = nx.MultiDiGraph(created_with="camloc_geo", crs="epsg:4326")
    G.add_nodes_from(nodes.items())
    paths: dict[int, tuple[dict[str, Any], list[int]]] = {}
    for way_id, tags, refs in ways:
        attrs: dict[str, Any] = {"osmid": way_id}
        for key in USEFUL_TAGS_WAY:
            if key in tags:
                attrs[key] = tags[key]
        paths[way_id] = (attrs, [k for k, _g in itertools.groupby(r[0] for r in refs)])
    for attrs, way_nodes in paths.values():
        one_way = attrs.get("oneway") in _ONEWAY_VALUES or attrs.get("junction") == "roundabout"
        if one_way and attrs.get("oneway") in _REVERSED_VALUES:
            way_nodes.reverse()
        attrs["oneway"] = one_way
        edges = list(itertools.pairwise(way_nodes))
        attrs["reversed"] = False
        G.add_edges_from(edges, **attrs)
        if not one_way:
            attrs["reversed"] = True
            G.add_edges_from([(v, u) for u, v in edges], **attrs)
    for u, v, data in G.edges(data=True):
        a, b = G.nodes[u], G.nodes[v]
        data["length"] = great_circle_m(lat1=a["y"], lon1=a["x"], lat2=b["y"], lon2=b["x"])
    return G


def _is_endpoint(G: nx.MultiDiGraph, node: Any, edge_attrs_differ: Iterable[str]) -> bool:
    neighbors = set(list(G.predecessors(node)) + list(G.successors(node)))
    n = len(neighbors)
    d = G.degree(node)
    if node in neighbors:  # self-loop
        return True
    if G.out_degree(node) == 0 or G.in_degree(node) == 0:  # dead end
        return True
    if not (n == 2 and d in {2, 4}):  # not a mid-street node (one-way or two-way)
        return True
    for attr in edge_attrs_differ:
        in_values = {v for _, _, v in G.in_edges(node, data=attr, keys=False)}
        out_values = {v for _, _, v in G.out_edges(node, data=attr, keys=False)}
        if len(in_values | out_values) > 1:
            return True
    return False


def _build_path(
    G: nx.MultiDiGraph, endpoint: Any, successor0: Any, endpoints: set[Any]
) -> list[Any]:
    path = [endpoint, successor0]
    for this_successor in G.successors(successor0):
        successor = this_successor
        if successor not in path:
            path.append(successor)
            while successor not in endpoints:
                successors = [n for n in G.successors(successor) if n not in path]
                if len(successors) == 1:
                    successor = successors[0]
                    path.append(successor)
                elif len(successors) == 0:
                    if endpoint in G.successors(successor):  # a ring back to the endpoint
                        return [*path, endpoint]
                    log.debug("unexpected simplify pattern near %s", successor)
                    return path
                else:  # pragma: no cover - cannot happen for a non-endpoint
                    raise RuntimeError(f"impossible simplify pattern near {successor}")
            return path
    return path


def _paths_to_simplify(G: nx.MultiDiGraph, edge_attrs_differ: Sequence[str]) -> Iterator[list[Any]]:
    endpoints = {n for n in G.nodes if _is_endpoint(G, n, edge_attrs_differ)}
    for endpoint in endpoints:
        for successor in G.successors(endpoint):
            if successor not in endpoints:
                yield _build_path(G, endpoint, successor, endpoints)


def simplify_graph(G: nx.MultiDiGraph, *, edge_attrs_differ: Sequence[str] = ()) -> nx.MultiDiGraph:
    """Merge each chain of mid-street nodes into one edge with a LineString geometry.

    ``osmnx.simplify_graph(G, edge_attrs_differ=...)`` with its defaults: nodes where an
    ``edge_attrs_differ`` attribute changes are kept; a merged edge sums ``length`` and keeps
    one value of every other attribute when all agree, else the list of distinct values;
    rings without any endpoint are removed.
    """
    if G.graph.get("simplified"):
        raise ValueError("this graph is already simplified")
    G = G.copy()
    nodes_to_remove: list[Any] = []
    edges_to_add: list[tuple[Any, Any, dict[str, Any]]] = []
    for path in _paths_to_simplify(G, edge_attrs_differ):
        path_attributes: dict[str, Any] = {}
        for u, v in itertools.pairwise(path):
            edge_data = next(iter(G.get_edge_data(u, v).values()))
            for attr in edge_data:
                if attr in path_attributes:
                    path_attributes[attr].append(edge_data[attr])
                else:
                    path_attributes[attr] = [edge_data[attr]]
        for name, values in path_attributes.items():
            if name in ("length", "travel_time"):
                path_attributes[name] = sum(values)
            elif len(set(values)) == 1:
                path_attributes[name] = values[0]
            else:
                path_attributes[name] = list(set(values))
        path_attributes["geometry"] = LineString(
            [(G.nodes[node]["x"], G.nodes[node]["y"]) for node in path]
        )
        nodes_to_remove.extend(path[1:-1])
        edges_to_add.append((path[0], path[-1], path_attributes))
    for u, v, attrs in edges_to_add:
        G.add_edge(u, v, **attrs)
    G.remove_nodes_from(set(nodes_to_remove))
    ring_nodes: set[Any] = set()
    for wcc in nx.weakly_connected_components(G):
        if not any(_is_endpoint(G, n, edge_attrs_differ) for n in wcc):
            ring_nodes.update(wcc)
    G.remove_nodes_from(ring_nodes)
    G.graph["simplified"] = True
    return G


def alt_names_by_name(
    ways: Iterable[tuple[int, Mapping[str, str], Any]],
) -> dict[str, tuple[str, ...]]:
    """``{street name: its other names}`` over street ways (:func:`alt_names_of`), each
    sorted; a way's own names (``name``, split at ``;``) left out."""
    found: dict[str, set[str]] = {}
    for _way_id, tags, _nodes in ways:
        alt = alt_names_of(tags)
        own = {n.strip() for n in str(tags.get("name") or "").split(";") if n.strip()}
        if alt is None or not own:
            continue
        alts = set(alt.split(";")) - own
        for n in own:
            found.setdefault(n, set()).update(alts)
    return {n: tuple(sorted(a)) for n, a in found.items() if a}
