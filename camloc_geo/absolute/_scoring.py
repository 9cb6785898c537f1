"""Stage 3, scores: each hypothesis against all the evidence, and its map plausibility."""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from camloc_geo.absolute._evidence import Evidence
from camloc_geo.absolute._model import Flag, FlagKind, LocateSettings, Match, Observation
from camloc_geo.absolute._similarity import Similarity2D
from camloc_geo.camera import Camera

FloatArray = npt.NDArray[np.float64]

# A matched point's squared Mahalanobis misfit counts up to this much (a robust likelihood).
OUTLIER_M2 = 50.0


def obs_precision(obs: Observation, R2: FloatArray, s: float) -> FloatArray:
    """Inverse covariance of an observation's ENU position under rotation ``R2``, scale ``s``."""
    cov = (s**2) * (R2 @ obs.cov_world @ R2.T) + obs.sigma_map_m**2 * np.eye(2)
    return np.asarray(np.linalg.inv(cov), dtype=np.float64)


def mahal(obs: Observation, q: FloatArray, enu_from_world: Similarity2D) -> float:
    """Squared Mahalanobis distance between an observation (carried to ENU) and a map point."""
    r = enu_from_world.apply(obs.world_xy) - q
    return float(r @ obs_precision(obs, enu_from_world.rotation, enu_from_world.scale) @ r)


class _Unknown:
    """Not computed yet."""


_UNKNOWN = _Unknown()


class _ObservationTable:
    """An evidence's observations stacked (the same on every placement): their rows by id,
    world positions ``(n, 2)``, covariances ``(n, 2, 2)`` and map covariances
    ``σ² I`` ``(n, 2, 2)``."""

    __slots__ = ("cov_world", "map_cov", "row", "world_xy")

    def __init__(self, ev: Evidence) -> None:
        obs = ev.observations
        self.row = {id(o): i for i, o in enumerate(obs)}
        self.world_xy = np.array([o.world_xy for o in obs], dtype=np.float64).reshape(-1, 2)
        self.cov_world = np.array([o.cov_world for o in obs], dtype=np.float64).reshape(-1, 2, 2)
        map_var = np.array([o.sigma_map_m**2 for o in obs], dtype=np.float64)
        self.map_cov = map_var[:, None, None] * np.eye(2)


class _Placement:
    """What one placement (an ``enu_from_world``) gives on one evidence, each computed once:
    the observations carried to ENU with their precisions (a hypothesis tests one
    observation against several map points: every corner assignment, every landmark
    corner; the refinement whitens with the same precisions) and the street under the car.

    The evidence's observations are carried together on first use (one product and one
    batched inverse for all, instead of a few small ones per observation): the values of
    :func:`mahal` and :func:`obs_precision` up to rounding (a few units in the last place).
    """

    __slots__ = ("_carried_all", "_ev", "sim", "street_angle")

    def __init__(self, enu_from_world: Similarity2D, ev: Evidence) -> None:
        self.sim = enu_from_world
        self._ev = ev
        self.street_angle: float | _Unknown | None = _UNKNOWN
        self._carried_all: tuple[dict[int, int], list[FloatArray], FloatArray] | None = None

    def _all(self) -> tuple[dict[int, int], list[FloatArray], FloatArray]:
        if self._carried_all is None:
            ev = self._ev
            table = ev.observation_table
            if table is None:
                table = ev.observation_table = _ObservationTable(ev)
            sim = self.sim
            R2 = sim.rotation
            s = sim.scale
            enu = s * table.world_xy @ R2.T + sim.translation_m
            cov = (s**2) * (R2 @ table.cov_world @ R2.T) + table.map_cov
            try:
                prec = np.linalg.inv(cov)  # LAPACK per matrix
            except np.linalg.LinAlgError:  # the singular one raises where it is used
                prec = np.stack([_inv_or_nan(c) for c in cov]).reshape(-1, 2, 2)
            self._carried_all = (table.row, list(enu), prec)
        return self._carried_all

    def carried(self, obs: Observation) -> tuple[FloatArray, FloatArray]:
        """The observation in ENU and its precision there (:func:`obs_precision`)."""
        row, enu, prec = self._all()
        i = row.get(id(obs))
        if i is None:  # not one of the evidence's own: alone
            sim = self.sim
            return sim.apply(obs.world_xy), obs_precision(obs, sim.rotation, sim.scale)
        if not np.isfinite(prec[i, 0, 0]):
            raise np.linalg.LinAlgError("Singular matrix")
        return enu[i], prec[i]

    def misfit(self, obs: Observation, q: FloatArray) -> tuple[FloatArray, float]:
        """``(r, m2)``: the ENU misfit to map point ``q`` and its squared Mahalanobis norm."""
        p, prec = self.carried(obs)
        r = p - q
        return r, float(r @ prec @ r)


def _inv_or_nan(m: FloatArray) -> FloatArray:
    try:
        return np.asarray(np.linalg.inv(m), dtype=np.float64)
    except np.linalg.LinAlgError:
        return np.full((2, 2), np.nan)


def placement(ev: Evidence, enu_from_world: Similarity2D) -> _Placement:
    """The placement's memo on the evidence (``Evidence.placement_memo``, by id; the memo
    holds the similarity, so the id cannot be reused while it is there)."""
    memo = ev.placement_memo
    got = memo.get(id(enu_from_world))
    if got is None or got.sim is not enu_from_world:
        got = _Placement(enu_from_world, ev)
        memo[id(enu_from_world)] = got
    return got


@dataclass
class Fit:
    """How a hypothesis fits the evidence."""

    log_likelihood: float = 0.0
    matches: list[Match] = field(default_factory=list)
    sq_misfits_m2: list[float] = field(default_factory=list)
    corner_assignment: tuple[int, ...] | None = None

    @property
    def residual_m(self) -> float:
        """RMS misfit of the matched points, metres (NaN with none)."""
        sq = self.sq_misfits_m2
        return math.sqrt(sum(sq) / len(sq)) if sq else math.nan

    def add(
        self,
        obs: Observation,
        q: FloatArray,
        m2: float,
        enu_from_world: Similarity2D,
        corner: tuple[str, int] | None = None,
        misfit: FloatArray | None = None,
    ) -> None:
        """Count one matched point (its misfit capped at the outlier cost).

        ``misfit``: the carried observation minus ``q``, when computed already.
        """
        self.log_likelihood -= 0.5 * min(m2, OUTLIER_M2)  # robust: one outlier costs at most 25
        d = enu_from_world.apply(obs.world_xy) - q if misfit is None else misfit
        dd = float(d @ d)
        self.sq_misfits_m2.append(dd)
        self.matches.append(
            Match(
                obs.kind,
                obs.label,
                obs.pixel,
                np.asarray(q, dtype=np.float64).copy(),
                math.sqrt(dd),  # np.linalg.norm(d): the same dot product and square root
                float(m2),
                None if corner is None else corner[0],
                None if corner is None else corner[1],
            )
        )


def score(
    enu_from_world: Similarity2D,
    ev: Evidence,
    settings: LocateSettings,
    corner_assignment: Sequence[int] | None,
) -> Fit:
    """Log-likelihood, RMS misfit, matches and corner assignment of one hypothesis.

    ``-1`` in a corner assignment leaves that image corner unmatched.
    """
    fit = Fit()
    carried = placement(ev, enu_from_world)
    for obs, q in ev.refs:
        r, m2 = carried.misfit(obs, q)
        fit.add(obs, q, m2, enu_from_world, misfit=r)
    if ev.corners and len(ev.map_corners):
        if corner_assignment is None:
            corner_assignment = best_assignment(enu_from_world, ev, carried)
        _score_corners(fit, enu_from_world, ev, corner_assignment, carried)
    for obs, pts in ev.landmarks:
        tried = [carried.misfit(obs, q) for q in pts]
        k = int(np.argmin([m2 for _r, m2 in tried]))
        fit.add(obs, pts[k], tried[k][1], enu_from_world, misfit=tried[k][0])
    s = enu_from_world.scale
    fit.log_likelihood -= 0.5 * ((s - 1.0) / max(settings.scale_sigma_rel, 1e-6)) ** 2
    if corner_assignment is not None:
        fit.corner_assignment = tuple(int(j) for j in corner_assignment)
    return fit


def _score_corners(
    fit: Fit,
    enu_from_world: Similarity2D,
    ev: Evidence,
    assignment: Sequence[int],
    carried: _Placement | None = None,
) -> None:
    carried = carried or placement(ev, enu_from_world)
    for obs, j in zip(ev.corners, assignment, strict=True):
        if j < 0:
            # A visible corner the map's junction has no counterpart for (more corners
            # listed than modelled): it costs what an outlier costs.
            fit.log_likelihood -= 0.5 * OUTLIER_M2
            continue
        q = ev.map_corners[j]
        r, m2 = carried.misfit(obs, q)
        fit.add(obs, q, m2, enu_from_world, corner=(ev.map_corner_ids[j], int(j)), misfit=r)


def unmatched_flags(ev: Evidence, assignment: tuple[int, ...] | None) -> list[Flag]:
    """``unmatched:<label>`` for visible corners a hypothesis leaves without a map corner."""
    if assignment is None:
        return []
    return [
        Flag(FlagKind.UNMATCHED, o.label)
        for o, j in zip(ev.corners, assignment, strict=True)
        if j < 0
    ]


def best_assignment(
    enu_from_world: Similarity2D, ev: Evidence, carried: _Placement | None = None
) -> list[int]:
    """The cyclic, order-preserving assignment of image corners to map corners that fits best."""
    carried = carried or placement(ev, enu_from_world)
    best: tuple[float, list[int]] | None = None
    for assign, _prior in assignments(len(ev.corners), len(ev.map_corners)):
        cost = sum(
            carried.misfit(o, ev.map_corners[j])[1] if j >= 0 else OUTLIER_M2
            for o, j in zip(ev.corners, assign, strict=True)
        )
        if best is None or cost < best[0]:
            best = (cost, list(assign))
    assert best is not None
    return best[1]


def assignments(k: int, n: int) -> Iterable[tuple[tuple[int, ...], float]]:
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


# ---------------------------------------------------------------------------- priors
def car_bearing_deg(enu_from_world: Similarity2D) -> float:
    """Bearing of the car's length axis (world x), folded into [0, 180)."""
    return (90.0 - math.degrees(enu_from_world.rotation_rad)) % 180.0


def street_angle_under_car(enu_from_world: Similarity2D, ev: Evidence) -> float | None:
    """Signed angle (degrees, in [-90, 90)) from the street under the car to the car's axis.

    None when the car (its centre under the similarity) is on no carriageway (farther than
    half the street's width + 2.5 m from every centre line); else the smallest angle among the
    streets it stands on.
    """
    return street_angles_under_car([enu_from_world], ev)[0]


def street_angles_under_car(sims: Sequence[Similarity2D], ev: Evidence) -> list[float | None]:
    """:func:`street_angle_under_car` of several placements of the car, in one pass.

    Each street within a 50 m box of the car (a box, not a buffered disc: the tree only
    tests envelopes) whose centre line passes within its half width + 2.5 m of the car
    gives the bearing of its chord from 5 m before to 5 m after the car's projection; the
    smallest angle to the car's axis wins (the first of equals, in the tree's order). The
    geometry is GEOS's (distance, project, interpolate), over arrays of every car and near
    street at once: one call each instead of several per street and car. Answers are
    remembered on the evidence (:func:`placement`): a placement is tested when scored,
    averaged over its uncertainty, refined and bundled.
    """
    places = [placement(ev, sim) for sim in sims]
    todo = list({id(p): p for p in places if isinstance(p.street_angle, _Unknown)}.values())
    if todo:
        for p, angle in zip(todo, _street_angles([p.sim for p in todo], ev), strict=True):
            p.street_angle = angle
    return [p.street_angle for p in places]  # type: ignore[misc]


def _street_angles(sims: Sequence[Similarity2D], ev: Evidence) -> list[float | None]:
    """:func:`street_angles_under_car`, computed."""
    import shapely

    assert ev.streets is not None
    # The cars' centres and bearings, all placements at once (Similarity2D.apply's and
    # car_bearing_deg's arithmetic, elementwise).
    theta = np.array([sim.rotation_rad for sim in sims], dtype=np.float64)
    scale = np.array([sim.scale for sim in sims], dtype=np.float64)
    shift = np.array([sim.translation_m for sim in sims], dtype=np.float64).reshape(-1, 2)
    cx, cy = (float(v) for v in ev.car_center_world)
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    xy = np.empty((len(sims), 2))
    xy[:, 0] = (scale * cos_t) * cx + (scale * -sin_t) * cy + shift[:, 0]
    xy[:, 1] = (scale * sin_t) * cx + (scale * cos_t) * cy + shift[:, 1]
    boxes = shapely.box(xy[:, 0] - 25.0, xy[:, 1] - 25.0, xy[:, 0] + 25.0, xy[:, 1] + 25.0)
    car_i, line_i = ev.street_tree.query(boxes)
    best: list[float | None] = [None] * len(sims)
    if not len(car_i):
        return best
    lines = ev.street_tree.geometries[line_i]
    pts = shapely.points(xy)[car_i]
    half_w = ev.streets.values_array[line_i]
    on = ~(shapely.distance(lines, pts) > half_w + 2.5)
    if not on.any():
        return best
    car_i, lines, pts = car_i[on], lines[on], pts[on]
    sproj = shapely.line_locate_point(lines, pts)
    # The chord's ends 5 m before and after the projection, in one call.
    ends = shapely.get_coordinates(
        shapely.line_interpolate_point(
            np.concatenate([lines, lines]),
            np.concatenate(
                [np.maximum(0.0, sproj - 5.0), np.minimum(shapely.length(lines), sproj + 5.0)]
            ),
        )
    )
    n_on = len(lines)
    a, b = ends[:n_on], ends[n_on:]
    brg = np.degrees(np.arctan2(b[:, 0] - a[:, 0], b[:, 1] - a[:, 1])) % 180.0
    car_brg = (90.0 - np.degrees(theta)) % 180.0
    diffs = ((car_brg[car_i] - brg + 90.0) % 180.0 - 90.0).tolist()
    for k, diff in zip(car_i.tolist(), diffs, strict=True):
        prev = best[k]
        if prev is None or abs(diff) < abs(prev):
            best[k] = diff
    return best


def _building_factor(
    C: FloatArray, ev: Evidence, settings: LocateSettings, matches: list[Match]
) -> tuple[float, list[Flag]]:
    """The camera is not deep inside a building; the corners it sees are not hidden."""
    return _building_factors(np.asarray(C, dtype=float)[None, :2], ev, settings, [matches])[0]


def _building_factors(
    centres: FloatArray,
    ev: Evidence,
    settings: LocateSettings,
    matches: Sequence[list[Match]],
) -> list[tuple[float, list[Flag]]]:
    """:func:`_building_factor` of several camera positions ``(P, 2)``, each with its matches.

    The tests are GEOS's, as one call per geometry would make them, over arrays: the
    footprints containing each position (its "home": deep inside one is suspect), and for
    each position and matched corner, the footprints other than its home that the sight
    line crosses for more than a metre.
    """
    import shapely

    assert ev.buildings is not None
    tree = ev.buildings_tree
    polys = tree.geometries
    pts = shapely.points(centres)
    n_pts = len(pts)
    pt_i, poly_i = tree.query(pts, predicate="within")  # the footprints containing each
    home: list[set[int]] = [set() for _ in range(n_pts)]
    for p, j in zip(pt_i.tolist(), poly_i.tolist(), strict=True):
        home[p].add(j)
    inside = [False] * n_pts
    if len(pt_i):
        deep = shapely.distance(shapely.get_exterior_ring(polys[poly_i]), pts[pt_i]) > 2.0
        for p in pt_i[deep].tolist():
            inside[p] = True
    corners = [[m for m in ms if m.kind == "corner"] for ms in matches]
    owner = [p for p, cs in enumerate(corners) for _m in cs]  # the position of each sight line
    occluded = np.zeros(len(owner), dtype=bool)
    if owner:
        coords = np.empty((len(owner), 2, 2))
        coords[:, 0, :] = centres[owner]
        coords[:, 1, :] = [m.map_en for cs in corners for m in cs]
        lines = shapely.linestrings(coords)
        line_i, poly_j = tree.query(lines, predicate="crosses")
        if len(line_i):
            not_home = np.array(
                [
                    j not in home[owner[i]]
                    for i, j in zip(line_i.tolist(), poly_j.tolist(), strict=True)
                ],
                dtype=bool,
            )
            line_i, poly_j = line_i[not_home], poly_j[not_home]
        if len(line_i):
            cut = shapely.length(shapely.intersection(lines[line_i], polys[poly_j])) > 1.0
            occluded[line_i[cut]] = True
    hidden = occluded.tolist()
    out = []
    line = 0
    for p in range(n_pts):
        factor = 1.0
        flags: list[Flag] = []
        if inside[p]:
            factor *= settings.inside_building_factor
            flags.append(Flag(FlagKind.INSIDE_BUILDING))
        for m in corners[p]:
            if hidden[line]:
                factor *= settings.occluded_corner_factor
                flags.append(Flag(FlagKind.OCCLUDED, m.label))
            line += 1
        out.append((factor, flags))
    return out


def _parallel_factor(
    enu_from_world: Similarity2D,
    ev: Evidence,
    settings: LocateSettings,
    street_angle: float | _Unknown | None = _UNKNOWN,
) -> tuple[float, list[Flag]]:
    """The car's length axis is parallel to a street (the one under it, when streets are known).

    ``street_angle``: :func:`street_angle_under_car` when computed already.
    """
    if ev.street_tree is not None:
        if isinstance(street_angle, _Unknown):
            street_angle = street_angle_under_car(enu_from_world, ev)
        signed = street_angle
        if signed is None:
            return settings.parallel_floor, [Flag(FlagKind.CAR_OFF_STREET)]
        diff = abs(signed)
    elif ev.street_bearings:
        car_bearing = car_bearing_deg(enu_from_world)
        diff = min(
            min(abs(car_bearing - b), 180.0 - abs(car_bearing - b)) for b in ev.street_bearings
        )
    else:
        return 1.0, []
    par = math.exp(-0.5 * (diff / settings.bearing_sigma_deg) ** 2)
    factor = settings.parallel_floor + (1.0 - settings.parallel_floor) * par
    if diff > 2.5 * settings.bearing_sigma_deg:
        return factor, [Flag(FlagKind.CAR_NOT_PARALLEL_TO_STREET)]
    return factor, []


def plausibility(
    cam: Camera,
    enu_from_world: Similarity2D,
    ev: Evidence,
    settings: LocateSettings,
    matches: list[Match],
) -> tuple[float, list[Flag]]:
    """The map plausibility factor of a hypothesis (buildings, prior, streets) and its flags."""
    return plausibility_many([cam], [enu_from_world], ev, settings, [matches])[0]


def plausibility_many(
    cams: Sequence[Camera],
    sims: Sequence[Similarity2D],
    ev: Evidence,
    settings: LocateSettings,
    matches: Sequence[list[Match]],
) -> list[tuple[float, list[Flag]]]:
    """:func:`plausibility` of several placements (camera, ``enu_from_world`` and matches
    each) on the same evidence; the building and street tests of all of them in one pass."""
    return plausibility_at([cam.center_in_world for cam in cams], sims, ev, settings, matches)


def plausibility_at(
    centres: Sequence[FloatArray],
    sims: Sequence[Similarity2D],
    ev: Evidence,
    settings: LocateSettings,
    matches: Sequence[list[Match]],
) -> list[tuple[float, list[Flag]]]:
    """:func:`plausibility_many` of placements given by their camera centres (``(3,)`` or
    ``(2,)`` each, metres in the local frame) instead of cameras: the tests use the centre
    only, and building a :class:`~camloc_geo.camera.Camera` per sigma point costs more than
    they do."""
    if ev.buildings_tree is not None:
        building = _building_factors(
            np.array([C[:2] for C in centres], dtype=float).reshape(-1, 2), ev, settings, matches
        )
    else:
        building = [(1.0, [])] * len(centres)
    angles: list[float | None] = [None] * len(sims)
    if ev.street_tree is not None:
        angles = street_angles_under_car(sims, ev)
    out = []
    for C, sim, ms, (f_b, fl_b), angle in zip(
        centres, sims, matches, building, angles, strict=True
    ):
        factor = 1.0
        flags: list[Flag] = []
        if ev.buildings_tree is not None:
            factor *= f_b
            flags += fl_b
        if ev.prior_en is not None and ev.prior_radius_m:
            # A soft prior: a Gaussian of the listed radius (0.61 at the radius, 0.14 at twice).
            away = C[:2] - ev.prior_en
            d = math.sqrt(float(away @ away))  # np.linalg.norm's own products
            factor *= math.exp(-0.5 * (d / ev.prior_radius_m) ** 2)
            if d > ev.prior_radius_m:
                flags.append(Flag(FlagKind.OUTSIDE_PRIOR))
        f, fl = _parallel_factor(sim, ev, settings, angle)
        factor *= f
        flags += fl
        if ev.worst_reference is not None:
            flags.append(Flag(FlagKind.WORST_REFERENCE, ev.worst_reference))
        # The flagged worst reference is reported, not held against the whole fit.
        m2 = [m.mahalanobis2 for m in ms if m.label != ev.worst_reference]
        if m2 and sum(m2) / len(m2) > settings.fit_gate:
            flags.append(Flag(FlagKind.POOR_FIT))
        out.append((factor, flags))
    return out
