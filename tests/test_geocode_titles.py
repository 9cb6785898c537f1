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
        # the fourth sweep's webcam list: these were read as one name, or kept the
        # direction in a name, or read HTML tags as street names
        (
            "C. Defensa Nacional esq. Calle Hacienda",
            ["C. Defensa Nacional", "Calle Hacienda"],
            None,
            None,
            None,
        ),
        ("Alexanderstr. Ecke Grunerstr.", ["Alexanderstr", "Grunerstr"], None, None, None),
        ("Carrera 7 con Calle 26", ["Carrera 7", "Calle 26"], None, None, None),
        (
            "Av. de los Fundadores / Jose Alonso Flores hacia el norte",
            ["Av. de los Fundadores", "Jose Alonso Flores"],
            None,
            None,
            0.0,
        ),
        (
            "Gontardstr. / Rathausstr. (Blick nach Osten)",
            ["Gontardstr", "Rathausstr"],
            None,
            None,
            90.0,
        ),
        (
            "Камера 12: Аргуновская ул. / 2-я Новоостанкинская (на север)",
            ["Аргуновская ул", "2-я Новоостанкинская"],
            "12",
            None,
            0.0,
        ),
        ("Rauhankatu & Unioninkatu (itään)", ["Rauhankatu", "Unioninkatu"], None, None, 90.0),
        ("南京西路 @ 中山北路一段 (北向)", ["南京西路", "中山北路一段"], None, None, 0.0),
        (
            "<script>alert(1)</script><b>E Monument St</b> &amp; N Lakewood Ave",
            ["E Monument St", "N Lakewood Ave"],
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


@pytest.mark.parametrize(
    "title",
    [
        "Foo St & Bar Ave",  # a bar called "Bar" is not "Bar Avenue"
        "Bar Ave",
        "Broadway & Bar St",  # one real street does not make the other real
        "Fleet St & Pub Ave",
        "Main St",  # no Main Street in this extract
        "Eastern Ave & Cafe St",
        "Qwertzuiop Tower & Plmokn Gate",
        "Fleet St & Zyxwvut Ave",
    ],
)
def test_baltimore_titles_that_must_not_be_placed(baltimore, title: str) -> None:  # type: ignore[no-untyped-def]
    found = geocode_title(title, map_data=baltimore)
    assert [m.status for m in found] == ["not_found"], [(m.status, m.reason) for m in found]
    assert not found[0].placed
    assert found[0].score == 0.0


def test_a_street_pair_is_placed_where_the_two_streets_meet(baltimore) -> None:  # type: ignore[no-untyped-def]
    best = geocode_title("N Milton Ave & E Biddle St", map_data=baltimore)[0]
    assert best.status == "junction"
    assert best.intersection is not None
    streets = set(best.intersection.street_names)
    assert {"North Milton Avenue", "East Biddle Street"} <= streets


def test_scores_tell_a_clean_match_from_a_fuzzy_one(baltimore) -> None:  # type: ignore[no-untyped-def]
    """Exact names > abbreviations > a name without its type > a misspelt name."""
    titles = [
        "North Milton Avenue & East Biddle Street",
        "N Milton Ave & E Biddle St",
        "Milton & E Biddle St",
        "N Miltn Ave & E Biddle St",
    ]
    found = [geocode_title(t, map_data=baltimore)[0] for t in titles]
    assert [m.status for m in found] == ["junction"] * 4
    inter = {m.intersection.id for m in found if m.intersection is not None}
    assert len(inter) == 1  # the same junction each time
    scores = [m.score for m in found]
    assert scores == sorted(scores, reverse=True)
    assert len(set(scores)) == 4, scores
    assert scores[0] == 1.0
    assert scores[-1] < 0.85


def test_a_landmark_name_never_stands_in_for_a_street(baltimore) -> None:  # type: ignore[no-untyped-def]
    """Every one-word named feature, given a street type and paired with a real street."""
    from camloc_geo.geocode import index_for

    index = index_for(baltimore)
    words = sorted(
        {
            toks[0]
            for toks in index.landmarks
            if len(toks) == 1 and toks[0].isalpha() and len(toks[0]) >= 3
        }
    )
    checked = 0
    for word in words:
        for typ, full in (("Ave", "avenue"), ("St", "street")):
            if any(full in t and word in t for t in index.displays):
                continue  # a real street of that name
            title = f"Eastern Ave & {word.title()} {typ}"
            best = geocode_title(title, map_data=baltimore)[0]
            if best.placed:
                assert best.status == "junction", (title, best.status, best.reason)
            checked += 1
    assert checked >= 10


def test_scraped_and_spanish_titles_are_placed() -> None:
    """Titles of the sweep's webcam list that were not_found: 'esq.' and 'Ecke' were not read
    as separators, 'hacia el norte' stayed in the second name, HTML tags were names."""
    berlin = load_map(OSM / "berlin_alexanderplatz.osm.pbf", 52.5219, 13.4132, radius_m=None)
    best = geocode_title("Alexanderstr. Ecke Grunerstr.", map_data=berlin)[0]
    assert best.status == "junction"
    assert _dist_m(best.lat, best.lon, 52.520833, 13.415198) < 30
    ags = load_map(OSM / "aguascalientes.osm.pbf", 21.8689, -102.2717, radius_m=None)
    best = geocode_title("C. Defensa Nacional esq. Calle Hacienda", map_data=ags)[0]
    assert best.status == "junction"
    assert _dist_m(best.lat, best.lon, 21.874077, -102.280185) < 30
    best = geocode_title("Av. de los Fundadores / Jose Alonso Flores hacia el norte", map_data=ags)[
        0
    ]
    assert best.status == "junction"
    assert _dist_m(best.lat, best.lon, 21.87163, -102.279456) < 30
    assert best.to_feature()["properties"]["view_bearing_deg"] == 0.0


def test_junction_beyond_the_radius_is_named(baltimore) -> None:  # type: ignore[no-untyped-def]
    """A list point 340 m off its junction (the sweep's webcam 'Ashland Av and N Glover'):
    the reason said only 'do not meet in this map within 300 m' although they do meet, 337 m
    away; it now says where (camloc batch's reason for the camera)."""
    found = geocode_title(
        "Ashland Av and N Glover", map_data=baltimore, near=(39.3035, -76.5780), radius_m=300
    )
    assert found[0].status == "not_found"
    assert "they meet 337 m away, at 39.30105,-76.58031" in found[0].reason


def test_taiwanese_road_sections_in_either_order() -> None:
    """OSM writes 'Section 1, Nanjing East Road' where signs and webcam titles write
    'Nanjing E. Rd. Sec. 1' (the reviewer sweep's Taipei webcam was not_found)."""
    assert name_tokens("Nanjing E. Rd. Sec. 1") == name_tokens("Section 1, Nanjing East Road")
    assert name_tokens("Zhongshan N. Rd. Sec. 2") == name_tokens("Zhongshan North Road Section 2")
    assert name_tokens("Section Road") == ("section", "road")  # no number: an ordinary word
    taipei = load_map(OSM / "taipei.osm", 25.05224, 121.52256, radius_m=None)
    best = geocode_title("Zhongshan N Rd Sec 1 / Nanjing E. Rd. Sec. 1", map_data=taipei)[0]
    assert best.status == "junction"
    assert _dist_m(best.lat, best.lon, 25.05217, 121.52257) < 30
