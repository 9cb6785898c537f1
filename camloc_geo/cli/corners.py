"""``camloc corners``: GeoJSON of the intersections near a point, with their kerb corners."""

from __future__ import annotations

import argparse
from typing import Any

from camloc_geo.cli import NETWORK_HELP, add_map_options, network_of, write_json

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``corners`` sub-command."""
    parser = subparsers.add_parser(
        "corners",
        help="intersections and their kerb corners near a point (GeoJSON)",
        description=(
            "Write a GeoJSON FeatureCollection of the road intersections within --radius-m "
            "of the point (or the one where --streets meet): Point features kind=intersection "
            "(id, streets) and kind=corner (intersection, order clockwise from above, streets). "
            "Map data © OpenStreetMap contributors (ODbL). " + NETWORK_HELP
        ),
    )
    add_map_options(parser, online_flag=True)
    parser.add_argument("--lat", type=float, required=True, help="latitude, degrees WGS 84")
    parser.add_argument("--lon", type=float, required=True, help="longitude, degrees WGS 84")
    parser.add_argument("--radius-m", type=float, default=150.0, help="search radius (150)")
    parser.add_argument("--streets", help='only the intersection where they meet, "A & B"')
    parser.add_argument("-o", "--output", metavar="OUT.geojson", help="output file (stdout)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``camloc corners``."""
    from camloc_geo.api import check_map_radius_m, corners_near
    from camloc_geo.cli import json_path

    check_map_radius_m(args.radius_m, "--radius-m")  # before the map is read
    json_path(args.output, inputs=[args.osm], what="GeoJSON")
    gj = corners_near(
        lat=args.lat,
        lon=args.lon,
        radius_m=args.radius_m,
        map_source=args.osm,
        network=network_of(args),
        streets=args.streets,
        cache_folder=args.cache_folder,
        overpass_url=args.overpass_url,
    )
    write_json(gj, args.output, inputs=[args.osm])
    return 0
