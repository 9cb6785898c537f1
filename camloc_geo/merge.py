"""Combine several annotators' scene files of one snapshot into one multi-annotator scene.

Each annotator saves a scene file from the annotation page (``camloc annotate``); the relative
pose is most robust with several of them (the paper's crowd). :func:`merge_scenes` checks that
the files describe the same picture, the same car and the same intersection, and names any
conflict in a :class:`~camloc_geo.SceneError`.
"""

from __future__ import annotations

import copy
import json
import logging
import math
import os
from collections.abc import Sequence
from pathlib import Path, PurePath
from typing import Any

from camloc_geo._errors import SceneError

log = logging.getLogger(__name__)

__all__ = ["merge_scenes"]

_SIZE_TOLERANCE_REL = 0.01
_INTERSECTION_TOLERANCE_M = 40.0
_CORNER_TOLERANCE_DIAG = 0.05


def _load(item: Any, index: int) -> tuple[str, dict[str, Any]]:
    from camloc_geo.scene import Scene, load_scene, parse_scene

    if isinstance(item, Scene):
        return f"scene {index + 1} ({item.id})", item.model_dump(mode="json", exclude_none=True)
    if isinstance(item, dict):
        parse_scene(item)
        return f"scene {index + 1} ({item.get('id', 'scene')})", copy.deepcopy(item)
    if isinstance(item, (str, os.PathLike)):
        path = Path(item)
        try:
            load_scene(path)
        except SceneError as exc:
            raise SceneError(f"{path.name}: {exc}") from None
        data: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
        return path.name, data
    raise SceneError(f"scene {index + 1}: a path, a dict or a Scene, not {type(item).__name__}")


def _size(data: dict[str, Any]) -> tuple[float, float, float]:
    from camloc_geo.scene import parse_scene

    s = parse_scene(data).object_size
    return (s.length_m, s.width_m, s.height_m)


def _image_size(data: dict[str, Any]) -> tuple[int, int]:
    """The image size as parsed numbers (a scene may give ``"width": "1920"`` as text)."""
    from camloc_geo.scene import parse_scene

    return parse_scene(data).image_size


def _car_box(ann: dict[str, Any]) -> tuple[float, float, float, float]:
    pts = [ann["axes"][k] for k in ("origin", "length", "width", "height")]
    o, ln, w = pts[0], pts[1], pts[2]
    pts.append([ln[0] + w[0] - o[0], ln[1] + w[1] - o[1]])  # the fourth ground corner
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    return min(xs), min(ys), max(xs), max(ys)


def _same_car(ref: dict[str, Any], other: dict[str, Any]) -> bool:
    x0, y0, x1, y1 = _car_box(ref)
    mx, my = 0.5 * (x1 - x0) + 10.0, 0.5 * (y1 - y0) + 10.0
    ox, oy = other["axes"]["origin"]
    return bool(x0 - mx <= ox <= x1 + mx and y0 - my <= oy <= y1 + my)


def _unique_name(name: str, taken: set[str]) -> str:
    if name not in taken:
        return name
    k = 2
    while f"{name}-{k}" in taken:
        k += 1
    return f"{name}-{k}"


def _merge_intersection(
    merged: dict[str, Any] | None,
    label_m: str,
    inter: dict[str, Any],
    label: str,
    diag: float,
) -> dict[str, Any]:
    from camloc_geo.geodesy import distance_m

    if merged is None:
        return copy.deepcopy(inter)
    if merged.get("lat") is not None and inter.get("lat") is not None:
        d = float(
            distance_m(lat1=merged["lat"], lon1=merged["lon"], lat2=inter["lat"], lon2=inter["lon"])
        )
        if d > _INTERSECTION_TOLERANCE_M:
            raise SceneError(
                f"{label} marks a different intersection than {label_m}: their positions are "
                f"{d:.0f} m apart"
            )
    if merged.get("streets") and inter.get("streets"):
        a = {s.casefold() for s in merged["streets"]}
        b = {s.casefold() for s in inter["streets"]}
        if not a & b:
            raise SceneError(
                f"{label} marks a different intersection than {label_m}: streets "
                f"{' & '.join(inter['streets'])} vs {' & '.join(merged['streets'])}"
            )
    ca, cb = merged["corners"], inter["corners"]
    if len(ca) != len(cb):
        raise SceneError(
            f"{label} lists {len(cb)} kerb corners, {label_m} {len(ca)}: they disagree on "
            "which corners are visible; correct one of them (camloc annotate --scene)"
        )
    far = [
        i
        for i, (p, q) in enumerate(zip(ca, cb, strict=True))
        if math.hypot(p[0] - q[0], p[1] - q[1]) > _CORNER_TOLERANCE_DIAG * diag
    ]
    if far:
        raise SceneError(
            f"{label} and {label_m} place kerb corner {far[0] + 1} far apart: a different "
            "intersection, or corners listed in another order"
        )
    for key in ("lat", "lon", "streets"):
        if merged.get(key) is None and inter.get(key) is not None:
            merged[key] = copy.deepcopy(inter[key])
    merged.setdefault("_clicks", [[list(p)] for p in ca])
    for i, q in enumerate(cb):
        merged["_clicks"][i].append(list(q))
    return merged


def merge_scenes(scenes: Sequence[Any], *, scene_id: str | None = None) -> dict[str, Any]:
    """Merge annotators' scenes of one snapshot.

    Parameters
    ----------
    scenes
        Two or more scenes (paths, ``camloc-scene/1`` dicts or :class:`Scene` models).
    scene_id
        ``id`` of the merged scene (default: the first scene's).

    Returns
    -------
    A ``camloc-scene/1`` dict: the first scene's fields, every annotation (duplicate
    annotator names suffixed ``-2``, ``-3``...), the intersection's corners averaged over
    the annotators who clicked them, references and landmarks pooled (exact duplicates
    dropped).

    Raises
    ------
    SceneError
        A scene does not validate, or the scenes conflict: another image size or file, a
        different car (object size, or an origin away from the first annotator's car), a
        different intersection, different priors or camera values.
    """
    from camloc_geo.geodesy import distance_m
    from camloc_geo.scene import parse_scene

    if len(scenes) < 1:
        raise SceneError("nothing to merge: give at least one scene")
    loaded = [_load(s, i) for i, s in enumerate(scenes)]
    label0, first = loaded[0]
    out = copy.deepcopy(first)
    out.pop("base_dir", None)
    if scene_id:
        out["id"] = scene_id
    w, h = _image_size(first)
    out["image"]["width"], out["image"]["height"] = w, h
    diag = math.hypot(w, h)
    size0 = _size(first)
    ref_ann = (first.get("annotations") or [None])[0]
    ref_label = label0
    annotations: list[dict[str, Any]] = []
    taken: set[str] = set()
    inter: dict[str, Any] | None = None
    inter_label = label0
    references: list[dict[str, Any]] = []
    landmarks: list[dict[str, Any]] = []
    for label, data in loaded:
        img = data["image"]
        wi, hi = _image_size(data)
        if (wi, hi) != (w, h):
            raise SceneError(
                f"{label} is for a {wi}x{hi} image, {label0} for {w}x{h}: not the same snapshot"
            )
        p0, p1 = first["image"].get("path"), img.get("path")
        if p0 and p1 and PurePath(p0).name != PurePath(p1).name:
            raise SceneError(
                f"{label} annotates {PurePath(p1).name}, {label0} annotates "
                f"{PurePath(p0).name}: not the same snapshot"
            )
        size = _size(data)
        if any(abs(a - b) > _SIZE_TOLERANCE_REL * b for a, b in zip(size, size0, strict=True)):
            raise SceneError(
                f"{label} describes a different car than {label0}: object "
                f"{'x'.join(f'{v:g}' for v in size)} m vs {'x'.join(f'{v:g}' for v in size0)} m"
            )
        for key in ("camera", "prior"):
            if data.get(key) and out.get(key) and data[key] != out[key]:
                if key == "prior":
                    a, b = out["prior"], data["prior"]
                    d = float(
                        distance_m(lat1=a["lat"], lon1=a["lon"], lat2=b["lat"], lon2=b["lon"])
                    )
                    if d <= max(a.get("radius_m", 150.0), b.get("radius_m", 150.0)):
                        continue
                    raise SceneError(f"{label}'s prior is {d:.0f} m from {label0}'s")
                raise SceneError(f"{label} gives other camera values than {label0}: {data[key]}")
            if data.get(key) and not out.get(key):
                out[key] = copy.deepcopy(data[key])
        for ann in data.get("annotations") or []:
            if ref_ann is None:
                ref_ann, ref_label = ann, label
            elif not _same_car(ref_ann, ann):
                raise SceneError(
                    f"{label} ({ann.get('annotator', 'anonymous')}) marks a different car than "
                    f"{ref_label}: its origin {ann['axes']['origin']} is away from that car"
                )
            a = copy.deepcopy(ann)
            name = _unique_name(str(a.get("annotator", "anonymous")), taken)
            taken.add(name)
            a["annotator"] = name
            annotations.append(a)
        if data.get("intersection"):
            if inter is None:
                inter_label = label
            inter = _merge_intersection(inter, inter_label, data["intersection"], label, diag)
        if not any(data.get(k) for k in ("annotations", "intersection", "references", "landmarks")):
            # (an annotator's file saved before any click was merged without a word)
            log.warning(
                "%s adds nothing to the merge: no annotation, kerb corner, reference or "
                "landmark in it",
                label,
            )
        for src, dst in ((data.get("references"), references), (data.get("landmarks"), landmarks)):
            for item in src or []:
                if item not in dst:
                    dst.append(copy.deepcopy(item))
    out["annotations"] = annotations
    if inter is not None:
        clicks = inter.pop("_clicks", None)
        if clicks:
            inter["corners"] = [
                [sum(p[0] for p in c) / len(c), sum(p[1] for p in c) / len(c)] for c in clicks
            ]
        out["intersection"] = inter
    if references:
        out["references"] = references
    if landmarks:
        out["landmarks"] = landmarks
    parse_scene(out)
    return out
