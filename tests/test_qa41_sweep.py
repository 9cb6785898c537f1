"""Stop 41 (qa3): bad input through the real clients gets a clear error naming it.

Each test failed before its fix.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camloc_geo import api
from camloc_geo._errors import InputError

REPO = Path(__file__).resolve().parents[1]
BALTIMORE = REPO / "sample_maps" / "baltimore.osm.pbf"


def _camloc(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", *args],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=cwd,
    )


@pytest.mark.parametrize("point", [(1e9, 3.0), (-5.0, 10.0), (10.0, 601.0)])
def test_vp_refuses_a_principal_point_off_the_image(point: tuple[float, float]) -> None:
    """``camloc vp --principal-point 1e9 3`` answered a focal length at a stated 0.0 % with
    confidence 0.94 and no warning."""
    img = np.zeros((600, 800), np.uint8)
    with pytest.raises(InputError, match=r"lies outside the 800x600 image"):
        api.vanishing_points(img, principal_point=point)


def test_vp_cli_names_the_principal_point(tmp_path: Path) -> None:
    import cv2

    path = tmp_path / "p.png"
    assert cv2.imwrite(str(path), np.zeros((60, 80), np.uint8))
    r = _camloc("vp", str(path), "--principal-point", "1e9", "3", cwd=tmp_path)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert "principal_point (1e+09, 3) lies outside the 80x60 image" in r.stderr


@pytest.mark.parametrize("content", ["id,title\n", "id,title\n\n\n"])
def test_geocode_refuses_a_list_without_rows(tmp_path: Path, content: str) -> None:
    """A list with a header and no row printed an empty FeatureCollection, exit 0, where
    ``camloc batch`` refuses it."""
    lst = tmp_path / "cams.csv"
    lst.write_text(content)
    out = tmp_path / "out.geojson"
    r = _camloc(
        "geocode", "--osm", str(BALTIMORE), "--list", str(lst), "-o", str(out), cwd=tmp_path
    )
    assert r.returncode == 2, r.stderr
    assert "holds no title (no row under its header)" in r.stderr
    assert "Traceback" not in r.stderr
    assert not out.exists()


def test_a_locate_output_given_as_a_scene_is_named(tmp_path: Path) -> None:
    """``camloc calibrate cands.geojson`` (and ``POST /v1/calibrate`` with it) said only
    "format: missing; expected 'camloc-scene/1'"."""
    from camloc_geo.scene import SceneError, parse_scene

    fc = {"type": "FeatureCollection", "features": []}
    with pytest.raises(SceneError, match="this is a GeoJSON FeatureCollection"):
        parse_scene(fc)
    calibration = {"scene": "s", "focal_px": 1000.0, "cam_from_world": [[1, 0, 0, 0]]}
    with pytest.raises(SceneError, match="this is camloc calibrate's output"):
        parse_scene(calibration)
    with pytest.raises(SceneError) as plain:
        parse_scene({"a": 1})
    assert str(plain.value) == "format: missing; expected 'camloc-scene/1'"
    path = tmp_path / "cands.geojson"
    path.write_text('{"type": "FeatureCollection", "features": []}')
    r = _camloc("calibrate", str(path), cwd=tmp_path)
    assert r.returncode == 2
    assert "not a scene; give the scene file the annotation page saved" in r.stderr


def _service_get(tmp_path: Path, path: str) -> Any:
    import asyncio

    import httpx

    from camloc_geo.service import create_app
    from camloc_geo.service.settings import Settings

    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.get(path)

    try:
        return asyncio.run(run())
    finally:
        app.state.compute.shutdown()


@pytest.mark.parametrize(
    ("path", "said"),
    [
        ("/v1/jobs/nope", "job_id: 'nope' is not an id of this service (32 hex digits"),
        ("/annotate/ABC", "task_id: 'ABC' is not an id of this service (32 hex digits"),
        ("/v1/verdicts/summary/zz", "identity: 'zz' is not a page identity (16 hex digits"),
    ],
)
def test_a_malformed_id_is_named_in_words(tmp_path: Path, path: str, said: str) -> None:
    """A job, task or page id of the wrong shape was answered "String should match pattern
    '^[0-9a-f]{32}$'": a regular expression for an analyst who pasted half an id."""
    r = _service_get(tmp_path, path)
    assert r.status_code == 422, r.text
    message = r.json()["error"]["message"]
    assert said in message
    assert "pattern" not in message


def _candidates_file(tmp_path: Path, score: object, **more: object) -> Path:
    import json

    fc = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [-76.59, 39.28]},
                "properties": {"kind": "candidate", "rank": 1, "score": score, **more},
            }
        ],
    }
    path = tmp_path / "cands.geojson"
    path.write_text(json.dumps(fc))
    return path


@pytest.mark.parametrize(
    ("score", "code", "said"),
    [
        ("high", 2, "feature 0: score 'high' is not a number from 0 to 1: skipped"),
        ([0.3], 2, "feature 0: score [0.3] is not a number from 0 to 1: skipped"),
        (None, 0, ""),  # as a candidate without a score
        ("0.37", 0, ""),  # a GIS's text for the number
    ],
)
def test_summary_map_of_a_candidate_with_a_bad_score(
    tmp_path: Path, score: object, code: int, said: str
) -> None:
    """A candidate's score of text or null failed with 'TypeError: must be real number, not
    str' (exit 1, an internal failure) or 'unsupported format string passed to
    NoneType.__format__'."""
    path = _candidates_file(tmp_path, score)
    r = _camloc("summary-map", str(path), "-o", str(tmp_path / "m.html"), cwd=tmp_path)
    assert r.returncode == code, r.stderr
    assert "TypeError" not in r.stderr
    assert said in r.stderr
    if code == 0 and score == "0.37":
        assert "0.37" in (tmp_path / "m.html").read_text()


def test_summary_map_of_a_candidate_with_a_heading_in_words(tmp_path: Path) -> None:
    """``"heading_deg": "north"`` failed with 'TypeError: must be real number, not str'."""
    path = _candidates_file(tmp_path, 0.5, heading_deg="north", height_m="7.5")
    r = _camloc("summary-map", str(path), "-o", str(tmp_path / "m.html"), cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "feature 0: heading_deg 'north' is not a number: drawn without it" in r.stderr
    assert "height_m" not in r.stderr  # numeric text is read


def test_an_extract_copied_into_the_services_folder_serves_without_a_restart(
    tmp_path: Path,
) -> None:
    """The service listed CAMLOC_MAP_DIR once, at start-up: an extract copied in later (as
    its own error message asks the operator to do) served nothing until a restart."""
    import asyncio
    import shutil

    import httpx

    from camloc_geo.service import create_app
    from camloc_geo.service.settings import Settings

    maps = tmp_path / "maps"
    maps.mkdir()
    shutil.copy(REPO / "data" / "osm" / "monaco.osm.pbf", maps)
    app = create_app(Settings(data_dir=tmp_path / "d", map_dir=maps, workers=0))
    params = {"lat": "39.2856", "lon": "-76.5935", "radius_m": "80"}

    async def corners() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.get("/v1/corners", params=params)

    async def health() -> dict[str, Any]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return (await client.get("/healthz")).json()

    try:
        before = asyncio.run(corners())
        assert before.status_code == 422, before.text
        assert before.json()["error"]["type"] == "map_data"
        assert asyncio.run(health())["extracts"] == 1
        shutil.copy(BALTIMORE, maps)
        after = asyncio.run(corners())
        assert after.status_code == 200, after.text
        assert any(f["properties"].get("kind") == "intersection" for f in after.json()["features"])
        assert asyncio.run(health())["extracts"] == 2
    finally:
        app.state.compute.shutdown()
