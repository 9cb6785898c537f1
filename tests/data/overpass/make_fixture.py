"""Rebuild the recorded Overpass responses from the Baltimore extract (run by hand).

The responses mimic what Overpass returns (``[out:json]``) for osmnx's street query
(``baltimore_streets.json``) and building query (``baltimore_buildings.json``) around
Eastern Avenue & South Bond Street, Baltimore. Data © OpenStreetMap contributors, ODbL 1.0
(from ``data/osm/baltimore.osm.pbf``, see its SOURCES.md).

    python tests/data/overpass/make_fixture.py
"""

from __future__ import annotations

import json
from pathlib import Path

import osmium

HERE = Path(__file__).resolve().parent
EXTRACT = HERE.parents[2] / "data" / "osm" / "baltimore.osm.pbf"
SOUTH, WEST, NORTH, EAST = 39.2840, -76.5970, 39.2870, -76.5937
STREETS = {"primary", "secondary", "tertiary", "residential", "unclassified"}


def main() -> None:
    streets: list[dict] = []
    buildings: list[dict] = []
    nodes_s: dict[int, dict] = {}
    nodes_b: dict[int, dict] = {}
    fp = (
        osmium.FileProcessor(str(EXTRACT), osmium.osm.NODE | osmium.osm.WAY)
        .with_locations()
        .with_filter(osmium.filter.EntityFilter(osmium.osm.WAY))
        .with_filter(osmium.filter.KeyFilter("highway", "building"))
    )
    for way in fp:
        locs = [(n.ref, n.location.lat, n.location.lon) for n in way.nodes]
        if not any(SOUTH <= y <= NORTH and WEST <= x <= EAST for _r, y, x in locs):
            continue
        is_street = way.tags.get("highway") in STREETS
        is_building = "building" in way.tags
        if not (is_street or is_building):
            continue
        elem = {
            "type": "way",
            "id": way.id,
            "nodes": [r for r, _y, _x in locs],
            "tags": dict(way.tags),
        }
        target, nodes = (streets, nodes_s) if is_street else (buildings, nodes_b)
        target.append(elem)
        for r, y, x in locs:
            nodes[r] = {"type": "node", "id": r, "lat": round(y, 7), "lon": round(x, 7)}
    for name, ways, nodes in (
        ("baltimore_streets.json", streets, nodes_s),
        ("baltimore_buildings.json", buildings, nodes_b),
    ):
        doc = {
            "version": 0.6,
            "generator": "Overpass API (recorded for camloc_geo tests)",
            "osm3s": {
                "copyright": "The data included in this document is from "
                "www.openstreetmap.org. The data is made available under ODbL."
            },
            "elements": list(nodes.values()) + ways,
        }
        (HERE / name).write_text(json.dumps(doc, separators=(",", ":")), encoding="utf-8")
        print(name, len(ways), "ways", len(nodes), "nodes")


if __name__ == "__main__":
    main()
