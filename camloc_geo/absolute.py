"""Absolute localisation: where the camera stands on the map, as ranked candidates.

The relative pose (:mod:`camloc_geo.relative`) puts the camera in the car's world frame.
What remains is the 2-D similarity that carries the world frame onto a local east/north
frame (:class:`~camloc_geo.geodesy.LocalFrame`, pyproj): a rotation about the vertical, a
translation and a scale close to 1 (the car's true size is known only to about 5 %):

    p_enu = s · Rz(θ) · p_world + T

Hypotheses for (θ, T, s) come from generators, one per kind of evidence, each a ``method``:

``two_references``
    Two or more ground pixels with known lat/lon: a weighted similarity fit (scale
    regularised towards 1). With a right-handed world frame the fit is unique: the paper
    needed the left/right order of the pixels to choose between two circle intersections
    because its distance-only construction loses the handedness that the frame keeps.
    With three or more points the one that agrees least with the others (leave-one-out)
    is flagged, and the fit without it is a second hypothesis.
``one_reference``
    One known ground pixel plus a street bearing (from the scene, else the streets that
    pass near the reference in the map): the car's length axis is parallel to the street,
    in one of its two directions, so two candidates per street direction. The paper counted
    four because it did not know on which side of the length axis the width edge lies; the
    annotated width end (the sign of y in the right-handed world frame) fixes it.
``corners``
    One to four visible kerb corners, clockwise on screen, matched to the map's corners of
    the intersection, clockwise from above (on the ground, below the horizon, the two orders
    agree). Every cyclic assignment of the visible corners to consecutive map corners (and,
    at a lower prior, to order-preserving non-consecutive ones) is fitted. One visible corner
    falls back to the intersection's street bearings (the paper's 16 candidates at a 4-way
    junction).
``landmark``
    A named building's corners or face midpoints, as map points for the annotated pixels;
    one landmark pixel uses the street bearings like ``one_reference``.

Every hypothesis is then scored against *all* the scene's evidence under a Gaussian noise
model (:class:`LocateSettings`): the ground position of a pixel is uncertain through the
click noise (propagated through the pixel-to-ground Jacobian) and the relative scale error,
and a map point is uncertain by ``sigma_*_m``. The likelihood is multiplied by map
plausibility factors: the camera is not deep inside a building, the corners it sees are not
hidden behind buildings, it lies within the prior's radius, the car's length axis is
parallel to a nearby street. Scores are normalised to sum to 1; candidates closer than
``merge_distance_m`` with similar headings are merged. The leading candidates are refined
by one nonlinear least-squares fit of the whole pose (focal length, rotation, camera centre,
car-to-map similarity) to all annotations and matched map features together, which also
gives a position uncertainty in metres.
"""

from __future__ import annotations

import itertools
import logging
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from camloc_geo._errors import MapDataError, SceneError
from camloc_geo.camera import Camera
from camloc_geo.geodesy import LocalFrame, normalize_bearing_deg
from camloc_geo.relative import CalibrationResult, CalibrationSettings, calibrate
from camloc_geo.scene import Scene

if TYPE_CHECKING:
    from camloc_geo.osm import Intersection, MapData

__all__ = [
    "Candidate",
    "LocateResult",
    "LocateSettings",
    "Observation",
    "candidates_geojson",
    "locate",
]

log = logging.getLogger(__name__)
FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class LocateSettings:
    """Noise model and ranking knobs of :func:`locate` (defaults are what the benchmark runs).

    Attributes
    ----------
    sigma_pixel_rel
        Click noise of a ground pixel, fraction of the image diagonal (0.15 %: 3.3 px at 1080p).
    scale_sigma_rel
        Relative error of the world frame's scale (the car's true size vs its preset).
    sigma_reference_m, sigma_corner_m, sigma_landmark_corner_m, sigma_face_midpoint_m
        Map-side uncertainty of each kind of point, metres (kerb corners modelled from
        centre lines and widths are off by a metre or two).
    non_consecutive_prior
        Prior weight of assigning visible corners to non-consecutive map corners.
    merge_distance_m, merge_heading_deg
        Candidates closer than this (and with headings this close) are merged.
    max_candidates
        At most this many candidates are returned (the rest's score is dropped, the
        remaining scores renormalised).
    refine_top
        How many leading candidates get the full nonlinear refinement.
    bearing_sigma_deg
        Spread of the car's heading around a street's bearing (the car-parallel-to-street
        prior); ``parallel_floor`` is the prior weight of a car not parallel to any street.
    fit_gate
        A candidate whose matched points' mean squared Mahalanobis misfit exceeds this is
        flagged ``poor_fit``; when every candidate is, none is returned (the evidence fits
        no hypothesis). 16: four standard deviations RMS (the noise model is generous: on
        the benchmark the right candidate's mean stays below 10).
    prior_gate_radii
        Hypotheses farther than this many ``prior.radius_m`` from the prior are dropped;
        when all are, none is returned (the evidence contradicts the prior).
    """

    sigma_pixel_rel: float = 0.0015
    scale_sigma_rel: float = 0.05
    sigma_reference_m: float = 1.0
    sigma_corner_m: float = 1.5
    sigma_landmark_corner_m: float = 2.0
    sigma_face_midpoint_m: float = 4.0
    non_consecutive_prior: float = 0.25
    merge_distance_m: float = 2.0
    merge_heading_deg: float = 15.0
    max_candidates: int = 32
    refine_top: int = 3
    bearing_sigma_deg: float = 10.0
    parallel_floor: float = 0.15
    inside_building_factor: float = 0.15
    occluded_corner_factor: float = 0.5
    street_search_m: float = 25.0
    view_cone_range_m: float = 60.0
    fit_gate: float = 16.0
    prior_gate_radii: float = 3.0


@dataclass(frozen=True)
class Observation:
    """A ground pixel with its possible map positions.

    Attributes
    ----------
    kind
        ``reference``, ``corner`` or ``landmark``.
    label
        Where it came from in the scene (``references[0]``, ``intersection.corners[1]``...).
    pixel
        Image pixel.
    world_xy
        Its ground position in the world frame (from the relative pose).
    cov_world
        2×2 covariance of ``world_xy`` from click noise and scale error, m².
    sigma_map_m
        Map-side uncertainty, metres.
    """

    kind: str
    label: str
    pixel: tuple[float, float]
    world_xy: FloatArray
    cov_world: FloatArray
    sigma_map_m: float


@dataclass
class Candidate:
    """One candidate camera position."""

    method: str
    theta_rad: float
    translation_en: FloatArray
    scale: float
    camera: Camera  # pose in the local ENU frame (x east, y north, z up)
    lat: float = math.nan
    lon: float = math.nan
    log_likelihood: float = 0.0
    prior: float = 1.0
    score: float = 0.0
    rank: int = 0
    residual_m: float = math.nan
    sigma_m: float | None = None
    matches: list[dict[str, Any]] = field(default_factory=list)
    flags: list[str] = field(default_factory=list)
    refined: bool = False
    merged: int = 1
    corner_assignment: tuple[int, ...] | None = None  # map corner per visible corner, -1 = none

    @property
    def east_north(self) -> FloatArray:
        """Camera position in the local frame, metres."""
        return np.asarray(self.camera.center_in_world[:2], dtype=np.float64)

    @property
    def heading_deg(self) -> float:
        """Camera heading, degrees clockwise from north (grid north of the local frame)."""
        return self.camera.angles_deg[0]


@dataclass
class LocateResult:
    """Candidates, best first, and how they were found."""

    candidates: list[Candidate]
    frame: LocalFrame
    calibration: CalibrationResult
    methods_tried: list[str]
    reason: str | None = None
    intersection: Intersection | None = None
    observations: list[Observation] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    scene_id: str = "scene"
    image_size: tuple[int, int] = (0, 0)


# ----------------------------------------------------------------------- small geometry
def _rot2(theta: float) -> FloatArray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def _theta_for_bearing(bearing_deg: float) -> float:
    """Rotation carrying the world x axis onto a bearing (clockwise from north)."""
    return math.radians(90.0 - bearing_deg)


def _similarity_fit(
    world: FloatArray, enu: FloatArray, weights: FloatArray, scale_sigma: float
) -> tuple[float, FloatArray, float]:
    """Weighted 2-D similarity (θ, T, s) with s regularised towards 1.

    Closed-form weighted Procrustes gives the rigid solution; the scale is the
    precision-weighted combination of the data's scale and the prior s = 1.
    """
    w = weights / weights.sum()
    mw = (w[:, None] * world).sum(axis=0)
    me = (w[:, None] * enu).sum(axis=0)
    a = world - mw
    b = enu - me
    sxx = float((w * (a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1])).sum())
    sxy = float((w * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])).sum())
    theta = math.atan2(sxy, sxx)
    var_a = float((w * (a**2).sum(axis=1)).sum())
    if var_a > 1e-12 and scale_sigma > 0:
        s_data = math.hypot(sxx, sxy) / var_a
        # Information of the data about s: sum(weights * |a|^2) in units of the weights.
        info = float((weights * (a**2).sum(axis=1)).sum())
        prior_info = 1.0 / scale_sigma**2
        s = (info * s_data + prior_info * 1.0) / (info + prior_info)
    else:
        s = 1.0
    T = me - s * _rot2(theta) @ mw
    return theta, T, s


def _camera_in_enu(world_cam: Camera, theta: float, T: FloatArray, s: float) -> Camera:
    Rz = np.eye(3)
    Rz[:2, :2] = _rot2(theta)
    R = world_cam.cam_from_world_rotation @ Rz.T
    C = s * Rz @ world_cam.center_in_world + np.array([T[0], T[1], 0.0])
    return Camera.from_center(world_cam.focal_px, world_cam.principal_point, R, C)


# ------------------------------------------------------------------------ observations
def _ground_observation(
    camera: Camera,
    pixel: Sequence[float],
    kind: str,
    label: str,
    sigma_map: float,
    settings: LocateSettings,
    diag: float,
) -> Observation:
    px = np.asarray(pixel, dtype=float)
    g = camera.ground_from_pixels(px)
    if not np.all(np.isfinite(g)):
        raise SceneError(
            f"pixel {px.tolist()} is at or above the horizon of the calibrated camera, so it "
            "cannot be a ground point",
            label,
        )
    # Jacobian of the ground point w.r.t. the pixel (central differences).
    J = np.empty((2, 2))
    for j in range(2):
        d = np.zeros(2)
        d[j] = 0.5
        gp = camera.ground_from_pixels(px + d)
        gm = camera.ground_from_pixels(px - d)
        J[:, j] = (gp[:2] - gm[:2]) / 1.0
    sig_px = settings.sigma_pixel_rel * diag
    cov = sig_px**2 * (J @ J.T)
    foot = camera.center_in_world[:2]
    rng = float(np.linalg.norm(g[:2] - foot)) + float(np.linalg.norm(foot))
    cov = cov + (settings.scale_sigma_rel * 0.5 * rng) ** 2 * np.eye(2)
    if not np.all(np.isfinite(cov)):
        cov = np.eye(2) * 1e6
    return Observation(kind, label, (float(px[0]), float(px[1])), g[:2].copy(), cov, sigma_map)


def _obs_precision(obs: Observation, R2: FloatArray, s: float) -> FloatArray:
    cov = (s**2) * (R2 @ obs.cov_world @ R2.T) + obs.sigma_map_m**2 * np.eye(2)
    return np.asarray(np.linalg.inv(cov), dtype=np.float64)


# ---------------------------------------------------------------------------- evidence
@dataclass
class _Evidence:
    """Everything a hypothesis is scored against, in the local frame."""

    refs: list[tuple[Observation, FloatArray]]
    corners: list[Observation]
    map_corners: FloatArray  # (n, 2) ENU, clockwise
    map_corner_ids: list[str]
    landmarks: list[tuple[Observation, FloatArray]]  # (obs, candidate map points (k, 2))
    street_bearings: list[float]
    buildings_enu: list[Any]
    prior_en: FloatArray | None
    prior_radius_m: float | None
    streets_enu: list[tuple[Any, float]] = field(default_factory=list)
    buildings_tree: Any = None
    street_tree: Any = None
    car_center_world: FloatArray = field(default_factory=lambda: np.zeros(2))
    worst_reference: str | None = None


# A matched point's squared Mahalanobis misfit counts up to this much (a robust likelihood).
_OUTLIER_M2 = 50.0


def _mahal(obs: Observation, q: FloatArray, theta: float, T: FloatArray, s: float) -> float:
    R2 = _rot2(theta)
    p = s * R2 @ obs.world_xy + T
    r = p - q
    return float(r @ _obs_precision(obs, R2, s) @ r)


def _score(
    theta: float,
    T: FloatArray,
    s: float,
    ev: _Evidence,
    settings: LocateSettings,
    corner_assignment: Sequence[int] | None,
) -> tuple[float, float, list[dict[str, Any]], list[float], tuple[int, ...] | None]:
    """Log-likelihood, RMS misfit (m), the matches, squared distances, corner assignment.

    ``-1`` in a corner assignment leaves that image corner unmatched.
    """
    ll = 0.0
    sq: list[float] = []
    matches: list[dict[str, Any]] = []
    R2 = _rot2(theta)
    for obs, q in ev.refs:
        m2 = _mahal(obs, q, theta, T, s)
        ll -= 0.5 * min(m2, _OUTLIER_M2)  # robust: one outlier costs at most 25
        d = s * R2 @ obs.world_xy + T - q
        sq.append(float(d @ d))
        matches.append(
            {
                "kind": "reference",
                "label": obs.label,
                "pixel": list(obs.pixel),
                "map_en": q.tolist(),
                "misfit_m": float(np.linalg.norm(d)),
                "mahalanobis2": float(m2),
            }
        )
    if ev.corners and len(ev.map_corners):
        if corner_assignment is None:
            corner_assignment = _best_assignment(theta, T, s, ev)
        for obs, j in zip(ev.corners, corner_assignment, strict=True):
            if j < 0:
                # A visible corner the map's junction has no counterpart for (more corners
                # listed than modelled): it costs what an outlier costs.
                ll -= 0.5 * _OUTLIER_M2
                continue
            q = ev.map_corners[j]
            m2 = _mahal(obs, q, theta, T, s)
            ll -= 0.5 * min(m2, _OUTLIER_M2)
            d = s * R2 @ obs.world_xy + T - q
            sq.append(float(d @ d))
            matches.append(
                {
                    "kind": "corner",
                    "label": obs.label,
                    "pixel": list(obs.pixel),
                    "map_en": q.tolist(),
                    "map_corner": ev.map_corner_ids[j],
                    "order": int(j),
                    "misfit_m": float(np.linalg.norm(d)),
                    "mahalanobis2": float(m2),
                }
            )
    for obs, pts in ev.landmarks:
        m2s = [_mahal(obs, q, theta, T, s) for q in pts]
        k = int(np.argmin(m2s))
        ll -= 0.5 * min(m2s[k], _OUTLIER_M2)
        d = s * R2 @ obs.world_xy + T - pts[k]
        sq.append(float(d @ d))
        matches.append(
            {
                "kind": "landmark",
                "label": obs.label,
                "pixel": list(obs.pixel),
                "map_en": pts[k].tolist(),
                "misfit_m": float(np.linalg.norm(d)),
                "mahalanobis2": float(m2s[k]),
            }
        )
    ll -= 0.5 * ((s - 1.0) / max(settings.scale_sigma_rel, 1e-6)) ** 2
    rms = math.sqrt(sum(sq) / len(sq)) if sq else math.nan
    assignment = tuple(int(j) for j in corner_assignment) if corner_assignment is not None else None
    return ll, rms, matches, sq, assignment


def _unmatched_flags(ev: _Evidence, assignment: tuple[int, ...] | None) -> list[str]:
    """``unmatched:<label>`` for visible corners a hypothesis leaves without a map corner."""
    if assignment is None:
        return []
    return [f"unmatched:{o.label}" for o, j in zip(ev.corners, assignment, strict=True) if j < 0]


def _best_assignment(theta: float, T: FloatArray, s: float, ev: _Evidence) -> list[int]:
    """The cyclic, order-preserving assignment of image corners to map corners that fits best."""
    best: tuple[float, list[int]] | None = None
    for assign, _prior in _assignments(len(ev.corners), len(ev.map_corners)):
        cost = sum(
            _mahal(o, ev.map_corners[j], theta, T, s) if j >= 0 else _OUTLIER_M2
            for o, j in zip(ev.corners, assign, strict=True)
        )
        if best is None or cost < best[0]:
            best = (cost, list(assign))
    assert best is not None
    return best[1]


def _assignments(k: int, n: int) -> Iterable[tuple[tuple[int, ...], float]]:
    """Order-preserving cyclic assignments of k visible corners to n map corners, with priors.

    Consecutive runs (the usual case) get prior 1; other order-preserving choices (a corner
    hidden or missing in between, or, with more visible corners than map corners, image
    corners left unmatched as ``-1``) get :attr:`LocateSettings.non_consecutive_prior`,
    applied by the caller through the returned flag value 0.
    """
    if k == 0 or n == 0:
        return
    if k > n:
        # More visible corners than the map models: leave k - n of them unmatched (-1),
        # the rest in order on every cyclic run of the map's corners.
        for keep in itertools.combinations(range(k), n):
            for start in range(n):
                assign = [-1] * k
                for step, i in enumerate(keep):
                    assign[i] = (start + step) % n
                yield tuple(assign), 0.0
        return
    seen = set()
    for start in range(n):
        run = tuple((start + i) % n for i in range(k))
        seen.add(run)
        yield run, 1.0
    if k >= 2 and k < n:
        for combo in itertools.combinations(range(n), k):
            for rot in range(k):
                cyc = combo[rot:] + combo[:rot]
                # Keep only cyclically increasing sequences (clockwise order preserved).
                steps = [(cyc[(i + 1) % k] - cyc[i]) % n for i in range(k - 1)]
                if sum(steps) >= n or cyc in seen:
                    continue
                seen.add(cyc)
                yield cyc, 0.0


# -------------------------------------------------------------------------- generators
@dataclass
class _Hypothesis:
    method: str
    theta: float
    T: FloatArray
    s: float
    log_prior: float = 0.0
    corner_assignment: tuple[int, ...] | None = None


def _gen_references(ev: _Evidence, settings: LocateSettings) -> list[_Hypothesis]:
    refs = ev.refs
    if len(refs) < 2:
        return []
    world = np.array([o.world_xy for o, _ in refs])
    enu = np.array([q for _, q in refs])
    wts = np.array([1.0 / (np.trace(o.cov_world) / 2 + o.sigma_map_m**2) for o, _ in refs])
    theta, T, s = _similarity_fit(world, enu, wts, settings.scale_sigma_rel)
    out = [_Hypothesis("two_references", theta, T, s)]
    if ev.worst_reference is not None:
        # The robust alternative: the fit of the others, the worst one an outlier.
        keep = [i for i, (o, _) in enumerate(refs) if o.label != ev.worst_reference]
        theta, T, s = _similarity_fit(world[keep], enu[keep], wts[keep], settings.scale_sigma_rel)
        out.append(_Hypothesis("two_references", theta, T, s))
    return out


def _worst_reference(
    refs: list[tuple[Observation, FloatArray]], settings: LocateSettings
) -> tuple[str, float] | None:
    """The reference that disagrees most with the others, and its misfit to their fit (m).

    The largest residual of the joint fit is a poor guide with few points (the fit leans
    towards the wrong one and spreads its error): leave each reference out in turn, fit the
    others, and name the one whose removal leaves the most consistent set.
    """
    if len(refs) < 3:
        return None
    world = np.array([o.world_xy for o, _ in refs])
    enu = np.array([q for _, q in refs])
    wts = np.array([1.0 / (np.trace(o.cov_world) / 2 + o.sigma_map_m**2) for o, _ in refs])
    best: tuple[float, str, float] | None = None
    for i in range(len(refs)):
        keep = [j for j in range(len(refs)) if j != i]
        theta, T, s = _similarity_fit(world[keep], enu[keep], wts[keep], settings.scale_sigma_rel)
        cost = sum(_mahal(refs[j][0], refs[j][1], theta, T, s) for j in keep)
        cost += ((s - 1.0) / max(settings.scale_sigma_rel, 1e-6)) ** 2
        miss = float(np.linalg.norm(s * _rot2(theta) @ world[i] + T - enu[i]))
        if best is None or cost < best[0]:
            best = (cost, refs[i][0].label, miss)
    assert best is not None
    return best[1], best[2]


def _gen_bearing_point(
    method: str, obs: Observation, points: FloatArray, bearings: Sequence[float]
) -> list[_Hypothesis]:
    out = []
    for q in points:
        for b in bearings:
            for flip in (0.0, 180.0):
                theta = _theta_for_bearing(b + flip)
                T = q - _rot2(theta) @ obs.world_xy
                out.append(_Hypothesis(method, theta, T, 1.0))
    return out


def _unique_bearings(bearings: Iterable[float]) -> list[float]:
    out: list[float] = []
    for b in bearings:
        b = float(b) % 180.0
        if all(min(abs(b - c), 180.0 - abs(b - c)) > 5.0 for c in out):
            out.append(b)
    return out


def _gen_corners(ev: _Evidence, settings: LocateSettings) -> list[_Hypothesis]:
    k, n = len(ev.corners), len(ev.map_corners)
    if k == 0 or n == 0:
        return []
    if k == 1:
        return _gen_bearing_point("corners", ev.corners[0], ev.map_corners, ev.street_bearings)
    if n == 1:
        # One modelled corner, several visible: each visible one in turn is that corner.
        out_one = []
        for ci in range(k):
            assign = tuple(0 if i == ci else -1 for i in range(k))
            for h in _gen_bearing_point(
                "corners", ev.corners[ci], ev.map_corners, ev.street_bearings
            ):
                out_one.append(replace(h, corner_assignment=assign))
        return out_one
    out = []
    world = np.array([o.world_xy for o in ev.corners])
    wts = np.array([1.0 / (np.trace(o.cov_world) / 2 + o.sigma_map_m**2) for o in ev.corners])
    for assign, consecutive in _assignments(k, n):
        used = [i for i, j in enumerate(assign) if j >= 0]
        if len(used) < 2:
            continue
        enu = ev.map_corners[[assign[i] for i in used]]
        theta, T, s = _similarity_fit(world[used], enu, wts[used], settings.scale_sigma_rel)
        lp = 0.0 if consecutive else math.log(settings.non_consecutive_prior)
        out.append(_Hypothesis("corners", theta, T, s, lp, tuple(assign)))
    return out


def _gen_landmarks(ev: _Evidence, settings: LocateSettings) -> list[_Hypothesis]:
    lms = ev.landmarks
    if not lms:
        return []
    if len(lms) == 1:
        obs, pts = lms[0]
        return _gen_bearing_point("landmark", obs, pts, ev.street_bearings)
    out = []
    world = np.array([o.world_xy for o, _ in lms])
    wts = np.array([1.0 / (np.trace(o.cov_world) / 2 + o.sigma_map_m**2) for o, _ in lms])
    pools = [range(len(pts)) for _, pts in lms]
    combos = list(itertools.product(*pools))
    if len(combos) > 5000:
        combos = combos[:5000]
    for combo in combos:
        enu = np.array([lms[i][1][j] for i, j in enumerate(combo)])
        if np.ptp(enu, axis=0).max() < 1.0:
            continue
        theta, T, s = _similarity_fit(world, enu, wts, settings.scale_sigma_rel)
        out.append(_Hypothesis("landmark", theta, T, s))
    return out


def _gen_one_reference(ev: _Evidence, street_bearing: float | None) -> list[_Hypothesis]:
    if len(ev.refs) != 1:
        return []
    obs, q = ev.refs[0]
    bearings = [street_bearing] if street_bearing is not None else ev.street_bearings
    return _gen_bearing_point("one_reference", obs, q[None, :], _unique_bearings(bearings))


# ---------------------------------------------------------------------------- priors
def _street_angle_under_car(theta: float, T: FloatArray, s: float, ev: _Evidence) -> float | None:
    """Signed angle (degrees, in [-90, 90)) from the street under the car to the car's axis.

    None when the car (its centre under the similarity) is on no carriageway (farther than
    half the street's width + 2.5 m from every centre line); else the smallest angle among the
    streets it stands on.
    """
    from shapely.geometry import Point, box

    car_bearing = (90.0 - math.degrees(theta)) % 180.0
    car = s * _rot2(theta) @ ev.car_center_world + T
    x, y = float(car[0]), float(car[1])
    pt = Point(x, y)
    best: float | None = None
    # A box, not a buffered disc: the tree only tests envelopes, and buffering is costly.
    for idx in ev.street_tree.query(box(x - 25.0, y - 25.0, x + 25.0, y + 25.0)):
        line, half_w = ev.streets_enu[int(idx)]
        if line.distance(pt) > half_w + 2.5:
            continue
        sproj = line.project(pt)
        a = line.interpolate(max(0.0, sproj - 5.0))
        b = line.interpolate(min(line.length, sproj + 5.0))
        brg = math.degrees(math.atan2(b.x - a.x, b.y - a.y)) % 180.0
        diff = (car_bearing - brg + 90.0) % 180.0 - 90.0
        if best is None or abs(diff) < abs(best):
            best = diff
    return best


def _plausibility(
    cam: Camera,
    theta: float,
    T: FloatArray,
    s: float,
    ev: _Evidence,
    settings: LocateSettings,
    matches: list[dict[str, Any]],
) -> tuple[float, list[str]]:
    factor = 1.0
    flags: list[str] = []
    C = cam.center_in_world
    if ev.buildings_enu and ev.buildings_tree is not None:
        from shapely.geometry import LineString, Point

        pt = Point(float(C[0]), float(C[1]))
        around = [ev.buildings_enu[int(i)] for i in ev.buildings_tree.query(pt)]
        home = [poly for poly in around if poly.contains(pt)]
        if any(poly.exterior.distance(pt) > 2.0 for poly in home):
            factor *= settings.inside_building_factor
            flags.append("inside_building")
        for m in matches:
            if m["kind"] != "corner":
                continue
            line = LineString([(C[0], C[1]), tuple(m["map_en"])])
            for i in ev.buildings_tree.query(line):
                poly = ev.buildings_enu[int(i)]
                if poly in home:
                    continue
                if line.crosses(poly) and line.intersection(poly).length > 1.0:
                    factor *= settings.occluded_corner_factor
                    flags.append(f"occluded:{m['label']}")
                    break
    if ev.prior_en is not None and ev.prior_radius_m:
        # A soft prior: a Gaussian of the listed radius (0.61 at the radius, 0.14 at twice).
        d = float(np.linalg.norm(C[:2] - ev.prior_en))
        factor *= math.exp(-0.5 * (d / ev.prior_radius_m) ** 2)
        if d > ev.prior_radius_m:
            flags.append("outside_prior")
    car_bearing = (90.0 - math.degrees(theta)) % 180.0
    if ev.street_tree is not None:
        # The car stands on a carriageway and is parallel to it (the street under the car).
        signed = _street_angle_under_car(theta, T, s, ev)
        if signed is None:
            factor *= settings.parallel_floor
            flags.append("car_off_street")
        else:
            best_diff = abs(signed)
            par = math.exp(-0.5 * (best_diff / settings.bearing_sigma_deg) ** 2)
            factor *= settings.parallel_floor + (1.0 - settings.parallel_floor) * par
            if best_diff > 2.5 * settings.bearing_sigma_deg:
                flags.append("car_not_parallel_to_street")
    elif ev.street_bearings:
        diff = min(
            min(abs(car_bearing - b), 180.0 - abs(car_bearing - b)) for b in ev.street_bearings
        )
        par = math.exp(-0.5 * (diff / settings.bearing_sigma_deg) ** 2)
        factor *= settings.parallel_floor + (1.0 - settings.parallel_floor) * par
        if diff > 2.5 * settings.bearing_sigma_deg:
            flags.append("car_not_parallel_to_street")
    if ev.worst_reference is not None:
        flags.append(f"worst_reference:{ev.worst_reference}")
    # The flagged worst reference is reported, not held against the whole fit.
    m2 = [m["mahalanobis2"] for m in matches if m["label"] != ev.worst_reference]
    if m2 and sum(m2) / len(m2) > settings.fit_gate:
        flags.append("poor_fit")
    return factor, flags


# -------------------------------------------------------------------------- refinement
def _refine(
    cand: Candidate, world_cam: Camera, ev: _Evidence, settings: LocateSettings
) -> Candidate:
    """Refine (θ, T, s) and the camera's position jointly against all matched evidence.

    The world-frame pose of the camera is kept from the relative fit (its own uncertainty
    enters through the observation covariances); the car-to-map similarity is fitted by
    least squares on the Mahalanobis residuals of every matched point plus the scale prior,
    and its covariance is propagated to the camera position.
    """
    obs_q: list[tuple[Observation, FloatArray]] = list(ev.refs)
    by_label = {m["label"]: m for m in cand.matches}
    for o in ev.corners:
        if o.label in by_label:
            obs_q.append((o, np.asarray(by_label[o.label]["map_en"])))
    for o, _pts in ev.landmarks:
        if o.label in by_label:
            obs_q.append((o, np.asarray(by_label[o.label]["map_en"])))
    # Points beyond the likelihood's cap are outliers to this hypothesis (they add a
    # constant): leave them out, or one wrong reference drags the fit back onto itself.
    inliers = [
        (o, q)
        for o, q in obs_q
        if by_label.get(o.label, {}).get("mahalanobis2", 0.0) <= _OUTLIER_M2
    ]
    if len(inliers) >= 2:
        obs_q = inliers
    if not obs_q:
        return cand
    # Whitening at the starting similarity (the rotation and scale change little here).
    R20 = _rot2(cand.theta_rad)
    L = np.stack([np.linalg.cholesky(_obs_precision(o, R20, cand.scale)) for o, _q in obs_q])
    P = np.array([o.world_xy for o, _q in obs_q])
    Q = np.array([q for _o, q in obs_q])
    s_sigma = max(settings.scale_sigma_rel, 1e-6)

    def resid_jac(x: FloatArray) -> tuple[FloatArray, FloatArray]:
        theta, tx, ty, ls = x
        s = math.exp(ls)
        R2 = _rot2(theta)
        dR2 = np.array([[-R2[1, 0], -R2[0, 0]], [R2[0, 0], -R2[1, 0]]])
        sp = s * P @ R2.T
        d = sp + np.array([tx, ty]) - Q
        r = np.einsum("nji,nj->ni", L, d).ravel()
        cols = [
            s * P @ dR2.T,
            np.broadcast_to([1.0, 0.0], P.shape),
            np.broadcast_to([0.0, 1.0], P.shape),
            sp,
        ]
        J = np.column_stack([np.einsum("nji,nj->ni", L, c).ravel() for c in cols])
        r = np.concatenate([r, [ls / s_sigma]])
        J = np.vstack([J, [0.0, 0.0, 0.0, 1.0 / s_sigma]])
        if street_brg is not None:
            # The car is parallel to the street it stands on, within bearing_sigma_deg (the
            # street found under the car at the start; the refinement moves it little).
            car_brg = (90.0 - math.degrees(theta)) % 180.0
            diff = (car_brg - street_brg + 90.0) % 180.0 - 90.0
            r = np.concatenate([r, [diff / settings.bearing_sigma_deg]])
            J = np.vstack([J, [-math.degrees(1.0) / settings.bearing_sigma_deg, 0, 0, 0]])
        return r, J

    x = np.array([cand.theta_rad, *cand.translation_en, math.log(cand.scale)])
    # The street prior only pulls a candidate that already (nearly) meets it: one whose car
    # is flagged off the street or across it is the evidence's, not the prior's, to move.
    street_brg: float | None = None
    if ev.street_tree is not None:
        diff0 = _street_angle_under_car(cand.theta_rad, cand.translation_en, cand.scale, ev)
        if diff0 is not None and abs(diff0) <= 2.5 * settings.bearing_sigma_deg:
            street_brg = ((90.0 - math.degrees(cand.theta_rad)) - diff0) % 180.0
    r, J = resid_jac(x)
    for _ in range(8):  # Gauss-Newton: the problem is nearly linear
        try:
            dx = -np.linalg.lstsq(J, r, rcond=None)[0]
        except np.linalg.LinAlgError:
            break
        x_new = x + dx
        r_new, J_new = resid_jac(x_new)
        if float(r_new @ r_new) > float(r @ r) * (1 + 1e-12):
            break
        x, r, J = x_new, r_new, J_new
        if np.max(np.abs(dx)) < 1e-10:
            break
    theta, tx, ty, ls = x
    T = np.array([tx, ty])
    s = math.exp(ls)
    cam = _camera_in_enu(world_cam, theta, T, s)
    sigma = None
    try:
        cov = np.linalg.pinv(J.T @ J)
        # Jacobian of the camera's ENU position w.r.t. (θ, tx, ty, ln s).
        Cw = world_cam.center_in_world[:2]
        R2 = _rot2(theta)
        dR = np.array([[-math.sin(theta), -math.cos(theta)], [math.cos(theta), -math.sin(theta)]])
        Jp = np.column_stack([s * dR @ Cw, [1.0, 0.0], [0.0, 1.0], s * R2 @ Cw])
        cov_p = Jp @ cov @ Jp.T
        sigma = float(math.sqrt(max(np.trace(cov_p), 0.0)))
    except np.linalg.LinAlgError:
        pass
    return replace(
        cand,
        theta_rad=float(theta),
        translation_en=T,
        scale=s,
        camera=cam,
        sigma_m=sigma,
        refined=True,
    )


# ------------------------------------------------------------------------------ driver
_STREETS_CACHE: dict[tuple[int, float, float], tuple[list[tuple[Any, float]], Any]] = {}


def _streets_index(map_data: MapData, frame: LocalFrame) -> tuple[list[tuple[Any, float]], Any]:
    """Street centre lines in the local frame with half carriageway widths, and an STRtree."""
    key = (id(map_data), frame.lat0, frame.lon0)
    hit = _STREETS_CACHE.get(key)
    if hit is not None and hit[0] and len(hit[0]) == len(map_data.streets):
        return hit
    from shapely import STRtree
    from shapely.geometry import LineString

    rows = []
    for st in map_data.streets:
        coords = np.asarray(st.geometry.coords, dtype=float)
        if len(coords) < 2:
            continue
        line = LineString(frame.points_enu_from_geographic(coords))
        if line.length > 0.5:
            rows.append((line, float(st.width_m) / 2.0))
    tree = STRtree([r[0] for r in rows]) if rows else None
    if len(_STREETS_CACHE) > 16:
        _STREETS_CACHE.clear()
    _STREETS_CACHE[key] = (rows, tree)
    return rows, tree


_BUILDINGS_CACHE: dict[tuple[int, float, float], tuple[list[Any], Any]] = {}


def _buildings_index(map_data: MapData, frame: LocalFrame) -> tuple[list[Any], Any]:
    """Building footprints in the local frame and an STRtree over them (cached per map)."""
    key = (id(map_data), frame.lat0, frame.lon0)
    hit = _BUILDINGS_CACHE.get(key)
    if hit is not None and len(hit[0]) <= len(map_data.buildings):
        return hit
    from shapely import STRtree
    from shapely.geometry import Polygon

    polys = []
    for b in map_data.buildings:
        coords = np.asarray(b.footprint.exterior.coords, dtype=float)
        poly = Polygon(frame.points_enu_from_geographic(coords))
        if poly.is_valid and poly.area > 1.0:
            polys.append(poly)
    tree = STRtree(polys) if polys else None
    if len(_BUILDINGS_CACHE) > 16:
        _BUILDINGS_CACHE.clear()
    _BUILDINGS_CACHE[key] = (polys, tree)
    return polys, tree


def _frame_anchor(scene: Scene, map_data: MapData | None) -> LocalFrame:
    if map_data is not None:
        return map_data.frame
    if scene.prior is not None:
        return LocalFrame(scene.prior.lat, scene.prior.lon)
    if scene.references:
        return LocalFrame(
            float(np.mean([r.lat for r in scene.references])),
            float(np.mean([r.lon for r in scene.references])),
        )
    if scene.intersection is not None and scene.intersection.lat is not None:
        assert scene.intersection.lon is not None
        return LocalFrame(scene.intersection.lat, scene.intersection.lon)
    raise SceneError(
        "no geographic hint: give prior, references, intersection lat/lon, or a map", "prior"
    )


def _choose_intersection(scene: Scene, map_data: MapData, frame: LocalFrame) -> Intersection:
    hint = scene.intersection
    assert hint is not None
    near = (scene.prior.lat, scene.prior.lon) if scene.prior is not None else None
    if hint.streets:
        return map_data.find_intersection(list(hint.streets), near=near)
    if hint.lat is not None and hint.lon is not None:
        return map_data.nearest_intersection(hint.lat, hint.lon)
    if scene.prior is not None:
        return map_data.nearest_intersection(scene.prior.lat, scene.prior.lon)
    return map_data.nearest_intersection(frame.lat0, frame.lon0)


def locate(
    scene: Scene,
    map_data: MapData | None = None,
    *,
    calibration: CalibrationResult | None = None,
    settings: LocateSettings | None = None,
    calibration_settings: CalibrationSettings | None = None,
) -> LocateResult:
    """Candidate camera positions for a scene, best first.

    Parameters
    ----------
    scene
        A validated scene with annotations and at least one kind of geographic evidence
        (references, an intersection's corners, landmarks).
    map_data
        The map around the scene (:func:`camloc_geo.osm.load_map`); needed for corners,
        landmarks and street bearings, optional for references.
    calibration
        A precomputed :func:`camloc_geo.relative.calibrate` result (computed if None).
    settings
        Noise model and ranking; see :class:`LocateSettings`.

    Returns
    -------
    LocateResult
        ``candidates`` is empty, with ``reason`` saying why, when no method applies or no
        hypothesis survives.

    Raises
    ------
    SceneError, MapDataError
        Malformed evidence (a reference pixel above the horizon, an unknown street or
        building name).
    """
    settings = settings or LocateSettings()
    cal = calibration or calibrate(scene, calibration_settings)
    world_cam = cal.camera
    frame = _frame_anchor(scene, map_data)
    width, height = scene.image_size
    diag = math.hypot(width, height)
    result = LocateResult([], frame, cal, [], scene_id=scene.id, image_size=(width, height))

    def observe(pixel: Sequence[float], kind: str, label: str, sigma: float) -> Observation | None:
        try:
            return _ground_observation(world_cam, pixel, kind, label, sigma, settings, diag)
        except SceneError as exc:
            result.warnings.append(f"{exc}; ignored")
            return None

    refs = []
    for i, ref in enumerate(scene.references):
        obs = observe(
            ref.pixel,
            "reference",
            f"references[{i}]",
            settings.sigma_reference_m / math.sqrt(ref.weight),
        )
        if obs is not None:
            refs.append((obs, np.array(frame.enu_from_geographic(ref.lon, ref.lat), dtype=float)))
    corners: list[Observation] = []
    map_corners = np.zeros((0, 2))
    map_corner_ids: list[str] = []
    inter = None
    bearings: list[float] = []
    if scene.intersection is not None:
        listed = np.asarray(scene.intersection.corners, dtype=float)
        for i in range(len(listed)):
            for j in range(i):
                if np.linalg.norm(listed[i] - listed[j]) < 2.0:
                    raise SceneError(
                        f"is the same pixel as intersection.corners[{j}] (less than 2 px "
                        "apart): each visible kerb corner is listed once",
                        f"intersection.corners[{i}]",
                    )
        for i, px in enumerate(scene.intersection.corners):
            c_obs = observe(px, "corner", f"intersection.corners[{i}]", settings.sigma_corner_m)
            if c_obs is not None:
                corners.append(c_obs)
        if map_data is None:
            raise MapDataError("the scene lists intersection corners but no map was given")
        inter = _choose_intersection(scene, map_data, frame)
        result.intersection = inter
        if inter.kind != "junction":
            result.warnings.append(
                f"intersection {inter.id} is a {inter.kind}: " + "; ".join(inter.warnings)
            )
        if inter.corners:
            map_corners = np.array(
                [frame.enu_from_geographic(c.lon, c.lat) for c in inter.corners], dtype=float
            )
            map_corner_ids = [f"{inter.id}:{c.order}" for c in inter.corners]
        bearings += [st.bearing_deg for st in inter.streets]
    landmarks = []
    if scene.landmarks:
        for i, lm in enumerate(scene.landmarks):
            label = f"landmarks[{i}]"
            sigma = (
                settings.sigma_landmark_corner_m
                if lm.kind == "building_corner"
                else settings.sigma_face_midpoint_m
            )
            lm_obs = observe(lm.pixel, "landmark", label, sigma)
            if lm_obs is None:
                continue
            pts_ll: list[tuple[float, float]]
            if lm.name is not None and map_data is not None:
                near_lm: tuple[float, float] | None = None
                if lm.lat is not None and lm.lon is not None:
                    near_lm = (lm.lat, lm.lon)
                elif scene.prior is not None:
                    near_lm = (scene.prior.lat, scene.prior.lon)
                building = map_data.find_building(lm.name, near=near_lm)
                pts_ll = list(
                    building.corners if lm.kind == "building_corner" else building.face_midpoints
                )
            elif lm.lat is not None and lm.lon is not None:
                pts_ll = [(lm.lon, lm.lat)]
            else:
                raise MapDataError(f"{label}: landmark {lm.name!r} needs a map or lat/lon")
            if not pts_ll:
                raise MapDataError(
                    f"{label}: the building has no usable {lm.kind.replace('_', ' ')}s"
                )
            pts = frame.points_enu_from_geographic(np.asarray(pts_ll, dtype=float))
            landmarks.append((lm_obs, pts))
    # Street bearings near the evidence.
    if scene.street_bearing_deg is not None:
        bearings = [scene.street_bearing_deg]
    elif map_data is not None:
        spots = [(q, settings.street_search_m) for _, q in refs]
        if inter is not None:
            spots.append(
                (
                    np.array(frame.enu_from_geographic(inter.lon, inter.lat)),
                    settings.street_search_m,
                )
            )
        for _, pts in landmarks:
            # The streets along any side of the building, not only near its centre.
            mid = pts.mean(axis=0)
            reach = float(np.max(np.linalg.norm(pts - mid, axis=1)))
            spots.append((mid, settings.street_search_m + reach))
        if not spots and scene.prior is not None:
            spots.append(
                (
                    np.array(frame.enu_from_geographic(scene.prior.lon, scene.prior.lat)),
                    settings.street_search_m,
                )
            )
        # Widen the search where nothing passes close (a reference on a plaza, a landmark
        # set back from the street): 1x, 3x, 8x the radius, then at least 200 m.
        base = settings.street_search_m
        for widen in (1.0, 3.0, 8.0, max(8.0, 200.0 / max(base, 1e-9))):
            for q, radius in spots:
                lon, lat = frame.geographic_from_enu(float(q[0]), float(q[1]))
                for _name, street_brg in map_data.street_bearings(
                    float(lat), float(lon), widen * radius
                ):
                    bearings.append(street_brg)
            if bearings or not spots:
                if widen > 1.0:
                    result.warnings.append(
                        f"street bearings: no street within {settings.street_search_m:g} m of the "
                        f"evidence; used those within {widen * settings.street_search_m:g} m"
                    )
                break
    bearings = _unique_bearings(bearings)

    buildings_enu: list[Any] = []
    buildings_tree = None
    if map_data is not None and map_data.buildings:
        buildings_enu, buildings_tree = _buildings_index(map_data, frame)
    prior_en = None
    prior_r = None
    if scene.prior is not None:
        prior_en = np.array(
            frame.enu_from_geographic(scene.prior.lon, scene.prior.lat), dtype=float
        )
        prior_r = scene.prior.radius_m
    ev = _Evidence(
        refs,
        corners,
        map_corners,
        map_corner_ids,
        landmarks,
        bearings,
        buildings_enu,
        prior_en,
        prior_r,
    )
    ev.buildings_tree = buildings_tree
    if map_data is not None and map_data.streets and scene.street_bearing_deg is None:
        ev.streets_enu, ev.street_tree = _streets_index(map_data, frame)
    size = scene.object_size
    ws = 1.0 if sum(cal.width_signs or [1.0]) >= 0 else -1.0
    ev.car_center_world = np.array([size.length_m / 2.0, ws * size.width_m / 2.0])
    result.observations = [o for o, _ in refs] + corners + [o for o, _ in landmarks]
    worst = _worst_reference(refs, settings)
    if worst is not None:
        ev.worst_reference = worst[0]
        result.warnings.append(
            f"{worst[0]} is the reference that agrees least with the others: "
            f"{worst[1]:.1f} m from where they put it"
        )

    hyps: list[_Hypothesis] = []
    if len(refs) >= 2:
        result.methods_tried.append("two_references")
        hyps += _gen_references(ev, settings)
    if len(refs) == 1 and not corners and not scene.landmarks:
        result.methods_tried.append("one_reference")
        if not bearings:
            result.warnings.append(
                "one_reference: no street bearing (scene or map) near the reference"
            )
        hyps += _gen_one_reference(ev, scene.street_bearing_deg)
    if scene.intersection is not None:
        result.methods_tried.append("corners")
        if not len(map_corners):
            result.warnings.append(
                f"corners: the map has no modelled kerb corners at intersection "
                f"{inter.id if inter else '?'}"
            )
        elif len(corners) > len(map_corners):
            result.warnings.append(
                f"corners: the scene lists {len(corners)} visible corners but the map's "
                f"intersection has {len(map_corners)}; every hypothesis leaves "
                f"{len(corners) - len(map_corners)} of them unmatched"
            )
        hyps += _gen_corners(ev, settings)
    if scene.landmarks:
        result.methods_tried.append("landmark")
        if len(landmarks) == 1 and not bearings:
            result.warnings.append(
                "landmark: one landmark and no street bearing (scene or map) near it"
            )
        hyps += _gen_landmarks(ev, settings)
    if not result.methods_tried:
        if scene.references or scene.intersection is not None or scene.landmarks:
            result.reason = (
                "every reference, corner or landmark pixel is at or above the calibrated "
                "camera's horizon, so none is a ground point (is the calibration wrong? its "
                f"focal length is {world_cam.focal_px:.0f} px): " + "; ".join(result.warnings)
            )
        else:
            result.reason = (
                "no geographic evidence: the scene has no references, intersection corners or "
                "landmarks"
            )
        return result
    if not hyps:
        result.reason = "no hypothesis: " + "; ".join(
            result.warnings or ["the evidence fits nothing"]
        )
        return result

    cands = []
    for h in hyps:
        ll, rms, matches, _sq, assign = _score(h.theta, h.T, h.s, ev, settings, h.corner_assignment)
        cam = _camera_in_enu(world_cam, h.theta, h.T, h.s)
        plaus, flags = _plausibility(cam, h.theta, h.T, h.s, ev, settings, matches)
        flags += _unmatched_flags(ev, assign)
        cands.append(
            Candidate(
                h.method,
                h.theta,
                h.T,
                h.s,
                cam,
                log_likelihood=ll + h.log_prior,
                prior=plaus,
                residual_m=rms,
                matches=matches,
                flags=flags,
                corner_assignment=assign,
            )
        )
    if ev.prior_en is not None and ev.prior_radius_m:
        limit = settings.prior_gate_radii * ev.prior_radius_m
        dist = [float(np.linalg.norm(c.east_north - ev.prior_en)) for c in cands]
        kept_near = [c for c, d in zip(cands, dist, strict=True) if d <= limit]
        if not kept_near:
            result.reason = (
                f"every hypothesis puts the camera more than {limit:.0f} m "
                f"({settings.prior_gate_radii:g} x prior.radius_m) from the prior, the nearest "
                f"{min(dist):.0f} m: the {', '.join(result.methods_tried)} evidence contradicts "
                "the prior (or the calibration is wrong: it puts the camera "
                f"{float(np.linalg.norm(world_cam.center_in_world[:2])):.0f} m from the car)"
            )
            return result
        if len(kept_near) < len(cands):
            result.warnings.append(
                f"{len(cands) - len(kept_near)} hypotheses more than {limit:.0f} m from the prior "
                "dropped"
            )
        cands = kept_near
    cands = _normalise_and_merge(cands, settings)
    # Refine the leaders, then score again.
    for i in range(min(settings.refine_top, len(cands))):
        c = _refine(cands[i], world_cam, ev, settings)
        ll, rms, matches, _sq, assign = _score(
            c.theta_rad, c.translation_en, c.scale, ev, settings, c.corner_assignment
        )
        plaus, flags = _plausibility(
            c.camera, c.theta_rad, c.translation_en, c.scale, ev, settings, matches
        )
        flags += _unmatched_flags(ev, assign)
        cands[i] = replace(
            c, log_likelihood=ll, prior=plaus, residual_m=rms, matches=matches, flags=flags
        )
    cands = _normalise_and_merge(cands, settings)[: settings.max_candidates]
    if all("poor_fit" in c.flags for c in cands):
        best = min(cands, key=lambda c: c.residual_m)
        result.reason = (
            f"no hypothesis fits the {', '.join(result.methods_tried)} evidence: the best misfits "
            f"by {best.residual_m:.1f} m RMS, more than {math.sqrt(settings.fit_gate):.0f} "
            "standard deviations of the noise model (wrong intersection, corners out of order, "
            "or a wrong calibration?)"
        )
        return result
    total = sum(c.score for c in cands) or 1.0
    for rank, c in enumerate(cands, start=1):
        c.score = c.score / total
        c.rank = rank
        lon, lat = frame.geographic_from_enu(
            float(c.camera.center_in_world[0]), float(c.camera.center_in_world[1])
        )
        c.lon, c.lat = float(lon), float(lat)
    result.candidates = cands
    if len(cands) >= 2 and cands[1].score >= 0.8 * cands[0].score:
        gap = float(np.linalg.norm(cands[0].east_north - cands[1].east_north))
        if gap > 2.0 * settings.merge_distance_m:
            result.warnings.append(
                f"ambiguous: candidates 1 and 2 fit the evidence equally well (scores "
                f"{cands[0].score:.2f} and {cands[1].score:.2f}) but stand {gap:.0f} m apart; "
                "a symmetric junction cannot tell them apart: more evidence (a reference pixel, "
                "a landmark, another corner) or a tighter prior decides"
            )
    return result


def _normalise_and_merge(cands: list[Candidate], settings: LocateSettings) -> list[Candidate]:
    if not cands:
        return cands
    logw = np.array([c.log_likelihood + math.log(max(c.prior, 1e-300)) for c in cands])
    w = np.exp(logw - logw.max())
    w /= w.sum()
    for c, wi in zip(cands, w, strict=True):
        c.score = float(wi)
    cands.sort(key=lambda c: -c.score)
    kept: list[Candidate] = []
    kept_heading: list[float] = []
    for c in cands:
        h = c.heading_deg
        for k, hk in zip(kept, kept_heading, strict=True):
            close = np.linalg.norm(c.east_north - k.east_north) < settings.merge_distance_m
            dh = abs((h - hk + 180.0) % 360.0 - 180.0)
            if close and dh < settings.merge_heading_deg:
                k.score += c.score
                k.merged += c.merged
                break
        else:
            kept.append(c)
            kept_heading.append(h)
    kept.sort(key=lambda c: -c.score)
    return kept


# -------------------------------------------------------------------------------- output
def _view_cone(cam: Camera, size: tuple[int, int], range_m: float) -> FloatArray:
    """Ground footprint of the view, clipped at ``range_m`` horizontally (ENU polygon)."""
    w, h = size
    C = cam.center_in_world
    border: list[tuple[float, float]] = []
    n = 12
    for i in range(n + 1):
        border.append((w * i / n, h))
    for i in range(n + 1):
        border.append((w, h * (1 - i / n)))
    for i in range(n + 1):
        border.append((w * (1 - i / n), 0.0))
    for i in range(n + 1):
        border.append((0.0, h * i / n))
    rays = cam.rays_in_world(np.asarray(border, dtype=float))
    pts = [C[:2].copy()]
    for r in rays:
        horiz = math.hypot(r[0], r[1])
        if horiz < 1e-9:
            continue
        if r[2] < -1e-9:
            lam = -C[2] / r[2]
            dist = lam * horiz
        else:
            dist = math.inf
        dist = min(dist, range_m)
        pts.append(C[:2] + dist * r[:2] / horiz)
    pts.append(C[:2].copy())
    return np.asarray(pts, dtype=np.float64)


def candidates_geojson(result: LocateResult, *, view_cones: bool = True) -> dict[str, Any]:
    """The candidate GeoJSON FeatureCollection of the scene contract.

    Candidate Point features (``kind: "candidate"``, best first) carry every property of
    the contract plus ``sigma_m`` (1-sigma position uncertainty), ``scale``, ``flags``,
    ``matches`` and ``merged``. Extra features: ``view_cone`` polygons (one per candidate),
    ``matched_point`` points (the map points each candidate matched), and the
    ``intersection`` used, with its ``corner`` points.
    """
    frame = result.frame
    feats: list[dict[str, Any]] = []
    _h, pitch, roll = result.calibration.camera.angles_deg
    for c in result.candidates:
        heading, pitch_c, roll_c = c.camera.angles_deg
        props = {
            "kind": "candidate",
            "rank": c.rank,
            "score": c.score,
            "lat": c.lat,
            "lon": c.lon,
            "height_m": c.camera.height_m,
            "heading_deg": float(normalize_bearing_deg(heading)),
            "pitch_deg": pitch_c,
            "roll_deg": roll_c,
            "focal_px": c.camera.focal_px,
            "method": c.method,
            "residual_m": None if math.isnan(c.residual_m) else c.residual_m,
            "sigma_m": c.sigma_m,
            "scale": c.scale,
            "refined": c.refined,
            "merged": c.merged,
            "flags": c.flags,
            "scene": result.scene_id,
            "matches": [
                {
                    **{k: v for k, v in m.items() if k != "map_en"},
                    "map_lonlat": list(frame.geographic_from_enu(*m["map_en"])),
                }
                for m in c.matches
            ],
        }
        feats.append(
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [c.lon, c.lat]},
                "properties": props,
            }
        )
    if view_cones:
        for c in result.candidates:
            poly = _view_cone(c.camera, result.image_size, 60.0)
            ll = frame.points_geographic_from_enu(poly)
            feats.append(
                {
                    "type": "Feature",
                    "geometry": {"type": "Polygon", "coordinates": [ll.tolist()]},
                    "properties": {"kind": "view_cone", "rank": c.rank, "score": c.score},
                }
            )
    for c in result.candidates:
        for m in c.matches:
            lon, lat = frame.geographic_from_enu(*m["map_en"])
            feats.append(
                {
                    "type": "Feature",
                    "geometry": {"type": "Point", "coordinates": [float(lon), float(lat)]},
                    "properties": {
                        "kind": "matched_point",
                        "rank": c.rank,
                        "label": m["label"],
                        "match_kind": m["kind"],
                        "pixel": m["pixel"],
                        "misfit_m": m["misfit_m"],
                        **({"map_corner": m["map_corner"]} if "map_corner" in m else {}),
                    },
                }
            )
    inter = result.intersection
    if inter is not None:
        feats.append(
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [inter.lon, inter.lat]},
                "properties": {
                    "kind": "intersection",
                    "id": inter.id,
                    "streets": [s.name for s in inter.streets],
                    "intersection_kind": inter.kind,
                },
            }
        )
        for corner in inter.corners:
            feats.append(
                {
                    "type": "Feature",
                    "geometry": {"type": "Point", "coordinates": [corner.lon, corner.lat]},
                    "properties": {
                        "kind": "corner",
                        "intersection": inter.id,
                        "order": corner.order,
                        "streets": list(corner.streets),
                    },
                }
            )
    out: dict[str, Any] = {
        "type": "FeatureCollection",
        "features": feats,
        "properties": {
            "scene": result.scene_id,
            "methods_tried": result.methods_tried,
            "n_candidates": len(result.candidates),
            "reason": result.reason,
            "warnings": result.warnings + result.calibration.warnings,
            "calibration": {
                "focal_px": result.calibration.camera.focal_px,
                "height_m": result.calibration.camera.height_m,
                "pitch_deg": pitch,
                "roll_deg": roll,
                "method": result.calibration.method,
                "intrinsics_method": result.calibration.intrinsics_method,
                "outlier_annotators": result.calibration.outlier_annotators,
            },
            "attribution": "Map data © OpenStreetMap contributors, ODbL",
        },
    }
    return out
