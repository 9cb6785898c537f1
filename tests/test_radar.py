"""Virtual radar (camloc_geo.sensors.radar, ``camloc radar``) on rendered synthetic videos.

Stated bounds (see docs/radar.md and benchmarks/radar.py): with background subtraction, the
best track of a lone vehicle is within 8 % of its true speed and every measured fragment
within the paper's 15 %; with the exact boxes given as tracks, within 1 %; with boxes
jittered by 2 px, within 3 %.
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camloc_geo._errors import InputError
from camloc_geo.api import calibrate_scene, radar_scene
from camloc_geo.cli import main
from camloc_geo.relative import CalibrationResult
from camloc_geo.sensors.radar import CSV_COLUMNS, measure_speeds, read_tracks
from camloc_geo.testing.synthetic_video import (
    SyntheticVehicle,
    SyntheticVideo,
    render_video,
    traffic_camera,
)

SIZE = (640, 360)
CASES = [  # direction (deg from +x), speed km/h, centre when in view, fps, size (L, W, H) m
    (0.0, 30.0, (4.0, -4.0), 25.0, (4.5, 1.8, 1.5)),
    (180.0, 60.0, (6.0, -8.0), 30.0, (3.7, 1.65, 1.45)),  # with a hard shadow
    (90.0, 45.0, (14.0, -6.0), 25.0, (5.3, 2.0, 2.4)),  # a van: not the cuboid prior
]
SHADOW = {1: (1.0, -1.0)}


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("radar")


@pytest.fixture(scope="module")
def videos(folder: Path) -> list[SyntheticVideo]:
    cam = traffic_camera(image_size=SIZE)
    out = []
    for k, (direction, speed, centre, fps, size) in enumerate(CASES):
        veh = SyntheticVehicle(centre, direction, speed, start_s=1.5, size_m=size)
        out.append(
            render_video(
                folder / f"v{k}.avi",
                cam,
                [veh],
                image_size=SIZE,
                fps=fps,
                duration_s=3.0,
                seed=k,
                shadow=SHADOW.get(k),
            )
        )
    return out


@pytest.fixture(scope="module")
def calibration(videos: list[SyntheticVideo]) -> CalibrationResult:
    return calibrate_scene(videos[0].scene)


@pytest.fixture(scope="module")
def scene_file(folder: Path, videos: list[SyntheticVideo]) -> Path:
    p = folder / "scene.json"
    p.write_text(json.dumps(videos[0].scene))
    return p


def _best(result: Any) -> Any:
    measured = result.measured
    assert measured, [v.reason for v in result.vehicles]
    return max(measured, key=lambda v: v.n_frames)


@pytest.mark.parametrize("case", range(len(CASES)))
def test_detection_speeds_within_bound(
    videos: list[SyntheticVideo], calibration: CalibrationResult, case: int
) -> None:
    video = videos[case]
    true = video.vehicles[0].speed_kmh
    result = measure_speeds(calibration, video.path, image_size=SIZE)
    assert result.source == "detection"
    assert result.video.fps == pytest.approx(video.fps)
    assert result.video.fps_source == "file"
    best = _best(result)
    assert abs(best.speed_kmh - true) <= 0.08 * true, best
    for v in result.measured:
        assert abs(v.speed_kmh - true) <= 0.15 * true, v
        assert v.sigma_kmh > 0
        assert v.first_frame <= v.last_frame
        assert v.n_frames >= 3
    # the heading is the direction of travel (world frame, clockwise from +y)
    want = (90.0 - video.vehicles[0].direction_deg) % 360.0
    assert abs((best.heading_deg - want + 180.0) % 360.0 - 180.0) < 5.0
    for v in result.vehicles:
        assert v.measured or v.reason


def test_vehicles_passing_each_other(folder: Path, calibration: CalibrationResult) -> None:
    """Two vehicles cross in the image (their blobs merge): each keeps its own speed."""
    cam = traffic_camera(image_size=SIZE)
    pair = [
        SyntheticVehicle((8.0, -4.0), 0.0, 50.0, start_s=1.5, colour=(40, 40, 180)),
        SyntheticVehicle((8.0, -8.0), 180.0, 35.0, start_s=1.5, colour=(160, 60, 30)),
    ]
    video = render_video(folder / "pair.avi", cam, pair, image_size=SIZE, duration_s=3.0)
    result = measure_speeds(calibration, video.path, image_size=SIZE)
    for veh in pair:
        want = (90.0 - veh.direction_deg) % 360.0
        mine = [
            v for v in result.measured if abs((v.heading_deg - want + 180.0) % 360.0 - 180.0) < 20.0
        ]
        assert mine, [v.to_dict(track=False) for v in result.vehicles]
        for v in mine:  # fragments too: never a speed mixing the two vehicles
            assert abs(v.speed_kmh - veh.speed_kmh) <= 0.15 * veh.speed_kmh, v
        best = max(mine, key=lambda v: v.n_frames)
        assert abs(best.speed_kmh - veh.speed_kmh) <= 0.08 * veh.speed_kmh, best
    assert all(v.speed_kmh < 60.0 for v in result.measured)


@pytest.mark.parametrize("case", [0, 2])
def test_given_tracks(
    videos: list[SyntheticVideo], calibration: CalibrationResult, case: int
) -> None:
    video = videos[case]
    true = video.vehicles[0].speed_kmh
    exact = measure_speeds(calibration, video.path, tracks=video.boxes, image_size=SIZE)
    assert exact.source == "tracks"
    (v,) = exact.measured
    assert v.vehicle_id == 0
    assert v.speed_kmh == pytest.approx(true, rel=0.01)
    rng = np.random.default_rng(case)
    noisy = {
        k: {f: tuple(np.add(b, rng.normal(0.0, 2.0, 4))) for f, b in per.items()}
        for k, per in video.boxes.items()
    }
    (w,) = measure_speeds(calibration, video.path, tracks=noisy, image_size=SIZE).measured
    assert w.speed_kmh == pytest.approx(true, rel=0.03)


def test_given_fps_scales_speed(
    videos: list[SyntheticVideo],
    calibration: CalibrationResult,
    capsys: pytest.CaptureFixture[str],
) -> None:
    video = videos[0]
    res = measure_speeds(
        calibration, video.path, tracks=video.boxes, fps=2 * video.fps, progress=True
    )
    assert "frame" in capsys.readouterr().err  # the tqdm bar, asked for
    assert res.video.fps_source == "given"
    assert res.video.fps_in_file == pytest.approx(video.fps)
    (v,) = res.measured
    assert v.speed_kmh == pytest.approx(2 * video.vehicles[0].speed_kmh, rel=0.01)


def test_max_frames(videos: list[SyntheticVideo], calibration: CalibrationResult) -> None:
    video = videos[0]
    res = measure_speeds(calibration, video.path, tracks=video.boxes, max_frames=40)
    assert res.video.n_frames == 40
    for v in res.vehicles:
        assert v.last_frame < 40
    with pytest.raises(InputError, match="max_frames"):
        measure_speeds(calibration, video.path, max_frames=0)


def test_short_track_is_skipped_with_reason(
    videos: list[SyntheticVideo], calibration: CalibrationResult
) -> None:
    video = videos[0]
    frames = sorted(video.boxes[0])[:8]  # 0.32 s at 25 fps
    res = measure_speeds(
        calibration, video.path, tracks={7: {f: video.boxes[0][f] for f in frames}}
    )
    (v,) = res.vehicles
    assert v.status == "skipped"
    assert "0.5 s" in (v.reason or "")
    assert not res.measured
    assert res.warnings


def test_tracks_file_formats(tmp_path: Path, videos: list[SyntheticVideo]) -> None:
    boxes = {k: dict(sorted(per.items())[:5]) for k, per in videos[0].boxes.items()}
    dets = [
        {"frame": f, "id": k, "box": list(b)} for k, per in boxes.items() for f, b in per.items()
    ]
    (tmp_path / "t.json").write_text(json.dumps(dets))
    (tmp_path / "t2.json").write_text(json.dumps({"detections": dets}))
    rows = ["frame,id,x1,y1,x2,y2"] + [
        f"{f},{k},{b[0]},{b[1]},{b[2]},{b[3]}" for k, per in boxes.items() for f, b in per.items()
    ]
    (tmp_path / "t.csv").write_text("\n".join(rows) + "\n")
    mot = [
        f"{f + 1},{k},{b[0]},{b[1]},{b[2] - b[0]},{b[3] - b[1]},1,-1,-1,-1"
        for k, per in boxes.items()
        for f, b in per.items()
    ]
    (tmp_path / "mot.txt").write_text("\n".join(mot) + "\n")
    for name in ("t.json", "t2.json", "t.csv", "mot.txt"):
        got = read_tracks(tmp_path / name)
        assert set(got) == set(boxes)
        for k in boxes:
            assert set(got[k]) == set(boxes[k])
            for f in boxes[k]:
                assert got[k][f] == pytest.approx(boxes[k][f])


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("frame,id,x1,y1,x2,y2\n0,1,10,10,5,20\n", "x2 > x1"),
        ("frame,id,x1,y1,x2,y2\n0,1,10,10,oops,20\n", "line 2"),
        ("frame,id,left\n0,1,2\n", "header"),
        ('[{"frame": 0, "box": [1, 2, 3, 4]}]', "missing id"),
        ("frame,id,x1,y1,x2,y2\n0,1,1,1,5,5\n0,1,1,1,5,5\n", "two boxes in frame 0"),
    ],
)
def test_bad_tracks(tmp_path: Path, text: str, needle: str) -> None:
    p = tmp_path / ("t.json" if text.startswith("[") else "t.csv")
    p.write_text(text)
    with pytest.raises(InputError, match=needle):
        read_tracks(p)


def test_radar_scene_api(videos: list[SyntheticVideo], scene_file: Path) -> None:
    res = radar_scene(scene_file, videos[1].path, tracks=videos[1].boxes)
    (v,) = res.measured
    assert v.speed_kmh == pytest.approx(60.0, rel=0.01)
    assert v.heading_deg == pytest.approx(270.0, abs=1.0)
    d = res.to_dict()
    json.dumps(d, allow_nan=False)
    assert d["n_measured"] == 1
    assert d["vehicles"][0]["track_world_m"]


def test_cli_json_and_csv(
    tmp_path: Path,
    videos: list[SyntheticVideo],
    scene_file: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    video = videos[2]
    tracks = tmp_path / "boxes.json"
    tracks.write_text(
        json.dumps(
            [
                {"frame": f, "id": k, "box": list(b)}
                for k, per in video.boxes.items()
                for f, b in per.items()
            ]
        )
    )
    assert (
        main(["radar", str(video.path), "--scene", str(scene_file), "--tracks", str(tracks)]) == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert out["video"]["fps"] == 25.0
    assert out["source"] == "tracks"
    assert out["vehicles"][0]["speed_kmh"] == pytest.approx(45.0, rel=0.01)
    csv_path = tmp_path / "speeds.csv"
    code = main(
        ["radar", str(video.path), "--scene", str(scene_file), "--no-progress", "-o", str(csv_path)]
    )
    assert code == 0
    rows = list(csv.DictReader(io.StringIO(csv_path.read_text())))
    assert tuple(rows[0]) == CSV_COLUMNS
    measured = [r for r in rows if r["status"] == "measured"]
    assert measured
    assert all(abs(float(r["speed_kmh"]) - 45.0) < 0.15 * 45.0 for r in measured)
    js = tmp_path / "speeds.json"
    assert main(["radar", str(video.path), "--scene", str(scene_file), "-o", str(js)]) == 0
    assert json.loads(js.read_text())["n_measured"] >= 1


def _fails(args: list[str], capsys: pytest.CaptureFixture[str], *needles: str) -> None:
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    for n in needles:
        assert n in err, err


def test_cli_bad_input(
    tmp_path: Path,
    videos: list[SyntheticVideo],
    scene_file: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    video = str(videos[0].path)
    scene = str(scene_file)
    not_video = tmp_path / "notes.avi"
    not_video.write_text("not a video")
    _fails(["radar", str(not_video), "--scene", scene], capsys, "cannot open video")
    _fails(["radar", str(tmp_path / "missing.avi"), "--scene", scene], capsys, "not found")
    big = json.loads(scene_file.read_text())
    big["image"] = {"width": 1280, "height": 720}
    big_file = tmp_path / "big.json"
    big_file.write_text(json.dumps(big))
    _fails(["radar", video, "--scene", str(big_file)], capsys, "640x360", "1280x720")
    bad = json.loads(scene_file.read_text())
    bad["annotations"] = []
    bad_file = tmp_path / "bad.json"
    bad_file.write_text(json.dumps(bad))
    _fails(["radar", video, "--scene", str(bad_file)], capsys, "error")
    _fails(["radar", video, "--scene", scene, "--fps", "-3"], capsys, "fps")
    tracks = tmp_path / "t.csv"
    tracks.write_text("frame,id,x1,y1,x2,y2\n0,1,a,1,5,5\n")
    _fails(["radar", video, "--scene", scene, "--tracks", str(tracks)], capsys, "line 2")
    _fails(["radar", video, "--scene", scene, "-o", str(tmp_path / "x.txt")], capsys, ".csv")


def test_no_vehicle_is_exit_2(
    tmp_path: Path, scene_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cam = traffic_camera(image_size=SIZE)
    empty = render_video(tmp_path / "empty.avi", cam, [], image_size=SIZE, duration_s=1.0)
    _fails(["radar", str(empty.path), "--scene", str(scene_file)], capsys, "no vehicle found")
    res = radar_scene(scene_file, empty.path)
    assert res.vehicles == []
    assert res.warnings[0] == "no vehicle found in the video"
    # and (session 36 QA) the calibration's word on the video's lines: none here
    assert len(res.warnings) == 2
    assert res.warnings[1].startswith(f"video {empty.path}: no lines of moving vehicles")


def test_cli_a_text_named_jpg_is_one_line_on_stderr(tmp_path: Path) -> None:
    """FFmpeg's own "[mjpeg @ 0x...] No JPEG data found in image" came before our error line;
    the real process (FFmpeg writes to the file descriptor) now prints only ours."""
    import os
    import subprocess
    import sys

    fake = tmp_path / "photo.jpg"
    fake.write_text("hello\n")
    root = Path(__file__).resolve().parents[1]
    env = {k: v for k, v in os.environ.items() if k != "OPENCV_FFMPEG_LOGLEVEL"}
    env["PYTHONPATH"] = str(root) + os.pathsep + env.get("PYTHONPATH", "")
    scene = root / "sample_maps" / "sample_scene.json"
    proc = subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", "radar", str(fake), "--scene", str(scene)],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        f"camloc radar: error: cannot read video {fake}: it states no frame size"
    ]


def test_vehicle_repr_leaves_out_its_track(
    videos: list[SyntheticVideo], calibration: CalibrationResult
) -> None:
    """repr() of a vehicle printed every (frame, x, y) of its ground track."""
    result = measure_speeds(calibration, videos[0].path, image_size=SIZE)
    best = _best(result)
    assert best.track_world_m  # still there
    assert "track_world_m" not in repr(best)
    assert f"speed_kmh={best.speed_kmh!r}" in repr(best)
