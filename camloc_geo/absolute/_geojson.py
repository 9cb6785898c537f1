"""The candidate GeoJSON FeatureCollection of a :class:`LocateResult`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from camloc_geo.absolute._model import Candidate, LocateResult, Match
from camloc_geo.camera import Camera
from camloc_geo.geodesy import LocalFrame, normalize_bearing_deg

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


def _feature(geometry: dict[str, Any], properties: dict[str, Any]) -> dict[str, Any]:
    return {"type": "Feature", "geometry": geometry, "properties": properties}


def _point(lon: float, lat: float) -> dict[str, Any]:
    return {"type": "Point", "coordinates": [lon, lat]}


def _match_properties(m: Match, frame: LocalFrame) -> dict[str, Any]:
    d = m.as_dict()
    del d["map_en"]
    d["map_lonlat"] = list(frame.geographic_from_enu(*m.map_en.tolist()))
    return d


def _candidate_feature(c: Candidate, result: LocateResult) -> dict[str, Any]:
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
        "flags": [str(f) for f in c.flags],
        "scene": result.scene_id,
        "matches": [_match_properties(m, result.frame) for m in c.matches],
    }
    return _feature(_point(c.lon, c.lat), props)


def _view_cone_feature(c: Candidate, result: LocateResult, range_m: float) -> dict[str, Any]:
    poly = view_cone(c.camera, result.image_size, range_m)
    ll = result.frame.points_geographic_from_enu(poly)
    return _feature(
        {"type": "Polygon", "coordinates": [ll.tolist()]},
        {"kind": "view_cone", "rank": c.rank, "score": c.score},
    )


def _matched_point_feature(c: Candidate, m: Match, frame: LocalFrame) -> dict[str, Any]:
    lon, lat = frame.geographic_from_enu(*m.map_en.tolist())
    props = {
        "kind": "matched_point",
        "rank": c.rank,
        "label": m.label,
        "match_kind": m.kind,
        "pixel": list(m.pixel),
        "misfit_m": m.misfit_m,
        **({"map_corner": m.map_corner} if m.map_corner is not None else {}),
    }
    return _feature(_point(float(lon), float(lat)), props)


def _intersection_features(result: LocateResult) -> list[dict[str, Any]]:
    inter = result.intersection
    if inter is None:
        return []
    props = {
        "kind": "intersection",
        "id": inter.id,
        "streets": [s.name for s in inter.streets],
        "intersection_kind": inter.kind,
    }
    feats = [_feature(_point(inter.lon, inter.lat), props)]
    for corner in inter.corners:
        corner_props = {
            "kind": "corner",
            "intersection": inter.id,
            "order": corner.order,
            "streets": list(corner.streets),
        }
        feats.append(_feature(_point(corner.lon, corner.lat), corner_props))
    return feats


def _collection_properties(result: LocateResult) -> dict[str, Any]:
    cal = result.calibration
    _h, pitch, roll = cal.camera.angles_deg
    return {
        "scene": result.scene_id,
        "methods_tried": result.methods_tried,
        "n_candidates": len(result.candidates),
        "reason": result.reason,
        "warnings": result.warnings + cal.warnings,
        "calibration": {
            "focal_px": cal.camera.focal_px,
            "height_m": cal.camera.height_m,
            "pitch_deg": pitch,
            "roll_deg": roll,
            "method": cal.method,
            "intrinsics_method": cal.intrinsics_method,
            "outlier_annotators": cal.outlier_annotators,
        },
        "attribution": "Map data © OpenStreetMap contributors, ODbL",
    }


def candidates_geojson(result: LocateResult, *, view_cones: bool = True) -> dict[str, Any]:
    """The candidate GeoJSON FeatureCollection of the scene contract.

    Candidate Point features (``kind: "candidate"``, best first) carry every property of
    the contract plus ``sigma_m`` (1-sigma position uncertainty), ``scale``, ``flags``,
    ``matches`` and ``merged``. Extra features: ``view_cone`` polygons (one per candidate),
    ``matched_point`` points (the map points each candidate matched), and the
    ``intersection`` used, with its ``corner`` points.
    """
    cands = result.candidates
    feats = [_candidate_feature(c, result) for c in cands]
    if view_cones:
        feats += [_view_cone_feature(c, result, 60.0) for c in cands]
    feats += [_matched_point_feature(c, m, result.frame) for c in cands for m in c.matches]
    feats += _intersection_features(result)
    return {
        "type": "FeatureCollection",
        "features": feats,
        "properties": _collection_properties(result),
    }
