"""Which horizontal vanishing point ``camloc vp`` names the street (issue 24 item 2).

Stop 40's walk: on a level phone photo down a street (``la foto.JPG``) the kerbs and lane
markings (181 segments) meet off the frame's right side, and the frame's third point, the
cross product of the other two with no segment of its own, lies nearer the image centre: the
rule "nearer the optical axis" named that unsupported point the street.
"""

from __future__ import annotations

import math

import numpy as np

from camloc_geo.autovp import AutoVPResult


def _result(n_lines: tuple[int, int, int], yaw_deg: float) -> AutoVPResult:
    """A level camera whose direction 1 is ``yaw_deg`` off its axis (direction 2 square to it)."""
    a = math.radians(yaw_deg)
    up = np.array([0.0, -1.0, 0.0])
    h1 = np.array([math.sin(a), 0.0, math.cos(a)])
    h2 = np.array([math.cos(a), 0.0, -math.sin(a)])
    d = np.vstack([up, h1, h2])
    f, pp = 1000.0, (800.0, 600.0)
    K = np.array([[f, 0.0, pp[0]], [0.0, f, pp[1]], [0.0, 0.0, 1.0]])
    return AutoVPResult(
        vanishing_points=(K @ d.T).T,
        directions_in_cam=d,
        focal_px=f,
        principal_point=pp,
        focal_source="estimated",
        focal_std_rel=0.05,
        pitch_deg=0.0,
        roll_deg=0.0,
        horizon=np.array([0.0, 1.0, -600.0]),
        segments=np.zeros((0, 4)),
        labels=np.zeros(0, dtype=np.int64),
        confidence=0.9,
        vertical_identified=True,
        image_size=(1600, 1200),
        n_lines=n_lines,
    )


def test_the_supported_direction_is_the_street_when_the_other_shows_no_line() -> None:
    # direction 1 (31 lines) lies 60 degrees off the axis, direction 2 (0 lines) 30 degrees:
    # the nearer one is a cross product, not a direction the photo shows
    res = _result((31, 20, 0), 60.0)
    assert res.street_index == 1
    assert res.to_json()["vanishing_point_names"] == ["vertical", "street", "across the street"]


def test_both_shown_the_nearer_to_the_axis_is_the_street() -> None:
    assert _result((31, 20, 14), 60.0).street_index == 2
    assert _result((31, 20, 14), 20.0).street_index == 1
    assert _result((31, 3, 2), 60.0).street_index == 2  # neither shown: the old rule
