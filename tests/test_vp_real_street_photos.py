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
    assert len(photos) >= 40
    shas = [p["sha256"] for p in photos]
    assert len(set(shas)) == len(shas)
    assert len({p["file"] for p in photos}) == len(photos)
    assert len({Path(p["file"]).name for p in photos}) == len(photos)  # the run's names
    batches = sorted({p["batch"] for p in photos})
    assert batches == [1, 2, 3, 4, 5, 6, 7]
    for batch in batches:
        ordered = sorted((p for p in photos if p["batch"] == batch), key=lambda p: p["sha256"])
        assert [p["half"] for p in ordered] == [
            "dev" if i % 2 == 0 else "held-out" for i in range(len(ordered))
        ]
    for p in photos:
        assert len(p["commit"]) == 40
        assert p["file"].startswith("street-photos/")


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
    assert len(rows) == len(doc["photos"])
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
