"""``camloc calibrate``: JSON on stdout, exit statuses, one-line errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import SCENES_DIR, camera_aimed_at_car, exact_scene

from camloc_geo.cli import main

REQUIRED = ("focal_px", "principal_point", "height_m", "camera_in_world", "pitch_deg", "roll_deg")


def _write(tmp_path: Path, data: dict[str, Any], name: str = "scene.json") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


def _run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.mark.parametrize(
    ("kwargs", "extra_args"),
    [
        (
            {
                "height_m": 6.0,
                "distance_m": 20.0,
                "roll_deg": 5.0,
                "principal_point": (1010.0, 500.0),
            },
            [],
        ),
        ({"height_m": 1.5, "distance_m": 30.0, "pitch_deg": 0.0}, []),
        ({"height_m": 35.0, "distance_m": 12.0, "roll_deg": -6.0, "focal_px": 800.0}, []),
        ({"height_m": 12.0, "distance_m": 70.0, "focal_px": 7000.0, "width_sign": -1.0}, []),
        ({"height_m": 6.0, "distance_m": 20.0, "roll_deg": 5.0}, ["--no-joint-fit"]),
    ],
)
def test_calibrate_recovers_exact_camera(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    kwargs: dict[str, Any],
    extra_args: list[str],
) -> None:
    cam = camera_aimed_at_car(**kwargs)
    # an off-centre principal point is given in the scene (the default prior would hold a
    # fitted one near the centre: noise-free lines cannot tell 64 px apart under the noise model)
    hints = (
        {"principal_point": list(kwargs["principal_point"])} if "principal_point" in kwargs else {}
    )
    path = _write(tmp_path, exact_scene(cam, width_sign=kwargs.get("width_sign", 1.0), **hints))
    code, out, err = _run(["calibrate", str(path), *extra_args], capsys)
    assert code == 0, err
    res = json.loads(out)
    for key in REQUIRED:
        assert key in res
    c_true = cam.center_in_world
    assert np.linalg.norm(np.array(res["camera_in_world"]) - c_true) <= 1e-6 * np.linalg.norm(
        c_true
    )
    assert res["height_m"] == pytest.approx(cam.height_m, rel=1e-6)
    assert res["focal_px"] == pytest.approx(cam.focal_px, rel=1e-6)
    _h, pitch, roll = cam.angles_deg
    assert res["pitch_deg"] == pytest.approx(pitch, abs=1e-5)
    assert res["roll_deg"] == pytest.approx(roll, abs=1e-5)
    assert res["method"] == ("cluster_centroid" if extra_args else "joint_fit")
    assert res["fallback"]
    assert res["intrinsics_reason"]
    assert len(res["annotators"]) == 3
    assert all("candidates" in a for a in res["annotators"])
    assert res["cluster"]["members"]
    assert res["scene"] == "synthetic"


def test_calibrate_output_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out_path = tmp_path / "out.json"
    code, out, _err = _run(
        [
            "calibrate",
            str(SCENES_DIR / "good.json"),
            "-o",
            str(out_path),
            "--principal-point",
            "centre",
        ],
        capsys,
    )
    assert code == 0
    assert out == ""
    res = json.loads(out_path.read_text())
    assert res["principal_point"] == [960.0, 540.0]
    assert res["height_m"] == pytest.approx(6.0, rel=1e-3)
    assert res["focal_px"] == pytest.approx(1400.0, rel=1e-3)


@pytest.mark.parametrize(
    ("filename", "message"),
    [
        ("bad_one_height_line.json", "annotations[0].vp_lines.height: needs at least 2 segments"),
        (
            "bad_collinear_axes.json",
            "annotations[0].axes: the length and width edges are collinear",
        ),
        (
            "bad_pixel_outside.json",
            "annotations[0].axes.origin: pixel [2500, 700] is 580 px outside",
        ),
        ("bad_nan_pixel.json", "NaN is not a number JSON allows"),
        ("bad_zero_length.json", "object.length_m: must be 1-30 m"),
        ("bad_negative_width.json", "object.width_m: must be 0.4-5 m"),
        ("bad_format_version.json", "format: unknown format version 'camloc-scene/2'"),
        ("bad_malformed.json", "malformed JSON in bad_malformed.json at line"),
        ("bad_missing_axis.json", "annotations[0].axes.height: required field is missing"),
        ("bad_missing_image.json", "image: required field is missing"),
        ("bad_unknown_preset.json", "object.preset: unknown object preset 'limousine'"),
        ("level_along_car.json", "cannot estimate the focal length"),
        ("no_such_file.json", "scene file not found"),
    ],
)
def test_bad_input_exit_2_one_line(
    capsys: pytest.CaptureFixture[str], filename: str, message: str
) -> None:
    code, out, err = _run(["calibrate", str(SCENES_DIR / filename)], capsys)
    assert code == 2
    assert out == ""
    assert err.endswith("\n")
    assert err.count("\n") == 1
    assert err.startswith("camloc calibrate: error: ")
    assert message in err
    assert "Traceback" not in err


def test_level_camera_with_focal_given(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _err = _run(["calibrate", str(SCENES_DIR / "level_along_car_focal.json")], capsys)
    assert code == 0
    res = json.loads(out)
    assert res["fallback"] == "given_focal"
    assert res["pitch_deg"] == pytest.approx(0.0, abs=0.05)
    assert res["height_m"] == pytest.approx(1.5, rel=1e-2)


def test_subprocess_bad_input_has_no_traceback() -> None:
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "camloc_geo.cli",
            "calibrate",
            str(SCENES_DIR / "bad_collinear_axes.json"),
        ],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert proc.returncode == 2
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1
    assert "Traceback" not in proc.stderr
    assert "collinear" in lines[0]


def test_subprocess_good_scene() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", "calibrate", str(SCENES_DIR / "good.json")],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["height_m"] == pytest.approx(6.0, rel=1e-3)


def test_usage_error_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(["calibrate"])
    assert info.value.code == 2
    assert "Traceback" not in capsys.readouterr().err


def test_fit_warnings_reach_stderr_once(tmp_path: Path) -> None:
    """The fit's own warnings (not only the scene's) are on stderr, each once, besides JSON.

    The hand-annotated taxi's own lines alone (no kerb, no building): the length and width
    directions rest on the car's edges, a warning that used to be in the JSON only.
    """
    from test_real_car import TAXI, _car_lines_only

    scene = json.loads(TAXI.read_text(encoding="utf-8"))
    scene["image"].pop("path", None)
    path = _write(tmp_path, _car_lines_only(scene))
    proc = subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", "calibrate", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    warnings = json.loads(proc.stdout)["warnings"]
    car = [w for w in warnings if "rests on the car's own edges" in w]
    assert len(car) == 2  # length and width
    lines = proc.stderr.splitlines()
    for w in warnings:
        assert sum(w in line for line in lines) == 1, w
    assert "Traceback" not in proc.stderr
