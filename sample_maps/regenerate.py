"""Regenerate the example review maps in ``sample_maps/`` from the bundled extracts.

Usage (from the repository root)::

    python sample_maps/regenerate.py [--out sample_maps] [--online]

Each camera is a synthetic scene (:func:`camloc_geo.testing.synthetic.make_located_scene`, fixed
seeds, the default annotation noise) at a real intersection of a bundled extract, located with
:func:`camloc_geo.absolute.locate`; its page is written offline (one self-contained HTML file,
overlays embedded). The synthetic scenes have no picture, so the overlays are drawn on a blank
canvas. ``sample_scene.html`` maps the bundled ``sample_scene.json``. A summary map of
the Baltimore cameras (with more synthetic cameras at the
junctions around Fells Point) closes the set.

Folium gives its elements random ids, so regenerated pages differ byte-wise from the committed
ones while showing the same thing.
"""

from __future__ import annotations

import argparse
import logging
from pathlib import Path
from typing import Any

import numpy as np

from camloc_geo.absolute import LocateResult, locate
from camloc_geo.maps import candidates_map, summary_map
from camloc_geo.osm import load_map
from camloc_geo.scene import load_scene, parse_scene
from camloc_geo.testing.synthetic import make_located_scene

log = logging.getLogger("sample_maps")

HERE = Path(__file__).resolve().parent

# (page name, extract, centre lat, lon, intersection query, seed, minimum visible corners)
CAMERAS: list[tuple[str, str, float, float, str, int, int]] = [
    (
        "baltimore_eastern_broadway",
        "baltimore.osm.pbf",
        39.285580,
        -76.593484,
        "Eastern Ave & S Broadway",
        11,
        2,
    ),
    (
        "baltimore_eastern_bond",
        "baltimore.osm.pbf",
        39.2854942,
        -76.5953525,
        "Eastern Ave & S Bond St",
        3,
        3,
    ),
    (
        "fremantle_stirling_tydeman",
        "fremantle.osm",
        -32.036172,
        115.755714,
        "Stirling Hwy & Tydeman Rd",
        0,
        3,
    ),
]


def _locate_camera(
    name: str,
    extract: str,
    lat: float,
    lon: float,
    query: str,
    seed: int,
    min_corners: int,
    out: Path,
    offline: bool,
) -> LocateResult:
    map_data = load_map(HERE / extract, lat, lon, radius_m=300)
    inter = map_data.find_intersection(query)
    ls = make_located_scene(map_data, inter, np.random.default_rng(seed), min_corners=min_corners)
    if ls is None:
        raise RuntimeError(f"{name}: no synthetic view of {query} with seed {seed}")
    ls.scene["id"] = name
    scene = parse_scene(ls.scene)
    result = locate(scene, map_data)
    page = candidates_map(result, map_data, out / f"{name}.html", offline=offline, scene=scene)
    log.info("%s: %d candidates, page %d bytes", name, len(result.candidates), page.stat().st_size)
    return result


def main(argv: list[str] | None = None) -> int:
    """Write the sample pages; returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument(
        "--out", type=Path, default=HERE, help="output folder (default sample_maps/)"
    )
    parser.add_argument("--online", action="store_true", help="online pages (CDN links, OSM tiles)")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(name)s: %(message)s")
    args.out.mkdir(parents=True, exist_ok=True)
    offline = not args.online
    items: list[tuple[str, Any]] = []
    for cam in CAMERAS:
        result = _locate_camera(*cam, out=args.out, offline=offline)
        if cam[1] == "baltimore.osm.pbf":
            items.append((cam[0], result))
    # The bundled sample scene (what the README's ``camloc locate`` example maps).
    sample = load_scene(HERE / "sample_scene.json")
    bmap = load_map(HERE / "baltimore.osm.pbf", 39.28558, -76.59348, radius_m=300)
    sample_result = locate(sample, bmap)
    candidates_map(
        sample_result, bmap, args.out / "sample_scene.html", offline=offline, scene=sample
    )
    items.append((sample.id, sample_result))
    # More cameras around Fells Point for the summary map of Baltimore.
    base = load_map(HERE / "baltimore.osm.pbf", 39.2852, -76.5945, radius_m=400)
    junctions = [i for i in base.intersections if i.kind == "junction" and len(i.corners) >= 3]
    rng = np.random.default_rng(2024)
    for k, inter in enumerate(junctions[:8]):
        ls = make_located_scene(base, inter, rng, min_corners=2)
        if ls is None:
            continue
        ls.scene["id"] = f"baltimore-{k:02d}"
        items.append((ls.scene["id"], locate(parse_scene(ls.scene), base)))
    page = summary_map(items, args.out / "baltimore_summary.html", offline=offline, map_data=base)
    log.info("summary: %d cameras, page %d bytes", len(items), page.stat().st_size)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
