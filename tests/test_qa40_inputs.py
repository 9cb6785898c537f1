"""Session 40 QA (a grader's walk with their own phone photo): inputs a new user gives.

An iPhone saves its photos as HEIC by default. ``camloc annotate IMG_1234.HEIC`` said "not an
image this page can show; give a JPEG, PNG or WebP file", ``camloc vp`` "not an image file
camloc reads", and ``POST /v1/tasks`` "not a readable JPEG, PNG or WebP image": the grader was
not told that the phone's format is the matter, nor how to get a JPEG.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camloc_geo import InputError, SceneError
from camloc_geo._io import heif_kind
from camloc_geo.cli import main
from camloc_geo.service.routers.crowd import image_info
from camloc_geo.web import read_image

# The first bytes of an iPhone's HEIC photo (ISO media: box size, "ftyp", major brand, ...)
HEIC_HEAD = b"\x00\x00\x00\x18ftypheic\x00\x00\x00\x00mif1heic"
AVIF_HEAD = b"\x00\x00\x00\x1cftypavif\x00\x00\x00\x00avifmif1miaf"


def _photo(tmp_path: Path, head: bytes, name: str) -> Path:
    path = tmp_path / name
    path.write_bytes(head + bytes(range(256)) * 8)
    return path


@pytest.mark.parametrize(
    ("head", "kind"),
    [(HEIC_HEAD, "HEIC"), (AVIF_HEAD, "AVIF"), (b"\xff\xd8\xff\xe0" + b"\0" * 12, None)],
)
def test_heif_kind_reads_the_brand(head: bytes, kind: str | None) -> None:
    assert heif_kind(head[:16]) == kind


def test_annotate_names_a_heic_photo_and_the_way_out(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    photo = _photo(tmp_path, HEIC_HEAD, "IMG_1234.HEIC")
    with pytest.raises(InputError) as page:
        read_image(photo)
    assert str(page.value).startswith(f"{photo} is a HEIC photo, which the page cannot show")
    assert "Most Compatible" in str(page.value)
    assert main(["annotate", str(photo), "-o", str(tmp_path / "p.html")]) == 2
    err = capsys.readouterr().err
    assert "is a HEIC photo" in err
    assert "convert it to JPEG first" in err
    assert not (tmp_path / "p.html").exists()


def test_vp_names_a_heic_photo(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    photo = _photo(tmp_path, HEIC_HEAD, "IMG_1234.HEIC")
    assert main(["vp", str(photo)]) == 2
    err = capsys.readouterr().err
    assert "a HEIC photo, which camloc cannot read" in err
    assert "truncated" not in err


def test_a_task_upload_names_an_avif_photo() -> None:
    with pytest.raises(SceneError) as upload:
        image_info(AVIF_HEAD + bytes(2000), 40_000_000)
    assert "the snapshot is an AVIF photo" in str(upload.value)
    assert "convert it to JPEG first" in str(upload.value)


def test_calibrate_on_the_annotation_page_says_what_to_give(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``camloc calibrate cam.html`` (the page ``annotate`` wrote, not the scene it saves)
    said "malformed JSON in cam.html at line 1, column 1: Expecting value"."""
    from PIL import Image

    snap = tmp_path / "cam.jpg"
    Image.new("RGB", (64, 48), (90, 90, 90)).save(snap)
    page = tmp_path / "cam.html"
    assert main(["annotate", str(snap), "-o", str(page)]) == 0
    capsys.readouterr()
    assert main(["calibrate", str(page)]) == 2
    err = capsys.readouterr().err
    assert "cam.html is a web page, not a scene file" in err
    assert "give the .json file it downloads" in err
    assert "malformed JSON" not in err
    # other broken JSON keeps its line and column
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "camloc-scene/1",\n oops}')
    assert main(["calibrate", str(bad)]) == 2
    assert "malformed JSON in bad.json at line 2, column 2" in capsys.readouterr().err


def test_a_scene_saved_away_from_its_photo_says_where_the_path_is_read(tmp_path: Path) -> None:
    """The page's Save lands in the browser's downloads folder; the scene names the photo by
    its file name alone, so ``calibrate`` there warned "'.../Downloads/la foto.JPG' does not
    exist; the photo is not used" and left the grader to guess why."""
    import json

    from camloc_geo.scene import load_scene

    scene = {
        "format": "camloc-scene/1",
        "id": "la foto",
        "image": {"width": 1632, "height": 1224, "path": "la foto.JPG"},
        "annotations": [
            {
                "axes": {
                    "origin": [600, 500],
                    "length": [800, 520],
                    "width": [560, 540],
                    "height": [600, 420],
                }
            }
        ],
    }
    downloads = tmp_path / "Downloads"
    downloads.mkdir()
    path = downloads / "la foto.json"
    path.write_text(json.dumps(scene), encoding="utf-8")
    notes = [w for w in load_scene(path).input_warnings if w.startswith("image.path: ")]
    assert len(notes) == 1
    assert "la foto.JPG' does not exist" in notes[0]
    assert notes[0].endswith(
        "(image.path is relative to the scene file's folder: keep the scene beside the photo, "
        "or write the photo's full path there)"
    )
    # an absolute path that does not exist: the hint about relative paths does not apply
    scene["image"]["path"] = str(tmp_path / "gone" / "la foto.JPG")
    path.write_text(json.dumps(scene), encoding="utf-8")
    notes = [w for w in load_scene(path).input_warnings if w.startswith("image.path: ")]
    assert notes[0].endswith(
        "the photo is not used (no lines detected in it, no background for the overlay)"
    )
