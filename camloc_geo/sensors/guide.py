"""Virtual guide: match people seen by a calibrated camera to GPS traces.

People's pixel tracks (a foot pixel or a detector's box per frame) are cast onto the ground
with the calibrated camera (:mod:`camloc_geo.sensors`), carried into local east/north metres
and matched to GPS traces over time.

Two modes
---------
- **absolute**: the camera's absolute pose is known (calibration + ``enu_from_world`` of a
  located candidate): the ground tracks are placed in the GPS traces' local frame directly.
- **relative**: no absolute pose. The unknown rigid transform (rotation and translation; the
  scale is known from the calibration) between the camera's ground frame and the traces'
  local frame is solved jointly with the assignment: each (track, trace) pair proposes a
  transform (least squares over their common times), every proposal is scored by its best
  assignment, the best is refined on all its matched pairs. The solved transform places the
  camera: it is reported as a location estimate.

Noise model and scores
----------------------
Everything is resampled on a common time grid (``step_s``). At each grid time where both a
ground track ``p`` and a trace ``g`` exist, ``d = |p - g|`` and ``s² = gps_sigma_m² +``
projection sigma² (per axis; the projection sigma is the Monte Carlo spread of the ground
point over the calibration's uncertainty and ``click_sigma_px``). The sample's
log-likelihood ratio between "this trace is this person's" (``d`` Gaussian with ``s`` per
axis) and "it is somebody else's nearby" (Gaussian with ``S² = s² + crowd_spread_m²``, the
spread of people around each other) is ``log(S²/s²) - d² (1/s² - 1/S²) / 2``, floored at -4
(robust: a GPS jump or a wrong detection costs at most that); it is weighted by
``w = min(1, step_s / gps_correlation_s)`` (GPS errors are correlated in time, so samples
closer than that are not independent) and summed into the pair's score. A score is thus a
log-likelihood ratio against "this person carries none of the traces" (score 0).

The assignment maximises the total score (``scipy.optimize.linear_sum_assignment``; one
"no match" column per track; a final match with less than ``min_overlap_s`` of common time
is reported unmatched). The certainty
of a track's outcome (matched to a trace or unmatched) is ``1 / (1 + exp(S₂ - S₁))``, ``S₁`` the
best total score and ``S₂`` the best total score with that outcome forbidden (in relative
mode, the best over the top transform proposals). It is evaluated on the data up to each of
up to ``max_evaluations`` times; ``certain_after_s`` is the time, counted from the track's
first sample, from which the track's outcome equals the final one and its certainty stays at
or above ``certainty``; ``stable_after_s`` the time from which the outcome equals the final
one, whatever its certainty (the paper's "bootstrapping time").
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from camloc_geo._errors import InputError
from camloc_geo._io import read_text_file
from camloc_geo.absolute._similarity import Similarity2D, rot2
from camloc_geo.camera import Camera, rotation_from_angles
from camloc_geo.geodesy import LocalFrame
from camloc_geo.sensors import _draws_posed, _ground, _pixels, _rays

if TYPE_CHECKING:
    from camloc_geo.relative import CalibrationResult

__all__ = [
    "AbsolutePose",
    "GpsTrace",
    "GuideMatch",
    "GuideResult",
    "GuideSettings",
    "PixelTrack",
    "format_time",
    "match_people",
    "parse_time",
    "pose_from_candidates_geojson",
    "read_gps",
    "read_tracks",
]

FloatArray = npt.NDArray[np.float64]

_LLR_FLOOR = -4.0
_BIG = 1e9
_SEED = 20261124
_MAX_GRID = 200_000
_MAX_CELLS = 20_000_000  # tracks x traces x grid steps held at once
_MAX_PROPOSALS = 40
_CHUNK = 2000  # pixels projected at once
_UNIX_MIN_S = 1e8  # numbers above this are UNIX times (1973 onwards), below: video seconds


# --------------------------------------------------------------------------- time


def parse_time(value: Any, *, what: str = "time") -> float:
    """UNIX seconds of an ISO 8601 string or a number (UNIX seconds).

    ISO times without a time zone are taken as UTC.

    Raises
    ------
    InputError
        Not a time.
    """
    if isinstance(value, bool):
        raise InputError(f"{what}: {value!r} is not a time")
    if isinstance(value, (int, float)):
        t = float(value)
    else:
        text = str(value).strip()
        try:
            t = float(text)
        except ValueError:
            try:
                dt = datetime.fromisoformat(text.replace("Z", "+00:00").replace("z", "+00:00"))
            except ValueError:
                raise InputError(f"{what}: {text!r} is not an ISO 8601 time") from None
            if dt.tzinfo is None:
                dt = dt.replace(tzinfo=timezone.utc)
            t = dt.timestamp()
    if not math.isfinite(t):
        raise InputError(f"{what}: {value!r} is not a finite time")
    return t


def format_time(t_s: float) -> str:
    """ISO 8601 UTC of UNIX seconds (milliseconds, ``Z``).

    Raises
    ------
    InputError
        ``t_s`` is not a finite number of seconds within the years 1..9999.
    """
    try:
        dt = datetime.fromtimestamp(float(t_s), tz=timezone.utc)
    except (TypeError, ValueError, OverflowError, OSError):
        raise InputError(f"time: {t_s!r} is not a number of UNIX seconds") from None
    return dt.isoformat(timespec="milliseconds").replace("+00:00", "Z")


# --------------------------------------------------------------------------- inputs


@dataclass(frozen=True)
class PixelTrack:
    """A person's foot pixels over time.

    Attributes
    ----------
    id
        The tracker's id of the person.
    times_s
        ``(N,)`` UNIX seconds, increasing.
    foot_px
        ``(N, 2)`` image pixels where the person stands on the ground.
    """

    id: str
    times_s: FloatArray
    foot_px: FloatArray


@dataclass(frozen=True)
class GpsTrace:
    """A GPS trace.

    Attributes
    ----------
    id
        The trace's id (device, person).
    times_s
        ``(N,)`` UNIX seconds, increasing.
    lonlat
        ``(N, 2)`` ``[lon, lat]`` degrees WGS 84.
    """

    id: str
    times_s: FloatArray
    lonlat: FloatArray


def _num(row: dict[str, Any], key: str, where: str) -> float:
    try:
        x = float(row[key])
    except (TypeError, ValueError):
        raise InputError(f"{where}: {key}={row[key]!r} is not a number") from None
    if not math.isfinite(x):
        raise InputError(f"{where}: {key} is not finite")
    return x


def _has(row: dict[str, Any], *keys: str) -> bool:
    return all(row.get(k) not in (None, "") for k in keys)


def _foot_of(row: dict[str, Any], where: str, box_format: str) -> tuple[float, float]:
    """Foot pixel of a row: ``u, v``, a box ``x1..y2`` / ``x, y, w, h`` or ``box: [...]``."""
    if _has(row, "u", "v"):
        return _num(row, "u", where), _num(row, "v", where)
    if _has(row, "x1", "y1", "x2", "y2"):
        x1, y1, x2, y2 = (_num(row, k, where) for k in ("x1", "y1", "x2", "y2"))
        return 0.5 * (x1 + x2), max(y1, y2)
    if _has(row, "x", "y", "w", "h"):
        x, y, w, h = (_num(row, k, where) for k in ("x", "y", "w", "h"))
        if w < 0 or h < 0:
            raise InputError(f"{where}: box width and height must be >= 0")
        return x + 0.5 * w, y + h
    box = row.get("box")
    if isinstance(box, (list, tuple)) and len(box) == 4:
        vals = dict(zip(("a", "b", "c", "d"), box, strict=True))
        a, b, c, d = (_num(vals, k, where) for k in ("a", "b", "c", "d"))
        if box_format == "xyxy":
            return 0.5 * (a + c), max(b, d)
        if c < 0 or d < 0:
            raise InputError(f"{where}: box width and height must be >= 0 (box is x, y, w, h)")
        return a + 0.5 * c, b + d
    raise InputError(
        f"{where}: no position: give u,v (foot pixel), x,y,w,h or x1,y1,x2,y2 (box), or box"
    )


def _row_time(
    row: dict[str, Any], where: str, video_start_s: float | None, fps: float | None
) -> float:
    key = next((k for k in ("t", "time", "timestamp") if _has(row, k)), None)
    if key is None:
        if _has(row, "frame"):
            if fps is None:
                raise InputError(f"{where}: frame numbers need the frame rate: give --fps")
            if video_start_s is None:
                raise InputError(
                    f"{where}: frame numbers are relative to the video: give --video-start"
                )
            return video_start_s + _num(row, "frame", where) / fps
        raise InputError(f"{where}: no time: give t (seconds or ISO 8601) or frame")
    value = row[key]
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            return parse_time(value, what=f"{where}: {key}")
    t = float(value)
    if not math.isfinite(t):
        raise InputError(f"{where}: {key} is not finite")
    if video_start_s is not None:
        if t > _UNIX_MIN_S:
            raise InputError(
                f"{where}: {key}={t:g} looks like a UNIX time while --video-start is given: "
                "times must then be seconds since the video start"
            )
        return video_start_s + t
    if t > _UNIX_MIN_S:
        return t
    raise InputError(
        f"{where}: {key}={t:g} is seconds since the video start: give --video-start ISO8601 "
        "(or absolute ISO 8601 / UNIX times)"
    )


def _rows_of_json(doc: Any, name: str) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    meta: dict[str, Any] = {}
    if isinstance(doc, dict):
        meta = {k: v for k, v in doc.items() if k in ("video_start", "fps", "box_format")}
        if "tracks" in doc:
            tracks = doc["tracks"]
            rows: list[dict[str, Any]] = []
            if isinstance(tracks, dict):
                items = list(tracks.items())
            elif isinstance(tracks, list):
                items = []
                for k, tr in enumerate(tracks):
                    if not isinstance(tr, dict) or "points" not in tr:
                        raise InputError(f"{name}: tracks[{k}] must be an object with points")
                    items.append((tr.get("id", k), tr["points"]))
            else:
                raise InputError(f"{name}: tracks must be a list or an object")
            for tid, pts in items:
                if not isinstance(pts, list):
                    raise InputError(f"{name}: the points of track {tid!r} must be a list")
                for p in pts:
                    if not isinstance(p, dict):
                        raise InputError(f"{name}: track {tid!r}: each point must be an object")
                    rows.append({**p, "id": tid})
            return rows, meta
        doc = doc.get("detections", doc.get("rows"))
    if not isinstance(doc, list) or not all(isinstance(r, dict) for r in doc):
        raise InputError(
            f"{name}: tracks JSON must be a list of rows or an object with 'tracks' "
            "(see docs/guide.md)"
        )
    return list(doc), meta


def read_tracks(
    source: str | Path | dict[str, Any] | list[Any],
    *,
    video_start: Any = None,
    fps: float | None = None,
    box_format: str | None = None,
) -> list[PixelTrack]:
    """People's pixel tracks from JSON or CSV (format in ``docs/guide.md``).

    Parameters
    ----------
    source
        A ``.json`` or ``.csv`` path, or already parsed JSON.
    video_start
        ISO 8601 time (or UNIX seconds) of the video's first frame; then times are seconds
        since it. Overrides the file's ``video_start``.
    fps
        Frame rate, for rows that give ``frame`` instead of ``t``.
    box_format
        ``"xywh"`` (default) or ``"xyxy"`` for ``box: [...]`` rows.

    Raises
    ------
    InputError
        Unreadable file, a row without id, time or position, no tracks.
    """
    name = "tracks"
    meta: dict[str, Any] = {}
    if isinstance(source, (str, Path)):
        path = Path(source)
        name = path.name
        text = read_text_file(path, what="tracks file")
        if path.suffix.lower() == ".csv":
            rows = list(csv.DictReader(io.StringIO(text)))
            if not rows:
                raise InputError(f"{name}: no rows (CSV with a header id,t,u,v or id,t,x,y,w,h)")
        else:
            try:
                doc = json.loads(text)
            except json.JSONDecodeError as exc:
                raise InputError(f"{name}: not JSON ({exc.msg}, line {exc.lineno})") from None
            rows, meta = _rows_of_json(doc, name)
    else:
        rows, meta = _rows_of_json(source, name)
    vs = video_start if video_start is not None else meta.get("video_start")
    video_start_s = None if vs is None else parse_time(vs, what="video start")
    if fps is None and meta.get("fps") is not None:
        fps = float(meta["fps"])
    if fps is not None and not (math.isfinite(fps) and fps > 0):
        raise InputError(f"fps must be positive, not {fps}")
    fmt = (box_format or meta.get("box_format") or "xywh").lower()
    if fmt not in ("xywh", "xyxy"):
        raise InputError(f"box format must be xywh or xyxy, not {fmt!r}")
    per: dict[str, list[tuple[float, float, float]]] = {}
    for k, row in enumerate(rows):
        where = f"{name} row {k + 1}"
        tid = row.get("id", row.get("track"))
        if tid in (None, ""):
            raise InputError(f"{where}: no id (the person's track id)")
        t = _row_time(row, where, video_start_s, fps)
        u, v = _foot_of(row, where, fmt)
        per.setdefault(str(tid), []).append((t, u, v))
    if not per:
        raise InputError(f"{name}: no tracks")
    out = []
    for tid, pts in per.items():
        arr = np.array(sorted(pts), dtype=np.float64)
        _, first = np.unique(arr[:, 0], return_index=True)
        arr = arr[first]
        out.append(PixelTrack(tid, arr[:, 0], arr[:, 1:]))
    return out


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _read_gpx(text: str, name: str) -> dict[str, list[tuple[float, float, float]]]:
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise InputError(f"{name}: not valid GPX/XML ({exc})") from None
    if _local(root.tag) != "gpx":
        raise InputError(f"{name}: not GPX (root element <{_local(root.tag)}>)")
    per: dict[str, list[tuple[float, float, float]]] = {}
    tracks = [e for e in root if _local(e.tag) == "trk"]
    for k, trk in enumerate(tracks):
        tname = next((c.text for c in trk if _local(c.tag) == "name" and c.text), None)
        tid = (tname or f"trk{k + 1}").strip()
        if tid in per:
            tid = f"{tid}#{k + 1}"
        pts: list[tuple[float, float, float]] = []
        for pt in trk.iter():
            if _local(pt.tag) != "trkpt":
                continue
            where = f"{name}: track {tid!r} point {len(pts) + 1}"
            ttext = next((c.text for c in pt if _local(c.tag) == "time" and c.text), None)
            if ttext is None:
                raise InputError(f"{where}: no <time>")
            try:
                lat, lon = float(pt.attrib["lat"]), float(pt.attrib["lon"])
            except (KeyError, ValueError):
                raise InputError(f"{where}: lat/lon attributes missing or not numbers") from None
            pts.append((parse_time(ttext, what=where), lon, lat))
        per[tid] = pts
    return per


def read_gps(source: str | Path) -> list[GpsTrace]:
    """GPS traces from a GPX file (one trace per ``<trk>``) or a CSV ``id,time,lat,lon``.

    Raises
    ------
    InputError
        Unreadable file, a point without time or with bad coordinates, no trace, or
        ``source`` is not a path.
    """
    if not isinstance(source, (str, os.PathLike)):
        raise InputError(
            f"GPS traces: give a .gpx or .csv path (or GpsTrace objects), not "
            f"{type(source).__name__}"
        )
    path = Path(source)
    name = path.name
    text = read_text_file(path, what="GPS traces file")
    if path.suffix.lower() == ".csv":
        per: dict[str, list[tuple[float, float, float]]] = {}
        reader = csv.DictReader(io.StringIO(text))
        cols = set(reader.fieldnames or ())
        tkey = next((k for k in ("time", "t", "timestamp") if k in cols), None)
        if not {"id", "lat", "lon"} <= cols or tkey is None:
            raise InputError(f"{name}: GPS CSV needs a header with id,time,lat,lon")
        for k, row in enumerate(reader):
            where = f"{name} row {k + 1}"
            if row.get("id") in (None, ""):
                raise InputError(f"{where}: no id")
            t = parse_time(row[tkey], what=f"{where}: {tkey}")
            per.setdefault(str(row["id"]), []).append(
                (t, _num(row, "lon", where), _num(row, "lat", where))
            )
    elif path.suffix.lower() == ".gpx" or text.lstrip().startswith("<"):
        per = _read_gpx(text, name)
    else:
        raise InputError(f"{name}: GPS traces must be .gpx or .csv (id,time,lat,lon)")
    out = []
    for tid, pts in per.items():
        if not pts:
            continue
        arr = np.array(sorted(pts), dtype=np.float64)
        if np.any(np.abs(arr[:, 2]) > 90) or np.any(np.abs(arr[:, 1]) > 180):
            raise InputError(f"{name}: trace {tid!r} has a latitude or longitude out of range")
        _, first = np.unique(arr[:, 0], return_index=True)
        arr = arr[first]
        out.append(GpsTrace(tid, arr[:, 0], arr[:, 1:]))
    if not out:
        raise InputError(f"{name}: no GPS points")
    return out


# --------------------------------------------------------------------------- pose


@dataclass(frozen=True)
class AbsolutePose:
    """The camera's absolute pose: ``enu_from_world`` (car frame → ``frame``'s metres).

    Attributes
    ----------
    enu_from_world
        The similarity carrying the calibration's world frame onto ``frame``.
    frame
        The local east/north frame.
    source
        Where it came from (``locate candidate 1``, ``candidates file ...``).
    camera_world
        The camera in the car's frame that ``enu_from_world`` belongs to, when it is not the
        calibration's own: ``locate``'s leading candidates are bundle-adjusted (their focal
        length and orientation re-fitted with the map), so their camera differs slightly.
    """

    enu_from_world: Similarity2D
    frame: LocalFrame
    source: str = "given"
    camera_world: Camera | None = None


def pose_from_candidates_geojson(
    doc: dict[str, Any], calibration: CalibrationResult, *, rank: int = 1, name: str = "candidates"
) -> AbsolutePose:
    """Rebuild ``enu_from_world`` from a ``camloc locate`` candidate GeoJSON.

    A candidate carries ``lat``, ``lon``, ``heading_deg`` and ``scale``; with the scene's
    calibration (its camera in the car's frame) they fix the similarity: the camera's world
    heading is turned onto ``heading_deg`` and its centre placed at ``lat, lon`` (the frame
    is anchored there).

    Raises
    ------
    InputError
        Not a candidate collection, no candidate of that rank, or a candidate whose focal
        length or pitch disagrees with the calibration (the file was made from another scene).
    """
    feats = doc.get("features") if isinstance(doc, dict) else None
    if not isinstance(feats, list):
        raise InputError(f"{name}: not a GeoJSON FeatureCollection")
    cands = [
        f.get("properties") or {}
        for f in feats
        if isinstance(f, dict) and (f.get("properties") or {}).get("kind") == "candidate"
    ]
    if not cands:
        raise InputError(f"{name}: no candidate features (write it with camloc locate)")
    props = next((p for p in cands if p.get("rank") == rank), None)
    if props is None:
        raise InputError(f"{name}: no candidate of rank {rank} (it has {len(cands)})")
    try:
        lat, lon = float(props["lat"]), float(props["lon"])
        heading_enu = float(props["heading_deg"])
        scale = float(props.get("scale") or 1.0)
    except (KeyError, TypeError, ValueError):
        raise InputError(f"{name}: candidate {rank} lacks lat, lon or heading_deg") from None
    cam = calibration.camera
    heading_w, pitch_w, roll_w = cam.angles_deg
    focal = props.get("focal_px")
    pitch = props.get("pitch_deg")
    roll = props.get("roll_deg")
    # The leaders are bundle-adjusted (focal length and orientation re-fitted with the map:
    # a few per cent, a degree or two); a candidate of another scene differs far more.
    if (isinstance(focal, (int, float)) and abs(focal - cam.focal_px) > 0.35 * cam.focal_px) or (
        isinstance(pitch, (int, float)) and abs(pitch - pitch_w) > 8.0
    ):
        raise InputError(
            f"{name}: candidate {rank} (focal {focal} px, pitch {pitch}°) was not computed from "
            f"this scene (focal {cam.focal_px:.1f} px, pitch {pitch_w:.1f}°)"
        )
    camera_world = Camera.from_center(
        float(focal) if isinstance(focal, (int, float)) else cam.focal_px,
        cam.principal_point,
        rotation_from_angles(
            heading_w,
            float(pitch) if isinstance(pitch, (int, float)) else pitch_w,
            float(roll) if isinstance(roll, (int, float)) else roll_w,
        ),
        cam.center_in_world,
    )
    theta = math.radians(heading_w - heading_enu)
    c_xy = cam.center_in_world[:2]
    translation = -scale * rot2(theta) @ c_xy
    return AbsolutePose(
        Similarity2D(theta, translation, scale),
        LocalFrame(lat=lat, lon=lon),
        f"{name} candidate {rank}",
        camera_world,
    )


# --------------------------------------------------------------------------- settings/results


@dataclass(frozen=True)
class GuideSettings:
    """Noise model and decision knobs of :func:`match_people` (module docstring).

    Attributes
    ----------
    gps_sigma_m
        GPS error per axis, metres.
    gps_correlation_s
        Time over which GPS errors stay correlated; samples closer count as one.
    crowd_spread_m
        How far apart, per axis, unrelated people and traces typically are (the
        alternative hypothesis of the scores).
    click_sigma_px
        Error of a foot pixel (a detector's box bottom), pixels per coordinate.
    step_s
        Time grid step, seconds.
    min_overlap_s
        Least common time for a (track, trace) pair to be matched.
    max_track_gap_s, max_gps_gap_s
        Longer gaps between samples are not interpolated.
    certainty
        Threshold of "certain".
    max_evaluations
        The assignment over time is evaluated at most this many times.
    n_samples
        Monte Carlo draws of the projection sigma.
    proposals
        Relative mode: how many transform proposals compete in the certainty.
    """

    gps_sigma_m: float = 4.0
    gps_correlation_s: float = 10.0
    crowd_spread_m: float = 15.0
    click_sigma_px: float = 3.0
    step_s: float = 1.0
    min_overlap_s: float = 3.0
    max_track_gap_s: float = 3.0
    max_gps_gap_s: float = 15.0
    certainty: float = 0.99
    max_evaluations: int = 60
    n_samples: int = 100
    proposals: int = 8

    def check(self) -> None:
        """Raise :class:`InputError` on a meaningless value."""
        for name in ("gps_sigma_m", "step_s", "gps_correlation_s", "crowd_spread_m"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"{name} must be positive, not {v}")
        if not (math.isfinite(self.click_sigma_px) and self.click_sigma_px >= 0):
            raise InputError(f"click_sigma_px must be >= 0, not {self.click_sigma_px}")
        if not (0.5 <= self.certainty < 1.0):
            raise InputError(f"certainty must be in [0.5, 1), not {self.certainty}")


@dataclass(frozen=True)
class GuideMatch:
    """A track's outcome: its trace (or none) and how certain, since when."""

    track: str
    gps: str | None
    certainty: float
    certain_after_s: float | None
    certain_at_s: float | None
    overlap_s: float
    mean_distance_m: float | None
    median_distance_m: float | None
    score: float
    reason: str | None = None
    stable_after_s: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {
            "track": self.track,
            "gps": self.gps,
            "certainty": round(self.certainty, 6),
            "certain_after_s": self.certain_after_s,
            "certain_at": None if self.certain_at_s is None else format_time(self.certain_at_s),
            "stable_after_s": self.stable_after_s,
            "overlap_s": self.overlap_s,
            "mean_distance_m": self.mean_distance_m,
            "median_distance_m": self.median_distance_m,
            "score": round(self.score, 4),
            **({"reason": self.reason} if self.reason else {}),
        }


@dataclass
class GuideResult:
    """What :func:`match_people` found.

    ``matches`` holds every track (``gps`` None when unmatched, with a ``reason``);
    ``unmatched_gps`` the traces no track took, with a reason. ``enu_from_world`` and
    ``frame`` place the ground tracks (given in absolute mode, solved in relative mode).
    """

    mode: str
    matches: list[GuideMatch]
    unmatched_gps: list[dict[str, Any]]
    enu_from_world: Similarity2D | None
    frame: LocalFrame
    # per-point data: left out of repr() (80,437 characters for 4 people over 60 s)
    ground_tracks_en: dict[str, FloatArray] = field(repr=False)
    ground_times_s: dict[str, FloatArray] = field(repr=False)
    gps_en: dict[str, FloatArray] = field(repr=False)
    gps_times_s: dict[str, FloatArray] = field(repr=False)
    timeline: list[dict[str, Any]] = field(repr=False)
    settings: GuideSettings = field(repr=False)
    camera_world_xy: FloatArray = field(repr=False)
    pose_source: str | None = None
    solved_pose: dict[str, Any] | None = None
    warnings: list[str] = field(default_factory=list)

    def match_of(self, track: str) -> GuideMatch:
        """The outcome of one track."""
        return next(m for m in self.matches if m.track == track)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready report."""
        s = self.settings
        return {
            "mode": self.mode,
            "pose_source": self.pose_source,
            "solved_pose": self.solved_pose,
            "matches": [m.to_dict() for m in self.matches if m.gps is not None],
            "unmatched_tracks": [
                {"track": m.track, "reason": m.reason, "certainty": round(m.certainty, 6)}
                for m in self.matches
                if m.gps is None
            ],
            "unmatched_gps": self.unmatched_gps,
            "timeline": self.timeline,
            "settings": {
                "gps_sigma_m": s.gps_sigma_m,
                "gps_correlation_s": s.gps_correlation_s,
                "crowd_spread_m": s.crowd_spread_m,
                "click_sigma_px": s.click_sigma_px,
                "step_s": s.step_s,
                "min_overlap_s": s.min_overlap_s,
                "certainty": s.certainty,
            },
            "warnings": self.warnings,
        }

    def to_geojson(self) -> dict[str, Any]:
        """People's ground tracks (LineStrings, lat/lon, with their GPS id), the traces and
        the camera; needs a placed result (absolute, or relative with a solved pose)."""
        if self.enu_from_world is None:
            raise InputError("no absolute pose: the ground tracks cannot be placed on the map")
        feats: list[dict[str, Any]] = []
        by_track = {m.track: m for m in self.matches}
        for tid, en in self.ground_tracks_en.items():
            ll = self.frame.points_geographic_from_enu(en)
            m = by_track[tid]
            feats.append(
                {
                    "type": "Feature",
                    "geometry": {"type": "LineString", "coordinates": _coords(ll)},
                    "properties": {
                        "kind": "person_track",
                        "track": tid,
                        "gps": m.gps,
                        "certainty": round(m.certainty, 6),
                        "certain_after_s": m.certain_after_s,
                        "start": format_time(float(self.ground_times_s[tid][0])),
                        "end": format_time(float(self.ground_times_s[tid][-1])),
                    },
                }
            )
        for gid, en in self.gps_en.items():
            ll = self.frame.points_geographic_from_enu(en)
            feats.append(
                {
                    "type": "Feature",
                    "geometry": {"type": "LineString", "coordinates": _coords(ll)},
                    "properties": {"kind": "gps_trace", "gps": gid},
                }
            )
        if self.solved_pose is not None or self.pose_source is not None:
            cam = self.camera_lonlat()
            feats.append(
                {
                    "type": "Feature",
                    "geometry": {"type": "Point", "coordinates": [cam[0], cam[1]]},
                    "properties": {"kind": "camera", "mode": self.mode},
                }
            )
        return {
            "type": "FeatureCollection",
            "features": feats,
            "properties": {"mode": self.mode, "pose_source": self.pose_source},
        }

    def camera_lonlat(self) -> tuple[float, float]:
        """The camera's ``(lon, lat)`` under the (given or solved) pose."""
        assert self.enu_from_world is not None
        en = self.enu_from_world.apply(self.camera_world_xy)
        lon, lat = self.frame.geographic_from_enu(float(en[0]), float(en[1]))
        return float(lon), float(lat)


def _coords(lonlat: FloatArray) -> list[list[float]]:
    return [[round(float(a), 8), round(float(b), 8)] for a, b in lonlat]


# --------------------------------------------------------------------------- projection


def _project_track(
    calibration: CalibrationResult, track: PixelTrack, settings: GuideSettings, seed: int
) -> tuple[FloatArray, FloatArray]:
    """Ground points ``(N, 2)`` in the car's world frame and their sigma ``(N,)``, metres."""
    pixels = _pixels(track.foot_px, f"track {track.id}")
    cam = calibration.camera
    xy = np.empty((len(pixels), 2))
    sigma = np.zeros(len(pixels))
    for c0 in range(0, len(pixels), _CHUNK):
        chunk = pixels[c0 : c0 + _CHUNK]
        centres, focals, rotations, px = _draws_posed(
            calibration, chunk, settings.n_samples, settings.click_sigma_px, seed + c0
        )
        pts = _ground(centres, _rays(px, focals, cam.principal_point, rotations))
        bad = ~np.all(np.isfinite(pts[0]), axis=-1)
        if np.any(bad):
            k = c0 + int(np.argmax(bad))
            u, v = pixels[k]
            raise InputError(
                f"track {track.id}: foot pixel ({u:g}, {v:g}) at "
                f"{format_time(track.times_s[k])} is at or above the horizon: its ray never "
                "meets the ground"
            )
        xy[c0 : c0 + len(chunk)] = pts[0, :, :2]
        draws = pts[1:, :, :2]
        if len(draws) > 1:
            with np.errstate(invalid="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                var = np.nanvar(draws, axis=0, ddof=1).mean(axis=-1)
            # Far points whose draws often miss the ground: a huge sigma, as it should be.
            sigma[c0 : c0 + len(chunk)] = np.sqrt(np.nan_to_num(var, nan=1e6))
    return xy, np.minimum(sigma, 1e3)


def _resample(
    times: FloatArray, values: FloatArray, grid: FloatArray, max_gap_s: float
) -> FloatArray:
    """Linear interpolation of ``values (N, D)`` onto ``grid``; NaN outside or across gaps."""
    out = np.full((len(grid), values.shape[1]), np.nan)
    if len(times) == 0:
        return out
    if len(times) == 1:
        hit = np.abs(grid - times[0]) <= 1e-9
        out[hit] = values[0]
        return out
    inside = (grid >= times[0] - 1e-9) & (grid <= times[-1] + 1e-9)
    idx = np.clip(np.searchsorted(times, grid, side="right"), 1, len(times) - 1)
    gap = times[idx] - times[idx - 1]
    ok = inside & (gap <= max_gap_s + 1e-9)
    for d in range(values.shape[1]):
        out[ok, d] = np.interp(grid[ok], times, values[:, d])
    return out


def _assign(W: FloatArray, allowed: npt.NDArray[np.bool_]) -> tuple[float, list[int]]:
    """Best total score and, per track, its trace index or -1 (no match)."""
    from scipy.optimize import linear_sum_assignment

    n, m = W.shape
    C = np.full((n, m + n), _BIG)
    C[:, :m] = np.where(allowed, -W, _BIG)
    C[np.arange(n), m + np.arange(n)] = 0.0
    rows, cols = linear_sum_assignment(C)
    total = 0.0
    out = [-1] * n
    for r, c in zip(rows, cols, strict=True):
        if C[r, c] >= _BIG:
            return -math.inf, out
        if c < m:
            out[r] = int(c)
            total += float(W[r, c])
    return total, out


def _assign_forbidding(W: FloatArray, allowed: npt.NDArray[np.bool_], i: int, j: int) -> float:
    """Best total score with track ``i``'s outcome ``j`` (-1: no match) forbidden."""
    from scipy.optimize import linear_sum_assignment

    n, m = W.shape
    C = np.full((n, m + n), _BIG)
    C[:, :m] = np.where(allowed, -W, _BIG)
    C[np.arange(n), m + np.arange(n)] = 0.0
    C[i, m + i if j < 0 else j] = _BIG
    rows, cols = linear_sum_assignment(C)
    if np.any(C[rows, cols] >= _BIG):
        return -math.inf
    return float(-C[rows, cols].sum())


def _rigid_fit(src: FloatArray, dst: FloatArray, w: FloatArray, scale: float) -> Similarity2D:
    """Weighted rigid ``dst ≈ scale · R src + T`` (the scale fixed)."""
    ws = w / w.sum()
    ms = (ws[:, None] * src).sum(axis=0)
    md = (ws[:, None] * dst).sum(axis=0)
    a, b = src - ms, dst - md
    sxx = float((ws * (a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1])).sum())
    sxy = float((ws * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])).sum())
    theta = math.atan2(sxy, sxx)
    return Similarity2D(theta, md - scale * rot2(theta) @ ms, scale)


# --------------------------------------------------------------------------- matching


@dataclass
class _Grid:
    times: FloatArray  # (K,)
    P: FloatArray  # (n, K, 2) ground tracks, car world frame
    SP: FloatArray  # (n, K) projection sigma
    G: FloatArray  # (m, K, 2) traces, local ENU
    w: float


def _scores(
    grid: _Grid, sim: Similarity2D, settings: GuideSettings, upto: int | None = None
) -> tuple[FloatArray, ...]:
    """Per-sample pair scores ``(n, m, K)``, validity and distances under ``sim``.

    ``upto``: only the grid times ``0..upto`` (the arrays are then that long).
    """
    end = None if upto is None else upto + 1
    P, SP, G = grid.P[:, :end], grid.SP[:, :end], grid.G[:, :end]
    Q = sim.apply(P.reshape(-1, 2)).reshape(P.shape)
    D = np.linalg.norm(Q[:, None] - G[None], axis=-1)  # (n, m, K)
    s2 = settings.gps_sigma_m**2 + (sim.scale * SP[:, None, :]) ** 2
    valid = np.isfinite(D)
    d2 = np.where(valid, D, 0.0) ** 2
    big2 = s2 + settings.crowd_spread_m**2
    with np.errstate(invalid="ignore"):
        llr = np.log(big2 / s2) - 0.5 * d2 * (1.0 / s2 - 1.0 / big2)
    # Robust: one sample (a GPS jump, a detector's wrong box) costs at most _LLR_FLOOR.
    per = np.where(valid, grid.w * np.maximum(llr, _LLR_FLOOR), 0.0)
    return per, valid, D


def match_people(
    calibration: CalibrationResult,
    tracks: Sequence[PixelTrack],
    traces: Sequence[GpsTrace],
    *,
    pose: AbsolutePose | None = None,
    settings: GuideSettings | None = None,
) -> GuideResult:
    """Match people's pixel tracks to GPS traces (module docstring).

    Parameters
    ----------
    calibration
        The calibrated camera (its ``camera`` in the car's world frame).
    tracks
        People's foot pixels over time (:func:`read_tracks`).
    traces
        GPS traces (:func:`read_gps`).
    pose
        The camera's absolute pose; None: relative mode (the transform is solved).
    settings
        Noise model and knobs.

    Raises
    ------
    InputError
        No tracks or traces, a foot pixel above the horizon, traces that overlap no track in
        time, bad settings.
    """
    if settings is not None and not isinstance(settings, GuideSettings):
        raise InputError(f"settings must be a GuideSettings, not {type(settings).__name__}")
    settings = settings or GuideSettings()
    settings.check()
    if pose is not None and pose.camera_world is not None:
        from dataclasses import replace as _replace

        calibration = _replace(calibration, camera=pose.camera_world)
    if not tracks:
        raise InputError("no tracks")
    if not traces:
        raise InputError("no GPS traces")
    t_lo = min(float(t.times_s[0]) for t in tracks)
    t_hi = max(float(t.times_s[-1]) for t in tracks)
    g_lo = min(float(g.times_s[0]) for g in traces)
    g_hi = max(float(g.times_s[-1]) for g in traces)
    if g_hi < t_lo or g_lo > t_hi:
        raise InputError(
            f"the GPS traces ({format_time(g_lo)} to {format_time(g_hi)}) do not overlap the "
            f"tracks in time ({format_time(t_lo)} to {format_time(t_hi)}): check --video-start "
            "and the time zones"
        )
    n_grid = math.floor((t_hi - t_lo) / settings.step_s) + 1
    if n_grid > _MAX_GRID:
        raise InputError(
            f"the tracks span {t_hi - t_lo:.0f} s: more than {_MAX_GRID} steps of "
            f"{settings.step_s:g} s; use a larger step"
        )
    if len(tracks) * len(traces) * n_grid > _MAX_CELLS:
        raise InputError(
            f"too much to match at once: {len(tracks)} tracks x {len(traces)} traces x "
            f"{n_grid} steps of {settings.step_s:g} s; use a larger step or split the video"
        )
    times: FloatArray = t_lo + settings.step_s * np.arange(n_grid, dtype=np.float64)
    # Ground tracks in the car's world frame.
    P = np.full((len(tracks), n_grid, 2), np.nan)
    SP = np.full((len(tracks), n_grid), np.nan)
    raw_ground: dict[str, FloatArray] = {}
    for i, tr in enumerate(tracks):
        xy, sig = _project_track(calibration, tr, settings, _SEED + i)
        raw_ground[tr.id] = xy
        res = _resample(tr.times_s, np.column_stack([xy, sig]), times, settings.max_track_gap_s)
        P[i], SP[i] = res[:, :2], res[:, 2]
    # Traces in a local frame: the pose's, or one at the traces' centre.
    if pose is not None:
        frame = pose.frame
    else:
        allll = np.vstack([g.lonlat for g in traces])
        frame = LocalFrame(lat=float(allll[:, 1].mean()), lon=float(allll[:, 0].mean()))
    G = np.full((len(traces), n_grid, 2), np.nan)
    gps_en: dict[str, FloatArray] = {}
    for j, g in enumerate(traces):
        en = frame.points_enu_from_geographic(g.lonlat)
        gps_en[g.id] = en
        G[j] = _resample(g.times_s, en, times, settings.max_gps_gap_s)
    grid = _Grid(times, P, SP, G, min(1.0, settings.step_s / settings.gps_correlation_s))
    both = np.isfinite(P[:, None, :, 0]) & np.isfinite(G[None, :, :, 0])  # (n, m, K)
    if not both.any():
        raise InputError(
            f"no GPS trace overlaps any track in time (traces {format_time(g_lo)} to "
            f"{format_time(g_hi)}, tracks {format_time(t_lo)} to {format_time(t_hi)}): check "
            "--video-start and the time zones"
        )
    overlap_cum = np.cumsum(both, axis=-1) * settings.step_s  # (n, m, K)
    # Evaluation times: where anything overlaps, at most max_evaluations of them.
    any_k = np.flatnonzero(both.any(axis=(0, 1)))
    first_k = int(any_k[0])
    evals = np.unique(
        np.round(np.linspace(first_k, n_grid - 1, min(settings.max_evaluations, n_grid - first_k)))
    ).astype(int)
    scale = pose.enu_from_world.scale if pose is not None else 1.0  # the car frame is metric
    abs_cum = None
    if pose is not None:
        abs_cum = np.cumsum(_scores(grid, pose.enu_from_world, settings)[0], axis=-1)

    previous: list[Similarity2D] = []

    def solve_at(k: int) -> tuple[Similarity2D | None, list[tuple[float, list[int], FloatArray]]]:
        """Transform(s) and their (total, assignment, W) at grid index k, best first."""
        allowed = overlap_cum[..., k] > 0
        if pose is not None and abs_cum is not None:
            W = abs_cum[..., k]
            total, assign = _assign(W, allowed)
            return pose.enu_from_world, [(total, assign, W)]
        sims = _proposals(grid, both, k, overlap_cum[..., k], _MAX_PROPOSALS, scale)
        if previous:
            sims.append(previous[0])  # the last evaluation's answer, refitted on more data
        scored: list[tuple[float, list[int], FloatArray, Similarity2D]] = []
        for sim in sims:
            for _it in range(2):
                W = _scores(grid, sim, settings, k)[0].sum(axis=-1)
                total, assign = _assign(W, allowed)
                refit = _refit(grid, both, k, assign, scale)
                if refit is None:
                    break
                sim = refit
            W = _scores(grid, sim, settings, k)[0].sum(axis=-1)
            total, assign = _assign(W, allowed)
            scored.append((total, assign, W, sim))
        scored.sort(key=lambda s: -s[0])
        top = scored[: settings.proposals]
        if not top:
            return None, []
        previous[:] = [top[0][3]]
        return top[0][3], [(s[0], s[1], s[2]) for s in top]

    timeline: list[dict[str, Any]] = []
    history: list[tuple[int, list[int], list[float]]] = []
    final_sim: Similarity2D | None = None
    for k in evals:
        sim, sols = solve_at(int(k))
        allowed = overlap_cum[..., k] > 0
        if not sols:
            history.append((int(k), [-1] * len(tracks), [0.0] * len(tracks)))
            continue
        best_total, assign, _W = sols[0]
        certs: list[float] = []
        for i in range(len(tracks)):
            alt = max(_assign_forbidding(W, allowed, i, assign[i]) for _t, _a, W in sols)
            # Other proposals that give track i another outcome also compete.
            for tot, a, _W2 in sols[1:]:
                if a[i] != assign[i]:
                    alt = max(alt, tot)
            certs.append(_certainty(best_total, alt))
        history.append((int(k), assign, certs))
        final_sim = sim
        timeline.append(
            {
                "time": format_time(float(times[k])),
                "t_s": round(float(times[k] - t_lo), 3),
                "assignment": {
                    tracks[i].id: (None if assign[i] < 0 else traces[assign[i]].id)
                    for i in range(len(tracks))
                },
                "certainty": {tracks[i].id: round(certs[i], 6) for i in range(len(tracks))},
            }
        )
    # Final outcome and time to certain.
    _k_last, final_assign, final_certs = history[-1]
    sim_final = pose.enu_from_world if pose is not None else final_sim
    per_f, _valid_f, D_f = (
        _scores(grid, sim_final, settings) if sim_final is not None else (None, None, None)
    )
    matches: list[GuideMatch] = []
    for i, tr in enumerate(tracks):
        j = final_assign[i]
        since: int | None = None
        for k, a, c in reversed(history):
            if a[i] == j and c[i] >= settings.certainty:
                since = k
            else:
                break
        stable: int | None = None
        for k, a, _c in reversed(history):
            if a[i] != j:
                break
            stable = k
        stable_after = (
            None
            if stable is None
            else round(max(0.0, float(times[stable]) - float(tr.times_s[0])), 3)
        )
        certain_at = None if since is None else float(times[since])
        after = (
            None if certain_at is None else round(max(0.0, certain_at - float(tr.times_s[0])), 3)
        )
        if j >= 0 and overlap_cum[i, j, -1] < settings.min_overlap_s - 1e-9:
            matches.append(
                GuideMatch(
                    tr.id,
                    None,
                    final_certs[i],
                    None,
                    None,
                    0.0,
                    None,
                    None,
                    0.0,
                    f"its best trace {traces[j].id} overlaps it for only "
                    f"{overlap_cum[i, j, -1]:g} s (< {settings.min_overlap_s:g} s)",
                    stable_after,
                )
            )
        elif j >= 0 and D_f is not None and per_f is not None:
            d = D_f[i, j][both[i, j]]
            matches.append(
                GuideMatch(
                    tr.id,
                    traces[j].id,
                    final_certs[i],
                    after,
                    certain_at,
                    float(overlap_cum[i, j, -1]),
                    round(float(np.mean(d)), 3),
                    round(float(np.median(d)), 3),
                    float(per_f[i, j].sum()),
                    None,
                    stable_after,
                )
            )
        else:
            ov = overlap_cum[i, :, -1]
            if not np.any(ov > 0):
                reason = "no GPS trace overlaps it in time"
            else:
                reason = "no GPS trace stays close enough to it"
            matches.append(
                GuideMatch(
                    tr.id,
                    None,
                    final_certs[i],
                    after,
                    certain_at,
                    0.0,
                    None,
                    None,
                    0.0,
                    reason,
                    stable_after,
                )
            )
    taken = {m.gps for m in matches if m.gps is not None}
    unmatched_gps = []
    for j, g in enumerate(traces):
        if g.id in taken:
            continue
        if not both[:, j].any():
            reason = "it overlaps no track in time"
        else:
            reason = "no track in view stays close enough to it"
        unmatched_gps.append({"gps": g.id, "reason": reason})
    ground_en: dict[str, FloatArray] = {}
    if sim_final is not None:
        ground_en = {tid: sim_final.apply(xy) for tid, xy in raw_ground.items()}
    result = GuideResult(
        mode="absolute" if pose is not None else "relative",
        matches=matches,
        unmatched_gps=unmatched_gps,
        enu_from_world=sim_final,
        frame=frame,
        ground_tracks_en=ground_en,
        ground_times_s={t.id: t.times_s for t in tracks},
        gps_en=gps_en,
        gps_times_s={g.id: g.times_s for g in traces},
        timeline=timeline,
        settings=settings,
        camera_world_xy=np.asarray(calibration.camera.center_in_world[:2], dtype=float),
        pose_source=None if pose is None else pose.source,
    )
    if pose is None:
        result.solved_pose = _solved_pose(result, calibration, grid, both, final_assign)
        if result.solved_pose is None:
            result.warnings.append(
                "no track matched: the camera's transform to the GPS frame is not determined"
            )
            result.enu_from_world = None  # nothing places the ground tracks
            result.ground_tracks_en = {}
    return result


def _certainty(best: float, alt: float) -> float:
    if not math.isfinite(alt):
        return 1.0
    return float(1.0 / (1.0 + math.exp(min(700.0, alt - best))))


def _proposals(
    grid: _Grid,
    both: npt.NDArray[np.bool_],
    k: int,
    overlap_s: FloatArray,
    most: int,
    scale: float,
) -> list[Similarity2D]:
    """Relative mode: one rigid transform per (track, trace) pair with common time up to k
    (at most ``most``, the longest common times first), each from their data ≤ k."""
    sims = []
    pairs = np.argwhere(overlap_s > 0)
    order = np.argsort(-overlap_s[overlap_s > 0], kind="stable")
    for i, j in pairs[order][:most]:
        sel = both[i, j, : k + 1]
        src = grid.P[i, : k + 1][sel]
        if len(src) < 2 or np.ptp(src, axis=0).max() < 1e-6:
            continue
        dst = grid.G[j, : k + 1][sel]
        w = 1.0 / (1.0 + grid.SP[i, : k + 1][sel] ** 2)
        sims.append(_rigid_fit(src, dst, w, scale))
    return sims


def _refit(
    grid: _Grid, both: npt.NDArray[np.bool_], k: int, assign: list[int], scale: float
) -> Similarity2D | None:
    """Relative mode: the rigid transform fitted on all matched pairs' samples ≤ k."""
    src, dst, w = [], [], []
    for i, j in enumerate(assign):
        if j < 0:
            continue
        sel = both[i, j, : k + 1]
        src.append(grid.P[i, : k + 1][sel])
        dst.append(grid.G[j, : k + 1][sel])
        w.append(1.0 / (1.0 + grid.SP[i, : k + 1][sel] ** 2))
    if not src:
        return None
    s, d, ww = np.vstack(src), np.vstack(dst), np.concatenate(w)
    if len(s) < 2 or np.ptp(s, axis=0).max() < 1e-6:
        return None
    return _rigid_fit(s, d, ww, scale)


def _solved_pose(
    result: GuideResult,
    calibration: CalibrationResult,
    grid: _Grid,
    both: npt.NDArray[np.bool_],
    assign: list[int],
) -> dict[str, Any] | None:
    """The camera placed by the solved transform, with a 1-sigma position estimate."""
    sim = result.enu_from_world
    if sim is None or all(j < 0 for j in assign):
        return None
    src, res, sig2 = [], [], []
    for i, j in enumerate(assign):
        if j < 0:
            continue
        sel = both[i, j]
        p = grid.P[i][sel]
        src.append(p)
        res.append(sim.apply(p) - grid.G[j][sel])
        sig2.append(result.settings.gps_sigma_m**2 + grid.SP[i][sel] ** 2)
    s = np.vstack(src)
    r = np.vstack(res)
    s2 = np.concatenate(sig2)
    n_eff = max(1.0, len(s) * grid.w)
    sigma2 = float(np.mean(s2))
    centroid = s.mean(axis=0)
    spread2 = float(np.mean(np.sum((s - centroid) ** 2, axis=1)))
    var_theta = sigma2 / max(n_eff * spread2, 1e-9)
    c_xy = calibration.camera.center_in_world[:2]
    lever2 = float(np.sum((c_xy - centroid) ** 2))
    sigma_pos = math.sqrt(sigma2 / n_eff + lever2 * var_theta)
    lon, lat = result.camera_lonlat()
    heading_w = calibration.camera.angles_deg[0]
    return {
        "lat": lat,
        "lon": lon,
        "heading_deg": round((heading_w - math.degrees(sim.rotation_rad)) % 360.0, 3),
        "sigma_m": round(sigma_pos, 3),
        "rotation_sigma_deg": round(math.degrees(math.sqrt(var_theta)), 3),
        "rms_residual_m": round(float(np.sqrt(np.mean(np.sum(r**2, axis=1)))), 3),
        "enu_from_world": {
            "rotation_rad": sim.rotation_rad,
            "translation_m": [float(x) for x in sim.translation_m],
            "scale": sim.scale,
            "frame_lat": result.frame.lat0,
            "frame_lon": result.frame.lon0,
        },
    }
