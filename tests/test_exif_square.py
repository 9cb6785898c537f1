"""A near-square photo's 35 mm tag (a phone's 1:1 mode), read on the frame it was written for."""

from __future__ import annotations

import math
from pathlib import Path

from camloc_geo.exif import focal_from_tags

# A Galaxy S8 (SM-G950U): 4.25 mm lens, 26 mm tag, 4032 x 3024 sensor of 1.4 um pixels.
S8_TAGS = {0x920A: 4.25, 0xA405: 26, 0x010F: "samsung", 0x0110: "SM-G950U"}
S8_FULL_HEIGHT_PX = 4.25 / 1.4e-3  # the lens over the pixel pitch: 3036 px
S8_OWN_DIAGONAL_PX = 26 * math.hypot(3024, 3024) / math.hypot(36, 24)  # 2570 px, 15 % low


def test_square_photo_of_an_unknown_sensor_covers_both_frames() -> None:
    got = focal_from_tags(S8_TAGS, 3024, 3024, bundled_table=False)
    assert got is not None
    assert got.source == "exif-35mm"
    for truth in (S8_FULL_HEIGHT_PX, S8_OWN_DIAGONAL_PX):
        # each frame's reading lies within one sigma of the mixture
        assert abs(math.log(truth / got.focal_px)) < got.sigma_rel
    assert 0.07 < got.sigma_rel < 0.12
    assert any("4:3 frame at the photo's height" in n for n in got.notes)


def test_square_photo_whose_sensor_is_known_reads_the_sensor_frame(tmp_path: Path) -> None:
    db = tmp_path / "sensors.txt"
    db.write_text("samsung SM-G950U;5.645\n")
    got = focal_from_tags(S8_TAGS, 3024, 3024, str(db), bundled_table=False)
    assert got is not None
    assert got.source == "exif-35mm"
    assert abs(got.focal_px / S8_FULL_HEIGHT_PX - 1) < 0.01
    assert got.sigma_rel == 0.04
    assert any("4:3 frame" in n for n in got.notes)


def test_four_by_three_photo_unchanged() -> None:
    got = focal_from_tags(S8_TAGS, 4032, 3024, bundled_table=False)
    assert got is not None
    assert got.sigma_rel == 0.04
    assert abs(got.focal_px / S8_FULL_HEIGHT_PX - 1) < 0.01
