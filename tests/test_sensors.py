"""Virtual scale and clinometer (camloc_geo.sensors, ``camloc measure``)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import camera_aimed_at_car, exact_scene

from camloc_geo._errors import InputError
from camloc_geo.api import calibrate_scene
from camloc_geo.camera import Camera
from camloc_geo.cli import main
from camloc_geo.relative import CalibrationResult
from camloc_geo.sensors import ground_distance, point_height
from camloc_geo.testing.synthetic import NoiseModel, make_scene

GROUND_PTS = np.array([[3.0, -4.0, 0.0], [10.0, -2.0, 0.0], [12.0, 3.0, 0.0]])
TRUE_LENGTH = float(np.linalg.norm(np.diff(GROUND_PTS, axis=0), axis=1).sum())
BASE, TOP = np.array([8.0, 4.0, 0.0]), np.array([8.0, 4.0, 7.5])


@pytest.fixture(scope="module")
def camera() -> Camera:
    return camera_aimed_at_car(6.0, 20.0)


@pytest.fixture(scope="module")
def scene(camera: Camera) -> dict[str, Any]:
    return exact_scene(camera)


@pytest.fixture(scope="module")
def calibration(scene: dict[str, Any]) -> CalibrationResult:
    return calibrate_scene(scene)


def test_ground_distance_exact(camera: Camera, calibration: CalibrationResult) -> None:
    m = ground_distance(calibration, camera.project(GROUND_PTS))
    assert m.value_m == pytest.approx(TRUE_LENGTH, rel=1e-3)
    # 1.5 px clicks at ~20 m give decimetres, not metres
    assert 0.0 < m.sigma_m < 0.05 * TRUE_LENGTH
    assert m.to_dict()["distance_m"] == m.value_m


def test_point_height_exact(camera: Camera, calibration: CalibrationResult) -> None:
    base, top = camera.project(np.array([BASE, TOP]))
    m = point_height(calibration, base, top)
    assert m.value_m == pytest.approx(7.5, rel=1e-3)
    assert 0.0 < m.sigma_m < 0.5
    assert set(m.to_dict()) == {"height_m", "sigma_m", "n_samples"}


def test_sigma_grows_with_click_noise(camera: Camera, calibration: CalibrationResult) -> None:
    px = camera.project(GROUND_PTS)
    base = ground_distance(calibration, px, click_sigma_px=0.0).sigma_m  # calibration only
    small = ground_distance(calibration, px, click_sigma_px=0.5).sigma_m
    large = ground_distance(calibration, px, click_sigma_px=3.0).sigma_m
    # the clicks' share of the variance grows with the square of their noise (36x here);
    # the calibration's own share (its ground-corner term included) stays
    assert base < small < large
    assert (large**2 - base**2) > 10.0 * (small**2 - base**2)


def test_noisy_scenes_within_sigma_bound() -> None:
    """With annotation noise, the errors stay within 3 sigma in most scenes."""
    rng = np.random.default_rng(7)
    noise = NoiseModel(wrong_corner_prob=0.0, sloppy_prob=0.0, size_rel=0.0)
    inside_d = inside_h = 0
    n = 6
    for i in range(n):
        cam = camera_aimed_at_car(5.0 + i, 15.0 + 2 * i, azimuth_deg=200.0 + 10 * i)
        syn = make_scene(cam, rng, noise=noise, n_annotators=5)
        cal = calibrate_scene(syn.scene)
        d = ground_distance(cal, cam.project(GROUND_PTS))
        h = point_height(cal, *cam.project(np.array([BASE, TOP])))
        inside_d += abs(d.value_m - TRUE_LENGTH) <= 3.0 * d.sigma_m + 0.05 * TRUE_LENGTH
        inside_h += abs(h.value_m - 7.5) <= 3.0 * h.sigma_m + 0.05 * 7.5
        assert abs(d.value_m - TRUE_LENGTH) < 0.2 * TRUE_LENGTH
        assert abs(h.value_m - 7.5) < 0.25 * 7.5
    assert inside_d >= n - 1
    assert inside_h >= n - 1


def test_above_horizon_is_refused(camera: Camera, calibration: CalibrationResult) -> None:
    px = camera.project(GROUND_PTS)
    sky = [960.0, 5.0]
    with pytest.raises(InputError, match=r"pixel \(960, 5\) is at or above the horizon"):
        ground_distance(calibration, [px[0], sky])
    with pytest.raises(InputError, match="above the horizon"):
        point_height(calibration, sky, [960.0, 0.0])


def test_top_below_base_is_refused(camera: Camera, calibration: CalibrationResult) -> None:
    base = camera.project(BASE)
    top = base + np.array([0.0, 40.0])
    with pytest.raises(InputError, match="is below its base pixel"):
        point_height(calibration, base, top)


def test_bad_pixel_arrays(calibration: CalibrationResult) -> None:
    with pytest.raises(InputError, match="at least two"):
        ground_distance(calibration, [[900.0, 900.0]])
    with pytest.raises(InputError, match="finite"):
        ground_distance(calibration, [[900.0, float("nan")], [900.0, 800.0]])
    with pytest.raises(InputError, match="pairs"):
        ground_distance(calibration, [[1.0, 2.0, 3.0]])


# ---------------------------------------------------------------- command line
@pytest.fixture(scope="module")
def scene_file(scene: dict[str, Any], tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("measure") / "scene.json"
    path.write_text(json.dumps(scene))
    return path


def _uv(p: np.ndarray) -> str:
    return f"{p[0]:.6f},{p[1]:.6f}"


def test_cli_ground_and_height(
    camera: Camera, scene_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    px = camera.project(GROUND_PTS)
    assert main(["measure", str(scene_file), "--ground", *(_uv(p) for p in px)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["distance_m"] == pytest.approx(TRUE_LENGTH, rel=1e-3)
    assert out["sigma_m"] > 0
    base, top = camera.project(np.array([BASE, TOP]))
    assert main(["measure", str(scene_file), "--height", _uv(base), _uv(top)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["height_m"] == pytest.approx(7.5, rel=1e-3)


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--ground", "960,5", "900,900"], "above the horizon"),
        (["--ground", "900,900"], "at least two"),
        (["--ground", "900;900", "900,800"], "is not U,V"),
        (["--height", "900,900", "900,1000"], "below its base"),
    ],
)
def test_cli_bad_pixels_exit_2(
    scene_file: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    assert main(["measure", str(scene_file), *extra]) == 2
    err = capsys.readouterr().err
    assert message in err
    assert len(err.strip().splitlines()) == 1
    assert "Traceback" not in err


def test_cli_missing_scene_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["measure", str(tmp_path / "nope.json"), "--ground", "1,2", "3,4"]) == 2
    assert "Traceback" not in capsys.readouterr().err


def test_rotation_sigma_reported_and_propagated() -> None:
    """The calibration reports its orientation's uncertainty; the sensors draw rotations."""
    from dataclasses import replace

    from camloc_geo.results import calibration_output

    cam = camera_aimed_at_car(7.0, 22.0, azimuth_deg=215.0)
    noise = NoiseModel(wrong_corner_prob=0.0, sloppy_prob=0.0, size_rel=0.0)
    syn = make_scene(cam, np.random.default_rng(11), noise=noise, n_annotators=5)
    cal = calibrate_scene(syn.scene)
    sig = cal.rotation_sigma_deg
    assert sig is not None
    assert sig.shape == (3,)
    assert np.all(sig > 0.0)
    assert np.all(sig < 5.0)
    assert cal.rotation_sigma_fit_deg is not None
    assert np.all(cal.rotation_sigma_fit_deg <= sig + 1e-12)  # the jackknife only adds
    assert cal.to_dict()["rotation_sigma_deg"] == sig.tolist()
    assert calibration_output(cal).rotation_sigma_deg == sig.tolist()
    px = cam.project(GROUND_PTS)
    with_rot = ground_distance(cal, px).sigma_m
    # Drawn independently (no covariance), the rotation adds to the spread ...
    independent = replace(cal, parameter_covariance=None)
    without = ground_distance(replace(independent, rotation_sigma_deg=None), px).sigma_m
    assert ground_distance(independent, px).sigma_m > without
    # ... drawn with the fit's correlations, the rotation compensates the principal point
    # and the focal length it trades against: leaving it out widens the spread.
    assert cal.parameter_covariance is not None
    assert ground_distance(replace(cal, rotation_sigma_deg=None), px).sigma_m > with_rot
    bigger = ground_distance(replace(cal, rotation_sigma_deg=sig * 10.0), px).sigma_m
    assert bigger > 2.0 * with_rot


def test_cli_output_never_overwrites_the_scene(
    scene_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``camloc measure scene.json ... -o scene.json`` replaced the scene with the
    measurement; it is refused before any work, and the scene kept."""
    before = scene_file.read_text()
    args = ["measure", str(scene_file), "--height", "900,900", "900,800", "-o", str(scene_file)]
    assert main(args) == 2
    assert "would overwrite the input" in capsys.readouterr().err
    assert scene_file.read_text() == before


def test_draws_lost_beyond_the_horizon_are_warned(
    camera: Camera, calibration: CalibrationResult
) -> None:
    """A pixel just below the horizon: some perturbed cameras see it above, their distance is
    unbounded, and the spread of the rest understates the sigma: said, not silent (session 38:
    n_samples 307 of 400 with no word)."""
    near = camera.project(GROUND_PTS)[0]
    partial = None
    for v in np.arange(0.0, 1080.0, 2.0):
        try:
            m = ground_distance(calibration, [near, [960.0, v]])
        except InputError:
            continue
        if m.n_samples < 400:
            partial = m
            break
    assert partial is not None, "no pixel near the horizon lost draws"
    assert len(partial.warnings) == 1
    assert f"{400 - partial.n_samples} of 400 perturbed cameras" in partial.warnings[0]
    assert partial.to_dict()["warnings"] == list(partial.warnings)
    far = ground_distance(calibration, camera.project(GROUND_PTS)[:2])
    assert far.n_samples == 400
    assert far.warnings == ()
    assert "warnings" not in far.to_dict()
