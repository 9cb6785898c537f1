"""Session 38 QA: ``camloc batch --scheduler`` with an address Dask cannot parse.

``--scheduler nonsense`` ended with ``failed: ValueError: missing port number in address
'nonsense'`` (exit 1, "a bug"); a typed address is the user's input: exit 2, one line.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from camloc_geo._errors import InputError
from camloc_geo.batch import run_batch

REPO = Path(__file__).resolve().parents[1]
OSM = REPO / "sample_maps" / "baltimore.osm.pbf"

pytest.importorskip("distributed")


@pytest.mark.parametrize(
    ("address", "words"),
    [
        ("nonsense", "missing port number"),
        ("tcp://host:notaport", "notaport"),
        ("http://x:1", "unknown address scheme 'http'"),
    ],
)
def test_a_bad_scheduler_address_is_input(tmp_path: Path, address: str, words: str) -> None:
    lst = tmp_path / "cams.csv"
    lst.write_text("id,title\nc1,Eastern Ave & S Broadway\n", encoding="utf-8")
    with pytest.raises(InputError, match="is not a Dask scheduler address") as info:
        run_batch(lst, out_gpkg=tmp_path / "o.gpkg", map_source=OSM, scheduler=address)
    assert words in str(info.value)
    env = {**os.environ, "PYTHONPATH": str(REPO), "CAMLOC_MAP_CACHE": "off"}
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "camloc_geo.cli",
            "batch",
            str(lst),
            "-o",
            str(tmp_path / "p.gpkg"),
            "--osm",
            str(OSM),
            "--no-progress",
            "--scheduler",
            address,
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert res.returncode == 2, res.stderr
    assert res.stderr.strip().splitlines() == [
        f"camloc batch: error: --scheduler {address!r} is not a Dask scheduler address "
        f"(tcp://HOST:PORT): {str(info.value).split('(tcp://HOST:PORT): ', 1)[1]}"
    ]
