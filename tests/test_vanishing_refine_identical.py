"""``_refine_on_sphere`` (one evaluation an iteration, up to 20 segments on Python floats)
against a frozen copy of its two-evaluation numpy form: the same answer bit for bit, not
merely to a tolerance (stop 39).

The calibrate answers downstream are loosely converged (the stopping rules leave ~1e-8), so
anything that changes a vanishing point's last digit moves them; this speed change must not.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
import pytest
from test_vanishing_equivalence import DIAG_PX, _segment_sets

from camloc_geo.vanishing import _refine_on_sphere, fit_vanishing_point

FloatArray = npt.NDArray[np.float64]


def _frozen_refine_on_sphere(
    seg_c: FloatArray, weights: FloatArray, theta0: float, phi0: float
) -> tuple[float, float]:
    """``_refine_on_sphere`` as it was before stop 39 (two evaluations an iteration)."""
    sx, sy = seg_c[:, 0], seg_c[:, 1]
    mx_c = (seg_c[:, 0] + seg_c[:, 2]) / 2.0
    my_c = (seg_c[:, 1] + seg_c[:, 3]) / 2.0
    h = 1e-7

    def fun_many(points: list[tuple[float, float]]) -> FloatArray:
        unit_pts = np.array(
            [[math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)] for t, p in points]
        )
        px, py, pw = unit_pts[:, 0:1], unit_pts[:, 1:2], unit_pts[:, 2:3]
        la, lb = my_c * pw - py, px - mx_c * pw
        lc = mx_c * py - my_c * px
        norm = np.maximum(np.sqrt(la * la + lb * lb), 1e-300)
        return np.asarray((la * sx + lb * sy + lc) / norm * weights)

    th, ph = theta0, phi0
    r = fun_many([(th, ph)])[0]
    cost = float(r @ r)
    lam = 1e-6
    for _ in range(10):
        F = fun_many([(th, ph), (th + h, ph), (th, ph + h)])
        J = (F[1:] - F[0]) / h
        JtJ = J @ J.T
        a, b, c = float(JtJ[0, 0]), float(JtJ[0, 1]), float(JtJ[1, 1])
        A = np.array([[a + lam * (a + 1e-12), b], [float(JtJ[1, 0]), c + lam * (c + 1e-12)]])
        try:
            dth, dph = (-np.linalg.solve(A, J @ r)).tolist()
        except np.linalg.LinAlgError:
            break
        r_new = fun_many([(th + dth, ph + dph)])[0]
        cost_new = float(r_new @ r_new)
        step = max(abs(dth), abs(dph))
        if cost_new < cost:
            th, ph, r = th + dth, ph + dph, r_new
            done = cost - cost_new <= 1e-12 * cost or step < 1e-10
            cost, lam = cost_new, lam * 0.3
            if done:
                break
        else:
            if step < 1e-10:
                break
            lam *= 10.0
            if lam > 1e6:
                break
    return th, ph


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_refine_is_bit_identical_to_the_frozen_form(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    compared = 0
    for seg in _segment_sets(seed, 600):
        if len(seg) < 3:
            continue
        pts = seg.reshape(-1, 2)
        seg_c = ((pts - pts.mean(axis=0)) / (float(np.max(np.abs(pts))) + 1.0)).reshape(-1, 4)
        weights = rng.uniform(0.3, 2.0, len(seg))
        starts = [(1.2, 0.4), (1e-3, -2.5), (float(rng.uniform(0, 3)), float(rng.uniform(-3, 3)))]
        for theta0, phi0 in starts:
            new = _refine_on_sphere(seg_c, weights, theta0, phi0)
            old = _frozen_refine_on_sphere(seg_c, weights, theta0, phi0)
            assert new == old, (seg.tolist(), theta0, phi0)  # exact, not approximate
            compared += 1
    assert compared > 1000


@pytest.mark.parametrize("n_segments", [13, 17, 20, 21, 30])
def test_refine_of_pooled_sets_is_bit_identical(n_segments: int) -> None:
    # Pooled segments (the screen's consensus, the pooled seed): both sides of the
    # Python-float / numpy switch (_PYTHON_REFINE_MAX), noisy and noise-free.
    rng = np.random.default_rng(n_segments)
    for k in range(60):
        vp = rng.uniform([-3000.0, -3000.0], [5000.0, 4000.0])
        a = rng.uniform([0.0, 0.0], [1920.0, 1080.0], size=(n_segments, 2))
        toward = (vp - a) / np.linalg.norm(vp - a, axis=1, keepdims=True)
        seg = np.column_stack([a, a + toward * rng.uniform(15.0, 600.0, size=(n_segments, 1))])
        seg += rng.normal(0.0, [0.0, 0.5, 2.0][k % 3], size=seg.shape)
        pts = seg.reshape(-1, 2)
        seg_c = ((pts - pts.mean(axis=0)) / DIAG_PX).reshape(-1, 4)
        weights = rng.uniform(0.3, 2.0, n_segments)
        start = (float(rng.uniform(0.01, 1.5)), float(rng.uniform(-3.0, 3.0)))
        new = _refine_on_sphere(seg_c, weights, *start)
        old = _frozen_refine_on_sphere(seg_c, weights, *start)
        assert new == old, (n_segments, k)


def test_refine_moves_from_a_poor_start_and_converges() -> None:
    # The comparison above would also pass for a refinement that never moved: pin that it
    # does, from a start 0.05 rad off, onto the noise-free segments' vanishing point.
    rng = np.random.default_rng(7)
    vp = np.array([2.5, -0.8, 1.0]) / np.linalg.norm([2.5, -0.8, 1.0])
    a = rng.uniform(-0.5, 0.5, size=(6, 2))
    toward = vp[:2] / vp[2] - a
    toward /= np.linalg.norm(toward, axis=1, keepdims=True)
    seg_c = np.column_stack([a, a + toward * 0.2])
    theta, phi = math.acos(vp[2]), math.atan2(vp[1], vp[0])
    th, ph = _refine_on_sphere(seg_c, np.ones(6), theta + 0.05, phi - 0.05)
    assert abs(th - theta) < 1e-7
    assert abs(ph - phi) < 1e-7
    fit = fit_vanishing_point(seg_c * 1000.0, scale_px=DIAG_PX)
    assert fit.pixel is not None
    np.testing.assert_allclose(fit.pixel, vp[:2] / vp[2] * 1000.0, rtol=1e-7)


@pytest.mark.parametrize("scale_px", [None, DIAG_PX])
def test_fit_on_python_floats_is_bit_identical_to_the_array_form(
    scale_px: float | None, monkeypatch: pytest.MonkeyPatch
) -> None:
    # fit_vanishing_point's Python-float paths (conditioning, weights, refinement,
    # residuals; up to _PYTHON_REFINE_MAX segments) against its array form, which
    # _PYTHON_REFINE_MAX = 0 selects for every set: the same bytes, the same errors.
    from camloc_geo import DegenerateGeometryError, vanishing

    sets = [seg for seed in (4, 5) for seg in _segment_sets(seed, 400)]
    results = []
    for limit in (vanishing._PYTHON_REFINE_MAX, 0):
        monkeypatch.setattr(vanishing, "_PYTHON_REFINE_MAX", limit)
        out: list[tuple[bytes, bytes, bool] | str] = []
        for seg in sets:
            try:
                fit = fit_vanishing_point(seg, scale_px=scale_px, name="s")
            except DegenerateGeometryError as exc:
                out.append(str(exc))
                continue
            out.append((fit.homogeneous.tobytes(), fit.residuals_px.tobytes(), fit.finite))
        results.append(out)
    assert results[0] == results[1]
    assert sum(isinstance(r, tuple) for r in results[0]) > 600


def test_vector_norm_is_np_linalg_norm_bit_for_bit() -> None:
    from camloc_geo.vanishing import _vector_norm

    rng = np.random.default_rng(3)
    cases: list[npt.ArrayLike] = [[3, 4], [1.0, 2.0, 2.0], np.zeros(3), [1e-200, 1e-200]]
    for n in (2, 3, 5, 9, 40):
        cases += [rng.normal(0.0, 10.0 ** rng.uniform(-8, 8), n) for _ in range(300)]
    wide = rng.normal(size=(6, 4))
    cases += [wide, wide.T, wide[::2, 1:3]]  # 2-D and non-contiguous: flattened as norm does
    for x in cases:
        got, want = _vector_norm(x), np.linalg.norm(x)
        assert got.tobytes() == np.float64(want).tobytes(), x
    assert float(_vector_norm([3, 4])) == 5.0
