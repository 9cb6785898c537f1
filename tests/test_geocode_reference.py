"""Geocoding titles generated from osmnx's own graph of the repository's extracts.

Every junction title must land within 30 m of the node where osmnx's graph has both names
(or be ``ambiguous`` with one of its places there); titles that must not be placed get
their status.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from geocode_reference import RefTitle, _dist_m, reference_titles

from camloc_geo.geocode import geocode_title, whole_map

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"
EXTRACTS = ["berlin_alexanderplatz.osm.pbf", "paris_bss.osm.pbf", "fremantle.osm"]


def _check(ref: RefTitle, map_data) -> str | None:  # type: ignore[no-untyped-def]
    found = geocode_title(
        ref.title, map_data=map_data, near=ref.near, radius_m=300.0 if ref.near else None
    )
    best = found[0]
    if ref.expect != "junction":
        return None if best.status == ref.expect else f"{best.status}: {best.reason}"
    assert ref.lat is not None
    assert ref.lon is not None
    options = [m for m in found if m.status == "ambiguous"] or [best]
    for m in options:
        if m.placed and _dist_m(ref.lat, ref.lon, m.lat, m.lon) <= 30.0:  # type: ignore[arg-type]
            return None
    where = (
        f"{_dist_m(ref.lat, ref.lon, best.lat, best.lon):.0f} m off"  # type: ignore[arg-type]
        if best.placed
        else "no point"
    )
    return f"{best.status} {where}: {best.names_matched} {best.reason}"


@pytest.mark.parametrize("extract", EXTRACTS)
def test_reference_titles(extract: str) -> None:
    path = OSM / extract
    refs = reference_titles(path, max_junctions=40)
    kinds = {r.expect for r in refs}
    assert {"junction", "not_found", "street"} <= kinds
    styles = {r.style for r in refs if r.expect == "junction"}
    assert {"abbrev", "upper", "camera", "typo"} <= styles
    m = whole_map(path)
    failures = [(r.title, r.style, why) for r in refs if (why := _check(r, m)) is not None]
    assert failures == []
