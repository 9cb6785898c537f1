"""``calibrate``'s focal length on the street scenes of the second generator (issue 28).

The scenes are what ``traffic_render.render_street`` annotates for a ``random_street``
camera (960x540, 6-9 m up, 3 annotators, 1 px); no video is rendered. The figures behind
the thresholds are in ``benchmarks/calibrate_traffic.py`` (docs/benchmarks.md).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from camloc_geo.api import calibrate_scene
from camloc_geo.testing.road_lines import (
    LANE_MARKINGS_Y,
    long_line_lengths,
    road_line_scene,
    street_noise,
    street_scene,
)
from camloc_geo.testing.synthetic import make_scene
from camloc_geo.testing.traffic_render import random_street


def _street_scene(seed: int, click_px: float = 1.0, lane_lines: bool = True) -> Any:
    """The camera and scene ``render_street`` makes for ``random_street(seed)``.

    ``lane_lines=False``: the car's clicks alone, as ``render_street`` annotated before the
    painted lane lines (the same draws).
    """
    cam, _ = random_street(np.random.default_rng(seed), n_vehicles=10, duration_s=20.0)
    if lane_lines:
        return street_scene(cam, seed, click_px=click_px)
    return make_scene(
        cam,
        np.random.default_rng(seed + 7),
        noise=street_noise(click_px),
        n_annotators=3,
        image_size=(960, 540),
    )


def _focal_errors(syns: list[Any]) -> tuple[np.ndarray, np.ndarray]:
    """Relative focal errors and their error/sigma of each scene."""
    err, z = [], []
    for syn in syns:
        res = calibrate_scene(syn.scene)
        assert not res.warnings, res.warnings  # no line left out, nothing suspicious
        e = res.camera.focal_px / syn.camera.focal_px - 1.0
        err.append(e)
        z.append(e * syn.camera.focal_px / res.focal_sigma_px)
    return np.array(err), np.array(z)


@pytest.mark.parametrize("seed", [100, 106, 300, 317])
@pytest.mark.parametrize("lane_lines", [True, False])
def test_street_scene_without_noise_is_exact(seed: int, lane_lines: bool) -> None:
    # the method itself has no bias on these cameras: the -4.6 % seen on seeds 100-106 is noise
    err, _ = _focal_errors([_street_scene(seed, click_px=0.0, lane_lines=lane_lines)])
    assert abs(err[0]) < 1e-3


def test_car_alone_no_focal_bias() -> None:
    # 40 cameras, the car's clicks alone with render_street's own noise: measured median
    # +0.7 %, mean +0.5 %, sd 5.8 %, 2-sigma coverage 90 %; a systematic low bias of the
    # size issue 28 saw (median -4.6 %) would fail both.
    err, z = _focal_errors([_street_scene(seed, lane_lines=False) for seed in range(300, 340)])
    assert abs(np.median(err)) < 0.02
    assert abs(np.mean(err)) < 0.02
    # the stated sigma is honest: the scatter is the annotations' information, not a bias
    assert np.mean(np.abs(z) < 2.0) >= 0.85
    assert np.median(np.abs(z)) < 1.0


def test_render_street_annotators_draw_the_painted_lane_lines() -> None:
    syn = _street_scene(500)
    cam = syn.camera
    for ann in syn.scene["annotations"]:
        lines = np.asarray(ann["vp_lines"]["length"], float)
        long_ = lines[np.hypot(lines[:, 2] - lines[:, 0], lines[:, 3] - lines[:, 1]) > 150]
        assert 1 <= len(long_) <= 2
        # each long line lies on one of the painted lines: its ends back-projected onto the
        # road are within 0.6 m (1 px noise at up to ~90 m) of a marking's y
        K_inv = np.linalg.inv(cam.img_from_cam)
        R, c = cam.cam_from_world_rotation, cam.center_in_world
        for seg in long_:
            ys = []
            for px in (seg[:2], seg[2:]):
                ray = R.T @ (K_inv @ np.array([*px, 1.0]))
                ys.append(float(c[1] + ray[1] * (-c[2] / ray[2])))
            assert min(abs(ys[0] - y) for y in LANE_MARKINGS_Y) < 0.6
            assert min(abs(ys[1] - y) for y in LANE_MARKINGS_Y) < 0.6


def test_street_scenes_within_3_percent_on_held_out_seeds() -> None:
    # Issue 28: every held-out street scene (3 annotators, 1 px, with the lane lines they
    # draw) within 3 % of the true focal length. Seeds 500-559 were not looked at while
    # choosing the annotation (seeds 300-339 were): measured max 2.6 % on 500-599, median
    # |err| 0.6 %; the car alone: 35-60 % within 3 %.
    syns = [_street_scene(seed) for seed in range(500, 560)]
    err, z = _focal_errors(syns)
    assert np.abs(err).max() < 0.03
    assert np.median(np.abs(err)) < 0.012
    # the lines are the long road lines (563-692 px there)
    lengths = [n for syn in syns for n in long_line_lengths(syn.scene)]
    assert 400 < float(np.median(lengths)) < 900
    # the sigma stays honest with the lines (not inflated: median error/sigma >= 0.4)
    assert np.mean(np.abs(z) < 2.0) >= 0.9
    assert np.median(np.abs(z)) > 0.35


def test_road_lines_pin_the_focal_length() -> None:
    # with one long lane line per annotator the street's vanishing point is pinned: measured
    # median |err| 1.0 %, 85 % of scenes within 3 %, max 6.7 % (seed 301, stated sigma 5.7 %)
    err, z = _focal_errors([road_line_scene(seed) for seed in range(300, 320)])
    assert np.median(np.abs(err)) < 0.02
    assert np.mean(np.abs(err) < 0.03) >= 0.75
    assert np.abs(err).max() < 0.08
    assert np.mean(np.abs(z) < 2.0) >= 0.9


def test_street_photo_lends_calibrate_the_painted_lines(tmp_path: Any) -> None:
    # Issue 28: the scene a radar user has carries the video, so a background frame can be
    # its image.path. On a development camera whose annotation reads the focal length 5.2 %
    # low (noise draw 11 of seed 49, stated sigma 2.4 %), the photo's painted lines (and the
    # far edge of the rendered street across it) bring it to -2.8 % (measured,
    # texture 0.05 m/px).
    import cv2

    from camloc_geo.testing.traffic_render import street_photo

    cam, _ = random_street(np.random.default_rng(49), n_vehicles=10, duration_s=20.0)
    syn = street_scene(cam, 10_000 * 49 + 11)
    plain = calibrate_scene(syn.scene)
    path = street_photo(cam, 49, tmp_path / "street.png", texture_m_per_px=0.05)
    assert path.is_absolute()
    image = cv2.imread(str(path))
    assert image is not None
    assert image.shape == (540, 960, 3)
    syn.scene["image"]["path"] = str(path)
    shot = calibrate_scene(syn.scene)
    assert shot.photo_segments.get("length", 0) >= 20  # the lane markings and kerbs
    f_true = cam.focal_px
    err_plain = plain.camera.focal_px / f_true - 1.0
    err_photo = shot.camera.focal_px / f_true - 1.0
    assert err_plain < -0.04
    assert abs(err_photo) < abs(err_plain) - 0.015
    assert shot.focal_sigma_px is not None
    assert abs(err_photo) < 2.0 * shot.focal_sigma_px / f_true  # still honest at 2 sigma


def test_render_street_names_its_background_frame_on_request(tmp_path: Any) -> None:
    from camloc_geo.testing.traffic_render import render_street, street_camera

    cam = street_camera(7.5, image_size=(320, 180))
    kw: dict[str, Any] = {"fps": 10.0, "duration_s": 0.2, "seed": 3, "texture_m_per_px": 0.1}
    without = render_street(tmp_path / "a.avi", cam, [], **kw)
    assert without.scene["image"].get("path") is None
    video = render_street(tmp_path / "b.avi", cam, [], photo=True, **kw)
    path = video.scene["image"]["path"]
    assert path == str((tmp_path / "b.png").resolve())
    import cv2

    photo = cv2.imread(path)
    assert photo is not None
    assert photo.shape == (180, 320, 3)
    # the photo is the video's frame without traffic, up to the sensor noise and the codec
    cap = cv2.VideoCapture(str(video.path))
    ok, frame = cap.read()
    cap.release()
    assert ok
    assert frame is not None
    assert float(np.median(np.abs(frame.astype(float) - photo.astype(float)))) < 6.0


def test_a_photo_that_carries_the_focal_length_is_a_witness_of_the_jackknife(
    tmp_path: Any,
) -> None:
    # Issue 28: where the photo's lines carry the answer, the stated sigma must know how much
    # it leans on them. Development camera 2738 (render_street's own draw): its annotators'
    # width lines are short, the clicks alone read the focal length +6.1 % at a stated
    # 2.9 %; the photo's painted lines (66 along the street, 10 across) bring it to +4.6 %.
    # When every leave-one-annotator-out fit kept the photo's lines, the jackknife said
    # 2.1 % (2.1 sigma off); with the photo left out in turn like an annotator it says
    # 2.9 % (1.6 sigma). Measured; the point estimate does not move.
    from camloc_geo.testing.traffic_render import street_photo

    cam, _ = random_street(np.random.default_rng(2738), n_vehicles=10, duration_s=20.0)
    syn = street_scene(cam, 2738)
    f_true = cam.focal_px
    plain = calibrate_scene(syn.scene)
    syn.scene["image"]["path"] = str(street_photo(cam, 2738, tmp_path / "street.png"))
    shot = calibrate_scene(syn.scene)
    assert set(shot.photo_segments) == {"length", "width"}
    err_plain = plain.camera.focal_px / f_true - 1.0
    err_photo = shot.camera.focal_px / f_true - 1.0
    assert 0.05 < err_plain < 0.07
    assert 0.035 < err_photo < 0.055  # the photo carries the answer ...
    assert shot.focal_sigma_px is not None
    sigma_rel = shot.focal_sigma_px / f_true
    assert abs(err_photo) < 2.0 * sigma_rel  # ... and the sigma says how much (was 2.1 sigma)
    assert abs(err_photo) > 1.0 * sigma_rel  # not by inflating it beyond the error
    # the photo's leave-out does not count as an annotator's influence
    assert len(shot.annotator_influence_m) == 3
    # the refit jackknife (a refit with photo_lines off as the photo's leave-out) agrees:
    # measured 2.82 % against the one-step's 2.93 % (their raw moves, without the leverage
    # correction both apply by default)
    from camloc_geo.relative import CalibrationSettings, calibrate
    from camloc_geo.scene import parse_scene

    slow = calibrate(
        parse_scene(syn.scene),
        CalibrationSettings(jackknife_method="refit", jackknife_leverage=False),
    )
    raw = calibrate(parse_scene(syn.scene), CalibrationSettings(jackknife_leverage=False))
    assert slow.camera.focal_px == pytest.approx(shot.camera.focal_px, rel=1e-9)
    assert slow.focal_sigma_px is not None
    assert raw.focal_sigma_px is not None
    assert slow.focal_sigma_px == pytest.approx(raw.focal_sigma_px, rel=0.15)
    assert len(slow.annotator_influence_m) == 3


def test_the_one_step_jackknife_selects_the_photo_lines_again_without_each_annotator(
    tmp_path: Any,
) -> None:
    # Development camera 300 with its photo: annotator 2 carries the scene (a refit without
    # them reads +13 %). The photo's lines join the fit where their direction agrees with
    # the annotators' own fit; without annotator 2 the others' fit is far enough off that
    # the photo's direction along the street no longer agrees, and a refit leaves its lines
    # out. The one-step jackknife kept them (2.7 %, the refits' spread 10.2 %): they stood in
    # for the annotator they had agreed with. Now it selects them again per leave-out
    # (measured 9.98 %). The point estimate does not move.
    from camloc_geo.relative import CalibrationSettings, calibrate
    from camloc_geo.scene import parse_scene
    from camloc_geo.testing.traffic_render import street_photo

    cam, _ = random_street(np.random.default_rng(300), n_vehicles=10, duration_s=20.0)
    syn = street_scene(cam, 300)
    syn.scene["image"]["path"] = str(street_photo(cam, 300, tmp_path / "street.png"))
    scene = parse_scene(syn.scene)
    fast = calibrate(scene)
    slow = calibrate(scene, CalibrationSettings(jackknife_method="refit"))
    assert fast.photo_segments
    assert fast.focal_sigma_px is not None
    assert slow.focal_sigma_px is not None
    assert abs(fast.camera.focal_px / cam.focal_px - 1.0) < 0.005
    assert slow.focal_sigma_px / cam.focal_px > 0.08  # the refits' spread
    assert fast.focal_sigma_px == pytest.approx(slow.focal_sigma_px, rel=0.15)  # was 0.27x


def _benchmark() -> Any:
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "calibrate_traffic.py"
    spec = importlib.util.spec_from_file_location("calibrate_traffic_bench", path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_benchmark_rows_carry_the_camera_height_and_its_sigma() -> None:
    bench = _benchmark()
    exact = bench.traffic_scene(106, click_px=0.0)
    row = bench.focal_row(exact.scene, exact.camera)
    assert row["height_error"] == pytest.approx(0.0, abs=1e-6)
    noisy = bench.traffic_scene(106, lane_lines=False)
    row = bench.focal_row(noisy.scene, noisy.camera)
    res = calibrate_scene(noisy.scene)
    h_true = float(noisy.camera.center_in_world[2])
    assert row["height_error"] == pytest.approx(float(res.camera.height_m) / h_true - 1.0, abs=1e-5)
    assert row["height_sigma_rel"] == pytest.approx(
        float(res.position_sigma_m[2]) / h_true, abs=1e-5
    )
    assert row["height_z"] == pytest.approx(row["height_error"] / row["height_sigma_rel"], rel=1e-2)
    summary = bench.summary([row, row])
    assert summary["height_max_abs"] == pytest.approx(abs(row["height_error"]), abs=1e-4)
    assert summary["height_cover_2sigma"] == (1.0 if abs(row["height_z"]) < 2 else 0.0)


def test_the_benchmark_keeps_video_lines_without_pickle(tmp_path: Any) -> None:
    from camloc_geo.sensors._video_lines import VideoLines

    bench = _benchmark()
    vps = np.array([[1.0, 0.0, 0.0], [np.nan] * 3, [0.0, 1.0, 1e-3]])
    lines = VideoLines(
        (960, 540),
        np.array([[1.0, 2.0, 30.0, 4.0], [5.0, 6.0, 7.0, 80.0]]),
        np.array([0, 2]),
        vps / np.linalg.norm(np.nan_to_num(vps), axis=1, keepdims=True).clip(1e-12),
        400,
        {"street": 1, "vertical": 1},
    )
    bench.save_lines(tmp_path / "s1_lines.npz", lines)
    back = bench.load_lines(tmp_path / "s1_lines.npz")
    assert back.image_size == (960, 540)
    assert np.array_equal(back.segments, lines.segments)
    assert np.array_equal(back.labels, lines.labels)
    assert np.array_equal(back.vanishing_points, lines.vanishing_points, equal_nan=True)
    assert back.n_frames == 400
    assert back.counts == lines.counts
