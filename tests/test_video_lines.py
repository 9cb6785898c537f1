"""The video as a calibration witness (issue 28): camloc_geo.sensors._video_lines."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camloc_geo import InputError
from camloc_geo.api import calibrate_scene
from camloc_geo.relative import CalibrationSettings
from camloc_geo.sensors._video_lines import GROUPS, VideoLines, _residual_px, video_lines
from camloc_geo.testing.road_lines import street_noise
from camloc_geo.testing.synthetic import make_scene
from camloc_geo.testing.traffic_render import (
    RenderedVideo,
    random_street,
    render_street,
    street_camera,
)

# Development camera 0 of benchmarks/calibrate_traffic.py (random_street(0)), its car
# annotated alone by 3 annotators with 1 px noise (noise draw 2000): short width and height
# lines only, the focal length 6.7 % high. Its video's vehicles give the across-street and
# vertical points.
SEED = 0
NOISE_SEED = 2000


def _axis_angle_deg(vp: np.ndarray, cam: Any, axis: int) -> float:
    f, pp, R = cam.focal_px, cam.principal_point, cam.cam_from_world_rotation
    K = np.array([[f, 0.0, pp[0]], [0.0, f, pp[1]], [0.0, 0.0, 1.0]])
    d = np.linalg.solve(K, vp)
    c = abs(float(R[:, axis] @ d)) / float(np.linalg.norm(d))
    return math.degrees(math.acos(min(1.0, c)))


@pytest.fixture(scope="module")
def street(tmp_path_factory: pytest.TempPathFactory) -> tuple[RenderedVideo, VideoLines]:
    cam, vehicles = random_street(np.random.default_rng(SEED), n_vehicles=6, duration_s=12.0)
    path = tmp_path_factory.mktemp("video_lines") / "street.avi"
    video = render_street(path, cam, vehicles, duration_s=12.0, seed=SEED, texture_m_per_px=0.05)
    return video, video_lines(video.path, image_size=video.image_size)


def _car_only_scene(cam: Any) -> dict[str, Any]:
    syn = make_scene(
        cam,
        np.random.default_rng(SEED + NOISE_SEED + 7),
        noise=street_noise(1.0),
        n_annotators=3,
        image_size=(960, 540),
    )
    return syn.scene


def test_groups_meet_at_the_true_vanishing_points(
    street: tuple[RenderedVideo, VideoLines],
) -> None:
    video, lines = street
    cam = video.camera
    assert lines.image_size == (960, 540)
    f, pp, R = cam.focal_px, cam.principal_point, cam.cam_from_world_rotation
    K = np.array([[f, 0.0, pp[0]], [0.0, f, pp[1]], [0.0, 0.0, 1.0]])
    for k, name in enumerate(GROUPS):
        segs = lines.group(name)
        assert len(segs) >= 12, (name, lines.counts)
        # the segments of each group pass through the true vanishing point of its axis
        res = _residual_px(segs, K @ R[:, k])
        assert float(np.median(res)) < 0.5, (name, float(np.median(res)))
    # the tracks pin the street's point: well under a degree
    assert _axis_angle_deg(lines.vanishing_points[0], cam, 0) < 0.5
    assert lines.counts["street"] > lines.counts["across"]
    d = lines.to_dict()
    assert set(d["segments"]) >= set(GROUPS)
    assert d["frames"] == video.n_frames


def test_static_scenery_never_counts(tmp_path: Path) -> None:
    # A street without traffic: the renderer's street end and painted lines are static.
    cam = street_camera(7.0)
    video = render_street(
        tmp_path / "empty.avi", cam, [], duration_s=2.0, seed=1, texture_m_per_px=0.05
    )
    lines = video_lines(video.path)
    assert len(lines.segments) == 0
    assert lines.counts["edges"] == 0
    assert lines.counts["tracks"] == 0
    assert np.all(np.isnan(lines.vanishing_points))


def test_the_video_brings_a_loose_car_only_scene_within_3_percent(
    street: tuple[RenderedVideo, VideoLines],
) -> None:
    video, lines = street
    scene = _car_only_scene(video.camera)
    f_true = video.camera.focal_px
    without = calibrate_scene(scene)
    assert abs(without.camera.focal_px / f_true - 1.0) > 0.05  # the old answer: 6.7 % off
    assert not without.video_segments
    with_video = calibrate_scene(scene, settings=CalibrationSettings(video_lines=lines))
    err = with_video.camera.focal_px / f_true - 1.0
    assert abs(err) < 0.03, err
    assert set(with_video.video_segments) == {"length", "width", "height"}
    assert with_video.to_dict()["video_segments"] == with_video.video_segments
    # honest: the error is within 2 stated sigmas, and the jackknife left the video out
    assert with_video.focal_sigma_px is not None
    assert abs(err) * f_true < 2.0 * with_video.focal_sigma_px
    assert not any(w.startswith("video") for w in with_video.warnings)


def test_calibrate_scene_takes_the_video_path(street: tuple[RenderedVideo, VideoLines]) -> None:
    video, lines = street
    scene = _car_only_scene(video.camera)
    a = calibrate_scene(scene, video=video.path)
    b = calibrate_scene(scene, settings=CalibrationSettings(video_lines=lines))
    assert a.camera.focal_px == pytest.approx(b.camera.focal_px, rel=1e-9)
    assert a.video_segments == b.video_segments


def test_a_video_of_another_camera_is_warned_and_not_used(
    street: tuple[RenderedVideo, VideoLines],
) -> None:
    _video, lines = street
    # Another camera's scene (same frame size, rolled 8 degrees): the video's lines disagree.
    other = street_camera(7.5, hfov_deg=60.0, along_m=-10.0, aim_xy_m=(8.0, -6.0), roll_deg=8.0)
    syn = make_scene(
        other,
        np.random.default_rng(3),
        noise=street_noise(1.0),
        n_annotators=3,
        image_size=(960, 540),
    )
    plain = calibrate_scene(syn.scene)
    res = calibrate_scene(syn.scene, settings=CalibrationSettings(video_lines=lines))
    warned = [w for w in res.warnings if w.startswith("video: its")]
    assert warned, res.warnings
    assert "disagree" in warned[0]
    assert len(res.video_segments) < 3
    if not res.video_segments:
        assert res.camera.focal_px == pytest.approx(plain.camera.focal_px, rel=1e-9)


def test_a_video_of_another_size_is_refused(tmp_path: Path) -> None:
    cam = street_camera(7.0, image_size=(480, 270))
    video = render_street(tmp_path / "small.avi", cam, [], duration_s=1.0, seed=1)
    with pytest.raises(InputError, match="480x270"):
        video_lines(video.path, image_size=(960, 540))


def test_bad_video_path_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="video"):
        video_lines(tmp_path / "missing.avi")
    bad = tmp_path / "bad.avi"
    bad.write_text("not a video")
    with pytest.raises(InputError, match="video"):
        video_lines(bad)


def test_cli_calibrate_video_option(
    street: tuple[RenderedVideo, VideoLines], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from camloc_geo.cli import main

    video, _lines = street
    scene_path = tmp_path / "scene.json"
    scene_path.write_text(json.dumps(_car_only_scene(video.camera)))
    assert main(["calibrate", str(scene_path)]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert "video_segments" not in plain
    assert main(["calibrate", str(scene_path), "--video", str(video.path)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out["video_segments"]) == {"length", "width", "height"}
    f_true = video.camera.focal_px
    assert abs(out["focal_px"] / f_true - 1.0) < 0.03
    assert abs(plain["focal_px"] / f_true - 1.0) > 0.05


def test_cli_radar_says_which_witnesses_calibrated_it(
    street: tuple[RenderedVideo, VideoLines], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from camloc_geo.cli import main

    video, _lines = street
    scene_path = tmp_path / "scene.json"
    scene_path.write_text(json.dumps(_car_only_scene(video.camera)))
    args = ["radar", str(video.path), "--scene", str(scene_path), "--max-frames", "60"]
    assert main([*args, "--no-video-lines"]) == 0
    plain = json.loads(capsys.readouterr().out)["calibration"]
    assert plain["witnesses"] == ["annotators"]
    assert "video_segments" not in plain
    assert main([*args, "--video-lines"]) == 0
    used = json.loads(capsys.readouterr().out)["calibration"]
    assert used["witnesses"] == ["annotators", "video"]
    # --max-frames 60 bounds the video's lines too: those of the first 60 frames only (the
    # street's and across points; too few uprights in 60 frames for the vertical one)
    first_60 = video_lines(video.path, image_size=video.image_size, max_frames=60)
    assert first_60.n_frames == 60
    # (the counts themselves move with the OpenCV build's decoder and detector: 156/29 here,
    # 158/34 in a clean clone's environment)
    assert set(used["video_segments"]) == {"length", "width"}
    assert used["video_segments"]["width"] >= 10
    assert used["video_segments"]["length"] == first_60.counts["street"]
    f_true = video.camera.focal_px
    assert abs(used["focal_px"] / f_true - 1.0) < 0.03
    assert abs(plain["focal_px"] / f_true - 1.0) > 0.05


def test_photo_and_video_are_two_witness_groups_of_the_jackknife(
    street: tuple[RenderedVideo, VideoLines], tmp_path: Path
) -> None:
    from camloc_geo.testing.traffic_render import street_photo

    video, lines = street
    scene = _car_only_scene(video.camera)
    scene["image"]["path"] = str(street_photo(video.camera, SEED, tmp_path / "street.png"))
    f_true = video.camera.focal_px
    one = calibrate_scene(scene, settings=CalibrationSettings(video_lines=lines))
    refit = calibrate_scene(
        scene, settings=CalibrationSettings(video_lines=lines, jackknife_method="refit")
    )
    assert one.photo_segments
    assert set(one.video_segments) == {"length", "width", "height"}
    assert one.camera.focal_px == pytest.approx(refit.camera.focal_px, rel=1e-9)
    assert abs(one.camera.focal_px / f_true - 1.0) < 0.03
    # the one-step jackknife (two witness groups beside the annotators) as the refits
    assert one.focal_sigma_px == pytest.approx(refit.focal_sigma_px, rel=0.25)
    # without the video the photo alone leaves this scene loose
    photo_only = calibrate_scene(scene)
    assert photo_only.focal_sigma_px is not None
    assert one.focal_sigma_px is not None
    assert photo_only.focal_sigma_px > 2.0 * one.focal_sigma_px


def test_video_lines_reads_no_more_than_max_frames(
    street: tuple[RenderedVideo, VideoLines],
) -> None:
    video, lines = street
    assert lines.n_frames == 240  # the whole 12 s video at 20 fps (under the 600 default)
    first = video_lines(video.path, image_size=video.image_size, max_frames=30)
    assert first.n_frames == 30
    assert first.counts["tracks"] < lines.counts["tracks"] / 4
    for bad in (0, -5):
        with pytest.raises(InputError, match=f"max_frames must be >= 1, not {bad}"):
            video_lines(video.path, max_frames=bad)
    with pytest.raises(InputError, match="whole number"):
        video_lines(video.path, max_frames=2.5)  # type: ignore[arg-type]


def _write_video(path: Path, n_frames: int, size: tuple[int, int] = (960, 540)) -> Path:
    import cv2

    fourcc = cv2.VideoWriter_fourcc(*"MJPG")  # type: ignore[attr-defined]
    out = cv2.VideoWriter(str(path), fourcc, 20.0, size)
    for i in range(n_frames):
        out.write(np.full((size[1], size[0], 3), 60 + i, dtype=np.uint8))
    out.release()
    return path


def test_bad_videos_for_calibrate_exit_2_with_one_line(
    street: tuple[RenderedVideo, VideoLines], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import cv2

    from camloc_geo.cli import main

    video, _lines = street
    scene_path = tmp_path / "scene.json"
    scene_path.write_text(json.dumps(_car_only_scene(video.camera)))
    photo = tmp_path / "frame.jpg"
    cv2.imwrite(str(photo), np.full((540, 960, 3), 90, dtype=np.uint8))
    cases = {
        # a still image: not "speeds need ..." (calibrate measures no speed)
        str(photo): "has a single frame (a still image?): its lines need a video",
        # a file OpenCV opens but of no frame: it was silently ignored (exit 0)
        str(_write_video(tmp_path / "zero.avi", 0)): "cannot decode any frame of video",
        str(tmp_path): "is not a regular file",
    }
    for path, message in cases.items():
        assert main(["calibrate", str(scene_path), "--video", path]) == 2, path
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1, (path, err)
        assert message in err[0], (path, err)
    for args, message in (
        (["--max-frames", "0", "--video", str(video.path)], "--max-frames must be >= 1, not 0"),
        (["--max-frames", "5"], "--max-frames needs --video VIDEO"),
    ):
        assert main(["calibrate", str(scene_path), *args]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1, (args, err)
        assert message in err[0], (args, err)


def test_a_video_without_lines_is_warned_and_the_scene_calibrates_alone(
    street: tuple[RenderedVideo, VideoLines],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture,
) -> None:
    from camloc_geo.cli import main

    video, _lines = street
    scene_path = tmp_path / "scene.json"
    scene_path.write_text(json.dumps(_car_only_scene(video.camera)))
    short = _write_video(tmp_path / "short.avi", 5)  # too short for a background
    assert main(["calibrate", str(scene_path)]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert main(["calibrate", str(scene_path), "--video", str(short)]) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert "video_segments" not in out
    assert out["focal_px"] == pytest.approx(plain["focal_px"], rel=1e-9)
    warned = [w for w in out["warnings"] if w.startswith(f"video {short}: no lines")]
    assert len(warned) == 1, out["warnings"]
    assert "calibrated from the scene alone" in warned[0]
    logged = [r for r in caplog.records if "no lines of moving vehicles" in r.getMessage()]
    assert len(logged) == 1  # on stderr once (the CLI's log handler)


def test_radar_refuses_max_frames_under_1_before_calibrating(
    street: tuple[RenderedVideo, VideoLines], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from camloc_geo.cli import main

    video, _lines = street
    scene_path = tmp_path / "scene.json"
    scene_path.write_text(json.dumps(_car_only_scene(video.camera)))
    code = main(["radar", str(video.path), "--scene", str(scene_path), "--max-frames", "0"])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["camloc radar: error: max_frames must be a whole number >= 1, not 0"]


def test_radar_says_when_the_video_gave_no_lines(
    street: tuple[RenderedVideo, VideoLines], tmp_path: Path
) -> None:
    from camloc_geo.api import radar_scene

    video, _lines = street
    still = _write_video(tmp_path / "still.avi", 12)  # nothing moves: no lines
    boxes = {1: {i: (100.0 + 10 * i, 300.0, 200.0 + 10 * i, 350.0) for i in range(12)}}
    res = radar_scene(_car_only_scene(video.camera), still, tracks=boxes, min_track_s=0.1)
    assert res.calibration["witnesses"] == ["annotators"]
    warned = [w for w in res.warnings if w.startswith(f"video {still}: no lines")]
    assert len(warned) == 1, res.warnings


def test_a_truncated_video_still_gives_its_lines(
    street: tuple[RenderedVideo, VideoLines], tmp_path: Path
) -> None:
    # a recording cut off: the file states 240 frames, about a third decode. The median
    # background was sampled over the stated 240, failed past the cut, and the video gave
    # no lines at all ("no lines of moving vehicles").
    video, _lines = street
    data = Path(video.path).read_bytes()
    cut = tmp_path / "cut.avi"
    cut.write_bytes(data[: len(data) // 3])
    lines = video_lines(cut, image_size=video.image_size)
    assert 40 < lines.n_frames < 120
    assert lines.has_groups()
    assert lines.counts["street"] >= 100
    res = calibrate_scene(_car_only_scene(video.camera), video=cut)
    assert set(res.video_segments) >= {"length", "width"}
    assert abs(res.camera.focal_px / video.camera.focal_px - 1.0) < 0.03
    assert not [w for w in res.warnings if "no lines" in w]


def test_radar_bounds_the_video_lines_by_max_frames_and_600(
    street: tuple[RenderedVideo, VideoLines], monkeypatch: pytest.MonkeyPatch
) -> None:
    import camloc_geo.sensors._video_lines as vl
    from camloc_geo.api import radar_scene

    video, lines = street
    asked: list[int] = []

    def recorded(path: Any, *, image_size: Any = None, max_frames: int = 600) -> VideoLines:
        asked.append(max_frames)
        return lines  # (the fixture's: the reading itself is tested above)

    monkeypatch.setattr(vl, "video_lines", recorded)
    scene = _car_only_scene(video.camera)
    boxes = {1: {i: (100.0 + 10 * i, 300.0, 200.0 + 10 * i, 350.0) for i in range(12)}}
    for max_frames, expected in ((None, 600), (12, 12), (5000, 600)):
        radar_scene(scene, video.path, tracks=boxes, max_frames=max_frames, min_track_s=0.1)
        assert asked[-1] == expected, (max_frames, asked)


def test_the_street_group_is_capped_by_information_the_edges_by_count() -> None:
    from types import SimpleNamespace

    from camloc_geo.relative import VIDEO_GROUP_CAP, _line_information, _video_group_widening

    # 3 annotators, 2 length lines of 100 px each; the line sigma 1 px
    ann = np.array([[0.0, 0.0, 100.0, 0.0]] * 6)
    prob = SimpleNamespace(
        segments=ann,
        seg_axis=np.zeros(6, dtype=int),
        n_annotators=3,
        sigma_line=1.0,
        image_wh=(960.0, 540.0),
    )
    assert _line_information(ann, 1.0) == pytest.approx(6 * 100.0**2)
    # 900 tracks of 20 px: 900 * 400 = 360,000 against a cap of 3 annotators' 20,000 each
    tracks = np.array([[0.0, 0.0, 20.0, 0.0]] * 900)
    sigma = np.ones(900)
    factor = _video_group_widening(prob, tracks, sigma, 0, True)
    assert factor == pytest.approx(360_000.0 / (VIDEO_GROUP_CAP * 20_000.0))
    # counted, the same group was held to 3 x 2 segments: 25 times less than its information
    assert _video_group_widening(prob, tracks, sigma, 0, False) == pytest.approx(900 / 6.0)
    # a group saying less than the cap keeps its own sigmas
    few = np.array([[0.0, 0.0, 20.0, 0.0]] * 40)
    assert _video_group_widening(prob, few, np.ones(40), 0, True) == 1.0
    assert _video_group_widening(prob, few, np.ones(40), 0, False) == pytest.approx(40 / 6.0)
    # an axis the annotators barely drew: at least 2 lines of 5 % of the diagonal each
    floor = 2.0 * (0.05 * math.hypot(960.0, 540.0)) ** 2
    factor = _video_group_widening(prob, tracks, sigma, 2, True)
    assert factor == pytest.approx(360_000.0 / (VIDEO_GROUP_CAP * floor))


def _exact_tracks(cam: Any, rng: np.random.Generator, n: int = 1500) -> np.ndarray:
    """Segments of points moving 3-6 m along the street (world x) in its lanes, 0.2 px noise
    (like a 20 s video's tracks: 1000-3000 of them, 60-90 px long)."""
    segs: list[np.ndarray] = []
    while len(segs) < n:
        x0 = rng.uniform(-5.0, 25.0)
        y = float(rng.choice([-3.0, -5.5, -8.5, -11.0])) + rng.uniform(-1.0, 1.0)
        z = rng.uniform(0.2, 1.5)
        px = cam.project(np.array([[x0, y, z], [x0 + rng.uniform(3.0, 6.0), y, z]]))
        inside = (px[:, 0] > 0) & (px[:, 0] < 960) & (px[:, 1] > 0) & (px[:, 1] < 540)
        if np.all(inside):
            segs.append((px + rng.normal(0.0, 0.2, px.shape)).ravel())
    return np.array(segs)


def test_the_street_group_is_held_to_its_direction_floor() -> None:
    from camloc_geo.relative import _group_direction_information, _video_direction_floor

    cam, _ = random_street(np.random.default_rng(SEED), n_vehicles=10, duration_s=20.0)
    f, pp, R = cam.focal_px, cam.principal_point, cam.cam_from_world_rotation
    K = np.array([[f, 0.0, pp[0]], [0.0, f, pp[1]], [0.0, 0.0, 1.0]])
    segs = _exact_tracks(cam, np.random.default_rng(1))
    sigma = np.ones(len(segs))
    H = _group_direction_information(segs, sigma, K, R[:, 0])
    assert H is not None
    top = float(np.max(np.linalg.eigvalsh(H)))
    # 1500 tracks at 1 px claim their direction to a hundredth of a degree or so
    assert math.degrees(1.0 / math.sqrt(top)) < 0.03
    factor = _video_direction_floor(segs, sigma, K, R[:, 0], 0.05)
    assert factor > 2.0
    assert factor == pytest.approx(top * math.radians(0.05) ** 2, rel=1e-6)
    # widened by it, no direction of the group is known better than the floor
    H_w = _group_direction_information(segs, sigma * math.sqrt(factor), K, R[:, 0])
    assert H_w is not None
    assert math.degrees(1.0 / math.sqrt(float(np.max(np.linalg.eigvalsh(H_w))))) == (
        pytest.approx(0.05, rel=0.02)
    )
    # a group saying less than the floor keeps its own sigmas
    assert _video_direction_floor(segs[:3], np.full(3, 30.0), K, R[:, 0], 0.05) == 1.0


def test_the_street_tracks_hold_the_length_axis_whatever_the_annotators_drew(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # The car alone (short length lines): capped at 3 annotators' information (session 37)
    # the tracks were held to about a degree there; held to their direction's accuracy
    # (VIDEO_DIRECTION_FLOOR_DEG) they fix the street's point as they do beside lane lines.
    import camloc_geo.relative as rel

    cam, _ = random_street(np.random.default_rng(SEED), n_vehicles=10, duration_s=20.0)
    f, pp, R = cam.focal_px, cam.principal_point, cam.cam_from_world_rotation
    K = np.array([[f, 0.0, pp[0]], [0.0, f, pp[1]], [0.0, 0.0, 1.0]])
    segs = _exact_tracks(cam, np.random.default_rng(1))
    vps = np.full((3, 3), np.nan)
    vps[0] = K @ R[:, 0] / np.linalg.norm(K @ R[:, 0])
    lines = VideoLines((960, 540), segs, np.zeros(len(segs), dtype=int), vps, 400, {})
    scene = make_scene(
        cam,
        np.random.default_rng(SEED + 1 + 7),
        noise=street_noise(1.0),
        n_annotators=3,
        image_size=(960, 540),
    ).scene
    settings = CalibrationSettings(video_lines=lines, jackknife=False)
    err = calibrate_scene(scene, settings=settings).camera.focal_px / f - 1.0
    assert abs(err) < 0.007, err
    monkeypatch.setattr(rel, "VIDEO_DIRECTION_FLOOR_DEG", {})  # the cap by information
    capped = calibrate_scene(scene, settings=settings).camera.focal_px / f - 1.0
    assert abs(capped) > 0.015, capped
