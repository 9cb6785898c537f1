"""Focal length of a photo from its EXIF tags, as a prior for the vanishing-point fit.

Read with Pillow (``PIL.Image.getexif``); nothing here touches the network.

Sources, best first:

``exif-35mm``
    ``FocalLengthIn35mmFilm`` (tag 0xA405). The CIPA/EXIF definition matches the angle of
    view of the diagonal, so ``focal_px = f35 * diagonal_px / 43.27``. The tag is an
    integer number of millimetres and ignores digital zoom and crops: relative sigma 4 %.
``exif-focal-plane``
    ``FocalLength`` (0x920A) with ``FocalPlaneXResolution`` (0xA20E) and its unit
    (0xA210), scaled by ``width / PixelXDimension`` when the photo was resized: sigma 5 %
    (some cameras write the resolution of a sensor crop).
``exif-sensor-table``
    ``FocalLength`` with the sensor width of ``Make`` + ``Model`` in a sensor-width table:
    the file named by ``CAMLOC_SENSOR_DB`` in the format of openMVG's maintained
    ``sensor_width_camera_database.txt`` (``Make Model;width_mm`` a line; e.g.
    https://github.com/openMVG/CameraSensorSizeDatabase). No table is bundled. Sigma 5 %.

A focal length outside ``PLAUSIBLE_FOCAL_REL`` times the longer image side (the range the
vanishing-point fit searches, :data:`camloc_geo._limits.FOCAL_BOUNDS_REL`) is a broken tag
(``FocalLength`` 5000 mm on a phone, ``FocalLengthIn35mmFilm`` 2000): it is ignored with a
warning, since as a prior it would pin the fit to the bound of that range.

The sigmas are for the prior; the vanishing points may still pull the focal length away
from it where they fix it well (see :func:`camloc_geo.autovp.detect_vanishing_points`).
A tag can be wrong (a OnePlus 5T's 35 mm tag reads 12 % low): ``detect_vanishing_points``
checks an EXIF focal length against the photo's own lines (``check_focal_prior``) and, where
they disagree beyond their combined sigma, states both readings and warns.
"""

from __future__ import annotations

import logging
import math
import os
import struct
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from camloc_geo._limits import FOCAL_BOUNDS_REL

__all__ = ["ExifFocal", "focal_from_exif", "focal_from_tags"]

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
_FP_UNIT_MM = {2: 25.4, 3: 10.0, 4: 1.0, 5: 1e-3}  # EXIF FocalPlaneResolutionUnit -> mm
SIGMA_35MM = 0.04
SIGMA_FOCAL_PLANE = 0.05
SIGMA_SENSOR_TABLE = 0.05
#: Plausible focal lengths, as multiples of the longer image side: the range autovp searches.
PLAUSIBLE_FOCAL_REL = FOCAL_BOUNDS_REL
F35_PLAUSIBLE_MM = (8.0, 2000.0)
"""A ``FocalLengthIn35mmFilm`` outside this is ignored (with a warning when nothing else gives
the focal length): a fisheye's 8 mm to a 2000 mm telephoto."""


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
        ``"exif-35mm"``, ``"exif-focal-plane"`` or ``"exif-sensor-table"``.
    """

    focal_px: float
    sigma_rel: float
    source: str


def _num(v: Any) -> float | None:
    try:
        x = float(v)
    except (TypeError, ValueError, ZeroDivisionError):
        return None
    return x if math.isfinite(x) and x > 0 else None


def _sensor_width_mm(make: str, model: str, db_path: str | os.PathLike[str]) -> float | None:
    """Sensor width from an openMVG-format table (``Make Model;width_mm``)."""
    try:
        text = Path(db_path).read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        log.warning("CAMLOC_SENSOR_DB %s: cannot read (%s)", db_path, exc)
        return None
    make_l, model_l = make.strip().lower(), model.strip().lower()
    keys = {model_l, f"{make_l} {model_l}"}
    if model_l.startswith(make_l):
        keys.add(model_l)
    for line in text.splitlines():
        name, sep, width = line.rpartition(";")
        if sep and name.strip().lower() in keys:
            return _num(width)
    return None


def focal_from_tags(
    tags: dict[int, Any],
    width_px: int,
    height_px: int,
    sensor_db: str | None = None,
    *,
    name: str = "photo",
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
        Path of a sensor-width table; default: ``CAMLOC_SENSOR_DB``.
    name
        The photo, for the warning about an implausible focal length.

    Returns
    -------
    ExifFocal or None
        None when the tags do not give the focal length, or give one outside
        ``PLAUSIBLE_FOCAL_REL`` times the longer side (then with a warning).
    """
    found = _focal_from_tags(tags, width_px, height_px, sensor_db)
    if found is None:
        f35 = _num(tags.get(_TAG_FOCAL_35MM))
        if f35 is not None and f35 > 0.0 and not F35_PLAUSIBLE_MM[0] <= f35 <= F35_PLAUSIBLE_MM[1]:
            # 0 is EXIF's "unknown"; anything else the photo does carry: say why it is not used
            log.warning(
                "%s: EXIF focal length ignored: FocalLengthIn35mmFilm is %g mm (plausible: %g to "
                "%g mm) and no other tag gives the focal length",
                name,
                f35,
                *F35_PLAUSIBLE_MM,
            )
        return None
    lo, hi = PLAUSIBLE_FOCAL_REL
    rel = found.focal_px / max(width_px, height_px, 1)
    if not lo <= rel <= hi:
        log.warning(
            "%s: EXIF focal length ignored: %s gives %.0f px, %.2g times the image's longer side "
            "(plausible: %g to %g)",
            name,
            found.source,
            found.focal_px,
            rel,
            lo,
            hi,
        )
        return None
    return found


def _focal_from_tags(
    tags: dict[int, Any], width_px: int, height_px: int, sensor_db: str | None
) -> ExifFocal | None:
    diag_px = math.hypot(width_px, height_px)
    f35 = _num(tags.get(_TAG_FOCAL_35MM))
    if f35 is not None and F35_PLAUSIBLE_MM[0] <= f35 <= F35_PLAUSIBLE_MM[1]:
        return ExifFocal(f35 * diag_px / FULL_FRAME_DIAGONAL_MM, SIGMA_35MM, "exif-35mm")
    f_mm = _num(tags.get(_TAG_FOCAL_LENGTH))
    if f_mm is None:
        return None
    xres = _num(tags.get(_TAG_FP_XRES))
    unit_mm = _FP_UNIT_MM.get(int(_num(tags.get(_TAG_FP_UNIT)) or 2))
    if xres is not None and unit_mm is not None:
        px_per_mm = xres / unit_mm
        orig_w = _num(tags.get(_TAG_PIXEL_X))
        orig_h = _num(tags.get(_TAG_PIXEL_Y))
        scale = 1.0
        if orig_w and orig_h:
            # the resolution refers to the stored size at capture; undo a resize
            scale = max(width_px, height_px) / max(orig_w, orig_h)
        sensor_w = max(orig_w or width_px, orig_h or height_px) / px_per_mm
        if 1.0 <= sensor_w <= 60.0:  # a plausible sensor: tiny phone to medium format
            return ExifFocal(f_mm * px_per_mm * scale, SIGMA_FOCAL_PLANE, "exif-focal-plane")
    db = sensor_db if sensor_db is not None else os.environ.get("CAMLOC_SENSOR_DB")
    make, model = tags.get(_TAG_MAKE), tags.get(_TAG_MODEL)
    if db and make and model:
        sw = _sensor_width_mm(str(make), str(model), db)
        if sw:
            return ExifFocal(
                f_mm / sw * max(width_px, height_px), SIGMA_SENSOR_TABLE, "exif-sensor-table"
            )
    return None


def focal_from_exif(path: str | os.PathLike[str], sensor_db: str | None = None) -> ExifFocal | None:
    """Focal length in pixels from a photo's EXIF, or None (no EXIF, or not enough of it).

    Never raises on a file Pillow cannot read, and reads only regular files: the EXIF
    is optional.
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
    return focal_from_tags(tags, width, height, sensor_db, name=str(path))
