"""``camloc vp IMAGE``: vanishing points, focal length, horizon, pitch and roll of a photo."""

from __future__ import annotations

import argparse
import logging
from typing import Any

from camloc_geo._errors import InputError, NotEnoughStructureError

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
    p.add_argument("image", metavar="IMAGE", help="photo (JPEG, PNG, TIFF, WebP, BMP, GIF...)")
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
            " prefer the vanishing points it points at and fit them as a line of the image;"
            " up to 3"
        ),
    )
    p.add_argument(
        "--distortion",
        type=float,
        default=None,
        metavar="K1",
        help=(
            "known radial lens distortion, division model k1 with radii in half image"
            " diagonals (negative: barrel, wide-angle); segments are undistorted before the fit."
            " Default: estimated from the photo's bowed edges; 0 turns that off"
        ),
    )
    p.add_argument(
        "--no-exif",
        action="store_true",
        help=(
            "ignore the photo's EXIF focal length (by default FocalLengthIn35mmFilm, or"
            " FocalLength with the sensor size, is used as a prior when present)"
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
    from camloc_geo.autovp import draw_segments
    from camloc_geo.cli import atomic_output, distinct_outputs, json_path, output_path, write_json

    out_path = output_path(args.output, inputs=[args.image])
    draw_path = output_path(args.draw, inputs=[args.image], option="--draw")
    distinct_outputs(("-o", out_path), ("--draw", draw_path))  # said first, as before
    json_path(args.output, inputs=[args.image], hint="the drawing is --draw OUT.png")
    if draw_path is not None and draw_path.suffix.lower() not in _IMAGE_SUFFIXES:
        raise InputError(f"--draw {draw_path}: give a .png or .jpg file name")
    options: dict[str, Any] = {}
    if args.distortion is None:
        options["estimate_distortion"] = True
    elif args.distortion == 0.0:
        options["estimate_distortion"] = False
    else:
        options["distortion_k1"] = args.distortion
    if args.focal_px is None and not args.no_exif:
        from camloc_geo.exif import focal_from_exif

        ex = focal_from_exif(args.image)
        if ex is not None:
            log.info("focal length prior from EXIF (%s): %.1f px", ex.source, ex.focal_px)
            options.update(
                focal_prior_px=ex.focal_px,
                focal_prior_sigma_rel=ex.sigma_rel,
                focal_prior_source=ex.source,
                check_focal_prior=True,  # a maker's tag can be wrong: checked against the lines
            )
    try:
        res = _vanishing_points(args, options)
    except NotEnoughStructureError as exc:  # name the photo, as every other refusal does
        raise NotEnoughStructureError(f"{args.image}: {exc}") from None
    for w in res.warnings:
        log.warning("%s: %s", args.image, w)
    if draw_path is not None:
        with atomic_output(draw_path) as tmp:
            draw_segments(args.image, res, tmp)
        log.info("segments drawn to %s", draw_path)
    out = res.to_json()
    out["image"] = str(args.image)
    write_json(out, args.output, inputs=[args.image])
    return 0


def _vanishing_points(args: argparse.Namespace, options: dict[str, Any]) -> Any:
    from camloc_geo.api import vanishing_points

    return vanishing_points(
        args.image,
        focal_px=args.focal_px,
        principal_point=tuple(args.principal_point) if args.principal_point else None,
        ignore_boxes_px=args.ignore or (),
        axes_px=args.axis or (),
        estimate_principal_point=args.estimate_principal_point,
        seed=args.seed,
        **options,
    )
