"""Session 40 QA: a map-writing command wrote its HTML page under any name.

``camloc locate --map x.pdf`` wrote the HTML under a ``.pdf`` name (a PDF viewer then failed
on it); the same for ``summary-map -o``, ``batch --map`` and ``annotate -o``. A page's name
must now end in .html or .htm (or have no suffix); another is refused before any work, exit 2,
naming the suffixes.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camloc_geo.cli import main

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "sample_maps" / "sample_scene.json"
BALTIMORE = REPO / "sample_maps" / "baltimore.osm.pbf"


def _refused(argv: list[str], option: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"{option} " in err
    assert "writes an HTML page, not .pdf; name it .html or .htm" in err
    assert "Traceback" not in err


def test_locate_map_pdf_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    page = tmp_path / "x.pdf"
    out = tmp_path / "c.geojson"
    argv = ["locate", str(SCENE), "--osm", str(BALTIMORE), "-o", str(out), "--map", str(page)]
    _refused(argv, "--map", capsys)
    assert not page.exists()
    assert not out.exists()


def test_summary_map_batch_and_annotate_pages_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cands = tmp_path / "c.geojson"
    cands.write_text('{"type": "FeatureCollection", "features": []}', encoding="utf-8")
    page = tmp_path / "s.PDF".lower()
    _refused(["summary-map", str(cands), "-o", str(page)], "-o", capsys)
    lst = tmp_path / "cams.csv"
    lst.write_text("id,title\n1,A & B\n", encoding="utf-8")
    gpkg = tmp_path / "o.gpkg"
    argv = ["batch", str(lst), "-o", str(gpkg), "--map", str(page), "--workers", "1"]
    _refused([*argv, "--no-progress"], "--map", capsys)
    from PIL import Image

    photo = tmp_path / "photos" / "cam.png"
    photo.parent.mkdir()
    Image.new("RGB", (64, 48), (90, 90, 90)).save(photo)
    _refused(["annotate", str(photo), "-o", str(page)], "-o", capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.geojson", "cams.csv", "photos"]


def test_html_htm_and_no_suffix_are_taken(tmp_path: Path) -> None:
    from camloc_geo.cli import page_path

    for name in ("a.html", "b.HTM", "c"):
        assert page_path(tmp_path / name, option="--map") == tmp_path / name


def test_an_empty_geocode_title_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    """``camloc geocode ""`` (an unset shell variable) printed a ``not_found`` feature and
    exited 0; it is refused before the map is read, naming the title."""
    assert main(["geocode", "Eastern Ave & S Broadway", " ", "--osm", str(BALTIMORE)]) == 2
    captured = capsys.readouterr()
    assert "title 2 is empty" in captured.err
    assert captured.out == ""


def test_summary_map_takes_a_candidates_point_from_its_geometry(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """A candidate GeoJSON whose lat/lon properties were dropped (columns removed in a GIS,
    another tool's output) had every candidate skipped, "lat=None ... is not a position",
    exit 2, though each feature's Point says where it is; the Point is taken now."""
    import json

    feats = [
        {
            "type": "Feature",
            "geometry": {"type": "Point", "coordinates": [-76.5935 + r * 1e-4, 39.2855]},
            "properties": {"kind": "candidate", "rank": r, "score": 0.5 / r},
        }
        for r in (1, 2)
    ]
    feats.append(
        {"type": "Feature", "geometry": None, "properties": {"kind": "candidate", "rank": 3}}
    )
    src = tmp_path / "cam-a.geojson"
    src.write_text(json.dumps({"type": "FeatureCollection", "features": feats}), "utf-8")
    page = tmp_path / "s.html"
    assert main(["summary-map", str(src), "-o", str(page), "--inline"]) == 0
    err = caplog.text
    assert "feature 2: lat=None, lon=None is not a position: skipped" in err
    assert "feature 0" not in err
    text = page.read_text(encoding="utf-8")
    assert "39.2855000°" in text  # the best candidate's popup, from its Point
    assert "<title>camloc summary: 1 of 1 camera on the map</title>" in text


CORNERS = ["corners", "--osm", str(BALTIMORE), "--lat", "39.2855", "--lon", "-76.5935"]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["locate", str(SCENE), "--osm", str(BALTIMORE), "-o", "{tmp}/review.html"],
            "writes GeoJSON, not .html; name it .geojson (the review page is --map OUT.html)",
        ),
        (["locate", str(SCENE), "--osm", str(BALTIMORE), "-o", "{tmp}/c.gpkg"], "not .gpkg"),
        (["calibrate", str(SCENE), "-o", "{tmp}/cal.pdf"], "writes JSON, not .pdf; name it .json"),
        (
            [*CORNERS, "-o", "{tmp}/corners.csv"],
            "writes GeoJSON, not .csv",
        ),
        (["measure", str(SCENE), "--ground", "1,2", "3,4", "-o", "{tmp}/m.xlsx"], "not .xlsx"),
        (["schema", "scene", "-o", "{tmp}/schema.html"], "writes JSON, not .html"),
    ],
)
def test_a_json_output_under_another_formats_name_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    """``locate -o review.html`` wrote GeoJSON under a page's name (``--map`` was meant),
    ``-o c.gpkg`` GeoJSON under a GeoPackage's; refused before any work, exit 2."""
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main(argv) == 2
    assert message in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_json_names_are_taken(tmp_path: Path) -> None:
    from camloc_geo.cli import json_path

    for name in ("a.json", "b.geojson", "c", "d.out", "e.JSON"):
        assert json_path(tmp_path / name) == tmp_path / name
