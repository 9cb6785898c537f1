"""Whole-extract maps and searching a title in several extracts (a folder)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from camloc_geo._errors import MapDataError
from camloc_geo.geocode._geocode import (
    SAME_JUNCTION_M,
    TitleMatch,
    check_map,
    check_near,
    geocode_title,
)
from camloc_geo.geodesy import great_circle_m

if TYPE_CHECKING:
    from camloc_geo.osm import MapData

__all__ = [
    "extract_paths",
    "geocode_title_in_maps",
    "map_contains",
    "miss_rank",
    "one_place",
    "whole_map",
]


def one_place(matches: Sequence[TitleMatch]) -> bool:
    """Whether the best matches of several extracts are one place: each a single placement
    (not ``ambiguous`` within its extract) with a point, all within
    :data:`~camloc_geo.geocode._geocode.SAME_JUNCTION_M` of each other (extracts that
    overlap, or one area in two formats, name the same junction)."""
    points = []
    for m in matches:
        if m.status == "ambiguous" or m.lat is None or m.lon is None:
            return False
        points.append((m.lat, m.lon))
    return all(
        great_circle_m(lat1=a[0], lon1=a[1], lat2=b[0], lon2=b[1]) <= SAME_JUNCTION_M
        for i, a in enumerate(points)
        for b in points[i + 1 :]
    )


def miss_rank(match: TitleMatch) -> tuple[float, int]:
    """Sort key of a title's misses in several extracts, most telling first: the highest
    score, then the most names found (an extract where both streets exist but do not meet
    says more than one where neither name exists)."""
    found = sum(1 for n in match.names_matched if n)
    return (-(match.score if match.score == match.score else 0.0), -found)


def folder_miss(reason: str, extract: str, n_searched: int) -> str:
    """A title's miss in every one of several extracts, worded as such.

    The reason of the most telling miss (:func:`miss_rank`) says "this map", where it
    is one extract of the many searched: the reader of a folder search took West Oakland's
    closest street names for the only map's (qa7). With one extract the reason is kept.
    """
    if n_searched < 2 or not reason:
        return reason
    return (
        f"found in none of the {n_searched} extracts searched; the nearest miss is in "
        f"{extract}: {reason}"
    )


def extract_paths(path: str | os.PathLike[str]) -> list[Path]:
    """The OSM extract itself, or every extract in a folder (sorted by name).

    Raises
    ------
    MapDataError
        The path does not exist, or the folder holds no extract.
    """
    from camloc_geo.osm import extract_files

    return [Path(f) for f in extract_files(path)]


def whole_map(path: str | os.PathLike[str]) -> MapData:
    """Load a whole extract, anchored at its centre (the map catalogue's ``file`` area).

    The same map, anchored at the same point, as every front end gets for a point in this
    extract (:class:`camloc_geo.osm.MapCatalogue`), loaded once per process.

    Raises
    ------
    MapDataError
        ``path`` is not a path, or the extract is missing or unreadable.
    """
    from camloc_geo.osm import area_map

    if not isinstance(path, (str, os.PathLike)):
        raise MapDataError(f"an extract's path must be a str or a Path, not {type(path).__name__}")
    p = Path(path).expanduser().absolute()
    return area_map(("file", str(p)))


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

    With ``near``, only the maps containing it are searched (all of them when none does). A
    title placed in two or more maps at different places is ``ambiguous``: the best match of
    each is returned, marked so. With ``near`` and no ``radius_m``, a match farther than
    :data:`FAR_FROM_POINT_M` from it says so in its reason (a point in London and a Baltimore
    title were placed in Baltimore, 6,000 km away, without a word).

    Returns
    -------
    Matches, best first (never empty).

    Raises
    ------
    InputError
        ``near`` or ``radius_m`` as for :func:`geocode_title`.
    MapDataError
        No maps, ``maps`` not a list of :class:`~camloc_geo.osm.MapData`, or ``area`` a
        named place of none of them.
    """
    found = _in_maps(title, maps, near=near, radius_m=radius_m, area=area)
    if near is not None:
        for m in found:
            if m.lat is None or m.lon is None:
                continue
            d = great_circle_m(lat1=near[0], lon1=near[1], lat2=m.lat, lon2=m.lon)
            if d > FAR_FROM_POINT_M:
                far = f"{d / 1000:,.1f} km" if d < 100_000 else f"{d / 1000:,.0f} km"
                m.reason += (
                    f"; {far} from the point given ({near[0]:.5f},{near[1]:.5f}): is it this "
                    "camera's point?"
                )
                if abs(near[1]) <= 90:  # the point with lat and lon swapped is here (qa7)
                    back = great_circle_m(lat1=near[1], lon1=near[0], lat2=m.lat, lon2=m.lon)
                    if back <= FAR_FROM_POINT_M:
                        m.reason += (
                            f" With lat and lon swapped it lies {back:,.0f} m from this match: "
                            "are the list's lat and lon columns the other way round?"
                        )
    return found


FAR_FROM_POINT_M = 1000.0
"""A match this far from the point it was searched near says so in its reason."""


def _in_maps(
    title: str,
    maps: Sequence[MapData],
    *,
    near: tuple[float, float] | None,
    radius_m: float | None,
    area: str | None,
) -> list[TitleMatch]:
    if isinstance(maps, (str, bytes, os.PathLike)) or not hasattr(maps, "__iter__"):
        raise MapDataError(
            f"maps must be a list of MapData (whole_map(path) for each), not {type(maps).__name__}"
        )
    maps = list(maps)
    if not maps:
        raise MapDataError("no maps to search: give at least one MapData")
    for k, m in enumerate(maps):
        check_map(m, f"maps[{k}]")
    near, radius_m = check_near(near, radius_m)
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
    if len(placed) >= 2 and near is None and one_place([r[0] for r in placed]):
        same = sorted(placed, key=lambda r: -r[0].score)[0]
        others = ", ".join(Path(r[0].source).name for r in placed if r is not same)
        same[0].reason += f"; the same junction in {others}"
        return same
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
    ranked = sorted(results, key=lambda r: miss_rank(r[0]))
    miss = ranked[0]
    if miss and miss[0].status == "not_found" and miss[0].source:
        miss[0].reason = folder_miss(miss[0].reason, Path(miss[0].source).name, len(results))
    return miss
