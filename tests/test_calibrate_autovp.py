"""`calibrate` fills an axis an annotator drew no lines for from the scene's image."""

from __future__ import annotations

import json
import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from camloc_geo import SceneError
from camloc_geo.camera import Camera, rotation_from_angles
from camloc_geo.relative import CalibrationSettings, calibrate
from camloc_geo.scene import load_scene
from camloc_geo.testing.synthetic import NoiseModel, make_scene


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


def test_missing_height_lines_come_from_the_image(tmp_path: Path) -> None:
    cam = _camera()
    size = (1280, 720)
    syn = make_scene(
        cam, np.random.default_rng(0), noise=NoiseModel.exact(), n_annotators=1, image_size=size
    )
    scene = syn.scene
    scene["annotations"][0]["vp_lines"]["height"] = []
    cv2.imwrite(str(tmp_path / "snap.png"), _render(cam, size))
    scene["image"]["path"] = "snap.png"
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    result = calibrate(load_scene(path))
    err = np.linalg.norm(result.camera.center_in_world - cam.center_in_world)
    assert err < 0.05 * np.linalg.norm(cam.center_in_world)
    assert abs(result.camera.focal_px - cam.focal_px) < 0.05 * cam.focal_px


def test_missing_lines_without_image_is_a_clear_error(tmp_path: Path) -> None:
    cam = _camera()
    syn = make_scene(
        cam,
        np.random.default_rng(0),
        noise=NoiseModel.exact(),
        n_annotators=1,
        image_size=(1280, 720),
    )
    syn.scene["annotations"][0]["vp_lines"]["height"] = []
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(syn.scene))
    with pytest.raises(SceneError, match=r"annotations\[0\]\.vp_lines\.height.*at least 2"):
        calibrate(load_scene(path))


def _scene_with_photo(tmp_path: Path, photo_cam: Camera) -> Path:
    """The annotators' exact scene of ``_camera()``, with a photo rendered by ``photo_cam``."""
    cam = _camera()
    size = (1280, 720)
    syn = make_scene(
        cam, np.random.default_rng(0), noise=NoiseModel.exact(), n_annotators=1, image_size=size
    )
    cv2.imwrite(str(tmp_path / "snap.png"), _render(photo_cam, size))
    syn.scene["image"]["path"] = "snap.png"
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(syn.scene))
    return path


def _photo_warnings(result: object) -> list[str]:
    return [w for w in result.warnings if "photo's" in w]  # type: ignore[attr-defined]


def test_a_photo_that_agrees_gives_no_warning(tmp_path: Path) -> None:
    result = calibrate(load_scene(_scene_with_photo(tmp_path, _camera())))
    assert _photo_warnings(result) == []


def test_a_photo_that_disagrees_is_reported(tmp_path: Path) -> None:
    """The photo seen by a camera turned 10 degrees about the vertical: the horizontal axes
    disagree by about 10 degrees, the vertical agrees."""
    cam = _camera()
    t = math.radians(10.0)
    turn = np.array([[math.cos(t), -math.sin(t), 0.0], [math.sin(t), math.cos(t), 0.0], [0, 0, 1]])
    R = cam.cam_from_world_rotation @ turn
    photo_cam = Camera.from_center(cam.focal_px, cam.principal_point, R, cam.center_in_world)
    result = calibrate(load_scene(_scene_with_photo(tmp_path, photo_cam)))
    warnings = _photo_warnings(result)
    axes = {a for w in warnings for a in ("length", "width", "height") if f" {a} vanish" in w}
    assert axes & {"length", "width"}
    assert "height" not in axes
    angles = [float(w.split(" is ")[1].split(" degrees")[0]) for w in warnings if " is " in w]
    assert angles
    assert all(5.0 < a < 15.0 for a in angles)


def _noisy_scene_with_photo(tmp_path: Path, seed: int, photo: bool) -> Path:
    """Two annotators with 2 px clicks and line ends on ``_camera()``; its photo if asked."""
    cam = _camera()
    size = (1280, 720)
    noise = NoiseModel(
        point_px=2.0, line_px=2.0, wrong_corner_prob=0.0, sloppy_prob=0.0, size_rel=0.0
    )
    syn = make_scene(cam, np.random.default_rng(seed), noise=noise, n_annotators=2, image_size=size)
    if photo:
        if not (tmp_path / "snap.png").exists():
            cv2.imwrite(str(tmp_path / "snap.png"), _render(cam, size))
        syn.scene["image"]["path"] = "snap.png"
    path = tmp_path / f"scene{seed}.json"
    path.write_text(json.dumps(syn.scene))
    return path


def test_the_photos_agreeing_lines_strengthen_the_fit(tmp_path: Path) -> None:
    """The photo's segments whose vanishing points agree with the annotators' fit join it
    with a small weight: over 12 noise draws the focal error shrinks and the stated sigma
    does not grow (measured: mean |error| 4.9 -> 4.2 %, median sigma 7.4 -> 7.2 %; 6.7 %
    before the photo's lines were a leave-out group of the jackknife, issue 28), and the
    sigma stays honest (median error/sigma 0.50)."""
    f_true = _camera().focal_px
    err: dict[bool, list[float]] = {True: [], False: []}
    sig: dict[bool, list[float]] = {True: [], False: []}
    for seed in range(12):
        for photo in (True, False):
            result = calibrate(load_scene(_noisy_scene_with_photo(tmp_path, seed, photo)))
            assert result.focal_sigma_px is not None
            err[photo].append(abs(result.camera.focal_px / f_true - 1.0))
            sig[photo].append(result.focal_sigma_px / f_true)
            if photo:
                # all three axes: the rendered buildings have edges along each
                assert set(result.photo_segments) == {"length", "width", "height"}
                assert min(result.photo_segments.values()) >= 20
                assert result.to_dict()["photo_segments"] == result.photo_segments
                assert _photo_warnings(result) == []
            else:
                assert result.photo_segments == {}
    assert np.mean(err[True]) < np.mean(err[False])
    assert np.median(sig[True]) < np.median(sig[False])
    z = np.array(err[True]) / np.array(sig[True])
    assert 0.3 < float(np.median(z)) < 1.0


def test_photo_lines_can_be_switched_off(tmp_path: Path) -> None:
    scene = load_scene(_noisy_scene_with_photo(tmp_path, 0, True))
    on = calibrate(scene)
    off = calibrate(scene, CalibrationSettings(photo_lines=False))
    assert on.photo_segments
    assert off.photo_segments == {}
    assert on.camera.focal_px != off.camera.focal_px


def test_a_disagreeing_photo_lends_no_lines_of_those_axes(tmp_path: Path) -> None:
    """The photo turned 10 degrees about the vertical: its horizontal directions disagree
    with the fit, so none of their segments join it (a warning says so); its vertical
    agrees and may."""
    cam = _camera()
    t = math.radians(10.0)
    turn = np.array([[math.cos(t), -math.sin(t), 0.0], [math.sin(t), math.cos(t), 0.0], [0, 0, 1]])
    R = cam.cam_from_world_rotation @ turn
    photo_cam = Camera.from_center(cam.focal_px, cam.principal_point, R, cam.center_in_world)
    result = calibrate(load_scene(_scene_with_photo(tmp_path, photo_cam)))
    assert "length" not in result.photo_segments
    assert "width" not in result.photo_segments
    assert _photo_warnings(result)
    # the annotators' exact answer stands, up to a fraction of its sigma (the agreeing
    # vertical lines' own error, 2.4 px here)
    assert result.focal_sigma_px is not None
    assert abs(result.camera.focal_px - cam.focal_px) < 0.5 * result.focal_sigma_px
    assert result.camera.focal_px == pytest.approx(cam.focal_px, rel=0.01)


_K1 = -0.2  # barrel: a corner moves outwards by about 25 % of its distance to the centre


def _render_distorted(cam: Camera, size: tuple[int, int], k1: float) -> np.ndarray:
    """:func:`_render`'s buildings through a division-model lens (edges drawn curved)."""
    from camloc_geo.camera import RadialDistortion, distort_points_px

    w, h = size
    dist = RadialDistortion.for_image(k1, w, h)
    img = np.full((h, w, 3), 90, np.uint8)
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 1.0, 60)[:, None]
    for _ in range(40):
        x0, y0 = rng.uniform(-10, 30), rng.uniform(6, 30)
        dx, dy, hz = rng.uniform(3, 10), rng.uniform(3, 8), rng.uniform(4, 15)
        corners = [(x0, y0), (x0 + dx, y0), (x0 + dx, y0 + dy), (x0, y0 + dy)]
        for i in range(4):
            a, b = corners[i], corners[(i + 1) % 4]
            for p3, q3 in (
                ((*a, 0.0), (*b, 0.0)),
                ((*a, hz), (*b, hz)),
                ((*a, 0.0), (*a, hz)),
            ):
                pts3 = np.array(p3) + t * (np.array(q3) - np.array(p3))
                px = distort_points_px(cam.project(pts3), dist, cam.principal_point)
                px = px[np.all(np.isfinite(px), axis=1) & np.all(np.abs(px) < 1e5, axis=1)]
                if len(px) >= 2:
                    poly = np.round(px * 16).astype(np.int32).reshape(-1, 1, 2)
                    cv2.polylines(img, [poly], False, (230, 230, 230), 2, cv2.LINE_AA, shift=4)
    return img


def _distorted_scene(tmp_path: Path, drop_height: bool) -> tuple[Path, Camera]:
    """``_camera()``'s exact annotations and photo, both through a ``_K1`` lens."""
    from camloc_geo.camera import RadialDistortion, distort_points_px

    cam = _camera()
    size = (1280, 720)
    dist = RadialDistortion.for_image(_K1, *size)
    syn = make_scene(
        cam, np.random.default_rng(0), noise=NoiseModel.exact(), n_annotators=2, image_size=size
    )

    def warp(values: list[float]) -> list[float]:
        arr = np.asarray(values, float).reshape(-1, 2)
        return [float(v) for v in distort_points_px(arr, dist, cam.principal_point).ravel()]

    data = syn.scene
    for ann in data["annotations"]:
        for k, v in ann["axes"].items():
            ann["axes"][k] = warp(v)
        for k, segs in ann.get("vp_lines", {}).items():
            ann["vp_lines"][k] = [warp(s) for s in segs]
        if drop_height:
            ann["vp_lines"]["height"] = []
    data["camera"] = {
        "principal_point": list(cam.principal_point),
        "distortion": {"model": "division", "k1": _K1},
    }
    cv2.imwrite(str(tmp_path / "snap.png"), _render_distorted(cam, size, _K1))
    data["image"]["path"] = "snap.png"
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data))
    return path, cam


def test_a_distorted_photo_is_undistorted_with_the_scenes_lens(tmp_path: Path) -> None:
    """camera.distortion reaches the photo's detector: its vanishing points are the pinhole
    camera's (focal within 2 %), its agreeing segments join the fit on all three axes (they
    were switched off with a lens before), undistorted as the annotations are (each within
    a pixel of its axis' true vanishing point), and nothing disagrees."""
    from camloc_geo import relative
    from camloc_geo.vanishing import segment_residuals_px

    path, cam = _distorted_scene(tmp_path, drop_height=False)
    scene = load_scene(path)
    res = relative._photo_result(scene)
    assert res is not None
    assert res.distortion == pytest.approx(_K1)
    assert abs(res.focal_px / cam.focal_px - 1.0) < 0.02
    segs = relative._photo_segments_px(scene, res.segments)
    labels = np.asarray(res.labels)
    R = cam.cam_from_world_rotation
    K = np.linalg.inv(cam.cam_from_img)
    true_vps = [K @ R[:, i] for i in range(3)]
    med = []
    for k in range(3):
        mine = segs[labels == k]
        assert len(mine) >= 20
        med.append(min(float(np.median(np.abs(segment_residuals_px(mine, v)))) for v in true_vps))
    assert max(med) < 1.0
    result = calibrate(scene)
    assert set(result.photo_segments) == {"length", "width", "height"}
    assert min(result.photo_segments.values()) >= 10
    assert _photo_warnings(result) == []
    assert abs(result.camera.focal_px / cam.focal_px - 1.0) < 0.01
    err = np.linalg.norm(result.camera.center_in_world - cam.center_in_world)
    assert err < 0.01 * np.linalg.norm(cam.center_in_world)


def test_lines_filled_from_a_distorted_photo_are_undistorted(tmp_path: Path) -> None:
    """No height lines drawn on a distorted photo: the photo's vertical segments fill them in
    the annotations' pinhole pixels (straight through the true vertical vanishing point),
    and the answer stays that of the exact annotations."""
    from camloc_geo import relative
    from camloc_geo.vanishing import segment_residuals_px

    path, cam = _distorted_scene(tmp_path, drop_height=True)
    scene = load_scene(path).undistorted()
    filled = relative._auto_segments(scene, 0, ["height"])["height"]
    assert len(filled) >= 20
    vp_up = np.linalg.inv(cam.cam_from_img) @ cam.cam_from_world_rotation[:, 2]
    # measured 0.03 px; the photo's pixels as they were (before): 1.4 px, focal +238 %
    assert float(np.median(np.abs(segment_residuals_px(filled, vp_up)))) < 0.3
    result = calibrate(load_scene(path), CalibrationSettings(photo_lines=False))
    assert abs(result.camera.focal_px / cam.focal_px - 1.0) < 0.01
    err = np.linalg.norm(result.camera.center_in_world - cam.center_in_world)
    assert err < 0.01 * np.linalg.norm(cam.center_in_world)


def test_a_photo_whose_focal_length_disagrees_widens_every_sigma(tmp_path: Path) -> None:
    """Annotators' clicks of ``_camera()`` (f = 1200 px) with the photo of a camera at the
    same place with f = 900 px: two witnesses 29 % apart. The answer is not moved, every
    stated sigma (and the covariance) is widened by one factor so that the photo's focal
    length lies within two sigma, and a warning says so (a slip shared by all annotators,
    as on the hand-annotated Corolla, shows in nothing else)."""
    cam = _camera()
    size = (1280, 720)
    photo_cam = Camera.from_center(
        900.0, cam.principal_point, cam.cam_from_world_rotation, cam.center_in_world
    )
    noise = NoiseModel(
        point_px=1.0, line_px=1.0, wrong_corner_prob=0.0, sloppy_prob=0.0, size_rel=0.0
    )
    syn = make_scene(cam, np.random.default_rng(5), noise=noise, n_annotators=3, image_size=size)
    bare = tmp_path / "bare.json"
    bare.write_text(json.dumps(syn.scene))
    cv2.imwrite(str(tmp_path / "snap.png"), _render(photo_cam, size))
    syn.scene["image"]["path"] = "snap.png"
    with_photo = tmp_path / "scene.json"
    with_photo.write_text(json.dumps(syn.scene))
    settings = CalibrationSettings(photo_lines=False)  # the photo only as a witness
    plain = calibrate(load_scene(bare), settings)
    result = calibrate(load_scene(with_photo), settings)
    msgs = [w for w in result.warnings if "disagree on the focal length" in w]
    assert len(msgs) == 1
    f_photo = float(msgs[0].split("(")[1].split(" against")[0])
    assert f_photo == pytest.approx(900.0, rel=0.06)
    assert result.camera.focal_px == pytest.approx(plain.camera.focal_px)
    assert plain.focal_sigma_px is not None
    assert result.focal_sigma_px is not None
    factor = result.focal_sigma_px / plain.focal_sigma_px
    assert factor > 2.0
    assert float(msgs[0].split("widened ")[1].split("x ")[0]) == pytest.approx(factor, abs=0.051)
    sd_rel = result.focal_sigma_px / result.camera.focal_px
    assert abs(math.log(f_photo / result.camera.focal_px)) == pytest.approx(2.0 * sd_rel, rel=0.01)
    assert plain.position_sigma_m is not None
    assert result.position_sigma_m is not None
    np.testing.assert_allclose(result.position_sigma_m, factor * plain.position_sigma_m)
    assert plain.rotation_sigma_deg is not None
    assert result.rotation_sigma_deg is not None
    np.testing.assert_allclose(result.rotation_sigma_deg, factor * plain.rotation_sigma_deg)
    assert plain.parameter_covariance is not None
    assert result.parameter_covariance is not None
    np.testing.assert_allclose(
        result.parameter_covariance, factor**2 * plain.parameter_covariance, atol=1e-12
    )
