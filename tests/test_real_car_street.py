"""Real cars annotated by hand on real compact-camera street photos (issue #24's real car).

Beyond York Urban (one 640x480 camera, ``tests/test_real_car.py``): two cars on photos of
``benchmarks/street_photos.json`` whose focal length is known from their EXIF (not from the
clicks), set ``street-photos-held-out-2`` (batch 8, development since stop 39; batch 9,
``held-out-3``, is not used). The photos stay out of this repository (no licence given);
``benchmarks/fetch_real_photos.sh`` fetches them into ``~/.cache/camloc_geo/photos`` (or
``CAMLOC_PHOTOS_DIR``). The scenes under ``tests/data/real_car/`` hold only the clicks, read
by eye off zoomed pixel-grid crops (two annotators each, ``hand-a`` and ``hand-b``, from
their own crops). The clicks-only tests
run everywhere; those with the photo skip without it. See benchmarks/README.md, "real_car".
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from camloc_geo.cli import main
from camloc_geo.relative import _photo_disagreeing_axes

PHOTOS = Path(
    os.environ.get("CAMLOC_PHOTOS_DIR", str(Path.home() / ".cache" / "camloc_geo" / "photos"))
)
PHOTO_MISSING = (
    "street photo not available (no licence given, not in this repository): run "
    "benchmarks/fetch_real_photos.sh with CAMLOC_PHOTO_SETS=street-photos-held-out-2 "
    "(or set CAMLOC_PHOTOS_DIR)"
)
DATA = Path(__file__).parent / "data" / "real_car"

# I1_STD_0034.JPG (Canon Digital IXUS 860 IS, 3264x2448): a Toyota Corolla Altis (E120, by
# its badge and 2004-2007 taillights) parked diagonally in a bay, seen from behind and to its
# left, ~11 degrees off its length axis. Scene size 4.53 x 1.705 x 1.48 m (the E120 Altis'
# published length, width and height; +/- 2 %). Truth: EXIF focal plane resolution and
# focal length, 5201.3 px (1.59x the longer side). Nothing else in the photo is parallel to
# the car: its length and width lines are its own (hand-a: tyre contacts, hubs, the sill,
# the number plate's edges; hand-b: the door handles, contacts, hubs, the trunk's crease
# and the chrome strip), and its far rear corner (the width end) is hidden by a shrub
# (clicked where the rear face ends). hand-b's clicks alone are refused (their vanishing
# points lie on one side of the principal point). Camera height, without calibrate:
# 1.1 +/- 0.3 m (the building's verticals show a level camera within ~1 degree, so the
# horizon lies near the photo's middle row, y 1224 +/- 90: it crosses the car at 0.77 of
# its 1.48 m and a woman standing by the porch at about half her height).
ALTIS = DATA / "street_I1_STD_0034_corolla_altis.json"
ALTIS_FOCAL_PX = 5201.27
ALTIS_HEIGHT_M = 1.1

# kyoto_street.JPG (Casio EX-Z850, 2816x2112): a 1993-1998 Honda Today (JA4, a kei car;
# 3,295 x 1,395 mm, the maker's figures; height 1.33 m, not published where we looked:
# +/- 0.05 m) driving along the street, seen from ahead and to its left. Two annotators from
# their own crops. hand-a: length, the tyre contacts, hubs and a zebra stripe's two long
# edges (parallel to the street in Japan); width, the crossing's edge and the front bumper;
# upright, a concrete utility pole's axis (tapered: its edges are not parallel), a signal
# pole and the pole's edge. hand-b: length, the orange centre line's two edges and the tyre
# contacts; width, the crossing's far boundary through five stripes' ends and the car's
# footprint shadow in front (overcast); upright, a street lamp's shaft and the tower's edge;
# its corners read on the footprint shadow (3-37 px from hand-a's).
# Truth: EXIF 35 mm equivalent, 3091.5 px (1.10x the longer side). Camera height, without
# calibrate: 1.40 +/- 0.15 m (the street's vanishing point from the crossing stripes, the
# centre line and the car's tyre contacts lies at y 1630-1680; that level crosses a
# pedestrian at ~0.87 of her height and the car just above its roof).
TODAY = DATA / "street_kyoto_street_honda_today.json"
TODAY_FOCAL_PX = 3091.53
TODAY_HEIGHT_M = 1.40


def _calibrate(
    path: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    with_photo: bool,
    only: str | None = None,
) -> dict:
    """``camloc calibrate`` on the scene at ``path`` through the CLI, with its photo or
    without (``only``: that annotator's clicks alone): exit 0, no traceback, its JSON."""
    scene = json.loads(path.read_text(encoding="utf-8"))
    names = [a["annotator"] for a in scene["annotations"]]
    assert names == ["hand-a", "hand-b"]
    if only is not None:
        scene["annotations"] = [a for a in scene["annotations"] if a["annotator"] == only]
    if with_photo:
        scene["image"]["path"] = str(PHOTOS / scene["image"]["path"])
    else:
        del scene["image"]["path"]
    run = tmp_path / "scene.json"
    run.write_text(json.dumps(scene), encoding="utf-8")
    code = main(["calibrate", str(run)])
    captured = capsys.readouterr()
    assert code == 0
    assert "Traceback" not in captured.err
    out: dict = json.loads(captured.out)
    return out


def _photo(path: Path) -> Path:
    return PHOTOS / json.loads(path.read_text(encoding="utf-8"))["image"]["path"]


def _sigmas_off(out: dict, truth_px: float) -> float:
    return abs(out["focal_px"] - truth_px) / out["focal_sigma_px"]


# --- the Corolla Altis: the car's own lines alone, wrong and warned ---------------------


def test_altis_clicks_alone_are_warned_on_both_axes_and_height_within_half_a_metre(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """2344.9 +/- 467.0 px (-54.9 %, 6.1 sigma), 0.77 +/- 0.32 m (hand-a alone 2391.7 +/-
    435.7, -54 %). Both length and width rest on the car's own edges, and both are named:
    the wrong focal length is warned, though its sigma does not cover it (the xfail below)."""
    out = _calibrate(ALTIS, tmp_path, capsys, with_photo=False)
    warned = [w.split(":")[0] for w in out["warnings"] if "car's own edges" in w]
    assert warned == ["vp_lines.length", "vp_lines.width"]
    assert out["focal_px"] < 0.6 * ALTIS_FOCAL_PX
    assert abs(out["height_m"] - ALTIS_HEIGHT_M) < 0.5


@pytest.mark.xfail(
    strict=True,
    reason=(
        "the car stands diagonally in its bay, so only its own lines carry length and width: "
        "the number plate's two 92 px edges (the width; 1.5 and 4.5 px of drop, where the "
        "EXIF focal length asks for ~0.1 px) and its wheels (the length); the width end is "
        "hidden by a shrub and the height end read off the wheels' scale. hand-a's own "
        "vanishing points give ~1,600 px, both annotators' joint fit 2,345 +/- 467 px "
        "(-55 %, 6.1 sigma, warned on both axes); with the focal length given the fit moves "
        "hand-a's clicks by 8-22 px"
    ),
)
def test_altis_clicks_alone_meet_issue_24(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue #24's check on the focal length (fails: see the xfail reason)."""
    out = _calibrate(ALTIS, tmp_path, capsys, with_photo=False)
    assert abs(out["focal_px"] / ALTIS_FOCAL_PX - 1.0) < 0.10
    assert _sigmas_off(out, ALTIS_FOCAL_PX) < 2.0


@pytest.mark.skipif(not _photo(ALTIS).is_file(), reason=PHOTO_MISSING)
def test_altis_photo_that_disagrees_does_not_make_the_wrong_answer_surer(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The photo's width direction is 6-11 degrees from the fit's (warned). Its length and
    upright segments used to join all the same (11 and 91 of them): the length no longer
    rested on the car's edges, its warning went, and the wrong answer looked surer,
    2343.5 +/- 194.7 px (-55 %, 14.7 sigma), height 0.83 +/- 0.06 m. Two witnesses that
    clearly disagree on one axis now lend each other nothing: the clicks' answer, its sigmas
    and both car-line warnings stand, with the photo's disagreement."""
    alone = _calibrate(ALTIS, tmp_path, capsys, with_photo=False)
    out = _calibrate(ALTIS, tmp_path, capsys, with_photo=True)
    assert any(
        w.startswith("image.path: the photo's lines disagree") and "width" in w
        for w in out["warnings"]
    )
    assert "photo_segments" not in out  # the photo lent none
    warned = [w.split(":")[0] for w in out["warnings"] if "car's own edges" in w]
    assert warned == ["vp_lines.length", "vp_lines.width"]
    assert out["focal_px"] == pytest.approx(alone["focal_px"], rel=1e-9)
    assert out["focal_sigma_px"] >= 0.99 * alone["focal_sigma_px"]
    assert out["height_sigma_m"] >= 0.99 * alone["height_sigma_m"]
    assert _sigmas_off(out, ALTIS_FOCAL_PX) < 7.0  # was 14.7


def test_altis_hand_b_alone_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """hand-b's clicks alone give no consistent pair of vanishing points: exit 2 naming
    camera.focal_px, not an answer."""
    scene = json.loads(ALTIS.read_text(encoding="utf-8"))
    scene["annotations"] = [a for a in scene["annotations"] if a["annotator"] == "hand-b"]
    del scene["image"]["path"]
    run = tmp_path / "scene.json"
    run.write_text(json.dumps(scene), encoding="utf-8")
    assert main(["calibrate", str(run)]) == 2
    assert "camera.focal_px" in capsys.readouterr().err


# --- the Honda Today: street lines along and across, covered but not within 10 % ------------


def test_today_clicks_alone_cover_the_truth_and_height_within_half_a_metre(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Both annotators: 3423.2 +/- 893.2 px (+10.7 %, 0.37 sigma), 1.81 +/- 0.31 m (0.41 m
    from the estimate): inside 2 sigma, with no car-line warning (the crossing and the
    centre line carry both axes). The two disagree (below), and the sigma says so."""
    out = _calibrate(TODAY, tmp_path, capsys, with_photo=False)
    assert _sigmas_off(out, TODAY_FOCAL_PX) < 2.0
    assert abs(out["height_m"] - TODAY_HEIGHT_M) < 0.5
    assert not any("car's own edges" in w for w in out.get("warnings", []))
    assert abs(out["focal_px"] / TODAY_FOCAL_PX - 1.0) < 0.15
    assert out["focal_sigma_px"] > 0.2 * out["focal_px"]


@pytest.mark.parametrize(
    ("only", "low", "high"),
    [("hand-a", 0.85, 0.90), ("hand-b", 1.35, 1.40)],
)
def test_today_each_annotator_alone_is_covered(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], only: str, low: float, high: float
) -> None:
    """hand-a alone: 2730.4 +/- 337.6 px (-11.7 %, 1.07 sigma); hand-b alone: 4262 +/- 697 px
    (+37.9 %, 1.7 sigma). Far apart, each inside 2 sigma of the truth."""
    out = _calibrate(TODAY, tmp_path, capsys, with_photo=False, only=only)
    assert low < out["focal_px"] / TODAY_FOCAL_PX < high
    assert _sigmas_off(out, TODAY_FOCAL_PX) < 2.0


@pytest.mark.xfail(
    strict=True,
    reason=(
        "+10.7 % (3423 px against 3092): the two annotators read the rounded, "
        "motion-blurred kei car and the street 1.56x apart (hand-a -11.7 %: the street's "
        "vanishing point from one worn crossing stripe, y 1684, and the width end where "
        "the bumper ends, the clicked width 1.14x the car's; hand-b +37.9 %: a street lamp's "
        "shaft leaning 10 px over 950 and the tower's edge for the uprights)"
    ),
)
def test_today_clicks_alone_within_10_percent(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue #24's 10 % (fails by 0.7 points: see the xfail reason)."""
    out = _calibrate(TODAY, tmp_path, capsys, with_photo=False)
    assert abs(out["focal_px"] / TODAY_FOCAL_PX - 1.0) < 0.10


@pytest.mark.skipif(not _photo(TODAY).is_file(), reason=PHOTO_MISSING)
def test_today_with_its_photo_warns_and_covers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The photo's length direction disagrees (4.2 degrees, warned): it lends nothing, so
    the answer is the clicks' (before: its width and upright segments joined, 3472.9 +/-
    905.0 px, +12.3 %)."""
    out = _calibrate(TODAY, tmp_path, capsys, with_photo=True)
    assert any(w.startswith("image.path: the photo's lines disagree") for w in out["warnings"])
    assert "photo_segments" not in out
    assert _sigmas_off(out, TODAY_FOCAL_PX) < 2.0
    assert abs(out["height_m"] - TODAY_HEIGHT_M) < 0.5


# --- the rule itself, without a photo ---------------------------------------------------------


def _vp_of(direction_cam: np.ndarray, f: float, pp: tuple[float, float]) -> np.ndarray:
    d = np.asarray(direction_cam, dtype=float)
    return np.array([f * d[0] + pp[0] * d[2], f * d[1] + pp[1] * d[2], d[2]])


def test_photo_disagreeing_axes_names_the_axis_between_4_and_30_degrees() -> None:
    """A photo direction 10 degrees from the width axis disagrees on it; 2 degrees agrees; a
    direction with too few segments does not count."""
    f, pp = 1000.0, (640.0, 360.0)
    a = math.radians(35.0)
    R = np.array(  # cam_from_world: a level camera, the car's length 35 degrees off its view
        [[math.cos(a), -math.sin(a), 0.0], [0.0, 0.0, -1.0], [math.sin(a), math.cos(a), 0.0]]
    )
    turn = math.radians(10.0)
    width_off = np.cos(turn) * R[:, 1] + np.sin(turn) * R[:, 2]
    small = math.radians(2.0)
    length_near = np.cos(small) * R[:, 0] + np.sin(small) * R[:, 2]
    K_inv = np.linalg.inv(np.array([[f, 0.0, pp[0]], [0.0, f, pp[1]], [0.0, 0.0, 1.0]]))
    vps = [_vp_of(length_near, f, pp), _vp_of(width_off, f, pp), _vp_of(R[:, 2], f, pp)]
    off = _photo_disagreeing_axes(vps, [20, 20, 20], K_inv, R)
    assert [i for i, _ in off] == [1]
    assert off[0][1] == pytest.approx(10.0, abs=1e-6)
    assert _photo_disagreeing_axes(vps, [20, 3, 20], K_inv, R) == []  # width's too few
    vps_ok = [_vp_of(length_near, f, pp), _vp_of(R[:, 1], f, pp), _vp_of(R[:, 2], f, pp)]
    assert _photo_disagreeing_axes(vps_ok, [20, 20, 20], K_inv, R) == []
