"""Stage 2, hypotheses: candidate ``enu_from_world`` similarities, one generator per evidence."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from camloc_geo.absolute._evidence import Evidence, unique_bearings
from camloc_geo.absolute._model import LocateResult, LocateSettings, Observation
from camloc_geo.absolute._scoring import assignments, mahal
from camloc_geo.absolute._similarity import Similarity2D, rot2, similarity_fit, theta_for_bearing
from camloc_geo.scene import Scene

FloatArray = npt.NDArray[np.float64]


@dataclass
class Hypothesis:
    """A candidate similarity, the generator that proposed it, and its prior."""

    method: str
    enu_from_world: Similarity2D
    log_prior: float = 0.0
    corner_assignment: tuple[int, ...] | None = None


class NoCandidatesError(Exception):
    """A stage found nothing to go on; the message is the result's ``reason``."""


def _weights(observations: Sequence[Observation]) -> FloatArray:
    return np.array([1.0 / (np.trace(o.cov_world) / 2 + o.sigma_map_m**2) for o in observations])


def _gen_references(ev: Evidence, settings: LocateSettings) -> list[Hypothesis]:
    refs = ev.refs
    if len(refs) < 2:
        return []
    world = np.array([o.world_xy for o, _ in refs])
    enu = np.array([q for _, q in refs])
    wts = _weights([o for o, _ in refs])
    out = [Hypothesis("two_references", similarity_fit(world, enu, wts, settings.scale_sigma_rel))]
    if ev.worst_reference is not None:
        # The robust alternative: the fit of the others, the worst one an outlier.
        keep = [i for i, (o, _) in enumerate(refs) if o.label != ev.worst_reference]
        sim = similarity_fit(world[keep], enu[keep], wts[keep], settings.scale_sigma_rel)
        out.append(Hypothesis("two_references", sim))
    return out


def worst_reference(
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
    wts = _weights([o for o, _ in refs])
    best: tuple[float, str, float] | None = None
    for i in range(len(refs)):
        keep = [j for j in range(len(refs)) if j != i]
        sim = similarity_fit(world[keep], enu[keep], wts[keep], settings.scale_sigma_rel)
        cost = sum(mahal(refs[j][0], refs[j][1], sim) for j in keep)
        cost += ((sim.scale - 1.0) / max(settings.scale_sigma_rel, 1e-6)) ** 2
        miss = float(np.linalg.norm(sim.apply(world[i]) - enu[i]))
        if best is None or cost < best[0]:
            best = (cost, refs[i][0].label, miss)
    assert best is not None
    return best[1], best[2]


REFERENCE_CONFLICT_Z = 3.0
"""Two references whose ground distance (as the calibrated camera sees their pixels) and
map distance differ by more than this many standard deviations disagree
(:func:`reference_conflict`). ``benchmarks/absolute_slips.py --n 120``: no clean pair
disagrees even at 2; one reference on another kerb corner stays confidently wrong in 14 /
11 / 8 / 6 of 117 scenes at 4 / 3 / 2.5 / 2. Real map clicks err more than the benchmark's
0.5 m per axis, so 3."""


def reference_conflict(
    refs: list[tuple[Observation, FloatArray]], settings: LocateSettings
) -> tuple[float, float, float] | None:
    """How far two references disagree: ``(z, ground_m, map_m)``, None when they agree.

    Two references fix any camera exactly up to the scale of the car's frame, so a wrong
    lat/lon (another corner's, a typo) leaves no residual except the scale the fit needs:
    their distance apart on the ground, as the calibrated camera casts their pixels, and on
    the map must agree within the pixels' noise, the map's and the car's size (5 %). ``z``
    is the difference in standard deviations; the pair disagrees beyond
    :data:`REFERENCE_CONFLICT_Z`.
    """
    if len(refs) != 2:
        return None
    (oa, qa), (ob, qb) = refs
    gap_world = np.asarray(ob.world_xy - oa.world_xy, dtype=float)
    ground_m = float(np.linalg.norm(gap_world))
    map_m = float(np.linalg.norm(np.asarray(qb - qa, dtype=float)))
    if ground_m <= 0.0:
        return None
    u = gap_world / ground_m
    var = float(u @ (oa.cov_world + ob.cov_world) @ u)
    var += oa.sigma_map_m**2 + ob.sigma_map_m**2 + (settings.scale_sigma_rel * ground_m) ** 2
    z = abs(ground_m - map_m) / math.sqrt(max(var, 1e-12))
    return (z, ground_m, map_m) if z > REFERENCE_CONFLICT_Z else None


def _gen_bearing_point(
    method: str, obs: Observation, points: FloatArray, bearings: Sequence[float]
) -> list[Hypothesis]:
    """The car's axis along each street bearing (both ways), the pixel on each map point."""
    out = []
    for q in points:
        for b in bearings:
            for flip in (0.0, 180.0):
                theta = theta_for_bearing(b + flip)
                T = q - rot2(theta) @ obs.world_xy
                out.append(Hypothesis(method, Similarity2D(theta, T, 1.0)))
    return out


def corner_hypotheses(
    ev: Evidence, settings: LocateSettings, *, counter_clockwise: bool = False
) -> list[Hypothesis]:
    """The kerb-corner hypotheses: visible corners assigned to the map's, in order.

    ``counter_clockwise``: instead, the list read backwards (at
    :data:`REVERSED_ORDER_PRIOR`), only the assignments the clockwise reading does not give.
    """
    k, n = len(ev.corners), len(ev.map_corners)
    if k == 0 or n == 0:
        return []
    if counter_clockwise and (k < 2 or n < 2):
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
    wts = _weights(ev.corners)
    for assign, consecutive, reversed_ in _both_orders(k, n):
        if reversed_ != counter_clockwise:
            continue
        used = [i for i, j in enumerate(assign) if j >= 0]
        if len(used) < 2:
            continue
        enu = ev.map_corners[[assign[i] for i in used]]
        sim = similarity_fit(world[used], enu, wts[used], settings.scale_sigma_rel)
        lp = 0.0 if consecutive else math.log(settings.non_consecutive_prior)
        if reversed_:
            lp += math.log(REVERSED_ORDER_PRIOR)
        out.append(Hypothesis("corners", sim, lp, tuple(assign)))
        if len(used) == 2:
            # Two corners fix the rotation poorly when they are close together and far
            # away: also try the car along each street, the corners' centroid matched.
            window = _rotation_window_rad(enu, wts[used])
            out += _street_aligned(
                world[used], enu, sim, ev.street_bearings, lp, tuple(assign), window
            )
    return out


REVERSED_ORDER_PRIOR = 0.1
"""The prior odds of the visible corners listed counter-clockwise (the scene says clockwise).
Crowds reverse the order (``benchmarks/absolute_slips.py``: 9 % of the closest candidates
beyond 15 m, and 3 of 54 scenes without any answer, before this was tried)."""


def _both_orders(k: int, n: int) -> list[tuple[tuple[int, ...], float, bool]]:
    """:func:`assignments` of the corners as listed (clockwise), then those of the list read
    backwards (counter-clockwise) that are new, as ``(assignment, consecutive, reversed)``."""
    out = [(a, c, False) for a, c in assignments(k, n)]
    if k < 2:
        return out
    seen = {a for a, _c, _r in out}
    for a, c in assignments(k, n):
        back = a[::-1]
        if back not in seen:
            seen.add(back)
            out.append((back, c, True))
    return out


def is_reversed(assignment: Sequence[int] | None, n_map: int) -> bool:
    """Whether a corner assignment reads the visible corners counter-clockwise (it is none
    of :func:`assignments`' clockwise ones)."""
    if assignment is None or n_map < 1:
        return False
    a = tuple(int(j) for j in assignment)
    if sum(1 for j in a if j >= 0) < 2:
        return False
    return a not in {x for x, _c in assignments(len(a), n_map)}


def _rotation_window_rad(enu: FloatArray, weights: FloatArray) -> float:
    """How far a two-corner fit's rotation may be off: three sigmas, at least 30°.

    Each corner's position is uncertain by ``1 / sqrt(weight)`` metres (its click noise seen
    on the ground plus the map's error); across a baseline of ``L`` metres that turns the
    rotation by about ``sqrt(σ1² + σ2²) / L`` radians. Corners a narrow side street apart
    (5 m), seen from 40 m, leave the rotation loose by 30° or more.
    """
    baseline = float(np.linalg.norm(enu[1] - enu[0]))
    sigma = math.sqrt(float(np.sum(1.0 / weights)))
    if baseline <= 0.0:
        return math.pi
    return min(math.pi, max(math.radians(30.0), 3.0 * math.atan2(sigma, baseline)))


def _street_aligned(
    world: FloatArray,
    enu: FloatArray,
    sim: Similarity2D,
    bearings: Sequence[float],
    log_prior: float,
    assign: tuple[int, ...],
    window_rad: float,
) -> list[Hypothesis]:
    """Hypotheses with the car's axis along a street within ``window_rad`` of the fitted
    rotation (the corners' centroid matched)."""
    out = []
    for b in bearings:
        for flip in (0.0, 180.0):
            theta = theta_for_bearing(b + flip)
            d = (theta - sim.rotation_rad + math.pi) % (2 * math.pi) - math.pi
            if abs(d) > window_rad or abs(d) < math.radians(1.0):
                continue
            T = enu.mean(axis=0) - rot2(theta) @ world.mean(axis=0)
            out.append(Hypothesis("corners", Similarity2D(theta, T, 1.0), log_prior, assign))
    return out


def _gen_landmarks(ev: Evidence, settings: LocateSettings) -> list[Hypothesis]:
    lms = ev.landmarks
    if not lms:
        return []
    if len(lms) == 1:
        obs, pts = lms[0]
        return _gen_bearing_point("landmark", obs, pts, ev.street_bearings)
    out = []
    world = np.array([o.world_xy for o, _ in lms])
    wts = _weights([o for o, _ in lms])
    pools = [range(len(pts)) for _, pts in lms]
    combos = list(itertools.product(*pools))
    if len(combos) > 5000:
        combos = combos[:5000]
    for combo in combos:
        enu = np.array([lms[i][1][j] for i, j in enumerate(combo)])
        if np.ptp(enu, axis=0).max() < 1.0:
            continue
        sim = similarity_fit(world, enu, wts, settings.scale_sigma_rel)
        out.append(Hypothesis("landmark", sim))
    return out


def landmark_hypotheses(ev: Evidence, settings: LocateSettings) -> list[Hypothesis]:
    """The ``landmark`` hypotheses of ``ev``'s landmarks (public name of the generator)."""
    return _gen_landmarks(ev, settings)


def _gen_one_reference(ev: Evidence, street_bearing: float | None) -> list[Hypothesis]:
    if len(ev.refs) != 1:
        return []
    obs, q = ev.refs[0]
    bearings = [street_bearing] if street_bearing is not None else ev.street_bearings
    return _gen_bearing_point("one_reference", obs, q[None, :], unique_bearings(bearings))


def bearing_hypotheses(ev: Evidence, settings: LocateSettings) -> list[Hypothesis]:
    """The hypotheses that rest on a street bearing (one reference, one kerb corner or a
    junction with one modelled corner, one landmark), along ``ev.street_bearings``."""
    out = []
    if len(ev.refs) == 1 and not ev.corners and not ev.landmarks:
        out += _gen_one_reference(ev, None)
    if len(ev.corners) == 1 or (ev.corners and len(ev.map_corners) == 1):
        out += corner_hypotheses(ev, settings)
    if len(ev.landmarks) == 1:
        out += _gen_landmarks(ev, settings)
    return out


def flag_worst_reference(ev: Evidence, settings: LocateSettings, result: LocateResult) -> None:
    """Name the reference that agrees least with the others (three or more references)."""
    worst = worst_reference(ev.refs, settings)
    if worst is not None:
        ev.worst_reference = worst[0]
        result.warnings.append(
            f"{worst[0]} is the reference that agrees least with the others: "
            f"{worst[1]:.1f} m from where they put it"
        )


def generate_hypotheses(
    scene: Scene, ev: Evidence, settings: LocateSettings, result: LocateResult
) -> list[Hypothesis]:
    """Stage 2: every generator the evidence allows; ``result.methods_tried`` lists them.

    Raises
    ------
    NoCandidatesError
        No method applies, or none proposes anything.
    """
    flag_worst_reference(ev, settings, result)
    tried, warn = result.methods_tried, result.warnings
    hyps: list[Hypothesis] = []
    if len(ev.refs) >= 2:
        tried.append("two_references")
        hyps += _gen_references(ev, settings)
        if len(ev.refs) == 2 and _warn_conflicting_references(ev, settings, result):
            hyps += single_reference_hypotheses(ev)
    if len(ev.refs) == 1 and not ev.corners and not scene.landmarks:
        tried.append("one_reference")
        if not ev.street_bearings:
            warn.append("one_reference: no street bearing (scene or map) near the reference")
        hyps += _gen_one_reference(ev, scene.street_bearing_deg)
    if scene.intersection is not None:
        tried.append("corners")
        _warn_corner_counts(ev, result)
        hyps += corner_hypotheses(ev, settings)
    if scene.landmarks:
        tried.append("landmark")
        if len(ev.landmarks) == 1 and not ev.street_bearings:
            warn.append("landmark: one landmark and no street bearing (scene or map) near it")
        hyps += _gen_landmarks(ev, settings)
    if not tried:
        raise NoCandidatesError(_no_method_reason(scene, result))
    if not hyps:
        reasons = warn or ["the evidence fits nothing"]
        raise NoCandidatesError("no hypothesis: " + "; ".join(reasons))
    return hyps


def _warn_conflicting_references(
    ev: Evidence, settings: LocateSettings, result: LocateResult
) -> bool:
    """With exactly two references that disagree (:func:`reference_conflict`): a warning,
    and True (each is then also tried alone, :func:`single_reference_hypotheses`)."""
    conflict = reference_conflict(ev.refs, settings)
    if conflict is None:
        return False
    z, ground_m, map_m = conflict
    (oa, _qa), (ob, _qb) = ev.refs
    result.warnings.append(
        f"{oa.label} and {ob.label} disagree: {ground_m:.1f} m apart as the calibrated "
        f"camera sees their pixels, {map_m:.1f} m on the map ({z:.0f} standard "
        "deviations); one lat/lon is probably wrong (another point's, swapped or "
        "mistyped): each was also tried alone with the car along a street"
        + ("" if ev.street_bearings else " (no street bearing near them: not tried)")
    )
    return True


def single_reference_hypotheses(ev: Evidence) -> list[Hypothesis]:
    """Each reference alone with the car along a street (``one_reference``).

    Two references fix any camera exactly, so the fit of a pair of which one is wrong (a
    lat/lon from another point, rounded, mistyped) stands wherever the wrong one pulls it,
    with nothing to say so. Each one alone with the car along a street puts the right camera
    among the candidates; the scoring (robust to one outlier, the car parallel to its
    street) weighs them against the joint fit.
    """
    bearings = unique_bearings(ev.street_bearings)
    out = []
    for obs, q in ev.refs:
        out += _gen_bearing_point("one_reference", obs, q[None, :], bearings)
    return out


def _warn_corner_counts(ev: Evidence, result: LocateResult) -> None:
    k, n = len(ev.corners), len(ev.map_corners)
    inter = result.intersection
    if not n:
        result.warnings.append(
            f"corners: the map has no modelled kerb corners at intersection "
            f"{inter.id if inter else '?'}"
        )
    elif k > n:
        result.warnings.append(
            f"corners: the scene lists {k} visible corners but the map's "
            f"intersection has {n}; every hypothesis leaves "
            f"{k - n} of them unmatched"
        )


def _no_method_reason(scene: Scene, result: LocateResult) -> str:
    if scene.references or scene.intersection is not None or scene.landmarks:
        return (
            "every reference, corner or landmark pixel is at or above the calibrated "
            "camera's horizon, so none is a ground point (is the calibration wrong? its "
            f"focal length is {result.calibration.camera.focal_px:.0f} px): "
            + "; ".join(result.warnings)
        )
    return "no geographic evidence: the scene has no references, intersection corners or landmarks"
