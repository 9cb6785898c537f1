"""Open a snapshot as safely as camloc_geo does: no hang, bounded memory, the displayed grid.

The dock reads images with Qt in the QGIS process, so it cannot lean on ``camloc_geo``'s checks
(``camloc_geo/_io.py`` ``read_image_gray``; the plugin never imports the library, whose
shapely/pyproj wheels crash inside QGIS, see docs/qgis.md). The same rules, with Qt:

- only a regular file is opened (a FIFO or a device would block QGIS for ever);
- the pixel count is read from the header (``QImageReader.size()``) and an image over
  :data:`MAX_IMAGE_PIXELS` is refused before anything is decoded (Qt 5 has no allocation limit:
  a PNG header claiming 60000x60000 would be decoded whole);
- the EXIF orientation is applied (``setAutoTransform``): the annotation is in the grid that
  viewers, the browser page, ``camloc vp`` and calibrate use;
- an empty, truncated or non-image file is refused with one line naming the file (Qt decodes
  a cut-off JPEG, GIF or BMP without an error, grey or black below the cut, and libpng logs
  its own error for a cut-off PNG: those four are checked here for their end first).
"""

from __future__ import annotations

import os
import re
import stat
import zlib
from typing import BinaryIO

from qgis.PyQt.QtGui import QImage, QImageReader

MAX_IMAGE_PIXELS = 50_000_000
"""Largest snapshot opened (width × height): ``camloc_geo._limits.MAX_IMAGE_PIXELS``, copied
because the plugin does not import camloc_geo (keep the two equal)."""

MAX_IMAGE_BYTES_PER_PIXEL = 8
MAX_IMAGE_EXTRA_BYTES = 64_000_000
"""A file larger than ``MAX_IMAGE_BYTES_PER_PIXEL`` a pixel plus ``MAX_IMAGE_EXTRA_BYTES`` is
padded or corrupt (``camloc_geo._io``'s, copied: keep them equal)."""
MIN_IMAGE_SIDE_PX = 8
"""Smallest image side (``camloc_geo._io.MIN_IMAGE_SIDE_PX``, copied: keep them equal)."""

_JPEG_MARKER = re.compile(rb"\xff[^\x00\xd0-\xd7\xff]")
"""In a JPEG's entropy-coded data, the next marker (``FF 00`` is a stuffed byte, ``FF D0``-``D7``
restart markers, ``FF FF`` fill)."""


class SnapshotError(ValueError):
    """A snapshot the dock cannot open; the message is one line naming the file."""


def check_regular_file(path: str, what: str) -> str | None:
    """Why ``path`` cannot be read as a ``what`` (one line), or None if it is a regular file.

    Never opens the file: a FIFO or a device is refused before anything could block on it.
    """
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return f"{what} not found: {path}"
    except OSError as exc:
        return f"cannot read the {what} {path}: {exc.strerror or exc}"
    if stat.S_ISDIR(mode):
        return f"the {what} {path} is a folder, not a file"
    if not stat.S_ISREG(mode):
        return f"the {what} {path} is not a regular file (a pipe or a device): not read"
    return None


class _FileBytes:
    """Random access to a file's bytes through a 1 MB window.

    Memory stays bounded whatever the file's size, and a file cut while it is read (still
    being copied or synced) gives short reads: a memory map would kill QGIS with SIGBUS.
    """

    WINDOW = 1 << 20

    def __init__(self, fh: BinaryIO, size: int) -> None:
        self.fh = fh
        self.size = size
        self.start = 0
        self.buf = b""

    def __len__(self) -> int:
        return self.size

    def _load(self, pos: int) -> None:
        self.fh.seek(pos)
        self.buf = self.fh.read(self.WINDOW)
        self.start = pos

    def __getitem__(self, pos: int) -> int:
        i = pos - self.start
        if not 0 <= i < len(self.buf):
            self._load(pos)
            if not self.buf:
                raise IndexError(pos)  # shorter than it was: cut meanwhile
            i = 0
        return self.buf[i]

    def read(self, pos: int, n: int) -> bytes:
        """Up to ``n`` bytes from ``pos`` (fewer at the end)."""
        i = pos - self.start
        if i >= 0 and i + n <= len(self.buf):
            return self.buf[i : i + n]
        self.fh.seek(pos)
        return self.fh.read(n)

    def search(self, pattern: re.Pattern[bytes], pos: int) -> int | None:
        """Where the next match of a two-byte ``pattern`` starts at or after ``pos``."""
        while pos < self.size:
            self._load(pos)
            found = pattern.search(self.buf)
            if found is not None:
                return pos + found.start()
            if len(self.buf) < 2:
                return None
            pos += len(self.buf) - 1  # one byte of overlap: a match across the edge
        return None

    def crc32(self, start: int, end: int) -> int | None:
        """CRC-32 of bytes ``start:end`` (None if the file ends before)."""
        crc = 0
        self.fh.seek(start)
        left = end - start
        while left > 0:
            chunk = self.fh.read(min(left, self.WINDOW))
            if not chunk:
                return None
            crc = zlib.crc32(chunk, crc)
            left -= len(chunk)
        return crc


def _jpeg_complete(data: _FileBytes) -> bool:
    """Whether a JPEG's segments run to its end-of-image marker (a cut-off file does not)."""
    n = len(data)
    pos = 2  # after SOI
    while True:
        while pos < n and data[pos] != 0xFF:  # stray bytes between segments: skip them
            pos += 1
        while pos < n and data[pos] == 0xFF:  # fill bytes
            pos += 1
        if pos >= n:
            return False
        marker = data[pos]
        pos += 1
        if marker == 0xD9:  # EOI
            return True
        if marker == 0x01 or 0xD0 <= marker <= 0xD7:  # no length
            continue
        if pos + 2 > n:
            return False
        pos += (data[pos] << 8) | data[pos + 1]
        if pos > n:
            return False
        if marker == 0xDA:  # SOS: entropy-coded data up to the next marker
            found = data.search(_JPEG_MARKER, pos)
            if found is None:
                return False
            pos = found


def _gif_complete(data: _FileBytes) -> bool:
    """Whether a GIF's blocks run to its trailer (``;``)."""
    n = len(data)
    if n < 13:
        return False
    flags = data[10]
    pos = 13 + (3 * 2 ** ((flags & 7) + 1) if flags & 0x80 else 0)

    def skip_sub_blocks(p: int) -> int:
        while p < n and data[p]:
            p += data[p] + 1
        return p + 1

    while pos < n:
        block = data[pos]
        if block == 0x3B:  # trailer
            return True
        if block == 0x21:  # extension: label, sub-blocks
            pos = skip_sub_blocks(pos + 2)
        elif block == 0x2C:  # image: descriptor, local colour table, LZW code size, data
            if pos + 10 > n:
                return False
            flags = data[pos + 9]
            pos += 10 + (3 * 2 ** ((flags & 7) + 1) if flags & 0x80 else 0)
            pos = skip_sub_blocks(pos + 1)
        else:
            return False
    return False


def _png_complete(data: _FileBytes) -> bool:
    """Whether a PNG's chunks run to ``IEND``, each with its checksum right (not decompressed)."""
    n = len(data)
    pos = 8  # after the signature
    while pos + 12 <= n:
        head = data.read(pos, 8)
        length = int.from_bytes(head[:4], "big")
        end = pos + 8 + length
        if len(head) < 8 or end + 4 > n:
            return False
        if data.crc32(pos + 4, end) != int.from_bytes(data.read(end, 4), "big"):
            return False
        if head[4:] == b"IEND":
            return True
        pos = end + 4
    return False


def data_complete(path: str, fmt: str) -> bool:
    """Whether a JPEG, PNG, GIF or BMP file holds all its data (other formats: Qt says so).

    Qt decodes a cut-off JPEG, GIF or BMP without an error (grey or black below the cut), and
    refuses a cut-off PNG only after libpng has written its own error to the log. The file is
    read through a 1 MB window: memory stays bounded whatever its size.
    """
    if fmt not in ("jpeg", "jpg", "png", "gif", "bmp"):
        return True
    try:
        with open(path, "rb") as fh:
            data = _FileBytes(fh, os.fstat(fh.fileno()).st_size)
            if fmt in ("jpeg", "jpg"):
                return data.read(0, 2) == b"\xff\xd8" and _jpeg_complete(data)
            if fmt == "png":
                return _png_complete(data)
            if fmt == "gif":
                return _gif_complete(data)
            # BMP: the header gives the file's size
            return len(data) >= 6 and len(data) >= int.from_bytes(data.read(2, 4), "little")
    except (OSError, ValueError, IndexError):
        return False


def read_snapshot(path: str) -> tuple[QImage, bool]:
    """Decode ``path`` as viewers show it (EXIF orientation applied), within the limits.

    Returns
    -------
    image : QImage
        The displayed image: a photo stored sideways with an EXIF orientation of 5-8 comes
        out upright, its width and height swapped.
    turned : bool
        Whether the EXIF orientation turned it a quarter (its stored width and height swap).

    Raises
    ------
    SnapshotError
        One line naming the file: missing, not a regular file (FIFO, device, folder), empty,
        not an image Qt reads, its size unknown from the header, over
        :data:`MAX_IMAGE_PIXELS`, under :data:`MIN_IMAGE_SIDE_PX` on a side, larger in bytes
        than its pixels can take (padded), truncated or corrupt.
    """
    problem = check_regular_file(path, "image")
    if problem:
        raise SnapshotError(problem)
    if os.path.getsize(path) == 0:
        raise SnapshotError(f"cannot read the image {path}: the file is empty (0 bytes)")
    reader = QImageReader(path)
    reader.setAutoTransform(True)  # the EXIF orientation, as browsers and camloc apply it
    if not reader.canRead():
        formats = ", ".join(bytes(f).decode() for f in QImageReader.supportedImageFormats())
        raise SnapshotError(
            f"cannot read the image {path}: {reader.errorString()} "
            f"(not an image file QGIS reads: {formats})"
        )
    size = reader.size()  # from the header: nothing decoded yet
    fmt = bytes(reader.format()).decode("ascii", "replace").lower()
    if not size.isValid():
        raise SnapshotError(
            f"cannot read the image {path}: its header does not give its size "
            f"(a corrupt {fmt.upper() or 'image'} file)"
        )
    width, height = size.width(), size.height()
    if width * height > MAX_IMAGE_PIXELS:
        raise SnapshotError(
            f"image {path} is {width}x{height} pixels ({width * height / 1e6:.0f} MP); "
            f"the supported limit is {MAX_IMAGE_PIXELS / 1e6:g} megapixels"
        )
    if min(width, height) < MIN_IMAGE_SIDE_PX:
        raise SnapshotError(
            f"image {path} is too small: {width}x{height} pixels "
            f"(at least {MIN_IMAGE_SIDE_PX} on a side)"
        )
    n_bytes = os.path.getsize(path)
    most = MAX_IMAGE_BYTES_PER_PIXEL * width * height + MAX_IMAGE_EXTRA_BYTES
    if n_bytes > most:  # the end checks would read it all
        raise SnapshotError(
            f"image {path} is {n_bytes / 1e6:.0f} MB for {width}x{height} pixels, more than "
            f"any encoding of them takes ({most / 1e6:.0f} MB): padded or corrupt"
        )
    if hasattr(reader, "setAllocationLimit"):  # Qt 6: its 128 MB default would refuse 40 MP
        reader.setAllocationLimit(MAX_IMAGE_PIXELS * 8 // 2**20 + 1)
    if not data_complete(path, fmt):
        raise SnapshotError(
            f"cannot read the image {path}: a truncated or corrupt {fmt.upper()} file"
        )
    image = reader.read()
    if image.isNull():
        raise SnapshotError(
            f"cannot read the image {path}: {reader.errorString()} "
            f"(a truncated or corrupt {fmt.upper() or 'image'} file)"
        )
    # from the sizes, not the transformation flags (their enum differs between PyQt5 and 6)
    turned = width != height and (image.width(), image.height()) == (height, width)
    return image, turned
