"""Session 38 QA: a rerun of ``camloc batch`` after the list changed under the same ids.

A row whose title was corrected (same id, same row) kept its old answer: the rerun said
"0 computed, 3 already done" and the GeoPackage gave camera c2 the junction of its old
title. Likewise a scene file annotated again. The journal now keeps a fingerprint of each
row as the list gave it; a changed row is computed again, with a warning naming it.
"""

from __future__ import annotations

import json
import os
import shutil
import sqlite3
from pathlib import Path

import pyogrio
import pytest

from camloc_geo.batch import run_batch
from camloc_geo.batch._journal import journal_path

REPO = Path(__file__).resolve().parents[1]
OSM = REPO / "sample_maps" / "baltimore.osm.pbf"
SCENE = REPO / "sample_maps" / "sample_scene.json"


def _run(lst: Path, out: Path) -> tuple[int, int, list[str]]:
    s = run_batch(lst, out_gpkg=out, map_source=OSM, progress=False, workers=1)
    return s.computed, s.skipped, list(s.warnings)


def _cameras(out: Path) -> dict[str, dict[str, object]]:
    df = pyogrio.read_dataframe(out, layer="cameras")
    return {str(r["id"]): dict(r) for _i, r in df.iterrows()}


def test_a_corrected_title_is_computed_again(tmp_path: Path) -> None:
    lst = tmp_path / "cams.csv"
    out = tmp_path / "cams.gpkg"
    lst.write_text(
        "id,title\nc1,Eastern Ave & S Broadway\nc2,Fleet St & S Broadway\n", encoding="utf-8"
    )
    assert _run(lst, out)[:2] == (2, 0)
    before = _cameras(out)["c2"]
    assert before["names_matched"] == "Fleet Street | South Broadway"
    lst.write_text(
        "id,title\nc1,Eastern Ave & S Broadway\nc2,Thames St & S Broadway\n", encoding="utf-8"
    )
    computed, skipped, warnings = _run(lst, out)
    assert (computed, skipped) == (1, 1)
    assert any("1 row(s) changed" in w and "row 2 ('c2')" in w for w in warnings), warnings
    after = _cameras(out)["c2"]
    assert after["title"] == "Thames St & S Broadway"
    assert after["names_matched"] == "Thames Street | South Broadway"
    assert after["lat"] != pytest.approx(before["lat"], abs=1e-5)
    # unchanged now: nothing computed, no warning
    computed, skipped, warnings = _run(lst, out)
    assert (computed, skipped) == (0, 2)
    assert not any("changed" in w for w in warnings)


def test_a_scene_file_annotated_again_is_located_again(tmp_path: Path) -> None:
    scene = tmp_path / "scene.json"
    shutil.copy(SCENE, scene)
    lst = tmp_path / "cams.csv"
    out = tmp_path / "cams.gpkg"
    lst.write_text("id,scene\nd1,scene.json\n", encoding="utf-8")
    assert _run(lst, out)[:2] == (1, 0)
    first = _cameras(out)["d1"]
    assert first["status"] == "located"
    data = json.loads(scene.read_text(encoding="utf-8"))
    data["annotations"] = data["annotations"][:1]  # another annotation under the same name
    scene.write_text(json.dumps(data), encoding="utf-8")
    st = scene.stat()
    os.utime(scene, ns=(st.st_atime_ns, st.st_mtime_ns + 5_000_000_000))
    computed, skipped, warnings = _run(lst, out)
    assert (computed, skipped) == (1, 0)
    assert any("row 1 ('d1')" in w for w in warnings), warnings


def test_a_journal_of_an_older_release_is_resumed(tmp_path: Path) -> None:
    """A journal without fingerprints (written before this release) is taken as it is."""
    lst = tmp_path / "cams.csv"
    out = tmp_path / "cams.gpkg"
    lst.write_text("id,title\nc1,Eastern Ave & S Broadway\n", encoding="utf-8")
    assert _run(lst, out)[:2] == (1, 0)
    journal = journal_path(out)
    with sqlite3.connect(journal) as db:  # as the older release wrote it
        db.execute("UPDATE done SET fp = NULL")
    lst.write_text("id,title\nc1,Fleet St & S Broadway\n", encoding="utf-8")
    assert _run(lst, out)[:2] == (0, 1)
