"""In-process CPU cost of one HTTP service ``/v1/locate`` request, with a cProfile breakdown.

Builds the same five-annotator scenes as ``service_load.py`` (seeded, every point moved by
up to a pixel), runs the service's locate path (parse, calibrate, locate, JSON) in this
process on the bundled Baltimore extract, and reports the median CPU time per request and
the top functions of a profile, and the CPU of each stage of the path (parse, calibrate,
each stage of :func:`camloc_geo.absolute.locate`, the candidate collection, JSON), which a
profile's call overhead distorts. Writes ``benchmarks/out/locate_profile.json``.

    PYTHONPATH=$PWD python benchmarks/locate_profile.py --scenes 12 --sort tottime
"""

from __future__ import annotations

import argparse
import cProfile
import functools
import io
import json
import pstats
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from service_load import scene_bodies

from camloc_geo.absolute import _pipeline
from camloc_geo.scene import parse_scene
from camloc_geo.service.compute import _as_json
from camloc_geo.service.mapstore import MapStore
from camloc_geo.service.routers.scenes import locate_work
from camloc_geo.service.settings import Settings

OUT_DIR = Path(__file__).resolve().parent / "out"

# The stages of absolute.locate (module-level functions of _pipeline), timed in place; nested
# ones (scoring inside _other_junction_candidates) count in both.
STAGES = (
    "gather_evidence",
    "generate_hypotheses",
    "score_hypothesis",
    "score_hypotheses",
    "_other_junction_candidates",
    "prior_gate",
    "normalise_and_merge",
    "expected_plausibility",
    "refine_leaders",
    "rank",
    "bundle_leaders",
    "mark_ties",
)


def stage_cpu_ms(maps: MapStore, bodies: list[dict[str, object]]) -> dict[str, float]:
    """Median CPU (ms) per request of each stage of the locate path, without a profiler."""
    from camloc_geo.api import calibrate_scene, map_for_scene
    from camloc_geo.results import candidates_collection, to_json

    spent: dict[str, float] = {}
    originals = {}

    def timed(name: str, fn: object) -> object:
        @functools.wraps(fn)  # type: ignore[arg-type]
        def run(*a: object, **k: object) -> object:
            t0 = time.process_time()
            try:
                return fn(*a, **k)  # type: ignore[operator]
            finally:
                spent[name] = spent.get(name, 0.0) + time.process_time() - t0

        return run

    for name in STAGES:
        if hasattr(_pipeline, name):
            originals[name] = getattr(_pipeline, name)
            setattr(_pipeline, name, timed(name, originals[name]))
    per: dict[str, list[float]] = {}
    try:
        for body in bodies:
            spent.clear()
            t0 = time.process_time()
            sc = parse_scene(body)
            t1 = time.process_time()
            cal = calibrate_scene(sc)
            t2 = time.process_time()
            m = map_for_scene(sc, map_source=maps.catalogue, network=False)
            res = _pipeline.locate(sc, m, calibration=cal)
            t3 = time.process_time()
            coll = candidates_collection(res)
            t4 = time.process_time()
            to_json(coll)
            t5 = time.process_time()
            row = {"parse": t1 - t0, "calibrate": t2 - t1, "locate": t3 - t2}
            row.update({f"  {k}": v for k, v in spent.items()})
            row.update({"candidates_collection": t4 - t3, "to_json": t5 - t4})
            for k, v in row.items():
                per.setdefault(k, []).append(1000.0 * v)
    finally:
        for name, fn in originals.items():
            setattr(_pipeline, name, fn)
    return {k: round(statistics.median(v), 2) for k, v in per.items()}


def main() -> None:
    """Time and profile the service's locate path; print and write the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=12, help="scenes (first one warms up)")
    parser.add_argument("--sort", default="tottime", help="pstats sort key")
    parser.add_argument("--top", type=int, default=30, help="profile rows to keep")
    parser.add_argument("--map-dir", default="sample_maps")
    args = parser.parse_args()

    maps = MapStore(Settings(map_dir=args.map_dir))
    bodies = [json.loads(b) for b in scene_bodies(args.scenes)]
    _as_json(maps, locate_work, parse_scene(bodies[0]), None)  # warm the map cache

    cpu_s = []
    for body in bodies[1:]:
        t0 = time.process_time()
        _as_json(maps, locate_work, parse_scene(body), None)
        cpu_s.append(time.process_time() - t0)
    median_ms = 1000.0 * statistics.median(cpu_s)
    print(f"service locate path: median {median_ms:.1f} ms CPU per request ({len(cpu_s)} scenes)")
    stages = stage_cpu_ms(maps, bodies[1:])
    print("median CPU per stage (ms; locate's stages indented):")
    for k, v in stages.items():
        print(f"  {k:32s} {v:7.2f}")

    profiler = cProfile.Profile()
    profiler.enable()
    for body in bodies[1:]:
        _as_json(maps, locate_work, parse_scene(body), None)
    profiler.disable()
    stream = io.StringIO()
    stats = pstats.Stats(profiler, stream=stream).sort_stats(args.sort)
    stats.print_stats(args.top)
    print(stream.getvalue())

    n = len(bodies) - 1
    rows = []
    for (path, line, name), (_cc, ncalls, tt, ct, _callers) in stats.stats.items():  # type: ignore[attr-defined]
        rows.append(
            {
                "function": f"{Path(path).name}:{line}({name})",
                "calls_per_request": ncalls / n,
                "tottime_ms_per_request": 1000.0 * tt / n,
                "cumtime_ms_per_request": 1000.0 * ct / n,
            }
        )
    key = "cumtime_ms_per_request" if args.sort.startswith("cum") else "tottime_ms_per_request"
    rows.sort(key=lambda r: -r[key])
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    out = OUT_DIR / "locate_profile.json"
    out.write_text(
        json.dumps(
            {
                "scenes": len(cpu_s),
                "median_cpu_ms_per_request": median_ms,
                "median_cpu_ms_per_stage": stages,
                "cpu_ms_per_request": [1000.0 * t for t in cpu_s],
                "sort": args.sort,
                "top": rows[: args.top],
            },
            indent=2,
        )
    )
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
