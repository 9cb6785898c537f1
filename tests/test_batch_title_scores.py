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


def test_a_journal_written_before_reads_on_the_one_scale(tmp_path: Path) -> None:
    """A resumed run rebuilds its GeoPackage and summary map from every record: a journal of
    the old scale (no ``match_score``) would have mixed the two scales in one layer."""
    from camloc_geo.batch._journal import Journal

    def title(rank: int, score: float) -> dict:
        return {"rank": rank, "source": "title", "score": score, "lat": 39.28, "lon": -76.59}

    old = [
        {  # an ambiguous title: two exact junctions
            "row": 1,
            "id": "a",
            "status": "ambiguous",
            "method": "title",
            "score": 1.0,
            "candidates": [title(1, 1.0), title(2, 1.0)],
        },
        {  # a located camera and its title's junction
            "row": 2,
            "id": "b",
            "status": "located",
            "method": "locate",
            "score": 0.48,
            "candidates": [
                {"rank": 1, "source": "locate", "score": 0.48, "lat": 39.28, "lon": -76.59},
                {"rank": 2, "source": "locate", "score": 0.52, "lat": 39.28, "lon": -76.59},
                title(3, 0.97),
            ],
        },
        {"row": 3, "id": "c", "status": "no_evidence", "candidates": []},
    ]
    j = Journal(tmp_path / "j.sqlite")
    try:
        j.write(old)
        a, b, c = list(j.records())
    finally:
        j.close()
    assert [x["score"] for x in a["candidates"]] == [0.5, 0.5]
    assert [x["match_score"] for x in a["candidates"]] == [1.0, 1.0]
    assert a["score"] == 0.5
    assert a["match_score"] == 1.0
    assert [x["score"] for x in b["candidates"]] == [0.48, 0.52, 0.0]
    assert b["candidates"][2]["match_score"] == 0.97
    assert b["score"] == 0.48
    assert c == old[2]
