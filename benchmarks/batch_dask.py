"""``run_batch`` on a Dask ``LocalCluster`` against two local processes: same answers, speed.

Generates (once, kept under ``benchmarks/out/batch_dask_work/``) a list of ``--n`` synthetic
cameras over two city extracts, every camera with an annotated scene (``--scene-fraction``),
then runs the list twice:

- ``local``: the default, ``workers=2`` local processes;
- ``dask``: a ``distributed.LocalCluster`` of 2 worker *processes* (1 thread each), passed as
  ``scheduler=Client``, the way a cluster is used.

and checks that the two GeoPackages hold the same rows (every layer, every column, the
geometries as WKB, exactly) and the two journals the same records. Writes
``benchmarks/out/batch_dask.json`` and ``benchmarks/out/batch_dask.png``::

    python benchmarks/batch_dask.py --n 10000
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
OUT = REPO / "benchmarks" / "out"
PAPER_S_PER_IMAGE = 0.41
LAYERS = ("cameras", "candidates", "view_cones", "errors")


def _layers(gpkg: Path) -> dict[str, Any]:
    import pandas as pd
    import pyogrio

    out = {}
    for name in LAYERS:
        df = pyogrio.read_dataframe(gpkg, layer=name)
        if "geometry" in df:
            wkb = [None if g is None else g.wkb_hex for g in df.geometry]
            df = pd.DataFrame(df.drop(columns="geometry")).assign(wkb=wkb)
        out[name] = df.reset_index(drop=True)
    return out


def _records(gpkg: Path) -> list[str]:
    from camloc_geo.batch._journal import Journal, journal_path

    j = Journal(journal_path(gpkg))
    try:
        return [json.dumps(r, sort_keys=True) for r in j.records()]
    finally:
        j.close()


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=10_000, help="cameras (10000)")
    ap.add_argument("--scene-fraction", type=float, default=1.0)
    ap.add_argument("--chunk-size", type=int, default=16)
    ns = ap.parse_args(argv)

    import pandas as pd
    from distributed import Client, LocalCluster

    from camloc_geo.batch import run_batch
    from camloc_geo.testing.camera_list import make_camera_list

    work = OUT / "batch_dask_work"
    extracts = [
        REPO / "data" / "osm" / "baltimore.osm.pbf",
        REPO / "data" / "osm" / "helsinki.osm.pbf",
    ]
    folder = work / "osm"
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    for p in extracts:
        (folder / p.name).symlink_to(p)
    lst = work / f"cameras_{ns.n}_{ns.scene_fraction:g}.csv"
    t = time.perf_counter()
    if not lst.exists():
        make_camera_list(
            work,
            list(folder.iterdir()),
            ns.n,
            seed=7,
            scene_fraction=ns.scene_fraction,
            name=lst.name,
        )
    gen_s = time.perf_counter() - t

    from camloc_geo.osm import clear_cache
    from camloc_geo.osm._catalogue import clear_maps

    # the list's generation loaded the extracts' maps in this process: forget them, or the
    # forked local workers would inherit them while the Dask workers load their own
    clear_maps()
    clear_cache()
    runs: dict[str, dict[str, Any]] = {}
    t0 = time.perf_counter()
    load_start = os.getloadavg()[0]
    local = run_batch(
        lst,
        out_gpkg=work / "local" / "out.gpkg",
        map_source=folder,
        progress=False,
        workers=2,
        chunk_size=ns.chunk_size,
        restart=True,
    )
    runs["local"] = {
        "wall_s": time.perf_counter() - t0,
        "load1_start_end": [load_start, os.getloadavg()[0]],
        "summary": local.to_dict(),
    }

    t0 = time.perf_counter()
    load_start = os.getloadavg()[0]
    with (
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as lc,
        Client(lc) as client,
    ):
        t_up = time.perf_counter() - t0
        dask = run_batch(
            lst,
            out_gpkg=work / "dask" / "out.gpkg",
            map_source=folder,
            scheduler=client,
            progress=False,
            chunk_size=ns.chunk_size,
            restart=True,
        )
    runs["dask"] = {
        "wall_s": time.perf_counter() - t0,
        "cluster_start_s": t_up,
        "load1_start_end": [load_start, os.getloadavg()[0]],
        "summary": dask.to_dict(),
    }

    a, b = _layers(work / "local" / "out.gpkg"), _layers(work / "dask" / "out.gpkg")
    layers_equal = {}
    for name in LAYERS:
        try:
            pd.testing.assert_frame_equal(a[name], b[name], check_exact=True)
            layers_equal[name] = True
        except AssertionError:
            layers_equal[name] = False
    rec_a, rec_b = _records(work / "local" / "out.gpkg"), _records(work / "dask" / "out.gpkg")
    differing = [i for i, (x, y) in enumerate(zip(rec_a, rec_b, strict=False)) if x != y]
    for r in runs.values():
        n = r["summary"]["total"]
        r["wall_s"] = round(r["wall_s"], 1)
        r["cameras_per_s"] = round(n / r["wall_s"], 1)
        r["s_per_camera"] = round(r["wall_s"] / n, 4)
        # the workers' CPU per camera: what the work costs, which a shared machine's load
        # (the wall time's main term here) does not stretch
        cpu = r["summary"]["stage_s"].get("geocode_cpu")
        r["worker_cpu_ms_per_camera"] = round(1000 * cpu / n, 1) if cpu is not None else None
    result = {
        "cameras": local.total,
        "scene_fraction": ns.scene_fraction,
        "chunk_size": ns.chunk_size,
        "list_generation_s": round(gen_s, 1),
        "paper_s_per_image": PAPER_S_PER_IMAGE,
        "runs": runs,
        "same_answers": {
            "layers_equal": layers_equal,
            "journal_records": len(rec_a),
            "journal_records_equal": len(rec_a) == len(rec_b) and not differing,
            "first_differing_rows": differing[:10],
        },
        "statuses": local.statuses,
    }
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "batch_dask.json").write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    print(json.dumps(result, indent=2))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    names = list(runs)
    ax.bar(names, [runs[k]["cameras_per_s"] for k in names], color=["tab:blue", "tab:orange"])
    ax.axhline(2 / PAPER_S_PER_IMAGE, color="grey", ls="--", label="paper, 2 cores (0.41 s/img)")
    ax.set_ylabel("cameras per second")
    same = "same answers" if result["same_answers"]["journal_records_equal"] else "DIFFERENT"
    ax.set_title(f"{local.total:,} cameras, 2 local processes vs Dask LocalCluster: {same}")
    ax.legend()
    fig.tight_layout()
    fig.savefig(OUT / "batch_dask.png", dpi=110)
    plt.close(fig)
    return 0 if result["same_answers"]["journal_records_equal"] else 1


if __name__ == "__main__":
    sys.exit(main())
