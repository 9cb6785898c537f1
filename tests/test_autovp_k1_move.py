"""The lens-distortion fit's move of the focal length enters the stated focal sigma.

Bowed edges and a lens's bowing look alike: where the fitted ``k1`` is applied, how far it
moves the focal length from the straight-lens reading is a model term of ``focal_std_rel``
(``focal_std_parts["distortion"]``), warned of above 10 %. On real photos the k1 fit moved
a compact's focal length from -5 % (k1 = 0) to -43 % at a k1 sigma of 0.004
(benchmarks/README.md, "Stop 41: the k1 fit and the focal sigma").
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import numpy.typing as npt
import pytest

from camloc_geo.autovp import detect_vanishing_points
from camloc_geo.camera import Camera, RadialDistortion, rotation_from_angles

W, H = 1280, 960
PP = (640.0, 480.0)
F_PX = 800.0


def _box_segments(sag_rel: float = 0.0, k1: float = 0.0, seed: int = 1) -> npt.NDArray[np.float64]:
    """Long lines of a box scene, each drawn as a chain of six short segments (pixels).

    ``sag_rel``: the lines along the first axis sag in the middle by this share of their
    length (cables, a bowed eave: edges that are not straight, through a straight lens).
    ``k1``: the lens's division-model distortion. End points get 0.3 px of noise.
    """
    rng = np.random.default_rng(seed)
    cam = Camera.from_center(F_PX, PP, rotation_from_angles(35.0, 12.0, 2.0), [-25.0, -30.0, 6.0])
    if k1:
        cam = Camera(
            F_PX,
            PP,
            cam.cam_from_world_rotation,
            cam.cam_from_world_translation,
            RadialDistortion.for_image(k1, W, H),
        )
    t = np.linspace(0.0, 1.0, 7)[:, None]
    segs = []
    for axis in range(3):
        for _ in range(14):
            p0 = rng.uniform([-10, -10, 0], [10, 10, 12])
            length_m = rng.uniform(6, 14)
            pts_world = p0 + t * np.eye(3)[axis] * length_m
            if axis == 0:
                pts_world = pts_world - sag_rel * length_m * 4.0 * t * (1.0 - t) * np.eye(3)[2]
            px = cam.project(pts_world)
            for a, b in itertools.pairwise(px):
                if np.all(np.isfinite([*a, *b])) and np.all((a > 0) & (a < [W, H])):
                    segs.append([*a, *b])
    out = np.array(segs)
    return out + np.random.default_rng(0).normal(0.0, 0.3, out.shape)


@pytest.mark.parametrize("sag_rel", [0.04, 0.06])
def test_sagging_lines_taken_for_distortion_are_in_the_focal_sigma(sag_rel: float) -> None:
    # a straight lens; the sag poses as pincushion distortion and the k1 fit takes it
    res = detect_vanishing_points(None, segments=_box_segments(sag_rel), image_size=(W, H))
    assert res.distortion > 0.05
    term = res.focal_std_parts["distortion"]
    assert term > 0.10
    assert res.focal_std_rel >= term
    # the answer is far off; without the term its sigma left the truth beyond 2 sigma
    err_log = abs(math.log(res.focal_px / F_PX))
    assert err_log > 0.3
    assert err_log <= 2.0 * res.focal_std_rel
    assert any("lens distortion fitted" in w for w in res.warnings)


def test_a_true_barrel_lens_keeps_its_answer_and_states_the_move() -> None:
    segs = _box_segments(k1=-0.15)
    res = detect_vanishing_points(None, segments=segs, image_size=(W, H))
    straight = detect_vanishing_points(
        None, segments=segs, image_size=(W, H), estimate_distortion=False
    )
    assert res.distortion == pytest.approx(-0.15, abs=0.03)
    # the right k1 fit's answer is not pulled toward the default prior by the term
    assert abs(res.focal_px / F_PX - 1.0) < 0.06
    assert abs(straight.focal_px / F_PX - 1.0) > 0.2
    term = res.focal_std_parts["distortion"]
    assert term > 0.05
    assert res.focal_std_rel >= term


def test_straight_lines_get_no_distortion_term() -> None:
    segs = _box_segments()
    res = detect_vanishing_points(None, segments=segs, image_size=(W, H))
    off = detect_vanishing_points(None, segments=segs, image_size=(W, H), estimate_distortion=False)
    assert res.distortion == 0.0
    assert res.focal_std_parts["distortion"] == 0.0
    assert res.focal_px == pytest.approx(off.focal_px, rel=1e-9)
    assert res.focal_std_rel == pytest.approx(off.focal_std_rel, rel=1e-9)
    assert not any("lens distortion fitted" in w for w in res.warnings)
