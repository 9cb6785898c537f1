"""The default focal prior weighs a loose photo's reading as a wrong frame's, with the frame's
chance of being wrong (``autovp._WRONG_FRAME_MIXTURE``, issue 24).

A level camera looking along a facade at a slant leaves the focal length loose: it rests on a
far-off across-street vanishing point. Where the across-street lines are not quite square to
the facade (paving joints, a kerb that bends), they pull that point and the focal length with
it, far beyond what the lines' sigma says. The Gaussian blend with the default prior then
keeps all of the pull the weights give it; the mixture lets a reading far from what cameras
are count for less, and states a sigma that covers both readings.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from camloc_geo import autovp

W_PX, H_PX = 1024, 768
F_PX = 1.0 * W_PX  # where the default prior is centred: a camera the default matches


def _sheared_street_segments(
    seed: int, shear_deg: float, n_per_direction: tuple[int, int, int]
) -> np.ndarray:
    """Segments (pixels) of a level camera (pitch 2 degrees) looking 6 degrees off a facade
    along a street; the across-street lines are turned ``shear_deg`` about the vertical,
    not square to the facade. Noise 0.4 px on each end point."""
    rng = np.random.default_rng(seed)
    cam_from_world = (
        Rotation.from_euler("x", 2.0, degrees=True).as_matrix()
        @ Rotation.from_euler("y", 6.0, degrees=True).as_matrix()
    )
    across = Rotation.from_euler("y", shear_deg, degrees=True).as_matrix() @ [1.0, 0.0, 0.0]
    directions = [np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]), across]
    pp_px = np.array([W_PX / 2, H_PX / 2])
    segs = []
    for direction, n in zip(directions, n_per_direction, strict=True):
        kept = 0
        while kept < n:
            p0_m = rng.uniform([-12.0, -8.0, 6.0], [12.0, 1.5, 40.0])
            length_m = rng.uniform(1.5, 6.0)
            ends_cam = np.array([p0_m, p0_m + length_m * direction]) @ cam_from_world.T
            if np.any(ends_cam[:, 2] < 1.0):
                continue
            uv = F_PX * ends_cam[:, :2] / ends_cam[:, 2:3] + pp_px
            if np.any(uv < 2) or np.any(uv[:, 0] > W_PX - 2) or np.any(uv[:, 1] > H_PX - 2):
                continue
            if np.hypot(*(uv[1] - uv[0])) < 40:
                continue
            segs.append(np.r_[uv[0], uv[1]] + rng.normal(0.0, 0.4, 4))
            kept += 1
    return np.array(segs)


def _detect(
    segs: np.ndarray, mixture: bool, monkeypatch: pytest.MonkeyPatch
) -> autovp.AutoVPResult:
    monkeypatch.setattr(autovp, "_WRONG_FRAME_MIXTURE", mixture)
    return autovp.detect_vanishing_points(
        None, segments=segs, image_size=(W_PX, H_PX), distortion_k1=0.0
    )


def test_a_loose_reading_far_from_the_default_moves_less_and_is_covered(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # 35 distinct lines: the frame is wrong with a chance of (25 / 35) ** 3 = 0.36, capped
    # at the measured 0.17
    segs = _sheared_street_segments(1, 7.0, (16, 14, 12))
    gauss = _detect(segs, False, monkeypatch)
    mixed = _detect(segs, True, monkeypatch)
    assert sum(mixed.n_lines) == 35
    err_gauss = math.log(gauss.focal_px / F_PX)
    err_mixed = math.log(mixed.focal_px / F_PX)
    assert err_gauss < -0.25  # -23.5 % at a stated 17 %: 1.6 sigma
    assert abs(err_gauss) > 1.5 * gauss.focal_std_rel
    assert err_gauss + 0.02 < err_mixed < 0.0  # moved towards the default, not past it
    assert abs(err_mixed) < 1.25 * mixed.focal_std_rel  # -21.7 % at 20.8 %: 1.2 sigma
    assert mixed.focal_std_rel > gauss.focal_std_rel + 0.03
    assert len(mixed.warnings) == len(gauss.warnings) == 1  # warned the same way (loose)


def test_on_few_lines_the_reading_still_counts(monkeypatch: pytest.MonkeyPatch) -> None:
    # 25 distinct lines: the cube says 1 (sure to be wrong), an extrapolation below the 40
    # lines it was measured on; capped, the reading still counts (a street camera's 25 lane
    # markings and kerbs may be right where the default is not)
    segs = _sheared_street_segments(1, 7.0, (12, 10, 8))
    gauss = _detect(segs, False, monkeypatch)
    mixed = _detect(segs, True, monkeypatch)
    assert sum(mixed.n_lines) == 25
    assert autovp._wrong_frame_chance(mixed.n_lines) == autovp._WRONG_FRAME_MAX
    err_gauss = gauss.focal_px / F_PX - 1.0
    err_mixed = mixed.focal_px / F_PX - 1.0
    assert err_gauss < err_mixed < -0.15  # -18.1 -> -16.8 %, not the default's 0 %
    assert mixed.focal_std_rel > gauss.focal_std_rel


def _model(f_n: float, logf_std: float) -> autovp._Model:
    return autovp._Model(
        R=np.eye(3),
        f_n=f_n,
        labels=np.full(2, -1, dtype=np.int64),
        score=0.0,
        logf_std=logf_std,
    )


def _no_segments() -> autovp._Segs:
    z2 = np.zeros((2, 2))
    return autovp._Segs(
        mid=z2,
        dirn=np.tile([1.0, 0.0], (2, 1)),
        length_px=np.ones(2),
        lines=np.zeros((2, 3)),
        weight=np.ones(2),
    )


@pytest.mark.parametrize(
    ("reading", "lines", "expected", "expected_std"),
    [
        # many lines: the frame is right, the Gaussian blend (0.15 and 0.35 in log): 1.487
        ((1.6, 0.15), 300, 1.487, 0.138),
        # a reading near the default barely feels the wrong-frame part (Gaussian: 1.074)
        ((1.1, 0.2), 35, 1.069, 0.191),
        # a reading twice the default on 60 lines (chance 0.07; Gaussian: 1.69 at 0.17)
        ((2.0, 0.2), 60, 1.598, 0.255),
        # on 30 lines (chance 0.58, capped at 0.17): towards the default, its sigma covering
        # both readings
        ((2.0, 0.2), 30, 1.493, 0.317),
        # the same on 25 lines: the cap holds
        ((2.0, 0.2), 25, 1.493, 0.317),
    ],
)
def test_the_mixture_arithmetic(
    reading: tuple[float, float], lines: int, expected: float, expected_std: float
) -> None:
    f_n, sd = reading
    chance = autovp._wrong_frame_chance((lines, 0, 0))
    out = autovp._with_default_prior(
        _model(f_n, sd), _no_segments(), 1.0, (0.3, 6.0), None, (1.0, 0.35), chance
    )
    assert out.f_n == pytest.approx(expected, rel=0.002)
    assert out.logf_std == pytest.approx(expected_std, abs=0.002)
    gauss_std = math.sqrt(1.0 / (1.0 / sd**2 + 1.0 / 0.35**2))
    assert out.logf_std >= gauss_std - 1e-12  # never narrower than the Gaussian blend


def test_an_infinite_default_sigma_is_no_prior() -> None:
    # the tests that switch the default off set its sigma to infinity: the photo's own
    chance = autovp._wrong_frame_chance((10, 10, 10))
    out = autovp._with_default_prior(
        _model(2.0, 0.2), _no_segments(), 1.0, (0.3, 6.0), None, (1.0, math.inf), chance
    )
    assert out.f_n == pytest.approx(2.0, rel=1e-9)
    assert out.logf_std == pytest.approx(0.2, rel=1e-9)
