"""Session 40 QA: a JSON camera list's object or list where text belongs went unsaid.

``POST /v1/jobs`` with ``{"cameras": [{"id": {"a": 1}, "title": "..."}]}`` was accepted and
the camera's id became the Python repr ``"{'a': 1}"``; a title given as a list was searched
for as ``"['A', 'B']"``. Both are now row problems (in the camera's ``reason``, as a bad
``lat`` is), the id kept as JSON text, the title dropped.
"""

from __future__ import annotations

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
