"""Typed outputs of every command and front end, one serialiser, and their JSON Schemas.

Three documents leave the library:

``candidates``
    The candidate GeoJSON of :func:`camloc_geo.api.locate_scene` (``camloc locate``): a
    FeatureCollection in EPSG:4326 (``[lon, lat]``) of ``candidate`` points (best first),
    ``view_cone`` polygons, ``matched_point`` points, and the ``intersection`` used with its
    ``corner`` points. See ``docs/candidates.md``.
``calibration``
    The relative pose of :func:`camloc_geo.api.calibrate_scene` (``camloc calibrate``).
``corners``
    Intersections and their kerb corners (``camloc corners``), a FeatureCollection.

Each is a tree of the dataclasses below; :func:`to_json` turns any of them into plain JSON
(optional fields are left out when ``None``), and :func:`output_json_schema` gives
the JSON Schema (draft 2020-12, through pydantic) of each.

Intersection features carry the intersection's kind under two names with the same value:
``kind_detail`` (the name ``camloc corners`` has always used) and ``intersection_kind`` (the
name ``camloc locate`` has always used). New code should read ``kind_detail``.

This module imports only the standard library (pydantic on :func:`output_json_schema`), so
front ends may import it at start-up.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from camloc_geo._ties import TIE_DISTANCE_M, TIE_SCORE_RATIO

if TYPE_CHECKING:
    from camloc_geo.absolute import Candidate, LocateResult, Match
    from camloc_geo.camera import Camera
    from camloc_geo.cameras import CameraResult
    from camloc_geo.osm import Intersection, MapData
    from camloc_geo.relative import CalibrationResult

__all__ = [
    "ATTRIBUTION",
    "JOB_LAYERS",
    "QGIS_STYLES",
    "QGIS_STYLE_NAME",
    "TIE_DISTANCE_M",
    "TIE_SCORE_RATIO",
    "CalibrationOutput",
    "CalibrationSummary",
    "CandidateCollection",
    "CandidateCollectionProperties",
    "CandidateProperties",
    "CornerProperties",
    "CornersCollection",
    "Feature",
    "IncidentStreetProperties",
    "IntersectionProperties",
    "MatchProperties",
    "MatchedPointProperties",
    "OutputKind",
    "PointGeometry",
    "PolygonGeometry",
    "TieProperties",
    "ViewConeProperties",
    "calibration_output",
    "camera_job_result",
    "candidates_collection",
    "candidates_geojson",
    "corners_collection",
    "intersection_features",
    "intersections_geojson",
    "job_result_geojson",
    "job_result_geopackage",
    "output_json_schema",
    "point",
    "streets_json",
    "to_json",
    "write_layer_styles",
]

ATTRIBUTION = "Map data © OpenStreetMap contributors, ODbL 1.0"
"""The one attribution string of every output built from OpenStreetMap data."""

OutputKind = Literal["candidates", "calibration", "corners"]


_OMIT_NONE = {"omit_none": True}  # field metadata: left out of the JSON when None


# ------------------------------------------------------------------------- geometries
@dataclass(kw_only=True)
class PointGeometry:
    """A GeoJSON Point, ``[lon, lat]`` degrees WGS 84."""

    type: Literal["Point"] = "Point"
    coordinates: list[float]


@dataclass(kw_only=True)
class PolygonGeometry:
    """A GeoJSON Polygon: one closed ring of ``[lon, lat]``."""

    type: Literal["Polygon"] = "Polygon"
    coordinates: list[list[list[float]]]


def point(lon: float, lat: float) -> PointGeometry:
    """A Point at ``lon``, ``lat`` (degrees)."""
    return PointGeometry(coordinates=[lon, lat])


# ------------------------------------------------------------------ candidate features
@dataclass(kw_only=True)
class MatchProperties:
    """One annotated ground pixel matched to a map point by a candidate."""

    kind: Literal["reference", "corner", "landmark"]
    label: str
    pixel: list[float]
    map_corner: str | None = field(default=None, metadata=_OMIT_NONE)
    order: int | None = field(default=None, metadata=_OMIT_NONE)
    misfit_m: float
    mahalanobis2: float
    map_lonlat: list[float]


@dataclass(kw_only=True)
class CandidateProperties:
    """A candidate camera position (``kind: "candidate"``); see ``docs/candidates.md``."""

    kind: Literal["candidate"] = "candidate"
    rank: int
    score: float
    lat: float
    lon: float
    height_m: float
    heading_deg: float
    pitch_deg: float
    roll_deg: float
    focal_px: float
    method: str
    residual_m: float | None
    sigma_m: float | None
    scale: float
    refined: bool
    merged: int
    flags: list[str]
    scene: str
    matches: list[MatchProperties]
    ambiguous_with: list[int] = field(default_factory=list)
    intersection: str | None = field(default=None, metadata=_OMIT_NONE)


@dataclass(kw_only=True)
class ViewConeProperties:
    """The ground footprint of a candidate's view (``kind: "view_cone"``)."""

    kind: Literal["view_cone"] = "view_cone"
    rank: int
    score: float


@dataclass(kw_only=True)
class MatchedPointProperties:
    """A map point a candidate matched (``kind: "matched_point"``)."""

    kind: Literal["matched_point"] = "matched_point"
    rank: int
    label: str
    match_kind: Literal["reference", "corner", "landmark"]
    pixel: list[float]
    misfit_m: float
    map_corner: str | None = field(default=None, metadata=_OMIT_NONE)


@dataclass(kw_only=True)
class IncidentStreetProperties:
    """A street meeting at an intersection (``camloc corners``)."""

    name: str
    bearing_deg: float
    back_bearing_deg: float
    highway: str
    oneway: bool
    lanes: float | None
    width_m: float
    width_source: str
    carriageways: int


@dataclass(kw_only=True)
class IntersectionProperties:
    """An intersection (``kind: "intersection"``).

    ``kind_detail`` and ``intersection_kind`` hold the same value (``junction``,
    ``roundabout``, ``unmodelled``...): both names are kept for older readers.
    """

    kind: Literal["intersection"] = "intersection"
    id: str
    streets: list[str]
    kind_detail: str
    intersection_kind: str
    warnings: list[str] | None = field(default=None, metadata=_OMIT_NONE)
    incident_streets: list[IncidentStreetProperties] | None = field(
        default=None, metadata=_OMIT_NONE
    )
    corner_distances_m: list[float] | None = field(default=None, metadata=_OMIT_NONE)
    osm_nodes: list[int] | None = field(default=None, metadata=_OMIT_NONE)


@dataclass(kw_only=True)
class CornerProperties:
    """A modelled kerb corner of an intersection (``kind: "corner"``)."""

    kind: Literal["corner"] = "corner"
    intersection: str
    order: int
    streets: list[str]


Properties = (
    CandidateProperties
    | ViewConeProperties
    | MatchedPointProperties
    | IntersectionProperties
    | CornerProperties
)


@dataclass(kw_only=True)
class Feature:
    """A GeoJSON Feature."""

    type: Literal["Feature"] = "Feature"
    geometry: PointGeometry | PolygonGeometry
    properties: Properties


@dataclass(kw_only=True)
class CalibrationSummary:
    """The relative pose a candidate list was computed from."""

    focal_px: float
    height_m: float
    pitch_deg: float
    roll_deg: float
    method: str
    intrinsics_method: str
    outlier_annotators: list[str]


@dataclass(kw_only=True)
class TieProperties:
    """Candidates the evidence cannot tell apart (the core's tie rule, as data)."""

    ranks: list[int]
    text: str
    why: str


@dataclass(kw_only=True)
class CandidateCollectionProperties:
    """What the candidate list as a whole says."""

    scene: str
    methods_tried: list[str]
    n_candidates: int
    reason: str | None
    warnings: list[str]
    calibration: CalibrationSummary
    ties: list[TieProperties] = field(default_factory=list)
    attribution: str = ATTRIBUTION


@dataclass(kw_only=True)
class CandidateCollection:
    """The candidate GeoJSON (``camloc locate``), EPSG:4326."""

    type: Literal["FeatureCollection"] = "FeatureCollection"
    features: list[Feature]
    properties: CandidateCollectionProperties


@dataclass(kw_only=True)
class CornersCollection:
    """Intersections and their corners (``camloc corners``), EPSG:4326."""

    type: Literal["FeatureCollection"] = "FeatureCollection"
    features: list[Feature]
    attribution: str = ATTRIBUTION


# ------------------------------------------------------------------------- calibration
@dataclass(kw_only=True)
class CalibrationOutput:
    """The relative pose (``camloc calibrate``): camera in the scene's world frame.

    ``fallback`` repeats ``intrinsics_method`` for older readers. ``annotators`` holds one
    free-form record per annotator (closed-form solution, vanishing points).
    """

    focal_px: float
    principal_point: list[float]
    height_m: float
    camera_in_world: list[float]
    pitch_deg: float
    roll_deg: float
    cam_from_world: list[list[float]]
    rotation: list[list[float]]
    method: str
    intrinsics_method: str
    fallback: str
    intrinsics_reason: str
    distance_to_origin_m: float
    camera_in_world_sigma_m: list[float] | None = field(default=None, metadata=_OMIT_NONE)
    height_sigma_m: float | None = field(default=None, metadata=_OMIT_NONE)
    focal_sigma_px: float | None = field(default=None, metadata=_OMIT_NONE)
    rotation_sigma_deg: list[float] | None = field(default=None, metadata=_OMIT_NONE)
    rms_residual_px: float | None = field(default=None, metadata=_OMIT_NONE)
    width_sign: float = 1.0
    annotator_weights: list[float] = field(default_factory=list)
    annotator_corners: list[str] | None = field(default=None, metadata=_OMIT_NONE)
    corner_mistakes: list[str] | None = field(default=None, metadata=_OMIT_NONE)
    outlier_annotators: list[str] = field(default_factory=list)
    cluster: dict[str, Any] = field(default_factory=dict)
    annotators: list[dict[str, Any]] = field(default_factory=list)
    warnings: list[str] | None = field(default=None, metadata=_OMIT_NONE)


def calibration_output(cal: CalibrationResult) -> CalibrationOutput:
    """The typed output of a calibration."""
    import numpy as np

    cam = cal.camera
    _heading, pitch, roll = cam.angles_deg
    sigma = cal.position_sigma_m
    return CalibrationOutput(
        focal_px=cam.focal_px,
        principal_point=list(cam.principal_point),
        height_m=cam.height_m,
        camera_in_world=cam.center_in_world.tolist(),
        pitch_deg=pitch,
        roll_deg=roll,
        cam_from_world=cam.cam_from_world.tolist(),
        rotation=cam.cam_from_world_rotation.tolist(),
        method=cal.method,
        intrinsics_method=cal.intrinsics_method,
        fallback=cal.intrinsics_method,
        intrinsics_reason=cal.intrinsics_reason,
        distance_to_origin_m=float(np.linalg.norm(cam.center_in_world)),
        camera_in_world_sigma_m=None if sigma is None else sigma.tolist(),
        height_sigma_m=None if sigma is None else float(sigma[2]),
        focal_sigma_px=cal.focal_sigma_px,
        rotation_sigma_deg=(
            None if cal.rotation_sigma_deg is None else cal.rotation_sigma_deg.tolist()
        ),
        rms_residual_px=cal.rms_residual_px,
        width_sign=cal.width_sign,
        annotator_weights=cal.annotator_weights,
        annotator_corners=cal.annotator_corners or None,
        corner_mistakes=cal.corner_mistakes if cal.annotator_corners else None,
        outlier_annotators=cal.outlier_annotators,
        cluster=cal.cluster,
        annotators=[a.to_dict() for a in cal.annotators],
        warnings=cal.warnings or None,
    )


# --------------------------------------------------------------------------- corners
def _intersection_properties(inter: Intersection, *, detailed: bool) -> IntersectionProperties:
    if not detailed:
        return IntersectionProperties(
            id=inter.id,
            streets=[s.name for s in inter.streets],
            kind_detail=inter.kind,
            intersection_kind=inter.kind,
        )
    streets = [
        IncidentStreetProperties(
            name=s.name,
            bearing_deg=round(s.bearing_deg, 3),
            back_bearing_deg=round(s.back_bearing_deg, 3),
            highway=s.highway,
            oneway=s.oneway,
            lanes=s.lanes,
            width_m=round(s.width_m, 2),
            width_source=s.width_source,
            carriageways=s.carriageways,
        )
        for s in inter.streets
    ]
    return IntersectionProperties(
        id=inter.id,
        streets=list(inter.street_names),
        kind_detail=inter.kind,
        intersection_kind=inter.kind,
        warnings=list(inter.warnings),
        incident_streets=streets,
        corner_distances_m=[round(d, 3) for d in inter.corner_distances_m],
        osm_nodes=list(inter.osm_nodes),
    )


def intersection_features(inter: Intersection, *, detailed: bool = True) -> list[Feature]:
    """An intersection's feature and its corners' (``detailed``: with incident streets...)."""
    feats = [
        Feature(
            geometry=point(inter.lon, inter.lat),
            properties=_intersection_properties(inter, detailed=detailed),
        )
    ]
    for corner in inter.corners:
        props = CornerProperties(
            intersection=inter.id, order=corner.order, streets=list(corner.streets)
        )
        feats.append(Feature(geometry=point(corner.lon, corner.lat), properties=props))
    return feats


def corners_collection(intersections: Iterable[Intersection]) -> CornersCollection:
    """The ``camloc corners`` FeatureCollection of intersections and their corners."""
    feats = [f for inter in intersections for f in intersection_features(inter)]
    return CornersCollection(features=feats)


# ------------------------------------------------------------------------ serialiser
_PLAIN_TYPES = frozenset({str, int, float, bool, type(None)})
_FIELDS: dict[type, tuple[tuple[str, bool], ...]] = {}


def _fields_of(cls: type) -> tuple[tuple[str, bool], ...]:
    """``(name, omit when None)`` of a dataclass' fields, once per class."""
    try:
        return _FIELDS[cls]
    except KeyError:
        out = tuple((f.name, bool(f.metadata.get("omit_none"))) for f in dataclasses.fields(cls))
        _FIELDS[cls] = out
        return out


def to_json(value: Any) -> Any:
    """Plain JSON (dicts, lists, numbers, strings) of an output dataclass tree.

    Fields with ``omit_none`` metadata are left out when None; floats are Python floats.
    """
    t = type(value)
    if t in _PLAIN_TYPES:
        return value
    if t is list or t is tuple:
        return [to_json(v) for v in value]
    if t is dict:
        return {str(k): to_json(v) for k, v in value.items()}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        out: dict[str, Any] = {}
        for name, omit_none in _fields_of(t):
            v = getattr(value, name)
            if v is None and omit_none:
                continue
            out[name] = to_json(v)
        return out
    if isinstance(value, dict):
        return {str(k): to_json(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_json(v) for v in value]
    if hasattr(value, "tolist"):  # numpy scalars and arrays
        return to_json(value.tolist())
    return value


_SCHEMA_ROOTS: dict[str, Any] = {
    "candidates": CandidateCollection,
    "calibration": CalibrationOutput,
    "corners": CornersCollection,
}


def output_json_schema(kind: OutputKind) -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of an output: ``candidates``, ``calibration``, ``corners``.

    Raises
    ------
    ValueError
        An unknown kind.
    """
    if kind not in _SCHEMA_ROOTS:
        raise ValueError(f"unknown output {kind!r}: expected one of {', '.join(_SCHEMA_ROOTS)}")
    from pydantic import TypeAdapter

    schema: dict[str, Any] = TypeAdapter(_SCHEMA_ROOTS[kind]).json_schema(mode="serialization")
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = f"camloc {kind} output"
    return schema


# ------------------------------------------------------------------------- candidates
def _angles_deg(camera: Camera) -> tuple[float, float, float]:
    """``camera.angles_deg`` (:func:`camloc_geo.camera.angles_from_rotation`, which now takes
    its clamp and cross product on Python floats itself)."""
    from camloc_geo.camera import angles_from_rotation

    return angles_from_rotation(camera.cam_from_world_rotation)


def _match_properties(m: Match, lonlat: list[float]) -> MatchProperties:
    return MatchProperties(
        kind=m.kind,
        label=m.label,
        pixel=list(m.pixel),
        map_corner=m.map_corner,
        order=m.order,
        misfit_m=m.misfit_m,
        mahalanobis2=m.mahalanobis2,
        map_lonlat=lonlat,
    )


def _candidate_feature(
    c: Candidate, result: LocateResult, match_lonlat: list[list[float]]
) -> Feature:
    from camloc_geo.geodesy import normalize_bearing_deg

    heading, pitch_c, roll_c = _angles_deg(c.camera)
    # Flag.__str__'s formula; ``_value_`` is the member's value without the enum property's
    # descriptor (~1 us a flag)
    flags = [f.kind._value_ if f.label is None else f"{f.kind._value_}:{f.label}" for f in c.flags]
    props = CandidateProperties(
        rank=c.rank,
        score=c.score,
        lat=c.lat,
        lon=c.lon,
        height_m=c.camera.height_m,
        heading_deg=normalize_bearing_deg(float(heading)),
        pitch_deg=pitch_c,
        roll_deg=roll_c,
        focal_px=c.camera.focal_px,
        method=c.method,
        residual_m=None if math.isnan(c.residual_m) else c.residual_m,
        sigma_m=c.sigma_m,
        scale=c.scale,
        refined=c.refined,
        merged=c.merged,
        flags=flags,
        scene=result.scene_id,
        matches=[_match_properties(m, ll) for m, ll in zip(c.matches, match_lonlat, strict=True)],
        ambiguous_with=list(c.ambiguous_with),
        intersection=c.intersection_id,
    )
    return Feature(geometry=point(c.lon, c.lat), properties=props)


def _view_cone_feature(c: Candidate, ring_lonlat: list[list[float]]) -> Feature:
    return Feature(
        geometry=PolygonGeometry(coordinates=[ring_lonlat]),
        properties=ViewConeProperties(rank=c.rank, score=c.score),
    )


def _matched_point_feature(c: Candidate, m: Match, lonlat: list[float]) -> Feature:
    props = MatchedPointProperties(
        rank=c.rank,
        label=m.label,
        match_kind=m.kind,
        pixel=list(m.pixel),
        misfit_m=m.misfit_m,
        map_corner=m.map_corner,
    )
    return Feature(geometry=point(lonlat[0], lonlat[1]), properties=props)


def _lonlat_of_points(
    result: LocateResult, range_m: float, view_cones: bool
) -> tuple[list[list[list[float]]], list[list[list[float]]]]:
    """Every candidate's matched map points and view-cone ring as ``[lon, lat]`` lists.

    One projection for the whole answer (the same numbers as one call per point).
    """
    import numpy as np

    from camloc_geo.absolute._cone import view_cones as _view_cones

    cands = result.candidates
    parts = [np.asarray([m.map_en for m in c.matches], dtype=float).reshape(-1, 2) for c in cands]
    if view_cones:
        parts += _view_cones([c.camera for c in cands], result.image_size, range_m)
    if not parts:
        return [], []
    ll = result.frame.points_geographic_from_enu(np.vstack(parts)).tolist()
    out: list[list[list[float]]] = []
    start = 0
    for part in parts:
        out.append(ll[start : start + len(part)])
        start += len(part)
    return out[: len(cands)], out[len(cands) :]


def _collection_properties(result: LocateResult) -> CandidateCollectionProperties:
    cal = result.calibration
    _h, pitch, roll = _angles_deg(cal.camera)
    return CandidateCollectionProperties(
        scene=result.scene_id,
        methods_tried=result.methods_tried,
        n_candidates=len(result.candidates),
        reason=result.reason,
        warnings=result.warnings + cal.warnings,
        ties=[TieProperties(ranks=list(t.ranks), text=t.text, why=t.why) for t in result.ties],
        calibration=CalibrationSummary(
            focal_px=cal.camera.focal_px,
            height_m=cal.camera.height_m,
            pitch_deg=pitch,
            roll_deg=roll,
            method=cal.method,
            intrinsics_method=cal.intrinsics_method,
            outlier_annotators=cal.outlier_annotators,
        ),
    )


def candidates_collection(
    result: LocateResult, *, view_cones: bool = True, view_cone_range_m: float | None = None
) -> CandidateCollection:
    """The typed candidate FeatureCollection (:class:`CandidateCollection`) of a locate result."""
    cands = result.candidates
    range_m = result.view_cone_range_m if view_cone_range_m is None else view_cone_range_m
    match_ll, cone_ll = _lonlat_of_points(result, range_m, view_cones)
    feats = [_candidate_feature(c, result, ll) for c, ll in zip(cands, match_ll, strict=True)]
    if view_cones:
        feats += [_view_cone_feature(c, ring) for c, ring in zip(cands, cone_ll, strict=True)]
    feats += [
        _matched_point_feature(c, m, lonlat)
        for c, lls in zip(cands, match_ll, strict=True)
        for m, lonlat in zip(c.matches, lls, strict=True)
    ]
    if result.intersection is not None:
        feats += intersection_features(result.intersection, detailed=False)
    return CandidateCollection(features=feats, properties=_collection_properties(result))


def candidates_geojson(
    result: LocateResult, *, view_cones: bool = True, view_cone_range_m: float | None = None
) -> dict[str, Any]:
    """The candidate GeoJSON FeatureCollection of the scene contract (``docs/candidates.md``).

    Candidate Point features (``kind: "candidate"``, best first) carry every property of
    the contract plus ``sigma_m`` (1-sigma position uncertainty), ``scale``, ``flags``,
    ``matches``, ``merged`` and ``ambiguous_with``. Extra features: ``view_cone`` polygons
    (one per candidate, reaching ``view_cone_range_m``, default the result's
    :attr:`LocateSettings.view_cone_range_m`), ``matched_point`` points (the map points each
    candidate matched), and the ``intersection`` used, with its ``corner`` points.
    """
    doc: dict[str, Any] = to_json(
        candidates_collection(result, view_cones=view_cones, view_cone_range_m=view_cone_range_m)
    )
    return doc


# ------------------------------------------------------------------------- map views
def intersections_geojson(intersections: Iterable[Intersection]) -> dict[str, Any]:
    """A FeatureCollection of intersections (``kind: "intersection"``) and their corners.

    Intersection properties: ``id``, ``streets`` (names, clockwise), ``kind_detail``
    (``junction``/``roundabout``/``unmodelled``; also as ``intersection_kind``, the same
    value), ``warnings``, ``incident_streets`` (bearing, highway, width... per street),
    ``corner_distances_m``. Corner properties: ``intersection`` (the id), ``order``
    (clockwise from above, from 0), ``streets`` (the two streets it lies between).
    Coordinates are ``[lon, lat]``. The typed model is
    :class:`CornersCollection`.
    """
    doc: dict[str, Any] = to_json(corners_collection(intersections))
    return doc


def streets_json(m: MapData, lat: float, lon: float, radius_m: float) -> dict[str, Any]:
    """Streets near a point with their bearings, and every street segment of the map."""
    near = [
        {"name": n, "bearing_deg": round(b, 3)} for n, b in m.street_bearings(lat, lon, radius_m)
    ]
    seen: dict[str, dict[str, Any]] = {}
    for s in m.streets:
        entry = seen.setdefault(
            s.name,
            {"name": s.name, "highway": s.highway, "oneway": s.oneway, "segments": 0, "ways": []},
        )
        entry["segments"] += 1
        entry["ways"] = sorted(set(entry["ways"]) | set(s.way_ids))
    return {
        "lat": lat,
        "lon": lon,
        "radius_m": radius_m,
        "near": near,
        "streets": sorted(seen.values(), key=lambda e: e["name"]),
        "attribution": ATTRIBUTION,
    }


# ------------------------------------------------------------------------- camera lists
_JOB_FIELDS = (
    "id",
    "title",
    "status",
    "reason",
    "lat",
    "lon",
    "score",
    "uncertainty_m",
    "method",
    "match_status",
    "match_score",
    "heading_deg",
    "height_m",
    "extract",
    "n_candidates",
)


def camera_job_result(result: CameraResult) -> dict[str, Any]:
    """One camera of an HTTP job, from the camera-list engine's result.

    The camera's fields (``status`` in the engine's vocabulary, ``docs/contract.md``), the
    tie as ``ambiguous`` (the engine's ``tie``), and ``candidates`` as GeoJSON point features
    (``kind: "candidate"``, best first) for the job's GeoJSON and GeoPackage.
    """
    out: dict[str, Any] = {k: getattr(result, k, None) for k in _JOB_FIELDS}
    out["ambiguous"] = bool(result.tie)
    feats = []
    for c in result.candidates:
        if c.get("lat") is None or c.get("lon") is None:
            continue
        props = {k: v for k, v in c.items() if v is not None}
        props["kind"] = "candidate"
        feats.append(
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [c["lon"], c["lat"]]},
                "properties": props,
            }
        )
    out["candidates"] = feats
    return out


# ------------------------------------------------------------------------- job results
def job_result_geojson(job_id: str, results: Iterable[dict[str, Any]]) -> dict[str, Any]:
    """The result of a camera-list job as one GeoJSON FeatureCollection.

    Per camera (in list order) one ``camera`` feature (its status, reason and best position;
    no geometry when it was not placed; ``row``, its row of the list from 1, when the results
    give it), then its ``candidate`` features, each carrying the camera's id as ``camera_id``
    and its row as ``camera_row`` (two rows of a list may share an id).
    """
    feats: list[dict[str, Any]] = []
    for r in results:
        props = {k: v for k, v in r.items() if k != "candidates"}
        props["kind"] = "camera"
        geom = (
            {"type": "Point", "coordinates": [r["lon"], r["lat"]]}
            if r.get("lat") is not None and r.get("lon") is not None
            else None
        )
        feats.append({"type": "Feature", "geometry": geom, "properties": props})
        for c in r.get("candidates", []) or []:
            cp = dict(c["properties"])
            cp["camera_id"] = r.get("id")
            if r.get("row") is not None:
                cp["camera_row"] = r["row"]
            feats.append({"type": "Feature", "geometry": c["geometry"], "properties": cp})
    return {
        "type": "FeatureCollection",
        "features": feats,
        "properties": {"job": job_id, "attribution": ATTRIBUTION},
    }


JOB_LAYERS = (("cameras", "camera"), ("candidates", "candidate"))
"""GeoPackage layers of a job result: ``(layer name, feature kind)``."""


_NUMERIC_NAMES = frozenset({"lat", "lon", "score", "rank", "row", "camera_row", "scale"})


def _numeric_name(name: str) -> bool:
    """Whether a job result's property is a number by its name (``heading_deg``, ``height_m``,
    ``focal_px``, ``score``...)."""
    return name in _NUMERIC_NAMES or name.endswith(("_deg", "_m", "_px"))


QGIS_STYLE_NAME = "camloc"
"""Name of camloc's default QGIS style of a layer in a GeoPackage's ``layer_styles`` table
(the QGIS plugin's name for its own)."""

QGIS_STYLES = Path(__file__).resolve().parent / "data" / "qgis_styles"
"""The QGIS styles camloc's GeoPackages carry (``<name>.qml`` and ``.sld``), made from the QGIS
plugin's by ``qgis_plugin/make_batch_styles.py`` (run it with QGIS's Python)."""


def write_layer_styles(gpkg: str | os.PathLike[str], styles: Mapping[str, str]) -> None:
    """Add QGIS's ``layer_styles`` table to a GeoPackage: each layer's style as its default.

    QGIS reads it when a layer of the file is opened (Add Layer, the Browser, drag and drop)
    and draws the layer as the QGIS plugin draws its own: candidates by rank with ties as
    stars, labelled; cameras as labelled triangles; cones faded by score. The table is as
    QGIS's "Save as Default" writes it (an attribute table: ``f_table_name``,
    ``f_geometry_column``, ``styleName``, ``styleQML``, ``styleSLD``, ``useAsDefault``...).

    Parameters
    ----------
    gpkg
        The GeoPackage, without a ``layer_styles`` table yet.
    styles
        Layer name → style name in :data:`QGIS_STYLES` (``{"cameras": "batch_cameras"}``);
        a style missing there (an install without its data) is skipped with a warning.
    """
    import datetime
    import logging

    import pandas as pd
    import pyogrio

    now = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0, tzinfo=None)
    rows = []
    for layer, style in styles.items():
        qml, sld = QGIS_STYLES / f"{style}.qml", QGIS_STYLES / f"{style}.sld"
        if not qml.is_file():
            logging.getLogger(__name__).warning("no QGIS style for %s (%s missing)", layer, qml)
            continue
        geom_col = pyogrio.read_info(str(gpkg), layer=layer).get("geometry_name") or "geom"
        rows.append(
            {
                "f_table_catalog": "",
                "f_table_schema": "",
                "f_table_name": layer,
                "f_geometry_column": geom_col,
                "styleName": QGIS_STYLE_NAME,
                "styleQML": qml.read_text(encoding="utf-8"),
                "styleSLD": sld.read_text(encoding="utf-8") if sld.is_file() else "",
                "useAsDefault": True,
                "description": f"camloc {style.replace('_', ' ')}",
                "owner": "",
                "ui": "",
                "update_time": now,
            }
        )
    if rows:
        frame = pd.DataFrame(rows)
        frame["update_time"] = pd.to_datetime(frame["update_time"])
        pyogrio.write_dataframe(frame, str(gpkg), layer="layer_styles", driver="GPKG")


_JOB_STYLED_COLUMNS = {
    "cameras": ("id", "status", "ambiguous"),
    "candidates": ("camera_id", "rank", "ambiguous_with"),
}
"""Columns a job GeoPackage's layer always has once it has features: its QGIS style reads
them (a job of title-placed cameras has no ``ambiguous_with`` of its own; the cameras' style
reads ``ambiguous`` since session 41, null where a stored camera has none)."""


def job_result_geopackage(collection: dict[str, Any]) -> bytes:
    """A job result (:func:`job_result_geojson`) as GeoPackage bytes, EPSG:4326.

    Layers ``cameras`` and ``candidates``, both always there (one without features has the
    column ``id`` only: before, it was left out, and a job with no camera done yet gave 0
    bytes, no GeoPackage at all); list and dict properties are stored as JSON text. Since
    session 40 also QGIS's ``layer_styles`` table (:func:`write_layer_styles`), and the
    columns those styles read (``ambiguous_with`` empty where no candidate has one). Needs
    geopandas and pyogrio.
    """
    import json
    import tempfile
    from pathlib import Path

    import geopandas as gpd
    import pandas as pd
    from shapely.geometry import shape

    with tempfile.TemporaryDirectory(prefix="camloc-job-") as tmp:
        path = Path(tmp) / "job.gpkg"
        for layer, kind in JOB_LAYERS:
            feats = [f for f in collection["features"] if f["properties"].get("kind") == kind]
            options = {} if path.exists() else {"dataset_options": {"VERSION": "1.2"}}
            if not feats:
                empty = gpd.GeoDataFrame(
                    {"id": pd.Series([], dtype=str)},
                    geometry=gpd.GeoSeries([], crs="EPSG:4326"),
                    crs="EPSG:4326",
                )
                empty.to_file(
                    path,
                    layer=layer,
                    driver="GPKG",
                    engine="pyogrio",
                    geometry_type="Point",
                    **options,
                )
                continue
            rows = [
                {
                    k: (json.dumps(v) if isinstance(v, (list, dict)) else v)
                    for k, v in f["properties"].items()
                }
                for f in feats
            ]
            frame = gpd.GeoDataFrame(
                rows,
                geometry=[shape(f["geometry"]) if f["geometry"] else None for f in feats],
                crs="EPSG:4326",
            )
            for col in _JOB_STYLED_COLUMNS[layer]:  # what the layer's QGIS style reads
                if col not in frame.columns:
                    frame[col] = None
            for col in frame.columns:
                # a numeric column null in every row (no camera of the job has a heading
                # yet) was written as a String field, which QGIS then styles and sorts as text
                if col != "geometry" and _numeric_name(str(col)) and frame[col].isna().all():
                    frame[col] = frame[col].astype("float64")
            # GeoPackage 1.2, as QGIS 3.22's GDAL 3.6 reads without a warning (1.4 is
            # pyogrio's default; camloc_geo.batch writes 1.2 for the same reason)
            frame.to_file(path, layer=layer, driver="GPKG", engine="pyogrio", **options)
        # QGIS draws the layers as the plugin's (session 40: they had no style)
        write_layer_styles(path, {layer: f"job_{layer}" for layer, _kind in JOB_LAYERS})
        return path.read_bytes()
