"""Stage 1, evidence: the scene's ground pixels and the map features they may match, in ENU."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from camloc_geo._errors import MapDataError, SceneError
from camloc_geo.absolute._model import EvidenceKind, LocateResult, LocateSettings, Observation
from camloc_geo.camera import Camera
from camloc_geo.geodesy import LocalFrame
from camloc_geo.osm._local import LocalIndex
from camloc_geo.osm._names import close_matches, split_street_query
from camloc_geo.scene import Scene

if TYPE_CHECKING:
    from camloc_geo.osm import Intersection, MapData

FloatArray = npt.NDArray[np.float64]


@dataclass
class Evidence:
    """Everything a hypothesis is scored against, in the local frame."""

    refs: list[tuple[Observation, FloatArray]]
    corners: list[Observation]
    map_corners: FloatArray  # (n, 2) ENU, clockwise
    map_corner_ids: list[str]
    landmarks: list[tuple[Observation, FloatArray]]  # (obs, candidate map points (k, 2))
    street_bearings: list[float]
    prior_en: FloatArray | None = None
    prior_radius_m: float | None = None
    buildings: LocalIndex | None = None  # the map's footprints (ENU) and their STRtree
    streets: LocalIndex | None = None  # the map's centre lines (ENU), half widths, STRtree
    car_center_world: FloatArray = field(default_factory=lambda: np.zeros(2))
    worst_reference: str | None = None
    substitution: str | None = None  # a landmark read as a neighbouring building's
    reference_substitution: str | None = None  # a corner reference read as another corner
    stated_bearing: float | None = None  # the scene's street_bearing_deg
    map_bearings: list[float] = field(default_factory=list)  # the map's others, with one
    intersection: Intersection | None = None  # the junction whose corners these are
    # A stated intersection lat/lon with no junction within 25 m: the junctions searched
    # around it (junction, distance from the stated point m, log prior odds against the
    # nearest), nearest first (choose_intersection); empty otherwise.
    junction_search: list[tuple[Intersection, float, float]] = field(default_factory=list)
    scene: Scene | None = None  # for the cues (view hint, the car's street, its front)
    map_data: MapData | None = None
    frame: LocalFrame | None = None
    # What was computed for a placement on this evidence, by id of its Similarity2D
    # (_scoring.placement: the observations carried and their precisions, the street under
    # the car); a placement is tested when scored, averaged, refined and bundled. A copy
    # (dataclasses.replace) starts empty.
    placement_memo: dict[int, Any] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )
    # The observations stacked for the placements (_scoring._ObservationTable), made on
    # first use; a copy starts without.
    observation_table: Any = field(default=None, init=False, repr=False, compare=False)

    @property
    def has_cues(self) -> bool:
        """The scene carries a tie-breaking cue (:mod:`camloc_geo.absolute._cues`)."""
        return self.scene is not None and self.scene.has_cues

    @property
    def buildings_tree(self) -> Any:
        """STRtree over the building footprints, None without any."""
        return None if self.buildings is None else self.buildings.tree

    @property
    def street_tree(self) -> Any:
        """STRtree over the street centre lines, None without any."""
        return None if self.streets is None else self.streets.tree

    @property
    def observations(self) -> list[Observation]:
        """Every usable ground pixel: references, corners, landmarks."""
        return [o for o, _ in self.refs] + self.corners + [o for o, _ in self.landmarks]


_HALF_PIXEL_STEPS = np.array([[0.0, 0.0], [0.5, 0.0], [-0.5, 0.0], [0.0, 0.5], [0.0, -0.5]])


def ground_observation(
    camera: Camera,
    pixel: Sequence[float],
    kind: EvidenceKind,
    label: str,
    sigma_map: float,
    settings: LocateSettings,
    diag: float,
) -> Observation:
    """A ground pixel's world position and its covariance (click noise, scale error)."""
    px = np.asarray(pixel, dtype=float)
    # The pixel and its central-difference neighbours (half a pixel along u, then v), cast
    # in one call: row by row the same products as one call each.
    ground = camera.ground_from_pixels(px + _HALF_PIXEL_STEPS)
    g = ground[0]
    if not np.all(np.isfinite(g)):
        raise SceneError(
            f"pixel {px.tolist()} is at or above the horizon of the calibrated camera, so it "
            "cannot be a ground point",
            label,
        )
    # Jacobian of the ground point w.r.t. the pixel (central differences).
    J = np.empty((2, 2))
    for j in range(2):
        J[:, j] = (ground[1 + 2 * j, :2] - ground[2 + 2 * j, :2]) / 1.0
    sig_px = settings.sigma_pixel_rel * diag
    cov = sig_px**2 * (J @ J.T)
    foot = camera.center_in_world[:2]
    rng = float(np.linalg.norm(g[:2] - foot)) + float(np.linalg.norm(foot))
    cov = cov + (settings.scale_sigma_rel * 0.5 * rng) ** 2 * np.eye(2)
    if not np.all(np.isfinite(cov)):
        cov = np.eye(2) * 1e6
    return Observation(kind, label, (float(px[0]), float(px[1])), g[:2].copy(), cov, sigma_map)


def frame_anchor(scene: Scene, map_data: MapData | None) -> LocalFrame:
    """The local frame: the map's, else one anchored at the scene's first geographic hint."""
    if map_data is not None:
        return map_data.frame
    if scene.prior is not None:
        return LocalFrame(lat=scene.prior.lat, lon=scene.prior.lon)
    if scene.references:
        return LocalFrame(
            lat=float(np.mean([r.lat for r in scene.references])),
            lon=float(np.mean([r.lon for r in scene.references])),
        )
    if scene.intersection is not None and scene.intersection.lat is not None:
        assert scene.intersection.lon is not None
        return LocalFrame(lat=scene.intersection.lat, lon=scene.intersection.lon)
    raise SceneError(
        "no geographic hint: give prior, references, intersection lat/lon, or a map", "prior"
    )


class _Observer:
    """Turns the scene's pixels into observations; pixels above the horizon become warnings."""

    def __init__(self, camera: Camera, settings: LocateSettings, scene: Scene) -> None:
        self.camera = camera
        self.settings = settings
        self.diag = math.hypot(*scene.image_size)
        self.warnings: list[str] = []

    def __call__(
        self, pixel: Sequence[float], kind: EvidenceKind, label: str, sigma: float
    ) -> Observation | None:
        try:
            return ground_observation(
                self.camera, pixel, kind, label, sigma, self.settings, self.diag
            )
        except SceneError as exc:
            self.warnings.append(f"{exc}; ignored")
            return None


SWAP_FAR_M = 20_000.0
"""A reference farther than this from the map's (or the prior's) point whose (lon, lat) read
the other way round lies within it was given as (lon, lat): it is read swapped."""


def _reference_enu(
    i: int, lat: float, lon: float, frame: LocalFrame, anchored: bool, warnings: list[str]
) -> FloatArray:
    """A reference's map point in the local frame, a (lon, lat) slip read the right way.

    ``anchored``: the frame stands at the map's or the prior's point (not at the references'
    own mean), so a reference thousands of km from it is a slip, not the scene's place.
    """
    en = np.array(frame.enu_from_geographic(lat=lat, lon=lon), dtype=float)
    if not anchored or abs(lon) > 90.0 or float(np.hypot(*en)) <= SWAP_FAR_M:
        return en
    swapped = np.array(frame.enu_from_geographic(lat=lon, lon=lat), dtype=float)
    if float(np.hypot(*swapped)) > SWAP_FAR_M:
        return en
    warnings.append(
        f"references[{i}]: lat={lat:.6f}, lon={lon:.6f} is {np.hypot(*en) / 1000:.0f} km "
        f"from the map, lat={lon:.6f}, lon={lat:.6f} {np.hypot(*swapped):.0f} m: read as "
        "(lon, lat) swapped; give lat first"
    )
    return swapped


def _references(
    scene: Scene, frame: LocalFrame, observe: _Observer, anchored: bool
) -> list[tuple[Observation, FloatArray]]:
    refs = []
    for i, ref in enumerate(scene.references):
        sigma = observe.settings.sigma_reference_m / math.sqrt(ref.weight)
        obs = observe(ref.pixel, "reference", f"references[{i}]", sigma)
        if obs is not None:
            refs.append(
                (obs, _reference_enu(i, ref.lat, ref.lon, frame, anchored, observe.warnings))
            )
    return refs


def _check_distinct_corners(scene: Scene) -> None:
    assert scene.intersection is not None
    listed = np.asarray(scene.intersection.corners, dtype=float)
    for i in range(len(listed)):
        for j in range(i):
            if np.linalg.norm(listed[i] - listed[j]) < 2.0:
                raise SceneError(
                    f"is the same pixel as intersection.corners[{j}] (less than 2 px "
                    "apart): each visible kerb corner is listed once",
                    f"intersection.corners[{i}]",
                )


LATLON_MATCH_M = 25.0
"""A stated intersection lat/lon names the junction (centre or member node) this near."""

LATLON_SEARCH_M = 200.0
"""With no junction within :data:`LATLON_MATCH_M` of a stated intersection lat/lon, the
junctions with kerb corners this near are searched (webcam listings give a rough point:
``benchmarks/absolute_slips.py``'s ``intersection_latlon_off``, 50-150 m off)."""

LATLON_SEARCH_SCALE_M = 100.0
"""The searched junctions' prior odds fall by e for each this many metres they lie farther
from the stated point than the nearest one."""

MAX_SEARCH_JUNCTIONS = 8
"""At most this many junctions (nearest the stated point first) are searched."""


def latlon_search(
    map_data: MapData, lat: float, lon: float, streets: Sequence[str] | None
) -> list[tuple[Intersection, float, float]]:
    """The junctions with kerb corners within :data:`LATLON_SEARCH_M` of a stated point,
    nearest first: ``(junction, distance_m, log prior odds against the nearest)``.

    The odds fall with the distance (e per :data:`LATLON_SEARCH_SCALE_M` beyond the nearest
    one's); with stated street names, a junction where they do not all meet is at
    :data:`NEIGHBOUR_JUNCTION_PRIOR` more. At most :data:`MAX_SEARCH_JUNCTIONS`.
    """
    near = [
        (x, d)
        for x, d in map_data.intersections_within(lat=lat, lon=lon, radius_m=LATLON_SEARCH_M)
        if x.corners
    ][:MAX_SEARCH_JUNCTIONS]
    if not near:
        return []
    named = {x.id for x in map_data.street_junctions(list(streets))} if streets else None
    out = []
    for x, d in near:
        log_prior = -(d - near[0][1]) / LATLON_SEARCH_SCALE_M
        if named is not None and x.id not in named:
            log_prior += math.log(NEIGHBOUR_JUNCTION_PRIOR)
        out.append((x, d, log_prior))
    best = max(lp for _x, _d, lp in out)
    out = [(x, d, lp - best) for x, d, lp in out]
    # the most likely first: it is the evidence's own junction (log prior 0)
    out.sort(key=lambda t: -t[2])
    return out


def choose_intersection(
    scene: Scene,
    map_data: MapData,
    frame: LocalFrame,
    search: list[tuple[Intersection, float, float]] | None = None,
) -> Intersection:
    """The map intersection the scene's corners belong to.

    A stated lat/lon matches a modelled junction (its centre or one of its member nodes)
    within 25 m, with the stated street names if any. When none does, the junctions with
    kerb corners within :data:`LATLON_SEARCH_M` of it are searched
    (:func:`latlon_search`): the most likely is returned and all of them are appended to
    ``search`` (the caller scores them all and warns which one the answer stands at).
    Without ``search``, or with no such junction, a :class:`MapDataError` names the nearest
    junctions and their distances.
    """
    hint = scene.intersection
    assert hint is not None
    near = (scene.prior.lat, scene.prior.lon) if scene.prior is not None else None
    if hint.lat is not None and hint.lon is not None:
        streets = list(hint.streets or []) or None
        inter, warnings = map_data.match_intersection(
            lat=hint.lat, lon=hint.lon, streets=streets, max_distance_m=LATLON_MATCH_M
        )
        if inter is not None:
            return inter
        found = latlon_search(map_data, hint.lat, hint.lon, streets) if search is not None else []
        if found and search is not None:
            search.extend(found)
            return found[0][0]
        raise MapDataError(
            "intersection: no modelled junction matches the scene's intersection "
            f"(lat={hint.lat:.6f}, lon={hint.lon:.6f}"
            + (f", streets {' & '.join(hint.streets)}" if hint.streets else "")
            + "): "
            + "; ".join(warnings)
            + (
                f"; and none with kerb corners within {LATLON_SEARCH_M:.0f} m to search"
                if search is not None
                else ""
            )
        )
    if hint.streets:
        names = split_street_query(list(hint.streets))
        if len(names) == 1:  # "(some of) its streets": the junctions along that one street
            return _junction_of_one_street(map_data, names[0], near or (frame.lat0, frame.lon0))
        return map_data.find_intersection(list(hint.streets), near=near)
    if scene.prior is not None:
        return map_data.nearest_intersection(lat=scene.prior.lat, lon=scene.prior.lon)
    return map_data.nearest_intersection(lat=frame.lat0, lon=frame.lon0)


def _junction_of_one_street(
    map_data: MapData, name: str, near: tuple[float, float]
) -> Intersection:
    """The junction along the one named street nearest to ``near`` (the prior, else the
    map's point); with a prior, :func:`other_junctions` tries its other junctions within it."""
    junctions = map_data.street_junctions([name])
    found = [x for x in junctions if x.corners] or junctions
    if not found:
        close = close_matches(name, map_data.street_names())
        raise MapDataError(
            f"intersection.streets: {name!r} meets no other street in this map; close "
            f"matches: {', '.join(repr(c) for c in close) if close else 'none'}"
        )
    lat, lon = near
    return min(found, key=lambda x: map_data.distance_to_m(x, lat=lat, lon=lon))


@dataclass
class _CornerEvidence:
    corners: list[Observation] = field(default_factory=list)
    map_corners: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))
    map_corner_ids: list[str] = field(default_factory=list)
    intersection: Intersection | None = None
    bearings: list[float] = field(default_factory=list)
    search: list[tuple[Intersection, float, float]] = field(default_factory=list)


def _corners(
    scene: Scene,
    map_data: MapData | None,
    frame: LocalFrame,
    observe: _Observer,
    skip: frozenset[int] = frozenset(),
) -> _CornerEvidence:
    out = _CornerEvidence()
    if scene.intersection is None:
        return out
    _check_distinct_corners(scene)
    for i, px in enumerate(scene.intersection.corners):
        if i in skip:
            continue
        label = f"intersection.corners[{i}]"
        c_obs = observe(px, "corner", label, observe.settings.sigma_corner_m)
        if c_obs is not None:
            out.corners.append(c_obs)
    if map_data is None:
        raise MapDataError("the scene lists intersection corners but no map was given")
    inter = choose_intersection(scene, map_data, frame, out.search)
    out.intersection = inter
    if inter.kind != "junction":
        observe.warnings.append(
            f"intersection {inter.id} is a {inter.kind}: " + "; ".join(inter.warnings)
        )
    if inter.corners:
        out.map_corners = _corners_enu(inter, frame)
        out.map_corner_ids = [f"{inter.id}:{c.order}" for c in inter.corners]
    out.bearings = [st.bearing_deg for st in inter.streets]
    return out


def _corners_enu(inter: Intersection, frame: LocalFrame) -> FloatArray:
    """The junction's kerb corners ``(n, 2)`` in the local frame, in one projection (the
    same numbers as one call per corner)."""
    lonlat = np.array([[c.lon, c.lat] for c in inter.corners], dtype=float).reshape(-1, 2)
    return frame.points_enu_from_geographic(lonlat)


def _landmarks(
    scene: Scene, map_data: MapData | None, frame: LocalFrame, observe: _Observer
) -> list[tuple[Observation, FloatArray]]:
    landmarks = []
    settings = observe.settings
    for i, lm in enumerate(scene.landmarks or []):
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
            raise MapDataError(f"{label}: the building has no usable {lm.kind.replace('_', ' ')}s")
        pts = frame.points_enu_from_geographic(np.asarray(pts_ll, dtype=float))
        landmarks.append((lm_obs, pts))
    return landmarks


UNSTATED_BEARING_PRIOR = 0.2
"""The prior odds of the car along a map street other than the scene's ``street_bearing_deg``
against along the stated one, tried where every candidate along the stated one is
implausible on the map.
A stated bearing is often the cross street's (the car in the other street:
``benchmarks/absolute_slips.py``); the map's streets and the car-parallel test then decide,
within the tie rule's odds (0.2 > 0.1) where they cannot."""


def bearing_log_prior(bearing_deg: float, stated_deg: float | None) -> float:
    """The log prior of the car along ``bearing_deg``: 0 without a stated bearing or within
    5 degrees of it, else ``log(UNSTATED_BEARING_PRIOR)``."""
    if stated_deg is None:
        return 0.0
    d = abs((float(bearing_deg) - float(stated_deg) + 90.0) % 180.0 - 90.0)
    return 0.0 if d <= 5.0 else math.log(UNSTATED_BEARING_PRIOR)


NEIGHBOUR_BUILDING_M = 60.0
"""How far from a named landmark's building its neighbours are tried under its name."""

MAX_NEIGHBOUR_BUILDINGS = 3
"""At most this many neighbouring named buildings per landmark are tried."""


def landmark_alternatives(ev: Evidence) -> list[tuple[Evidence, str]]:
    """``ev`` with one named landmark's building replaced by a neighbouring named building,
    each with a note (``landmarks[0] as 'Other Hall'``).

    Crowds name a landmark by the building next to it (``benchmarks/absolute_slips.py``);
    the nearest :data:`MAX_NEIGHBOUR_BUILDINGS` other named buildings within
    :data:`NEIGHBOUR_BUILDING_M` of the named one stand in for it, one landmark at a time.
    """
    scene, map_data, frame = ev.scene, ev.map_data, ev.frame
    if scene is None or map_data is None or frame is None or not scene.landmarks:
        return []
    from dataclasses import replace

    by_label = {o.label: k for k, (o, _pts) in enumerate(ev.landmarks)}
    named = [b for b in map_data.buildings if b.name]
    out = []
    for i, lm in enumerate(scene.landmarks):
        k = by_label.get(f"landmarks[{i}]")
        if k is None or lm.name is None:
            continue
        near_lm = (lm.lat, lm.lon) if lm.lat is not None and lm.lon is not None else None
        if near_lm is None and scene.prior is not None:
            near_lm = (scene.prior.lat, scene.prior.lon)
        try:
            building = map_data.find_building(lm.name, near=near_lm)
        except MapDataError:
            continue
        cx, cy = building.centroid
        here = LocalFrame(lat=cy, lon=cx)
        others = []
        for b in named:
            if b.name == building.name:
                continue
            e, n = here.enu_from_geographic(lat=b.centroid[1], lon=b.centroid[0])
            d = math.hypot(e, n)
            if d <= NEIGHBOUR_BUILDING_M:
                others.append((d, b))
        others.sort(key=lambda t: t[0])
        for _d, b in others[:MAX_NEIGHBOUR_BUILDINGS]:
            pts_ll = list(b.corners if lm.kind == "building_corner" else b.face_midpoints)
            if not pts_ll:
                continue
            pts = frame.points_enu_from_geographic(np.asarray(pts_ll, dtype=float))
            lms = list(ev.landmarks)
            lms[k] = (lms[k][0], pts)
            out.append((replace(ev, landmarks=lms), f"landmarks[{i}] as {b.name!r}"))
    return out


CORNER_REFERENCE_M = 3.0
"""A reference this near a modelled kerb corner stands on that corner: it may be another
corner's lat/lon (:func:`reference_corner_alternatives`)."""


def reference_corner_alternatives(ev: Evidence) -> list[tuple[Evidence, str]]:
    """``ev`` with one reference on a modelled kerb corner moved to each other kerb corner of
    that junction, each with a note (``references[0] as corner 2 of junction n123 (A &
    B)``).

    Crowds click a kerb corner in the picture and give the lat/lon of another corner of the
    junction (``benchmarks/absolute_slips.py``'s ``reference_other_corner``): two references
    fix a camera exactly whatever their lat/lon, so the wrong corner's answer carries no
    misfit. Only scenes whose evidence is exactly two references; a reference lies on a
    corner when it is within :data:`CORNER_REFERENCE_M` of it.
    """
    map_data, frame = ev.map_data, ev.frame
    if map_data is None or frame is None or len(ev.refs) != 2 or ev.corners or ev.landmarks:
        return []
    from dataclasses import replace

    out = []
    for k, (obs, q) in enumerate(ev.refs):
        lon, lat = frame.geographic_from_enu(float(q[0]), float(q[1]))
        # a kerb corner lies within a junction's reach of its centre (or a member node)
        near = map_data.intersections_within(lat=float(lat), lon=float(lon), radius_m=60.0)
        for inter, _d in near:
            if len(inter.corners) < 2:
                continue
            corners = _corners_enu(inter, frame)
            gap = np.hypot(corners[:, 0] - q[0], corners[:, 1] - q[1])
            on = int(np.argmin(gap))
            if gap[on] > CORNER_REFERENCE_M:
                continue
            streets = " & ".join(inter.street_names)
            for j, c in enumerate(inter.corners):
                if j == on:
                    continue
                refs = list(ev.refs)
                refs[k] = (obs, corners[j].copy())
                note = f"{obs.label} as corner {c.order} of junction {inter.id} ({streets})"
                out.append((replace(ev, refs=refs), note))
            break
    return out


def unique_bearings(bearings: Iterable[float]) -> list[float]:
    """Bearings folded into [0, 180), those within 5° of an earlier one dropped."""
    out: list[float] = []
    for b in bearings:
        b = float(b) % 180.0
        if all(min(abs(b - c), 180.0 - abs(b - c)) > 5.0 for c in out):
            out.append(b)
    return out


def _search_spots(
    scene: Scene,
    frame: LocalFrame,
    settings: LocateSettings,
    refs: list[tuple[Observation, FloatArray]],
    inter: Intersection | None,
    landmarks: list[tuple[Observation, FloatArray]],
) -> list[tuple[FloatArray, float]]:
    """Where to look for street bearings, with the search radius around each spot."""
    spots = [(q, settings.street_search_m) for _, q in refs]
    if inter is not None:
        en = np.array(frame.enu_from_geographic(lat=inter.lat, lon=inter.lon))
        spots.append((en, settings.street_search_m))
    for _, pts in landmarks:
        # The streets along any side of the building, not only near its centre.
        mid = pts.mean(axis=0)
        reach = float(np.max(np.linalg.norm(pts - mid, axis=1)))
        spots.append((mid, settings.street_search_m + reach))
    if not spots and scene.prior is not None:
        en = np.array(frame.enu_from_geographic(lat=scene.prior.lat, lon=scene.prior.lon))
        spots.append((en, settings.street_search_m))
    return spots


def _map_street_bearings(
    map_data: MapData,
    frame: LocalFrame,
    settings: LocateSettings,
    spots: list[tuple[FloatArray, float]],
    bearings: list[float],
    warnings: list[str],
) -> None:
    """Add the bearings of the map's streets near the spots to ``bearings``.

    The search widens where nothing passes close (a reference on a plaza, a landmark set
    back from the street) and nothing is known yet: 1x, 3x, 8x the radius, then at least
    200 m.
    """
    base = settings.street_search_m
    for widen in (1.0, 3.0, 8.0, max(8.0, 200.0 / max(base, 1e-9))):
        for q, radius in spots:
            lon, lat = frame.geographic_from_enu(float(q[0]), float(q[1]))
            for _name, street_brg in map_data.street_bearings(
                lat=float(lat), lon=float(lon), radius_m=widen * radius
            ):
                bearings.append(street_brg)
        if bearings or not spots:
            if widen > 1.0:
                warnings.append(
                    f"street bearings: no street within {settings.street_search_m:g} m of the "
                    f"evidence; used those within {widen * settings.street_search_m:g} m"
                )
            break


def gather_evidence(
    scene: Scene,
    map_data: MapData | None,
    world_cam: Camera,
    settings: LocateSettings,
    result: LocateResult,
    skip_corners: frozenset[int] = frozenset(),
) -> Evidence:
    """Stage 1: every ground pixel of the scene with the map points it may match (ENU).

    ``skip_corners``: indices of listed kerb corners left out (the pipeline's
    leave-one-corner-out run, where no reading fits them all)."""
    frame = result.frame
    observe = _Observer(world_cam, settings, scene)
    observe.warnings = result.warnings
    refs = _references(scene, frame, observe, map_data is not None or scene.prior is not None)
    ce = _corners(scene, map_data, frame, observe, skip_corners)
    result.intersection = ce.intersection
    landmarks = _landmarks(scene, map_data, frame, observe)
    bearings = ce.bearings
    map_bearings: list[float] = []
    if map_data is not None:
        spots = _search_spots(scene, frame, settings, refs, ce.intersection, landmarks)
        _map_street_bearings(
            map_data,
            frame,
            settings,
            spots,
            bearings,
            result.warnings if scene.street_bearing_deg is None else [],
        )
    if scene.street_bearing_deg is not None:
        # The stated bearing alone; the map's other streets are kept for when every
        # candidate along it is implausible on the map (a crowd states the cross street's
        # bearing as readily as the car's street's: _pipeline._map_bearing_candidates).
        map_bearings = [
            b for b in unique_bearings(bearings) if bearing_log_prior(b, scene.street_bearing_deg)
        ]
        bearings = [scene.street_bearing_deg]
    ev = Evidence(
        refs,
        ce.corners,
        ce.map_corners,
        ce.map_corner_ids,
        landmarks,
        unique_bearings(bearings),
    )
    ev.intersection = ce.intersection
    ev.junction_search = ce.search
    ev.stated_bearing = scene.street_bearing_deg
    ev.map_bearings = map_bearings
    ev.scene, ev.map_data, ev.frame = scene, map_data, frame
    _add_map_context(ev, scene, map_data, frame, settings)
    size = scene.object_size
    ws = 1.0 if sum(result.calibration.width_signs or [1.0]) >= 0 else -1.0
    ev.car_center_world = np.array([size.length_m / 2.0, ws * size.width_m / 2.0])
    result.observations = ev.observations
    return ev


def _add_map_context(
    ev: Evidence,
    scene: Scene,
    map_data: MapData | None,
    frame: LocalFrame,
    settings: LocateSettings,
) -> None:
    """Buildings and streets (projected, indexed) and the prior, for the plausibility factors."""
    if map_data is not None and map_data.buildings:
        ev.buildings = map_data.building_index
    if scene.prior is not None:
        ev.prior_en = np.array(
            frame.enu_from_geographic(lat=scene.prior.lat, lon=scene.prior.lon), dtype=float
        )
        ev.prior_radius_m = scene.prior.radius_m
    if map_data is not None and map_data.streets:
        ev.streets = map_data.street_index


MAX_PRIOR_JUNCTIONS = 24
"""At most this many junctions (nearest the prior first) are hypotheses of a prior-only scene."""

NEIGHBOUR_JUNCTION_PRIOR = 0.2
"""The prior odds of a junction within the prior where only some of the scene's named streets
meet, against one where all meet. Crowds name the cross street a block away
(``benchmarks/absolute_slips.py``); the corners then fit the named junction no better than
the real one, and a junction whose corners fit as well stays within the tie rule's odds
(0.2 > 0.1): the answer says it cannot tell instead of naming the wrong junction alone."""

MAX_NEIGHBOUR_JUNCTIONS = 8
"""At most this many junctions where only some of the named streets meet are tried."""


def other_junctions(
    scene: Scene, map_data: MapData | None, ev: Evidence
) -> list[tuple[Intersection, float]]:
    """The junctions besides ``ev.intersection`` whose corners the scene's corners may be,
    each with its log prior odds against the scene's own.

    A scene that gives only a prior keeps every junction with kerb corners within
    ``prior.radius_m`` of the prior (at most :data:`MAX_PRIOR_JUNCTIONS`, nearest first;
    log prior 0): the corners' geometry, the prior's density and the map's plausibility rank
    them, instead of the nearest one being assumed. Where it names streets, the junctions
    where they all meet keep log prior 0, and those within the prior where only some of them
    meet (the cross street a block away) are tried at :data:`NEIGHBOUR_JUNCTION_PRIOR` (at
    most :data:`MAX_NEIGHBOUR_JUNCTIONS`). A scene that states a lat/lon is taken at its
    word when a junction lies within 25 m of it (its neighbours tried at odds of 0.03 cost
    the absolute benchmark's corner scenes 3 % of their right top candidates and four times
    the time); when none does, the junctions searched around it
    (:func:`latlon_search`, ``Evidence.junction_search``) are scored instead of these.
    """
    hint = scene.intersection
    if map_data is None or hint is None or not ev.corners:
        return []
    current = ev.intersection.id if ev.intersection is not None else None
    neighbour = math.log(NEIGHBOUR_JUNCTION_PRIOR)
    if scene.prior is None or (hint.lat is not None and hint.lon is not None):
        return []
    near = map_data.intersections_within(
        lat=scene.prior.lat, lon=scene.prior.lon, radius_m=scene.prior.radius_m
    )
    pool = [x for x, _d in near if x.corners and x.id != current]
    if not hint.streets:
        return [(x, 0.0) for x in pool[: MAX_PRIOR_JUNCTIONS - 1]]
    named = {x.id for x in map_data.street_junctions(list(hint.streets))}
    some: set[str] = set()
    for name in hint.streets:
        some |= {x.id for x in map_data.street_junctions([name])}
    out = [(x, 0.0) for x in pool if x.id in named][: MAX_PRIOR_JUNCTIONS - 1]
    out += [(x, neighbour) for x in pool if x.id not in named and x.id in some][
        :MAX_NEIGHBOUR_JUNCTIONS
    ]
    return out


def named_junctions(scene: Scene, map_data: MapData | None, ev: Evidence) -> set[str] | None:
    """The ids of the junctions the scene itself names (its lat/lon's, or where all its
    streets meet), None when it names none (a prior alone)."""
    hint = scene.intersection
    if map_data is None or hint is None:
        return None
    if hint.lat is not None and hint.lon is not None:
        return {ev.intersection.id} if ev.intersection is not None else set()
    if hint.streets:
        return {x.id for x in map_data.street_junctions(list(hint.streets))}
    return None


def evidence_at(
    ev: Evidence,
    inter: Intersection,
    map_data: MapData,
    frame: LocalFrame,
    settings: LocateSettings,
) -> Evidence:
    """``ev`` with another junction's kerb corners and the street bearings around it."""
    from dataclasses import replace

    corners = _corners_enu(inter, frame)
    bearings = [st.bearing_deg for st in inter.streets]
    for _name, brg in map_data.street_bearings(
        lat=inter.lat, lon=inter.lon, radius_m=settings.street_search_m
    ):
        bearings.append(brg)
    return replace(
        ev,
        map_corners=corners,
        map_corner_ids=[f"{inter.id}:{c.order}" for c in inter.corners],
        street_bearings=unique_bearings(bearings),
        intersection=inter,
    )
