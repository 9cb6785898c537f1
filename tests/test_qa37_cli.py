"""Session 37 QA: faults found driving the ``camloc`` command line as a user."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
BALTIMORE = REPO / "sample_maps" / "baltimore.osm.pbf"


def _camloc(args: list[str | bytes], cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(REPO), "LC_ALL": "C.UTF-8"}
    cmd: list[str | bytes] = [sys.executable, "-m", "camloc_geo.cli", *args]
    return subprocess.run(
        cmd, capture_output=True, text=True, errors="replace", timeout=600, cwd=cwd, env=env
    )


def test_geocode_title_not_utf8_to_file(tmp_path: Path) -> None:
    """A title typed in a Windows-1252 terminal (``\\xe9`` for é) was read into a lone
    surrogate: ``-o`` then failed with ``UnicodeEncodeError`` (exit 1) after the work. It is
    read as Windows-1252 with a warning, and the file is valid UTF-8 JSON."""
    out = tmp_path / "g.geojson"
    title = b"Eastern Ave \xe9& S Broadway"
    proc = _camloc(["geocode", "--osm", str(BALTIMORE), title, "-o", str(out)], tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "title 1 is not UTF-8 text: read as Windows-1252" in proc.stderr
    features = json.loads(out.read_text(encoding="utf-8"))["features"]
    assert features[0]["properties"]["title"] == "Eastern Ave \u00e9& S Broadway"
    assert features[0]["properties"]["status"] == "junction"


def test_job_camera_names_its_bad_row(tmp_path: Path) -> None:
    """An HTTP job camera whose lat is not a number was ``not_found`` with only the title's
    reason: the row's problem (which ``camloc batch`` keeps in its ``errors`` layer) was lost,
    a job's result having no such layer. It is now in the reason."""
    from camloc_geo.service.mapstore import MapStore
    from camloc_geo.service.settings import Settings
    from camloc_geo.service.work import process_camera

    folder = tmp_path / "maps"
    folder.mkdir()
    (folder / BALTIMORE.name).symlink_to(BALTIMORE)
    settings = Settings(map_dir=folder, network=False, data_dir=tmp_path / "data")
    maps = MapStore(settings)
    bad = process_camera({"id": "a", "title": "Nonsense title", "lat": "x"}, maps, settings)
    assert bad["status"] == "not_found"
    assert "list row: lat 'x' is not a number" in bad["reason"]
    placed = process_camera(
        {"id": "b", "title": "Eastern Ave & S Broadway", "lat": 39.2851, "lon": "x"},
        maps,
        settings,
    )
    assert placed["status"] == "title_only"
    # said once (the engine already notes a placed camera's problems)
    assert placed["reason"].count("lon 'x' is not a number") == 1
    none = process_camera({"id": "c", "lat": "x"}, maps, settings)
    assert none["status"] == "no_evidence"
    assert none["reason"].count("lat 'x' is not a number") == 1


def test_batch_refuses_an_unusable_extract_before_work(tmp_path: Path) -> None:
    """``camloc batch --osm`` naming an empty extract or a file of another kind ran the whole
    list (every camera ``map_error``/``no_map``, the warning once per camera) and exited 0;
    ``locate`` and ``geocode`` refuse it. It is refused before any work (exit 2), no
    GeoPackage or journal written."""
    lst = tmp_path / "cams.csv"
    lst.write_text("id,title,lat,lon\nc1,Eastern Ave & S Broadway,39.2851,-76.5930\n")
    (tmp_path / "empty.osm.pbf").write_bytes(b"")
    (tmp_path / "cams.json").write_text("{}")
    for extract, says in [
        ("empty.osm.pbf", "OSM extract is empty"),
        ("cams.json", "unsupported OSM extract 'cams.json'"),
    ]:
        proc = _camloc(
            ["batch", str(lst), "-o", "out.gpkg", "--osm", extract, "--no-progress"], tmp_path
        )
        assert proc.returncode == 2, proc.stderr
        assert says in proc.stderr
        assert "Traceback" not in proc.stderr
        assert not (tmp_path / "out.gpkg").exists()
        assert not (tmp_path / "out.camloc-batch.sqlite").exists()


def test_batch_list_that_is_a_folder(tmp_path: Path) -> None:
    """``camloc batch FOLDER`` said "camera list not found" of a folder that exists."""
    proc = _camloc(["batch", str(tmp_path), "-o", "out.gpkg", "--no-progress"], tmp_path)
    assert proc.returncode == 2
    assert f"camera list {tmp_path} is a folder" in proc.stderr


def test_batch_refuses_a_list_without_a_placing_column(tmp_path: Path) -> None:
    """A file of titles without a header row (its first title taken as the header) or a
    table of other columns ran: every camera ``no_evidence``, exit 0. It is refused, naming
    the header row; a list with a street pair but no title still runs."""
    titles = tmp_path / "titles.txt"
    titles.write_text("Eastern Ave & S Broadway\nFleet St & S Broadway\n", encoding="utf-8")
    other = tmp_path / "other.csv"
    other.write_text("foo,lat,lon\n1,39.2851,-76.593\n", encoding="utf-8")
    for lst, header in [(titles, "'Eastern Ave & S Broadway'"), (other, "'foo,lat,lon'")]:
        proc = _camloc(
            ["batch", str(lst), "-o", "out.gpkg", "--osm", str(BALTIMORE), "--no-progress"],
            tmp_path,
        )
        assert proc.returncode == 2, proc.stderr
        assert "has no column a camera can be placed by" in proc.stderr
        assert f"its header row is {header}" in proc.stderr
        assert not (tmp_path / "out.gpkg").exists()
    pairs = tmp_path / "pairs.csv"
    pairs.write_text("id,street1,street2\na,Eastern Ave,S Broadway\n", encoding="utf-8")
    proc = _camloc(
        ["batch", str(pairs), "-o", "out.gpkg", "--osm", str(BALTIMORE), "--no-progress"],
        tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    assert "1 title_only" in proc.stderr


def test_device_inputs_are_refused_not_read_for_ever(tmp_path: Path) -> None:
    """``/dev/zero`` as a GeoJSON, verdicts or list file was read whole: memory grew until
    ``MemoryError`` (exit 1; without a memory limit the machine swapped), and ``geocode
    --list /dev/zero`` never ended. Each is refused at once (exit 2, naming the file)."""
    loc = tmp_path / "loc.geojson"
    loc.write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "features": [
                    {
                        "type": "Feature",
                        "geometry": {"type": "Point", "coordinates": [-76.593, 39.2851]},
                        "properties": {
                            "kind": "candidate",
                            "rank": 1,
                            "score": 1.0,
                            "lat": 39.2851,
                            "lon": -76.593,
                        },
                    }
                ],
            }
        ),
        encoding="utf-8",
    )
    cases = [
        (["summary-map", "/dev/zero", "-o", "a.html"], "GeoJSON file"),
        (["summary-map", str(loc), "-o", "b.html", "--verdicts", "/dev/zero"], "verdicts file"),
        (["geocode", "--list", "/dev/zero", "--osm", str(BALTIMORE)], "list of titles"),
        (["batch", "/dev/zero", "-o", "c.gpkg"], "camera list /dev/zero is not a regular file"),
    ]
    for args, says in cases:
        proc = _camloc(args, tmp_path)  # the timeout of 600 s is the hang's test
        assert proc.returncode == 2, (args, proc.stderr)
        assert "/dev/zero" in proc.stderr, proc.stderr
        assert says in proc.stderr, proc.stderr
    # a pipe (bash's <(camloc locate ...)) is still read, bounded
    read_fd, write_fd = os.pipe()
    os.write(write_fd, loc.read_bytes())
    os.close(write_fd)
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    cmd = [sys.executable, "-m", "camloc_geo.cli", "summary-map", f"/dev/fd/{read_fd}"]
    proc2 = subprocess.run(
        [*cmd, "-o", "d.html"],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
        env=env,
        pass_fds=(read_fd,),
    )
    os.close(read_fd)
    assert proc2.returncode == 0, proc2.stderr
    assert (tmp_path / "d.html").stat().st_size > 1000


def test_read_json_file_bounds_its_read(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A JSON file over ``MAX_JSON_BYTES`` is refused by its size (regular file) or after
    reading that much (a pipe), never read whole."""
    from camloc_geo import _io
    from camloc_geo._errors import InputError

    big = tmp_path / "big.json"
    big.write_text("[" + "0," * 600 + "0]", encoding="utf-8")
    monkeypatch.setattr(_io, "MAX_JSON_BYTES", 1000)
    with pytest.raises(InputError, match=r"big\.json: .*camloc reads \(0 MB at most\)"):
        _io.read_json_file(big)
    small = tmp_path / "small.json"
    small.write_text("[1, 2]", encoding="utf-8")
    assert _io.read_json_file(small) == [1, 2]


def test_serve_names_the_bad_variable(tmp_path: Path) -> None:
    """A bad ``CAMLOC_*`` value stopped ``camloc serve`` with pydantic's text, which names the
    field (``max_request_bytes``), a type code and a pydantic URL; the line names the
    variable and its value now (exit 2, no server started)."""
    pytest.importorskip("uvicorn")
    env = {
        **os.environ,
        "PYTHONPATH": str(REPO),
        "CAMLOC_DATA_DIR": str(tmp_path),
        "CAMLOC_MAX_REQUEST_BYTES": "-5",
        "CAMLOC_NETWORK": "maybe",
    }
    proc = subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", "serve", "--port", "1"],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
        env=env,
    )
    assert proc.returncode == 2, proc.stderr
    line = proc.stderr.strip()
    assert "\n" not in line
    assert "CAMLOC_MAX_REQUEST_BYTES='-5': Input should be greater than or equal to 1000" in line
    assert "CAMLOC_NETWORK='maybe'" in line
    assert "errors.pydantic.dev" not in line


@pytest.mark.parametrize("near", ["nan", "-3", "inf"])
def test_streets_near_m_must_be_a_distance(tmp_path: Path, near: str) -> None:
    """``camloc streets --near-m nan`` loaded the map and failed with "ValueError: Out of
    range float values are not JSON compliant" (exit 1); ``-3`` listed nothing near without
    a word. Both are refused (exit 2) before the map is read."""
    args = ["streets", "--osm", str(BALTIMORE), "--lat", "39.2851", "--lon", "-76.593"]
    proc = _camloc([*args, f"--near-m={near}"], tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert f"--near-m must be a number of metres, 0 or more, got {float(near)}" in proc.stderr
