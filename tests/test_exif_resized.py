"""Resized and rotated photos: the EXIF's focal length on the photo as stored."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from camloc_geo.exif import FULL_FRAME_DIAGONAL_MM, focal_from_exif, focal_from_tags

PIL_Image = pytest.importorskip("PIL.Image")

# A Canon EOS 30D: 3504 x 2336 on a 22.5 mm sensor (the table's), 3959.32 px per inch
# (FocalPlaneXResolution, unit inches), a 24 mm lens.
EOS_30D = {0x010F: "Canon", 0x0110: "Canon EOS 30D", 0x920A: 24.0, 0xA20E: 3959.32, 0xA210: 2}
FULL_W, FULL_H = 3504, 2336


def _truth(width_px: int) -> float:
    return 24.0 / (FULL_W / 3959.32 * 25.4) * width_px


def test_a_resized_photo_keeping_its_pixel_size_scales_the_focal_plane() -> None:
    tags = {**EOS_30D, 0xA002: FULL_W, 0xA003: FULL_H}
    got = focal_from_tags(tags, 600, 400, sensor_db="")
    assert got is not None
    assert got.source == "exif-focal-plane"
    assert got.focal_px == pytest.approx(_truth(600))
    assert got.warnings == ()


@pytest.mark.parametrize("pixel_size", [{0xA002: 1200, 0xA003: 800}, {}])
def test_a_resize_that_rewrote_or_dropped_the_pixel_size_is_caught_by_the_table(
    pixel_size: dict[int, int],
) -> None:
    # the resolution still refers to the 3504 px frame: read on 1200 px it gives a 7.7 mm
    # sensor and 3741 px; the table's 22.5 mm gives the right 1280 px
    got = focal_from_tags({**EOS_30D, **pixel_size}, 1200, 800, sensor_db="")
    assert got is not None
    assert got.source == "exif-sensor-table"  # before: an exif-conflict, 2188 px +/- 54 %
    assert got.focal_px == pytest.approx(24.0 / 22.5 * 1200)
    assert abs(got.focal_px / _truth(1200) - 1) < 0.01
    assert "FocalPlaneXResolution" in got.warnings[0]
    assert "not used" in got.warnings[0]


def test_a_resize_that_rewrote_the_pixel_size_is_caught_by_the_35mm_tag() -> None:
    tags = {0x920A: 24.0, 0xA20E: 3959.32, 0xA210: 2, 0xA002: 1200, 0xA003: 800, 0xA405: 38}
    got = focal_from_tags(tags, 1200, 800, sensor_db="", bundled_table=False)
    assert got is not None
    assert got.source == "exif-35mm"  # before: an exif-conflict
    assert got.focal_px == pytest.approx(38 * math.hypot(1200, 800) / FULL_FRAME_DIAGONAL_MM)
    assert "35 mm tag's crop factor" in got.warnings[0]


def test_a_crop_of_the_sensor_keeps_the_focal_plane_reading() -> None:
    # a camera writing its resolution for a frame 10 % narrower: within what the table allows
    tags = {**EOS_30D, 0xA20E: 3959.32 * 1.1, 0xA002: FULL_W, 0xA003: FULL_H}
    got = focal_from_tags(tags, FULL_W, FULL_H, sensor_db="")
    assert got is not None
    assert got.source == "exif-focal-plane"


@pytest.mark.parametrize("orientation", [1, 6, 8])
def test_a_rotated_photo_reads_the_same_focal_length(tmp_path: Path, orientation: int) -> None:
    # Orientation 6 / 8: stored as shot (landscape), shown turned; stored turned (portrait,
    # pixel size as shot or swapped) reads the same: the longer side and diagonal are used
    tags = {**EOS_30D, 0xA002: FULL_W, 0xA003: FULL_H, 0xA405: 38}
    want = _truth(876)
    for size in ((876, 584), (584, 876)):
        got = focal_from_tags({**tags, 0x0112: orientation}, *size, sensor_db="")
        assert got is not None
        assert got.source == "exif-focal-plane"
        assert got.focal_px == pytest.approx(want)
    im = PIL_Image.new("RGB", (584, 876), (128, 128, 128))
    exif = PIL_Image.Exif()
    exif[0x010F], exif[0x0110], exif[0x0112] = "Canon", "Canon EOS 30D", orientation
    sub = exif.get_ifd(0x8769)
    for k in (0x920A, 0xA20E, 0xA210, 0xA405):
        sub[k] = tags[k]
    sub[0xA002], sub[0xA003] = FULL_H, FULL_W  # a rotating tool that swapped them
    path = tmp_path / "turned.jpg"
    im.save(path, exif=exif)
    got = focal_from_exif(path, sensor_db="")
    assert got is not None
    assert got.focal_px == pytest.approx(want, rel=1e-4)


def test_a_photo_cropped_to_another_shape_covers_the_crops_unknown_resize() -> None:
    # a 4:3 crop of the 30D's 3:2 frame at its full height (3115 x 2336), resized to
    # 1200 x 900: the true scale is 900 / 2336; read as a resize of the whole frame
    # (1200 / 3504), the focal-plane reading was 11 % short at a stated 5 %
    tags = {**EOS_30D, 0xA002: FULL_W, 0xA003: FULL_H}
    truth = _truth(FULL_W) * 900 / FULL_H
    got = focal_from_tags(tags, 1200, 900, sensor_db="")
    assert got is not None
    assert got.source == "exif-focal-plane"
    assert abs(math.log(got.focal_px / truth)) <= got.sigma_rel  # within one sigma
    # and a crop at full resolution (no resize) too: the range's other end
    assert abs(math.log(got.focal_px / _truth(FULL_W))) <= got.sigma_rel
    assert any("cropped after capture" in n for n in got.notes)


def test_a_crop_that_keeps_the_scale_is_read_on_the_frame() -> None:
    # a 3000 x 2336 crop at full resolution: s between 2336 / 2336 and 1, exact
    tags = {**EOS_30D, 0xA002: FULL_W, 0xA003: FULL_H, 0x0112: 6}
    got = focal_from_tags(tags, 2336, 3000, sensor_db="")  # stored turned, too
    assert got is not None
    assert got.focal_px == pytest.approx(_truth(FULL_W))
    assert got.sigma_rel == pytest.approx(0.05)
