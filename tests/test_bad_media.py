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
