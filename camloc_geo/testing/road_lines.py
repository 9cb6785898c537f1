"""Scenes whose length lines are a few long road lines and many short car edges.

Issue 28's case: on a 960×540 street video each annotator drew one long lane line
(500-1000 px, 1 px endpoint noise) along the street and two or three short pieces of the
car's own edges (20-90 px, same noise). The long lines pin the street's vanishing point;
the short edges barely constrain it, and a screen that trusts every line alike takes its
reference from them and leaves the long lines out.

:func:`street_scene` is the annotated scene of
:func:`camloc_geo.testing.traffic_render.render_street`: the parked reference car as
:func:`~camloc_geo.testing.synthetic.make_scene` annotates it, and the painted lane lines
of the rendered street (:data:`LANE_MARKINGS_Y`) that each annotator also draws
(:func:`add_lane_lines`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from camloc_geo.camera import Camera
from camloc_geo.testing.synthetic import (
    NoiseModel,
    SyntheticScene,
    _visible_segment,
    make_scene,
    random_camera,
)

__all__ = [
    "LANE_MARKINGS_Y",
    "add_lane_lines",
    "long_line_lengths",
    "road_line_scene",
    "street_noise",
    "street_scene",
]

# The painted lines along the street that traffic_render's asphalt texture draws (world y,
# metres; the street runs along x): the solid edge lines at -1.8 and -12.2 and the dashed
# lane lines between them. They run from x = -90 to 110 m.
LANE_MARKINGS_Y = (-1.8, -4.25, -7.0, -9.75, -12.2)
_MARKINGS_X = (-90.0, 110.0)
_MIN_LANE_LINE_PX = 200.0  # shorter visible stretches are not drawn


def street_noise(click_px: float = 1.0) -> NoiseModel:
    """The annotators' noise of the street scenes: ``click_px`` for clicks and line ends."""
    return NoiseModel(
        point_px=click_px,
        line_px=click_px,
        wrong_corner_prob=0.0,
        sloppy_prob=0.0,
        size_rel=0.0,
        car_yaw_deg=0.0,
    )


def add_lane_lines(
    scene: dict[str, Any],
    camera: Camera,
    rng: np.random.Generator,
    *,
    line_px: float = 1.0,
    per_annotator: tuple[int, int] = (1, 2),
    extent: float = 0.6,
) -> None:
    """Add to each annotator's length lines the painted lane lines they draw (in place).

    Each annotator draws ``per_annotator`` (inclusive range) of the painted lines
    (:data:`LANE_MARKINGS_Y`) whose visible stretch is at least 200 px long, each along a
    random part of at least ``extent`` of that stretch (annotators rarely draw a line to the
    image border), with ``line_px`` Gaussian noise on each end.
    """
    size = (int(scene["image"]["width"]), int(scene["image"]["height"]))
    visible = []
    for y in LANE_MARKINGS_Y:
        a = np.array([_MARKINGS_X[0], y, 0.0])
        b = np.array([_MARKINGS_X[1], y, 0.0])
        seg = _visible_segment(camera, a, b, size)
        if seg is not None and float(np.hypot(*(seg[2:] - seg[:2]))) >= _MIN_LANE_LINE_PX:
            visible.append(seg)
    if not visible:
        return
    for ann in scene["annotations"]:
        k = min(int(rng.integers(per_annotator[0], per_annotator[1] + 1)), len(visible))
        for i in rng.choice(len(visible), k, replace=False):
            seg = visible[int(i)]
            start = float(rng.uniform(0.0, 1.0 - extent))
            stop = float(rng.uniform(start + extent, 1.0))
            ends = np.r_[
                seg[:2] + start * (seg[2:] - seg[:2]), seg[:2] + stop * (seg[2:] - seg[:2])
            ]
            ann["vp_lines"]["length"].append([float(v) for v in ends + rng.normal(0, line_px, 4)])


def street_scene(
    camera: Camera,
    seed: int,
    *,
    click_px: float = 1.0,
    image_size: tuple[int, int] = (960, 540),
) -> SyntheticScene:
    """The annotated scene of :func:`~camloc_geo.testing.traffic_render.render_street`.

    Three annotators click the parked reference sedan at the origin
    (:func:`~camloc_geo.testing.synthetic.make_scene`, noise ``default_rng(seed + 7)``, as
    before the lane lines) and each draws one or two of the street's painted lane lines
    (:func:`add_lane_lines`, ``default_rng(seed + 11)``), all with ``click_px`` noise (0:
    exact).
    """
    syn = make_scene(
        camera,
        np.random.default_rng(seed + 7),
        noise=street_noise(click_px),
        n_annotators=3,
        image_size=image_size,
    )
    add_lane_lines(syn.scene, camera, np.random.default_rng(seed + 11), line_px=click_px)
    return syn


def road_line_scene(
    seed: int,
    *,
    image_size: tuple[int, int] = (960, 540),
    n_annotators: int = 3,
    line_px: float = 1.0,
    edge_px: float | None = None,
) -> SyntheticScene:
    """A street camera 6-9 m up; each annotator's length lines: short car edges + one road line.

    Parameters
    ----------
    seed
        Random seed (camera, noise, the road line's offset).
    image_size
        ``(width, height)`` pixels.
    n_annotators
        Annotators, each with 2-3 short car edges and one long lane line for the length axis
        (their width and height lines and clicks as
        :func:`camloc_geo.testing.synthetic.make_scene`).
    line_px
        Endpoint noise of the lane lines and of the other axes' lines, pixels.
    edge_px
        Endpoint noise of the short car edges (default ``line_px``).

    Returns
    -------
    SyntheticScene
        The scene dict and its truth; the long line is the last of each annotator's length
        lines.
    """
    rng = np.random.default_rng(seed)
    edge_noise = line_px if edge_px is None else edge_px
    cam = random_camera(
        rng, image_size=image_size, height_m=(6.0, 9.0), distance_m=(12.0, 25.0), roll_deg=2.0
    )
    noise = NoiseModel(
        point_px=1.0, line_px=line_px, wrong_corner_prob=0.0, sloppy_prob=0.0, size_rel=0.0
    )
    syn = make_scene(cam, rng, noise=noise, n_annotators=n_annotators, image_size=image_size)
    size = syn.true_size
    length, width, height = size.length_m, size.width_m, size.height_m
    edges = [
        ((0.0, 0.0, 0.3), (length, 0.0, 0.3)),
        ((0.0, 0.0, 0.8 * height), (length, 0.0, 0.8 * height)),
        ((0.0, width, 0.3), (length, width, 0.3)),
    ]
    for ann in syn.scene["annotations"]:
        lines: list[list[float]] = []
        for p, q in edges:
            seg = _visible_segment(cam, np.array(p), np.array(q), image_size)
            if seg is None:
                continue
            a = rng.uniform(0.0, 0.3)
            b = a + rng.uniform(0.3, 0.5)  # a piece of the edge: a car edge is rarely whole
            piece = np.r_[seg[:2] + a * (seg[2:] - seg[:2]), seg[:2] + b * (seg[2:] - seg[:2])]
            lines.append([float(v) for v in piece + rng.normal(0.0, edge_noise, 4)])
        y = -float(rng.uniform(2.0, 5.0))  # a lane line beside the car
        seg = _visible_segment(cam, np.array([-60.0, y, 0.0]), np.array([60.0, y, 0.0]), image_size)
        if seg is not None:
            lines.append([float(v) for v in seg + rng.normal(0.0, line_px, 4)])
        ann["vp_lines"]["length"] = lines
    return syn


def long_line_lengths(scene: dict[str, Any]) -> list[float]:
    """Length (px) of each annotator's last length line: the road line."""
    out = []
    for ann in scene["annotations"]:
        x1, y1, x2, y2 = ann["vp_lines"]["length"][-1]
        out.append(float(np.hypot(x2 - x1, y2 - y1)))
    return out
