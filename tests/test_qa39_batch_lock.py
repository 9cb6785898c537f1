"""Session 39 QA: two ``camloc batch`` runs on one output at once.

Both computed every camera, and the first to finish lost its GeoPackage to the other's
temporary file: "camloc batch: failed: FileNotFoundError: [Errno 2] No such file or
directory: 'many.part.gpkg' -> 'many.gpkg'" (exit 1). The second run is now refused at once
(exit 2, one line), and the first writes its GeoPackage.
"""

from __future__ import annotations

from pathlib import Path

import pyogrio
import pytest

from camloc_geo import InputError
from camloc_geo.batch import run_batch
from camloc_geo.cli import main

REPO = Path(__file__).resolve().parents[1]
OSM = REPO / "sample_maps" / "baltimore.osm.pbf"


def test_a_second_run_on_the_same_output_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    lst = tmp_path / "cams.csv"
    lst.write_text(
        "id,title\nc1,Eastern Ave & S Broadway\nc2,Fleet St & S Broadway\n", encoding="utf-8"
    )
    out = tmp_path / "cams.gpkg"
    seen: list[str] = []

    def meanwhile(_done: int) -> None:  # while the first run holds the output
        if seen:
            return
        with pytest.raises(InputError) as info:
            run_batch(lst, out_gpkg=out, map_source=OSM, progress=False, workers=1)
        seen.append(str(info.value))
        args = ["batch", str(lst), "-o", str(out), "--osm", str(OSM), "--workers", "1"]
        seen.append(str(main(args)))
        seen.append(capsys.readouterr().err.strip().splitlines()[-1])

    s = run_batch(
        lst,
        out_gpkg=out,
        map_source=OSM,
        progress=False,
        workers=1,
        chunk_size=1,
        on_chunk=meanwhile,
    )
    assert s.computed == 2
    assert seen[0] == (
        f"another camloc batch is writing {out} (it holds cams.camloc-batch.lock): wait for "
        "it to end, or give another -o"
    )
    assert seen[1] == "2"
    assert seen[2] == "camloc batch: error: " + seen[0]
    assert len(pyogrio.read_dataframe(out, layer="cameras")) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "cams.camloc-batch.sqlite",
        "cams.csv",
        "cams.gpkg",
    ]
    # the first run over, the output is free again
    again = run_batch(lst, out_gpkg=out, map_source=OSM, progress=False, workers=1)
    assert (again.computed, again.skipped) == (0, 2)


def test_rows_cut_from_the_end_of_the_list_leave_the_output(tmp_path: Path) -> None:
    """A rerun after the list's last row was deleted kept that camera in the GeoPackage,
    and said "2 cameras (0 computed, 2 already done): 3 title_only"."""
    lst = tmp_path / "cams.csv"
    out = tmp_path / "cams.gpkg"
    rows = ["c1,Eastern Ave & S Broadway", "c2,Fleet St & S Broadway", "c3,Thames St & S Broadway"]
    lst.write_text("id,title\n" + "\n".join(rows) + "\n", encoding="utf-8")
    first = run_batch(lst, out_gpkg=out, map_source=OSM, progress=False, workers=1)
    assert first.computed == 3
    lst.write_text("id,title\n" + "\n".join(rows[:2]) + "\n", encoding="utf-8")
    again = run_batch(lst, out_gpkg=out, map_source=OSM, progress=False, workers=1)
    assert (again.total, again.computed, again.skipped) == (2, 0, 2)
    assert sum(again.statuses.values()) == 2
    assert (
        "cams.csv: 1 camera(s) cams.camloc-batch.sqlite recorded are no longer in the list, "
        "left out of the output: row 3 ('c3')"
    ) in again.warnings
    assert list(pyogrio.read_dataframe(out, layer="cameras")["id"]) == ["c1", "c2"]
    # the list grows back: the row is computed again, not taken from the old journal
    lst.write_text("id,title\n" + "\n".join(rows) + "\n", encoding="utf-8")
    grown = run_batch(lst, out_gpkg=out, map_source=OSM, progress=False, workers=1)
    assert (grown.computed, grown.skipped) == (1, 2)
