"""Junction coverage and kerb corners of camloc's OSM model against independent references.

Coverage: for every extract in ``data/osm`` the *oracle* is osmnx's own street graph of the
whole extract, built without camloc code:

- the extract is converted to OSM XML with pyosmium, keeping the ways osmnx's ``drive``
  network keeps except service roads (:data:`ORACLE_HIGHWAYS`, no ``area=yes``, no
  ``access=private``) and the nodes they use;
- :func:`osmnx.graph_from_xml` (simplified) gives the graph and osmnx's ``street_count``
  per node; nodes with ``street_count >= 3`` are junctions;
- junctions closer than :data:`MERGE_M` are merged as :func:`osmnx.consolidate_intersections`
  does (buffers of half that distance, centroid of each buffer union).

An oracle junction is *covered* when a camloc intersection (``camloc corners`` of the whole
extract) lies within :data:`COVER_M`: its centre or one of its member nodes (a scene's point
matches a grouped intersection at any member node). ``coverage_centre_only`` counts centres
only. Every miss is listed with its reason.

Kerb corners: where OSM maps kerbs independently of the centre lines (``area:highway``
polygons, ``barrier=kerb`` ways, ``footway=sidewalk`` ways), the distance from each camloc
corner to the nearest such evidence is reported per city, next to a naive baseline (a corner
:data:`NAIVE_OFFSET_M` from the centre along the bisector of each pair of adjacent streets).
Only corners with evidence within :data:`KERB_EVIDENCE_M` count (elsewhere OSM says nothing).

Writes ``benchmarks/out/junctions.json`` and ``benchmarks/out/junctions.png``::

    python benchmarks/junctions.py [--extract kotka.osm.pbf ...]
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
OUT = HERE / "out"
OSM = ROOT / "data" / "osm"

log = logging.getLogger("junctions")

ORACLE_HIGHWAYS = frozenset(
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
"""osmnx's ``drive`` network without ``service`` (the issue's reference)."""
MERGE_M = 15.0
"""Oracle junctions closer than this are one junction (osmnx consolidation, tolerance/2)."""
COVER_M = 15.0
"""An oracle junction is covered by a camloc intersection centre within this distance."""
NAIVE_OFFSET_M = 5.0
"""The naive baseline's corner distance from the centre-line crossing, metres."""
KERB_EVIDENCE_M = 15.0
"""A junction counts in the kerb comparison when kerb evidence lies within this distance of
every naive corner (chosen on the map's kerb mapping, never on camloc's own answer)."""
UNSEEN = frozenset(
    {
        "rome_centro.osm.pbf",
        "andorra.osm.pbf",
        "harrisburg.osm.pbf",
        "manchester_kingsway.osm",
        "berlin_siegessaeule.osm.gz",
        "frederiksted.osm.pbf",
    }
)
"""Held-out extracts (``benchmarks/unseen_cities.py``): not in this benchmark's default run,
so its figures stay comparable with the earlier runs (``--extract`` still takes them)."""
EXTRACTS = sorted(
    p.name
    for p in OSM.iterdir()
    if p.name.endswith((".osm", ".osm.pbf", ".osm.gz", ".osm.bz2"))
    and p.name != "aguascalientes.osm.bz2"  # the same area as aguascalientes.osm.pbf
    and p.name not in UNSEEN
)


# -- the oracle --------------------------------------------------------------------------


def oracle_xml(src: Path, dst: Path) -> None:
    """Write the oracle's street ways (and their nodes) of an extract as OSM XML."""
    import osmium

    present = {n.id for n in osmium.FileProcessor(str(src), osmium.osm.NODE)}
    keep_nodes: set[int] = set()
    keep_ways: dict[int, list[int]] = {}
    for way in osmium.FileProcessor(str(src), osmium.osm.WAY):
        tags = way.tags
        if tags.get("highway") not in ORACLE_HIGHWAYS:
            continue
        if tags.get("area") == "yes" or tags.get("access") == "private":
            continue
        refs = [n.ref for n in way.nodes if n.ref in present]  # clipped ways: nodes held
        if len(refs) >= 2:
            keep_ways[way.id] = refs
            keep_nodes.update(refs)
    with osmium.SimpleWriter(str(dst)) as writer:
        for obj in osmium.FileProcessor(str(src), osmium.osm.NODE | osmium.osm.WAY):
            if isinstance(obj, osmium.osm.Node) and obj.id in keep_nodes:
                writer.add_node(obj)
            elif isinstance(obj, osmium.osm.Way) and obj.id in keep_ways:
                writer.add_way(obj.replace(nodes=keep_ways[obj.id]))


def oracle_junctions(src: Path) -> tuple[list[dict[str, Any]], Any]:
    """The oracle junctions of an extract and osmnx's graph.

    Returns
    -------
    ``[{"lat", "lon", "nodes": [...], "streets": [...]}, ...]`` and the simplified graph.
    """
    import osmnx as ox
    import shapely

    with tempfile.TemporaryDirectory(prefix="camloc_oracle_") as tmp:
        xml = Path(tmp) / "oracle.osm"
        oracle_xml(src, xml)
        ox.settings.log_console = False
        G = ox.graph_from_xml(xml, bidirectional=False, simplify=True, retain_all=True)
    counts = ox.stats.count_streets_per_node(G)
    nodes = [n for n in G.nodes if counts.get(n, 0) >= 3]
    if not nodes:
        return [], G
    lat0 = float(np.mean([G.nodes[n]["y"] for n in nodes]))
    lon0 = float(np.mean([G.nodes[n]["x"] for n in nodes]))
    from camloc_geo.geodesy import LocalFrame

    frame = LocalFrame(lat=lat0, lon=lon0)
    en = frame.points_enu_from_geographic([[G.nodes[n]["x"], G.nodes[n]["y"]] for n in nodes])
    pts = shapely.points(en[:, 0], en[:, 1])
    union = shapely.union_all(shapely.buffer(pts, MERGE_M / 2.0, quad_segs=16))
    polys = list(getattr(union, "geoms", [union]))
    tree = shapely.STRtree(polys)
    owner = tree.query(pts, predicate="intersects")
    members: dict[int, list[int]] = {}
    for i_pt, i_poly in zip(owner[0].tolist(), owner[1].tolist(), strict=True):
        members.setdefault(i_poly, []).append(i_pt)
    out = []
    for i_poly, idx in members.items():
        c = polys[i_poly].centroid
        lon, lat = frame.geographic_from_enu(c.x, c.y)
        names: set[str] = set()
        highways: set[str] = set()
        for i in idx:
            for _u, _v, d in list(G.edges(nodes[i], data=True)) + list(
                G.in_edges(nodes[i], data=True)
            ):
                for key, dest in (("name", names), ("highway", highways)):
                    val = d.get(key)
                    dest.update(val if isinstance(val, list) else [val] if val else [])
        out.append(
            {
                "lat": float(lat),
                "lon": float(lon),
                "nodes": [int(nodes[i]) for i in idx],
                "streets": sorted(names),
                "highways": sorted(highways),
            }
        )
    return out, G


# -- coverage ----------------------------------------------------------------------------


def _extract_centre(path: Path) -> tuple[float, float]:
    import osmium

    box = osmium.io.Reader(str(path), osmium.osm.NOTHING)
    try:
        b = box.header().box()
    finally:
        box.close()
    if b.valid():
        return (
            (b.bottom_left.lat + b.top_right.lat) / 2.0,
            (b.bottom_left.lon + b.top_right.lon) / 2.0,
        )
    lats, lons = [], []
    for n in osmium.FileProcessor(str(path), osmium.osm.NODE):
        lats.append(n.location.lat)
        lons.append(n.location.lon)
    return float(np.median(lats)), float(np.median(lons))


def _miss_reason(junction: dict[str, Any], camloc: Any, centres_en: np.ndarray, frame: Any) -> str:
    """Why no camloc intersection is within COVER_M of an oracle junction."""
    e, n = frame.enu_from_geographic(lat=junction["lat"], lon=junction["lon"])
    p = np.array([float(e), float(n)])
    d = np.hypot(*(centres_en - p).T) if len(centres_en) else np.array([math.inf])
    i = int(np.argmin(d))
    nearest = camloc.intersections[i] if math.isfinite(float(d[i])) else None
    member_hit = None
    for x in camloc.intersections:
        if set(junction["nodes"]) & set(x.osm_nodes):
            member_hit = x
            break
    diag = getattr(camloc, "rejected", {})
    dropped = [diag[nid] for nid in junction["nodes"] if nid in diag]
    if member_hit is not None:
        e2, n2 = frame.enu_from_geographic(lat=member_hit.lat, lon=member_hit.lon)
        dist = float(np.hypot(e2 - p[0], n2 - p[1]))
        return (
            f"grouped into {member_hit.id} ({len(member_hit.osm_nodes)} nodes, "
            f"{' & '.join(member_hit.street_names)}) whose centre is {dist:.0f} m away"
        )
    if dropped:
        return "not an intersection in camloc: " + "; ".join(dict.fromkeys(dropped))
    if junction["nodes"][0] not in camloc.graph:
        return f"nodes not in camloc's street graph (highways {', '.join(junction['highways'])})"
    near = f"; nearest {nearest.id} at {float(d[i]):.0f} m" if nearest is not None else ""
    return f"no camloc intersection{near}"


def coverage(name: str) -> dict[str, Any]:
    """Coverage of one extract's oracle junctions by camloc intersections."""
    from camloc_geo.geodesy import LocalFrame
    from camloc_geo.osm import load_map

    path = OSM / name
    t0 = time.perf_counter()
    junctions, _G = oracle_junctions(path)
    t_oracle = time.perf_counter() - t0
    lat, lon = _extract_centre(path)
    t0 = time.perf_counter()
    camloc = load_map(path, lat, lon, None)
    t_camloc = time.perf_counter() - t0
    frame = LocalFrame(lat=lat, lon=lon)
    centres = camloc.intersections
    centres_en = (
        frame.points_enu_from_geographic([[x.lon, x.lat] for x in centres])
        if centres
        else np.zeros((0, 2))
    )
    member_ll = [ll for x in centres for ll in x.osm_node_lonlat]
    members_en = frame.points_enu_from_geographic(member_ll) if member_ll else np.zeros((0, 2))
    anywhere_en = np.vstack([centres_en, members_en])
    misses = []
    dists = []
    centre_misses = 0
    for j in junctions:
        e, n = frame.enu_from_geographic(lat=j["lat"], lon=j["lon"])
        d_centre = (
            float(np.min(np.hypot(centres_en[:, 0] - e, centres_en[:, 1] - n)))
            if len(centres_en)
            else math.inf
        )
        centre_misses += d_centre > COVER_M
        d = (
            float(np.min(np.hypot(anywhere_en[:, 0] - e, anywhere_en[:, 1] - n)))
            if len(anywhere_en)
            else math.inf
        )
        dists.append(d)
        if d > COVER_M:
            misses.append(
                {
                    "lat": round(j["lat"], 7),
                    "lon": round(j["lon"], 7),
                    "streets": j["streets"],
                    "oracle_nodes": j["nodes"],
                    "nearest_m": round(d, 1),
                    "reason": _miss_reason(j, camloc, centres_en, frame),
                }
            )
    n = len(junctions)
    return {
        "extract": name,
        "oracle_junctions": n,
        "camloc_intersections": len(centres),
        "covered": n - len(misses),
        "coverage": (n - len(misses)) / n if n else None,
        "coverage_centre_only": (n - centre_misses) / n if n else None,
        "median_distance_m": float(np.median(dists)) if dists else None,
        "seconds_oracle": round(t_oracle, 2),
        "seconds_camloc": round(t_camloc, 2),
        "misses": misses,
    }


# -- kerb corners ------------------------------------------------------------------------


def kerb_evidence(path: Path) -> list[Any]:
    """Kerb lines mapped independently of centre lines, as (lon, lat) shapely geometries.

    ``area:highway`` polygons (their outlines), ``barrier=kerb`` ways and
    ``footway=sidewalk`` ways.
    """
    import osmium
    from shapely.geometry import LineString

    out = []
    fp = osmium.FileProcessor(str(path), osmium.osm.NODE | osmium.osm.WAY).with_locations()
    for obj in fp:
        if not isinstance(obj, osmium.osm.Way):
            continue
        tags = obj.tags
        kind = None
        if "area:highway" in tags:
            kind = "area:highway"
        elif tags.get("barrier") == "kerb":
            kind = "barrier=kerb"
        elif tags.get("footway") == "sidewalk":
            kind = "footway=sidewalk"
        if kind is None:
            continue
        coords = [(n.location.lon, n.location.lat) for n in obj.nodes if n.location.valid()]
        if len(coords) >= 2:
            out.append((kind, LineString(coords)))
    return out


def _naive_corners(x: Any, frame: Any) -> list[np.ndarray]:
    """Corners NAIVE_OFFSET_M from the centre along the bisector of adjacent streets."""
    e, n = frame.enu_from_geographic(lat=x.lat, lon=x.lon)
    brgs = sorted(s.bearing_deg for s in x.streets)
    out = []
    for i, a in enumerate(brgs):
        b = brgs[(i + 1) % len(brgs)]
        gap = (b - a) % 360.0
        if gap >= 160.0 or gap < 1e-6:
            continue
        mid = math.radians(a + gap / 2.0)
        out.append(
            np.array(
                [
                    float(e) + NAIVE_OFFSET_M * math.sin(mid),
                    float(n) + NAIVE_OFFSET_M * math.cos(mid),
                ]
            )
        )
    return out


def kerbs(name: str) -> dict[str, Any] | None:
    """Distances from camloc and naive corners to independently mapped kerbs."""
    import shapely

    from camloc_geo.geodesy import LocalFrame
    from camloc_geo.osm import load_map

    path = OSM / name
    evidence = kerb_evidence(path)
    if not evidence:
        return None
    lat, lon = _extract_centre(path)
    frame = LocalFrame(lat=lat, lon=lon)
    lines = [
        shapely.LineString(frame.points_enu_from_geographic(list(g.coords))) for _k, g in evidence
    ]
    tree = shapely.STRtree(lines)
    camloc = load_map(path, lat, lon, None)
    ours: list[float] = []
    naive: list[float] = []
    by_kind: dict[str, list[float]] = {}
    for x in camloc.intersections:
        if not x.corners:
            continue
        naive_pts = _naive_corners(x, frame)
        pts = [
            np.asarray(frame.enu_from_geographic(lat=c.lat, lon=c.lon), dtype=float)
            for c in x.corners
        ]
        d_ours = _nearest(tree, lines, pts)
        d_naive = _nearest(tree, lines, naive_pts)
        if not d_ours or not d_naive or max(d_naive) > KERB_EVIDENCE_M:
            continue  # no kerb mapped around this junction
        ours.extend(d_ours)
        naive.extend(d_naive)
        kind = x.kind
        if any("median opening" in w for w in x.warnings):
            kind = "median_opening"
        elif any("fork's gore" in w for w in x.warnings):
            kind = "sharp_fork"
        by_kind.setdefault(kind, []).extend(d_ours)
    if not ours:
        return None
    kinds: dict[str, int] = {}
    for k, _g in evidence:
        kinds[k] = kinds.get(k, 0) + 1
    return {
        "extract": name,
        "evidence_ways": kinds,
        "corners": len(ours),
        "camloc_median_m": float(np.median(ours)),
        "camloc_p90_m": float(np.percentile(ours, 90)),
        "naive_corners": len(naive),
        "naive_median_m": float(np.median(naive)),
        "naive_p90_m": float(np.percentile(naive, 90)),
        "camloc_by_kind": {
            k: {
                "corners": len(v),
                "median_m": float(np.median(v)),
                "p90_m": float(np.percentile(v, 90)),
            }
            for k, v in sorted(by_kind.items())
        },
    }


def _nearest(tree: Any, lines: list[Any], pts: list[np.ndarray]) -> list[float]:
    import shapely

    if not pts:
        return []
    geoms = shapely.points(np.asarray(pts))
    idx = tree.nearest(geoms)
    return [float(shapely.distance(g, lines[int(i)])) for g, i in zip(geoms, idx, strict=True)]


# -- main --------------------------------------------------------------------------------


def plot(rows: list[dict[str, Any]], kerb_rows: list[dict[str, Any]], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(14, 5), gridspec_kw={"width_ratios": [3, 2]})
    names = [r["extract"].split(".")[0] for r in rows]
    cov = [100.0 * (r["coverage"] or 0.0) for r in rows]
    ax = axes[0]
    ax.bar(names, cov, color=["tab:green" if c >= 98 else "tab:red" for c in cov])
    ax.axhline(98, color="k", ls="--", lw=1, label="aim 98 %")
    ax.set_ylim(min(50.0, min(cov, default=50.0) - 5), 100.5)
    ax.set_ylabel(f"oracle junctions with a camloc intersection < {COVER_M:.0f} m (%)")
    ax.set_title("Junction coverage against osmnx's graph")
    ax.tick_params(axis="x", rotation=60)
    ax.legend(loc="lower right")
    ax = axes[1]
    if kerb_rows:
        kn = [r["extract"].split(".")[0] for r in kerb_rows]
        x = np.arange(len(kn))
        ax.bar(x - 0.2, [r["camloc_median_m"] for r in kerb_rows], 0.4, label="camloc corners")
        ax.bar(x + 0.2, [r["naive_median_m"] for r in kerb_rows], 0.4, label="naive 5 m bisector")
        ax.set_xticks(x, kn, rotation=60)
        ax.set_ylabel("median distance to mapped kerb (m)")
        ax.legend()
    ax.set_title("Kerb corners against independently mapped kerbs")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--extract", action="append", help="extract file name in data/osm")
    parser.add_argument("--no-kerbs", action="store_true", help="skip the kerb comparison")
    parser.add_argument("-o", "--out", type=Path, default=OUT / "junctions.json")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    names = args.extract or EXTRACTS
    rows = []
    kerb_rows = []
    for name in names:
        row = coverage(name)
        rows.append(row)
        log.info(
            "%-28s %4d oracle junctions, coverage %.1f %% (%d misses), centres only %.1f %%",
            name,
            row["oracle_junctions"],
            100.0 * (row["coverage"] or 0.0),
            len(row["misses"]),
            100.0 * (row["coverage_centre_only"] or 0.0),
        )
        if not args.no_kerbs:
            k = kerbs(name)
            if k is not None:
                kerb_rows.append(k)
                log.info(
                    "%-28s kerbs: %d corners, camloc median %.1f m, naive %.1f m",
                    name,
                    k["corners"],
                    k["camloc_median_m"],
                    k["naive_median_m"],
                )
    total = sum(r["oracle_junctions"] for r in rows)
    covered = sum(r["covered"] for r in rows)
    result = {
        "oracle": "osmnx graph_from_xml, street_count >= 3, drive network without service, "
        f"merged within {MERGE_M:.0f} m",
        "cover_m": COVER_M,
        "overall_coverage": covered / total if total else None,
        "extracts": rows,
        "kerbs": kerb_rows,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=1, ensure_ascii=False), encoding="utf-8")
    plot(rows, kerb_rows, args.out.with_suffix(".png"))
    log.info("overall coverage %.1f %% -> %s", 100.0 * (result["overall_coverage"] or 0), args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
