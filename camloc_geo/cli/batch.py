"""``camloc batch LIST -o OUT.gpkg``: geocode a camera list into a GeoPackage (resumable)."""

from __future__ import annotations

import argparse
import logging
import sys
from typing import Any

from camloc_geo._errors import InputError

log = logging.getLogger(__name__)


def register(subparsers: Any) -> None:
    """Add the ``batch`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "batch",
        help="geocode a camera list (CSV/GeoJSON) into a GeoPackage, resumable",
        description=(
            "Place every camera of a list from its title's junction and, when it has one, its "
            "located scene. Writes a GeoPackage (layers cameras, candidates, view_cones, "
            "errors); OUT.camloc-batch.sqlite next to it records finished cameras, so a "
            "rerun after an interruption continues where it stopped. Columns: docs/batch.md."
        ),
    )
    p.add_argument("list", help="camera list: CSV or GeoJSON (id, title, lat, lon, scene...)")
    p.add_argument("-o", "--output", required=True, metavar="OUT.gpkg", help="GeoPackage to write")
    p.add_argument("--map", metavar="SUMMARY.html", help="also write a summary map (clustered)")
    src = p.add_mutually_exclusive_group()
    src.add_argument(
        "--osm",
        metavar="EXTRACT_OR_FOLDER",
        help="an OSM extract or a folder of extracts (each camera uses the one covering it)",
    )
    src.add_argument(
        "--network",
        action="store_true",
        help="fetch each area's map from Overpass (cameras need lat/lon)",
    )
    p.add_argument(
        "--area",
        metavar="NAME",
        help="search titles without a point only in extracts whose file name contains NAME",
    )
    p.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        help="run on this Dask distributed scheduler instead of local processes",
    )
    p.add_argument("--workers", type=int, default=None, help="local processes (default: all cores)")
    p.add_argument(
        "--chunk-size",
        type=int,
        default=16,
        help="cameras per task and per journal transaction (default 16)",
    )
    p.add_argument("--restart", action="store_true", help="forget finished cameras, start again")
    p.add_argument(
        "--online-map", action="store_true", help="summary map with web tiles (not self-contained)"
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument(
        "--verdict-url",
        metavar="URL",
        help=(
            "with --map: the page shares its reviewers' verdicts with this camloc service "
            "(http(s)://host[:port], /v1/verdicts added), from a file too; the service must "
            "allow the page's origin (CAMLOC_CORS_ORIGINS; null for a file), see docs/service.md"
        ),
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo.batch import run_batch
    from camloc_geo.cli import output_path, page_path

    # before any work: the GeoPackage and the page never land on the list or an extract (the
    # page used to overwrite the list with --map LIST.csv), nor on each other
    inputs = [args.list, args.osm]
    out = output_path(args.output, inputs=inputs)
    if out is not None and out.suffix.lower() != ".gpkg":
        from camloc_geo.batch import journal_path

        # a name without a suffix wrote a GeoPackage no file manager or QGIS browser knew
        # (stop 41); a run begun under such a name before then still resumes (its journal)
        if out.suffix or not journal_path(out).exists():
            got = f"not {out.suffix}" if out.suffix else "and the name has no suffix"
            raise InputError(
                f"-o {args.output}: camloc batch writes a GeoPackage, {got}; name it .gpkg "
                f"(as {out.stem}.gpkg; its layers: cameras, candidates, view_cones, errors)"
            )
    if args.map is not None:
        page = output_path(args.map, inputs=inputs, option="--map")
        if page is not None and out is not None and page.resolve() == out.resolve():
            raise InputError(f"--map {args.map}: the same file as -o; give the page its own name")
        page_path(args.map, inputs=inputs, option="--map")  # an .html name
    service = None
    if args.verdict_url is not None:
        from camloc_geo.cli.locate import verdict_url

        if args.map is None:
            raise InputError("--verdict-url needs --map SUMMARY.html (the page shares verdicts)")
        service = verdict_url(args.verdict_url)
    if args.workers is not None and args.workers < 1:
        raise InputError("--workers must be at least 1")
    if args.scheduler is not None and not args.scheduler.strip():
        raise InputError("--scheduler needs an address such as tcp://HOST:8786")
    try:
        summary = run_batch(
            args.list,
            out_gpkg=args.output,
            map_source=args.osm,
            network=args.network,
            scheduler=args.scheduler,
            summary_map=args.map,
            progress=not args.no_progress and sys.stderr.isatty(),
            workers=args.workers,
            area=args.area,
            chunk_size=args.chunk_size,
            restart=args.restart,
            offline_map=not args.online_map,
            verdict_service=service,
        )
    except KeyboardInterrupt:
        from camloc_geo.batch import journal_path

        if out is not None:
            sys.stderr.write(
                "camloc batch: stopped; the cameras finished are kept in "
                f"{journal_path(out)}: run the same command again to continue\n"
            )
        raise
    for line in summary.warnings:
        sys.stderr.write(f"camloc batch: warning: {line}\n")
    counts = ", ".join(f"{n} {s}" for s, n in sorted(summary.statuses.items()))
    sys.stderr.write(
        f"camloc batch: {summary.total} cameras ({summary.computed} computed, "
        f"{summary.skipped} already done): {counts}; wrote {summary.out_gpkg}"
        + (f" and {summary.summary_map}" if summary.summary_map else "")
        + "\n"
    )
    return 0
