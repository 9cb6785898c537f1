"""Crowd endpoints: a task per snapshot, its annotation page, annotators' scenes, its result.

When a task has its annotations, the library merges them (with the task's point as prior)
and locates the merged scene.
"""

from __future__ import annotations

import io
import json
from typing import Annotated, Any, cast

from fastapi import APIRouter, Query, Request
from fastapi.responses import HTMLResponse

from camloc_geo import CamlocError, MapDataError, SceneError
from camloc_geo._io import (
    HEIF_HINT,
    MIN_IMAGE_SIDE_PX,
    displayed_size,
    heif_kind,
    heif_photo,
    image_data_complete,
    is_lat_lon,
    magic_format,
)
from camloc_geo.service.deps import (
    ApiKey,
    SceneBody,
    ServiceSettings,
    ServiceStore,
    Workers,
    raw_body,
    run_cpu,
)
from camloc_geo.service.errors import LimitError, NotFoundError, ServiceError
from camloc_geo.service.mapstore import MapStore
from camloc_geo.service.models import HTML_ROUTE_ERRORS, TaskId, TaskQuery
from camloc_geo.service.routers.scenes import review_work, scene_body_doc
from camloc_geo.service.store import Store, TaskFullError
from camloc_geo.service.work import locate_body

__all__ = ["router"]

router = APIRouter(tags=["crowd"])

IMAGE_TYPES = {"JPEG": "jpg", "PNG": "png", "WEBP": "webp"}
IMAGE_MEDIA_TYPES = tuple(f"image/{kind.lower()}" for kind in IMAGE_TYPES)
_UPLOAD_DOC = {
    "requestBody": {
        "required": True,
        "content": {
            media: {"schema": {"type": "string", "format": "binary"}} for media in IMAGE_MEDIA_TYPES
        },
    }
}


def image_info(raw: bytes, max_pixels: int) -> tuple[str, int, int]:
    """``(extension, width, height)`` of an uploaded snapshot, as browsers show it.

    The size comes from the header (EXIF orientation applied); then the data are checked
    complete (:func:`camloc_geo._io.image_data_complete`).
    """
    import warnings

    from PIL import Image, UnidentifiedImageError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # Pillow's bomb warning: the limit is checked below
            with Image.open(io.BytesIO(raw)) as img:
                fmt = img.format or ""
                width, height = displayed_size(img)  # as the annotators' browsers show it
    except (UnidentifiedImageError, OSError, ValueError):
        cut = magic_format(raw[:16])
        if cut in IMAGE_TYPES:  # cut off inside its header (an upload interrupted early)
            raise SceneError(f"the snapshot is a truncated or corrupt {cut} file", "body") from None
        heif = heif_kind(raw[:16])
        if heif is not None:  # an iPhone's photo
            raise SceneError(
                f"the snapshot is {heif_photo(heif)}, not a JPEG, PNG or WebP image; {HEIF_HINT}",
                "body",
            ) from None
        raise SceneError("the snapshot is not a readable JPEG, PNG or WebP image", "body") from None
    except Image.DecompressionBombError:
        raise LimitError("the snapshot has too many pixels", "body") from None
    if fmt not in IMAGE_TYPES:
        raise SceneError(
            f"snapshot format {fmt or 'unknown'} not supported (JPEG, PNG, WebP)", "body"
        )
    if width * height > max_pixels:
        raise LimitError(
            f"the snapshot is {width}×{height}; this server accepts at most {max_pixels} pixels",
            "body",
        )
    if min(width, height) < MIN_IMAGE_SIDE_PX:
        raise SceneError(
            f"the snapshot is {width}×{height}: too small to annotate (at least "
            f"{MIN_IMAGE_SIDE_PX} pixels a side)",
            "body",
        )
    if not image_data_complete(raw, fmt):
        raise SceneError(f"the snapshot is a truncated or corrupt {fmt} file", "body")
    return IMAGE_TYPES[fmt], width, height


def servable_work(maps: MapStore, network: bool, point: tuple[float, float] | None) -> None:
    """Refuse a task no map can serve, before anyone annotates it (runs on a worker).

    Raises
    ------
    MapDataError
        The network is off and no configured extract covers the point (or there is none).
    """
    if network:
        return
    if point is None:
        if not maps.extracts:
            raise MapDataError(
                "this server has no map data (no CAMLOC_MAP_DIR, network off): no task can be "
                "located"
            )
        return
    try:
        maps.map_for_point(lat=point[0], lon=point[1])
    except MapDataError as exc:
        raise MapDataError(f"refused: the task could never be located: {exc}") from None


@router.post("/v1/tasks", status_code=201, dependencies=[ApiKey], openapi_extra=_UPLOAD_DOC)
async def create_task(
    request: Request,
    q: Annotated[TaskQuery, Query()],
    settings: ServiceSettings,
    store: ServiceStore,
    workers: Workers,
) -> dict[str, Any]:
    """Create a crowd task from a snapshot (the raw image as the body)."""
    raw = await raw_body(request, IMAGE_MEDIA_TYPES)
    kind, width, height = image_info(raw, settings.max_upload_pixels)
    if (q.lat is None) != (q.lon is None):
        raise SceneError("give both lat and lon, or neither", "lat" if q.lat is None else "lon")
    point = (q.lat, q.lon) if q.lat is not None and q.lon is not None else None
    await workers.run(servable_work, settings.network, point)
    base: dict[str, Any] = {"format": "camloc-scene/1", "image": {"width": width, "height": height}}
    if point is not None:
        base["prior"] = {"lat": point[0], "lon": point[1], "radius_m": q.radius_m}
    needed = q.annotations or settings.annotations_per_task
    task_id = store.create_task(
        image=raw, image_type=kind, width=width, height=height, needed=needed, base_scene=base
    )
    return {
        "id": task_id,
        "annotate_url": f"/annotate/{task_id}",
        "status_url": f"/v1/tasks/{task_id}",
        "needed": needed,
    }


def _task(store: Store, task_id: str) -> dict[str, Any]:
    task = store.task(task_id)
    if task is None:
        raise NotFoundError(f"no task {task_id}")
    return task


def junction_work(maps: MapStore, lat: float, lon: float) -> dict[str, Any] | None:
    """The junction nearest a task's point, for the page's small map (runs on a worker); None
    where the server's maps have none (the page is then made without the map, as before).

    A task's page had no map where ``camloc annotate --osm --lat --lon`` has one: its
    annotators were asked for the kerb corners "clockwise" with no junction to see them on,
    and the scene they sent named none (session 42 QA)."""
    from camloc_geo.cli.annotate import junction_geojson

    try:
        if maps.catalogue.area_for_point(lat, lon)[0] not in ("file", "cell"):
            return None  # the configured extracts only: a page view never calls Overpass
        m = maps.map_for_point(lat=lat, lon=lon)
        return junction_geojson(lat=lat, lon=lon, map_source=m)
    except CamlocError:
        return None


@router.get("/annotate/{task_id}", response_class=HTMLResponse, responses=HTML_ROUTE_ERRORS)
async def annotate(
    request: Request, task_id: TaskId, store: ServiceStore, workers: Workers
) -> HTMLResponse:
    """The annotation page in crowd mode: a submit button instead of a download."""
    task = _task(store, task_id)
    prior = (task["base_scene"] or {}).get("prior") or {}
    corners = None
    if task["status"] == "collecting" and is_lat_lon(prior.get("lat"), prior.get("lon")):
        try:
            corners = await workers.run(junction_work, float(prior["lat"]), float(prior["lon"]))
        except ServiceError:  # the time limit, a lost worker: the page without its map
            corners = None

    def work() -> str:
        from camloc_geo.web import annotation_page_html

        closed = None
        if task["status"] != "collecting":
            closed = (
                f"This task has all its {task['needed']} annotations already: it takes no "
                "more work. Thank you!"
            )
            nowhere = _no_candidate_reason(task)
            if nowhere is not None:  # located with no candidate: why, not a link to none
                closed += f" It was located with no candidate: {nowhere[:300]}"
            elif task["status"] == "located":  # where its answer is (the page named none)
                closed += f" The camera's candidates: /v1/tasks/{task_id}/map"
            elif task["status"] == "failed":  # and why there is none
                why = str((task.get("result") or {}).get("reason") or "").strip()
                if why:
                    closed += f" It could not be located: {why[:300]}"
        return annotation_page_html(
            store.task_image(task),
            scene=task["base_scene"],
            mode="crowd",
            submit_url=f"/v1/tasks/{task_id}/annotations",
            closed=closed,
            corners_geojson=corners,
        )

    return HTMLResponse(await run_cpu(request, work))


def crowd_work(
    maps: MapStore, scenes: list[dict[str, Any]], prior: dict[str, Any] | None
) -> tuple[str, dict[str, Any]]:
    """Merge a task's scenes and locate them: ``(status, result)`` (runs on a worker)."""
    from camloc_geo.api import crowd_scene

    try:
        merged = crowd_scene(scenes, prior=prior)
        out, _m = locate_body(merged, maps)
    except CamlocError as exc:
        return "failed", {"reason": " ".join(str(exc).split())}
    return "located", {"scene": merged, "candidates": out.to_geojson()}


@router.post(
    "/v1/tasks/{task_id}/annotations",
    openapi_extra=scene_body_doc("one annotator's scene for this task's snapshot"),
)
async def submit(
    task_id: TaskId, body: SceneBody, store: ServiceStore, workers: Workers
) -> dict[str, Any]:
    """Collect one annotator's work; the task is merged and located when enough came in.

    No API key: the task id is the annotators' capability.
    """
    task = _task(store, task_id)
    image = body.scene.image
    if (image.width, image.height) != (task["width"], task["height"]):
        raise SceneError(
            f"the scene is for a {image.width}×{image.height} image; this "
            f"task's snapshot is {task['width']}×{task['height']}",
            "image",
        )
    if body.data in store.annotations(task_id):
        # the same scene again (a retry after a lost answer, a double click on Submit): the
        # answer it had, not a second annotator (it used to count twice and could complete
        # the task with one person's work)
        return {
            "annotations": task["annotations"],
            "needed": task["needed"],
            "status": task["status"],
            "duplicate": True,
        }
    if task["status"] != "collecting":
        raise SceneError("this task has all its annotations already", "task")
    try:
        n, new = store.add_annotation_once(task_id, body.data, needed=task["needed"])
    except TaskFullError:  # another submission completed the task meanwhile
        raise SceneError("this task has all its annotations already", "task") from None
    if new and n >= task["needed"]:
        prior = task["base_scene"].get("prior")
        try:
            status, result = await workers.run(crowd_work, store.annotations(task_id), prior)
        except BaseException:
            # not located (the time limit, a lost worker): the submission is taken back,
            # so that sending it again locates the task (a full task is refused otherwise)
            store.remove_annotation(task_id, n)
            raise
        store.set_task_result(task_id, status, result)
    got = cast(dict[str, Any], store.task(task_id))
    answer = {"annotations": n, "needed": task["needed"], "status": got["status"]}
    why = _no_candidate_reason(got)
    if why is not None:
        answer["reason"] = why
    if not new:  # an identical submission raced this one in
        answer["duplicate"] = True
    return answer


def _no_candidate_reason(task: dict[str, Any]) -> str | None:
    """Why a located task has no candidate (the locate's reason), or ``None`` if it has one.

    A crowd task whose merged scene holds no geographic evidence the server's maps can use
    (a prior where no configured extract lies, no junction, no references) is ``located``
    with an empty FeatureCollection: the status stays (a new value would break clients
    polling for ``located``), and this reason is given beside it.
    """
    if task.get("status") != "located":
        return None
    cands = (task.get("result") or {}).get("candidates") or {}
    if cands.get("features"):
        return None
    why = str((cands.get("properties") or {}).get("reason") or "").strip()
    return " ".join(why.split()) or "the scene gave no candidate"


@router.get("/v1/tasks/{task_id}")
async def task_status(task_id: TaskId, store: ServiceStore) -> dict[str, Any]:
    """A task's progress, and its merged scene and candidates once located."""
    task = _task(store, task_id)
    answer = {
        "id": task_id,
        "status": task["status"],
        "annotations": task["annotations"],
        "needed": task["needed"],
        "image": {"width": task["width"], "height": task["height"]},
        "result": task["result"],
    }
    if task["status"] == "located":
        answer["map_url"] = f"/v1/tasks/{task_id}/map"
        feats = ((task["result"] or {}).get("candidates") or {}).get("features") or []
        answer["n_candidates"] = len(feats)
        why = _no_candidate_reason(task)
        if why is not None:  # located, yet nowhere: say so beside the status (qa7)
            answer["reason"] = why
    return answer


@router.get("/v1/tasks/{task_id}/map", response_class=HTMLResponse, responses=HTML_ROUTE_ERRORS)
async def task_map(task_id: TaskId, store: ServiceStore, workers: Workers) -> HTMLResponse:
    """The review page of a located task (its merged scene's candidates, the annotators left
    out named): one self-contained offline HTML file, as ``POST /v1/maps`` gives."""
    task = _task(store, task_id)
    if task["status"] != "located":
        why = (
            f"it is collecting ({task['annotations']} of {task['needed']} annotations)"
            if task["status"] == "collecting"
            else f"it {task['status']}: {(task['result'] or {}).get('reason') or 'no result'}"
        )
        raise NotFoundError(f"task {task_id} has no map: {why}", "task")
    raw = json.dumps(task["result"]["scene"]).encode("utf-8")
    return HTMLResponse(await workers.run(review_work, raw))
