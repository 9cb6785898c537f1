"""``camloc annotate IMAGE``: an offline annotation page that saves a scene file."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

__all__ = ["junction_geojson", "register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``annotate`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "annotate",
        help="write an offline HTML page to mark the car, lines and kerb corners on a snapshot",
        description=(
            "Write one self-contained HTML file (the snapshot embedded, nothing loaded from the "
            "network). Opened in a browser, it guides a person through marking the car, lines "
            "along each axis and the junction's kerb corners, checks the clicks live (vanishing "
            "points, focal length, horizon, wrong corner) and saves a camloc-scene/1 file. "
            "Images: JPEG, PNG or WebP."
        ),
    )
    p.add_argument("image", help="the snapshot (JPEG, PNG or WebP)")
    p.add_argument("-o", "--output", help="page to write (default: IMAGE_NAME.annotate.html here)")
    p.add_argument("--scene", help="an existing scene file to review or correct")
    p.add_argument("--osm", metavar="EXTRACT", help="OSM extract: show the junction on a small map")
    p.add_argument("--lat", type=float, help="the camera's coarse latitude (written as the prior)")
    p.add_argument("--lon", type=float, help="the camera's coarse longitude")
    p.add_argument("--radius-m", type=float, default=150.0, help="junction search radius (150)")
    p.add_argument("--streets", help='the junction where these streets meet, "A & B"')
    p.set_defaults(func=run)


def junction_geojson(
    *, lat: float, lon: float, map_source: Any, radius_m: float = 150.0, streets: str | None = None
) -> dict[str, Any]:
    """The junction nearest to a point (or where ``streets`` meet): corners and street lines.

    Returns the GeoJSON of :func:`camloc_geo.api.corners_near` reduced to one intersection,
    plus ``kind: "street"`` LineStrings within ``radius_m`` of it for context.
    """
    import numpy as np
    from shapely.geometry import LineString, Point, mapping

    from camloc_geo._errors import MapDataError
    from camloc_geo.api import corners_near, streets_near

    m = streets_near(
        lat=lat, lon=lon, radius_m=max(radius_m, 150.0), map_source=map_source, network=False
    )
    doc = corners_near(
        lat=lat, lon=lon, radius_m=radius_m, map_source=m, network=False, streets=streets
    )
    inters = [f for f in doc["features"] if f["properties"]["kind"] == "intersection"]
    if not inters:
        raise MapDataError(f"no road intersection within {radius_m:g} m of {lat}, {lon}")
    first = inters[0]
    ident = first["properties"]["id"]
    feats = [first] + [
        f
        for f in doc["features"]
        if f["properties"]["kind"] == "corner" and f["properties"]["intersection"] == ident
    ]
    jlon, jlat = first["geometry"]["coordinates"]
    east, north = m.frame.enu_from_geographic(lat=jlat, lon=jlon)
    centre = Point(east, north)
    for street in m.streets:
        lonlat = np.asarray(street.geometry.coords, dtype=float)
        e, n = m.frame.enu_from_geographic(lat=lonlat[:, 1], lon=lonlat[:, 0])
        if LineString(np.column_stack([e, n])).distance(centre) > 120.0:
            continue
        feats.append(
            {
                "type": "Feature",
                "geometry": mapping(street.geometry),
                "properties": {"kind": "street", "name": street.name},
            }
        )
    return {"type": "FeatureCollection", "attribution": doc.get("attribution"), "features": feats}


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo._errors import InputError
    from camloc_geo._io import write_text_atomic
    from camloc_geo.cli import page_path
    from camloc_geo.scene import load_scene
    from camloc_geo.web import annotation_page_html

    if (args.lat is None) != (args.lon is None):
        raise InputError("give --lat and --lon together")
    if args.streets and not args.osm:  # it was dropped without a word: a page without them
        raise InputError("--streets needs --osm EXTRACT (the junction is looked up in the map)")
    if args.osm:
        from camloc_geo.api import check_map_radius_m

        check_map_radius_m(args.radius_m, "--radius-m")  # before the map is read
    out = args.output or (Path(args.image).stem + ".annotate.html")
    # before any work; never over the photo, the scene or the extract (-o cam.jpg replaced
    # the photo with the page)
    out_path = page_path(out, inputs=[args.image, args.scene, args.osm])
    lat, lon = args.lat, args.lon
    scene = load_scene(args.scene) if args.scene else None
    if args.osm and lat is None:
        if scene is not None and scene.prior is not None:
            lat, lon = scene.prior.lat, scene.prior.lon
        else:
            raise InputError("--osm needs --lat and --lon (where the camera roughly is)")
    corners = None
    if args.osm:
        corners = junction_geojson(
            lat=lat, lon=lon, map_source=args.osm, radius_m=args.radius_m, streets=args.streets
        )
    page = annotation_page_html(
        args.image,
        scene=args.scene,
        corners_geojson=corners,
        prior=(lat, lon) if lat is not None else None,
    )
    if out_path is None:
        sys.stdout.write(page)
    else:
        write_text_atomic(out_path, page)
        sys.stderr.write(f"camloc annotate: wrote {out}; open it in a browser\n")
    return 0
