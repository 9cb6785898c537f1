"""Maps built from extracts are kept on disk between processes (issue 26, start-up).

A kept map gives the same intersections, corners and located candidates as a built one; a
changed file, a torn cache file or ``CAMLOC_MAP_CACHE=off`` builds the map again.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from camloc_geo.osm import _diskcache, clear_cache, load_map
from camloc_geo.osm import _map as _map_module

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "sample_maps"
POINT = (51.45544, -2.59523)  # Bristol, White Lion (bristol_whitelion.osm.pbf)


@pytest.fixture
def extract(tmp_path: Path) -> Path:
    src = tmp_path / "bristol.osm.pbf"
    shutil.copy(SAMPLE / "bristol_whitelion.osm.pbf", src)
    return src


@pytest.fixture
def cache_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    folder = tmp_path / "maps"
    monkeypatch.setenv("CAMLOC_MAP_CACHE", str(folder))
    clear_cache()
    yield folder
    clear_cache()


def _reads(monkeypatch: pytest.MonkeyPatch) -> list[Path]:
    reads: list[Path] = []
    real_read = _map_module.read_extract

    def counting_read(path: Path, *args: Any, **kwargs: Any) -> Any:
        reads.append(path)
        return real_read(path, *args, **kwargs)

    monkeypatch.setattr(_map_module, "read_extract", counting_read)
    return reads


def _summary(m: Any) -> list[tuple[Any, ...]]:
    return [(x.id, x.lat, x.lon, x.street_names, x.corners) for x in m.intersections]


def test_a_kept_map_is_the_built_map(
    extract: Path, cache_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    reads = _reads(monkeypatch)
    built = load_map(extract, *POINT, 150)
    assert len(reads) == 1
    assert len(list(cache_dir.glob("*.camloc-map.pickle"))) == 1
    clear_cache()  # a new process: only the disk remembers
    kept = load_map(extract, *POINT, 150)
    assert len(reads) == 1  # not read again
    assert kept is not built
    assert _summary(kept) == _summary(built)
    assert [b.id for b in kept.buildings] == [b.id for b in built.buildings]
    assert kept.bounds == built.bounds
    assert kept.warnings == built.warnings


def test_a_changed_file_or_area_is_built_again(
    extract: Path, cache_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    reads = _reads(monkeypatch)
    load_map(extract, *POINT, 150)
    clear_cache()
    load_map(extract, *POINT, 100)  # another radius
    stat = extract.stat()
    os.utime(extract, ns=(stat.st_atime_ns, stat.st_mtime_ns + 2_000_000_000))
    clear_cache()
    load_map(extract, *POINT, 150)  # the file changed
    assert len(reads) == 3


def test_a_torn_file_is_built_again(
    extract: Path, cache_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    reads = _reads(monkeypatch)
    built = load_map(extract, *POINT, 150)
    (kept_file,) = cache_dir.glob("*.camloc-map.pickle")
    kept_file.write_bytes(kept_file.read_bytes()[:100])
    clear_cache()
    again = load_map(extract, *POINT, 150)
    assert len(reads) == 2
    assert _summary(again) == _summary(built)
    clear_cache()
    load_map(extract, *POINT, 150)  # the rewritten file serves
    assert len(reads) == 2


@pytest.mark.parametrize("value", ["off", "0", ""])
def test_off_keeps_nothing(
    extract: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, value: str
) -> None:
    monkeypatch.setenv("CAMLOC_MAP_CACHE", value)
    assert _diskcache.cache_folder() is None
    reads = _reads(monkeypatch)
    clear_cache()
    load_map(extract, *POINT, 150)
    clear_cache()
    load_map(extract, *POINT, 150)
    assert len(reads) == 2
    clear_cache()


def test_default_folder_follows_xdg(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("CAMLOC_MAP_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert _diskcache.cache_folder() == tmp_path / "xdg" / "camloc_geo" / "maps"


def test_prune_keeps_the_newest(tmp_path: Path) -> None:
    for i in range(5):
        p = tmp_path / f"{i}.camloc-map.pickle"
        p.write_bytes(b"x" * 1000)
        os.utime(p, (1_000_000 + i, 1_000_000 + i))
    _diskcache._prune(tmp_path, max_bytes=2500)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "3.camloc-map.pickle",
        "4.camloc-map.pickle",
    ]


def test_locate_from_a_kept_map_gives_the_same_candidates(cache_dir: Path) -> None:
    from camloc_geo.api import locate_scene

    def run() -> dict[str, Any]:
        clear_cache()
        out = locate_scene(
            SAMPLE / "sample_scene.json", map_source=SAMPLE / "baltimore.osm.pbf", network=False
        )
        return out.to_geojson()

    built = run()
    assert list(cache_dir.glob("*.camloc-map.pickle"))
    kept = run()
    assert kept == built
    assert kept["features"]
