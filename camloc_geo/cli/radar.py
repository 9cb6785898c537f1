"""``camloc radar VIDEO --scene SCENE [-o speeds.csv|.json]``: vehicle speeds from a video."""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any

from camloc_geo._errors import InputError


def register(subparsers: Any) -> None:
    """Add the ``radar`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "radar",
        help="measure vehicle speeds (km/h) in a video of the calibrated camera",
        description=(
            "Virtual radar: calibrate the scene (and, by default, the video's own lines: "
            "--no-video-lines), find the vehicles in the video (background "
            "subtraction, or the boxes of --tracks), follow them with KLT features and fit "
            "the ground-plane motion of each vehicle's ground contact. Prints JSON (or writes "
            "-o FILE: .json, or .csv with one row per vehicle) with speed_kmh and sigma_kmh "
            "per vehicle; vehicles that cannot be measured are listed with a reason. The video "
            "must have the scene image's size. Exit 2 when no vehicle is found."
        ),
    )
    p.add_argument("video", help="video file from the scene's camera (any format OpenCV reads)")
    p.add_argument("--scene", required=True, help="scene file (camloc-scene/1 JSON)")
    p.add_argument(
        "--tracks",
        metavar="FILE",
        help="vehicle boxes per frame from another detector (JSON or CSV, see docs/radar.md)",
    )
    p.add_argument("--fps", type=float, help="frame rate (default: the one the file states)")
    p.add_argument(
        "--min-track-s",
        type=float,
        default=0.5,
        help="shorter tracks are skipped with a reason (default 0.5 s)",
    )
    p.add_argument(
        "--max-frames",
        type=int,
        metavar="N",
        help=(
            "process only the first N frames (the video's lines for the calibration too, "
            "at most 600 of them: the first 600 without it)"
        ),
    )
    p.add_argument(
        "--video-lines",
        action=argparse.BooleanOptionalAction,
        default=True,
        help=(
            "calibrate with the video's own lines too: the moving vehicles' tracks and edges "
            "(default; the JSON's calibration.witnesses says which were used); "
            "--no-video-lines: from the scene alone"
        ),
    )
    p.add_argument(
        "--progress",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="progress bar on stderr (default: when stderr is a terminal)",
    )
    p.add_argument(
        "--no-track-points",
        action="store_true",
        help="leave the per-frame ground positions out of the JSON",
    )
    p.add_argument("-o", "--output", help="write .json or .csv here instead of JSON on stdout")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo._io import write_text_atomic
    from camloc_geo.api import radar_scene
    from camloc_geo.cli import output_path, write_json

    out = output_path(args.output, inputs=[args.video, args.scene, args.tracks])
    if not (args.verbose or args.debug):
        # FFmpeg, under OpenCV, prints its own lines ("[mjpeg @ 0x...] No JPEG data found in
        # image") next to our one-line error: silenced, read before the first VideoCapture
        os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")
    csv_out = out is not None and out.suffix.lower() == ".csv"
    if out is not None and out.suffix.lower() not in (".csv", ".json"):
        raise InputError(f"-o {out}: give a .json or .csv file")
    progress = sys.stderr.isatty() if args.progress is None else bool(args.progress)
    result = radar_scene(
        args.scene,
        args.video,
        fps=args.fps,
        tracks=args.tracks,
        min_track_s=args.min_track_s,
        max_frames=args.max_frames,
        progress=progress,
        video_lines=args.video_lines,
    )
    if not result.vehicles:
        raise InputError(f"{result.warnings[0]} ({args.video}, {result.video.n_frames} frames)")
    for w in result.warnings:
        sys.stderr.write(f"camloc radar: warning: {w}\n")
    if csv_out:
        assert out is not None
        write_text_atomic(out, result.to_csv())
    else:
        write_json(result.to_dict(tracks=not args.no_track_points), out)
    return 0
