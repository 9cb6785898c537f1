"""``camloc measure SCENE --ground ... | --height ...``: the virtual scale and clinometer."""

from __future__ import annotations

import argparse
import logging
import math
from typing import Any

from camloc_geo._errors import InputError

log = logging.getLogger(__name__)


def _pixel(text: str, option: str = "pixel") -> tuple[float, float]:
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        u, v = float(parts[0]), float(parts[1])
    except ValueError:
        raise InputError(
            f"{option}: pixel {text!r} is not U,V (two numbers separated by a comma)"
        ) from None
    if not (math.isfinite(u) and math.isfinite(v)):
        raise InputError(f"{option}: pixel {text!r} is not a finite number pair")
    return u, v


def _in_image(
    pixels: list[tuple[float, float]], texts: list[str], option: str, size: tuple[int, int]
) -> None:
    """Refuse a pixel more than one image size outside the image, naming the option
    (``--ground 1e308,2 3,4`` exited 0 with 762 m ± 50 km)."""
    width, height = size
    for (u, v), text in zip(pixels, texts, strict=True):
        if not (-width <= u <= 2 * width and -height <= v <= 2 * height):
            raise InputError(
                f"{option}: pixel {text!r} is far outside the {width}x{height} image (more "
                "than one image size beyond its edge)"
            )


def register(subparsers: Any) -> None:
    """Add the ``measure`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "measure",
        help="measure ground distances and heights with the calibrated camera",
        description=(
            "Calibrate the scene, then measure in metres: --ground U1,V1 U2,V2 [...] gives the "
            "length of the path through ground pixels (virtual scale); --height UBASE,VBASE "
            "UTOP,VTOP gives the height of a point above a ground point (virtual clinometer). "
            "Prints JSON with sigma_m (Monte Carlo over the camera's uncertainty and clicks)."
        ),
    )
    p.add_argument("scene", help="scene file (camloc-scene/1 JSON)")
    what = p.add_mutually_exclusive_group(required=True)
    what.add_argument("--ground", nargs="+", metavar="U,V", help="two or more ground pixels")
    what.add_argument(
        "--height", nargs=2, metavar=("UBASE,VBASE", "UTOP,VTOP"), help="base and top pixels"
    )
    p.add_argument(
        "--click-sigma-px",
        type=float,
        default=1.5,
        help="standard deviation of a click, pixels (default 1.5)",
    )
    p.add_argument("-o", "--output", help="write JSON here instead of stdout")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo.api import calibrate_scene
    from camloc_geo.cli import json_path, write_json
    from camloc_geo.scene import load_scene
    from camloc_geo.sensors import ground_distance, point_height

    json_path(args.output, inputs=[args.scene])  # before the work; never over the scene
    if not (args.click_sigma_px >= 0.0 and args.click_sigma_px < float("inf")):
        raise InputError(f"--click-sigma-px must be >= 0, not {args.click_sigma_px}")
    if args.ground is not None:
        pixels = [_pixel(t, "--ground") for t in args.ground]
        if len(pixels) < 2:
            raise InputError("--ground needs at least two pixels")
        scene = load_scene(args.scene)  # read once: its warnings said once
        _in_image(pixels, args.ground, "--ground", scene.image_size)
        calibration = calibrate_scene(scene)
        m = ground_distance(calibration, pixels, click_sigma_px=args.click_sigma_px)
    else:
        base, top = (_pixel(t, "--height") for t in args.height)
        scene = load_scene(args.scene)
        _in_image([base, top], list(args.height), "--height", scene.image_size)
        calibration = calibrate_scene(scene)
        m = point_height(calibration, base, top, click_sigma_px=args.click_sigma_px)
    for w in m.warnings:
        log.warning("%s", w)
    out = m.to_dict()
    out["click_sigma_px"] = args.click_sigma_px
    write_json(out, args.output, inputs=[args.scene])
    return 0
