"""Title parsing and geocoding on the repository's extracts (Baltimore, Berlin, Paris)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from camloc_geo.geocode import geocode_title, name_tokens, parse_title
from camloc_geo.osm import load_map

ROOT = Path(__file__).resolve().parents[1]
OSM = ROOT / "data" / "osm"


def _dist_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    kx = 111_320.0 * math.cos(math.radians(lat1))
    return math.hypot((lon2 - lon1) * kx, (lat2 - lat1) * 110_574.0)


@pytest.fixture(scope="module")
def baltimore():  # type: ignore[no-untyped-def]
    return load_map(OSM / "baltimore.osm.pbf", 39.2826, -76.5685, radius_m=None)


@pytest.mark.parametrize(
    ("title", "streets", "camera", "house", "bearing"),
    [
        ("625 - Milton & E Biddle St", ["Milton", "E Biddle St"], "625", None, None),
        ("221 Broadway - Fleet/Broadway (Eastside)", ["Fleet", "Broadway"], None, None, 90.0),
        ("204-E Baltimore St - S Ann St", ["E Baltimore St", "S Ann St"], "204", None, None),
        ("2501-Greenmount and Madison", ["Greenmount", "Madison"], "2501", None, None),
        ("N POTOMAC ST @ E FAYETTE ST", ["N POTOMAC ST", "E FAYETTE ST"], None, None, None),
        (
            "Karl-Liebknecht-Str. / Wadzeckstr.",
            ["Karl-Liebknecht-Str", "Wadzeckstr"],
            None,
            None,
            None,
        ),
        (
            "Av. de la Republique x R. Saint-Maur",
            ["Av. de la Republique", "R. Saint-Maur"],
            None,
            None,
            None,
        ),
        ("1200 N Charles St", ["N Charles St"], None, "1200", None),
        ("Main St at 5th Ave looking north", ["Main St", "5th Ave"], None, None, 0.0),
        ("Cam 12: Broadway & Fleet St - west", ["Broadway", "Fleet St"], "12", None, 270.0),
        ("I-95 NB @ Exit 50", ["I-95", "Exit 50"], None, None, 0.0),
        ("Malcolm X Blvd & W 125th St", ["Malcolm X Blvd", "W 125th St"], None, None, None),
        ("Broadway (facing SW)", ["Broadway"], None, None, 225.0),
        ("ул. Королёва и ул. Цандера", ["ул. Королёва", "ул. Цандера"], None, None, None),
        ("Calle 5 y Av. Juárez", ["Calle 5", "Av. Juárez"], None, None, None),
        ("Hauptstraße 12", ["Hauptstraße"], None, "12", None),
        ("Rue de Rivoli et Rue du Louvre", ["Rue de Rivoli", "Rue du Louvre"], None, None, None),
        (
            "Frankfurter Allee und Warschauer Str.",
            ["Frankfurter Allee", "Warschauer Str"],
            None,
            None,
            None,
        ),
    ],
)
def test_parse_title(
    title: str, streets: list[str], camera: str | None, house: str | None, bearing: float | None
) -> None:
    p = parse_title(title)
    assert p.streets == streets
    assert p.camera_number == camera
    assert p.house_number == house
    assert p.view_bearing_deg == bearing


@pytest.mark.parametrize(
    "title", ["", "   ", ";;; --- ///", "!!!", "\x00\x07\x1b", "a" * 10_000, "&" * 10_000]
)
def test_parse_bad_input_never_raises(title: str) -> None:
    p = parse_title(title)
    assert len(" ".join(p.streets)) <= 300


def test_name_tokens_languages() -> None:
    same = [
        ("E Biddle St", "East Biddle Street"),
        ("Karl-Liebknecht-Str.", "Karl-Liebknecht-Straße"),
        ("Wadzeckstr.", "Wadzeckstraße"),
        ("Av. de la Republique", "Avenue de la République"),
        ("R. St-Maur", "Rue Saint-Maur"),
        ("5th Ave", "Fifth Avenue"),
        ("ул. Академика Королёва", "улица Академика Королёва"),
        ("просп. Мира", "проспект Мира"),
        ("пер. Аптекарский", "переулок Аптекарский"),
        ("C/ Mayor", "Calle Mayor"),
        ("Prol. Reforma", "Prolongación Reforma"),
        ("R. Augusta", "Rua Augusta"),
        ("Bd Voltaire", "Boulevard Voltaire"),
        ("MLK Jr Blvd", "Martin Luther King Junior Boulevard"),
    ]
    for a, b in same:
        assert name_tokens(a) == name_tokens(b), (a, b)


@pytest.mark.parametrize(
    ("title", "expected"),
    [
        ("625 - Milton & E Biddle St", ("North Milton Avenue", "East Biddle Street")),
        ("221 Broadway - Fleet/Broadway (Eastside)", ("Fleet Street", "South Broadway")),
        ("204-E Baltimore St - S Ann St", ("East Baltimore Street", "South Ann Street")),
        ("2501-Greenmount and Madison", ("Greenmount Avenue", "East Madison Street")),
        ("N POTOMAC ST @ E FAYETTE ST", ("North Potomac Street", "East Fayette Street")),
        ("S Broadway St & Eastern Ave", ("South Broadway", "Eastern Avenue")),
    ],
)
def test_baltimore_issue_titles(baltimore, title: str, expected: tuple[str, str]) -> None:  # type: ignore[no-untyped-def]
    best = geocode_title(title, map_data=baltimore)[0]
    assert best.status == "junction", best.reason
    assert tuple(best.names_matched) == expected
    inter = best.intersection
    assert inter is not None
    assert _dist_m(best.lat, best.lon, inter.lat, inter.lon) < 1.0  # type: ignore[arg-type]
