"""Session 39 QA: ``--verdicts`` given a file that is not a verdicts export.

A camera list (``id,title,lat,lon,...``) given to ``camloc summary-map --verdicts`` was
"not a verdicts CSV: no column camera, verdict (columns: camera, rank, lat, lon, verdict,
...)": the columns listed were the export's, and read as the file's own, which then seemed
to hold the columns said to be missing.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camloc_geo import InputError, maps


def test_a_camera_list_as_verdicts_names_its_own_columns(tmp_path: Path) -> None:
    cams = tmp_path / "cams.csv"
    cams.write_text("id,title,lat,lon\nc1,Main St & 1st Ave,39.28,-76.59\n", encoding="utf-8")
    with pytest.raises(InputError) as info:
        maps.read_verdicts(cams)
    assert str(info.value) == (
        f"{cams}: not a verdicts CSV: no column camera, verdict (its columns: id, title, lat, "
        "lon; a page's export has camera, rank, lat, lon, verdict, note, reviewer, time, page, "
        "identity)"
    )


def test_a_verdicts_csv_without_verdicts_names_the_one_missing(tmp_path: Path) -> None:
    half = tmp_path / "half.csv"
    half.write_text("camera,rank,lat,lon\nc1,1,39.28,-76.59\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"no column verdict \(its columns: camera, rank, lat"):
        maps.read_verdicts(half)


def test_summary_map_draws_a_file_given_twice_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """``camloc summary-map cam-*.geojson cam-1.geojson`` drew cam-1 twice: two markers on
    one spot, both named "cam-1 (cam-1.geojson)"."""
    import json
    import re

    from camloc_geo.cli import main

    cam = {
        "type": "FeatureCollection",
        "properties": {"scene": "cam-1"},
        "features": [
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [-76.5934, 39.2851]},
                "properties": {
                    "kind": "candidate",
                    "rank": 1,
                    "score": 1.0,
                    "lat": 39.2851,
                    "lon": -76.5934,
                    "scene": "cam-1",
                },
            }
        ],
    }
    (tmp_path / "cam-1.geojson").write_text(json.dumps(cam), encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    args = ["summary-map", "cam-1.geojson", "./cam-1.geojson", "-o", "s.html", "--inline"]
    assert main(args) == 0
    page = (tmp_path / "s.html").read_text(encoding="utf-8")
    assert len(re.findall(r"L\.marker\(", page)) == 1
    assert "cam-1 (cam-1.geojson)" not in page
    assert "./cam-1.geojson is given twice (also as cam-1.geojson): shown once" in caplog.text


@pytest.mark.parametrize("value", ["0", "-5"])
def test_locate_max_candidates_below_one_names_the_option(
    value: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """``camloc locate --max-candidates -5`` said "max_candidates: max_candidates must be at
    least 1", after reading the map."""
    from camloc_geo.cli import main

    repo = Path(__file__).resolve().parents[1]
    scene = repo / "sample_maps" / "sample_scene.json"
    osm = repo / "sample_maps" / "baltimore.osm.pbf"
    assert main(["locate", str(scene), "--osm", str(osm), "--max-candidates", value]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"camloc locate: error: --max-candidates must be at least 1 (got {value})"]


def test_geocode_failing_writes_no_collection_to_stdout(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``camloc geocode TITLE --area nowhere`` exited 2 but printed a complete, empty
    ``{"type": "FeatureCollection", "features": []}``: a pipe's reader took it for "no
    match"."""
    from camloc_geo.cli import main

    osm = Path(__file__).resolve().parents[1] / "sample_maps" / "baltimore.osm.pbf"
    args = ["geocode", "Eastern Ave & S Broadway", "--osm", str(osm), "--area", "nowhere"]
    assert main(args) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "area 'nowhere' is not a named place of the map" in captured.err
    assert main(["geocode", "Eastern Ave & S Broadway", "--osm", str(osm)]) == 0
    import json

    (feature,) = json.loads(capsys.readouterr().out)["features"]
    assert feature["properties"]["status"] == "junction"
