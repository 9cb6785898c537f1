"""The HTTP service: ``create_app(settings)`` builds a FastAPI app over the library API.

Nothing is built at import. Errors from the library become 4xx through one table
(:data:`ERROR_STATUS`); anything else is a 500 logged with its request id, whose details
never reach the client.
"""

import asyncio
import csv
import hmac
import io
import json
import logging
import tempfile
import threading
import uuid
from collections.abc import AsyncIterator, Callable
from concurrent.futures import ThreadPoolExecutor
from contextlib import asynccontextmanager
from pathlib import Path
from typing import Annotated, Any, TypeVar

from fastapi import FastAPI, Header, Query, Request
from fastapi import Path as PathParam
from fastapi.openapi.utils import get_openapi
from fastapi.responses import HTMLResponse, JSONResponse, Response

from camloc_geo import __version__
from camloc_geo._errors import (
    CamlocError,
    DegenerateGeometryError,
    InputError,
    MapDataError,
    MapSourceError,
    NotEnoughStructureError,
    SceneError,
)
from camloc_geo.service.mapstore import MapStore, distance_m
from camloc_geo.service.settings import Settings
from camloc_geo.service.store import Store
from camloc_geo.service.work import LimitError, check_scene_body, locate_body, process_camera

__all__ = ["ERROR_STATUS", "create_app"]

log = logging.getLogger(__name__)
T = TypeVar("T")

ERROR_STATUS: tuple[tuple[type[BaseException], int, str], ...] = (
    (LimitError, 413, "limit_exceeded"),
    (SceneError, 422, "invalid_scene"),
    (NotEnoughStructureError, 422, "not_enough_structure"),
    (DegenerateGeometryError, 422, "degenerate_geometry"),
    (MapDataError, 422, "map_data"),
    (InputError, 422, "invalid_input"),
    (MapSourceError, 503, "map_source_unavailable"),
)
"""Library error → HTTP status and error type; the first matching row wins."""

_ID = r"^[0-9a-f]{32}$"
_IMAGE_TYPES = {"JPEG": "jpg", "PNG": "png", "WEBP": "webp"}


class _TimeoutError(Exception):
    pass


class _UnsupportedMediaError(Exception):
    pass


class _NotFoundError(Exception):
    pass


class _UnauthorizedError(Exception):
    pass


def _error(status: int, kind: str, message: str, field: str | None, rid: str) -> JSONResponse:
    body: dict[str, Any] = {"error": {"type": kind, "message": message}, "request_id": rid}
    if field:
        body["error"]["field"] = field
    return JSONResponse(body, status_code=status)


def _rid(request: Request) -> str:
    return str(getattr(request.state, "request_id", "-"))


def _reject_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number JSON allows")


def _parse_json(raw: bytes) -> Any:
    try:
        return json.loads(raw.decode("utf-8"), parse_constant=_reject_constant)
    except RecursionError:
        raise SceneError("the JSON body is nested too deeply", "body") from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise SceneError(f"the body is not valid JSON: {exc}", "body") from None


async def _body(request: Request, *, kinds: tuple[str, ...] = ("application/json",)) -> bytes:
    ctype = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if ctype not in kinds:
        raise _UnsupportedMediaError(
            f"content type {ctype or 'none'!r} not supported here; send {' or '.join(kinds)}"
        )
    return await request.body()


def _scene_schema_components() -> dict[str, Any]:
    from camloc_geo.scene import Scene

    schema = Scene.model_json_schema(ref_template="#/components/schemas/{model}")
    defs = schema.pop("$defs", {})
    schema.get("properties", {}).pop("base_dir", None)
    defs["Scene"] = schema
    return dict(defs)


def _scene_body_doc(description: str) -> dict[str, Any]:
    return {
        "requestBody": {
            "required": True,
            "description": description,
            "content": {"application/json": {"schema": {"$ref": "#/components/schemas/Scene"}}},
        }
    }


def create_app(settings: Settings | None = None) -> FastAPI:
    """Build the service.

    Parameters
    ----------
    settings
        Configuration (default: from ``CAMLOC_*`` environment variables).
    """
    settings = settings or Settings()
    maps = MapStore(settings)
    store = Store(settings.data_dir)
    executor = ThreadPoolExecutor(max_workers=4, thread_name_prefix="camloc")
    stop = threading.Event()

    def worker() -> None:
        while not stop.is_set():
            try:
                claimed = store.claim_camera()
            except Exception:  # database busy or gone: try again later
                log.exception("job worker could not claim a camera")
                stop.wait(1.0)
                continue
            if claimed is None:
                stop.wait(0.2)
                continue
            job_id, idx, camera = claimed
            store.finish_camera(job_id, idx, process_camera(camera, maps, settings))

    @asynccontextmanager
    async def lifespan(_app: FastAPI) -> AsyncIterator[None]:
        store.release_own_claims()
        thread = threading.Thread(target=worker, name="camloc-jobs", daemon=True)
        thread.start()
        try:
            yield
        finally:
            stop.set()
            thread.join(timeout=5.0)
            executor.shutdown(wait=False, cancel_futures=True)

    app = FastAPI(
        title="camloc",
        version=__version__,
        description=(
            "Find where a street camera stands from one snapshot. Map data comes from the "
            "server's configuration only. Errors: 4xx with `error.type`, `error.message` and "
            "`error.field` naming what is wrong."
        ),
        lifespan=lifespan,
    )
    app.state.settings = settings
    app.state.maps = maps
    app.state.store = store

    async def run(fn: Callable[[], T]) -> T:
        loop = asyncio.get_running_loop()
        try:
            return await asyncio.wait_for(
                loop.run_in_executor(executor, fn), timeout=settings.request_timeout_s
            )
        except asyncio.TimeoutError:
            raise _TimeoutError() from None

    def need_key(key: str | None) -> None:
        if settings.api_key is None:
            return
        expected = settings.api_key.get_secret_value().encode()
        if key is None or not hmac.compare_digest(key.encode(), expected):
            raise _UnauthorizedError()

    # --- middleware: request id and body size -------------------------------------------
    @app.middleware("http")
    async def limits(request: Request, call_next: Any) -> Response:
        rid = uuid.uuid4().hex[:16]
        request.state.request_id = rid
        limit = (
            settings.max_upload_bytes
            if request.url.path == "/v1/tasks"
            else settings.max_request_bytes
        )
        length = request.headers.get("content-length")
        if length is not None:
            try:
                too_big = int(length) > limit
            except ValueError:
                return _error(400, "bad_request", "invalid Content-Length header", None, rid)
            if too_big:
                return _error(
                    413, "limit_exceeded", f"request body over {limit} bytes", "body", rid
                )
        response: Response = await call_next(request)
        response.headers["X-Request-ID"] = rid
        return response

    # --- error table -----------------------------------------------------------------------
    @app.exception_handler(CamlocError)
    async def camloc_error(request: Request, exc: CamlocError) -> JSONResponse:
        for cls, status, kind in ERROR_STATUS:
            if isinstance(exc, cls):
                field = getattr(exc, "field", None)
                if status >= 500:
                    log.warning("request %s: %s", _rid(request), exc)
                return _error(status, kind, " ".join(str(exc).split()), field, _rid(request))
        return await unexpected(request, exc)

    @app.exception_handler(_UnsupportedMediaError)
    async def unsupported(request: Request, exc: _UnsupportedMediaError) -> JSONResponse:
        return _error(415, "unsupported_media_type", str(exc), "content-type", _rid(request))

    @app.exception_handler(_TimeoutError)
    async def timeout(request: Request, exc: _TimeoutError) -> JSONResponse:
        return _error(
            503,
            "time_limit",
            f"processing took longer than {settings.request_timeout_s:g} s",
            None,
            _rid(request),
        )

    @app.exception_handler(_NotFoundError)
    async def not_found(request: Request, exc: _NotFoundError) -> JSONResponse:
        return _error(404, "not_found", str(exc), None, _rid(request))

    @app.exception_handler(_UnauthorizedError)
    async def unauthorized(request: Request, exc: _UnauthorizedError) -> JSONResponse:
        return _error(401, "unauthorized", "missing or wrong X-API-Key", "X-API-Key", _rid(request))

    @app.exception_handler(Exception)
    async def unexpected(request: Request, exc: Exception) -> JSONResponse:
        rid = _rid(request)
        log.error("request %s failed", rid, exc_info=exc)
        return _error(500, "internal", f"internal error (request id {rid})", None, rid)

    # --- routes ------------------------------------------------------------------------------
    @app.get("/healthz", tags=["meta"])
    async def healthz() -> dict[str, Any]:
        """Liveness: the version and how many extracts are configured."""
        return {"status": "ok", "version": __version__, "extracts": len(maps.extracts)}

    async def scene_body(request: Request) -> dict[str, Any]:
        data = _parse_json(await _body(request))
        return check_scene_body(data, settings)

    @app.post(
        "/v1/calibrate",
        tags=["scenes"],
        openapi_extra=_scene_body_doc("a camloc-scene/1 scene (no image.path)"),
    )
    async def calibrate(
        request: Request, x_api_key: Annotated[str | None, Header()] = None
    ) -> dict[str, Any]:
        """Relative pose (focal length, rotation, camera position in the car's frame)."""
        need_key(x_api_key)
        data = await scene_body(request)

        def work() -> dict[str, Any]:
            from camloc_geo.api import calibrate_scene, scene_from

            scene = scene_from(data)
            return {"scene": scene.id, **calibrate_scene(scene).to_dict()}

        return await run(work)

    @app.post(
        "/v1/locate",
        tags=["scenes"],
        openapi_extra=_scene_body_doc("a camloc-scene/1 scene (no image.path)"),
    )
    async def locate(
        request: Request,
        max_candidates: Annotated[int | None, Query(ge=1, le=100)] = None,
        x_api_key: Annotated[str | None, Header()] = None,
    ) -> dict[str, Any]:
        """Candidate camera positions as the candidate GeoJSON, best first."""
        need_key(x_api_key)
        data = await scene_body(request)

        def work() -> dict[str, Any]:
            out, _m = locate_body(data, maps, max_candidates=max_candidates)
            return dict(out.to_geojson())

        return await run(work)

    @app.post(
        "/v1/maps",
        tags=["scenes"],
        response_class=HTMLResponse,
        openapi_extra=_scene_body_doc("a camloc-scene/1 scene (no image.path)"),
    )
    async def review_map(
        request: Request, x_api_key: Annotated[str | None, Header()] = None
    ) -> HTMLResponse:
        """The review page of a scene's candidates: one self-contained offline HTML file."""
        need_key(x_api_key)
        data = await scene_body(request)

        def work() -> str:
            from camloc_geo.maps import candidates_map

            out, m = locate_body(data, maps)
            with tempfile.TemporaryDirectory(prefix="camloc-map-") as tmp:
                path = Path(tmp) / "review.html"
                candidates_map(out.result, m, path, offline=True, scene=out.scene)
                return path.read_text(encoding="utf-8")

        return HTMLResponse(await run(work))

    Lat = Annotated[float, Query(ge=-90.0, le=90.0, description="latitude, degrees WGS 84")]
    Lon = Annotated[float, Query(ge=-180.0, le=180.0, description="longitude, degrees WGS 84")]
    Radius = Annotated[
        float, Query(gt=0.0, le=settings.max_radius_m, description="search radius, metres")
    ]

    @app.get("/v1/corners", tags=["map"])
    async def corners(
        lat: Lat,
        lon: Lon,
        radius_m: Radius = 150.0,
        streets: Annotated[
            str | None, Query(max_length=200, description='"A & B": only where they meet')
        ] = None,
    ) -> dict[str, Any]:
        """Intersections and their kerb corners around a point (GeoJSON)."""

        def work() -> dict[str, Any]:
            from camloc_geo.api import corners_near

            m = maps.map_for_point(lat=lat, lon=lon)
            gj = corners_near(lat=lat, lon=lon, radius_m=radius_m, map_source=m, streets=streets)
            if streets:
                return gj
            keep = {
                f["properties"]["id"]
                for f in gj["features"]
                if f["properties"].get("kind") == "intersection"
                and distance_m(
                    lat, lon, f["geometry"]["coordinates"][1], f["geometry"]["coordinates"][0]
                )
                <= radius_m
            }
            gj["features"] = [
                f
                for f in gj["features"]
                if f["properties"].get("id") in keep or f["properties"].get("intersection") in keep
            ]
            return gj

        return await run(work)

    @app.get("/v1/streets", tags=["map"])
    async def streets_route(lat: Lat, lon: Lon, radius_m: Radius = 150.0) -> dict[str, Any]:
        """Streets near a point with their bearings."""

        def work() -> dict[str, Any]:
            from camloc_geo.results import streets_json

            m = maps.map_for_point(lat=lat, lon=lon)
            out = streets_json(m, lat, lon, radius_m)
            names = {n["name"] for n in out["near"]}
            out["streets"] = [s for s in out["streets"] if s["name"] in names]
            return out

        return await run(work)

    # --- jobs --------------------------------------------------------------------------------
    @app.post(
        "/v1/jobs",
        tags=["jobs"],
        status_code=202,
        openapi_extra={
            "requestBody": {
                "required": True,
                "description": (
                    'A webcam list: JSON {"cameras": [{"id", "title", "lat", "lon", "radius_m", '
                    '"scene"}, ...]} or CSV with columns id,title,lat,lon,radius_m'
                ),
                "content": {
                    "application/json": {
                        "schema": {
                            "type": "object",
                            "required": ["cameras"],
                            "properties": {
                                "cameras": {"type": "array", "items": {"type": "object"}}
                            },
                        }
                    },
                    "text/csv": {"schema": {"type": "string"}},
                },
            }
        },
    )
    async def create_job(
        request: Request, x_api_key: Annotated[str | None, Header()] = None
    ) -> dict[str, Any]:
        """Queue a webcam list; poll ``/v1/jobs/{id}``. Jobs survive a server restart."""
        need_key(x_api_key)
        raw = await _body(request, kinds=("application/json", "text/csv"))
        ctype = request.headers.get("content-type", "").split(";")[0].strip().lower()
        cameras = _cameras_from(raw, ctype)
        if not cameras:
            raise SceneError("the list holds no camera", "cameras")
        if len(cameras) > settings.max_cameras_per_job:
            raise LimitError(
                f"{len(cameras)} cameras; this server accepts at most "
                f"{settings.max_cameras_per_job} per job",
                "cameras",
            )
        job_id = await run(lambda: store.create_job(cameras))
        return {"id": job_id, "status_url": f"/v1/jobs/{job_id}", "total": len(cameras)}

    JobId = Annotated[str, PathParam(pattern=_ID, description="job id (32 hex digits)")]

    @app.get("/v1/jobs/{job_id}", tags=["jobs"])
    async def job_status(job_id: JobId) -> dict[str, Any]:
        """A job's status and progress."""
        job = store.job(job_id)
        if job is None:
            raise _NotFoundError(f"no job {job_id}")
        job["result_url"] = f"/v1/jobs/{job_id}/result"
        return job

    @app.get("/v1/jobs/{job_id}/result", tags=["jobs"], response_model=None)
    async def job_result(
        job_id: JobId,
        format: Annotated[str, Query(pattern="^(geojson|gpkg)$")] = "geojson",
    ) -> Response | dict[str, Any]:
        """The finished cameras: GeoJSON (best location per camera, then all candidates) or
        GeoPackage (layers ``cameras`` and ``candidates``)."""
        if store.job(job_id) is None:
            raise _NotFoundError(f"no job {job_id}")
        results = store.job_results(job_id)
        gj = _job_geojson(job_id, results)
        if format == "geojson":
            return gj
        data = await run(lambda: _geojson_to_gpkg(gj))
        return Response(
            data,
            media_type="application/geopackage+sqlite3",
            headers={"Content-Disposition": f'attachment; filename="camloc-{job_id}.gpkg"'},
        )

    # --- crowd tasks ---------------------------------------------------------------------
    @app.post(
        "/v1/tasks",
        tags=["crowd"],
        status_code=201,
        openapi_extra={
            "requestBody": {
                "required": True,
                "content": {
                    "image/jpeg": {"schema": {"type": "string", "format": "binary"}},
                    "image/png": {"schema": {"type": "string", "format": "binary"}},
                    "image/webp": {"schema": {"type": "string", "format": "binary"}},
                },
            }
        },
    )
    async def create_task(
        request: Request,
        annotations: Annotated[int | None, Query(ge=1, le=50)] = None,
        lat: Annotated[float | None, Query(ge=-90.0, le=90.0)] = None,
        lon: Annotated[float | None, Query(ge=-180.0, le=180.0)] = None,
        radius_m: Annotated[float, Query(gt=0.0, le=5_000.0)] = 150.0,
        x_api_key: Annotated[str | None, Header()] = None,
    ) -> dict[str, Any]:
        """Create a crowd task from a snapshot (the raw image as the body)."""
        need_key(x_api_key)
        raw = await _body(request, kinds=("image/jpeg", "image/png", "image/webp"))
        kind, width, height = _image_info(raw, settings.max_upload_pixels)
        base: dict[str, Any] = {
            "format": "camloc-scene/1",
            "image": {"width": width, "height": height},
        }
        if (lat is None) != (lon is None):
            raise SceneError("give both lat and lon, or neither", "lat" if lat is None else "lon")
        if lat is not None and lon is not None:
            base["prior"] = {"lat": lat, "lon": lon, "radius_m": radius_m}
        needed = annotations or settings.annotations_per_task
        task_id = store.create_task(
            image=raw, image_type=kind, width=width, height=height, needed=needed, base_scene=base
        )
        return {
            "id": task_id,
            "annotate_url": f"/annotate/{task_id}",
            "status_url": f"/v1/tasks/{task_id}",
            "needed": needed,
        }

    TaskId = Annotated[str, PathParam(pattern=_ID, description="task id (32 hex digits)")]

    def task_or_404(task_id: str) -> dict[str, Any]:
        task = store.task(task_id)
        if task is None:
            raise _NotFoundError(f"no task {task_id}")
        return task

    @app.get("/annotate/{task_id}", tags=["crowd"], response_class=HTMLResponse)
    async def annotate(task_id: TaskId) -> HTMLResponse:
        """The annotation page in crowd mode: a submit button instead of a download."""
        task = task_or_404(task_id)

        def work() -> str:
            from camloc_geo.web import annotation_page_html

            return annotation_page_html(
                store.task_image(task),
                scene=task["base_scene"],
                mode="crowd",
                submit_url=f"/v1/tasks/{task_id}/annotations",
            )

        return HTMLResponse(await run(work))

    @app.post(
        "/v1/tasks/{task_id}/annotations",
        tags=["crowd"],
        openapi_extra=_scene_body_doc("one annotator's scene for this task's snapshot"),
    )
    async def submit(task_id: TaskId, request: Request) -> dict[str, Any]:
        """Collect one annotator's work; the task is merged and located when enough came in.

        No API key: the task id is the annotators' capability.
        """
        task = task_or_404(task_id)
        data = await scene_body(request)
        image_any = data.get("image")
        image: dict[str, Any] = image_any if isinstance(image_any, dict) else {}
        if (image.get("width"), image.get("height")) != (task["width"], task["height"]):
            raise SceneError(
                f"the scene is for a {image.get('width')}×{image.get('height')} image; this "
                f"task's snapshot is {task['width']}×{task['height']}",
                "image",
            )
        if task["status"] != "collecting":
            raise SceneError("this task has all its annotations already", "task")
        from camloc_geo.api import scene_from

        await run(lambda: scene_from(data))  # validate before storing
        n = store.add_annotation(task_id, data)
        if n >= task["needed"]:
            await run(lambda: _finish_task(task_id, task))
        got = store.task(task_id)
        assert got is not None
        return {"annotations": n, "needed": task["needed"], "status": got["status"]}

    def _finish_task(task_id: str, task: dict[str, Any]) -> None:
        try:
            merged = _merge(store.annotations(task_id), task["base_scene"])
            out, _m = locate_body(merged, maps)
            store.set_task_result(
                task_id, "located", {"scene": merged, "candidates": out.to_geojson()}
            )
        except CamlocError as exc:
            store.set_task_result(task_id, "failed", {"reason": " ".join(str(exc).split())})

    @app.get("/v1/tasks/{task_id}", tags=["crowd"])
    async def task_status(task_id: TaskId) -> dict[str, Any]:
        """A task's progress, and its merged scene and candidates once located."""
        task = task_or_404(task_id)
        return {
            "id": task_id,
            "status": task["status"],
            "annotations": task["annotations"],
            "needed": task["needed"],
            "image": {"width": task["width"], "height": task["height"]},
            "result": task["result"],
        }

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            schema = get_openapi(
                title=app.title, version=app.version, description=app.description, routes=app.routes
            )
            schema.setdefault("components", {}).setdefault("schemas", {}).update(
                _scene_schema_components()
            )
            app.openapi_schema = schema
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
    return app


def _merge(scenes: list[dict[str, Any]], base: dict[str, Any]) -> dict[str, Any]:
    from camloc_geo.merge import merge_scenes

    merged = dict(merge_scenes(scenes))
    if "prior" in base and "prior" not in merged:
        merged["prior"] = base["prior"]
    return merged


def _cameras_from(raw: bytes, ctype: str) -> list[Any]:
    if ctype == "text/csv":
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError:
            raise SceneError("the CSV list is not UTF-8 text", "body") from None
        reader = csv.DictReader(io.StringIO(text))
        if not reader.fieldnames:
            raise SceneError("the CSV list has no header row", "body")
        rows = []
        for row in reader:
            rows.append({k.strip().lower(): (v or "").strip() for k, v in row.items() if k})
            if len(rows) > 1_000_000:
                break
        for row in rows:
            for a, b in (("latitude", "lat"), ("lng", "lon"), ("longitude", "lon")):
                if a in row and b not in row:
                    row[b] = row.pop(a)
        return rows
    data = _parse_json(raw)
    if not isinstance(data, dict) or not isinstance(data.get("cameras"), list):
        raise SceneError('the body must be {"cameras": [...]}', "cameras")
    return list(data["cameras"])


def _job_geojson(job_id: str, results: list[dict[str, Any]]) -> dict[str, Any]:
    from camloc_geo.results import ATTRIBUTION

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
            feats.append({"type": "Feature", "geometry": c["geometry"], "properties": cp})
    return {
        "type": "FeatureCollection",
        "features": feats,
        "properties": {"job": job_id, "attribution": ATTRIBUTION},
    }


def _geojson_to_gpkg(gj: dict[str, Any]) -> bytes:
    import geopandas as gpd

    with tempfile.TemporaryDirectory(prefix="camloc-job-") as tmp:
        path = Path(tmp) / "job.gpkg"
        for layer, kind in (("cameras", "camera"), ("candidates", "candidate")):
            feats = [f for f in gj["features"] if f["properties"].get("kind") == kind]
            rows = []
            for f in feats:
                props = {
                    k: (json.dumps(v) if isinstance(v, (list, dict)) else v)
                    for k, v in f["properties"].items()
                }
                rows.append({**props, "geometry": f["geometry"]})
            if not rows:
                continue
            from shapely.geometry import shape

            frame = gpd.GeoDataFrame(
                [{k: v for k, v in r.items() if k != "geometry"} for r in rows],
                geometry=[shape(r["geometry"]) if r["geometry"] else None for r in rows],
                crs="EPSG:4326",
            )
            frame.to_file(path, layer=layer, driver="GPKG", engine="pyogrio")
        if not path.exists():
            return b""
        return path.read_bytes()


def _image_info(raw: bytes, max_pixels: int) -> tuple[str, int, int]:
    """``(extension, width, height)`` of an uploaded snapshot, from its header only."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(io.BytesIO(raw)) as img:
            fmt = img.format or ""
            width, height = img.size
    except (UnidentifiedImageError, OSError, ValueError):
        raise SceneError("the snapshot is not a readable JPEG, PNG or WebP image", "body") from None
    except Image.DecompressionBombError:
        raise LimitError("the snapshot has too many pixels", "body") from None
    if fmt not in _IMAGE_TYPES:
        raise SceneError(
            f"snapshot format {fmt or 'unknown'} not supported (JPEG, PNG, WebP)", "body"
        )
    if width * height > max_pixels:
        raise LimitError(
            f"the snapshot is {width}×{height}; this server accepts at most {max_pixels} pixels",
            "body",
        )
    return _IMAGE_TYPES[fmt], width, height
