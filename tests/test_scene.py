"""The scene file model: validation errors name the field; presets; JSON Schema."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import pytest
from conftest import SCENES_DIR

from camloc_geo import InputError, SceneError
from camloc_geo.objects import DEFAULT_PRESET, PRESETS, ObjectSize, object_preset
from camloc_geo.scene import SCENE_FORMAT, load_scene, parse_scene, scene_json_schema


@pytest.fixture
def good() -> dict[str, Any]:
    data: dict[str, Any] = json.loads((SCENES_DIR / "good.json").read_text())
    return data


def test_good_scene_loads() -> None:
    scene = load_scene(SCENES_DIR / "good.json")
    assert scene.format == SCENE_FORMAT
    assert scene.image_size == (1920, 1080)
    assert scene.object_size == ObjectSize(4.6, 1.8, 1.45)
    assert len(scene.annotations) == 1
    assert len(scene.annotations[0].vp_lines.length) == 2
    assert scene.base_dir == str(SCENES_DIR.resolve())
    assert scene.image_file() is None


def test_contract_example_parses() -> None:
    """The example of SCENE.md (with its segment placeholders filled in)."""
    data = {
        "format": "camloc-scene/1",
        "id": "cam-042",
        "image": {"width": 1920, "height": 1080, "path": "cam-042.jpg"},
        "prior": {"lat": 39.2851, "lon": -76.6120, "radius_m": 150},
        "object": {"length_m": 4.6, "width_m": 1.8, "height_m": 1.45},
        "camera": {"focal_px": 1400.0, "principal_point": [960, 540]},
        "annotations": [
            {
                "annotator": "w1",
                "axes": {
                    "origin": [812.4, 701.0],
                    "length": [1015.2, 688.9],
                    "width": [760.3, 668.2],
                    "height": [811.9, 640.5],
                },
                "vp_lines": {"length": [[1, 2, 3, 4], [5, 6, 7, 9]], "width": [], "height": []},
            }
        ],
        "references": [{"pixel": [402.0, 880.5], "lat": 39.28512, "lon": -76.61188}],
        "intersection": {
            "corners": [[300.2, 610.0], [1500.8, 590.3]],
            "lat": 39.2852,
            "lon": -76.6119,
            "streets": ["South Broadway", "Eastern Avenue"],
        },
        "landmarks": [{"pixel": [1200, 400], "kind": "building_corner", "name": "Broadway Market"}],
        "street_bearing_deg": 12.5,
        "some_extension": {"kept": True},
    }
    scene = parse_scene(data)
    assert scene.camera.focal_px == 1400.0
    assert scene.intersection is not None
    assert scene.intersection.streets == ["South Broadway", "Eastern Avenue"]
    assert scene.image_file() == Path("cam-042.jpg")


@pytest.mark.parametrize(
    ("filename", "message"),
    [
        ("bad_format_version.json", "format: unknown format version 'camloc-scene/2'"),
        (
            "bad_zero_length.json",
            "object.length_m: must be 1-30 m, the range of road vehicles (got 0)",
        ),
        (
            "bad_negative_width.json",
            "object.width_m: must be 0.4-5 m, the range of road vehicles (got -1.8)",
        ),
        ("bad_missing_axis.json", "annotations[0].axes.height: required field is missing"),
        ("bad_missing_image.json", "image: required field is missing"),
        (
            "bad_nan_pixel.json",
            "malformed JSON in bad_nan_pixel.json: NaN is not a number JSON allows",
        ),
        ("bad_malformed.json", "malformed JSON in bad_malformed.json at line 37, column"),
        (
            "bad_unknown_preset.json",
            "object.preset: unknown object preset 'limousine'; known: bus,",
        ),
    ],
)
def test_bad_scene_files(filename: str, message: str) -> None:
    with pytest.raises(SceneError) as info:
        load_scene(SCENES_DIR / filename)
    assert str(info.value).startswith(message)
    assert isinstance(info.value, InputError)
    assert isinstance(info.value, ValueError)


def test_missing_file() -> None:
    with pytest.raises(SceneError, match="scene file not found"):
        load_scene(SCENES_DIR / "no_such_scene.json")


@pytest.mark.parametrize(
    ("edit", "field", "message"),
    [
        (
            lambda d: d["annotations"][0]["vp_lines"]["width"].__setitem__(0, [1, 2, 3]),
            "annotations[0].vp_lines.width[0][3]",
            "required field is missing",
        ),
        (lambda d: d["object"].__setitem__("height_m", -1), "object.height_m", "must be 0.5-6 m"),
        (
            lambda d: d.__setitem__("image", {"width": 0, "height": 10}),
            "image.width",
            "greater than 0",
        ),
        (
            lambda d: d.__setitem__("image", {"width": "big", "height": 10}),
            "image.width",
            "valid integer",
        ),
        (lambda d: d.pop("format"), "format", "missing; expected 'camloc-scene/1'"),
        (
            lambda d: d.__setitem__("prior", {"lat": 91, "lon": 0}),
            "prior.lat",
            "less than or equal to 90",
        ),
        (
            lambda d: d.__setitem__("street_bearing_deg", float("inf")),
            "street_bearing_deg",
            "finite",
        ),
        (lambda d: d.__setitem__("camera", {"focal_px": 0}), "camera.focal_px", "greater than 0"),
        # was a TypeError ("'int' object is not iterable") from the size check, before the
        # validation: "camloc calibrate: failed: TypeError", exit 1; the QGIS dock's load
        (lambda d: d.__setitem__("annotations", 5), "annotations", "a valid list (got 5)"),
        (lambda d: d.__setitem__("annotations", "x"), "annotations", "a valid list"),
        (
            lambda d: d.__setitem__("landmarks", [{"pixel": [1, 1], "kind": "tree", "name": "x"}]),
            "landmarks[0].kind",
            "Input should be 'building_corner' or 'face_midpoint'",
        ),
    ],
)
def test_parse_errors_name_the_field(
    good: dict[str, Any], edit: Any, field: str, message: str
) -> None:
    data = copy.deepcopy(good)
    edit(data)
    with pytest.raises(SceneError) as info:
        parse_scene(data)
    assert info.value.field == field
    assert str(info.value).startswith(f"{field}: ")
    assert message in str(info.value)


@pytest.mark.parametrize(
    ("where", "value", "swapped"),
    [
        ("prior", {"lat": -76.5935, "lon": 39.2856}, False),  # a valid (if odd) latitude
        ("prior", {"lat": -120.5, "lon": 39.2856}, True),  # a longitude read as latitude
        ("prior", {"lat": 95.0, "lon": 10.0}, True),
        ("prior", {"lat": 300.0, "lon": 10.0}, False),  # no longitude either: no hint
    ],
)
def test_a_latitude_that_is_a_longitude_hints_at_a_swap(
    good: dict[str, Any], where: str, value: dict[str, float], swapped: bool
) -> None:
    """Crowds and spreadsheets give (lon, lat): the refusal says so (found by the absolute
    slips sweep, where such a reference was refused with pydantic's bare range message)."""
    data = copy.deepcopy(good)
    data[where] = {**value, "radius_m": 150}
    if value["lat"] == -76.5935:
        parse_scene(data)
        return
    with pytest.raises(SceneError) as info:
        parse_scene(data)
    assert info.value.field == f"{where}.lat"
    assert ("are lat and lon swapped?" in str(info.value)) is swapped


def test_unknown_preset_is_rejected_when_the_scene_is_read(good: dict[str, Any]) -> None:
    """Not only when the size is first used (a scene with references may never use it)."""
    data = copy.deepcopy(good)
    data["object"] = {"preset": "limousine", "length_m": 5.0}
    with pytest.raises(
        SceneError, match=r"^object\.preset: unknown object preset 'limousine'"
    ) as info:
        parse_scene(data)
    assert info.value.field == "object.preset"


def test_not_an_object() -> None:
    with pytest.raises(SceneError, match="a scene is a JSON object, got list"):
        parse_scene([1, 2])


def test_several_problems_are_counted(good: dict[str, Any]) -> None:
    data = copy.deepcopy(good)
    data["object"] = {"length_m": 0, "width_m": 0}
    with pytest.raises(SceneError, match=r"\(\+1 more problems\)"):
        parse_scene(data)


# --------------------------------------------------------------------------- presets
def test_presets() -> None:
    assert DEFAULT_PRESET == "sedan"
    assert object_preset("sedan") == ObjectSize(4.6, 1.8, 1.45)
    assert object_preset(" Taxi-NY ") == PRESETS["taxi_ny"]
    for name in ("sedan", "suv", "van", "bus"):
        size = PRESETS[name]
        assert 1.0 < size.width_m < size.length_m
        assert 1.0 < size.height_m < 4.0
    with pytest.raises(SceneError, match="unknown object preset 'tank'; known: bus, hatchback"):
        object_preset("tank")


def test_preset_with_overrides(good: dict[str, Any]) -> None:
    data = copy.deepcopy(good)
    data["object"] = {"preset": "suv", "height_m": 1.6}
    assert parse_scene(data).object_size == ObjectSize(4.7, 1.88, 1.6)
    data["object"] = {}
    assert parse_scene(data).object_size == PRESETS["sedan"]


@pytest.mark.parametrize("bad", [0, -1.0, float("nan"), 1e5])
def test_object_size_rejects_nonsense(bad: float) -> None:
    with pytest.raises(SceneError, match=r"object\.length_m: must be a positive size"):
        ObjectSize(bad, 1.8, 1.45)


def test_json_schema() -> None:
    schema = scene_json_schema()
    assert schema["title"] == SCENE_FORMAT
    assert "base_dir" not in schema["properties"]
    assert {"format", "image"} <= set(schema["required"])
    json.dumps(schema)
