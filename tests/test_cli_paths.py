"""Output paths behave the same in every command: missing directory, atomic writes, inputs kept.

Also: every command reads its inputs with the same one-line error style, ``summary-map``
skips features it cannot draw, and building the parser imports nothing heavy.
"""

from __future__ import annotations

import json
import math
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from camloc_geo import InputError
from camloc_geo._io import atomic_path, check_output_path, read_json_file, write_text_atomic
from camloc_geo.cli import main, write_json

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "sample_maps" / "sample_scene.json"
BALTIMORE = ROOT / "data" / "osm" / "baltimore.osm.pbf"
LAT, LON = "39.28558", "-76.59348"
IMAGE = ROOT / "tests" / "data" / "scenes"


def one_line_error(err: str, command: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert lines[0].startswith(f"camloc {command}: error: "), lines[0]
    return lines[0]


def listing(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


# --------------------------------------------------------------------- missing directories
def _commands(missing: Path) -> list[tuple[str, list[str], str]]:
    out = str(missing / "x.json")
    return [
        ("calibrate", ["calibrate", str(SCENE), "-o", out], "-o"),
        ("schema", ["schema", "-o", out], "-o"),
        ("locate", ["locate", str(SCENE), "--osm", str(BALTIMORE), "-o", out], "-o"),
        (
            "locate",
            ["locate", str(SCENE), "--osm", str(BALTIMORE), "--map", str(missing / "m.html")],
            "--map",
        ),
        (
            "corners",
            ["corners", "--osm", str(BALTIMORE), "--lat", LAT, "--lon", LON, "-o", out],
            "-o",
        ),
        (
            "streets",
            ["streets", "--osm", str(BALTIMORE), "--lat", LAT, "--lon", LON, "-o", out],
            "-o",
        ),
        ("vp", ["vp", str(SCENE), "-o", out], "-o"),
        ("vp", ["vp", str(SCENE), "--draw", str(missing / "d.png")], "--draw"),
        ("summary-map", ["summary-map", str(SCENE), "-o", str(missing / "s.html")], "-o"),
    ]


@pytest.mark.parametrize("index", range(9))
def test_missing_directory_is_exit_2_and_never_created(
    index: int, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    missing = tmp_path / "no" / "such"
    command, argv, option = _commands(missing)[index]
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    line = one_line_error(captured.err, command)
    assert option in line
    assert "does not exist" in line
    assert not (tmp_path / "no").exists()


def test_missing_overlays_directory(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["locate", str(SCENE), "--osm", str(BALTIMORE), "--map", str(tmp_path / "m.html")]
    assert main([*argv, "--overlays", str(tmp_path / "none")]) == 2
    line = one_line_error(capsys.readouterr().err, "locate")
    assert "--overlays" in line
    assert "does not exist" in line
    assert listing(tmp_path) == []
    assert main(["locate", str(SCENE), "--overlays", str(tmp_path)]) == 2
    assert "needs --map" in one_line_error(capsys.readouterr().err, "locate")


def test_directory_given_as_output_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["schema", "-o", str(tmp_path)]) == 2
    assert "is a directory" in one_line_error(capsys.readouterr().err, "schema")


# --------------------------------------------------------------------------- inputs kept
def test_calibrate_never_overwrites_its_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "s.json"
    shutil.copy(SCENE, scene)
    before = scene.read_bytes()
    assert main(["calibrate", str(scene), "-o", str(scene)]) == 2
    line = one_line_error(capsys.readouterr().err, "calibrate")
    assert "overwrite the input" in line
    assert scene.read_bytes() == before
    # the same file under another spelling is caught too
    assert main(["calibrate", str(scene), "-o", str(tmp_path / "." / "s.json")]) == 2
    capsys.readouterr()
    assert scene.read_bytes() == before


def test_locate_never_overwrites_the_extract(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    extract = tmp_path / "b.osm.pbf"
    shutil.copy(BALTIMORE, extract)
    size = extract.stat().st_size
    argv = ["locate", str(SCENE), "--osm", str(extract)]
    assert main([*argv, "--map", str(extract)]) == 2
    assert "overwrite the input" in one_line_error(capsys.readouterr().err, "locate")
    assert extract.stat().st_size == size


def test_summary_map_never_overwrites_an_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gj = tmp_path / "a.geojson"
    gj.write_text(json.dumps(_collection([_candidate(39.28, -76.59)])))
    assert main(["summary-map", str(gj), "-o", str(gj)]) == 2
    assert "overwrite the input" in one_line_error(capsys.readouterr().err, "summary-map")
    assert json.loads(gj.read_text())["type"] == "FeatureCollection"


# ------------------------------------------------------------------------- atomic writes
def test_atomic_path_failure_leaves_old_file_and_no_temporary(tmp_path: Path) -> None:
    target = tmp_path / "out.json"
    target.write_text("old")

    def half_write() -> None:
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("disk full halfway")

    with pytest.raises(RuntimeError):
        half_write()
    assert target.read_text() == "old"
    assert listing(tmp_path) == ["out.json"]


def test_atomic_path_success_replaces_and_cleans_up(tmp_path: Path) -> None:
    target = tmp_path / "out.png"
    with atomic_path(target) as tmp:
        assert tmp.parent == tmp_path
        assert tmp.suffix == ".png"  # writers that pick the format from the name still work
        tmp.write_bytes(b"\x89PNG")
    assert target.read_bytes() == b"\x89PNG"
    assert listing(tmp_path) == ["out.png"]


def test_atomic_path_nothing_written_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(OSError, match="nothing was written"), atomic_path(tmp_path / "x"):
        pass
    assert listing(tmp_path) == []


def test_write_json_that_cannot_be_serialised_keeps_the_old_file(tmp_path: Path) -> None:
    target = tmp_path / "out.json"
    target.write_text('{"old": true}\n')
    with pytest.raises(ValueError, match="JSON compliant"):
        write_json({"x": math.nan}, str(target))
    assert target.read_text() == '{"old": true}\n'
    assert listing(tmp_path) == ["out.json"]


def test_write_text_atomic_keeps_permissions_sane(tmp_path: Path) -> None:
    out = write_text_atomic(tmp_path / "a.txt", "hello")
    assert out.read_text() == "hello"
    assert out.stat().st_mode & 0o644 == 0o644


def test_commands_leave_only_their_outputs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["calibrate", str(SCENE), "-o", str(tmp_path / "cal.json")]) == 0
    assert main(["schema", "-o", str(tmp_path / "schema.json")]) == 0
    argv = ["corners", "--osm", str(BALTIMORE), "--lat", LAT, "--lon", LON]
    assert main([*argv, "-o", str(tmp_path / "c.geojson")]) == 0
    assert capsys.readouterr().out == ""
    assert listing(tmp_path) == ["c.geojson", "cal.json", "schema.json"]
    assert json.loads((tmp_path / "cal.json").read_text())["scene"]
    assert json.loads((tmp_path / "c.geojson").read_text())["type"] == "FeatureCollection"


def test_check_output_path_stdout_and_relative(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    assert check_output_path("here.json") == Path("here.json")
    with pytest.raises(InputError, match="directory"):
        check_output_path("nope/here.json")


# ------------------------------------------------------------------- inputs, same style
@pytest.mark.parametrize(
    ("content", "message"),
    [
        (None, "no such file"),
        ("{oops", "line 1 column 2"),
        (b"\xff\xfe\x00", "not UTF-8"),
    ],
)
def test_read_json_file_errors(tmp_path: Path, content: Any, message: str) -> None:
    path = tmp_path / "in.json"
    if isinstance(content, str):
        path.write_text(content)
    elif isinstance(content, bytes):
        path.write_bytes(content)
    with pytest.raises(InputError, match=message) as info:
        read_json_file(path)
    assert str(path) in str(info.value)


@pytest.mark.parametrize("command", ["calibrate", "locate", "summary-map"])
def test_unreadable_inputs_are_one_line(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    extra = ["-o", str(tmp_path / "o.html")] if command == "summary-map" else []
    assert main([command, str(bad), *extra]) == 2
    assert "line 1" in one_line_error(capsys.readouterr().err, command)
    assert main([command, str(tmp_path / "missing.json"), *extra]) == 2
    line = one_line_error(capsys.readouterr().err, command)
    assert "missing.json" in line
    assert "not found" in line or "no such file" in line


def test_vp_draw_needs_an_image_name(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vp", str(SCENE), "--draw", str(tmp_path / "d.txt")]) == 2
    assert ".png" in one_line_error(capsys.readouterr().err, "vp")


# -------------------------------------------------------------------------- summary-map
def _candidate(lat: Any, lon: Any, rank: int = 1) -> dict[str, Any]:
    return {
        "type": "Feature",
        "geometry": {"type": "Point", "coordinates": [lon, lat]},
        "properties": {
            "kind": "candidate",
            "rank": rank,
            "lat": lat,
            "lon": lon,
            "score": 1.0,
            "method": "test",
            "heading_deg": 90.0,
        },
    }


def _collection(features: list[Any], scene: str = "cam") -> dict[str, Any]:
    return {"type": "FeatureCollection", "properties": {"scene": scene}, "features": features}


def test_summary_map_skips_undrawable_features(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    good = tmp_path / "good.geojson"
    good.write_text(json.dumps(_collection([_candidate(39.2851, -76.5934)], "good")))
    bad = tmp_path / "bad.geojson"
    bad.write_text(
        json.dumps(
            _collection(
                [
                    {"type": "Feature", "geometry": None},  # no properties at all
                    {"type": "Feature", "geometry": None, "properties": None},
                    _candidate(999, -76.59),
                    _candidate(39.28, 1e400, rank=2),  # JSON Infinity
                ],
                "bad",
            )
        ).replace("1e+400", "Infinity")
    )
    out = tmp_path / "s.html"
    assert main(["summary-map", str(good), str(bad), "-o", str(out), "--inline"]) == 0
    page = out.read_text()
    assert re.search(r"\[\s*999(\.0)?\s*,", page) is None  # no marker at lat 999
    assert len(re.findall(r"L\.marker\(", page)) == 1  # only the good camera
    assert "1 without candidates" in page  # the bad camera, listed, not drawn
    assert caplog.text.count("skipped") == 4
    assert "lat=999" in caplog.text
    assert listing(tmp_path) == ["bad.geojson", "good.geojson", "s.html"]


def test_summary_map_nothing_usable_is_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.geojson"
    bad.write_text(json.dumps(_collection([_candidate(999, 999), _candidate(None, 3)])))
    assert main(["summary-map", str(bad), "-o", str(tmp_path / "s.html")]) == 2
    assert "no usable camera" in one_line_error(capsys.readouterr().err, "summary-map")
    assert listing(tmp_path) == ["bad.geojson"]


def test_summary_map_rejects_other_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "list.geojson"
    bad.write_text("[1, 2]")
    assert main(["summary-map", str(bad), "-o", str(tmp_path / "s.html")]) == 2
    assert "FeatureCollection" in one_line_error(capsys.readouterr().err, "summary-map")
    bad.write_text(json.dumps({"type": "FeatureCollection", "features": {"a": 1}}))
    assert main(["summary-map", str(bad), "-o", str(tmp_path / "s.html")]) == 2
    assert "features" in one_line_error(capsys.readouterr().err, "summary-map")


# --------------------------------------------------------------------------- start-up
def test_parser_imports_nothing_heavy() -> None:
    """``camloc --help`` builds every command's parser without numpy, scipy or osmnx."""
    code = (
        "import sys\n"
        "from camloc_geo.cli import _build_parser\n"
        "_build_parser().format_help()\n"
        "heavy = [m for m in ('numpy', 'scipy', 'osmnx', 'geopandas', 'pandas', 'cv2', "
        "'folium', 'shapely', 'pyproj', 'networkx', 'pydantic') if m in sys.modules]\n"
        "print(','.join(heavy))\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True
    )
    assert proc.stdout.strip() == ""


def test_calibrate_imports_no_map_code() -> None:
    """``calibrate`` needs no map: osmnx, geopandas and folium stay unimported."""
    code = (
        "import sys\n"
        "from camloc_geo.cli import main\n"
        f"rc = main(['calibrate', {str(SCENE)!r}])\n"
        "print('RC', rc, *(m in sys.modules for m in ('osmnx', 'geopandas', 'folium')))\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    assert proc.stdout.splitlines()[-1] == "RC 0 False False False"


def test_summary_map_with_extract_draws_its_streets(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from camloc_geo.api import map_around

    gj = tmp_path / "a.geojson"
    gj.write_text(json.dumps(_collection([_candidate(39.2856, -76.5935)])))
    plain, with_map = tmp_path / "plain.html", tmp_path / "map.html"
    assert main(["summary-map", str(gj), "-o", str(plain), "--inline"]) == 0
    argv = ["summary-map", str(gj), "-o", str(with_map), "--inline", "--osm", str(BALTIMORE)]
    assert main(argv) == 0
    assert "Eastern" not in plain.read_text()
    assert "Eastern" in with_map.read_text()  # street names of the extract in the page
    m = map_around([(39.2856, -76.5935), (39.2900, -76.5935)], map_source=BALTIMORE)
    assert m is not None
    assert m.radius_m == pytest.approx(245 + 150, abs=5)  # half of 490 m, plus the margin
    assert map_around([], map_source=BALTIMORE) is None


def test_two_outputs_of_one_command_are_distinct(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``locate -o x --map x`` wrote the GeoJSON and then the page over it (exit 0, no
    GeoJSON left); ``vp -o x.png --draw x.png`` likewise. Both are refused before any work."""
    out = tmp_path / "same.html"
    args = ["locate", str(SCENE), "--osm", str(BALTIMORE), "-o", str(out), "--map", str(out)]
    assert main([*args, "--offline"]) == 2
    err = capsys.readouterr().err
    assert f"--map {out}: the same file as -o" in err
    assert not out.exists()
    png = tmp_path / "x.png"
    assert main(["vp", str(SCENE), "-o", str(png), "--draw", str(png)]) == 2  # checked first
    assert "the same file as -o" in capsys.readouterr().err
    assert not png.exists()


def test_an_unknown_option_gets_the_command_s_own_usage(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # before: the top-level usage ("camloc [-h] [--version] ... COMMAND ...") for a typo in
    # one command's options, which says nothing of what that command takes
    from camloc_geo.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["calibrate", "--frobnicate", "scene.json"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("usage: camloc calibrate ")
    assert "camloc calibrate: error: unrecognized arguments: --frobnicate" in err


def test_summary_map_names_apart_two_outputs_of_one_scene(tmp_path: Path) -> None:
    """Two locate outputs of one scene id (a rerun, an edited scene) were two markers, two
    tooltips and two popups saying 'cam' (Chromium): a reviewer could not tell which file
    each was. A shared id is now followed by the file's name; a unique id is left alone."""
    run1 = tmp_path / "run1.geojson"
    run1.write_text(json.dumps(_collection([_candidate(39.2851, -76.5934)], "cam")))
    run2 = tmp_path / "run2.geojson"
    run2.write_text(json.dumps(_collection([_candidate(39.2855, -76.5931)], "cam")))
    other = tmp_path / "other.geojson"
    other.write_text(json.dumps(_collection([_candidate(39.2858, -76.5938)], "cam-7")))
    out = tmp_path / "s.html"
    assert main(["summary-map", str(run1), str(run2), str(other), "-o", str(out), "--inline"]) == 0
    page = out.read_text(encoding="utf-8")
    assert "cam (run1.geojson)" in page
    assert "cam (run2.geojson)" in page
    assert "cam-7 (other.geojson)" not in page
