"""``benchmarks/crowd_slips.py``'s scoring: a warning naming the slipped annotator by its place
in the scene (``annotations[1]``) says the slip as much as one naming its id (``'w2'``)."""

from __future__ import annotations

import sys
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))

import crowd_slips

from camloc_geo.testing.synthetic import NoiseModel, make_scene, random_camera


def _syn() -> Any:
    rng = np.random.default_rng(3)
    cam = random_camera(rng)
    syn = make_scene(cam, rng, noise=NoiseModel(wrong_corner_prob=0.0), n_annotators=3)
    for k, ann in enumerate(syn.scene["annotations"]):
        ann["annotator"] = f"w{k + 1}"
    return syn


def _wrong_result(syn: Any, warnings: list[str]) -> Any:
    """A calibration 20 m off at a stated 0.1 m, with these warnings and nobody left out."""
    truth = syn.camera
    camera = SimpleNamespace(
        center_in_world=truth.center_in_world + np.array([20.0, 0.0, 0.0]),
        height_m=truth.height_m,
        focal_px=truth.focal_px,
    )
    return SimpleNamespace(
        camera=camera,
        warnings=warnings,
        outlier_annotators=[],
        corner_mistakes=[],
        excluded_annotators=[],
        position_sigma_m=np.array([0.1, 0.1, 0.1]),
        focal_sigma_px=1.0,
    )


@pytest.mark.parametrize(
    ("warning", "said"),
    [
        ("annotations[1].vp_lines.length[0] (w2): shorter than 20 px", True),
        ("annotations[1].vp_lines.length: fewer than 2 segments; this annotator has none", True),
        ("annotator 'w2' (annotations[1]) left out: pixel clicks off the image", True),
        ("annotations[2].vp_lines.length: fewer than 2 segments", False),
        ("annotations[10].vp_lines.length: fewer than 2 segments", False),
        ("the focal length rests on one vanishing point", False),
    ],
)
def test_a_warning_naming_the_slipped_annotator_by_index_counts(
    monkeypatch: pytest.MonkeyPatch, warning: str, said: bool
) -> None:
    syn = _syn()
    monkeypatch.setattr(crowd_slips, "calibrate", lambda *a, **k: _wrong_result(syn, [warning]))
    row = crowd_slips.classify(syn, 1)
    assert row["warned"] is said
    assert row["outcome"] == ("flagged" if said else "confidently_wrong")


def test_names_annotator_by_id_or_index() -> None:
    assert crowd_slips.names_annotator("annotator 'w2' left out", "w2", 1)
    assert crowd_slips.names_annotator("line 3 (w2): far from the rest", "w2", 1)
    assert crowd_slips.names_annotator("annotations[1].vp_lines.width[0]: short", "w2", 1)
    assert not crowd_slips.names_annotator("annotations[11].vp_lines.width[0]: short", "w2", 1)
    assert not crowd_slips.names_annotator("annotator 'w22' left out", "w2", 1)


def test_a_left_out_annotator_counts_by_its_index(monkeypatch: pytest.MonkeyPatch) -> None:
    syn = _syn()
    res = _wrong_result(syn, [])
    res.excluded_annotators = [{"annotator": "anonymous", "index": 1, "reason": "x"}]
    monkeypatch.setattr(crowd_slips, "calibrate", lambda *a, **k: res)
    assert crowd_slips.classify(syn, 1)["warned"] is True
