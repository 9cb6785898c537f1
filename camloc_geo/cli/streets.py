"""``camloc streets``: the streets near a point with their bearings (JSON)."""

from __future__ import annotations

import argparse
from typing import Any

from camloc_geo.cli import write_json

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``streets`` sub-command."""
    parser = subparsers.add_parser(
        "streets",
        help="streets near a point with their bearings (JSON)",
        description=(
            "Print JSON: 'near' lists the streets passing within --near-m of the point with "
            "their local bearing in [0, 180) degrees from true north; 'streets' lists every "
            "street loaded within --radius-m. Map data © OpenStreetMap contributors (ODbL)."
        ),
    )
    parser.add_argument("--osm", metavar="EXTRACT", help=".osm/.osm.gz/.osm.bz2/.osm.pbf extract")
    parser.add_argument("--online", action="store_true", help="query Overpass live via osmnx")
    parser.add_argument("--lat", type=float, required=True, help="latitude, degrees WGS 84")
    parser.add_argument("--lon", type=float, required=True, help="longitude, degrees WGS 84")
    parser.add_argument("--radius-m", type=float, default=150.0, help="area loaded (150)")
    parser.add_argument("--near-m", type=float, default=50.0, help="'near' radius (50)")
    parser.add_argument("-o", "--output", metavar="OUT.json", help="output file (stdout)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``camloc streets``."""
    from camloc_geo._errors import InputError
    from camloc_geo.osm import load_map, streets_json

    if not args.osm and not args.online:
        raise InputError("give --osm EXTRACT or --online")
    m = load_map(args.osm if not args.online else None, args.lat, args.lon, args.radius_m)
    write_json(streets_json(m, args.lat, args.lon, args.near_m), args.output)
    return 0
