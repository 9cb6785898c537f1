"""A phone's other cameras (telephoto, ultra-wide, front): the table's width is the main one's."""

from __future__ import annotations

import logging
import math
from pathlib import Path

import pytest

from camloc_geo.exif import FULL_FRAME_DIAGONAL_MM, focal_from_exif, focal_from_tags

PIL_Image = pytest.importorskip("PIL.Image")

# An iPhone 11 Pro (the bundled table: 5.76 mm, the main camera's sensor), 4032 x 3024.
W, H = 4032, 3024
IPHONE_11_PRO = {0x010F: "Apple", 0x0110: "iPhone 11 Pro", 0xA432: (1.54, 6.0, 1.8, 2.4)}
TELE = {**IPHONE_11_PRO, 0x920A: 6.0, 0xA434: "iPhone 11 Pro back triple camera 6mm f/2"}
MAIN = {**IPHONE_11_PRO, 0x920A: 4.25, 0xA434: "iPhone 11 Pro back triple camera 4.25mm f/1.8"}
ULTRA_WIDE = {
    0x010F: "Apple",
    0x0110: "iPhone 11",
    0xA432: (1.54, 4.25, 1.8, 2.4),
    0x920A: 1.54,
    0xA434: "iPhone 11 back dual wide camera 1.54mm f/2.4",
}


def _on_diagonal(f35: float) -> float:
    return f35 * math.hypot(W, H) / FULL_FRAME_DIAGONAL_MM


def test_the_telephoto_reads_its_own_35mm_tag_not_the_main_sensor() -> None:
    got = focal_from_tags({**TELE, 0xA405: 52}, W, H, sensor_db="")
    assert got is not None
    # before: the main sensor's 4200 px mixed with the tag's 6057 px, exif-conflict +/- 19 %
    assert got.source == "exif-35mm"
    assert got.focal_px == pytest.approx(_on_diagonal(52))
    assert got.sigma_rel == pytest.approx(0.04)
    assert len(got.warnings) == 1
    assert "telephoto camera" in got.warnings[0]
    assert "not used" in got.warnings[0]
    assert [r[0] for r in got.readings] == ["exif-35mm"]


def test_the_telephoto_without_a_35mm_tag_gets_no_prior(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger="camloc_geo.exif"):
        got = focal_from_tags(TELE, W, H, sensor_db="")
    assert got is None  # before: 4200 px from the main camera's sensor, 31 % short
    assert "telephoto camera" in caplog.text


def test_the_main_camera_of_a_triple_module_keeps_the_table() -> None:
    got = focal_from_tags({**MAIN, 0xA405: 26}, W, H, sensor_db="")
    assert got is not None
    assert got.source == "exif-sensor-table"
    assert got.focal_px == pytest.approx(4.25 / 5.76 * W)
    assert got.warnings == ()


def test_the_ultra_wide_is_not_read_on_the_main_sensor() -> None:
    got = focal_from_tags({**ULTRA_WIDE, 0xA405: 13}, W, H, sensor_db="")
    assert got is not None
    assert got.source == "exif-35mm"
    assert got.focal_px == pytest.approx(_on_diagonal(13))
    assert "ultra-wide camera" in got.warnings[0]


@pytest.mark.parametrize(
    "lens",
    [
        "iPhone 11 Pro front camera 2.71mm f/2.2",
        "iPhone X front TrueDepth camera 2.87mm f/2.2",
        "Pixel 7 Pro back telephoto camera 19mm f/3.5",
    ],
)
def test_words_in_the_lens_model_name_another_camera(lens: str) -> None:
    tags = {0x010F: "Apple", 0x0110: "iPhone 11 Pro", 0x920A: 2.71, 0xA434: lens, 0xA405: 23}
    got = focal_from_tags(tags, W, H, sensor_db="")
    assert got is not None
    assert got.source == "exif-35mm"  # before: the table's 1897 px came first
    assert "not used" in got.warnings[0]


def test_a_single_camera_phone_keeps_its_conflict() -> None:
    # the iPhone 4's one back camera: its 35 mm tag (35) and its lens on the table's sensor
    # (3.85 mm on 4.54 mm) disagree, and nothing says which is right
    tags = {
        0x010F: "Apple",
        0x0110: "iPhone 4",
        0x920A: 3.85,
        0xA405: 35,
        0xA434: "iPhone 4 back camera 3.85mm f/2.8",
        0xA432: (3.85, 3.85, 2.8, 2.8),
    }
    got = focal_from_tags(tags, 2592, 1936, sensor_db="")
    assert got is not None
    assert got.source == "exif-conflict"
    assert "one of several" not in got.warnings[0]


def test_a_conflict_on_a_phone_of_several_cameras_names_the_cause() -> None:
    # the main camera's lens, but a 35 mm tag far from it: still a conflict, its cause named
    got = focal_from_tags({**MAIN, 0xA405: 40}, W, H, sensor_db="")
    assert got is not None
    assert got.source == "exif-conflict"
    assert "names one of several cameras" in got.warnings[-1]


def test_the_lens_model_is_read_from_a_photo(tmp_path: Path) -> None:
    im = PIL_Image.new("RGB", (W // 8, H // 8), (128, 128, 128))
    exif = PIL_Image.Exif()
    exif[0x010F], exif[0x0110] = "Apple", "iPhone 11 Pro"
    sub = exif.get_ifd(0x8769)
    sub[0x920A], sub[0xA405] = 6.0, 52
    sub[0xA434] = TELE[0xA434]
    sub[0xA432] = (1.54, 6.0, 1.8, 2.4)
    path = tmp_path / "tele.jpg"
    im.save(path, exif=exif)
    got = focal_from_exif(path, sensor_db="")
    assert got is not None
    assert got.source == "exif-35mm"
    assert got.focal_px == pytest.approx(_on_diagonal(52) / 8, rel=1e-6)
    assert "telephoto camera" in got.warnings[0]


def test_a_duo_camera_named_alone_is_still_one_of_two() -> None:
    # an iPhone 7 Plus's telephoto as some apps write it: "iSight Duo", its own focal length
    # alone in LensSpecification; 6.6 mm on the main 4.89 mm sensor would be 47 mm
    tags = {
        0x010F: "Apple",
        0x0110: "iPhone 7 Plus",
        0x920A: 6.6,
        0xA405: 56,
        0xA434: "iPhone 7 Plus back iSight Duo camera 6.6mm f/2.8",
        0xA432: (6.6, 6.6, 2.8, 2.8),
    }
    got = focal_from_tags(tags, W, H, sensor_db="")
    assert got is not None
    assert got.source == "exif-35mm"
    assert got.focal_px == pytest.approx(_on_diagonal(56))
    assert "a telephoto camera's photo" in got.warnings[0]


def test_the_warning_reaches_the_vanishing_point_result(tmp_path: Path) -> None:
    # detect_vanishing_points(use_exif=True): the 35 mm tag is the prior, and the reason the
    # table was left out comes first among the result's warnings
    from test_autovp_failure_modes import corner_segments

    from camloc_geo.autovp import detect_vanishing_points

    segs, (w, h) = corner_segments(0, 0.0, seed=0)  # a corner seen at 700 px
    f35 = round(700.0 * FULL_FRAME_DIAGONAL_MM / math.hypot(w, h))
    im = PIL_Image.new("RGB", (w, h), (128, 128, 128))
    exif = PIL_Image.Exif()
    exif[0x010F], exif[0x0110] = "Apple", "iPhone 11 Pro"
    sub = exif.get_ifd(0x8769)
    sub[0x920A], sub[0xA405], sub[0xA434] = 6.0, f35, TELE[0xA434]
    sub[0xA432] = (1.54, 6.0, 1.8, 2.4)
    path = tmp_path / "tele.jpg"
    im.save(path, exif=exif)
    res = detect_vanishing_points(path, segments=segs, use_exif=True)
    assert res.focal_source == "exif-35mm"
    assert res.warnings[0].startswith("LensModel 'iPhone 11 Pro back triple camera 6mm f/2'")
    assert abs(math.log(res.focal_px / 700.0)) < 2.0 * res.focal_std_rel


def test_a_camera_that_is_not_a_phone_keeps_the_table(tmp_path: Path) -> None:
    # a compact's zoom at its long end (105 mm equivalent on its sensor), its LensModel
    # naming no back or front camera: the table's width is its own
    db = tmp_path / "sensors.txt"
    db.write_text("ACME Zoom 9;6.4\n", encoding="utf-8")
    tags = {0x010F: "ACME", 0x0110: "Zoom 9", 0x920A: 19.4, 0xA434: "ACME camera zoom lens"}
    got = focal_from_tags(tags, 1600, 1200, sensor_db=str(db), bundled_table=False)
    assert got is not None
    assert got.source == "exif-sensor-table"
    assert got.focal_px == pytest.approx(19.4 / 6.4 * 1600)


def test_the_warning_reaches_the_api_result(tmp_path: Path) -> None:
    # api.vanishing_points(use_exif=True) reads the EXIF from the file before loading it; the
    # readings' warnings were dropped there (stop 42): the telephoto's reason must reach the
    # result's warnings, first, as detect_vanishing_points puts it given the path
    import cv2
    import numpy as np
    from test_autovp_failure_modes import corner_segments

    from camloc_geo import api

    segs, (w, h) = corner_segments(0, 0.0, seed=0)
    f35 = round(700.0 * FULL_FRAME_DIAGONAL_MM / math.hypot(w, h))
    canvas = np.full((h, w, 3), 200, np.uint8)
    for x0, y0, x1, y1 in np.asarray(segs, float):
        cv2.line(canvas, (round(x0), round(y0)), (round(x1), round(y1)), (20, 20, 20), 2)
    im = PIL_Image.fromarray(canvas)
    exif = PIL_Image.Exif()
    exif[0x010F], exif[0x0110] = "Apple", "iPhone 11 Pro"
    sub = exif.get_ifd(0x8769)
    sub[0x920A], sub[0xA405], sub[0xA434] = 6.0, f35, TELE[0xA434]
    sub[0xA432] = (1.54, 6.0, 1.8, 2.4)
    path = tmp_path / "tele.jpg"
    im.save(path, exif=exif, quality=95)
    res = api.vanishing_points(path, use_exif=True)
    assert res.focal_source == "exif-35mm"
    assert res.warnings[0].startswith("LensModel 'iPhone 11 Pro back triple camera 6mm f/2'")
    assert sum("LensModel" in w for w in res.warnings) == 1
