"""The :func:`locate` pipeline.

evidence → hypotheses → scores → prior gate → refinement → ranking → bundle adjustment → ties.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from camloc_geo._ties import TIE_MIN_SCORE, is_tie
from camloc_geo.absolute._bundle import bundle_adjust_many
from camloc_geo.absolute._cues import cue_log_likelihood
from camloc_geo.absolute._evidence import (
    NEIGHBOUR_JUNCTION_PRIOR,
    UNSTATED_BEARING_PRIOR,
    Evidence,
    evidence_at,
    frame_anchor,
    gather_evidence,
    landmark_alternatives,
    named_junctions,
    other_junctions,
    reference_corner_alternatives,
)
from camloc_geo.absolute._hypotheses import (
    REVERSED_ORDER_PRIOR,
    Hypothesis,
    NoCandidatesError,
    _gen_references,
    bearing_hypotheses,
    corner_hypotheses,
    generate_hypotheses,
    is_reversed,
    landmark_hypotheses,
    single_reference_hypotheses,
)
from camloc_geo.absolute._model import (
    Candidate,
    Flag,
    FlagKind,
    LocateResult,
    LocateSettings,
    Match,
    Observation,
    Tie,
)
from camloc_geo.absolute._refine import (
    calibration_sigmas_m,
    focal_moves_m,
    position_sigma_m,
    position_sigmas_m,
    refine_many,
)
from camloc_geo.absolute._scoring import (
    OUTLIER_M2,
    car_bearing_deg,
    plausibility_at,
    score,
    street_angles_under_car,
    unmatched_flags,
)
from camloc_geo.absolute._similarity import Similarity2D
from camloc_geo.camera import Camera
from camloc_geo.relative import CalibrationResult, CalibrationSettings, calibrate
from camloc_geo.scene import Scene

if TYPE_CHECKING:
    from camloc_geo.osm import MapData

FloatArray = npt.NDArray[np.float64]

__all__ = [
    "apply_cues",
    "bundle_leaders",
    "locate",
    "mark_ties",
    "normalise_and_merge",
    "prior_gate",
    "rank",
    "refine_leaders",
]


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
    scene, spelling = _spelled(scene, map_data)
    result = _locate_once(scene, map_data, cal, settings, frozenset())
    if not result.candidates and _corner_misfit(scene, result):
        result = _leave_one_corner_out(scene, map_data, cal, settings, result)
    result.warnings[:0] = spelling
    return result


def _spelled(scene: Scene, map_data: MapData | None) -> tuple[Scene, list[str]]:
    """The scene with ``intersection.streets`` that meet nowhere on the map read as the map's
    names they misspell (:meth:`~camloc_geo.osm.MapData.spell_streets`: only when exactly
    one reading meets), and a warning per corrected name."""
    hint = scene.intersection
    if map_data is None or hint is None or not hint.streets or len(hint.streets) < 2:
        return scene, []
    names, notes = map_data.spell_streets(list(hint.streets))
    if not notes:
        return scene, []
    fixed = hint.model_copy(update={"streets": names})
    return scene.model_copy(update={"intersection": fixed}), [
        f"intersection.streets: {n}" for n in notes
    ]


def _locate_once(
    scene: Scene,
    map_data: MapData | None,
    cal: CalibrationResult,
    settings: LocateSettings,
    skip_corners: frozenset[int],
) -> LocateResult:
    """One run of the pipeline, the listed corners ``skip_corners`` (indices) left out."""
    frame = frame_anchor(scene, map_data)
    width, height = scene.image_size
    result = LocateResult(
        [],
        frame,
        cal,
        [],
        scene_id=scene.id,
        image_size=(width, height),
        view_cone_range_m=settings.view_cone_range_m,
    )
    world_cam = cal.camera
    ev = gather_evidence(scene, map_data, world_cam, settings, result, skip_corners=skip_corners)
    result.cues_applied = ev.has_cues
    try:
        hyps = generate_hypotheses(scene, ev, settings, result)
        cands = score_hypotheses(hyps, world_cam, ev, settings)
        cands += _counter_clockwise_candidates(cands, world_cam, ev, settings)
        cands += _references_alone(cands, world_cam, ev, settings)
        cands += _map_bearing_candidates(cands, world_cam, ev, settings)
        cands += _neighbour_building_candidates(cands, world_cam, ev, settings)
        cands += _reference_corner_candidates(world_cam, ev, settings)
        cands += _other_junction_candidates(scene, map_data, world_cam, ev, settings, result, cands)
        cands = prior_gate(cands, ev, settings, result)
        cands = normalise_and_merge(cands, settings)
        cands = expected_plausibility(cands, world_cam, ev, settings)
        cands = refine_leaders(cands, world_cam, ev, settings)
        cands = rank(cands, settings, result)
        _warn_references_off_street(cands, ev, result)
        result.candidates = bundle_leaders(cands, cal, ev, settings, result)
        mark_ties(result.candidates, settings, result)  # on the leaders' adjusted positions
        _warn_other_junction(scene, map_data, ev, result)
        _warn_rival_neighbour(map_data, settings, result)
        _warn_stated_bearing(ev, result)
        _warn_reversed_corners(result)
        _warn_corner_outlier(result)
        _warn_one_corner_decides(ev, settings, result)
        _warn_substituted_landmark(result)
        _warn_landmarks_off_street(ev, result)
        _warn_corners_car_off_street(ev, result)
        _add_rounding_sigma(scene, ev, settings, result)
        _warn_fragile_references(scene, ev, settings, result)
        _warn_reference_corner(result)
        _warn_outside_prior(ev, result)
        top_ev = result.candidates[0].evidence if result.candidates else None
        if top_ev is not None and top_ev.intersection is not None:
            result.intersection = top_ev.intersection
    except NoCandidatesError as exc:
        result.reason = str(exc)
    finally:
        _forget_placements(ev, result.candidates)
    return result


NO_FIT_REASON = "no hypothesis fits"
"""How :func:`rank`'s refusal begins when every candidate misfits (``poor_fit``)."""


def _corner_misfit(scene: Scene, result: LocateResult) -> bool:
    """Whether an empty answer is every hypothesis misfitting a scene that lists two or more
    kerb corners (one of them may be another junction's, or no kerb corner at all)."""
    return (
        (result.reason or "").startswith(NO_FIT_REASON)
        and scene.intersection is not None
        and len(scene.intersection.corners) >= 2
    )


def _leave_one_corner_out(
    scene: Scene,
    map_data: MapData | None,
    cal: CalibrationResult,
    settings: LocateSettings,
    empty: LocateResult,
) -> LocateResult:
    """The scene located again with each listed corner left out in turn, where no hypothesis
    fits them all (``empty``: the answer so far).

    A corner of a neighbouring junction in view, clicked too, or a point that is no kerb
    corner (a T junction's straight far kerb read as a crossroads' corner), leaves every
    reading of the junction misfitting: the answer was empty. Only then (a scene with an
    answer is never changed) each corner is left out once; the candidates of every run that
    fits are pooled by their weight (log likelihood with prior odds, and plausibility: each
    run has the same evidence but one corner), near-duplicates merged, ranked and their ties
    named, and a warning names the corner the best candidate leaves out. When no run fits,
    ``empty`` is returned as it was.
    """
    assert scene.intersection is not None
    runs: list[tuple[int, LocateResult]] = []
    for k in range(len(scene.intersection.corners)):
        got = _locate_once(scene, map_data, cal, settings, frozenset({k}))
        if got.candidates:
            runs.append((k, got))
    if not runs:
        return empty
    pool = sorted(
        ((_weight(c), k, c) for k, got in runs for c in got.candidates), key=lambda t: -t[0]
    )
    kept: list[tuple[float, int, Candidate]] = []
    for w, k, c in pool:
        if len(kept) >= settings.max_candidates:
            break
        dup = any(
            float(np.linalg.norm(c.east_north - o.east_north)) < settings.merge_distance_m
            and abs((c.heading_deg - o.heading_deg + 180.0) % 360.0 - 180.0)
            < settings.merge_heading_deg
            for _w, _k, o in kept
        )
        if not dup:
            kept.append((w, k, c))
    w0, k0, _c0 = kept[0]
    result = next(got for k, got in runs if k == k0)
    total = sum(math.exp(w - w0) for w, _k, _c in kept)
    cands = []
    for i, (w, _k, c) in enumerate(kept, start=1):
        c.score = math.exp(w - w0) / total
        c.rank = i
        cands.append(c)
    result.candidates = cands
    mark_ties(cands, settings, result)
    inter = result.intersection
    where = f"junction {inter.id} ({' & '.join(inter.street_names)})" if inter else "the map"
    others = sorted({k for _w, k, _c in kept[1:] if k != k0})
    misfit = (empty.reason or "").partition(": ")[2].partition(", more than")[0]
    result.warnings.append(
        f"intersection.corners[{k0}]: no reading of the junction fits all the listed corners "
        f"({misfit}); without corners[{k0}] they fit {where}: a corner of another "
        "junction, or no kerb corner (a T junction's straight far kerb)? The answer leaves it "
        "out; check it"
        + (
            "; leaving out "
            + ", ".join(f"corners[{k}]" for k in others)
            + " instead gives other candidates in this list"
            if others
            else ""
        )
    )
    return result


def _counter_clockwise_candidates(
    cands: list[Candidate], world_cam: Camera, ev: Evidence, settings: LocateSettings
) -> list[Candidate]:
    """The visible corners read counter-clockwise (odds
    :data:`~camloc_geo.absolute._hypotheses.REVERSED_ORDER_PRIOR`), kept when one of those
    readings fits better than every clockwise corner candidate, its prior odds left out (kept
    always, they nearly doubled the candidates of every corner scene, to no gain where the
    order was right).

    Before stop 39 they were kept only when they outweighed the clockwise ones with their
    odds in: a reversed list (three or more corners) whose clockwise misreading fitted
    another placement nearly as well was answered there with no warning (5 of 131
    ``corners_ccw`` scenes of ``benchmarks/absolute_slips.py --set held-out``, 23-103 m off).
    Kept, a better-fitting reversed reading ties with the clockwise top or is warned
    (:func:`_warn_reversed_fits`). Two corners have no reversed reading of their own: every
    ordered pair of a junction's corners is a clockwise reading too.
    """
    if len(ev.corners) < 2 or len(ev.map_corners) < 2:
        return []
    hyps = corner_hypotheses(ev, settings, counter_clockwise=True)
    if not hyps:
        return []
    back = score_hypotheses(hyps, world_cam, ev, settings)
    ahead = [c for c in cands if c.method == "corners"]
    odds = math.log(REVERSED_ORDER_PRIOR)
    if ahead and max(map(_weight, back)) - odds <= max(map(_weight, ahead)):
        return []
    return back


def _references_alone(
    cands: list[Candidate], world_cam: Camera, ev: Evidence, settings: LocateSettings
) -> list[Candidate]:
    """Two references alone whose joint fit puts the car off or across its street: each
    reference also tried alone with the car along a street, scored.

    (When the two disagree on their distance apart, :func:`generate_hypotheses` has tried
    them already.)
    """
    if len(ev.refs) != 2 or ev.corners or ev.landmarks:
        return []
    if any(c.method == "one_reference" for c in cands):
        return []
    joint = [c for c in cands if c.method == "two_references"]
    if not any({f.kind for f in c.flags} & _CAR_FLAGS for c in joint):
        return []
    return score_hypotheses(single_reference_hypotheses(ev), world_cam, ev, settings)


def _map_bearing_candidates(
    cands: list[Candidate], world_cam: Camera, ev: Evidence, settings: LocateSettings
) -> list[Candidate]:
    """The map's other street bearings, scored at odds of
    :data:`~camloc_geo.absolute._evidence.UNSTATED_BEARING_PRIOR`, when every candidate along
    the scene's ``street_bearing_deg`` is implausible on the map (its car off or across the
    street under it, or the camera inside a building).

    A crowd states the cross street's bearing as readily as the car's street's (the car in
    the other street: ``benchmarks/absolute_slips.py``); then the map's streets, and the
    car-parallel test, decide.

    Where some candidate's car lies along the stated bearing, the map's other readings are
    kept only as rivals (:data:`RIVAL_BEARING`): those whose car stands plausibly on its
    street and that come within the tie rule's odds of the best candidate, their prior odds
    in and kept through refinement, so that the tie rule names them. Before stop 41 the
    stated bearing was then taken at its word, and where the cross street's reading put the
    car on a street too the answer stood 16-73 m off with no tie and no warning
    (``bearing_cross_street``: 2 of 109 development scenes, 2 of 143 of held-out-3); a
    one-reference answer's own half turn is tied already in nearly every scene, so the
    rivals add a tie to 2 of 108 right control answers (``control_bearing``).
    """
    if ev.stated_bearing is None or not ev.map_bearings or not cands:
        return []
    ev_map = replace(ev, street_bearings=list(ev.map_bearings))
    hyps = bearing_hypotheses(ev_map, settings)
    odds = math.log(UNSTATED_BEARING_PRIOR)
    for h in hyps:
        h.log_prior += odds
    # (A car beside its street counted as plausible here: control_bearing warned 4 -> 2 %,
    # but bearing_cross_street lost closest < 15 m 74 -> 65 %: not kept.)
    if not any(map(_plausible, cands)):
        return score_hypotheses(hyps, world_cam, ev_map, settings)
    floor = max(map(_weight, cands)) + math.log(settings.tie_score_ratio)
    rivals = [
        c
        for c in score_hypotheses(hyps, world_cam, ev_map, settings)
        if _weight(c) >= floor and _plausible(c)
    ]
    rivals = _apart(rivals, cands, settings)
    for c in rivals:
        c.log_prior_odds = odds
        c.rival = RIVAL_BEARING
    return rivals


def _plausible(c: Candidate) -> bool:
    """No flag of ``c`` says the map finds its car implausible (:data:`_IMPLAUSIBLE`)."""
    return not ({f.kind for f in c.flags} & _IMPLAUSIBLE)


def _apart(
    rivals: list[Candidate], cands: list[Candidate], settings: LocateSettings
) -> list[Candidate]:
    """The ``rivals`` that stand more than the tie distance from every one of ``cands``: a
    rival within it is the same answer at the accuracy the tie rule asks (it names no tie),
    and kept, it moved the weights of the candidates it stood by (three right one-reference
    answers of ``absolute_slips.py``'s held-out-2 ``control_bearing`` flipped, within their
    ties, to a reading 48-76 m off; left out, two of them no longer do)."""
    if not rivals or not cands:
        return rivals
    here = np.array([c.east_north for c in cands], dtype=float)
    out = []
    for r in rivals:
        gap = np.hypot(*(here - r.east_north).T)
        if float(gap.min()) > settings.tie_distance_m:
            out.append(r)
    return out


RIVAL_BEARING = "map bearing"
"""``Candidate.rival`` of a reading along another street of the map than the stated bearing."""


NEIGHBOUR_BUILDING_PRIOR = 0.1
"""The prior odds of a named landmark being a neighbouring named building's corner."""


def _neighbour_building_candidates(
    cands: list[Candidate], world_cam: Camera, ev: Evidence, settings: LocateSettings
) -> list[Candidate]:
    """Named landmarks read as a neighbouring building's, one at a time (odds
    :data:`NEIGHBOUR_BUILDING_PRIOR`), in scenes whose only evidence is landmarks: crowds
    name a landmark by the building next to it. (Tried only where every landmark candidate
    fitted poorly or stood implausibly on the map, it found half as many: the wrong
    building's corners fit some placement as well.)"""
    if not ev.landmarks or ev.corners or ev.refs:
        return []
    if not any(c.method == "landmark" for c in cands):
        return []
    odds = math.log(NEIGHBOUR_BUILDING_PRIOR)
    out = []
    for ev_alt, note in landmark_alternatives(ev):
        ev_alt.substitution = note
        hyps = landmark_hypotheses(ev_alt, settings)
        for h in hyps:
            h.log_prior += odds
        scored = score_hypotheses(hyps, world_cam, ev_alt, settings)
        if scored:
            # The best reading of each neighbour only: all of them crowded right candidates
            # of the named buildings out of the first max_candidates (absolute.py --n 200:
            # landmark closest < 10 m 91 -> 88 %).
            out.append(max(scored, key=lambda c: c.log_likelihood + math.log(max(c.prior, 1e-300))))
    return out


REFERENCE_CORNER_PRIOR = 0.2
"""The prior odds of a reference on a kerb corner being another corner of its junction."""


def _reference_corner_candidates(
    world_cam: Camera, ev: Evidence, settings: LocateSettings
) -> list[Candidate]:
    """Two references, one on a modelled kerb corner read as each other corner of its
    junction (odds :data:`REFERENCE_CORNER_PRIOR`;
    :func:`~camloc_geo.absolute._evidence.reference_corner_alternatives`). Kept always: the
    pair's scale and the map (the car on its street, along it) weigh them against the
    stated corner; one that fits as well ties with it instead of the stated one being
    answered alone."""
    odds = math.log(REFERENCE_CORNER_PRIOR)
    out: list[Candidate] = []
    for ev_alt, note in reference_corner_alternatives(ev):
        ev_alt.reference_substitution = note
        hyps = _gen_references(ev_alt, settings)
        for h in hyps:
            h.log_prior += odds
        out += _keep_odds(score_hypotheses(hyps, world_cam, ev_alt, settings), odds)
    return out


def _warn_reference_corner(result: LocateResult) -> None:
    """Warn when the best candidate reads a reference as another kerb corner."""
    if not result.candidates:
        return
    ev = result.candidates[0].evidence
    if ev is None or ev.reference_substitution is None:
        return
    result.warnings.append(
        f"references: the best candidate reads {ev.reference_substitution}: the pair fits "
        "the picture and the map better so; is the stated lat/lon another corner's? Check it"
    )


def _warn_substituted_landmark(result: LocateResult) -> None:
    """Warn when the best candidate reads a landmark as a neighbouring building's."""
    if not result.candidates:
        return
    ev = result.candidates[0].evidence
    if ev is None or ev.substitution is None:
        return
    result.warnings.append(
        f"landmarks: the best candidate reads {ev.substitution} (a neighbouring building): "
        "its corners fit where the named building's do not; check the landmark's name"
    )


_IMPLAUSIBLE = {
    FlagKind.CAR_OFF_STREET,
    FlagKind.CAR_NOT_PARALLEL_TO_STREET,
    FlagKind.INSIDE_BUILDING,
}


_REFERENCE_MISS_M2 = 16.0
"""A reference the best candidate misses by more than 4 standard deviations (squared) is
named as the one to check when that candidate trusts the other reference alone."""

_CAR_FLAGS = {FlagKind.CAR_OFF_STREET, FlagKind.CAR_NOT_PARALLEL_TO_STREET}


BESIDE_STREET_M = 6.0
"""A car off every modelled carriageway by at most this (metres beyond a street's half width)
and along that street (:data:`BESIDE_STREET_DEG`) stands beside it: parked, or the map's width
estimate too narrow."""

BESIDE_STREET_DEG = 15.0
"""How far from a street's direction a car beside it may point, degrees."""


def car_beside_street(cand: Candidate, ev: Evidence) -> bool:
    """The candidate's car, off every modelled carriageway, stands beside one, along it.

    Clean two-reference scenes were warned of a car "off any street" for cars 2.5-5 m beyond
    the modelled carriageway and parallel to it (7 of 117, ``benchmarks/absolute_slips.py``):
    street widths are estimates and cars park at the kerb. A wrong reference moves the car
    tens of metres and turns it (28-89 degrees off the nearest street in 25 of the 26 wrong
    tops flagged so).
    """
    streets = ev.streets
    if streets is None or streets.tree is None:
        return False
    import shapely

    xy = cand.enu_from_world.apply(np.asarray(ev.car_center_world, dtype=float))
    reach = BESIDE_STREET_M + 25.0
    box = shapely.box(xy[0] - reach, xy[1] - reach, xy[0] + reach, xy[1] + reach)
    idx = streets.tree.query(box)
    if not len(idx):
        return False
    lines = streets.tree.geometries[idx]
    pt = shapely.points(xy[0], xy[1])
    near = shapely.distance(lines, pt) - streets.values_array[idx] <= BESIDE_STREET_M
    if not near.any():
        return False
    lines = lines[near]
    s = shapely.line_locate_point(lines, pt)
    length = shapely.length(lines)
    a = shapely.get_coordinates(shapely.line_interpolate_point(lines, np.maximum(0.0, s - 5.0)))
    b = shapely.get_coordinates(shapely.line_interpolate_point(lines, np.minimum(length, s + 5.0)))
    street_deg = np.degrees(np.arctan2(b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]))
    diff = np.abs((car_bearing_deg(cand.enu_from_world) - street_deg + 90.0) % 180.0 - 90.0)
    return bool(np.any(diff <= BESIDE_STREET_DEG))


def _car_where(kinds: set[FlagKind]) -> str | None:
    """Where the car flags put the car, for a warning: ``across its street``, ``off any
    street``, or None without a car flag."""
    if not kinds:
        return None
    return "across its street" if FlagKind.CAR_NOT_PARALLEL_TO_STREET in kinds else "off any street"


def _warn_references_off_street(cands: list[Candidate], ev: Evidence, result: LocateResult) -> None:
    """Warn when two references alone put the car off or across its street.

    Two references fix a camera exactly whatever their lat/lon, so a wrong one (another
    point's, rounded to 4 decimals) moves the answer tens of metres with a small sigma and
    no misfit. The map is the only witness left: the car of a real camera stands on a street,
    along it. A car beside its street, along it, is no contradiction
    (:func:`car_beside_street`). Measured (``benchmarks/absolute_slips.py --n 120``): 1 of 117
    clean two-reference scenes gets a reference warning (8 before the beside-street test).
    """
    if len(ev.refs) != 2 or ev.corners or ev.landmarks or not cands:
        return
    top = cands[0]
    if top.method not in ("one_reference", "two_references"):
        return
    kinds = {f.kind for f in top.flags} & _CAR_FLAGS
    if kinds == {FlagKind.CAR_OFF_STREET} and car_beside_street(top, ev):
        kinds = set()  # beside its street, along it: no contradiction (see car_beside_street)
    if top.method == "one_reference" and not kinds:
        worst = max(
            (m for m in top.matches if m.kind == "reference"),
            key=lambda m: m.misfit_m,
            default=None,
        )
        if worst is not None and worst.mahalanobis2 > _REFERENCE_MISS_M2:
            result.warnings.append(
                f"references: the best candidate trusts one reference alone, with the car "
                f"along a street: {worst.label} lies {worst.misfit_m:.0f} m from where it puts "
                "that pixel; check that reference's lat/lon (another point's, rounded, "
                "swapped?)"
            )
        return
    where = _car_where(kinds)
    if where is None:
        return
    result.warnings.append(
        f"references: the two references put the car {where}; if the car does stand on a "
        "street, along it, one reference's lat/lon is wrong (another point's, rounded, "
        "swapped): check both, or add a third; the one_reference candidates trust each "
        "alone"
    )


REFERENCE_SLIP_M = 3.0
"""A reference's lat/lon this far off is an ordinary slip (a click on the kerb for a point on
the centre line, half a lane, a lat/lon rounded to 4 decimals): what the fragile-references
warning moves a reference by."""
WRONG_M = 15.0
"""A camera moved farther than this stands somewhere else (the benchmarks' wrong answer)."""


def rounding_m(lat: float, lon: float, max_decimals: int = 4) -> float:
    """How far a lat/lon given with at most ``max_decimals`` decimals may lie from the point
    it rounds, metres: half its last step in latitude and in longitude, together (the
    diagonal); 0 for a lat/lon with more decimals.

    A precise lat/lon has 4 decimals or fewer in both numbers about once in 10^8 draws; a
    rounded one (copied from a listing, typed short) is up to 5.6 m off in latitude at 4,
    and 5.6 m times cos(lat) in longitude.
    """
    east_m, north_m = rounding_steps_m(lat, lon, max_decimals)
    return float(math.hypot(east_m, north_m))


def rounding_steps_m(lat: float, lon: float, max_decimals: int = 4) -> tuple[float, float]:
    """Half the last step of a lat/lon given with at most ``max_decimals`` decimals, east and
    north (metres): the box around it where the point it rounds lies; ``(0, 0)`` for a
    lat/lon with more decimals (:func:`rounding_m` is its diagonal)."""
    for k in range(max_decimals + 1):
        scale = 10.0**k
        if all(abs(v * scale - round(v * scale)) < 1e-6 for v in (lat, lon)):
            half_m = 0.5 / scale * 111_320.0
            return float(half_m * math.cos(math.radians(lat))), float(half_m)
    return 0.0, 0.0


ROUNDING_TURN_FREE_DEG = 5.0
"""How far a real car may point off the map's street under it (parked askew, the map's
centre line a few degrees off) before the turn says the references turned the camera."""
ROUNDING_TURN_SIGMA_DEG = 5.0
"""Beyond :data:`ROUNDING_TURN_FREE_DEG`, a turn of this many degrees counts one standard
deviation against a reading of a rounded reference (:func:`_rounding_moves_m`)."""
ROUNDING_GRID = 7
"""Points per axis over a rounded reference's box (:func:`_rounding_moves_m`)."""
ROUNDING_CHI2_GAIN = 6.0
"""A reading of a rounded reference within its box that fits the two references' distance
apart and the car's street this much better (chi-square) than the rounded lat/lon itself
says the rounding moved the answer (:func:`_warn_fragile_references`)."""


@dataclass
class RoundingMoves:
    """How the rounding of two references' lat/lon moves a two-reference candidate
    (:func:`_rounding_moves_m`), metres: ``rms`` and ``most`` over the rounding boxes, and
    ``moved``, how far the reading that fits best within them stands from the answer, with
    ``gain`` (how much better it fits, chi-square) and the reference it moves (``label``)."""

    rms: float
    most: float
    moved: float
    gain: float
    label: str


def _reference_index(obs: Observation) -> int | None:
    """The scene's index of a reference observation (its label ``references[i]``)."""
    head, _sep, tail = obs.label.partition("[")
    if head != "references" or not tail.endswith("]") or not tail[:-1].isdigit():
        return None
    return int(tail[:-1])


def _rounding_moves_m(
    cand: Candidate, scene: Scene, ev: Evidence, settings: LocateSettings
) -> RoundingMoves | None:
    """How far the rounding of the references' lat/lon moves a two-reference candidate, None
    when neither is rounded (:func:`rounding_steps_m`).

    A lat/lon with 4 decimals or fewer stands for any point of a box of its half steps. Two
    references fix the camera exactly (up to the fit's 5 % scale prior), so each point of a
    rounded reference's box gives its own camera: the similarity that carries the two
    references' ground points (as the calibrated camera casts their pixels) onto that point
    and the other reference, computed exactly on a :data:`ROUNDING_GRID` square grid over the
    box (the camera turns about the other reference, and far from it moves much more than
    linearly). ``rms`` and ``most`` are the cameras' moves from the one at the rounded
    lat/lon over the grid (uniform), both references' boxes in turn.

    Two witnesses tell the points of a box apart: the references' distance apart on the map
    against the ground (the calibration's scale, 5 %, and the pixels' noise), and the car,
    which stands along its street (:func:`~camloc_geo.absolute._scoring.street_angle_under_car`;
    :data:`ROUNDING_TURN_FREE_DEG` free, then :data:`ROUNDING_TURN_SIGMA_DEG` per sigma).
    ``moved`` is how far the camera of the best-fitting point stands from the one at the
    rounded lat/lon, ``gain`` how much better that point fits (chi-square): what the rounding
    moved, as far as the map and the pixels can tell.
    """
    if len(ev.refs) != 2 or len(scene.references) < 2:
        return None
    pts = [np.asarray(q, dtype=float) for _o, q in ev.refs]
    world = [np.asarray(o.world_xy, dtype=float) for o, _q in ev.refs]
    cam_w = complex(*np.asarray(cand.enu_from_world.inverse().apply(cand.east_north), float))
    ground_m = float(np.linalg.norm(world[0] - world[1]))
    if not math.isfinite(ground_m) or ground_m <= 0.0:
        return None
    u = (world[0] - world[1]) / ground_m
    (oa, _qa), (ob, _qb) = ev.refs
    var = float(u @ (oa.cov_world + ob.cov_world) @ u) + oa.sigma_map_m**2 + ob.sigma_map_m**2
    sq: list[float] = []
    most = 0.0
    best: RoundingMoves | None = None
    t = np.linspace(-1.0, 1.0, ROUNDING_GRID)
    centre = ROUNDING_GRID * ROUNDING_GRID // 2
    mid_w = 0.5 * (complex(*world[0]) + complex(*world[1]))
    dw = complex(*world[0]) - complex(*world[1])
    for k in (0, 1):
        obs_k = ev.refs[k][0]
        i = _reference_index(obs_k)
        if i is None or i >= len(scene.references):
            continue
        east_m, north_m = rounding_steps_m(scene.references[i].lat, scene.references[i].lon)
        if east_m <= 0.0:
            continue
        box = (t[:, None] * east_m + 1j * t[None, :] * north_m).ravel()
        qs = [complex(*pts[0]) + (box if k == 0 else 0.0), complex(*pts[1]) + (box if k else 0.0)]
        dq = np.asarray(qs[0] - qs[1], dtype=complex)
        mid_q = 0.5 * (qs[0] + qs[1])
        ln_s, misfit2 = _scaled_fit(abs(dw), np.abs(dq), var, settings.scale_sigma_rel)
        ratio = np.exp(ln_s) * dq / np.abs(dq) * abs(dw) / dw  # scale · e^{iθ}
        cams = mid_q + ratio * (cam_w - mid_w)
        moves = np.abs(cams - cams[centre])
        sq += (moves**2).tolist()
        most += float(moves.max())
        shift = mid_q - ratio * mid_w
        sims = [
            Similarity2D(float(np.angle(r)), np.array([c.real, c.imag]), float(abs(r)))
            for r, c in zip(ratio, shift, strict=True)
        ]
        turns = street_angles_under_car(sims, ev)
        excess = np.array(
            [0.0 if a is None else max(0.0, abs(a) - ROUNDING_TURN_FREE_DEG) for a in turns]
        )
        chi2 = misfit2 + (excess / ROUNDING_TURN_SIGMA_DEG) ** 2
        j = int(np.argmin(chi2))
        here = RoundingMoves(0.0, 0.0, float(moves[j]), float(chi2[centre] - chi2[j]), obs_k.label)
        if best is None or here.gain > best.gain:
            best = here
    if best is None:
        return None
    # the boxes' moves add as independent variances, each the mean over its grid
    best.rms = math.sqrt(float(np.sum(sq)) / (ROUNDING_GRID * ROUNDING_GRID))
    best.most = most
    return best


def _scaled_fit(
    ground_m: float, map_m: FloatArray, var_m2: float, scale_sigma_rel: float
) -> tuple[FloatArray, FloatArray]:
    """The two-reference fit's log scale and its chi-square, per map distance apart: the
    references' distance apart on the ground (``ground_m``, as the calibrated camera casts
    their pixels) scaled by ``s`` against the map's (``map_m``, variance ``var_m2`` of the
    difference), with the fit's prior on ``ln s`` (``scale_sigma_rel``). The rotation fits
    exactly and the translation matches the midpoints, so this one number is the fit's;
    Newton's method on ``ln s`` from 0."""
    sig2 = max(scale_sigma_rel, 1e-6) ** 2
    v = max(var_m2, 1e-12)
    ln_s = np.zeros_like(map_m, dtype=float)
    for _ in range(8):
        g = ground_m * np.exp(ln_s)
        grad = 2.0 * (g - map_m) * g / v + 2.0 * ln_s / sig2
        hess = 2.0 * g * (2.0 * g - map_m) / v + 2.0 / sig2
        ln_s = ln_s - grad / np.maximum(hess, 1e-12)
    g = ground_m * np.exp(ln_s)
    return ln_s, (g - map_m) ** 2 / v + ln_s**2 / sig2


def _add_rounding_sigma(
    scene: Scene, ev: Evidence, settings: LocateSettings, result: LocateResult
) -> None:
    """The rounding of rounded references' lat/lon added to the ``sigma_m`` of two-reference
    candidates, in place, in quadrature: half the camera's farthest move over the rounding
    boxes (:func:`_rounding_moves_m`), so that two ``sigma_m`` reach the box's worst corner.

    A lat/lon with 4 decimals is a box 11 m by 11 m cos(lat), not a point measured to 0.5 m,
    and far from the other reference the camera moves much more than linearly with it: the
    rms over the box (uniform) left a camera 22 m off at a ``sigma_m`` of 10 m
    (``absolute_slips.py --set held-out-2`` scene 57, the point near the box's corner).
    """
    if len(ev.refs) != 2 or ev.corners or ev.landmarks:
        return
    for cand in result.candidates:
        if cand.method != "two_references" or cand.sigma_m is None:
            continue
        got = _rounding_moves_m(cand, scene, ev, settings)
        if got is not None and got.most > 0.0:
            cand.sigma_m = math.hypot(cand.sigma_m, 0.5 * got.most)


def _warn_fragile_references(
    scene: Scene, ev: Evidence, settings: LocateSettings, result: LocateResult
) -> None:
    """Warn when two references alone leave the answer fragile: one reference's lat/lon
    :data:`REFERENCE_SLIP_M` off across their baseline would move the camera farther than
    :data:`WRONG_M` and than two of its ``sigma_m``.

    Two references fix the camera exactly; their distance apart is the only check on them
    (``references[0] and references[1] disagree``), and it cannot see a slip across their
    baseline. Such a slip turns the camera about the other reference by slip / baseline, so
    the camera moves by about slip x (its distance from that reference) / baseline: a lever
    of 5-13 turned 3-8 m slips (a pixel on the kerb for a lat/lon on the centre line, four
    decimals) into answers 18-74 m off with sigmas of 4-10 m (``benchmarks/absolute_slips.py``,
    session 38). The warning says how far and what would hold the answer.

    A reference whose lat/lon has 4 decimals or fewer (:func:`rounding_m`) stands for a box,
    not a point: its move is in ``sigma_m`` (:func:`_add_rounding_sigma`), and its own warning
    fires only where a point of the box that fits the references' distance apart and the
    car's street better (by :data:`ROUNDING_CHI2_GAIN`) moves the camera beyond
    :data:`WRONG_M` (:func:`_rounding_moves_m`): what the rounding did move, as far as the
    pixels and the map can tell. Until stop 40 the rounding's half diagonal was taken as the
    slip, and the warning fired on 61 of 120 rounded development scenes, 59 of them right.

    A ``one_reference`` top (the pair's joint fit put the car off or across its street, or
    they disagree, so each was tried alone) gets the same lever test, worded for it: two
    references that close cannot tell that reading from the street's other readings either
    (stop 42: ``absolute_slips.py --set held-out-5`` scene 113, a reading 34 m off at a
    ``sigma_m`` of 7 m, untied, had no warning).
    """
    if len(ev.refs) != 2 or ev.corners or ev.landmarks or not result.candidates:
        return
    top = result.candidates[0]
    if top.method not in ("two_references", "one_reference"):
        return
    (_o0, q0), (_o1, q1) = ev.refs
    a, b = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    baseline = float(np.linalg.norm(a - b))
    if not math.isfinite(baseline) or baseline <= 0.0:
        return
    cam = top.east_north
    lever = max(float(np.linalg.norm(cam - a)), float(np.linalg.norm(cam - b))) / baseline
    sigma = top.sigma_m if top.sigma_m is not None else 0.0
    moves = _rounding_moves_m(top, scene, ev, settings) if top.method == "two_references" else None
    if moves is not None and moves.most > WRONG_M:
        # the rounding is in sigma_m; say so only where the pixels and the car's street
        # say that it moved the answer beyond WRONG_M
        if moves.moved > WRONG_M and moves.gain > ROUNDING_CHI2_GAIN:
            result.warnings.append(
                f"references: {moves.label}'s lat/lon has 4 decimals or fewer, a box, not a "
                f"point: a point within it fits the references' distance apart and the car's "
                f"street better and moves the camera {moves.moved:.0f} m (up to "
                f"{moves.most:.0f} m within the box; sigma_m {sigma:.0f} m includes the "
                "rounding); give the lat/lon with 5 decimals or more, or add a kerb corner"
            )
        return
    slip = max(REFERENCE_SLIP_M, _half_carriageway_m(ev, a), _half_carriageway_m(ev, b))
    move = slip * lever
    if move <= max(WRONG_M, 2.0 * sigma):
        return
    if top.method == "one_reference":
        result.warnings.append(
            f"references: the best candidate trusts one reference alone, with the car along "
            f"a street, and the two references are {baseline:.0f} m apart and the camera "
            f"{lever * baseline:.0f} m from the farther: one reference's lat/lon {slip:.0f} m "
            "off across them (a pixel on the kerb for a point on the centre line, a rounded "
            f"lat/lon) would move their joint fit about {move:.0f} m, beyond its sigma_m, so "
            "they cannot tell the car's readings apart; check both, or add a reference farther "
            "apart, a kerb corner or a landmark"
        )
        return
    result.warnings.append(
        f"references: the two references are {baseline:.0f} m apart and the camera "
        f"{lever * baseline:.0f} m from the farther: one reference's lat/lon "
        f"{slip:.0f} m off across them (a pixel on the kerb for a point on the centre line, "
        "a rounded lat/lon) would move the camera about "
        f"{move:.0f} m, beyond its sigma_m; check both, or add a reference farther apart, "
        "a kerb corner or a landmark"
    )


def _half_carriageway_m(ev: Evidence, point_en: FloatArray) -> float:
    """Half the widest carriageway (the map's, metres) whose centre line ``point_en`` lies
    on (within a quarter of the carriageway's width), 0 where none: how far a pixel on the
    kerb lies from a lat/lon taken on that street's centre line, as maps draw streets. A
    wide avenue's carriageway is wider than the 3 m of :data:`REFERENCE_SLIP_M` (stop 39: a
    reference at a dual carriageway's junction 3.3 m across its street put the camera 33 m
    off, unwarned, on ``benchmarks/absolute_slips.py --set held-out``'s ``reference_kerb``).
    A lat/lon near a kerb (a kerb corner's) is no centre-line point: 0."""
    if ev.streets is None or ev.street_tree is None:
        return 0.0
    import shapely

    pt = shapely.Point(float(point_en[0]), float(point_en[1]))
    idx = ev.street_tree.query(pt.buffer(30.0))
    if not len(idx):
        return 0.0
    half = ev.streets.values_array[idx]
    d = shapely.distance(ev.street_tree.geometries[idx], pt)
    inside = half[d <= 0.5 * half]
    return float(inside.max()) if len(inside) else 0.0


def _warn_landmarks_off_street(ev: Evidence, result: LocateResult) -> None:
    """Warn when landmarks alone put the best candidate's car off or across its street.

    A landmark named by the wrong building (its neighbour's name, a shop that moved) is
    matched at its word: the camera lands where that building stands, tens of metres off,
    with a small sigma. The map is the witness, as for two references
    (:func:`_warn_references_off_street`): a real car stands on a street, along it; one
    beside its street, along it, is no contradiction (:func:`car_beside_street`). Measured
    on ``benchmarks/absolute_slips.py`` (session 38, dev runs): of 37 landmark tops whose car
    stands off or across its street, 33 were more than 15 m off.
    """
    if not ev.landmarks or ev.refs or ev.corners or not result.candidates:
        return
    top = result.candidates[0]
    if top.method not in ("landmark", "one_landmark"):
        return
    where = _top_car_where(top, ev)
    if where is None:
        return
    result.warnings.append(
        f"landmarks: the best candidate puts the car {where}; if the car does stand on a "
        "street, along it, a landmark is named wrong (the building next to it, a name that "
        "moved) or its pixel is not that building's corner: check the names, or add a "
        "reference"
    )


def _top_car_where(top: Candidate, ev: Evidence) -> str | None:
    """Where a candidate's car stands against its street, in words, when the map contradicts
    it (off or across its street); None when it stands on or beside its street, along it."""
    kinds = {f.kind for f in top.flags} & _CAR_FLAGS
    if kinds == {FlagKind.CAR_OFF_STREET} and car_beside_street(top, top.evidence or ev):
        return None
    return _car_where(kinds)


def _warn_corners_car_off_street(ev: Evidence, result: LocateResult) -> None:
    """Warn when kerb corners alone put the best candidate's car off or across its street.

    The map's witness, as for landmarks (:func:`_warn_landmarks_off_street`): a corner
    clicked where the centre lines cross can fit a wrong placement whose car stands across
    its street, 80 m off with a sigma of 4 m, unwarned (``benchmarks/absolute_slips.py
    --n 120``, ``corner_centreline``). Until stop 39 the scene maker put cars beside dual
    carriageways, and 6 of 89 right clean answers had their car so flagged; with cars in
    their carriageway, 1 of 91, and the warning fires on none of the 120 clean corner runs.
    """
    if not ev.corners or ev.refs or ev.landmarks or not result.candidates:
        return
    top = result.candidates[0]
    if top.method != "corners" or top.ambiguous_with:
        return
    where = _top_car_where(top, ev)
    if where is None:
        return
    result.warnings.append(
        f"corners: the best candidate puts the car {where}; if the car does stand on a "
        "street, along it, the corners are read wrong (one clicked off its kerb corner, "
        "listed in another order, another junction's?): check the corners, or add a "
        "reference"
    )


def _forget_placements(ev: Evidence, cands: list[Candidate]) -> None:
    """Empty the placement memos of the evidence the result keeps (its candidates'): they
    serve one run of :func:`locate`, and would hold every placement tried (~100 per scene)
    for as long as the result lives."""
    for e in {id(e): e for e in [ev, *(c.evidence for c in cands)] if e is not None}.values():
        e.placement_memo.clear()
        e.observation_table = None


def _other_junction_candidates(
    scene: Scene,
    map_data: MapData | None,
    world_cam: Camera,
    ev: Evidence,
    settings: LocateSettings,
    result: LocateResult,
    named_cands: list[Candidate],
) -> list[Candidate]:
    """Corner hypotheses at the other junctions the scene may show, scored with their
    prior odds (:func:`~camloc_geo.absolute._evidence.other_junctions`).

    ``named_cands``: the candidates at the scene's own junction. The junctions where only
    some of the named streets meet count only when one of their candidates outweighs every
    candidate at a named junction (prior odds included): kept always, a same-shaped
    neighbour tied with the sample scene's right candidate at odds of 9 to 1 and tripled its
    candidates; tried only when no named candidate was plausible, they found a tenth of the
    wrong cross streets.
    """
    if ev.junction_search:
        return _searched_junction_candidates(map_data, world_cam, ev, settings, result)
    others = other_junctions(scene, map_data, ev)
    if not others:
        return _rough_point_candidates(
            scene, map_data, world_cam, ev, settings, result, named_cands
        )
    assert map_data is not None
    out: list[Candidate] = []
    # The junctions as likely as the scene's own first; then the neighbours (where only
    # some of the named streets meet), kept only when one of them beats every candidate at
    # a named junction, its prior odds included.
    for inter, log_prior in others:
        if log_prior < 0.0:
            continue
        ev_j = evidence_at(ev, inter, map_data, result.frame, settings)
        out += score_hypotheses(corner_hypotheses(ev_j, settings), world_cam, ev_j, settings)
    neighbours: list[Candidate] = []
    for inter, log_prior in others:
        if log_prior >= 0.0:
            continue
        ev_j = evidence_at(ev, inter, map_data, result.frame, settings)
        hyps = corner_hypotheses(ev_j, settings)
        for h in hyps:
            h.log_prior += log_prior
        neighbours += score_hypotheses(hyps, world_cam, ev_j, settings)
    named = [*named_cands, *out]
    if neighbours and (not named or max(map(_weight, neighbours)) > max(map(_weight, named))):
        out += neighbours
    elif neighbours:
        out += _rival_neighbours(neighbours, named, settings)
    hint = scene.intersection
    n_equal = sum(1 for _x, lp in others if lp == 0.0)  # as likely as the scene's own
    if scene.prior is not None and hint is not None and hint.lat is None and n_equal:
        one = hint.streets or []
        along = f" along {one[0]!r}" if len(one) == 1 else ""
        more = "a second street name" if along else "street names"
        result.warnings.append(
            f"corners: no intersection lat/lon in the scene, so the corners were matched at "
            f"the {n_equal + 1} junctions{along} with kerb corners within "
            f"{scene.prior.radius_m:g} m of the prior; give intersection.lat/lon (or {more}) "
            "to fix the junction"
        )
    return out


def _rival_neighbours(
    neighbours: list[Candidate], named: list[Candidate], settings: LocateSettings
) -> list[Candidate]:
    """The candidates at junctions where only some of the named streets meet that come within
    the tie rule's odds of the best candidate at a named junction, their prior odds
    (:data:`~camloc_geo.absolute._evidence.NEIGHBOUR_JUNCTION_PRIOR`) in and kept through
    refinement (:func:`_keep_odds`).

    A same-shaped junction a block away, where the named street meets another cross street,
    fits the corners as well as the named one: named by the cross street a block away
    (``benchmarks/absolute_slips.py``'s ``wrong_cross_street``), the answer stood at the named
    junction alone, 54-94 m off, sure of itself, because a neighbour was kept only when it
    outweighed every named candidate. Kept as a rival at its odds (0.2, above the tie rule's
    0.1), one that fits at least half as well is named tied with the top; one that fits
    worse is left out, as before, so that a named junction whose corners fit alone keeps its
    answer and its candidate list.
    """
    best = max(map(_weight, named))
    floor = best + math.log(settings.tie_score_ratio)
    rivals = _apart([c for c in neighbours if _weight(c) >= floor], named, settings)
    for c in rivals:
        c.log_prior_odds = math.log(NEIGHBOUR_JUNCTION_PRIOR)
        c.rival = RIVAL_NEIGHBOUR
    return rivals


RIVAL_NEIGHBOUR = "neighbour junction"
"""``Candidate.rival`` of a junction where only some of the named streets meet."""

RIVAL_WARN_FIT = 1.0 / 3.0
"""A rival junction (:func:`_rival_neighbours`) whose best candidate's fit, its prior odds
left out, is at least this share of the top candidate's is a warning when the tie rule does
not name it: at its odds of 0.2 it then stands within 15 to 1 of the top, where the tie rule
asks for 10 to 1. On ``absolute_slips.py``'s development control (``control_streets``, the
streets named right) the untied right answers so warned were 7 of 90 at a share of 0.1 and 4
at a third; the wrong answers the warning catches fit 0.43-0.5 as well."""


def _warn_rival_neighbour(
    map_data: MapData | None, settings: LocateSettings, result: LocateResult
) -> None:
    """Warn when a same-shaped junction where only some of the named streets meet fits the
    corners nearly as well as the top candidate's and is not named tied with it.

    The tie rule weighs the rival at its prior odds (0.2): one that fits a third as well
    stands at 0.07 of the top, under the rule's 0.1, and the answer, 63 m off at the junction
    of the named cross street a block away, said nothing (``absolute_slips.py --set
    held-out-3``, ``wrong_cross_street``).
    """
    cands = result.candidates
    if map_data is None or len(cands) < 2 or cands[0].rival is not None:
        return
    top = cands[0]
    if any(c.rival == RIVAL_NEIGHBOUR and c.rank in top.ambiguous_with for c in cands):
        return  # named tied with the top: the tie's words say it
    rivals = [
        c
        for c in cands[1:]
        if c.rival == RIVAL_NEIGHBOUR and c.intersection_id != top.intersection_id
    ]
    if not rivals:
        return
    best = max(rivals, key=lambda c: c.score)
    fit = best.score / max(top.score, 1e-300) / NEIGHBOUR_JUNCTION_PRIOR
    if fit < RIVAL_WARN_FIT or best.intersection_id is None:
        return
    there = map_data.intersection(best.intersection_id)
    gap = float(np.linalg.norm(best.east_north - top.east_north))
    result.warnings.append(
        f"intersection: junction {there.id} ({' & '.join(there.street_names)}), where only "
        f"some of the named streets meet, fits the corners {fit:.2f} times as well as the "
        f"answer's junction (candidate {best.rank}, {gap:.0f} m from the best): a cross "
        "street a block away, of the same shape? Check the cross street's name, or give "
        "the junction's lat/lon"
    )


def _searched_junction_candidates(
    map_data: MapData | None,
    world_cam: Camera,
    ev: Evidence,
    settings: LocateSettings,
    result: LocateResult,
) -> list[Candidate]:
    """Corner hypotheses at the junctions searched around a stated lat/lon that matched
    none (:func:`~camloc_geo.absolute._evidence.latlon_search`), each at its prior odds
    (falling with its distance from the stated point); the most likely one is ``ev``'s own,
    scored already. All are kept: the corners' fit and the map decide among them."""
    assert map_data is not None
    out: list[Candidate] = []
    for inter, _d, log_prior in ev.junction_search:
        if ev.intersection is not None and inter.id == ev.intersection.id:
            continue
        ev_j = evidence_at(ev, inter, map_data, result.frame, settings)
        hyps = corner_hypotheses(ev_j, settings)
        for h in hyps:
            h.log_prior += log_prior
        out += _keep_odds(score_hypotheses(hyps, world_cam, ev_j, settings), log_prior)
    return out


ROUGH_POINT_PRIOR = 0.1
"""The prior odds of a junction near a stated intersection lat/lon against the junction
within 25 m of it (:func:`_rough_point_candidates`), before the fall with distance."""

ROUGH_POINT_GATE = 0.5
"""The stated junction fits badly when its best candidate's map plausibility (the factor of
:func:`~camloc_geo.absolute._scoring.plausibility_at`) is under this, or when its matched
points misfit (``poor_fit``). A visible corner left ``unmatched`` does not count: it is what a
corner of a neighbouring junction clicked too gives (``absolute_slips.py``'s
``corner_extra``), and counted, it cost that slip 3 of 84 right top candidates for 3 of 120
rough points."""


def fits_badly(cands: list[Candidate]) -> bool:
    """Whether the best of ``cands`` (by weight) fits the image evidence badly: implausible
    on the map (its car off or across its street, its camera in a building, its corners seen
    through one: plausibility under :data:`ROUGH_POINT_GATE`) or its matched points misfit
    (``poor_fit``). No candidate at all fits badly too."""
    if not cands:
        return True
    best = max(cands, key=_weight)
    return best.prior < ROUGH_POINT_GATE or FlagKind.POOR_FIT in {f.kind for f in best.flags}


def _rough_point_candidates(
    scene: Scene,
    map_data: MapData | None,
    world_cam: Camera,
    ev: Evidence,
    settings: LocateSettings,
    result: LocateResult,
    named_cands: list[Candidate],
) -> list[Candidate]:
    """Corner hypotheses at the junctions around a stated intersection lat/lon that did
    match a junction within 25 m, when that junction fits the image evidence badly
    (:func:`fits_badly`).

    A webcam listing's rough point lands within 25 m of the wrong junction about one time in
    four (``benchmarks/absolute_slips.py``'s ``intersection_latlon_off``). The junctions
    with kerb corners within :data:`~camloc_geo.absolute._evidence.LATLON_SEARCH_M` of the
    point (:func:`~camloc_geo.absolute._evidence.latlon_search`, at most
    :data:`~camloc_geo.absolute._evidence.MAX_SEARCH_JUNCTIONS`) are tried at prior odds
    :data:`ROUGH_POINT_PRIOR`, falling by e per
    :data:`~camloc_geo.absolute._evidence.LATLON_SEARCH_SCALE_M` beyond the stated
    junction's distance; they are kept only when one of them outweighs every candidate at
    the stated junction (their odds included); where no hypothesis fits at the stated
    junction at all (every one ``poor_fit``), only when their best fits well itself (else
    the empty answer and its reason stand: a junction that fits badly too is no answer). A
    warning names the junction used
    (:func:`_warn_other_junction`). A stated junction that fits well is taken at its word,
    as before (``absolute_slips.py``: 11 of 120 clean corner scenes fit their junction
    badly and pay the search; none changes).
    """
    hint = scene.intersection
    if (
        map_data is None
        or hint is None
        or hint.lat is None
        or hint.lon is None
        or ev.intersection is None
        or not ev.corners
    ):
        return []
    if not fits_badly(named_cands):
        _warn_rough_point(scene, map_data, world_cam, ev, settings, result, named_cands)
        return []
    out = _rough_point_alternatives(scene, map_data, world_cam, ev, settings, result)
    if not out:
        return []
    if all(FlagKind.POOR_FIT in {f.kind for f in c.flags} for c in named_cands):
        # nothing fits at the stated junction: its empty answer and reason stand unless a
        # junction around fits well
        return [] if fits_badly(out) else out
    if max(map(_weight, out)) > max(map(_weight, named_cands)):
        return out
    return []


ROUGH_POINT_WARN_M = 10.0
"""A stated intersection lat/lon this far or farther from every node of the junction it
names (and from its centre) is read as possibly rough (:func:`_warn_rough_point`). A point
taken from the map stands on the junction (the benchmarks' clean scenes: 0 m); a webcam
listing's rough point that happens to land within 25 m of a junction, 0-25 m from it."""

ROUGH_POINT_AS_WELL = math.log(10.0)
"""Another junction "fits as well" when its best candidate's fit (likelihood and map
plausibility, its prior odds left out) is within this (log odds of 10 to 1) of the stated
junction's best, and it does not fit badly itself (:func:`fits_badly`)."""


def _warn_rough_point(
    scene: Scene,
    map_data: MapData,
    world_cam: Camera,
    ev: Evidence,
    settings: LocateSettings,
    result: LocateResult,
    named_cands: list[Candidate],
) -> None:
    """Warn when a stated intersection lat/lon off its junction's nodes could be a rough
    point that landed near the wrong junction: another junction around fits as well.

    The stated junction fits well, so it is taken at its word (:func:`_rough_point_candidates`);
    but a rough point (a webcam listing's, 50-150 m off) lands within 25 m of another junction
    about one time in four, and where that junction has the same shape the corners fit it as
    well: the answer was wrong by 90-180 m with no warning (``benchmarks/absolute_slips.py
    --set held-out-2``'s ``intersection_latlon_off``, 4 of 149). Only points at least
    :data:`ROUGH_POINT_WARN_M` from the junction's nodes pay the search.
    """
    hint = scene.intersection
    assert hint is not None
    assert hint.lat is not None
    assert hint.lon is not None
    assert ev.intersection is not None
    own = ev.intersection
    d_own = map_data.distance_to_m(own, lat=hint.lat, lon=hint.lon)
    if d_own < ROUGH_POINT_WARN_M or not named_cands:
        return
    alts = _rough_point_alternatives(scene, map_data, world_cam, ev, settings, result)
    if not alts or fits_badly(alts):
        return
    best_own = max(map(_weight, named_cands))
    best = max(alts, key=lambda c: _weight(c) - c.log_prior_odds)
    if _weight(best) - best.log_prior_odds < best_own - ROUGH_POINT_AS_WELL:
        return
    if best.intersection_id is None:
        return
    there = map_data.intersection(best.intersection_id)
    d_there = map_data.distance_to_m(there, lat=hint.lat, lon=hint.lon)
    result.warnings.append(
        f"intersection: the scene's intersection lat/lon (lat={hint.lat:.6f}, "
        f"lon={hint.lon:.6f}) stands {d_own:.0f} m from junction {own.id} "
        f"({' & '.join(own.street_names)}), not on it, and junction {there.id} "
        f"({' & '.join(there.street_names)}), {d_there:.0f} m from the point, fits the corners "
        "as well; the answer stands at the stated junction. Is the lat/lon a rough point (a "
        "webcam listing's)? Check the junction, or give the junction's own lat/lon or its "
        "street names"
    )


def _rough_point_alternatives(
    scene: Scene,
    map_data: MapData,
    world_cam: Camera,
    ev: Evidence,
    settings: LocateSettings,
    result: LocateResult,
) -> list[Candidate]:
    """The scored corner hypotheses of :func:`_rough_point_candidates` at every junction
    searched around the stated point but the stated one, each at its prior odds."""
    from camloc_geo.absolute._evidence import (
        LATLON_SEARCH_SCALE_M,
        NEIGHBOUR_JUNCTION_PRIOR,
        latlon_search,
    )

    hint = scene.intersection
    assert hint is not None
    assert hint.lat is not None
    assert hint.lon is not None
    assert ev.intersection is not None
    streets = list(hint.streets or []) or None
    found = latlon_search(map_data, hint.lat, hint.lon, streets)
    if not found:
        return []
    own = map_data.distance_to_m(ev.intersection, lat=hint.lat, lon=hint.lon)
    named = {x.id for x in map_data.street_junctions(streets)} if streets else None
    out: list[Candidate] = []
    for inter, d, _lp in found:
        if inter.id == ev.intersection.id:
            continue
        lp = math.log(ROUGH_POINT_PRIOR) - max(0.0, d - own) / LATLON_SEARCH_SCALE_M
        if named is not None and inter.id not in named:
            lp += math.log(NEIGHBOUR_JUNCTION_PRIOR)
        ev_j = evidence_at(ev, inter, map_data, result.frame, settings)
        hyps = corner_hypotheses(ev_j, settings)
        for h in hyps:
            h.log_prior += lp
        out += _keep_odds(score_hypotheses(hyps, world_cam, ev_j, settings), lp)
    return out


def _keep_odds(cands: list[Candidate], log_prior: float) -> list[Candidate]:
    """``cands`` whose prior odds stay in their score once refined
    (:func:`refine_leaders`).

    Only the junctions searched around a stated point and the other-corner readings of a
    reference keep them: kept for every alternative reading, the map's other street
    bearings (``bearing_cross_street``) lost their right top answers (60 -> 17 %) and
    neighbouring buildings theirs (23 -> 7 %), their odds having been set with refinement
    dropping them (``benchmarks/absolute_slips.py --n 120``).
    """
    for c in cands:
        c.log_prior_odds = log_prior
    return cands


def _warn_searched_junction(scene: Scene, ev: Evidence, result: LocateResult) -> None:
    """Name the junction the best candidate stands at, and its distance from the stated
    intersection lat/lon, when that point matched no junction and the junctions around it
    were searched."""
    hint = scene.intersection
    if not ev.junction_search or hint is None or hint.lat is None or hint.lon is None:
        return
    from camloc_geo.absolute._evidence import LATLON_MATCH_M, LATLON_SEARCH_M

    said = f"lat={hint.lat:.6f}, lon={hint.lon:.6f}"
    n = len(ev.junction_search)
    head = (
        f"intersection: no modelled junction within {LATLON_MATCH_M:.0f} m of the scene's "
        f"intersection ({said}); the corners were matched at the {n} junction"
        f"{'s' if n > 1 else ''} with kerb corners within {LATLON_SEARCH_M:.0f} m of it"
    )
    top = result.candidates[0] if result.candidates else None
    where = {x.id: (x, d) for x, d, _lp in ev.junction_search}
    if top is None or top.intersection_id not in where:
        result.warnings.append(f"{head}; check the intersection's lat/lon")
        return
    inter, d = where[top.intersection_id]
    result.warnings.append(
        f"{head}: the best candidate stands at junction {inter.id} "
        f"({' & '.join(inter.street_names)}), {d:.0f} m from the stated point; check the "
        "intersection's lat/lon"
    )


def _warn_outside_prior(ev: Evidence, result: LocateResult) -> None:
    """Warn when the best candidate stands beyond the scene's prior radius.

    Its score paid for it (the prior's Gaussian factor, flag ``outside_prior``), but a flag
    alone says nothing to the user: a rough intersection lat/lon that landed on another
    junction put the answer 148 m off, outside the stated prior, with no warning
    (``benchmarks/absolute_slips.py --set held-out-2``, ``intersection_latlon_off``). A right
    answer stands within the prior whenever the prior is right, so it does not fire on them.
    """
    if not result.candidates or ev.prior_en is None or not ev.prior_radius_m:
        return
    top = result.candidates[0]
    if FlagKind.OUTSIDE_PRIOR not in {f.kind for f in top.flags}:
        return
    d = float(np.linalg.norm(top.east_north - ev.prior_en))
    if d <= ev.prior_radius_m:
        return
    result.warnings.append(
        f"prior: the best candidate stands {d:.0f} m from the scene's prior, beyond its "
        f"radius_m ({ev.prior_radius_m:.0f} m): the other evidence outweighed it; check the "
        "prior, or the evidence that put the camera there (the intersection's lat/lon?)"
    )


def _weight(c: Candidate) -> float:
    """A scored candidate's log weight: its log likelihood (prior odds included) and log
    plausibility."""
    return c.log_likelihood + math.log(max(c.prior, 1e-300))


CORNER_OUTLIER_M2 = 16.0
"""A matched corner of the best candidate this far off (squared standard deviations of the
noise model: 4 sigma) is a warning."""


def _warn_corner_outlier(result: LocateResult) -> None:
    """Warn when the best candidate leaves one matched kerb corner far off its map corner."""
    if not result.candidates:
        return
    worst = max(
        (m for m in result.candidates[0].matches if m.kind == "corner"),
        key=lambda m: m.mahalanobis2,
        default=None,
    )
    if worst is None or worst.mahalanobis2 <= CORNER_OUTLIER_M2:
        return
    result.warnings.append(
        f"{worst.label}: the best candidate puts it {worst.misfit_m:.0f} m from its map corner "
        "(more than 4 standard deviations): clicked off the kerb corner (where the centre "
        "lines cross, across a wide pavement, another junction's)? Check it"
    )


MISCLICK_ODDS = 0.05
"""The prior odds of one listed kerb corner being misclicked (where the centre lines cross,
across a wide pavement, another junction's corner, a T junction's straight far kerb): what
:func:`_warn_one_corner_decides` charges for reading a corner so."""


def _misclick_weight(c: Candidate) -> tuple[float, str | None]:
    """A corners candidate's log weight with its worst-fitting listed corner read as
    misclicked when that fits better (at :data:`MISCLICK_ODDS`), and that corner's label
    (None when reading none so fits better).

    The corner's term is taken out of the weight as it stands (the placement is not refitted
    without it: a lower bound of the leave-one-out fit). A corner left unmatched already
    costs an outlier's share (``OUTLIER_M2``)."""
    w = _weight(c)
    terms = [
        (0.5 * min(m.mahalanobis2, OUTLIER_M2), m.label) for m in c.matches if m.kind == "corner"
    ]
    unmatched = sum(1 for j in (c.corner_assignment or ()) if j < 0)
    if unmatched:
        terms.append((0.5 * OUTLIER_M2, "an unmatched corner"))
    if not terms:
        return w, None
    gain, label = max(terms, key=lambda t: t[0])
    gain += math.log(MISCLICK_ODDS)
    return (w + gain, label) if gain > 0.0 else (w, None)


def _warn_one_corner_decides(ev: Evidence, settings: LocateSettings, result: LocateResult) -> None:
    """Warn when one listed corner decides the answer: read as misclicked, the other corners
    fit a candidate more than :data:`WRONG_M` from the best about as well (within the tie
    ratio, at :data:`MISCLICK_ODDS`).

    Scenes with three or more listed corners only (two leave one: it fits anywhere). At a
    dual carriageway's junction (two corners per side a median apart) a corner clicked where
    the centre lines cross, or across a wide pavement, fits another reading of the junction
    well, 40-60 m off: those answers had no warning (``benchmarks/absolute_slips.py --set
    held-out``, stop 38's `corner_centreline` and `corner_far_pavement` rows)."""
    if len(ev.corners) < 3 or len(result.candidates) < 2:
        return
    top = result.candidates[0]
    if top.method != "corners":
        return
    w_top, _label = _misclick_weight(top)
    floor = w_top + math.log(settings.tie_score_ratio)
    for c in result.candidates[1:]:
        if c.method != "corners":
            continue
        gap = float(np.linalg.norm(c.east_north - top.east_north))
        if gap <= WRONG_M:
            continue
        w, label = _misclick_weight(c)
        if label is None or w < floor:
            continue
        result.warnings.append(
            f"{label}: the answer rests on it: read as misclicked (where the centre lines "
            "cross, across a wide pavement, another junction's corner), the other corners fit "
            f"candidate {c.rank}, {gap:.0f} m from the best, about as well; check it"
        )
        return


def _warn_reversed_corners(result: LocateResult) -> None:
    """Warn when the best candidate reads the visible corners counter-clockwise, or when it
    reads them clockwise but a counter-clockwise reading that fits better (its prior odds
    left out: :func:`_counter_clockwise_candidates` keeps only those) stands elsewhere."""
    if not result.candidates:
        return
    top = result.candidates[0]
    ev = top.evidence
    if ev is None:
        return
    n_map = len(ev.map_corners)
    if is_reversed(top.corner_assignment, n_map):
        result.warnings.append(
            "intersection.corners: the best candidate reads the listed corners "
            "counter-clockwise (they fit the map better that way): the scene lists them "
            "clockwise as seen on screen; check their order"
        )
        return
    if top.method != "corners":
        return
    back = [
        c
        for c in result.candidates[1:]
        if c.evidence is not None
        and is_reversed(c.corner_assignment, len(c.evidence.map_corners))
        and float(np.linalg.norm(c.east_north - top.east_north)) > WRONG_M
    ]
    if not back:
        return
    alt = back[0]
    gap = float(np.linalg.norm(alt.east_north - top.east_north))
    result.warnings.append(
        "intersection.corners: the listed corners fit the map better read counter-clockwise "
        f"(candidate {alt.rank}, {gap:.0f} m from the best); the best reads them clockwise, as "
        "the scene lists them. Check their order (clockwise as seen on screen)"
    )


STATED_BEARING_WARN_DEG = 20.0
"""The best candidate's car this far from the scene's ``street_bearing_deg`` is a warning."""


def _warn_stated_bearing(ev: Evidence, result: LocateResult) -> None:
    """Warn when the best candidate's car does not lie along the stated street bearing."""
    if ev.stated_bearing is None or not result.candidates:
        return
    car = car_bearing_deg(result.candidates[0].enu_from_world) % 180.0
    d = abs((car - ev.stated_bearing + 90.0) % 180.0 - 90.0)
    if d <= STATED_BEARING_WARN_DEG:
        return
    result.warnings.append(
        f"street_bearing_deg: the best candidate puts the car along {car:.0f} degrees (or "
        f"{car + 180.0:.0f}), {d:.0f} degrees from the stated {ev.stated_bearing:g}: the map's "
        "streets fit better; is the stated bearing the cross street's?"
    )


def _warn_other_junction(
    scene: Scene, map_data: MapData | None, ev: Evidence, result: LocateResult
) -> None:
    """Warn when the best candidate stands at a junction the scene did not name."""
    from camloc_geo.absolute._evidence import LATLON_SEARCH_M

    named = named_junctions(scene, map_data, ev)
    if ev.junction_search:
        _warn_searched_junction(scene, ev, result)
        return
    if named is None or not result.candidates:
        return
    top = result.candidates[0]
    if top.intersection_id is None or top.intersection_id in named:
        return
    assert map_data is not None
    there = map_data.intersection(top.intersection_id)
    hint = scene.intersection
    assert hint is not None
    if hint.lat is not None and hint.lon is not None and ev.intersection is not None:
        own = ev.intersection
        d_top = map_data.distance_to_m(there, lat=hint.lat, lon=hint.lon)
        d_own = map_data.distance_to_m(own, lat=hint.lat, lon=hint.lon)
        k, n = len(ev.corners), len(ev.map_corners)
        why = f" (it has {n} kerb corners, the image shows {k})" if k > n else ""
        if why:  # the count warning spoke of every hypothesis; the best stands elsewhere
            result.warnings[:] = [
                w for w in result.warnings if not w.startswith("corners: the scene lists")
            ]
        result.warnings.append(
            f"intersection: the junction at the scene's intersection lat/lon (lat={hint.lat:.6f}, "
            f"lon={hint.lon:.6f}), {own.id} ({' & '.join(own.street_names)}) {d_own:.0f} m "
            f"from it, fits the image badly{why}; the junctions with kerb corners within "
            f"{LATLON_SEARCH_M:.0f} m were tried: the best candidate stands at junction "
            f"{there.id} ({' & '.join(there.street_names)}), {d_top:.0f} m from the stated "
            "point. Is the lat/lon a rough point (a webcam listing's)? Check the best "
            "candidate's junction"
        )
        return
    said = " & ".join(hint.streets or [])
    result.warnings.append(
        f"intersection: the corners fit junction {there.id} ({' & '.join(there.street_names)}) "
        f"better than the scene's own ({said}): is the cross street or the lat/lon of "
        "another junction? Check the best candidate's junction"
    )


def _rescore(
    cand: Candidate,
    world_cam: Camera,
    ev: Evidence,
    settings: LocateSettings,
    log_prior: float,
    *,
    expected: bool = False,
) -> Candidate:
    """The candidate with its likelihood, plausibility, matches and flags (re)computed.

    With ``expected``, the plausibility is averaged over the candidate's position
    uncertainty (:func:`_expected_plausibility`; its ``sigma_m``, else the fit's covariance
    at the candidate).
    """
    return _rescore_many([cand], world_cam, ev, settings, [log_prior], expected=expected)[0]


def _rescore_many(
    cands: list[Candidate],
    world_cam: Camera,
    ev: Evidence,
    settings: LocateSettings,
    log_priors: list[float],
    *,
    expected: bool = False,
) -> list[Candidate]:
    """:func:`_rescore` of several candidates: the plausibility tests of all the candidates
    on one evidence (and of their sigma points, with ``expected``) in one pass."""
    evs = [c.evidence if c.evidence is not None else ev for c in cands]
    fits = [
        score(c.enu_from_world, e, settings, c.corner_assignment)
        for c, e in zip(cands, evs, strict=True)
    ]
    # Each candidate's placements (camera centre, similarity): itself, then (expected) its
    # four sigma points.
    places: list[list[tuple[FloatArray, Similarity2D]]] = []
    for c, e, fit in zip(cands, evs, fits, strict=True):
        here = [(c.camera.center_in_world, c.enu_from_world)]
        if expected:
            sigma = c.sigma_m
            if sigma is None:
                sigma = position_sigma_m(replace(c, matches=fit.matches), world_cam, e, settings)
            if sigma is not None and math.isfinite(sigma) and sigma > 0.0:
                here += _sigma_points(c.enu_from_world, sigma, world_cam)
        places.append(here)
    tests: list[list[tuple[float, list[Flag]]]] = [[] for _ in cands]
    for e_id in dict.fromkeys(id(e) for e in evs):  # one pass per evidence, in order
        mine = [i for i, e in enumerate(evs) if id(e) == e_id]
        got = iter(
            plausibility_at(
                [centre for i in mine for centre, _sim in places[i]],
                [sim for i in mine for _centre, sim in places[i]],
                evs[mine[0]],
                settings,
                [fits[i].matches for i in mine for _place in places[i]],
            )
        )
        for i in mine:
            tests[i] = [next(got) for _place in places[i]]
    out = []
    for c, e, fit, log_prior, (centre, *spread) in zip(
        cands, evs, fits, log_priors, tests, strict=True
    ):
        plaus, flags = centre
        if spread:
            total = plaus / 3.0
            for f, _flags in spread:
                total += f / 6.0
            plaus = total
        flags += unmatched_flags(e, fit.corner_assignment)
        cue_log = 0.0
        if e.has_cues:
            cue_log, cue_flags = _cues(c, e)
            flags += cue_flags
        out.append(
            replace(
                c,
                log_likelihood=fit.log_likelihood + log_prior + cue_log,
                prior=plaus,
                residual_m=fit.residual_m,
                matches=fit.matches,
                flags=flags,
                corner_assignment=fit.corner_assignment,
            )
        )
    return out


SIGMA_POINT_CAP_M = 8.0
"""The position sigma of :func:`_expected_plausibility` is capped at this: its sigma points
then stand at most √3 · 8 / √2 ≈ 10 m out, about a street's width. A larger isotropic spread
would sample the buildings either side of a street that holds the truth, where a candidate
is really uncertain along the street, not across it (measured: a cap of 25 m lost 3 of 57
landmark scenes' right top candidates in dense old towns; 8 m keeps the corner scenes'
gain)."""


def _expected_plausibility(
    plaus_centre: float,
    cand: Candidate,
    sigma_m: float,
    world_cam: Camera,
    ev: Evidence,
    settings: LocateSettings,
    matches: list[Match],
) -> float:
    """The map plausibility averaged over the candidate's position uncertainty.

    A candidate a few metres off with a position sigma of 10 m may stand inside a building,
    see its corners through one and put its car beside the street, where the truth it
    stands for does none of that. The plausibility tests are step functions of the
    position, so their value at the estimate alone over-penalises uncertain candidates:
    this is their expectation over an isotropic Gaussian of ``sigma_m`` (per axis
    ``sigma_m / √2``, capped at :data:`SIGMA_POINT_CAP_M`), by the unscented transform's
    five points (the centre, weight 1/3, and ``±√3`` per-axis sigmas east and north, 1/6
    each). The camera and its car move together (the similarity's translation).
    """
    total = plaus_centre / 3.0
    points = _sigma_points(cand.enu_from_world, sigma_m, world_cam)
    centres, sims = [centre for centre, _s in points], [sim for _c, sim in points]
    for f, _flags in plausibility_at(centres, sims, ev, settings, [matches] * len(points)):
        total += f / 6.0
    return total


def _sigma_points(
    sim: Similarity2D, sigma_m: float, world_cam: Camera
) -> list[tuple[FloatArray, Similarity2D]]:
    """The four outer sigma points of :func:`_expected_plausibility`: the placement moved
    ``±√3`` per-axis sigmas east and north (camera and car together), as (camera centre in
    the local frame, similarity).

    The centre is ``moved.camera(world_cam).center_in_world`` without building the camera
    (the plausibility tests need the centre only): the same products, without the camera's
    ``-Rᵀ(-R c)`` round trip, so equal to within 1e-14 m.
    """
    step = math.sqrt(3.0) * min(sigma_m, SIGMA_POINT_CAP_M) / math.sqrt(2.0)
    Rz = np.eye(3)
    Rz[:2, :2] = sim.rotation
    # Similarity2D.camera's centre: scale · Rz · C + (T, 0); Rz · C is the same for all.
    scaled = sim.scale * Rz @ world_cam.center_in_world
    shifts = np.array([[step, 0.0], [-step, 0.0], [0.0, step], [0.0, -step]])
    T = np.asarray(sim.translation_m) + shifts  # the four translations, row by row
    centres = scaled + np.column_stack([T, np.zeros(4)])
    return [
        (centre, Similarity2D(sim.rotation_rad, t, sim.scale))
        for centre, t in zip(centres, T, strict=True)
    ]


def _cues(cand: Candidate, ev: Evidence) -> tuple[float, list[Flag]]:
    """The scene's tie-breaking cues for one candidate: log factor and ``cue`` flags."""

    assert ev.scene is not None
    cue = cue_log_likelihood(
        ev.scene,
        heading_deg=float(cand.heading_deg),
        theta_rad=float(cand.theta_rad),
        translation_en=np.asarray(cand.translation_en, float),
        scale=float(cand.scale),
        car_center_world=ev.car_center_world,
        map_data=ev.map_data,
        frame=ev.frame,
    )
    return cue.log_factor, [Flag(FlagKind.CUE, f" {n}") for n in cue.notes]


def score_hypothesis(
    h: Hypothesis, world_cam: Camera, ev: Evidence, settings: LocateSettings
) -> Candidate:
    """Stage 3: a hypothesis scored against all the evidence, as a candidate."""
    return score_hypotheses([h], world_cam, ev, settings)[0]


def score_hypotheses(
    hyps: list[Hypothesis], world_cam: Camera, ev: Evidence, settings: LocateSettings
) -> list[Candidate]:
    """:func:`score_hypothesis` of each hypothesis (their map tests in one pass)."""
    cands = [
        Candidate(
            h.method,
            h.enu_from_world,
            h.enu_from_world.camera(world_cam),
            corner_assignment=h.corner_assignment,
            intersection_id=(
                ev.intersection.id
                if h.method == "corners" and ev.intersection is not None
                else None
            ),
            evidence=ev,
        )
        for h in hyps
    ]
    return _rescore_many(cands, world_cam, ev, settings, [h.log_prior for h in hyps])


def prior_gate(
    cands: list[Candidate], ev: Evidence, settings: LocateSettings, result: LocateResult
) -> list[Candidate]:
    """Stage 4: drop hypotheses farther than ``prior_gate_radii`` prior radii from the prior.

    Raises
    ------
    NoCandidatesError
        Every hypothesis is that far: the evidence contradicts the prior.
    """
    if ev.prior_en is None or not ev.prior_radius_m:
        return cands
    limit = settings.prior_gate_radii * ev.prior_radius_m
    dist = [float(np.linalg.norm(c.east_north - ev.prior_en)) for c in cands]
    kept_near = [c for c, d in zip(cands, dist, strict=True) if d <= limit]
    if not kept_near:
        cam_dist = float(np.linalg.norm(result.calibration.camera.center_in_world[:2]))
        raise NoCandidatesError(
            f"every hypothesis puts the camera more than {limit:.0f} m "
            f"({settings.prior_gate_radii:g} x prior.radius_m) from the prior, the nearest "
            f"{min(dist):.0f} m: the {', '.join(result.methods_tried)} evidence contradicts "
            "the prior (or the calibration is wrong: it puts the camera "
            f"{cam_dist:.0f} m from the car)"
        )
    if len(kept_near) < len(cands):
        result.warnings.append(
            f"{len(cands) - len(kept_near)} hypotheses more than {limit:.0f} m from the prior "
            "dropped"
        )
    return kept_near


PLAUSIBILITY_MARGIN = 10.0
"""Candidates whose likelihood alone trails the best score by more than this (in log units:
22,000 to 1) keep the plausibility at their estimate; averaging it could not bring them
near the leaders (a plausibility is at most 1)."""


def expected_plausibility(
    cands: list[Candidate], world_cam: Camera, ev: Evidence, settings: LocateSettings
) -> list[Candidate]:
    """Stage 5a: the plausibility of the leading merged candidates averaged over their
    position uncertainty (:func:`_expected_plausibility`), so that a candidate a few metres
    off is not ruled out by a building or a kerb that the truth it stands for is clear of.

    It runs on merged candidates (sorted by score, as :func:`normalise_and_merge` leaves
    them): near-duplicates share one place, so they must share one plausibility (five sigma
    points of step functions would otherwise pick among them at random). Bounded work: the
    first ``max_candidates`` whose likelihood alone is within :data:`PLAUSIBILITY_MARGIN`
    of the best score. Scores are re-normalised and re-sorted.
    """
    if not cands:
        return cands
    best = max(c.score for c in cands)
    floor = best * math.exp(-PLAUSIBILITY_MARGIN)
    out = list(cands)
    # The candidates averaged: (index, score with a plausibility of 1, evidence).
    chosen: list[tuple[int, float, Evidence]] = []
    for i, c in enumerate(cands):
        upper = c.score / max(c.prior, 1e-300)  # the score with a plausibility of 1
        if i < settings.max_candidates and upper >= floor:
            chosen.append((i, upper, c.evidence or ev))
    sigmas = position_sigmas_m(
        [cands[i] for i, _u, _e in chosen], world_cam, [e for _i, _u, e in chosen], settings
    )
    # (index, score with a plausibility of 1, evidence, sigma points) of each one averaged
    todo: list[tuple[int, float, Evidence, list[tuple[FloatArray, Similarity2D]]]] = []
    for (i, upper, c_ev), sigma in zip(chosen, sigmas, strict=True):
        if sigma is not None and math.isfinite(sigma) and sigma > 0.0:
            todo.append((i, upper, c_ev, _sigma_points(cands[i].enu_from_world, sigma, world_cam)))
    # The sigma points of every candidate on one evidence: one pass of the map tests.
    for e_id in dict.fromkeys(id(e) for _i, _u, e, _pts in todo):
        mine = [t for t in todo if id(t[2]) == e_id]
        got = iter(
            plausibility_at(
                [centre for *_x, pts in mine for centre, _sim in pts],
                [sim for *_x, pts in mine for _centre, sim in pts],
                mine[0][2],
                settings,
                [cands[i].matches for i, _u, _e, pts in mine for _p in pts],
            )
        )
        for i, upper, _e, pts in mine:
            c = cands[i]
            p = c.prior / 3.0  # the centre's weight; each sigma point's 1/6
            for _p in pts:
                p += next(got)[0] / 6.0
            out[i] = replace(c, prior=p, score=upper * p)
    total = sum(c.score for c in out) or 1.0
    for c in out:
        c.score = c.score / total
    out.sort(key=lambda c: -c.score)
    return out


def refine_leaders(
    cands: list[Candidate], world_cam: Camera, ev: Evidence, settings: LocateSettings
) -> list[Candidate]:
    """Stage 5: refine the ``refine_top`` leading candidates, then score them again (the
    plausibility averaged over their refined uncertainty)."""
    leaders = cands[: settings.refine_top]
    rest = cands[settings.refine_top :]
    # The best rival reading (a same-shaped neighbour junction: _rival_neighbours) is refined
    # too, so that the tie rule weighs it as it weighs the leaders: unrefined, a rival that
    # fitted as well stood at 0.4-0.5 of a refined top and went unnamed.
    rival = next((c for c in rest if c.rival is not None), None)
    if rival is not None and not any(c.rival is not None for c in leaders):
        leaders = [*leaders, rival]
        rest = [c for c in rest if c is not rival]
    before = [_weight(c) for c in leaders]
    top = refine_many(leaders, world_cam, [c.evidence or ev for c in leaders], settings)
    # The prior odds a reading keeps once refined (_keep_odds: a searched junction's, another
    # corner's reading of a reference); the other alternatives compete at even odds here.
    top = _rescore_many(
        top, world_cam, ev, settings, [c.log_prior_odds for c in top], expected=True
    )
    for c, w in zip(top, before, strict=True):
        c.unrefined_log_weight = w
    return top + rest


def normalise_and_merge(cands: list[Candidate], settings: LocateSettings) -> list[Candidate]:
    """Scores from likelihood × plausibility, summing to 1; near-duplicates merged."""
    if not cands:
        return cands
    logw = np.array([c.log_likelihood + math.log(max(c.prior, 1e-300)) for c in cands])
    w = np.exp(logw - logw.max())
    w /= w.sum()
    for c, wi in zip(cands, w, strict=True):
        c.score = float(wi)
    cands.sort(key=lambda c: -c.score)
    # Vectorised over the kept ones (landmark scenes have thousands of hypotheses) once
    # there are many; the same arithmetic on floats while there are few.
    en = np.array([c.east_north for c in cands], dtype=float)
    heading = np.array([c.heading_deg for c in cands], dtype=float)
    en_l, heading_l = en.tolist(), heading.tolist()
    kept: list[Candidate] = []
    kept_rows: list[int] = []
    for i, c in enumerate(cands):
        if len(kept_rows) > _MERGE_LOOP_MAX:
            d = np.linalg.norm(en[kept_rows] - en[i], axis=1)
            dh = np.abs((heading[i] - heading[kept_rows] + 180.0) % 360.0 - 180.0)
            hit = np.flatnonzero(
                (d < settings.merge_distance_m) & (dh < settings.merge_heading_deg)
            )
            first = int(hit[0]) if hit.size else None
        else:
            first = _first_near(en_l, heading_l, kept_rows, i, settings)
        if first is not None:
            k = kept[first]
            k.score += c.score
            k.merged += c.merged
            continue
        kept.append(c)
        kept_rows.append(i)
    kept.sort(key=lambda c: -c.score)
    return kept


_MERGE_LOOP_MAX = 32
"""Up to this many kept candidates, :func:`normalise_and_merge` compares on floats (numpy's
per-call overhead outweighs the arithmetic); beyond, on arrays."""


def _first_near(
    en: list[list[float]],
    heading: list[float],
    kept_rows: list[int],
    i: int,
    settings: LocateSettings,
) -> int | None:
    """The first kept candidate (its position in ``kept_rows``) within the merge distance
    and heading of candidate ``i``: :func:`normalise_and_merge`'s array test on floats
    (the same products, sums and remainders)."""
    x, y = en[i]
    h = heading[i]
    for pos, j in enumerate(kept_rows):
        dx, dy = en[j][0] - x, en[j][1] - y
        if math.sqrt(dx * dx + dy * dy) < settings.merge_distance_m and (
            abs((h - heading[j] + 180.0) % 360.0 - 180.0) < settings.merge_heading_deg
        ):
            return pos
    return None


def rank(cands: list[Candidate], settings: LocateSettings, result: LocateResult) -> list[Candidate]:
    """Stage 6: merged, cut to ``max_candidates``, ranked and placed on the map.

    Ties are named after stage 7 (:func:`mark_ties`), on the leaders' adjusted positions.

    Raises
    ------
    NoCandidatesError
        Every candidate fits the evidence poorly (``poor_fit``).
    """
    cands = normalise_and_merge(cands, settings)[: settings.max_candidates]
    if all(FlagKind.POOR_FIT in {f.kind for f in c.flags} for c in cands):
        best = min(cands, key=lambda c: c.residual_m)
        raise NoCandidatesError(
            f"no hypothesis fits the {', '.join(result.methods_tried)} evidence: the best misfits "
            f"by {best.residual_m:.1f} m RMS, more than {math.sqrt(settings.fit_gate):.0f} "
            "standard deviations of the noise model (wrong intersection, corners out of order, "
            "or a wrong calibration?)"
        )
    total = sum(c.score for c in cands) or 1.0
    for i, c in enumerate(cands, start=1):
        c.score = c.score / total
        c.rank = i
    _place(cands, result)
    return cands


def _place(cands: list[Candidate], result: LocateResult) -> None:
    """Each candidate's ``lon`` and ``lat`` from its camera centre (one projection for all)."""
    if not cands:
        return
    en = np.array([c.camera.center_in_world[:2] for c in cands], dtype=float)
    for c, (lon, lat) in zip(
        cands, result.frame.points_geographic_from_enu(en).tolist(), strict=True
    ):
        c.lon, c.lat = lon, lat


def _tie(
    a: Candidate,
    b: Candidate,
    settings: LocateSettings,
    positions: dict[int, FloatArray] | None = None,
    scores: tuple[float, float] | None = None,
) -> bool:
    """The tie rule for two candidates (``positions``: their ``east_north`` by ``id``;
    ``scores``: what to weigh instead of their ``score``)."""
    ea = a.east_north if positions is None else positions[id(a)]
    eb = b.east_north if positions is None else positions[id(b)]
    gap = ea - eb
    sa, sb = (a.score, b.score) if scores is None else scores
    return is_tie(
        sa,
        sb,
        math.sqrt(float(gap @ gap)),  # np.linalg.norm's own products
        score_ratio=settings.tie_score_ratio,
        distance_m=settings.tie_distance_m,
        merge_distance_m=settings.merge_distance_m,
    )


def _tie_unrefined(
    a: Candidate, b: Candidate, settings: LocateSettings, positions: dict[int, FloatArray]
) -> bool:
    """The tie rule on like-for-like weights where one of two candidates was refined and the
    other not: the refined one's weight before refinement against the other's.

    Refinement raises the leaders' fit; a rival left unrefined that fitted as well before
    then stands under the rule's odds though nothing in the evidence tells them apart
    (``absolute_slips.py --set held-out-3``, ``corners_ccw`` at a Leeds roundabout: the
    right reading at 0.085 of a refined top 75 m off)."""
    if (a.unrefined_log_weight is None) == (b.unrefined_log_weight is None):
        return False
    wa = a.unrefined_log_weight if a.unrefined_log_weight is not None else _weight(a)
    wb = b.unrefined_log_weight if b.unrefined_log_weight is not None else _weight(b)
    scores = (math.exp(min(wa - wb, 0.0)), math.exp(min(wb - wa, 0.0)))
    return _tie(a, b, settings, positions, scores)


def mark_ties(cands: list[Candidate], settings: LocateSettings, result: LocateResult) -> None:
    """Name the candidates that tie: ``ambiguous_with``, and a warning for the two leaders.

    Two candidates tie when the weaker scores at least ``settings.tie_score_ratio`` of the
    stronger (:data:`~camloc_geo._ties.TIE_SCORE_RATIO`: the evidence favours the
    stronger by less than 10 to 1) and at least :data:`~camloc_geo._ties.TIE_MIN_SCORE`, yet
    they stand more than ``tie_distance_m`` apart (a symmetric junction: the evidence cannot
    tell them apart); the rule is :func:`camloc_geo._ties.is_tie`.
    Earlier marks and the earlier warning are replaced.
    """
    positions = {id(c): c.east_north for c in cands}
    for c in cands:
        c.ambiguous_with = []
    # A tie needs both scores at least TIE_MIN_SCORE (is_tie's rule): the pairs of the rest
    # need no test.
    contenders = [c for c in cands if c.score >= TIE_MIN_SCORE]
    for a, b in itertools.combinations(contenders, 2):
        if _tie(a, b, settings, positions) or _tie_unrefined(a, b, settings, positions):
            a.ambiguous_with.append(b.rank)
            b.ambiguous_with.append(a.rank)
    for c in cands:
        c.ambiguous_with.sort()
    result.warnings = [w for w in result.warnings if not w.startswith("ambiguous:")]
    result.leaders_tie = len(cands) >= 2 and _tie(cands[0], cands[1], settings, positions)
    why_default = (
        "even with the scene's cues"
        if result.cues_applied
        else "a symmetric junction cannot tell them apart: more evidence (a reference "
        "pixel, a landmark, another corner), a viewing-direction hint (view_hint) or "
        "a tighter prior decides"
    )
    result.ties = []
    by_rank = {c.rank: c for c in cands}
    for group in _tie_groups(cands):
        why = _tie_why([by_rank[r] for r in group if r in by_rank], why_default)
        if result.leaders_tie and group[:2] == [cands[0].rank, cands[1].rank]:
            gap = float(np.linalg.norm(cands[0].east_north - cands[1].east_north))
            odds = cands[0].score / max(cands[1].score, 1e-300)
            text = (
                f"candidates 1 and 2 both fit the evidence (scores "
                f"{cands[0].score:.2f} and {cands[1].score:.2f}: odds of {odds:.1f} to 1, under "
                f"{1.0 / settings.tie_score_ratio:g} to 1) but stand {gap:.0f} m apart; {why}"
            )
            result.warnings.append(f"ambiguous: {text}")
        else:
            names = ", ".join(str(r) for r in group[:-1]) + f" and {group[-1]}"
            text = (
                f"candidates {names} fit the evidence within odds of "
                f"{1.0 / settings.tie_score_ratio:g} to 1 but stand apart; {why}"
            )
        result.ties.append(Tie(ranks=group, text=text, why=why))


def _tie_why(group: list[Candidate], default: str) -> str:
    """Why the candidates of a tie group cannot be told apart: a reference read on its stated
    kerb corner and on another, or the junctions searched around a rough point, when that
    is what sets them apart; else ``default``."""
    evs = [c.evidence for c in group if c.evidence is not None]
    notes = sorted({e.reference_substitution for e in evs if e.reference_substitution})
    if notes and len({e.reference_substitution for e in evs}) > 1:
        label = notes[0].split(" as ")[0]
        return (
            f"{label} read as different kerb corners of its junction (at its stated lat/lon "
            "or another corner's) fit alike: check that reference's lat/lon, or add a third "
            "reference, a corner or a landmark"
        )
    if any(c.rival == RIVAL_BEARING for c in group) and any(c.rival is None for c in group):
        return (
            "the car along the stated street_bearing_deg and along another street of the map "
            "(the cross street's bearing?) fit alike: check the bearing, or add a second "
            "reference"
        )
    if (
        any(c.rival == RIVAL_NEIGHBOUR for c in group)
        and len({c.intersection_id for c in group}) > 1
    ):
        lead = group[:2]
        if (
            all(c.rival is None for c in lead)
            and lead[0].intersection_id == lead[1].intersection_id
        ):
            # the leaders tie at the named junction (a symmetric one); the rival only joins them
            ranks = [str(c.rank) for c in group if c.rival == RIVAL_NEIGHBOUR]
            which = ("candidate " if len(ranks) == 1 else "candidates ") + ", ".join(ranks)
            return (
                f"{default}; and {which}, at a junction where only some of the named streets "
                f"meet (a cross street a block away, of the same shape), "
                f"{'fits' if len(ranks) == 1 else 'fit'} nearly as well: check the cross "
                "street's name"
            )
        return (
            "the junction where the named streets meet and a junction where only some of "
            "them meet (a cross street a block away, of the same shape) fit alike: check the "
            "cross street's name, or give the junction's lat/lon"
        )
    if any(e.junction_search for e in evs) and len({c.intersection_id for c in group}) > 1:
        return (
            "the junctions around the scene's intersection lat/lon (no junction within 25 m "
            "of it) fit alike: give the junction's own lat/lon or its street names"
        )
    return default


def _tie_groups(cands: list[Candidate]) -> list[list[int]]:
    """The groups of ranks linked by ``ambiguous_with`` (two or more each), ascending."""
    parent = {c.rank: c.rank for c in cands}

    def root(r: int) -> int:
        while parent[r] != r:
            parent[r] = parent[parent[r]]
            r = parent[r]
        return r

    for c in cands:
        for other in c.ambiguous_with:
            if other in parent:
                parent[root(other)] = root(c.rank)
    groups: dict[int, list[int]] = {}
    for r in sorted(parent):
        groups.setdefault(root(r), []).append(r)
    return sorted((g for g in groups.values() if len(g) >= 2), key=lambda g: g[0])


def bundle_leaders(
    cands: list[Candidate],
    calibration: CalibrationResult,
    ev: Evidence,
    settings: LocateSettings,
    result: LocateResult,
) -> list[Candidate]:
    """Stage 7: the ``refine_top`` leaders' cameras re-fitted with the annotations and the map.

    Ranks and scores stay (they compare hypotheses on the same evidence); the position,
    camera and ``sigma_m`` become the bundle's (:mod:`camloc_geo.absolute._bundle`). The
    leaders are fitted together (each its own fit, evaluated in one batch per step).
    """
    top = cands[: settings.refine_top]
    evs = [c.evidence or ev for c in top]
    if settings.bundle_adjust:
        adjusted = bundle_adjust_many(top, calibration, evs, settings, result.image_size)
        _place([a for a, c in zip(adjusted, top, strict=True) if a is not c], result)
    else:
        adjusted = list(top)
    held = [k for k, (a, c) in enumerate(zip(adjusted, top, strict=True)) if a is c]
    extra = _add_calibration_sigma(
        [adjusted[k] for k in held], calibration, [evs[k] for k in held], settings
    )
    if held and held[0] == 0:
        _warn_loose_calibration(adjusted[0], extra[0], calibration, evs[0], settings, result)
    return adjusted + cands[settings.refine_top :]


def _add_calibration_sigma(
    cands: list[Candidate],
    calibration: CalibrationResult,
    evs: list[Evidence],
    settings: LocateSettings,
) -> list[float | None]:
    """The calibration's own uncertainty added to the ``sigma_m`` of refined candidates that
    kept the calibrated camera (not re-fitted by the bundle), in place: the refinement's
    sigma carries the clicks and the map only (:func:`~camloc_geo.absolute._refine.
    calibration_sigmas_m`). The two add in quadrature."""
    out: list[float | None] = [None] * len(cands)
    todo = [k for k, c in enumerate(cands) if c.refined and c.sigma_m is not None]
    if not todo:
        return out
    extra = calibration_sigmas_m(
        [cands[k] for k in todo], calibration, [evs[k] for k in todo], settings
    )
    for k, sig_cal in zip(todo, extra, strict=True):
        sig = cands[k].sigma_m
        if sig_cal is not None and sig is not None and math.isfinite(sig_cal):
            cands[k].sigma_m = math.hypot(sig, sig_cal)
            out[k] = sig_cal
    return out


LOOSE_FOCAL_REL = 0.15
"""A calibration whose focal length's stated 1-sigma exceeds this fraction is loose
(:func:`_warn_loose_calibration`). ``benchmarks/unseen_cities.py --n 30``: the four
calibrations 32-62 % off in focal length stated 16-35 %; 13 of the 124 two-reference scenes
state over 15 % (and move their top candidate at least 5 m)."""

LOOSE_CALIBRATION_M = 5.0
"""... and the calibration alone moves the top candidate by at least this much (1-sigma)."""

LOOSE_FOCAL_SIGMAS = 2.0
"""... and a focal length this many sigmas shorter or longer (the other parameters moved
with it as the calibration's covariance correlates them, the pixels cast exactly) moves the
top candidate farther than its ``sigma_m``: the warning says how far."""


def _warn_loose_calibration(
    top: Candidate,
    sig_cal: float | None,
    calibration: CalibrationResult,
    ev: Evidence,
    settings: LocateSettings,
    result: LocateResult,
) -> None:
    """A warning when the top candidate kept a loose calibration's camera: its focal length
    over :data:`LOOSE_FOCAL_REL` uncertain, alone moving the candidate by
    :data:`LOOSE_CALIBRATION_M` or more (1 sigma), and a focal length
    :data:`LOOSE_FOCAL_SIGMAS` sigmas off moving it farther than its ``sigma_m``
    (:func:`~camloc_geo.absolute._refine.focal_moves_m`). With two references (or two corners)
    the map cannot correct the focal length (``unseen_cities.py``: Stretford's Lacy Street
    26.6 m off, Andorra 21.5 m at a sigma of 9.5 m). The warning names the focal length that
    far off and how far it moves the candidate."""
    f_sig = calibration.focal_sigma_px
    if sig_cal is None or f_sig is None or top.sigma_m is None:
        return
    focal = float(calibration.camera.focal_px)
    rel = float(f_sig) / focal
    if rel <= LOOSE_FOCAL_REL or sig_cal < LOOSE_CALIBRATION_M:
        return
    k = LOOSE_FOCAL_SIGMAS
    moves = focal_moves_m(top, calibration, ev, settings, k)
    if moves is None or max(moves) <= top.sigma_m:
        return
    short = moves[0] >= moves[1]
    far = max(moves)
    moved_px = focal - k * float(f_sig) if short else focal + k * float(f_sig)
    which = (
        f"{k:g} sigma {'shorter' if short else 'longer'} ({moved_px:.0f} px against {focal:.0f} px)"
        if moved_px > 0.0
        else f"{k:g} sigma shorter (at or below zero)"
    )
    how = (
        "leaves no camera that casts every matched pixel onto the ground"
        if math.isinf(far)
        else f"moves it {far:.0f} m"
    )
    result.warnings.append(
        f"calibration: the focal length is uncertain by {100.0 * rel:.0f} % (1 sigma) and "
        f"alone moves the top candidate by {sig_cal:.0f} m (1 sigma; its sigma_m "
        f"{top.sigma_m:.0f} m includes it); a focal length {which} {how}; "
        f"{top.method.replace('_', ' ')} cannot correct it: more vanishing lines, another "
        "reference or kerb corners would"
    )


def apply_cues(
    result: Any, scene: Scene, map_data: MapData | None, *, merge_distance_m: float | None = None
) -> Any:
    """Re-rank a :class:`~camloc_geo.absolute.LocateResult` by the scene's cues, in place.

    :func:`camloc_geo.absolute.locate` scores every hypothesis with the cues itself (before
    merging, refinement and ranking), and its result says so (``cues_applied``): then this
    does nothing. It remains for results computed without them.

    Each candidate's score (a posterior weight) is multiplied by its cue factor
    (:func:`~camloc_geo.absolute._cues.cue_log_likelihood`) and the scores renormalised; the
    ranks follow. Notes go to the candidate's ``flags`` (``cue: ...``), and the ties are
    recomputed with the rule of :func:`locate` (:func:`mark_ties`). A scene
    without cues leaves the result unchanged.
    """
    cands = list(getattr(result, "candidates", []) or [])
    if getattr(result, "cues_applied", False):
        return result  # locate() already ranked with them
    if not cands or not scene.has_cues:
        return result
    if merge_distance_m is None:
        merge_distance_m = LocateSettings().merge_distance_m
    size = scene.object_size
    ws = float(getattr(result.calibration, "width_sign", 1.0) or 1.0)
    centre = np.array([size.length_m / 2.0, ws * size.width_m / 2.0])
    logs = []
    for c in cands:
        cue = cue_log_likelihood(
            scene,
            heading_deg=float(c.heading_deg),
            theta_rad=float(c.theta_rad),
            translation_en=np.asarray(c.translation_en, float),
            scale=float(c.scale),
            car_center_world=centre,
            map_data=map_data,
            frame=result.frame,
        )
        logs.append(cue.log_factor)
        c.flags = [f for f in c.flags if f.kind is not FlagKind.CUE] + [
            Flag(FlagKind.CUE, f" {n}") for n in cue.notes
        ]
    w = np.array([max(c.score, 1e-300) for c in cands]) * np.exp(np.array(logs) - max(logs))
    w /= w.sum()
    for c, wi in zip(cands, w, strict=True):
        c.score = float(wi)
    cands.sort(key=lambda c: -c.score)
    for rank, c in enumerate(cands, start=1):
        c.rank = rank
    result.candidates = cands
    result.cues_applied = True
    mark_ties(cands, LocateSettings(merge_distance_m=merge_distance_m), result)
    return result
