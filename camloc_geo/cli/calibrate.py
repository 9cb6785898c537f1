"""``camloc calibrate SCENE.json``: relative pose as JSON on stdout."""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
from collections.abc import Iterator
from typing import Any

from camloc_geo._errors import InputError
from camloc_geo.cli import write_json

log = logging.getLogger(__name__)

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``calibrate`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "calibrate",
        help="camera intrinsics, orientation and position relative to the annotated car",
        description=(
            "Estimate focal length, principal point, rotation and the camera position in the "
            "car's world frame from a scene's annotations. Prints JSON. Never uses the network."
        ),
    )
    p.add_argument("scene", help="scene file (camloc-scene/1 JSON)")
    p.add_argument("-o", "--output", help="write JSON here instead of stdout")
    p.add_argument(
        "--no-joint-fit",
        action="store_true",
        help="report the paper's answer (centroid of the largest candidate cluster) only",
    )
    p.add_argument(
        "--principal-point",
        choices=("auto", "centre", "free"),
        default="auto",
        help="principal point model of the joint fit (default: auto, decided by the data)",
    )
    p.add_argument(
        "--video",
        metavar="VIDEO",
        help=(
            "a video of the scene's camera (the image's size): the moving vehicles' tracks and "
            "edges join the fit as one more witness (video_segments in the JSON)"
        ),
    )
    p.add_argument(
        "--max-frames",
        type=int,
        metavar="N",
        help="with --video: read at most its first N frames (default 600; the cost is about "
        "linear in N)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo.api import calibrate_scene, scene_from
    from camloc_geo.cli import json_path

    json_path(args.output, inputs=[args.scene, args.video])
    if args.max_frames is not None:
        if args.video is None:
            raise InputError("--max-frames needs --video VIDEO (the frames read of it)")
        if args.max_frames < 1:
            raise InputError(f"--max-frames must be >= 1, not {args.max_frames}")
    if args.video is not None and not (args.verbose or args.debug):
        # FFmpeg, under OpenCV, prints its own lines ("[mjpeg @ 0x...] overread 8") next to
        # our one-line error: silenced, read before the first VideoCapture (as camloc radar)
        os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")
    with _logged_warnings() as logged:
        scene = scene_from(args.scene)
        if args.video is not None:
            from camloc_geo.sensors._video_lines import _NEED
            from camloc_geo.sensors.radar import probe_video

            probe_video(args.video, image_size=(scene.image.width, scene.image.height), need=_NEED)
        result = calibrate_scene(
            scene,
            joint_fit=not args.no_joint_fit,
            principal_point=args.principal_point,
            video=args.video,
            video_max_frames=args.max_frames,
        )
    # Every warning of the answer also on stderr, once: those the library logged while
    # reading and screening the scene are there already; the fit's own (a loose focal
    # length, lines resting on the car's own edges, a photo that disagrees) are not.
    for msg in result.warnings:
        if msg not in logged:
            log.warning("%s", msg)
    write_json({"scene": scene.id, **result.to_dict()}, args.output, inputs=[args.scene])
    return 0


@contextlib.contextmanager
def _logged_warnings() -> Iterator[set[str]]:
    """The messages of the warnings ``camloc_geo`` logs inside the block."""
    seen: set[str] = set()

    class _Collect(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            if record.levelno >= logging.WARNING:
                seen.add(record.getMessage())

    handler = _Collect()
    root = logging.getLogger("camloc_geo")
    root.addHandler(handler)
    try:
        yield seen
    finally:
        root.removeHandler(handler)
