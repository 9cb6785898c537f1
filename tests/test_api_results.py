"""Results as a notebook user meets them: a short useful repr, JSON without numpy types."""

from __future__ import annotations

import json
import threading
from pathlib import Path
from typing import Any

import pytest

from camloc_geo import api

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "sample_maps" / "sample_scene.json"
EXTRACT = REPO / "sample_maps" / "baltimore.osm.pbf"


def _foreign_types(value: Any, path: str = "$") -> list[str]:
    """Paths of values whose type is not exactly a JSON type (np.float64 passes json.dumps)."""
    if isinstance(value, dict):
        return [p for k, v in value.items() for p in _foreign_types(v, f"{path}.{k}")]
    if type(value) is list:
        return [p for i, v in enumerate(value) for p in _foreign_types(v, f"{path}[{i}]")]
    if value is None or type(value) in (str, int, float, bool):
        return []
    return [f"{path}: {type(value).__name__}"]


@pytest.fixture(scope="module")
def located() -> api.LocateOutput:
    return api.locate_scene(SCENE, map_source=EXTRACT)


def test_locate_output_repr_is_one_useful_line(located: api.LocateOutput) -> None:
    """It printed the whole scene, every candidate and its evidence (30,568 characters)."""
    text = repr(located)
    best = located.result.candidates[0]
    assert len(text) < 400
    assert "\n" not in text
    assert text.startswith("LocateOutput(scene='baltimore-eastern-broadway', candidates=")
    assert f"lat={best.lat:.6f}, lon={best.lon:.6f}" in text
    assert "MapData(" in text


def test_geojson_of_results_holds_only_json_types(located: api.LocateOutput) -> None:
    assert _foreign_types(located.to_geojson()) == []
    lat, lon = located.result.candidates[0].lat, located.result.candidates[0].lon
    assert _foreign_types(api.corners_near(lat=lat, lon=lon, map_source=EXTRACT)) == []
    assert _foreign_types(api.streets_within(lat=lat, lon=lon, map_source=EXTRACT)) == []


def test_calibrate_from_four_threads_gives_the_serial_answer() -> None:
    """A notebook or the service calibrating one scene from several threads at once."""
    serial = json.dumps(api.calibrate_scene(SCENE).to_dict(), sort_keys=True)
    answers: list[str] = []
    errors: list[BaseException] = []
    barrier = threading.Barrier(4)

    def run() -> None:
        try:
            barrier.wait()
            answers.append(json.dumps(api.calibrate_scene(SCENE).to_dict(), sort_keys=True))
        except BaseException as exc:  # reported below
            errors.append(exc)

    threads = [threading.Thread(target=run) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert answers == [serial] * 4


def test_a_scene_with_a_photo_from_four_threads_gives_the_serial_answer(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The photo's decoded pixels and detected vanishing points are cached per file version:
    threads sharing those caches get the serial answer, and the photo is detected once (it
    was detected in each of the 4 threads: the cache missed in all of them)."""
    pytest.importorskip("cv2")
    from camloc_geo import autovp
    from tests.test_calibrate_autovp import _noisy_scene_with_photo

    scene = _noisy_scene_with_photo(tmp_path, 3, True)
    detections: list[object] = []
    real_detect = autovp.detect_vanishing_points

    def counting(*args: Any, **kwargs: Any) -> Any:
        detections.append(args[0])
        return real_detect(*args, **kwargs)

    monkeypatch.setattr(autovp, "detect_vanishing_points", counting)
    answers: list[str] = []
    barrier = threading.Barrier(4)

    def run() -> None:
        barrier.wait()
        answers.append(json.dumps(api.calibrate_scene(scene).to_dict(), sort_keys=True))

    threads = [threading.Thread(target=run) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    serial = json.dumps(api.calibrate_scene(scene).to_dict(), sort_keys=True)
    assert answers == [serial] * 4
    assert "photo" in serial  # the photo's lines were used (a real photo path, not skipped)
    assert len(detections) == 1


def test_calibration_and_locate_results_repr_in_one_line(located: api.LocateOutput) -> None:
    """CalibrationResult printed every array and annotator (~6,200 characters),
    LocateResult every candidate, observation and the calibration (~28,500)."""
    cal = located.result.calibration
    text = repr(cal)
    assert len(text) < 200
    assert "\n" not in text
    assert text.startswith(f"CalibrationResult(focal_px={cal.camera.focal_px:.1f} ± ")
    assert f"height_m={cal.camera.height_m:.2f}" in text
    text = repr(located.result)
    best = located.result.candidates[0]
    assert len(text) < 300
    assert "\n" not in text
    assert text.startswith("LocateResult(scene_id='baltimore-eastern-broadway', candidates=")
    assert f"lat={best.lat:.6f}, lon={best.lon:.6f}" in text


def test_each_annotator_s_solution_holds_only_json_types() -> None:
    """height_check_ratio was an np.float64 (json.dumps takes it, other encoders do not)."""
    cal = api.calibrate_scene(SCENE)
    solutions = [a.to_dict() for a in cal.annotators]
    assert any("height_check_ratio" in s for s in solutions)
    assert _foreign_types(solutions) == []
