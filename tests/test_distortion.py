"""Radial lens distortion (division model): camera functions, scene field, vp fit."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from camloc_geo._errors import DegenerateGeometryError
from camloc_geo.camera import (
    Camera,
    RadialDistortion,
    distort_points_px,
    rotation_from_angles,
    undistort_points_px,
)

W, H = 1280, 960
PP = (640.0, 480.0)
DIST = RadialDistortion.for_image(-0.15, W, H)


def test_round_trip_and_direction() -> None:
    rng = np.random.default_rng(0)
    pts = rng.uniform([0, 0], [W, H], size=(200, 2))
    und = undistort_points_px(pts, DIST, PP)
    assert np.allclose(distort_points_px(und, DIST, PP), pts, atol=1e-9)
    # barrel (k1 < 0): undistorted points lie farther from the centre
    r_d = np.hypot(*(pts - PP).T)
    r_u = np.hypot(*(und - PP).T)
    assert np.all(r_u >= r_d - 1e-12)
    corner = undistort_points_px(np.array([0.0, 0.0]), DIST, PP)
    assert np.hypot(*(corner - PP)) == pytest.approx(800.0 / (1 - 0.15), rel=1e-12)
    # the centre does not move; k1 = 0 or None changes nothing
    assert np.allclose(undistort_points_px(np.array(PP), DIST, PP), PP)
    assert np.array_equal(undistort_points_px(pts, None, PP), pts)
    with pytest.raises(DegenerateGeometryError):
        RadialDistortion(1.5, 800.0)


def test_camera_projects_through_the_distortion() -> None:
    R = rotation_from_angles(30.0, 10.0, 0.0)
    pinhole = Camera.from_center(900.0, PP, R, [0.0, -20.0, 5.0])
    lens = Camera(
        900.0, PP, pinhole.cam_from_world_rotation, pinhole.cam_from_world_translation, DIST
    )
    pts = np.array([[3.0, 2.0, 0.0], [10.0, -4.0, 0.0], [6.0, 1.0, 2.0]])
    px_pin = pinhole.project(pts)
    px = lens.project(pts)
    assert np.allclose(undistort_points_px(px, DIST, PP), px_pin, atol=1e-9)
    assert not np.allclose(px, px_pin, atol=1.0)
    # rays and ground casts take photo pixels: back to the same ground points
    ground = lens.ground_from_pixels(px[:2])
    assert np.allclose(ground, pts[:2], atol=1e-6)


def test_scene_accepts_the_distortion_field() -> None:
    from camloc_geo.scene import scene_json_schema

    schema = scene_json_schema()
    text = str(schema)
    assert "LensDistortion" in text
    assert "k1" in text


def _manhattan_segments(f: float, dist: RadialDistortion | None, seed: int = 1) -> np.ndarray:
    """Long lines of a box scene, each sampled as a chain of short segments in the photo."""
    rng = np.random.default_rng(seed)
    R = rotation_from_angles(35.0, 12.0, 2.0)
    cam = Camera.from_center(f, PP, R, [-25.0, -30.0, 6.0])
    if dist is not None:
        cam = Camera(f, PP, cam.cam_from_world_rotation, cam.cam_from_world_translation, dist)
    segs = []
    for axis in range(3):
        for _ in range(14):
            p0 = rng.uniform([-10, -10, 0], [10, 10, 12])
            d = np.eye(3)[axis] * rng.uniform(6, 14)
            ts = np.linspace(0, 1, 7)
            px = cam.project(p0 + ts[:, None] * d)
            for a, b in itertools.pairwise(px):
                if np.all(np.isfinite([*a, *b])) and np.all((a > 0) & (a < [W, H])):
                    segs.append([*a, *b])
    return np.array(segs)


def test_vp_fit_with_the_distortion_given_recovers_the_focal() -> None:
    from camloc_geo.autovp import detect_vanishing_points

    f = 800.0
    segs = _manhattan_segments(f, DIST)
    plain = detect_vanishing_points(None, segments=segs, image_size=(W, H))
    given = detect_vanishing_points(None, segments=segs, image_size=(W, H), distortion_k1=-0.15)
    assert given.focal_px == pytest.approx(f, rel=0.02)
    assert abs(given.focal_px - f) < abs(plain.focal_px - f)
    assert given.distortion == -0.15
    assert len(given.segments) == len(segs)  # reported in the photo's pixels
    assert np.array_equal(np.sort(given.segments, axis=0), np.sort(segs, axis=0))


def test_missing_photo_is_warned(tmp_path: Path) -> None:
    """A scene whose image.path does not exist loads with a warning naming it."""
    import json

    from camloc_geo.scene import load_scene

    scene = {
        "format": "camloc-scene/1",
        "image": {"width": 1280, "height": 720, "path": "nowhere.jpg"},
        "camera": {"distortion": {"k1": -0.05}},
        "annotations": [
            {
                "axes": {
                    "origin": [600, 500],
                    "length": [800, 520],
                    "width": [560, 540],
                    "height": [600, 420],
                }
            }
        ],
    }
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene), encoding="utf-8")
    loaded = load_scene(path)
    assert any("nowhere.jpg" in w and "does not exist" in w for w in loaded.input_warnings)
    assert loaded.camera.distortion is not None
    assert loaded.camera.distortion.k1 == -0.05
    from PIL import Image

    Image.new("RGB", (1280, 720)).save(tmp_path / "nowhere.jpg")  # a photo of the scene's size
    assert not any("image.path" in w for w in load_scene(path).input_warnings)
    (tmp_path / "nowhere.jpg").write_bytes(b"x")  # not a photo: warned, as a missing one
    assert any("not an image file" in w for w in load_scene(path).input_warnings)


def test_calibrate_undistorts_the_annotations() -> None:
    """A scene annotated on a barrel-distorted photo: with camera.distortion the focal
    length is found as on the pinhole photo; without it, it is off."""
    from camloc_geo.relative import calibrate
    from camloc_geo.scene import parse_scene
    from camloc_geo.testing.synthetic import NoiseModel, make_scene, random_camera

    rng = np.random.default_rng(7)
    size = (1920, 1080)
    cam = random_camera(rng, image_size=size, focal_px=(900.0, 900.0), roll_deg=0.0)
    syn = make_scene(cam, rng, noise=NoiseModel.exact(), n_annotators=3, image_size=size)
    dist = RadialDistortion.for_image(-0.2, *size)
    pp = cam.principal_point

    def warp(values: list[float]) -> list[float]:
        arr = np.asarray(values, float).reshape(-1, 2)
        return [float(v) for v in distort_points_px(arr, dist, pp).ravel()]

    data = syn.scene
    for ann in data["annotations"]:
        for k, v in ann["axes"].items():
            ann["axes"][k] = warp(v)
        for k, segs in ann.get("vp_lines", {}).items():
            ann["vp_lines"][k] = [warp(s) for s in segs]
    data["camera"] = {"principal_point": list(pp)}
    plain = calibrate(parse_scene(data))
    data["camera"]["distortion"] = {"model": "division", "k1": -0.2}
    fixed = calibrate(parse_scene(data))
    f_true = cam.focal_px
    assert abs(fixed.camera.focal_px - f_true) / f_true < 0.02
    assert abs(fixed.camera.focal_px - f_true) < abs(plain.camera.focal_px - f_true)


def test_vp_estimates_the_distortion_from_bowed_lines() -> None:
    from camloc_geo.autovp import detect_vanishing_points

    f = 800.0
    segs = _manhattan_segments(f, DIST)
    segs = segs + np.random.default_rng(0).normal(0.0, 0.3, segs.shape)
    est = detect_vanishing_points(None, segments=segs, image_size=(W, H), estimate_distortion=True)
    assert est.distortion == pytest.approx(-0.15, abs=0.03)
    assert 0.0 < est.distortion_std < 0.05
    assert abs(est.focal_px - f) / f < 0.06
    straight = _manhattan_segments(f, None)
    straight = straight + np.random.default_rng(0).normal(0.0, 0.3, straight.shape)
    none = detect_vanishing_points(
        None, segments=straight, image_size=(W, H), estimate_distortion=True
    )
    assert abs(none.distortion) <= 2.5 * none.distortion_std
