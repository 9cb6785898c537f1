"""The candidate GeoJSON FeatureCollection of a :class:`LocateResult`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from camloc_geo.absolute._model import Candidate, LocateResult, Match
from camloc_geo.camera import Camera
from camloc_geo.geodesy import LocalFrame, normalize_bearing_deg
from camloc_geo.results import (
    CalibrationSummary,
    CandidateCollection,
    CandidateCollectionProperties,
    CandidateProperties,
    Feature,
    MatchedPointProperties,
    MatchProperties,
    PolygonGeometry,
    ViewConeProperties,
    intersection_features,
    point,
    to_json,
)

FloatArray = npt.NDArray[np.float64]


def view_cone(cam: Camera, size: tuple[int, int], range_m: float) -> FloatArray:
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


def _match_properties(m: Match, frame: LocalFrame) -> MatchProperties:
    lon, lat = frame.geographic_from_enu(*m.map_en.tolist())
    return MatchProperties(
        kind=m.kind,
        label=m.label,
        pixel=list(m.pixel),
        map_corner=m.map_corner,
        order=m.order,
        misfit_m=m.misfit_m,
        mahalanobis2=m.mahalanobis2,
        map_lonlat=[lon, lat],
    )


def _candidate_feature(c: Candidate, result: LocateResult) -> Feature:
    heading, pitch_c, roll_c = c.camera.angles_deg
    props = CandidateProperties(
        rank=c.rank,
        score=c.score,
        lat=c.lat,
        lon=c.lon,
        height_m=c.camera.height_m,
        heading_deg=float(normalize_bearing_deg(heading)),
        pitch_deg=pitch_c,
        roll_deg=roll_c,
        focal_px=c.camera.focal_px,
        method=c.method,
        residual_m=None if math.isnan(c.residual_m) else c.residual_m,
        sigma_m=c.sigma_m,
        scale=c.scale,
        refined=c.refined,
        merged=c.merged,
        flags=[str(f) for f in c.flags],
        scene=result.scene_id,
        matches=[_match_properties(m, result.frame) for m in c.matches],
        ambiguous_with=list(c.ambiguous_with),
        intersection=c.intersection_id,
    )
    return Feature(geometry=point(c.lon, c.lat), properties=props)


def _view_cone_feature(c: Candidate, result: LocateResult, range_m: float) -> Feature:
    poly = view_cone(c.camera, result.image_size, range_m)
    ll = result.frame.points_geographic_from_enu(poly)
    return Feature(
        geometry=PolygonGeometry(coordinates=[ll.tolist()]),
        properties=ViewConeProperties(rank=c.rank, score=c.score),
    )


def _matched_point_feature(c: Candidate, m: Match, frame: LocalFrame) -> Feature:
    lon, lat = frame.geographic_from_enu(*m.map_en.tolist())
    props = MatchedPointProperties(
        rank=c.rank,
        label=m.label,
        match_kind=m.kind,
        pixel=list(m.pixel),
        misfit_m=m.misfit_m,
        map_corner=m.map_corner,
    )
    return Feature(geometry=point(float(lon), float(lat)), properties=props)


def _collection_properties(result: LocateResult) -> CandidateCollectionProperties:
    cal = result.calibration
    _h, pitch, roll = cal.camera.angles_deg
    return CandidateCollectionProperties(
        scene=result.scene_id,
        methods_tried=result.methods_tried,
        n_candidates=len(result.candidates),
        reason=result.reason,
        warnings=result.warnings + cal.warnings,
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
    """The typed candidate FeatureCollection (:class:`camloc_geo.results.CandidateCollection`)."""
    cands = result.candidates
    range_m = result.view_cone_range_m if view_cone_range_m is None else view_cone_range_m
    feats = [_candidate_feature(c, result) for c in cands]
    if view_cones:
        feats += [_view_cone_feature(c, result, range_m) for c in cands]
    feats += [_matched_point_feature(c, m, result.frame) for c in cands for m in c.matches]
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
