"""``camloc corners``: GeoJSON of the intersections near a point, with their kerb corners."""

from __future__ import annotations

import argparse
from typing import Any

from camloc_geo.cli import write_json

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
            "Map data © OpenStreetMap contributors (ODbL)."
        ),
    )
    parser.add_argument(
        "--osm",
        metavar="EXTRACT",
        help=".osm/.osm.gz/.osm.bz2/.osm.pbf extract (omit with --online to query Overpass)",
    )
    parser.add_argument("--online", action="store_true", help="query Overpass live via osmnx")
    parser.add_argument("--lat", type=float, required=True, help="latitude, degrees WGS 84")
    parser.add_argument("--lon", type=float, required=True, help="longitude, degrees WGS 84")
    parser.add_argument("--radius-m", type=float, default=150.0, help="search radius (150)")
    parser.add_argument("--streets", help='only the intersection where they meet, "A & B"')
    parser.add_argument("-o", "--output", metavar="OUT.geojson", help="output file (stdout)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``camloc corners``."""
    from camloc_geo._errors import InputError
    from camloc_geo.osm import intersections_geojson, load_map

    if not args.osm and not args.online:
        raise InputError("give --osm EXTRACT or --online")
    m = load_map(args.osm if not args.online else None, args.lat, args.lon, args.radius_m)
    if args.streets:
        inters = [m.find_intersection(args.streets, near=(args.lat, args.lon))]
    else:
        inters = m.intersections
    write_json(intersections_geojson(inters), args.output)
    return 0
