"""Image overlays: near-plane clipping, horizon, projected corners on the annotated pixels."""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import cv2
import numpy as np
import pytest
from shapely.geometry import LineString, Polygon

from camloc_geo import overlay
from camloc_geo.absolute import locate
from camloc_geo.camera import Camera, rotation_from_angles
from camloc_geo.geodesy import LocalFrame
from camloc_geo.osm import load_map
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import NoiseModel, make_located_scene

SAMPLES = Path(__file__).resolve().parents[1] / "sample_maps"
FREMANTLE = (-32.036172, 115.755714)


@pytest.fixture(scope="module")
def fremantle() -> object:
    return load_map(SAMPLES / "fremantle.osm", *FREMANTLE, radius_m=250)


def _junction(map_data: object) -> object:
    its = [i for i in map_data.intersections if i.kind == "junction" and len(i.corners) >= 4]  # type: ignore[attr-defined]
    assert its
    return its[0]


def _camera(heading: float = 0.0, pitch: float = 10.0, height: float = 5.0) -> Camera:
    R = rotation_from_angles(heading, pitch, 0.0)
    return Camera.from_center(1000.0, (960.0, 540.0), R, [0.0, 0.0, height])


# ------------------------------------------------------------------ clipping / horizon
def test_segment_through_the_camera_plane_is_cut_at_the_near_plane() -> None:
    cam = _camera()
    pieces = overlay.clip_polyline_near(cam, [[0.0, -20.0, 0.0], [0.0, 20.0, 0.0]], near_m=0.5)
    assert len(pieces) == 1
    z_cam = pieces[0] @ cam.cam_from_world_rotation[2] + cam.cam_from_world_translation[2]
    assert z_cam.min() == pytest.approx(0.5)
    assert np.allclose(pieces[0][-1], [0.0, 20.0, 0.0])
    px = overlay.project_polyline(cam, [[0.0, -20.0, 0.0], [0.0, 20.0, 0.0]])
    assert len(px) == 1
    assert np.all(np.isfinite(px[0]))


def test_polyline_entirely_behind_gives_nothing() -> None:
    cam = _camera()
    assert overlay.clip_polyline_near(cam, [[-5.0, -3.0, 0.0], [5.0, -30.0, 0.0]]) == []
    assert overlay.project_polyline(cam, [[-5.0, -3.0, 0.0], [5.0, -30.0, 0.0]]) == []


def test_polyline_leaving_and_reentering_the_view_splits() -> None:
    cam = _camera()
    line = [[-3.0, 20.0, 0.0], [-3.0, -20.0, 0.0], [3.0, -20.0, 0.0], [3.0, 20.0, 0.0]]
    pieces = overlay.clip_polyline_near(cam, line)
    assert len(pieces) == 2
    for piece in pieces:
        z_cam = piece @ cam.cam_from_world_rotation[2] + cam.cam_from_world_translation[2]
        assert z_cam.min() >= 0.5 - 1e-9


@pytest.mark.parametrize("pitch", [-5.0, 0.0, 3.0, 30.0])
def test_ground_lines_stay_below_the_horizon(pitch: float) -> None:
    cam = _camera(heading=30.0, pitch=pitch, height=8.0)
    far = [[-5000.0, 8000.0, 0.0], [0.0, 2.0, 0.0], [4000.0, 9000.0, 0.0], [-20.0, -20.0, 0.0]]
    hz = cam.horizon_line()
    pieces = overlay.project_polyline(cam, far, below_horizon=True)
    assert pieces
    for px in pieces:
        assert np.all(px @ hz[:2] + hz[2] > 0)


def test_camera_below_the_ground_draws_no_ground_feature() -> None:
    cam = _camera(pitch=-10.0, height=-2.0)
    line = [[-10.0, 10.0, 0.0], [10.0, 30.0, 0.0]]
    assert overlay.project_polyline(cam, line, below_horizon=True) == []


# -------------------------------------------------------------------- corner pixels
def test_true_pose_projects_map_corners_onto_annotated_pixels(fremantle: object) -> None:
    inter = _junction(fremantle)
    ls = make_located_scene(
        fremantle,
        inter,
        np.random.default_rng(1),
        noise=NoiseModel.exact(),
        corner_sigma_m=0.0,
        min_corners=3,
    )
    assert ls is not None
    corners_en = inter.corners_enu(fremantle.frame)  # type: ignore[attr-defined]
    px = overlay.project_ground_points(ls.camera_enu, corners_en[ls.visible_corner_orders])
    annotated = np.asarray(ls.scene["intersection"]["corners"])
    np.testing.assert_allclose(px, annotated, atol=1e-6)


def test_true_pose_lands_within_click_noise(fremantle: object) -> None:
    inter = _junction(fremantle)
    noise = NoiseModel(point_px=2.0)
    ls = make_located_scene(
        fremantle, inter, np.random.default_rng(5), noise=noise, corner_sigma_m=0.0, min_corners=3
    )
    assert ls is not None
    corners_en = inter.corners_enu(fremantle.frame)  # type: ignore[attr-defined]
    px = overlay.project_ground_points(ls.camera_enu, corners_en[ls.visible_corner_orders])
    err = np.linalg.norm(px - np.asarray(ls.scene["intersection"]["corners"]), axis=1)
    assert err.max() < 5 * 2.0  # 5 sigma of the click noise


def test_best_candidate_overlay_points_match_annotations(fremantle: object, tmp_path: Path) -> None:
    inter = _junction(fremantle)
    ls = make_located_scene(
        fremantle,
        inter,
        np.random.default_rng(2),
        noise=NoiseModel.exact(),
        corner_sigma_m=0.0,
        min_corners=3,
    )
    assert ls is not None
    scene = parse_scene(ls.scene)
    res = locate(scene, fremantle)
    best = res.candidates[0]
    pts = overlay.overlay_points(best, res)
    corners = [p for p in pts if p.kind == "corner"]
    assert len(corners) == len(ls.visible_corner_orders)
    for i, p in enumerate(corners):
        assert p.label == str(i)  # the scene's index
        assert np.linalg.norm(p.projected_px - p.annotated_px) < 1.0
    # the matched map corners are the true ones, in the scene's order
    assert [int(p.map_label[1:]) for p in corners] == ls.visible_corner_orders

    out = tmp_path / "ov" / "best.png"
    img = overlay.candidate_overlay(res, best, fremantle, scene=scene, path=out)
    assert img.shape == (1080, 1920, 3)
    disk = cv2.imread(str(out))
    assert disk is not None
    assert disk.shape == (1080, 1920, 3)
    # no snapshot: drawn on the blank canvas, which most pixels keep
    blank = np.all(disk == np.array(overlay._BLANK_BGR, np.uint8), axis=2)
    assert blank.mean() > 0.5


def test_snapshot_is_the_background(fremantle: object, tmp_path: Path) -> None:
    inter = _junction(fremantle)
    ls = make_located_scene(fremantle, inter, np.random.default_rng(3), min_corners=2)
    assert ls is not None
    photo = np.zeros((540, 960, 3), np.uint8)
    photo[:] = (0, 0, 200)  # red, half the stated size: resized to the image size
    cv2.imwrite(str(tmp_path / "snap.png"), photo)
    ls.scene["image"]["path"] = "snap.png"
    scene = parse_scene(ls.scene, base_dir=tmp_path)
    res = locate(scene, fremantle)
    img = overlay.candidate_overlay(
        res, res.candidates[0], fremantle, scene=scene, path=tmp_path / "o.png"
    )
    assert img.shape == (1080, 1920, 3)
    b, g, r = (int(v) for v in img[1075, 5])
    assert r > 100  # dimmed red photo, not the blank canvas
    assert max(b, g) < 40


def test_missing_snapshot_falls_back_to_blank(fremantle: object, tmp_path: Path) -> None:
    inter = _junction(fremantle)
    ls = make_located_scene(fremantle, inter, np.random.default_rng(3), min_corners=2)
    assert ls is not None
    ls.scene["image"]["path"] = "missing.jpg"
    scene = parse_scene(ls.scene, base_dir=tmp_path)
    res = locate(scene, fremantle)
    img = overlay.candidate_overlay(res, res.candidates[0], fremantle, scene=scene)
    assert img.shape == (1080, 1920, 3)


# ------------------------------------------------------------------------ features
def test_features_kerbs_and_rooflines() -> None:
    frame = LocalFrame(lat=0.0, lon=0.0)

    def lonlat(en: list[tuple[float, float]]) -> list[tuple[float, float]]:
        return [tuple(p) for p in frame.points_geographic_from_enu(np.asarray(en)).tolist()]

    street = SimpleNamespace(geometry=LineString(lonlat([(-50.0, 0.0), (50.0, 0.0)])), width_m=10.0)
    square = lonlat([(10.0, 10.0), (20.0, 10.0), (20.0, 20.0), (10.0, 20.0), (10.0, 10.0)])
    tall = SimpleNamespace(footprint=Polygon(square), height_m=12.0, levels=None)
    low = SimpleNamespace(footprint=Polygon(square), height_m=None, levels=None)
    md = SimpleNamespace(streets=[street], buildings=[tall, low])
    feats = overlay.map_features_enu(md, frame, (0.0, 0.0), radius_m=40.0)  # type: ignore[arg-type]
    ys = np.concatenate([k[:, 1] for k in feats.kerbs])
    # kerb lines at ±5 m (half width) within the disc
    assert np.all(np.isclose(np.abs(ys[np.abs(ys) < 6]), 5.0, atol=0.05))
    assert len(feats.building_ground) == 2
    assert len(feats.building_roofs) == 1
    ring, h = feats.building_roofs[0]
    assert h == 12.0
    assert np.allclose(ring[:, 2], 12.0)
    assert math.isclose(float(np.max(np.abs(feats.centre_lines[0][:, 1]))), 0.0, abs_tol=1e-6)
