"""Bad input to each ``camloc_geo.api`` function raises the package's own error, naming it.

A library user calling the API from a notebook or a script must meet an :class:`InputError`
(or a subclass) whose message names the argument, never a bare TypeError, AttributeError or
IndexError from deep inside.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camloc_geo import api
from camloc_geo._errors import InputError, MapDataError, SceneError

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "sample_maps" / "sample_scene.json"
EXTRACT = str(REPO / "sample_maps" / "baltimore.osm.pbf")
LAT, LON = 39.2856, -76.5935


def _scene() -> dict[str, Any]:
    return dict(json.loads(SCENE.read_text()))


CASES: list[tuple[str, Callable[[], object], type[Exception], str]] = [
    (
        "calibrate settings dict",
        lambda: api.calibrate_scene(_scene(), settings={"joint_fit": True}),  # type: ignore[arg-type]
        InputError,
        "settings must be a CalibrationSettings",
    ),
    (
        "locate max_candidates str",
        lambda: api.locate_scene(_scene(), map_source=EXTRACT, max_candidates="3"),  # type: ignore[arg-type]
        SceneError,
        "max_candidates must be a whole number",
    ),
    (
        "locate max_candidates 1.5",
        lambda: api.locate_scene(_scene(), map_source=EXTRACT, max_candidates=1.5),  # type: ignore[arg-type]
        SceneError,
        "max_candidates must be a whole number",
    ),
    (
        "locate map_source int",
        lambda: api.locate_scene(_scene(), map_source=5),  # type: ignore[arg-type]
        MapDataError,
        "map_source must be",
    ),
    (
        "locate calibration dict",
        lambda: api.locate_scene(_scene(), map_source=EXTRACT, calibration={"a": 1}),  # type: ignore[arg-type]
        InputError,
        "calibration must be a CalibrationResult",
    ),
    (
        "locate settings dict",
        lambda: api.locate_scene(_scene(), map_source=EXTRACT, settings={"a": 1}),  # type: ignore[arg-type]
        InputError,
        "settings must be a LocateSettings",
    ),
    (
        "corners lat str",
        lambda: api.corners_near(lat="x", lon=LON, map_source=EXTRACT),  # type: ignore[arg-type]
        MapDataError,
        "lat must be a number of degrees",
    ),
    (
        "streets lon None",
        lambda: api.streets_near(lat=LAT, lon=None, map_source=EXTRACT),  # type: ignore[arg-type]
        MapDataError,
        "lon must be a number of degrees",
    ),
    (
        "streets_within lat list",
        lambda: api.streets_within(lat=[1], lon=LON, map_source=EXTRACT),  # type: ignore[arg-type]
        MapDataError,
        "lat must be a number of degrees",
    ),
    (
        "map_around short point",
        lambda: api.map_around([(LAT, LON), (1.0,)], map_source=EXTRACT),  # type: ignore[list-item]
        MapDataError,
        "points[1] must be a (lat, lon) pair",
    ),
    (
        "map_around str point",
        lambda: api.map_around([("a", "b")], map_source=EXTRACT),  # type: ignore[list-item]
        MapDataError,
        "points[0] lat must be a number",
    ),
    (
        "locate_camera int",
        lambda: api.locate_camera(5, map_source=EXTRACT),  # type: ignore[arg-type]
        InputError,
        "camera must be a CameraRow or a mapping",
    ),
    (
        "locate_camera map_source int",
        lambda: api.locate_camera({"title": "A & B"}, map_source=3),  # type: ignore[arg-type]
        MapDataError,
        "map_source must be",
    ),
    (
        "vp box of strings",
        lambda: api.vanishing_points(
            np.zeros((50, 50), np.uint8),
            ignore_boxes_px=[("a", "b", "c", "d")],  # type: ignore[list-item]
        ),
        InputError,
        "ignore box: give four finite numbers",
    ),
    (
        "vp short axis",
        lambda: api.vanishing_points(np.zeros((50, 50), np.uint8), axes_px=[(1.0, 2.0)]),
        InputError,
        "axis: give four finite numbers",
    ),
    (
        "vp unknown option",
        lambda: api.vanishing_points(np.zeros((50, 50), np.uint8), frobnicate=1),
        InputError,
        "unknown vanishing-point option(s): frobnicate",
    ),
    (
        "vp focal str",
        lambda: api.vanishing_points(np.zeros((50, 50), np.uint8), focal_px="wide"),  # type: ignore[arg-type]
        InputError,
        "focal_px must be a positive number of pixels",
    ),
    (
        "guide candidate str",
        lambda: api.guide_scene(_scene(), [], [], candidate="1"),  # type: ignore[arg-type]
        InputError,
        "candidate rank must be a whole number",
    ),
    (
        "radar video int",
        lambda: api.radar_scene(_scene(), 5),  # type: ignore[arg-type]
        InputError,
        "video must be a file path",
    ),
    (
        "crowd one path not a list",
        lambda: api.crowd_scene(str(SCENE)),
        SceneError,
        "scenes must be a list of scenes",
    ),
    (
        "crowd prior int",
        lambda: api.crowd_scene([_scene()], prior=5),  # type: ignore[arg-type]
        SceneError,
        "prior must be a mapping",
    ),
]


@pytest.mark.parametrize(
    ("call", "error", "words"), [c[1:] for c in CASES], ids=[c[0] for c in CASES]
)
def test_bad_input_raises_the_package_error(
    call: Callable[[], object], error: type[Exception], words: str
) -> None:
    with pytest.raises(error) as info:
        call()
    assert words in str(info.value)


def test_numpy_numbers_are_accepted() -> None:
    """numpy scalars (either width) are numbers, as a user of arrays passes them."""
    doc = api.corners_near(lat=np.float64(LAT), lon=np.float32(LON), map_source=EXTRACT)
    assert doc["type"] == "FeatureCollection"
    out = api.locate_scene(_scene(), map_source=EXTRACT, max_candidates=np.int64(2))
    assert 1 <= len(out.result.candidates) <= 2


@pytest.fixture(scope="module")
def calibration() -> Any:
    return api.calibrate_scene(SCENE)


@pytest.mark.parametrize(
    ("options", "words"),
    [
        ({"n_samples": 0}, "n_samples must be a whole number >= 2, got 0"),
        ({"n_samples": "many"}, "n_samples must be a whole number >= 2"),
        ({"click_sigma_px": -1.0}, "click_sigma_px must be a finite number of pixels >= 0"),
        ({"click_sigma_px": float("nan")}, "click_sigma_px must be a finite number"),
        ({"seed": "x"}, "seed must be a whole number >= 0"),
    ],
)
def test_sensor_options_are_checked(calibration: Any, options: dict[str, Any], words: str) -> None:
    """n_samples=0 said 'too close to the horizon'; -1 px: numpy's 'scale < 0'; 'x': TypeError."""
    from camloc_geo.sensors import ground_distance, point_height

    with pytest.raises(InputError) as info:
        ground_distance(calibration, [(900, 700), (1000, 700)], **options)
    assert words in str(info.value)
    with pytest.raises(InputError) as info:
        point_height(calibration, (1363.4, 592.9), (1369.0, 502.0), **options)
    assert words in str(info.value)


def test_sensor_refuses_what_is_not_a_calibration() -> None:
    from camloc_geo.sensors import ground_distance

    with pytest.raises(InputError, match="calibration must be a CalibrationResult"):
        ground_distance({}, [(900, 700), (1000, 700)])  # type: ignore[arg-type]


def test_sensor_numbers_unchanged(calibration: Any) -> None:
    """The checks change nothing for good options (numpy integers accepted)."""
    from camloc_geo.sensors import ground_distance

    m = ground_distance(calibration, np.array([(900, 700), (1000, 700)]), n_samples=np.int64(400))
    # rel 1e-7: another CPU or BLAS moves the last digits (1.7e-9 seen on a fresh machine);
    # a change of the sensor's numbers moves them by far more.
    assert m.value_m == pytest.approx(1.2938980364696304, rel=1e-7)
    assert m.n_samples == 400
    assert all(type(v) in (int, float) for v in m.to_dict().values())


def test_scene_may_be_any_mapping() -> None:
    """A read-only mapping of a scene (MappingProxyType) was refused as 'not a dict'."""
    import types

    scene = api.scene_from(types.MappingProxyType(_scene()))
    assert scene.id == "baltimore-eastern-broadway"
    assert len(scene.annotations) == len(_scene()["annotations"])


def test_vanishing_points_of_8_bit_values_in_a_wide_integer_array() -> None:
    """img.astype(int) (int64 holding 0..255) was scaled by 255 / 2**63 to black: 'not
    enough structure'; now the same answer as the uint8 photo."""
    pytest.importorskip("cv2")
    from tests.test_autovp import cam_from_world, render_scene

    img = render_scene(cam_from_world(30.0, 12.0, 4.0), 700.0)
    ref = api.vanishing_points(img)
    assert ref.focal_px is not None
    for dtype in (np.int64, np.int32, np.uint32):
        wide = api.vanishing_points(img.astype(dtype))
        assert wide.focal_px == ref.focal_px


@pytest.mark.parametrize(
    ("call", "words"),
    [
        (lambda: api.map_for_scene(_scene(), map_source=EXTRACT, radius_m="x"), "radius_m must"),  # type: ignore[arg-type]
        (lambda: api.locate_scene(_scene(), map_source=EXTRACT, radius_m=[1]), "radius_m must"),  # type: ignore[arg-type]
        (lambda: api.map_around([(LAT, LON)], map_source=EXTRACT, margin_m="x"), "margin_m must"),  # type: ignore[arg-type]
        (lambda: api.corners_near(lat=LAT, lon=LON, map_source=EXTRACT, streets=5), "streets must"),  # type: ignore[arg-type]
    ],
)
def test_more_bad_options_are_map_data_errors(call: Callable[[], object], words: str) -> None:
    """Before: ValueError from float('x'), TypeError from float([1]) / 'x' + float / iter(5)."""
    with pytest.raises(MapDataError, match=words):
        call()


def test_corners_near_takes_a_list_of_street_names() -> None:
    both = api.corners_near(
        lat=LAT, lon=LON, map_source=EXTRACT, streets=["Eastern Avenue", "South Broadway"]
    )
    text = api.corners_near(lat=LAT, lon=LON, map_source=EXTRACT, streets="Eastern & Broadway")
    assert both["features"]
    assert both["features"][0]["properties"] == text["features"][0]["properties"]
