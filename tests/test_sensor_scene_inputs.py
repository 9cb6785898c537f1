"""scene.py and the sensors' readers from Python: a wrong type is an InputError naming it."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camloc_geo import api
from camloc_geo._errors import InputError, SceneError
from camloc_geo.scene import load_scene, parse_compass
from camloc_geo.sensors import guide, radar

SCENE = Path(__file__).resolve().parents[1] / "sample_maps" / "sample_scene.json"

CASES: list[tuple[str, Callable[[], Any], type[Exception], str]] = [
    ("load_scene int", lambda: load_scene(5), SceneError, "must be a str or a Path, not int"),  # type: ignore[arg-type]
    ("load_scene None", lambda: load_scene(None), SceneError, "not NoneType"),  # type: ignore[arg-type]
    ("compass int", lambda: parse_compass(5), InputError, "compass words must be text"),  # type: ignore[arg-type]
    ("format_time text", lambda: guide.format_time("x"), InputError, "not a number"),  # type: ignore[arg-type]
    ("format_time huge", lambda: guide.format_time(1e20), InputError, "not a number"),
    ("read_gps int", lambda: guide.read_gps(5), InputError, "give a .gpx or .csv path"),  # type: ignore[arg-type]
    ("read_gps dicts", lambda: guide.read_gps([{"lat": 1}]), InputError, "not list"),  # type: ignore[arg-type]
    ("radar tracks int", lambda: radar.read_tracks(5), InputError, "tracks file: give a file path"),  # type: ignore[arg-type]
    ("probe_video int", lambda: radar.probe_video(5), InputError, "video: give a file path"),  # type: ignore[arg-type]
]  # fmt: skip


@pytest.mark.parametrize(
    ("call", "error", "words"), [c[1:] for c in CASES], ids=[c[0] for c in CASES]
)
def test_wrong_type_is_named(call: Callable[[], Any], error: type[Exception], words: str) -> None:
    """Before: TypeError from pathlib / datetime / slicing."""
    with pytest.raises(error) as info:
        call()
    assert words in str(info.value)


def test_match_people_settings_of_the_wrong_type() -> None:
    """A dict of settings raised AttributeError 'check'."""
    cal = api.calibrate_scene(SCENE)
    times = np.array([0.0, 1.0])
    track = guide.PixelTrack("p1", times, np.array([[900.0, 700.0], [910.0, 700.0]]))
    gps = guide.GpsTrace("g1", times, np.array([[-76.5935, 39.2856], [-76.5935, 39.2857]]))
    with pytest.raises(InputError, match="settings must be a GuideSettings, not dict"):
        guide.match_people(cal, [track], [gps], settings={"a": 1})  # type: ignore[arg-type]


def test_compass_words_still_read() -> None:
    assert parse_compass("facing SW") == 225.0
    assert parse_compass(None) is None
