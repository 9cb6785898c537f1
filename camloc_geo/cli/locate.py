"""``camloc locate SCENE.json``: candidate camera positions as GeoJSON."""

from __future__ import annotations

import argparse
import logging
from typing import Any

from camloc_geo._errors import MapDataError, SceneError
from camloc_geo.scene import Scene, load_scene

log = logging.getLogger(__name__)


def register(subparsers: Any) -> None:
    """Add the ``locate`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "locate",
        help="candidate absolute camera positions (GeoJSON), best first",
        description=(
            "Locate the camera on the map: enumerate, rank and refine candidate positions from "
            "the scene's references, intersection corners and landmarks. Without --osm the map "
            "around the scene's prior is fetched from Overpass (osmnx, cached)."
        ),
    )
    p.add_argument("scene", help="scene file (camloc-scene/1 JSON)")
    p.add_argument(
        "--osm", metavar="EXTRACT", help="local OSM extract (.osm, .osm.bz2, .osm.gz, .osm.pbf)"
    )
    p.add_argument(
        "-o", "--output", metavar="OUT.geojson", help="write GeoJSON here (default stdout)"
    )
    p.add_argument("--map", metavar="OUT.html", help="also write a Leaflet review map")
    p.add_argument(
        "--offline",
        action="store_true",
        help="never use the network: no Overpass, and --map inlines Leaflet into one HTML file",
    )
    p.add_argument(
        "--radius-m",
        type=float,
        default=None,
        help="map radius around the scene (default: prior radius + 200 m, at least 300 m)",
    )
    p.add_argument("--cache-folder", default=None, help="osmnx HTTP cache folder for Overpass")
    p.add_argument("--overpass-url", default=None, help="Overpass API endpoint")
    p.add_argument("--max-candidates", type=int, default=None, help="at most this many candidates")
    p.add_argument(
        "--overlays",
        metavar="DIR",
        default=None,
        help="with --map: write candidate image overlays (PNG) here",
    )
    p.set_defaults(func=run)


def _needs_map(scene: Scene) -> bool:
    if scene.intersection is not None or scene.landmarks:
        return True
    return len(scene.references) == 1 and scene.street_bearing_deg is None


def _map_centre(scene: Scene) -> tuple[float, float] | None:
    if scene.prior is not None:
        return scene.prior.lat, scene.prior.lon
    if scene.intersection is not None and scene.intersection.lat is not None:
        assert scene.intersection.lon is not None
        return scene.intersection.lat, scene.intersection.lon
    if scene.references:
        return scene.references[0].lat, scene.references[0].lon
    lms = [lm for lm in scene.landmarks if lm.lat is not None and lm.lon is not None]
    if lms:
        lat, lon = lms[0].lat, lms[0].lon
        assert lat is not None
        assert lon is not None
        return lat, lon
    return None


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo.absolute import LocateSettings, candidates_geojson, locate
    from camloc_geo.cli import write_json

    scene = load_scene(args.scene)
    map_data = None
    centre = _map_centre(scene)
    radius = args.radius_m
    if radius is None:
        radius = max(300.0, (scene.prior.radius_m if scene.prior else 0.0) + 200.0)
    if args.osm or _needs_map(scene) or args.map:
        if centre is None:
            raise SceneError(
                "no location to load the map around: give prior (lat/lon), intersection lat/lon "
                "or references",
                "prior",
            )
        from camloc_geo.osm import load_map

        if args.osm:
            map_data = load_map(args.osm, centre[0], centre[1], radius_m=radius)
        elif _needs_map(scene):
            if args.offline:
                raise MapDataError(
                    "this scene needs a map (intersection corners, landmarks or street bearings) "
                    "and --offline forbids fetching one: give --osm EXTRACT"
                )
            map_data = load_map(
                None,
                centre[0],
                centre[1],
                radius_m=radius,
                cache_folder=args.cache_folder,
                overpass_url=args.overpass_url,
            )
    settings = LocateSettings()
    if args.max_candidates is not None:
        if args.max_candidates < 1:
            raise SceneError("--max-candidates must be at least 1")
        settings = LocateSettings(max_candidates=args.max_candidates)
    result = locate(scene, map_data, settings=settings)
    from camloc_geo.cues import apply_cues

    apply_cues(result, scene, map_data, merge_distance_m=settings.merge_distance_m)
    for warning in result.warnings:
        if warning.startswith("ambiguous"):
            log.warning("%s", warning)  # a tie is never only in the GeoJSON
    gj = candidates_geojson(result)
    write_json(gj, args.output)
    if args.map:
        from camloc_geo.maps import candidates_map

        candidates_map(
            result, map_data, args.map, offline=args.offline, scene=scene, overlay_dir=args.overlays
        )
    if not result.candidates:
        log.warning("no candidates: %s", result.reason)
    return 0
