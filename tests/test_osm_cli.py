"""``camloc corners`` and ``camloc streets`` driven through the real command line."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from camloc_geo.cli import main

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"
SAMPLES = Path(__file__).resolve().parents[1] / "sample_maps"


BALTIMORE = str(OSM / "baltimore.osm.pbf")
LAT, LON = "39.28558", "-76.59348"  # Eastern Avenue & South Broadway


def test_corners_geojson_stdout(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["corners", "--osm", BALTIMORE, "--lat", LAT, "--lon", LON, "--radius-m", "120"])
    assert code == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["type"] == "FeatureCollection"
    inters = [f for f in doc["features"] if f["properties"]["kind"] == "intersection"]
    corners = [f for f in doc["features"] if f["properties"]["kind"] == "corner"]
    assert len(inters) >= 3
    ids = {f["properties"]["id"] for f in inters}
    for f in corners:
        props = f["properties"]
        assert props["intersection"] in ids
        assert len(props["streets"]) == 2
        lon, lat = f["geometry"]["coordinates"]
        assert -77 < lon < -76
        assert 39 < lat < 40
    first = inters[0]["properties"]
    assert first["streets"] == ["Eastern Avenue", "South Broadway"]
    mine = [f["properties"] for f in corners if f["properties"]["intersection"] == first["id"]]
    assert [p["order"] for p in mine] == [0, 1, 2, 3]


def test_corners_by_street_names_to_file(tmp_path: Path) -> None:
    out = tmp_path / "x.geojson"
    code = main(
        [
            "corners",
            "--osm",
            BALTIMORE,
            "--lat",
            LAT,
            "--lon",
            LON,
            "--radius-m",
            "300",
            "--streets",
            "eastern ave & s bond st",
            "-o",
            str(out),
        ]
    )
    assert code == 0
    doc = json.loads(out.read_text())
    kinds = [f["properties"]["kind"] for f in doc["features"]]
    assert kinds == ["intersection", "corner", "corner", "corner", "corner"]
    inter = doc["features"][0]
    assert inter["properties"]["id"] == "n49478228"
    assert inter["geometry"]["coordinates"] == pytest.approx([-76.5953525, 39.2854942])


def test_streets_json(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["streets", "--osm", BALTIMORE, "--lat", LAT, "--lon", LON, "--radius-m", "100"])
    assert code == 0
    doc = json.loads(capsys.readouterr().out)
    near = {s["name"]: s["bearing_deg"] for s in doc["near"]}
    assert set(near) >= {"Eastern Avenue", "South Broadway"}
    assert all(0 <= b < 180 for b in near.values())
    assert "Eastern Avenue" in {s["name"] for s in doc["streets"]}


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--osm", "/nonexistent/x.osm.pbf", "--lat", "1", "--lon", "2"], "not found"),
        (["--osm", BALTIMORE, "--lat", "48.85", "--lon", "2.35"], "outside the extract"),
        (
            ["--osm", BALTIMORE, "--lat", LAT, "--lon", LON, "--streets", "Eastern Ave & Fleet St"],
            "do not meet",
        ),
        (["--no-network", "--lat", LAT, "--lon", LON], "--osm"),
        (["--offline", "--lat", LAT, "--lon", LON], "--osm"),
    ],
)
def test_bad_input_is_one_line_exit_2(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["corners", *args]) == 2
    err = capsys.readouterr().err
    assert message in err
    assert err.count("\n") == 1
    assert "Traceback" not in err


def test_subprocess_no_traceback(tmp_path: Path) -> None:
    empty = tmp_path / "empty.osm"
    empty.write_text("")
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "camloc_geo.cli",
            "streets",
            "--osm",
            str(empty),
            "--lat",
            "1",
            "--lon",
            "2",
        ],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 2
    assert "empty" in proc.stderr
    assert "Traceback" not in proc.stderr


@pytest.mark.skipif(not SAMPLES.is_dir(), reason="sample_maps not present")
def test_sample_maps_work_offline(capsys: pytest.CaptureFixture[str]) -> None:
    sample = SAMPLES / "baltimore.osm.pbf"
    assert sample.exists()
    assert (
        main(
            [
                "corners",
                "--osm",
                str(sample),
                "--lat",
                LAT,
                "--lon",
                LON,
                "--streets",
                "Eastern Avenue & South Broadway",
            ]
        )
        == 0
    )
    doc = json.loads(capsys.readouterr().out)
    assert len(doc["features"]) == 5
