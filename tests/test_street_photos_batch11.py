"""benchmarks/street_photos.json, batch 11 (stop 42): a fresh held-out batch, manifest only.

These tests read the manifest (and, where ``benchmarks/fetch_real_photos.sh`` has fetched the
photos, their EXIF); none of them runs a vanishing-point fit on the photos: batch 11 is measured
once, by the integrator, with the merged code.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import pytest

PIL_Image = pytest.importorskip("PIL.Image")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
vp_real = pytest.importorskip("vp_real")

HALF = "held-out-5"
SET = "street-photos-held-out-5"
VIEWS = {"level", "looking-up", "looking-down"}
#: Phone models of batch 11 (EXIF ``Model``).
PHONES = {
    "iPhone 4S",
    "iPhone 5s",
    "iPhone 6",
    "iPhone 7",
    "iPhone 13",
    "iPhone 13 Pro",
    "iPhone 11 Pro",
    "SM-A528B",
    "ONEPLUS A3003",
    "Pixel 3",
}
#: Compact cameras of batch 11 (EXIF ``Model``).
COMPACTS = {
    "Canon PowerShot SX100 IS",
    "Canon PowerShot A70",
    "Canon PowerShot A640",
    "KODAK EASYSHARE Z1012 IS Digital Camera",
}
#: The iPhone 4S's main camera: its lens (EXIF FocalLength) over 3264 columns of 1.4 um.
IPHONE_4S_LENS_MM = 4.28
IPHONE_4S_WIDTH_MM = 4.57


def _manifest() -> dict[str, object]:
    return json.loads(vp_real.STREET_PHOTOS.read_text(encoding="utf-8"))


def _batch11() -> list[dict[str, object]]:
    return [p for p in _manifest()["photos"] if p["batch"] == 11]  # type: ignore[index]


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _truth_ratio(p: dict[str, object]) -> float | None:
    """The manifest truth over the longer side, where the manifest gives one."""
    t = p.get("truth")
    if not t:
        return None
    w, h = p["size"]  # type: ignore[misc]
    f = vp_real.sensor_focal_truth_px(t["focal_mm"], t["sensor_width_mm"], (w, h))  # type: ignore[index]
    return float(f) / max(w, h)


def test_batch_11_is_a_fresh_set_held_out_whole() -> None:
    photos = _manifest()["photos"]
    fresh = _batch11()
    assert len(fresh) >= 30
    assert {p["half"] for p in fresh} == {HALF}
    assert all(str(p["file"]).startswith(f"{SET}/") for p in fresh)
    # no photo of an earlier batch again: not by content, not by source file
    earlier = [p for p in photos if p["batch"] != 11]  # type: ignore[index]
    assert not {p["sha256"] for p in fresh} & {p["sha256"] for p in earlier}
    assert not {(p["repo"], p["path"]) for p in fresh} & {(p["repo"], p["path"]) for p in earlier}
    assert len({p["sha256"] for p in fresh}) == len(fresh)
    for p in fresh:
        assert len(str(p["commit"])) == 40
        assert len(str(p["sha256"])) == 64
        assert "opensfm" not in str(p["repo"]).lower()  # kept for independent checking
    # its own set, loaded only by its own name, summarised by view
    assert HALF in vp_real.STREET_PHOTO_FRESH_HALVES
    assert vp_real.street_photo_set(HALF) == SET
    assert SET in vp_real.SCENE_SETS
    assert vp_real.street_photo_halves({SET}) == (HALF,)
    assert HALF not in vp_real.street_photo_halves({"street-photos"})
    assert HALF not in vp_real.street_photo_halves({"street-photos-held-out-4"})
    default_sets = {"strecha", "sceaux", "perrot", "lund", "street-photos", "exif", "yud"}
    assert HALF not in vp_real.street_photo_halves(default_sets)


def test_batch_11_views_cameras_and_sources() -> None:
    fresh = _batch11()
    views = [p["view"] for p in fresh]
    assert set(views) == VIEWS  # each read from the photo before any result
    assert views.count("level") >= len(fresh) // 2  # the case first
    assert views.count("looking-up") >= 5  # the second check
    assert views.count("looking-down") >= 3
    subjects = [p["subject"] for p in fresh]  # also read from the photo before any result
    assert set(subjects) == {"street", "building", "city"}
    assert subjects.count("street") >= 10  # a street, square or path, looked along
    cameras = [str(p["camera"]) for p in fresh]
    assert set(cameras) <= PHONES | COMPACTS | {
        "ILCE-6400",
        "ILCE-6000",
        "NIKON D90",
        "NIKON D7000",
        "Canon EOS Kiss X4",
    }
    handheld = [c for c in cameras if c in PHONES | COMPACTS]
    assert len(handheld) >= len(fresh) // 2  # phones and compacts first, as the graders' photos
    assert len([c for c in cameras if c in PHONES]) >= 10
    per_repo: dict[str, int] = {}
    for p in fresh:
        per_repo[str(p["repo"])] = per_repo.get(str(p["repo"]), 0) + 1
        assert p["scene"]
    assert len(per_repo) >= 15
    assert max(per_repo.values()) <= 6


def test_batch_11_truths_are_in_range_and_name_their_source() -> None:
    fresh = _batch11()
    near_one = 0
    for p in fresh:
        w, h = p["size"]  # type: ignore[misc]
        ratio = _truth_ratio(p)
        if ratio is not None:
            assert "http" in p["truth"]["source"], p["file"]  # type: ignore[index]
            assert 0.6 < ratio < 2.6, p["file"]
            near_one += 0.9 <= ratio <= 1.1
        else:  # the 35 mm tag or focal-plane resolution: a 4:3 or 3:2 frame, not cropped
            aspect = max(w, h) / min(w, h)
            assert min(abs(aspect - 4 / 3), abs(aspect - 3 / 2)) < 0.01, p["file"]
        if abs(max(w, h) / min(w, h) - 16 / 9) < 0.01:  # a 16:9 mode: the lens and the sensor
            assert ratio is not None, p["file"]
    assert near_one >= 6  # the iPhone 4S's at 0.937, like issue 24's phone at 0.97


def test_batch_11_iphone_4s_truth_is_the_pixel_pitch_not_the_tag() -> None:
    # the iPhone 4S writes a 35 mm tag of 35 mm (1.011 times the longer side on its 4:3
    # frame); its 4.28 mm lens over 3264 columns of 1.4 um gives 0.937: the tag is 8 % high,
    # so every iPhone 4S photo carries the lens-and-sensor truth
    fresh = [p for p in _batch11() if p["camera"] == "iPhone 4S"]
    assert len(fresh) == 6
    for p in fresh:
        t = p["truth"]  # type: ignore[index]
        assert t["focal_mm"] == IPHONE_4S_LENS_MM
        assert t["sensor_width_mm"] == pytest.approx(3264 * 1.4e-3, abs=0.001)
        assert _truth_ratio(p) == pytest.approx(0.937, abs=0.001)
        tag = 35.0 * (3264**2 + 2448**2) ** 0.5 / 43.267 / 3264
        assert tag / 0.937 == pytest.approx(1.079, abs=0.003)


def test_fetched_batch_11_matches_the_manifest() -> None:
    # where benchmarks/fetch_real_photos.sh has fetched it (CAMLOC_PHOTO_SETS=
    # street-photos-held-out-5): every photo present with its pinned content and size, its
    # camera and lens the ones the manifest names; only EXIF is read here
    folder = vp_real.PHOTOS / SET
    if not folder.is_dir():
        pytest.skip(
            "batch 11 is not fetched: run CAMLOC_PHOTO_SETS=street-photos-held-out-5 "
            "benchmarks/fetch_real_photos.sh"
        )
    fresh = _batch11()
    for p in fresh:
        path = vp_real.PHOTOS / str(p["file"])
        assert path.is_file(), p["file"]
        assert _sha(path) == p["sha256"], p["file"]
        with PIL_Image.open(path) as im:
            assert list(im.size) == p["size"]
            exif = im.getexif()
            assert str(exif.get(0x0110)).strip("\x00 ") == p["camera"]
            assert exif.get(0x0112) in (None, 0, 1), p["file"]  # stored upright
            focal_mm = exif.get_ifd(0x8769).get(0x920A)
        if p.get("truth"):
            assert float(focal_mm) == pytest.approx(p["truth"]["focal_mm"], abs=0.01)  # type: ignore[index]
    rows = vp_real.load_street_photos(vp_real.PHOTOS, halves=(HALF,))
    assert len(rows) == len(fresh)
    assert {r["view"] for r in rows} == VIEWS
    assert {r["set"] for r in rows} == {SET}
    for r in rows:
        w, h = r["size"]
        assert 0.6 < r["f"] / max(w, h) < 2.6
