"""Bad photos, videos and output paths: one clear line naming the file, never a traceback.

Each input is made here (Pillow, numpy, OpenCV) in ``tmp_path``: empty, truncated or text
files posing as photos, decompression bombs, absurd EXIF, photos of another size than the
scene's, unwritable outputs. ``camloc vp`` and ``camloc radar`` refuse them with exit 2;
``camloc calibrate`` leaves a bad scene photo out with a warning and still uses the
annotations (one bad part never sinks the rest).
"""

from __future__ import annotations

import os
import struct
import zlib
from pathlib import Path

import pytest

from camloc_geo.cli import main

PROC = Path("/proc")


def one_line_error(err: str, command: str) -> str:
    """The single non-empty stderr line of a refused command (no traceback)."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err, err
    assert len(lines) == 1, err
    assert lines[0].startswith(f"camloc {command}: error: "), lines[0]
    return lines[0]


def png_header(path: Path, width: int, height: int) -> Path:
    """A PNG whose header claims ``width`` x ``height`` gray pixels, with almost no data."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        crc = zlib.crc32(kind + data) & 0xFFFFFFFF
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", crc)

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", zlib.compress(b"\0" * 100))
        + chunk(b"IEND", b"")
    )
    return path


# ------------------------------------------------------------------------------ outputs
def _unwritable_dir(tmp_path: Path) -> Path:
    if os.geteuid() != 0:
        d = tmp_path / "ro"
        d.mkdir()
        d.chmod(0o500)
        return d
    if not PROC.is_dir():  # pragma: no cover - not Linux
        pytest.skip("no unwritable directory for root here")
    return PROC


@pytest.mark.parametrize("option", ["-o", "--draw"])
def test_vp_output_in_an_unwritable_directory_is_refused_before_work(
    option: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the photo is not even read: the output is checked first (it used to fail after the
    # work with exit 1 and "FileNotFoundError: ... .tmp.png")
    target = _unwritable_dir(tmp_path) / ("x.png" if option == "--draw" else "x.json")
    assert main(["vp", str(tmp_path / "missing.jpg"), option, str(target)]) == 2
    line = one_line_error(capsys.readouterr().err, "vp")
    assert f"{option} {target}: cannot write in the directory" in line


# ------------------------------------------------------------------------------- photos
@pytest.mark.parametrize(
    ("width", "height", "size_text"),
    [(60000, 60000, "(3600 MP)"), (10000, 10000, "10000x10000 pixels (100 MP)")],
)
def test_vp_refuses_a_decompression_bomb_from_its_header(
    width: int, height: int, size_text: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # 60000 x 60000 used to end in exit 1 "failed: DecompressionBombError" (raised while
    # reading the EXIF); 100 MP printed Pillow's DecompressionBombWarning (two more lines)
    photo = png_header(tmp_path / "bomb.png", width, height)
    assert main(["vp", str(photo)]) == 2
    line = one_line_error(capsys.readouterr().err, "vp")
    assert f"image {photo} is too large" in line or f"image {photo} is {width}x" in line
    assert size_text in line
    assert "limit is 50 megapixels" in line


@pytest.mark.parametrize(
    "tags",
    [
        {0xA405: 2000},  # FocalLengthIn35mmFilm 2000 mm: 53 times the longer side
        {0x920A: 5000.0, 0xA20E: 1280 / 6.0, 0xA210: 4},  # 5 m lens on a 6 mm sensor
        {0x920A: 0.01, 0xA20E: 1280 / 6.0, 0xA210: 4},  # 0.01 mm
    ],
)
def test_an_implausible_exif_focal_length_is_ignored_with_a_warning(
    tags: dict[int, object], tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    from PIL import Image

    from camloc_geo.exif import focal_from_exif

    photo = tmp_path / "p.jpg"
    exif = Image.Exif()
    sub = exif.get_ifd(0x8769)
    sub.update(tags)
    Image.new("RGB", (1280, 720), (90, 90, 90)).save(photo, exif=exif)
    # before: a prior of 101829, 1600000 or 3 px that pinned autovp's fit to its bound
    assert focal_from_exif(photo) is None
    assert f"{photo}: EXIF focal length ignored" in caplog.text
    assert "plausible: 0.3 to 6" in caplog.text


@pytest.mark.parametrize("f35", [3.0, 5000.0])
def test_an_implausible_35mm_tag_alone_is_named(
    f35: float, tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    # before: dropped without a word, and vp then asked for "a photo with EXIF" although the
    # photo has one
    from PIL import Image

    from camloc_geo.exif import focal_from_exif

    photo = tmp_path / "p.jpg"
    exif = Image.Exif()
    exif.get_ifd(0x8769).update({0xA405: int(f35)})
    Image.new("RGB", (1280, 720), (90, 90, 90)).save(photo, exif=exif)
    assert focal_from_exif(photo) is None
    assert f"{photo}: EXIF focal length ignored: FocalLengthIn35mmFilm is {f35:g} mm" in caplog.text


def test_an_unknown_35mm_tag_is_not_a_fault(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    from PIL import Image

    from camloc_geo.exif import focal_from_exif

    photo = tmp_path / "p.jpg"
    exif = Image.Exif()
    exif.get_ifd(0x8769).update({0xA405: 0})  # EXIF's "unknown"
    Image.new("RGB", (1280, 720), (90, 90, 90)).save(photo, exif=exif)
    assert focal_from_exif(photo) is None
    assert "ignored" not in caplog.text


def test_exif_plausible_range_is_the_range_autovp_searches() -> None:
    from camloc_geo.autovp import FOCAL_BOUNDS_REL
    from camloc_geo.exif import PLAUSIBLE_FOCAL_REL

    assert PLAUSIBLE_FOCAL_REL == FOCAL_BOUNDS_REL


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("empty.jpg", "cannot decode image {p}: the file is empty (0 bytes)"),
        ("cut.jpg", "cannot decode image {p}: a truncated or corrupt JPEG file"),
        ("cut_in_header.jpg", "cannot decode image {p}: a truncated or corrupt JPEG file"),
        ("cut.png", "cannot decode image {p}: a truncated or corrupt PNG file"),
        ("text.jpg", "cannot decode image {p}: not an image file camloc reads (JPEG, PNG, TIFF,"),
        ("bomb.hdr", "cannot decode image {p}: not an image file camloc reads (JPEG, PNG, TIFF,"),
        ("tiny.png", "image {p} is too small: 1x1 pixels (at least 8 on a side)"),
        ("float.tif", "cannot decode image {p}: a TIFF file OpenCV does not decode (truncated,"),
    ],
)
def test_vp_names_the_file_and_what_is_wrong(
    name: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # before: "cannot decode image 'x' (not a supported image file)" for all of them, and
    # "libpng error: PNG input buffer is incomplete" on stderr for the cut PNG
    photo = _bad_photo(tmp_path, name)
    assert main(["vp", str(photo)]) == 2
    assert message.format(p=photo) in one_line_error(capsys.readouterr().err, "vp")


def _good_photo(path: Path, size: tuple[int, int], orientation: int | None = None) -> Path:
    """A photo of ``size`` (as stored) with a few lines, and an EXIF orientation if given."""
    import numpy as np
    from PIL import Image, ImageDraw

    im = Image.new("RGB", size, (90, 90, 90))
    draw = ImageDraw.Draw(im)
    rng = np.random.default_rng(1)
    for _ in range(30):
        draw.line(
            [tuple(rng.uniform(0, size[0], 2)), tuple(rng.uniform(0, size[1], 2))], "white", 2
        )
    exif = Image.Exif()
    if orientation is not None:
        exif[0x0112] = orientation
    im.save(path, exif=exif)
    return path


def _bad_photo(tmp_path: Path, name: str) -> Path:
    """The bad photos of these tests, made in ``tmp_path``."""
    p = tmp_path / name
    if name == "empty.jpg":
        p.write_bytes(b"")
    elif name in ("cut.jpg", "cut_in_header.jpg"):
        whole = _good_photo(tmp_path / "whole.jpg", (640, 480)).read_bytes()
        p.write_bytes(whole[: len(whole) // 3] if name == "cut.jpg" else whole[:200])
    elif name == "cut.png":
        from PIL import Image

        Image.new("RGB", (640, 480), (20, 90, 200)).save(tmp_path / "whole.png")
        whole = (tmp_path / "whole.png").read_bytes()
        p.write_bytes(whole[: len(whole) // 2])
    elif name == "text.jpg":
        p.write_text("I am not a photo\n", encoding="utf-8")
    elif name == "bomb.hdr":  # a Radiance HDR claiming 30000 x 30000 (Pillow cannot read it)
        p.write_bytes(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 30000 +X 30000\n" + b"\0" * 40)
    elif name == "float.tif":  # 32-bit float samples: OpenCV printed a WARN line, then
        import numpy as np  # "truncated or corrupt"
        from PIL import Image

        Image.fromarray(np.random.default_rng(0).random((48, 64)).astype(np.float32)).save(p)
    elif name == "tiny.png":
        from PIL import Image

        Image.new("RGB", (1, 1)).save(p)
    elif name == "folder.jpg":
        p.mkdir()
    elif name == "bomb.png":
        png_header(p, 60000, 60000)
    elif name == "other size.jpg":  # a scaled copy: the overlay's background only
        _good_photo(p, (1280, 960))
    elif name == "other shape.jpg":
        _good_photo(p, (1280, 720))
    elif name == "turned.jpg":  # stored 640x480, displayed 480x640 (EXIF orientation 6)
        _good_photo(p, (640, 480), orientation=6)
    else:  # pragma: no cover - a typo in a test
        raise AssertionError(name)
    return p


# ---------------------------------------------------------------- calibrate's scene photo
REAL_CAR = Path(__file__).resolve().parent / "data" / "real_car" / "yud_P1020822_corolla.json"


def _scene_with_photo(tmp_path: Path, photo: str | None) -> Path:
    import json

    data = json.loads(REAL_CAR.read_text(encoding="utf-8"))  # a 640x480 scene
    data["image"] = {"width": 640, "height": 480}
    if photo is not None:
        data["image"]["path"] = photo
    scene = tmp_path / f"scene-{len(list(tmp_path.iterdir()))}.json"
    scene.write_text(json.dumps(data), encoding="utf-8")
    return scene


def _calibrate(scene: Path, capsys: pytest.CaptureFixture[str]) -> tuple[dict, str]:
    import json

    assert main(["calibrate", str(scene)]) == 0
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    return json.loads(captured.out), captured.err


@pytest.mark.parametrize(
    ("name", "why"),
    [
        ("empty.jpg", "the file is empty (0 bytes)"),
        ("cut.jpg", "a truncated or corrupt JPEG file"),
        ("text.jpg", "not an image file"),
        ("tiny.png", "is too small: 1x1 pixels"),
        ("folder.jpg", "is not a regular file"),
        ("bomb.png", "is too large (3600 MP)"),
        ("other size.jpg", "is 1280x960 pixels as displayed but the scene's image is 640x480"),
        ("other shape.jpg", "is 1280x720 pixels as displayed but the scene's image is 640x480"),
        ("turned.jpg", "is 480x640 pixels as displayed but the scene's image is 640x480 (turned"),
    ],
)
def test_calibrate_leaves_a_bad_photo_out_with_a_warning_and_uses_the_annotations(
    name: str,
    why: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture,
) -> None:
    # before: the photo was skipped silently (empty, cut, text, tiny, bomb), said "does not
    # exist" (a folder), or was used although its pixels are not the scene's (other size,
    # turned: its lines then widened every stated sigma with a focal length of its own)
    (tmp_path / "photos").mkdir()
    photo = _bad_photo(tmp_path / "photos", name)
    without, _ = _calibrate(_scene_with_photo(tmp_path, None), capsys)
    result, _ = _calibrate(_scene_with_photo(tmp_path, str(photo)), capsys)
    notes = [w for w in result["warnings"] if w.startswith("image.path: ")]
    assert len(notes) == 1, result["warnings"]
    assert why in notes[0]
    assert str(photo) in notes[0]
    assert notes[0].endswith(
        ": a scaled copy, used as the overlay's background only (no lines detected in it)"
        if name == "other size.jpg"
        else "the photo is not used (no lines detected in it, no background for the overlay)"
    )
    assert notes[0] in caplog.text  # also on stderr
    assert result["focal_px"] == pytest.approx(without["focal_px"], rel=1e-9)
    assert result["focal_sigma_px"] == pytest.approx(without["focal_sigma_px"], rel=1e-9)


def test_calibrate_uses_a_photo_its_exif_orientation_turns_to_the_scene_size(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # stored 480x640, displayed 640x480 (EXIF orientation 6): the grid the annotators saw
    photo = _good_photo(tmp_path / "upright.jpg", (480, 640), orientation=6)
    result, _ = _calibrate(_scene_with_photo(tmp_path, photo.name), capsys)
    assert not any("the photo is not used" in w for w in result["warnings"])


@pytest.mark.parametrize(
    ("option", "message"),
    [
        (["--focal-px", "1e300"], "focal_px 1e+300 is not a focal length for a 640x480 image"),
        (["--seed", "-1"], "seed must be a non-negative integer, got -1"),
    ],
)
def test_vp_refuses_absurd_options(
    option: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # before: 1e300 printed numpy's RuntimeWarning lines then "no vanishing point
    # hypothesis"; a negative seed was exit 1 "failed: ValueError: expected non-negative"
    photo = _good_photo(tmp_path / "p.jpg", (640, 480))
    assert main(["vp", str(photo), *option]) == 2
    assert message in one_line_error(capsys.readouterr().err, "vp")


# --------------------------------------------------------------------- service uploads
@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("cut.jpg", "body: the snapshot is a truncated or corrupt JPEG file"),
        ("cut.png", "body: the snapshot is a truncated or corrupt PNG file"),
        ("tiny.png", "body: the snapshot is 1×1: too small to annotate (at least 8 pixels a side)"),
    ],
)
def test_service_refuses_a_cut_off_or_tiny_snapshot(
    name: str, message: str, tmp_path: Path
) -> None:
    # before: POST /v1/tasks made a task of it (only the header was read), which its
    # annotators then got as a broken or 1-pixel image
    pytest.importorskip("fastapi")
    from camloc_geo import SceneError
    from camloc_geo.service.routers.crowd import image_info

    raw = _bad_photo(tmp_path, name).read_bytes()
    with pytest.raises(SceneError) as info:
        image_info(raw, 40_000_000)
    assert str(info.value) == message
    whole = tmp_path / ("whole.jpg" if name == "cut.jpg" else "whole.png")
    if whole.exists():
        assert image_info(whole.read_bytes(), 40_000_000)[1:] == (640, 480)


# ------------------------------------------------------------------------------- videos
def _video(path: Path, n_frames: int, size: tuple[int, int] = (640, 480)) -> Path:
    import cv2
    import numpy as np

    writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*"MJPG"), 25.0, size)
    if not writer.isOpened():  # pragma: no cover - OpenCV built without its AVI writer
        pytest.skip("OpenCV cannot write MJPG AVI here")
    for i in range(n_frames):
        frame = np.full((size[1], size[0], 3), 90, np.uint8)
        cv2.rectangle(frame, (10 + 5 * i, 200), (110 + 5 * i, 260), (200, 50, 50), -1)
        writer.write(frame)
    writer.release()
    return path


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("empty.avi", "cannot open video {p}: the file is empty (0 bytes)"),
        ("one.avi", "video {p} has a single frame (a still image?)"),
        ("photo.jpg", "video {p} has a single frame (a still image?)"),
        ("photo.avi", "video {p} has a single frame (a still image?)"),
    ],
)
def test_radar_names_an_empty_or_one_frame_video(
    name: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # before: "not a video file OpenCV can read" (empty), "no vehicle found in the video
    # (X, 1 frames)" (a still image, a one-frame video)
    p = tmp_path / name
    if name == "empty.avi":
        p.write_bytes(b"")
    elif name == "one.avi":
        _video(p, 1)
    else:  # a photo, under its own name or posing as a video
        p.write_bytes(_good_photo(tmp_path / "still.jpg", (640, 480)).read_bytes())
    scene = _scene_with_photo(tmp_path, None)
    assert main(["radar", str(p), "--scene", str(scene)]) == 2
    assert message.format(p=p) in one_line_error(capsys.readouterr().err, "radar")


def test_vp_names_the_photo_without_structure(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from PIL import Image

    photo = tmp_path / "blank.png"
    Image.new("RGB", (10, 10), (90, 90, 90)).save(photo)
    assert main(["vp", str(photo)]) == 2
    line = one_line_error(capsys.readouterr().err, "vp")
    assert line == f"camloc vp: error: {photo}: not enough structure: 0 straight line segments " + (
        "found (at least 6 needed)"
    )


def test_vp_refuses_a_photo_padded_far_beyond_its_pixels(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the file is read whole: a 640x480 JPEG followed by 100 MB (a sparse file here) used
    # to take 100 MB more memory, unbounded by the pixel limit
    photo = _good_photo(tmp_path / "padded.jpg", (640, 480))
    with open(photo, "r+b") as fh:
        fh.truncate(100_000_000)
    assert main(["vp", str(photo)]) == 2
    line = one_line_error(capsys.readouterr().err, "vp")
    assert f"image {photo} is 100 MB for 640x480 pixels, more than any encoding" in line
    assert "(66 MB): padded or corrupt" in line


# --------------------------------------------------------------------- annotate's photo
@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs POSIX FIFOs")
def test_annotate_never_opens_a_fifo(tmp_path: Path) -> None:
    import subprocess
    import sys

    # before: read_bytes() on the FIFO waited for a writer forever
    fifo = tmp_path / "snap.jpg"
    os.mkfifo(fifo)
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "camloc_geo.cli",
            "annotate",
            str(fifo),
            "-o",
            str(tmp_path / "a.html"),
        ],
        capture_output=True,
        text=True,
        timeout=120,  # a guard against the old hang, not a measurement
        env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])},
    )
    assert proc.returncode == 2
    assert one_line_error(proc.stderr, "annotate") == (
        f"camloc annotate: error: image {fifo} is not a regular file"
    )


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("cut.jpg", "{p} is a truncated or corrupt JPEG file"),
        ("cut.png", "{p} is a truncated or corrupt PNG file"),
        ("tiny.png", "{p} is 1x1 pixels: too small to annotate (at least 8 a side)"),
    ],
)
def test_annotate_refuses_a_cut_off_or_tiny_photo(
    name: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # before: the page was written, with a broken or 1-pixel picture to click on
    photo = _bad_photo(tmp_path, name)
    assert main(["annotate", str(photo), "-o", str(tmp_path / "a.html")]) == 2
    line = one_line_error(capsys.readouterr().err, "annotate")
    assert line == f"camloc annotate: error: {message.format(p=photo)}"
    assert not (tmp_path / "a.html").exists()


def test_annotate_and_service_give_the_size_the_browser_shows(tmp_path: Path) -> None:
    # stored 640x480 with EXIF orientation 6: browsers (and OpenCV) show it 480x640, so
    # the scene's image size must be 480x640 (before: 640x480, the photo then drawn
    # squeezed into the wrong frame and the clicks in another grid than calibrate's)
    from camloc_geo.web import read_image

    photo = _bad_photo(tmp_path, "turned.jpg")
    info = read_image(photo)
    assert (info.width, info.height) == (480, 640)
    pytest.importorskip("fastapi")
    from camloc_geo.service.routers.crowd import image_info

    assert image_info(photo.read_bytes(), 40_000_000) == ("jpg", 480, 640)


def test_a_decoder_failure_never_sinks_the_scene(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # any exception of the decoder (cv2.error, MemoryError...) leaves the photo out
    import camloc_geo._io as io_module
    from camloc_geo.scene import load_scene

    def broken(path: object) -> object:
        raise MemoryError("no room")

    photo = _good_photo(tmp_path / "p.jpg", (640, 480))
    monkeypatch.setattr(io_module, "read_image_gray", broken)
    scene = load_scene(_scene_with_photo(tmp_path, photo.name))
    assert scene.image_file() is None
    assert [w for w in scene.input_warnings if w.startswith("image.path")] == [
        f"image.path: cannot read image {photo}: MemoryError: no room; the photo is not used "
        "(no lines detected in it, no background for the overlay)"
    ]


def test_service_refuses_a_100_mp_header_without_pillows_warning(tmp_path: Path) -> None:
    import warnings

    pytest.importorskip("fastapi")
    from camloc_geo.service.errors import LimitError
    from camloc_geo.service.routers.crowd import image_info

    raw = png_header(tmp_path / "big.png", 10000, 10000).read_bytes()
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        with pytest.raises(LimitError, match="10000×10000; this server accepts at most"):
            image_info(raw, 40_000_000)
    assert [str(w.message) for w in seen] == []  # before: DecompressionBombWarning


def test_calibrate_decodes_the_scene_photo_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # before: the photo was decoded when the scene was read (to check it) and again by the
    # line detector
    from camloc_geo import _io

    photo = _good_photo(tmp_path / "once.jpg", (640, 480))
    calls: list[Path] = []
    real = _io._decode_image_gray

    def counting(p: Path):  # type: ignore[no-untyped-def]
        calls.append(p)
        return real(p)

    monkeypatch.setattr(_io, "_decode_image_gray", counting)
    _calibrate(_scene_with_photo(tmp_path, photo.name), capsys)
    assert [p.name for p in calls] == ["once.jpg"]


def test_the_decoded_photo_cache_follows_the_file(tmp_path: Path) -> None:
    import numpy as np

    from camloc_geo import _io

    photo = _good_photo(tmp_path / "cached.png", (320, 240))
    first = _io.read_image_gray(photo)
    assert _io.read_image_gray(photo) is first  # unchanged file: not decoded again
    assert not first.flags.writeable  # shared: a caller cannot change what others get
    from PIL import Image

    Image.new("L", (320, 240), 200).save(photo)  # rewritten in place
    os.utime(photo, ns=(1, 1))  # another modification time whatever the clock's resolution
    again = _io.read_image_gray(photo)
    assert again is not first
    assert np.all(again == 200)
    for i in range(_io.GRAY_CACHE_ENTRIES + 1):  # bounded: the oldest go
        _io.read_image_gray(_good_photo(tmp_path / f"other{i}.png", (320, 240)))
    assert len(_io._GRAY_CACHE) == _io.GRAY_CACHE_ENTRIES
    assert _io.read_image_gray(photo) is not again


def test_the_library_names_a_one_frame_video_for_every_front_end(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # before: a file stating no frame count (or a wrong one) decoded to one frame came back
    # as a result with no vehicle; only the CLI turned it into this message (the service,
    # the QGIS plugin and batch saw "no vehicle found")
    import cv2

    from camloc_geo._errors import InputError
    from camloc_geo.api import radar_scene

    video = _video(tmp_path / "one.avi", 1)
    real_capture = cv2.VideoCapture

    class NoCount:
        """OpenCV's capture, stating no frame count (as some containers do)."""

        def __init__(self, *args: object) -> None:
            self._cap = real_capture(*args)

        def get(self, prop: int) -> float:
            return 0.0 if prop == cv2.CAP_PROP_FRAME_COUNT else float(self._cap.get(prop))

        def __getattr__(self, name: str) -> object:
            return getattr(self._cap, name)

    monkeypatch.setattr(cv2, "VideoCapture", NoCount)
    with pytest.raises(InputError, match=r"has a single frame \(a still image\?\)"):
        radar_scene(_scene_with_photo(tmp_path, None), video)
