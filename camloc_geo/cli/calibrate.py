"""``camloc calibrate SCENE.json``: relative pose as JSON on stdout."""

from __future__ import annotations

import argparse
from typing import Any

from camloc_geo.relative import CalibrationSettings, calibrate
from camloc_geo.scene import load_scene


def register(subparsers: Any) -> None:
    """Add the ``calibrate`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "calibrate",
        help="camera intrinsics, orientation and position relative to the annotated car",
        description=(
            "Estimate focal length, principal point, rotation and the camera position in the "
            "car's world frame from a scene's annotations. Prints JSON."
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
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo.cli import write_json

    scene = load_scene(args.scene)
    free = {"auto": None, "centre": False, "free": True}[args.principal_point]
    settings = CalibrationSettings(joint_fit=not args.no_joint_fit, free_principal_point=free)
    result = calibrate(scene, settings)
    out: dict[str, Any] = {"scene": scene.id, **result.to_dict()}
    write_json(out, args.output)
    return 0
