"""Reading inputs and writing outputs safely (one rule for the library and every front end).

- Writes are atomic: the data go to a temporary file in the target's directory, which then
  replaces the target (:func:`os.replace`); a failure halfway leaves the old file (or none),
  never a truncated one.
- :func:`check_output_path` refuses a missing directory, a directory as a file, a directory
  nothing can be written in (read-only, no permission, ``/proc``) and an output that is one of
  the inputs, each with an :class:`~camloc_geo.InputError` of one line, before any work.
- :func:`read_json_file` reads JSON with the same error style for every command.
- :func:`read_image_gray` decodes a photo (OpenCV, EXIF orientation applied) after the size
  checks of :func:`camloc_geo._limits.check_image_file`; every failure names the file and what
  is wrong with it (empty, truncated or corrupt, not an image, too large, too small).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import tempfile
import threading
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from camloc_geo._errors import InputError

__all__ = [
    "EXIF_TURNED_QUARTER",
    "MAX_IMAGE_BYTES_PER_PIXEL",
    "MAX_IMAGE_EXTRA_BYTES",
    "MAX_JSON_BYTES",
    "MIN_IMAGE_SIDE_PX",
    "atomic_path",
    "check_input_file",
    "check_output_path",
    "displayed_size",
    "image_data_complete",
    "is_lat_lon",
    "read_image_gray",
    "read_json_file",
    "write_text_atomic",
]

PathLike = str | os.PathLike[str]


def is_lat_lon(lat: Any, lon: Any) -> bool:
    """Both finite numbers (not booleans) within ±90 and ±180 degrees: a place on the map."""
    return (
        isinstance(lat, (int, float))
        and isinstance(lon, (int, float))
        and not isinstance(lat, bool)
        and not isinstance(lon, bool)
        and math.isfinite(lat)
        and math.isfinite(lon)
        and -90.0 <= lat <= 90.0
        and -180.0 <= lon <= 180.0
    )


MAX_JSON_BYTES = 200_000_000
"""Largest JSON, GeoJSON or verdicts file the command line reads whole (bytes): a candidate
file of one scene is kilobytes, a verdict export of 10 000 cameras about 2 MB."""

MIN_IMAGE_SIDE_PX = 8
"""Smallest image side (pixels) worth looking for lines in."""
MAX_IMAGE_BYTES_PER_PIXEL = 8
"""Most bytes a pixel takes in an image file (16-bit RGBA, uncompressed)."""
MAX_IMAGE_EXTRA_BYTES = 64_000_000
"""Room for the rest of an image file (EXIF, thumbnails, ICC profile): a larger file is padded."""


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return a.resolve() == b.resolve()


def check_output_path(
    path: PathLike,
    *,
    inputs: Iterable[PathLike | None] = (),
    option: str = "-o",
    directory: bool = False,
) -> Path:
    """Validate an output path before any work is done.

    Parameters
    ----------
    path
        The file (or, with ``directory``, the folder) to write.
    inputs
        Files the command reads; the output may be none of them.
    option
        The option naming the output, for the message (``-o``, ``--map``...).
    directory
        The output is a folder that must exist (``--overlays DIR``).

    Raises
    ------
    InputError
        The directory is missing (it is never created), the path is a directory (or, with
        ``directory``, not one), nothing can be written in the directory, or the output would
        overwrite an input.
    """
    p = Path(path)
    if directory:
        if not p.is_dir():
            what = "is not a directory" if p.exists() else "does not exist"
            raise InputError(f"{option} {p}: directory {what} (create it first)")
        _check_writable(p, f"{option} {p}")
        return p
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(
            f"{option} {p}: directory {parent} does not exist (create it first)"
            if not parent.exists()
            else f"{option} {p}: {parent} is not a directory"
        )
    if p.is_dir():
        raise InputError(f"{option} {p}: is a directory, give a file name")
    for src in inputs:
        if src is not None and _same_file(p, Path(src)):
            raise InputError(f"{option} {p}: would overwrite the input {src}; choose another file")
    _check_writable(parent, f"{option} {p}")
    return p


def _check_writable(folder: Path, what: str) -> None:
    """Refuse a folder nothing can be written in, by creating and removing an empty file there.

    :func:`os.access` is not enough: it says yes to root on a read-only file system or in
    ``/proc``; the outputs are written through a temporary file in the same folder
    (:func:`atomic_path`), so this is the very operation that must succeed.
    """
    try:
        fd, name = tempfile.mkstemp(prefix=".camloc-write-test.", dir=folder)
    except OSError as exc:
        raise InputError(
            f"{what}: cannot write in the directory {folder} ({exc.strerror or exc})"
        ) from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(name)


@contextlib.contextmanager
def atomic_path(path: PathLike) -> Iterator[Path]:
    """A temporary path next to ``path`` (same suffix); it replaces ``path`` on success.

    Write the file at the yielded path (any writer: ``open``, ``cv2.imwrite``...). When the
    block raises, or writes nothing, the temporary file is removed and ``path`` is untouched.
    """
    target = Path(path)
    fd, tmp_name = tempfile.mkstemp(
        prefix=f".{target.name}.", suffix=f".tmp{target.suffix}", dir=target.parent or "."
    )
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        if not tmp.exists() or tmp.stat().st_size == 0:
            raise OSError(f"nothing was written to {target}")
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, target)
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def write_text_atomic(path: PathLike, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; returns the path."""
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as fh:
        fh.write(text)
        fh.flush()
        os.fsync(fh.fileno())
    return Path(path)


def check_input_file(
    path: PathLike,
    *,
    what: str = "file",
    max_bytes: int | None = -1,
    pipes: bool = False,
) -> Path:
    """``path`` if it is a regular file of at most ``max_bytes``; never opens it.

    A device (``/dev/zero``) or a file of gigabytes read whole grew memory until the process
    died (``MemoryError``, exit 1) or hung; they are refused with a clear error.

    Parameters
    ----------
    path
        The input file.
    what
        What it should be, for the messages ("GeoJSON file", "verdicts file").
    max_bytes
        Largest size accepted (None: any; default :data:`MAX_JSON_BYTES`).
    pipes
        Accept a pipe (``<(camloc locate ...)``; its size is unknown: the reader bounds it).

    Returns
    -------
    Path
        The path.

    Raises
    ------
    InputError
        Missing, a directory, not a regular file, or too large.
    """
    import stat

    if max_bytes == -1:
        max_bytes = MAX_JSON_BYTES
    p = Path(path)
    try:
        st = p.stat()
    except FileNotFoundError:
        raise InputError(f"cannot read the {what} {p}: no such file") from None
    except OSError as exc:
        raise InputError(f"cannot read the {what} {p}: {exc.strerror or exc}") from None
    if stat.S_ISDIR(st.st_mode):
        raise InputError(f"{p}: is a directory, expected a {what}")
    if pipes and stat.S_ISFIFO(st.st_mode):
        return p
    if not stat.S_ISREG(st.st_mode):
        raise InputError(f"{p}: not a regular file (a device or a pipe), expected a {what}")
    if max_bytes is not None and st.st_size > max_bytes:
        raise InputError(
            f"{p}: {st.st_size / 1e6:.0f} MB is more than a {what} camloc reads "
            f"({max_bytes / 1e6:.0f} MB at most)"
        )
    return p


BINARY_KINDS: tuple[tuple[bytes, str], ...] = (
    (b"SQLite format 3\x00", "a GeoPackage or SQLite database"),
    (b"PK\x03\x04", "a ZIP archive (an Excel or LibreOffice workbook, a zipped shapefile?)"),
    (b"\xd0\xcf\x11\xe0", "an old Excel (.xls) workbook"),
    (b"\x00\x00\x27\x0a", "a shapefile's geometry (.shp)"),
    (b"%PDF", "a PDF document"),
)
"""What a file's first bytes say it is when it is no text (a camera list, a scene, JSON)."""


def map_file_kind(raw: bytes) -> str | None:
    """What a file's first bytes say when it is an OSM extract or a compressed one (None:
    neither): a scene or a list given where the extract goes, and the other way round, was
    "not UTF-8 text (byte 0x95 at position 16)" (``camloc locate EXTRACT --osm SCENE``, qa7).
    """
    if raw[4:15] == b"\n\tOSMHeader":
        return "an OSM extract (.osm.pbf)"
    if raw.startswith(b"\x1f\x8b"):
        return "a gzip-compressed file (an .osm.gz extract?)"
    if raw.startswith(b"BZh"):
        return "a bzip2-compressed file (an .osm.bz2 extract?)"
    return None


class NotTextError(ValueError):
    """Bytes that are no text a JSON reader takes; the message says what they look like."""


def json_text(raw: bytes) -> str:
    """The text of a JSON file's or body's bytes.

    UTF-8, a leading byte-order mark dropped (Windows Notepad and PowerShell's ``Out-File
    -Encoding utf8`` write one; ``json.loads`` refused it, "Unexpected UTF-8 BOM"); UTF-16
    with its mark (Notepad's "Unicode") decoded.

    Raises
    ------
    NotTextError
        Not such text; the message completes "X is ...": ``a GeoPackage or SQLite
        database``, ``a JPEG image``, ``not UTF-8 text (byte 0xd8 at position 63)``.
    """
    import codecs

    try:
        if raw.startswith(codecs.BOM_UTF8):
            return raw[len(codecs.BOM_UTF8) :].decode("utf-8")
        if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
            return raw.decode("utf-16")
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        kind = next((k for magic, k in BINARY_KINDS if raw.startswith(magic)), None)
        kind = kind or map_file_kind(raw[:16])
        image = magic_format(raw[:16])
        if kind is None and image is not None:
            kind = f"a {image} image"
        if kind is None:
            bad = raw[exc.start : exc.start + 1].hex()
            kind = f"not UTF-8 text (byte 0x{bad} at position {exc.start})"
        raise NotTextError(kind) from None


def read_text_file(path: PathLike, *, what: str) -> str:
    """The text of a small text input (CSV, GPX, JSON) the caller has checked, decoded as
    :func:`json_text` decodes (UTF-8, a byte-order mark dropped, UTF-16 with its mark).

    Raises
    ------
    InputError
        Unreadable, or not text: the message names what the file is instead (``cams.gpkg: not
        a GPS traces file (a GeoPackage or SQLite database)``), never the codec's words.
    """
    p = Path(path)
    try:
        return json_text(p.read_bytes())
    except NotTextError as exc:
        raise InputError(f"{p}: not a {what} ({exc})") from None
    except OSError as exc:
        raise InputError(f"cannot read {what} {p}: {exc.strerror or exc}") from None


def read_json_file(path: PathLike, *, what: str = "JSON file") -> Any:
    """Parse a JSON file; every failure is an :class:`InputError` naming the file.

    Raises
    ------
    InputError
        Missing, unreadable, not a regular file, over :data:`MAX_JSON_BYTES`, not UTF-8 or
        not JSON (the message gives line and column).
    """
    p = check_input_file(path, what=what, pipes=True)
    try:
        with open(p, "rb") as fh:
            raw = fh.read(MAX_JSON_BYTES + 1)  # bounded: a pipe's size is not known
        if len(raw) > MAX_JSON_BYTES:
            raise InputError(
                f"{p}: more than a {what} camloc reads ({MAX_JSON_BYTES / 1e6:.0f} MB at most)"
            )
        text = json_text(raw)
    except FileNotFoundError as exc:
        raise InputError(f"{p}: no such file") from exc
    except IsADirectoryError as exc:
        raise InputError(f"{p}: is a directory, expected a {what}") from exc
    except NotTextError as exc:
        raise InputError(f"{p}: not a {what} ({exc})") from exc
    except OSError as exc:
        raise InputError(f"{p}: cannot read ({exc.strerror or exc})") from exc
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(
            f"{p}: not a {what} (line {exc.lineno} column {exc.colno}: {exc.msg})"
        ) from exc


_FORMATS = "JPEG, PNG, TIFF, WebP, BMP, GIF..."
_MAGIC = (
    (b"\xff\xd8\xff", "JPEG"),
    (b"\x89PNG\r\n\x1a\n", "PNG"),
    (b"GIF8", "GIF"),
    (b"BM", "BMP"),
    (b"II*\x00", "TIFF"),
    (b"MM\x00*", "TIFF"),
)


def _image_format(path: Path, head: bytes) -> str | None:
    """The image format of a file (``JPEG``, ``PNG``...) from its header, or None.

    Pillow's reading of the header first, else the first bytes (``head``): a JPEG cut off
    inside its header is still named a JPEG.
    """
    try:
        import warnings

        from PIL import Image

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with Image.open(path) as im:
                if im.format:
                    return str(im.format)
    except Exception:  # any failure: try the first bytes
        pass
    return magic_format(head)


def magic_format(head: bytes) -> str | None:
    """The image format its first bytes announce (``JPEG``, ``PNG``, ``WEBP``...), or None.

    For a file Pillow cannot open: a JPEG cut off inside its header is still a JPEG, and the
    error should say "truncated or corrupt JPEG", not "not an image".
    """
    if head[:4] == b"RIFF" and head[8:12] == b"WEBP":
        return "WEBP"
    return next((name for magic, name in _MAGIC if head.startswith(magic)), None)


_HEIF_BRANDS = {
    b"heic": "HEIC",
    b"heix": "HEIC",
    b"hevc": "HEIC",
    b"hevx": "HEIC",
    b"heim": "HEIC",
    b"heis": "HEIC",
    b"mif1": "HEIF",
    b"msf1": "HEIF",
    b"avif": "AVIF",
    b"avis": "AVIF",
}


def heif_kind(head: bytes) -> str | None:
    """``HEIC``, ``HEIF`` or ``AVIF`` when the first bytes are an ISO media file of that
    brand (an iPhone's photo by default is HEIC), else None.

    Pillow reads none of them without a plugin, and the messages said "not an image this
    page can show" to a grader holding a phone photo (issue 24): they now name the format and
    the way out (:data:`HEIF_HINT`).
    """
    if len(head) < 12 or head[4:8] != b"ftyp":
        return None
    return _HEIF_BRANDS.get(head[8:12])


def heif_photo(kind: str) -> str:
    """``a HEIC photo``, ``an AVIF photo``: a :func:`heif_kind` in a sentence."""
    return f"{'an' if kind == 'AVIF' else 'a'} {kind} photo"


HEIF_HINT = (
    "convert it to JPEG first (an iPhone: Settings > Camera > Formats > Most Compatible, or "
    "share the photo as JPEG; on a computer, an image editor or `heif-convert`)"
)
"""What to do with a HEIC, HEIF or AVIF photo (:func:`heif_kind`)."""


_SIMPLE_FORMATS = ("JPEG", "PNG", "GIF", "BMP", "WEBP")
"""Formats OpenCV decodes in every variant: a failure means the file is cut off or corrupt."""


_QUIET = threading.Lock()
_quiet_users = 0
_loud_level: int | None = None


def _gray_from_colour(cv2: Any, buf: Any) -> Any:
    """Decode in colour (BGR), then to gray with ``cv2.cvtColor``: the one grey conversion
    that an array the caller decoded itself (``cv2.imread``) goes through too
    (:func:`camloc_geo.autovp.load_image`). Decoding straight to gray (``IMREAD_GRAYSCALE``:
    libjpeg's luma, libpng's own weights) differs from it by a grey level on up to half the
    pixels, and the line detector's segments, and a loose photo's focal length, followed
    that difference (issue 24: one photo read from a file and from an array, 806 and
    1211 px)."""
    arr = cv2.imdecode(buf, cv2.IMREAD_COLOR)
    if arr is None:
        return None
    return cv2.cvtColor(arr, cv2.COLOR_BGR2GRAY)


def _imdecode_quietly(cv2: Any, buf: Any) -> Any:
    """``cv2.imdecode`` to 8-bit gray (:func:`_gray_from_colour`), without OpenCV's own
    warning and error lines on stderr.

    OpenCV's log level is process-wide: it is lowered while any thread decodes here and
    restored by the last one out.
    """
    global _quiet_users, _loud_level
    logging_ = getattr(getattr(cv2, "utils", None), "logging", None)
    if logging_ is None:  # pragma: no cover - an OpenCV build without cv2.utils.logging
        return _gray_from_colour(cv2, buf)
    with _QUIET:
        if _quiet_users == 0:
            _loud_level = logging_.getLogLevel()
            logging_.setLogLevel(logging_.LOG_LEVEL_SILENT)  # our message names the fault
        _quiet_users += 1
    try:
        return _gray_from_colour(cv2, buf)
    finally:
        with _QUIET:
            _quiet_users -= 1
            if _quiet_users == 0 and _loud_level is not None:
                logging_.setLogLevel(_loud_level)


def _png_intact(path: Path) -> bool:
    """False when a PNG's chunks are cut off or fail their checksums (Pillow's ``verify``).

    Checked before OpenCV decodes it: libpng would print its own error line on stderr.
    """
    try:
        import warnings

        from PIL import Image

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with Image.open(path) as im:
                im.verify()
    except Exception:  # whatever the reason, not intact
        return False
    return True


_GRAY_CACHE: dict[tuple[str, int, int, int], Any] = {}
_GRAY_CACHE_LOCK = threading.Lock()
GRAY_CACHE_ENTRIES = 2
"""How many decoded photos :func:`read_image_gray` keeps (a scene's photo is decoded when the
scene is read, to check it, and again by the line detector: the second is a cache hit)."""
GRAY_CACHE_MAX_PIXELS = 25_000_000
"""Larger photos are not kept (at most ``GRAY_CACHE_ENTRIES`` x 25 MB held)."""


def read_image_gray(path: PathLike) -> Any:
    """Decode an image file to an 8-bit grayscale array, as the user sees it.

    The last ``GRAY_CACHE_ENTRIES`` photos decoded are kept, keyed on the file's resolved
    path, modification time, size and inode: reading the same unchanged file again returns
    the same **read-only** array without decoding it (copy it to change it).

    OpenCV decodes it and applies its EXIF orientation (a portrait photo stored sideways
    comes out upright). The header is checked first (:func:`camloc_geo._limits.check_image_file`:
    a regular file, at most ``MAX_IMAGE_PIXELS``), so a decompression bomb is refused before
    any memory is spent on it; a file whose header Pillow cannot read is refused too, its size
    being unknown (JPEG, PNG, TIFF, WebP, BMP, GIF, PNM... are read).

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` ``uint8``.

    Raises
    ------
    InputError
        One line naming the file: missing, not a regular file, empty, too large (pixels, or
        bytes beyond ``MAX_IMAGE_BYTES_PER_PIXEL`` a pixel plus ``MAX_IMAGE_EXTRA_BYTES``: the
        file is read whole), not an image, truncated or corrupt, or smaller than
        ``MIN_IMAGE_SIDE_PX`` on a side.
    """
    p = Path(path)
    try:
        st = p.stat()
        key: tuple[str, int, int, int] | None = (
            str(p.resolve()),
            st.st_mtime_ns,
            st.st_size,
            st.st_ino,
        )
    except (OSError, RuntimeError):  # missing, a loop of links: the checks below say why
        key = None
    if key is not None:
        with _GRAY_CACHE_LOCK:
            hit = _GRAY_CACHE.get(key)
        if hit is not None:
            return hit
    gray = _decode_image_gray(p)
    if key is not None and gray.size <= GRAY_CACHE_MAX_PIXELS:
        gray.setflags(write=False)
        with _GRAY_CACHE_LOCK:
            _GRAY_CACHE[key] = gray
            while len(_GRAY_CACHE) > GRAY_CACHE_ENTRIES:
                del _GRAY_CACHE[next(iter(_GRAY_CACHE))]
    return gray


def _decode_image_gray(p: Path) -> Any:
    """:func:`read_image_gray` without its cache."""
    import cv2
    import numpy as np

    from camloc_geo._limits import check_image_file

    width, height = check_image_file(p)  # regular file, size from the header before decoding
    try:
        n_bytes = p.stat().st_size
        with open(p, "rb") as fh:
            head = fh.read(16)
    except OSError as exc:
        raise InputError(f"cannot read image {p}: {exc.strerror or exc}") from None
    if n_bytes == 0:
        raise InputError(f"cannot decode image {p}: the file is empty (0 bytes)")
    fmt = _image_format(p, head)
    if (width, height) == (0, 0):
        # Pillow cannot read the header, so the size is not known: OpenCV is not asked (it
        # would allocate what a Radiance HDR or EXR header claims, up to 2^30 pixels)
        heif = heif_kind(head)
        if heif is not None:
            raise InputError(
                f"cannot decode image {p}: {heif_photo(heif)}, which camloc cannot read; "
                f"{HEIF_HINT}"
            )
        raise InputError(
            f"cannot decode image {p}: a truncated or corrupt {fmt} file"
            if fmt
            else f"cannot decode image {p}: not an image file camloc reads ({_FORMATS})"
        )
    most = MAX_IMAGE_BYTES_PER_PIXEL * width * height + MAX_IMAGE_EXTRA_BYTES
    if n_bytes > most:  # the whole file is read into memory: bound it by what it can hold
        raise InputError(
            f"image {p} is {n_bytes / 1e6:.0f} MB for {width}x{height} pixels, more than any "
            f"encoding of them takes ({most / 1e6:.0f} MB): padded or corrupt"
        )
    if fmt == "PNG" and not _png_intact(p):
        arr = None
    else:
        try:
            buf = np.fromfile(str(p), dtype=np.uint8)
        except OSError as exc:
            raise InputError(f"cannot read image {p}: {exc.strerror or exc}") from None
        arr = _imdecode_quietly(cv2, buf)
        del buf
    if arr is None and fmt in _SIMPLE_FORMATS:
        raise InputError(f"cannot decode image {p}: a truncated or corrupt {fmt} file")
    if arr is None:
        raise InputError(
            f"cannot decode image {p}: a {fmt or 'image'} file OpenCV does not decode (truncated, "
            "corrupt, or a kind it does not read, e.g. 32-bit float samples)"
        )
    h, w = arr.shape[:2]
    if min(h, w) < MIN_IMAGE_SIDE_PX:
        raise InputError(
            f"image {p} is too small: {w}x{h} pixels (at least {MIN_IMAGE_SIDE_PX} on a side)"
        )
    return np.ascontiguousarray(arr, dtype=np.uint8)


EXIF_TURNED_QUARTER = (5, 6, 7, 8)
"""EXIF ``Orientation`` values that turn the stored image a quarter (width and height swap)."""


def displayed_size(im: Any) -> tuple[int, int]:
    """Width and height of an open Pillow image as viewers show it (EXIF orientation applied).

    OpenCV's decoder and browsers (``<img>``, canvas ``drawImage``) turn a photo whose EXIF
    ``Orientation`` is 5-8 a quarter: its pixels, and so the annotations', are in that grid.
    """
    width, height = (int(v) for v in im.size)
    try:
        orientation = im.getexif().get(0x0112)
    except Exception:  # a malformed EXIF block: as stored
        return width, height
    return (height, width) if orientation in EXIF_TURNED_QUARTER else (width, height)


def image_data_complete(data: bytes, fmt: str) -> bool:
    """Whether an image's data are all there (``fmt``: Pillow's ``JPEG``, ``PNG``, ``WEBP``...).

    A cut-off upload or file would be shown to annotators as a broken picture. A JPEG is
    decoded at 1/8 scale (Pillow's draft mode: a few milliseconds, little memory), a PNG's
    chunks and checksums are verified without decompressing, anything else decoded fully:
    call it only after the pixel count has been bounded.
    """
    import warnings

    from PIL import Image

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with Image.open(io.BytesIO(data)) as img:
                if fmt == "PNG":
                    img.verify()
                else:
                    if fmt == "JPEG":
                        img.draft("L", (max(1, img.width // 8), max(1, img.height // 8)))
                    img.load()
    except Exception:  # any decoder failure: the data are not all there
        return False
    return True
