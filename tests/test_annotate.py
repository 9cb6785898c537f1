"""``camloc annotate`` and camloc_geo.web without a browser: the page, its limits, bad input."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest
from annotate_synthetic import BALTIMORE, located_case, render_snapshot

from camloc_geo import web
from camloc_geo._errors import InputError, SceneError
from camloc_geo.cli import main
from camloc_geo.web import annotation_page_html, read_image

REMOTE = re.compile(
    r"""<(?:script|img|link|iframe)\b[^>]*\b(?:src|href)=["']?(?:https?:)?//""", re.IGNORECASE
)


def one_line_error(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


@pytest.fixture(scope="module")
def snapshot(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("snap") / "cam.jpg"
    path.write_bytes(render_snapshot(located_case()))
    return path


def embedded_config(page: str) -> dict[str, Any]:
    m = re.search(r'<script id="camloc-config" type="application/json">(.*?)</script>', page)
    assert m
    return dict(json.loads(m.group(1)))


def test_page_is_self_contained_and_small(snapshot: Path) -> None:
    """A 1920x1080 JPEG page stays under the image size + 1 MB, with or without the map."""
    ls = located_case()
    from camloc_geo.cli.annotate import junction_geojson

    prior = ls.scene["prior"]
    corners = junction_geojson(lat=prior["lat"], lon=prior["lon"], map_source=str(BALTIMORE))
    image_bytes = snapshot.stat().st_size
    for gj in (None, corners):
        page = annotation_page_html(snapshot, corners_geojson=gj)
        assert len(page.encode()) < image_bytes + 1_000_000
        assert REMOTE.findall(page) == []
        assert "http://" not in page.replace("http://www.w3.org", "")
        cfg = embedded_config(page)
        assert cfg["image"] == {"name": "cam.jpg", "width": 1920, "height": 1080}
        assert cfg["mode"] == "file"
        assert "connect-src 'none'" in page
    assert "corner-label" in page
    assert "L.map" in page


def test_page_escapes_embedded_text(snapshot: Path) -> None:
    scene = dict(located_case().scene)
    scene["id"] = "</script><script>alert(1)</script>"
    page = annotation_page_html(snapshot, scene=scene)
    assert "</script><script>alert(1)" not in page
    assert embedded_config(page)["scene"]["id"] == scene["id"]


def test_crowd_mode_needs_submit_url(snapshot: Path) -> None:
    with pytest.raises(InputError, match="submit_url"):
        annotation_page_html(snapshot, mode="crowd")
    page = annotation_page_html(snapshot, mode="crowd", submit_url="/tasks/7/submit")
    assert embedded_config(page)["submitUrl"] == "/tasks/7/submit"
    assert "connect-src 'self'" in page


def test_cli_writes_page_with_prior_and_map(
    tmp_path: Path, snapshot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    prior = located_case().scene["prior"]
    out = tmp_path / "page.html"
    args = ["annotate", str(snapshot), "-o", str(out), "--osm", str(BALTIMORE)]
    assert main([*args, "--lat", str(prior["lat"]), "--lon", str(prior["lon"])]) == 0
    cfg = embedded_config(out.read_text())
    assert cfg["prior"] == {"lat": prior["lat"], "lon": prior["lon"]}
    kinds = [f["properties"]["kind"] for f in cfg["corners"]["features"]]
    assert kinds.count("intersection") == 1
    assert kinds.count("corner") >= 3
    assert "street" in kinds
    assert "wrote" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("make", "words"),
    [
        (lambda p: p.write_text("not a picture"), "JPEG, PNG or WebP"),
        (lambda p: p.write_bytes(b""), "empty"),
        (
            lambda p: p.write_bytes(bytes(cv2.imencode(".bmp", np.zeros((8, 8, 3), np.uint8))[1])),
            "BMP image; the page takes JPEG, PNG or WebP",
        ),
        (
            lambda p: p.write_bytes(
                bytes(cv2.imencode(".png", np.zeros((8, 8, 3), np.uint8))[1])[:40]
            ),
            "truncated or corrupt PNG file",  # (session 39; it said "give a JPEG, PNG or WebP")
        ),
    ],
)
def test_bad_images_exit_2(
    tmp_path: Path, make: Any, words: str, capsys: pytest.CaptureFixture[str]
) -> None:
    img = tmp_path / "snap.img"
    make(img)
    assert main(["annotate", str(img), "-o", str(tmp_path / "p.html")]) == 2
    line = one_line_error(capsys.readouterr().err)
    assert line.startswith("camloc annotate: error:")
    assert words in line
    assert not (tmp_path / "p.html").exists()


def test_missing_image_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["annotate", str(tmp_path / "nope.jpg")]) == 2
    assert "image not found" in one_line_error(capsys.readouterr().err)


def test_huge_images_are_refused_from_the_header(tmp_path: Path) -> None:
    # A PNG header claiming 60000 x 60000 pixels: refused without decoding anything.
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    ihdr = struct.pack(">IIBBBBB", 60000, 60000, 8, 2, 0, 0, 0)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IEND", b"")
    with pytest.raises(InputError, match="megapixels"):
        read_image(png)
    ihdr = struct.pack(">IIBBBBB", 8000, 6000, 8, 2, 0, 0, 0)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IEND", b"")
    with pytest.raises(InputError, match="8000x6000 pixels; the page takes images up to 40"):
        read_image(png)


def test_large_files_are_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(web, "MAX_IMAGE_BYTES", 1000)
    big = tmp_path / "big.jpg"
    big.write_bytes(b"\xff\xd8\xff" + bytes(2000))
    with pytest.raises(InputError, match="too large"):
        read_image(big)


def test_scene_for_another_image_exit_2(
    tmp_path: Path, snapshot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = dict(located_case().scene)
    scene["image"] = {"width": 1280, "height": 720}
    scene.pop("intersection")
    scene["annotations"] = []
    path = tmp_path / "s.json"
    path.write_text(json.dumps(scene))
    assert main(["annotate", str(snapshot), "--scene", str(path), "-o", "-"]) == 2
    line = one_line_error(capsys.readouterr().err)
    assert "scene is for a 1280x720 image but cam.jpg is 1920x1080" in line


def test_invalid_scene_exit_2(
    tmp_path: Path, snapshot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = json.loads(json.dumps(located_case().scene))
    scene["annotations"][0]["axes"]["origin"] = [812.0]  # one number: not a pixel
    path = tmp_path / "s.json"
    path.write_text(json.dumps(scene))
    assert main(["annotate", str(snapshot), "--scene", str(path), "-o", "-"]) == 2
    line = one_line_error(capsys.readouterr().err)
    assert "annotations[0].axes.origin" in line
    with pytest.raises(SceneError, match=r"annotations\[0\]\.axes\.origin"):
        annotation_page_html(snapshot, scene=scene)


def test_osm_needs_a_point(
    tmp_path: Path, snapshot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["annotate", str(snapshot), "--osm", str(BALTIMORE), "-o", "-"]) == 2
    assert "--lat and --lon" in one_line_error(capsys.readouterr().err)
    assert main(["annotate", str(snapshot), "--lat", "39.2", "-o", "-"]) == 2
    assert "together" in one_line_error(capsys.readouterr().err)


def test_web_assets_are_package_data() -> None:
    import tomllib

    root = Path(__file__).resolve().parents[1]
    conf = tomllib.loads((root / "pyproject.toml").read_text())
    assert "web/*" in conf["tool"]["setuptools"]["package-data"]["camloc_geo"]
    for name in ("annotate.html", "annotate.js", "annotate.css"):
        text = (root / "camloc_geo" / "web" / name).read_text()
        assert "</script" not in text.lower() or name == "annotate.html"
        assert not re.search(r"""(?:src|href)=["']?(?:https?:)?//""", text)


def test_ground_corner_drawing_is_the_docs_drawing_and_inlined(snapshot: Path) -> None:
    """The page inlines web/ground-corner.svg, the same file as docs/ground-corner.svg."""
    from camloc_geo.web import _asset

    root = Path(__file__).parents[1]
    doc = (root / "docs" / "ground-corner.svg").read_text(encoding="utf-8")
    assert _asset("ground-corner.svg") == doc
    page = annotation_page_html(snapshot)
    assert '<template id="ground-corner-drawing"><svg' in page
    assert doc.strip() in page
    assert "ground-corner.svg" in (root / "docs" / "annotate.md").read_text(encoding="utf-8")
    assert "ground-corner.svg" in (root / "docs" / "scene-format.md").read_text(encoding="utf-8")


def test_cli_output_never_overwrites_the_photo_or_scene(
    tmp_path: Path, snapshot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``-o cam.jpg`` replaced the photo with the page and ``-o scene.json --scene
    scene.json`` the scene; both are refused before any work, a missing folder is exit 2
    (was exit 1, FileNotFoundError), and the page is written atomically."""
    photo = tmp_path / "cam.jpg"
    photo.write_bytes(snapshot.read_bytes())
    assert main(["annotate", str(photo), "-o", str(photo)]) == 2
    assert "would overwrite the input" in capsys.readouterr().err
    assert photo.read_bytes() == snapshot.read_bytes()
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(located_case().scene))
    before = scene.read_text()
    assert main(["annotate", str(photo), "-o", str(scene), "--scene", str(scene)]) == 2
    assert "would overwrite the input" in capsys.readouterr().err
    assert scene.read_text() == before
    assert main(["annotate", str(photo), "-o", str(tmp_path / "no" / "p.html")]) == 2
    assert "does not exist (create it first)" in capsys.readouterr().err
    out = tmp_path / "page.html"
    assert main(["annotate", str(photo), "-o", str(out)]) == 0
    assert embedded_config(out.read_text())["mode"] == "file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cam.jpg", "page.html", "scene.json"]
