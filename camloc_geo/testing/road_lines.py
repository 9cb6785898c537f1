"""Scenes whose length lines are a few long road lines and many short car edges.

Issue 28's case: on a 960×540 street video each annotator drew one long lane line
(500-1000 px, 1 px endpoint noise) along the street and two or three short pieces of the
car's own edges (20-90 px, same noise). The long lines pin the street's vanishing point;
the short edges barely constrain it, and a screen that trusts every line alike takes its
reference from them and leaves the long lines out.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from camloc_geo.testing.synthetic import (
    NoiseModel,
    SyntheticScene,
    _visible_segment,
    make_scene,
    random_camera,
)

__all__ = ["long_line_lengths", "road_line_scene"]


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
