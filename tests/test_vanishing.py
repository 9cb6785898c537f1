"""Vanishing points, intrinsics from them (with fallbacks), rotation from their directions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from camloc_geo import DegenerateGeometryError
from camloc_geo.camera import Camera, rotation_from_angles
from camloc_geo.vanishing import (
    direction_sign,
    estimate_intrinsics,
    fit_vanishing_point,
    focal_from_vanishing_pair,
    principal_point_from_orthocentre,
    rotation_from_vanishing_directions,
    segment_residuals_px,
)

SIZE = (1920, 1080)
DIAG = math.hypot(*SIZE)


def _cam(heading: float, pitch: float, roll: float, f: float, pp: tuple[float, float]) -> Camera:
    return Camera.from_center(
        f, pp, rotation_from_angles(heading, pitch, roll), [-15.0, -12.0, 8.0]
    )


def _segments_along(
    cam: Camera, direction: np.ndarray, starts: np.ndarray, length: float
) -> np.ndarray:
    """Projected segments of 3-D lines through ``starts`` parallel to ``direction``."""
    a = cam.project(starts)
    b = cam.project(starts + length * direction)
    return np.column_stack([a, b])


def _vp_pixel(cam: Camera, direction: np.ndarray) -> np.ndarray:
    v = cam.img_from_cam @ cam.cam_from_world_rotation @ direction
    return v[:2] / v[2]


# ---------------------------------------------------------------- fit_vanishing_point
@settings(max_examples=150, deadline=None)
@given(
    st.floats(0.0, 359.0),
    st.floats(5.0, 60.0),
    st.floats(-15.0, 15.0),
    st.floats(500.0, 5000.0),
    st.integers(0, 2),
    st.integers(2, 6),
    st.integers(0, 10_000),
)
def test_vanishing_point_of_projected_parallel_lines_is_k_r_d(
    heading: float, pitch: float, roll: float, f: float, axis: int, n: int, seed: int
) -> None:
    cam = _cam(heading, pitch, roll, f, (990.0, 520.0))
    d = np.eye(3)[axis]
    rng = np.random.default_rng(seed)
    ahead = cam.center_in_world + 30.0 * cam.cam_from_world_rotation[2]
    starts = ahead + rng.uniform(-8, 8, (n, 3))
    seg = _segments_along(cam, d, starts, 3.0)
    assume(np.all(np.isfinite(seg)))
    lengths = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1])
    assume(lengths.min() > 5.0)
    vp = fit_vanishing_point(seg, scale_px=DIAG)
    expected = cam.img_from_cam @ cam.cam_from_world_rotation @ d
    expected = expected / np.linalg.norm(expected)
    got = vp.homogeneous
    # Same homogeneous point (up to sign), both at infinity or not.
    assert min(np.linalg.norm(got - expected), np.linalg.norm(got + expected)) < 1e-7
    np.testing.assert_allclose(vp.residuals_px, 0.0, atol=1e-6)
    if vp.finite:
        np.testing.assert_allclose(vp.pixel, expected[:2] / expected[2], rtol=1e-6)


def test_parallel_image_lines_give_point_at_infinity() -> None:
    seg = np.array([[100, 100, 500, 300], [100, 400, 500, 600], [900, 50, 1300, 250.0]])
    vp = fit_vanishing_point(seg, scale_px=DIAG)
    assert not vp.finite
    assert vp.pixel is None
    assert abs(vp.homogeneous[2]) < 1e-12
    # The direction of the point at infinity is the lines' direction.
    d = vp.homogeneous[:2] / np.linalg.norm(vp.homogeneous[:2])
    assert abs(d @ np.array([2, 1]) / math.sqrt(5)) == pytest.approx(1.0)
    assert vp.rms_px == pytest.approx(0.0, abs=1e-9)


def test_two_segments_exact_intersection() -> None:
    vp = fit_vanishing_point([[0, 0, 10, 10], [100, 0, 90, 10]], scale_px=DIAG)
    assert vp.finite
    np.testing.assert_allclose(vp.pixel, [50.0, 50.0], atol=1e-9)


@pytest.mark.parametrize(
    ("segments", "message"),
    [
        ([[0, 0, 10, 10]], "needs at least 2 segments, got 1"),
        (np.zeros((0, 4)), "needs at least 2 segments, got 0"),
        ([[0, 0, 10, 10], [5, 5, 5, 5]], r"x\[1\]: segment has zero length"),
        ([[0, 0, 10, 10], [20, 20, 30, 30]], "all segments lie on one line"),
        ([[0, 0, 10, 10], [20, 20, 30, 30], [-5, -5, 40, 40]], "all segments lie on one line"),
        ([[0, 0, 10, float("nan")], [20, 20, 30, 31]], "NaN or infinite"),
        ([[0, 0, 10], [20, 20, 30]], r"must be \[x1, y1, x2, y2\] rows"),
    ],
)
def test_fit_vanishing_point_errors(segments: object, message: str) -> None:
    with pytest.raises(DegenerateGeometryError, match=message) as info:
        fit_vanishing_point(segments, name="x")
    assert str(info.value).startswith("x")


def test_segment_residuals_sign_and_size() -> None:
    vp = np.array([1000.0, 0.0, 1.0])
    seg = np.array([[0, 0, 100, 0], [0, 10, 100, 0]], float)
    r = segment_residuals_px(seg, vp)
    assert r[0] == pytest.approx(0.0)
    assert abs(r[1]) > 1.0


# ----------------------------------------------------------------------- intrinsics
@settings(max_examples=200, deadline=None)
@given(
    st.floats(0.0, 359.0),
    st.floats(10.0, 70.0),
    st.floats(-20.0, 20.0),
    st.floats(400.0, 4000.0),
    st.floats(-200.0, 200.0),
    st.floats(-150.0, 150.0),
)
def test_orthocentre_is_principal_point(
    heading: float, pitch: float, roll: float, f: float, dx: float, dy: float
) -> None:
    pp = (960.0 + dx, 540.0 + dy)
    cam = _cam(heading, pitch, roll, f, pp)
    # Three finite vanishing points: no world axis parallel to the image plane.
    assume(np.abs(cam.cam_from_world_rotation[2]).min() > 0.02)
    vps = [cam.img_from_cam @ cam.cam_from_world_rotation @ e for e in np.eye(3)]
    px = [v[:2] / v[2] for v in vps]
    scale = max(np.linalg.norm(p) for p in px)
    ortho = principal_point_from_orthocentre(*px)
    np.testing.assert_allclose(ortho, pp, atol=1e-8 * scale)
    assert focal_from_vanishing_pair(vps[0], vps[1], pp) == pytest.approx(f, rel=1e-8)
    assert focal_from_vanishing_pair(vps[1], vps[2], pp) == pytest.approx(f, rel=1e-8)


def test_orthocentre_rejects_collinear_points() -> None:
    with pytest.raises(DegenerateGeometryError, match="collinear"):
        principal_point_from_orthocentre([0, 0], [100, 100], [300, 300])


def test_focal_pair_errors() -> None:
    pp = (960.0, 540.0)
    with pytest.raises(DegenerateGeometryError, match="at infinity"):
        focal_from_vanishing_pair([1.0, 0.0, 0.0], [960.0, 5000.0, 1.0], pp)
    with pytest.raises(DegenerateGeometryError, match="not consistent with orthogonal"):
        focal_from_vanishing_pair([3000.0, 540.0, 1.0], [2000.0, 600.0, 1.0], pp)


def _true_vps(cam: Camera) -> dict[str, np.ndarray]:
    KR = cam.img_from_cam @ cam.cam_from_world_rotation
    return {k: KR[:, i] for i, k in enumerate(("length", "width", "height"))}


def test_estimate_intrinsics_fallback_chain() -> None:
    cam = _cam(40.0, 25.0, 4.0, 1300.0, (1000.0, 510.0))
    vps = _true_vps(cam)
    # 1. given
    est = estimate_intrinsics(vps, SIZE, focal_px=1234.0, principal_point=(900.0, 500.0))
    assert (est.method, est.focal_px, est.principal_point) == ("given", 1234.0, (900.0, 500.0))
    # 2. orthocentre: three finite points
    est = estimate_intrinsics(vps, SIZE)
    assert est.method == "orthocentre"
    assert est.focal_px == pytest.approx(1300.0, rel=1e-9)
    np.testing.assert_allclose(est.principal_point, (1000.0, 510.0), atol=1e-6)
    assert "orthocentre" in est.reason
    # 3. two_vp: the vertical point unknown -> principal point at the image centre
    est = estimate_intrinsics({**vps, "height": None}, SIZE, principal_point=(1000.0, 510.0))
    assert est.method == "two_vp"
    assert est.focal_px == pytest.approx(1300.0, rel=1e-9)
    assert "given principal point" in est.reason
    est = estimate_intrinsics({**vps, "height": None}, SIZE)
    assert est.method == "two_vp"
    assert est.principal_point == (960.0, 540.0)
    assert "image centre" in est.reason
    # 4. given focal, principal point at the image centre
    est = estimate_intrinsics({"length": vps["length"]}, SIZE, focal_px=1300.0)
    assert est.method == "given_focal"
    assert est.principal_point == (960.0, 540.0)


def test_estimate_intrinsics_orthocentre_far_off_centre_falls_back() -> None:
    cam = _cam(40.0, 25.0, 4.0, 1300.0, (960.0 + 900.0, 540.0))
    est = estimate_intrinsics(_true_vps(cam), SIZE)
    assert est.method == "two_vp"
    assert "diagonals from the image centre" in est.reason


def test_estimate_intrinsics_parallel_everywhere_without_focal_is_an_error() -> None:
    """Level camera, vertical lines parallel in the image, length lines parallel too."""
    cam = _cam(90.0, 0.0, 0.0, 1300.0, (960.0, 540.0))  # looking along +x: width VP finite
    vps = _true_vps(cam)
    with pytest.raises(DegenerateGeometryError, match=r"give camera\.focal_px in the scene"):
        estimate_intrinsics({**vps, "length": np.array([0.0, 1.0, 0.0])}, SIZE)


# ------------------------------------------------------------------- signs, rotation
def test_direction_sign() -> None:
    m = np.array([0.1, 0.2, 1.0])
    d = np.array([1.0, 0.0, 0.2])
    g = d[:2] - m[:2] * d[2]
    assert direction_sign(d, m, g) == 1.0
    assert direction_sign(d, m, -g) == -1.0
    assert direction_sign(d, m, [-g[1], g[0]]) == 0.0  # perpendicular: ambiguous


@pytest.mark.parametrize("drop", [None, "length", "width", "height"])
def test_rotation_from_directions(drop: str | None) -> None:
    R = rotation_from_angles(130.0, 35.0, -7.0)
    dirs = {k: R[:, i] for i, k in enumerate(("length", "width", "height")) if k != drop}
    np.testing.assert_allclose(rotation_from_vanishing_directions(dirs), R, atol=1e-12)


def test_rotation_from_noisy_directions_is_proper() -> None:
    rng = np.random.default_rng(0)
    R = rotation_from_angles(10.0, 50.0, 3.0)
    dirs = {
        k: R[:, i] + rng.normal(0, 0.01, 3) for i, k in enumerate(("length", "width", "height"))
    }
    Q = rotation_from_vanishing_directions(dirs)
    np.testing.assert_allclose(Q @ Q.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(Q) == pytest.approx(1.0)
    assert np.abs(Q - R).max() < 0.03
    with pytest.raises(DegenerateGeometryError, match="at least two"):
        rotation_from_vanishing_directions({"length": R[:, 0]})


def test_many_lines_do_not_allocate_a_square_matrix() -> None:
    """A vanishing point from 4000 segments stays within a few MB: the line matrix's SVD once
    built its (n, n) left factor (128 MB here; 23 GB for a 200 x 200-line scene, issue found by
    the session-39 client sweep), and the answer is the one the small problem gives."""
    import tracemalloc

    rng = np.random.default_rng(3)
    vp = np.array([4000.0, -300.0])
    n = 4000
    starts = rng.uniform(0.0, 1000.0, size=(n, 2))
    ends = starts + 0.3 * (vp - starts)
    segments = np.hstack([starts, ends])
    tracemalloc.start()
    try:
        got = fit_vanishing_point(segments)
        _cur, peak_b = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak_b < 40e6, f"peak {peak_b / 1e6:.0f} MB"
    assert got.pixel is not None
    assert np.allclose(got.pixel, vp, rtol=1e-6)
    few = fit_vanishing_point(segments[:2]).pixel
    assert few is not None
    assert np.allclose(few, vp, rtol=1e-6)
