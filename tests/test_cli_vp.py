"""``camloc vp``: JSON output, drawing, exit statuses."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

cv2 = pytest.importorskip("cv2")

from camloc_geo.cli import main  # noqa: E402


def _load_scene_helpers() -> object:
    """The synthetic-scene renderer of test_autovp.py, whatever the import mode."""
    spec = importlib.util.spec_from_file_location(
        "_camloc_autovp_scene", Path(__file__).with_name("test_autovp.py")
    )
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_scene = _load_scene_helpers()
cam_from_world = _scene.cam_from_world  # type: ignore[attr-defined]
render_scene = _scene.render_scene  # type: ignore[attr-defined]


@pytest.fixture(scope="module")
def scene_png(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("vp") / "scene.png"
    cv2.imwrite(str(path), render_scene(cam_from_world(25.0, 8.0, -3.0), 650.0, seed=2))
    return path


def test_vp_prints_json(scene_png: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vp", str(scene_png)]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in (
        "vanishing_points",
        "focal_px",
        "principal_point",
        "horizon",
        "pitch_deg",
        "roll_deg",
        "confidence",
        "n_segments",
    ):
        assert key in out
    assert len(out["vanishing_points"]) == 3
    assert out["focal_px"] == pytest.approx(650.0, rel=0.05)
    assert out["pitch_deg"] == pytest.approx(8.0, abs=0.7)
    assert out["roll_deg"] == pytest.approx(-3.0, abs=0.7)
    assert out["principal_point"] == [400.0, 300.0]
    assert 0.0 <= out["confidence"] <= 1.0


def test_vp_focal_and_draw(
    scene_png: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    drawing = tmp_path / "segs.png"
    assert main(["vp", str(scene_png), "--focal-px", "650", "--draw", str(drawing)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["focal_px"] == 650.0
    assert out["focal_source"] == "given"
    img = cv2.imread(str(drawing))
    assert img is not None
    assert img.shape == (600, 800, 3)
    assert (img[:, :, 2] > 200).sum() > 100  # red (vertical) segments drawn


@pytest.mark.parametrize("kind", ["blank", "garbage", "missing"])
def test_vp_bad_input_exit_2(kind: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "in.png"
    if kind == "blank":
        cv2.imwrite(str(path), np.full((480, 640), 200, np.uint8))
    elif kind == "garbage":
        path.write_bytes(b"\x00not a png")
    assert main(["vp", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    err = captured.err.strip()
    assert err.startswith("camloc vp: error:")
    assert "\n" not in err
    assert "Traceback" not in err
    if kind == "blank":
        assert "not enough structure" in err


def test_vp_negative_focal_exit_2(scene_png: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vp", str(scene_png), "--focal-px", "-5"]) == 2
    assert "focal" in capsys.readouterr().err


def test_vp_subprocess(scene_png: Path, tmp_path: Path) -> None:
    blank = tmp_path / "blank.png"
    cv2.imwrite(str(blank), np.zeros((100, 100), np.uint8))
    root = Path(__file__).resolve().parents[1]
    ok = subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", "vp", str(scene_png)],
        capture_output=True,
        text=True,
        cwd=root,
        check=False,
    )
    assert ok.returncode == 0, ok.stderr
    assert json.loads(ok.stdout)["n_segments"] > 10
    bad = subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", "vp", str(blank)],
        capture_output=True,
        text=True,
        cwd=root,
        check=False,
    )
    assert bad.returncode == 2
    assert "not enough structure" in bad.stderr


def test_vp_ignore_boxes(scene_png: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vp", str(scene_png)]) == 0
    n_all = json.loads(capsys.readouterr().out)["n_segments"]
    args = [
        "vp",
        str(scene_png),
        "--ignore",
        "0",
        "0",
        "400",
        "600",
        "--ignore",
        "400",
        "0",
        "500",
        "100",
    ]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out)
    assert 0 < out["n_segments"] < n_all


def test_vp_axis_hint_option(scene_png: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vp", str(scene_png), "--axis", "400", "500", "450", "490"]) == 0
    assert json.loads(capsys.readouterr().out)["confidence"] > 0.5
    assert main(["vp", str(scene_png), "--axis", "400", "500", "400", "500"]) == 2
    assert "axes_hint[0]" in capsys.readouterr().err


def test_vp_exif_prior_named_and_no_exif(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A photo with FocalLengthIn35mmFilm: the prior is used and named; --no-exif drops it."""
    image_mod = pytest.importorskip("PIL.Image")
    img = render_scene(cam_from_world(25.0, 8.0, -3.0), 650.0, seed=2)
    path = tmp_path / "exif.jpg"
    exif = image_mod.Exif()
    # 35 mm equivalent of 650 px on an 800 x 600 photo (diagonal 1000 px)
    exif.get_ifd(0x8769)[0xA405] = round(650.0 * 43.2666 / 1000.0)
    image_mod.fromarray(img).save(path, exif=exif, quality=95)
    assert main(["vp", str(path)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["focal_source"] == "exif-35mm"
    assert out["focal_px"] == pytest.approx(650.0, rel=0.05)
    assert isinstance(out["warnings"], list)
    assert out["street_vanishing_point"] in (1, 2)
    assert out["vanishing_point_names"][0] == "vertical"
    assert sorted(out["vanishing_point_names"][1:]) == ["across the street", "street"]
    assert main(["vp", str(path), "--no-exif"]) == 0
    out2 = json.loads(capsys.readouterr().out)
    assert out2["focal_source"] == "estimated"


def test_vp_axis_changes_the_answer(scene_png: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vp", str(scene_png)]) == 0
    plain = json.loads(capsys.readouterr().out)
    vp = plain["vanishing_points"][1]
    assert vp is not None
    # an axis drawn 1.5 degrees off the direction of a vanishing point pulls the fit
    o = np.array([400.0, 450.0])
    d = np.array(vp) - o
    c, s = np.cos(np.radians(1.5)), np.sin(np.radians(1.5))
    e = o + 0.3 * np.array([c * d[0] - s * d[1], s * d[0] + c * d[1]])
    assert main(["vp", str(scene_png), "--axis", *map(str, [*o, *e])]) == 0
    hinted = json.loads(capsys.readouterr().out)
    assert hinted["n_segments"] == plain["n_segments"] + 1
    assert hinted["vanishing_points_homogeneous"] != plain["vanishing_points_homogeneous"]


def test_vp_draw_has_a_legend(scene_png: Path, tmp_path: Path) -> None:
    drawing = tmp_path / "legend.png"
    assert main(["vp", str(scene_png), "--draw", str(drawing)]) == 0
    img = cv2.imread(str(drawing))
    box = img[6:60, 6:120]
    assert (box.max(axis=2) < 20).mean() > 0.5  # a black legend box
    assert (box.min(axis=2) > 230).sum() > 20  # white text in it


def test_vp_distortion_options(scene_png: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vp", str(scene_png)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["distortion"]["model"] == "division"
    assert out["distortion"]["k1_std"] is not None  # estimated by default
    assert abs(out["distortion"]["k1"]) <= 2.5 * out["distortion"]["k1_std"] + 1e-9
    assert main(["vp", str(scene_png), "--distortion", "0"]) == 0
    off = json.loads(capsys.readouterr().out)
    assert off["distortion"]["k1"] == 0.0
    assert off["distortion"]["k1_std"] is None
    assert main(["vp", str(scene_png), "--distortion", "-0.05"]) == 0
    given = json.loads(capsys.readouterr().out)
    assert given["distortion"]["k1"] == -0.05
    assert given["focal_px"] != off["focal_px"]
    assert main(["vp", str(scene_png), "--distortion", "3"]) == 2
    assert "distortion" in capsys.readouterr().err


def test_vp_reports_tilt_sigmas(scene_png: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vp", str(scene_png)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert 0.0 < out["pitch_std_deg"] < 2.0
    assert 0.0 < out["roll_std_deg"] < 2.0
    # the truth (pitch 8, roll -3) within 3 sigma (rendered lines: a tiny sigma is fine)
    assert abs(out["pitch_deg"] - 8.0) <= 3 * out["pitch_std_deg"] + 0.2
    assert abs(out["roll_deg"] + 3.0) <= 3 * out["roll_std_deg"] + 0.2


def test_a_direction_no_line_supports_is_named_implied(tmp_path: Path) -> None:
    """A vanishing point with no inlier is implied by the other two and the focal length: the
    JSON says so (``vanishing_point_implied``) and ``--draw``'s legend says "no lines,
    implied" in a box wide enough for it (stop 42: the legend named such a point as if seen)."""
    import sys

    sys.path.insert(0, str(Path(__file__).parent))
    from test_autovp_failure_modes import corner_segments

    from camloc_geo.autovp import detect_vanishing_points, draw_segments

    segs, (w, h) = corner_segments(0, 0.0, seed=0)
    grey = np.full((h, w), 128, np.uint8)
    full = detect_vanishing_points(grey, segments=segs, focal_px=700.0)
    keep = np.asarray(full.labels) != 2  # leave one horizontal family out
    res = detect_vanishing_points(grey, segments=np.asarray(segs)[keep], focal_px=700.0)
    implied = res.to_json()["vanishing_point_implied"]
    assert implied == [n == 0 for n in res.n_inliers]
    assert implied.count(True) == 1
    assert implied[0] is False
    assert full.to_json()["vanishing_point_implied"] == [False, False, False]
    drawing = tmp_path / "implied.png"
    draw_segments(grey, res, drawing)
    img = cv2.imread(str(drawing))
    top = img[5, 4:].max(axis=1) < 20  # the legend box's top row, black from x = 4
    width = int(np.argmin(top)) if not top.all() else top.size
    # wider than the old fixed box (384 px at this size: 250 px at font scale 0.5) to hold
    # the longer text (388 px of text after the 34 px colour line)
    assert width > 430
    assert (img[5:, :4].max(axis=2) >= 20).any()  # the photo, not the box, left of it
