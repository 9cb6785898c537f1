"""Whole-extract maps and searching a title in several extracts (a folder)."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from camloc_geo._errors import MapDataError
from camloc_geo.geocode._geocode import TitleMatch, geocode_title

if TYPE_CHECKING:
    from camloc_geo.osm import MapData

__all__ = ["extract_paths", "geocode_title_in_maps", "map_contains", "whole_map"]


def extract_paths(path: str | os.PathLike[str]) -> list[Path]:
    """The OSM extract itself, or every extract in a folder (sorted by name).

    Raises
    ------
    MapDataError
        The path does not exist, or the folder holds no extract.
    """
    from camloc_geo.osm._load import EXTRACT_SUFFIXES

    p = Path(path).expanduser()
    if p.is_file():
        return [p]
    if not p.is_dir():
        raise MapDataError(f"OSM extract or folder not found: {p}")
    found = sorted(
        f for f in p.iterdir() if f.is_file() and f.name.lower().endswith(EXTRACT_SUFFIXES)
    )
    if not found:
        raise MapDataError(f"no OSM extract (.osm, .osm.gz, .osm.bz2, .osm.pbf) in {p}")
    return found


def _extract_box(path: Path) -> tuple[float, float, float, float]:
    """(south, west, north, east) from the header, else from the nodes."""
    import osmium

    from camloc_geo.osm._load import _check_extract_path, _header_box

    _check_extract_path(path)
    box = _header_box(path)
    if box is not None:
        return box
    s, w, n, e = math.inf, math.inf, -math.inf, -math.inf
    try:
        for node in osmium.FileProcessor(str(path), osmium.osm.NODE):
            if not isinstance(node, osmium.osm.Node):
                continue
            loc = node.location
            if loc.valid():
                s, n = min(s, loc.lat), max(n, loc.lat)
                w, e = min(w, loc.lon), max(e, loc.lon)
    except RuntimeError as exc:
        raise MapDataError(f"cannot read OSM extract {path.name}: {exc}") from exc
    if not math.isfinite(s):
        raise MapDataError(f"OSM extract {path.name} holds no located nodes")
    return s, w, n, e


def whole_map(path: str | os.PathLike[str]) -> MapData:
    """Load a whole extract, anchored at its centre (cached like every :func:`load_map`)."""
    from camloc_geo.osm import load_map

    p = Path(path).expanduser()
    s, w, n, e = _extract_box(p)
    return load_map(p, (s + n) / 2.0, (w + e) / 2.0, radius_m=None)


def map_contains(map_data: MapData, lat: float, lon: float) -> bool:
    """Whether a point lies inside the map's extract bounds."""
    if map_data.bounds is None:
        return True
    s, w, n, e = map_data.bounds
    return s <= lat <= n and w <= lon <= e


def geocode_title_in_maps(
    title: str,
    maps: Sequence[MapData],
    *,
    near: tuple[float, float] | None = None,
    radius_m: float | None = None,
    area: str | None = None,
) -> list[TitleMatch]:
    """Geocode a title in several maps (the extracts of a folder).

    With ``near``, only the maps containing it are searched. A title placed in two or more
    maps is ``ambiguous``: the best match of each is returned, marked so.

    Returns
    -------
    Matches, best first (never empty).
    """
    chosen = list(maps)
    if near is not None:
        chosen = [m for m in maps if map_contains(m, near[0], near[1])] or list(maps)
    results: list[list[TitleMatch]] = []
    for m in chosen:
        try:
            results.append(
                geocode_title(title, map_data=m, near=near, radius_m=radius_m, area=area)
            )
        except MapDataError:
            if area is None or len(chosen) == 1:
                raise
    results = [r for r in results if r]
    if not results:
        raise MapDataError(f"area {area!r} is not a named place of any map")
    placed = [r for r in results if r[0].placed]
    if len(placed) >= 2 and near is None:
        out: list[TitleMatch] = []
        where = ", ".join(Path(r[0].source).name for r in placed)
        for r in placed:
            best = r[0]
            best.status = "ambiguous"
            best.reason = f"placed in {len(placed)} extracts ({where}); " + best.reason
            out.append(best)
        out.sort(key=lambda m: -m.score)
        return out
    if placed:
        return placed[0]
    ranked = sorted(results, key=lambda r: -max(m.score for m in r))
    return ranked[0]
