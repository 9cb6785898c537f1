"""Session 37 QA: scene files read as a user writes them."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import pytest

from camloc_geo._errors import SceneError
from camloc_geo.scene import parse_scene

SAMPLE = Path(__file__).resolve().parents[1] / "sample_maps" / "sample_scene.json"


def _sample() -> dict[str, Any]:
    data: dict[str, Any] = json.loads(SAMPLE.read_text(encoding="utf-8"))
    return data


@pytest.mark.parametrize(
    ("path", "value", "field"),
    [
        (("camera",), {"focal_px": True}, "camera.focal_px"),
        (("image", "width"), True, "image.width"),
        (("prior", "lat"), False, "prior.lat"),
        (("object", "length_m"), True, "object.length_m"),
        (("annotations", 0, "axes", "origin"), [True, 5], "annotations[0].axes.origin"),
    ],
)
def test_true_false_is_not_a_number(path: tuple[Any, ...], value: Any, field: str) -> None:
    """``"focal_px": true`` was read as a 1 px focal length ("implausible, ignored"), a
    ``true`` width as a 1-pixel image, a ``false`` latitude as 0: each is refused, naming
    the field."""
    data = copy.deepcopy(_sample())
    node: Any = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    with pytest.raises(SceneError) as info:
        parse_scene(data)
    assert str(info.value).startswith(f"{field}: true/false is not a number")


def test_numbers_still_read() -> None:
    scene = parse_scene(_sample())
    assert scene.image.width == 1920
    assert scene.annotations[0].axes.origin[0] == pytest.approx(
        _sample()["annotations"][0]["axes"]["origin"][0]
    )
