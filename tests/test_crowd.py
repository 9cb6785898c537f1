"""Crowd slips: what is kept, clamped, left out and reported; what is refused, and how.

The scene is the sample scene (three annotators, camera 9.4 m above the car), the one the
issue's slips were found on.
"""

from __future__ import annotations

import copy
import json
import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from camloc_geo import DegenerateGeometryError, InputError, SceneError
from camloc_geo.relative import CalibrationResult, calibrate, implausibility
from camloc_geo.scene import load_scene, parse_scene

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "sample_maps" / "sample_scene.json"
W, H = 1920, 1080


@pytest.fixture(scope="module")
def sample() -> dict[str, Any]:
    return json.loads(SAMPLE.read_text())


@pytest.fixture(scope="module")
def reference(sample: dict[str, Any]) -> CalibrationResult:
    return calibrate(parse_scene(sample))


def _cal(data: dict[str, Any]) -> CalibrationResult:
    return calibrate(parse_scene(data))


def _excluded(result: CalibrationResult) -> dict[str, str]:
    return {e["annotator"]: e["reason"] for e in result.excluded_annotators}


def _cli(*args: str, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
        env=env,
    )


# ------------------------------------------------------------------ clicks off the image
def test_reference_is_plausible(reference: CalibrationResult) -> None:
    assert reference.height_m == pytest.approx(9.4, abs=0.1)
    assert reference.excluded_annotators == []
    assert reference.warnings == []
    assert reference.clamped_clicks == 0


def _extended_past_border(seg: list[float], offset: float) -> list[float]:
    """The segment's second end moved along its line to ``offset`` px past the image border."""
    p, q = np.array(seg[:2]), np.array(seg[2:])
    d = (q - p) / np.linalg.norm(q - p)
    ts = ((0 - p[0]) / d[0], (W - p[0]) / d[0], (0 - p[1]) / d[1], (H - p[1]) / d[1])
    t = min(t for t in ts if t > 0)
    return [*p.tolist(), *(p + (t + offset) * d).tolist()]


@pytest.mark.parametrize("offset", [0.02, 3.0, 9.0])
def test_click_just_outside_is_clamped_and_counted(
    sample: dict[str, Any], reference: CalibrationResult, offset: float
) -> None:
    """A line drawn to the image border (and a little past it) is clamped, not refused."""
    data = copy.deepcopy(sample)
    for a in (1, 2):
        segs = data["annotations"][a]["vp_lines"]["length"]
        segs[0] = _extended_past_border(segs[0], offset)
    result = _cal(data)
    assert result.clamped_clicks == 2
    assert result.excluded_annotators == []
    assert not any("left out" in w for w in result.warnings)
    on_border = copy.deepcopy(sample)  # the same lines ending exactly on the border
    for a in (1, 2):
        segs = on_border["annotations"][a]["vp_lines"]["length"]
        segs[0] = _extended_past_border(segs[0], 0.0)
    expected = _cal(on_border)
    assert np.allclose(result.camera.center_in_world, expected.camera.center_in_world, atol=0.15)


def test_click_far_outside_leaves_the_annotator_out(
    sample: dict[str, Any], reference: CalibrationResult
) -> None:
    data = copy.deepcopy(sample)
    data["annotations"][1]["axes"]["length"] = [W + 400.0, 500.0]
    result = _cal(data)
    reasons = _excluded(result)
    assert list(reasons) == ["w2"]
    assert reasons["w2"].startswith("axes.length: pixel [2320, 500] is 400 px outside")
    assert result.annotator_weights[1] == 0.0
    assert any("'w2' (annotations[1]) left out" in w for w in result.warnings)
    assert result.height_m == pytest.approx(reference.height_m, abs=1.5)


def test_nan_click_leaves_the_annotator_out(sample: dict[str, Any]) -> None:
    data = copy.deepcopy(sample)
    data["annotations"][0]["vp_lines"]["height"][1][2] = float("nan")
    result = _cal(data)
    assert _excluded(result) == {"w1": "vp_lines.height[1]: pixel [nan, 3.1] is not finite"} or (
        list(_excluded(result)) == ["w1"] and "not finite" in _excluded(result)["w1"]
    )


def test_warning_names_the_annotator(sample: dict[str, Any], caplog: Any) -> None:
    data = copy.deepcopy(sample)
    data["annotations"][2]["axes"]["height"] = [float("inf"), 3.0]
    with caplog.at_level("WARNING", logger="camloc_geo.relative"):
        result = _cal(data)
    assert list(_excluded(result)) == ["w3"]
    assert any("'w3' (annotations[2]) left out: axes.height" in r.message for r in caplog.records)


def test_too_few_usable_annotators_fail_in_one_line(sample: dict[str, Any]) -> None:
    data = copy.deepcopy(sample)
    for ann in data["annotations"]:
        ann["axes"]["origin"] = [5000.0, 5000.0]
    with pytest.raises(SceneError, match=r"^no usable annotator: annotations\[0\]\.axes\.origin"):
        _cal(data)


# ------------------------------------------------------------------ degenerate work
def test_edge_ends_on_the_origin_leave_the_annotator_out(
    sample: dict[str, Any], reference: CalibrationResult
) -> None:
    """The issue's case: one annotator of three with every end on the origin gave 369 m."""
    data = copy.deepcopy(sample)
    axes = data["annotations"][1]["axes"]
    for k in ("length", "width", "height"):
        axes[k] = list(axes["origin"])
    result = _cal(data)
    assert list(_excluded(result)) == ["w2"]
    assert "coincides with the origin pixel" in _excluded(result)["w2"]
    assert reference.position_sigma_m is not None
    assert result.height_m == pytest.approx(
        reference.height_m, abs=3 * reference.position_sigma_m[2]
    )


def test_collinear_axes_leave_the_annotator_out(sample: dict[str, Any]) -> None:
    data = copy.deepcopy(sample)
    axes = data["annotations"][0]["axes"]
    o, e = np.array(axes["origin"]), np.array(axes["length"])
    axes["width"] = (o + 0.5 * (e - o)).tolist()
    result = _cal(data)
    assert list(_excluded(result)) == ["w1"]
    assert "collinear" in _excluded(result)["w1"]


def test_zero_length_segment_is_dropped_not_fatal(
    sample: dict[str, Any], reference: CalibrationResult
) -> None:
    data = copy.deepcopy(sample)
    seg = data["annotations"][2]["vp_lines"]["height"][0]
    seg[2:] = seg[:2]
    result = _cal(data)
    assert result.excluded_annotators == []
    assert any("vp_lines.height[0] (w3): shorter than 2 px" in w for w in result.warnings)
    assert result.height_m == pytest.approx(reference.height_m, abs=0.5)


def test_lines_drawn_for_the_wrong_axis_leave_the_annotator_out(
    sample: dict[str, Any], reference: CalibrationResult
) -> None:
    data = copy.deepcopy(sample)
    ann = data["annotations"][2]
    ann["vp_lines"]["width"] = copy.deepcopy(ann["vp_lines"]["height"])[:3]
    result = _cal(data)
    assert list(_excluded(result)) == ["w3"]
    assert "vp_lines.width" in _excluded(result)["w3"]
    assert result.height_m == pytest.approx(reference.height_m, abs=1.5)


def test_line_end_on_the_top_edge_never_puts_the_camera_underground(
    sample: dict[str, Any],
) -> None:
    """The issue's case: one end of one width line moved to y = 0 gave -6.4 m."""
    data = copy.deepcopy(sample)
    data["annotations"][0]["vp_lines"]["width"][1][3] = 0.0
    result = _cal(data)
    assert implausibility(result, (W, H)) is None
    assert result.height_m == pytest.approx(9.4, abs=1.5)


# ------------------------------------------------------------------ implausible values
def test_focal_length_of_one_pixel_is_ignored(
    sample: dict[str, Any], reference: CalibrationResult
) -> None:
    data = copy.deepcopy(sample)
    data["camera"] = {"focal_px": 1}
    result = _cal(data)
    assert any(w.startswith("camera.focal_px: 1 px is implausible") for w in result.warnings)
    assert result.height_m == pytest.approx(reference.height_m, abs=0.1)


def test_far_principal_point_is_ignored(
    sample: dict[str, Any], reference: CalibrationResult
) -> None:
    data = copy.deepcopy(sample)
    data["camera"] = {"principal_point": [50000, -20000]}
    result = _cal(data)
    assert any(
        w.startswith("camera.principal_point: [50000, -20000] is outside") for w in result.warnings
    )
    assert np.linalg.norm(result.camera.center_in_world) < 100


@pytest.mark.parametrize(
    ("obj", "message"),
    [
        ({"length_m": 9999, "width_m": 1e-9}, "object.length_m: must be 1-30 m"),
        ({"width_m": 1e-9}, "object.width_m: must be 0.4-5 m"),
        ({"height_m": 40}, "object.height_m: must be 0.5-6 m"),
    ],
)
def test_implausible_object_size_is_refused(
    sample: dict[str, Any], obj: dict[str, float], message: str
) -> None:
    data = copy.deepcopy(sample)
    data["object"] = obj
    with pytest.raises(SceneError, match=f"^{message}"):
        parse_scene(data)


def test_single_implausible_annotator_fails_with_the_reason(sample: dict[str, Any]) -> None:
    """A height edge clicked downwards puts the camera underground: refused, not returned."""
    data = copy.deepcopy(sample)
    data["annotations"] = data["annotations"][:1]
    axes = data["annotations"][0]["axes"]
    o, h = axes["origin"], axes["height"]
    axes["height"] = [2 * o[0] - h[0], 2 * o[1] - h[1]]
    with pytest.raises(
        DegenerateGeometryError,
        match=r"^no plausible camera: the camera is [0-9.]+ m below the ground; the only usable "
        r"annotator \(w1\)",
    ):
        _cal(data)


def test_downward_height_edge_of_one_annotator_of_three(
    sample: dict[str, Any], reference: CalibrationResult
) -> None:
    data = copy.deepcopy(sample)
    axes = data["annotations"][1]["axes"]
    o, h = axes["origin"], axes["height"]
    axes["height"] = [2 * o[0] - h[0], 2 * o[1] - h[1]]
    result = _cal(data)
    assert implausibility(result, (W, H)) is None
    assert reference.position_sigma_m is not None
    assert result.height_m == pytest.approx(
        reference.height_m, abs=3 * reference.position_sigma_m[2]
    )


def test_implausibility_reasons(reference: CalibrationResult) -> None:
    from camloc_geo.camera import Camera

    cam = reference.camera

    def moved(center: list[float], f: float | None = None, pp: Any = None) -> CalibrationResult:
        res = copy.copy(reference)
        res.camera = Camera.from_center(
            f or cam.focal_px, pp or cam.principal_point, cam.cam_from_world_rotation, center
        )
        return res

    assert "below the ground" in str(implausibility(moved([5, 5, -6.4]), (W, H)))
    assert "369 m above" in str(implausibility(moved([5, 5, 369]), (W, H)))
    assert "km from the car" in str(implausibility(moved([5e4, 0, 9]), (W, H)))
    assert "focal length" in str(implausibility(moved([5, 5, 9], f=1.0), (W, H)))
    assert "principal point" in str(implausibility(moved([5, 5, 9], pp=(-50.0, 5.0)), (W, H)))
    assert implausibility(moved([5, 5, 9]), (W, H)) is None


# ------------------------------------------------------------------ other evidence
def test_bad_reference_and_corner_are_left_out_not_fatal(sample: dict[str, Any]) -> None:
    data = copy.deepcopy(sample)
    data["references"] = [
        {"pixel": [100.0, 900.0], "lat": 39.28, "lon": -76.61},
        {"pixel": [-900.0, 900.0], "lat": 39.28, "lon": -76.61},
        {"pixel": [1922.0, 1000.0], "lat": 39.28, "lon": -76.61},
    ]
    data["intersection"] = {"corners": [[300.0, 600.0], [1e9, 5.0]]}
    scene = parse_scene(data)
    assert len(scene.references) == 2
    assert scene.references[1].pixel == (1920.0, 1000.0)
    assert scene.intersection is not None
    assert scene.intersection.corners == [(300.0, 600.0)]
    assert any(w.startswith("references[1].pixel: pixel [-900, 900]") for w in scene.input_warnings)
    assert "references[2].pixel: clamped onto the image" in scene.input_warnings
    assert any(w.startswith("intersection.corners[1]: pixel") for w in scene.input_warnings)
    result = calibrate(scene)
    assert "references[2].pixel: clamped onto the image" in result.warnings


# ------------------------------------------------------------------ command line
def test_calibrate_json_reports_clamps_and_exclusions(
    sample: dict[str, Any], tmp_path: Path
) -> None:
    data = copy.deepcopy(sample)
    segs = data["annotations"][0]["vp_lines"]["length"]
    segs[0] = _extended_past_border(segs[0], 0.02)
    data["annotations"][1]["axes"]["width"] = [900.0, -300.0]
    path = tmp_path / "slips.json"
    path.write_text(json.dumps(data))
    proc = _cli("calibrate", str(path))
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["clamped_clicks"] == 1
    assert [e["annotator"] for e in out["excluded_annotators"]] == ["w2"]
    assert out["excluded_annotators"][0]["index"] == 1
    assert (
        "axes.width: pixel [900, -300] is 300 px outside" in out["excluded_annotators"][0]["reason"]
    )
    assert "WARNING: annotator 'w2' (annotations[1]) left out" in proc.stderr


def _one_line_exit_2(proc: subprocess.CompletedProcess[str]) -> str:
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


def test_deeply_nested_json_is_exit_2(tmp_path: Path) -> None:
    path = tmp_path / "deep.json"
    path.write_text('{"format": "camloc-scene/1", "x": ' + "[" * 100_000 + "]" * 100_000 + "}")
    line = _one_line_exit_2(_cli("calibrate", str(path)))
    assert "nested too deeply" in line


def test_scene_file_size_limit(tmp_path: Path) -> None:
    path = tmp_path / "big.json"
    with path.open("w") as fh:
        fh.write('{"format": "camloc-scene/1", "pad": "')
        fh.write("x" * 10_000_100)
        fh.write('"}')
    assert "the limit is 10 MB" in _one_line_exit_2(_cli("calibrate", str(path)))


def test_too_many_lines_are_refused(sample: dict[str, Any]) -> None:
    data = copy.deepcopy(sample)
    data["annotations"][0]["vp_lines"]["length"] = [[1.0, 2.0, 3.0, 4.0]] * 100_000
    with pytest.raises(
        SceneError,
        match=r"^annotations\[0\]\.vp_lines\.length: 100000 segments; the limit is 200",
    ):
        parse_scene(data)


def test_too_many_annotators_are_refused(sample: dict[str, Any]) -> None:
    data = copy.deepcopy(sample)
    data["annotations"] = data["annotations"] * 3334
    with pytest.raises(SceneError, match=r"^annotations: 10002 annotators; the limit is 200"):
        parse_scene(data)


@pytest.mark.parametrize("weight", [5e-324, 1e300, -1.0])
def test_reference_weight_range(sample: dict[str, Any], weight: float) -> None:
    data = copy.deepcopy(sample)
    data["references"] = [{"pixel": [10.0, 900.0], "lat": 39.28, "lon": -76.61, "weight": weight}]
    with pytest.raises(SceneError, match=r"^references\[0\]\.weight: Input should be"):
        parse_scene(data)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs POSIX FIFOs")
def test_fifo_is_never_opened(sample: dict[str, Any], tmp_path: Path) -> None:
    fifo = tmp_path / "snap.png"
    os.mkfifo(fifo)
    data = copy.deepcopy(sample)
    data["image"] = {"width": W, "height": H, "path": "snap.png"}
    # an annotator without height lines makes calibrate look at the image
    data["annotations"][0]["vp_lines"]["height"] = []
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data))
    proc = _cli("calibrate", str(path), timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "is not a regular file" in _one_line_exit_2(_cli("vp", str(fifo), timeout=60))
    scene_fifo = tmp_path / "scene_fifo.json"
    os.mkfifo(scene_fifo)
    with pytest.raises(SceneError, match="is not a regular file"):
        load_scene(scene_fifo)


def test_vp_refuses_huge_image_before_decoding(tmp_path: Path) -> None:
    pil = pytest.importorskip("PIL.Image")
    path = tmp_path / "huge.png"
    pil.new("L", (8000, 8000)).save(path)  # 64 MP, a few hundred KB
    line = _one_line_exit_2(_cli("vp", str(path)))
    assert "8000x8000 pixels (64 MP); the supported limit is 50 megapixels" in line


def test_input_error_is_a_value_error() -> None:
    assert issubclass(SceneError, InputError)


# ------------------------------------------------------------------ property
_KINDS = (
    "move_click",
    "click_off_image",
    "move_line_end",
    "line_far_off",
    "nan",
    "swap_axes_lines",
    "drop_lines",
    "collapse_axes",
    "shift_all",
    "wrong_corner",
)


@settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    annotator=st.integers(0, 2),
    kind=st.sampled_from(_KINDS),
    u=st.floats(0.0, 1.0),
    v=st.floats(0.0, 1.0),
    pick=st.integers(0, 100),
)
def test_one_perturbed_annotator_is_named_or_harmless(
    sample: dict[str, Any],
    reference: CalibrationResult,
    annotator: int,
    kind: str,
    u: float,
    v: float,
    pick: int,
) -> None:
    """Whatever one annotator does, the result stays within a few sigma or they are named."""
    data = copy.deepcopy(sample)
    ann = data["annotations"][annotator]
    name = ann["annotator"]
    axes_names = ("origin", "length", "width", "height")
    line_axes = ("length", "width", "height")
    point = axes_names[pick % 4]
    axis = line_axes[pick % 3]
    segs = ann["vp_lines"][axis]
    if kind == "move_click":
        ann["axes"][point] = [u * W, v * H]
    elif kind == "click_off_image":
        ann["axes"][point] = [u * 3 * W - W, -1.0 - v * 500]
    elif kind == "move_line_end":
        segs[pick % len(segs)][2 * (pick % 2) : 2 * (pick % 2) + 2] = [u * W, v * H]
    elif kind == "line_far_off":
        segs[pick % len(segs)][0] = W + 50 + u * 1e6
    elif kind == "nan":
        segs[pick % len(segs)][pick % 4] = float("nan")
    elif kind == "swap_axes_lines":
        other = line_axes[(pick + 1) % 3]
        ann["vp_lines"][axis], ann["vp_lines"][other] = (
            ann["vp_lines"][other],
            ann["vp_lines"][axis],
        )
    elif kind == "drop_lines":
        ann["vp_lines"][axis] = segs[:1]
    elif kind == "collapse_axes":
        ann["axes"][point] = list(ann["axes"][axes_names[(pick + 1) % 4]])
    elif kind == "shift_all":
        dx, dy = (u - 0.5) * 200, (v - 0.5) * 200
        for k in axes_names:
            ann["axes"][k] = [ann["axes"][k][0] + dx, ann["axes"][k][1] + dy]
    elif kind == "wrong_corner":
        ann["axes"]["origin"], ann["axes"]["length"] = ann["axes"]["length"], ann["axes"]["origin"]
    try:
        result = _cal(data)
    except InputError as exc:  # refusing is allowed only when it names the slip
        raise AssertionError(f"{kind}: a three-annotator scene refused: {exc}") from exc
    assert implausibility(result, (W, H)) is None
    named = {e["annotator"] for e in result.excluded_annotators} | set(result.outlier_annotators)
    named |= set(result.corner_mistakes)
    if name in named:
        return
    assert reference.position_sigma_m is not None
    assert result.position_sigma_m is not None
    sigma = np.hypot(reference.position_sigma_m, result.position_sigma_m)
    dev = np.abs(result.camera.center_in_world - reference.camera.center_in_world)
    assert np.all(dev <= 3.0 * sigma + 0.5), (kind, dev, sigma)
    assert math.isfinite(result.height_m)
