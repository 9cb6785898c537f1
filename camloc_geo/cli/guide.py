"""``camloc guide --scene SCENE --tracks TRACKS --gps TRACES``: the virtual guide."""

from __future__ import annotations

import argparse
import math
from typing import Any

from camloc_geo._errors import InputError
from camloc_geo.cli import (
    NETWORK_HELP,
    add_map_options,
    json_path,
    network_of,
    write_json,
)

__all__ = ["register", "run"]


def _positive(name: str, value: float) -> None:
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be positive, not {value}")


def register(subparsers: Any) -> None:
    """Add the ``guide`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "guide",
        help="match people tracked in the camera's video to GPS traces (virtual guide)",
        description=(
            "Cast people's pixel tracks onto the ground with the calibrated camera, place them "
            "with the camera's absolute pose (from --candidates, or by locating the scene) or "
            "solve the camera's placement in the GPS frame (--pose relative), and match them "
            "to GPS traces over time. Prints JSON: each match, its certainty and how long it "
            "took to become certain; -o OUT.geojson writes the ground tracks in lat/lon. "
            "Formats in docs/guide.md. " + NETWORK_HELP
        ),
    )
    p.add_argument("--scene", required=True, help="scene file (camloc-scene/1 JSON)")
    p.add_argument(
        "--tracks",
        required=True,
        metavar="TRACKS",
        help="people's pixel tracks, .json or .csv (id, t or frame, u,v or a box)",
    )
    p.add_argument(
        "--gps", required=True, metavar="TRACES", help="GPS traces, .gpx or .csv (id,time,lat,lon)"
    )
    p.add_argument(
        "--video-start",
        metavar="ISO8601",
        help="time of the video's first frame, when track times are seconds since it",
    )
    p.add_argument("--fps", type=float, help="frame rate, for tracks given by frame number")
    p.add_argument(
        "--pose",
        choices=("auto", "absolute", "relative"),
        default="auto",
        help="absolute: locate the scene (or --candidates) and fail without a pose; relative: "
        "solve the camera's placement from the traces; auto (default): absolute when possible",
    )
    p.add_argument(
        "--candidates",
        metavar="CANDS.geojson",
        help="a candidate GeoJSON written by camloc locate for this scene (then no map needed)",
    )
    p.add_argument("--candidate", type=int, default=1, help="the candidate rank to use (default 1)")
    add_map_options(p)
    p.add_argument(
        "--gps-sigma-m", type=float, default=4.0, help="GPS error per axis, metres (default 4)"
    )
    p.add_argument(
        "--click-sigma-px",
        type=float,
        default=3.0,
        help="error of a foot pixel (a box's bottom centre), pixels (default 3)",
    )
    p.add_argument(
        "--certainty",
        type=float,
        default=0.99,
        help="the certainty a match must keep to count as certain (default 0.99)",
    )
    p.add_argument("--step-s", type=float, default=1.0, help="time grid step, s (default 1)")
    p.add_argument(
        "-o",
        "--output",
        metavar="OUT.json|OUT.geojson",
        help="write the JSON report, or with .geojson the ground tracks (default: JSON on stdout)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo.api import guide_scene
    from camloc_geo.sensors.guide import GuideSettings

    inputs = [args.scene, args.tracks, args.gps, args.candidates, args.osm]
    out_path = json_path(args.output, inputs=inputs)
    for name in ("gps_sigma_m", "step_s"):
        _positive("--" + name.replace("_", "-"), getattr(args, name))
    if not (math.isfinite(args.click_sigma_px) and args.click_sigma_px >= 0):
        raise InputError(f"--click-sigma-px must be >= 0, not {args.click_sigma_px}")
    if not (0.5 <= args.certainty < 1.0):
        raise InputError(f"--certainty must be in [0.5, 1), not {args.certainty}")
    if args.fps is not None:
        _positive("--fps", args.fps)
    settings = GuideSettings(
        gps_sigma_m=args.gps_sigma_m,
        click_sigma_px=args.click_sigma_px,
        certainty=args.certainty,
        step_s=args.step_s,
    )
    result = guide_scene(
        args.scene,
        args.tracks,
        args.gps,
        video_start=args.video_start,
        fps=args.fps,
        pose=args.pose,
        candidates=args.candidates,
        candidate=args.candidate,
        map_source=args.osm,
        network=network_of(args),
        cache_folder=args.cache_folder,
        overpass_url=args.overpass_url,
        settings=settings,
    )
    if out_path is not None and out_path.suffix.lower() == ".geojson":
        write_json(result.to_geojson(), args.output, inputs=inputs)
    else:
        write_json(result.to_dict(), args.output, inputs=inputs)
    return 0
