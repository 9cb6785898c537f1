"""Bad photos, videos and output paths: one clear line naming the file, never a traceback.

Each input is made here (Pillow, numpy, OpenCV) in ``tmp_path``: empty, truncated or text
files posing as photos, decompression bombs, absurd EXIF, photos of another size than the
scene's, unwritable outputs. ``camloc vp`` and ``camloc radar`` refuse them with exit 2;
``camloc calibrate`` leaves a bad scene photo out with a warning and still uses the
annotations (one bad part never sinks the rest).
"""

from __future__ import annotations

import os
import struct
import zlib
from pathlib import Path

import pytest

from camloc_geo.cli import main

PROC = Path("/proc")


def one_line_error(err: str, command: str) -> str:
    """The single non-empty stderr line of a refused command (no traceback)."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err, err
    assert len(lines) == 1, err
    assert lines[0].startswith(f"camloc {command}: error: "), lines[0]
    return lines[0]


def png_header(path: Path, width: int, height: int) -> Path:
    """A PNG whose header claims ``width`` x ``height`` gray pixels, with almost no data."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        crc = zlib.crc32(kind + data) & 0xFFFFFFFF
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", crc)

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", zlib.compress(b"\0" * 100))
        + chunk(b"IEND", b"")
    )
    return path


# ------------------------------------------------------------------------------ outputs
def _unwritable_dir(tmp_path: Path) -> Path:
    if os.geteuid() != 0:
        d = tmp_path / "ro"
        d.mkdir()
        d.chmod(0o500)
        return d
    if not PROC.is_dir():  # pragma: no cover - not Linux
        pytest.skip("no unwritable directory for root here")
    return PROC


@pytest.mark.parametrize("option", ["-o", "--draw"])
def test_vp_output_in_an_unwritable_directory_is_refused_before_work(
    option: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the photo is not even read: the output is checked first (it used to fail after the
    # work with exit 1 and "FileNotFoundError: ... .tmp.png")
    target = _unwritable_dir(tmp_path) / ("x.png" if option == "--draw" else "x.json")
    assert main(["vp", str(tmp_path / "missing.jpg"), option, str(target)]) == 2
    line = one_line_error(capsys.readouterr().err, "vp")
    assert f"{option} {target}: cannot write in the directory" in line


# ------------------------------------------------------------------------------- photos
@pytest.mark.parametrize(
    ("width", "height", "size_text"),
    [(60000, 60000, "(3600 MP)"), (10000, 10000, "10000x10000 pixels (100 MP)")],
)
def test_vp_refuses_a_decompression_bomb_from_its_header(
    width: int, height: int, size_text: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # 60000 x 60000 used to end in exit 1 "failed: DecompressionBombError" (raised while
    # reading the EXIF); 100 MP printed Pillow's DecompressionBombWarning (two more lines)
    photo = png_header(tmp_path / "bomb.png", width, height)
    assert main(["vp", str(photo)]) == 2
    line = one_line_error(capsys.readouterr().err, "vp")
    assert f"image {photo} is too large" in line or f"image {photo} is {width}x" in line
    assert size_text in line
    assert "limit is 50 megapixels" in line


@pytest.mark.parametrize(
    "tags",
    [
        {0xA405: 2000},  # FocalLengthIn35mmFilm 2000 mm: 53 times the longer side
        {0x920A: 5000.0, 0xA20E: 1280 / 6.0, 0xA210: 4},  # 5 m lens on a 6 mm sensor
        {0x920A: 0.01, 0xA20E: 1280 / 6.0, 0xA210: 4},  # 0.01 mm
    ],
)
def test_an_implausible_exif_focal_length_is_ignored_with_a_warning(
    tags: dict[int, object], tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    from PIL import Image

    from camloc_geo.exif import focal_from_exif

    photo = tmp_path / "p.jpg"
    exif = Image.Exif()
    sub = exif.get_ifd(0x8769)
    sub.update(tags)
    Image.new("RGB", (1280, 720), (90, 90, 90)).save(photo, exif=exif)
    # before: a prior of 101829, 1600000 or 3 px that pinned autovp's fit to its bound
    assert focal_from_exif(photo) is None
    assert f"{photo}: EXIF focal length ignored" in caplog.text
    assert "plausible: 0.3 to 6" in caplog.text


def test_exif_plausible_range_is_the_range_autovp_searches() -> None:
    from camloc_geo.autovp import FOCAL_BOUNDS_REL
    from camloc_geo.exif import PLAUSIBLE_FOCAL_REL

    assert PLAUSIBLE_FOCAL_REL == FOCAL_BOUNDS_REL
