"""Session 40 QA: a verdict posted without ``camera`` sank the team's whole export.

``POST /v1/verdicts/...`` took an item with no ``camera`` without a word; its export then had
a row with an empty camera, and ``read_verdicts`` (``camloc summary-map --verdicts``,
``camloc locate --map ... --verdicts``) refused the whole file: "line 3: no camera id". The
post now answers a warning naming the item, and the reader leaves that row out, warned, and
reads the rest.
"""

from __future__ import annotations

import asyncio
import logging
from pathlib import Path
from typing import Any

import httpx
import pytest

from camloc_geo import maps
from camloc_geo._errors import InputError
from camloc_geo.service import create_app
from camloc_geo.service.settings import Settings

URL = "/v1/verdicts/summary/0123456789abcdef"


def _calls(tmp_path: Path, body: dict[str, Any]) -> tuple[httpx.Response, httpx.Response]:
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> tuple[httpx.Response, httpx.Response]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            posted = await client.post(URL, json=body)
            export = await client.get(URL, params={"format": "csv"})
            return posted, export

    try:
        return asyncio.run(run())
    finally:
        app.state.compute.shutdown()


def test_an_item_without_camera_is_named_and_the_export_still_reads(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    body = {
        "items": {
            "c0": {"verdict": "yes", "camera": "cam-a", "lat": 51.5, "lon": -0.1},
            "c1": {"verdict": "no"},  # no camera
            "c2": {"verdict": "unsure", "camera": "cam-c"},
            "c3": {"verdict": None},  # a withdrawal: nothing to warn about
        }
    }
    posted, export = _calls(tmp_path, body)
    assert posted.status_code == 200, posted.text
    out = posted.json()
    assert sorted(out["taken"]) == ["c0", "c1", "c2", "c3"]
    assert len(out["warnings"]) == 1
    assert out["warnings"][0].startswith("item 'c1': no camera")
    path = tmp_path / "team.csv"
    path.write_bytes(export.content)
    with caplog.at_level(logging.WARNING, logger="camloc_geo.maps"):
        rows = maps.read_verdicts(path)
    assert [(r["camera"], r["verdict"]) for r in rows] == [("cam-a", "yes"), ("cam-c", "unsure")]
    assert "1 verdict row(s) without a camera id left out (line 3)" in caplog.text


def test_a_post_with_cameras_has_no_warning(tmp_path: Path) -> None:
    posted, _export = _calls(tmp_path, {"items": {"c0": {"verdict": "yes", "camera": "x"}}})
    assert posted.json()["warnings"] == []


def test_a_file_where_no_row_names_a_camera_is_still_refused(tmp_path: Path) -> None:
    path = tmp_path / "v.csv"
    path.write_text(
        ",".join(maps.VERDICT_FIELDS) + "\n,1,,,yes,,,,summary,0123456789abcdef\n"
        ",2,,,no,,,,summary,0123456789abcdef\n",
        encoding="utf-8",
    )
    with pytest.raises(InputError, match=r"line 2, line 3: no camera id, in any row"):
        maps.read_verdicts(path)
