"""The ``camloc`` command line.

One module per command (``calibrate``, ``locate``, ``corners``, ``streets``, ``vp``...);
each exposes ``register(subparsers)`` that adds its parser and sets ``func``. This layer is
the only place where library errors become exit statuses:

- 0: success;
- 2: bad input (:class:`camloc_geo.InputError`, argparse usage errors), one line on stderr;
- 1: any other failure, one line on stderr (a traceback only with ``--debug``).

Data goes to stdout, logging to stderr.
"""

from __future__ import annotations

import argparse
import importlib
import json
import logging
import sys
from collections.abc import Sequence
from typing import Any

from camloc_geo import __version__
from camloc_geo._errors import InputError

__all__ = ["main", "write_json"]

_COMMAND_MODULES = (
    "calibrate",
    "locate",
    "corners",
    "streets",
    "vp",
    "summary_map",
    "schema",
    "serve",
)

log = logging.getLogger("camloc_geo.cli")


def write_json(data: Any, out: str | None = None) -> None:
    """Write JSON to ``out`` (a path) or to stdout when ``out`` is None or ``-``."""
    text = json.dumps(data, indent=2, allow_nan=False)
    if out in (None, "-"):
        sys.stdout.write(text + "\n")
    else:
        with open(str(out), "w", encoding="utf-8") as fh:
            fh.write(text + "\n")


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="camloc",
        description="Find where a street camera stands from one snapshot of it.",
    )
    parser.add_argument("--version", action="version", version=f"camloc {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="more logging on stderr")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of failures")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in _COMMAND_MODULES:
        try:
            module = importlib.import_module(f"camloc_geo.cli.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"camloc_geo.cli.{name}":
                continue  # command not built yet
            raise
        module.register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    parser = _build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.WARNING - 10 * min(args.verbose, 2),
        format="camloc: %(levelname)s: %(message)s",
        stream=sys.stderr,
    )
    if not getattr(args, "func", None):
        parser.print_help(sys.stderr)
        return 2
    try:
        return int(args.func(args) or 0)
    except InputError as exc:
        if args.debug:
            raise
        sys.stderr.write(f"camloc {args.command}: error: {_one_line(exc)}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("camloc: interrupted\n")
        return 130
    except Exception as exc:  # the CLI boundary: never a traceback for the user
        if args.debug:
            raise
        sys.stderr.write(f"camloc {args.command}: failed: {type(exc).__name__}: {_one_line(exc)}\n")
        return 1


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
