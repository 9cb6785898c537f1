"""Reading a camera list (CSV or GeoJSON), streamed row by row.

Columns (case-insensitive, first variant present wins; see ``docs/batch.md``):

============  ======================================================================
field         accepted column names
============  ======================================================================
id            id, camera_id, cam_id, cameraid, camera, uid, ident, key
title         title, name, camera_name, description, desc, label, location
lat           lat, latitude, y
lon           lon, lng, long, longitude, x
radius_m      radius_m, radius, uncertainty_m, uncertainty, accuracy_m, accuracy
streets       streets, street_pair, intersection, cross_streets, junction
street pair   street1 + street2, street_a + street_b, street + cross_street,
              on_street + cross_street
scene         scene, scene_file, scene_path, annotations
view          view, direction, facing, heading, bearing (compass words or degrees)
area          area, city, extract, region (restricts the extracts searched)
============  ======================================================================

A GeoJSON list is a FeatureCollection (or one Feature per line); a Point geometry gives
lat/lon and the properties give the other columns. A FeatureCollection is parsed
incrementally (its ``features`` array feature by feature), so memory does not grow with the
length of the list.
"""

from __future__ import annotations

import codecs
import csv
import json
import logging
import math
import os
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, TextIO

from camloc_geo._errors import InputError
from camloc_geo._io import BINARY_KINDS, is_lat_lon
from camloc_geo._limits import MAX_SCENE_BYTES

log = logging.getLogger(__name__)

_DECIMAL_COMMA = re.compile(r"\s*[+-]?\d+,\d+\s*")
"""A number written with a decimal comma (``39,2851``: a European spreadsheet's export)."""

__all__ = [
    "COLUMN_VARIANTS",
    "CameraRow",
    "count_camera_rows",
    "parse_coordinate",
    "read_camera_csv",
    "read_camera_list",
    "row_from_mapping",
]

COLUMN_VARIANTS: dict[str, tuple[str, ...]] = {
    "id": ("id", "camera_id", "cam_id", "cameraid", "camera", "uid", "ident", "key"),
    "title": ("title", "name", "camera_name", "description", "desc", "label", "location"),
    "lat": ("lat", "latitude", "y"),
    "lon": ("lon", "lng", "long", "longitude", "x"),
    "radius_m": ("radius_m", "radius", "uncertainty_m", "uncertainty", "accuracy_m", "accuracy"),
    "streets": ("streets", "street_pair", "intersection", "cross_streets", "junction"),
    "scene": ("scene", "scene_file", "scene_path", "annotations"),
    "view": ("view", "direction", "facing", "heading", "bearing"),
    "area": ("area", "city", "extract", "region"),
}
"""Accepted column names per field, in order of preference (compared case-insensitively)."""

_STREET_PAIRS = (
    ("street1", "street2"),
    ("street_1", "street_2"),
    ("street_a", "street_b"),
    ("street", "cross_street"),
    ("on_street", "cross_street"),
    ("main_street", "cross_street"),
)

_MAX_FIELD_CHARS = 10_000
DEFAULT_RADIUS_M = 150.0


@dataclass(frozen=True)
class CameraRow:
    """One camera of the list, as read (nothing resolved yet).

    Attributes
    ----------
    row
        1-based position in the list (the key of the batch journal).
    id
        The camera's id (``row-N`` when the list gives none).
    title
        The listing's title ("" when none).
    lat, lon, radius_m
        The rough point and its uncertainty (metres), when given.
    streets
        An explicit street pair, when given.
    scene
        Absolute path of the scene file, when given (relative paths are resolved against the
        list's folder).
    scene_data
        The scene itself (a ``camloc-scene/1`` dict), when the list holds it inline (a GeoJSON
        property, an HTTP job); it wins over ``scene``.
    view
        The view column's text (compass words or degrees), when given.
    area
        Name restricting the extracts a title without point is searched in.
    problems
        What is wrong with the row (bad numbers, missing columns); a row with problems may
        still be placed from what is usable.
    """

    row: int
    id: str
    title: str = ""
    lat: float | None = None
    lon: float | None = None
    radius_m: float | None = None
    streets: tuple[str, ...] | None = None
    scene: str | None = None
    view: str | None = None
    area: str | None = None
    problems: tuple[str, ...] = field(default_factory=tuple)
    scene_data: dict[str, Any] | None = field(default=None, hash=False)

    @property
    def has_point(self) -> bool:
        """True when the row gives a usable rough point."""
        return self.lat is not None and self.lon is not None

    @property
    def has_scene(self) -> bool:
        """True when the row gives a scene (a file or inline)."""
        return bool(self.scene) or self.scene_data is not None


def scene_point(row: CameraRow) -> tuple[float, float] | None:
    """Where a row's scene says the camera is: its intersection's lat/lon, else its prior's.

    Only for choosing the map (the extract of a folder, a network cell) of a row that gives
    no point itself; None where the row has no scene or the scene names no valid point (a
    broken scene is reported when it is located, not here). Reads at most
    :data:`~camloc_geo._limits.MAX_SCENE_BYTES` of a scene file, as plain JSON.
    """
    data: Any = row.scene_data
    if data is None and row.scene:
        try:
            p = Path(row.scene)
            if not p.is_file() or p.stat().st_size > MAX_SCENE_BYTES:
                return None
            with open(p, encoding="utf-8-sig") as fh:
                data = json.load(fh)
        except (OSError, ValueError):
            return None
    if not isinstance(data, dict):
        return None
    for key in ("intersection", "prior"):
        part = data.get(key)
        if not isinstance(part, dict):
            continue
        lat: Any = part.get("lat")
        lon: Any = part.get("lon")
        if is_lat_lon(lat, lon):
            return float(lat), float(lon)
    return None


def area_row(row: CameraRow) -> CameraRow:
    """The row as its map is chosen: a row without a point takes its scene's point.

    A camera given only a scene (``id,scene``; an HTTP job's inline scene) was searched by
    its title in every extract of a folder, found no title, and ended ``no_evidence``
    although its scene names where it is (located with one extract given).
    """
    if row.has_point or not row.has_scene:
        return row
    point = scene_point(row)
    if point is None:
        return row
    return replace(row, lat=point[0], lon=point[1])


def _clean(value: Any) -> str:
    if value is None:
        return ""
    text = (value if isinstance(value, str) else str(value))[:_MAX_FIELD_CHARS]
    if text.isprintable():  # nearly every field: no character-by-character rewrite
        return text.strip()
    return "".join(ch if ch.isprintable() else " " for ch in text).strip()


def _text(value: Any, name: str, problems: list[str]) -> str:
    """A text column's value; an object or a list (a JSON list's ``"id": {"a": 1}``) is
    named as a row problem and kept as its JSON text (it became a Python repr, ``{'a': 1}``,
    without a word; ``"title": ["A", "B"]`` was searched for as ``['A', 'B']``)."""
    if isinstance(value, (dict, list)):
        import json

        text = json.dumps(value, ensure_ascii=False, sort_keys=True, default=str)
        problems.append(f"{name} {text[:40]!r} is not text or a number")
        return "" if name == "title" else _clean(text)
    return _clean(value)


_NUM = r"\d+(?:[.,]\d+)?"
_COORDINATE = re.compile(
    rf"""(?P<h1>[NSEW])?\s*(?P<sign>[+-])?\s*(?P<deg>{_NUM})\s*[°º˚]?\s*
    (?:(?P<min>{_NUM})\s*['′’]\s*(?:(?P<sec>{_NUM})\s*(?:"|″|”|''|′′)?\s*)?)?
    (?P<h2>[NSEW])?""",
    re.IGNORECASE | re.VERBOSE,
)
"""A coordinate as a GPS, a map site or a person writes it: ``60.1697 N``, ``N 60.1697``,
``60.1697°``, ``76°35'36.6"W``, ``60° 10.18' N`` (degrees, minutes, seconds; a hemisphere
letter before or after)."""

_AXIS_OF = {"N": "lat", "S": "lat", "E": "lon", "W": "lon"}


def parse_coordinate(text: str, name: str) -> float:
    """A latitude or longitude cell in decimal degrees, read as people write them.

    Parameters
    ----------
    text : str
        The cell: ``60.1697``, ``60,1697`` (a decimal comma), ``60.1697 N``, ``N60.1697``,
        ``60.1697°``, ``76°35'36.6"W``, ``60° 10.18' N``.
    name : str
        ``"lat"`` or ``"lon"``: which hemisphere letters belong to it (N/S, E/W).

    Returns
    -------
    float
        Decimal degrees, negative in the south and the west.

    Raises
    ------
    ValueError
        The text is no coordinate; the message says why when it is close to one (a
        hemisphere letter of the other axis, minutes of 60 or more, a sign and a letter).
    """
    cleaned = text.strip()
    if _DECIMAL_COMMA.fullmatch(cleaned):
        cleaned = cleaned.replace(",", ".")
    try:
        return float(cleaned)
    except ValueError:
        pass
    # a coordinate is short: a long cell is not searched (bounded regular-expression work)
    m = _COORDINATE.fullmatch(cleaned) if len(cleaned) <= 40 else None
    if m is None:
        raise ValueError("is not a number")
    h1, h2 = m.group("h1"), m.group("h2")
    if h1 and h2:
        raise ValueError("has two hemisphere letters")
    letter = (h1 or h2 or "").upper()
    if letter and _AXIS_OF[letter] != name:
        other = "latitude (N/S)" if _AXIS_OF[letter] == "lat" else "longitude (E/W)"
        raise ValueError(
            f"is a {other}, not a {'latitude' if name == 'lat' else 'longitude'}: are the "
            "list's lat and lon columns the other way round?"
        )
    if letter and m.group("sign"):
        raise ValueError(f"has both a sign and the hemisphere {letter}: give one")

    def part(key: str) -> float:
        got = m.group(key) if m is not None else None
        return float(got.replace(",", ".")) if got else 0.0

    minutes, seconds = part("min"), part("sec")
    if minutes >= 60 or seconds >= 60:
        raise ValueError("has minutes or seconds of 60 or more")
    value = part("deg") + minutes / 60.0 + seconds / 3600.0
    if m.group("sign") == "-" or letter in ("S", "W"):
        value = -value
    return value


def _number(
    value: Any, name: str, problems: list[str], *, coordinate: bool = False
) -> float | None:
    """A number column's value (a decimal comma read), or None with the problem named.

    With ``coordinate``, text is read as people write a latitude or longitude
    (:func:`parse_coordinate`: ``60.1697 N`` was "not a number" and the camera's point lost).
    """
    if value is None or (isinstance(value, str) and not value.strip()):
        return None
    try:
        if isinstance(value, str) and coordinate:
            num = parse_coordinate(value[:_MAX_FIELD_CHARS], name)
        elif isinstance(value, str) and _DECIMAL_COMMA.fullmatch(value):
            num = float(value.replace(",", "."))
        else:
            num = float(value)
    except (TypeError, ValueError) as exc:
        why = str(exc) if coordinate and isinstance(value, str) else "is not a number"
        problems.append(f"{name} {_clean(value)[:40]!r} {why}")
        return None
    if not math.isfinite(num):
        problems.append(f"{name} {value!r} is not a finite number")
        return None
    return num


def _pick(lower: Mapping[str, Any], key: str) -> Any:
    for name in COLUMN_VARIANTS[key]:
        if name in lower and lower[name] not in (None, ""):
            return lower[name]
    return None


def row_from_mapping(
    values: Mapping[str, Any],
    row: int,
    *,
    base_dir: Path | None = None,
    point: tuple[float, float] | None = None,
    list_problems: tuple[str, ...] = (),
    scene_paths: bool = True,
) -> CameraRow:
    """A :class:`CameraRow` from one record's columns (names matched case-insensitively).

    ``point`` is ``(lat, lon)`` from a geometry, used when the columns give none. A scene
    column holding an object is an inline scene (``scene_data``); with ``scene_paths`` false
    (a list sent by a stranger) a scene given as a file path is refused as a row problem.
    """
    lower = {str(k).strip().lower(): v for k, v in values.items() if k is not None}
    problems = list(list_problems)
    ident = _text(_pick(lower, "id"), "id", problems) or f"row-{row}"
    title = _text(_pick(lower, "title"), "title", problems)
    lat = _number(_pick(lower, "lat"), "lat", problems, coordinate=True)
    lon = _number(_pick(lower, "lon"), "lon", problems, coordinate=True)
    if lat is None and lon is None and point is not None:
        lat, lon = point
    if (lat is None) != (lon is None):
        problems.append("give both lat and lon, or neither")
        lat = lon = None
    if lat is not None and lon is not None and not (-90 <= lat <= 90 and -180 <= lon <= 180):
        hint = ""
        if max(abs(lat), abs(lon)) > 1000:  # metres of a projected CRS (Web Mercator, UTM)
            hint = (
                " (projected coordinates, in metres? a list gives WGS 84 degrees: export it "
                "in EPSG:4326, as GeoJSON requires)"
            )
        problems.append(f"lat={lat}, lon={lon} is not a point on Earth{hint}")
        lat = lon = None
    radius = _number(_pick(lower, "radius_m"), "radius_m", problems)
    if radius is not None and radius <= 0:
        problems.append(f"radius_m {radius} is not positive")
        radius = None
    streets: tuple[str, ...] | None = None
    raw_streets = _clean(_pick(lower, "streets"))
    if raw_streets:
        from camloc_geo.osm._names import split_street_query

        parts = [p for p in split_street_query(raw_streets) if p]
        streets = tuple(parts) if parts else None
    else:
        for a, b in _STREET_PAIRS:
            sa, sb = _clean(lower.get(a)), _clean(lower.get(b))
            if sa and sb:
                streets = (sa, sb)
                break
    raw_scene = _pick(lower, "scene")
    scene_data = raw_scene if isinstance(raw_scene, dict) else None
    scene_text = "" if scene_data is not None else _clean(raw_scene)
    scene: str | None = None
    if scene_text and not scene_paths:
        problems.append("a scene must be given inline (a JSON object), not as a file path")
        scene_text = ""
    if scene_text:
        p = Path(scene_text).expanduser()
        if not p.is_absolute() and base_dir is not None:
            p = base_dir / p
        scene = str(p)
    view = _clean(_pick(lower, "view")) or None
    area = _clean(_pick(lower, "area")) or None
    return CameraRow(
        row=row,
        id=ident,
        title=title,
        lat=lat,
        lon=lon,
        radius_m=radius,
        streets=streets,
        scene=scene,
        view=view,
        area=area,
        problems=tuple(problems),
        scene_data=scene_data,
    )


# the binary files a camera list is mistaken for, by their first bytes
_BINARY_KINDS = BINARY_KINDS


_UTF16_BOMS = (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)


def _check_text_list(path: Path, head: bytes) -> None:
    """Refuse a binary file as a list, naming what it looks like.

    A GeoPackage given as the list was read as Latin-1 "text": the error quoted its SQLite
    header's bytes as the list's header row. Text lists (CSV, GeoJSON; UTF-8, UTF-8 with a
    byte-order mark, Windows-1252) never hold a NUL byte.
    """
    from camloc_geo._io import map_file_kind

    extract = map_file_kind(head[:16])
    if extract is not None:  # the extract given as the list (qa7): "holds NUL bytes" and
        # advice to export the cameras from QGIS; a .osm.bz2 was even read as text
        raise InputError(
            f"the camera list {path.name} is {extract}, not a CSV or GeoJSON list of cameras: "
            "give the extract (or its folder) after --osm and the camera list first"
        )
    what = binary_list_kind(head)
    if what is None:
        return
    raise InputError(
        f"the camera list {path.name} is {what}, not a CSV or GeoJSON list: save the cameras "
        "as CSV or GeoJSON (QGIS: Export > Save Features As...; GDAL: ogr2ogr -f GeoJSON "
        f"cameras.geojson {path.name}) and give that file"
    )


def binary_list_kind(head: bytes) -> str | None:
    """What a list's first bytes say it is when it is no text (None: text, maybe UTF-16).

    A NUL byte never occurs in a UTF-8 or Windows-1252 list; UTF-16 with its byte-order mark
    (Excel's "Unicode Text") is text.
    """
    if b"\x00" not in head or head.startswith(_UTF16_BOMS):
        return None
    what = next((kind for magic, kind in _BINARY_KINDS if head.startswith(magic)), None)
    return what or "not a text file (it holds NUL bytes)"


def _list_kind(path: Path) -> str:
    with open(path, "rb") as fh:
        head = fh.read(4096)
    _check_text_list(path, head)
    name = path.name.lower()
    if name.endswith((".geojson", ".json", ".geojsonl", ".geojsons", ".ndjson", ".jsonl")):
        return "geojson"
    if name.endswith((".csv", ".tsv", ".txt")):
        return "csv"
    return "geojson" if head.lstrip()[:64].startswith((b"{", b"[")) else "csv"


def _missing_column_problems(columns: list[str]) -> tuple[str, ...]:
    lower = {c.strip().lower() for c in columns if c}
    problems = []
    if not any(n in lower for n in COLUMN_VARIANTS["title"]):
        problems.append(
            "the list has no title column (" + ", ".join(COLUMN_VARIANTS["title"][:3]) + ", ...)"
        )
    if not any(n in lower for n in COLUMN_VARIANTS["id"]):
        problems.append("the list has no id column; rows are named row-N")
    return tuple(problems)


def _text_encoding(path: Path) -> str:
    """``utf-8-sig`` for UTF-8 text (with or without a byte-order mark), ``utf-16`` for text
    that starts with a UTF-16 byte-order mark (Excel's "Unicode Text"), else the
    Windows-1252 that spreadsheets export on Western systems (``latin-1`` where even that
    does not decode), with a warning: a list saved so is read, not refused.

    One streaming pass over the bytes (an incremental decoder: bounded memory).
    """
    decoder: codecs.IncrementalDecoder = codecs.getincrementaldecoder("utf-8")()
    with open(path, "rb") as fh:
        if fh.read(2) in _UTF16_BOMS:  # Excel's "Unicode Text" export (tab-separated)
            return "utf-16"
        fh.seek(0)
        try:
            while chunk := fh.read(1 << 20):
                decoder.decode(chunk)
            decoder.decode(b"", final=True)
            return "utf-8-sig"
        except UnicodeDecodeError:
            pass
        fh.seek(0)
        decoder = codecs.getincrementaldecoder("cp1252")()
        try:
            while chunk := fh.read(1 << 20):
                decoder.decode(chunk)
            encoding = "cp1252"
        except UnicodeDecodeError:
            encoding = "latin-1"
    st = path.stat()
    key = (str(path.resolve()), st.st_mtime_ns, st.st_size)
    if key not in _ENCODING_WARNED:  # the list is read twice (count, then rows): say it once
        if len(_ENCODING_WARNED) > 1000:
            _ENCODING_WARNED.clear()
        _ENCODING_WARNED.add(key)
        log.warning(
            "camera list %s is not UTF-8 text: read as %s (a spreadsheet's export); check "
            "accented names, and save it as UTF-8 to be sure",
            path.name,
            "Windows-1252" if encoding == "cp1252" else "Latin-1",
        )
    return encoding


_ENCODING_WARNED: set[tuple[str, int, int]] = set()


def _read_csv(path: Path) -> Iterator[CameraRow]:
    with open(path, encoding=_text_encoding(path), newline="") as fh:
        yield from read_camera_csv(
            fh, base_dir=path.resolve().parent, tsv=path.name.lower().endswith(".tsv")
        )


def read_camera_csv(
    fh: TextIO, *, base_dir: Path | None = None, tsv: bool = False
) -> Iterator[CameraRow]:
    """Stream the cameras of CSV text (an open file or :class:`io.StringIO`).

    The in-memory entry point of :func:`read_camera_list` (same columns, delimiter sniffed
    among ``, ; tab |``). ``base_dir`` resolves relative scene paths (None: left relative).
    """
    sample = fh.read(8192)
    fh.seek(0)
    delimiter = ","
    if tsv:
        delimiter = "\t"
    else:
        try:
            delimiter = csv.Sniffer().sniff(sample, delimiters=",;\t|").delimiter
        except csv.Error:
            delimiter = ","
    csv.field_size_limit(max(csv.field_size_limit(), 1 << 20))
    reader = csv.DictReader(fh, delimiter=delimiter)
    columns = list(reader.fieldnames or [])
    if not columns:
        return
    list_problems = _missing_column_problems(columns)
    # a missing id column only renames rows: not a problem of the camera
    list_problems = tuple(p for p in list_problems if "no id column" not in p)
    for n, rec in enumerate(reader, start=1):
        yield row_from_mapping(rec, n, base_dir=base_dir, list_problems=list_problems)


def _feature_row(feat: Any, n: int, base: Path, *, scene_paths: bool = True) -> CameraRow:
    if not isinstance(feat, dict):
        return CameraRow(row=n, id=f"row-{n}", problems=("not a GeoJSON feature",))
    props = feat.get("properties") or {}
    if not isinstance(props, dict):
        props = {}
    if "id" in feat and not any(k.lower() in COLUMN_VARIANTS["id"] for k in props):
        props = {**props, "id": feat["id"]}
    point = None
    geom = feat.get("geometry")
    problems: tuple[str, ...] = ()
    if isinstance(geom, dict) and geom.get("type") == "Point":
        coords = geom.get("coordinates") or []
        try:
            point = (float(coords[1]), float(coords[0]))
        except (TypeError, ValueError, IndexError):
            problems = ("the Point geometry has no usable coordinates",)
    elif geom is not None:
        problems = (f"geometry {geom.get('type') if isinstance(geom, dict) else geom!r} ignored",)
    if not any(k.lower() in COLUMN_VARIANTS["title"] for k in props):
        problems = (*problems, "the feature has no title property")
    return row_from_mapping(
        props, n, base_dir=base, point=point, list_problems=problems, scene_paths=scene_paths
    )


def _iter_json_features(fh: TextIO, name: str) -> Iterator[Any]:
    """Features of a FeatureCollection read incrementally (or of a top-level array)."""
    dec = json.JSONDecoder()
    buf = ""
    pos = 0
    eof = False

    def fill() -> bool:
        nonlocal buf, pos, eof
        if eof:
            return False
        chunk = fh.read(1 << 16)
        if not chunk:
            eof = True
            return False
        buf = buf[pos:] + chunk
        pos = 0
        return True

    def skip_ws() -> str:
        nonlocal pos
        while True:
            while pos < len(buf) and buf[pos] in " \t\r\n":
                pos += 1
            if pos < len(buf):
                return buf[pos]
            if not fill():
                return ""

    def value() -> Any:
        nonlocal pos
        skip_ws()
        while True:
            try:
                obj, end = dec.raw_decode(buf, pos)
            except json.JSONDecodeError as exc:
                if fill():
                    continue
                raise InputError(f"malformed GeoJSON in {name}: {exc.msg}") from None
            # a number at the buffer's end may be cut: read on before trusting it
            if end >= len(buf) and not eof and fill():
                continue
            pos = end
            return obj

    def array_items() -> Iterator[Any]:
        nonlocal pos
        pos += 1  # '['
        if skip_ws() == "]":
            pos += 1
            return
        while True:
            skip_ws()
            yield value()
            c = skip_ws()
            if c == ",":
                pos += 1
            elif c == "]":
                pos += 1
                return
            else:
                raise InputError(f"malformed GeoJSON in {name}: expected ',' or ']'")

    c = skip_ws()
    if c == "[":
        yield from array_items()
        return
    if c != "{":
        raise InputError(f"{name} is neither a CSV list nor GeoJSON")
    pos += 1
    found = False
    while True:
        c = skip_ws()
        if c == "}":
            break
        key = value()
        if skip_ws() != ":":
            raise InputError(f"malformed GeoJSON in {name}: expected ':'")
        pos += 1
        if key == "features" and skip_ws() == "[":
            found = True
            yield from array_items()
        else:
            obj = value()
            if key == "type" and obj == "Feature":
                raise _SingleFeatureError
        c = skip_ws()
        if c == ",":
            pos += 1
    if not found:
        raise InputError(f"{name} is a JSON object without a 'features' array")


class _SingleFeatureError(Exception):
    pass


def _read_geojson(path: Path) -> Iterator[CameraRow]:
    base = path.resolve().parent
    with open(path, encoding="utf-8-sig") as fh:
        head = fh.read(1 << 16)
        fh.seek(0)
        lines = head.splitlines()
        seq = len(lines) > 1 and all(
            ln.strip().lstrip("\x1e").startswith("{") for ln in lines[:2] if ln.strip()
        )
        if seq and lines[0].rstrip().endswith("}"):
            # GeoJSON text sequence / one feature per line
            for n, line in enumerate((ln for ln in fh if ln.strip()), start=1):
                try:
                    feat = json.loads(line.strip().lstrip("\x1e"))
                except json.JSONDecodeError as exc:
                    yield CameraRow(
                        row=n, id=f"row-{n}", problems=(f"malformed JSON line: {exc.msg}",)
                    )
                    continue
                yield _feature_row(feat, n, base)
            return
        try:
            for n, feat in enumerate(_iter_json_features(fh, path.name), start=1):
                yield _feature_row(feat, n, base)
        except _SingleFeatureError:
            fh.seek(0)
            yield _feature_row(json.load(fh), 1, base)


def read_camera_list(path: str | os.PathLike[str]) -> Iterator[CameraRow]:
    """Stream the cameras of a CSV or GeoJSON list, one :class:`CameraRow` per record.

    Never raises for a bad row: what is wrong goes into :attr:`CameraRow.problems`.

    Raises
    ------
    InputError
        The file does not exist, cannot be read, or is neither CSV nor GeoJSON.
    """
    p = Path(path).expanduser()
    if not p.is_file():
        raise InputError(f"camera list not found: {p}")
    try:
        kind = _list_kind(p)
        if kind == "geojson":
            yield from _read_geojson(p)
        else:
            yield from _read_csv(p)
    except UnicodeDecodeError as exc:
        enc = "UTF-8" if exc.encoding.lower().startswith("utf-8") else exc.encoding.upper()
        raise InputError(f"camera list {p.name} is not {enc} text: {exc.reason}") from None
    except csv.Error as exc:
        raise InputError(f"malformed CSV in {p.name}: {exc}") from None
    except OSError as exc:
        raise InputError(f"cannot read camera list {p}: {exc}") from None


def count_camera_rows(path: str | os.PathLike[str]) -> int:
    """How many cameras a list holds (one streaming pass)."""
    n = 0
    for _ in read_camera_list(path):
        n += 1
    return n
