"""Session 38 QA: an interruption while ``camloc batch`` writes its GeoPackage.

Ctrl-C (or SIGTERM) during the last stage left ``OUT.part.gpkg`` behind (seen: 3 MB of a
40,000-camera list), though every output is written atomically "with no temporary file
behind" (docs/cli.md). The previous GeoPackage stays and the partial file is removed.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pyogrio
import pytest

from camloc_geo.batch import run_batch

REPO = Path(__file__).resolve().parents[1]
OSM = REPO / "sample_maps" / "baltimore.osm.pbf"


def test_an_interrupted_geopackage_leaves_no_part_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    lst = tmp_path / "cams.csv"
    out = tmp_path / "cams.gpkg"
    lst.write_text(
        "id,title\nc1,Eastern Ave & S Broadway\nc2,Fleet St & S Broadway\n", encoding="utf-8"
    )
    run_batch(lst, out_gpkg=out, map_source=OSM, progress=False, workers=1)
    before = out.read_bytes()
    real = pyogrio.write_dataframe
    calls = {"n": 0}

    def interrupted(*args: Any, **kwargs: Any) -> Any:
        calls["n"] += 1
        if calls["n"] == 2:  # the first layer written, then Ctrl-C
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(pyogrio, "write_dataframe", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run_batch(lst, out_gpkg=out, map_source=OSM, progress=False, workers=1)
    assert calls["n"] == 2
    assert sorted(p.name for p in tmp_path.iterdir() if ".part" in p.name) == []
    assert out.read_bytes() == before
    monkeypatch.setattr(pyogrio, "write_dataframe", real)
    summary = run_batch(lst, out_gpkg=out, map_source=OSM, progress=False, workers=1)
    assert (summary.computed, summary.skipped) == (0, 2)
    assert len(pyogrio.read_dataframe(out, layer="cameras")) == 2
