"""benchmarks/vp_real.py: photo folders whose EXIF is the focal-length truth."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

PIL_Image = pytest.importorskip("PIL.Image")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
vp_real = pytest.importorskip("vp_real")


def _jpeg(path: Path, size: tuple[int, int], sub_tags: dict[int, object]) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    im = PIL_Image.new("RGB", size, (128, 128, 128))
    exif = PIL_Image.Exif()
    sub = exif.get_ifd(0x8769)
    for k, v in sub_tags.items():
        sub[k] = v
    im.save(path, exif=exif)
    return path


def test_exif_folder_truth_prefers_the_focal_plane_to_the_35mm_tag(tmp_path: Path) -> None:
    # 18 mm lens, 200 px per mm (FocalPlaneResolutionUnit 4 = mm), 600 px wide at capture
    _jpeg(
        tmp_path / "church" / "a.JPG",
        (600, 400),
        {0x920A: 18.0, 0xA20E: 200.0, 0xA210: 4, 0xA405: 29, 0xA002: 600, 0xA003: 400},
    )
    _jpeg(tmp_path / "church" / "b.jpg", (600, 400), {0xA405: 28})  # 35 mm tag only
    _jpeg(tmp_path / "door" / "c.jpg", (600, 400), {})  # no focal length: skipped
    (tmp_path / ".git").mkdir()
    _jpeg(tmp_path / ".git" / "d.jpg", (600, 400), {0xA405: 28})  # hidden: skipped
    rows = vp_real.load_exif_folder(tmp_path, "perrot")
    assert [r["name"] for r in rows] == ["perrot/church/a.JPG", "perrot/church/b.jpg"]
    a, b = rows
    assert a["f"] == pytest.approx(18.0 * 200.0)
    assert a["f_source"] == "exif-focal-plane"
    assert b["f"] == pytest.approx(28.0 * 721.11 / 43.267, rel=1e-3)
    assert b["f_source"] == "exif-35mm"
    assert a["exif"] is True
    assert a["up"] is None
    assert a["size"] == (600, 400)
