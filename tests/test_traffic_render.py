"""The second generator draws where the camera model projects (Camera's pixel convention).

``Camera`` puts the first pixel's centre at ``(0.5, 0.5)``; OpenCV's fills put it at ``(0, 0)``
and their anti-aliasing grows a polygon by about 0.7 px a side. These tests render known
polygons and a known box and read the drawn edges back to sub-pixel precision.
"""

from __future__ import annotations

import numpy as np
import pytest

from camloc_geo.testing.traffic_render import (
    SHAPES,
    StreetVehicle,
    _box_faces,
    _coverage,
    _darken,
    _Layer,
    street_camera,
)


def _column_extent(alpha: np.ndarray, col: int) -> tuple[float, float]:
    """Top and bottom edge of the drawn run in one column (coverage-weighted)."""
    a = alpha[:, col]
    centres = np.arange(len(a)) + 0.5
    length = float(a.sum())
    mid = float((a * centres).sum()) / length
    return mid - length / 2, mid + length / 2


@pytest.mark.parametrize("x0", [10.0, 10.25, 10.5, 10.8])
def test_square_lies_where_its_corners_are(x0: float) -> None:
    sq = np.array([[x0, 7.3], [x0 + 10, 7.3], [x0 + 10, 17.3], [x0, 17.3]])
    cov = _coverage(sq, 0, 0, 40, 30)
    uu = np.arange(40) + 0.5
    assert cov.sum() == pytest.approx(100.0, abs=1e-4)  # no growth (OpenCV AA: 129.7)
    assert (cov.sum(axis=0) * uu).sum() / cov.sum() == pytest.approx(x0 + 5, abs=1e-4)
    top, bottom = _column_extent(cov, 15)
    assert (top, bottom) == pytest.approx((7.3, 17.3), abs=1e-4)


def test_slanted_polygon_keeps_its_area_and_centroid() -> None:
    quad = np.array([[5.2, 5.1], [30.4, 12.0], [28.0, 20.7], [6.0, 9.3]])
    cov = _coverage(quad, 0, 0, 40, 30)
    x, y = quad[:, 0], quad[:, 1]
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    area = cross.sum() / 2
    cx = ((x + np.roll(x, -1)) * cross).sum() / (6 * area)
    cy = ((y + np.roll(y, -1)) * cross).sum() / (6 * area)
    vv, uu = np.mgrid[0:30, 0:40] + 0.5
    assert cov.sum() == pytest.approx(abs(area), rel=0.01)
    assert (cov * uu).sum() / cov.sum() == pytest.approx(cx, abs=0.05)
    assert (cov * vv).sum() / cov.sum() == pytest.approx(cy, abs=0.05)


def test_sliver_keeps_its_area() -> None:
    sliver = np.array([[5.0, 5.0], [30.0, 12.0], [30.0, 12.2], [5.0, 5.2]])
    assert _coverage(sliver, 0, 0, 40, 30).sum() == pytest.approx(5.0, rel=0.01)


def test_rendered_box_edges_match_camera_projection() -> None:
    """A cuboid drawn by the renderer: its outline in each column within 0.2 px of the
    projected box's outline (the silhouette of a box is the hull of its corners)."""
    import cv2

    camera = street_camera(7.5)
    veh = StreetVehicle((10.0, -5.5), 0.0, 0.0, shape=SHAPES["cuboid"])
    body = veh.parts_at(0.0)["body"]
    faces = _box_faces(camera, body, np.array([200.0, 200.0, 200.0]), glass=False)
    img = np.zeros((540, 960, 3), np.uint8)
    layer = _Layer(faces, (960, 540))
    layer.paint(img)
    alpha = np.zeros((540, 960))
    alpha[layer.y0 : layer.y0 + layer.h, layer.x0 : layer.x0 + layer.w] = layer.alpha
    hull = cv2.convexHull(camera.project(body).astype(np.float32)).reshape(-1, 2)
    lo, hi = hull.min(axis=0), hull.max(axis=0)
    checked = 0
    for col in range(int(lo[0]) + 3, int(hi[0]) - 3, 5):
        u = col + 0.5
        if np.min(np.abs(hull[:, 0] - u)) < 1.5:
            continue  # a vertex inside the column: the outline bends within it
        ys = []  # the hull's outline crossings at the column's centre
        for a, b in zip(hull, np.roll(hull, -1, axis=0), strict=True):
            if (a[0] - u) * (b[0] - u) < 0:
                ys.append(a[1] + (u - a[0]) / (b[0] - a[0]) * (b[1] - a[1]))
        top, bottom = _column_extent(alpha, col)
        assert top == pytest.approx(min(ys), abs=0.2)
        assert bottom == pytest.approx(max(ys), abs=0.2)
        checked += 1
    assert checked >= 10
    # drawn wholly inside (no seams between the faces): the interior is opaque
    mid = int((lo[0] + hi[0]) / 2)
    top, bottom = _column_extent(alpha, mid)
    assert alpha[int(top) + 2 : int(bottom) - 2, mid].min() == pytest.approx(1.0)
    assert abs(alpha.sum() - cv2.contourArea(hull)) < 0.01 * cv2.contourArea(hull)


def test_shadow_darkens_its_area_only() -> None:
    img = np.full((30, 40, 3), 200, np.uint8)
    _darken(img, np.array([[10.0, 10.0], [20.0, 10.0], [20.0, 15.0], [10.0, 15.0]]), 0.5)
    lost = (200.0 - img.astype(float)).sum() / 3
    assert lost == pytest.approx(50 * 100.0, rel=0.03)
    assert img[12, 9].min() == 200
    assert img[12, 20].min() == 200


def test_first_generator_cuboid_edges_match_camera_projection() -> None:
    """``synthetic_video`` (the radar's own cuboids) draws in the same convention: its
    outline per column within 0.2 px of the projected hull (opacity read from the same
    cuboid drawn on black and on white)."""
    import cv2

    from camloc_geo.testing.synthetic_video import SyntheticVehicle, _draw_vehicle, traffic_camera

    camera = traffic_camera()
    corners = SyntheticVehicle((6.0, 3.0), 30.0, 0.0).corners_at(0.0)
    black = np.zeros((360, 640, 3), np.uint8)
    white = np.full((360, 640, 3), 255, np.uint8)
    assert _draw_vehicle(black, camera, corners, (200, 180, 160))
    assert _draw_vehicle(white, camera, corners, (200, 180, 160))
    alpha = 1.0 - (white.astype(float) - black.astype(float)).mean(axis=2) / 255.0
    hull = cv2.convexHull(camera.project(corners).astype(np.float32)).reshape(-1, 2)
    lo, hi = hull.min(axis=0), hull.max(axis=0)
    checked = 0
    for col in range(int(lo[0]) + 3, int(hi[0]) - 3, 4):
        u = col + 0.5
        if np.min(np.abs(hull[:, 0] - u)) < 1.5:
            continue  # a vertex inside the column: the outline bends within it
        ys = []
        for a, b in zip(hull, np.roll(hull, -1, axis=0), strict=True):
            if (a[0] - u) * (b[0] - u) < 0:
                ys.append(a[1] + (u - a[0]) / (b[0] - a[0]) * (b[1] - a[1]))
        top, bottom = _column_extent(alpha, col)
        assert top == pytest.approx(min(ys), abs=0.2)
        assert bottom == pytest.approx(max(ys), abs=0.2)
        checked += 1
    assert checked >= 10
