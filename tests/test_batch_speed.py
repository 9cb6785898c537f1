"""The batch's per-camera overhead: records, parsed titles and repeated listings (issue 26)."""

from __future__ import annotations

import csv
import dataclasses
import json
from pathlib import Path

import pytest

from camloc_geo.batch import _run, geocode_camera, journal_path, read_camera_list, run_batch
from camloc_geo.batch._journal import Journal
from camloc_geo.geocode import parse_title
from camloc_geo.testing.camera_list import make_camera_list

REPO = Path(__file__).resolve().parents[1]
BALTIMORE = REPO / "sample_maps" / "baltimore.osm.pbf"


@pytest.fixture(scope="module")
def repeated_list(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Title-only and point cameras, each listing given three times under other ids."""
    base = tmp_path_factory.mktemp("batch_speed")
    osm = base / "osm"
    osm.mkdir()
    (osm / "baltimore.osm.pbf").symlink_to(BALTIMORE)
    src = make_camera_list(
        base / "src", [osm / "baltimore.osm.pbf"], 8, seed=11, scene_fraction=0.25
    )
    with src.open(newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        fields = list(reader.fieldnames or [])
        rows = list(reader)
    # scene paths are relative to the list: keep the copy next to the original
    lst = src.with_name("repeated.csv")
    with lst.open("w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=fields)
        w.writeheader()
        for k in range(3):
            for r in rows:
                w.writerow({**r, "id": f"{r['id']}-{k}"})
    return {"osm": osm, "list": lst}


def _records(out: Path) -> list[dict[str, object]]:
    j = Journal(journal_path(out))
    try:
        return list(j.records())
    finally:
        j.close()


def test_to_dict_is_asdict(repeated_list: dict[str, Path]) -> None:
    rows = list(read_camera_list(repeated_list["list"]))[:8]
    for row in rows:
        res = geocode_camera(row, map_source=repeated_list["osm"])
        assert res.to_dict() == dataclasses.asdict(res)
        assert json.dumps(res.to_dict()) == json.dumps(dataclasses.asdict(res))


def test_parse_title_hands_out_copies() -> None:
    a = parse_title("625 - Milton & E Biddle St (looking north)")
    a.streets.append("Nowhere St")
    a.notes.append("mine")
    b = parse_title("625 - Milton & E Biddle St (looking north)")
    assert b.streets == ["Milton", "E Biddle St"]
    assert "mine" not in b.notes
    assert b.view_bearing_deg == 0.0


def test_repeated_listings_reuse_the_answer(
    repeated_list: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    lst, osm = repeated_list["list"], repeated_list["osm"]
    rows = list(read_camera_list(lst))
    n_scene = sum(1 for r in rows if r.has_scene)
    _run._MEMO.clear()
    memo = run_batch(
        lst,
        out_gpkg=tmp_path / "memo.gpkg",
        map_source=osm,
        progress=False,
        workers=1,
        chunk_size=4,
    )
    # every listing without a scene is computed once, its two repeats reused (not the
    # cameras whose map failed or is missing: a rerun tries those again)
    n_no_map = memo.statuses.get("no_map", 0)
    assert memo.repeats == 2 * (len(rows) - n_scene - n_no_map) // 3 > 0
    monkeypatch.setattr(_run, "_MEMO_SIZE", 0)
    _run._MEMO.clear()
    fresh = run_batch(
        lst,
        out_gpkg=tmp_path / "fresh.gpkg",
        map_source=osm,
        progress=False,
        workers=1,
        chunk_size=4,
    )
    assert fresh.repeats == 0
    assert memo.statuses == fresh.statuses
    a, b = _records(tmp_path / "memo.gpkg"), _records(tmp_path / "fresh.gpkg")
    assert len(a) == len(b) == len(rows)
    assert [json.dumps(r, sort_keys=True) for r in a] == [json.dumps(r, sort_keys=True) for r in b]
    by_id = {r["id"]: r for r in a}
    placed = 0
    for r in a:
        first = by_id[str(r["id"]).rsplit("-", 1)[0] + "-0"]
        assert {**r, "row": 0, "id": ""} == {**first, "row": 0, "id": ""}
        placed += r["lat"] is not None
    assert placed >= len(rows) // 2


def test_fresh_run_counts_rows_without_a_first_pass(
    repeated_list: dict[str, Path], tmp_path: Path
) -> None:
    lst, osm = repeated_list["list"], repeated_list["osm"]
    n = sum(1 for _ in read_camera_list(lst))
    assert _run._count_rows(lst) == n
    out = tmp_path / "o.gpkg"
    first = run_batch(lst, out_gpkg=out, map_source=osm, progress=False, workers=1)
    assert (first.total, first.computed, first.skipped) == (n, n, 0)
    again = run_batch(lst, out_gpkg=out, map_source=osm, progress=False, workers=1)
    assert (again.total, again.computed, again.skipped) == (n, 0, n)


def test_geocode_finds_shapely_ops_in_a_fresh_process() -> None:
    """The title matcher used ``shapely.ops`` without importing it: in a worker that had
    not imported it by chance (maps from the disk cache) every title with two named streets
    meeting only near each other failed with an AttributeError, so the same camera got
    different answers in different processes."""
    import subprocess
    import sys

    code = "import camloc_geo.geocode._geocode as g; print(g.shapely.ops.nearest_points.__name__)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "nearest_points"


def test_degenerate_scene_is_no_candidate_not_a_failure(
    repeated_list: dict[str, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A scene whose geometry is degenerate is the scene's answer, not an internal failure
    (``failed`` is computed again by every rerun); the title's junction is the fallback."""
    import camloc_geo.absolute
    from camloc_geo._errors import DegenerateGeometryError

    row = next(r for r in read_camera_list(repeated_list["list"]) if r.has_scene)
    good = geocode_camera(row, map_source=repeated_list["osm"])
    assert good.status == "located"

    def degenerate(*_a: object, **_k: object) -> None:
        raise DegenerateGeometryError("the length and width vanishing directions are 16.8° apart")

    monkeypatch.setattr(camloc_geo.absolute, "locate", degenerate)
    res = geocode_camera(row, map_source=repeated_list["osm"])
    assert res.status in ("no_candidates", "title_only")
    assert res.status != "failed"
    assert [e["stage"] for e in res.errors] == ["locate"]
    assert "16.8°" in (res.reason or "")
    if res.status == "title_only":
        assert str(res.reason).startswith("scene not located")
        assert res.lat is not None
