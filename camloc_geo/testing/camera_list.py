"""Synthetic camera lists over real extracts (tests and benchmarks).

Each camera watches a real junction of an extract: its title is written from OSM's own
street names in one of the listing styles ("A & B", "12 - A / B looking north", "A at B",
upper case), it may carry a rough point near the junction and a synthetic annotated scene
(:func:`camloc_geo.testing.synthetic.make_located_scene`). The truth goes into extra columns
(``true_lat``, ``true_lon``, ``true_junction``) that the batch reader ignores.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["BAD_ROWS", "make_camera_list"]

_COMPASS = ["looking north", "facing SW", "NB", "looking east", "(Westside)"]

BAD_ROWS = ("unknown_streets", "missing_scene", "far_point", "empty_title", "bad_lat")
"""Kinds of bad rows :func:`make_camera_list` can add."""


def _junctions(map_data: Any) -> list[Any]:
    out = []
    for x in map_data.intersections:
        names = [n for n in x.street_names if n and not n.startswith("(")]
        if len(set(names)) >= 2 and len(x.corners) >= 2 and x.kind == "junction":
            out.append(x)
    return out


_COMPASS_8 = ("north", "NE", "east", "SE", "south", "SW", "west", "NW")


def _true_compass(title: str, heading_deg: float) -> str:
    """The title with its compass words (if any) replaced by the camera's true heading's."""
    for word in _COMPASS[:3]:
        if title.endswith(" " + word):
            return f"{title[: -len(word)]}looking {_COMPASS_8[round(heading_deg / 45.0) % 8]}"
    return title


def _title(names: Sequence[str], style: int, rng: np.random.Generator) -> str:
    a, b = names[0], names[1]
    if style == 0:
        return f"{a} & {b}"
    if style == 1:
        return f"{int(rng.integers(100, 999))} - {a} / {b} {_COMPASS[int(rng.integers(3))]}"
    if style == 2:
        return f"{a} at {b}"
    return f"{a.upper()} @ {b.upper()}"


def make_camera_list(
    folder: str | Path,
    extracts: Sequence[str | Path],
    n: int,
    *,
    seed: int = 0,
    scene_fraction: float = 0.5,
    point_fraction: float = 0.8,
    strip_scene_junction: float = 0.3,
    bad_rows: Sequence[str] = (),
    name: str = "cameras.csv",
) -> Path:
    """Write a CSV camera list (and its scene files under ``scenes/``) into ``folder``.

    Parameters
    ----------
    extracts
        OSM extracts to take junctions from (cameras spread evenly over them).
    n
        Good cameras (bad rows come on top, one per kind in ``bad_rows``).
    scene_fraction
        Share of cameras with a scene file.
    point_fraction
        Share with a rough point (30 m off the junction, radius 150 m); the others are
        found from their titles alone.
    strip_scene_junction
        Share of scenes whose intersection hint loses its lat/lon (the title must give it).
    """
    from camloc_geo.osm import extract_bounds, load_map
    from camloc_geo.testing.synthetic import make_located_scene

    rng = np.random.default_rng(seed)
    out = Path(folder)
    (out / "scenes").mkdir(parents=True, exist_ok=True)
    maps = []
    for e in extracts:
        path = str(Path(e).absolute())
        s, w, nn, ee = extract_bounds(path)
        m = load_map(path, (s + nn) / 2, (w + ee) / 2, radius_m=None)
        maps.append((m, _junctions(m)))
    rows: list[dict[str, Any]] = []
    k = 0
    while len(rows) < n:
        m, juncs = maps[k % len(maps)]
        k += 1
        x = juncs[int(rng.integers(len(juncs)))]
        names = sorted(set(x.street_names))
        names = [names[i] for i in rng.permutation(len(names))[:2]]
        cam_id = f"cam{len(rows) + 1:04d}"
        row: dict[str, Any] = {
            "id": cam_id,
            "title": _title(names, int(rng.integers(4)), rng),
            "lat": "",
            "lon": "",
            "radius_m": "",
            "scene": "",
            "true_lat": f"{x.lat:.7f}",
            "true_lon": f"{x.lon:.7f}",
            "true_junction": x.id,
        }
        if rng.random() < point_fraction:
            d, az = rng.uniform(0, 30), rng.uniform(0, 2 * math.pi)
            row["lat"] = f"{x.lat + d * math.cos(az) / 111_320:.7f}"
            row["lon"] = (
                f"{x.lon + d * math.sin(az) / (111_320 * math.cos(math.radians(x.lat))):.7f}"
            )
            row["radius_m"] = "150"
        if rng.random() < scene_fraction:
            ls = make_located_scene(m, x, rng, max_tries=200)
            if ls is not None:
                scene = ls.scene
                scene["id"] = cam_id
                if rng.random() < strip_scene_junction:
                    scene["intersection"].pop("lat", None)
                    scene["intersection"].pop("lon", None)
                    scene.pop("prior", None)
                rel = f"scenes/{cam_id}.json"
                (out / rel).write_text(json.dumps(scene), encoding="utf-8")
                row["scene"] = rel
                # a listing's compass words describe the camera it lists
                row["title"] = _true_compass(
                    row["title"], float(ls.camera_enu.angles_deg[0]) % 360.0
                )
                row["true_lat"] = f"{ls.lat:.7f}"
                row["true_lon"] = f"{ls.lon:.7f}"
        rows.append(row)
    j0 = maps[0][1]
    x0 = j0[0]
    for kind in bad_rows:
        cam_id = f"bad_{kind}"
        row = {"id": cam_id, "title": "", "lat": "", "lon": "", "radius_m": "", "scene": ""}
        if kind == "unknown_streets":
            row.update(title="Nowhere Lane & Imaginary Boulevard", lat=f"{x0.lat}", lon=f"{x0.lon}")
        elif kind == "missing_scene":
            row.update(
                title=" & ".join(sorted(set(x0.street_names))[:2]),
                scene="scenes/does_not_exist.json",
            )
        elif kind == "far_point":
            row.update(
                title=" & ".join(sorted(set(x0.street_names))[:2]), lat="-45.0", lon="-120.0"
            )
        elif kind == "empty_title":
            pass
        elif kind == "bad_lat":
            row.update(
                title=" & ".join(sorted(set(x0.street_names))[:2]), lat="north-ish", lon=f"{x0.lon}"
            )
        rows.append(row)
    list_path = out / name
    fields = [
        "id",
        "title",
        "lat",
        "lon",
        "radius_m",
        "scene",
        "true_lat",
        "true_lon",
        "true_junction",
    ]
    with open(list_path, "w", encoding="utf-8", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=fields)
        writer.writeheader()
        for r in rows:
            writer.writerow({f: r.get(f, "") for f in fields})
    return list_path
