"""Stop 41 QA (qa5): the job map's popup (``GET /v1/jobs/{id}/map``) and ``camloc batch
--map``'s showed ``residual_m`` as "—" for every located camera: the camera-list engine's
candidates did not carry locate's ``residual_m`` (the RMS misfit of the matched map
features), which the popup reads."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from camloc_geo.api import locate_camera
from camloc_geo.results import camera_job_result
from camloc_geo.service.routers.jobs import job_summary_page

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "sample_maps" / "sample_scene.json"
EXTRACT = REPO / "sample_maps" / "baltimore.osm.pbf"


@pytest.fixture(scope="module")
def located() -> dict:
    res = locate_camera({"id": "s1", "scene": str(SCENE)}, map_source=str(EXTRACT))
    assert res.status == "located"
    return camera_job_result(res)


def test_a_located_cameras_candidates_carry_their_residual(located: dict) -> None:
    props = [
        f["properties"] for f in located["candidates"] if f["properties"]["source"] == "locate"
    ]
    assert props
    residuals = [p["residual_m"] for p in props]
    assert all(isinstance(r, float) and 0.0 <= r < 50.0 for r in residuals)
    assert residuals[0] < 10.0  # the best candidate fits the sample's corners closely


def test_the_job_maps_popup_shows_the_best_candidates_residual(located: dict) -> None:
    page = job_summary_page([located])
    best = located["candidates"][0]["properties"]["residual_m"]
    shown = re.findall(r"<th>residual_m</th><td>([^<]*)</td>", page)
    assert shown == [f"{best:.2f} m"]


def test_batch_maps_popup_shows_the_best_candidates_residual(tmp_path: Path) -> None:
    import pyogrio

    from camloc_geo.batch import run_batch

    lst = tmp_path / "cams.csv"
    lst.write_text(f"id,scene\ns1,{SCENE}\n", encoding="utf-8")
    out, page = tmp_path / "o.gpkg", tmp_path / "o.html"
    run_batch(lst, out_gpkg=out, map_source=EXTRACT, summary_map=page, workers=1, progress=False)
    cands = pyogrio.read_dataframe(out, layer="candidates")
    best = float(cands.loc[cands["rank"] == 1, "residual_m"].iloc[0])
    assert 0.0 <= best < 10.0
    shown = re.findall(r"<th>residual_m</th><td>([^<]*)</td>", page.read_text(encoding="utf-8"))
    assert shown == [f"{best:.2f} m"]
