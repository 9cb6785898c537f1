"""In-process CPU cost of one HTTP service ``/v1/locate`` request, with a cProfile breakdown.

Builds the same five-annotator scenes as ``service_load.py`` (seeded, every point moved by
up to a pixel), runs the service's locate path (parse, calibrate, locate, JSON) in this
process on the bundled Baltimore extract, and reports the median CPU time per request and
the top functions of a profile. Writes ``benchmarks/out/locate_profile.json``.

    PYTHONPATH=$PWD python benchmarks/locate_profile.py --scenes 12 --sort tottime
"""

from __future__ import annotations

import argparse
import cProfile
import io
import json
import pstats
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from service_load import scene_bodies

from camloc_geo.scene import parse_scene
from camloc_geo.service.compute import _as_json
from camloc_geo.service.mapstore import MapStore
from camloc_geo.service.routers.scenes import locate_work
from camloc_geo.service.settings import Settings

OUT_DIR = Path(__file__).resolve().parent / "out"


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
