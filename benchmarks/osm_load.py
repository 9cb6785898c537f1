"""Benchmark the OSM layer: time and peak memory, camloc_geo.osm vs osmnx.

For each extract (default: the largest ones in data/osm):

- ``camloc_full``: :func:`camloc_geo.osm.load_map` on the whole extract (``radius_m=None``):
  every intersection with its kerb corners, plus streets and buildings;
- ``osmnx_full``: :func:`osmnx.graph_from_xml` building the graph of the whole extract (the
  extract converted to OSM XML first with pyosmium, not timed), as a reference;
- ``camloc_point``: loading the area around one point (300 m) in a fresh process;
- ``camloc_cached``: loading the same point again in the same process.

Each case runs in its own subprocess; peak memory is that process' ``ru_maxrss`` (and the
increase over the process after imports). Wall and CPU (user + system) seconds are both
recorded: on a shared machine CPU time is the steadier number. The best of ``--repeat``
runs is kept. Results go to ``benchmarks/out/osm_load.json`` and
``benchmarks/out/osm_load.png``::

    python benchmarks/osm_load.py [--extract baltimore.osm.pbf ...] [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import platform
import subprocess
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
OUT = HERE / "out"
OSM = HERE.parents[0] / "data" / "osm"
POINTS = {  # one point per extract for the "around a point" case
    "baltimore.osm.pbf": (39.28558, -76.59348),
    "monaco.osm.pbf": (43.7384, 7.4246),
    "helsinki.osm.pbf": (60.1699, 24.9384),
}

log = logging.getLogger("osm_load")

_CHILD = r"""
import json, resource, sys, time
case, path, xml = sys.argv[1], sys.argv[2], sys.argv[5]
lat, lon = float(sys.argv[3]), float(sys.argv[4])
import osmnx as ox
from camloc_geo.osm import load_map
def rss_mib():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
base = rss_mib()
result = {}
t0 = time.perf_counter()
c0 = cpu()
if case == "camloc_full":
    m = load_map(path, lat, lon, None)
    result["intersections"] = len(m.intersections)
    result["corners"] = sum(len(x.corners) for x in m.intersections)
    result["junctions"] = sum(x.kind == "junction" for x in m.intersections)
elif case == "osmnx_full":
    G = ox.graph_from_xml(xml, bidirectional=False, simplify=True, retain_all=True)
    result["nodes"] = G.number_of_nodes()
    result["edges"] = G.number_of_edges()
elif case in ("camloc_point", "camloc_cached"):
    m = load_map(path, lat, lon, 300.0)
    if case == "camloc_cached":
        t0 = time.perf_counter()
        c0 = cpu()
        m = load_map(path, lat, lon, 300.0)
    result["intersections"] = len(m.intersections)
    result["corners"] = sum(len(x.corners) for x in m.intersections)
result["seconds"] = time.perf_counter() - t0
result["cpu_seconds"] = cpu() - c0
result["peak_rss_mib"] = rss_mib()
result["import_rss_mib"] = base
result["peak_increase_mib"] = result["peak_rss_mib"] - base
print(json.dumps(result))
"""


def _to_xml(src: Path, dst: Path) -> None:
    """Convert an extract to plain OSM XML with pyosmium (for osmnx, which reads XML only)."""
    import osmium

    if dst.exists():
        return
    with osmium.SimpleWriter(str(dst)) as writer:
        for obj in osmium.FileProcessor(str(src)):
            if isinstance(obj, osmium.osm.Node):
                writer.add_node(obj)
            elif isinstance(obj, osmium.osm.Way):
                writer.add_way(obj)
            elif isinstance(obj, osmium.osm.Relation):
                writer.add_relation(obj)


def _run(case: str, path: Path, lat: float, lon: float, xml: Path) -> dict[str, Any]:
    env = dict(os.environ, PYTHONPATH=str(HERE.parent))
    proc = subprocess.run(
        [sys.executable, "-c", _CHILD, case, str(path), str(lat), str(lon), str(xml)],
        capture_output=True,
        text=True,
        check=False,
        env=env,
        timeout=900,
    )
    if proc.returncode != 0:
        raise RuntimeError(f"{case} failed: {proc.stderr.strip().splitlines()[-1:]}")
    return dict(json.loads(proc.stdout.strip().splitlines()[-1]))


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and write JSON and a PNG plot to benchmarks/out/."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--extract", action="append", help="file name in data/osm")
    parser.add_argument("--repeat", type=int, default=3, help="runs per case (best time kept)")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    OUT.mkdir(parents=True, exist_ok=True)
    extracts = args.extract or ["baltimore.osm.pbf", "monaco.osm.pbf"]
    results: dict[str, Any] = {
        "python": sys.version.split()[0],
        "machine": platform.machine(),
        "cpus": os.cpu_count(),
        "extracts": {},
    }
    for name in extracts:
        path = OSM / name
        lat, lon = POINTS.get(name, (0.0, 0.0))
        xml = OUT / (name.split(".")[0] + ".full.osm")
        _to_xml(path, xml)
        per: dict[str, Any] = {"bytes": path.stat().st_size, "point": [lat, lon]}
        for case in ("camloc_full", "osmnx_full", "camloc_point", "camloc_cached"):
            runs = [_run(case, path, lat, lon, xml) for _ in range(args.repeat)]
            best = min(runs, key=lambda r: r["seconds"])
            best["seconds_all"] = [round(r["seconds"], 4) for r in runs]
            best["peak_rss_mib"] = max(r["peak_rss_mib"] for r in runs)
            per[case] = best
            log.info(
                "%-22s %-14s %8.3f s wall %8.3f s cpu  peak %6.1f MiB (+%.1f over imports)",
                name,
                case,
                best["seconds"],
                best["cpu_seconds"],
                best["peak_rss_mib"],
                best["peak_increase_mib"],
            )
        results["extracts"][name] = per
    (OUT / "osm_load.json").write_text(json.dumps(results, indent=2), encoding="utf-8")
    _plot(results, OUT / "osm_load.png")
    log.info("wrote %s", OUT / "osm_load.json")
    return 0


def _plot(results: dict[str, Any], png: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = ["camloc_full", "osmnx_full", "camloc_point", "camloc_cached"]
    names = list(results["extracts"])
    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(11, 4))
    width = 0.8 / len(cases)
    for i, case in enumerate(cases):
        xs = [k + i * width for k in range(len(names))]
        ax_t.bar(
            xs, [results["extracts"][n][case]["cpu_seconds"] for n in names], width, label=case
        )
        ax_m.bar(
            xs, [results["extracts"][n][case]["peak_rss_mib"] for n in names], width, label=case
        )
    for ax, title in ((ax_t, "CPU time (s)"), (ax_m, "peak RSS (MiB)")):
        ax.set_xticks([k + 0.4 - width / 2 for k in range(len(names))], names)
        ax.set_title(title)
    ax_t.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=100)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
