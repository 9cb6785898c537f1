"""Session 38 QA: list points in the wrong CRS or with lat and lon swapped.

- A GeoJSON list exported in Web Mercator (a QGIS layer saved without reprojecting) gave
  ``lat=4763120.0, lon=-8526410.0 is not a point on Earth``: now it says they look like
  projected metres and asks for EPSG:4326. A camera of such a list with no title ended
  ``no_evidence`` without naming the unusable point at all.
- A list with lat and lon the other way round ended ``no_map`` ("outside every extract")
  with no word of the swap; the reason now says the swapped point lies in a map.
"""

from __future__ import annotations

import json
from pathlib import Path

import pyogrio

from camloc_geo.batch import run_batch

REPO = Path(__file__).resolve().parents[1]


def _maps(tmp_path: Path) -> Path:
    folder = tmp_path / "maps"
    folder.mkdir()
    (folder / "baltimore.osm.pbf").symlink_to(REPO / "sample_maps" / "baltimore.osm.pbf")
    (folder / "frederiksted.osm.pbf").symlink_to(REPO / "data" / "osm" / "frederiksted.osm.pbf")
    return folder


def _reasons(tmp_path: Path, features: list[dict[str, object]]) -> dict[str, tuple[str, str]]:
    lst = tmp_path / "cams.geojson"
    lst.write_text(json.dumps({"type": "FeatureCollection", "features": features}), "utf-8")
    out = tmp_path / "out.gpkg"
    run_batch(lst, out_gpkg=out, map_source=_maps(tmp_path), progress=False, workers=1)
    df = pyogrio.read_dataframe(out, layer="cameras")
    return {str(r["id"]): (str(r["status"]), str(r["reason"])) for _i, r in df.iterrows()}


def _feature(fid: str, x: float, y: float, title: str | None) -> dict[str, object]:
    props: dict[str, object] = {"id": fid}
    if title:
        props["title"] = title
    return {
        "type": "Feature",
        "geometry": {"type": "Point", "coordinates": [x, y]},
        "properties": props,
    }


def test_projected_and_swapped_points_are_named(tmp_path: Path) -> None:
    got = _reasons(
        tmp_path,
        [
            _feature("m1", -8526410.0, 4763120.0, "Eastern Ave & S Broadway"),
            _feature("m2", -8526410.0, 4763120.0, None),
            _feature("s1", 39.2856, -76.5935, "Nowhere & Fake"),  # [lat, lon]
        ],
    )
    status, reason = got["m1"]
    assert status == "title_only"
    assert "projected coordinates, in metres?" in reason
    assert "EPSG:4326" in reason
    status, reason = got["m2"]
    assert status == "no_evidence"
    assert "is not a point on Earth (projected coordinates" in reason
    status, reason = got["s1"]
    assert status == "no_map"
    assert "with lat and lon swapped, lat=39.285600, lon=-76.593500 lies in a map" in reason
    assert "baltimore.osm.pbf" in reason.split("swapped", 1)[1]
