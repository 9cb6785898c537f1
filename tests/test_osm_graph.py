"""The street graph built without osmnx is the graph osmnx builds from the same ways."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import networkx as nx
import osmnx as ox
import pytest

from camloc_geo.osm import _load
from camloc_geo.osm._graph import graph_from_ways, simplify_graph

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"

Ways = list[tuple[int, dict[str, str], list[tuple[int, float, float]]]]


def _ways_of(path: Path, lat: float, lon: float, radius_m: float | None) -> Ways:
    seen: list[Ways] = []
    real = _load._graph_from_ways

    def spy(ways: Ways) -> nx.MultiDiGraph:
        seen.append(ways)
        return real(ways)

    _load._graph_from_ways = spy  # type: ignore[assignment]
    try:
        _load.read_extract(path, lat, lon, radius_m)
    finally:
        _load._graph_from_ways = real  # type: ignore[assignment]
    return seen[0]


def _osmnx_graph(ways: Ways, tmp_path: Path) -> nx.MultiDiGraph:
    """What the loader did before: an OSM XML file read by osmnx, then simplified by osmnx."""
    nodes: dict[int, tuple[float, float]] = {}
    way_lines: list[str] = []
    for way_id, tags, refs in ways:
        way_lines.append(f'<way id="{way_id}">')
        for ref, y, x in refs:
            nodes[ref] = (y, x)
            way_lines.append(f'<nd ref="{ref}"/>')
        way_lines.extend(f"<tag k={quoteattr(k)} v={quoteattr(v)}/>" for k, v in tags.items())
        way_lines.append("</way>")
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', '<osm version="0.6" generator="test">']
    lines.extend(f'<node id="{r}" lat="{y:.7f}" lon="{x:.7f}"/>' for r, (y, x) in nodes.items())
    lines.extend([*way_lines, "</osm>"])
    xml = tmp_path / "streets.osm"
    xml.write_text("\n".join(lines), encoding="utf-8")
    G = ox.graph_from_xml(xml, bidirectional=False, simplify=False, retain_all=True)
    return ox.simplify_graph(G, edge_attrs_differ=list(_load.SIMPLIFY_EDGE_ATTRS_DIFFER))


def _same_value(key: str, a: Any, b: Any) -> bool:
    if key == "length":
        return math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-9)
    if key == "geometry":
        return bool(a.equals_exact(b, 0.0))
    return bool(a == b)


@pytest.mark.parametrize(
    ("name", "lat", "lon", "radius_m"),
    [
        ("baltimore.osm.pbf", 39.2851, -76.5934, 400.0),
        ("fremantle.osm", -32.0365, 115.7558, None),
        ("paris_bss.osm.pbf", 48.8600, 2.3500, None),
        ("krems.osm.gz", 48.4100, 15.6000, None),
    ],
)
def test_graph_matches_osmnx(
    name: str, lat: float, lon: float, radius_m: float | None, tmp_path: Path
) -> None:
    ways = _ways_of(OSM / name, lat, lon, radius_m)
    ours = simplify_graph(graph_from_ways(ways), edge_attrs_differ=_load.SIMPLIFY_EDGE_ATTRS_DIFFER)
    theirs = _osmnx_graph(ways, tmp_path)
    assert list(ours.nodes(data=True)) == list(theirs.nodes(data=True))
    ours_edges = list(ours.edges(keys=True, data=True))
    their_edges = list(theirs.edges(keys=True, data=True))
    assert [e[:3] for e in ours_edges] == [e[:3] for e in their_edges]
    for (_u, _v, _k, a), (_u2, _v2, _k2, b) in zip(ours_edges, their_edges, strict=True):
        assert a.keys() == b.keys()
        for key in a:
            assert _same_value(key, a[key], b[key]), (key, a[key], b[key])
    assert ours.graph["simplified"] is True


def test_simplify_twice_is_refused() -> None:
    G = simplify_graph(
        graph_from_ways([(1, {"highway": "residential"}, [(1, 0.0, 0.0), (2, 0.0, 0.001)])])
    )
    with pytest.raises(ValueError, match="already simplified"):
        simplify_graph(G)


def test_local_extract_needs_no_osmnx() -> None:
    code = (
        "import sys\n"
        "from camloc_geo.osm import load_map\n"
        f"m = load_map({str(OSM / 'fremantle.osm')!r}, -32.0365, 115.7558, 200)\n"
        "print(len(m.intersections) > 0, 'osmnx' in sys.modules, 'geopandas' in sys.modules)\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    assert proc.stdout.split() == ["True", "False", "False"]
