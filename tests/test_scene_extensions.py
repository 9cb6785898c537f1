"""Scene extensions (view_hint, object.street, object.front), compass words, the schema."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest

from camloc_geo import SceneError
from camloc_geo.scene import parse_compass, parse_scene, scene_json_schema

DOC = Path(__file__).resolve().parents[1] / "docs" / "scene-format.md"


@pytest.mark.parametrize(
    ("text", "bearing"),
    [
        ("looking north", 0.0),
        ("NB", 0.0),
        ("northbound", 0.0),
        ("Northbound I-5 at Main St", 0.0),
        ("facing SW", 225.0),
        ("(Eastside)", 90.0),
        ("I-95 SB at Exit 4", 180.0),
        ("S/B", 180.0),
        ("Camera 3 - Eastbound", 90.0),
        ("view to the west", 270.0),
        ("looking north-east", 45.0),
        ("towards Southwest", 225.0),
        ("cam looking NNW", 337.5),
        ("Westwards", 270.0),
        ("Broadway (NE)", 45.0),
        ("south-east", 135.0),
        ("(north side)", 0.0),
    ],
)
def test_parse_compass_reads_directions(text: str, bearing: float) -> None:
    assert parse_compass(text) == bearing


@pytest.mark.parametrize(
    "text",
    ["Main St & E 5th St", "SE 5th Ave", "North Ave", "Newark", "boundary rd", "", None, "W" * 600],
)
def test_parse_compass_reads_nothing_from_names(text: str | None) -> None:
    assert parse_compass(text) is None


def _minimal() -> dict[str, Any]:
    return {"format": "camloc-scene/1", "image": {"width": 640, "height": 480}}


def test_view_hint_from_text_or_bearing() -> None:
    data = _minimal()
    data["view_hint"] = {"text": "Main St looking west"}
    scene = parse_scene(data)
    assert scene.view_hint is not None
    assert scene.view_hint.resolved_bearing_deg == 270.0
    assert scene.view_hint.tolerance_deg == 45.0
    data["view_hint"] = {"bearing_deg": -30, "tolerance_deg": 20, "text": "looking north"}
    hint = parse_scene(data).view_hint
    assert hint is not None
    assert hint.resolved_bearing_deg == 330.0  # the bearing wins over the words
    data["view_hint"] = {"text": "Camera 7"}
    hint = parse_scene(data).view_hint
    assert hint is not None
    assert hint.resolved_bearing_deg is None


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        ({"view_hint": {"bearing_deg": 10, "tolerance_deg": 0}}, "view_hint.tolerance_deg"),
        ({"view_hint": {"bearing_deg": 10, "tolerance_deg": 200}}, "view_hint.tolerance_deg"),
        ({"object": {"front": "back"}}, "object.front"),
        ({"object": {"street": 5}}, "object.street"),
    ],
)
def test_extensions_are_validated(edit: dict[str, Any], message: str) -> None:
    with pytest.raises(SceneError, match=f"^{re.escape(message)}"):
        parse_scene({**_minimal(), **edit})


def test_street_and_front() -> None:
    scene = parse_scene({**_minimal(), "object": {"street": "Eastern Avenue", "front": "origin"}})
    assert scene.object.street == "Eastern Avenue"
    assert scene.object.front == "origin"
    assert scene.object_size.length_m == 4.6  # the sedan preset still applies


def test_every_schema_field_is_described() -> None:
    schema = scene_json_schema()
    missing = [k for k, v in schema["properties"].items() if "description" not in v]
    for name, model in schema["$defs"].items():
        assert "description" in model, name
        missing += [
            f"{name}.{k}" for k, v in model.get("properties", {}).items() if "description" not in v
        ]
    assert missing == []
    assert "view_hint" in schema["properties"]
    assert {"street", "front"} <= set(schema["$defs"]["ObjectSpec"]["properties"])


def test_documented_example_parses() -> None:
    text = DOC.read_text(encoding="utf-8")
    block = re.search(r"## Worked example\s+```json\n(.*?)```", text, re.DOTALL)
    assert block is not None
    scene = parse_scene(json.loads(block.group(1)))
    assert scene.view_hint is not None
    assert scene.view_hint.resolved_bearing_deg == 270.0
    assert scene.object.front == "length_end"
    for field in ("view_hint", "street", "front", "excluded_annotators", "clamped_clicks"):
        assert field in text
