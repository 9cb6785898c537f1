"""Session 38 QA: ``POST /v1/jobs`` CSV bodies that are not plain UTF-8 CSV.

A GeoPackage sent as ``text/csv`` and a CSV whose rows end with a bare CR (a Mac
spreadsheet's "CSV (Macintosh)") were 500s (the csv module's error escaped); a UTF-16 body
(Excel's "Unicode Text") was read as Windows-1252 and its cameras lost. ``camloc batch``
reads the CR list and the UTF-16 list, and refuses the GeoPackage naming it.
"""

from __future__ import annotations

import asyncio
from pathlib import Path

import httpx
import pytest

from camloc_geo import SceneError
from camloc_geo.service import create_app
from camloc_geo.service.routers.jobs import camera_records, csv_encoding_warning
from camloc_geo.service.settings import Settings


def _post_jobs(tmp_path: Path, body: bytes) -> httpx.Response:
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            return await client.post("/v1/jobs", content=body, headers={"content-type": "text/csv"})

    try:
        return asyncio.run(run())
    finally:
        app.state.compute.shutdown()


@pytest.mark.parametrize(
    ("body", "words"),
    [
        (b"SQLite format 3\x00\x10\x00\x01\x01\x00@  " + b"\x00" * 80, "a GeoPackage"),
        (b"id,title\nc1,Ea\x00st\n", "NUL bytes"),
        (b"\xff\xfei\x00d\x00\x00\xd8", "not UTF-16 text"),
    ],
)
def test_a_body_that_is_no_csv_text_is_a_422_naming_it(
    tmp_path: Path, body: bytes, words: str
) -> None:
    r = _post_jobs(tmp_path, body)
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["field"] == "body"
    assert words in err["message"]


def test_rows_ended_by_a_bare_cr_are_rows(tmp_path: Path) -> None:
    body = b"id,title\rc1,Eastern Ave & S Broadway\rc2,Fleet St & S Broadway\r"
    cams = camera_records(body, "text/csv", 10)
    assert [(c["id"], c["title"]) for c in cams] == [
        ("c1", "Eastern Ave & S Broadway"),
        ("c2", "Fleet St & S Broadway"),
    ]
    r = _post_jobs(tmp_path, body)
    assert r.status_code == 202, r.text
    assert r.json()["total"] == 2


def test_a_malformed_csv_is_a_422_not_a_500(tmp_path: Path) -> None:
    # a field over the csv module's limit (1 MB): its csv.Error is the client's error
    r = _post_jobs(tmp_path, b"id,title\nc1," + b"A" * 1_200_000 + b"\n")
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["field"] == "body"
    assert "malformed CSV list" in err["message"]


def test_excel_unicode_text_body_is_read(tmp_path: Path) -> None:
    body = "id\ttitle\tlat\tlon\nc1\tStraße & Blücherplatz\t52,5\t13,4\n".encode("utf-16")
    (cam,) = camera_records(body, "text/csv", 10)
    assert cam["id"] == "c1"
    assert cam["title"] == "Straße & Blücherplatz"
    assert (cam["lat"], cam["lon"]) == (52.5, 13.4)
    assert csv_encoding_warning(body) is None


@pytest.mark.parametrize(
    "body",
    [
        b"foo,bar\n1,2\n3,4\n",
        b"Eastern Ave & S Broadway\nFleet St & S Broadway\n",  # titles without a header
        b"id,lat,lon\nc1,39.28,-76.59\n",
    ],
)
def test_a_csv_no_camera_can_be_placed_by_is_refused(tmp_path: Path, body: bytes) -> None:
    """As ``camloc batch`` refuses it (session 37): the job was accepted and every camera
    ended ``no_evidence``."""
    r = _post_jobs(tmp_path, body)
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["field"] == "body"
    assert "no column a camera can be placed by" in err["message"]
    assert body.decode().splitlines()[0][:20] in err["message"]


def test_a_csv_with_one_placeable_row_is_taken(tmp_path: Path) -> None:
    body = b"id,title\nc1,\nc2,Eastern Ave & S Broadway\n"
    assert [c["id"] for c in camera_records(body, "text/csv", 10)] == ["c1", "c2"]


@pytest.mark.parametrize("body", [b"", b"\n\n", b"id,title,lat,lon\n", b"\xef\xbb\xbfid,title\r\n"])
def test_a_csv_without_a_camera_names_the_body(tmp_path: Path, body: bytes) -> None:
    """Session 41 QA: a CSV body without a row was 'cameras: the list holds no camera', field
    ``cameras``, a JSON field a CSV body has not."""
    r = _post_jobs(tmp_path, body)
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["field"] == "body"
    assert "the CSV list holds no camera" in err["message"]


def test_an_empty_feature_collection_names_its_features(tmp_path: Path) -> None:
    with pytest.raises(SceneError) as err:
        camera_records(b'{"type": "FeatureCollection", "features": []}', "application/json", 10)
    assert err.value.field == "features"
    assert "FeatureCollection holds no camera" in str(err.value)
    # a JSON list keeps its own field ('cameras: the list holds no camera', POST /v1/jobs)
    assert camera_records(b'{"cameras": []}', "application/json", 10) == []
