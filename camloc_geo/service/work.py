"""What the service does with a request body, independent of HTTP: checks and library calls."""

from __future__ import annotations

import logging
import math
from typing import TYPE_CHECKING, Any

from camloc_geo._errors import CamlocError, InputError, SceneError

if TYPE_CHECKING:
    from camloc_geo.service.mapstore import MapStore
    from camloc_geo.service.settings import Settings

__all__ = ["check_scene_body", "locate_body", "process_camera"]

log = logging.getLogger(__name__)


class LimitError(InputError):
    """A request exceeds one of the server's stated limits (HTTP 413)."""

    def __init__(self, message: str, field: str | None = None) -> None:
        super().__init__(message)
        self.field = field


def check_scene_body(data: Any, settings: Settings, *, where: str = "body") -> dict[str, Any]:
    """Reject what a stranger must not send before any parsing work: server paths, huge scenes.

    Raises
    ------
    SceneError
        Not an object, or ``image.path`` given (clients never name server files).
    LimitError
        Too many annotators, lines or references.
    """
    if not isinstance(data, dict):
        raise SceneError("the scene must be a JSON object", where)
    image = data.get("image")
    if isinstance(image, dict) and image.get("path") is not None:
        raise SceneError(
            "image.path is not accepted over HTTP (the server never opens files a client names)",
            "image.path",
        )
    anns = data.get("annotations")
    if isinstance(anns, list):
        if len(anns) > settings.max_annotations:
            raise LimitError(
                f"{len(anns)} annotations; this server accepts at most {settings.max_annotations}",
                "annotations",
            )
        for i, ann in enumerate(anns):
            lines = ann.get("vp_lines") if isinstance(ann, dict) else None
            if not isinstance(lines, dict):
                continue
            for axis, segs in lines.items():
                if isinstance(segs, list) and len(segs) > settings.max_lines_per_axis:
                    raise LimitError(
                        f"{len(segs)} lines for axis {axis!r}; this server accepts at most "
                        f"{settings.max_lines_per_axis} per axis",
                        f"annotations[{i}].vp_lines.{axis}",
                    )
    refs = data.get("references")
    if isinstance(refs, list) and len(refs) > settings.max_references:
        raise LimitError(
            f"{len(refs)} references; this server accepts at most {settings.max_references}",
            "references",
        )
    return data


def _anchor(scene: Any) -> tuple[float, float] | None:
    from camloc_geo.api import scene_anchor

    return scene_anchor(scene)


def locate_body(
    data: dict[str, Any], maps: MapStore, *, max_candidates: int | None = None
) -> tuple[Any, Any]:
    """Locate a scene dict with the server's maps; returns ``(LocateOutput, map or None)``."""
    from camloc_geo.api import locate_scene, scene_from, scene_needs_map

    scene = scene_from(data)
    map_data = None
    anchor = _anchor(scene)
    if anchor is not None:
        try:
            map_data = maps.map_for_point(lat=anchor[0], lon=anchor[1])
        except InputError:
            if scene_needs_map(scene):
                raise
    elif scene_needs_map(scene):
        raise SceneError(
            "no location to find the map around: give prior (lat/lon), intersection lat/lon "
            "or references",
            "prior",
        )
    out = locate_scene(scene, map_source=map_data, network=False, max_candidates=max_candidates)
    return out, map_data


def _finite(value: Any) -> float | None:
    try:
        v = float(value)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def process_camera(camera: Any, maps: MapStore, settings: Settings) -> dict[str, Any]:
    """One camera of a job: never raises; the result says ``status`` and ``reason``.

    A camera is ``{"id", "title", "lat", "lon", "radius_m", "scene"}`` (all optional but one
    piece of evidence). With a scene it is located; with a title only, the title's junction
    is looked up when title geocoding is available.
    """
    cam_id = str(camera.get("id", "")) if isinstance(camera, dict) else ""
    out: dict[str, Any] = {"id": cam_id, "status": "failed", "reason": None}
    try:
        if not isinstance(camera, dict):
            raise SceneError("a camera must be a JSON object")
        lat, lon = _finite(camera.get("lat")), _finite(camera.get("lon"))
        scene = camera.get("scene")
        if scene is not None:
            scene = check_scene_body(scene, settings, where="scene")
            if lat is not None and lon is not None and "prior" not in scene:
                radius = _finite(camera.get("radius_m")) or 150.0
                scene = {**scene, "prior": {"lat": lat, "lon": lon, "radius_m": radius}}
            located, _m = locate_body(scene, maps)
            gj = located.to_geojson()
            cands = [f for f in gj["features"] if f["properties"].get("kind") == "candidate"]
            if not cands:
                out.update(status="no_candidate", reason=gj["properties"].get("reason"))
            else:
                best = cands[0]["properties"]
                out.update(
                    status="located",
                    lat=best["lat"],
                    lon=best["lon"],
                    score=best["score"],
                    uncertainty_m=best.get("sigma_m"),
                    ambiguous=bool(best.get("ambiguous_with")),
                    candidates=cands,
                )
            return out
        title = camera.get("title")
        if isinstance(title, str) and title.strip():
            try:
                from camloc_geo.geocode import geocode_title
            except ImportError:
                out.update(status="no_evidence", reason="title geocoding is not available")
                return out
            if lat is None or lon is None:
                raise SceneError("a title-only camera needs lat/lon on this server", "lat")
            m = maps.map_for_point(lat=lat, lon=lon)
            matches = geocode_title(
                title, map_data=m, near=(lat, lon), radius_m=_finite(camera.get("radius_m"))
            )
            if not matches or matches[0].lat is None:
                reason = matches[0].reason if matches else "nothing matched"
                out.update(status="not_found", reason=reason)
            else:
                best_match = matches[0]
                out.update(
                    status="title_only",
                    lat=best_match.lat,
                    lon=best_match.lon,
                    uncertainty_m=best_match.uncertainty_m,
                    match_status=best_match.status,
                )
            return out
        out.update(status="no_evidence", reason="give a scene or a title")
    except CamlocError as exc:
        out.update(status="failed", reason=" ".join(str(exc).split()))
    except Exception as exc:  # one bad camera never sinks the job
        log.exception("camera %r failed", cam_id)
        out.update(status="failed", reason=f"internal error ({type(exc).__name__})")
    return out
