"""fit_vanishing_point against a frozen copy of its slower implementation (issue 26).

The speed-up (closed-form 2x2 steps, eigh of the normal matrix, written-out cross products)
must not change answers beyond rounding, nor which inputs raise and with what message.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
import pytest

from camloc_geo import DegenerateGeometryError
from camloc_geo.vanishing import _is_finite, fit_vanishing_point, segment_residuals_px

FloatArray = npt.NDArray[np.float64]


def _old_fit_vanishing_point(
    segments_px: npt.ArrayLike,
    *,
    scale_px: float | None = None,
    name: str = "segments",
) -> tuple[FloatArray, FloatArray, bool]:
    """The implementation before the per-call speed-up (frozen, for comparison)."""
    seg = np.asarray(segments_px, dtype=float)
    if seg.ndim != 2 or seg.shape[1] != 4:
        raise DegenerateGeometryError(f"{name}: segments must be [x1, y1, x2, y2] rows")
    if len(seg) < 2:
        raise DegenerateGeometryError(f"{name}: needs at least 2 segments, got {len(seg)}")
    if not np.all(np.isfinite(seg)):
        raise DegenerateGeometryError(f"{name}: segments contain NaN or infinite values")
    lengths = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1])
    if np.any(lengths < 1e-6):
        i = int(np.argmin(lengths))
        raise DegenerateGeometryError(f"{name}[{i}]: segment has zero length")
    pts = seg.reshape(-1, 2)
    center = pts.mean(axis=0)
    spread = float(np.max(np.abs(pts - center))) or 1.0
    scale = float(scale_px) if scale_px else spread
    # Conditioned homogeneous lines through each segment, normalised to unit normals.
    p1 = np.column_stack([(seg[:, 0:2] - center) / scale, np.ones(len(seg))])
    p2 = np.column_stack([(seg[:, 2:4] - center) / scale, np.ones(len(seg))])
    lines = np.cross(p1, p2)
    lines /= np.linalg.norm(lines[:, :2], axis=1, keepdims=True)
    weights = np.sqrt(lengths / lengths.mean())
    _u, s, vt = np.linalg.svd(lines * weights[:, None])
    # s[1], not s[-2]: with two segments there are only two singular values.
    if s[1] < 1e-9 * max(s[0], 1e-300):
        raise DegenerateGeometryError(
            f"{name}: all segments lie on one line, so they do not define a vanishing point"
        )
    v0 = vt[-1]

    def to_pixels(vc: FloatArray) -> FloatArray:
        # Conditioned homogeneous point back to pixel homogeneous coordinates.
        return np.array(
            [vc[0] * scale + center[0] * vc[2], vc[1] * scale + center[1] * vc[2], vc[2]]
        )

    def unit(theta_phi: FloatArray) -> FloatArray:
        th, ph = theta_phi
        return np.array([math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)])

    # Refine on the sphere in conditioned coordinates (well scaled for any VP, finite or not).
    if v0[2] < 0:
        v0 = -v0
    theta0 = math.acos(float(np.clip(v0[2], -1.0, 1.0)))
    phi0 = math.atan2(v0[1], v0[0])
    seg_c = np.column_stack([(seg[:, 0:2] - center) / scale, (seg[:, 2:4] - center) / scale])

    mx_c = (seg_c[:, 0] + seg_c[:, 2]) / 2.0
    my_c = (seg_c[:, 1] + seg_c[:, 3]) / 2.0

    def fun_many(X: FloatArray) -> FloatArray:
        # segment_residuals_px of the conditioned segments to the unit points of the rows of
        # X = (theta, phi), all at once: (P, n).
        th, ph = X[:, 0:1], X[:, 1:2]
        px, py, pw = np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)
        la, lb = my_c * pw - py, px - mx_c * pw
        lc = mx_c * py - my_c * px
        norm = np.maximum(np.sqrt(la * la + lb * lb), 1e-300)
        return np.asarray((la * seg_c[:, 0] + lb * seg_c[:, 1] + lc) / norm * weights)

    def fun(x: FloatArray) -> FloatArray:
        return np.asarray(fun_many(x[None, :])[0])

    if len(seg) > 2:
        # A few damped Gauss-Newton steps (2 parameters: cheaper than a general solver); the
        # forward-difference Jacobian in the same call as the residuals.
        x = np.array([theta0, phi0])
        r = fun(x)
        cost = float(r @ r)
        lam = 1e-6
        for _ in range(10):
            F = fun_many(np.vstack([x, x + 1e-7 * np.eye(2)]))
            J = ((F[1:] - F[0]) / 1e-7).T
            JtJ, Jtr = J.T @ J, J.T @ r
            try:
                dx = -np.linalg.solve(JtJ + lam * np.diag(np.diag(JtJ) + 1e-12), Jtr)
            except np.linalg.LinAlgError:
                break
            r_new = fun(x + dx)
            cost_new = float(r_new @ r_new)
            if cost_new < cost:
                x, r = x + dx, r_new
                done = cost - cost_new <= 1e-12 * cost or np.max(np.abs(dx)) < 1e-10
                cost, lam = cost_new, lam * 0.3
                if done:
                    break
            else:
                # No decrease: at the minimum to rounding when even this step is tiny.
                if np.max(np.abs(dx)) < 1e-10:
                    break
                lam *= 10.0
                if lam > 1e6:
                    break
        vc = unit(x)
    else:
        vc = v0  # two segments: the linear solution is exact
    vp_h = to_pixels(vc)
    vp_h = vp_h / np.linalg.norm(vp_h)
    residuals = segment_residuals_px(seg, vp_h)
    diag = float(scale_px) if scale_px else 2.0 * spread
    return vp_h.astype(np.float64), residuals, _is_finite(vp_h, diag)


DIAG_PX = math.hypot(1920.0, 1080.0)


def _through(rng: np.random.Generator, vp: np.ndarray, n: int, noise_px: float) -> np.ndarray:
    """``n`` segments in a 1920 x 1080 image on lines through the pixel point ``vp``."""
    a = rng.uniform([0.0, 0.0], [1920.0, 1080.0], size=(n, 2))
    toward = vp - a
    toward /= np.linalg.norm(toward, axis=1, keepdims=True)
    b = a + toward * rng.uniform(20.0, 400.0, size=(n, 1))
    return np.column_stack([a, b]) + rng.normal(0.0, noise_px, size=(n, 4))


def _parallel(rng: np.random.Generator, n: int, noise_px: float) -> np.ndarray:
    """``n`` segments with one image direction (a vanishing point at infinity)."""
    a = rng.uniform([0.0, 0.0], [1920.0, 1080.0], size=(n, 2))
    ang = rng.uniform(0.0, math.pi)
    d = np.array([math.cos(ang), math.sin(ang)])
    b = a + d * rng.uniform(20.0, 400.0, size=(n, 1))
    return np.column_stack([a, b]) + rng.normal(0.0, noise_px, size=(n, 4))


def _segment_sets(seed: int, count: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    sets = []
    for k in range(count):
        n = int(rng.choice([2, 2, 3, 4, 5, 6, 8, 12]))
        kind = k % 6
        if kind == 0:  # a vanishing point in or near the image
            vp = rng.uniform([-2000.0, -2000.0], [4000.0, 3000.0])
            sets.append(_through(rng, vp, n, float(rng.choice([0.0, 0.5, 3.0]))))
        elif kind == 1:  # far out: near-parallel segments
            ang = rng.uniform(0.0, 2.0 * math.pi)
            dist = 10.0 ** rng.uniform(4.0, 8.0)
            vp = np.array([960.0, 540.0]) + dist * np.array([math.cos(ang), math.sin(ang)])
            sets.append(_through(rng, vp, n, float(rng.choice([0.0, 0.2, 1.0]))))
        elif kind == 2:  # parallel in the image, exactly or to the noise
            sets.append(_parallel(rng, n, float(rng.choice([0.0, 0.0, 0.3]))))
        elif kind == 3:  # unrelated segments
            sets.append(rng.uniform(0.0, 1920.0, size=(n, 4)))
        elif kind == 4:  # short segments, integer pixels (as annotated)
            vp = rng.uniform([-5000.0, -5000.0], [7000.0, 6000.0])
            a = rng.uniform([0.0, 0.0], [1920.0, 1080.0], size=(n, 2))
            toward = (vp - a) / np.linalg.norm(vp - a, axis=1, keepdims=True)
            b = a + toward * rng.uniform(8.0, 60.0, size=(n, 1))
            sets.append(np.round(np.column_stack([a, b])))
        else:  # duplicated segments plus one other
            base = _through(rng, rng.uniform(-3000.0, 5000.0, size=2), 2, 0.5)
            sets.append(np.vstack([base[0], base[0], base[1]][: max(n, 2)]))
    return sets


def _assert_same(seg: np.ndarray, scale_px: float | None) -> None:
    message = ""
    try:
        old = _old_fit_vanishing_point(seg, scale_px=scale_px, name="s")
    except DegenerateGeometryError as exc:
        message = str(exc)
    if message:
        with pytest.raises(DegenerateGeometryError) as info:
            fit_vanishing_point(seg, scale_px=scale_px, name="s")
        assert str(info.value) == message
        return
    new = fit_vanishing_point(seg, scale_px=scale_px, name="s")
    # Unit homogeneous vectors, sign included: equal to 1e-9.
    np.testing.assert_allclose(new.homogeneous, old[0], rtol=0.0, atol=1e-9)
    scale = float(np.max(np.abs(seg))) + 1.0
    np.testing.assert_allclose(new.residuals_px, old[1], rtol=0.0, atol=1e-6 * scale)
    if abs(abs(old[0][2]) * 1e3 * (scale_px or 1.0) - np.linalg.norm(old[0][:2])) > 1e-6:
        assert new.finite == old[2]


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("scale_px", [None, DIAG_PX])
def test_fit_matches_the_frozen_implementation(seed: int, scale_px: float | None) -> None:
    for seg in _segment_sets(seed, 600):
        _assert_same(seg, scale_px)


@pytest.mark.parametrize(
    "seg",
    [
        np.array([[0.0, 0.0, 10.0, 10.0], [20.0, 20.0, 35.0, 35.0], [-5.0, -5.0, -1.0, -1.0]]),
        np.array([[0.0, 0.0, 10.0, 10.0], [20.0, 20.0, 35.0, 35.0]]),
        np.array([[100.0, 5.0, 900.0, 5.0], [1000.0, 5.0, 1200.0, 5.0]]),
        np.array([[0.0, 0.0, 10.0, 10.0], [0.0, 0.0, 10.0, 10.0]]),
        np.array([[0.0, 0.0, 10.0, 10.0], [3.0, 3.0, 3.0, 3.0]]),
        np.array([[0.0, 0.0, 10.0, 10.0]]),
        np.array([[0.0, 0.0, 10.0, np.nan], [1.0, 2.0, 3.0, 4.0]]),
        np.array([[0.0, 0.0, 10.0], [1.0, 2.0, 3.0]]),
    ],
)
def test_degenerate_inputs_raise_as_before(seg: np.ndarray) -> None:
    with pytest.raises(DegenerateGeometryError) as old:
        _old_fit_vanishing_point(seg, name="annotations[0].vp_lines.length")
    with pytest.raises(DegenerateGeometryError) as new:
        fit_vanishing_point(seg, name="annotations[0].vp_lines.length")
    assert str(new.value) == str(old.value)
    assert str(new.value).startswith("annotations[0].vp_lines.length")


def test_exactly_parallel_segments_stay_at_infinity() -> None:
    seg = np.array([[0.0, 0.0, 100.0, 50.0], [10.0, 300.0, 210.0, 400.0], [5.0, 9.0, 45.0, 29.0]])
    for s in (seg, seg[:2]):
        new = fit_vanishing_point(s, scale_px=DIAG_PX)
        old = _old_fit_vanishing_point(s, scale_px=DIAG_PX)
        assert not new.finite
        assert not old[2]
        np.testing.assert_allclose(new.homogeneous, old[0], rtol=0.0, atol=1e-9)
        assert abs(new.homogeneous[2]) < 1e-9
