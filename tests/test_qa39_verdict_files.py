"""Session 39 QA: ``--verdicts`` given a file that is not a verdicts export.

A camera list (``id,title,lat,lon,...``) given to ``camloc summary-map --verdicts`` was
"not a verdicts CSV: no column camera, verdict (columns: camera, rank, lat, lon, verdict,
...)": the columns listed were the export's, and read as the file's own, which then seemed
to hold the columns said to be missing.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camloc_geo import InputError, maps


def test_a_camera_list_as_verdicts_names_its_own_columns(tmp_path: Path) -> None:
    cams = tmp_path / "cams.csv"
    cams.write_text("id,title,lat,lon\nc1,Main St & 1st Ave,39.28,-76.59\n", encoding="utf-8")
    with pytest.raises(InputError) as info:
        maps.read_verdicts(cams)
    assert str(info.value) == (
        f"{cams}: not a verdicts CSV: no column camera, verdict (its columns: id, title, lat, "
        "lon; a page's export has camera, rank, lat, lon, verdict, note, reviewer, time, page, "
        "identity)"
    )


def test_a_verdicts_csv_without_verdicts_names_the_one_missing(tmp_path: Path) -> None:
    half = tmp_path / "half.csv"
    half.write_text("camera,rank,lat,lon\nc1,1,39.28,-76.59\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"no column verdict \(its columns: camera, rank, lat"):
        maps.read_verdicts(half)
