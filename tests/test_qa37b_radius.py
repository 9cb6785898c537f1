"""A map radius has a documented upper bound, named when refused (QA sweep 37b).

``camloc locate SCENE --osm baltimore.osm.pbf --radius-m 30000000`` loaded the extract and said
it "holds buildings but no streets".
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from annotate_synthetic import located_case, render_snapshot

from camloc_geo._errors import MapDataError
from camloc_geo.api import MAX_MAP_RADIUS_M, corners_near, scene_map_radius_m, streets_near
from camloc_geo.cli import main
from camloc_geo.scene import parse_scene

REPO = Path(__file__).resolve().parents[1]
BALTIMORE = str(REPO / "sample_maps" / "baltimore.osm.pbf")


def error_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


def test_bound_value() -> None:
    assert MAX_MAP_RADIUS_M == 50_000.0


@pytest.mark.parametrize("command", ["locate", "corners", "streets"])
def test_cli_refuses_a_radius_over_the_bound(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    if command == "locate":
        scene = tmp_path / "scene.json"
        scene.write_text(json.dumps(located_case().scene))
        args = ["locate", str(scene)]
    else:
        args = [command, "--lat", "39.2851", "--lon", "-76.5934"]
    code = main([*args, "--osm", BALTIMORE, "--offline", "--radius-m", "30000000"])
    assert code == 2
    line = error_line(capsys)
    assert "--radius-m 3e+07 m is over the largest map radius, 50000 m (50 km)" in line
    assert "no streets" not in line


def test_library_refuses_a_radius_over_the_bound() -> None:
    with pytest.raises(MapDataError, match=r"radius_m 60000 m is over .* 50000 m"):
        corners_near(lat=39.2851, lon=-76.5934, radius_m=60_000, map_source=BALTIMORE)
    with pytest.raises(MapDataError, match="largest map radius"):
        streets_near(lat=39.2851, lon=-76.5934, radius_m=1e9, map_source=BALTIMORE)
    scene = parse_scene(located_case().scene)
    with pytest.raises(MapDataError, match="largest map radius"):
        scene_map_radius_m(scene, 50_001.0)
    assert scene_map_radius_m(scene, 50_000.0) == 50_000.0


def test_annotate_refuses_a_radius_over_the_bound(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    snap = tmp_path / "cam.jpg"
    snap.write_bytes(render_snapshot(located_case()))
    out = tmp_path / "page.html"
    args = ["annotate", str(snap), "-o", str(out), "--osm", BALTIMORE]
    code = main([*args, "--lat", "39.2851", "--lon", "-76.5934", "--radius-m", "30000000"])
    assert code == 2
    assert "--radius-m 3e+07 m is over the largest map radius, 50000 m" in error_line(capsys)
    assert not out.exists()
