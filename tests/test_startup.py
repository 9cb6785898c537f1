"""Start-up: each command imports only what its path needs (issue 26, item 4).

Each case runs in a fresh interpreter and asserts on which modules are in ``sys.modules``
afterwards, never on time (the times live in ``benchmarks/startup.py``).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "sample_maps" / "sample_scene.json"
EXTRACT = ROOT / "sample_maps" / "baltimore.osm.pbf"

MAP_AND_PAGE = ("osmnx", "geopandas", "pandas", "folium", "matplotlib", "cv2")
"""Never on the ``calibrate`` or ``locate`` path (online maps, pages, images)."""

HEAVY = (
    "numpy",
    "scipy",
    "scipy.spatial.transform",
    "networkx",
    "pyproj",
    "shapely",
    "osmium",
    "pydantic",
    *MAP_AND_PAGE,
)


def _loaded(snippet: str, watch: tuple[str, ...]) -> dict[str, object]:
    """Run ``snippet`` in a fresh interpreter; which of ``watch`` it imported, and ``rc``."""
    code = (
        "import json, sys\n"
        "rc = None\n"
        f"{snippet}\n"
        f"print(json.dumps({{'rc': rc, 'loaded': [m for m in {watch!r} if m in sys.modules]}}))\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
        cwd=ROOT,
    )
    out: dict[str, object] = json.loads(proc.stdout.strip().splitlines()[-1])
    return out


def test_import_cli_loads_nothing_heavy() -> None:
    got = _loaded("import camloc_geo.cli", HEAVY)
    assert got["loaded"] == []


def test_help_loads_nothing_heavy() -> None:
    """``camloc --help`` as the console script runs it (``main`` exits through argparse)."""
    snippet = (
        "import contextlib, io\n"
        "from camloc_geo.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()) as buf:\n"
        "    try:\n"
        "        main(['--help'])\n"
        "    except SystemExit as exc:\n"
        "        rc = exc.code\n"
        "assert 'locate' in buf.getvalue() and 'calibrate' in buf.getvalue()\n"
    )
    got = _loaded(snippet, HEAVY)
    assert got == {"rc": 0, "loaded": []}


def test_calibrate_loads_no_map_code(tmp_path: Path) -> None:
    """``calibrate`` needs numpy and the scene model: no scipy, no map or page code."""
    out = tmp_path / "cal.json"
    snippet = (
        "from camloc_geo.cli import main\n"
        f"rc = main(['calibrate', {str(SCENE)!r}, '-o', {str(out)!r}])\n"
    )
    watch = ("networkx", "pyproj", "shapely", "osmium", "scipy", *MAP_AND_PAGE)
    got = _loaded(snippet, watch)
    assert got == {"rc": 0, "loaded": []}
    assert json.loads(out.read_text())["scene"]


@pytest.mark.skipif(not EXTRACT.exists(), reason="sample extract missing")
def test_locate_offline_loads_no_online_or_page_code(tmp_path: Path) -> None:
    """``locate --osm`` reads the extract with pyosmium: no osmnx, geopandas, pages, images."""
    out = tmp_path / "c.geojson"
    snippet = (
        "from camloc_geo.cli import main\n"
        f"rc = main(['locate', {str(SCENE)!r}, '--osm', {str(EXTRACT)!r}, "
        f"'-o', {str(out)!r}, '--offline'])\n"
    )
    other_commands = ("camloc_geo.cli.batch", "camloc_geo.cli.serve", "camloc_geo.cli.calibrate")
    # scipy.spatial and scipy.cluster cost over a second: the fit uses camera.py's rotations
    watch = ("scipy.optimize", "scipy.spatial", "scipy.cluster", *MAP_AND_PAGE, *other_commands)
    got = _loaded(snippet, watch)
    assert got == {"rc": 0, "loaded": []}
    assert json.loads(out.read_text())["features"]


def test_library_modules_import_scipy_on_use() -> None:
    """The scene model, the relative fit's module and the map code import no scipy at import."""
    got = _loaded(
        "import camloc_geo.relative, camloc_geo.geodesy, camloc_geo.osm, camloc_geo.api",
        ("scipy", "scipy.spatial.transform", "scipy.sparse", *MAP_AND_PAGE),
    )
    assert got["loaded"] == []


@pytest.mark.parametrize("argv", [["-h"], ["-v", "--help", "locate"], []])
def test_help_lists_every_command(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    """Only a named command is registered alone: help and no command list them all."""
    from camloc_geo.cli import main

    rc: object
    try:
        rc = main(argv)
    except SystemExit as exc:
        rc = exc.code
    out = capsys.readouterr()
    text = out.out + out.err
    assert rc == (2 if not argv else 0)
    for command in ("calibrate", "locate", "batch", "summary-map", "serve"):
        assert command in text


def test_a_typo_names_every_command(capsys: pytest.CaptureFixture[str]) -> None:
    from camloc_geo.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["locat", "scene.json"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "invalid choice: 'locat'" in err
    assert "summary-map" in err
    assert "calibrate" in err


def test_gc_policy_only_when_main_owns_the_process(tmp_path: Path) -> None:
    """A short command run as the program collects less often and skips the exit collection;
    ``batch``/``serve`` keep the default thresholds; a caller passing ``argv`` keeps its own."""
    out = tmp_path / "cal.json"
    code = (
        "import contextlib, gc, io, json, sys\n"
        "from camloc_geo.cli import main\n"
        "seen = {'default': gc.get_threshold()}\n"
        f"assert main(['calibrate', {str(SCENE)!r}, '-o', {str(out)!r}]) == 0\n"
        "seen['explicit'] = (gc.get_threshold(), gc.isenabled())\n"
        "sys.argv = ['camloc', 'batch', '--help']\n"
        "with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):\n"
        "    main()\n"
        "seen['batch'] = gc.get_threshold()\n"
        "gc.enable()\n"
        f"sys.argv = ['camloc', 'calibrate', {str(SCENE)!r}, '-o', {str(out)!r}]\n"
        "rc = main()\n"
        "seen['owned'] = (rc, gc.get_threshold(), gc.isenabled(), gc.get_freeze_count() > 0)\n"
        "print(json.dumps(seen))\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    seen = json.loads(proc.stdout.strip().splitlines()[-1])
    default = seen["default"]
    assert seen["explicit"] == [default, True]
    assert seen["batch"] == default
    assert seen["owned"] == [0, [10_000, 20, 100], False, True]
