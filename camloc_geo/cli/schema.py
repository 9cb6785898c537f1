"""``camloc schema``: the JSON Schema of the scene format and of every output."""

from __future__ import annotations

import argparse
from typing import Any

_DOCUMENTS = ("scene", "candidates", "calibration", "corners")


def register(subparsers: Any) -> None:
    """Add the ``schema`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "schema",
        help="print the JSON Schema of scene files or of an output",
        description=(
            "Print the JSON Schema (draft 2020-12) of a document: the camloc-scene/1 scene "
            "format (default), or an output: 'candidates' (camloc locate's GeoJSON), "
            "'calibration' (camloc calibrate), 'corners' (camloc corners)."
        ),
    )
    p.add_argument(
        "document",
        nargs="?",
        choices=_DOCUMENTS,
        default="scene",
        help="which document (default: scene)",
    )
    p.add_argument("-o", "--output", help="write the schema here instead of stdout")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo.cli import json_path, write_json

    json_path(args.output)  # a JSON Schema under a .html or .pdf name is refused
    if args.document == "scene":
        from camloc_geo.scene import scene_json_schema

        schema = scene_json_schema()
    else:
        from camloc_geo.results import output_json_schema

        schema = output_json_schema(args.document)
    write_json(schema, args.output)
    return 0
