"""Tests of camloc_geo.autovp: synthetic Manhattan scenes with a known camera, York Urban photos."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

cv2 = pytest.importorskip("cv2")

from camloc_geo import InputError, NotEnoughStructureError  # noqa: E402
from camloc_geo.autovp import (  # noqa: E402
    AutoVPResult,
    detect_segments,
    detect_vanishing_points,
    horizon_from_up,
    pitch_roll_from_up,
    segments_for_axis,
)

YUD = Path(
    os.environ.get(
        "CAMLOC_YUD_DIR",
        str(Path(__file__).resolve().parents[2] / "shared" / "data" / "yud" / "YorkUrbanDB"),
    )
)
YUD_MISSING = (
    "York Urban DB not available (research use only, not in this repository): download the "
    "York Urban Line Segment Database (Denis, Elder, Estrada, ECCV 2008, Elder Lab, York "
    "University) and set CAMLOC_YUD_DIR to its YorkUrbanDB folder"
)


# ----------------------------------------------------------------- synthetic scenes


def cam_from_world(yaw_deg: float, pitch_deg: float, roll_deg: float) -> np.ndarray:
    """Rotation with rows = camera right, down, forward in a z-up world."""
    ps, th, ph = (math.radians(a) for a in (yaw_deg, pitch_deg, roll_deg))
    fwd = np.array([math.cos(ps) * math.cos(th), math.sin(ps) * math.cos(th), -math.sin(th)])
    r0 = np.cross(fwd, [0.0, 0.0, 1.0])
    r0 /= np.linalg.norm(r0)
    d0 = np.cross(fwd, r0)
    right = math.cos(ph) * r0 + math.sin(ph) * d0
    down = math.cos(ph) * d0 - math.sin(ph) * r0
    return np.array([right, down, fwd])


def render_scene(
    R: np.ndarray,
    f: float,
    size: tuple[int, int] = (800, 600),
    *,
    n_lines: int = 150,
    clutter: int = 20,
    seed: int = 1,
    world_axes: np.ndarray | None = None,
) -> np.ndarray:
    """Draw random world-axis-aligned segments seen by camera ``R`` (pp = image centre)."""
    rng = np.random.default_rng(seed)
    w, h = size
    K = np.array([[f, 0, w / 2], [0, f, h / 2], [0, 0, 1.0]])
    img = np.full((h, w), 235, np.uint8)
    fwd_w = R[2]
    drawn = 0
    tries = 0
    while drawn < n_lines + clutter and tries < 20000:
        tries += 1
        depth = rng.uniform(8, 40)
        lateral = rng.uniform(-1, 1, 3) * depth * 0.8
        p = fwd_w * depth + lateral
        if drawn < n_lines:
            axis = (np.eye(3) if world_axes is None else world_axes)[drawn % 3]
        else:
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
        q = p + axis * rng.uniform(2, 8) * (1 if rng.random() < 0.5 else -1)
        pc, qc = R @ p, R @ q
        if pc[2] < 1 or qc[2] < 1:
            continue
        a = K @ pc
        b = K @ qc
        a, b = a[:2] / a[2], b[:2] / b[2]
        if not (all(a >= 0) and all(b >= 0) and a[0] < w and b[0] < w and a[1] < h and b[1] < h):
            continue
        if np.hypot(*(a - b)) < 30:
            continue
        pa = tuple(int(v) for v in np.rint((a - 0.5) * 16))
        pb = tuple(int(v) for v in np.rint((b - 0.5) * 16))
        cv2.line(img, pa, pb, 30, 2, cv2.LINE_AA, 4)
        drawn += 1
    return img


def dir_errors_deg(est: np.ndarray, true_rows: np.ndarray) -> np.ndarray:
    """For each true direction, the angle to the closest estimated one (up to sign)."""
    c = np.abs(true_rows @ est.T).max(axis=1)
    return np.degrees(np.arccos(np.clip(c, 0, 1)))


@pytest.fixture(scope="module")
def tilted_scene() -> tuple[np.ndarray, np.ndarray, float]:
    R = cam_from_world(30.0, 12.0, 4.0)
    f = 700.0
    return render_scene(R, f), R, f


def test_synthetic_three_vps_and_focal(tilted_scene: tuple[np.ndarray, np.ndarray, float]) -> None:
    img, R, f = tilted_scene
    res = detect_vanishing_points(img)
    assert isinstance(res, AutoVPResult)
    true_dirs = R.T  # rows: world x, y, z axes in the camera frame
    assert dir_errors_deg(res.directions_in_cam, true_dirs).max() < 0.5
    assert res.focal_px == pytest.approx(f, rel=0.03)
    # vertical first, pointing up; pitch and roll as rendered
    assert np.degrees(np.arccos(abs(res.directions_in_cam[0] @ R[:, 2]))) < 0.5
    assert res.directions_in_cam[0] @ R[:, 2] > 0
    assert res.pitch_deg == pytest.approx(12.0, abs=0.5)
    assert res.roll_deg == pytest.approx(4.0, abs=0.5)
    assert res.confidence > 0.7
    assert res.focal_source == "estimated"
    assert res.segments.shape[1] == 4
    assert res.labels.shape == (len(res.segments),)
    assert set(np.unique(res.labels)) <= {-1, 0, 1, 2}
    # the pixel VPs agree with the homogeneous ones
    for v, px in zip(res.vanishing_points, res.vanishing_points_px, strict=True):
        if px is not None:
            assert px == pytest.approx([v[0] / v[2], v[1] / v[2]])
    # horizon passes through both horizontal vanishing points
    a, b, c = res.horizon
    for v in res.vanishing_points[1:]:
        assert abs(a * v[0] + b * v[1] + c * v[2]) / np.linalg.norm(v) < 1e-6


def test_synthetic_known_focal_is_used(tilted_scene: tuple[np.ndarray, np.ndarray, float]) -> None:
    img, R, f = tilted_scene
    res = detect_vanishing_points(img, focal_px=f)
    assert res.focal_px == f
    assert res.focal_source == "given"
    assert dir_errors_deg(res.directions_in_cam, R.T).max() < 0.5


def test_deterministic_for_a_seed(tilted_scene: tuple[np.ndarray, np.ndarray, float]) -> None:
    img, _, _ = tilted_scene
    a = detect_vanishing_points(img, seed=3)
    b = detect_vanishing_points(img, seed=3)
    np.testing.assert_array_equal(a.directions_in_cam, b.directions_in_cam)


def test_vps_at_infinity_are_null() -> None:
    # Level camera square to a facade: vertical and one horizontal VP at infinity.
    R = cam_from_world(0.0, 0.0, 0.0)
    img = render_scene(R, 600.0, seed=4)
    res = detect_vanishing_points(img, focal_px=600.0)
    px = res.vanishing_points_px
    assert px[0] is None  # vertical
    assert sum(p is None for p in px) == 2
    finite = next(p for p in px if p is not None)
    assert finite == pytest.approx([400.0, 300.0], abs=3.0)
    assert res.pitch_deg == pytest.approx(0.0, abs=0.3)
    assert res.roll_deg == pytest.approx(0.0, abs=0.3)
    js = res.to_json()
    assert js["vanishing_points"][0] is None
    assert np.all(np.isfinite(res.vanishing_points))


def test_segments_for_axis(tilted_scene: tuple[np.ndarray, np.ndarray, float]) -> None:
    img, R, f = tilted_scene
    res = detect_vanishing_points(img)
    K = np.array([[f, 0, 400.0], [0, f, 300.0], [0, 0, 1]])
    origin = np.array([400.0, 420.0])
    # the image of world-x through origin: towards the VP of world x
    for axis in range(3):
        v = K @ R[:, axis]
        d = v[:2] - v[2] * origin
        end = origin + 60 * d / np.linalg.norm(d)
        segs = segments_for_axis(res, origin, end)
        assert len(segs) >= 2
        # every returned segment points at the same VP as the axis
        mid = 0.5 * (segs[:, :2] + segs[:, 2:])
        u = segs[:, 2:] - segs[:, :2]
        to_v = v[:2] - v[2] * mid
        cos = np.abs(np.sum(u * to_v, 1)) / np.linalg.norm(u, axis=1) / np.linalg.norm(to_v, axis=1)
        assert np.degrees(np.arccos(np.clip(cos, 0, 1))).max() < 3.0
    # an axis pointing nowhere near a VP
    v0, v1 = (K @ R[:, 0]), (K @ R[:, 1])
    d0 = v0[:2] / v0[2] - origin if abs(v0[2]) > 1e-9 else v0[:2]
    d1 = v1[:2] / v1[2] - origin if abs(v1[2]) > 1e-9 else v1[:2]
    d0, d1 = d0 / np.linalg.norm(d0), d1 / np.linalg.norm(d1)
    bis = d0 + d1 if np.dot(d0, d1) > 0 else d0 - d1
    dirs = [origin + 50 * bis / np.linalg.norm(bis)]
    for end in dirs:
        angles = []
        for vk in res.vanishing_points:
            dk = vk[:2] - vk[2] * origin
            dd = end - origin
            angles.append(
                math.degrees(
                    math.acos(min(1, abs(dd @ dk) / np.linalg.norm(dd) / np.linalg.norm(dk)))
                )
            )
        if min(angles) > 10:
            with pytest.raises(NotEnoughStructureError):
                segments_for_axis(res, origin, end)
    with pytest.raises(InputError):
        segments_for_axis(res, origin, origin)


def test_segments_for_axis_far_off_raises(
    tilted_scene: tuple[np.ndarray, np.ndarray, float],
) -> None:
    img, _, _ = tilted_scene
    res = detect_vanishing_points(img)
    origin = np.array([400.0, 300.0])
    # search a direction at least 15 deg from every VP direction at origin
    angs = []
    for v in res.vanishing_points:
        d = v[:2] - v[2] * origin
        angs.append(math.degrees(math.atan2(d[1], d[0])) % 180)
    for cand in np.arange(0, 180, 1.0):
        if all(min(abs(cand - a), 180 - abs(cand - a)) > 15 for a in angs):
            end = origin + 50 * np.array(
                [math.cos(math.radians(cand)), math.sin(math.radians(cand))]
            )
            with pytest.raises(NotEnoughStructureError, match="not enough structure"):
                segments_for_axis(res, origin, end)
            break
    else:
        pytest.fail("no direction far from all VPs")


# --------------------------------------------------------------------- conventions


def test_pitch_roll_conventions() -> None:
    assert pitch_roll_from_up(np.array([0.0, -1.0, 0.0])) == (0.0, 0.0)
    for yaw, pitch, roll in [(10, 20, 5), (200, -15, -8), (75, 40, 0)]:
        R = cam_from_world(yaw, pitch, roll)
        up_in_cam = R @ np.array([0.0, 0.0, 1.0])
        p, r = pitch_roll_from_up(up_in_cam)
        assert p == pytest.approx(pitch, abs=1e-9)
        assert r == pytest.approx(roll, abs=1e-9)


def test_horizon_from_up_level_camera() -> None:
    line = horizon_from_up(np.array([0.0, -1.0, 0.0]), 500.0, (320.0, 240.0))
    np.testing.assert_allclose(line, [0.0, 1.0, -240.0], atol=1e-12)
    # looking down 10 deg: horizon above the centre by f tan(10 deg)
    R = cam_from_world(0, 10, 0)
    line = horizon_from_up(R @ [0, 0, 1.0], 500.0, (320.0, 240.0))
    y = -(line[0] * 320 + line[2]) / line[1]
    assert y == pytest.approx(240 - 500 * math.tan(math.radians(10)))


# ----------------------------------------------------------------------- bad input


def test_blank_image_is_not_enough_structure() -> None:
    with pytest.raises(NotEnoughStructureError, match="not enough structure"):
        detect_vanishing_points(np.full((480, 640, 3), 127, np.uint8))


def test_noise_image_is_refused_or_unconfident() -> None:
    rng = np.random.default_rng(0)
    img = cv2.GaussianBlur(rng.integers(0, 255, (480, 640), dtype=np.uint8), (5, 5), 0)
    try:
        res = detect_vanishing_points(img)
    except NotEnoughStructureError:
        return
    assert res.confidence < 0.3


@pytest.mark.parametrize("kind", ["blobs", "random_lines"])
def test_unstructured_images_are_not_confident(kind: str) -> None:
    rng = np.random.default_rng(1)
    img = np.full((480, 640), 200, np.uint8)
    for _ in range(70):
        if kind == "blobs":
            centre = (int(rng.integers(0, 640)), int(rng.integers(0, 480)))
            cv2.circle(img, centre, int(rng.integers(5, 80)), int(rng.integers(0, 255)), -1)
        else:
            p = (int(rng.integers(0, 640)), int(rng.integers(0, 480)))
            q = (int(rng.integers(0, 640)), int(rng.integers(0, 480)))
            cv2.line(img, p, q, 0, 2)
    try:
        res = detect_vanishing_points(img)
    except NotEnoughStructureError:
        return
    assert res.confidence < 0.3


def test_too_few_lines() -> None:
    img = np.full((480, 640), 255, np.uint8)
    cv2.rectangle(img, (200, 150), (440, 330), 0, 3)
    with pytest.raises(NotEnoughStructureError):
        detect_vanishing_points(img)


def test_unreadable_file(tmp_path: Path) -> None:
    bad = tmp_path / "bad.jpg"
    bad.write_text("not an image")
    with pytest.raises(InputError, match="cannot decode"):
        detect_vanishing_points(bad)
    with pytest.raises(InputError, match="cannot read"):
        detect_vanishing_points(tmp_path / "missing.png")


def test_bad_arrays_and_focal() -> None:
    with pytest.raises(InputError):
        detect_vanishing_points(np.zeros((4, 4)))
    with pytest.raises(InputError):
        detect_vanishing_points(np.zeros((10, 10, 2)))
    with pytest.raises(InputError):
        detect_vanishing_points(np.zeros((100, 100)), focal_px=-3.0)
    with pytest.raises(InputError, match="principal_point"):
        detect_vanishing_points(np.zeros((100, 100)), principal_point=(np.nan, 3.0))
    with pytest.raises(InputError, match="max_iterations"):
        detect_vanishing_points(np.zeros((100, 100)), max_iterations=0)


def test_detect_segments_convention() -> None:
    img = np.full((200, 300), 255, np.uint8)
    img[:, 150:] = 0  # vertical edge between pixel columns 149 and 150: x = 150
    segs = detect_segments(img, method="lsd")
    assert len(segs) >= 1
    assert np.median(segs[:, [0, 2]]) == pytest.approx(150.0, abs=0.6)
    segs_h = detect_segments(img, method="hough")
    assert len(segs_h) >= 1


def test_float_and_gray_inputs_agree(tilted_scene: tuple[np.ndarray, np.ndarray, float]) -> None:
    img, _, _ = tilted_scene
    a = detect_segments(img)
    b = detect_segments(img.astype(np.float64) / 255.0)
    c = detect_segments(cv2.cvtColor(img, cv2.COLOR_GRAY2BGR))
    d = detect_segments(img.astype(np.uint16) * 257)  # 16-bit
    np.testing.assert_allclose(a, b)
    np.testing.assert_allclose(a, c)
    np.testing.assert_allclose(a, d)


# ---------------------------------------------------------------------- York Urban

YUD_CASES = ["P1020171", "P1020826", "P1040813", "P1080020", "P1020838"]


def _yud_truth(name: str) -> tuple[Path, np.ndarray, float]:
    sio = pytest.importorskip("scipy.io")
    cam = sio.loadmat(str(YUD / "cameraParameters.mat"))
    f = float(cam["focal"][0, 0] / cam["pixelSize"][0, 0])
    orth = sio.loadmat(str(YUD / name / f"{name}GroundTruthVP_Orthogonal_CamParams.mat"))
    dirs = (np.diag([1.0, -1.0, 1.0]) @ orth["vp_orthogonal"]).T
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    return YUD / name / f"{name}.jpg", dirs, f


@pytest.mark.skipif(not YUD.exists(), reason=YUD_MISSING)
@pytest.mark.parametrize("name", YUD_CASES)
def test_york_urban_photo(name: str) -> None:
    path, true_dirs, f_true = _yud_truth(name)
    res = detect_vanishing_points(path)
    assert res.focal_px == pytest.approx(f_true, rel=0.15)
    errs = dir_errors_deg(res.directions_in_cam, true_dirs)
    assert errs.max() < 3.0, errs
    assert res.confidence > 0.5
    assert res.vertical_identified
    # the vertical VP is the ground truth's most vertical direction
    kv = int(np.argmax(np.abs(true_dirs[:, 1])))
    assert abs(res.directions_in_cam[0] @ true_dirs[kv]) > math.cos(math.radians(3.0))


@pytest.mark.parametrize(
    ("size", "f", "yaw", "pitch", "roll"),
    [
        ((1920, 1080), 1400.0, 35.0, 25.0, 2.0),  # HD street camera, shrunk for detection
        ((1280, 720), 900.0, 45.0, 50.0, 0.0),  # mast camera looking down steeply
        ((640, 480), 600.0, 20.0, -20.0, 0.0),  # photo looking up at buildings
    ],
)
def test_synthetic_cameras(
    size: tuple[int, int], f: float, yaw: float, pitch: float, roll: float
) -> None:
    R = cam_from_world(yaw, pitch, roll)
    res = detect_vanishing_points(render_scene(R, f, size, n_lines=200, seed=5))
    assert res.image_size == size
    assert res.focal_px == pytest.approx(f, rel=0.03)
    assert res.pitch_deg == pytest.approx(pitch, abs=0.5)
    assert res.roll_deg == pytest.approx(roll, abs=0.5)
    assert dir_errors_deg(res.directions_in_cam, R.T).max() < 0.5


def test_principal_point_refinement_moves_towards_truth() -> None:
    w, h, f = 800, 600, 700.0
    R = cam_from_world(30.0, 15.0, 0.0)
    true_pp = np.array([w / 2 + 20.0, h / 2 - 15.0])
    # render with an off-centre principal point: shift the centred rendering
    img = render_scene(R, f, (w, h), n_lines=250, seed=7)
    shift = np.array([[1, 0, true_pp[0] - w / 2], [0, 1, true_pp[1] - h / 2]], dtype=np.float64)
    img = cv2.warpAffine(img, shift, (w, h), borderValue=235)
    fixed = detect_vanishing_points(img, focal_px=f)
    free = detect_vanishing_points(img, focal_px=f, estimate_principal_point=True)
    assert fixed.principal_point == (400.0, 300.0)
    err_fixed = np.hypot(*(np.array(fixed.principal_point) - true_pp))
    err_free = np.hypot(*(np.array(free.principal_point) - true_pp))
    assert err_free < 0.5 * err_fixed
    assert (
        dir_errors_deg(free.directions_in_cam, R.T).max()
        < dir_errors_deg(fixed.directions_in_cam, R.T).max()
    )
    given = detect_vanishing_points(img, focal_px=f, principal_point=tuple(true_pp))
    assert dir_errors_deg(given.directions_in_cam, R.T).max() < 0.3


def test_letterbox_bars_and_mask(tilted_scene: tuple[np.ndarray, np.ndarray, float]) -> None:
    img, R, f = tilted_scene
    h, w = img.shape
    boxed = np.zeros((h + 120, w), np.uint8)  # black bars above and below
    boxed[60 : 60 + h] = img
    segs = detect_segments(boxed)
    # no segment along the bars' edges
    flat = np.abs(segs[:, 1] - segs[:, 3]) < 1.0
    near_bar = (np.abs(segs[:, 1] - 60) < 2) | (np.abs(segs[:, 1] - (60 + h)) < 2)
    assert not np.any(flat & near_bar & (np.abs(segs[:, 0] - segs[:, 2]) > 0.5 * w))
    res = detect_vanishing_points(boxed)
    assert res.principal_point == (w / 2, (h + 120) / 2)
    # the camera's principal point is the centre of the picture inside the bars
    res = detect_vanishing_points(boxed, principal_point=(w / 2, 60 + h / 2))
    assert dir_errors_deg(res.directions_in_cam, R.T).max() < 0.5
    assert res.focal_px == pytest.approx(f, rel=0.03)
    # a mask drops segments
    mask = np.ones(boxed.shape, bool)
    mask[:, : w // 2] = False
    masked = detect_segments(boxed, mask=mask)
    assert len(masked) > 0
    assert np.all(masked[:, [0, 2]] >= w // 2)
    with pytest.raises(InputError, match="mask"):
        detect_segments(boxed, mask=np.ones((5, 5), bool))


def project_segments(
    R: np.ndarray, f: float, size: tuple[int, int], n: int = 60, seed: int = 0
) -> np.ndarray:
    """Exact image segments of random world-axis-aligned 3-D segments (no rendering)."""
    rng = np.random.default_rng(seed)
    w, h = size
    K = np.array([[f, 0, w / 2], [0, f, h / 2], [0, 0, 1.0]])
    out: list[list[float]] = []
    while len(out) < n:
        depth = rng.uniform(8, 40)
        p = R[2] * depth + rng.uniform(-1, 1, 3) * depth * 0.6
        q = p + np.eye(3)[len(out) % 3] * rng.uniform(2, 8)
        a, b = K @ (R @ p), K @ (R @ q)
        if a[2] < 1 or b[2] < 1:
            continue
        a, b = a[:2] / a[2], b[:2] / b[2]
        if (
            np.all((a > 0) & (a < size))
            and np.all((b > 0) & (b < size))
            and np.hypot(*(a - b)) > 25
        ):
            out.append([*a, *b])
    return np.array(out)


def test_exact_segments_without_image() -> None:
    R = cam_from_world(40.0, 10.0, -2.0)
    segs = project_segments(R, 900.0, (1000, 750))
    res = detect_vanishing_points(None, segments=segs, image_size=(1000, 750))
    assert dir_errors_deg(res.directions_in_cam, R.T).max() < 0.01
    assert res.focal_px == pytest.approx(900.0, rel=1e-3)
    assert res.image_size == (1000, 750)
    with pytest.raises(InputError):
        detect_vanishing_points(None, segments=segs)


def test_exact_vps_at_infinity_without_warnings() -> None:
    # Level camera square to the world axes: two VPs exactly at infinity (w = 0).
    R = cam_from_world(0.0, 0.0, 0.0)
    segs = project_segments(R, 800.0, (800, 600), seed=2)
    res = detect_vanishing_points(None, segments=segs, image_size=(800, 600), focal_px=800.0)
    px = res.vanishing_points_px
    assert px[0] is None
    assert sum(p is None for p in px) == 2
    assert next(p for p in px if p is not None) == pytest.approx([400.0, 300.0], abs=1e-3)
    assert res.pitch_deg == pytest.approx(0.0, abs=1e-3)
    assert res.roll_deg == pytest.approx(0.0, abs=1e-3)
    assert res.horizon == pytest.approx([0.0, 1.0, -300.0], abs=1e-3)
    assert np.all(np.isfinite(res.vanishing_points))
    # focal unknown and unobservable here: flagged, not a confident number
    res = detect_vanishing_points(None, segments=segs, image_size=(800, 600))
    assert res.focal_source in ("prior", "bound")
    assert res.confidence <= 0.5


def test_axes_hint_selects_the_annotated_frame() -> None:
    size, f = (800, 600), 700.0
    R = cam_from_world(20.0, 10.0, 0.0)
    yaw = math.radians(35.0)
    other = np.array(
        [[math.cos(yaw), math.sin(yaw), 0.0], [-math.sin(yaw), math.cos(yaw), 0.0], [0, 0, 1.0]]
    )
    img = np.minimum(
        render_scene(R, f, size, n_lines=180, clutter=0, seed=11),
        render_scene(R, f, size, n_lines=90, clutter=0, seed=12, world_axes=other),
    )
    plain = detect_vanishing_points(img, focal_px=f)
    assert dir_errors_deg(plain.directions_in_cam, R.T).max() < 0.5  # the dominant frame
    # annotated axes of an object aligned with the other frame, at pixel (400, 450)
    K = np.array([[f, 0, 400.0], [0, f, 300.0], [0, 0, 1]])
    origin = np.array([400.0, 450.0])
    hint = []
    for axis in other[:2]:
        v = K @ (R @ axis)
        d = v[:2] - v[2] * origin
        hint.append((origin, origin + 40 * d / np.linalg.norm(d)))
    hinted = detect_vanishing_points(img, focal_px=f, axes_hint=hint)
    assert dir_errors_deg(hinted.directions_in_cam, (R @ other.T).T).max() < 0.5
    for o, e in hint:
        assert len(segments_for_axis(hinted, o, e)) >= 5
    free = detect_vanishing_points(img, axes_hint=hint)  # focal length unknown too
    assert dir_errors_deg(free.directions_in_cam, (R @ other.T).T).max() < 1.0
    assert free.focal_px == pytest.approx(f, rel=0.05)
    with pytest.raises(InputError, match="axes_hint"):
        detect_vanishing_points(img, focal_px=f, axes_hint=[(origin, origin)])


def _street_segments(
    f: float, lean_deg: float, seed: int = 0
) -> tuple[np.ndarray, tuple[int, int]]:
    """A level camera looking down a street lined with buildings (the street along +y).

    Only the street's vanishing point is finite; the across-street one and the vertical
    one lie far off. ``lean_deg`` turns every vertical segment the same way (a bias).
    """
    from camloc_geo.camera import Camera, rotation_from_angles

    rng = np.random.default_rng(seed)
    w, h = 1024, 768
    R = rotation_from_angles(1.0, 1.5, 0.3)
    cam = Camera.from_center(f, (w / 2, h / 2), R, [0.5, 0.0, 1.6])
    segs = []

    def add(p: np.ndarray, q: np.ndarray) -> None:
        a, b = cam.project(np.array([p, q]))
        inside = all(0 <= v[0] <= w and 0 <= v[1] <= h for v in (a, b))
        if np.all(np.isfinite([*a, *b])) and np.hypot(*(b - a)) > 20 and inside:
            segs.append([*a, *b])

    for side in (-8.0, 8.0):
        for y in rng.uniform(8, 90, 30):  # building edges (vertical)
            add(np.array([side, y, 0.5]), np.array([side, y, rng.uniform(5, 14)]))
        for z in rng.uniform(0.5, 12, 16):  # cornices, window rows (along the street)
            y0 = rng.uniform(8, 40)
            add(np.array([side, y0, z]), np.array([side, y0 + rng.uniform(8, 40), z]))
    for y in rng.uniform(10, 40, 4):  # a few lines across the street
        add(np.array([-6.0, y, 0.0]), np.array([6.0, y, 0.0]))
    segs_a = np.array(segs)
    segs_a += rng.normal(0.0, 0.3, segs_a.shape)
    # bias the verticals' lean
    d = segs_a[:, 2:] - segs_a[:, :2]
    vert = np.abs(d[:, 1]) > 3 * np.abs(d[:, 0])
    c, s = math.cos(math.radians(lean_deg)), math.sin(math.radians(lean_deg))
    mid = 0.5 * (segs_a[:, :2] + segs_a[:, 2:])
    half = 0.5 * d @ np.array([[c, s], [-s, c]])
    segs_a[vert] = np.hstack([mid - half, mid + half])[vert]
    return segs_a, (w, h)


def test_level_street_view_states_a_loose_focal() -> None:
    """The failure mode of issue 24: with a 0.5 degree lean bias of the verticals the focal
    length moves a lot; the stated sigma must say so and the error stay within ~2 sigma."""
    f = 900.0
    segs, size = _street_segments(f, 0.5)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    err = abs(math.log(res.focal_px / f))
    assert res.focal_std_rel > 0.05
    assert err <= 2.5 * res.focal_std_rel
    segs0, _ = _street_segments(f, 0.0)
    res0 = detect_vanishing_points(None, segments=segs0, image_size=size)
    assert abs(math.log(res0.focal_px / f)) <= 2.0 * res0.focal_std_rel


# Where benchmarks/fetch_real_photos.sh puts the photos (never in the repository).
PHOTOS = Path(
    os.environ.get("CAMLOC_PHOTOS_DIR", str(Path.home() / ".cache" / "camloc_geo" / "photos"))
)
SCEAUX = Path(
    os.environ.get("CAMLOC_SCEAUX_DIR", str(PHOTOS / "ImageDataset_SceauxCastle" / "images"))
)
SCEAUX_MISSING = (
    "Sceaux castle photos not found: run benchmarks/fetch_real_photos.sh, or git clone "
    "https://github.com/openMVG/ImageDataset_SceauxCastle and set CAMLOC_SCEAUX_DIR to its "
    "images folder"
)
STRECHA = Path(
    os.environ.get(
        "CAMLOC_STRECHA_DIR",
        str(PHOTOS / "SfM_quality_evaluation" / "Benchmarking_Camera_Calibration_2008"),
    )
)
STRECHA_MISSING = (
    "Strecha 2008 photos not found: run benchmarks/fetch_real_photos.sh, or git clone "
    "https://github.com/openMVG/SfM_quality_evaluation and set CAMLOC_STRECHA_DIR to its "
    "Benchmarking_Camera_Calibration_2008 folder"
)


@pytest.mark.skipif(not SCEAUX.exists(), reason=SCEAUX_MISSING)
def test_real_photo_with_exif_and_barrel_distortion() -> None:
    """A compact camera's photo (EXIF kept): the EXIF prior puts the focal length within
    10 % of the published calibration (+6 % here; +12 % without EXIF), and the lens' barrel
    distortion is found."""
    f_true = float(np.loadtxt(SCEAUX / "K.txt")[0, 0])
    res = detect_vanishing_points(str(SCEAUX / "100_7100.JPG"), use_exif=True)
    # the Kodak Z612 is the bundled table's EasyShare Z612 since stop 41 (its lens over the
    # table's width; the 35 mm tag agrees within the sigmas)
    assert res.focal_source == "exif-sensor-table"
    assert abs(res.focal_px - f_true) / f_true < 0.10
    assert res.distortion < 0.0
    assert abs(res.distortion) > 2 * res.distortion_std


@pytest.mark.skipif(not STRECHA.exists(), reason=STRECHA_MISSING)
@pytest.mark.parametrize("name", ["castle-P30/0000", "entry-P10/0000", "Herz-Jesus-P25/0000"])
def test_real_building_photo_focal_and_pitch(name: str) -> None:
    """Photos of buildings with a published calibration: focal length within 10 % (or a
    stated sigma that covers the error), pitch within 2 degrees."""
    group, stem = name.split("/")
    vals = [
        [float(x) for x in ln.split()]
        for ln in (STRECHA / group / "gt_dense_cameras" / f"{stem}.jpg.camera")
        .read_text(encoding="ascii")
        .splitlines()
        if ln.strip()
    ]
    f_true = 0.5 * (vals[0][0] + vals[1][1])
    up = -np.array(vals[6])
    up = up if up[1] < 0 else -up
    pitch_true, _ = pitch_roll_from_up(up)
    res = detect_vanishing_points(str(STRECHA / group / "images" / f"{stem}.jpg"))
    err = abs(math.log(res.focal_px / f_true))
    assert err < 0.10 or err < 2 * res.focal_std_rel
    assert abs(res.pitch_deg - pitch_true) < 2.0


LUND = Path(os.environ.get("CAMLOC_LUND_DIR", str(PHOTOS / "Structure-From-Motion" / "data")))
LUND_MISSING = (
    "Lund course photos not found: run benchmarks/fetch_real_photos.sh, or git clone "
    "https://github.com/erik-norlin/Structure-From-Motion and set CAMLOC_LUND_DIR to its data "
    "folder"
)
#: Coolpix 4200 at 7.8 mm over its 7.11 mm sensor, times the long side (2272 px)
LUND_HEIDELBERG_F_PX = 7.8 / 7.11 * 2272


@pytest.mark.skipif(not (LUND / "7").exists(), reason=LUND_MISSING)
def test_real_photo_gable_of_few_lines_is_in_the_sigma() -> None:
    """Heidelberg castle's facade, looking up 21 degrees: a direction of 7 lines pulls the
    focal length 10 % high. It stays there (the facade and the vertical fix it too), but the
    stated sigma says so: within 1.5 sigmas (it was 3.0 sigmas, at a stated 3.3 %)."""
    res = detect_vanishing_points(str(LUND / "7" / "DSCN7409.JPG"))
    err = abs(math.log(res.focal_px / LUND_HEIDELBERG_F_PX))
    assert 0.07 < err < 0.12
    assert err < 1.5 * res.focal_std_rel
    assert res.pitch_deg == pytest.approx(-21.0, abs=2.0)


@pytest.mark.skipif(not (LUND / "7").exists(), reason=LUND_MISSING)
def test_real_photo_direction_of_few_lines_against_the_exif_is_left_out() -> None:
    """With its EXIF, a Heidelberg castle photo was pulled to -17 % by a direction of 6
    lines (at a stated 5.5 %); that direction now goes and the EXIF holds."""
    res = detect_vanishing_points(str(LUND / "7" / "DSCN7414.JPG"), use_exif=True)
    # the Coolpix 4200's lens over its sensor width in the bundled table since stop 41
    # (the truth's own width, 7.11 mm); its 35 mm tag agrees within the sigmas
    assert res.focal_source == "exif-sensor-table"
    assert abs(math.log(res.focal_px / LUND_HEIDELBERG_F_PX)) < 0.03


@pytest.mark.skipif(not (LUND / "6").exists(), reason=LUND_MISSING)
def test_real_photo_focal_resting_on_a_few_lines_is_warned() -> None:
    """A statue niche of the Landhaus in Graz: the focal length rests on 8 lines that pull it
    to -25 %; it was stated at 3.2 % with confidence 0.87 and no warning."""
    res = detect_vanishing_points(str(LUND / "6" / "DSCN2117.JPG"))
    assert any("rests on a direction of only 8 lines" in w for w in res.warnings)
    assert res.confidence < 0.2
    assert res.focal_std_rel > 0.3
    assert res.focal_source == "estimated"


def test_unobservable_focal_length_gets_the_default_with_its_spread() -> None:
    """A level camera square to the world axes: the photo cannot fix the focal length
    (two vanishing points at infinity). The answer is the default, the longer side, with
    the spread of cameras' focal lengths as its sigma (0.35 in log), not the 4.1 a fit
    with a near-flat prior stated; it is warned and the confidence stays low."""
    R = cam_from_world(0.0, 0.0, 0.0)
    for f_true in (600.0, 1000.0):
        segs = project_segments(R, f_true, (800, 600), seed=2)
        res = detect_vanishing_points(None, segments=segs, image_size=(800, 600))
        assert res.focal_px == pytest.approx(800.0, rel=0.01)
        assert res.focal_std_rel == pytest.approx(0.35, abs=0.01)
        assert abs(math.log(res.focal_px / f_true)) < res.focal_std_rel
        assert res.focal_source == "prior"
        assert any("does not fix the focal length" in w for w in res.warnings)
        assert res.confidence < 0.25


def test_the_default_focal_prior_can_be_left_out_for_a_caller_with_its_own() -> None:
    """``calibrate`` lends a photo's lines to the annotators' fit, which has its own focal
    length: the default prior must not turn the photo's vanishing points about (it did on a
    street photo whose focal length the lines leave loose, and its lines then seemed 6.2
    degrees off the fit's, `tests/test_calibrate_traffic.py`)."""
    R = cam_from_world(0.0, 0.0, 0.0)
    segs = project_segments(R, 600.0, (800, 600), seed=2)
    with_default = detect_vanishing_points(None, segments=segs, image_size=(800, 600))
    own = detect_vanishing_points(
        None, segments=segs, image_size=(800, 600), default_focal_prior=False
    )
    assert with_default.focal_std_rel == pytest.approx(0.35, abs=0.01)  # the default's
    assert own.focal_std_rel > 1.0  # the photo's own: loose, and said so
    assert any("does not fix the focal length" in w for w in own.warnings)
    # a photo that fixes its focal length is the same either way
    segs = project_segments(cam_from_world(30.0, 5.0, 0.0), 600.0, (800, 600), seed=2)
    a = detect_vanishing_points(None, segments=segs, image_size=(800, 600))
    b = detect_vanishing_points(
        None, segments=segs, image_size=(800, 600), default_focal_prior=False
    )
    assert b.focal_px == a.focal_px
    np.testing.assert_array_equal(b.vanishing_points, a.vanishing_points)


def test_line_groups_join_collinear_pieces() -> None:
    from camloc_geo.autovp import _line_groups, _n_distinct_lines

    segs = np.array(
        [
            [0.0, 0.0, 100.0, 0.0],
            [110.0, 1.0, 200.0, 1.0],  # the same line, broken
            [0.0, 50.0, 100.0, 50.0],  # a parallel one
            [0.0, 0.0, 0.0, 80.0],  # a crossing one
        ]
    )
    groups = _line_groups(segs, merge_px=4.0)
    assert groups[0] == groups[1]
    assert len({int(groups[0]), int(groups[2]), int(groups[3])}) == 3
    assert _n_distinct_lines(segs, 4.0) == 3


@pytest.mark.skipif(not (LUND / "3").exists(), reason=LUND_MISSING)
def test_real_frontal_gate_focal_is_the_default_and_said_so() -> None:
    """The Lund cathedral's side gate seen square-on (one finite horizontal vanishing
    point, the vertical one far off): the photo does not fix the focal length. It was
    +50 % at a stated 55 % out of a loose fit; it is now the default joined with what the
    photo says, within 10 %, warned, with a sigma of about 30 %."""
    res = detect_vanishing_points(str(LUND / "3" / "DSC_0003.JPG"))
    f_true = 2379.0  # 55 mm (EXIF) over the D60's 23.6 mm sensor times 1936 px
    err = abs(math.log(res.focal_px / f_true))
    assert err < 0.10
    assert 0.2 < res.focal_std_rel < 0.36
    assert res.focal_source == "prior"
    assert res.confidence < 0.3


@pytest.mark.skipif(not STRECHA.exists(), reason=STRECHA_MISSING)
def test_real_photo_third_direction_of_a_few_lines_is_jackknifed() -> None:
    """Strecha fountain-P11/0000: +10 % at a stated 3.9 % (confidently wrong). Leaving the
    lines of its thinly supported directions out one at a time moves the focal length
    enough to widen the sigma to about 5 %: the error is within 2 sigma. (Stop 39: its
    basin's rim leans on chords of a curve, so it is read again without them: +14 % at a
    stated 7.5 %, still within 2 sigma.)"""
    vals = [
        [float(x) for x in ln.split()]
        for ln in (STRECHA / "fountain-P11" / "gt_dense_cameras" / "0000.jpg.camera")
        .read_text(encoding="ascii")
        .splitlines()
        if ln.strip()
    ]
    f_true = 0.5 * (vals[0][0] + vals[1][1])
    res = detect_vanishing_points(str(STRECHA / "fountain-P11" / "images" / "0000.jpg"))
    err = abs(math.log(res.focal_px / f_true))
    assert 0.07 < err < 0.16
    assert res.focal_std_rel > 0.045
    assert err < 2.0 * res.focal_std_rel


def test_load_image_reads_wide_integer_arrays_by_their_values() -> None:
    """int64 holding 0..255 (img.astype(int)) was scaled by 255 / 2**63 to black; only the
    api worked around it. 16-bit values in an int32 array are read as 16-bit."""
    from camloc_geo.autovp import load_image

    rng = np.random.default_rng(0)
    img8 = rng.integers(0, 256, (40, 60), dtype=np.uint8)
    for dtype in (np.int64, np.int32, np.uint32, np.uint64):
        np.testing.assert_array_equal(load_image(img8.astype(dtype)), img8)
    img16 = img8.astype(np.int32) * 257  # 0..65535
    np.testing.assert_array_equal(load_image(img16), img8)
    np.testing.assert_array_equal(load_image(img8.astype(np.uint16) * 257), img8)  # unchanged
