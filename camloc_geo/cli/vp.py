"""``camloc vp IMAGE``: vanishing points, focal length, horizon, pitch and roll of a photo."""

from __future__ import annotations

import argparse
import logging
from typing import Any

from camloc_geo._errors import InputError

__all__ = ["register", "run"]

log = logging.getLogger(__name__)

_IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp")


def register(subparsers: Any) -> None:
    """Add the ``vp`` sub-command to the ``camloc`` parser."""
    p = subparsers.add_parser(
        "vp",
        help="find the three orthogonal vanishing points, focal length and horizon of a photo",
        description=(
            "Detect line segments, find three mutually orthogonal vanishing points and "
            "the focal length, and print them with the horizon line, pitch and roll as "
            "JSON. Vanishing points at infinity are null. Never uses the network."
        ),
    )
    p.add_argument("image", metavar="IMAGE", help="photo (any format OpenCV reads)")
    p.add_argument("--focal-px", type=float, default=None, help="known focal length, pixels")
    p.add_argument(
        "--principal-point",
        type=float,
        nargs=2,
        metavar=("X", "Y"),
        default=None,
        help="known principal point, pixels (default: the image centre)",
    )
    p.add_argument(
        "--ignore",
        type=float,
        nargs=4,
        action="append",
        metavar=("X0", "Y0", "X1", "Y1"),
        default=None,
        help="ignore segments in this pixel box (time stamps, logos); repeatable",
    )
    p.add_argument(
        "--axis",
        type=float,
        nargs=4,
        action="append",
        metavar=("OX", "OY", "EX", "EY"),
        default=None,
        help=(
            "an annotated object axis from origin to end pixel (e.g. a car's length edge);"
            " prefer the vanishing points it points at; up to 3"
        ),
    )
    p.add_argument(
        "--estimate-principal-point",
        action="store_true",
        help="also refine the principal point around the image centre",
    )
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--draw", metavar="OUT.png", default=None, help="draw segments coloured by VP")
    p.add_argument("-o", "--output", metavar="OUT.json", default=None, help="write JSON here")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``camloc vp``."""
    import numpy as np

    from camloc_geo.autovp import detect_vanishing_points, draw_segments, load_image
    from camloc_geo.cli import atomic_output, output_path, write_json

    output_path(args.output, inputs=[args.image])
    draw_path = output_path(args.draw, inputs=[args.image], option="--draw")
    if draw_path is not None and draw_path.suffix.lower() not in _IMAGE_SUFFIXES:
        raise InputError(f"--draw {draw_path}: give a .png or .jpg file name")
    if args.focal_px is not None and not args.focal_px > 0:
        raise InputError(f"--focal-px must be positive, got {args.focal_px}")
    image = load_image(args.image)
    pp = tuple(args.principal_point) if args.principal_point else None
    mask = None
    if args.ignore:
        h, w = image.shape[:2]
        mask = np.ones((h, w), dtype=bool)
        for x0, y0, x1, y1 in args.ignore:
            if not all(np.isfinite([x0, y0, x1, y1])):
                raise InputError("--ignore: box corners must be finite numbers")
            xa, xb = sorted((x0, x1))
            ya, yb = sorted((y0, y1))
            mask[
                max(0, int(ya)) : max(0, int(np.ceil(yb))),
                max(0, int(xa)) : max(0, int(np.ceil(xb))),
            ] = False
    res = detect_vanishing_points(
        image,
        focal_px=args.focal_px,
        principal_point=pp,
        seed=args.seed,
        mask=mask,
        estimate_principal_point=args.estimate_principal_point,
        axes_hint=[((a[0], a[1]), (a[2], a[3])) for a in args.axis] if args.axis else None,
    )
    if draw_path is not None:
        with atomic_output(draw_path) as tmp:
            draw_segments(image, res, tmp)
        log.info("segments drawn to %s", draw_path)
    out = res.to_json()
    out["image"] = str(args.image)
    write_json(out, args.output, inputs=[args.image])
    return 0
