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


def test_lund_truth_is_the_focal_length_over_the_sensor_width(tmp_path: Path) -> None:
    # a Nikon D60 photo at 29 mm, stored landscape but turned by its EXIF orientation (8),
    # and a Coolpix 4200 photo at 7.8 mm; scene 5 (indoors) and an unknown camera are left out
    d60 = _jpeg(tmp_path / "2" / "DSC_0025.JPG", (300, 200), {0x920A: 29.0, 0xA405: 43})
    with PIL_Image.open(d60) as im:
        exif = im.getexif()
        exif[0x0110] = "NIKON D60"
        exif[0x0112] = 8
        im.save(d60, exif=exif)
    e4200 = _jpeg(tmp_path / "7" / "DSCN7409.JPG", (400, 300), {0x920A: 7.8})
    with PIL_Image.open(e4200) as im:
        exif = im.getexif()
        exif[0x0110] = "E4200"
        im.save(e4200, exif=exif)
    _jpeg(tmp_path / "5" / "DSC_0336.JPG", (300, 200), {0x920A: 30.0})  # not an outdoor set
    other = _jpeg(tmp_path / "3" / "DSC_0001.JPG", (300, 200), {0x920A: 30.0})
    with PIL_Image.open(other) as im:
        exif = im.getexif()
        exif[0x0110] = "Some Phone"
        im.save(other, exif=exif)
    rows = vp_real.load_lund(tmp_path)
    assert [r["name"] for r in rows] == [
        "lund/2-courtyard/DSC_0025.JPG",
        "lund/7-heidelberg-castle/DSCN7409.JPG",
    ]
    a, b = rows
    assert a["f"] == pytest.approx(29.0 / 23.6 * 300)
    assert a["size"] == (200, 300)  # as OpenCV decodes it: turned upright
    assert a["pp"] == (100.0, 150.0)
    assert b["f"] == pytest.approx(7.8 / 7.11 * 400)
    assert b["exif"] is True
    assert b["up"] is None
