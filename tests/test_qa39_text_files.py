"""Session 39 QA: scene files and bodies that are not plain UTF-8 JSON.

- A scene saved by Windows Notepad or PowerShell (``Out-File -Encoding utf8``) starts with a
  UTF-8 byte-order mark: ``camloc calibrate`` refused it ("Unexpected UTF-8 BOM (decode
  using utf-8-sig)"), and so did ``POST /v1/calibrate`` with the file as its body; Notepad's
  "Unicode" (UTF-16) was "'utf-8' codec can't decode byte 0xff in position 0". Camera lists,
  verdicts, tracks and GPS files already took both.
- A GeoPackage or a photo given as the scene was "'utf-8' codec can't decode byte 0xd8 in
  position 63: invalid continuation byte": now it says what the file is.
"""

from __future__ import annotations

import asyncio
import codecs
import io
from pathlib import Path

import httpx
import pytest
from PIL import Image

from camloc_geo import SceneError
from camloc_geo._errors import InputError
from camloc_geo.scene import load_scene
from camloc_geo.service import create_app
from camloc_geo.service.settings import Settings

SAMPLE = Path(__file__).resolve().parents[1] / "sample_maps" / "sample_scene.json"


@pytest.mark.parametrize("encoding", ["utf-8-sig", "utf-16"])
def test_a_scene_with_a_byte_order_mark_is_read(tmp_path: Path, encoding: str) -> None:
    text = SAMPLE.read_text(encoding="utf-8")
    marked = tmp_path / "notepad.json"
    marked.write_bytes(text.encode(encoding))
    assert marked.read_bytes()[:2] in (
        codecs.BOM_UTF8[:2],
        codecs.BOM_UTF16_LE,
        codecs.BOM_UTF16_BE,
    )
    read, plain = load_scene(marked), load_scene(SAMPLE)
    assert read.model_dump(exclude={"base_dir"}) == plain.model_dump(exclude={"base_dir"})


def _jpeg() -> bytes:
    buf = io.BytesIO()
    Image.new("RGB", (16, 16)).save(buf, format="JPEG")
    return buf.getvalue()


@pytest.mark.parametrize(
    ("data", "kind"),
    [
        (b"SQLite format 3\x00" + bytes(range(256)) * 4, "a GeoPackage or SQLite database"),
        (_jpeg(), "a JPEG image"),
        (
            b'{"schema": "camloc-scene/1", "id": "caf\xe9"}',
            "not UTF-8 text (byte 0xe9 at position 39)",
        ),
    ],
)
def test_a_scene_that_is_no_text_says_what_it_is(tmp_path: Path, data: bytes, kind: str) -> None:
    path = tmp_path / "scene.json"
    path.write_bytes(data)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert str(info.value) == (
        f"cannot read scene file {path}: it is {kind}; a scene is camloc-scene/1 JSON text"
    )


def _calibrate(tmp_path: Path, body: bytes) -> httpx.Response:
    app = create_app(Settings(data_dir=tmp_path / "d", workers=0))

    async def run() -> httpx.Response:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            headers = {"content-type": "application/json"}
            return await client.post("/v1/calibrate", content=body, headers=headers, timeout=60)

    try:
        return asyncio.run(run())
    finally:
        app.state.compute.shutdown()


def test_a_body_with_a_byte_order_mark_is_calibrated(tmp_path: Path) -> None:
    plain = SAMPLE.read_bytes()
    r_plain = _calibrate(tmp_path / "a", plain)
    r_marked = _calibrate(tmp_path / "b", codecs.BOM_UTF8 + plain)
    assert r_plain.status_code == 200, r_plain.text
    assert r_marked.status_code == 200, r_marked.text
    assert r_marked.json()["focal_px"] == r_plain.json()["focal_px"]


def test_a_geopackage_body_says_what_it_is(tmp_path: Path) -> None:
    r = _calibrate(tmp_path, b"SQLite format 3\x00" + bytes(range(256)) * 4)
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["field"] == "body"
    assert err["message"] == (
        "body: the body is not valid JSON: it is a GeoPackage or SQLite database"
    )


@pytest.mark.parametrize("reader", ["guide.read_gps", "guide.read_tracks", "radar.read_tracks"])
def test_sensor_inputs_name_a_geopackage_not_the_codec(tmp_path: Path, reader: str) -> None:
    """``camloc guide --gps cams.gpkg`` / ``--tracks`` and ``camloc radar --tracks cams.gpkg``
    said "'utf-8' codec can't decode byte 0xd8 ...": they now name what the file is."""
    import sqlite3

    from camloc_geo.sensors import guide, radar

    gpkg = tmp_path / "cams.gpkg"
    con = sqlite3.connect(gpkg)
    con.execute("create table t (x integer)")
    con.commit()
    con.close()
    module, name = reader.split(".")
    fn = getattr({"guide": guide, "radar": radar}[module], name)
    with pytest.raises(InputError) as info:
        fn(gpkg)
    msg = str(info.value)
    assert "a GeoPackage or SQLite database" in msg
    assert "codec" not in msg


def test_sensor_csv_with_byte_order_mark_still_reads(tmp_path: Path) -> None:
    """The GPS CSV saved by Notepad (UTF-8 with a mark) reads as before."""
    from camloc_geo.sensors.guide import read_gps

    p = tmp_path / "gps.csv"
    p.write_bytes(b"\xef\xbb\xbfid,time,lat,lon\na,0,52.5,13.4\na,1,52.50001,13.4\n")
    traces = read_gps(p)
    assert [t.id for t in traces] == ["a"]
    assert len(traces[0].times_s) == 2
