"""Batch memory: the resume check streams the journal instead of holding it (issue 26, item 5).

The memory of whole runs is measured in ``benchmarks/batch_scale.py``; these tests check the
pieces that keep it bounded give the same answers as the dictionary they replace.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camloc_geo._errors import InputError
from camloc_geo.batch._journal import Journal
from camloc_geo.batch._run import _RowBits, run_batch


def _record(row: int, status: str = "located") -> dict[str, object]:
    return {"row": row, "id": f"cam{row}", "status": status}


def test_iter_done_is_done_rows_in_row_order(tmp_path: Path) -> None:
    j = Journal(tmp_path / "j.sqlite")
    try:
        rows = [5, 1, 900, 3, 17, 2, 40, 41]
        j.write([_record(r, "failed" if r in (3, 41) else "located") for r in rows])
        for retry in ((), ("failed",)):
            streamed = list(j.iter_done(retry=retry, page=3))  # several pages
            assert streamed == sorted(j.done_rows(retry=retry).items())
        assert [r for r, _ in j.iter_done(retry=("failed",), page=2)] == [1, 2, 5, 17, 40, 900]
    finally:
        j.close()


def test_row_bits_membership() -> None:
    bits = _RowBits()
    added = [0, 7, 8, 9, 63, 64, 1000, 999_999]
    for r in added:
        bits.add(r)
    for r in range(0, 1100):
        assert (r in bits) == (r in added)
    assert 999_999 in bits
    assert 999_998 not in bits
    assert 1_000_000 not in bits
    assert -1 not in bits
    assert "3" not in bits


def test_resume_refuses_a_changed_list(tmp_path: Path) -> None:
    """The streamed resume check still names a row whose camera changed since the journal."""
    lst = tmp_path / "cams.csv"
    lst.write_text("id,title\ncam1,A & B\ncam2,C & D\ncam3,E & F\n")
    out = tmp_path / "out.gpkg"
    j = Journal(tmp_path / "out.camloc-batch.sqlite")
    try:
        j.check_options(
            {"list": str(lst.resolve()), "map_source": None, "network": False, "area": None},
            False,
        )
        j.write([{"row": 2, "id": "other", "status": "located"}])
    finally:
        j.close()
    with pytest.raises(InputError, match=r"row 2 of cams.csv is camera 'cam2'.*'other'"):
        run_batch(lst, out_gpkg=out, progress=False, workers=1)
