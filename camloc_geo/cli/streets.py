"""``camloc streets``: the streets near a point with their bearings (JSON)."""

from __future__ import annotations

import argparse
from typing import Any

from camloc_geo.cli import NETWORK_HELP, add_map_options, network_of, write_json

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``streets`` sub-command."""
    parser = subparsers.add_parser(
        "streets",
        help="streets near a point with their bearings (JSON)",
        description=(
            "Print JSON: 'near' lists the streets passing within --near-m of the point with "
            "their local bearing in [0, 180) degrees from true north; 'streets' lists every "
            "street loaded within --radius-m. Map data © OpenStreetMap contributors (ODbL). "
            + NETWORK_HELP
        ),
    )
    add_map_options(parser, online_flag=True)
    parser.add_argument("--lat", type=float, required=True, help="latitude, degrees WGS 84")
    parser.add_argument("--lon", type=float, required=True, help="longitude, degrees WGS 84")
    parser.add_argument("--radius-m", type=float, default=150.0, help="area loaded (150)")
    parser.add_argument("--near-m", type=float, default=50.0, help="'near' radius (50)")
    parser.add_argument("-o", "--output", metavar="OUT.json", help="output file (stdout)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``camloc streets``."""
    import math

    from camloc_geo._errors import InputError
    from camloc_geo.api import check_map_radius_m, streets_near
    from camloc_geo.cli import json_path
    from camloc_geo.results import streets_json

    if not (math.isfinite(args.near_m) and args.near_m >= 0):
        # nan ended in "failed: ValueError: Out of range float values..." (exit 1) after
        # loading the map; a negative value listed nothing near, without a word
        raise InputError(f"--near-m must be a number of metres, 0 or more, got {args.near_m}")
    check_map_radius_m(args.radius_m, "--radius-m")  # before the map is read
    json_path(args.output, inputs=[args.osm])
    m = streets_near(
        lat=args.lat,
        lon=args.lon,
        radius_m=args.radius_m,
        map_source=args.osm,
        network=network_of(args),
        cache_folder=args.cache_folder,
        overpass_url=args.overpass_url,
    )
    write_json(streets_json(m, args.lat, args.lon, args.near_m), args.output, inputs=[args.osm])
    return 0
