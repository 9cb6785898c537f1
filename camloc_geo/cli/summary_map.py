"""``camloc summary-map``: one Leaflet page with the best candidate of many cameras."""

from __future__ import annotations

import argparse
import json
import logging
import math
from pathlib import Path
from typing import Any

from camloc_geo._errors import InputError

__all__ = ["register", "run"]

log = logging.getLogger(__name__)


def register(subparsers: Any) -> None:
    """Add the ``summary-map`` sub-command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "summary-map",
        help="Leaflet page of many cameras' best candidates (from camloc locate GeoJSON)",
        description=(
            "Read candidate GeoJSON files written by `camloc locate` and write one HTML page with "
            "the best candidate of each camera (arrow = heading, colour = score; popups with id, "
            "score, method). Cameras without candidates are listed in the page's title box."
        ),
    )
    p.add_argument("inputs", nargs="+", metavar="CANDIDATES.geojson", help="camloc locate output")
    p.add_argument("-o", "--output", metavar="OUT.html", required=True, help="page to write")
    p.add_argument(
        "--offline",
        action="store_true",
        help="one self-contained file (Leaflet inlined, no tiles, plain markers)",
    )
    p.add_argument(
        "--osm",
        metavar="EXTRACT",
        help="draw this extract's streets and buildings (within 500 m of the cameras' centre)",
    )
    p.add_argument("--no-cluster", action="store_true", help="plain markers on online pages too")
    p.set_defaults(func=run)


def _read(path: str) -> tuple[str, dict[str, Any]]:
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError as exc:
        raise InputError(f"{path}: no such file") from exc
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path}: not a JSON file ({exc})") from exc
    if not isinstance(data, dict) or data.get("type") != "FeatureCollection":
        raise InputError(f"{path}: not a GeoJSON FeatureCollection (camloc locate output)")
    props = data.get("properties") or {}
    scene_id = str(props.get("scene") or Path(path).stem)
    return scene_id, data


def run(args: argparse.Namespace) -> int:
    """Run ``camloc summary-map``."""
    from camloc_geo.maps import summary_map

    items = [_read(p) for p in args.inputs]
    map_data = None
    if args.osm:
        from camloc_geo.geodesy import LocalFrame
        from camloc_geo.osm import load_map

        pts = [
            (f["properties"]["lat"], f["properties"]["lon"])
            for _s, gj in items
            for f in gj.get("features", [])
            if (f.get("properties") or {}).get("kind") == "candidate"
            and f["properties"].get("rank") == 1
        ]
        if pts:
            lat = sum(p[0] for p in pts) / len(pts)
            lon = sum(p[1] for p in pts) / len(pts)
            frame = LocalFrame(lat=lat, lon=lon)
            radius = max(math.hypot(*frame.enu_from_geographic(lat=q[0], lon=q[1])) for q in pts)
            map_data = load_map(args.osm, lat, lon, radius_m=min(radius + 150.0, 2000.0))
    summary_map(
        items, args.output, offline=args.offline, cluster=not args.no_cluster, map_data=map_data
    )
    return 0
