"""``camloc geocode``: titles, lists, folders, bad input; the library's bad-input paths."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tracemalloc
from pathlib import Path

import pytest

from camloc_geo.cli import main
from camloc_geo.geocode import geocode_title, geocode_title_in_maps, index_for, whole_map

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"
BERLIN = OSM / "berlin_alexanderplatz.osm.pbf"
PARIS = OSM / "paris_bss.osm.pbf"


@pytest.fixture(scope="module")
def berlin():  # type: ignore[no-untyped-def]
    return whole_map(BERLIN)


def test_cli_titles_to_file(tmp_path: Path) -> None:
    out = tmp_path / "out.geojson"
    code = main(
        [
            "geocode",
            "Karl-Liebknecht-Str. / Wadzeckstr.",
            "Alexanderstraße",
            "Nowhere Street & Missing Road",
            "--osm",
            str(BERLIN),
            "--best",
            "-o",
            str(out),
        ]
    )
    assert code == 0
    features = json.loads(out.read_text())["features"]
    statuses = [f["properties"]["status"] for f in features]
    assert statuses == ["junction", "street", "not_found"]
    j = features[0]
    assert j["properties"]["names_matched"] == ["Karl-Liebknecht-Straße", "Wadzeckstraße"]
    assert j["properties"]["match_kinds"] == ["abbreviation", "abbreviation"]
    lon, lat = j["geometry"]["coordinates"]
    assert abs(lat - 52.5259) < 0.0005
    assert abs(lon - 13.4146) < 0.0005
    assert features[1]["geometry"]["type"] in ("LineString", "MultiLineString")
    assert features[2]["geometry"] is None
    assert "Nowhere Street" in features[2]["properties"]["reason"]


def test_cli_folder_ambiguous_and_near(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "maps"
    folder.mkdir()
    shutil.copy(BERLIN, folder / BERLIN.name)
    shutil.copy(PARIS, folder / PARIS.name)
    maps = [whole_map(p) for p in sorted(folder.iterdir())]
    # a Paris junction is found in the Paris extract only
    found = geocode_title_in_maps("Av. de la Republique x R. Saint-Maur", maps)
    assert found[0].status == "junction"
    assert Path(found[0].source).name == PARIS.name
    # names in neither extract
    both = geocode_title_in_maps("Street A & Street B", maps)
    assert both[0].status == "not_found"
    code = main(
        ["geocode", "Grunerstr. x Alexanderstr.", "--osm", str(folder), "--near", "52.52,13.41"]
    )
    assert code == 0
    features = json.loads(capsys.readouterr().out)["features"]
    assert features[0]["properties"]["status"] == "junction"
    assert Path(features[0]["properties"]["source"]).name == BERLIN.name


def test_two_extracts_naming_one_junction_place_it(tmp_path: Path) -> None:
    """Overlapping extracts (here one area twice, as data/osm's aguascalientes .pbf and .bz2)
    name the same junction: placed, the other extract named (was 'ambiguous', no point)."""
    a = tmp_path / "a.osm.pbf"
    b = tmp_path / "b.osm.pbf"
    shutil.copy(BERLIN, a)
    shutil.copy(BERLIN, b)
    found = geocode_title_in_maps("Grunerstr. x Alexanderstr.", [whole_map(a), whole_map(b)])
    assert [m.status for m in found] == ["junction"]
    assert "the same junction in b.osm.pbf" in found[0].reason


def test_two_extracts_two_places_are_ambiguous() -> None:
    from camloc_geo.geocode import TitleMatch
    from camloc_geo.geocode._maps import miss_rank, one_place

    here = TitleMatch(status="junction", lat=52.5208, lon=13.4152, source="a.osm.pbf")
    near = TitleMatch(status="junction", lat=52.5210, lon=13.4155, source="b.osm.pbf")
    far = TitleMatch(status="junction", lat=48.8604, lon=2.3549, source="c.osm.pbf")
    tied = TitleMatch(status="ambiguous", lat=52.5208, lon=13.4152, source="d.osm.pbf")
    assert one_place([here, near])
    assert not one_place([here, far])
    assert not one_place([here, tied])
    # a miss where both names exist says more than one where neither does
    both = TitleMatch(status="not_found", names_matched=["Alexanderstraße", "Grunerstraße"])
    none = TitleMatch(status="not_found", names_matched=["", ""])
    assert sorted([none, both], key=miss_rank)[0] is both


def test_a_title_missing_everywhere_says_why_from_its_own_city(tmp_path: Path) -> None:
    """A Berlin title missing from a folder of extracts took its reason from whichever
    extract sorted first ('not a street name of this map (closest: Aleksi, ...)': Helsinki's
    names); the reason now comes from the extract where the most of its names exist."""
    folder = tmp_path / "maps"
    folder.mkdir()
    shutil.copy(BERLIN, folder / "berlin.osm.pbf")
    shutil.copy(OSM / "bristol_whitelion.osm.pbf", folder / "a_bristol.osm.pbf")
    maps = [whole_map(p) for p in sorted(folder.iterdir())]
    found = geocode_title_in_maps("Alexanderstr. & Qzxwvstr.", maps)
    assert found[0].status == "not_found"
    assert Path(found[0].source).name == "berlin.osm.pbf"
    assert "Qzxwv" in found[0].reason


def test_cli_list_streams(tmp_path: Path) -> None:
    rows = tmp_path / "list.csv"
    rows.write_text(
        "id,title,lat,lon\n"
        "c1,Karl-Liebknecht-Str. / Wadzeckstr.,,\n"
        'c2,"Grunerstr. x Alexanderstr.",52.52,13.415\n'
        "c3,,,\n"
        "c4,!!!,,\n",
        encoding="utf-8",
    )
    out = tmp_path / "out.geojson"
    assert (
        main(["geocode", "--list", str(rows), "--osm", str(BERLIN), "--best", "-o", str(out)]) == 0
    )
    features = json.loads(out.read_text())["features"]
    assert [f["properties"]["id"] for f in features] == ["c1", "c2", "c3", "c4"]
    assert [f["properties"]["status"] for f in features] == [
        "junction",
        "junction",
        "not_found",
        "not_found",
    ]


def test_list_memory_does_not_grow(tmp_path: Path, berlin) -> None:  # type: ignore[no-untyped-def]
    from camloc_geo.cli.geocode import _rows

    rows = tmp_path / "big.csv"
    with rows.open("w", encoding="utf-8") as fh:
        fh.write("id,title\n")
        for i in range(200_000):
            fh.write(f"{i},{i} - Street {i} & Road {i % 97}\n")
    index_for(berlin)
    tracemalloc.start()
    n = 0
    for _row, _ident, title, _point in _rows(rows):
        n += 1
        if n == 1_000:
            base = tracemalloc.get_traced_memory()[0]
        if n % 20_000 == 0:
            geocode_title(title, map_data=berlin)
    peak_growth = tracemalloc.get_traced_memory()[0] - base
    tracemalloc.stop()
    assert n == 200_000
    assert peak_growth < 5_000_000  # bytes: the rows are not kept


@pytest.mark.parametrize(
    "title",
    ["", "   ", ";;; --- ///", "\x00\x07\x1b", "a" * 10_000, "& " * 5_000, "12345", "(north)"],
)
def test_bad_titles_get_a_status(berlin, title: str) -> None:  # type: ignore[no-untyped-def]
    found = geocode_title(title, map_data=berlin)
    assert found
    assert found[0].status in ("not_found", "street", "landmark")
    assert found[0].reason
    json.dumps(found[0].to_feature(), allow_nan=False)


def test_not_found_names_the_missing_name(berlin) -> None:  # type: ignore[no-untyped-def]
    best = geocode_title("Karl-Liebknecht-Str. & Quxbazstraße", map_data=berlin)[0]
    assert best.status == "not_found"
    assert "'Quxbazstraße' is not a street name" in best.reason
    assert best.suggestions["Quxbazstraße"]


def test_never_meet_and_single_street(berlin) -> None:  # type: ignore[no-untyped-def]
    best = geocode_title("Wadzeckstraße & Spandauer Straße", map_data=berlin)[0]
    assert best.status == "not_found"
    assert "do not meet" in best.reason
    street = geocode_title("Karl-Liebknecht-Str.", map_data=berlin)[0]
    assert street.status == "street"
    assert street.lat is None
    assert street.geometry is not None


def test_radius_filters(berlin) -> None:  # type: ignore[no-untyped-def]
    far = geocode_title(
        "Grunerstr. x Alexanderstr.", map_data=berlin, near=(52.5255, 13.4060), radius_m=50.0
    )
    assert far[0].status == "not_found"
    with pytest.raises(ValueError, match="radius_m"):
        geocode_title("a & b", map_data=berlin, radius_m=-1.0)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["geocode", "--osm", "/nonexistent/x.osm.pbf", "A & B"], "not found"),
        (["geocode", "--osm", str(BERLIN)], "give one or more titles"),
        (["geocode", "--osm", str(BERLIN), "--near", "abc", "A & B"], "--near"),
        (["geocode", "--osm", str(BERLIN), "--list", "/nonexistent.csv"], "cannot read the list"),
    ],
)
def test_cli_bad_input_exit_2(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(args) == 2
    err = capsys.readouterr().err
    assert message in err
    assert "Traceback" not in err


def test_cli_list_without_title_column(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rows = tmp_path / "bad.csv"
    rows.write_text("foo,bar\n1,2\n", encoding="utf-8")
    assert main(["geocode", "--osm", str(BERLIN), "--list", str(rows)]) == 2
    assert "no title column" in capsys.readouterr().err


def test_cli_subprocess(tmp_path: Path) -> None:
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "camloc_geo.cli",
            "geocode",
            "Otto-Braun-Str und Mollstr.",
            "--osm",
            str(BERLIN),
            "--best",
        ],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    feature = json.loads(proc.stdout)["features"][0]
    assert feature["properties"]["names_matched"] == ["Otto-Braun-Straße", "Mollstraße"]


def test_cli_list_refused_before_any_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A missing or headless list prints nothing on stdout (was: an empty collection)."""
    assert main(["geocode", "--osm", str(BERLIN), "--list", str(tmp_path / "none.csv")]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "cannot read the list" in captured.err
    rows = tmp_path / "bad.csv"
    rows.write_text("foo,bar\n1,2\n", encoding="utf-8")
    assert main(["geocode", "--osm", str(BERLIN), "--list", str(rows)]) == 2
    assert capsys.readouterr().out == ""


def test_cli_output_never_overwrites_the_list(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``-o`` naming the list is refused and the list kept (was: the list truncated)."""
    rows = tmp_path / "cams.csv"
    text = "id,title\n1,Karl-Liebknecht-Str. / Wadzeckstr.\n"
    rows.write_text(text, encoding="utf-8")
    assert main(["geocode", "--osm", str(BERLIN), "--list", str(rows), "-o", str(rows)]) == 2
    assert "would overwrite the input" in capsys.readouterr().err
    assert rows.read_text(encoding="utf-8") == text


def test_cli_output_in_missing_folder_is_bad_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A missing output folder is exit 2 naming it (was: exit 1, FileNotFoundError)."""
    out = tmp_path / "no" / "out.geojson"
    assert main(["geocode", "Alexanderstraße", "--osm", str(BERLIN), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "does not exist (create it first)" in err
    assert not out.parent.exists()


def test_cli_output_is_atomic(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A list that fails half way leaves the earlier output file as it was, no temp files."""
    import camloc_geo.cli.geocode as geocode_cli

    out = tmp_path / "out.geojson"
    out.write_text("old", encoding="utf-8")
    rows = tmp_path / "cams.csv"
    rows.write_text("id,title\n1,Alexanderstraße\n2,Alexanderstraße\n", encoding="utf-8")
    real = geocode_cli._data_rows

    def broken(*args: object, **kwargs: object):  # type: ignore[no-untyped-def]
        for n, row in enumerate(real(*args, **kwargs)):  # type: ignore[arg-type]
            if n == 1:
                raise RuntimeError("disk on fire")
            yield row

    monkeypatch.setattr(geocode_cli, "_data_rows", broken)
    assert main(["geocode", "--osm", str(BERLIN), "--list", str(rows), "-o", str(out)]) == 1
    assert out.read_text(encoding="utf-8") == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cams.csv", "out.geojson"]


def test_cli_reader_closing_the_pipe_is_quiet(tmp_path: Path) -> None:
    """``camloc geocode --list ... | head`` ended with "failed: BrokenPipeError" on stderr;
    a closed stdout now stops the command quietly (exit 1), as Unix tools do."""
    rows = tmp_path / "cams.csv"
    rows.write_text(
        "id,title\n" + "".join(f"{i},Karl-Liebknecht-Str. / Wadzeckstr.\n" for i in range(3000)),
        encoding="utf-8",
    )
    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(root) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    cmd = [sys.executable, "-m", "camloc_geo.cli", "geocode", "--list", str(rows)]
    proc = subprocess.Popen(
        [*cmd, "--osm", str(BERLIN)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
    )
    assert proc.stdout is not None
    assert proc.stderr is not None
    assert proc.stdout.read(100).startswith(b'{"type": "FeatureCollection"')
    proc.stdout.close()  # the reader goes away, as head does
    err = proc.stderr.read().decode()
    proc.stderr.close()
    assert proc.wait(timeout=120) == 1
    assert err == ""


def test_cli_broken_pipe_elsewhere_is_still_reported(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A BrokenPipeError that is not stdout's (a socket) stays a named failure."""
    import camloc_geo.cli.geocode as geocode_cli

    def broken(args: object) -> int:
        raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(geocode_cli, "run", broken)
    import camloc_geo.cli as cli

    monkeypatch.setattr(cli, "_stdout_closed", lambda: False)
    assert main(["geocode", "x", "--osm", str(BERLIN)]) == 1
    assert "failed: BrokenPipeError" in capsys.readouterr().err


def test_cli_list_read_as_batch_reads_it(tmp_path: Path) -> None:
    """A spreadsheet's semicolon list with a byte-order mark and decimal commas, and the same
    list as GeoJSON: ``camloc batch`` read both, ``camloc geocode --list`` refused the first
    ('has no title column ...; its columns: id;title;lat;lon') and could not read the second."""
    rows = tmp_path / "cams.csv"
    rows.write_text(
        "id;title;lat;lon\r\n"
        "c1;Karl-Liebknecht-Str. / Wadzeckstr.;;\r\n"
        "c2;Grunerstr. x Alexanderstr.;52,5205;13,4150\r\n",
        encoding="utf-8-sig",
    )
    out = tmp_path / "out.geojson"
    args = ["geocode", "--list", str(rows), "--osm", str(BERLIN), "--best", "-o", str(out)]
    assert main(args) == 0
    props = [f["properties"] for f in json.loads(out.read_text())["features"]]
    assert [(p["id"], p["row"], p["status"]) for p in props] == [
        ("c1", 2, "junction"),
        ("c2", 3, "junction"),
    ]
    assert props[1]["lat"] == pytest.approx(52.5208, abs=5e-4)
    collection = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [13.415, 52.5205]},
                "properties": {"id": "g1", "title": "Grunerstr. x Alexanderstr."},
            },
            {"type": "Feature", "geometry": None, "properties": {"title": "Wadzeckstr."}},
        ],
    }
    listed = tmp_path / "cams.geojson"
    listed.write_text(json.dumps(collection), encoding="utf-8")
    out2 = tmp_path / "out2.geojson"
    args = ["geocode", "--list", str(listed), "--osm", str(BERLIN), "--best", "-o", str(out2)]
    assert main(args) == 0
    props = [f["properties"] for f in json.loads(out2.read_text())["features"]]
    assert [(p["id"], p["row"], p["status"]) for p in props] == [
        ("g1", 1, "junction"),
        (None, 2, "street"),
    ]


def test_a_match_far_from_the_list_point_says_so(tmp_path: Path) -> None:
    """A list row with a London point and a Berlin title: placed in Berlin (junction, score
    1) without a word, 933 km from the point the list gave; the reason now says how far."""
    rows = tmp_path / "far.csv"
    rows.write_text(
        "id,title,lat,lon\n"
        "far,Grunerstr. x Alexanderstr.,51.5154,-0.1419\n"
        "near,Grunerstr. x Alexanderstr.,52.5205,13.4150\n",
        encoding="utf-8",
    )
    out = tmp_path / "out.geojson"
    args = ["geocode", "--list", str(rows), "--osm", str(BERLIN), "--best", "-o", str(out)]
    assert main(args) == 0
    props = [f["properties"] for f in json.loads(out.read_text())["features"]]
    assert props[0]["status"] == "junction"
    assert "; 933 km from the point given (51.51540,-0.14190)" in props[0]["reason"]
    assert "from the point given" not in props[1]["reason"]


def test_cli_list_names_a_bad_point(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A row whose point is unusable ('abc', one of the two, out of range) lost its point
    without a word and its title was searched everywhere; stderr now names the row."""
    rows = tmp_path / "bad.csv"
    rows.write_text(
        "id,title,lat,lon\n"
        "a,Grunerstr. x Alexanderstr.,abc,13.4\n"
        "b,Grunerstr. x Alexanderstr.,52.52,\n"
        "c,Grunerstr. x Alexanderstr.,952.52,13.4\n"
        "d,Grunerstr. x Alexanderstr.,,\n",
        encoding="utf-8",
    )
    out = tmp_path / "out.geojson"
    args = ["geocode", "--list", str(rows), "--osm", str(BERLIN), "--best", "-o", str(out)]
    assert main(args) == 0
    err = capsys.readouterr().err
    assert "row 2: lat 'abc' is not a number; searched without a point" in err
    assert "row 3: give both lat and lon, or neither" in err
    assert "row 4: lat/lon 952.52,13.4 is out of range" in err
    assert "row 5" not in err
    props = [f["properties"] for f in json.loads(out.read_text())["features"]]
    assert [p["status"] for p in props] == ["junction"] * 4
