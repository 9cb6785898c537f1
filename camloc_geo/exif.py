"""Focal length of a photo from its EXIF tags, as a prior for the vanishing-point fit.

Read with Pillow (``PIL.Image.getexif``); nothing here touches the network.

Readings
--------
Each of these the photo's tags give is read:

``exif-focal-plane``
    ``FocalLength`` (0x920A) with ``FocalPlaneXResolution`` (0xA20E) and its unit
    (0xA210), scaled by ``width / PixelXDimension`` when the photo was resized: sigma 5 %
    (some cameras write the resolution of a sensor crop). The resolution refers to the frame
    the camera stored; a tool that resized the photo and rewrote (or dropped)
    ``PixelXDimension`` leaves it on the old frame, so it gives a sensor too small by the
    resize. Where the table's width (or the 35 mm tag's crop factor, on the photo's own
    diagonal) is more than :data:`FOCAL_PLANE_SHRUNK` times wider than the resolution's, the
    reading is not used, with a warning saying why. The photo's orientation does not matter
    (``Orientation`` 6 or 8, pixels turned or not, pixel sizes swapped or not): the longer
    side and the diagonal are used. A photo whose shape differs from the frame its
    ``PixelXDimension`` and ``PixelYDimension`` describe (by more than 2 %) was cropped
    after capture: every reading is made on that frame and scaled by the crop's resize,
    which is not known: between the least that fits the crop in the frame and none
    (:func:`_capture_frame`), the prior's sigma covering that range (said in the notes).
``exif-sensor-table``
    ``FocalLength`` with the sensor width of ``Make`` + ``Model`` in a sensor-width table,
    ``focal_px = FocalLength / width_mm * longer_side_px`` (the photo's longer side spans the
    sensor's width: a 4:3 photo, or a 16:9 one cut from a 4:3 sensor): sigma 5 % (tables
    give the nominal optical format, a few per cent off the active area). The table is the
    file named by ``CAMLOC_SENSOR_DB`` where it has the camera (its lines ``Make Model;width_mm``
    as in openMVG's ``sensor_width_camera_database.txt``, or ``Make,Model,width_mm`` as in
    openMVG's ``sensor_database.csv``; its first matching line wins), else the bundled table,
    ``camloc_geo/data/sensor_widths/sensor_widths.csv``: COLMAP's camera table (BSD 3-clause;
    4400 cameras, phones to the iPhone 16; source commit and licence in the ``NOTICE.md``
    beside it). Make and model are matched in lower case without spaces or hyphens, with a
    maker's name the model repeats removed (``Canon`` + ``Canon EOS 5D``, ``NIKON
    CORPORATION`` + ``NIKON D40``, ``SAMSUNG-SM-N900A``); a maker's company name
    (``CASIO COMPUTER CO.,LTD.``, ``EASTMAN KODAK COMPANY``) finds its make. Only an exact
    model matches (after a trailing ``ZOOM DIGITAL CAMERA`` or ``DIGITAL CAMERA`` is
    dropped, or with the maker's series name the table writes before some models and EXIF
    does not: ``DMC-TZ2`` is the table's ``lumixdmctz2``): an unknown model gives no
    reading (logged), and so does one the bundled table gives two widths for (more than
    2 % apart; logged as a warning), or whose widths are for other aspect ratios than the
    photo's (a multi-aspect sensor's rows, ``4:3``, ``3:2``, ``16:9``, are the only ones
    used for it). A near-square photo (narrower than 4:3) gets no table reading: its
    longer side may be the sensor's height.
``exif-35mm``
    ``FocalLengthIn35mmFilm`` (tag 0xA405). The CIPA/EXIF definition matches the angle of
    view of the diagonal, so ``focal_px = f35 * diagonal_px / 43.27``. The tag is an
    integer number of millimetres and ignores crops (digital zoom: below): relative sigma 4 %.
    Phones write it for the sensor's 4:3 frame also in their 16:9 mode, where the diagonal
    rule reads it 8 % low (stop 40: Galaxy Note 3, S21 Ultra, Mi A1). Where the sensor's
    width is known (either reading above), the tag's own crop factor tells the frame it was
    written for (``43.27 * FocalLength / f35`` is that frame's diagonal in millimetres): a
    photo wider than a 4:3 or 3:2 frame the tag fits (within 4 %) is read on that frame,
    ``f35 * longer_side_px * frame_diagonal / frame_width / 43.27``. Where it is not known,
    a photo 16:10 or wider reads the tag both ways (on its own diagonal and on the 4:3
    frame, or 3:2 where the tag's frame is 15 mm across or more) and takes their equal
    mixture, its sigma covering both (about 6 %), said in ``ExifFocal.notes`` (and the log).
    A photo narrower than 4:3 (a phone's 1:1 mode, 5:4) is cut from the sensor at its full
    height, and phones write the tag for the whole frame: on the square's own diagonal it
    reads 15 % low (a Galaxy S8's square photos; found on stop 41's held-out batch 10 after
    its one run). Where the table gives the sensor's width and the tag's crop factor fits
    its 4:3 or 3:2 frame, the tag is read on that frame, its height the photo's shorter
    side; otherwise both readings make an equal mixture (about 9 % for a square).

How they combine
----------------
The lens and the sensor come first: ``exif-focal-plane``, then ``exif-sensor-table``, then
``exif-35mm`` (a figure the maker's firmware derives from the lens and a crop factor it
assumes; stop 40 found it 8-19 % off on an iPhone 4 and 4S and a OnePlus 5T). The first
reading is the prior; the others check it. Where one of them lies more than twice the
combined sigma from it (``|log(f_a / f_b)| > 2 sqrt(s_a^2 + s_b^2)``), the tags contradict
each other and the photo does not say which is right: the prior is the equal mixture of the
first reading and the farthest one (their geometric mean, sigma
``sqrt((s_a^2 + s_b^2) / 2 + (log(f_a / f_b) / 2)^2)``, so that it covers both), named
``exif-conflict``, with a warning naming both (logged, and in ``ExifFocal.warnings``, which
``detect_vanishing_points(use_exif=True)`` puts first in the result's ``warnings``).
Readings that agree leave the first reading and its sigma as they are (they are not
independent: both rest on the same ``FocalLength``).

A focal length outside ``PLAUSIBLE_FOCAL_REL`` times the longer image side (the range the
vanishing-point fit searches, :data:`camloc_geo._limits.FOCAL_BOUNDS_REL`) is a broken tag
(``FocalLength`` 5000 mm on a phone, ``FocalLengthIn35mmFilm`` 2000): that reading is
ignored with a warning, since as a prior it would pin the fit to the bound of that range.

The sigmas are for the prior; the vanishing points may still pull the focal length away
from it where they fix it well (see :func:`camloc_geo.autovp.detect_vanishing_points`).
A tag can be wrong (a OnePlus 5T's 35 mm tag reads 12 % low): ``detect_vanishing_points``
checks an EXIF focal length against the photo's own lines (``check_focal_prior``) and, where
they disagree beyond their combined sigma, states both readings and warns.

Digital zoom
------------
A ``DigitalZoomRatio`` above 1 (up to :data:`DIGITAL_ZOOM_MAX`; 0, 0/0 and 1 are no zoom)
means the stored photo spans ``1 / ratio`` of the lens's frame: the lens readings
(``exif-focal-plane``, ``exif-sensor-table``) are multiplied by it. Makers differ on the
35 mm tag: an iPhone's includes the zoom (an iPhone SE at 1.951x writes 55 mm for its 28 mm;
Hugin bug 2064625), other phones' leave it out. Where a lens reading is there, the tag is
read the way (with the zoom, or times it) that lies nearer to it, said in the notes; where
none is, both ways make an equal mixture whose sigma covers both.

A phone's other cameras
-----------------------
A phone's telephoto, ultra-wide and front cameras write the phone's ``Make`` and ``Model``
with their own ``FocalLength``; a table has the main back camera's sensor only. Where
``LensModel`` names a phone's back, rear or front camera (\"iPhone 11 Pro back triple
camera 6mm f/2\"; a lens's name, \"EF-S18-55mm f/3.5-5.6 IS\", is not read) and says
it is another one (front, selfie, TrueDepth, tele..., ultra wide, macro, periscope), or one
of several (dual, triple or quad, or a ``LensSpecification`` range, or none to tell) whose
``FocalLength`` on the table's sensor would be a 35 mm equivalent outside
:data:`MAIN_CAMERA_EQ_MM` (the iPhone 11 Pro's 6 mm telephoto: 36 mm on the main camera's
5.76 mm sensor), the table's reading is not used, with a warning that says why; the 35 mm
tag, which the phone writes for that camera, is the prior, and without one there is none.
A conflict between the table and the 35 mm tag on a phone of several cameras is still an
``exif-conflict``; its warning names the ``LensModel`` as a likely cause.

Limits: a phone's other camera that writes no ``LensModel`` (most Android phones) still
gets the main camera's table reading, an ``exif-conflict`` with its 35 mm tag where it has
one. A table's widths are nominal optical formats (6.08 mm for two Panasonic compacts
whose tags imply 5.6-5.7 mm: 7 %, within the 2 sigmas that make a conflict). A 16:9 photo of
a natively 16:9 sensor the table lacks (a Galaxy S5) gets the mixture, 4 % off its own
diagonal's right reading. A photo of a natively square (or 5:4) frame whose sensor the
table lacks gets the near-square mixture below, 8 % off its own diagonal's right reading.
"""

from __future__ import annotations

import csv
import functools
import logging
import math
import os
import re
import struct
import warnings
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any

from camloc_geo._limits import FOCAL_BOUNDS_REL

__all__ = ["ExifFocal", "focal_from_exif", "focal_from_tags", "sensor_width_mm"]

log = logging.getLogger(__name__)

#: Diagonal of a 36 x 24 mm frame, millimetres.
FULL_FRAME_DIAGONAL_MM = math.hypot(36.0, 24.0)
_TAG_FOCAL_LENGTH = 0x920A
_TAG_FOCAL_35MM = 0xA405
_TAG_FP_XRES = 0xA20E
_TAG_FP_UNIT = 0xA210
_TAG_PIXEL_X = 0xA002
_TAG_PIXEL_Y = 0xA003
_TAG_MAKE = 0x010F
_TAG_MODEL = 0x0110
_TAG_EXIF_IFD = 0x8769
_TAG_LENS_SPEC = 0xA432
_TAG_DIGITAL_ZOOM = 0xA404
_TAG_LENS_MODEL = 0xA434
_FP_UNIT_MM = {2: 25.4, 3: 10.0, 4: 1.0, 5: 1e-3}  # EXIF FocalPlaneResolutionUnit -> mm
SIGMA_35MM = 0.04
SIGMA_FOCAL_PLANE = 0.05
SIGMA_SENSOR_TABLE = 0.05
#: Plausible focal lengths, as multiples of the longer image side: the range autovp searches.
PLAUSIBLE_FOCAL_REL = FOCAL_BOUNDS_REL
F35_PLAUSIBLE_MM = (8.0, 2000.0)
"""A ``FocalLengthIn35mmFilm`` outside this is ignored (with a warning when nothing else gives
the focal length): a fisheye's 8 mm to a 2000 mm telephoto."""
SENSOR_WIDTH_PLAUSIBLE_MM = (1.0, 60.0)
"""A sensor width outside this (a tiny phone sensor to medium format) is not used."""
#: The bundled sensor-width table (package data; see NOTICE.md beside it).
BUNDLED_SENSOR_TABLE = ("data", "sensor_widths", "sensor_widths.csv")
#: Two widths of one camera further apart than this (relative) make its model ambiguous.
TABLE_WIDTH_SPREAD = 0.02
#: A table width given for an aspect ratio holds for photos within this of it (relative).
_ASPECT_TOL = 0.03
#: A photo whose aspect ratio is this far (log) from its EXIF pixel size's was cropped.
_CROP_ASPECT_TOL = 0.02
#: Frames a 35 mm tag may be written for besides the photo's own: diagonal / width.
_FRAME_RATIOS = {"4:3": 1.25, "3:2": math.hypot(3.0, 2.0) / 3.0}
#: How far (relative) the tag's own crop factor may be from a frame it is read on.
_FRAME_TOL = 0.04
#: A photo at least this wide (longer / shorter side) may be a crop of a 4:3 or 3:2 sensor.
_WIDE_ASPECT = 1.6
#: A photo narrower than this (near square) gets no sensor-table reading.
_TABLE_MIN_ASPECT = 1.3
#: A 35 mm tag whose frame is at least this wide (diagonal, mm) reads a wide photo on 3:2.
_LARGE_SENSOR_DIAGONAL_MM = 15.0
DIGITAL_ZOOM_MAX = 20.0
"""A ``DigitalZoomRatio`` above this is taken for a broken tag (not applied)."""
FOCAL_PLANE_SHRUNK = 1.3
"""A focal-plane sensor width this many times smaller than the table's (or the 35 mm tag's)
is a resized photo's: its resolution is for the frame before the resize (not used)."""
MAIN_CAMERA_EQ_MM = (20.0, 32.0)
"""35 mm equivalents (mm) of a phone's main back camera: 23-28 mm on the phones with several
back cameras (2016 on). A ``FocalLength`` that would be outside this on the table's sensor is
another camera's (an ultra-wide's 13-16 mm, a telephoto's 36 mm and up on the main sensor)."""
_FRONT_WORDS = re.compile(r"\b(front|selfie|truedepth)\b")
_OTHER_WORDS = re.compile(r"\b(tele\w*|ultra[ -]?wide|macro|periscope)\b")
_PHONE_CAMERA = re.compile(r"\b(back|rear|front)\b.*\bcamera\b")
_MULTI_WORDS = re.compile(r"\b(dual|duo|triple|quad)\b")
#: Makes whose EXIF name does not begin with, or contain, the table's name.
_MAKE_ALIASES = {
    "fujiphotofilm": "fujifilm",
    "hewlettpackard": "hp",
    "omdigitalsolutions": "omsystem",
    "asahioptical": "pentax",
    "generalimaging": "ge",
}
#: What some makers append to the model in EXIF and the table leaves out (squashed).
_MODEL_SUFFIXES = ("zoomdigitalcamera", "digitalcamera")
#: Series names the table puts before a model where the camera's EXIF ``Model`` may not
#: (``DMC-TZ2`` is the table's ``lumixdmctz2``, ``EX-Z850`` its ``exilimexz850``).
_MODEL_SERIES = {
    "panasonic": ("lumix",),
    "casio": ("exilim",),
    "sony": ("alpha", "cybershot"),
    "kodak": ("easyshare",),
    "pentax": ("optio",),
    "fujifilm": ("finepix",),
    "nikon": ("coolpix",),
    "canon": ("powershot",),
    "ricoh": ("caplio",),
    "samsung": ("digimax",),
}


@dataclass(frozen=True)
class ExifFocal:
    """A focal length read from EXIF.

    Attributes
    ----------
    focal_px
        Focal length in pixels of the image as stored (after any resize).
    sigma_rel
        Relative standard deviation to give the prior.
    source
        ``"exif-focal-plane"``, ``"exif-sensor-table"``, ``"exif-35mm"``, or
        ``"exif-conflict"`` where two readings disagree (see the module's docstring).
    readings
        Every reading the tags gave, ``(source, focal_px, sigma_rel)``, the one used first.
    warnings
        Readings that contradict each other (``exif-conflict``), in words: what a user should
        act on (give the focal length if it is known).
    notes
        How the tags were read where it is not the plain rule (a 16:9 photo's tag read on
        its sensor's 4:3 frame, or both ways; a table reading left out), in words.
    """

    focal_px: float
    sigma_rel: float
    source: str
    readings: tuple[tuple[str, float, float], ...] = ()
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()


def _num(v: Any) -> float | None:
    try:
        x = float(v)
    except (TypeError, ValueError, ZeroDivisionError):
        return None
    return x if math.isfinite(x) and x > 0 else None


def _text(v: Any) -> str:
    if isinstance(v, bytes):
        v = v.decode("latin-1", errors="replace")
    return str(v).replace("\x00", " ").strip() if v is not None else ""


def _squash(s: str) -> str:
    """Lower case without white space or hyphens (COLMAP's key for make and model)."""
    return "".join(s.lower().split()).replace("-", "")


def _aspect_ratio(text: str) -> float | None:
    a, sep, b = text.partition(":")
    num, den = _num(a), _num(b)
    return num / den if sep and num and den else None


@functools.lru_cache(maxsize=1)
def _bundled_widths() -> dict[str, dict[str, list[tuple[float, float | None]]]]:
    """The bundled table: make -> model -> ``[(width_mm, aspect or None), ...]``."""
    table: dict[str, dict[str, list[tuple[float, float | None]]]] = {}
    try:
        ref = resources.files("camloc_geo")
        for part in BUNDLED_SENSOR_TABLE:  # one part a call: Python 3.10's Traversable
            ref = ref / part
        text = ref.read_text("utf-8")
    except OSError as exc:  # pragma: no cover - package data missing from an install
        log.warning("bundled sensor-width table not read: %s", exc)
        return table
    lines = [ln for ln in text.splitlines() if ln and not ln.startswith("#")]
    for row in csv.DictReader(lines):
        width = _num(row.get("width_mm"))
        if width is None or not row.get("make") or not row.get("model"):
            continue
        aspect = _aspect_ratio(row.get("aspect") or "")
        table.setdefault(row["make"], {}).setdefault(row["model"], []).append((width, aspect))
    return table


def _table_makes(make: str, makes: Any) -> set[str]:
    """The table's makes an EXIF ``Make`` names (``NIKON CORPORATION`` -> ``nikon``)."""
    sq = _squash(make)
    if not sq:
        return set()
    found = {m for m in makes if sq.startswith(m) or (len(m) >= 4 and m in sq)}
    found |= {m for alias, m in _MAKE_ALIASES.items() if alias in sq and m in makes}
    return found


def _model_keys(make: str, model: str, prefixes: set[str]) -> set[str]:
    """``model`` squashed, and again with each maker's name it begins with removed."""
    words = make.lower().replace(",", " ").split()
    prefixes = {p for p in prefixes | set(words[:1]) if p}
    keys = {_squash(model)}
    todo = list(keys)
    while todo:  # "Canon Canon EOS 5D" -> "canoncanoneos5d" -> "canoneos5d" -> "eos5d"
        k = todo.pop()
        for p in prefixes:
            if k.startswith(p) and len(k) > len(p) and k[len(p) :] not in keys:
                keys.add(k[len(p) :])
                todo.append(k[len(p) :])
    for k in list(keys):  # "KODAK CX6330 ZOOM DIGITAL CAMERA" -> "cx6330"
        for suffix in _MODEL_SUFFIXES:
            if k.endswith(suffix) and len(k) > len(suffix):
                keys.add(k[: -len(suffix)])
                break
    return {k for k in keys if k}


def _user_table_width(make: str, model: str, db_path: str | os.PathLike[str]) -> float | None:
    """Sensor width from a user's table (``Make Model;width_mm`` or ``Make,Model,width_mm``)."""
    try:
        text = Path(db_path).read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        log.warning("CAMLOC_SENSOR_DB %s: cannot read (%s)", db_path, exc)
        return None
    make_l, model_l = make.strip().lower(), model.strip().lower()
    exact = {model_l, f"{make_l} {model_l}"}
    keys = _model_keys(make, model, {_squash(make)}) | {_squash(make) + _squash(model)}
    for line in text.splitlines():
        name, sep, width = line.rpartition(";")
        names = [name]
        if not sep:  # openMVG's CSV: Make,Model,width_mm (its model may repeat the make)
            parts = line.split(",")
            if len(parts) < 3 or _num(parts[-1]) is None:
                continue
            names, width = [" ".join(parts[:-1]), ",".join(parts[1:-1])], parts[-1]
        for n in names:
            n_l = n.strip().lower()
            if n_l in exact or _squash(n_l) in keys:
                return _num(width)
    return None


def sensor_width_mm(
    make: str,
    model: str,
    size_px: tuple[int, int] | None = None,
    sensor_db: str | None = None,
    *,
    bundled: bool = True,
) -> tuple[float, str] | None:
    """The sensor width of a camera, from ``CAMLOC_SENSOR_DB`` or the bundled table.

    Parameters
    ----------
    make, model
        The EXIF ``Make`` and ``Model`` as written (any case, spacing, repeated maker).
    size_px
        The photo's ``(width, height)``: picks the width a table gives per aspect ratio
        (a camera whose photos of each aspect span a different part of its sensor).
    sensor_db
        Path of a user table; default ``CAMLOC_SENSOR_DB`` (an empty string: none).
    bundled
        Also look in the bundled table (COLMAP's) where the user's has no line. Where it
        gives the camera a width per aspect ratio, only the photo's aspect counts (no
        width without ``size_px``, or for an aspect it does not list).

    Returns
    -------
    tuple or None
        ``(width_mm, origin)``, origin ``"CAMLOC_SENSOR_DB"`` or ``"bundled table"``; None
        for an unknown or ambiguous camera (logged).
    """
    make, model = _text(make), _text(model)
    if not model:
        return None
    db = sensor_db if sensor_db is not None else os.environ.get("CAMLOC_SENSOR_DB")
    if db:
        w = _user_table_width(make, model, db)
        if w is not None:
            return w, "CAMLOC_SENSOR_DB"
    if not bundled:
        return None
    table = _bundled_widths()
    makes = _table_makes(make, table)
    keys = _model_keys(make, model, makes)
    hits = [
        hit
        for m in makes
        for k in keys | {series + k for series in _MODEL_SERIES.get(m, ()) for k in keys}
        for hit in table[m].get(k, [])
    ]
    if any(a is not None for _, a in hits):
        # a width per aspect ratio (a multi-aspect sensor): the photo's, and only that
        aspect = math.nan
        if size_px is not None:
            aspect = max(size_px) / max(min(size_px), 1)
        hits = [
            (w, a) for w, a in hits if a is not None and abs(math.log(aspect / a)) < _ASPECT_TOL
        ]
    widths = sorted({w for w, _ in hits})
    if not widths:
        log.info(
            "sensor width of %r %r not in the sensor table%s: no sensor-table reading",
            make,
            model,
            "" if makes else " (make unknown)",
        )
        return None
    if widths[-1] / widths[0] - 1.0 > TABLE_WIDTH_SPREAD:
        log.warning(
            "sensor width of %r %r is ambiguous in the sensor table (%s mm): not used",
            make,
            model,
            ", ".join(f"{w:g}" for w in widths),
        )
        return None
    return sum(widths) / len(widths), "bundled table"


@dataclass(frozen=True)
class _Reading:
    source: str
    focal_px: float
    sigma_rel: float
    what: str  # in words, for a warning


def focal_from_tags(
    tags: dict[int, Any],
    width_px: int,
    height_px: int,
    sensor_db: str | None = None,
    *,
    name: str = "photo",
    bundled_table: bool = True,
) -> ExifFocal | None:
    """Focal length in pixels from EXIF tags (tag number -> value).

    Parameters
    ----------
    tags
        EXIF tags of the main IFD and the EXIF sub-IFD, merged.
    width_px, height_px
        Size of the image as stored (the orientation does not matter: the diagonal and
        the longer side are used).
    sensor_db
        Path of a sensor-width table; default: ``CAMLOC_SENSOR_DB``. It takes precedence
        over the bundled table.
    name
        The photo, for the warnings.
    bundled_table
        Use the bundled sensor-width table where ``sensor_db`` has no line for the camera.

    Returns
    -------
    ExifFocal or None
        None when the tags do not give the focal length, or give one outside
        ``PLAUSIBLE_FOCAL_REL`` times the longer side (then with a warning).
    """
    frame = _capture_frame(tags, width_px, height_px)
    if frame is None:
        readings, said = _readings(tags, width_px, height_px, sensor_db, bundled_table)
    else:
        # cropped after capture: read on the frame the EXIF describes, then scaled by the
        # crop's unknown resize, between the least that fits the crop in it and none
        cap_w, cap_h, s_lo, s_hi = frame
        readings, said = _readings(tags, cap_w, cap_h, sensor_db, bundled_table)
        mid, spread = math.sqrt(s_lo * s_hi), 0.5 * math.log(s_hi / s_lo)
        readings = [
            replace(
                r,
                focal_px=r.focal_px * mid,
                sigma_rel=math.hypot(r.sigma_rel, spread),
                what=f"{r.what} (on the {cap_w}x{cap_h} frame, scaled)",
            )
            for r in readings
        ]
        said.notes.append(
            f"the {width_px}x{height_px} photo is not the shape of the {cap_w}x{cap_h} frame "
            "its EXIF describes (PixelXDimension, PixelYDimension): cropped after capture. "
            f"Read on that frame and scaled by {s_lo:.3g}-{s_hi:.3g} (the crop's resize is "
            f"not known): +/- {100 * spread:.0f} % more"
        )
    lo, hi = PLAUSIBLE_FOCAL_REL
    longer = max(width_px, height_px, 1)
    kept = []
    for r in readings:
        rel = r.focal_px / longer
        if lo <= rel <= hi:
            kept.append(r)
            continue
        log.warning(
            "%s: EXIF focal length ignored: %s gives %.0f px, %.2g times the image's longer "
            "side (plausible: %g to %g)",
            name,
            r.source,
            r.focal_px,
            rel,
            lo,
            hi,
        )
    if not kept:
        for w in said.warnings:
            log.warning("%s: %s", name, w)
        f35 = _num(tags.get(_TAG_FOCAL_35MM))
        if (
            not readings
            and f35 is not None
            and not F35_PLAUSIBLE_MM[0] <= f35 <= F35_PLAUSIBLE_MM[1]
        ):
            # 0 is EXIF's "unknown"; anything else the photo does carry: say why it is not used
            log.warning(
                "%s: EXIF focal length ignored: FocalLengthIn35mmFilm is %g mm (plausible: %g to "
                "%g mm) and no other tag gives the focal length",
                name,
                f35,
                *F35_PLAUSIBLE_MM,
            )
        return None
    return _combine(kept, said, name)


def _capture_frame(
    tags: dict[int, Any], width_px: int, height_px: int
) -> tuple[int, int, float, float] | None:
    """The frame the EXIF describes, where the photo was cropped to another shape, else None.

    Returns ``(width, height, s_lo, s_hi)``: ``PixelXDimension`` and ``PixelYDimension``
    turned to the photo's orientation, and the range of the crop's resize. A crop
    ``w x h`` of a ``W x H`` frame resized by ``s`` fits in it, ``w <= s W`` and
    ``h <= s H``, so ``s >= max(w / W, h / H)``; up to 1 (no enlargement), or that least
    ``s`` where the photo was enlarged. A photo of the frame's shape (within
    :data:`_CROP_ASPECT_TOL`) is a plain resize (or an unseen crop): None.
    """
    cap_w, cap_h = _num(tags.get(_TAG_PIXEL_X)), _num(tags.get(_TAG_PIXEL_Y))
    if not cap_w or not cap_h or width_px < 1 or height_px < 1:
        return None
    if (cap_w >= cap_h) != (width_px >= height_px):
        cap_w, cap_h = cap_h, cap_w  # a turned photo whose tags were not turned
    if abs(math.log((width_px / height_px) / (cap_w / cap_h))) <= _CROP_ASPECT_TOL:
        return None
    s_lo = max(width_px / cap_w, height_px / cap_h)
    return round(cap_w), round(cap_h), s_lo, max(1.0, s_lo)


def _equal_mixture(a: _Reading, b: _Reading) -> tuple[float, float]:
    """The equal mixture of two readings in ``log(focal)``: their geometric mean, and a
    sigma covering both, ``sqrt((s_a^2 + s_b^2) / 2 + (log(f_a / f_b) / 2)^2)``."""
    half_gap = 0.5 * math.log(a.focal_px / b.focal_px)
    sigma = math.sqrt(0.5 * (a.sigma_rel**2 + b.sigma_rel**2) + half_gap**2)
    return math.sqrt(a.focal_px * b.focal_px), sigma


def _combine(readings: list[_Reading], said: _Said, name: str) -> ExifFocal:
    """The first reading, or the equal mixture of it and the farthest that disagrees."""
    first = readings[0]
    table = tuple((r.source, r.focal_px, r.sigma_rel) for r in readings)
    notes = tuple(said.notes)
    for w in said.warnings:
        log.warning("%s: %s", name, w)

    def gap(r: _Reading) -> float:
        return abs(math.log(r.focal_px / first.focal_px))

    far = [r for r in readings[1:] if gap(r) > 2.0 * math.hypot(r.sigma_rel, first.sigma_rel)]
    if not far:
        for note in notes:
            log.info("%s: %s", name, note)
        return ExifFocal(
            first.focal_px, first.sigma_rel, first.source, table, tuple(said.warnings), notes
        )
    other = max(far, key=gap)
    d = math.log(other.focal_px / first.focal_px)
    f_mix, sigma = _equal_mixture(first, other)
    cause = ""
    if said.table_cause and "exif-sensor-table" in (first.source, other.source):
        cause = (
            f" (LensModel {said.table_cause!r} names one of several cameras: the table's "
            "width is the main camera's, and this may be another's)"
        )
    msg = (
        f"the EXIF tags disagree: {first.what} gives {first.focal_px:.0f} px, {other.what} "
        f"{other.focal_px:.0f} px ({100 * (math.exp(d) - 1):+.0f} %){cause}; which is right "
        f"the tags do not say: the prior covers both, {f_mix:.0f} px +/- {100 * sigma:.0f} % "
        "(exif-conflict); give --focal-px if it is known"
    )
    log.warning("%s: %s", name, msg)
    for note in notes:
        log.info("%s: %s", name, note)
    return ExifFocal(f_mix, sigma, "exif-conflict", table, (*said.warnings, msg), notes)


def _readings(
    tags: dict[int, Any],
    width_px: int,
    height_px: int,
    sensor_db: str | None,
    bundled: bool,
) -> tuple[list[_Reading], _Said]:
    """Every reading the tags give, the lens and the sensor first, and what was said."""
    longer = float(max(width_px, height_px))
    shorter = float(max(min(width_px, height_px), 1))
    aspect = longer / shorter
    own_ratio = math.hypot(width_px, height_px) / max(longer, 1.0)  # diagonal / longer side
    out: list[_Reading] = []
    said = _Said()
    notes = said.notes
    width_mm: float | None = None  # the sensor width the photo's longer side spans
    fp_width_mm: float | None = None  # the sensor width of the focal-plane resolution
    table_width_mm: float | None = None  # the sensor width of the table's reading
    square_sensor_mm: float | None = None  # a near-square photo's camera's sensor width
    f_mm = _num(tags.get(_TAG_FOCAL_LENGTH))
    lo_w, hi_w = SENSOR_WIDTH_PLAUSIBLE_MM
    zoom = _digital_zoom(tags)  # the stored photo spans 1 / zoom of the lens's frame
    zoom_words = f" times the {zoom:g}x digital zoom" if zoom != 1.0 else ""
    if f_mm is not None:
        xres = _num(tags.get(_TAG_FP_XRES))
        unit_mm = _FP_UNIT_MM.get(int(_num(tags.get(_TAG_FP_UNIT)) or 2))
        if xres is not None and unit_mm is not None:
            px_per_mm = xres / unit_mm
            orig_w = _num(tags.get(_TAG_PIXEL_X))
            orig_h = _num(tags.get(_TAG_PIXEL_Y))
            scale = 1.0
            if orig_w and orig_h:
                # the resolution refers to the stored size at capture; undo a resize
                scale = longer / max(orig_w, orig_h)
            sensor_w = max(orig_w or width_px, orig_h or height_px) / px_per_mm
            if lo_w <= sensor_w <= hi_w:
                width_mm = fp_width_mm = sensor_w
                out.append(
                    _Reading(
                        "exif-focal-plane",
                        f_mm * px_per_mm * scale * zoom,
                        SIGMA_FOCAL_PLANE,
                        f"FocalLength {f_mm:g} mm on the focal-plane resolution's "
                        f"{sensor_w:.2f} mm sensor{zoom_words}",
                    )
                )
        make, model = _text(tags.get(_TAG_MAKE)), _text(tags.get(_TAG_MODEL))
        if model:
            got = sensor_width_mm(make, model, (width_px, height_px), sensor_db, bundled=bundled)
            if got is not None and lo_w <= got[0] <= hi_w:
                sw, origin = got
                other = _other_camera(tags, f_mm, sw)
                if other is not None:
                    said.warnings.append(other)
                elif aspect < _TABLE_MIN_ASPECT:
                    square_sensor_mm = sw
                    notes.append(
                        f"no sensor-table reading: a {width_px}x{height_px} photo is narrower "
                        "than 4:3, so its longer side need not span the sensor's width"
                    )
                else:
                    width_mm = width_mm or sw
                    table_width_mm = sw
                    said.table_cause = _several_cameras(tags)
                    out.append(
                        _Reading(
                            "exif-sensor-table",
                            f_mm / sw * longer * zoom,
                            SIGMA_SENSOR_TABLE,
                            f"FocalLength {f_mm:g} mm on the {sw:g} mm sensor of "
                            f"{make} {model} ({origin}){zoom_words}",
                        )
                    )
    f35 = _num(tags.get(_TAG_FOCAL_35MM))
    if f35 is not None and not F35_PLAUSIBLE_MM[0] <= f35 <= F35_PLAUSIBLE_MM[1]:
        f35 = None
    if fp_width_mm is not None and f_mm is not None:
        # the sensor the focal-plane resolution gives, against the table's or the tag's
        ref_mm, ref_what = table_width_mm, "the sensor table's width"
        if ref_mm is None and f35 is not None and zoom == 1.0 and aspect >= _TABLE_MIN_ASPECT:
            # (a near-square photo's longer side may be the sensor's height: not compared)
            ref_mm = FULL_FRAME_DIAGONAL_MM * f_mm / f35 / own_ratio
            ref_what = f"the {f35:g} mm 35 mm tag's crop factor: a width of"
        if ref_mm is not None and fp_width_mm * FOCAL_PLANE_SHRUNK < ref_mm:
            out = [r for r in out if r.source != "exif-focal-plane"]
            width_mm = table_width_mm
            said.warnings.append(
                f"FocalPlaneXResolution gives a {fp_width_mm:.2f} mm wide sensor for the "
                f"{_pixel_size(tags, width_px, height_px)} frame, {ref_what} {ref_mm:.2f} mm: "
                "the resolution is for a larger frame than the EXIF's pixel size (a photo "
                "resized after capture, its PixelXDimension rewritten or gone): not used"
            )
    if f35 is None:
        return out, said

    def tag(f35_optical: float, notes: list[str]) -> list[_Reading]:
        """The tag read as the lens's own 35 mm equivalent, times the digital zoom."""
        if aspect < _TABLE_MIN_ASPECT:
            got = _reading_35mm_square(
                f35_optical, f_mm, square_sensor_mm, longer, shorter, own_ratio, notes
            )
        else:
            got = _reading_35mm(f35_optical, f_mm, width_mm, longer, aspect, own_ratio, notes)
        return [replace(r, focal_px=r.focal_px * zoom, what=r.what + zoom_words) for r in got]

    if zoom == 1.0:
        out.extend(tag(f35, notes))
        return out, said
    # Makers differ: an iPhone's tag includes the digital zoom, other phones' do not (Hugin
    # bug 2064625). The lens reading, where there is one, tells which; else both, mixed.
    notes_with: list[str] = []
    notes_without: list[str] = []
    with_zoom = tag(f35 / zoom, notes_with)
    without = tag(f35, notes_without)
    if out:
        ref = out[0].focal_px

        def miss(rs: list[_Reading]) -> float:
            return abs(math.log(rs[0].focal_px / ref))

        included = miss(with_zoom) <= miss(without)
        notes.extend(notes_with if included else notes_without)
        notes.append(
            f"the {f35:g} mm 35 mm tag {'includes' if included else 'leaves out'} the "
            f"{zoom:g}x digital zoom (so the lens reading says): read so"
        )
        out.extend(with_zoom if included else without)
        return out, said
    a, b = without[0], with_zoom[0]
    f_mix, sigma = _equal_mixture(a, b)
    notes.extend(notes_with)
    notes.append(
        f"the {f35:g} mm 35 mm tag may include the {zoom:g}x digital zoom (as an iPhone's "
        f"does: {b.focal_px:.0f} px) or leave it out ({a.focal_px:.0f} px); no lens reading "
        f"tells which: the prior covers both, {f_mix:.0f} px +/- {100 * sigma:.0f} %"
    )
    what = f"FocalLengthIn35mmFilm {f35:g} mm with or without the {zoom:g}x digital zoom"
    out.append(_Reading("exif-35mm", f_mix, sigma, what))
    return out, said


def _pixel_size(tags: dict[int, Any], width_px: int, height_px: int) -> str:
    """``PixelXDimension`` x ``PixelYDimension``, or the stored size where they are not."""
    w, h = _num(tags.get(_TAG_PIXEL_X)), _num(tags.get(_TAG_PIXEL_Y))
    if w and h:
        return f"{w:.0f}x{h:.0f} (PixelXDimension)"
    return f"stored {width_px}x{height_px}"


def _digital_zoom(tags: dict[int, Any]) -> float:
    """``DigitalZoomRatio`` where it zooms (above 1, up to :data:`DIGITAL_ZOOM_MAX`), else 1.

    0 (EXIF's "not used"), 0/0, 1 and anything implausible read as no zoom."""
    r = _num(tags.get(_TAG_DIGITAL_ZOOM))
    if r is None or r <= 1.0 + 1e-3 or r > DIGITAL_ZOOM_MAX:
        return 1.0
    return r


@dataclass
class _Said:
    """What the readings say besides their values: notes, warnings, a conflict's cause."""

    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    table_cause: str = ""  # why a table reading may be wrong (named if it conflicts)


def _lens_model(tags: dict[int, Any]) -> str:
    """``LensModel`` where it names a phone's camera (\"iPhone 11 Pro back triple camera
    6mm f/2\", \"Pixel 7 Pro front camera 2.74mm f/2.2\": a back, rear or front camera),
    else \"\" (a lens's name, \"EF-S18-55mm f/3.5-5.6 IS\", or another camera's words)."""
    lens = _text(tags.get(_TAG_LENS_MODEL))
    return lens if _PHONE_CAMERA.search(lens.lower()) else ""


def _several_cameras(tags: dict[int, Any]) -> str:
    """The ``LensModel`` of a phone camera that may be one of several, else \"\".

    One of several: its ``LensModel`` says a dual, duo, triple or quad camera, or
    ``LensSpecification`` spans more than one focal length (phones write the range of all
    their back cameras), or there is no ``LensSpecification`` to tell (a Pixel)."""
    lens = _lens_model(tags)
    if not lens:
        return ""
    if _MULTI_WORDS.search(lens.lower()):
        return lens
    spec = tags.get(_TAG_LENS_SPEC)
    try:
        f_lo, f_hi = _num(spec[0]), _num(spec[1])  # type: ignore[index]
    except (TypeError, IndexError, KeyError):
        return lens
    if f_lo is None or f_hi is None:
        return lens
    return lens if f_hi > f_lo * 1.02 else ""


def _other_camera(tags: dict[int, Any], f_mm: float, sensor_w_mm: float) -> str | None:
    """Why the table's sensor width, a phone's main back camera's, is not this photo's
    camera's (a warning), or None.

    A phone's other cameras (front, ultra-wide, telephoto) write the phone's ``Make`` and
    ``Model`` with their own ``FocalLength``; the table gives the main camera's sensor.
    ``LensModel`` tells them apart: the words front, selfie, TrueDepth, tele..., ultra
    wide, macro or periscope, or one camera of several (:func:`_several_cameras`) whose
    ``FocalLength`` on the table's sensor (its 4:3 frame) would be a 35 mm equivalent
    outside :data:`MAIN_CAMERA_EQ_MM` (the iPhone 11 Pro's 6 mm telephoto: 36 mm on the
    main camera's 5.76 mm sensor, where its own 52 mm tag is right).
    """
    lens = _lens_model(tags)
    if not lens:
        return None
    low = lens.lower()
    main = f"the table's {sensor_w_mm:g} mm width is the main back camera's: not used"
    word = _FRONT_WORDS.search(low) or _OTHER_WORDS.search(low)
    if word is not None:
        return f"LensModel {lens!r} says the {word.group(0)} camera; {main}"
    if not _several_cameras(tags):
        return None  # the phone's one back camera: the table's
    eq_mm = f_mm * FULL_FRAME_DIAGONAL_MM / (sensor_w_mm * _FRAME_RATIOS["4:3"])
    lo, hi = MAIN_CAMERA_EQ_MM
    if lo <= eq_mm <= hi:
        return None
    kind = "an ultra-wide" if eq_mm < lo else "a telephoto"
    return (
        f"LensModel {lens!r} names one camera of several, and FocalLength {f_mm:g} mm on "
        f"the table's {sensor_w_mm:g} mm sensor would be a {eq_mm:.0f} mm equivalent, "
        f"outside a main camera's {lo:g}-{hi:g} mm: {kind} camera's photo; {main}"
    )


def _reading_35mm(
    f35: float,
    f_mm: float | None,
    width_mm: float | None,
    longer: float,
    aspect: float,
    own_ratio: float,
    notes: list[str],
) -> list[_Reading]:
    """The 35 mm tag read on the frame it was written for (see the module's docstring)."""

    def on(ratio: float) -> float:
        return f35 * longer * ratio / FULL_FRAME_DIAGONAL_MM

    what = f"FocalLengthIn35mmFilm {f35:g} mm"
    frame_mm = FULL_FRAME_DIAGONAL_MM * f_mm / f35 if f_mm is not None else None
    if width_mm is not None and frame_mm is not None:
        k = frame_mm / width_mm  # the tag's frame: diagonal / width
        cands = {"own": own_ratio, **_FRAME_RATIOS}
        best = min(cands, key=lambda c: abs(math.log(k / cands[c])))
        if (
            best != "own"
            and abs(math.log(k / cands[best])) < _FRAME_TOL
            and cands[best] > own_ratio * 1.01
            and abs(math.log(k / own_ratio)) > _FRAME_TOL
        ):
            notes.append(
                f"the {f35:g} mm 35 mm tag is written for the sensor's {best} frame (its crop "
                f"factor and the {width_mm:.2f} mm sensor say so), not for this photo's "
                f"{aspect:.2f}:1 crop: read on that frame"
            )
            return [_Reading("exif-35mm", on(cands[best]), SIGMA_35MM, f"{what} ({best} frame)")]
        return [_Reading("exif-35mm", on(own_ratio), SIGMA_35MM, what)]
    if aspect >= _WIDE_ASPECT:
        large = frame_mm is not None and frame_mm >= _LARGE_SENSOR_DIAGONAL_MM
        name = "3:2" if large else "4:3"
        frame = f"sensor's {name} frame"
        return _two_ways(f35, aspect, on(own_ratio), on(_FRAME_RATIOS[name]), frame, notes)
    return [_Reading("exif-35mm", on(own_ratio), SIGMA_35MM, what)]


def _reading_35mm_square(
    f35: float,
    f_mm: float | None,
    sensor_w_mm: float | None,
    longer: float,
    shorter: float,
    own_ratio: float,
    notes: list[str],
) -> list[_Reading]:
    """The 35 mm tag of a photo narrower than 4:3 (a phone's square mode, 5:4), read on the
    frame it was written for.

    Such a photo is usually cut from a 4:3 (or 3:2) sensor at its full height, and phones
    write the tag for the sensor's whole frame: on the square's own diagonal it reads 15 %
    low (a Galaxy S8's 1:1 photos, stop 41). Where the table gives the sensor's width and the
    tag's crop factor (``43.27 * FocalLength / f35``, its frame's diagonal in millimetres)
    fits that sensor's 4:3 or 3:2 frame, the tag is read on that frame, its height the
    photo's shorter side. Where it cannot be told, both readings (the photo's own diagonal,
    and the 4:3 frame at full height, or 3:2 for a frame 15 mm across or more) make an
    equal mixture whose sigma covers both.
    """
    D = FULL_FRAME_DIAGONAL_MM
    own = f35 * longer * own_ratio / D  # on the photo's own diagonal
    aspect = longer / shorter
    full_height = {"4:3": 5.0 / 3.0, "3:2": math.hypot(3.0, 2.0) / 2.0}  # diagonal / height
    what = f"FocalLengthIn35mmFilm {f35:g} mm"
    frame_mm = D * f_mm / f35 if f_mm is not None else None
    if frame_mm is not None and sensor_w_mm is not None:
        k = frame_mm / sensor_w_mm  # the tag's frame on this sensor: diagonal / width
        best = min(_FRAME_RATIOS, key=lambda c: abs(math.log(k / _FRAME_RATIOS[c])))
        if abs(math.log(k / _FRAME_RATIOS[best])) < _FRAME_TOL:
            notes.append(
                f"the {f35:g} mm 35 mm tag is written for the {sensor_w_mm:g} mm sensor's "
                f"{best} frame (its crop factor says so), not for this photo's "
                f"{aspect:.2f}:1 crop: read on that frame at the photo's height"
            )
            f = f35 * shorter * full_height[best] / D
            return [_Reading("exif-35mm", f, SIGMA_35MM, f"{what} ({best} frame)")]
    large = frame_mm is not None and frame_mm >= _LARGE_SENSOR_DIAGONAL_MM
    name = "3:2" if large else "4:3"
    f_b = f35 * shorter * full_height[name] / D
    frame = f"sensor's {name} frame at the photo's height"
    return _two_ways(f35, aspect, own, f_b, frame, notes)


def _two_ways(
    f35: float, aspect: float, f_own: float, f_frame: float, frame: str, notes: list[str]
) -> list[_Reading]:
    """The 35 mm tag read on the photo's own diagonal and on a sensor frame, where the
    sensor's width cannot tell which it was written for: their equal mixture, its sigma
    covering both, said in ``notes``."""
    f_mix, sigma = _equal_mixture(
        _Reading("exif-35mm", f_own, SIGMA_35MM, ""), _Reading("exif-35mm", f_frame, SIGMA_35MM, "")
    )
    notes.append(
        f"the {f35:g} mm 35 mm tag of a {aspect:.2f}:1 photo may be written for the {frame} "
        f"({f_frame:.0f} px) or for the photo's own ({f_own:.0f} px); the sensor's width is "
        f"not known: the prior covers both, {f_mix:.0f} px +/- {100 * sigma:.0f} %"
    )
    what = f"FocalLengthIn35mmFilm {f35:g} mm (read two ways)"
    return [_Reading("exif-35mm", f_mix, sigma, what)]


def focal_from_exif(
    path: str | os.PathLike[str],
    sensor_db: str | None = None,
    *,
    bundled_table: bool = True,
) -> ExifFocal | None:
    """Focal length in pixels from a photo's EXIF, or None (no EXIF, or not enough of it).

    Never raises on a file Pillow cannot read, and reads only regular files: the EXIF
    is optional. ``sensor_db`` and ``bundled_table`` as in :func:`focal_from_tags`.
    """
    try:
        from PIL import Image, UnidentifiedImageError
    except ImportError:  # pragma: no cover - Pillow is a dependency
        log.debug("Pillow missing: EXIF not read")
        return None
    if not Path(path).is_file():  # a FIFO or a device would block; the reader names it
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # Pillow's bomb and EXIF warnings: the image's
            with Image.open(path) as im:  # reader checks its size and names the problem
                width, height = im.size
                exif = im.getexif()
                tags: dict[int, Any] = dict(exif)
                tags.update(exif.get_ifd(_TAG_EXIF_IFD))
    except (
        OSError,
        UnidentifiedImageError,
        Image.DecompressionBombError,
        ValueError,
        SyntaxError,
        struct.error,
    ) as exc:
        log.debug("no EXIF read from %s: %s", path, exc)
        return None
    return focal_from_tags(
        tags, width, height, sensor_db, name=str(path), bundled_table=bundled_table
    )
