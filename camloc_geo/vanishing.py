"""Vanishing points from annotated segments, intrinsics and rotation from vanishing points.

Vanishing points are kept homogeneous, ``v = (x, y, w)`` in image pixels (``w = 0`` for a
point at infinity, i.e. segments parallel in the image), so nothing divides by zero.

References: Caprile & Torre (1990) and Hartley & Zisserman, *Multiple View Geometry*, 8.6-8.8
(principal point as the orthocentre of three orthogonal vanishing points; focal length from
two of them).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from camloc_geo._errors import DegenerateGeometryError
from camloc_geo.camera import project_to_rotation

__all__ = [
    "AXES",
    "IntrinsicsEstimate",
    "VanishingPoint",
    "direction_sign",
    "estimate_intrinsics",
    "fit_vanishing_point",
    "focal_from_vanishing_pair",
    "principal_point_from_orthocentre",
    "rotation_from_vanishing_directions",
    "segment_residuals_px",
]

FloatArray = npt.NDArray[np.float64]
AXES: tuple[str, str, str] = ("length", "width", "height")
"""World axis names, in the order x, y, z of the world frame."""

# A vanishing point farther from the image centre than this many image diagonals is reported
# as "at infinity" (the segments are parallel in the image to within ~0.06°).
_INFINITY_DIAGONALS = 1e3


def segment_residuals_px(segments_px: npt.ArrayLike, vp_h: npt.ArrayLike) -> FloatArray:
    """Misfit of segments to a vanishing point, pixels.

    For each segment, the distance of its first endpoint from the line through the
    segment's midpoint and the vanishing point (the standard consistency measure; it is
    defined for vanishing points at infinity too).

    Parameters
    ----------
    segments_px
        ``(N, 4)`` segments ``[x1, y1, x2, y2]``.
    vp_h
        Homogeneous vanishing point ``(3,)``.

    Returns
    -------
    ``(N,)`` signed distances in pixels.
    """
    seg = np.asarray(segments_px, dtype=float).reshape(-1, 4)
    px, py, pw = np.asarray(vp_h, dtype=float).reshape(3)
    mx = (seg[:, 0] + seg[:, 2]) / 2.0
    my = (seg[:, 1] + seg[:, 3]) / 2.0
    # Line through (mx, my, 1) and the vanishing point: the cross product, written out.
    la = my * pw - py
    lb = px - mx * pw
    lc = mx * py - my * px
    norm = np.sqrt(la * la + lb * lb)
    norm = np.where(norm < 1e-300, 1e-300, norm)
    return np.asarray((la * seg[:, 0] + lb * seg[:, 1] + lc) / norm, dtype=np.float64)


@dataclass(frozen=True)
class VanishingPoint:
    """A vanishing point fitted to segments.

    Attributes
    ----------
    homogeneous
        Unit 3-vector ``(x, y, w)`` in pixels; ``w = 0`` at infinity.
    residuals_px
        Per-segment misfit (see :func:`segment_residuals_px`).
    finite
        False when the segments are parallel in the image (the point is at infinity).
    """

    homogeneous: FloatArray
    residuals_px: FloatArray
    finite: bool

    @property
    def pixel(self) -> FloatArray | None:
        """``[x, y]`` pixels, or None when at infinity."""
        if not self.finite:
            return None
        return np.asarray(self.homogeneous[:2] / self.homogeneous[2], dtype=np.float64)

    @property
    def rms_px(self) -> float:
        """RMS of the per-segment residuals."""
        return float(np.sqrt(np.mean(self.residuals_px**2)))


def _vector_norm(x: npt.ArrayLike) -> np.float64:
    """``np.linalg.norm(x)`` (no ``ord``, no ``axis``) by its own arithmetic, ``sqrt(x·x)``
    of the flattened floats (the same bits), without its dispatch (~3 us a call)."""
    v = np.asarray(x)
    if not issubclass(v.dtype.type, np.inexact):
        v = v.astype(float)
    v = v.ravel(order="K")
    return np.float64(np.sqrt(v.dot(v)))


def _is_finite(vp_h: FloatArray, scale_px: float) -> bool:
    xy = vp_h[:2]
    # np.linalg.norm(xy) is sqrt(xy.dot(xy)): the same, without its dispatch.
    return bool(abs(vp_h[2]) * _INFINITY_DIAGONALS * scale_px > np.sqrt(xy.dot(xy)))


def fit_vanishing_point(
    segments_px: npt.ArrayLike,
    *,
    scale_px: float | None = None,
    name: str = "segments",
) -> VanishingPoint:
    """Least-squares vanishing point of two or more segments.

    A linear estimate (smallest singular vector of the conditioned, length-weighted line
    matrix) is refined by minimising the geometric residuals of
    :func:`segment_residuals_px` over the unit sphere of homogeneous points.

    Parameters
    ----------
    segments_px
        ``(N, 4)`` segments ``[x1, y1, x2, y2]``, ``N >= 2``.
    scale_px
        A typical image size (the diagonal) for conditioning and the at-infinity test;
        default: the segments' extent.
    name
        Used in error messages (for example ``annotations[0].vp_lines.length``).

    Returns
    -------
    VanishingPoint

    Raises
    ------
    DegenerateGeometryError
        Fewer than two segments, a zero-length segment, or all segments on one line.
    """
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
    center = np.add.reduce(pts, axis=0) / len(pts)  # pts.mean(axis=0), cheaper
    spread = float(np.max(np.abs(pts - center))) or 1.0
    scale = float(scale_px) if scale_px else spread
    # Conditioned segments and the homogeneous line through each, normalised to unit normals:
    # the cross product of (x1, y1, 1) and (x2, y2, 1), written out (the same rounding as
    # np.cross, without its per-call cost on these tiny arrays).
    mean_length = float(np.add.reduce(lengths)) / len(lengths)
    small = (
        _conditioned_rows(seg, lengths, center, scale, mean_length)
        if len(seg) <= _PYTHON_REFINE_MAX
        else None
    )
    if small is not None:
        seg_c, weights, weighted_lines = small
    else:
        seg_c = (seg - center[[0, 1, 0, 1]]) / scale
        x1, y1, x2, y2 = seg_c.T
        lines = np.empty((len(seg), 3))
        lines[:, 0], lines[:, 1], lines[:, 2] = y1 - y2, x2 - x1, x1 * y2 - y1 * x2
        lines /= np.sqrt(lines[:, 0] * lines[:, 0] + lines[:, 1] * lines[:, 1])[:, None]
        weights = np.sqrt(lengths / mean_length)
        weighted_lines = lines * weights[:, None]
    v0 = _linear_estimate(weighted_lines, name)

    # Refine on the sphere in conditioned coordinates (well scaled for any VP, finite or not).
    if v0[2] < 0:
        v0 = -v0
    v0x, v0y, v0w = (float(c) for c in v0)
    if len(seg) > 2:
        theta0 = math.acos(min(max(v0w, -1.0), 1.0))
        phi0 = math.atan2(v0y, v0x)
        th, ph = _refine_on_sphere(seg_c, weights, theta0, phi0)
        vcx, vcy, vcw = math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)
    else:
        vcx, vcy, vcw = v0x, v0y, v0w  # two segments: the linear solution is exact
    # Conditioned homogeneous point back to pixel homogeneous coordinates, unit length.
    cx, cy = float(center[0]), float(center[1])
    hx, hy, hw = vcx * scale + cx * vcw, vcy * scale + cy * vcw, vcw
    norm = math.sqrt(hx * hx + hy * hy + hw * hw)
    vp_h = np.array([hx / norm, hy / norm, hw / norm])
    if small is not None:
        residuals = _segment_residuals_small(seg, hx / norm, hy / norm, hw / norm)
    else:
        residuals = segment_residuals_px(seg, vp_h)
    diag = float(scale_px) if scale_px else 2.0 * spread
    return VanishingPoint(vp_h, residuals, _is_finite(vp_h, diag))


def _conditioned_rows(
    seg: FloatArray, lengths: FloatArray, center: FloatArray, scale: float, mean_length: float
) -> tuple[FloatArray, FloatArray, FloatArray] | None:
    """:func:`fit_vanishing_point`'s conditioned segments, weights and weighted unit lines
    on Python floats (a few segments): the same correctly rounded operations, one by one, as
    its array expressions, so the same bits. None where a conditioned segment has no
    direction (the array expressions then give the NaN that follows)."""
    cx, cy = center.tolist()
    seg_rows, weight_list, line_rows = [], [], []
    for (a1, b1, a2, b2), length in zip(seg.tolist(), lengths.tolist(), strict=True):
        x1, y1, x2, y2 = (a1 - cx) / scale, (b1 - cy) / scale, (a2 - cx) / scale, (b2 - cy) / scale
        la, lb, lc = y1 - y2, x2 - x1, x1 * y2 - y1 * x2
        norm = math.sqrt(la * la + lb * lb)
        if not norm > 0.0 or norm == math.inf:
            return None
        w = math.sqrt(length / mean_length)
        seg_rows.append([x1, y1, x2, y2])
        weight_list.append(w)
        line_rows.append([la / norm * w, lb / norm * w, lc / norm * w])
    return np.array(seg_rows), np.array(weight_list), np.array(line_rows)


def _segment_residuals_small(seg: FloatArray, px: float, py: float, pw: float) -> FloatArray:
    """:func:`segment_residuals_px` on Python floats, operation for operation (the same
    bits), for a few segments."""
    out = []
    for x1, y1, x2, y2 in seg.tolist():
        mx, my = (x1 + x2) / 2.0, (y1 + y2) / 2.0
        la, lb = my * pw - py, px - mx * pw
        lc = mx * py - my * px
        norm = math.sqrt(la * la + lb * lb)
        if norm < 1e-300:  # np.where(norm < 1e-300, 1e-300, norm): NaN kept
            norm = 1e-300
        out.append((la * x1 + lb * y1 + lc) / norm)
    return np.array(out)


def _linear_estimate(weighted_lines: FloatArray, name: str) -> FloatArray:
    """Smallest right singular vector of the ``(n, 3)`` weighted line matrix.

    (An eigen-decomposition of the 3x3 normal matrix is cheaper, but its different rounding
    moves the Gauss-Newton start and so the loosely converged answer by up to 1e-8.)

    Raises
    ------
    DegenerateGeometryError
        When the second singular value is below 1e-9 of the first (all lines one line).
    """
    # Only the right singular vectors are used: the reduced form keeps U at (n, 3) instead of
    # (n, n), which grew with the square of the line count (23 GB for a 200-annotator scene).
    # Two segments still need the full form, whose third row of vt is the null vector.
    _u, s, vt = np.linalg.svd(weighted_lines, full_matrices=weighted_lines.shape[0] < 3)
    # s[1], not s[-2]: with two segments there are only two singular values.
    if s[1] < 1e-9 * max(s[0], 1e-300):
        raise DegenerateGeometryError(
            f"{name}: all segments lie on one line, so they do not define a vanishing point"
        )
    return np.asarray(vt[-1], dtype=np.float64)


_FD_STEP = 1e-7  # forward-difference step of the Jacobian, radians
# Up to this many segments the sphere refinement evaluates its residuals on Python floats
# (the same bits as numpy's, see _refine_on_sphere; cheaper up to ~20 segments, measured).
_PYTHON_REFINE_MAX = 20


def _refine_on_sphere(
    seg_c: FloatArray, weights: FloatArray, theta0: float, phi0: float
) -> tuple[float, float]:
    """Damped Gauss-Newton on (theta, phi) of the weighted, conditioned segment residuals.

    Two parameters; the residuals and the forward-difference Jacobian come from one
    evaluation at three points, built from Python floats rather than stacked arrays, one
    evaluation an iteration (the trial point's with its neighbours).
    """
    sx, sy = seg_c[:, 0], seg_c[:, 1]
    mx_c = (seg_c[:, 0] + seg_c[:, 2]) / 2.0
    my_c = (seg_c[:, 1] + seg_c[:, 3]) / 2.0
    h = _FD_STEP

    def fun_many_numpy(points: list[tuple[float, float]]) -> FloatArray:
        # segment_residuals_px of the conditioned segments to the unit points (theta, phi),
        # all at once: (P, n).
        unit_pts = np.array(
            [[math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)] for t, p in points]
        )
        px, py, pw = unit_pts[:, 0:1], unit_pts[:, 1:2], unit_pts[:, 2:3]
        la, lb = my_c * pw - py, px - mx_c * pw
        lc = mx_c * py - my_c * px
        norm = np.maximum(np.sqrt(la * la + lb * lb), 1e-300)
        return np.asarray((la * sx + lb * sy + lc) / norm * weights)

    def fun_many_python(points: list[tuple[float, float]]) -> FloatArray:
        # The same residuals from Python floats: every product, sum, quotient and square
        # root is the same correctly rounded IEEE operation as numpy's element-wise one (no
        # fused multiply-add in either), so the bits are the same; on a few segments the
        # ~14 ufunc calls of an evaluation cost more than the arithmetic.
        out = []
        for t, p in points:
            qx, qy, qw = math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)
            row = []
            for ax, ay, mx, my, w in rows_c:
                la, lb = my * qw - qy, qx - mx * qw
                norm = math.sqrt(la * la + lb * lb)
                if not norm >= 1e-300:  # np.maximum(norm, 1e-300), NaN kept
                    norm = norm if norm != norm else 1e-300
                row.append((la * ax + lb * ay + (mx * qy - my * qx)) / norm * w)
            out.append(row)
        return np.array(out)

    if len(seg_c) <= _PYTHON_REFINE_MAX:
        rows_c = list(
            zip(
                sx.tolist(),
                sy.tolist(),
                mx_c.tolist(),
                my_c.tolist(),
                np.asarray(weights, dtype=float).tolist(),
                strict=True,
            )
        )
        fun_many = fun_many_python
    else:
        fun_many = fun_many_numpy

    # Every evaluation is at a point and its two forward-difference neighbours: a trial step
    # that is taken then already has the next iteration's Jacobian rows (the same floats as
    # evaluating them afterwards), and a refused one leaves the Jacobian as it was, so each
    # iteration costs one call instead of two, with the same answer bit for bit.
    th, ph = theta0, phi0
    F = fun_many([(th, ph), (th + h, ph), (th, ph + h)])
    r = F[0]
    cost = float(r @ r)
    lam = 1e-6
    normal: tuple[float, float, float, float, FloatArray] | None = None
    for _ in range(10):
        if normal is None:
            J = (F[1:] - F[0]) / h  # (2, n): the Jacobian, transposed
            JtJ = J @ J.T
            normal = (
                float(JtJ[0, 0]),
                float(JtJ[0, 1]),
                float(JtJ[1, 0]),
                float(JtJ[1, 1]),
                J @ r,
            )
        a, b, b10, c, Jr = normal
        # JtJ + lam diag(diag(JtJ) + 1e-12), built from floats with the same roundings.
        A = np.array([[a + lam * (a + 1e-12), b], [b10, c + lam * (c + 1e-12)]])
        try:
            # np.linalg.solve, not Cramer's rule: its rounding is what the answers were
            # frozen with (the stopping rule leaves them converged only to ~1e-8).
            dth, dph = (-np.linalg.solve(A, Jr)).tolist()
        except np.linalg.LinAlgError:
            break
        th_new, ph_new = th + dth, ph + dph
        F_new = fun_many([(th_new, ph_new), (th_new + h, ph_new), (th_new, ph_new + h)])
        r_new = F_new[0]
        cost_new = float(r_new @ r_new)
        step = max(abs(dth), abs(dph))
        if cost_new < cost:
            th, ph, r, F, normal = th_new, ph_new, r_new, F_new, None
            done = cost - cost_new <= 1e-12 * cost or step < 1e-10
            cost, lam = cost_new, lam * 0.3
            if done:
                break
        else:
            # No decrease: at the minimum to rounding when even this step is tiny.
            if step < 1e-10:
                break
            lam *= 10.0
            if lam > 1e6:
                break
    return th, ph


def principal_point_from_orthocentre(
    v1: npt.ArrayLike, v2: npt.ArrayLike, v3: npt.ArrayLike
) -> FloatArray:
    """Orthocentre of the triangle of three finite orthogonal vanishing points (pixels).

    Raises
    ------
    DegenerateGeometryError
        When the three points are (nearly) collinear.
    """
    a, b, c = (np.asarray(v, dtype=float).reshape(2) for v in (v1, v2, v3))
    # (H - a)·(b - c) = 0 and (H - b)·(a - c) = 0
    A = np.array([b - c, a - c])
    rhs = np.array([a @ (b - c), b @ (a - c)])
    det = float(np.linalg.det(A))
    if abs(det) < 1e-12 * max(float(np.linalg.norm(A)) ** 2, 1e-300):
        raise DegenerateGeometryError("the three vanishing points are collinear")
    return np.asarray(np.linalg.solve(A, rhs), dtype=np.float64)


def focal_from_vanishing_pair(
    v1_h: npt.ArrayLike, v2_h: npt.ArrayLike, principal_point: npt.ArrayLike
) -> float:
    """Focal length (pixels) from two orthogonal vanishing points and the principal point.

    With ``v = (x, y, w)`` and ``p = (cx, cy)``:
    ``(x1 - cx w1)(x2 - cx w2) + (y1 - cy w1)(y2 - cy w2) + f² w1 w2 = 0``.

    Raises
    ------
    DegenerateGeometryError
        If a point is at infinity (f is then not determined by this pair) or the points are
        inconsistent with orthogonal directions (f² ≤ 0).
    """
    a = np.asarray(v1_h, dtype=float).reshape(3)
    b = np.asarray(v2_h, dtype=float).reshape(3)
    cx, cy = np.asarray(principal_point, dtype=float).reshape(2)
    a = a / _vector_norm(a)
    b = b / _vector_norm(b)
    ww = a[2] * b[2]
    dot = (a[0] - cx * a[2]) * (b[0] - cx * b[2]) + (a[1] - cy * a[2]) * (b[1] - cy * b[2])
    scale = math.sqrt(
        ((a[0] - cx * a[2]) ** 2 + (a[1] - cy * a[2]) ** 2)
        * ((b[0] - cx * b[2]) ** 2 + (b[1] - cy * b[2]) ** 2)
    )
    if abs(ww) < 1e-12 * max(scale, 1e-300):
        raise DegenerateGeometryError(
            "a vanishing point is at infinity: this pair does not determine the focal length"
        )
    f2 = -dot / ww
    if not f2 > 0:
        raise DegenerateGeometryError(
            "the vanishing points are not consistent with orthogonal directions (f² ≤ 0): "
            "they lie on the same side of the principal point"
        )
    return math.sqrt(f2)


@dataclass(frozen=True)
class IntrinsicsEstimate:
    """Focal length and principal point with the method that gave them and why."""

    focal_px: float
    principal_point: tuple[float, float]
    method: str
    reason: str


def estimate_intrinsics(
    vps_h: Mapping[str, npt.ArrayLike | None],
    image_size: tuple[float, float],
    *,
    focal_px: float | None = None,
    principal_point: tuple[float, float] | None = None,
    max_pp_offset: float = 0.25,
) -> IntrinsicsEstimate:
    """Intrinsics from up to three orthogonal vanishing points, with documented fallbacks.

    In order:

    1. ``given``: focal length and principal point both given.
    2. ``orthocentre``: three finite vanishing points; the principal point is their
       orthocentre, accepted when it lies within ``max_pp_offset`` image diagonals of the
       image centre and gives a real focal length.
    3. ``two_vp``: the principal point is the given one or the image centre, and the focal
       length comes from the best-conditioned pair of finite vanishing points (the pair
       whose points are farthest apart relative to the image).
    4. ``given_focal``: focal length given, principal point given or the image centre.

    Parameters
    ----------
    vps_h
        Homogeneous vanishing points by axis name; None or missing for an unknown axis.
    image_size
        ``(width, height)`` pixels.
    focal_px, principal_point
        Known values; each optional.
    max_pp_offset
        Largest accepted distance of an orthocentre from the image centre, in image diagonals.

    Raises
    ------
    DegenerateGeometryError
        When no method applies (for example two vanishing points at infinity and no focal
        length given).
    """
    width, height = image_size
    centre = np.array([width / 2.0, height / 2.0])
    diag = math.hypot(width, height)
    pp = np.asarray(principal_point, dtype=float) if principal_point is not None else None
    if focal_px is not None and pp is not None:
        return IntrinsicsEstimate(float(focal_px), (pp[0], pp[1]), "given", "scene gives both")

    vps = {k: np.asarray(v, dtype=float) for k, v in vps_h.items() if v is not None}
    finite = {k: v for k, v in vps.items() if _is_finite(v / _vector_norm(v), diag)}
    why = ""
    if focal_px is None and pp is None and len(finite) == 3:
        px = [finite[k][:2] / finite[k][2] for k in AXES]
        try:
            ortho = principal_point_from_orthocentre(*px)
            f = focal_from_vanishing_pair(finite["length"], finite["width"], ortho)
            if _vector_norm(ortho - centre) <= max_pp_offset * diag:
                return IntrinsicsEstimate(
                    f,
                    (float(ortho[0]), float(ortho[1])),
                    "orthocentre",
                    "three finite vanishing points; principal point = their orthocentre",
                )
            why = (
                f"orthocentre {np.round(ortho, 1).tolist()} is more than {max_pp_offset} "
                "diagonals from the image centre; "
            )
        except DegenerateGeometryError as exc:
            why = f"orthocentre rejected ({exc}); "
    pp_used = pp if pp is not None else centre
    pp_word = "given principal point" if pp is not None else "principal point at the image centre"
    if focal_px is not None:
        return IntrinsicsEstimate(
            float(focal_px),
            (float(pp_used[0]), float(pp_used[1])),
            "given_focal",
            f"{why}focal length given; {pp_word}",
        )
    best: tuple[float, float, str] | None = None
    names = sorted(finite)
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            a, b = finite[names[i]], finite[names[j]]
            try:
                f = focal_from_vanishing_pair(a, b, pp_used)
            except DegenerateGeometryError:
                continue
            # Conditioning: a pair whose points are both far out gives an unstable f.
            da = _vector_norm(a[:2] / a[2] - pp_used)
            db = _vector_norm(b[:2] / b[2] - pp_used)
            quality = -float(max(da, db)) / diag
            if best is None or quality > best[0]:
                best = (quality, f, f"{names[i]}+{names[j]}")
    if best is not None:
        return IntrinsicsEstimate(
            best[1],
            (float(pp_used[0]), float(pp_used[1])),
            "two_vp",
            f"{why}focal length from the {best[2]} vanishing points; {pp_word}",
        )
    at_infinity = sorted(set(vps) - set(finite))
    if at_infinity:
        why += f"the {' and '.join(at_infinity)} lines are parallel in the image; "
    raise DegenerateGeometryError(
        f"{why}cannot estimate the focal length: fewer than two finite, mutually consistent "
        "vanishing points; give camera.focal_px in the scene"
    )


def direction_sign(
    direction_in_cam: npt.ArrayLike,
    origin_ray_in_cam: npt.ArrayLike,
    image_step: npt.ArrayLike,
) -> float:
    """Sign (+1 or -1) that makes a 3-D direction move the origin's image toward a step.

    Moving a point at depth ``z`` along ``d`` moves its normalised image point in the
    direction ``d_xy - m_xy d_z`` (``m`` the point's ray with ``m_z = 1``), whatever ``z``.
    Returns the sign of its dot product with the annotated image step (normalised
    coordinates), or 0.0 when the two are (nearly) perpendicular: the sign is then ambiguous.
    """
    d = np.asarray(direction_in_cam, dtype=float).reshape(3)
    m = np.asarray(origin_ray_in_cam, dtype=float).reshape(3)
    m = m / m[2]
    step = np.asarray(image_step, dtype=float).reshape(2)
    g = d[:2] - m[:2] * d[2]
    dot = float(g @ step)
    # np.linalg.norm of a vector is sqrt(x.dot(x)): the same, without its dispatch.
    denom = float(np.sqrt(g.dot(g)) * np.sqrt(step.dot(step)))
    if denom <= 0 or abs(dot) < 0.05 * denom:
        return 0.0
    return 1.0 if dot > 0 else -1.0


def rotation_from_vanishing_directions(
    directions_in_cam: Mapping[str, npt.ArrayLike],
    weights: Mapping[str, float] | None = None,
) -> FloatArray:
    """Proper rotation whose columns best match sign-fixed axis directions.

    Parameters
    ----------
    directions_in_cam
        Unit directions of the world x (``length``), y (``width``) and z (``height``) axes in
        the camera frame, signs already fixed; at least two of them.
    weights
        Optional confidence per axis.

    Returns
    -------
    ``cam_from_world`` rotation: the weighted orthogonal Procrustes solution (SVD, det = +1).
    A missing third axis is completed by the right-handed cross product.
    """
    cols = {"length": 0, "width": 1, "height": 2}
    dirs = {k: np.asarray(v, dtype=float) / _vector_norm(v) for k, v in directions_in_cam.items()}
    if len(dirs) < 2:
        raise DegenerateGeometryError("at least two axis directions are needed for a rotation")
    w = dict(weights or {})
    M = np.zeros((3, 3))
    for k, d in dirs.items():
        M += w.get(k, 1.0) * np.outer(d, np.eye(3)[cols[k]])
    if len(dirs) == 2:
        (k1, d1), (k2, d2) = sorted(dirs.items(), key=lambda kv: cols[kv[0]])
        i1, i2 = cols[k1], cols[k2]
        third = ({0, 1, 2} - {i1, i2}).pop()
        # e_third = e_i1 × e_i2 up to the cyclic sign.
        sign = 1.0 if (i1, i2, third) in ((0, 1, 2), (1, 2, 0), (2, 0, 1)) else -1.0
        d3 = sign * np.cross(d1, d2)
        M += np.outer(d3 / _vector_norm(d3), np.eye(3)[third])
    return project_to_rotation(M)
