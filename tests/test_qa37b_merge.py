"""camloc merge compares the parsed image size, not the raw JSON values (QA sweep 37b)."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest
from annotate_synthetic import located_case

from camloc_geo._errors import SceneError
from camloc_geo.cli import main
from camloc_geo.merge import merge_scenes


def test_width_given_as_text_is_the_same_snapshot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a = copy.deepcopy(located_case().scene)
    b = copy.deepcopy(a)
    a["annotations"][0]["annotator"] = "w1"
    b["annotations"][0]["annotator"] = "w2"
    b["image"]["width"] = str(a["image"]["width"])
    b["image"]["height"] = str(a["image"]["height"])
    merged = merge_scenes([b, a])
    assert merged["image"]["width"] == a["image"]["width"]
    assert isinstance(merged["image"]["width"], int)
    assert [x["annotator"] for x in merged["annotations"]] == ["w2", "w1"]
    paths = []
    for i, s in enumerate((a, b)):
        p = tmp_path / f"s{i}.json"
        p.write_text(json.dumps(s))
        paths.append(str(p))
    out = tmp_path / "m.json"
    assert main(["merge", *paths, "-o", str(out)]) == 0
    assert "not the same snapshot" not in capsys.readouterr().err
    assert len(json.loads(out.read_text())["annotations"]) == 2


def test_other_size_as_text_still_refused(tmp_path: Path) -> None:
    a = copy.deepcopy(located_case().scene)
    b = copy.deepcopy(a)
    b["image"]["width"] = "3840"
    b["image"]["height"] = "2160"
    with pytest.raises(SceneError, match=r"3840x2160 image.*1920x1080: not the same snapshot"):
        merge_scenes([a, b])
