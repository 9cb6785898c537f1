"""camloc measure refuses pixels that are not finite or far outside the image (QA sweep 37b).

``--ground 1e308,2 3,4`` exited 0 with 762 m ± 50 km.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from conftest import camera_aimed_at_car, exact_scene

from camloc_geo._errors import InputError
from camloc_geo.api import calibrate_scene
from camloc_geo.cli import main
from camloc_geo.relative import CalibrationResult
from camloc_geo.sensors import ground_distance, point_height


@pytest.fixture(scope="module")
def scene() -> dict[str, Any]:
    return exact_scene(camera_aimed_at_car(6.0, 20.0))


@pytest.fixture(scope="module")
def calibration(scene: dict[str, Any]) -> CalibrationResult:
    return calibrate_scene(scene)


@pytest.fixture(scope="module")
def scene_file(scene: dict[str, Any], tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("measure37b") / "scene.json"
    path.write_text(json.dumps(scene))
    return path


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--ground", "1e308,2", "3,4"], "--ground: pixel '1e308,2' is far outside the"),
        (["--ground", "900,900", "900,-5000"], "--ground: pixel '900,-5000' is far outside"),
        (["--ground", "nan,2", "3,4"], "--ground: pixel 'nan,2' is not a finite number pair"),
        (["--ground", "inf,2", "3,4"], "--ground: pixel 'inf,2' is not a finite number pair"),
        (["--height", "900,900", "900,-1e9"], "--height: pixel '900,-1e9' is far outside"),
    ],
)
def test_cli_refuses_naming_the_argument(
    scene_file: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    assert main(["measure", str(scene_file), *extra]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert message in captured.err
    assert "more than one image size beyond its edge" in captured.err or "finite" in message
    assert len(captured.err.strip().splitlines()) == 1
    assert "Traceback" not in captured.err


def test_cli_keeps_pixels_just_outside(
    scene_file: Path, scene: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    # a pixel less than one image size outside (a point off-screen) is still measured
    w = scene["image"]["width"]
    code = main(["measure", str(scene_file), "--ground", "900,900", f"{w + 10},900"])
    captured = capsys.readouterr()
    assert "far outside" not in captured.err
    assert code == 0, captured.err
    assert json.loads(captured.out)["distance_m"] > 0


def test_library_refuses_far_pixels(calibration: CalibrationResult) -> None:
    with pytest.raises(InputError, match=r"ground: pixel \(1e\+308, 2\) is far outside"):
        ground_distance(calibration, [[1e308, 2.0], [3.0, 4.0]])
    with pytest.raises(InputError, match=r"height top: pixel .* is far outside"):
        point_height(calibration, [900.0, 900.0], [900.0, -1e9])
