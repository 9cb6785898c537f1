"""Session 39 QA: snapshots cut off inside their header.

A JPEG cut off after 300 bytes (an upload or a copy interrupted early) was "not an image
this page can show; give a JPEG, PNG or WebP file" from ``camloc annotate`` and "not a
readable JPEG, PNG or WebP image" from ``POST /v1/tasks``: the user was told to give the
format they gave. ``camloc vp`` already said "a truncated or corrupt JPEG file".
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from camloc_geo import InputError, SceneError
from camloc_geo.service.routers.crowd import image_info
from camloc_geo.web import read_image


def _encoded(fmt: str) -> bytes:
    rng = np.random.default_rng(39)
    pixels = (rng.random((60, 80, 3)) * 255).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(pixels).save(buf, format=fmt)
    return buf.getvalue()


@pytest.mark.parametrize(("fmt", "cut"), [("JPEG", 300), ("PNG", 20), ("WEBP", 14)])
def test_a_snapshot_cut_in_its_header_is_named_truncated(
    tmp_path: Path, fmt: str, cut: int
) -> None:
    data = _encoded(fmt)[:cut]
    path = tmp_path / "cut.img"
    path.write_bytes(data)
    with pytest.raises(InputError) as page:
        read_image(path)
    assert str(page.value) == f"{path} is a truncated or corrupt {fmt} file"
    with pytest.raises(SceneError) as upload:
        image_info(data, 40_000_000)
    assert str(upload.value).endswith(f"the snapshot is a truncated or corrupt {fmt} file")


def test_bytes_of_no_image_are_still_not_an_image() -> None:
    with pytest.raises(InputError, match="is not an image this page can show"):
        read_image(b"<osm version='0.6'></osm>")
    with pytest.raises(SceneError, match="not a readable JPEG, PNG or WebP image"):
        image_info(b"<osm version='0.6'></osm>", 40_000_000)


def test_annotate_streets_without_a_map_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``camloc annotate cam.jpg --streets "A & B"`` without ``--osm`` wrote a page without
    the junction and said nothing (the option was dropped)."""
    from camloc_geo.cli import main

    snap = tmp_path / "cam.jpg"
    snap.write_bytes(_encoded("JPEG"))
    out = tmp_path / "a.html"
    assert main(["annotate", str(snap), "-o", str(out), "--streets", "Main St & 1st Ave"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "camloc annotate: error: --streets needs --osm EXTRACT (the junction is looked up in "
        "the map)"
    ]
    assert not out.exists()
