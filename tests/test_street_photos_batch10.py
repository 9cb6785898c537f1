"""benchmarks/street_photos.json, batch 10 (stop 41): a fresh held-out batch, manifest only.

These tests read the manifest (and, where ``benchmarks/fetch_real_photos.sh`` has fetched the
photos, their EXIF); none of them runs a vanishing-point fit on the photos: batch 10 is measured
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

from test_vp_real_loader import _jpeg  # noqa: E402  (an EXIF-tagged JPEG)

HALF = "held-out-4"
SET = "street-photos-held-out-4"
VIEWS = {"level", "looking-up", "looking-down"}
#: Phone models of batch 10 (EXIF ``Model``): Galaxy S8, S7, S7 edge and A70, a Pixel 6, iPhones.
PHONES = {
    "SM-G950U",
    "SM-G930F",
    "SM-G935T",
    "SM-A705FN",
    "Pixel 6",
    "iPhone 6",
    "iPhone 6s",
    "iPhone 7",
    "iPhone 11 Pro",
    "iPhone 13 Pro Max",
}
#: openMVG CameraSensorSizeDatabase rows (sensor width, mm) that batch 10's lens-only truths
#: cite, at commit 07da7acbf97348405cf859ce76a00ac642ba1fc5 of its sensor_database.csv.
OPENMVG_WIDTH_MM = {
    "Olympus Stylus 400": 5.75,
    "Nikon D3": 36.0,
    "Sony Cybershot DSC G1": 5.75,
    "Olympus E-10": 8.8,
    "Kyocera Finecam S3": 7.11,
    "Sony Cybershot DSC W170": 6.16,
    "Olympus C-40 Zoom": 7.11,
}


def _manifest() -> dict[str, object]:
    return json.loads(vp_real.STREET_PHOTOS.read_text(encoding="utf-8"))


def _batch10() -> list[dict[str, object]]:
    return [p for p in _manifest()["photos"] if p["batch"] == 10]  # type: ignore[index]


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_batch_10_is_a_fresh_set_held_out_whole() -> None:
    photos = _manifest()["photos"]
    fresh = _batch10()
    assert len(fresh) >= 40  # 29 in stop 41's first round, 11 in its second
    assert {p["half"] for p in fresh} == {HALF}
    assert all(str(p["file"]).startswith(f"{SET}/") for p in fresh)
    # no photo of an earlier batch again: not by content, not by source file
    earlier = [p for p in photos if p["batch"] != 10]  # type: ignore[index]
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
    assert HALF not in vp_real.street_photo_halves({"street-photos-held-out-3"})


def test_batch_10_views_cameras_and_sources() -> None:
    fresh = _batch10()
    views = [p["view"] for p in fresh]
    assert set(views) == VIEWS  # each read from the photo before any result
    assert views.count("level") >= len(fresh) // 2  # the case first
    assert views.count("looking-up") >= 8  # the second check
    assert views.count("looking-down") >= 5  # a webcam's usual view
    cameras = [str(p["camera"]) for p in fresh]
    phones = [c for c in cameras if c in PHONES]
    assert len(phones) >= 15
    assert len(fresh) - len(phones) >= 20  # compacts, DSLRs and a mirrorless too
    assert len(set(cameras)) >= 30
    per_repo: dict[str, int] = {}
    for p in fresh:
        per_repo[str(p["repo"])] = per_repo.get(str(p["repo"]), 0) + 1
        assert p["scene"]
    assert len(per_repo) >= 10
    assert max(per_repo.values()) <= 7


def test_batch_10_truths_are_in_range_and_name_their_source() -> None:
    fresh = _batch10()
    near_one = 0
    for p in fresh:
        w, h = p["size"]  # type: ignore[misc]
        t = p.get("truth")
        if t:
            assert "http" in t["source"], p["file"]
            f = vp_real.sensor_focal_truth_px(t["focal_mm"], t["sensor_width_mm"], (w, h))
            ratio = f / max(w, h)
            assert 0.6 < ratio < 2.6, p["file"]
            near_one += 0.9 <= ratio <= 1.05
        else:  # the 35 mm tag or focal-plane resolution: a 4:3 or 3:2 frame, not cropped
            aspect = max(w, h) / min(w, h)
            assert min(abs(aspect - 4 / 3), abs(aspect - 3 / 2)) < 0.01, p["file"]
    assert near_one >= 4  # like issue 24's phone at 0.97 times the longer side


def test_batch_10_galaxy_s8_square_truth_is_the_pixel_pitch() -> None:
    # the S8's in-camera 1:1 mode is the sensor's centre 3024 columns of 1.4 um: the lens
    # (4.25 mm) over 4.2336 mm is 1.004 times the side, where the 35 mm tag (26 mm, written
    # for the 4:3 frame) read on the square's diagonal gives 0.850, 15 % low
    s8 = [p for p in _batch10() if p["camera"] == "SM-G950U"]
    assert len(s8) == 4
    for p in s8:
        assert p["size"] == [3024, 3024]
        t = p["truth"]
        assert t["sensor_width_mm"] == pytest.approx(3024 * 1.4e-3)
        f = vp_real.sensor_focal_truth_px(t["focal_mm"], t["sensor_width_mm"], (3024, 3024))
        assert f / 3024 == pytest.approx(1.004, abs=0.001)
        tag_square = 26.0 * (2 * 3024**2) ** 0.5 / 43.267
        tag_4_3 = 26.0 * (4032**2 + 3024**2) ** 0.5 / 43.267
        assert tag_square / f == pytest.approx(0.847, abs=0.003)
        assert tag_4_3 / f == pytest.approx(1.0, abs=0.005)  # the tag fits the 4:3 frame


def test_batch_10_lens_only_truths_cite_the_openmvg_widths() -> None:
    lens_only = [p for p in _batch10() if p.get("truth") and "openMVG" in p["truth"]["source"]]
    assert len(lens_only) == 8
    for p in lens_only:
        t = p["truth"]
        assert "07da7acbf97348405cf859ce76a00ac642ba1fc5" in t["source"]
        row = [name for name in OPENMVG_WIDTH_MM if f",{name}," in t["source"]]
        assert len(row) == 1, p["file"]
        assert t["sensor_width_mm"] == OPENMVG_WIDTH_MM[row[0]]


def test_loader_takes_a_lens_only_photo_by_its_manifest_truth(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # FocalLength alone (no 35 mm tag, no focal-plane resolution, no sensor table): skipped
    # without a manifest truth, loaded with it at the lens over the sensor width
    monkeypatch.delenv("CAMLOC_SENSOR_DB", raising=False)
    photos = tmp_path / "photos"
    a = _jpeg(photos / SET / "x" / "a.jpg", (600, 450), {0x920A: 5.8})
    b = _jpeg(photos / SET / "x" / "b.jpg", (600, 450), {0x920A: 5.8})
    truth = {"focal_mm": 5.8, "sensor_width_mm": 5.75, "source": "a sensor table"}
    entries = [
        {"file": f"{SET}/x/a.jpg", "sha256": _sha(a), "half": HALF, "view": "level"},
        {"file": f"{SET}/x/b.jpg", "sha256": _sha(b), "half": HALF, "view": "level"},
    ]
    entries[1]["truth"] = truth
    manifest = tmp_path / "m.json"
    manifest.write_text(json.dumps({"photos": entries}), encoding="utf-8")
    rows = vp_real.load_street_photos(photos, manifest, (HALF,))
    assert [r["name"] for r in rows] == [f"{SET}/level/b.jpg"]
    assert rows[0]["f"] == pytest.approx(5.8 / 5.75 * 600)
    assert rows[0]["f_source"] == "exif-focal-mm+sensor-width"
    assert rows[0]["size"] == (600, 450)
    assert rows[0]["set"] == SET


def test_fetched_batch_10_matches_the_manifest() -> None:
    # where benchmarks/fetch_real_photos.sh has fetched it (CAMLOC_PHOTO_SETS=
    # street-photos-held-out-4): every photo present with its pinned content and size, its
    # EXIF lens focal length the one its truth names; only EXIF is read here
    folder = vp_real.PHOTOS / SET
    if not folder.is_dir():
        pytest.skip(
            "batch 10 is not fetched: run CAMLOC_PHOTO_SETS=street-photos-held-out-4 "
            "benchmarks/fetch_real_photos.sh"
        )
    fresh = _batch10()
    for p in fresh:
        path = vp_real.PHOTOS / str(p["file"])
        assert path.is_file(), p["file"]
        assert _sha(path) == p["sha256"], p["file"]
        with PIL_Image.open(path) as im:
            assert list(im.size) == p["size"]
            exif = im.getexif()
            focal_mm = exif.get_ifd(0x8769).get(0x920A)
            assert str(exif.get(0x0110)).strip("\x00 ") == p["camera"]
        if p.get("truth"):
            assert float(focal_mm) == pytest.approx(p["truth"]["focal_mm"], abs=0.01)
    rows = vp_real.load_street_photos(vp_real.PHOTOS, halves=(HALF,))
    assert len(rows) == len(fresh)
    assert {r["view"] for r in rows} == VIEWS
    for r in rows:
        w, h = r["size"]
        assert 0.6 < r["f"] / max(w, h) < 2.6


def test_run_loads_batch_10_only_by_its_own_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # vp_real.main: "--sets street-photos-held-out-4" hands exactly batch 10's photos to the
    # estimation (stubbed: nothing is estimated), named by view; the other sets' names do not
    photos = tmp_path / "photos"
    u = _jpeg(photos / SET / "y" / "u.jpg", (640, 480), {0xA405: 35})
    v = _jpeg(photos / "street-photos-held-out-3" / "z" / "v.jpg", (640, 480), {0xA405: 26})
    entries = [
        {"file": f"{SET}/y/u.jpg", "sha256": _sha(u), "half": HALF, "view": "looking-up"},
        {
            "file": "street-photos-held-out-3/z/v.jpg",
            "sha256": _sha(v),
            "half": "held-out-3",
            "view": "level",
        },
    ]
    manifest = tmp_path / "m.json"
    manifest.write_text(json.dumps({"photos": entries}), encoding="utf-8")

    class LoadedError(Exception):
        pass

    def stub(data: list[dict[str, object]], use_exif: bool, **_: object) -> None:
        raise LoadedError([str(t["name"]) for t in data])

    monkeypatch.setattr(vp_real, "run", stub)
    args = ["--drive-photos", str(photos), "--street-photos", str(manifest)]
    args += ["--out", str(tmp_path / "out")]
    with pytest.raises(LoadedError) as got:
        vp_real.main([*args, "--sets", SET])
    assert got.value.args[0] == [f"{SET}/looking-up/u.jpg"]
    with pytest.raises(LoadedError) as got:
        vp_real.main([*args, "--sets", "street-photos-held-out-3"])
    assert got.value.args[0] == ["street-photos-held-out-3/level/v.jpg"]
