"""Session 40 QA: a JSON camera list's object or list where text belongs went unsaid.

``POST /v1/jobs`` with ``{"cameras": [{"id": {"a": 1}, "title": "..."}]}`` was accepted and
the camera's id became the Python repr ``"{'a': 1}"``; a title given as a list was searched
for as ``"['A', 'B']"``. Both are now row problems (in the camera's ``reason``, as a bad
``lat`` is), the id kept as JSON text, the title dropped.
"""

from __future__ import annotations

import pytest

from camloc_geo.cameras import row_from_mapping


def test_an_object_id_is_named_and_kept_as_json_text() -> None:
    row = row_from_mapping({"id": {"a": 1}, "title": "Eastern Ave & S Broadway"}, 1)
    assert row.id == '{"a": 1}'
    assert row.title == "Eastern Ave & S Broadway"
    assert row.problems == ("id '{\"a\": 1}' is not text or a number",)


def test_a_list_title_is_named_and_not_searched_for() -> None:
    row = row_from_mapping({"id": 7, "title": ["Eastern Ave", "S Broadway"]}, 2)
    assert row.id == "7"  # a number is an id, as before
    assert row.title == ""
    assert row.problems == ('title \'["Eastern Ave", "S Broadway"]\' is not text or a number',)


def test_merge_names_a_file_that_adds_nothing(caplog: pytest.LogCaptureFixture) -> None:
    """An annotator's file saved before any click (no annotation, corner, reference or
    landmark) was merged without a word; the merge now says which file added nothing."""
    import copy
    import json
    import logging
    from pathlib import Path

    from camloc_geo.merge import merge_scenes

    sample = Path(__file__).resolve().parents[1] / "sample_maps" / "sample_scene.json"
    full = json.loads(sample.read_text(encoding="utf-8"))
    empty = copy.deepcopy(full)
    empty["annotations"] = []
    for key in ("intersection", "references", "landmarks"):
        empty.pop(key, None)
    with caplog.at_level(logging.WARNING, logger="camloc_geo.merge"):
        merged = merge_scenes([full, empty])
    assert len(merged["annotations"]) == len(full["annotations"])
    said = [r.getMessage() for r in caplog.records]
    assert len(said) == 1
    assert said[0].startswith("scene 2 (baltimore-eastern-broadway) adds nothing to the merge")


def test_a_scene_camera_on_no_map_is_no_map() -> None:
    """A camera with a scene whose point no extract covers (or with no map source at all)
    ended ``no_candidates`` ("this scene needs a map ... and no map covers it"), while a
    titled camera there says ``no_map``: a reader filtering the cameras that need a map
    missed it (seen in camloc:geocodelist without OSM). It is ``no_map`` now, with why."""
    import json
    from pathlib import Path

    from camloc_geo.api import locate_camera

    samples = Path(__file__).resolve().parents[1] / "sample_maps"
    scene = json.loads((samples / "sample_scene.json").read_text(encoding="utf-8"))
    row = row_from_mapping({"id": "s1", "scene": scene}, 1)
    none = locate_camera(row, map_source=None, network=False)
    assert none.status == "no_map"
    assert none.reason.startswith("this scene needs a map (intersection corners, landmarks")
    far = {**scene, "prior": {"lat": 0.5, "lon": -30.0, "radius_m": 150.0}}  # mid-Atlantic
    far_row = row_from_mapping({"id": "s2", "scene": far}, 2)
    outside = locate_camera(far_row, map_source=samples, network=False)  # a folder of extracts
    assert outside.status == "no_map", (outside.status, outside.reason)
    assert "outside" in outside.reason
