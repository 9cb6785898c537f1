"""``camloc schema``: the JSON Schema of the scene format."""

from __future__ import annotations

import argparse
from typing import Any


def register(subparsers: Any) -> None:
    """Add the ``schema`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "schema",
        help="print the JSON Schema of camloc-scene/1 files",
        description="Print the JSON Schema (draft 2020-12) of the camloc-scene/1 scene format.",
    )
    p.add_argument("-o", "--output", help="write the schema here instead of stdout")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo.cli import write_json
    from camloc_geo.scene import scene_json_schema

    write_json(scene_json_schema(), args.output)
    return 0
