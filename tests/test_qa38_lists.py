"""Session 38 QA: camera lists that are not CSV or GeoJSON text.

A GeoPackage given as the list (``camloc batch cams.gpkg``, a GIS analyst's natural input)
was read as Latin-1 "text" with a warning calling it a spreadsheet's export, and refused
quoting its SQLite header's bytes as the header row; ``camloc geocode --list`` printed a
screenful of them. Excel's "Unicode Text" export (UTF-16 with a byte-order mark,
tab-separated) was read the same way and every camera lost.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import geopandas as gpd
import pytest
from shapely.geometry import Point

from camloc_geo._errors import InputError
from camloc_geo.cameras import read_camera_list

REPO = Path(__file__).resolve().parents[1]
OSM = REPO / "sample_maps" / "baltimore.osm.pbf"


def _camloc(*args: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(REPO), "CAMLOC_MAP_CACHE": "off"}
    return subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


@pytest.fixture
def gpkg_list(tmp_path: Path) -> Path:
    df = gpd.GeoDataFrame(
        {"id": ["c1"], "title": ["Eastern Ave & S Broadway"]},
        geometry=[Point(-76.5935, 39.2856)],
        crs="EPSG:4326",
    )
    path = tmp_path / "cams.gpkg"
    df.to_file(path, layer="cameras", driver="GPKG")
    return path


def test_a_geopackage_list_is_refused_naming_what_it_is(gpkg_list: Path, tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"cams\.gpkg is a GeoPackage or SQLite database"):
        list(read_camera_list(gpkg_list))
    out = tmp_path / "out.gpkg"
    res = _camloc("batch", str(gpkg_list), "-o", str(out), "--osm", str(OSM), "--no-progress")
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    assert "GeoPackage" in lines[0]
    assert "ogr2ogr -f GeoJSON" in lines[0]
    assert "SQLite format" not in res.stderr
    assert "Latin-1" not in res.stderr
    assert not out.exists()


def test_geocode_list_refuses_a_geopackage_in_one_line(gpkg_list: Path) -> None:
    res = _camloc("geocode", "--list", str(gpkg_list), "--osm", str(OSM))
    assert res.returncode == 2
    assert len(res.stderr.strip().splitlines()) == 1, res.stderr
    assert "is a GeoPackage or SQLite database" in res.stderr
    assert len(res.stderr) < 400
    assert res.stdout == ""


@pytest.mark.parametrize(
    ("head", "what"),
    [
        (b"PK\x03\x04\x14\x00\x06\x00", "ZIP archive"),
        (b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1\x00\x00", "old Excel"),
        (b"id,title\nc1,Main\x00St\n", "not a text file"),
    ],
)
def test_other_binary_lists_are_named(tmp_path: Path, head: bytes, what: str) -> None:
    path = tmp_path / "cams.csv"
    path.write_bytes(head + b"\x00" * 64)
    with pytest.raises(InputError, match=what):
        list(read_camera_list(path))


def test_excel_unicode_text_is_read(tmp_path: Path) -> None:
    path = tmp_path / "cams.txt"
    path.write_text(
        "id\ttitle\tlat\tlon\nc1\tEastern Ave & S Broadway\t39,2856\t-76,5935\n"
        "c2\tFleet St & S Broadway\t\t\n",
        encoding="utf-16",
    )
    rows = list(read_camera_list(path))
    assert [r.id for r in rows] == ["c1", "c2"]
    assert rows[0].title == "Eastern Ave & S Broadway"
    assert rows[0].lat == pytest.approx(39.2856)
    assert rows[0].lon == pytest.approx(-76.5935)
    assert rows[1].lat is None
    assert rows[0].problems == ()


def test_broken_utf16_names_its_encoding(tmp_path: Path) -> None:
    path = tmp_path / "cams.csv"
    path.write_bytes(b"\xff\xfei\x00d\x00\x00\xd8")
    with pytest.raises(InputError, match=r"is not UTF-16-LE text"):
        list(read_camera_list(path))
