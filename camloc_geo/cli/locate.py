"""``camloc locate SCENE.json``: candidate camera positions as GeoJSON."""

from __future__ import annotations

import argparse
import logging
from typing import Any

from camloc_geo.cli import (
    NETWORK_HELP,
    add_map_options,
    atomic_output,
    distinct_outputs,
    inline_of,
    json_path,
    network_of,
    output_path,
    page_path,
    write_json,
)

__all__ = ["register", "run", "verdict_url"]

log = logging.getLogger(__name__)


def register(subparsers: Any) -> None:
    """Add the ``locate`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "locate",
        help="candidate absolute camera positions (GeoJSON), best first",
        description=(
            "Locate the camera on the map: enumerate, rank and refine candidate positions from "
            "the scene's references, intersection corners and landmarks. " + NETWORK_HELP
        ),
    )
    p.add_argument("scene", help="scene file (camloc-scene/1 JSON)")
    add_map_options(p, page=True)
    p.add_argument(
        "-o", "--output", metavar="OUT.geojson", help="write GeoJSON here (default stdout)"
    )
    p.add_argument("--map", metavar="OUT.html", help="also write a Leaflet review map")
    p.add_argument(
        "--radius-m",
        type=float,
        default=None,
        help="map radius around the scene (default: prior radius + 200 m, at least 300 m)",
    )
    p.add_argument("--max-candidates", type=int, default=None, help="at most this many candidates")
    p.add_argument(
        "--overlays",
        metavar="DIR",
        default=None,
        help="with --map: write candidate image overlays (PNG) into this existing folder",
    )
    p.add_argument(
        "--verdicts",
        metavar="FILE",
        help=(
            "with --map: show the verdicts a reviewer exported from a review or summary page "
            "(.csv or .geojson) on this scene's candidates again (see docs/candidates.md)"
        ),
    )
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


def verdict_url(url: str) -> str:
    """The verdicts endpoint of a service named by ``--verdict-url``.

    Parameters
    ----------
    url
        ``http(s)://host[:port]`` with or without a path prefix (``/camloc``) or the
        ``/v1/verdicts`` endpoint itself.

    Returns
    -------
    str
        ``<url>/v1/verdicts``, without a trailing slash.

    Raises
    ------
    InputError
        Not an http(s) URL with a host, or with a query, fragment or user name.
    """
    from urllib.parse import urlsplit

    from camloc_geo._errors import InputError

    text = url.strip()
    try:
        parts = urlsplit(text)
        parts.port  # noqa: B018 (a bad port raises here)
    except ValueError as exc:
        raise InputError(f"--verdict-url {url!r}: not a URL ({exc})") from None
    if parts.scheme not in ("http", "https") or not parts.hostname:
        raise InputError(
            f"--verdict-url {url!r}: give the service's http:// or https:// address "
            "(e.g. http://reviews.example.org:8000)"
        )
    if parts.query or parts.fragment or parts.username or parts.password:
        raise InputError(f"--verdict-url {url!r}: no query, fragment or user name, please")
    if any(c in text for c in "\"'<>` \\"):
        raise InputError(f"--verdict-url {url!r}: not a URL")
    base = text.split("?")[0].rstrip("/")
    return base if base.endswith("/v1/verdicts") else base + "/v1/verdicts"


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo._errors import InputError
    from camloc_geo.api import check_map_radius_m, locate_scene

    if args.radius_m is not None:  # 30000000 loaded the extract, then "no streets"
        check_map_radius_m(args.radius_m, "--radius-m")
    if args.max_candidates is not None and args.max_candidates < 1:
        # before the locating, in the option's name (it came after the map was read, as
        # "max_candidates: max_candidates must be at least 1")
        raise InputError(f"--max-candidates must be at least 1 (got {args.max_candidates})")
    inputs = [args.scene, args.osm, args.verdicts]
    out_path = output_path(args.output, inputs=inputs)
    map_path = page_path(args.map, inputs=inputs, option="--map")
    distinct_outputs(("-o", out_path), ("--map", map_path))  # said first, as before
    json_path(args.output, inputs=inputs, what="GeoJSON", hint="the review page is --map OUT.html")
    if args.overlays is not None:
        if map_path is None:
            raise InputError("--overlays needs --map OUT.html")
        output_path(args.overlays, option="--overlays", directory=True)
    verdicts = None
    if args.verdicts is not None:
        if map_path is None:
            raise InputError("--verdicts needs --map OUT.html (the verdicts are shown on it)")
        from camloc_geo._io import check_input_file
        from camloc_geo.maps import read_verdicts

        check_input_file(args.verdicts, what="verdicts file", pipes=True)  # no /dev/zero
        verdicts = read_verdicts(args.verdicts)  # a bad file stops before the locating
    service = None
    if args.verdict_url is not None:
        if map_path is None:
            raise InputError("--verdict-url needs --map OUT.html (the page shares verdicts)")
        service = verdict_url(args.verdict_url)
    out = locate_scene(
        args.scene,
        map_source=args.osm,
        network=network_of(args),
        radius_m=args.radius_m,
        max_candidates=args.max_candidates,
        cache_folder=args.cache_folder,
        overpass_url=args.overpass_url,
    )
    if out.result.leaders_tie:  # a tie is never only in the GeoJSON
        log.warning("ambiguous: %s", out.result.ties[0].text)
    write_json(out.to_geojson(), args.output, inputs=inputs)
    if map_path is not None:
        from camloc_geo.maps import candidates_map

        with atomic_output(map_path) as tmp:
            candidates_map(
                out.result,
                out.map_data,
                tmp,
                offline=inline_of(args),
                scene=out.scene,
                overlay_dir=args.overlays,
                verdicts=verdicts,
                verdict_service=service,
            )
    if not out.result.candidates:
        log.warning("no candidates: %s", out.result.reason)
    return 0
