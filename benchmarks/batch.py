"""Benchmark ``run_batch`` on 1,000 synthetic cameras over two city extracts.

Reports cameras per second, peak memory (main process + workers), seconds per stage, and a
plot of memory against cameras done, next to the paper's 0.41 s per image. Writes
``benchmarks/out/batch.json`` and ``benchmarks/out/batch_memory.png``.

    python benchmarks/batch.py [--n 1000] [--workers 2]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import shutil
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
OUT = REPO / "benchmarks" / "out"
PAPER_S_PER_IMAGE = 0.41


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--scene-fraction", type=float, default=0.5)
    args = ap.parse_args()

    sys.path.insert(0, str(REPO / "tests"))
    import _geocode_double
    import psutil

    stand_in = _geocode_double.install_if_missing()
    from camloc_geo.batch import run_batch
    from camloc_geo.testing.camera_list import make_camera_list

    work = OUT / "batch_work"
    lst = work / f"cameras_{args.n}.csv"
    osm = [REPO / "data" / "osm" / "baltimore.osm.pbf", REPO / "data" / "osm" / "helsinki.osm.pbf"]
    t = time.perf_counter()
    if not lst.exists():
        make_camera_list(
            work, osm, args.n, seed=1, scene_fraction=args.scene_fraction, name=lst.name
        )
    gen_s = time.perf_counter() - t
    folder = work / "osm"
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir()
    for p in osm:
        (folder / p.name).symlink_to(p)
    out = work / "out.gpkg"
    me = psutil.Process()
    samples: list[tuple[int, float]] = []

    def rss_mb() -> float:
        procs = [me, *me.children(recursive=True)]
        total = 0
        for p in procs:
            with contextlib.suppress(psutil.Error):
                total += p.memory_info().rss
        return total / 2**20

    samples.append((0, rss_mb()))
    t0 = time.perf_counter()
    summary = run_batch(
        lst,
        out_gpkg=out,
        map_source=folder,
        summary_map=work / "summary.html",
        progress=False,
        workers=args.workers,
        restart=True,
        on_chunk=lambda n: samples.append((n, rss_mb())),
    )
    wall = time.perf_counter() - t0
    n = summary.total
    result = {
        "cameras": n,
        "workers": args.workers,
        "wall_s": round(wall, 2),
        "cameras_per_s": round(n / wall, 1),
        "s_per_camera": round(wall / n, 4),
        "paper_s_per_image": PAPER_S_PER_IMAGE,
        "target_wall_s": 30.0,
        "peak_rss_mb": round(max(m for _n, m in samples), 1),
        "rss_first_mb": round(samples[1][1] if len(samples) > 1 else samples[0][1], 1),
        "rss_last_mb": round(samples[-1][1], 1),
        "stage_s": summary.to_dict()["stage_s"],
        "statuses": summary.statuses,
        "list_generation_s": round(gen_s, 1),
        "geocoder": "tests/_geocode_double stand-in" if stand_in else "camloc_geo.geocode",
    }
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "batch.json").write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    print(json.dumps(result, indent=2))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot([s[0] for s in samples], [s[1] for s in samples], marker=".")
    ax.set_xlabel("cameras done")
    ax.set_ylabel("RSS, main + workers (MiB)")
    ax.set_title(f"camloc batch: {n} cameras in {wall:.1f} s on {args.workers} workers")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(OUT / "batch_memory.png", dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
