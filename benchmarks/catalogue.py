"""Which extract serves a point: :meth:`camloc_geo.osm.MapCatalogue.area_for_point` per camera.

A batch, a job map and the geocoder ask the catalogue for each camera's area. Before session
41 each question stat-ed and normalised the path of every extract of the folder (and
re-stat-ed the chosen one's size); the catalogue now indexes its extracts once (bounds and
sizes, smallest first) and re-reads them only when their folder changes.

Asks ``--points`` points (spread over the extracts' boxes, a fifth outside every one) of the
catalogue of ``--folder`` (default: ``data/osm``, 26 extracts) and records the seconds per
``--points`` questions (best of ``--repeat``) and the areas' digest (the answers must not
change)::

    python benchmarks/catalogue.py [--points 3000] [--repeat 5] [--label after]

Writes ``benchmarks/out/catalogue_<label>.json``.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import platform
import random
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
OUT = REPO / "benchmarks" / "out"


def main() -> None:
    """Run the benchmark and write its JSON."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--folder", default=str(REPO / "data" / "osm"))
    ap.add_argument("--points", type=int, default=3000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--label", default="after")
    args = ap.parse_args()

    from camloc_geo.osm import MapCatalogue, extract_bounds

    cat = MapCatalogue.from_source(args.folder)
    boxes = [extract_bounds(f) for f in cat.files]
    rng = random.Random(41)
    points = []
    for k in range(args.points):
        if k % 5 == 4:
            points.append((rng.uniform(-60, -50), rng.uniform(-170, -160)))  # no extract
            continue
        s, w, n, e = boxes[k % len(boxes)]
        points.append((rng.uniform(s, n), rng.uniform(w, e)))
    cat.area_for_point(*points[0])  # bounds read (the first question pays for it)
    best = float("inf")
    areas: list[str] = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        areas = [repr(cat.area_for_point(lat, lon)) for lat, lon in points]
        best = min(best, time.perf_counter() - t0)
    digest = hashlib.sha256("\n".join(areas).encode()).hexdigest()[:16]
    out = {
        "label": args.label,
        "extracts": len(cat.files),
        "points": args.points,
        "repeat": args.repeat,
        "best_s": round(best, 4),
        "us_per_point": round(best / args.points * 1e6, 1),
        "areas_sha256_16": digest,
        "python": platform.python_version(),
    }
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / f"catalogue_{args.label}.json"
    path.write_text(json.dumps(out, indent=2) + "\n")
    print(json.dumps(out))


if __name__ == "__main__":
    main()
