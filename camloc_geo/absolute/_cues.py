"""Cues that break ties between candidate camera positions where the geometry cannot.

A symmetric junction fits the evidence equally well from two sides; the paper stops there.
Three optional scene fields say more (``docs/scene-format.md``):

- ``view_hint``: the camera's viewing direction (a bearing with a tolerance, or a compass
  phrase from a webcam listing, read by :func:`camloc_geo.scene.parse_compass`);
- ``object.street``: the street the car stands on;
- ``object.front``: which end of the annotated length edge is the car's front, so that a car
  facing against a one-way street is unlikely.

Each cue is a likelihood factor between :data:`CUE_FLOOR` and 1 (soft: a wrong hint lowers
the right candidate, it never removes it). :func:`cue_log_likelihood` returns the sum of
their logarithms for one candidate, with one note per cue that acted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:
    from camloc_geo.geodesy import LocalFrame
    from camloc_geo.osm import MapData
    from camloc_geo.scene import Scene, ViewHint

__all__ = [
    "CUE_FLOOR",
    "OFF_STREET_FACTOR",
    "VIEW_SIGMA_DEG",
    "WRONG_WAY_FACTOR",
    "CueScore",
    "cue_log_likelihood",
    "view_log_factor",
]

FloatArray = npt.NDArray[np.float64]

CUE_FLOOR = 0.02
"""No single cue multiplies a candidate's likelihood by less than this."""

VIEW_SIGMA_DEG = 15.0
"""Beyond the hint's tolerance, the view factor falls as a Gaussian of this width (degrees)."""

OFF_STREET_FACTOR = 0.1
"""Factor for a candidate whose car does not stand on the street the scene names."""

WRONG_WAY_FACTOR = 0.1
"""Factor for a candidate whose car faces against a one-way street."""

_ON_STREET_MARGIN_M = 2.5


@dataclass
class CueScore:
    """The cues' verdict on one candidate: ``log_factor`` (≤ 0) and one note per cue."""

    log_factor: float
    notes: list[str]


def _angle_diff_deg(a: float, b: float) -> float:
    """Absolute difference of two bearings, degrees in [0, 180]."""
    return abs((a - b + 180.0) % 360.0 - 180.0)


def view_log_factor(heading_deg: float, hint: ViewHint) -> tuple[float, str | None]:
    """Log-likelihood factor of a camera heading under a viewing-direction hint.

    1 inside ``tolerance_deg`` of the hint's bearing, then a Gaussian fall-off of
    :data:`VIEW_SIGMA_DEG`, floored at :data:`CUE_FLOOR`. ``(0, None)`` when the hint gives no
    bearing.
    """
    bearing = hint.resolved_bearing_deg
    if bearing is None:
        return 0.0, None
    off = _angle_diff_deg(heading_deg, bearing)
    excess = max(0.0, off - hint.tolerance_deg)
    log_f = max(-0.5 * (excess / VIEW_SIGMA_DEG) ** 2, math.log(CUE_FLOOR))
    if excess == 0.0:
        return 0.0, f"view_hint: heading {heading_deg:.0f}° within {hint.tolerance_deg:g}°"
    return log_f, (
        f"view_hint: heading {heading_deg:.0f}° is {off:.0f}° from the hinted {bearing:.0f}° "
        f"(tolerance {hint.tolerance_deg:g}°)"
    )


@dataclass(frozen=True)
class _StreetENU:
    line: Any  # shapely LineString in the frame's east/north metres, in OSM way direction
    half_width_m: float
    names: frozenset[str]
    label: str
    oneway: bool


def _streets_enu(map_data: MapData, frame: LocalFrame) -> tuple[list[_StreetENU], Any]:
    """The map's streets in the frame's metres, with an STRtree (cached per map and frame)."""

    key = f"cues.streets_enu:{frame.lat0:.9f},{frame.lon0:.9f}"
    return map_data.cached(key, lambda: _build_streets_enu(map_data, frame))


def _build_streets_enu(map_data: MapData, frame: LocalFrame) -> tuple[list[_StreetENU], Any]:
    from shapely.geometry import LineString
    from shapely.strtree import STRtree

    from camloc_geo.osm._names import normalize_name

    out: list[_StreetENU] = []
    for st in map_data.streets:
        lon, lat = np.asarray(st.geometry.xy[0]), np.asarray(st.geometry.xy[1])
        e, n = frame.enu_from_geographic(lat=lat, lon=lon)
        names = {normalize_name(x) for x in (st.name, *st.names) if x}
        out.append(
            _StreetENU(
                LineString(np.column_stack([e, n])),
                0.5 * float(st.width_m),
                frozenset(names),
                st.name,
                bool(st.oneway),
            )
        )
    tree = STRtree([s.line for s in out])
    return out, tree


def _streets_under(
    point_en: FloatArray, streets: list[_StreetENU], tree: Any
) -> list[tuple[_StreetENU, float]]:
    """Streets whose carriageway holds the point, with the way's bearing there (degrees)."""
    from shapely.geometry import Point, box

    x, y = float(point_en[0]), float(point_en[1])
    pt = Point(x, y)
    out = []
    for idx in tree.query(box(x - 30.0, y - 30.0, x + 30.0, y + 30.0)):
        s = streets[int(idx)]
        if s.line.distance(pt) > s.half_width_m + _ON_STREET_MARGIN_M:
            continue
        proj = s.line.project(pt)
        a = s.line.interpolate(max(0.0, proj - 5.0))
        b = s.line.interpolate(min(s.line.length, proj + 5.0))
        out.append((s, math.degrees(math.atan2(b.x - a.x, b.y - a.y)) % 360.0))
    return out


def cue_log_likelihood(
    scene: Scene,
    *,
    heading_deg: float,
    theta_rad: float,
    translation_en: FloatArray,
    scale: float,
    car_center_world: FloatArray,
    map_data: MapData | None,
    frame: LocalFrame | None,
) -> CueScore:
    """The cues' log-likelihood factor for one candidate.

    Parameters
    ----------
    scene
        The scene (its ``view_hint``, ``object.street`` and ``object.front``).
    heading_deg
        The candidate camera's heading, degrees clockwise from north.
    theta_rad, translation_en, scale
        The candidate's similarity from the car's world frame to the local east/north frame:
        ``en = scale · R(theta) · xy + translation``.
    car_center_world
        The car's footprint centre in its world frame (x, y), metres.
    map_data, frame
        The map and the local frame of the result (the street cues need both).
    """
    notes: list[str] = []
    total = 0.0
    if scene.view_hint is not None:
        lf, note = view_log_factor(heading_deg, scene.view_hint)
        total += lf
        if note:
            notes.append(note)
    street = scene.object.street
    front = scene.object.front
    if (street or front) and map_data is not None and frame is not None:
        from camloc_geo.osm._names import normalize_name

        c, s_ = math.cos(theta_rad), math.sin(theta_rad)
        R2 = np.array([[c, -s_], [s_, c]])
        car_en = scale * R2 @ np.asarray(car_center_world, float) + np.asarray(translation_en)
        streets, tree = _streets_enu(map_data, frame)
        under = _streets_under(car_en, streets, tree)
        if street:
            want = normalize_name(street)
            if any(want in s.names for s, _b in under):
                notes.append(f"object.street: the car stands on {street}")
            else:
                total += math.log(max(OFF_STREET_FACTOR, CUE_FLOOR))
                on = sorted({s.label for s, _b in under})
                notes.append(
                    f"object.street: the car is not on {street}"
                    + (f" (on {', '.join(on)})" if on else " (on no street)")
                )
        if front:
            # Bearing of the world +x axis (origin → length end) in the local frame.
            axis_brg = (90.0 - math.degrees(theta_rad)) % 360.0
            front_brg = axis_brg if front == "length_end" else (axis_brg + 180.0) % 360.0
            one_way = [(s, b) for s, b in under if s.oneway]
            if one_way:
                s, b = min(one_way, key=lambda sb: _angle_diff_deg(front_brg, sb[1]) % 180.0)
                if _angle_diff_deg(front_brg, b) > 90.0:
                    total += math.log(max(WRONG_WAY_FACTOR, CUE_FLOOR))
                    notes.append(f"object.front: the car faces against one-way {s.label}")
                else:
                    notes.append(f"object.front: the car drives with one-way {s.label}")
    return CueScore(total, notes)
