"""Camera model: frames, angle conventions, projection round trips, horizon policy."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from camloc_geo import DegenerateGeometryError
from camloc_geo.camera import (
    Camera,
    angles_from_rotation,
    project_to_rotation,
    rotation_from_angles,
)

headings = st.floats(0.0, 359.999)
pitches = st.floats(-80.0, 89.0)
rolls = st.floats(-179.0, 179.0)


def _camera(heading: float, pitch: float, roll: float, height: float, f: float = 1000.0) -> Camera:
    R = rotation_from_angles(heading, pitch, roll)
    return Camera.from_center(f, (640.0, 360.0), R, [3.0, -7.0, height])


# ------------------------------------------------------------------------- rotations
@settings(max_examples=200, deadline=None)
@given(headings, pitches, rolls)
def test_rotation_from_angles_is_proper(heading: float, pitch: float, roll: float) -> None:
    R = rotation_from_angles(heading, pitch, roll)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-12)


@settings(max_examples=300, deadline=None)
@given(headings, st.floats(-89.0, 89.0), rolls)
def test_angles_round_trip(heading: float, pitch: float, roll: float) -> None:
    h, p, r = angles_from_rotation(rotation_from_angles(heading, pitch, roll))
    assert p == pytest.approx(pitch, abs=1e-9)
    assert r == pytest.approx(roll, abs=1e-8)
    # Heading in [0, 360), compared on the circle.
    assert 0.0 <= h < 360.0
    assert math.remainder(h - heading, 360.0) == pytest.approx(0.0, abs=1e-8)


def test_heading_is_clockwise_from_north() -> None:
    """World +y is north, +x east: heading 90 looks along +x, heading 180 along -y."""
    for heading, forward in (
        (0.0, [0, 1, 0]),
        (90.0, [1, 0, 0]),
        (180.0, [0, -1, 0]),
        (270.0, [-1, 0, 0]),
    ):
        R = rotation_from_angles(heading, 0.0, 0.0)
        np.testing.assert_allclose(R[2], forward, atol=1e-12)  # optical axis in the world
        np.testing.assert_allclose(R[0], np.cross(forward, [0, 0, 1]), atol=1e-12)  # image right
        np.testing.assert_allclose(R[1], [0, 0, -1], atol=1e-12)  # image down = world down


def test_positive_pitch_looks_down() -> None:
    R = rotation_from_angles(0.0, 30.0, 0.0)
    forward = R[2]
    assert forward[2] == pytest.approx(-0.5)
    assert forward[1] == pytest.approx(math.cos(math.radians(30)))
    # A point straight ahead on the horizon appears above the image centre.
    cam = Camera.from_center(1000.0, (640.0, 360.0), R, [0, 0, 10.0])
    assert cam.project([0.0, 1e6, 10.0])[1] < 360.0


def test_positive_roll_tilts_image_right_down_and_rotates_scene_anticlockwise() -> None:
    """Module docstring: positive roll = image right side tilts down = scene anticlockwise."""
    R = rotation_from_angles(0.0, 0.0, 10.0)
    right = R[0]
    assert right[2] < 0  # camera x axis points below the horizontal
    assert math.degrees(math.asin(-right[2])) == pytest.approx(10.0)
    cam = Camera.from_center(1000.0, (640.0, 360.0), R, [0, 0, 1.5])
    # Horizon points to the left and right of the optical axis, far away, at eye level.
    left_px = cam.project([-50.0, 1000.0, 1.5])
    right_px = cam.project([50.0, 1000.0, 1.5])
    # In the image (y down), the horizon rises to the right: the scene turned anticlockwise.
    assert right_px[1] < left_px[1]
    slope_deg = math.degrees(math.atan2(left_px[1] - right_px[1], right_px[0] - left_px[0]))
    assert slope_deg == pytest.approx(10.0, abs=1e-6)
    assert cam.angles_deg[2] == pytest.approx(10.0)


def test_straight_down_heading_is_zero() -> None:
    h, p, _r = angles_from_rotation(rotation_from_angles(123.0, 90.0, 0.0))
    assert p == pytest.approx(90.0)
    assert h == 0.0


def test_project_to_rotation_is_proper_and_nearest() -> None:
    rng = np.random.default_rng(3)
    R = rotation_from_angles(40.0, 20.0, -5.0)
    noisy = R + rng.normal(0, 1e-3, (3, 3))
    Q = project_to_rotation(noisy)
    np.testing.assert_allclose(Q @ Q.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(Q) == pytest.approx(1.0)
    assert np.abs(Q - R).max() < 5e-3
    # A reflection is turned into a proper rotation, not kept.
    Q2 = project_to_rotation(np.diag([1.0, 1.0, -1.0]))
    assert np.linalg.det(Q2) == pytest.approx(1.0)
    with pytest.raises(DegenerateGeometryError, match="not finite"):
        project_to_rotation(np.full((3, 3), np.nan))


# ------------------------------------------------------------------------ the camera
def test_camera_frames(basic_camera: Camera) -> None:
    cam = basic_camera
    R, t = cam.cam_from_world_rotation, cam.cam_from_world_translation
    np.testing.assert_allclose(cam.center_in_world, -R.T @ t)
    np.testing.assert_allclose(cam.img_from_cam @ cam.cam_from_img, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(cam.img_from_world, cam.img_from_cam @ np.column_stack([R, t]))
    assert cam.height_m == pytest.approx(6.0)
    # The camera centre projects nowhere; the world origin projects through K [R | t].
    x = cam.img_from_world @ np.array([0, 0, 0, 1.0])
    np.testing.assert_allclose(cam.project([0, 0, 0]), x[:2] / x[2])
    d = cam.to_dict()
    assert d["height_m"] == pytest.approx(6.0)
    assert d["roll_deg"] == pytest.approx(5.0)
    assert d["principal_point"] == [1010.0, 500.0]


def test_camera_rejects_bad_focal_and_pose() -> None:
    with pytest.raises(DegenerateGeometryError, match="focal_px must be positive"):
        Camera(0.0, (0, 0), np.eye(3), np.zeros(3))
    with pytest.raises(DegenerateGeometryError, match="focal_px must be positive"):
        Camera(float("nan"), (0, 0), np.eye(3), np.zeros(3))
    with pytest.raises(DegenerateGeometryError, match="not finite"):
        Camera(100.0, (0, 0), np.eye(3), np.array([0, np.inf, 0]))


def test_project_behind_camera_is_nan(basic_camera: Camera) -> None:
    behind = basic_camera.center_in_world - 5.0 * basic_camera.cam_from_world_rotation[2]
    px = basic_camera.project(np.vstack([behind, [0, 0, 0]]))
    assert np.all(np.isnan(px[0]))
    assert np.all(np.isfinite(px[1]))


@settings(max_examples=200, deadline=None)
@given(
    headings,
    st.floats(5.0, 85.0),
    st.floats(-30.0, 30.0),
    st.floats(1.5, 40.0),
    st.floats(0.0, 1280.0),
    st.floats(0.0, 720.0),
)
def test_ground_from_pixels_round_trip(
    heading: float, pitch: float, roll: float, height: float, u: float, v: float
) -> None:
    cam = _camera(heading, pitch, roll, height)
    g = cam.ground_from_pixels([u, v])
    if np.all(np.isnan(g)):
        # Then the pixel really is at or above the horizon.
        assert cam.rays_in_world([u, v])[2] > -1e-6
        return
    assert g[2] == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(cam.project(g), [u, v], atol=1e-6 * max(1.0, np.linalg.norm(g)))


@settings(max_examples=200, deadline=None)
@given(
    headings,
    st.floats(-20.0, 85.0),
    rolls,
    st.floats(1.5, 40.0),
    st.floats(-200.0, 200.0),
    st.floats(-200.0, 200.0),
    st.floats(-3.0, 3.0),
)
def test_project_then_ground_round_trip(
    heading: float, pitch: float, roll: float, height: float, x: float, y: float, z: float
) -> None:
    cam = _camera(heading, pitch, roll, height)
    point = np.array([x, y, z])
    px = cam.project(point)
    assume(np.all(np.isfinite(px)))
    depth = (cam.cam_from_world_rotation @ point + cam.cam_from_world_translation)[2]
    assume(depth > 0.5)
    back = cam.ground_from_pixels(px, ground_z_m=z)
    assume(np.all(np.isfinite(back)))  # rays parallel to the plane are NaN by policy
    np.testing.assert_allclose(
        back, point, atol=1e-6 * max(1.0, np.linalg.norm(point - cam.center_in_world))
    )


def test_above_horizon_policy() -> None:
    cam = _camera(0.0, 10.0, 0.0, 5.0)
    sky = [640.0, 10.0]  # 10° pitch, f=1000: the horizon is at y ≈ 184
    ground = [640.0, 700.0]
    out = cam.ground_from_pixels(np.array([sky, ground]))
    assert np.all(np.isnan(out[0]))
    assert np.all(np.isfinite(out[1]))
    with pytest.raises(
        DegenerateGeometryError, match=r"pixel \[640.0, 10.0\] is at or above the horizon"
    ):
        cam.ground_from_pixels(np.array([ground, sky]), above_horizon="error")
    # Single pixel in, single row out.
    assert cam.ground_from_pixels(ground).shape == (3,)


def test_horizon_line_sign_and_position() -> None:
    cam = _camera(30.0, 10.0, 4.0, 5.0)
    line = cam.horizon_line()
    # A far-away point at camera height lies on the horizon.
    far = cam.center_in_world + 1e7 * np.array(
        [math.sin(math.radians(30)), math.cos(math.radians(30)), 0]
    )
    px = cam.project(far)
    assert line @ [*px, 1.0] == pytest.approx(0.0, abs=1e-3)
    # Ground pixels are on the positive side.
    g = cam.project([cam.center_in_world[0] + 5, cam.center_in_world[1] + 20, 0.0])
    assert line @ [*g, 1.0] > 0


@settings(max_examples=200, deadline=None)
@given(
    headings,
    st.floats(0.0, 60.0),
    st.floats(-20.0, 20.0),
    st.floats(1.5, 40.0),
    st.floats(0.0, 30.0),
    st.floats(0.0, 1.0),
)
def test_point_on_vertical_recovers_height(
    heading: float, pitch: float, roll: float, height: float, h_point: float, frac: float
) -> None:
    cam = _camera(heading, pitch, roll, height)
    fwd = cam.cam_from_world_rotation[2]
    horiz = fwd[:2] / max(np.linalg.norm(fwd[:2]), 1e-9)
    ground_xy = cam.center_in_world[:2] + (5.0 + 40.0 * frac) * horiz
    top = np.array([*ground_xy, h_point])
    foot_px, top_px = cam.project(np.array([[*ground_xy, 0.0], top]))
    assume(np.all(np.isfinite(top_px)) and np.all(np.isfinite(foot_px)))
    p = cam.point_on_vertical(ground_xy, top_px)
    np.testing.assert_allclose(p, top, atol=1e-6 * (1.0 + 50.0))
    h = cam.height_on_vertical(foot_px, top_px, above_horizon="nan")
    if math.isfinite(h):
        assert h == pytest.approx(h_point, abs=1e-6 * 50.0)


def test_height_on_vertical_clinometer(basic_camera: Camera) -> None:
    cam = basic_camera
    foot, top = cam.project(np.array([[3.0, 1.0, 0.0], [3.0, 1.0, 1.45]]))
    assert cam.height_on_vertical(foot, top) == pytest.approx(1.45, rel=1e-9)
    # The camera's own height: the horizon pixel above a ground point.
    sky = [cam.principal_point[0], 1.0]
    with pytest.raises(DegenerateGeometryError, match="above the horizon"):
        cam.height_on_vertical(sky, foot)
    assert math.isnan(cam.height_on_vertical(sky, foot, above_horizon="nan"))


def test_pixel_exactly_on_the_horizon_is_nan_without_warnings() -> None:
    """A level camera's principal point looks exactly along the horizon (ray z = 0)."""
    cam = Camera.from_center(
        1000.0, (640.0, 360.0), rotation_from_angles(0.0, 0.0, 0.0), [0, 0, 5.0]
    )
    assert cam.rays_in_world([640.0, 360.0])[2] == 0.0
    out = cam.ground_from_pixels(np.array([[640.0, 360.0], [640.0, 700.0]]))  # warnings are errors
    assert np.all(np.isnan(out[0]))
    assert np.all(np.isfinite(out[1]))
    with pytest.raises(DegenerateGeometryError, match="at or above the horizon"):
        cam.ground_from_pixels([640.0, 360.0], above_horizon="error")


def test_cameras_compare_and_hash_without_raising() -> None:
    from camloc_geo.camera import Camera, rotation_from_angles

    R = rotation_from_angles(30.0, 10.0, 0.0)
    a = Camera.from_center(1000.0, (960.0, 540.0), R, np.array([1.0, 2.0, 5.0]))
    b = Camera.from_center(1000.0, (960.0, 540.0), R.copy(), np.array([1.0, 2.0, 5.0]))
    c = Camera.from_center(1001.0, (960.0, 540.0), R, np.array([1.0, 2.0, 5.0]))
    assert a == b
    assert hash(a) == hash(b)
    assert a != c
    assert a != "camera"
    assert len({a, b, c}) == 2


def _liang_barsky(p, q, w, h, m):  # type: ignore[no-untyped-def]
    t0, t1 = 0.0, 1.0
    d = q - p
    for pk, qk in (
        (-d[0], p[0] + m),
        (d[0], w + m - p[0]),
        (-d[1], p[1] + m),
        (d[1], h + m - p[1]),
    ):
        if pk == 0:
            if qk < 0:
                return None
            continue
        r = qk / pk
        if pk < 0:
            t0 = max(t0, r)
        else:
            t1 = min(t1, r)
        if t0 > t1:
            return None
    return np.array([p + t0 * d, p + t1 * d])


def test_clip_segment_to_image_agrees_with_liang_barsky() -> None:
    from camloc_geo.camera import clip_segment_to_image

    rng = np.random.default_rng(0)
    for _ in range(500):
        p, q = rng.uniform(-300.0, 2200.0, (2, 2))
        m = float(rng.choice([0.0, 4.0]))
        got = clip_segment_to_image(p, q, 1920.0, 1080.0, m)
        want = _liang_barsky(p, q, 1920.0, 1080.0, m)
        if want is None or np.allclose(want[0], want[1]):
            assert got is None or np.allclose(got[0], got[1], atol=1e-6)
        else:
            assert got is not None
            np.testing.assert_allclose(got, want, atol=1e-6)


def test_rotvec_conversions_match_scipy() -> None:
    """camera.py's rotation vectors agree with scipy's at every angle, π and 0 included."""
    from scipy.spatial.transform import Rotation

    from camloc_geo.camera import rotation_from_rotvec, rotvec_from_rotation

    rng = np.random.default_rng(3)
    angles = np.concatenate(
        [rng.uniform(0.0, np.pi, 300), np.pi - 10.0 ** rng.uniform(-12, -1, 100), [0.0, 1e-9]]
    )
    for angle in angles:
        axis = rng.normal(size=3)
        v = axis / np.linalg.norm(axis) * angle
        R = Rotation.from_rotvec(v).as_matrix()
        np.testing.assert_allclose(rotation_from_rotvec(v), R, atol=1e-12)
        got, want = rotvec_from_rotation(R), Rotation.from_matrix(R).as_rotvec()
        if np.linalg.norm(want) > np.pi - 1e-6:  # at π, v and -v are one rotation
            assert min(np.linalg.norm(got - want), np.linalg.norm(got + want)) < 1e-7
        else:
            np.testing.assert_allclose(got, want, atol=1e-9)


def test_single_linkage_is_scipys() -> None:
    """The calibration's clusters are scipy's single-linkage flat clusters."""
    from scipy.cluster.hierarchy import fcluster, linkage

    from camloc_geo.relative import _single_linkage_labels

    rng = np.random.default_rng(5)
    for _ in range(300):
        n = int(rng.integers(1, 30))
        pts = rng.normal(size=(n, 3)) * rng.uniform(0.5, 5.0)
        t = float(rng.uniform(0.1, 3.0))
        ours = _single_linkage_labels(pts, t)
        theirs = fcluster(linkage(pts, "single"), t=t, criterion="distance") if n > 1 else [1]
        parts = [
            {frozenset(np.flatnonzero(np.asarray(lab) == k)) for k in set(lab)}
            for lab in (ours, theirs)
        ]
        assert parts[0] == parts[1]
