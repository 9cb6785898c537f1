"""Regenerate ``sample_maps/sample_scene.json``: a camera at a real Baltimore intersection.

The scene is synthetic (there is no photograph of it): a camera at Eastern Avenue & South
Broadway (OSM data of the bundled ``baltimore.osm.pbf``), a sedan in a lane of South
Broadway, three annotators with the documented noise of :mod:`camloc_geo.testing.synthetic`, three
visible kerb corners listed clockwise as a person sees them on screen, the streets named.
The true camera position is written next to it (``sample_scene.truth.json``) so the
README's command can be checked against it.

    python sample_maps/make_sample_scene.py
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from camloc_geo.osm import load_map
from camloc_geo.testing.synthetic import NoiseModel, make_located_scene

HERE = Path(__file__).resolve().parent


def main() -> None:
    """Write the sample scene and its truth."""
    m = load_map(HERE / "baltimore.osm.pbf", 39.28558, -76.59348, radius_m=300)
    inter = m.find_intersection("Eastern Avenue & South Broadway")
    rng = np.random.default_rng(2024)
    noise = NoiseModel(point_px=2.0, line_px=1.0, wrong_corner_prob=0.0, sloppy_prob=0.0)
    ls = None
    while ls is None:
        ls = make_located_scene(
            m,
            inter,
            rng,
            noise=noise,
            n_annotators=3,
            min_corners=3,
            max_corners=3,
            give_streets=True,
        )
    scene = ls.scene
    scene["id"] = "baltimore-eastern-broadway"
    scene["object"] = {"preset": "sedan"}
    for ann in scene["annotations"]:
        ann["axes"] = {k: [round(v, 1) for v in p] for k, p in ann["axes"].items()}
        ann["vp_lines"] = {
            k: [[round(v, 1) for v in seg] for seg in segs] for k, segs in ann["vp_lines"].items()
        }
    scene["intersection"]["corners"] = [
        [round(v, 1) for v in p] for p in scene["intersection"]["corners"]
    ]
    scene["prior"] = {"lat": 39.2856, "lon": -76.5935, "radius_m": 150}
    (HERE / "sample_scene.json").write_text(json.dumps(scene, indent=1) + "\n")
    heading, pitch, roll = ls.camera_enu.angles_deg
    truth = {
        "lat": ls.lat,
        "lon": ls.lon,
        "height_m": ls.camera_enu.height_m,
        "heading_deg": heading,
        "pitch_deg": pitch,
        "roll_deg": roll,
        "focal_px": ls.camera_enu.focal_px,
        "intersection": ls.intersection_id,
        "visible_corner_orders": ls.visible_corner_orders,
    }
    (HERE / "sample_scene.truth.json").write_text(json.dumps(truth, indent=1) + "\n")


if __name__ == "__main__":
    main()
