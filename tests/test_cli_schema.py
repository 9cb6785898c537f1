"""`camloc schema` prints the scene format's JSON Schema."""

from __future__ import annotations

import json

import pytest


def test_schema_command_prints_the_scene_schema(capsys: pytest.CaptureFixture[str]) -> None:
    from camloc_geo.cli import main

    assert main(["schema"]) == 0
    schema = json.loads(capsys.readouterr().out)
    assert schema["title"] == "camloc-scene/1"
    assert {"format", "image"} <= set(schema["required"])
    assert "annotations" in schema["properties"]
