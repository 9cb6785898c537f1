"""Regenerate the small scene files of this folder: ``python tests/data/scenes/make_scenes.py``.

``good.json`` is a noise-free view (rounded to 0.01 px) of a 6 m high camera 20 m from the car
by one annotator; every ``bad_*.json`` breaks one rule of ``camloc-scene/1`` or one geometric
requirement, as its name says. ``level_along_car.json`` is a level camera looking along the
car: the width and height lines are parallel in the image, so the focal length is unknown
unless the scene gives it (``level_along_car_focal.json``).
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from camloc_geo.camera import Camera, rotation_from_angles
from camloc_geo.testing.synthetic import NoiseModel, make_scene

HERE = Path(__file__).parent


def _rounded(value: Any) -> Any:
    if isinstance(value, float):
        return round(value, 2)
    if isinstance(value, list):
        return [_rounded(v) for v in value]
    if isinstance(value, dict):
        return {k: _rounded(v) for k, v in value.items()}
    return value


def _scene(camera: Camera, seed: int) -> dict[str, Any]:
    syn = make_scene(camera, np.random.default_rng(seed), noise=NoiseModel.exact(), n_annotators=1)
    scene = syn.scene
    for ann in scene["annotations"]:
        ann["vp_lines"] = {k: v[:2] for k, v in ann["vp_lines"].items()}
    return _rounded(scene)


def _write(name: str, scene: dict[str, Any]) -> None:
    (HERE / name).write_text(json.dumps(scene, indent=1) + "\n", encoding="utf-8")


def main() -> None:
    az = math.radians(225.0)
    centre = np.array([20 * math.cos(az), 20 * math.sin(az), 6.0])
    fwd = np.array([2.3, 0.9, 0.7]) - centre
    heading = math.degrees(math.atan2(fwd[0], fwd[1]))
    pitch = math.degrees(math.atan2(-fwd[2], math.hypot(fwd[0], fwd[1])))
    cam = Camera.from_center(
        1400.0, (960.0, 540.0), rotation_from_angles(heading, pitch, 3.0), centre
    )
    good = _scene(cam, 0)
    _write("good.json", good)

    s = copy.deepcopy(good)
    s["annotations"][0]["vp_lines"]["height"] = s["annotations"][0]["vp_lines"]["height"][:1]
    _write("bad_one_height_line.json", s)

    s = copy.deepcopy(good)
    axes = s["annotations"][0]["axes"]
    o, e = np.array(axes["origin"]), np.array(axes["length"])
    axes["width"] = _rounded((o + 0.4 * (e - o)).tolist())
    _write("bad_collinear_axes.json", s)

    s = copy.deepcopy(good)
    s["annotations"][0]["axes"]["origin"] = [2500.0, 700.0]
    _write("bad_pixel_outside.json", s)

    s = copy.deepcopy(good)
    s["object"]["length_m"] = 0
    _write("bad_zero_length.json", s)

    s = copy.deepcopy(good)
    s["object"]["width_m"] = -1.8
    _write("bad_negative_width.json", s)

    s = copy.deepcopy(good)
    s["format"] = "camloc-scene/2"
    _write("bad_format_version.json", s)

    s = copy.deepcopy(good)
    del s["annotations"][0]["axes"]["height"]
    _write("bad_missing_axis.json", s)

    s = copy.deepcopy(good)
    del s["image"]
    _write("bad_missing_image.json", s)

    s = copy.deepcopy(good)
    s["object"] = {"preset": "limousine"}
    _write("bad_unknown_preset.json", s)

    text = (HERE / "good.json").read_text(encoding="utf-8")
    first = str(good["annotations"][0]["axes"]["origin"][0])
    (HERE / "bad_nan_pixel.json").write_text(text.replace(first, "NaN", 1), encoding="utf-8")
    (HERE / "bad_malformed.json").write_text(text[: len(text) // 2], encoding="utf-8")

    # Level camera looking along +x, 20 m behind the car.
    level = Camera.from_center(
        1400.0, (960.0, 540.0), rotation_from_angles(90.0, 0.0, 0.0), [-20.0, 0.9, 1.5]
    )
    s = _scene(level, 1)
    _write("level_along_car.json", s)
    s["camera"] = {"focal_px": 1400.0}
    _write("level_along_car_focal.json", s)


if __name__ == "__main__":
    main()
