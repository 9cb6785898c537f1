"""The analyst's annotation of one snapshot, as a ``camloc-scene/1`` dict (no Qt, no qgis).

The steps follow the annotation page: the car's ground corner and the ends of its three
edges, segments parallel to each edge, the visible kerb corners of the intersection in
clockwise order, and the intersection's position picked on the map. Validation of the
finished scene is the library's (``camloc_geo.scene`` through the worker).
"""

from __future__ import annotations

import copy
from typing import Any

SCENE_FORMAT = "camloc-scene/1"

# (key, label, kind): kind "point" (one click, then the next step), "line" (two clicks per
# segment, any number of segments) or "multi" (any number of points).
STEPS = [
    ("origin", "1. Car corner on the ground (origin)", "point"),
    ("length", "2. End of the car's length edge", "point"),
    ("width", "3. End of the car's width edge", "point"),
    ("height", "4. Top of the height edge (roof line)", "point"),
    ("lines_length", "5. Lines parallel to the length (2 clicks each)", "line"),
    ("lines_width", "6. Lines parallel to the width (2 clicks each)", "line"),
    ("lines_height", "7. Vertical lines (2 clicks each)", "line"),
    ("corners", "8. Intersection kerb corners, clockwise on screen", "multi"),
]
STEP_KEYS = [s[0] for s in STEPS]
GUIDANCE = {
    "origin": "Click the corner of the car where its length, width and height edges meet, "
    "on the ground (wheel to zoom, right-drag to pan).",
    "length": "Click the other end of the car's long edge along the ground.",
    "width": "Click the other end of the car's short edge along the ground.",
    "height": "Click straight above the first corner, on the roof line.",
    "lines_length": "Draw lines parallel to the car's length (kerbs, lane marks): two "
    "clicks each, as many as you see; at least one.",
    "lines_width": "Draw lines parallel to the car's width (stop lines, crossings): two "
    "clicks each; at least one.",
    "lines_height": "Draw vertical lines (poles, building edges): two clicks each; optional.",
    "corners": "Click the visible kerb corners of the intersection, clockwise on screen; then "
    "pick the intersection on the map or name its streets.",
}
"""What to do at each step, in words shown above the snapshot."""
AXES = ("origin", "length", "width", "height")


def _r(v: float) -> float:
    return round(float(v), 1)


class Annotation:
    """Clicks of one analyst on one snapshot."""

    def __init__(self, width: int = 0, height: int = 0, scene_id: str = "scene") -> None:
        self.width = int(width)
        self.height = int(height)
        self.scene_id = scene_id
        self.image_path: str | None = None
        self.annotator = "qgis"
        self.preset = "sedan"
        self.axes: dict[str, list[float]] = {}
        self.lines: dict[str, list[list[float]]] = {"length": [], "width": [], "height": []}
        self.corners: list[list[float]] = []
        self.streets: list[str] = []
        self.lat: float | None = None
        self.lon: float | None = None
        # the point is the scene's prior only (not a junction picked on the map or named by
        # the scene's intersection): written back as the prior, never as the junction (qa7)
        self.point_is_prior = False
        self.radius_m = 150.0
        self.view_hint: str = ""
        self.step = STEP_KEYS[0]
        self.pending: list[float] | None = None
        self.base: dict[str, Any] | None = None  # a scene from elsewhere (the browser page)

    @classmethod
    def from_scene(cls, scene: dict[str, Any]) -> Annotation:
        """An annotation holding a scene made elsewhere (its first annotation editable here).

        Everything the dock does not edit (more annotators, references, landmarks...) is kept
        as it came and written back by :meth:`to_scene`.
        """
        image = scene.get("image") or {}
        a = cls(
            int(image.get("width") or 0), int(image.get("height") or 0), scene.get("id") or "scene"
        )
        a.base = copy.deepcopy(scene)
        a.image_path = image.get("path")
        obj = scene.get("object") or {}
        a.preset = obj.get("preset") or a.preset
        anns = scene.get("annotations") or []
        if anns:
            first = anns[0]
            a.annotator = first.get("annotator") or a.annotator
            a.axes = {k: list(v) for k, v in (first.get("axes") or {}).items() if k in AXES}
            for k, segs in (first.get("vp_lines") or {}).items():
                if k in a.lines:
                    a.lines[k] = [list(seg) for seg in segs]
        inter = scene.get("intersection") or {}
        a.corners = [list(c) for c in inter.get("corners") or []]
        a.streets = list(inter.get("streets") or [])
        prior = scene.get("prior") or {}
        lat, lon = inter.get("lat", prior.get("lat")), inter.get("lon", prior.get("lon"))
        if lat is not None and lon is not None:
            a.set_location(lat=lat, lon=lon)
            # a scene whose intersection gives no point keeps it so: the prior's point written
            # as the junction's pinned the search to the junction nearest it, and the dock
            # lost the sample's candidate at the cross street a block away that camloc locate
            # gives (13 candidates there, 12 in the dock, and a surer-looking tie)
            a.point_is_prior = inter.get("lat") is None or inter.get("lon") is None
        if prior.get("radius_m"):
            a.radius_m = float(prior["radius_m"])
        hint = scene.get("view_hint") or {}
        if hint.get("bearing_deg") is not None:
            a.view_hint = f"{hint['bearing_deg']:g}"
        elif hint.get("text"):
            a.view_hint = str(hint["text"])
        return a

    # --- editing -------------------------------------------------------------------------
    def set_step(self, key: str) -> None:
        """Make ``key`` the current step (drops a half-drawn line)."""
        if key not in STEP_KEYS:
            raise ValueError(f"unknown step {key!r}")
        self.step = key
        self.pending = None

    def click(self, x: float, y: float) -> str:
        """Record a click at pixel ``(x, y)`` for the current step; what happened."""
        if not (0 <= x <= self.width and 0 <= y <= self.height):
            return "outside the image"
        kind = {k: t for k, _l, t in STEPS}[self.step]
        if kind == "point":
            self.axes[self.step] = [_r(x), _r(y)]
            done = self.step
            nxt = STEP_KEYS.index(self.step) + 1
            self.set_step(STEP_KEYS[nxt])
            return f"{done} set"
        if kind == "line":
            if self.pending is None:
                self.pending = [_r(x), _r(y)]
                return "line started"
            seg = [*self.pending, _r(x), _r(y)]
            self.pending = None
            self.lines[self.step.split("_", 1)[1]].append(seg)
            return "line added"
        self.corners.append([_r(x), _r(y)])
        return f"corner {len(self.corners) - 1} added"

    def undo(self) -> None:
        """Remove the last thing added in the current step."""
        if self.pending is not None:
            self.pending = None
        elif self.step.startswith("lines_"):
            lst = self.lines[self.step.split("_", 1)[1]]
            if lst:
                lst.pop()
        elif self.step == "corners":
            if self.corners:
                self.corners.pop()
        else:
            idx = STEP_KEYS.index(self.step)
            prev = STEP_KEYS[max(idx - 1, 0)]
            self.axes.pop(prev, None)
            self.set_step(prev)

    def set_location(self, *, lat: float, lon: float) -> None:
        """The intersection's position picked on the map (degrees WGS 84)."""
        self.lat = round(float(lat), 7)
        self.lon = round(float(lon), 7)
        self.point_is_prior = False

    # --- checks and output ---------------------------------------------------------------
    def problems(self) -> list[str]:
        """What is still missing before the scene can be located (empty: ready)."""
        out = []
        if not self.width or not self.height:
            out.append("open a snapshot first")
        missing = [a for a in AXES if a not in self.axes]
        if missing:
            out.append("click the car's " + ", ".join(missing))
        for axis in ("length", "width"):
            if len(self.lines[axis]) < 1:
                out.append(f"draw at least one more line parallel to the {axis}")
        if self.corners and (self.lat is None and not self.streets):
            out.append("pick the intersection on the map (or name its streets)")
        if not self.corners and self.lat is None:
            out.append("mark the intersection's corners and pick it on the map")
        return out

    def to_scene(self) -> dict[str, Any]:
        """The ``camloc-scene/1`` dict of this annotation (over :attr:`base`, when set)."""
        scene: dict[str, Any] = copy.deepcopy(self.base) if self.base else {}
        scene["format"] = SCENE_FORMAT
        scene["id"] = self.scene_id
        image = scene.get("image") or {}
        image.update({"width": self.width, "height": self.height})
        if self.image_path:
            image["path"] = self.image_path
        scene["image"] = image
        scene["object"] = {**(scene.get("object") or {}), "preset": self.preset}
        anns = scene.get("annotations") or []
        if all(a in self.axes for a in AXES):
            mine: dict[str, Any] = {
                **(anns[0] if anns else {}),
                "annotator": self.annotator,
                "axes": {a: list(self.axes[a]) for a in AXES},
                "vp_lines": {k: [list(s) for s in v] for k, v in self.lines.items() if v},
            }
            anns = [mine, *anns[1:]]
        elif anns:
            anns = anns[1:]
        if anns:
            scene["annotations"] = anns
        else:
            scene.pop("annotations", None)
        if self.corners:
            inter: dict[str, Any] = {
                **(scene.get("intersection") or {}),
                "corners": [list(c) for c in self.corners],
            }
            if self.lat is not None and self.lon is not None and not self.point_is_prior:
                inter["lat"] = self.lat
                inter["lon"] = self.lon
            if self.streets:
                inter["streets"] = list(self.streets)
            scene["intersection"] = inter
        else:
            scene.pop("intersection", None)
        if self.lat is not None and self.lon is not None:
            scene["prior"] = {"lat": self.lat, "lon": self.lon, "radius_m": self.radius_m}
        hint = self.view_hint.strip()
        if hint:
            try:
                scene["view_hint"] = {"bearing_deg": float(hint)}
            except ValueError:
                scene["view_hint"] = {"text": hint}
        else:
            scene.pop("view_hint", None)
        return scene
