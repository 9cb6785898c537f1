"""One camera of a batch: evidence from its listing and scene, placed on its area's map.

:func:`geocode_camera` is pure library code and never raises for a bad row: every outcome is
a :class:`CameraResult` with a ``status`` and a ``reason``.

Statuses
--------
``located``
    The scene was located; the point is the best candidate's camera position.
``title_only``
    No scene: placed at the junction (or address, landmark) the title names.
``ambiguous``
    Two places fit equally well (two junctions, the same title in two extracts, or two
    located candidates far apart); no point is given, the candidates layer has them all.
``street_only``
    The title names one street only: no point invented.
``not_found``
    The title's names are not in the map (the reason lists the nearest names).
``no_candidates``
    The scene was read but no candidate survived, or its geometry is degenerate (the
    reason says why).
``no_evidence``
    No title, street pair or scene to place the camera with.
``no_map``
    No map covers the camera (outside every extract, network off).
``scene_error``
    The scene file is missing or breaks the contract.
``map_error``
    The map could not be read or fetched.
``failed``
    An unexpected error (the reason names it); retried by a rerun.
"""

from __future__ import annotations

import logging
import math
import os
import threading
from collections import OrderedDict
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any

from camloc_geo._errors import (
    DegenerateGeometryError,
    InputError,
    MapDataError,
    MapSourceError,
    NotEnoughStructureError,
    SceneError,
)

if TYPE_CHECKING:
    from camloc_geo.cameras import CameraRow
    from camloc_geo.osm import Area, MapData, MapPlan

__all__ = [
    "PLACED_STATUSES",
    "RETRY_STATUSES",
    "STATUSES",
    "STATUS_ALIASES",
    "CameraResult",
    "geocode_camera",
    "normalize_status",
]

log = logging.getLogger(__name__)

PLACED_STATUSES = frozenset({"located", "title_only"})
"""Statuses that come with a point."""

RETRY_STATUSES = frozenset({"failed", "map_error"})
"""Statuses a rerun computes again (the cause may be transient)."""

STATUSES = (
    "located",
    "title_only",
    "ambiguous",
    "street_only",
    "not_found",
    "no_candidates",
    "no_evidence",
    "no_map",
    "scene_error",
    "map_error",
    "failed",
)
"""The one status vocabulary of a camera (module docstring, ``docs/contract.md``)."""

STATUS_ALIASES = {"no_candidate": "no_candidates"}
"""Old status words accepted on input (the service's jobs said ``no_candidate``)."""


def normalize_status(status: str) -> str:
    """The status word of :data:`STATUSES` for an old or current one."""
    return STATUS_ALIASES.get(status, status)


_CONE_RANGE_M = 60.0
_TITLE_CONE_HALF_DEG = 30.0


@dataclass
class CameraResult:
    """What the batch found for one camera (plain data: picklable, JSON-able).

    Attributes
    ----------
    row, id, title
        The list's row (1-based), the camera's id and title.
    status, reason
        See the module docstring; ``reason`` is None when nothing needs saying.
    lat, lon
        The camera's point (None when not placed).
    score
        The best candidate's score: its share of the evidence over the camera's candidates
        (they sum to 1), located or title alike. A title's places share it in proportion to
        their name-match scores (since session 41: a title's candidates carried the match
        score itself, on another scale: two exact matches summed to 2, and a located
        camera's title junction at 1.0 outranked its best candidate's 0.48).
    match_score
        The title's best name-match score in [0, 1] (``geocode_title``'s ``score``: 1 for
        exact names); None without a title match.
    uncertainty_m
        Radius of the point's uncertainty, metres (located: 1-sigma of the best candidate;
        title: the junction's size).
    tie
        Two candidates fit equally well.
    method
        ``"locate"`` (scene) or ``"title"``.
    names_read, names_matched, match_status, match_kinds
        What the title gave: street names read, OSM names matched, the title match's status
        and how each name matched.
    view_text, view_bearing_deg
        Compass words read (title or view column) and their bearing.
    heading_deg, height_m
        The located camera's heading and height (scene only).
    extract
        File name of the extract used (or ``overpass``).
    list_lat, list_lon
        The list's rough point, when it gave one.
    candidates
        Every candidate (dicts with ``rank``, ``source``, ``lat``, ``lon``, ``score``...).
    cones
        View cones: dicts with ``rank``, ``source``, ``score`` and ``lonlat`` (a ring).
    errors
        Problems met on the way: dicts with ``stage`` and ``message``.
    """

    row: int
    id: str
    title: str = ""
    status: str = "failed"
    reason: str | None = None
    lat: float | None = None
    lon: float | None = None
    score: float | None = None
    uncertainty_m: float | None = None
    tie: bool = False
    method: str | None = None
    n_candidates: int = 0
    names_read: list[str] = field(default_factory=list)
    names_matched: list[str] = field(default_factory=list)
    match_status: str | None = None
    match_score: float | None = None
    match_kinds: list[str] = field(default_factory=list)
    view_text: str | None = None
    view_bearing_deg: float | None = None
    heading_deg: float | None = None
    height_m: float | None = None
    extract: str | None = None
    list_lat: float | None = None
    list_lon: float | None = None
    candidates: list[dict[str, Any]] = field(default_factory=list)
    cones: list[dict[str, Any]] = field(default_factory=list)
    errors: list[dict[str, str]] = field(default_factory=list)

    @property
    def placed(self) -> bool:
        """True when the camera has a point."""
        return self.lat is not None and self.lon is not None

    def to_dict(self) -> dict[str, Any]:
        """A JSON-able dict (the batch journal's record).

        The same dict as :func:`dataclasses.asdict`, built without its recursive deep copy
        (0.4 ms a camera, most of a title-only camera's cost): the lists and their dicts
        are copied one level down, the values in them are numbers, strings and rings of
        coordinates that nothing mutates.
        """
        out: dict[str, Any] = {}
        for name in _FIELD_NAMES:
            v = getattr(self, name)
            if isinstance(v, list):
                v = [dict(x) if isinstance(x, dict) else x for x in v]
            out[name] = v
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> CameraResult:
        """Inverse of :meth:`to_dict` (old status words accepted, :data:`STATUS_ALIASES`)."""
        if isinstance(data.get("status"), str):
            data = {**data, "status": normalize_status(data["status"])}
        return cls(**data)

    def fail(self, status: str, reason: str, stage: str) -> CameraResult:
        """Set a failure status and record it in ``errors``."""
        self.status = status
        self.reason = reason
        self.errors.append({"stage": stage, "message": reason})
        return self


_FIELD_NAMES = tuple(f.name for f in fields(CameraResult))


def _finite(x: Any) -> float | None:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _extract_name(m: MapData | None) -> str | None:
    if m is None:
        return None
    src = str(getattr(m, "source", "") or "")
    return os.path.basename(src) if src and os.sep in src else (src or None)


def _compass(text: str | None) -> float | None:
    """Bearing (degrees) of a view column: a number or compass words."""
    if not text:
        return None
    v = _finite(text.replace("°", "").strip())
    if v is not None:
        return v % 360.0
    from camloc_geo.scene import parse_compass

    try:
        b = parse_compass(text)
    except Exception:  # a parser's bug must not stop the batch
        b = None
    if b is not None:
        return float(b)
    try:
        from camloc_geo.geocode import parse_title

        return _finite(parse_title(text).view_bearing_deg)
    except Exception:
        return None


def _cone(lat: float, lon: float, bearing_deg: float, half_deg: float) -> list[list[float]]:
    from camloc_geo.geodesy import GEOD

    ring = [[lon, lat]]
    for k in range(9):
        az = bearing_deg - half_deg + 2.0 * half_deg * k / 8.0
        lo, la, _ = GEOD.fwd(lon, lat, az, _CONE_RANGE_M)
        ring.append([round(float(lo), 8), round(float(la), 8)])
    ring.append([lon, lat])
    return ring


def _match_candidate(match: Any, rank: int, extract: str | None) -> dict[str, Any]:
    """A title match as a candidate; its ``score`` is set by :func:`_share_title_scores`."""
    inter = getattr(match, "intersection", None)
    return {
        "rank": rank,
        "source": "title",
        "status": match.status,
        "score": _finite(match.score),
        "match_score": _finite(match.score),
        "lat": _finite(match.lat),
        "lon": _finite(match.lon),
        "uncertainty_m": _finite(match.uncertainty_m),
        "heading_deg": None,
        "height_m": None,
        "method": "title:" + str(match.status),
        "detail": " & ".join(str(n) for n in (match.names_matched or [])) or None,
        "intersection": getattr(inter, "id", None),
        "extract": extract,
    }


def _share_title_scores(cands: list[dict[str, Any]]) -> None:
    """The title's candidates' ``score``: each place's share of the name-match scores.

    The candidates' scale (shares summing to 1, as ``locate``'s are); ``match_score`` keeps
    the name match. A candidate without a point (``not_found``) has no share.
    """
    placed = [c for c in cands if c.get("lat") is not None and (c.get("match_score") or 0.0) > 0.0]
    total = sum(float(c["match_score"]) for c in placed)
    for c in cands:
        c["score"] = 0.0
    for c in placed:
        c["score"] = float(c["match_score"]) / total


def _title_matches(row: CameraRow, m: MapData, res: CameraResult) -> tuple[list[Any], str | None]:
    """Title matches on a map (best first) and the query used; [] when nothing to match."""
    from camloc_geo.geocode import geocode_title

    if row.streets:
        query = " & ".join(row.streets)
    elif row.title:
        query = row.title
    else:
        return [], None
    near = (row.lat, row.lon) if row.lat is not None and row.lon is not None else None
    radius = None
    if near is not None:
        radius = (row.radius_m or 150.0) + 150.0
    matches = list(geocode_title(query, map_data=m, near=near, radius_m=radius))
    return matches, query


def _read_title(row: CameraRow, res: CameraResult) -> None:
    if not row.title:
        res.view_text = row.view
        res.view_bearing_deg = _compass(row.view)
        return
    from camloc_geo.geocode import parse_title

    parsed = parse_title(row.title)
    res.names_read = [str(s) for s in (row.streets or parsed.streets or [])]
    res.view_text = row.view or parsed.compass_text
    res.view_bearing_deg = _compass(row.view) if row.view else _finite(parsed.view_bearing_deg)


def _equal_places(res: CameraResult, places: list[Any]) -> str:
    """Why a title placed at equal scores is ``ambiguous``: how many places, how far apart,
    how far from the list's point, and what decides.

    A camera "Mabgate & Regent Street" (two streets meeting twice, 61 m apart, both within
    the list point's radius) was ``ambiguous`` with the reason "junction of the map's model,
    at the nodes the two streets share", which says nothing of a second place.
    """
    from camloc_geo.geodesy import great_circle_m

    top = _finite(places[0].score)
    level = [mt for mt in places if _finite(mt.score) == top] or places[:2]
    pts = [(float(mt.lat), float(mt.lon)) for mt in level]
    apart = max(
        great_circle_m(lat1=a[0], lon1=a[1], lat2=b[0], lon2=b[1])
        for i, a in enumerate(pts)
        for b in pts[i + 1 :]
    )
    names = " & ".join(res.names_matched) or "the title's streets"
    text = f"{len(pts)} places fit the title equally well ({names}), up to {apart:.0f} m apart"
    if res.list_lat is not None and res.list_lon is not None:
        dists = [
            great_circle_m(lat1=res.list_lat, lon1=res.list_lon, lat2=p[0], lon2=p[1]) for p in pts
        ]
        text += (
            "; from the list's point "
            + ", ".join(f"{d:.0f} m" for d in dists)
            + ": a radius_m holding one alone, a view or a scene decides"
        )
    else:
        text += ": a point (lat, lon, radius_m), a view or a scene decides"
    return text


def _apply_match(res: CameraResult, matches: list[Any], extract: str | None) -> None:
    """Fill a title-only result from title matches."""
    best = matches[0]
    res.method = "title"
    res.match_status = str(best.status)
    res.names_matched = [str(n) for n in (best.names_matched or [])]
    res.match_kinds = [str(k) for k in (best.match_kinds or [])]
    res.candidates = [_match_candidate(mt, k, extract) for k, mt in enumerate(matches, start=1)]
    _share_title_scores(res.candidates)
    # a not_found match says why nothing was found: it is no candidate
    res.n_candidates = 0 if best.status == "not_found" else len(res.candidates)
    res.score = res.candidates[0]["score"]
    res.match_score = _finite(best.score)
    status = best.status
    with_point = [mt for mt in matches if _finite(mt.lat) is not None]
    tie = status == "ambiguous" or (
        len(with_point) >= 2
        and _finite(with_point[0].score) is not None
        and _finite(with_point[0].score) == _finite(with_point[1].score)
        and status == "junction"
    )
    res.tie = bool(tie)
    if status == "ambiguous" or tie:
        res.status = "ambiguous"
        res.reason = best.reason or "two places match the title equally well"
        if status != "ambiguous":  # a junction's reason alone did not say why (qa7)
            res.reason = _equal_places(res, with_point) + "; " + res.reason
        return
    if status in ("junction", "address", "landmark") and _finite(best.lat) is not None:
        res.status = "title_only"
        res.lat, res.lon = _finite(best.lat), _finite(best.lon)
        res.uncertainty_m = _finite(best.uncertainty_m)
        res.reason = best.reason or None
        if res.view_bearing_deg is not None and res.lat is not None and res.lon is not None:
            res.cones.append(
                {
                    "rank": 1,
                    "source": "title",
                    "score": res.score,
                    "lonlat": _cone(res.lat, res.lon, res.view_bearing_deg, _TITLE_CONE_HALF_DEG),
                }
            )
        return
    if status == "street":
        res.status = "street_only"
        res.reason = best.reason or "the title names one street only: no point invented"
        return
    res.status = "not_found"
    res.reason = best.reason or "the title's names are not in the map"


def _scene_with_evidence(row: CameraRow, res: CameraResult, match: Any | None) -> Any:
    """The row's scene, with the title's junction, prior and view hint where it has none."""
    from camloc_geo.scene import Scene, load_scene, parse_scene

    if row.scene_data is not None:
        sc = parse_scene(row.scene_data)
    else:
        assert row.scene is not None
        sc = load_scene(row.scene)
    data = sc.model_dump(mode="json", exclude={"base_dir"}, exclude_none=True)
    changed = False
    junction = getattr(match, "intersection", None) if match is not None else None
    if match is not None and str(match.status) != "junction":
        junction = None
    if sc.intersection is not None and junction is not None:
        hint = sc.intersection
        if not hint.streets and hint.lat is None:
            data["intersection"]["lat"] = float(junction.lat)
            data["intersection"]["lon"] = float(junction.lon)
            changed = True
    if sc.prior is None:
        if row.has_point:
            data["prior"] = {
                "lat": row.lat,
                "lon": row.lon,
                "radius_m": min(max(row.radius_m or 150.0, 1.0), 50_000.0),
            }
            changed = True
        elif match is not None and _finite(match.lat) is not None:
            data["prior"] = {
                "lat": float(match.lat),
                "lon": float(match.lon),
                "radius_m": min(max(_finite(match.uncertainty_m) or 50.0, 30.0) + 50.0, 50_000.0),
            }
            changed = True
    if (
        res.view_bearing_deg is not None
        and "view_hint" in Scene.model_fields
        and getattr(sc, "view_hint", None) is None
    ):
        data["view_hint"] = {"bearing_deg": res.view_bearing_deg, "text": res.view_text}
        changed = True
    if not changed:
        return sc
    return parse_scene(data, base_dir=sc.base_dir)


def _locate(
    row: CameraRow,
    res: CameraResult,
    m: MapData | None,
    match: Any | None,
    no_map: str | None = None,
) -> None:
    from camloc_geo.absolute import locate
    from camloc_geo.absolute import view_cone as _view_cone
    from camloc_geo.geodesy import normalize_bearing_deg

    try:
        sc = _scene_with_evidence(row, res, match)
    except SceneError as exc:
        where = "scene"
        if row.scene_data is None:
            where = f"scene {os.path.basename(str(row.scene))}"
        res.fail("scene_error", f"{where}: {exc}", "scene")
        return
    if m is None and sc.needs_map:
        if no_map is not None:
            # its point is on no map (no extract covers it, no map source): no_map, as a
            # titled camera there says (it was no_candidates, which a reader filtering the
            # cameras that need a map did not find)
            res.fail(
                "no_map",
                "this scene needs a map (intersection corners, landmarks or street bearings): "
                + no_map,
                "map",
            )
            return
        res.fail(
            "no_candidates",
            "this scene needs a map (intersection corners, landmarks or street bearings) and "
            "no map covers it",
            "locate",
        )
        return
    try:
        r = locate(sc, m)
    except (MapDataError, DegenerateGeometryError, NotEnoughStructureError) as exc:
        # the scene's own geometry (vanishing directions not orthogonal, the camera under
        # the ground): as final as no candidate surviving, never an internal failure that
        # every rerun would compute again
        res.fail("no_candidates", str(exc), "locate")
        return
    except SceneError as exc:
        res.fail("scene_error", str(exc), "locate")
        return
    res.method = "locate"
    res.extract = res.extract or _extract_name(m)
    frame = r.frame
    title_cands = res.candidates
    res.candidates = []
    for c in r.candidates:
        heading = _finite(normalize_bearing_deg(c.camera.angles_deg[0]))
        res.candidates.append(
            {
                "rank": c.rank,
                "source": "locate",
                "status": None,
                "score": _finite(c.score),
                "lat": _finite(c.lat),
                "lon": _finite(c.lon),
                "uncertainty_m": _finite(c.sigma_m),
                "heading_deg": heading,
                "height_m": _finite(c.camera.height_m),
                # the RMS misfit of the map features it matched (locate's residual_m): the
                # job and batch summary pages' popups showed "—" for it (stop 41)
                "residual_m": _finite(c.residual_m),
                "method": c.method,
                "detail": ", ".join(str(f) for f in c.flags) or None,
                "intersection": getattr(r.intersection, "id", None),
                "extract": res.extract,
                # the core's tie rule, as data: the ranks this candidate ties with
                "ambiguous_with": [int(o) for o in c.ambiguous_with],
            }
        )
        poly = _view_cone(c.camera, r.image_size, _CONE_RANGE_M)
        ll = frame.points_geographic_from_enu(poly)
        res.cones.append(
            {
                "rank": c.rank,
                "source": "locate",
                "score": _finite(c.score),
                "lonlat": [[round(float(a), 8), round(float(b), 8)] for a, b in ll],
            }
        )
    # keep the title's matches after the located candidates: the located ones share the
    # evidence (the title's junction among it), so the title's places hold no share of their
    # own (score 0; their name match stays in match_score)
    for k, tc in enumerate(title_cands, start=len(res.candidates) + 1):
        res.candidates.append({**tc, "rank": k, "score": 0.0})
    res.n_candidates = len(r.candidates)
    warnings = list(r.warnings) + list(r.calibration.warnings)
    if not r.candidates:
        res.fail("no_candidates", r.reason or "no candidate survived", "locate")
        return
    best = r.candidates[0]
    res.score = _finite(best.score)
    res.uncertainty_m = _finite(best.sigma_m)
    res.heading_deg = res.candidates[0]["heading_deg"]
    res.height_m = res.candidates[0]["height_m"]
    # a tie between candidates at the same junction (a symmetric one) keeps the best
    # candidate's point, flagged; the candidates layer has both
    res.tie = r.leaders_tie
    if res.tie:
        lead = f"ambiguous: {r.ties[0].text}"
        warnings = [lead] + [w for w in warnings if w != lead]
    res.status = "located"
    res.lat, res.lon = _finite(best.lat), _finite(best.lon)
    res.reason = "; ".join(warnings[:3]) or None


def _with_map(
    row: CameraRow,
    res: CameraResult,
    m: MapData | None,
    matches: list[Any] | None = None,
    extract: str | None = None,
    no_map: str | None = None,
) -> CameraResult:
    """Place a camera with one map (None: scene evidence only; ``no_map`` says why there is
    none where the camera's point is on no map)."""
    res.extract = extract or _extract_name(m)
    if matches is None and m is not None and (row.title or row.streets):
        try:
            matches, _q = _title_matches(row, m, res)
        except Exception as exc:
            res.errors.append({"stage": "title", "message": f"{type(exc).__name__}: {exc}"})
            matches = []
    matches = matches or []
    if matches:
        _apply_match(res, matches, res.extract)
    if row.has_scene:
        title_status, title_reason = res.status, res.reason
        best = matches[0] if matches else None
        res.lat = res.lon = None
        res.cones = []
        _locate(row, res, m, best, no_map)
        if res.status in ("no_candidates",) and title_status == "title_only" and best is not None:
            # the scene failed: fall back to the title's junction, saying so
            locate_reason = res.reason
            _apply_match(res, matches, res.extract)
            res.reason = f"scene not located ({locate_reason}); placed from the title"
        elif res.status == "scene_error" and title_status not in ("failed",):
            res.match_status = res.match_status or title_status
            # no point is given (the scene could not be read): nor the spread of one; the
            # title's junction, with its own, stays in the candidates
            res.uncertainty_m = None
            if title_reason and res.reason:
                res.reason = f"{res.reason}; title: {title_reason}"
        return res
    if not matches:
        if not (row.title or row.streets):
            res.status = "no_evidence"
            res.reason = "no title, street pair or scene to place the camera with" + (
                " (" + "; ".join(row.problems) + ")" if row.problems else ""
            )
            res.errors.append({"stage": "input", "message": res.reason})
        elif m is None:
            res.fail("no_map", "no map to place the title on", "map")
        else:
            res.fail("not_found", "the title names no street found in the map", "title")
        return res
    if res.status not in PLACED_STATUSES:
        res.errors.append({"stage": "title", "message": res.reason or res.status})
    return res


def _note_problems(row: CameraRow, res: CameraResult) -> CameraResult:
    """Say in the reason what was wrong with the row, when the camera was placed anyway."""
    if row.problems and res.status in PLACED_STATUSES:
        note = "list row: " + "; ".join(row.problems)
        res.reason = f"{res.reason}; {note}" if res.reason else note
    return res


def _search(row: CameraRow, res: CameraResult, files: tuple[str, ...]) -> CameraResult:
    """A camera without a point: its title searched in every extract."""
    from camloc_geo.geocode._maps import folder_miss, miss_rank, one_place
    from camloc_geo.osm import area_map

    if not (row.title or row.streets) and row.has_scene:
        # a scene naming no point on any map (or that cannot be read): located without a
        # map, which says what it lacks (scene_error, or a scene that needs a map)
        return _with_map(row, res, None)
    if not (row.title or row.streets):
        res.status = "no_evidence"
        res.reason = "no point, no title and no street pair: nothing to search the maps with" + (
            " (" + "; ".join(row.problems) + ")" if row.problems else ""
        )
        res.errors.append({"stage": "input", "message": res.reason})
        return res
    found: list[tuple[Any, list[Any], str]] = []
    misses: list[tuple[tuple[float, int], str, str]] = []
    for f in files:
        try:
            m = area_map(("file", f))
        except (MapDataError, MapSourceError) as exc:
            res.errors.append({"stage": "map", "message": str(exc)})
            continue
        try:
            matches, _q = _title_matches(row, m, res)
        except Exception as exc:
            res.errors.append({"stage": "title", "message": f"{type(exc).__name__}: {exc}"})
            continue
        if matches and matches[0].status not in ("not_found",):
            found.append((m, matches, os.path.basename(f)))
        elif matches:
            misses.append((miss_rank(matches[0]), matches[0].reason or "", os.path.basename(f)))
    placed = [
        (m, mt, name)
        for m, mt, name in found
        if mt[0].status in ("junction", "address", "landmark", "ambiguous")
    ]
    if len(placed) >= 2 and one_place([mt[0] for _m, mt, _name in placed]):
        # overlapping extracts (or one area in two formats) name the same junction
        top = max(_finite(mt[0].score) or 0.0 for _m, mt, _name in placed)
        m, matches, name = next(p for p in placed if (_finite(p[1][0].score) or 0.0) == top)
        others = ", ".join(other for _m, _mt, other in placed if other != name)
        res = _with_map(row, res, m, matches, extract=name)
        res.reason = (res.reason or "") + f"; the same junction in {others}"
        return res
    if len(placed) >= 2:
        res.method = "title"
        res.tie = True
        res.match_status = "ambiguous"
        names = [name for _m, _mt, name in placed]
        k = 0
        for _m, mt, name in placed:
            for one in mt:
                k += 1
                res.candidates.append(_match_candidate(one, k, name))
        _share_title_scores(res.candidates)
        res.n_candidates = len(res.candidates)
        res.score = res.candidates[0]["score"]
        res.match_score = _finite(placed[0][1][0].score)
        return res.fail(
            "ambiguous", "the title matches in several extracts: " + ", ".join(names), "title"
        )
    if placed or found:
        m, matches, name = (placed or found)[0]
        return _with_map(row, res, m, matches, extract=name)
    if misses:
        _rank, why, where = min(misses, key=lambda x: x[0])
        reason = folder_miss(why, where, len(misses))
    else:
        reason = "the title names no street found in any extract"
    return res.fail(
        "not_found", reason or "the title names no street found in any extract", "title"
    )


def _swapped_hint(plan: MapPlan, row: CameraRow) -> str:
    """A hint when the row's point, outside every map, lies in one with lat and lon swapped
    (a list exported as x=lat, y=lon: the camera was only ``no_map``)."""
    from dataclasses import replace

    lat, lon = row.lat, row.lon
    if lat is None or lon is None or not (-90 <= lon <= 90):
        return ""
    try:
        area = plan.area_of(replace(row, lat=lon, lon=lat))
    except Exception:  # a hint only
        return ""
    if area[0] in ("none", "net"):
        return ""
    name = plan.source_name(area) if hasattr(plan, "source_name") else None
    where = f" (in {name})" if name else ""
    return (
        f"; with lat and lon swapped, lat={lon:.6f}, lon={lat:.6f} lies in a map{where}: "
        "are the list's lat and lon columns the other way round?"
    )


def area_of_row(plan: MapPlan, row: CameraRow) -> Area:
    """The row's area; a row without a point but with a scene: the area at the scene's
    point (its intersection or prior), when a map covers it (else as before: its title is
    searched in every extract)."""
    from camloc_geo.cameras._list import area_row

    at_scene = area_row(row)
    if at_scene is not row:
        area = plan.area_of(at_scene)
        if area[0] != "none" or not (row.title or row.streets):
            # (a scene's point on no map, and no title to search: that area's "none", so
            # the camera says no_map and why; searching every extract for nothing ended
            # no_candidates)
            return area
    return plan.area_of(row)


def geocode_camera(
    row: CameraRow,
    *,
    map_data: MapData | None = None,
    map_source: str | os.PathLike[str] | None = None,
    network: bool = False,
    plan: MapPlan | None = None,
    area: Area | None = None,
) -> CameraResult:
    """Place one camera from its listing (title, point, street pair) and its scene.

    Never raises for a bad row: the result's ``status`` and ``reason`` say what happened
    (see the module docstring for the statuses).

    Parameters
    ----------
    row
        The camera (:func:`camloc_geo.batch.read_camera_list` or :class:`CameraRow`).
    map_data
        The map to use (a loaded :class:`~camloc_geo.osm.MapData`); overrides the others.
    map_source
        An extract or a folder of extracts; the one covering the camera's point is used
        (loaded once per process), a title without point is searched in each.
    network
        Without ``map_source``: may the map around the camera's point be fetched from
        Overpass.
    plan, area
        A prepared :func:`~camloc_geo.osm.map_plan` and the camera's area (what
        :func:`run_batch` passes; computed from ``map_source`` when omitted).
    """
    res = CameraResult(row=row.row, id=row.id, title=row.title, list_lat=row.lat, list_lon=row.lon)
    try:
        for p in row.problems:
            res.errors.append({"stage": "input", "message": p})
        _read_title(row, res)
        return _note_problems(row, _geocode(row, res, map_data, map_source, network, plan, area))
    except Exception as exc:  # isolate every camera: the batch goes on
        log.debug("camera %s failed", row.id, exc_info=True)
        return res.fail("failed", f"{type(exc).__name__}: {exc}", "internal")


def _geocode(
    row: CameraRow,
    res: CameraResult,
    map_data: MapData | None,
    map_source: str | os.PathLike[str] | None,
    network: bool,
    plan: MapPlan | None,
    area: Area | None,
) -> CameraResult:
    if map_data is not None:
        return _with_map(row, res, map_data)
    if plan is None:
        from camloc_geo.osm import map_plan

        plan = (
            _cached_plan(map_source, network)
            if map_source is not None
            else map_plan(None, network=network)
        )
    if area is None:
        area = area_of_row(plan, row)
    kind = area[0]
    if kind == "none":
        if row.has_scene and not (row.title or row.streets):
            # a scene with references may not need a map at all
            return _with_map(row, res, None, no_map=str(area[1]) + _swapped_hint(plan, row))
        edge = _edge_extract(plan, row)
        if edge is not None:
            near_res = _at_the_edge(row, res, plan, *edge)
            if near_res is not None:
                return near_res
        return res.fail("no_map", str(area[1]) + _swapped_hint(plan, row), "map")
    if kind == "search":
        return _search(row, res, tuple(area[1]))
    from camloc_geo.osm import area_map

    try:
        m = area_map(area)
    except (MapDataError, MapSourceError) as exc:
        return res.fail("map_error", str(exc), "map")
    name = "overpass" if kind == "net" else os.path.basename(str(area[1]))
    return _with_map(row, res, m, extract=name)


def _edge_extract(plan: MapPlan, row: CameraRow) -> tuple[str, float, float, float] | None:
    """For a titled camera whose point no extract contains: the extract whose bounds come
    nearest its point within the title's search radius, as ``(path, distance_m, lat, lon)``
    (the point of the bounds nearest the camera's); None when there is none."""
    if row.lat is None or row.lon is None or not (row.title or row.streets):
        return None
    files = [
        f
        for f in getattr(plan, "files", ()) or ()
        if not row.area or row.area.lower() in os.path.basename(f).lower()
    ]
    if not files:
        return None
    from camloc_geo.geodesy import great_circle_m
    from camloc_geo.osm import extract_bounds

    radius = (row.radius_m or 150.0) + 150.0  # as _title_matches searches
    best: tuple[str, float, float, float] | None = None
    for f in files:
        try:
            s, w, n, e = extract_bounds(f)
        except (MapDataError, OSError):
            continue
        lat, lon = min(max(row.lat, s), n), min(max(row.lon, w), e)
        d = great_circle_m(lat1=row.lat, lon1=row.lon, lat2=lat, lon2=lon)
        if d <= radius and (best is None or d < best[1]):
            best = (f, d, lat, lon)
    return best


def _at_the_edge(
    row: CameraRow,
    res: CameraResult,
    plan: MapPlan,
    path: str,
    dist_m: float,
    lat: float,
    lon: float,
) -> CameraResult | None:
    """The camera placed by its title on an extract its point lies just outside of (a
    rough point past the edge of a city's extract was 'no_map' although the junction its
    title names is in the extract, within the point's radius); None when not placed."""
    from camloc_geo.osm import area_map

    try:
        m = area_map(plan.area_for_point(lat, lon, name=row.area))
    except (MapDataError, MapSourceError, InputError):
        return None
    import copy

    placed = _with_map(row, copy.deepcopy(res), m, extract=os.path.basename(path))
    if placed.status not in PLACED_STATUSES:
        return None
    placed.reason = (placed.reason or "") + (
        f"; the list's point lies {dist_m:.0f} m outside {os.path.basename(path)}: placed at"
        " what its title names there"
    )
    return placed


_PLANS: OrderedDict[tuple[str, bool, int, int], MapPlan] = OrderedDict()
_PLANS_LOCK = threading.Lock()
PLAN_CACHE_ENTRIES = 16
"""How many map sources' plans are kept (the most recently used)."""


def _source_version(map_source: str | os.PathLike[str]) -> tuple[int, int]:
    """``(mtime_ns, size)`` of an extract or a folder of extracts (a folder's modification
    time changes when an extract is added, removed or renamed in it); ``(0, 0)`` when it is
    not on disk (the plan then says why)."""
    try:
        st = os.stat(map_source)
    except (OSError, TypeError, ValueError):
        return 0, 0
    return st.st_mtime_ns, st.st_size


def _cached_plan(map_source: str | os.PathLike[str], network: bool) -> MapPlan:
    """The map plan of a source, kept per version of it (an extract copied into a folder
    after a first look is found), at most ``PLAN_CACHE_ENTRIES`` sources."""
    from camloc_geo.osm import map_plan

    key = (str(map_source), bool(network), *_source_version(map_source))
    with _PLANS_LOCK:
        plan = _PLANS.get(key)
        if plan is not None:
            _PLANS.move_to_end(key)
            return plan
    plan = map_plan(map_source, network=network)
    with _PLANS_LOCK:
        _PLANS[key] = plan
        while len(_PLANS) > PLAN_CACHE_ENTRIES:
            _PLANS.popitem(last=False)
    return plan
