"""Crowd slips over synthetic scenes: a wrong calibration must never look sure.

The classes ``benchmarks/crowd_slips.py`` found confidently wrong (outside the paper's bars,
outside 2 sigma, no warning), each on a few fixed synthetic scenes, and a control that the
same checks stay quiet on clean work.
"""

from __future__ import annotations

import json
import logging
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camloc_geo.camera import Camera
from camloc_geo.objects import PRESETS
from camloc_geo.relative import CalibrationResult, CalibrationSettings, calibrate
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import (
    NoiseModel,
    SyntheticScene,
    _visible_segment,
    make_scene,
    random_camera,
)

CLEAN = NoiseModel(wrong_corner_prob=0.0, sloppy_prob=0.0)


@pytest.fixture(autouse=True)
def _quiet(caplog: Any) -> None:
    caplog.set_level(logging.ERROR, logger="camloc_geo")


def _scene(seed: int, true: str = "sedan", n: int = 4) -> SyntheticScene:
    rng = np.random.default_rng(seed)
    cam = random_camera(rng)
    syn = make_scene(cam, rng, noise=CLEAN, n_annotators=n, true_size=PRESETS[true])
    syn.scene["object"] = {"preset": "sedan"}
    return syn


def _cal(syn: SyntheticScene) -> CalibrationResult:
    return calibrate(parse_scene(syn.scene))


def _proportion_warnings(result: CalibrationResult) -> list[str]:
    return [w for w in result.warnings if "proportions" in w]


def _within_2_sigma(result: CalibrationResult, truth: Camera) -> bool:
    assert result.position_sigma_m is not None
    err = np.linalg.norm(result.camera.center_in_world - truth.center_in_world)
    h_err = abs(result.height_m - truth.height_m)
    sigma = result.position_sigma_m
    return bool(err <= 2.0 * np.linalg.norm(sigma) and h_err <= 2.0 * sigma[2])


# ------------------------------------------------------------------ another class of car
@pytest.mark.parametrize("seed", [2, 4, 6])
def test_van_called_sedan_is_said_and_inside_two_sigma(seed: int) -> None:
    """A van (2.30 m roof) annotated as a sedan (1.45 m): the old fit put the camera 6.3-9.2 m
    off at a stated 2.1-3.4 m (seeds 0, 2, 6; seed 4: 8.6 m at 9.8 m), with no warning. (Seed 0
    is seen so obliquely that its proportions are within the clicks' noise: 6.3 m at a stated
    3.4 m, inside 2 sigma, no warning.)"""
    syn = _scene(seed, "van")
    result = _cal(syn)
    assert len(_proportion_warnings(result)) == 1
    assert "another class" in _proportion_warnings(result)[0]
    props = result.object_proportions
    assert props is not None
    assert props["disagrees"] is True
    # The roof is clicked 1.25-1.45x higher than the length and width say.
    assert props["scale"]["height"] / props["scale"]["length"] > 1.25
    assert _within_2_sigma(result, syn.camera)
    assert result.to_dict()["object_proportions"]["disagrees"] is True


@pytest.mark.parametrize("seed", range(8))
def test_sedan_proportions_stay_quiet(seed: int) -> None:
    """The control: clean sedans give no proportion warning and scales near 1."""
    result = _cal(_scene(seed, "sedan"))
    assert _proportion_warnings(result) == []
    props = result.object_proportions
    assert props is not None
    assert props["disagrees"] is False
    assert all(0.8 < v < 1.2 for v in props["scale"].values())
    assert props["odd_annotators"] == []
    assert not any("the other annotators'" in w for w in result.warnings)
    assert not any("line sigmas off" in w for w in result.warnings)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_one_annotators_roof_click_on_a_van_is_named(seed: int) -> None:
    """One of four annotators clicks the height edge's end at a van's roof behind the sedan
    (2.30 m for 1.45): named, with the ratio; the old code named nobody."""
    syn = _scene(seed, "sedan")
    size = syn.true_size
    roof = [0.0, 0.0, size.height_m * 2.30 / 1.45]
    syn.scene["annotations"][2]["axes"]["height"] = syn.camera.project(roof).tolist()
    result = _cal(syn)
    props = result.object_proportions
    assert props is not None
    odd = props["odd_annotators"]
    assert [o["annotator"] for o in odd] == ["w3"]
    assert odd[0]["axis"] == "height"
    assert 1.35 < odd[0]["ratio"] < 1.8
    assert any(
        w.startswith("annotator 'w3' (annotations[2]): their height edge is")
        for w in result.warnings
    )


# ------------------------------------------------------------------ tyre contacts
def _tyre_points(syn: SyntheticScene, rng: np.random.Generator) -> np.ndarray:
    """The tyre contacts under the corner and the two edge ends, and the roof above."""
    size = syn.true_size
    s = syn.width_sign
    over, inset = rng.uniform(0.6, 1.0), rng.uniform(0.1, 0.25)
    L, W, H = size.length_m, s * size.width_m, size.height_m
    return np.array(
        [
            [over, s * inset, 0.0],
            [L - over, s * inset, 0.0],
            [over, W - s * inset, 0.0],
            [over, s * inset, H],
        ]
    )


@pytest.mark.parametrize("seed", [1, 3, 5, 7])
def test_every_annotator_at_the_tyre_contacts_is_said(seed: int) -> None:
    """Ground corners at the tyre contacts (issue 24's rounded body), by every annotator:
    the clicked length edge is ~1.6 m short. Named, with the position inside 2 sigma."""
    syn = _scene(seed, "sedan")
    rng = np.random.default_rng(100 + seed)
    for ann in syn.scene["annotations"]:
        pix = syn.camera.project(_tyre_points(syn, rng)) + rng.normal(0.0, 2.0, (4, 2))
        for key, p in zip(("origin", "length", "width", "height"), pix, strict=True):
            ann["axes"][key] = p.tolist()
    result = _cal(syn)
    warnings = _proportion_warnings(result)
    assert len(warnings) == 1
    assert "tyre contacts" in warnings[0]
    props = result.object_proportions
    assert props is not None
    assert props["scale"]["length"] / props["scale"]["height"] < 0.8
    assert _within_2_sigma(result, syn.camera)


# ------------------------------------------------------------------ one line off its axis
NONPARALLEL = json.loads(
    (Path(__file__).parent / "data" / "crowd_slips_nonparallel.json").read_text()
)


@pytest.mark.parametrize("key", sorted(NONPARALLEL))
def test_one_long_line_off_its_axis_is_inside_two_sigma(key: str) -> None:
    """One annotator's single long line 12-15 deg off its axis (benchmarks/crowd_slips.py,
    scenes 13 and 50) carries the whole fit: focal length x2.9-5.7. The one-step jackknife
    found no camera without that annotator and left it out of the spread: stated 578-2227 px
    and 10-60 m for errors of 2850-5900 px and 64-161 m. Now that leave-out is refitted."""
    case = NONPARALLEL[key]
    result = calibrate(parse_scene(case["scene"]))
    truth = case["truth"]
    slot = [a["annotator"] for a in case["scene"]["annotations"]].index(case["annotator"])
    influence = result.annotator_influence_m[slot]
    assert influence is not None
    assert influence > 50.0
    err = float(np.linalg.norm(result.camera.center_in_world - np.array(truth["camera_in_world"])))
    assert result.position_sigma_m is not None
    assert err <= 2.0 * float(np.linalg.norm(result.position_sigma_m))
    assert result.focal_sigma_px is not None
    assert abs(result.camera.focal_px - truth["focal_px"]) <= 2.0 * result.focal_sigma_px


# ------------------------------------------------------------------ duplicated submissions
@pytest.mark.parametrize("seed", [0, 3])
def test_a_duplicated_submission_counts_once(seed: int) -> None:
    """The same work twice more (under another name): left out, named, and the answer and
    its sigmas those of the scene without the copies (the copies shrank the jackknife's
    spread and tripled one annotator's weight)."""
    syn = _scene(seed, "sedan", n=4)
    base = _cal(syn)
    copies = [dict(syn.scene["annotations"][1], annotator=f"w2-again{k}") for k in (1, 2)]
    syn.scene["annotations"] += copies
    result = _cal(syn)
    excluded = {e["index"]: e["reason"] for e in result.excluded_annotators}
    assert sorted(excluded) == [4, 5]
    assert all("same clicks and lines as annotations[1] ('w2')" in r for r in excluded.values())
    assert any("'w2-again1' (annotations[4]) left out" in w for w in result.warnings)
    assert np.allclose(result.camera.center_in_world, base.camera.center_in_world, atol=1e-9)
    assert result.position_sigma_m is not None
    assert base.position_sigma_m is not None
    assert np.allclose(result.position_sigma_m, base.position_sigma_m, rtol=1e-9)


def test_a_near_copy_is_not_a_duplicate() -> None:
    """Work that differs by one click (0.5 px) is another witness, kept."""
    syn = _scene(0, "sedan", n=4)
    near = json.loads(json.dumps(syn.scene["annotations"][1]))
    near["annotator"] = "w5"
    near["axes"]["height"][0] += 0.5
    syn.scene["annotations"].append(near)
    result = _cal(syn)
    assert result.excluded_annotators == []


@pytest.mark.parametrize("seed", [2, 3, 6, 7, 9])
def test_a_kerb_curve_drawn_as_a_length_line_is_named(seed: int) -> None:
    """One annotator adds a long ground line 10 deg off the car's length (a kerb's curve)
    that the line screen keeps: the fit's residual names it (8-18 line sigmas off); the old
    code said nothing."""
    syn = _scene(seed, "sedan")
    off = math.radians(10.0)
    a = np.array([-15.0, -6.0, 0.0])
    b = a + 20.0 * np.array([math.cos(off), math.sin(off), 0.0])
    seg = _visible_segment(syn.camera, a, b, (1920, 1080))
    assert seg is not None
    syn.scene["annotations"][1]["vp_lines"]["length"].append([float(v) for v in seg])
    result = _cal(syn)
    named = [w for w in result.warnings if "line sigmas off" in w]
    assert len(named) == 1
    assert named[0].startswith("annotator 'w2' (annotations[1]): the vp_lines.length segment [")
    sigmas = float(named[0].split(" is ")[1].split(" line sigmas")[0])
    assert sigmas > 7.0


def test_an_annotator_the_answer_rests_on_is_named() -> None:
    """A grazing view (camera 3.6 m high, 27 m away) where the length and width edges run
    ~5 deg apart on screen; one annotator of three filed their length and width lines under
    each other (benchmarks/crowd_slips.py, seed 7, scene 32). The fit follows them: 26 m off
    at a stated 2 m, and the leave-out without them gives another frame, so the spread
    cannot show it. The old code said nothing about them; now they are named. (The answer
    itself is still wrong: the next step.)"""
    case = json.loads(
        (Path(__file__).parent / "data" / "crowd_slips_lines_wrong_axis.json").read_text()
    )
    result = calibrate(parse_scene(case["scene"]))
    assert case["annotator"] == "w1"
    pivotal = [w for w in result.warnings if "no comparable camera" in w]
    assert len(pivotal) == 1
    assert pivotal[0].startswith("annotator 'w1' (annotations[0]): without their work")
    assert result.annotator_influence_m[0] is None


# ------------------------------------------------- slips the leverage correction would hide
LEVERAGE = json.loads((Path(__file__).parent / "data" / "crowd_slips_leverage.json").read_text())
BARS = {"position_m": 5.0, "height_m": 1.0, "focal_rel": 0.10}  # benchmarks/crowd_slips.py


def _confidently_wrong(result: CalibrationResult, case: dict[str, Any]) -> bool:
    """``benchmarks/crowd_slips.py``'s verdict: outside a bar, outside 2 sigma, nothing said."""
    truth = case["truth"]
    c_err = result.camera.center_in_world - np.array(truth["camera_in_world"])
    pos = float(np.linalg.norm(c_err))
    hgt = abs(result.camera.height_m - truth["height_m"])
    foc = abs(result.camera.focal_px - truth["focal_px"])
    outside = {
        "position": pos >= BARS["position_m"],
        "height": hgt >= BARS["height_m"],
        "focal": foc >= BARS["focal_rel"] * truth["focal_px"],
    }
    if not any(outside.values()):
        return False
    sig = result.position_sigma_m
    assert sig is not None
    assert result.focal_sigma_px is not None
    covered = {
        "position": pos <= 2.0 * float(np.linalg.norm(sig)),
        "height": hgt <= 2.0 * float(sig[2]),
        "focal": foc <= 2.0 * result.focal_sigma_px,
    }
    if all(covered[k] for k, out in outside.items() if out):
        return False
    who = case["annotator"]
    if who is None:  # a crowd-wide slip: any warning says it
        return not result.warnings
    named = set(result.outlier_annotators) | set(result.corner_mistakes)
    return who not in named and not any(f"'{who}'" in w for w in result.warnings)


@pytest.mark.parametrize("key", sorted(LEVERAGE))
def test_slips_stay_said_or_covered_with_the_leverage_correction(key: str) -> None:
    """The jackknife's leverage correction (CR2, default since stop 38) shrinks the spread an
    unevenly loaded crowd had over-stated; the over-stated spread had also covered, by
    accident, slips no jackknife is built to see. Four scenes of ``benchmarks/crowd_slips.py``
    (every corner at the tyre contacts; three SUVs called sedans, two of them confidently
    wrong with stop 37's sigmas as well) that the plain correction leaves confidently wrong:
    the default keeps them covered, by the leave-outs beyond the linearisation keeping their
    move (``jackknife_leverage_max_move``: the tyre contacts) and by the car-class mixture
    (``car_class_prior``: the SUVs)."""
    case = LEVERAGE[key]
    scene = parse_scene(case["scene"])
    plain = calibrate(
        scene, CalibrationSettings(jackknife_leverage_max_move=math.inf, car_class_prior=0.0)
    )
    assert _confidently_wrong(plain, case)
    assert not _confidently_wrong(calibrate(scene), case)


# ------------------------------------------- one line that carries its axis, off its axis
DISCORDANT = json.loads(
    (Path(__file__).parent / "data" / "crowd_slips_discordant_line.json").read_text()
)
_CARRIES = "carries the answer"


@pytest.mark.parametrize("key", sorted(DISCORDANT))
def test_a_line_that_carries_its_axis_off_it_is_named_and_covered(key: str) -> None:
    """One annotator's height line 9 deg off (benchmarks/crowd_slips.py, seed 20261124,
    nonparallel_line, scene 39) is its axis' only long line: the fit follows it, its own
    residual is 0.3 line sigmas, and the answer was confidently wrong (focal length +11.7 %
    at a stated 5 %, the camera 1.44 m too high at a stated 0.54 m), nothing said. With its
    leverage taken out its residual is 3.1 sigmas, and without it the focal length moves
    -11 % and the height -1.03 m: the line is named and that move is in the sigmas."""
    case = DISCORDANT[key]
    scene = parse_scene(case["scene"])
    off = CalibrationSettings(discordant_line_t=0.0)
    before = calibrate(scene, off)
    assert _confidently_wrong(before, case)
    assert not any(_CARRIES in w for w in before.warnings)
    result = calibrate(scene)
    assert not _confidently_wrong(result, case)
    named = [w for w in result.warnings if _CARRIES in w]
    assert len(named) == 1
    assert named[0].startswith("annotator 'w1' (annotations[0]): the vp_lines.height segment [")
    # the linear move without the line: within 2 points of the refit's -10.4 %
    move = float(named[0].split("the focal length ")[1].split(" %")[0])
    assert -12.5 < move < -8.5
    # the camera is where it was; only the sigmas grew, the height's to cover its 1.44 m miss
    assert np.allclose(result.camera.center_in_world, before.camera.center_in_world)
    assert result.position_sigma_m is not None
    assert before.position_sigma_m is not None
    assert before.position_sigma_m[2] < 0.6 < 1.0 < result.position_sigma_m[2]
    truth = case["truth"]
    assert abs(result.camera.height_m - truth["height_m"]) < 2.0 * result.position_sigma_m[2]
    assert result.parameter_covariance is not None
    assert math.isclose(
        math.sqrt(result.parameter_covariance[8, 8]), result.position_sigma_m[2], rel_tol=0.05
    )


@pytest.mark.parametrize("key", sorted(DISCORDANT))
def test_the_same_scene_without_the_slip_is_not_named(key: str) -> None:
    """The control: the scene before the slip (its lines all along their axes) has no line
    named, and its sigmas are those without the check."""
    scene = parse_scene(DISCORDANT[key]["clean_scene"])
    result = calibrate(scene)
    assert not any(_CARRIES in w for w in result.warnings)
    plain = calibrate(scene, CalibrationSettings(discordant_line_t=0.0))
    assert result.focal_sigma_px == plain.focal_sigma_px
    assert result.position_sigma_m is not None
    assert plain.position_sigma_m is not None
    assert np.array_equal(result.position_sigma_m, plain.position_sigma_m)
