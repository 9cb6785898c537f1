"""camloc_geo.exif: the focal length from a photo's EXIF tags."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from camloc_geo.exif import FULL_FRAME_DIAGONAL_MM, focal_from_exif, focal_from_tags

PIL_Image = pytest.importorskip("PIL.Image")


def _jpeg(path: Path, size: tuple[int, int], exif_tags: dict[int, object]) -> Path:
    im = PIL_Image.new("RGB", size, (128, 128, 128))
    exif = PIL_Image.Exif()
    sub = exif.get_ifd(0x8769)
    for k, v in exif_tags.items():
        if k in (0x010F, 0x0110):
            exif[k] = v
        else:
            sub[k] = v
    im.save(path, exif=exif)
    return path


def test_35mm_equivalent_uses_the_diagonal(tmp_path: Path) -> None:
    p = _jpeg(tmp_path / "a.jpg", (800, 600), {0xA405: 28})
    ex = focal_from_exif(p)
    assert ex is not None
    assert ex.source == "exif-35mm"
    assert ex.focal_px == pytest.approx(28.0 * 1000.0 / FULL_FRAME_DIAGONAL_MM, rel=1e-9)
    assert ex.sigma_rel == pytest.approx(0.04)


def test_focal_plane_resolution_scaled_to_a_resized_photo() -> None:
    # 4.0 mm lens, 1000 px per mm at capture (4000 px wide sensor of 4 mm), photo halved
    tags = {0x920A: 4.0, 0xA20E: 1000.0, 0xA210: 4, 0xA002: 4000, 0xA003: 3000}
    ex = focal_from_tags(tags, 2000, 1500)
    assert ex is not None
    assert ex.source == "exif-focal-plane"
    assert ex.focal_px == pytest.approx(2000.0)


def test_sensor_table(tmp_path: Path) -> None:
    db = tmp_path / "sensors.txt"
    db.write_text("Other Cam;5.0\nACME Snap 1;6.4\n", encoding="utf-8")
    tags = {0x920A: 4.8, 0x010F: "ACME", 0x0110: "Snap 1"}
    ex = focal_from_tags(tags, 1600, 1200, sensor_db=str(db))
    assert ex is not None
    assert ex.source == "exif-sensor-table"
    assert ex.focal_px == pytest.approx(4.8 / 6.4 * 1600)
    assert focal_from_tags(tags, 1600, 1200, sensor_db=str(tmp_path / "none.txt")) is None


def test_no_or_unusable_exif(tmp_path: Path) -> None:
    assert focal_from_exif(_jpeg(tmp_path / "b.jpg", (64, 48), {})) is None
    assert focal_from_tags({0x920A: 4.0}, 640, 480, sensor_db="") is None  # no sensor size
    assert focal_from_tags({0xA405: 0}, 640, 480) is None
    garbage = tmp_path / "c.jpg"
    garbage.write_bytes(b"not an image")
    assert focal_from_exif(garbage) is None
    assert focal_from_exif(tmp_path / "missing.jpg") is None


def test_exif_prior_decides_a_loose_focal(tmp_path: Path) -> None:
    """A frontal view fixes no focal length: the EXIF prior does, named in focal_source."""
    from camloc_geo.autovp import detect_vanishing_points

    f_true, w, h = 900.0, 1200, 800
    rng = np.random.default_rng(3)
    segs = []
    # verticals and horizontals of a fronto-parallel facade: both VPs at infinity
    for x in np.linspace(100, 1100, 14):
        segs.append([x, 150 + rng.normal(0, 0.2), x + rng.normal(0, 0.2), 650])
    for y in np.linspace(120, 680, 12):
        segs.append([80, y, 1120, y + rng.normal(0, 0.2)])
    # a few receding lines towards the centre
    for a in np.radians([20, 60, 120, 160, 200, 250, 290, 340]):
        segs.append(
            [
                600 + 60 * math.cos(a),
                400 + 60 * math.sin(a),
                600 + 300 * math.cos(a),
                400 + 300 * math.sin(a),
            ]
        )
    res = detect_vanishing_points(
        None,
        segments=np.array(segs, float),
        image_size=(w, h),
        focal_prior_px=f_true,
        focal_prior_sigma_rel=0.04,
        focal_prior_source="exif-35mm",
    )
    assert res.focal_source == "exif-35mm"
    assert res.focal_px == pytest.approx(f_true, rel=0.08)
    assert res.focal_std_rel <= 0.05
