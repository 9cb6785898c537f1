"""Benchmark title geocoding: precision and recall on generated titles, and speed.

Accuracy: for each extract, titles are generated from osmnx's own graph of it
(``tests/geocode_reference.py``: OSM names at graph nodes where two named streets meet,
rewritten abbreviated, upper case, accent-free, with camera numbers, typos, the N/S half
left out; plus titles that must not be placed). A junction title is correct when its best
match lies within 30 m of the reference node (``ambiguous``: when one of its places does).

- precision = correct placed junction titles / placed junction titles;
- recall = correct placed junction titles / junction titles;
- far = junction titles placed more than 150 m away / junction titles;
- negatives_ok = titles that must not be placed and got the right status.

Speed: 10,000 distinct titles (every style of every name pair of the extract, camera
numbers varied) over one city extract, the map loaded once; the name index is built on
the first title and timed apart.

Results: ``benchmarks/out/geocode.json`` and ``benchmarks/out/geocode.png``::

    python benchmarks/geocode.py [--extract baltimore.osm.pbf ...] [--speed-extract NAME]
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT = HERE / "out"
OSM = ROOT / "data" / "osm"
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT))

DEFAULT_EXTRACTS = [
    "baltimore.osm.pbf",
    "berlin_alexanderplatz.osm.pbf",
    "paris_bss.osm.pbf",
    "fremantle.osm",
    "heidelberg_altstadt.osm.pbf",
    "moscow_ostankino.osm.gz",
    "krems.osm.gz",
    "campo_grande.osm.gz",
]


def _accuracy(path: Path, max_junctions: int) -> dict[str, Any]:
    from geocode_reference import _dist_m, reference_titles

    from camloc_geo.geocode import geocode_title, whole_map

    refs = reference_titles(path, max_junctions=max_junctions)
    m = whole_map(path)
    junctions = [r for r in refs if r.expect == "junction"]
    negatives = [r for r in refs if r.expect != "junction"]
    correct = placed = far = 0
    by_style: dict[str, list[int]] = {}
    failures: list[dict[str, Any]] = []
    for r in junctions:
        found = geocode_title(r.title, map_data=m, near=r.near, radius_m=300.0 if r.near else None)
        best = found[0]
        options = [x for x in found if x.status == "ambiguous"] or [best]
        dists = [
            _dist_m(r.lat, r.lon, x.lat, x.lon)  # type: ignore[arg-type]
            for x in options
            if x.placed
        ]
        ok = bool(dists) and min(dists) <= 30.0
        if best.placed:
            placed += 1
            if min(dists) > 150.0:
                far += 1
        correct += ok
        by_style.setdefault(r.style, [0, 0])
        by_style[r.style][0] += ok
        by_style[r.style][1] += 1
        if not ok:
            failures.append(
                {
                    "title": r.title,
                    "expected": list(r.names),
                    "status": best.status,
                    "matched": best.names_matched,
                    "distance_m": round(min(dists), 1) if dists else None,
                    "reason": best.reason,
                }
            )
    neg_ok = 0
    for r in negatives:
        best = geocode_title(r.title, map_data=m)[0]
        if best.status == r.expect:
            neg_ok += 1
        else:
            failures.append({"title": r.title, "expected": r.expect, "status": best.status})
    n = len(junctions)
    return {
        "extract": path.name,
        "junction_titles": n,
        "placed": placed,
        "correct_30m": correct,
        "precision": correct / placed if placed else None,
        "recall": correct / n if n else None,
        "far_150m": far / n if n else None,
        "negatives": len(negatives),
        "negatives_ok": neg_ok,
        "recall_by_style": {k: v[0] / v[1] for k, v in sorted(by_style.items())},
        "failures": failures[:30],
    }


def _speed(path: Path, n_titles: int) -> dict[str, Any]:
    from geocode_reference import osmnx_graph, reference_titles

    from camloc_geo.geocode import geocode_title, index_for, whole_map
    from camloc_geo.osm import clear_cache

    graph = osmnx_graph(path)
    titles: list[str] = []
    seen: set[str] = set()
    seed = 0
    while len(titles) < n_titles and seed < 200:
        for r in reference_titles(path, max_junctions=100_000, seed=seed, graph=graph):
            if r.title not in seen:
                seen.add(r.title)
                titles.append(r.title)
        seed += 1
    titles = titles[:n_titles]
    clear_cache()  # load and index from scratch
    t0 = time.perf_counter()
    m = whole_map(path)
    t_load = time.perf_counter() - t0
    t0 = time.perf_counter()
    index_for(m)
    t_index = time.perf_counter() - t0
    times = []
    statuses: dict[str, int] = {}
    t0 = time.perf_counter()
    for title in titles:
        t1 = time.perf_counter()
        best = geocode_title(title, map_data=m)[0]
        times.append(time.perf_counter() - t1)
        statuses[best.status] = statuses.get(best.status, 0) + 1
    total = time.perf_counter() - t0
    times.sort()
    return {
        "extract": path.name,
        "titles": len(titles),
        "distinct_titles": len(set(titles)),
        "load_s": round(t_load, 3),
        "index_s": round(t_index, 3),
        "geocode_s": round(total, 3),
        "titles_per_s": round(len(titles) / total, 1),
        "median_ms": round(1000 * times[len(times) // 2], 3),
        "p99_ms": round(1000 * times[int(len(times) * 0.99)], 3),
        "statuses": statuses,
        "target_s": 10.0,
        "cumulative_s": [round(sum(times[: i + 1]), 4) for i in range(0, len(times), 100)],
    }


def _plot(result: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    acc = result["accuracy"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 4.8))
    names = [a["extract"].split(".")[0] for a in acc]
    x = range(len(acc))
    ax1.bar([i - 0.2 for i in x], [a["precision"] or 0 for a in acc], 0.4, label="precision")
    ax1.bar([i + 0.2 for i in x], [a["recall"] or 0 for a in acc], 0.4, label="recall")
    ax1.axhline(0.9, color="k", lw=0.8, ls="--", label="90 % target")
    ax1.set_xticks(list(x), names, rotation=30, ha="right")
    ax1.set_ylim(0, 1.05)
    ax1.set_title("junction titles within 30 m (osmnx reference)")
    ax1.legend(loc="lower right")
    sp = result["speed"]
    per_title = sorted(sp["cumulative_s"])
    ax2.plot([i * 100 for i in range(len(per_title))], per_title)
    ax2.axhline(sp["target_s"], color="r", ls="--", label="10 s target")
    ax2.set_xlabel("titles")
    ax2.set_ylabel("cumulative geocoding time, s")
    ax2.set_title(
        f"{sp['extract']}: {sp['titles']} titles in {sp['geocode_s']} s "
        f"(+ index {sp['index_s']} s, load {sp['load_s']} s)"
    )
    ax2.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> int:
    """Run the benchmark; write JSON and PNG to benchmarks/out/."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--extract", action="append", help="extract names in data/osm")
    parser.add_argument("--speed-extract", default="baltimore.osm.pbf")
    parser.add_argument("--titles", type=int, default=10_000)
    parser.add_argument("--max-junctions", type=int, default=150)
    args = parser.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    accuracy = []
    for name in args.extract or DEFAULT_EXTRACTS:
        row = _accuracy(OSM / name, args.max_junctions)
        accuracy.append(row)
        print(
            f"{name}: precision {row['precision']:.3f} recall {row['recall']:.3f} "
            f"far {row['far_150m']:.3f} negatives {row['negatives_ok']}/{row['negatives']}",
            flush=True,
        )
    speed = _speed(OSM / args.speed_extract, args.titles)
    print(
        f"speed: {speed['titles']} titles in {speed['geocode_s']} s "
        f"(index {speed['index_s']} s, load {speed['load_s']} s)",
        flush=True,
    )
    total_j = sum(a["junction_titles"] for a in accuracy)
    total_c = sum(a["correct_30m"] for a in accuracy)
    total_p = sum(a["placed"] for a in accuracy)
    result = {
        "machine": platform.platform(),
        "python": platform.python_version(),
        "overall": {
            "junction_titles": total_j,
            "precision": total_c / total_p if total_p else None,
            "recall": total_c / total_j if total_j else None,
        },
        "accuracy": accuracy,
        "speed": speed,
    }
    (OUT / "geocode.json").write_text(json.dumps(result, indent=2), encoding="utf-8")
    _plot(result, OUT / "geocode.png")
    print(json.dumps(result["overall"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
