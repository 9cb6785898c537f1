"""Reference titles for geocoding, generated from osmnx's own graph of an extract.

The reference is independent of camloc_geo's junction model: the extract's ``highway`` ways
go through :func:`osmnx.graph_from_xml` (PBF converted to OSM XML with pyosmium), and every
graph node where two or more named streets meet gives the OSM ``name`` values of its edges
and its position. Pairs of names are then written into a title by rule, in the styles of
published webcam lists (abbreviated, upper case, accent-free, camera-number prefixes,
several separators, typos, the N/S half left out). Titles that must not be placed are
added: a landmark missing from OSM, two streets that never meet, a single street name.

Used by ``tests/test_geocode_reference.py`` and ``benchmarks/geocode.py``.
"""

from __future__ import annotations

import math
import random
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

from anyascii import anyascii

__all__ = ["RefTitle", "osmnx_graph", "reference_titles"]

NON_ROAD = frozenset(
    {
        "footway",
        "path",
        "steps",
        "cycleway",
        "bridleway",
        "corridor",
        "platform",
        "elevator",
        "proposed",
        "construction",
        "track",
        "bus_stop",
        "raceway",
    }
)

SAME_PLACE_M = 60.0

_ABBREV = [
    (r"\bStreet\b", "St"),
    (r"\bAvenue\b", "Ave"),
    (r"\bBoulevard\b", "Blvd"),
    (r"\bRoad\b", "Rd"),
    (r"\bDrive\b", "Dr"),
    (r"\bLane\b", "Ln"),
    (r"\bCourt\b", "Ct"),
    (r"\bTerrace\b", "Ter"),
    (r"\bParkway\b", "Pkwy"),
    (r"\bHighway\b", "Hwy"),
    (r"\bSquare\b", "Sq"),
    (r"\bPlace\b", "Pl"),
    (r"^North\b", "N"),
    (r"^South\b", "S"),
    (r"^East\b", "E"),
    (r"^West\b", "W"),
    (r"straße\b", "str."),
    (r"Straße\b", "Str."),
    (r"^Rue\b", "R."),
    (r"^Avenue\b", "Av."),
    (r"^Boulevard\b", "Bd"),
    (r"\bSaint-", "St-"),
    (r"\bSainte-", "Ste-"),
    (r"^Calle\b", "C."),
    (r"^Avenida\b", "Av."),
    (r"^Rua\b", "R."),
    (r"\bулица\b", "ул."),
    (r"\bпроспект\b", "просп."),
    (r"\bпереулок\b", "пер."),
    (r"\bKatu\b", "k."),
]
_SEPARATORS = [" & ", " @ ", " / ", " at ", " and ", " x ", " - ", "/", " & "]
_DIRECTIONAL_RE = re.compile(r"^(?:North|South|East|West|N|S|E|W)\s+(?=\S)")


@dataclass(frozen=True)
class RefTitle:
    """A generated title and what the geocoder must answer."""

    title: str
    expect: str  # "junction", "not_found", "street"
    lat: float | None = None
    lon: float | None = None
    names: tuple[str, ...] = ()
    style: str = ""
    near: tuple[float, float] | None = None


def _dist_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    kx = 111_320.0 * math.cos(math.radians(lat1))
    return math.hypot((lon2 - lon1) * kx, (lat2 - lat1) * 110_574.0)


def _highway_xml(path: Path, out: Path) -> None:
    """The extract's highway ways (and their nodes) as plain OSM XML, via pyosmium."""
    import osmium

    nodes: dict[int, tuple[float, float]] = {}
    ways: list[tuple[int, list[int], dict[str, str]]] = []
    processor = (
        osmium.FileProcessor(str(path), osmium.osm.NODE | osmium.osm.WAY)
        .with_locations()
        .with_filter(osmium.filter.EntityFilter(osmium.osm.WAY))
        .with_filter(osmium.filter.KeyFilter("highway"))
    )
    for way in processor:
        if not isinstance(way, osmium.osm.Way) or way.tags.get("area") == "yes":
            continue
        refs = []
        for nd in way.nodes:
            if nd.location.valid():
                nodes[nd.ref] = (nd.location.lat, nd.location.lon)
                refs.append(nd.ref)
        if len(refs) >= 2:
            ways.append((way.id, refs, dict(way.tags)))
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', '<osm version="0.6" generator="test">']
    lines += [f'<node id="{n}" lat="{y:.7f}" lon="{x:.7f}"/>' for n, (y, x) in nodes.items()]
    for wid, refs, tags in ways:
        lines.append(f'<way id="{wid}">')
        lines += [f'<nd ref="{r}"/>' for r in refs]
        lines += [f"<tag k={quoteattr(k)} v={quoteattr(v)}/>" for k, v in tags.items()]
        lines.append("</way>")
    lines.append("</osm>")
    out.write_text("\n".join(lines), encoding="utf-8")


def osmnx_graph(path: Path) -> Any:
    """osmnx's graph of the extract's highway ways (``graph_from_xml``, simplified keeping
    the nodes where a street's name changes)."""
    import osmnx as ox

    with tempfile.TemporaryDirectory(prefix="camloc_ref_") as tmp:
        xml = Path(tmp) / "ref.osm"
        _highway_xml(path, xml)
        G = ox.graph_from_xml(xml, simplify=False, retain_all=True)
    # keep nodes where the name changes, so every edge carries one street's name
    return ox.simplify_graph(G, edge_attrs_differ=["name"])


def _names(value: Any) -> list[str]:
    out: list[str] = []
    for v in value if isinstance(value, list) else [value]:
        if isinstance(v, str):
            out.extend(x.strip() for x in v.split(";") if x.strip())
    return out


def _first(value: Any) -> str:
    return str(value[0] if isinstance(value, list) else value)


def _style(a: str, b: str, k: int, rng: random.Random) -> tuple[str, str]:
    """Write two OSM names as a title in style number ``k``."""
    styles = [
        "abbrev",
        "upper",
        "ascii",
        "camera",
        "typo",
        "plain",
        "abbrev+upper",
        "camera+abbrev",
        "no_directional",
    ]
    style = styles[k % len(styles)]

    def abbrev(s: str) -> str:
        for pat, rep in _ABBREV:
            s = re.sub(pat, rep, s)
        return s

    def typo(s: str) -> str:
        words = s.split()
        i = max(range(len(words)), key=lambda j: len(words[j]))
        w = words[i]
        if len(w) >= 7:
            cut = len(w) // 2
            words[i] = w[:cut] + w[cut + 1 :]
        return " ".join(words)

    if "abbrev" in style:
        a, b = abbrev(a), abbrev(b)
    if "typo" in style:
        a = typo(a)
    if "no_directional" in style:
        a = _DIRECTIONAL_RE.sub("", a)
    if "ascii" in style:
        a, b = anyascii(a), anyascii(b)
    sep = _SEPARATORS[k % len(_SEPARATORS)]
    title = f"{a}{sep}{b}"
    if "upper" in style:
        title = title.upper()
    if "camera" in style:
        n = rng.randint(1, 9999)
        title = f"{n} - {title}" if k % 2 else f"{n}-{title}"
    return title, style


def reference_titles(
    path: Path, *, max_junctions: int = 60, seed: int = 0, graph: Any = None
) -> list[RefTitle]:
    """Titles generated from the extract's osmnx graph, with the answers expected.

    Parameters
    ----------
    path
        The extract.
    max_junctions
        At most this many junction titles (a deterministic sample).
    seed
        Seed of the sample and of the camera numbers.
    graph
        osmnx graph already built by :func:`osmnx_graph` (built here when None).
    """
    G = osmnx_graph(path) if graph is None else graph
    rng = random.Random(seed)
    # names at each node, and where every pair of names meets
    pair_places: dict[tuple[str, str], list[tuple[float, float]]] = {}
    street_lines: dict[str, list[tuple[float, float]]] = {}
    for node, data in G.nodes(data=True):
        names: set[str] = set()
        for _u, _v, edata in list(G.out_edges(node, data=True)) + list(G.in_edges(node, data=True)):
            if _first(edata.get("highway")) in NON_ROAD:
                continue
            for n in _names(edata.get("name")):
                names.add(n)
                street_lines.setdefault(n, []).append((data["y"], data["x"]))
        for a in sorted(names):
            for b in sorted(names):
                if a < b:
                    pair_places.setdefault((a, b), []).append((data["y"], data["x"]))
    out: list[RefTitle] = []
    pairs = sorted(pair_places)
    rng.shuffle(pairs)
    k = 0
    for a, b in pairs:
        places = pair_places[(a, b)]
        lat, lon = places[0]
        spread = max(_dist_m(lat, lon, y, x) for y, x in places)
        if spread <= SAME_PLACE_M:  # one junction (a dual carriageway's nodes): its centre
            lat = sum(y for y, _x in places) / len(places)
            lon = sum(x for _y, x in places) / len(places)
        # names that read alike (one contains the other) are not a fair test
        if a.lower() in b.lower() or b.lower() in a.lower() or "(" in a + b:
            continue
        if re.sub(r"\W", "", a.lower()) == re.sub(r"\W", "", b.lower()):
            continue  # two spellings of one street
        near = None
        if spread > SAME_PLACE_M:
            near = (lat, lon)  # the pair meets at several places: a point says which
        if rng.random() < 0.5:
            a, b = b, a
        title, style = _style(a, b, k, rng)
        k += 1
        out.append(RefTitle(title, "junction", lat, lon, (a, b), style, near))
        if k >= max_junctions:
            break
    # titles that must not be placed
    out.append(RefTitle("Zyxwvut Memorial Fountain", "not_found", style="missing landmark"))
    out.append(RefTitle("Qwertzuiop Tower & Plmokn Gate", "not_found", style="missing names"))
    names_sorted = sorted(n for n in street_lines if len(n) >= 6)
    far: list[tuple[str, str]] = []
    for i, a in enumerate(names_sorted):
        for b in names_sorted[i + 1 :]:
            if (min(a, b), max(a, b)) in pair_places:
                continue
            gap = min(
                _dist_m(y1, x1, y2, x2) for y1, x1 in street_lines[a] for y2, x2 in street_lines[b]
            )
            if gap > 400.0 and a.lower() not in b.lower() and b.lower() not in a.lower():
                far.append((a, b))
                break
        if len(far) >= 3:
            break
    for a, b in far:
        out.append(RefTitle(f"{a} & {b}", "not_found", names=(a, b), style="never meet"))
    # a real street and a made-up one: one real name does not place the pair
    for name in rng.sample(names_sorted, min(2, len(names_sorted))):
        out.append(
            RefTitle(f"{name} & Qzxwv Ave", "not_found", names=(name,), style="made-up street")
        )
    out.append(RefTitle("Plmokn St & Qzxwv Ave", "not_found", style="made-up streets"))
    for name in rng.sample(names_sorted, min(3, len(names_sorted))):
        out.append(RefTitle(name, "street", names=(name,), style="single street"))
    return out
