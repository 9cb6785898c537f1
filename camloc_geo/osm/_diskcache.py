"""Maps built from local extracts, kept on disk between processes.

Building the map of an area (reading the extract with pyosmium, the street graph, the
intersections and their kerb corners) is most of a one-shot ``camloc locate``'s own work:
0.16 s of CPU for the sample, against 7 ms to read the built map back. :func:`load_map`
therefore keeps each map it builds from a file in a cache folder and reads it from there in
later processes.

- **Folder**: ``CAMLOC_MAP_CACHE`` (a folder), else ``$XDG_CACHE_HOME/camloc_geo/maps``
  (``~/.cache/camloc_geo/maps``); ``CAMLOC_MAP_CACHE=off`` (or ``0``, ``no``, ``false``)
  turns it off. Created private (``0700``).
- **Key**: the extract's resolved path, modification time and size, the point, radius and
  options, and a fingerprint of the code (every module of ``camloc_geo``, and the versions of
  Python, numpy, shapely, networkx and pyosmium), so a changed file, option or code never
  reads an old map.
- Files are written atomically (a temporary file, then a rename); a file that cannot be read
  is removed and the map is built again. The folder is kept under :data:`MAX_BYTES`, oldest
  files first. Overpass maps are not kept (osmnx has its own HTTP cache).
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import pickle
import sys
import tempfile
from functools import lru_cache
from pathlib import Path
from typing import Any

__all__ = ["MAX_BYTES", "cache_folder", "disk_get", "disk_put"]

log = logging.getLogger(__name__)

MAX_BYTES = 256 * 1024 * 1024
"""The folder is pruned to this size (oldest files first) after each write."""

_OFF = ("off", "0", "no", "false", "none")
_SUFFIX = ".camloc-map.pickle"


def cache_folder() -> Path | None:
    """The cache folder, or None when ``CAMLOC_MAP_CACHE`` turns the cache off."""
    value = os.environ.get("CAMLOC_MAP_CACHE")
    if value is not None:
        if value.strip().lower() in _OFF or not value.strip():
            return None
        return Path(value).expanduser()
    base = os.environ.get("XDG_CACHE_HOME")
    if not base:
        try:
            base = str(Path.home() / ".cache")
        except RuntimeError:  # no home directory: keep nothing
            return None
    return Path(base) / "camloc_geo" / "maps"


@lru_cache(maxsize=1)
def _code_fingerprint() -> str:
    """What the built maps depend on besides the extract and the options."""
    import networkx
    import numpy
    import osmium
    import shapely

    h = hashlib.sha256()
    package = Path(__file__).resolve().parents[1]
    # the whole package (1 MB, 4 ms): whatever module the map model moves to is covered
    for path in sorted(package.rglob("*.py")):
        h.update(str(path.relative_to(package)).encode())
        with contextlib.suppress(OSError):
            h.update(path.read_bytes())
    for version in (
        sys.version,
        numpy.__version__,
        shapely.__version__,
        networkx.__version__,
        getattr(osmium, "__version__", "?"),
    ):
        h.update(version.encode())
    return h.hexdigest()


def _path_of(folder: Path, key: tuple[Any, ...]) -> Path:
    digest = hashlib.sha256((repr(key) + _code_fingerprint()).encode()).hexdigest()
    return folder / f"{digest[:40]}{_SUFFIX}"


def disk_get(key: tuple[Any, ...]) -> Any:
    """The map kept under ``key``, or None (no cache, not kept, unreadable)."""
    folder = cache_folder()
    if folder is None:
        return None
    path = _path_of(folder, key)
    try:
        with path.open("rb") as fh:
            value = pickle.load(fh)
    except FileNotFoundError:
        return None
    except Exception as exc:  # a torn or foreign file: build the map again
        log.debug("map cache file %s unreadable (%s): removed", path, exc)
        with contextlib.suppress(OSError):
            path.unlink()
        return None
    with contextlib.suppress(OSError):
        os.utime(path)  # recently used: pruned last
    return value


def disk_put(key: tuple[Any, ...], value: Any) -> None:
    """Keep a built map under ``key`` (never raises: a cache that cannot be written is skipped)."""
    folder = cache_folder()
    if folder is None:
        return
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        path = _path_of(folder, key)
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as fh:
                pickle.dump(value, fh, protocol=pickle.HIGHEST_PROTOCOL)
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
        _prune(folder)
    except Exception as exc:
        log.debug("map not kept in the cache %s: %s", folder, exc)


def _prune(folder: Path, max_bytes: int = MAX_BYTES) -> None:
    files = []
    for p in folder.glob(f"*{_SUFFIX}"):
        with contextlib.suppress(OSError):
            st = p.stat()
            files.append((st.st_mtime, st.st_size, p))
    total = sum(size for _t, size, _p in files)
    for _t, size, p in sorted(files):
        if total <= max_bytes:
            break
        with contextlib.suppress(OSError):
            p.unlink()
            total -= size
