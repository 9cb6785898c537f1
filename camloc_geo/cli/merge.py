"""``camloc merge SCENE ... -o SCENE.json``: several annotators' files into one scene."""

from __future__ import annotations

import argparse
from typing import Any

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``merge`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "merge",
        help="combine several annotators' scene files of one snapshot into one scene",
        description=(
            "Merge scene files saved by several annotators of the same snapshot into one "
            "multi-annotator camloc-scene/1 file. Fails (exit 2) naming the conflict when "
            "they describe another image, a different car or a different intersection."
        ),
    )
    p.add_argument("scenes", nargs="+", metavar="SCENE", help="scene files to merge")
    p.add_argument("-o", "--output", help="write the merged scene here instead of stdout")
    p.add_argument("--id", dest="scene_id", help="id of the merged scene (default: the first's)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from pathlib import Path

    from camloc_geo._errors import InputError
    from camloc_geo.cli import json_path, write_json
    from camloc_geo.merge import merge_scenes

    out = json_path(args.output, inputs=args.scenes)  # never over an annotator's file
    seen: dict[Path, str] = {}
    for name in args.scenes:
        key = Path(name).resolve()
        if key in seen:  # its annotators would count twice in the fit
            raise InputError(
                f"{name} is given twice (also as {seen[key]}): each annotator's file once"
            )
        seen[key] = name
    write_json(merge_scenes(args.scenes, scene_id=args.scene_id), out, inputs=args.scenes)
    return 0
