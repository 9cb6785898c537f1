"""Name normalisation and carriageway width resolution (pure functions)."""

from __future__ import annotations

import pytest

from camloc_geo.osm._names import close_matches, normalize_name, split_street_query
from camloc_geo.osm._widths import (
    DEFAULT_WIDTH_M,
    in_north_america,
    parse_lanes,
    parse_width_m,
    resolve_width_m,
)


@pytest.mark.parametrize(
    ("a", "b"),
    [
        ("Eastern Ave", "Eastern Avenue"),
        ("S. Broadway", "South Broadway"),
        ("N Charles St", "North Charles Street"),
        ("St Paul St", "Saint Paul Street"),
        ("Hauptstr.", "Hauptstraße"),
        ("HAUPTSTRASSE", "hauptstraße"),
        ("Martin Luther King Jr Blvd", "Martin Luther King Jr Boulevard"),
    ],
)
def test_equivalent_names(a: str, b: str) -> None:
    assert normalize_name(a) == normalize_name(b)


def test_different_names_stay_different() -> None:
    assert normalize_name("Saint Paul Street") != normalize_name("Paul Street")
    assert normalize_name("Broadway") != normalize_name("South Broadway")
    # one normaliser for the map and the geocoder: other scripts are transliterated, so a
    # Cyrillic name and its Latin spelling compare equal
    assert normalize_name("улица Руставели") == "ulitsa rustaveli"
    assert normalize_name("улица Руставели") != normalize_name("улица Пушкина")


@pytest.mark.parametrize(
    ("query", "expected"),
    [
        ("Eastern Avenue & South Broadway", ["Eastern Avenue", "South Broadway"]),
        ("A / B", ["A", "B"]),
        ("Main St and 2nd Ave", ["Main St", "2nd Ave"]),
        ("Rue A × Rue B", ["Rue A", "Rue B"]),
        (["  X ", "Y"], ["X", "Y"]),
        ("Elm St", ["Elm St"]),
    ],
)
def test_split_street_query(query: str | list[str], expected: list[str]) -> None:
    assert split_street_query(query) == expected


def test_close_matches() -> None:
    names = ["Eastern Avenue", "Fleet Street", "South Broadway", "Aliceanna Street"]
    assert close_matches("Estern Ave", names)[0] == "Eastern Avenue"
    assert "South Broadway" in close_matches("Broadway", names)
    assert close_matches("Zzz", names) == []


@pytest.mark.parametrize(
    ("raw", "metres"),
    [
        ("7", 7.0),
        ("7.5 m", 7.5),
        ("7,5", 7.5),
        ("24'", 7.3152),
        ("24'6\"", 7.4676),
        ("30 ft", 9.144),
        (["6", "8"], 6.0),
        ("wide", None),
        ("0", None),
        (None, None),
        (float("nan"), None),
    ],
)
def test_parse_width(raw: object, metres: float | None) -> None:
    got = parse_width_m(raw)
    if metres is None:
        assert got is None
    else:
        assert got == pytest.approx(metres)


def test_parse_lanes() -> None:
    assert parse_lanes("2") == 2.0
    assert parse_lanes("2;3") == 2.0
    assert parse_lanes(None) is None
    assert parse_lanes("many") is None


def test_resolve_width_order_and_conventions() -> None:
    assert resolve_width_m(width="9", lanes="4", highway="primary", oneway=False) == (9.0, "width")
    assert resolve_width_m(width=None, lanes="2", highway="primary", oneway=False) == (
        6.5,
        "lanes",
    )
    assert resolve_width_m(
        width=None, lanes="2", highway="primary", oneway=False, north_america=True
    ) == (pytest.approx(7.2), "lanes")
    two_way, src = resolve_width_m(width=None, lanes=None, highway="residential", oneway=False)
    assert (two_way, src) == (DEFAULT_WIDTH_M["residential"], "default")
    one_way, _ = resolve_width_m(width=None, lanes=None, highway="residential", oneway=True)
    assert one_way < two_way
    us, _ = resolve_width_m(
        width=None, lanes=None, highway="residential", oneway=False, north_america=True
    )
    assert us > two_way
    assert resolve_width_m(width=None, lanes=None, highway="weird", oneway=False)[0] == 7.0
    assert resolve_width_m(width=None, lanes=None, highway="living_street", oneway=True)[0] >= 3.0


def test_north_america() -> None:
    assert in_north_america(39.28, -76.59)
    assert in_north_america(49.28, -123.1)
    assert not in_north_america(48.86, 2.35)
    assert not in_north_america(21.87, -102.27)  # Mexico keeps the default conventions
