"""``camloc geocode``: place webcam titles at the junctions they name (GeoJSON)."""

from __future__ import annotations

import argparse
import csv
import itertools
import json
import math
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

__all__ = ["register", "run"]

_TITLE_COLUMNS = (
    "title",
    "name",
    "camera_title",
    "camera_name",
    "description",
    "desc",
    "label",
    "location",
)
_ID_COLUMNS = ("id", "camera_id", "cam_id", "number")
_LAT_COLUMNS = ("lat", "latitude", "y")
_LON_COLUMNS = ("lon", "lng", "longitude", "x")


def register(subparsers: Any) -> None:
    """Add the ``geocode`` sub-command."""
    parser = subparsers.add_parser(
        "geocode",
        help="place webcam titles at the junctions they name (GeoJSON)",
        description=(
            "Read webcam titles ('625 - Milton & E Biddle St', 'N POTOMAC ST @ E FAYETTE ST', "
            "'Karl-Liebknecht-Str. / Wadzeckstr.') and write a GeoJSON FeatureCollection with "
            "one feature per match, best first: status junction | street | address | landmark "
            "| ambiguous | not_found, the names read and the OSM names matched, how each "
            "matched, the score and the reason. Map data © OpenStreetMap contributors (ODbL)."
        ),
    )
    parser.add_argument("titles", nargs="*", metavar="TITLE", help="webcam titles")
    parser.add_argument(
        "--osm",
        metavar="EXTRACT_OR_FOLDER",
        required=True,
        help="an .osm/.osm.gz/.osm.bz2/.osm.pbf extract, or a folder of them (a title is "
        "then searched in every extract; placed in two means ambiguous)",
    )
    parser.add_argument("--near", metavar="LAT,LON", help="rank by distance from this point")
    parser.add_argument(
        "--radius-m", type=float, help="with --near (or --area): keep matches within this radius"
    )
    parser.add_argument("--area", help="search around this named place of the map")
    parser.add_argument(
        "--list",
        metavar="LIST.csv",
        help="CSV (any of , ; tab |) or GeoJSON list of titles (column title or name; "
        "optional id, lat, lon), streamed",
    )
    parser.add_argument("--best", action="store_true", help="only the best match per title")
    parser.add_argument("-o", "--output", metavar="OUT.geojson", help="output file (stdout)")
    parser.set_defaults(func=run)


def _best_of(found: list[Any]) -> list[Any]:
    """``--best``: the first match, its reason saying when another placed match scores as
    well. Leeds' "Mabgate & Regent Street" (two junctions 79 m apart, equal scores) came out
    a plain ``junction`` at one of them, the other dropped without a word (qa7)."""
    import math

    from camloc_geo.geodesy import great_circle_m

    if not found:
        return found
    best = found[0]
    same = [
        m
        for m in found[1:]
        if m.lat is not None
        and best.lat is not None
        and m.score == best.score
        and math.isfinite(float(m.score))
    ]
    if same:
        far = max(
            great_circle_m(lat1=best.lat, lon1=best.lon, lat2=m.lat, lon2=m.lon) for m in same
        )
        word = "match" if len(same) == 1 else "matches"
        best.reason = (
            f"{best.reason}; --best left out {len(same)} {word} of the same score, up to "
            f"{far:.0f} m away (without --best all are listed)"
        )
    return [best]


def _parse_near(text: str | None) -> tuple[float, float] | None:
    from camloc_geo._errors import InputError

    if text is None:
        return None
    try:
        lat_s, lon_s = text.split(",")
        lat, lon = float(lat_s), float(lon_s)
    except ValueError:
        raise InputError(f"--near must be LAT,LON in degrees, got {text!r}") from None
    if not (-90.0 <= lat <= 90.0 and -180.0 <= lon <= 180.0):
        raise InputError(f"--near out of range: {text!r}")
    return lat, lon


def _column(header: list[str], options: tuple[str, ...]) -> str | None:
    lowered = {h.strip().lower(): h for h in header if h}
    for o in options:
        if o in lowered:
            return lowered[o]
    return None


def _rows(path: Path) -> Iterator[tuple[int, str | None, str, tuple[float, float] | None]]:
    """(row number, id, title, point) of each row of a CSV or GeoJSON list, one at a time.

    The list is read as ``camloc batch`` reads it: a CSV's delimiter is detected among
    ``, ; tab |``, its text is UTF-8 (a byte-order mark is fine) or else Windows-1252 with a
    warning, and a coordinate may use a decimal comma; a GeoJSON list (a FeatureCollection, or
    one Feature per line) gives the point from its geometry. A CSV row's number is its line
    in a spreadsheet (the header is row 1); a GeoJSON feature's is its position (from 1).

    The file is opened and its header checked at once, before the first row is asked for,
    so a missing or headless list fails before any output is written.
    """
    from camloc_geo._errors import InputError
    from camloc_geo._io import check_input_file
    from camloc_geo.cameras._list import _list_kind, _text_encoding

    # a device or a pipe (/dev/zero) was read for ever; a list may be large (streamed)
    check_input_file(path, what="list of titles", max_bytes=None)
    csv.field_size_limit(max(csv.field_size_limit(), 1 << 20))
    try:
        kind = _list_kind(path)
        if kind == "geojson":
            return _geojson_rows(path)
        encoding = _text_encoding(path)
        fh = path.open(newline="", encoding=encoding, errors="replace")
    except OSError as exc:
        raise InputError(f"cannot read the list {path}: {exc.strerror or exc}") from None
    try:
        try:
            sample = fh.read(8192)
            fh.seek(0)
            delimiter = ","
            if path.name.lower().endswith(".tsv"):
                delimiter = "\t"
            elif sample:
                try:
                    delimiter = csv.Sniffer().sniff(sample, delimiters=",;\t|").delimiter
                except csv.Error:
                    delimiter = ","
            reader = csv.reader(fh, delimiter=delimiter)
            header = next(reader)
        except StopIteration:
            raise InputError(f"the list {path} is empty") from None
        except csv.Error as exc:
            raise InputError(f"the list {path} is not CSV: {exc}") from None
        except (OSError, UnicodeError) as exc:
            raise InputError(f"cannot read the list {path}: {exc}") from None
        title_col = _column(header, _TITLE_COLUMNS)
        if title_col is None:
            raise InputError(
                f"the list {path} has no title column (one of {', '.join(_TITLE_COLUMNS)}); "
                f"its columns: {', '.join(header)}"
            )
    except BaseException:
        fh.close()
        raise
    return _data_rows(fh, reader, header, title_col)


def _non_empty(rows: Iterator[_Row], path: Path) -> Iterator[_Row]:
    """``rows``, or an :class:`InputError` when the list holds none (read before any output).

    A list with a header and no row printed an empty FeatureCollection, exit 0, where
    ``camloc batch`` refuses it (stop 41, qa3).
    """
    from camloc_geo._errors import InputError

    first = next(rows, None)
    if first is None:
        raise InputError(
            f"the list {path} holds no title (no row under its header); a list is CSV with a "
            "header naming a title column, or GeoJSON"
        )
    return itertools.chain([first], rows)


_Row = tuple[int, str | None, str, tuple[float, float] | None]


def _geojson_rows(
    path: Path,
) -> Iterator[tuple[int, str | None, str, tuple[float, float] | None]]:
    """The features of a GeoJSON list as (number, id, title, point); the first is read at
    once so that a list that is no GeoJSON fails before any output."""
    from camloc_geo.cameras import read_camera_list

    cameras = read_camera_list(path)
    first = next(cameras, None)

    def rows() -> Iterator[tuple[int, str | None, str, tuple[float, float] | None]]:
        if first is None:
            return
        for cam in itertools.chain([first], cameras):
            for problem in cam.problems:
                if "title column" not in problem:
                    sys.stderr.write(f"camloc geocode: feature {cam.row}: {problem}\n")
            point = None
            lat, lon = cam.lat, cam.lon
            if lat is not None and lon is not None and -90 <= lat <= 90 and -180 <= lon <= 180:
                point = (lat, lon)
            ident = None if cam.id == f"row-{cam.row}" else cam.id
            yield cam.row, ident, cam.title, point

    return rows()


def _data_rows(
    fh: IO[str], reader: Any, header: list[str], title_col: str
) -> Iterator[tuple[int, str | None, str, tuple[float, float] | None]]:
    """The rows after the header of an opened list (closes ``fh`` at the end)."""
    with fh:
        idx = {h: i for i, h in enumerate(header)}
        t_i = idx[title_col]
        id_col = _column(header, _ID_COLUMNS)
        lat_col, lon_col = _column(header, _LAT_COLUMNS), _column(header, _LON_COLUMNS)
        row_no = 1
        while True:
            try:
                row = next(reader)
            except StopIteration:
                return
            except csv.Error as exc:
                row_no += 1
                yield row_no, None, "", None
                sys.stderr.write(f"camloc geocode: row {row_no}: unreadable ({exc})\n")
                continue
            row_no += 1
            if not row:
                continue
            title = row[t_i] if t_i < len(row) else ""
            ident = row[idx[id_col]] if id_col is not None and idx[id_col] < len(row) else None
            point = None
            if lat_col is not None and lon_col is not None:
                cells = [row[idx[c]] if idx[c] < len(row) else "" for c in (lat_col, lon_col)]
                point, problem = _point_of(cells[0], cells[1])
                if problem:
                    # a bad point was dropped without a word and the title searched
                    # everywhere (camloc batch names it in the camera's reason)
                    sys.stderr.write(
                        f"camloc geocode: row {row_no}: {problem}; searched without a point\n"
                    )
            yield row_no, ident, title, point


def _point_of(lat_text: str, lon_text: str) -> tuple[tuple[float, float] | None, str | None]:
    """A row's point and what is wrong with it (None, None: no point given)."""
    if not lat_text.strip() and not lon_text.strip():
        return None, None
    if not lat_text.strip() or not lon_text.strip():
        return None, "give both lat and lon, or neither"
    from camloc_geo.cameras import parse_coordinate

    # as camloc batch reads them: a decimal comma, ``60.1697 N``, ``76°35'36.6"W``
    try:
        lat = parse_coordinate(lat_text, "lat")
    except ValueError as exc:
        return None, f"lat {lat_text.strip()[:40]!r} {exc}"
    try:
        lon = parse_coordinate(lon_text, "lon")
    except ValueError as exc:
        return None, f"lon {lon_text.strip()[:40]!r} {exc}"
    if not (math.isfinite(lat) and math.isfinite(lon)):
        return None, f"lat/lon {lat_text.strip()[:40]},{lon_text.strip()[:40]} is not finite"
    if not (-90.0 <= lat <= 90.0 and -180.0 <= lon <= 180.0):
        return None, f"lat/lon {lat:g},{lon:g} is out of range"
    return (lat, lon), None


@contextmanager
def _feature_writer(out: Path | None) -> Iterator[Any]:
    """Stream features to stdout, or to ``out`` atomically (nothing is left on failure)."""
    if out is None:
        with _features_to(sys.stdout) as write:
            yield write
        return
    from camloc_geo.cli import atomic_output

    with (
        atomic_output(out) as tmp,
        open(tmp, "w", encoding="utf-8") as fh,
        _features_to(fh) as write,
    ):
        yield write


@contextmanager
def _features_to(fh: IO[str]) -> Iterator[Any]:
    """A FeatureCollection streamed to ``fh``, closed only when the work succeeds.

    On a failure (``--area`` naming no place, an unreadable extract) stdout held a complete,
    empty ``{"type": "FeatureCollection", "features": []}`` beside exit 2, which a pipe's
    reader took for "no match" (session 39): now nothing is written before the first feature,
    and a collection cut by a failure stays unclosed, so no JSON reader takes it as whole.
    """
    started = [False]
    head = '{"type": "FeatureCollection", "features": [\n'

    def write(feature: dict[str, Any]) -> None:
        fh.write(",\n" if started[0] else head)
        started[0] = True
        fh.write(json.dumps(feature, allow_nan=False, ensure_ascii=False))

    yield write
    fh.write("\n]}\n" if started[0] else head + "\n]}\n")
    fh.flush()


def _title_text(title: str, number: int) -> str:
    """A title from the command line as text.

    Python reads arguments that are not UTF-8 into lone surrogates, which no UTF-8 file can
    hold: ``-o`` then failed with a ``UnicodeEncodeError`` (exit 1) after the work. Such a
    title is read as Windows-1252 (Latin-1 where even that fails), as ``--list`` reads a
    list that is not UTF-8, with a warning.
    """
    import logging
    import os

    try:
        title.encode("utf-8")
    except UnicodeEncodeError:
        raw = os.fsencode(title)
        try:
            text, encoding = raw.decode("cp1252"), "Windows-1252"
        except UnicodeDecodeError:
            text, encoding = raw.decode("latin-1"), "Latin-1"
        logging.getLogger("camloc_geo.cli").warning(
            "title %d is not UTF-8 text: read as %s (%r); check accented names",
            number,
            encoding,
            text,
        )
        return text
    return title


def run(args: argparse.Namespace) -> int:
    """Run ``camloc geocode``."""
    from camloc_geo._errors import InputError
    from camloc_geo.geocode import extract_paths, geocode_title_in_maps, whole_map

    if not args.titles and not args.list:
        raise InputError("give one or more titles, or --list LIST.csv")
    for number, arg in enumerate(args.titles, start=1):
        if not arg.strip():  # ("$TITLE" unset: it printed a not_found feature, exit 0)
            raise InputError(f"title {number} is empty: give the webcam title's text")
    near = _parse_near(args.near)
    if args.radius_m is not None and not (args.radius_m > 0):
        raise InputError(f"--radius-m must be positive, got {args.radius_m}")
    from camloc_geo.cli import json_path

    paths = extract_paths(args.osm)
    out = json_path(args.output, inputs=[args.list, *paths], what="GeoJSON")
    rows = _non_empty(_rows(Path(args.list)), Path(args.list)) if args.list else None
    maps = [whole_map(p) for p in paths]

    def matches_of(title: str, point: tuple[float, float] | None) -> list[dict[str, Any]]:
        found = geocode_title_in_maps(
            title, maps, near=point or near, radius_m=args.radius_m, area=args.area
        )
        if args.best:
            found = _best_of(found)
        return [m.to_feature() for m in found]

    with _feature_writer(out) as write:
        for number, arg in enumerate(args.titles, start=1):
            title = _title_text(arg, number)
            for rank, feature in enumerate(matches_of(title, None)):
                feature["properties"]["rank"] = rank
                write(feature)
        if rows is not None:
            for row_no, ident, title, point in rows:
                for rank, feature in enumerate(matches_of(title, point)):
                    props = feature["properties"]
                    props["row"] = row_no
                    props["id"] = ident
                    props["rank"] = rank
                    write(feature)
    return 0
