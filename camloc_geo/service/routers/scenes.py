"""Scene endpoints: calibrate, locate, and the review page of a scene's candidates."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, cast

from fastapi import APIRouter, Query
from fastapi.responses import HTMLResponse, Response

from camloc_geo.service.deps import ApiKey, SceneBytes, Workers, scene_from_raw
from camloc_geo.service.fastpath import WorkCall
from camloc_geo.service.models import HTML_ROUTE_ERRORS, LocateQuery
from camloc_geo.service.work import locate_body

if TYPE_CHECKING:
    from camloc_geo.scene import Scene
    from camloc_geo.service.mapstore import MapStore

__all__ = ["FAST_ROUTES", "SCENE_BODY", "router"]

router = APIRouter(tags=["scenes"], dependencies=[ApiKey])


def scene_body_doc(description: str) -> dict[str, Any]:
    """OpenAPI of a scene request body (the ``Scene`` schema is added by the app)."""
    return {
        "requestBody": {
            "required": True,
            "description": description,
            "content": {"application/json": {"schema": {"$ref": "#/components/schemas/Scene"}}},
        }
    }


SCENE_BODY = scene_body_doc("a camloc-scene/1 scene (no image.path)")


def _scene(maps: MapStore, scene: Scene | bytes) -> Scene:
    """A validated scene: as it is, or parsed and validated from a raw body (on the worker)."""
    if isinstance(scene, bytes):
        return scene_from_raw(scene, maps.settings)
    return scene


def calibrate_work(maps: MapStore, scene: Scene | bytes) -> dict[str, Any]:
    """The calibration answer of a scene or a raw scene body (runs on a worker)."""
    from camloc_geo.api import calibrate_scene

    sc = _scene(maps, scene)
    return {"scene": sc.id, **calibrate_scene(sc).to_dict()}


def locate_work(maps: MapStore, scene: Scene | bytes, max_candidates: int | None) -> dict[str, Any]:
    """The candidate GeoJSON of a scene or a raw scene body (runs on a worker)."""
    out, _m = locate_body(cast(Any, _scene(maps, scene)), maps, max_candidates=max_candidates)
    return dict(out.to_geojson())


def review_work(maps: MapStore, scene: Scene | bytes) -> str:
    """The offline review page of a scene or a raw scene body (runs on a worker); opened
    from this server, it shares its verdicts through ``/v1/verdicts``."""
    from camloc_geo.maps import candidates_map
    from camloc_geo.service.routers.verdicts import VERDICTS_PATH

    out, m = locate_body(cast(Any, _scene(maps, scene)), maps)
    with tempfile.TemporaryDirectory(prefix="camloc-map-") as tmp:
        path = Path(tmp) / "review.html"
        candidates_map(
            out.result,
            m,
            path,
            offline=True,
            scene=out.scene,
            verdict_service=VERDICTS_PATH,
        )
        return path.read_text(encoding="utf-8")


def _locate_call(raw: bytes, max_candidates: int | None) -> tuple[Any, tuple[Any, ...]]:
    return locate_work, (raw, max_candidates)


def _calibrate_call(raw: bytes, _max_candidates: int | None) -> tuple[Any, tuple[Any, ...]]:
    return calibrate_work, (raw,)


FAST_ROUTES: dict[str, WorkCall] = {"/v1/locate": _locate_call, "/v1/calibrate": _calibrate_call}
"""The worker call of each endpoint that :class:`~camloc_geo.service.fastpath.SceneFastPath`
answers on its plain requests; the routes below make the same call."""


@router.post("/v1/calibrate", openapi_extra=SCENE_BODY, response_model=dict[str, Any])
async def calibrate(body: SceneBytes, workers: Workers) -> Response:
    """Relative pose (focal length, rotation, camera position in the car's frame)."""
    fn, args = _calibrate_call(body.raw, None)
    return await workers.run_json(fn, *args)


@router.post("/v1/locate", openapi_extra=SCENE_BODY, response_model=dict[str, Any])
async def locate(
    body: SceneBytes, workers: Workers, q: Annotated[LocateQuery, Query()]
) -> Response:
    """Candidate camera positions as the candidate GeoJSON, best first."""
    fn, args = _locate_call(body.raw, q.max_candidates)
    return await workers.run_json(fn, *args)


@router.post(
    "/v1/maps",
    response_class=HTMLResponse,
    openapi_extra=SCENE_BODY,
    responses=HTML_ROUTE_ERRORS,
)
async def review_map(body: SceneBytes, workers: Workers) -> HTMLResponse:
    """The review page of a scene's candidates: one self-contained offline HTML file."""
    return HTMLResponse(await workers.run(review_work, body.raw))
