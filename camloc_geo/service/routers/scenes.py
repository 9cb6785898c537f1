"""Scene endpoints: calibrate, locate, and the review page of a scene's candidates."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Annotated, Any, cast

from fastapi import APIRouter, Query, Request
from fastapi.responses import HTMLResponse, JSONResponse

from camloc_geo.service.deps import ApiKey, Maps, SceneBody, run_cpu
from camloc_geo.service.models import LocateQuery
from camloc_geo.service.work import locate_body

__all__ = ["SCENE_BODY", "router"]

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


@router.post("/v1/calibrate", openapi_extra=SCENE_BODY)
async def calibrate(request: Request, body: SceneBody) -> JSONResponse:
    """Relative pose (focal length, rotation, camera position in the car's frame)."""
    from camloc_geo.api import calibrate_scene

    def work() -> dict[str, Any]:
        return {"scene": body.scene.id, **calibrate_scene(body.scene).to_dict()}

    return JSONResponse(await run_cpu(request, work))


@router.post("/v1/locate", openapi_extra=SCENE_BODY)
async def locate(
    request: Request, body: SceneBody, maps: Maps, q: Annotated[LocateQuery, Query()]
) -> JSONResponse:
    """Candidate camera positions as the candidate GeoJSON, best first."""

    def work() -> dict[str, Any]:
        out, _m = locate_body(cast(Any, body.scene), maps, max_candidates=q.max_candidates)
        return dict(out.to_geojson())

    return JSONResponse(await run_cpu(request, work))


@router.post("/v1/maps", response_class=HTMLResponse, openapi_extra=SCENE_BODY)
async def review_map(request: Request, body: SceneBody, maps: Maps) -> HTMLResponse:
    """The review page of a scene's candidates: one self-contained offline HTML file."""

    def work() -> str:
        from camloc_geo.maps import candidates_map

        out, m = locate_body(cast(Any, body.scene), maps)
        with tempfile.TemporaryDirectory(prefix="camloc-map-") as tmp:
            path = Path(tmp) / "review.html"
            candidates_map(out.result, m, path, offline=True, scene=out.scene)
            return path.read_text(encoding="utf-8")

    return HTMLResponse(await run_cpu(request, work))
