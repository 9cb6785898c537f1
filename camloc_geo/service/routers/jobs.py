"""Job endpoints: queue a webcam list, poll it, fetch its result; and the job runner thread.

A list is read by the batch list reader (:mod:`camloc_geo.batch`: the same columns and
variants as ``camloc batch``); each camera is processed alone by the runner and committed to
the store, so a job survives a restart.
"""

from __future__ import annotations

import codecs
import csv
import io
import logging
import re
import threading
from concurrent.futures.process import BrokenProcessPool
from dataclasses import asdict
from typing import Annotated, Any

from fastapi import APIRouter, Query, Request
from fastapi.responses import HTMLResponse, Response
from pydantic import ValidationError

from camloc_geo import SceneError
from camloc_geo.service.compute import Compute
from camloc_geo.service.deps import (
    ApiKey,
    Maps,
    ServiceSettings,
    ServiceStore,
    content_type,
    parse_json,
    raw_body,
    run_cpu,
)
from camloc_geo.service.errors import LimitError, NotFoundError
from camloc_geo.service.mapstore import MapStore
from camloc_geo.service.models import HTML_ROUTE_ERRORS, JobId, JobList, ResultQuery
from camloc_geo.service.settings import Settings
from camloc_geo.service.store import Store
from camloc_geo.service.work import process_camera

__all__ = ["JobRunner", "camera_records", "router"]

log = logging.getLogger(__name__)

router = APIRouter(tags=["jobs"])

_LIST_DOC = {
    "requestBody": {
        "required": True,
        "description": (
            'A webcam list: JSON {"cameras": [{"id", "title", "lat", "lon", "radius_m", '
            '"scene"}, ...]}, a GeoJSON FeatureCollection of cameras (properties as columns, '
            "a Point as the camera's point, scenes inline) or CSV with columns "
            "id,title,lat,lon,radius_m (the column variants of camloc batch are accepted)"
        ),
        "content": {
            "application/json": {"schema": JobList.model_json_schema()},
            "text/csv": {"schema": {"type": "string"}},
        },
    }
}
_ROW_FIELDS = ("id", "title", "lat", "lon", "radius_m", "streets", "view", "area", "problems")


def _record(row: Any, scene: Any = None) -> dict[str, Any]:
    values = asdict(row)
    out = {k: values[k] for k in _ROW_FIELDS if values[k] not in (None, "", ())}
    if scene is not None:
        out["scene"] = scene
    return out


def csv_text(raw: bytes) -> str:
    """A CSV body as text: UTF-8 (a byte-order mark is fine), else Windows-1252 (Latin-1 where
    even that fails), as ``camloc batch`` reads a spreadsheet's export (``docs/batch.md``).

    Such a body was refused (422 "the CSV list is not UTF-8 text"), though the service reads
    its lists "with camloc batch's reader"; the job's answer now says how it was read
    (:func:`csv_encoding_warning`).
    """
    if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        try:  # Excel's "Unicode Text", as camloc batch reads it
            return raw.decode("utf-16")
        except UnicodeDecodeError as exc:
            raise SceneError(f"the CSV list is not UTF-16 text: {exc.reason}", "body") from None
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        pass
    try:
        return raw.decode("cp1252")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def csv_encoding_warning(raw: bytes) -> str | None:
    """The warning for a CSV body that is not UTF-8 (or UTF-16 with its mark), or None."""
    if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return None
    try:
        raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        try:
            raw.decode("cp1252")
            encoding = "Windows-1252"
        except UnicodeDecodeError:
            encoding = "Latin-1"
        return (
            f"the CSV list is not UTF-8 text: read as {encoding} (a spreadsheet's export); "
            "check accented names, and send UTF-8 to be sure"
        )
    return None


def _feature_records(data: dict[str, Any], max_cameras: int) -> list[Any]:
    """The cameras of a GeoJSON list body (a QGIS or GDAL export, as ``camloc batch`` reads
    it: properties as columns, a Point as the camera's point), at most ``max_cameras + 1``.
    Scenes only inline (a ``scene`` object); a scene file path is the row's problem. It was
    refused, 'the body must be {"cameras": [...]}' (session 39)."""
    from pathlib import Path

    from camloc_geo.cameras._list import _feature_row

    feats = data.get("features")
    if not isinstance(feats, list):
        raise SceneError("a GeoJSON camera list needs a 'features' list", "features")
    out = []
    for n, feat in enumerate(feats[: max_cameras + 1], start=1):
        props = feat.get("properties") if isinstance(feat, dict) else None
        scene = props.get("scene") if isinstance(props, dict) else None
        row = _feature_row(feat, n, Path("."), scene_paths=False)
        out.append(_record(row, scene if isinstance(scene, dict) else None))
    return out


def camera_records(raw: bytes, ctype: str, max_cameras: int) -> list[Any]:
    """The cameras of a list body, as the job store keeps them (at most ``max_cameras + 1``).

    Raises
    ------
    SceneError
        Not UTF-8, not ``{"cameras": [...]}``, or a CSV naming scene files.
    """
    from camloc_geo.batch import read_camera_csv, row_from_mapping
    from camloc_geo.cameras import binary_list_kind

    if ctype == "text/csv":
        what = binary_list_kind(raw[:4096])
        if what is not None:  # a GeoPackage sent as the list was a 500
            raise SceneError(f"the CSV list is {what}: send CSV text (UTF-8)", "body")
        text = csv_text(raw)
        out: list[Any] = []
        placeable = False
        try:
            # newline="": rows ended by a bare CR (a Mac spreadsheet's CSV) are rows, as
            # camloc batch reads them; the csv module refused them (a 500)
            for row in read_camera_csv(io.StringIO(text, newline="")):
                if row.scene is not None:
                    raise SceneError(
                        "a list sent over HTTP cannot name scene files: send it as JSON with "
                        "each camera's scene inline",
                        "scene",
                    )
                out.append(_record(row))
                placeable = placeable or bool(row.title or row.streets)
                if len(out) > max_cameras:
                    break
        except csv.Error as exc:
            raise SceneError(f"malformed CSV list: {exc}", "body") from None
        if not out:
            # the body's own words: 'cameras: the list holds no camera' named a JSON field a
            # CSV body has not (session 41 QA)
            raise SceneError(
                "the CSV list holds no camera (no row under its header): a header row "
                "(id,title,lat,lon,radius_m) and one camera a row",
                "body",
            )
        if out and not placeable and len(out) <= max_cameras:  # (over it: the limit's 413)
            # as camloc batch refuses it: a list of titles without a header row (its first
            # title read as the header), another table; every camera was no_evidence
            header = text.lstrip("\ufeff").splitlines()[0][:80] if text.strip() else ""
            raise SceneError(
                "the CSV list has no column a camera can be placed by (title, name, streets, "
                f"street1+street2, ...): its header row is {header!r}",
                "body",
            )
        return out
    try:
        data = parse_json(raw)
    except SceneError as exc:
        hint = _csv_sent_as_json(raw)
        if hint:  # the type told the server JSON; the body is the list as CSV (qa7)
            said = str(exc).removeprefix(f"{exc.field}: ") if exc.field else str(exc)
            raise SceneError(f"{said}{hint}", exc.field or "body") from None
        raise
    if isinstance(data, dict) and data.get("type") == "FeatureCollection":
        records = _feature_records(data, max_cameras)
        if not records:
            raise SceneError(
                "the GeoJSON FeatureCollection holds no camera: one Feature a camera", "features"
            )
        return records
    try:
        cameras = JobList.model_validate(data).cameras
    except ValidationError:
        raise SceneError(
            'the body must be {"cameras": [...]} or a GeoJSON FeatureCollection of cameras',
            "cameras",
        ) from None
    return [
        _record(row_from_mapping({k: v for k, v in c.items() if k != "scene"}, n), c.get("scene"))
        if isinstance(c, dict)
        else c
        for n, c in enumerate(cameras[: max_cameras + 1], start=1)
    ]


@router.post("/v1/jobs", status_code=202, dependencies=[ApiKey], openapi_extra=_LIST_DOC)
async def create_job(
    request: Request, settings: ServiceSettings, store: ServiceStore
) -> dict[str, Any]:
    """Queue a webcam list; poll ``/v1/jobs/{id}``. Jobs survive a server restart."""
    raw = await raw_body(request, ("application/json", "text/csv"))
    limit = settings.max_cameras_per_job
    cameras = await run_cpu(request, lambda: camera_records(raw, content_type(request), limit))
    if not cameras:
        raise SceneError("the list holds no camera", "cameras")
    if len(cameras) > limit:
        raise LimitError(
            f"over {limit} cameras; this server accepts at most {limit} per job", "cameras"
        )
    job_id = await run_cpu(request, lambda: store.create_job(cameras))
    answer: dict[str, Any] = {
        "id": job_id,
        "status_url": f"/v1/jobs/{job_id}",
        "total": len(cameras),
    }
    from camloc_geo.batch._run import duplicate_id_warnings

    warnings = duplicate_id_warnings(c.get("id") if isinstance(c, dict) else None for c in cameras)
    if content_type(request) == "text/csv":
        encoding_warning = csv_encoding_warning(raw)
        if encoding_warning:
            warnings = [encoding_warning, *warnings]
    if warnings:  # accepted, as camloc batch accepts it, but named
        answer["warnings"] = warnings
    return answer


@router.get("/v1/jobs/{job_id}")
async def job_status(job_id: JobId, store: ServiceStore) -> dict[str, Any]:
    """A job's status and progress."""
    job = store.job(job_id)
    if job is None:
        raise NotFoundError(f"no job {job_id}")
    job["result_url"] = f"/v1/jobs/{job_id}/result"
    job["map_url"] = f"/v1/jobs/{job_id}/map"
    return job


_RESULT_CONTENT: dict[int | str, dict[str, Any]] = {
    200: {
        "description": "GeoJSON (format=geojson) or a GeoPackage (format=gpkg)",
        "content": {
            "application/json": {"schema": {"type": "object"}},
            "application/geopackage+sqlite3": {"schema": {"type": "string", "format": "binary"}},
        },
    }
}


@router.get("/v1/jobs/{job_id}/result", response_model=None, responses=_RESULT_CONTENT)
async def job_result(
    request: Request, job_id: JobId, q: Annotated[ResultQuery, Query()], store: ServiceStore
) -> Response | dict[str, Any]:
    """The finished cameras: GeoJSON (best location per camera, then all candidates) or
    GeoPackage (layers ``cameras`` and ``candidates``)."""
    from camloc_geo.results import job_result_geojson, job_result_geopackage

    if store.job(job_id) is None:
        raise NotFoundError(f"no job {job_id}")
    gj = job_result_geojson(job_id, store.job_results(job_id))
    if q.format == "geojson":
        return gj
    data = await run_cpu(request, lambda: job_result_geopackage(gj))
    return Response(
        data,
        media_type="application/geopackage+sqlite3",
        headers={"Content-Disposition": f'attachment; filename="camloc-{job_id}.gpkg"'},
    )


_CSV_HEADER_WORDS = re.compile(
    r"^\ufeff?\"?(id|title|name|camera|camera_id|lat|latitude|lon|lng|streets|description)\"?"
    r"\s*[,;\t|]",
    re.IGNORECASE,
)


def _csv_sent_as_json(raw: bytes) -> str:
    """A hint when a body that is not JSON starts like a camera list's CSV header row."""
    head = raw[:200].decode("utf-8", errors="replace").lstrip()
    if not _CSV_HEADER_WORDS.match(head):
        return ""
    return (
        "; it looks like a CSV list (its first row "
        f"{head.splitlines()[0][:60]!r}): send it with the header Content-Type: text/csv"
    )


def _summary_items(results: list[dict[str, Any]]) -> list[tuple[str, dict[str, Any]]]:
    """A job's cameras as the summary page takes them: each camera's candidates (a
    title-only camera: its point as its one candidate; none placed: its status and reason),
    named ``id title`` as ``camloc batch --map`` names them."""
    items = []
    for r in results:
        label = f"{r.get('id') or ''} {r.get('title') or ''}".strip() or "(no id)"
        feats = list(r.get("candidates") or [])
        if not feats and r.get("lat") is not None and r.get("lon") is not None:
            feats = [
                {
                    "type": "Feature",
                    "geometry": {"type": "Point", "coordinates": [r["lon"], r["lat"]]},
                    "properties": {
                        "kind": "candidate",
                        "rank": 1,
                        "lat": r["lat"],
                        "lon": r["lon"],
                        "score": r.get("score") or 0.0,
                        "method": f"{r.get('method')} ({r.get('status')})",
                        "heading_deg": r.get("heading_deg"),
                        "height_m": r.get("height_m"),
                        "sigma_m": r.get("uncertainty_m"),
                        "flags": [r.get("status")],
                    },
                }
            ]
        if r.get("status") == "ambiguous" and feats:
            # drawn at its first place, tied (dashed ring), counted as ambiguous: it read as
            # "1 located" in the heading, a title the engine would not place (qa7)
            feats = [_status_first(f, "ambiguous") for f in feats]
            feats = [_tied(f) for f in feats]
        elif r.get("status") in _PLACED_BY_TITLE:
            # the status leads the flags, as in camloc batch --map's page: the heading then
            # says "on the map: 1 title_only (at the junction its title names)", not "1
            # camera(s) located" (a title's candidates carried no status: located, they read)
            feats = [_status_first(f, str(r["status"])) for f in feats]
        feats = [_with_sigma(f) for f in feats]
        reason = r.get("reason") if feats else f"{r.get('status')}: {r.get('reason') or ''}"
        gj = {"type": "FeatureCollection", "features": feats, "properties": {"reason": reason}}
        items.append((label, gj))
    return items


_PLACED_BY_TITLE = ("title_only", "street_only")
"""Statuses of cameras placed where their title points, not located from a scene."""


def _with_sigma(feature: dict[str, Any]) -> dict[str, Any]:
    """A candidate feature whose uncertainty the page shows: a title's candidate states it
    as ``uncertainty_m`` (the batch's name), which the page's ``sigma_m`` row left as "—"
    (a junction placed within 20 m read as of unknown uncertainty)."""
    props = feature.get("properties") or {}
    if props.get("sigma_m") is not None or props.get("uncertainty_m") is None:
        return feature
    return {**feature, "properties": {**props, "sigma_m": props["uncertainty_m"]}}


def _tied(feature: dict[str, Any]) -> dict[str, Any]:
    """A copy of a candidate feature flagged ``tie`` (the page's dashed ring)."""
    props = dict(feature.get("properties") or {})
    flags = list(props.get("flags") or [])
    if "tie" not in flags:
        props["flags"] = [*flags, "tie"]
    return {**feature, "properties": props}


def _status_first(feature: dict[str, Any], status: str) -> dict[str, Any]:
    """A copy of a candidate feature whose ``flags`` start with the camera's ``status``."""
    props = dict(feature.get("properties") or {})
    flags = [f for f in props.get("flags") or [] if f != status]
    props["flags"] = [status, *flags]
    return {**feature, "properties": props}


def job_summary_page(
    results: list[dict[str, Any]],
    tile_url: str | None = None,
    tile_attribution: str | None = None,
    *,
    maps: MapStore | None = None,
    pending: int = 0,
) -> str:
    """The summary page of a job's finished cameras, clustered (Leaflet and its cluster
    plug-in inlined), sharing its reviewers' verdicts through ``/v1/verdicts`` when opened
    from the server; a tile basemap only with ``tile_url`` (``CAMLOC_TILE_URL``), otherwise,
    with ``maps``, the streets and buildings of the server's extracts around the cameras
    drawn inline (never the network). Runs in the thread pool."""
    from camloc_geo.maps import summary_page
    from camloc_geo.service.routers.verdicts import VERDICTS_PATH

    return summary_page(
        _summary_items(results),
        tiles=tile_url,
        tiles_attribution=tile_attribution,
        verdict_service=VERDICTS_PATH,
        map_source=None if maps is None or tile_url else maps.catalogue,
        pending=pending,
    )


@router.get("/v1/jobs/{job_id}/map", response_class=HTMLResponse, responses=HTML_ROUTE_ERRORS)
async def job_map(
    request: Request, job_id: JobId, store: ServiceStore, settings: ServiceSettings, maps: Maps
) -> HTMLResponse:
    """The summary page of the job's finished cameras (best candidate each, the others to
    pick from, clustered with their verdicts counted): one self-contained HTML file whose
    reviewers share their verdicts here; a tile basemap only when ``CAMLOC_TILE_URL`` is
    set, otherwise the server's extracts' streets and buildings around the cameras."""
    job = store.job(job_id)
    if job is None:
        raise NotFoundError(f"no job {job_id}")
    results = store.job_results(job_id)
    # the cameras not done yet are counted and said: a running job's page said "0 of 0
    # cameras on the map"
    pending = max(0, int(job.get("total") or 0) - len(results))
    tiles, attribution = settings.tile_url, settings.tile_attribution
    return HTMLResponse(
        await run_cpu(
            request,
            lambda: job_summary_page(results, tiles, attribution, maps=maps, pending=pending),
        )
    )


def camera_work(maps: MapStore, camera: Any, settings: Settings) -> dict[str, Any]:
    """One camera of a job; never raises (runs on a worker)."""
    return process_camera(camera, maps, settings)


class JobRunner:
    """The thread that claims queued cameras one at a time and commits their results."""

    def __init__(self, store: Store, compute: Compute, settings: Settings) -> None:
        self.store, self.compute, self.settings = store, compute, settings
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        """Release what a dead process had claimed, then start working."""
        self.store.release_own_claims()
        reopened = self.store.reopen_full_tasks()
        if reopened:
            log.warning(
                "%d crowd task(s) had all their annotations but no result (the server "
                "stopped while locating them): each took its last annotation back",
                reopened,
            )
        self._thread = threading.Thread(target=self._run, name="camloc-jobs", daemon=True)
        self._thread.start()

    def stop(self, timeout_s: float = 5.0) -> None:
        """Stop after the camera in hand."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=timeout_s)

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                claimed = self.store.claim_camera()
            except Exception:  # database busy or gone: try again later
                log.exception("job runner could not claim a camera")
                self._stop.wait(1.0)
                continue
            if claimed is None:
                self._stop.wait(0.2)
                continue
            job_id, idx, camera = claimed
            try:
                try:
                    result = self.compute.submit(camera_work, camera, self.settings).result()
                except BrokenProcessPool:
                    # the worker died (killed, out of memory): once more on a new one, as a
                    # restart does the cameras in flight again (it was "failed" for good)
                    log.warning("camera %d of job %s: its worker died; computed again", idx, job_id)
                    result = self.compute.submit(camera_work, camera, self.settings).result()
            except Exception as exc:  # a worker died again or the pool is shutting down
                if self._stop.is_set():
                    return  # the claim goes back to pending at the next start
                log.exception("camera %d of job %s failed", idx, job_id)
                result = {
                    "id": str(camera.get("id", "")) if isinstance(camera, dict) else "",
                    "status": "failed",
                    "reason": f"internal error ({type(exc).__name__})",
                }
            self.store.finish_camera(job_id, idx, result)
