"""A camera's title candidates are on the candidates' scale (stop 41).

The candidates' ``score`` is each one's share of the evidence (a camera's scores sum to 1,
``docs/contract.md``). A title's candidates carried the geocoder's name-match score instead:
a title matching two junctions exactly gave two candidates of 1.0 (summing to 2), and a
located camera's title junction, listed after its located candidates, showed 1.0 beside a
best candidate of 0.48 (the batch GeoPackage, the service's job, the summary map's score).
The match score now has its own field, ``match_score``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camloc_geo.batch import CameraRow, geocode_camera
from camloc_geo.osm import load_map
from camloc_geo.osm._map import MapData

REPO = Path(__file__).resolve().parents[1]
BALTIMORE = REPO / "sample_maps" / "baltimore.osm.pbf"
# synthetic cameras of the Baltimore sample (camloc_geo.testing.camera_list, seed 3)
AMBIGUOUS_TITLE = "184 - King Circle / Halsey Road looking north"  # two junctions


@pytest.fixture(scope="module")
def baltimore() -> MapData:
    return load_map(str(BALTIMORE), 39.29, -76.6, radius_m=None)


def _sum(cands: list[dict]) -> float:
    return sum(c["score"] for c in cands)


def test_an_ambiguous_titles_places_share_the_evidence(baltimore: MapData) -> None:
    res = geocode_camera(CameraRow(row=1, id="a", title=AMBIGUOUS_TITLE), map_data=baltimore)
    assert res.status == "ambiguous"
    cands = [c for c in res.candidates if c["lat"] is not None]
    assert len(cands) == 2
    assert [c["score"] for c in cands] == pytest.approx([0.5, 0.5])  # were 1.0 and 1.0
    assert [c["match_score"] for c in cands] == [1.0, 1.0]
    assert res.score == pytest.approx(0.5)
    assert res.match_score == 1.0


def test_a_single_junction_holds_the_whole_share(baltimore: MapData) -> None:
    row = CameraRow(row=1, id="t", title="Dundalk Avenue at Holabird Avenue")
    res = geocode_camera(row, map_data=baltimore)
    assert res.status == "title_only"
    assert _sum(res.candidates) == pytest.approx(1.0)
    assert res.score == res.candidates[0]["score"]
    assert res.match_score == res.candidates[0]["match_score"]


def test_a_located_cameras_title_junction_holds_no_share(baltimore: MapData) -> None:
    row = CameraRow(
        row=1,
        id="s",
        title=AMBIGUOUS_TITLE,
        scene=str(REPO / "sample_maps" / "sample_scene.json"),
    )
    res = geocode_camera(row, map_data=baltimore)
    assert res.status == "located"
    located = [c for c in res.candidates if c["source"] == "locate"]
    title = [c for c in res.candidates if c["source"] == "title"]
    assert located
    assert title
    assert _sum(located) == pytest.approx(1.0)
    assert all(c["score"] == 0.0 for c in title)  # was 1.0, above the best located one
    assert all(c["match_score"] == 1.0 for c in title)
    assert max(c["score"] for c in res.candidates) == located[0]["score"] == res.score
