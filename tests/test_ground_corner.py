"""The ground-corner ambiguity of a rounded car enters calibrate's stated sigmas (issue 24)."""

from __future__ import annotations

import copy

import numpy as np

from camloc_geo.relative import CalibrationSettings, calibrate
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import NoiseModel, make_scene, random_camera


def _tyre_contact_scene(seed: int) -> tuple[dict, float, float]:
    """A noise-free one-annotator scene whose origin click is at the tyre contact.

    The click is moved from the ground under the bumper corner by 0.2-0.4 m along the
    car's length. Returns the scene, the true focal length and the shift (m).
    """
    rng = np.random.default_rng(seed)
    cam = random_camera(rng)
    syn = make_scene(cam, rng, noise=NoiseModel.exact(), n_annotators=1)
    scene = copy.deepcopy(syn.scene)
    shift_m = float(rng.uniform(0.2, 0.4))
    moved = cam.project(np.array([[shift_m, 0.0, 0.0], [0.0, 0.0, 0.0]]))
    origin = np.asarray(scene["annotations"][0]["axes"]["origin"], float)
    scene["annotations"][0]["axes"]["origin"] = (origin + moved[0] - moved[1]).tolist()
    return scene, float(cam.focal_px), shift_m


def test_tyre_contact_click_is_inside_the_stated_focal_sigma() -> None:
    off = CalibrationSettings(ground_corner_sigma_rel=0.0)
    on = CalibrationSettings()
    assert on.ground_corner_sigma_rel == 0.025
    z_off, z_on, sig_ratio = [], [], []
    for seed in range(12):
        scene, f_true, _ = _tyre_contact_scene(seed)
        before = calibrate(parse_scene(scene), off)
        after = calibrate(parse_scene(scene), on)
        assert before.focal_sigma_px is not None
        assert after.focal_sigma_px is not None
        # The same fit: only the stated uncertainty changes.
        assert abs(after.camera.focal_px - before.camera.focal_px) < 1e-6 * f_true
        z_off.append(abs(before.camera.focal_px - f_true) / before.focal_sigma_px)
        z_on.append(abs(after.camera.focal_px - f_true) / after.focal_sigma_px)
        sig_ratio.append(after.focal_sigma_px / before.focal_sigma_px)
    z_off_a, z_on_a = np.array(z_off), np.array(z_on)
    assert np.count_nonzero(z_on_a <= 2.0) >= np.count_nonzero(z_off_a <= 2.0)
    assert np.median(z_on_a) < 0.9 * np.median(z_off_a)
    assert min(sig_ratio) >= 1.0
    assert np.median(sig_ratio) > 1.05
    # Modest: the sigma grows, it is not blown up.
    assert max(sig_ratio) < 5.0
