"""The ``camloc`` command line.

One module per command (``calibrate``, ``locate``, ``corners``, ``streets``, ``vp``...);
each exposes ``register(subparsers)`` that adds its parser and sets ``func``. This layer is
the only place where library errors become exit statuses:

- 0: success;
- 2: bad input (:class:`camloc_geo.InputError`, argparse usage errors), one line on stderr;
- 1: any other failure, one line on stderr (a traceback only with ``--debug``).

Data goes to stdout, logging to stderr.

Shared rules, implemented once here and used by every command:

- **Network** (:func:`add_map_options`, :func:`network_of`): with ``--osm EXTRACT`` the
  network is never used; without it Overpass is queried (osmnx HTTP cache) unless
  ``--no-network`` (or ``--offline``). A command that needs a map with neither fails at once
  (exit 2, one line naming ``--osm EXTRACT``).
- **Pages** (``--inline``): the HTML page inlines Leaflet and jQuery and makes no request.
  ``--offline`` is ``--no-network --inline`` (kept for the tools that use it).
- **Output paths** (:func:`output_path`, :func:`write_json`, :func:`atomic_output`): a
  missing directory is exit 2 (never created), writes are atomic (a temporary file in the
  same directory, then a rename), an output never overwrites an input.

Building the parser imports no heavy module (numpy, scipy, osmnx...): command modules import
those inside ``run()``, so ``camloc --help`` starts fast.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import json
import logging
import re
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from camloc_geo import __version__
from camloc_geo._errors import InputError
from camloc_geo._io import atomic_path, check_output_path, read_json_file, write_text_atomic

__all__ = [
    "NETWORK_HELP",
    "add_map_options",
    "atomic_output",
    "distinct_outputs",
    "inline_of",
    "main",
    "network_of",
    "output_path",
    "read_json_file",
    "write_json",
]

NETWORK_HELP = (
    "Network: with --osm EXTRACT the network is never used; without it the map is fetched "
    "from Overpass (osmnx HTTP cache) unless --no-network (or --offline)."
)
"""The one network rule, quoted in every command's --help."""

atomic_output = atomic_path

_COMMAND_MODULES = (
    "calibrate",
    "locate",
    "corners",
    "streets",
    "vp",
    "summary_map",
    "schema",
    "annotate",
    "merge",
    "geocode",
    "batch",
    "serve",
    "measure",
    "radar",
    "guide",
)

log = logging.getLogger("camloc_geo.cli")


def output_path(
    path: str | Path | None,
    *,
    inputs: Iterable[str | Path | None] = (),
    option: str = "-o",
    directory: bool = False,
) -> Path | None:
    """Check an output path before any work; None for stdout (None or ``-``).

    Raises
    ------
    InputError
        Missing directory, a directory given as a file, or an output naming an input
        (exit 2, one line).
    """
    if path is None or (str(path) == "-" and not directory):
        return None
    return check_output_path(path, inputs=inputs, option=option, directory=directory)


PAGE_SUFFIXES: tuple[str, ...] = (".html", ".htm")
"""Names an HTML page (``--map``, ``summary-map -o``, ``annotate -o``) may end with; a name
without a suffix is taken as it is (``/dev/stdout``)."""


def page_path(
    path: str | Path | None, *, inputs: Iterable[str | Path | None] = (), option: str = "-o"
) -> Path | None:
    """:func:`output_path` for an HTML page: a name ending in another suffix is refused.

    ``locate --map x.pdf`` wrote the HTML page under a PDF name, which a PDF viewer then
    could not open.

    Raises
    ------
    InputError
        As :func:`output_path`, or the name ends in a suffix other than
        :data:`PAGE_SUFFIXES` (exit 2, one line naming them).
    """
    out = output_path(path, inputs=inputs, option=option)
    if out is not None and out.suffix and out.suffix.lower() not in PAGE_SUFFIXES:
        raise InputError(
            f"{option} {path}: writes an HTML page, not {out.suffix}; name it "
            f"{' or '.join(PAGE_SUFFIXES)} (as {out.stem}.html)"
        )
    return out


NOT_JSON_SUFFIXES: frozenset[str] = frozenset(
    {
        ".html", ".htm", ".pdf", ".png", ".jpg", ".jpeg", ".gif", ".webp", ".tif", ".tiff",
        ".gpkg", ".shp", ".kml", ".kmz", ".csv", ".xlsx", ".xls", ".sqlite", ".zip",
    }
)  # fmt: skip
"""Suffixes of other formats that a JSON output (``locate -o``, ``calibrate -o``...) refuses:
``locate -o review.html`` wrote GeoJSON under a page's name, ``-o cams.gpkg`` GeoJSON under a
GeoPackage's (a name without a suffix, ``.json``, ``.geojson`` or any other is taken)."""


def json_path(
    path: str | Path | None,
    *,
    inputs: Iterable[str | Path | None] = (),
    what: str = "JSON",
    hint: str = "",
) -> Path | None:
    """:func:`output_path` for ``-o`` of a command that writes JSON or GeoJSON.

    Raises
    ------
    InputError
        As :func:`output_path`, or the name ends in a suffix of another format
        (:data:`NOT_JSON_SUFFIXES`; exit 2, one line; ``hint`` says where that format comes
        from, such as "the review page is --map OUT.html").
    """
    out = output_path(path, inputs=inputs)
    if out is not None and out.suffix.lower() in NOT_JSON_SUFFIXES:
        ext = ".geojson" if what == "GeoJSON" else ".json"
        raise InputError(
            f"-o {path}: writes {what}, not {out.suffix}; name it {ext}"
            + (f" ({hint})" if hint else "")
        )
    return out


def distinct_outputs(*outputs: tuple[str, Path | None]) -> None:
    """Refuse two outputs of one command naming the same file (``-o x --map x``: the last
    written replaced the other). ``outputs`` are ``(option, path)`` pairs; None is stdout.

    Raises
    ------
    InputError
        Two of them are the same file (exit 2, one line naming both options).
    """
    seen: dict[Path, str] = {}
    for option, path in outputs:
        if path is None:
            continue
        key = path.resolve()
        if key in seen:
            raise InputError(
                f"{option} {path}: the same file as {seen[key]}; give each output its own name"
            )
        seen[key] = option


def write_json(
    data: Any, out: str | Path | None = None, *, inputs: Iterable[str | Path | None] = ()
) -> None:
    """Write JSON to ``out`` (atomically, see :func:`output_path`) or to stdout.

    The text is built first, so a value that cannot be serialised writes nothing.
    """
    text = json.dumps(data, indent=2, allow_nan=False) + "\n"
    path = output_path(out, inputs=inputs)
    if path is None:
        sys.stdout.write(text)
    else:
        write_text_atomic(path, text)


def add_map_options(
    p: argparse.ArgumentParser,
    *,
    page: bool = False,
    online_flag: bool = False,
    cache: bool = True,
) -> None:
    """The map source and network options, the same for every command.

    Parameters
    ----------
    page
        The command writes an HTML page: add ``--inline``.
    online_flag
        Accept ``--online`` (a no-op kept for old scripts: the network is the default).
    cache
        Add ``--cache-folder`` and ``--overpass-url``.
    """
    p.add_argument(
        "--osm",
        metavar="EXTRACT",
        help=(
            "local OSM extract (.osm, .osm.gz, .osm.bz2, .osm.pbf) or a folder of them (the one "
            "covering the point is used); then no network is used"
        ),
    )
    p.add_argument(
        "--no-network",
        action="store_true",
        help="never query Overpass (without --osm, a command that needs a map fails at once)",
    )
    if page:
        p.add_argument(
            "--inline",
            action="store_true",
            help="one self-contained HTML page: Leaflet and jQuery inlined, no tiles, no request",
        )
        p.add_argument("--offline", action="store_true", help="--no-network --inline")
    else:
        p.add_argument("--offline", action="store_true", help="same as --no-network")
    if online_flag:
        p.add_argument(
            "--online",
            action="store_true",
            help="query Overpass when no --osm is given (the default; kept for old scripts)",
        )
    if cache:
        p.add_argument(
            "--cache-folder", metavar="DIR", default=None, help="osmnx HTTP cache for Overpass"
        )
        p.add_argument("--overpass-url", metavar="URL", default=None, help="Overpass API endpoint")


def network_of(args: argparse.Namespace) -> bool:
    """May Overpass be queried: not with ``--no-network`` / ``--offline``."""
    if getattr(args, "online", False) and (args.no_network or args.offline):
        raise InputError("--online contradicts --no-network / --offline")
    return not (args.no_network or args.offline)


def inline_of(args: argparse.Namespace) -> bool:
    """Should the HTML page be self-contained: ``--inline`` or ``--offline``."""
    return bool(getattr(args, "inline", False) or args.offline)


def _named_command(argv: Sequence[str] | None) -> str | None:
    """The module of the command ``argv`` names exactly, or None (help, a typo, none given).

    Top-level options take no value, so the first argument that is not an option is the
    command; ``-h`` before it asks for the whole list.
    """
    for arg in sys.argv[1:] if argv is None else argv:
        if arg in ("--", "-h", "--help"):
            return None
        if not arg.startswith("-"):
            module = arg.replace("-", "_")
            return module if module in _COMMAND_MODULES and "_" not in arg else None
    return None


def _build_parser(
    argv: Sequence[str] | None = (), *, all_commands: bool = True
) -> argparse.ArgumentParser:
    """The ``camloc`` parser, with every command or only the one ``argv`` names.

    With ``all_commands=False`` only the command ``argv`` names exactly is registered, so
    ``camloc locate`` neither imports nor compiles the other 14 command modules (16 ms);
    help, a typo or no command still get the whole list.
    """
    parser = argparse.ArgumentParser(
        prog="camloc",
        description="Find where a street camera stands from one snapshot of it.",
    )
    parser.add_argument("--version", action="version", version=f"camloc {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="more logging on stderr")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of failures")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    only = None if all_commands else _named_command(argv)
    for name in _COMMAND_MODULES if only is None else (only,):
        try:
            module = importlib.import_module(f"camloc_geo.cli.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"camloc_geo.cli.{name}":
                continue  # command not built yet
            raise
        module.register(subparsers)
    return parser


def _command_parser(
    parser: argparse.ArgumentParser, command: str | None
) -> argparse.ArgumentParser:
    """The sub-parser of ``command`` (``parser`` itself without one)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction) and command in action.choices:
            sub = action.choices[command]
            assert isinstance(sub, argparse.ArgumentParser)
            return sub
    return parser


_LONG_RUNNING = ("batch", "serve")
"""Commands that keep the garbage collector's default thresholds (they run for hours)."""


def _one_shot_gc(argv: Sequence[str] | None) -> None:
    """Collect garbage less often in a short command (imports make ~10^6 objects, most for good).

    Only when :func:`main` owns the process (``argv`` is None: the console script or ``python
    -m camloc_geo.cli``), never for ``batch`` or ``serve``. ``camloc locate`` on the sample:
    60 ms less CPU.
    """
    if argv is None and _named_command(None) not in _LONG_RUNNING:
        gc.set_threshold(10_000, 20, 100)


def _fast_exit(argv: Sequence[str] | None) -> None:
    """Skip the interpreter's last full collection at exit (0.15-0.2 s after ``locate``).

    The output is written; only this process's own objects are left. Only when :func:`main`
    owns the process (a library caller or a test keeps its collector as it was).
    """
    if argv is None:
        gc.disable()
        gc.freeze()


class Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``, ``timeout``, ``docker stop``, a scheduler's limit) during a command.

    A :class:`KeyboardInterrupt`, so that every clean-up an interruption gets (``camloc
    batch`` stopping its worker processes, atomic outputs left as they were) runs for it too:
    Python's default for SIGTERM ends the process at once, and ``camloc batch``'s workers
    were left running, orphaned, for ever.
    """


def _raise_terminated(signum: int, frame: Any) -> None:
    raise Terminated()


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    _one_shot_gc(argv)
    import signal
    import threading

    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        return _main(argv)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
        _fast_exit(argv)


def _main(argv: Sequence[str] | None) -> int:
    parser = _build_parser(argv, all_commands=False)
    args, unknown = parser.parse_known_args(argv)
    if unknown:  # the command's own usage names what it takes, not the list of commands
        _command_parser(parser, getattr(args, "command", None)).error(
            f"unrecognized arguments: {' '.join(unknown)}"
        )
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
        sys.stderr.write(
            f"camloc {args.command}: error: {_one_line(exc)}{_swapped_hint(args, exc)}\n"
        )
        return 2
    except KeyboardInterrupt as exc:
        if isinstance(exc, Terminated):
            sys.stderr.write("camloc: terminated (SIGTERM)\n")
            return 143
        sys.stderr.write("camloc: interrupted\n")
        return 130
    except BrokenPipeError as exc:
        if not _stdout_closed():  # another pipe or socket: an ordinary failure
            if args.debug:
                raise
            sys.stderr.write(f"camloc {args.command}: failed: BrokenPipeError: {_one_line(exc)}\n")
            return 1
        # the reader closed stdout (camloc geocode ... | head): stop quietly, as Unix tools
        # do, instead of "failed: BrokenPipeError"; stdout goes nowhere from here on, so the
        # interpreter's own flush at exit does not complain either
        _drop_stdout()
        return 1
    except Exception as exc:  # the CLI boundary: never a traceback for the user
        if args.debug:
            raise
        sys.stderr.write(f"camloc {args.command}: failed: {type(exc).__name__}: {_one_line(exc)}\n")
        return 1


def _stdout_closed() -> bool:
    """True when stdout's reader has gone (a write or flush there raises BrokenPipeError)."""
    import os

    try:
        sys.stdout.flush()
        fd = sys.stdout.fileno()
    except BrokenPipeError:
        return True
    except (OSError, ValueError, AttributeError):
        return False
    try:
        os.write(fd, b"")
    except BrokenPipeError:
        return True
    except OSError:
        return False
    import select

    try:  # a pipe whose reader closed is "readable" (error/hang-up) for poll
        poller = select.poll()
        poller.register(fd, select.POLLERR | select.POLLHUP)
        return any(ev & (select.POLLERR | select.POLLHUP) for _fd, ev in poller.poll(0))
    except (OSError, AttributeError, ValueError):
        return False


def _drop_stdout() -> None:
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # stdout without a descriptor (a test's)
        pass


_EXTRACT_COVERS = re.compile(
    r"is outside the extract .*cover lat (-?[\d.]+)\.\.(-?[\d.]+), lon (-?[\d.]+)\.\.(-?[\d.]+)\)"
)


def _swapped_hint(args: argparse.Namespace, exc: BaseException) -> str:
    """A hint when ``--lat``/``--lon`` outside the map lie in it the other way round.

    ``camloc corners --lat 24.9455 --lon 60.1699 --osm helsinki.osm.pbf`` (the two swapped,
    as GeoJSON and QGIS write lon first) was refused as outside the extract with no word that
    the swapped point is inside it (``camloc batch``, the service and QGIS say so).
    """
    lat, lon, osm = (
        getattr(args, "lat", None),
        getattr(args, "lon", None),
        getattr(args, "osm", None),
    )
    if not isinstance(lat, float) or not isinstance(lon, float) or not -90.0 <= lon <= 90.0:
        return ""
    message = str(exc)
    where = ""
    m = _EXTRACT_COVERS.search(message)
    if m is not None:
        south, north, west, east = (float(v) for v in m.groups())
        if south <= lon <= north and west <= lat <= east:
            where = "the extract"
    elif "is outside every extract" in message and osm:
        try:
            from camloc_geo.osm import MapCatalogue

            covering = MapCatalogue.from_source(osm).covering(lon, lat)
        except Exception:  # a hint only
            covering = []
        if covering:
            where = Path(covering[0]).name
    if not where:
        return ""
    return (
        f"; with --lat and --lon swapped (--lat {lon:g} --lon {lat:g}) the point lies in "
        f"{where}: are they the other way round?"
    )


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
