"""benchmarks/vp_real.py: the handheld street photos (manifest and loader)."""

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


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_manifest_halves_follow_the_fixed_rule() -> None:
    # the rule stated in the manifest: within each batch, sorted by sha256, every other one
    # (1st, 3rd, ...) dev (a later batch leaves the halves of the earlier ones as they were)
    doc = json.loads(vp_real.STREET_PHOTOS.read_text(encoding="utf-8"))
    photos = doc["photos"]
    assert len(photos) >= 70
    shas = [p["sha256"] for p in photos]
    assert len(set(shas)) == len(shas)
    assert len({p["file"] for p in photos}) == len(photos)
    assert len({Path(p["file"]).name for p in photos}) == len(photos)  # the run's names
    batches = sorted({p["batch"] for p in photos})
    assert batches[:8] == [1, 2, 3, 4, 5, 6, 7, 8]
    for batch in batches[:7]:  # batches 8 on are fresh held-out batches, held out whole
        ordered = sorted((p for p in photos if p["batch"] == batch), key=lambda p: p["sha256"])
        assert [p["half"] for p in ordered] == [
            "dev" if i % 2 == 0 else "held-out" for i in range(len(ordered))
        ]
    fresh_folder = {
        8: "street-photos-held-out-2/",
        9: "street-photos-held-out-3/",
        10: "street-photos-held-out-4/",
        11: "street-photos-held-out-5/",
    }
    for p in photos:
        assert len(p["commit"]) == 40
        folder = "street-photos/" if p["batch"] < 8 else fresh_folder[p["batch"]]
        assert p["file"].startswith(folder)
    # every fresh half is a set the run summarises by view
    for half in vp_real.STREET_PHOTO_FRESH_HALVES:
        assert vp_real.street_photo_set(half) in vp_real.SCENE_SETS


def test_fresh_batch_is_held_out_whole_in_a_set_of_its_own() -> None:
    # batch 8 (stop 39): all held out, in its own folder, each with the view read from it
    doc = json.loads(vp_real.STREET_PHOTOS.read_text(encoding="utf-8"))
    fresh = [p for p in doc["photos"] if p["batch"] == 8]
    assert len(fresh) >= 30
    assert {p["half"] for p in fresh} == {"held-out-2"}
    assert {p["view"] for p in fresh} <= {"level", "looking-up", "looking-down"}
    assert sum(p["view"] == "looking-up" for p in fresh) >= 3
    # a dozen sources, none of them more than 12 photos (at most 3 or so of one place)
    per_repo: dict[str, int] = {}
    for p in fresh:
        per_repo[p["repo"]] = per_repo.get(p["repo"], 0) + 1
    assert len(per_repo) >= 10
    assert max(per_repo.values()) <= 12
    assert vp_real.street_photo_set("held-out-2") == "street-photos-held-out-2"
    assert vp_real.street_photo_set("dev") == "street-photos"
    # "street-photos" (and so the default --sets) never loads it: only its own name does
    assert vp_real.street_photo_halves({"street-photos"}) == ("dev", "held-out")
    assert vp_real.street_photo_halves({"street-photos-held-out"}) == ("held-out",)
    assert vp_real.street_photo_halves({"street-photos-held-out-2"}) == ("held-out-2",)
    assert vp_real.street_photo_halves({"yud", "lund"}) == ()
    default_sets = {"strecha", "sceaux", "perrot", "lund", "street-photos", "exif", "yud"}
    assert "held-out-2" not in vp_real.street_photo_halves(default_sets)


def test_fresh_batch_9_is_phones_held_out_whole_with_views() -> None:
    # batch 9 (stop 40): phones only, held out whole in a set of its own, each view read
    # from the photo before any result, at most two views of one place, a cited truth
    # wherever the 35 mm tag does not fit the frame
    doc = json.loads(vp_real.STREET_PHOTOS.read_text(encoding="utf-8"))
    fresh = [p for p in doc["photos"] if p["batch"] == 9]
    assert len(fresh) >= 24  # 18 in stop 40's first round, 6 more in its second
    assert {p["half"] for p in fresh} == {"held-out-3"}
    assert all(p["file"].startswith("street-photos-held-out-3/") for p in fresh)
    views = [p["view"] for p in fresh]
    assert set(views) <= {"level", "looking-up", "looking-down"}
    assert views.count("level") >= len(fresh) // 2  # the issue's case first
    phones = ("iPhone", "Pixel", "SM-", "ONEPLUS")
    assert all(p["camera"].startswith(phones) for p in fresh)
    per_source: dict[str, int] = {}
    for p in fresh:
        per_source[p["repo"]] = per_source.get(p["repo"], 0) + 1
    assert max(per_source.values()) <= 2
    for p in fresh:
        w, h = p["size"]
        aspect = max(w, h) / min(w, h)
        if abs(aspect - 4 / 3) > 0.01:  # a 16:9 mode: only with a lens-and-sensor truth
            assert p.get("truth"), p["file"]
        if p.get("truth"):
            t = p["truth"]
            assert "http" in t["source"]
            f = vp_real.sensor_focal_truth_px(t["focal_mm"], t["sensor_width_mm"], (w, h))
            assert 0.6 < f / max(w, h) < 1.0  # a phone's main camera
    assert vp_real.street_photo_set("held-out-3") == "street-photos-held-out-3"
    assert "street-photos-held-out-3" in vp_real.SCENE_SETS
    assert vp_real.street_photo_halves({"street-photos-held-out-3"}) == ("held-out-3",)
    assert vp_real.street_photo_halves({"street-photos-held-out-2"}) == ("held-out-2",)
    assert vp_real.street_photo_halves({"street-photos"}) == ("dev", "held-out")


def test_batch_9_leaves_out_the_xperia_z2_set_whose_truth_is_not_pinned_down() -> None:
    # The Xperia Z2's 16:9 8 MP photos (3840x2160, EXIF FocalLength 4.9 mm, no 35 mm tag)
    # resample the sensor's full 5248-column width, so f/W is the 4:3 frame's; but the two
    # published widths for it disagree by far more than the 3 % a pinned truth needs:
    # Sony's 27 mm equivalent on the 4:3 diagonal and TechSpot's 1.1 um pixels.
    size = (3840, 2160)
    width_27mm = 4.9 * 43.27 / 27.0 * 0.8  # 4:3 diagonal -> width, mm
    width_pitch = 5248 * 1.1e-3
    f_a = vp_real.sensor_focal_truth_px(4.9, width_27mm, size) / 3840
    f_b = vp_real.sensor_focal_truth_px(4.9, width_pitch, size) / 3840
    assert f_a == pytest.approx(0.780, abs=0.002)
    assert f_b == pytest.approx(0.849, abs=0.002)
    assert abs(f_b / f_a - 1.0) > 0.03  # so none of them is pinned
    doc = json.loads(vp_real.STREET_PHOTOS.read_text(encoding="utf-8"))
    fresh = [p for p in doc["photos"] if p["batch"] == 9]
    assert not [p for p in fresh if p["camera"].startswith("D65")]  # the Z2's model codes
    assert "Xperia Z2" in doc["about"]
    assert "9 %" in doc["about"]
    # the second round's photos: a 4:3 main-camera frame each, the 35 mm tag as truth
    second = {
        "rushk014/image-autostitch",
        "dominathan/Photos-for-Calvin",
        "shortstheory/cis581-3a",
        "karahannibal/karahannibal.github.io",
        "mwomick/computational-photography",
    }
    added = [p for p in fresh if p["repo"] in second]
    assert len(added) == 6
    for p in added:
        w, h = p["size"]
        assert max(w, h) / min(w, h) == pytest.approx(4 / 3, abs=0.01)
        assert "truth" not in p


def test_loader_pins_content_and_reads_the_exif_truth(tmp_path: Path) -> None:
    photos = tmp_path / "photos"
    a = _jpeg(photos / "street-photos" / "x" / "a.jpg", (640, 480), {0xA405: 28})
    b = _jpeg(photos / "street-photos" / "x" / "b.jpg", (640, 480), {0xA405: 50})
    c = _jpeg(photos / "street-photos" / "x" / "c.jpg", (640, 480), {})  # no focal length
    entries = [
        {"file": "street-photos/x/a.jpg", "sha256": _sha(a), "half": "dev"},
        {"file": "street-photos/x/b.jpg", "sha256": _sha(b), "half": "held-out"},
        {"file": "street-photos/x/c.jpg", "sha256": _sha(c), "half": "dev"},
        {"file": "street-photos/x/gone.jpg", "sha256": "0" * 64, "half": "dev"},
        {"file": "street-photos/x/a.jpg", "sha256": "f" * 64, "half": "dev"},  # changed
    ]
    manifest = tmp_path / "m.json"
    manifest.write_text(json.dumps({"photos": entries}), encoding="utf-8")
    both = vp_real.load_street_photos(photos, manifest)
    assert [(t["name"], t["half"]) for t in both] == [
        ("street-photos/a.jpg", "dev"),
        ("street-photos/b.jpg", "held-out"),
    ]
    t = both[0]
    assert t["set"] == "street-photos"
    assert t["f"] == pytest.approx(28.0 * 800.0 / 43.267, rel=1e-3)  # 35 mm tag, 640x480
    assert t["exif"] is True
    assert t["up"] is None
    assert t["size"] == (640, 480)
    dev = vp_real.load_street_photos(photos, manifest, ("dev",))
    assert [t["name"] for t in dev] == ["street-photos/a.jpg"]
    held = vp_real.load_street_photos(photos, manifest, ("held-out",))
    assert [t["f"] for t in held] == [pytest.approx(50.0 * 800.0 / 43.267, rel=1e-3)]


def test_loader_serves_a_fresh_half_as_its_own_set_named_by_view(tmp_path: Path) -> None:
    photos = tmp_path / "photos"
    a = _jpeg(photos / "street-photos" / "x" / "a.jpg", (640, 480), {0xA405: 28})
    u = _jpeg(photos / "street-photos-held-out-2" / "y" / "u.jpg", (480, 640), {0xA405: 26})
    v = _jpeg(photos / "street-photos-held-out-2" / "y" / "v.jpg", (640, 480), {0xA405: 35})
    entries = [
        {"file": "street-photos/x/a.jpg", "sha256": _sha(a), "half": "dev", "view": "level"},
        {
            "file": "street-photos-held-out-2/y/u.jpg",
            "sha256": _sha(u),
            "half": "held-out-2",
            "view": "looking-up",
        },
        {"file": "street-photos-held-out-2/y/v.jpg", "sha256": _sha(v), "half": "held-out-2"},
    ]
    manifest = tmp_path / "m.json"
    manifest.write_text(json.dumps({"photos": entries}), encoding="utf-8")
    # the default halves leave the fresh batch alone
    assert [t["name"] for t in vp_real.load_street_photos(photos, manifest)] == [
        "street-photos/a.jpg"
    ]
    fresh = vp_real.load_street_photos(photos, manifest, ("held-out-2",))
    assert [(t["set"], t["name"], t["half"]) for t in fresh] == [
        ("street-photos-held-out-2", "street-photos-held-out-2/looking-up/u.jpg", "held-out-2"),
        ("street-photos-held-out-2", "street-photos-held-out-2/v.jpg", "held-out-2"),
    ]
    assert fresh[0]["view"] == "looking-up"
    assert "view" not in fresh[1]
    assert fresh[0]["f"] == pytest.approx(26.0 * 800.0 / 43.267, rel=1e-3)
    assert fresh[0]["size"] == (480, 640)
    # the fresh set is summarised by view, as Lund is by scene
    assert "street-photos-held-out-2" in vp_real.SCENE_SETS


def test_fetch_script_copies_the_fresh_batch_alone_from_a_mirror(tmp_path: Path) -> None:
    # benchmarks/fetch_real_photos.sh with CAMLOC_PHOTO_SETS=street-photos-held-out-2: the
    # manifest's batch-8 files, from a local mirror's blobs at the pinned commit, sha256
    # checked; nothing else (curl is stubbed to fail: a test never reaches the internet)
    import shutil
    import subprocess

    if shutil.which("git") is None or shutil.which("bash") is None:
        pytest.skip("git and bash are needed")
    work = tmp_path / "src"
    good = _jpeg(work / "pics" / "good.jpg", (64, 48), {0xA405: 28})
    _jpeg(work / "pics" / "old.jpg", (64, 48), {0xA405: 50})
    env = {
        "PATH": f"{tmp_path / 'bin'}:/usr/bin:/bin",
        "HOME": str(tmp_path),
        "GIT_AUTHOR_NAME": "t",
        "GIT_AUTHOR_EMAIL": "t@t",
        "GIT_COMMITTER_NAME": "t",
        "GIT_COMMITTER_EMAIL": "t@t",
    }
    (tmp_path / "bin").mkdir()
    (tmp_path / "bin" / "curl").write_text("#!/bin/sh\nexit 22\n", encoding="utf-8")
    (tmp_path / "bin" / "curl").chmod(0o755)
    for cmd in (["init", "-q"], ["add", "-A"], ["commit", "-qm", "photos"]):
        subprocess.run(["git", *cmd], cwd=work, env=env, check=True)
    commit = subprocess.run(
        ["git", "rev-parse", "HEAD"], cwd=work, env=env, check=True, capture_output=True, text=True
    ).stdout.strip()
    mirror = tmp_path / "mirror"
    subprocess.run(
        ["git", "clone", "-q", "--bare", str(work), str(mirror / "me+pics" / "repo")],
        env=env,
        check=True,
    )
    bench = tmp_path / "bench"
    bench.mkdir()
    script = Path(__file__).resolve().parents[1] / "benchmarks" / "fetch_real_photos.sh"
    shutil.copy(script, bench / "fetch_real_photos.sh")
    entry = {"repo": "me/pics", "commit": commit, "half": "held-out-2", "batch": 8}
    photos = [
        dict(
            entry,
            file="street-photos-held-out-2/me/good.jpg",
            path="pics/good.jpg",
            sha256=_sha(good),
        ),
        dict(
            entry, file="street-photos-held-out-2/me/bad.jpg", path="pics/old.jpg", sha256="0" * 64
        ),  # another content than pinned: not kept
        dict(
            entry,
            file="street-photos/me/old.jpg",
            path="pics/old.jpg",
            half="dev",
            batch=1,
            sha256=_sha(work / "pics" / "old.jpg"),
        ),
    ]
    (bench / "street_photos.json").write_text(json.dumps({"photos": photos}), encoding="utf-8")
    dest = tmp_path / "dest"
    run = subprocess.run(
        ["bash", str(bench / "fetch_real_photos.sh")],
        env=dict(
            env,
            CAMLOC_PHOTOS_DIR=str(dest),
            CAMLOC_MIRROR_DIR=str(mirror),
            CAMLOC_PHOTO_SETS="street-photos-held-out-2",
        ),
        capture_output=True,
        text=True,
        check=True,
    )
    got = sorted(p.relative_to(dest).as_posix() for p in dest.rglob("*") if p.is_file())
    assert got == ["street-photos-held-out-2/me/good.jpg"]
    assert _sha(dest / got[0]) == _sha(good)
    assert "1 not fetched" in run.stderr


def test_fetched_street_photos_match_the_manifest() -> None:
    # where benchmarks/fetch_real_photos.sh has copied them: every one loads, with a truth
    photos = vp_real.PHOTOS
    if not (photos / "street-photos").is_dir():
        pytest.skip(
            "the street photos are not fetched: run benchmarks/fetch_real_photos.sh "
            "(ianare/exif-samples, drewnoakes/metadata-extractor-images)"
        )
    rows = vp_real.load_street_photos(photos)
    doc = json.loads(vp_real.STREET_PHOTOS.read_text(encoding="utf-8"))
    pinned = [p for p in doc["photos"] if p["half"] in vp_real.STREET_PHOTO_HALVES]
    assert len(rows) == len(pinned)
    for half in vp_real.STREET_PHOTO_FRESH_HALVES:  # the fresh batches: their EXIF only
        if (photos / vp_real.street_photo_set(half)).is_dir():
            fresh = vp_real.load_street_photos(photos, halves=(half,))
            assert len(fresh) == sum(p["half"] == half for p in doc["photos"])
            rows = rows + fresh
    for t in rows:
        w, h = t["size"]
        assert 0.4 < t["f"] / max(w, h) < 5.0


def test_issue24_bars_judge_the_three_figures() -> None:
    stripped = {"n_images": 29, "share_focal_within_10pct": 0.76, "n_confidently_wrong": 1}
    kept = {"n_images": 29, "share_focal_within_10pct": 0.93, "n_confidently_wrong": 0}
    bars = vp_real.issue24_bars(stripped, kept)
    assert bars["stripped_within_10pct"]["met"] is True
    assert bars["stripped_confidently_wrong_share"]["value"] == pytest.approx(1 / 29)
    assert bars["stripped_confidently_wrong_share"]["met"] is True
    assert bars["kept_within_10pct"]["met"] is False
    two_wrong = dict(stripped, n_confidently_wrong=2, share_focal_within_10pct=0.5)
    bars = vp_real.issue24_bars(two_wrong, None)
    assert bars["stripped_confidently_wrong_share"]["met"] is False
    assert bars["stripped_within_10pct"]["met"] is False
    assert bars["kept_within_10pct"] == {"value": None, "bar": 0.95, "met": None}


def test_run_loads_the_fresh_set_only_when_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # vp_real.main: "--sets street-photos-held-out-2" hands exactly batch 8's photos to the
    # estimation (stubbed here: nothing is estimated), "--sets street-photos" none of them
    photos = tmp_path / "photos"
    a = _jpeg(photos / "street-photos" / "x" / "a.jpg", (640, 480), {0xA405: 28})
    u = _jpeg(photos / "street-photos-held-out-2" / "y" / "u.jpg", (640, 480), {0xA405: 26})
    entries = [
        {"file": "street-photos/x/a.jpg", "sha256": _sha(a), "half": "held-out"},
        {
            "file": "street-photos-held-out-2/y/u.jpg",
            "sha256": _sha(u),
            "half": "held-out-2",
            "view": "looking-up",
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
        vp_real.main([*args, "--sets", "street-photos-held-out-2"])
    assert got.value.args[0] == ["street-photos-held-out-2/looking-up/u.jpg"]
    with pytest.raises(LoadedError) as got:
        vp_real.main([*args, "--sets", "street-photos"])
    assert got.value.args[0] == ["street-photos/a.jpg"]
    # batch 9's set the same way: only its own name loads it, by view
    v = _jpeg(photos / "street-photos-held-out-3" / "z" / "v.jpg", (640, 480), {0xA405: 26})
    entries.append(
        {
            "file": "street-photos-held-out-3/z/v.jpg",
            "sha256": _sha(v),
            "half": "held-out-3",
            "view": "level",
        }
    )
    manifest.write_text(json.dumps({"photos": entries}), encoding="utf-8")
    with pytest.raises(LoadedError) as got:
        vp_real.main([*args, "--sets", "street-photos-held-out-3"])
    assert got.value.args[0] == ["street-photos-held-out-3/level/v.jpg"]
    with pytest.raises(LoadedError) as got:
        vp_real.main([*args, "--sets", "street-photos-held-out-2"])
    assert got.value.args[0] == ["street-photos-held-out-2/looking-up/u.jpg"]


def test_sensor_rule_gives_the_lens_over_the_sensor_width() -> None:
    # the truth of a 16:9 phone photo whose 35 mm tag is written for the 4:3 frame: the
    # Galaxy Note 3 (4.13 mm lens, 4128 columns of 1.12 um) at 4128x2322 and resized
    f = vp_real.sensor_focal_truth_px(4.13, 4128 * 0.00112, (4128, 2322))
    assert f == pytest.approx(4.13 / 0.00112, rel=1e-9)  # 3687.5 px: the pixel pitch
    assert vp_real.sensor_focal_truth_px(4.13, 4.62336, (2322, 4128)) == pytest.approx(f)
    assert vp_real.sensor_focal_truth_px(4.13, 4.62336, (1032, 580)) == pytest.approx(f / 4)
    # the 35 mm tag (31 mm) read on the 16:9 diagonal is 8.7 % below it; read on the
    # diagonal of the 4:3 frame it was written for, it agrees within its rounding
    tag_16_9 = 31.0 * (4128**2 + 2322**2) ** 0.5 / 43.267
    tag_4_3 = 31.0 * (4128**2 + 3096**2) ** 0.5 / 43.267
    assert f / tag_16_9 == pytest.approx(1.087, abs=0.002)
    assert f / tag_4_3 == pytest.approx(1.0, abs=0.005)
    with pytest.raises(ValueError, match="must be > 0"):
        vp_real.sensor_focal_truth_px(0.0, 4.6, (640, 480))


def test_manifest_truth_replaces_the_exif_truth(tmp_path: Path) -> None:
    photos = tmp_path / "photos"
    a = _jpeg(photos / "street-photos" / "x" / "a.jpg", (640, 360), {0xA405: 31})  # 16:9
    b = _jpeg(photos / "street-photos" / "x" / "b.jpg", (640, 360), {0xA405: 31})
    truth = {"focal_mm": 4.13, "sensor_width_mm": 4.62336, "source": "a teardown"}
    entries = [
        {"file": "street-photos/x/a.jpg", "sha256": _sha(a), "half": "dev", "truth": truth},
        {"file": "street-photos/x/b.jpg", "sha256": _sha(b), "half": "dev"},
    ]
    manifest = tmp_path / "m.json"
    manifest.write_text(json.dumps({"photos": entries}), encoding="utf-8")
    got = {t["name"]: t for t in vp_real.load_street_photos(photos, manifest)}
    sensor, tag = got["street-photos/a.jpg"], got["street-photos/b.jpg"]
    assert sensor["f"] == pytest.approx(4.13 / 4.62336 * 640, rel=1e-9)
    assert sensor["f_source"] == "exif-focal-mm+sensor-width"
    assert sensor["exif"] is True  # the EXIF-kept run still reads the photo's own tags
    assert tag["f"] == pytest.approx(31.0 * (640**2 + 360**2) ** 0.5 / 43.267, rel=1e-3)
    assert tag["f_source"] == "exif-35mm"
    assert sensor["f"] / tag["f"] == pytest.approx(1.087, abs=0.003)


def test_batch2_16_9_phone_truths_come_from_the_sensor() -> None:
    # stop 40: batch 2's 16:9 phone photos carry a cited lens-and-sensor truth, and that
    # truth is what the lens focal length over the sensor width gives (before -> after:
    # Note 3 0.822 -> 0.893, Mi A1 1.379 -> 1.498, Galaxy S5 0.823 -> 0.807 of the longer side)
    doc = json.loads(vp_real.STREET_PHOTOS.read_text(encoding="utf-8"))
    with_truth = {
        p["camera"]: p
        for p in doc["photos"]
        if p.get("truth") and p["batch"] < 9 and p["camera"] != "iPhone 4S"
    }
    assert set(with_truth) == {"SAMSUNG-SM-N900A", "SM-G900F", "Mi A1"}
    want = {"SAMSUNG-SM-N900A": 0.893, "SM-G900F": 0.807, "Mi A1": 1.498}
    for camera, p in with_truth.items():
        t = p["truth"]
        assert t["source"].count("http") >= 1
        rel = vp_real.sensor_focal_truth_px(t["focal_mm"], t["sensor_width_mm"], p["size"])
        assert rel / max(p["size"]) == pytest.approx(want[camera], abs=0.002)
        w, h = p["size"]
        assert max(w, h) / min(w, h) == pytest.approx(16 / 9, abs=0.01)


def test_fetch_script_takes_any_fresh_batch_by_name(tmp_path: Path) -> None:
    # CAMLOC_PHOTO_SETS="street-photos-held-out-3" copies batch 9's folder alone; naming
    # both fresh sets copies both (curl stubbed to fail: no internet)
    import shutil
    import subprocess

    if shutil.which("git") is None or shutil.which("bash") is None:
        pytest.skip("git and bash are needed")
    work = tmp_path / "src"
    p2 = _jpeg(work / "pics" / "two.jpg", (64, 48), {0xA405: 28})
    p3 = _jpeg(work / "pics" / "three.jpg", (64, 48), {0xA405: 26})
    env = {
        "PATH": f"{tmp_path / 'bin'}:/usr/bin:/bin",
        "HOME": str(tmp_path),
        "GIT_AUTHOR_NAME": "t",
        "GIT_AUTHOR_EMAIL": "t@t",
        "GIT_COMMITTER_NAME": "t",
        "GIT_COMMITTER_EMAIL": "t@t",
    }
    (tmp_path / "bin").mkdir()
    (tmp_path / "bin" / "curl").write_text("#!/bin/sh\nexit 22\n", encoding="utf-8")
    (tmp_path / "bin" / "curl").chmod(0o755)
    for cmd in (["init", "-q"], ["add", "-A"], ["commit", "-qm", "photos"]):
        subprocess.run(["git", *cmd], cwd=work, env=env, check=True)
    commit = subprocess.run(
        ["git", "rev-parse", "HEAD"], cwd=work, env=env, check=True, capture_output=True, text=True
    ).stdout.strip()
    mirror = tmp_path / "mirror"
    subprocess.run(
        ["git", "clone", "-q", "--bare", str(work), str(mirror / "me+pics" / "repo")],
        env=env,
        check=True,
    )
    bench = tmp_path / "bench"
    bench.mkdir()
    script = Path(__file__).resolve().parents[1] / "benchmarks" / "fetch_real_photos.sh"
    shutil.copy(script, bench / "fetch_real_photos.sh")
    photos = [
        {
            "repo": "me/pics",
            "commit": commit,
            "file": "street-photos-held-out-2/me/two.jpg",
            "path": "pics/two.jpg",
            "sha256": _sha(p2),
        },
        {
            "repo": "me/pics",
            "commit": commit,
            "file": "street-photos-held-out-3/me/three.jpg",
            "path": "pics/three.jpg",
            "sha256": _sha(p3),
        },
    ]
    (bench / "street_photos.json").write_text(json.dumps({"photos": photos}), encoding="utf-8")

    def fetched(sets: str, dest: Path) -> list[str]:
        subprocess.run(
            ["bash", str(bench / "fetch_real_photos.sh")],
            env=dict(
                env,
                CAMLOC_PHOTOS_DIR=str(dest),
                CAMLOC_MIRROR_DIR=str(mirror),
                CAMLOC_PHOTO_SETS=sets,
            ),
            capture_output=True,
            text=True,
            check=True,
        )
        return sorted(p.relative_to(dest).as_posix() for p in dest.rglob("*") if p.is_file())

    assert fetched("street-photos-held-out-3", tmp_path / "d3") == [
        "street-photos-held-out-3/me/three.jpg"
    ]
    assert fetched("street-photos-held-out-2 street-photos-held-out-3", tmp_path / "d23") == [
        "street-photos-held-out-2/me/two.jpg",
        "street-photos-held-out-3/me/three.jpg",
    ]
    assert fetched("yud", tmp_path / "none") == []


def test_iphone_4s_truths_come_from_the_sensor() -> None:
    # stop 40: the iPhone 4S writes a 35 mm tag of 35 mm (1.011 times the longer side) where
    # its 4.28 mm lens on a 3264 x 1.4 um = 4.570 mm wide sensor gives 0.937; all five of its
    # photos (batches 1-2, both halves) carry the sensor truth, cited, whatever their result
    doc = json.loads(vp_real.STREET_PHOTOS.read_text(encoding="utf-8"))
    phones = [p for p in doc["photos"] if p.get("camera") == "iPhone 4S" and p["batch"] < 8]
    assert len(phones) == 5
    assert {p["half"] for p in phones} == {"dev", "held-out"}
    # batch 11's six (stop 42) carry the same truth: tests/test_street_photos_batch11.py
    for p in phones:
        t = p["truth"]
        assert "anandtech" in t["source"]
        f_px = vp_real.sensor_focal_truth_px(t["focal_mm"], t["sensor_width_mm"], p["size"])
        assert f_px / max(p["size"]) == pytest.approx(0.937, abs=0.001)
        assert max(p["size"]) / min(p["size"]) == pytest.approx(4 / 3, abs=0.01)
