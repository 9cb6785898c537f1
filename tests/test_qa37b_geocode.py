"""A title that gives no street name says why for what it holds (QA sweep 37b).

An HTTP job camera with ``"title": 5`` got "no street name in the title (empty title)"
though the title is not empty.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camloc_geo.batch import row_from_mapping
from camloc_geo.geocode import geocode_title, whole_map
from camloc_geo.osm import MapData

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def baltimore() -> MapData:
    return whole_map(REPO / "sample_maps" / "baltimore.osm.pbf")


def reason(title: object, map_data: MapData) -> str:
    (best,) = geocode_title(title, map_data=map_data)  # type: ignore[arg-type]
    assert best.status == "not_found"
    return str(best.reason)


def test_number_title_is_not_called_empty(baltimore: MapData) -> None:
    # the HTTP job path: the list reader reads 5 as the text "5"
    row = row_from_mapping({"id": "a", "title": 5, "lat": 39.29, "lon": -76.61}, 1)
    text = reason(row.title, baltimore)
    assert "empty" not in text
    assert "only a number, '5'" in text
    raw = reason(5, baltimore)
    assert "the title is not text (int)" in raw
    assert "empty" not in raw


def test_other_titles_without_a_street(baltimore: MapData) -> None:
    assert reason("", baltimore) == "no street name in the title (empty title)"
    assert reason("   ", baltimore) == "no street name in the title (empty title)"
    assert "only a view direction, 'NB'" in reason("NB", baltimore)
    assert "no letters or digits" in reason("&", baltimore)
