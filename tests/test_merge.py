"""``camloc merge`` and camloc_geo.merge: agreeing and conflicting annotators."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from annotate_synthetic import located_case

from camloc_geo._errors import SceneError
from camloc_geo.api import calibrate_scene
from camloc_geo.cli import main
from camloc_geo.merge import merge_scenes
from camloc_geo.scene import parse_scene


def annotator(seed: int, name: str = "w1", jitter_px: float = 0.2) -> dict[str, Any]:
    """One annotator's file: the truth scene with their own click noise."""
    rng = np.random.default_rng(seed)
    scene = copy.deepcopy(located_case().scene)
    scene["image"]["path"] = "cam.jpg"
    ann = scene["annotations"][0]
    ann["annotator"] = name
    for k, p in ann["axes"].items():
        ann["axes"][k] = (np.array(p) + rng.normal(0, jitter_px, 2)).tolist()
    for axis, segs in ann["vp_lines"].items():
        ann["vp_lines"][axis] = [(np.array(s) + rng.normal(0, jitter_px, 4)).tolist() for s in segs]
    corners = np.array(scene["intersection"]["corners"]) + rng.normal(
        0, jitter_px, (len(scene["intersection"]["corners"]), 2)
    )
    scene["intersection"]["corners"] = np.clip(corners, 0, [1920, 1080]).tolist()
    return scene


def write(tmp_path: Path, scenes: list[dict[str, Any]]) -> list[str]:
    paths = []
    for i, s in enumerate(scenes):
        p = tmp_path / f"a{i + 1}.json"
        p.write_text(json.dumps(s))
        paths.append(str(p))
    return paths


def test_agreeing_annotators_merge(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scenes = [annotator(1, "w1"), annotator(2, "w1"), annotator(3, "ann")]
    out = tmp_path / "merged.json"
    assert main(["merge", *write(tmp_path, scenes), "-o", str(out), "--id", "cam-7"]) == 0
    merged = json.loads(out.read_text())
    parse_scene(merged)
    assert merged["id"] == "cam-7"
    assert [a["annotator"] for a in merged["annotations"]] == ["w1", "w1-2", "ann"]
    mean = np.mean([s["intersection"]["corners"] for s in scenes], axis=0)
    assert np.allclose(merged["intersection"]["corners"], mean)
    assert merged["intersection"]["lat"] == scenes[0]["intersection"]["lat"]
    assert merged["prior"] == scenes[0]["prior"]
    cal = calibrate_scene(merged)
    truth = located_case().camera_world.center_in_world
    assert np.linalg.norm(np.asarray(cal.camera.center_in_world) - truth) < 1.0
    # stdout without -o; a single scene passes through with its annotations
    assert main(["merge", str(tmp_path / "a1.json")]) == 0
    assert json.loads(capsys.readouterr().out)["annotations"][0]["annotator"] == "w1"


def test_models_dicts_and_paths_mix(tmp_path: Path) -> None:
    a, b = annotator(4, "x"), annotator(5, "y")
    path = write(tmp_path, [b])[0]
    merged = merge_scenes([parse_scene(a), path])
    assert [x["annotator"] for x in merged["annotations"]] == ["x", "y"]


def conflict(tmp_path: Path, capsys: pytest.CaptureFixture[str], other: dict[str, Any]) -> str:
    paths = write(tmp_path, [annotator(1), other])
    assert main(["merge", *paths]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = [ln for ln in captured.err.splitlines() if ln.strip()]
    assert len(lines) == 1
    assert "Traceback" not in captured.err
    assert lines[0].startswith("camloc merge: error:")
    return lines[0]


def test_another_image_size(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    other = annotator(2)
    other["image"] = {"width": 3840, "height": 2160, "path": "cam.jpg"}
    line = conflict(tmp_path, capsys, other)
    assert "a2.json is for a 3840x2160 image, a1.json for 1920x1080" in line


def test_another_image_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    other = annotator(2)
    other["image"]["path"] = "other-cam.jpg"
    assert "annotates other-cam.jpg, a1.json annotates cam.jpg" in conflict(tmp_path, capsys, other)


def test_different_car_by_size(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    other = annotator(2)
    other["object"] = {"preset": "bus"}
    line = conflict(tmp_path, capsys, other)
    assert "different car" in line
    assert "12x2.55x3.1 m" in line


def test_different_car_by_place(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    other = annotator(2)
    axes = other["annotations"][0]["axes"]
    dx = 400.0 if axes["origin"][0] < 1400 else -400.0
    for k in axes:
        axes[k] = [axes[k][0] + dx, axes[k][1]]
    line = conflict(tmp_path, capsys, other)
    assert "marks a different car than a1.json" in line


def test_wrong_corner_is_the_same_car() -> None:
    """An annotator starting at the far end of the length edge still marks the same car."""
    other = annotator(2)
    axes = other["annotations"][0]["axes"]
    axes["origin"], axes["length"] = axes["length"], axes["origin"]
    merged = merge_scenes([annotator(1), other])
    assert len(merged["annotations"]) == 2


def test_different_intersection(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    other = annotator(2)
    other["intersection"]["lat"] += 0.002  # about 220 m north
    assert "marks a different intersection" in conflict(tmp_path, capsys, other)
    other = annotator(2)
    other["intersection"]["corners"] = other["intersection"]["corners"][:1]
    n = len(annotator(1)["intersection"]["corners"])
    assert f"lists 1 kerb corners, a1.json {n}" in conflict(tmp_path, capsys, other)
    other = annotator(2)
    other["intersection"]["corners"] = other["intersection"]["corners"][::-1]
    assert "far apart" in conflict(tmp_path, capsys, other)


def test_invalid_scene_is_named(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    other = annotator(2)
    other["annotations"][0]["axes"]["origin"] = ["x", 10]
    line = conflict(tmp_path, capsys, other)
    assert "a2.json" in line
    assert "annotations[0].axes.origin" in line
    with pytest.raises(SceneError, match="at least one"):
        merge_scenes([])


def test_output_never_overwrites_an_input_and_no_file_twice(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``-o a1.json`` replaced the first annotator's file with the merge, and the same file
    given twice merged its annotators twice (w1, w1-2: counted double in the fit)."""
    a1, a2 = write(tmp_path, [annotator(1, "w1"), annotator(2, "ann")])
    before = Path(a1).read_text()
    assert main(["merge", a1, a2, "-o", a1]) == 2
    assert "would overwrite the input" in capsys.readouterr().err
    assert Path(a1).read_text() == before
    assert main(["merge", a1, a2, a1, "-o", str(tmp_path / "m.json")]) == 2
    err = capsys.readouterr().err
    assert f"{a1} is given twice" in err
    assert not (tmp_path / "m.json").exists()
    assert main(["merge", a1, a2, "-o", str(tmp_path / "no" / "m.json")]) == 2
    assert "does not exist (create it first)" in capsys.readouterr().err
