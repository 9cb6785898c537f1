"""``camloc locate`` driven through the real command line (in process and as a subprocess)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camloc_geo.cli import main
from camloc_geo.geodesy import distance_m
from camloc_geo.osm import load_map
from camloc_geo.testing.synthetic import LocatedScene, NoiseModel, make_located_scene

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"
BALTIMORE = OSM / "baltimore.osm.pbf"


@pytest.fixture(scope="module")
def located() -> LocatedScene:
    m = load_map(BALTIMORE, 39.2851, -76.5934, radius_m=300)
    inter = next(i for i in m.intersections if i.kind == "junction" and len(i.corners) >= 3)
    ls = make_located_scene(
        m,
        inter,
        np.random.default_rng(1),
        noise=NoiseModel.exact(),
        corner_sigma_m=0.0,
        min_corners=2,
    )
    assert ls is not None
    return ls


def write(tmp_path: Path, scene: dict[str, Any], name: str = "scene.json") -> str:
    path = tmp_path / name
    path.write_text(json.dumps(scene))
    return str(path)


def one_line_error(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


def test_locate_geojson_on_stdout(
    tmp_path: Path, located: LocatedScene, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["locate", write(tmp_path, located.scene), "--osm", str(BALTIMORE), "--offline"])
    assert code == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["type"] == "FeatureCollection"
    cands = [f for f in doc["features"] if f["properties"]["kind"] == "candidate"]
    assert cands
    assert doc["properties"]["n_candidates"] == len(cands)
    assert sum(f["properties"]["score"] for f in cands) == pytest.approx(1.0)
    errs = [
        distance_m(
            lat1=f["geometry"]["coordinates"][1],
            lon1=f["geometry"]["coordinates"][0],
            lat2=located.lat,
            lon2=located.lon,
        )
        for f in cands
    ]
    assert min(errs) < 0.1
    assert any(f["properties"]["kind"] == "view_cone" for f in doc["features"])


def test_locate_writes_output_file(
    tmp_path: Path, located: LocatedScene, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out.geojson"
    code = main(["locate", write(tmp_path, located.scene), "--osm", str(BALTIMORE), "-o", str(out)])
    assert code == 0
    assert capsys.readouterr().out == ""
    doc = json.loads(out.read_text())
    assert doc["features"][0]["properties"]["rank"] == 1


def test_max_candidates(
    tmp_path: Path, located: LocatedScene, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["locate", write(tmp_path, located.scene), "--osm", str(BALTIMORE), "--max-candidates"]
    assert main([*args, "1"]) == 0
    doc = json.loads(capsys.readouterr().out)
    cands = [f for f in doc["features"] if f["properties"]["kind"] == "candidate"]
    assert len(cands) == 1
    assert cands[0]["properties"]["score"] == pytest.approx(1.0)
    assert main([*args, "0"]) == 2
    one_line_error(capsys.readouterr().err)


def test_unknown_streets_exit_2_naming_them(
    tmp_path: Path, located: LocatedScene, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = json.loads(json.dumps(located.scene))
    scene["intersection"] = {
        "corners": scene["intersection"]["corners"],
        "streets": ["Nowhere Lane", "Imaginary Street"],
    }
    code = main(["locate", write(tmp_path, scene), "--osm", str(BALTIMORE)])
    assert code == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    line = one_line_error(captured.err)
    assert line.startswith("camloc locate: error:")
    assert "Nowhere Lane" in line
    assert "Imaginary Street" in line


def test_offline_without_osm_when_a_map_is_needed(
    tmp_path: Path, located: LocatedScene, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["locate", write(tmp_path, located.scene), "--offline"])
    assert code == 2
    line = one_line_error(capsys.readouterr().err)
    assert "--osm" in line


def test_no_evidence_gives_empty_collection_with_reason(
    tmp_path: Path,
    located: LocatedScene,
    capsys: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture,
) -> None:
    scene = json.loads(json.dumps(located.scene))
    del scene["intersection"]
    code = main(["locate", write(tmp_path, scene), "--offline"])
    assert code == 0
    captured = capsys.readouterr()
    doc = json.loads(captured.out)
    assert doc["properties"]["n_candidates"] == 0
    assert "no geographic evidence" in doc["properties"]["reason"]
    assert "no candidates" in caplog.text


def test_no_location_at_all_exit_2(
    tmp_path: Path, located: LocatedScene, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = json.loads(json.dumps(located.scene))
    del scene["prior"]
    scene["intersection"] = {"corners": scene["intersection"]["corners"]}
    code = main(["locate", write(tmp_path, scene), "--offline"])
    assert code == 2
    one_line_error(capsys.readouterr().err)


def test_bad_scene_file_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    assert main(["locate", str(bad), "--offline"]) == 2
    one_line_error(capsys.readouterr().err)
    assert main(["locate", str(tmp_path / "missing.json"), "--offline"]) == 2
    one_line_error(capsys.readouterr().err)


def test_subprocess_end_to_end(tmp_path: Path, located: LocatedScene) -> None:
    """The installed entry point: a good run, then bad input without a traceback."""
    path = write(tmp_path, located.scene)
    cmd = [sys.executable, "-m", "camloc_geo.cli", "locate"]
    ok = subprocess.run(
        [*cmd, path, "--osm", str(BALTIMORE), "--offline"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert ok.returncode == 0, ok.stderr
    assert json.loads(ok.stdout)["properties"]["n_candidates"] >= 1
    bad = subprocess.run([*cmd, path, "--offline"], capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2
    assert bad.stdout == ""
    assert "--osm" in one_line_error(bad.stderr)
