"""Stop 42's sigma changes move no estimate (issue 24, item 4).

The ground-corner evidence compares the clicks' scatter with the line ends' at the settings'
own precision ratio (``ground_corner_click_ratio``; stop 41 compared them at equal
precision), and the per-group variance factors (``variance_groups``, an option) share the
pooled factor where a group has no redundancy of its own or the clicked box is not the
stated car's. Each is a change of the stated sigmas only: on 40 crowd scenes the camera and
the focal length are identical, bit for bit, and the sigmas do move.
"""

from __future__ import annotations

import numpy as np
import pytest

from camloc_geo import InputError
from camloc_geo.relative import CalibrationSettings, calibrate
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import NoiseModel, make_scene, random_camera

N_SCENES = 40


def _scenes() -> list:  # type: ignore[type-arg]
    out = []
    for seed in range(N_SCENES):
        rng = np.random.default_rng([42, seed])
        cam = random_camera(rng, height_m=(2.0, 15.0), distance_m=(8.0, 40.0), roll_deg=4.0)
        syn = make_scene(cam, rng, noise=NoiseModel(), n_annotators=int(rng.integers(3, 8)))
        syn.scene["object"] = {"preset": "sedan"}
        out.append(parse_scene(syn.scene))
    return out


@pytest.fixture(scope="module")
def scenes() -> list:  # type: ignore[type-arg]
    return _scenes()


@pytest.mark.parametrize(
    "old",
    [
        CalibrationSettings(ground_corner_click_ratio=1.0),
        CalibrationSettings(variance_groups=True),
    ],
    ids=["ground_corner_at_equal_precision", "variance_groups"],
)
def test_sigma_changes_move_no_estimate(scenes, old) -> None:  # type: ignore[no-untyped-def]
    moved = 0
    compared = 0
    for scene in scenes:
        try:
            a = calibrate(scene)
        except InputError:
            with pytest.raises(InputError):
                calibrate(scene, old)
            continue
        b = calibrate(scene, old)
        compared += 1
        np.testing.assert_array_equal(a.camera.center_in_world, b.camera.center_in_world)
        np.testing.assert_array_equal(
            a.camera.cam_from_world_rotation, b.camera.cam_from_world_rotation
        )
        assert a.camera.focal_px == b.camera.focal_px
        assert a.camera.principal_point == b.camera.principal_point
        assert a.focal_sigma_px is not None
        assert b.focal_sigma_px is not None
        moved += a.focal_sigma_px != b.focal_sigma_px
    assert compared >= 35
    assert moved >= 5  # the change does reach the sigmas


def test_the_click_ratio_is_the_settings_own() -> None:
    """None (the default): ``sigma_point_rel / sigma_line_rel``; a number overrides it."""
    scene = _scenes()[0]
    state = calibrate(scene).joint_state
    assert state is not None
    assert state.problem.ground_corner_click_ratio == pytest.approx(0.0015 / 0.0010)
    custom = CalibrationSettings(sigma_point_rel=0.003, sigma_line_rel=0.001)
    state = calibrate(scene, custom).joint_state
    assert state is not None
    assert state.problem.ground_corner_click_ratio == pytest.approx(3.0)
    state = calibrate(scene, CalibrationSettings(ground_corner_click_ratio=1.0)).joint_state
    assert state is not None
    assert state.problem.ground_corner_click_ratio == 1.0
