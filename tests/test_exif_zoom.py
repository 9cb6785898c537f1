"""``DigitalZoomRatio``: a digitally zoomed photo's focal length is the lens's times the ratio."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from camloc_geo.exif import FULL_FRAME_DIAGONAL_MM, focal_from_exif, focal_from_tags

PIL_Image = pytest.importorskip("PIL.Image")


def _on_diagonal(f35: float, w: int, h: int) -> float:
    return f35 * math.hypot(w, h) / FULL_FRAME_DIAGONAL_MM


@pytest.fixture
def acme_db(tmp_path: Path) -> str:
    db = tmp_path / "sensors.txt"
    db.write_text("ACME Snap 1;6.4\n", encoding="utf-8")  # a 6.4 x 4.8 mm sensor
    return str(db)


def test_the_lens_on_the_sensor_times_the_zoom(acme_db: str) -> None:
    tags = {0x920A: 4.8, 0x010F: "ACME", 0x0110: "Snap 1", 0xA404: 2.0}
    got = focal_from_tags(tags, 1600, 1200, sensor_db=acme_db, bundled_table=False)
    assert got is not None
    assert got.source == "exif-sensor-table"
    assert got.focal_px == pytest.approx(2.0 * 4.8 / 6.4 * 1600)  # before: 1200 px


def test_the_focal_plane_resolution_times_the_zoom() -> None:
    tags = {0x920A: 4.0, 0xA20E: 1000.0, 0xA210: 4, 0xA002: 4000, 0xA003: 3000, 0xA404: 1.5}
    got = focal_from_tags(tags, 4000, 3000, sensor_db="", bundled_table=False)
    assert got is not None
    assert got.source == "exif-focal-plane"
    assert got.focal_px == pytest.approx(1.5 * 4000.0)


def test_a_tag_that_includes_the_zoom_agrees_with_the_lens() -> None:
    # an iPhone SE (3rd generation), 2x zoomed in Camera.app (Hugin bug 2064625's tags):
    # 3.99 mm lens on the table's 4.89 mm sensor, zoom 1.951, 35 mm tag 55 (28 without)
    tags = {
        0x010F: "Apple",
        0x0110: "iPhone SE (3rd generation)",
        0x920A: 3.99,
        0xA404: 1.951,
        0xA405: 55,
        0xA434: "iPhone SE (3rd generation) back camera 3.99mm f/1.8",
        0xA432: (3.99, 3.99, 1.8, 1.8),
    }
    got = focal_from_tags(tags, 4032, 3024, sensor_db="")
    assert got is not None
    assert got.source == "exif-sensor-table"  # before: an exif-conflict of 3290 and 6406 px
    assert got.focal_px == pytest.approx(3.99 / 4.89 * 4032 * 1.951)
    assert got.focal_px == pytest.approx(_on_diagonal(55, 4032, 3024), rel=0.01)
    assert any("includes the 1.951x digital zoom" in n for n in got.notes)


def test_a_tag_that_leaves_the_zoom_out_is_multiplied(acme_db: str) -> None:
    # the lens's own 26 mm equivalent (4.8 mm on an 8 mm diagonal), zoom 2
    tags = {0x920A: 4.8, 0x010F: "ACME", 0x0110: "Snap 1", 0xA404: 2.0, 0xA405: 26}
    got = focal_from_tags(tags, 1600, 1200, sensor_db=acme_db, bundled_table=False)
    assert got is not None
    assert got.source == "exif-sensor-table"
    tag = {s: f for s, f, _ in got.readings}["exif-35mm"]
    assert tag == pytest.approx(2.0 * _on_diagonal(26, 1600, 1200))
    assert any("leaves out the 2x digital zoom" in n for n in got.notes)


def test_a_tag_alone_with_a_zoom_covers_both_readings() -> None:
    tags = {0xA404: 2.0, 0xA405: 26}
    got = focal_from_tags(tags, 1600, 1200, sensor_db="", bundled_table=False)
    assert got is not None
    assert got.source == "exif-35mm"
    for truth in (_on_diagonal(26, 1600, 1200), 2.0 * _on_diagonal(26, 1600, 1200)):
        assert abs(math.log(truth / got.focal_px)) <= got.sigma_rel  # each within 1 sigma
    assert 0.3 < got.sigma_rel < 0.4
    assert any("may include the 2x digital zoom" in n for n in got.notes)


@pytest.mark.parametrize("ratio", [0, 1, 1.0, float("nan"), 500.0])
def test_no_zoom_and_broken_ratios_change_nothing(ratio: float) -> None:
    tags = {0xA405: 26, 0xA404: ratio}
    got = focal_from_tags(tags, 1600, 1200, sensor_db="", bundled_table=False)
    assert got is not None
    assert got.focal_px == pytest.approx(_on_diagonal(26, 1600, 1200))
    assert got.sigma_rel == pytest.approx(0.04)


def test_the_zoom_is_read_from_a_photo(tmp_path: Path, acme_db: str) -> None:
    im = PIL_Image.new("RGB", (800, 600), (128, 128, 128))
    exif = PIL_Image.Exif()
    exif[0x010F], exif[0x0110] = "ACME", "Snap 1"
    sub = exif.get_ifd(0x8769)
    sub[0x920A], sub[0xA404] = 4.8, 2.5
    path = tmp_path / "zoomed.jpg"
    im.save(path, exif=exif)
    got = focal_from_exif(path, sensor_db=acme_db, bundled_table=False)
    assert got is not None
    assert got.focal_px == pytest.approx(2.5 * 4.8 / 6.4 * 800)
