"""A preset's wrong proportions are shared by every annotator: the focal sigma must say so.

benchmarks/unseen_cities.py's and benchmarks/absolute.py's scenes: a car 5 % off the preset
per dimension, five annotators clicking the same wrong box. The old sigma counted the size
error as independent per click (averaged down over annotators; the jackknife cannot see a
shared error) and stated 1-2 % where the focal length was 5-20 % off.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from camloc_geo.objects import PRESETS, ObjectSize
from camloc_geo.relative import calibrate
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import NoiseModel, make_scene, random_camera

SEDAN = PRESETS["sedan"]
# The real car: 5 % longer and 5 % lower than the preset (one preset sigma each).
TRUE = ObjectSize(SEDAN.length_m * 1.05, SEDAN.width_m, SEDAN.height_m * 0.95)


def _scene(seed: int) -> tuple[dict, float]:
    rng = np.random.default_rng(seed)
    cam = random_camera(rng, height_m=(2.5, 4.0))
    syn = make_scene(cam, rng, noise=NoiseModel.exact(), true_size=TRUE)
    syn.scene["object"] = {"preset": "sedan"}
    return syn.scene, cam.focal_px


@pytest.mark.parametrize("seed", [26, 31, 38])
def test_focal_sigma_covers_a_shared_size_error(seed: int) -> None:
    """Old code: the error was 2.4, 5.3 and 2.7 stated sigmas; now 1.1, 1.2 and 1.0."""
    scene, true_f = _scene(seed)
    res = calibrate(parse_scene(scene))
    assert res.focal_sigma_px is not None
    z = abs(res.camera.focal_px - true_f) / res.focal_sigma_px
    assert z < 2.0, (res.camera.focal_px, true_f, res.focal_sigma_px)


def test_focal_sigma_holds_the_length_sensitivity() -> None:
    """The stated sigma is at least most of the answer's move under a one-sigma (5 %) longer
    preset length (old code: 0.010 of the focal length against a 0.05 move)."""
    scene, _f = _scene(31)
    res = calibrate(parse_scene(scene))
    longer = dict(scene, object={"length_m": SEDAN.length_m * 1.05})
    moved = calibrate(parse_scene(longer))
    assert res.focal_sigma_px is not None
    shift = abs(moved.camera.focal_px - res.camera.focal_px)
    assert shift > 0.02 * res.camera.focal_px  # the length matters here
    assert res.focal_sigma_px > 0.6 * shift


def test_size_given_has_no_size_term() -> None:
    """A stated true size: no preset error, the noise-free answer's sigma stays tiny."""
    scene, true_f = _scene(31)
    scene["object"] = {
        "length_m": TRUE.length_m,
        "width_m": TRUE.width_m,
        "height_m": TRUE.height_m,
    }
    res = calibrate(parse_scene(scene))
    assert res.focal_sigma_px is not None
    assert abs(res.camera.focal_px / true_f - 1.0) < 0.01
    assert res.focal_sigma_px < 0.03 * true_f


def _low_camera_scene(seed: int) -> tuple[dict, float]:
    rng = np.random.default_rng(seed)
    cam = random_camera(rng, height_m=(2.5, 3.5), distance_m=(15.0, 40.0))
    syn = make_scene(cam, rng, noise=NoiseModel())
    syn.scene["object"] = {"preset": "sedan"}
    return syn.scene, cam.focal_px


def test_a_flat_focal_profile_widens_the_sigma_and_a_better_fit_is_warned() -> None:
    """A 3 m camera 15-40 m away, crowd noise: the fit sits in a local minimum 56 % short of
    the truth. Old code: 2.2 stated sigmas off; the fit held at a longer focal length fits
    the annotations better, so now the sigma is widened (0.75 sigma) and a warning says so."""
    scene, true_f = _low_camera_scene(6)
    res = calibrate(parse_scene(scene))
    assert res.focal_sigma_px is not None
    assert res.camera.focal_px < 0.5 * true_f  # the answer itself is still wrong
    assert abs(res.camera.focal_px - true_f) < 2.0 * res.focal_sigma_px
    assert any("focal length is not well determined" in w for w in res.warnings)


def test_a_well_determined_focal_length_is_not_widened() -> None:
    """Where the profile rises as the sigma says, nothing changes (same sigma to 1e-9)."""
    import camloc_geo.relative as rel

    scene, _f = _low_camera_scene(2)
    res = calibrate(parse_scene(scene))
    assert res.joint_state is not None
    assert rel._focal_profile_widening(res) is None
    assert not any("not well determined" in w for w in res.warnings)


@pytest.mark.parametrize("seed", [2, 6])
def test_the_held_fits_early_stop_agrees_with_the_full_held_fit(seed: int) -> None:
    """The profile check's held fits stop early (below the answer's cost, or clearly above
    it); on both sides the verdict is the full fit's (seed 6: the longer side is better)."""
    import math

    import camloc_geo.relative as rel
    from camloc_geo._optimize import soft_l1_cost

    scene, _f = _low_camera_scene(seed)
    res = calibrate(parse_scene(scene))
    state = res.joint_state
    assert state is not None
    assert state.focal_px is None
    assert res.focal_sigma_px is not None
    prob = state.problem
    saved = prob.weights
    prob.weights = state.weights
    try:
        x = np.asarray(state.x, dtype=float)
        fun0 = prob.residuals(x, state.rotation0, state.principal_point, None)
        cost0 = soft_l1_cost(fun0, rel._F_SCALE)
        s2 = 2.0 * cost0 / (len(fun0) - len(x))
        sig_log = res.focal_sigma_px / res.camera.focal_px
        verdicts = []
        for side in (-1.0, 1.0):
            f_held = math.exp(float(x[0]) + side * 2.0 * sig_log)
            pc = 0.0
            if prob.log_f_prior_sigma > 0.0:
                z = (math.log(f_held) - prob.log_f_prior) / prob.log_f_prior_sigma
                pc = soft_l1_cost(np.array([z]), rel._F_SCALE)
            full = rel._fit(prob, x[1:].copy(), state.rotation0, state.principal_point, f_held)
            full_below = soft_l1_cost(full.fun, rel._F_SCALE) + pc < cost0
            quick = rel._held_focal_fit_drops(
                prob, x[1:], state.rotation0, state.principal_point, f_held, cost0 - pc, s2
            )
            assert quick == full_below
            verdicts.append(quick)
    finally:
        prob.weights = saved
    assert verdicts == ([False, True] if seed == 6 else [False, False])


def _equal_annotators(n: int, seed: int) -> dict:
    """``n`` annotators who drew the same lines and clicks (0.5 px apart): equal leverage."""
    rng = np.random.default_rng(seed)
    cam = random_camera(rng, height_m=(6.0, 8.0))
    syn = make_scene(cam, rng, noise=NoiseModel.exact(), n_annotators=1)
    base = syn.scene["annotations"][0]
    anns = []
    for k in range(n):
        axes = {
            name: (np.asarray(p) + rng.normal(0.0, 0.5, 2)).tolist()
            for name, p in base["axes"].items()
        }
        lines = {
            axis: [(np.asarray(s) + rng.normal(0.0, 0.5, 4)).tolist() for s in segs]
            for axis, segs in base["vp_lines"].items()
        }
        anns.append({"annotator": f"a{k}", "axes": axes, "vp_lines": lines})
    syn.scene["annotations"] = anns
    syn.scene["object"] = {"preset": "sedan"}
    return syn.scene


def test_leverage_of_equal_annotators_is_one_over_n() -> None:
    """Annotators doing the same work each hold 1/n of every quantity: the jackknife's moves
    are scaled by √(1 − 1/n) (the delete-one jackknife is then unbiased as it stands)."""
    from camloc_geo.relative import _leverage_factors

    n = 4
    res = calibrate(parse_scene(_equal_annotators(n, 5)))
    assert res.joint_state is not None
    lev = _leverage_factors(res.joint_state, list(range(n)))
    assert lev is not None
    assert lev.shape == (n, 7)
    np.testing.assert_allclose(lev, np.sqrt(1.0 - 1.0 / n), atol=0.03)


def test_leverage_option_never_widens_the_jackknife() -> None:
    """With ``jackknife_leverage`` (the default since stop 38) each leave-out's move shrinks
    (factors in (0, 1]), so the stated sigmas (the larger of the fit's and the jackknife's)
    do not grow; off they are as before."""
    from camloc_geo.relative import CalibrationSettings

    rng = np.random.default_rng(11)
    cam = random_camera(rng)
    syn = make_scene(cam, rng, noise=NoiseModel(), n_annotators=5)
    syn.scene["object"] = {"preset": "sedan"}
    scene = parse_scene(syn.scene)
    off = calibrate(scene, CalibrationSettings(jackknife_leverage=False))
    on = calibrate(scene)
    assert off.focal_sigma_px is not None
    assert on.focal_sigma_px is not None
    assert on.focal_sigma_px <= off.focal_sigma_px * (1.0 + 1e-9)
    assert off.position_sigma_jackknife_m is not None
    assert on.position_sigma_jackknife_m is not None
    assert np.all(on.position_sigma_jackknife_m <= off.position_sigma_jackknife_m + 1e-12)
    assert np.any(on.position_sigma_jackknife_m < 0.99 * off.position_sigma_jackknife_m)


def _class_scene(true: ObjectSize, seed: int) -> tuple[dict, float]:
    rng = np.random.default_rng(seed)
    cam = random_camera(rng, height_m=(6.0, 12.0))
    syn = make_scene(cam, rng, noise=NoiseModel.exact(), true_size=true)
    syn.scene["object"] = {"preset": "sedan"}
    return syn.scene, cam.height_m


@pytest.mark.parametrize("seed", [1, 2, 5, 7])
def test_an_suv_called_a_sedan_is_named(seed: int) -> None:
    """Exact clicks on an SUV (1.70 m roof) stated as a sedan: its proportions (height
    x1.17) are within the sedan's 5 % sigmas' reach, so the proportion test is silent; the
    class comparison names the SUV and widens the position sigmas to cover the height.
    Not every SUV: of seeds 1-11 the comparison names 6 (these four among them), the older
    proportion test one more (seed 3); the other four look like a sedan within the clicks'
    and the preset's noise (old code: none named)."""
    scene, true_h = _class_scene(PRESETS["suv"], seed)
    res = calibrate(parse_scene(scene))
    named = [w for w in res.warnings if "better than the stated sedan's" in w]
    assert len(named) == 1, res.warnings
    assert "fit a suv's (4.70 x 1.88 x 1.70 m)" in named[0]
    assert res.position_sigma_m is not None
    assert abs(res.camera.height_m - true_h) < 2.0 * float(res.position_sigma_m[2])


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_sedan_is_not_called_another_class(seed: int) -> None:
    scene, _h = _class_scene(SEDAN, seed)
    res = calibrate(parse_scene(scene))
    assert not [w for w in res.warnings if "better than the stated" in w], res.warnings


def test_unequal_annotators_sigma_is_not_inflated() -> None:
    """Four crowd annotators doing unequal work (``calibrate_coverage.py``'s crowd set, seed 7,
    scene 164: w1 and w2 drew the long lines, 205-338 px, w3 and w4 only short ones): the
    delete-one jackknife moved the focal length by w1's and w2's whole leverage and stated
    26 px for an error of 6 px (0.22 sigma; stop 37's default, ``jackknife_leverage`` off).
    The leverage correction scales each move by ``√(1 − h)`` (w1 and w2 0.23-0.36 on the
    focal length, w3 and w4 0.98): 9 px, the error 0.6 sigma, and the fit's own covariance
    is not undercut."""
    from camloc_geo.relative import CalibrationSettings, _leverage_factors

    case = json.loads(
        (Path(__file__).parent / "data" / "calibrate_unequal_annotators.json").read_text()
    )
    scene = parse_scene(case["scene"])
    true_f = case["truth"]["focal_px"]
    old = calibrate(scene, CalibrationSettings(jackknife_leverage=False, car_class_prior=0.0))
    res = calibrate(scene)
    assert old.focal_sigma_px is not None
    assert res.focal_sigma_px is not None
    err = abs(res.camera.focal_px - true_f)
    assert err / old.focal_sigma_px < 0.3  # the inflated sigma
    assert res.focal_sigma_px < 0.5 * old.focal_sigma_px
    assert 0.4 < err / res.focal_sigma_px < 1.0
    assert res.joint_state is not None
    lev = _leverage_factors(res.joint_state, list(range(4)))
    assert lev is not None
    assert np.all(lev[:2, 0] < 0.4)
    assert np.all(lev[2:, 0] > 0.9)
    # Not below the fit's own covariance (the jackknife only ever adds to it).
    fit = calibrate(scene, CalibrationSettings(jackknife=False))
    assert fit.focal_sigma_px is not None
    assert res.focal_sigma_px >= fit.focal_sigma_px * (1.0 - 1e-9)
