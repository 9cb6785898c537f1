"""What the service does with a request body, independent of HTTP: checks and library calls."""

from __future__ import annotations

import dataclasses
import logging
from typing import TYPE_CHECKING, Any

from camloc_geo._errors import CamlocError, InputError, SceneError

if TYPE_CHECKING:
    from camloc_geo.service.mapstore import MapStore
    from camloc_geo.service.settings import Settings

__all__ = ["check_scene_body", "locate_body", "process_camera", "server_words"]

log = logging.getLogger(__name__)


_SERVER_HINT = "this server has no map data there (its operator adds extracts to CAMLOC_MAP_DIR)"
_CLI_HINTS = (
    "give --osm EXTRACT_OR_FOLDER or allow --network",
    "give --osm EXTRACT_OR_FOLDER",
    "give --osm EXTRACT (map_source=...)",
    "give --osm EXTRACT (a local OSM extract) to work without the network",
)


def server_words(text: str) -> str:
    """``text`` with the command line's map hints put as a service client can act on them.

    The library's "give --osm EXTRACT_OR_FOLDER or allow --network" reached clients of the
    service, which have no such option: the server's operator configures the maps.
    """
    for hint in _CLI_HINTS:
        text = text.replace(hint, _SERVER_HINT)
    return text


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


def locate_body(
    data: dict[str, Any], maps: MapStore, *, max_candidates: int | None = None
) -> tuple[Any, Any]:
    """Locate a scene dict with the server's maps; returns ``(LocateOutput, map or None)``.

    One library call: the server's :class:`~camloc_geo.osm.MapCatalogue` chooses the map
    for the scene (or none, when the scene needs none and no map covers it).
    """
    from camloc_geo.api import locate_scene

    out = locate_scene(
        data, map_source=maps.catalogue, network=False, max_candidates=max_candidates
    )
    return out, out.map_data


def process_camera(camera: Any, maps: MapStore, settings: Settings) -> dict[str, Any]:
    """One camera of a job: never raises; the result says ``status`` and ``reason``.

    A camera is ``{"id", "title", "lat", "lon", "radius_m", "scene", ...}`` with the column
    names and aliases of a camera list (``docs/batch.md``); the scene is inline. It is placed
    by the library's camera-list engine (:func:`camloc_geo.api.locate_camera`), exactly as
    ``camloc batch`` places it: title, prior, scene and evidence, on the map the server's
    catalogue chooses; statuses are the engine's (``docs/contract.md``).
    """
    from camloc_geo.api import locate_camera
    from camloc_geo.cameras import CameraResult, row_from_mapping
    from camloc_geo.results import camera_job_result

    cam_id = str(camera.get("id", "")) if isinstance(camera, dict) else ""
    try:
        if not isinstance(camera, dict):
            raise InputError("a camera must be a JSON object")
        scene = camera.get("scene")
        if scene is not None:
            check_scene_body(scene, settings, where="scene")
        row = row_from_mapping(camera, 1, scene_paths=False)
        # the problems the list's first reading found (POST /v1/jobs keeps the parsed row:
        # a lat of 'x' is gone from it, and only its problem says it was there)
        first = camera.get("problems")
        if isinstance(first, (list, tuple)) and first:
            kept = [str(p) for p in first if isinstance(p, str)]
            row = dataclasses.replace(row, problems=tuple(dict.fromkeys([*kept, *row.problems])))
        if not cam_id:
            row = dataclasses.replace(row, id="")
        res = locate_camera(row, map_source=maps.catalogue)
        if res.reason:  # the library's hints in the server's words, not the CLI's options
            res.reason = server_words(res.reason)
        problems = "; ".join(row.problems)
        if problems and problems not in (res.reason or ""):
            # batch keeps them in its errors layer; a job's result has only the reason
            note = "list row: " + problems
            res.reason = f"{res.reason}; {note}" if res.reason else note
    except CamlocError as exc:
        res = CameraResult(row=1, id=cam_id).fail(
            "scene_error" if isinstance(exc, (SceneError, LimitError)) else "failed",
            server_words(" ".join(str(exc).split())),
            "input",
        )
    except Exception as exc:  # one bad camera never sinks the job
        log.exception("camera %r failed", cam_id)
        res = CameraResult(row=1, id=cam_id).fail(
            "failed", f"internal error ({type(exc).__name__})", "internal"
        )
    return camera_job_result(res)
