"""Tie-breaking cues: viewing direction, the car's street, one-way streets against the car."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from test_absolute import (
    OSM,
    car_bearing_deg,
    errors_m,
    exact_located,
    ground_refs,
    junctions,
)

from camloc_geo.absolute import (
    CUE_FLOOR,
    OFF_STREET_FACTOR,
    WRONG_WAY_FACTOR,
    apply_cues,
    cue_log_likelihood,
    locate,
    view_log_factor,
)
from camloc_geo.osm import MapData, load_map
from camloc_geo.scene import ViewHint, parse_scene


@pytest.fixture(scope="module")
def heidelberg() -> MapData:
    return load_map(OSM / "heidelberg_altstadt.osm.pbf", 49.4120, 8.7080, radius_m=300)


def test_view_factor() -> None:
    hint = ViewHint(bearing_deg=90.0, tolerance_deg=30.0)
    assert view_log_factor(100.0, hint)[0] == 0.0
    assert view_log_factor(60.0, hint)[0] == 0.0
    lf, note = view_log_factor(135.0, hint)
    assert lf == pytest.approx(-0.5 * (15.0 / 15.0) ** 2)
    assert note is not None
    assert "45° from the hinted 90°" in note
    assert view_log_factor(270.0, hint)[0] == pytest.approx(math.log(CUE_FLOOR))
    assert view_log_factor(10.0, ViewHint(text="Camera 3"))[0] == 0.0


def _flip_scene(m: MapData) -> tuple[Any, dict[str, Any]]:
    ls = exact_located(m, junctions(m)[0], seed=8)
    scene = dict(ls.scene)
    del scene["intersection"]
    scene["references"] = ground_refs(m, ls, [(900.0, 950.0)])
    scene["street_bearing_deg"] = (car_bearing_deg(ls) + 180.0) % 360.0
    return ls, scene


@pytest.mark.parametrize("words", [False, True])
def test_view_hint_puts_the_true_candidate_first(heidelberg: MapData, words: bool) -> None:
    ls, scene = _flip_scene(heidelberg)
    heading = float(ls.camera_enu.angles_deg[0]) % 360.0
    if words:
        names = ("north", "NE", "east", "SE", "south", "SW", "west", "NW")
        scene["view_hint"] = {"text": f"looking {names[round(heading / 45.0) % 8]}"}
    else:
        scene["view_hint"] = {"bearing_deg": heading + 20.0, "tolerance_deg": 30.0}
    sc = parse_scene(scene)
    result = apply_cues(locate(sc, heidelberg), sc, heidelberg)
    errs = errors_m(result, ls)
    assert len(errs) == 2
    assert errs[0] < 0.1 < errs[1]
    assert result.candidates[0].score > 0.9
    assert any(str(f).startswith("cue: view_hint") for f in result.candidates[1].flags)
    assert not any(w.startswith("ambiguous") for w in result.warnings)


def test_wrong_view_hint_lowers_but_keeps_the_true_candidate(heidelberg: MapData) -> None:
    ls, scene = _flip_scene(heidelberg)
    heading = float(ls.camera_enu.angles_deg[0])
    scene["view_hint"] = {"bearing_deg": heading + 180.0, "tolerance_deg": 10.0}
    sc = parse_scene(scene)
    result = apply_cues(locate(sc, heidelberg), sc, heidelberg)
    errs = errors_m(result, ls)
    assert len(errs) == 2
    assert errs[1] < 0.1  # still there, second
    assert result.candidates[1].score > 0.0


def _street_pose(m: MapData, street: Any) -> tuple[float, np.ndarray]:
    """theta and translation that put a 4.6 x 1.8 car's centre on the street's midpoint,
    its length axis along the way's direction."""
    line = street.geometry
    a = line.interpolate(0.45, normalized=True)
    b = line.interpolate(0.55, normalized=True)
    ea, na = m.frame.enu_from_geographic(lat=a.y, lon=a.x)
    eb, nb = m.frame.enu_from_geographic(lat=b.y, lon=b.x)
    theta = math.atan2(nb - na, eb - ea)  # x axis along the way
    mid = np.array([(ea + eb) / 2, (na + nb) / 2])
    c, s = math.cos(theta), math.sin(theta)
    centre_world = np.array([2.3, 0.9])
    t = mid - np.array([[c, -s], [s, c]]) @ centre_world
    return theta, t


def _cue(m: MapData, theta: float, t: np.ndarray, **obj: Any) -> Any:
    scene = parse_scene(
        {"format": "camloc-scene/1", "image": {"width": 640, "height": 480}, "object": obj}
    )
    return cue_log_likelihood(
        scene,
        heading_deg=0.0,
        theta_rad=theta,
        translation_en=t,
        scale=1.0,
        car_center_world=np.array([2.3, 0.9]),
        map_data=m,
        frame=m.frame,
    )


def test_street_cue(heidelberg: MapData) -> None:
    street = next(
        s
        for s in heidelberg.streets
        if not s.name.startswith("unnamed") and s.geometry.length > 0.0005
    )
    theta, t = _street_pose(heidelberg, street)
    on = _cue(heidelberg, theta, t, street=street.name)
    assert on.log_factor == 0.0
    assert on.notes == [f"object.street: the car stands on {street.name}"]
    off = _cue(heidelberg, theta, t, street="No Such Strasse")
    assert off.log_factor == pytest.approx(math.log(OFF_STREET_FACTOR))
    assert "object.street: the car is not on No Such Strasse" in off.notes[0]


def test_one_way_cue(heidelberg: MapData) -> None:
    street = next((s for s in heidelberg.streets if s.oneway and s.geometry.length > 0.0005), None)
    assert street is not None, "the extract has one-way streets"
    theta, t = _street_pose(heidelberg, street)
    along = _cue(heidelberg, theta, t, front="length_end")
    against = _cue(heidelberg, theta, t, front="origin")
    assert along.log_factor == 0.0
    assert any("drives with one-way" in n for n in along.notes)
    assert against.log_factor == pytest.approx(math.log(WRONG_WAY_FACTOR))
    assert any("faces against one-way" in n for n in against.notes)


def test_no_cue_leaves_the_result_alone(heidelberg: MapData) -> None:
    _ls, scene = _flip_scene(heidelberg)
    sc = parse_scene(scene)
    result = locate(sc, heidelberg)
    before = [(c.rank, c.score) for c in result.candidates]
    apply_cues(result, sc, heidelberg)
    assert [(c.rank, c.score) for c in result.candidates] == before


def test_locate_prints_the_tie_and_the_hint_breaks_it(
    heidelberg: MapData, tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    from camloc_geo.cli import main

    ls, scene = _flip_scene(heidelberg)
    path = tmp_path / "tie.json"
    path.write_text(json.dumps(scene))
    osm = str(OSM / "heidelberg_altstadt.osm.pbf")
    with caplog.at_level("WARNING", logger="camloc_geo.cli.locate"):
        assert main(["locate", str(path), "--osm", osm, "-o", str(tmp_path / "a.geojson")]) == 0
    ties = [r.message for r in caplog.records if r.message.startswith("ambiguous")]
    assert len(ties) == 1
    assert "candidates 1 and 2" in ties[0]
    caplog.clear()
    heading = float(ls.camera_enu.angles_deg[0])
    scene["view_hint"] = {"bearing_deg": heading, "tolerance_deg": 30}
    path.write_text(json.dumps(scene))
    with caplog.at_level("WARNING", logger="camloc_geo.cli.locate"):
        assert main(["locate", str(path), "--osm", osm, "-o", str(tmp_path / "b.geojson")]) == 0
    assert not [r for r in caplog.records if r.message.startswith("ambiguous")]
    out = json.loads((tmp_path / "b.geojson").read_text())
    first = next(f for f in out["features"] if f["properties"].get("rank") == 1)
    assert first["properties"]["score"] > 0.9
