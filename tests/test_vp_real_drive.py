"""benchmarks/vp_real.py: the street-level driving frames (truth file, loader, real frames)."""

from __future__ import annotations

import hashlib
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

PIL_Image = pytest.importorskip("PIL.Image")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
vp_real = pytest.importorskip("vp_real")

HOW_TO_FETCH = (
    "the driving frames are not here: run benchmarks/fetch_real_photos.sh (it copies "
    "jeremy-shannon/CarND-Advanced-Lane-Lines, Phoenix8215/FCN_KITTI, "
    "open-mmlab/mmdetection3d and marikhu/BrnoCompSpeed into "
    "~/.cache/camloc_geo/photos, or CAMLOC_PHOTOS_DIR)"
)


def _png(path: Path, size: tuple[int, int], shade: int) -> str:
    path.parent.mkdir(parents=True, exist_ok=True)
    PIL_Image.new("RGB", size, (shade, shade, shade)).save(path)
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _truth(tmp_path: Path, frames: list[dict[str, object]]) -> Path:
    doc = {
        "cameras": {
            "dash": {"focal_px": [1000.0, 990.0], "principal_point": [321.0, 239.0]},
        },
        "frames": frames,
    }
    p = tmp_path / "truth.json"
    p.write_text(json.dumps(doc), encoding="utf-8")
    return p


def test_drive_loader_reads_shared_and_own_calibrations_and_the_halves(tmp_path: Path) -> None:
    photos = tmp_path / "photos"
    sha_a = _png(photos / "lane" / "a.jpg", (640, 480), 100)
    sha_b = _png(photos / "kitti" / "b.png", (620, 190), 120)
    truth = _truth(
        tmp_path,
        [
            {
                "set": "udacity-lane",
                "file": "lane/a.jpg",
                "sha256": sha_a,
                "size": [640, 480],
                "camera": "dash",
                "sequence": "project",
                "half": "dev",
            },
            {
                "set": "kitti-road",
                "file": "kitti/b.png",
                "sha256": sha_b,
                "size": [620, 190],
                "focal_px": [721.5377, 721.5377],
                "principal_point": [609.5593, 172.854],
                "sequence": "road-training-um_000000",
                "half": "held-out",
            },
        ],
    )
    both = vp_real.load_drive_set(photos, truth)
    assert [r["name"] for r in both] == [
        "udacity-lane/project/a.jpg",
        "kitti-road/road-training-um_000000/b.png",
    ]
    a, b = both
    assert a["f"] == pytest.approx(995.0)  # the mean of fx and fy
    assert a["pp"] == (321.0, 239.0)
    assert a["size"] == (640, 480)
    assert a["up"] is None
    assert a["half"] == "dev"
    assert b["f"] == pytest.approx(721.5377)
    assert b["pp"] == (609.5593, 172.854)
    dev = vp_real.load_drive_set(photos, truth, ("dev",))
    assert [r["name"] for r in dev] == ["udacity-lane/project/a.jpg"]
    held = vp_real.load_drive_set(photos, truth, ("held-out",))
    assert [r["half"] for r in held] == ["held-out"]


def test_drive_loader_skips_missing_and_changed_frames(tmp_path: Path) -> None:
    photos = tmp_path / "photos"
    _png(photos / "a.jpg", (64, 48), 100)
    frame: dict[str, object] = {
        "set": "udacity-lane",
        "file": "a.jpg",
        "sha256": "0" * 64,  # not this content
        "size": [64, 48],
        "camera": "dash",
        "sequence": "s",
        "half": "dev",
    }
    gone: dict[str, object] = {**frame, "file": "gone.jpg"}
    assert vp_real.load_drive_set(photos, _truth(tmp_path, [frame, gone])) == []


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"camera": "nope"}, "unknown camera 'nope'"),
        ({"camera": None, "focal_px": [0.0, 0.0], "principal_point": [1, 1]}, "not positive"),
        ({"camera": None}, "no usable focal_px"),
    ],
)
def test_drive_loader_names_what_is_wrong_in_the_truth(
    tmp_path: Path, change: dict[str, object], message: str
) -> None:
    frame: dict[str, object] = {
        "set": "s",
        "file": "a.jpg",
        "sha256": "0" * 64,
        "size": [64, 48],
        "camera": "dash",
        "sequence": "s",
        "half": "dev",
    }
    frame.update(change)
    if frame["camera"] is None:
        del frame["camera"]
    with pytest.raises(ValueError, match=message):
        vp_real.load_drive_set(tmp_path, _truth(tmp_path, [frame]))


def test_committed_drive_truth_is_complete_and_split_by_sequence() -> None:
    doc = json.loads(vp_real.STREET_TRUTH.read_text(encoding="utf-8"))
    cams = doc["cameras"]
    assert cams["udacity-dash"]["focal_px"] == pytest.approx([1156.46, 1151.27])
    halves: dict[str, set[str]] = {}
    for fr in doc["frames"]:
        assert fr["set"] in vp_real.DRIVE_SETS
        assert fr["half"] in vp_real.DRIVE_HALVES
        assert len(fr["sha256"]) == 64
        assert int(fr["sha256"], 16) >= 0
        cam = cams[fr["camera"]] if "camera" in fr else fr
        fx, fy = cam["focal_px"]
        assert 0.3 * max(fr["size"]) < fx < 3.0 * max(fr["size"])
        assert math.isclose(fx, fy, rel_tol=0.01)
        halves.setdefault(fr["sequence"], set()).add(fr["half"])
    # no sequence has frames in both halves
    assert all(len(h) == 1 for h in halves.values())
    assert {"dev", "held-out"} == set().union(*halves.values())
    assert len({fr["sha256"] for fr in doc["frames"]}) == len(doc["frames"])


def _dev_frames() -> list[dict[str, Any]]:
    frames = vp_real.load_drive_set(vp_real.PHOTOS, vp_real.STREET_TRUTH, ("dev",))
    if not frames:
        pytest.skip(HOW_TO_FETCH)
    return frames


def test_level_street_frames_are_never_confidently_wrong() -> None:
    # A level dash camera looking down a highway: one finite vanishing point, (almost) no
    # vertical line. The focal length then rests on the default prior: vp must say so
    # (a warning, a wide sigma, a low confidence) rather than give a sure wrong number.
    from camloc_geo import NotEnoughStructureError
    from camloc_geo.autovp import detect_vanishing_points

    for t in _dev_frames():
        try:
            res = detect_vanishing_points(t["path"], seed=0, use_exif=False)
        except NotEnoughStructureError:
            continue  # a refusal (4 of the 9 BrnoCompSpeed dev frames) is no wrong answer
        err = abs(math.log(res.focal_px / float(t["f"])))
        assert res.focal_std_rel is not None
        sure = not res.warnings and res.confidence >= 0.5
        assert not (err > math.log(1.1) and err > 2 * res.focal_std_rel and sure), t["name"]
        assert np.isfinite(res.pitch_deg)
        if t["set"] == "kitti":  # a 1242x375 crop: the stated sigma covers the truth
            assert err <= 2 * res.focal_std_rel, t["name"]
        if t["set"] == "udacity-lane":  # a highway: the geometry is loose, the sigma says so
            assert res.focal_std_rel > 0.2, t["name"]
            assert res.confidence < 0.5, t["name"]


def test_drive_loader_reads_the_up_direction_where_the_truth_gives_it(tmp_path: Path) -> None:
    photos = tmp_path / "photos"
    sha = _png(photos / "a.jpg", (64, 48), 100)
    frame: dict[str, object] = {
        "set": "nuscenes",
        "file": "a.jpg",
        "sha256": sha,
        "size": [64, 48],
        "focal_px": [60.0, 60.0],
        "principal_point": [32.0, 24.0],
        "up_in_cam": [0.0, 2.0, 0.0],  # scaled and pointing down: normalised, turned up
        "sequence": "s",
        "half": "dev",
    }
    (t,) = vp_real.load_drive_set(photos, _truth(tmp_path, [frame]))
    assert t["up"] == pytest.approx([0.0, -1.0, 0.0])
    frame["up_in_cam"] = [0.0, 1.0]
    with pytest.raises(ValueError, match="up_in_cam is not a 3-vector"):
        vp_real.load_drive_set(photos, _truth(tmp_path, [frame]))


def test_traffic_camera_without_verticals_does_not_rest_on_a_few_lines_surely() -> None:
    # BrnoCompSpeed session4_left (development half): a camera over a highway, no vertical
    # line, the road's direction right to the pixel, "across the road" 4 lines of a car and
    # a guard rail. The focal length (-48 %, the truth 3602 px) rests on those 4: it was
    # stated at 11 %; now the sigma says the photo does not fix it.
    from camloc_geo.autovp import detect_vanishing_points

    (t,) = [fr for fr in _dev_frames() if fr["name"] == "brno/session4_left/screen.png"]
    res = detect_vanishing_points(t["path"], seed=0, use_exif=False)
    assert res.n_lines[0] == 0
    assert res.focal_std_rel is not None
    assert res.focal_std_rel > 0.25
    assert abs(math.log(res.focal_px / t["f"])) <= 2.0 * res.focal_std_rel
    assert res.confidence < 0.5
    assert any("only 4 lines" in w for w in res.warnings)
