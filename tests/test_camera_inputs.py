"""camloc_geo.camera as a library user meets it: bad input is an InputError, numbers are floats."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest

from camloc_geo._errors import DegenerateGeometryError, InputError
from camloc_geo.camera import Camera, RadialDistortion

R0 = np.eye(3)
T0 = np.array([0.0, 0.0, 10.0])


@pytest.mark.parametrize(
    ("args", "error", "words"),
    [
        (("wide", (1, 2), R0, T0), InputError, "focal_px must be a number"),
        ((900, (1,), R0, T0), InputError, "principal_point must be"),
        ((900, (np.nan, 2), R0, T0), InputError, "principal_point must be two finite numbers"),
        ((900, (1, 2), np.eye(2), T0), InputError, "cam_from_world_rotation must be"),
        ((900, (1, 2), R0, [1.0, 2.0]), InputError, "cam_from_world_translation must be"),
        ((900, (1, 2), 2 * R0, T0), DegenerateGeometryError, "not a proper rotation"),
        ((900, (1, 2), -R0, T0), DegenerateGeometryError, "not a proper rotation"),
    ],
)
def test_camera_refuses_bad_parts(
    args: tuple[Any, ...], error: type[Exception], words: str
) -> None:
    """Before: TypeError, 'not enough values to unpack', numpy reshape errors, or accepted."""
    with pytest.raises(error, match=words):
        Camera(*args)


@pytest.mark.parametrize(
    ("method", "value", "words"),
    [
        ("project", [1.0, 2.0], "points_in_world must be"),
        ("project", "abc", "points_in_world must be numbers"),
        ("rays_in_world", [1.0, 2.0, 3.0], "pixels must be"),
        ("ground_from_pixels", [1.0, 2.0, 3.0], "pixels must be"),
    ],
)
def test_camera_methods_refuse_bad_shapes(method: str, value: Any, words: str) -> None:
    cam = Camera(900.0, (1.0, 2.0), R0, T0)
    with pytest.raises(InputError, match=words):
        getattr(cam, method)(value)


def test_distortion_refuses_text() -> None:
    with pytest.raises(InputError, match="distortion k1 must be a number"):
        RadialDistortion("x", 10.0)  # type: ignore[arg-type]


def test_numpy_scalars_become_floats() -> None:
    """A np.float32 focal length was kept, and to_dict() then failed in json.dumps."""
    cam = Camera(np.float32(900.0), (np.float32(960.0), 540), R0.astype(np.float32), T0)  # type: ignore[arg-type]
    assert type(cam.focal_px) is float
    assert cam.focal_px == 900.0
    assert all(type(v) is float for v in cam.principal_point)
    doc = cam.to_dict()
    assert json.loads(json.dumps(doc))["focal_px"] == 900.0
    uv = cam.project(np.array([[0.0, 0.0, 0.0]], dtype=np.float32))
    assert uv.tolist() == [[960.0, 540.0]]


def test_a_rotation_rounded_in_json_is_still_a_rotation() -> None:
    """Only matrices that are not rotations are refused: one rounded to 5 decimals passes."""
    from camloc_geo.camera import rotation_from_angles

    R = np.round(rotation_from_angles(33.3, -12.7, 2.1), 5)
    cam = Camera(900.0, (960.0, 540.0), R, T0)
    assert cam.cam_from_world_rotation.tolist() == R.tolist()
