"""``camloc summary-map``: one Leaflet page with the best candidate of many cameras."""

from __future__ import annotations

import argparse
import logging
import math
from pathlib import Path
from typing import Any

from camloc_geo._errors import InputError
from camloc_geo._io import is_lat_lon

__all__ = ["register", "run"]

log = logging.getLogger(__name__)


def register(subparsers: Any) -> None:
    """Add the ``summary-map`` sub-command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "summary-map",
        help="Leaflet page of many cameras' best candidates (from camloc locate GeoJSON)",
        description=(
            "Read candidate GeoJSON files written by `camloc locate` and write one HTML page with "
            "the best candidate of each camera (arrow = heading, colour = score; popups with id, "
            "score, method). Cameras without candidates are listed in the page's title box; "
            "features without properties or with coordinates out of range are skipped with a "
            "warning. Never uses the network (map data only from --osm)."
        ),
    )
    p.add_argument("inputs", nargs="+", metavar="CANDIDATES.geojson", help="camloc locate output")
    p.add_argument("-o", "--output", metavar="OUT.html", required=True, help="page to write")
    p.add_argument(
        "--inline",
        action="store_true",
        help="one self-contained file (Leaflet inlined, no tiles, plain markers)",
    )
    p.add_argument("--offline", action="store_true", help="same as --inline")
    p.add_argument(
        "--osm",
        metavar="EXTRACT",
        help=(
            "draw this extract's (or this folder's covering extract's) streets and buildings "
            "(within 250 m of each camera, at most 1500 of each; the page says when capped)"
        ),
    )
    p.add_argument("--no-cluster", action="store_true", help="plain markers on online pages too")
    p.add_argument(
        "--verdicts",
        metavar="FILE",
        help=(
            "show the verdicts a reviewer exported from a summary or review page (.csv or "
            ".geojson) again on this page (see docs/candidates.md)"
        ),
    )
    p.add_argument(
        "--verdict-url",
        metavar="URL",
        help=(
            "the page shares its reviewers' verdicts with this camloc service "
            "(http(s)://host[:port], /v1/verdicts added), from a file too; the service must "
            "allow the page's origin (CAMLOC_CORS_ORIGINS; null for a file), see docs/service.md"
        ),
    )
    p.set_defaults(func=run)


def _point_of(geometry: Any) -> tuple[float, float] | None:
    """``(lon, lat)`` of a GeoJSON Point on Earth, else None."""
    if not isinstance(geometry, dict) or geometry.get("type") != "Point":
        return None
    coords = geometry.get("coordinates")
    if not isinstance(coords, list) or len(coords) < 2:
        return None
    lon, lat = coords[0], coords[1]
    return (float(lon), float(lat)) if is_lat_lon(lat, lon) else None


def clean_candidates(path: str, data: Any) -> tuple[str, dict[str, Any], int]:
    """Validate one candidate GeoJSON; drop (with a warning) features that cannot be drawn.

    A candidate without a ``lat``/``lon`` position takes its Point geometry's.

    Returns
    -------
    The scene id, the cleaned FeatureCollection and how many features were skipped.

    Raises
    ------
    InputError
        Not a FeatureCollection.
    """
    if not isinstance(data, dict) or data.get("type") != "FeatureCollection":
        raise InputError(f"{path}: not a GeoJSON FeatureCollection (camloc locate output)")
    props = data.get("properties")
    props = props if isinstance(props, dict) else {}
    feats = data.get("features")
    if not isinstance(feats, list):
        raise InputError(f"{path}: 'features' must be a list")
    kept = []
    skipped = 0
    for i, f in enumerate(feats):
        fp = f.get("properties") if isinstance(f, dict) else None
        if not isinstance(fp, dict):
            log.warning("%s: feature %d has no properties: skipped", path, i)
            skipped += 1
            continue
        if fp.get("kind") == "candidate" and "score" in fp and fp["score"] is None:
            # null: as a candidate without a score (drawn in the lowest score's colour); it
            # failed with "unsupported format string passed to NoneType.__format__", exit 1
            fp = {k: v for k, v in fp.items() if k != "score"}
            f = {**f, "properties": fp}
        if fp.get("kind") == "candidate" and "score" in fp:
            score = _score_of(fp.get("score"))
            if score is None:
                # 'high', or a list: the page failed with "TypeError: must be real number,
                # not str", exit 1 (stop 41, qa3)
                log.warning(
                    "%s: feature %d: score %r is not a number from 0 to 1: skipped",
                    path,
                    i,
                    fp.get("score"),
                )
                skipped += 1
                continue
            if score != fp.get("score"):  # text a GIS wrote for the number ("0.37")
                fp = {**fp, "score": score}
                f = {**f, "properties": fp}
        if fp.get("kind") == "candidate":
            fp = _numbers_of(fp, path, i)
            f = {**f, "properties": fp}
        if fp.get("kind") == "candidate" and not is_lat_lon(fp.get("lat"), fp.get("lon")):
            point = _point_of(f.get("geometry"))
            if point is not None:  # the feature's own Point (lat/lon columns dropped in
                # a GIS, or another tool's GeoJSON): every candidate was skipped, exit 2
                kept.append({**f, "properties": {**fp, "lat": point[1], "lon": point[0]}})
                continue
            log.warning(
                "%s: feature %d: lat=%r, lon=%r is not a position: skipped",
                path,
                i,
                fp.get("lat"),
                fp.get("lon"),
            )
            skipped += 1
            continue
        kept.append(f)
    scene_id = str(props.get("scene") or Path(path).stem)
    return scene_id, {**data, "properties": props, "features": kept}, skipped


_NUMBER_FIELDS = (
    "heading_deg",
    "pitch_deg",
    "roll_deg",
    "height_m",
    "sigma_m",
    "focal_px",
    "residual_m",
)
"""A candidate's numbers the page draws or prints besides its score and position."""


def _numbers_of(props: dict[str, Any], path: str, index: int) -> dict[str, Any]:
    """``props`` with numeric text read as numbers and other non-numbers left out (warned).

    ``"heading_deg": "north"`` failed with "TypeError: must be real number, not str", exit 1
    (stop 41, qa3); the page draws a candidate without a heading or height as it draws
    ``locate``'s title-only ones.
    """
    out = dict(props)
    for key in _NUMBER_FIELDS:
        value = out.get(key)
        if value is None or (isinstance(value, (int, float)) and not isinstance(value, bool)):
            if isinstance(value, float) and not math.isfinite(value):
                out.pop(key)
            continue
        number = None
        if isinstance(value, str):
            try:
                number = float(value.strip())
            except ValueError:
                number = None
        if number is not None and math.isfinite(number):
            out[key] = number
            continue
        log.warning(
            "%s: feature %d: %s %r is not a number: drawn without it", path, index, key, value
        )
        out.pop(key)
    return out


def _score_of(value: Any) -> float | None:
    """A candidate's score as a number in [0, 1] (numeric text read), None if it is none."""
    if isinstance(value, bool):
        return None
    if isinstance(value, str):
        try:
            value = float(value.strip())
        except ValueError:
            return None
    if not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value) if 0.0 <= value <= 1.0 else None


def _refuse_a_batch_geopackage(path: str) -> None:
    """Refuse a GeoPackage given where a locate GeoJSON belongs, saying what gives its page.

    A batch team gives ``camloc summary-map`` the batch's GeoPackage: it was "not a GeoJSON
    file (camloc locate output) (a GeoPackage or SQLite database)", with no word of the page
    ``camloc batch --map`` writes (session 41 QA).
    """
    p = Path(path)
    try:
        if not p.is_file():  # a pipe (<(...)), a device: read once, by read_json_file
            return
        with open(p, "rb") as fh:
            head = fh.read(64)
    except OSError:
        return  # read_json_file names it
    if not head.startswith(b"SQLite format 3\x00"):
        return
    raise InputError(
        f"{path}: a GeoPackage (camloc batch's output?), not a GeoJSON file (camloc locate "
        "output): a batch's summary page is written by camloc batch itself, with --map "
        "SUMMARY.html (run the same command again with it: the cameras already done are read "
        "from the batch's journal, not computed again)"
    )


def run(args: argparse.Namespace) -> int:
    """Run ``camloc summary-map``."""
    from camloc_geo.cli import atomic_output, page_path, read_json_file
    from camloc_geo.cli.locate import verdict_url

    # a bad URL stops before any reading
    service = None if args.verdict_url is None else verdict_url(args.verdict_url)

    out = page_path(args.output, inputs=[*args.inputs, args.osm, args.verdicts], option="-o")
    if out is None:
        raise InputError("-o: give an HTML file name (a page cannot go to stdout)")
    inputs = _once_each(args.inputs)
    for p in inputs:
        _refuse_a_batch_geopackage(p)
    cleaned = [
        clean_candidates(p, read_json_file(p, what="GeoJSON file (camloc locate output)"))
        for p in inputs
    ]
    items = _named_apart(
        [(scene_id, gj) for scene_id, gj, _n in cleaned], [Path(p).name for p in inputs]
    )
    best = [_best_lat_lon(gj) for _s, gj in items]
    pts = [p for p in best if p is not None]
    if not pts and any(n > 0 for _s, _g, n in cleaned):
        raise InputError("no usable camera position in the inputs (every candidate was skipped)")
    if not pts:
        log.warning(
            "no camera in the inputs has a candidate: the page lists %d camera(s) without "
            "a position on the map",
            len(items),
        )
    verdicts = None
    if args.verdicts:
        from camloc_geo._io import check_input_file
        from camloc_geo.maps import read_verdicts

        check_input_file(args.verdicts, what="verdicts file", pipes=True)  # no /dev/zero
        verdicts = read_verdicts(args.verdicts)
    map_data = None
    if args.osm:
        from camloc_geo.api import map_around

        map_data = map_around(pts, map_source=args.osm)
    from camloc_geo.maps import summary_map

    with atomic_output(out) as tmp:
        summary_map(
            items,
            tmp,
            offline=args.inline or args.offline,
            cluster=not args.no_cluster,
            map_data=map_data,
            verdicts=verdicts,
            verdict_service=service,
        )
    return 0


def _once_each(paths: list[str]) -> list[str]:
    """The input files, a file given again (``cam-*.geojson cam-3.geojson``) dropped with a
    warning: it was drawn twice, two markers on one spot under one name."""
    seen: dict[Path, str] = {}
    kept = []
    for name in paths:
        try:
            key = Path(name).resolve()
        except (OSError, RuntimeError):  # a loop of links: reading it says what is wrong
            key = Path(name).absolute()
        if key in seen:
            log.warning("%s is given twice (also as %s): shown once", name, seen[key])
            continue
        seen[key] = name
        kept.append(name)
    return kept


def _named_apart(
    items: list[tuple[str, dict[str, Any]]], files: list[str]
) -> list[tuple[str, dict[str, Any]]]:
    """The cameras, a scene id that several inputs share followed by each one's file name
    ("cam-3 (run2.geojson)"): two outputs of one scene (a rerun, an edited scene) were two
    markers and popups under one name, which the reviewer could not tell apart."""
    from collections import Counter

    seen = Counter(scene_id for scene_id, _gj in items)
    return [
        ((f"{scene_id} ({name})" if seen[scene_id] > 1 else scene_id), gj)
        for (scene_id, gj), name in zip(items, files, strict=True)
    ]


def _best_lat_lon(gj: dict[str, Any]) -> tuple[float, float] | None:
    cands = [f["properties"] for f in gj["features"] if f["properties"].get("kind") == "candidate"]
    if not cands:
        return None
    p = min(cands, key=_rank)
    return float(p["lat"]), float(p["lon"])


def _rank(props: dict[str, Any]) -> int:
    rank = props.get("rank")
    return rank if isinstance(rank, int) else 1 << 30
