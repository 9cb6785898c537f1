"""`calibrate` takes the focal length from the scene's photo where the annotations cannot fix it.

Issue #24 item 5: the annotators' width and height lines are parallel in the image (only the
length vanishing point is finite), so the clicks alone are refused; the scene's photo, drawn
by the true camera, fixes the focal length through :mod:`camloc_geo.autovp`.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from camloc_geo import DegenerateGeometryError
from camloc_geo.camera import Camera, rotation_from_angles
from camloc_geo.relative import CalibrationSettings, calibrate
from camloc_geo.scene import load_scene
from camloc_geo.testing.synthetic import NoiseModel, make_scene

SIZE = (1280, 720)


# The same camera and box-building photo as tests/test_calibrate_autovp.py.
def _camera() -> Camera:
    centre = np.array([-12.0, -9.0, 6.0])
    fwd = np.array([2.3, 0.9, 0.7]) - centre
    heading = math.degrees(math.atan2(fwd[0], fwd[1]))
    pitch = math.degrees(math.atan2(-fwd[2], math.hypot(fwd[0], fwd[1])))
    return Camera.from_center(
        1200.0, (640.0, 360.0), rotation_from_angles(heading, pitch, 2.0), centre
    )


def _render(cam: Camera, size: tuple[int, int]) -> np.ndarray:
    """A grey image of box-like buildings: edges along the three world axes."""
    w, h = size
    img = np.full((h, w, 3), 90, np.uint8)
    rng = np.random.default_rng(3)
    for _ in range(40):
        x0, y0 = rng.uniform(-10, 30), rng.uniform(6, 30)
        dx, dy, hz = rng.uniform(3, 10), rng.uniform(3, 8), rng.uniform(4, 15)
        corners = [(x0, y0), (x0 + dx, y0), (x0 + dx, y0 + dy), (x0, y0 + dy)]
        edges: list[tuple[tuple[float, ...], tuple[float, ...]]] = []
        for i in range(4):
            a, b = corners[i], corners[(i + 1) % 4]
            edges += [((*a, 0.0), (*b, 0.0)), ((*a, hz), (*b, hz)), ((*a, 0.0), (*a, hz))]
        for p3, q3 in edges:
            pa, pb = cam.project(np.array(p3)), cam.project(np.array(q3))
            if np.all(np.isfinite(pa)) and np.all(np.isfinite(pb)):
                cv2.line(
                    img,
                    tuple(int(v) for v in pa),
                    tuple(int(v) for v in pb),
                    (230, 230, 230),
                    2,
                    cv2.LINE_AA,
                )
    return img


def _parallel(segments: list[list[float]]) -> list[list[float]]:
    """The segments turned about their midpoints onto their mean direction (parallel)."""
    segs = np.asarray(segments, dtype=float).reshape(-1, 4)
    d = segs[:, 2:] - segs[:, :2]
    d *= np.sign(d[:, :1] + 1e-12)
    u = d.sum(axis=0) / np.linalg.norm(d.sum(axis=0))
    mid = 0.5 * (segs[:, :2] + segs[:, 2:])
    half = 0.5 * np.linalg.norm(d, axis=1)[:, None]
    return np.hstack([mid - half * u, mid + half * u]).tolist()


def _degenerate_scene(tmp_path: Path, photo: bool) -> Path:
    cam = _camera()
    syn = make_scene(
        cam, np.random.default_rng(0), noise=NoiseModel.exact(), n_annotators=1, image_size=SIZE
    )
    lines = syn.scene["annotations"][0]["vp_lines"]
    for axis in ("width", "height"):
        lines[axis] = _parallel(lines[axis])
    if photo:
        cv2.imwrite(str(tmp_path / "snap.png"), _render(cam, SIZE))
    syn.scene["image"]["path"] = "snap.png"
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(syn.scene))
    return path


def test_the_photo_gives_the_focal_length_the_annotations_cannot(tmp_path: Path) -> None:
    result = calibrate(load_scene(_degenerate_scene(tmp_path, photo=True)))
    truth = _camera().focal_px
    assert result.intrinsics_method == "photo_focal"
    assert abs(result.camera.focal_px / truth - 1.0) < 0.03
    assert result.focal_sigma_px is not None
    assert 0.0 < result.focal_sigma_px < 0.1 * truth
    warned = [w for w in result.warnings if "came from the photo's vanishing points" in w]
    assert len(warned) == 1
    assert f"{result.camera.focal_px:.0f} +/- {result.focal_sigma_px:.0f} px" in warned[0]
    assert result.to_dict()["intrinsics_method"] == "photo_focal"


def test_without_the_photo_the_refusal_stands(tmp_path: Path) -> None:
    scene = load_scene(_degenerate_scene(tmp_path, photo=False))
    with pytest.raises(DegenerateGeometryError, match=r"give camera\.focal_px"):
        calibrate(scene)


def test_photo_lines_off_keeps_the_refusal(tmp_path: Path) -> None:
    scene = load_scene(_degenerate_scene(tmp_path, photo=True))
    with pytest.raises(DegenerateGeometryError, match=r"give camera\.focal_px"):
        calibrate(scene, CalibrationSettings(photo_lines=False))
