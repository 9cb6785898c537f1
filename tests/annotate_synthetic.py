"""A synthetic snapshot for the annotation page: a known camera at a real Baltimore junction.

The picture is drawn with OpenCV from :mod:`camloc_geo.testing.synthetic` geometry: ground and
sky split at the true horizon, the car's box, the scene lines the synthetic annotator uses and
the kerb corners. The scene dict holds the exact pixels a careful person would click.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from camloc_geo.osm import load_map
from camloc_geo.testing.synthetic import LocatedScene, NoiseModel, make_located_scene

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"
BALTIMORE = OSM / "baltimore.osm.pbf"


@lru_cache(maxsize=1)
def located_case() -> LocatedScene:
    """A noise-free located scene with one annotator (camera truth in ``camera_world``)."""
    m = load_map(BALTIMORE, 39.2851, -76.5934, radius_m=300)
    inter = next(i for i in m.intersections if i.kind == "junction" and len(i.corners) >= 3)
    ls = make_located_scene(
        m,
        inter,
        np.random.default_rng(1),
        noise=NoiseModel.exact(),
        corner_sigma_m=0.0,
        min_corners=2,
        n_annotators=1,
    )
    assert ls is not None
    ls.scene["id"] = "synthetic-baltimore"
    return ls


def render_snapshot(ls: LocatedScene, *, quality: int = 90) -> bytes:
    """The scene's snapshot as JPEG bytes."""
    import cv2

    w, h = ls.scene["image"]["width"], ls.scene["image"]["height"]
    cam = ls.camera_world
    img = np.zeros((h, w, 3), np.uint8)
    a, b, c = cam.horizon_line()
    ys = np.arange(h)[:, None] + 0.5
    xs = np.arange(w)[None, :] + 0.5
    ground = (a * xs + b * ys + c) > 0
    img[:] = (235, 206, 170)  # sky (BGR)
    img[ground] = (95, 100, 104)  # asphalt
    rng = np.random.default_rng(0)
    img = np.clip(img.astype(np.int16) + rng.integers(-6, 7, img.shape), 0, 255).astype(np.uint8)

    def pt(p: np.ndarray) -> tuple[int, int]:
        # cv2 draws at integer pixel indices: continuous (x, y) is index (x - 0.5, y - 0.5)
        return round(float(p[0]) * 16 - 8), round(float(p[1]) * 16 - 8)

    def line(p: np.ndarray, q: np.ndarray, colour: tuple[int, int, int], width: int) -> None:
        cv2.line(img, pt(p), pt(q), colour, width, cv2.LINE_AA, shift=4)

    ann = ls.scene["annotations"][0]
    for k, colour in (
        ("length", (240, 240, 240)),
        ("width", (200, 230, 255)),
        ("height", (60, 60, 60)),
    ):
        for s in ann["vp_lines"][k]:
            line(np.array(s[:2]), np.array(s[2:]), colour, 3)
    size = ls.scene["object"]
    L, W, H = size["length_m"], size["width_m"], size["height_m"]
    wend = np.array(ann["axes"]["width"])
    # width sign: which side the width end is on, from the exact projections
    ws = 1.0
    pw = cam.project([0.0, W, 0.0])
    if np.linalg.norm(pw - wend) > np.linalg.norm(cam.project([0.0, -W, 0.0]) - wend):
        ws = -1.0
    box = np.array([[x, y, z] for x in (0, L) for y in (0, ws * W) for z in (0, H)])
    pix = cam.project(box)
    body = cv2.convexHull(np.round(pix * 16 - 8).astype(np.int32))
    cv2.fillConvexPoly(img, body, (40, 40, 170), cv2.LINE_AA, shift=4)
    for i in range(8):
        for j in range(i + 1, 8):
            if np.sum(box[i] != box[j]) == 1:
                line(pix[i], pix[j], (20, 220, 255), 2)
    for p in ls.scene["intersection"]["corners"]:
        q = np.array(p)
        dx, dy = np.array([14.0, 0.0]), np.array([0.0, 14.0])
        line(q - dx, q + dx, (255, 255, 255), 2)
        line(q - dy, q + dy, (255, 255, 255), 2)
        cv2.circle(img, pt(q), 6 * 16, (0, 200, 0), 2, cv2.LINE_AA, shift=4)
    ok, buf = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, quality])
    assert ok
    return bytes(buf)
