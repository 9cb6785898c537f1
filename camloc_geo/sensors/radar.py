"""Virtual radar: vehicle speeds from a video of a calibrated camera.

The camera is calibrated once from a snapshot (:func:`camloc_geo.relative.calibrate`); its
ground plane ``z = 0`` turns a pixel where a vehicle touches the ground into metres. The
radar (see ``docs/radar.md``):

1. **Vehicles.** Background subtraction at reduced resolution, in colour (a car may have
   the road's grey level): the background starts as the median of 9 frames sampled over
   the video and is updated (running average) where no vehicle is; pixels more than 30
   levels away in some channel are foreground, except cast shadows (the background dimmed
   by the same ratio, 0.35-0.9, in every channel); pixels above a weak threshold (6 levels,
   or more in a noisy video) between two foreground pixels of their column are
   foreground too, where a detection pixel covers at most 1 m of road (a silver or
   road-grey body's lit face near the road's grey keeps the vehicle whole down to its
   wheels, :func:`_foreground`); morphology and connected components
   give blobs; blobs are associated frame to frame by IoU with the track's
   predicted box (Hungarian assignment, :func:`scipy.optimize.linear_sum_assignment`).
   The pieces of one vehicle (a road-grey car falls apart under the threshold) inside its
   track's predicted box are joined by that motion (:func:`_join_fragments`); a track is
   cut where its features' motion turns back (it came out of a merge on another vehicle).
   A vehicle whose track was lost (hidden behind another for longer than a track may
   coast) and found again is joined by its motion too: two tracks whose ground contacts
   lie where the other's fitted motion puts its vehicle (within 4 s) are refitted as one
   track, or, where that fit would be less sure than the better of the two (or one
   repeats the other's frames), the less sure one is reported skipped as the other's
   fragment (:func:`_fragment_of`).
   With ``tracks`` (boxes per frame from any detector) the given boxes and ids are used.
2. **Ground contact.** In each frame, the lowest corner of the vehicle's foreground
   silhouette, to sub-pixel: the bottom outline around its lowest point is fitted with two
   lines meeting at a corner (on a shallow outline, far away, many pixels share the lowest
   row, and taking one of them slides the contact along the vehicle). For a vehicle seen
   from above, that corner is a tyre on the road or a bottom corner of the body, up to its
   ground clearance above it (unknown: it is in ``sigma_kmh``, not corrected). Without a
   usable silhouette (given boxes with no foreground), the bottom-centre of the box is
   used (see step 4).
3. **KLT.** Features (:func:`cv2.goodFeaturesToTrack`) inside each vehicle are tracked with
   :func:`cv2.calcOpticalFlowPyrLK`. Their median image motion predicts the contact pixel's
   motion; where the measured contact jumps away from it (another corner became the lowest,
   two vehicles merged, an occlusion) the track is split into segments. The same motion
   predicts the vehicle's box in the next frame (association, coasting through merged
   blobs). Features are never cast onto the ground themselves: their height is unknown.
4. **Speed.** The contact's ground positions are fitted, by iteratively reweighted (Huber)
   least squares weighted by each frame's ground variance (a pixel's footprint on the
   road), with one velocity shared by all segments and one offset per segment (constant
   velocity over the track). Speed = |velocity| in km/h. Frames where a detection pixel
   at the contact covers more than 1 m of road are not used (far away the contact moves
   in steps of a pixel and stalls; a track left too short is skipped, "too far");
   segments that fit one offset, or whose offsets lie within 0.5 m (the contact wandering
   on its corner, not another corner), are merged (:func:`_merge_segments`), segments whose
   contact stands still while the features move are left out (:func:`_still_segments`),
   and where segments' speeds disagree beyond their noise the standard error of their
   random-effects mean is model error (:func:`_segments_pooled`).

Without a silhouette in most frames (boxes given for a video whose background shows no
foreground) a cuboid (weak prior: a car, 4.5 × 1.8 × 1.5 m) moving at constant velocity
along the fitted direction is fitted (soft-L1) so that its projected image box (plus a
constant margin in pixels) matches the vehicle's box in every frame, and its velocity is
the reported one (a cuboid is not a car: on two-box cars with ground clearance it reads
2-5 % fast, so it is not used where the contact is seen). Each track is fitted as soon as
it ends, so a long video holds only the active tracks in memory.

Uncertainty (``sigma_kmh``), combined in quadrature: the fit's standard error (from its
residuals); the contact's unknown height, not corrected: its root mean square over the
camera's height ``H`` (given boxes: a tyre on the road or the body's lower edge up to 0.2 m
up, uniform, 0.115 m; a detected silhouette's lowest corner: 0.03 m, measured; 0.6 m for a
silhouette lower than 1.5 m, a piece of a vehicle); model error: half the disagreement
of the track's two halves in time beyond their noise (a contact that followed another
vehicle through a merge, a corner sliding along the body); the
calibration's part: the contact pixels are recast and refitted with ``n_samples`` cameras
drawn as in :mod:`camloc_geo.sensors` (camera centre and focal length perturbed by the
calibration's sigmas; rotation fixed), and the spread of the speeds taken.

Tracks shorter than ``min_track_s``, vehicles never wholly inside the frame, stationary
blobs, contacts above the horizon and fragments of a vehicle measured on another track
(reason ``a fragment of the vehicle tracked over frames ...``) are reported with
``status="skipped"`` and a reason: a skipped entry is never a vehicle with a speed.
A measured speed whose ``sigma_kmh`` exceeds 5 % of it carries a ``warning`` naming the
main cause (a track that held other vehicles, a piece of a vehicle, ...).
"""

from __future__ import annotations

import csv
import io
import itertools
import json
import logging
import math
import os
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from camloc_geo._errors import InputError
from camloc_geo._io import read_text_file
from camloc_geo._limits import (
    MAX_TRACK_BOXES,
    MAX_TRACKS_BYTES,
    MAX_VIDEO_FRAMES,
    MAX_VIDEO_PIXELS,
    check_regular_file,
)
from camloc_geo.sensors import _draws_posed, _ground, _rays

if TYPE_CHECKING:
    from camloc_geo.relative import CalibrationResult

__all__ = [
    "CSV_COLUMNS",
    "RadarResult",
    "VehicleSpeed",
    "VideoInfo",
    "measure_speeds",
    "probe_video",
    "read_tracks",
]

log = logging.getLogger(__name__)

FloatArray = npt.NDArray[np.float64]
Box = tuple[float, float, float, float]
TrackBoxes = dict[int, dict[int, Box]]
"""Given tracks: ``{vehicle id: {frame index (0-based): (x1, y1, x2, y2)}}``, pixels."""

CSV_COLUMNS = (
    "vehicle_id",
    "status",
    "speed_kmh",
    "sigma_kmh",
    "first_frame",
    "last_frame",
    "n_frames",
    "duration_s",
    "distance_m",
    "heading_deg",
    "contact",
    "reason",
    "warning",
)
"""Columns of :meth:`RadarResult.to_csv`, one row per vehicle (``warning`` added last)."""

_SEED = 20261123
_MAX_BLOBS = 64  # largest blobs kept per frame (bounds the work per frame)
_MAX_MISSED = 3  # frames a detected track may go unseen before it is closed
_MAX_COAST_S = 1.5  # longest a track may stay hidden in a merged blob
_MIN_DETECTED_FRAMES = 3  # shorter detections are noise, not vehicles
_MAX_FEATURES = 40
_MIN_PIECE_PX = 6  # reduced pixels: smaller foreground pieces are noise, never joined
_FG_THRESHOLD = 30  # grey levels (largest channel) from the background: foreground
# Bridges: pixels above a weak threshold lying between two foreground (above _FG_THRESHOLD)
# pixels of one column, each at most _FG_BRIDGE_PX away, are foreground too (a silver or
# road-grey body's lit face is 5-15 levels from the road's grey: the body fell apart, its
# lower part lost, its contact read high and the speed fast). A bridge never grows the
# silhouette's outline outward (a halo of a pixel round every vehicle reads it slow), and
# is vertical only (rows bridged too joined vehicles side by side on development seeds). The
# weak threshold follows the frame's noise: _FG_WEAK_NOISE times the median level (the
# background's pixels), at least _FG_WEAK_MIN, at most _FG_THRESHOLD.
_FG_WEAK_MIN = 6  # grey levels
_FG_WEAK_NOISE = 5.0  # times the frame's median level (about 6 noise sigmas)
_FG_BRIDGE_PX = 32  # reduced pixels: longest vertical gap bridged
_BG_RATE = 0.02  # background update rate per frame, where no foreground
_SHADOW_RATIO = (0.35, 0.9)  # a shadow dims every channel of the background by this much
_SHADOW_SPREAD = 0.1  # ... by nearly the same ratio (a colour change is a vehicle)
_TEXTURE_MIN = 4.0  # grey levels: local deviation of a background with texture
_SHADOW_NCC = 0.4  # ... which a shadow keeps: correlation of frame and background
_BG_SAMPLES = 9  # frames sampled over the video for the initial background (median)
_CONTACT_PX = 1.5  # pixels: noise of the contact pixel (sub-pixel hinge at reduced scale)
_CONTACT_FLOOR_M = 0.05  # metres: the contact's own wander on the vehicle, in every frame
# The contact's height is not corrected; its root mean square over the camera's height is
# a relative speed error. With given boxes the box's bottom cuts the silhouette at a tyre
# (0) or at the body's lower edge, up to a car's clearance (0.2 m) up: uniform, RMS 0.115 m
# (measured on development seeds 0-5 with the exact boxes, session 37: RMS 0.115 m of the
# height h = H e / (1 + e) the speed error e implies, mean +0.07 m). A detected
# silhouette's lowest corner, where the tyres, the body's edge and the contact shadow's
# boundary meet, stands lower: its implied height on the same seeds (detection, true
# camera) had mean +0.001 m, RMS 0.024 m, 5-95 % -0.03 ... +0.035 m; the term takes 0.03 m.
# (Until session 37 both took 0.144 m, a height uniform over 0-0.25 m: measured on videos
# whose renderer drew every polygon half a pixel low and 0.7 px too large, which read
# detected speeds -0.8 % slow.)
_CLEARANCE_MAX_M = 0.2  # given boxes: a tyre (0) up to a car's body's lower edge
_CONTACT_HEIGHT_SIGMA_M = _CLEARANCE_MAX_M / math.sqrt(3.0)  # RMS of an uncorrected height
_DETECTED_CONTACT_SIGMA_M = 0.03  # a detected silhouette's lowest corner (measured)
_MIN_VEHICLE_HEIGHT_M = 1.5  # a silhouette lower than this above its contact is a piece
_PIECE_CONTACT_SIGMA_M = 0.6  # ... whose contact may be the body's top edge (0.9 m up)
_MAX_GROUND_PER_PX_M = 1.0  # metres of road per detection pixel: farther frames not used
_SEGMENT_MERGE_CHI2 = 9.2  # residuals' rise allowed to merge two segments (chi2, 2 dof, 99 %)
# Two segments adjacent in time whose offsets lie closer than this on the road are one
# contact wandering on its corner, not another corner (a car's other corners and its tyres'
# contacts are 0.8 m or more away): with an offset each, the jumps forward between them are
# thrown away while the slow creeps back within them stay, and the speed reads slow (a
# receding SUV whose contact crept back 5 cm a frame and jumped 0.3 m forward every 5
# frames near the camera read -5.7 %, development seed 721)
_CONTACT_WANDER_M = 0.5
_STILL_KLT_PX = 3.0  # pixels the features of a segment moved: enough to tell a still contact
_STILL_RATIO = 0.3  # ... which moved less than this fraction of it along their motion
_UNCERTAIN_REL = 0.05  # sigma_kmh above this fraction of the speed: a warning (2 sigma > 10 %)
# Fragments of one vehicle in time (its track lost while it hid behind or merged with another
# vehicle, a new track started where it came out; development seed 723's white hatchback,
# 3 s hidden behind a van, gave a second track reading -67 %) are joined by their motion
# (:func:`_fragment_of`): two tracks whose ground contacts lie where the other's fitted
# motion (the earlier's carried forward or the later's carried back) puts that vehicle at
# the same times, within
_LINK_MAX_GAP_S = 4.0  # ... this long after the earlier track ended,
_LINK_ALONG_M = 2.0  # ... this far along its motion (the contact on another corner), plus 2
# sigma of the extrapolation (that track's speed sigma times the time from its anchor),
_LINK_ACROSS_M = 1.2  # ... and this far across it (half a lane: not the next lane's car)
_LINK_MAX_OVERLAP = 5  # frames both tracks hold: more, and the later one is a duplicate


# --------------------------------------------------------------------------- results
@dataclass(frozen=True)
class VideoInfo:
    """The video as read.

    Attributes
    ----------
    path
        The file.
    width, height
        Frame size, pixels.
    fps
        Frame rate used for the speeds.
    fps_source
        ``"file"`` (from the container) or ``"given"``.
    fps_in_file
        What the file states (None when it states nothing usable).
    n_frames
        Frames processed.
    """

    path: str
    width: int
    height: int
    fps: float
    fps_source: str
    fps_in_file: float | None
    n_frames: int

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {
            "path": self.path,
            "width": self.width,
            "height": self.height,
            "fps": self.fps,
            "fps_source": self.fps_source,
            "fps_in_file": self.fps_in_file,
            "n_frames": self.n_frames,
        }


@dataclass(frozen=True)
class VehicleSpeed:
    """One vehicle's speed, or why it has none.

    Attributes
    ----------
    vehicle_id
        Track id (the given id with ``tracks``).
    status
        ``"measured"`` or ``"skipped"``.
    speed_kmh, sigma_kmh
        Speed over the track and its 1-sigma uncertainty (NaN when skipped).
    first_frame, last_frame, n_frames
        0-based frame range of the track and the number of frames used in the fit.
    duration_s
        Time spanned by the frames used.
    distance_m
        Ground distance covered over ``duration_s`` at the fitted velocity.
    heading_deg
        Direction of travel in the scene's world frame, clockwise from +y (NaN when skipped).
    contact
        How the ground contact was found: ``"silhouette"``, ``"box"`` or ``"mixed"``.
    n_segments
        Pieces the track was split into (contact jumps), each with its own offset.
    reason
        Why the vehicle was skipped (None when measured).
    track_world_m
        ``(frame, x, y)`` of the ground contact in each frame used (metres, world frame).
    warning
        Set when the speed is uncertain: ``sigma_kmh`` above 5 % of the speed (2 sigma
        above 10 %), with its main cause (e.g. a track that held other vehicles). The
        speed is still given; do not use it as a measurement of record.
    """

    vehicle_id: int
    status: str
    speed_kmh: float
    sigma_kmh: float
    first_frame: int
    last_frame: int
    n_frames: int
    duration_s: float
    distance_m: float
    heading_deg: float
    contact: str
    n_segments: int = 0
    reason: str | None = None
    track_world_m: list[tuple[int, float, float]] = field(default_factory=list, repr=False)
    warning: str | None = None

    @property
    def measured(self) -> bool:
        """True when the speed was measured."""
        return self.status == "measured"

    def to_dict(self, *, track: bool = True) -> dict[str, Any]:
        """JSON-ready (NaN becomes None); ``track=False`` leaves out ``track_world_m``."""
        out: dict[str, Any] = {
            "vehicle_id": self.vehicle_id,
            "status": self.status,
            "speed_kmh": _num(self.speed_kmh),
            "sigma_kmh": _num(self.sigma_kmh),
            "first_frame": self.first_frame,
            "last_frame": self.last_frame,
            "n_frames": self.n_frames,
            "duration_s": _num(self.duration_s),
            "distance_m": _num(self.distance_m),
            "heading_deg": _num(self.heading_deg),
            "contact": self.contact,
            "n_segments": self.n_segments,
            "reason": self.reason,
            "warning": self.warning,
        }
        if track:
            out["track_world_m"] = [[f, round(x, 4), round(y, 4)] for f, x, y in self.track_world_m]
        return out

    def csv_row(self) -> dict[str, Any]:
        """One row of :data:`CSV_COLUMNS` (empty cells for missing values)."""
        d = self.to_dict(track=False)
        return {k: "" if d[k] is None else d[k] for k in CSV_COLUMNS}


@dataclass(frozen=True)
class RadarResult:
    """Everything the radar found.

    Attributes
    ----------
    video
        The video as read.
    vehicles
        Every vehicle, measured or skipped, in order of first appearance.
    source
        ``"detection"`` (background subtraction) or ``"tracks"`` (given boxes).
    processing_s
        Wall time of the video pass and the fits.
    noise_blobs
        Detected blobs seen in fewer than 3 frames, dropped as noise (not vehicles).
    warnings
        Things the caller should know (e.g. no vehicle found).
    calibration
        The calibration used (:func:`calibration_summary`): its focal length and sigma, and
        which witnesses it rests on (``"annotators"``, ``"photo"``, ``"video"``), with the
        photo's and the video's segments per axis.
    """

    video: VideoInfo
    vehicles: list[VehicleSpeed]
    source: str
    processing_s: float
    noise_blobs: int = 0
    warnings: list[str] = field(default_factory=list)
    calibration: dict[str, Any] = field(default_factory=dict)

    @property
    def measured(self) -> list[VehicleSpeed]:
        """The vehicles with a speed."""
        return [v for v in self.vehicles if v.measured]

    @property
    def frames_per_second(self) -> float:
        """Processing speed, video frames per wall-clock second."""
        return self.video.n_frames / self.processing_s if self.processing_s > 0 else math.inf

    def to_dict(self, *, tracks: bool = True) -> dict[str, Any]:
        """JSON-ready: video, counts, warnings and one entry per vehicle."""
        return {
            "video": self.video.to_dict(),
            "source": self.source,
            "n_vehicles": len(self.vehicles),
            "n_measured": len(self.measured),
            "noise_blobs": self.noise_blobs,
            "processing_s": round(self.processing_s, 3),
            "processing_fps": round(self.frames_per_second, 1),
            "warnings": list(self.warnings),
            **({"calibration": dict(self.calibration)} if self.calibration else {}),
            "vehicles": [v.to_dict(track=tracks) for v in self.vehicles],
        }

    def to_csv(self) -> str:
        """CSV text with a header and one row per vehicle (:data:`CSV_COLUMNS`)."""
        buf = io.StringIO()
        writer = csv.DictWriter(buf, fieldnames=list(CSV_COLUMNS), lineterminator="\n")
        writer.writeheader()
        for v in self.vehicles:
            writer.writerow(v.csv_row())
        return buf.getvalue()


def _num(x: float) -> float | None:
    return round(float(x), 4) if math.isfinite(x) else None


# --------------------------------------------------------------------------- tracks input
def _box(values: Any, where: str) -> Box:
    try:
        x1, y1, x2, y2 = (float(v) for v in values)
    except (TypeError, ValueError):
        raise InputError(f"{where}: a box is four numbers x1, y1, x2, y2") from None
    if not all(math.isfinite(v) for v in (x1, y1, x2, y2)):
        raise InputError(f"{where}: box coordinates must be finite")
    if x2 <= x1 or y2 <= y1:
        raise InputError(f"{where}: box needs x2 > x1 and y2 > y1, got {[x1, y1, x2, y2]}")
    return (x1, y1, x2, y2)


def _int(value: Any, what: str, where: str) -> int:
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{where}: {what} must be an integer, not {value!r}") from None
    if not math.isfinite(f) or f != int(f):
        raise InputError(f"{where}: {what} must be an integer, not {value!r}")
    return int(f)


def _add(out: TrackBoxes, vid: int, frame: int, box: Box, where: str, count: list[int]) -> None:
    if frame < 0:
        raise InputError(f"{where}: frame must be >= 0 (frames count from 0), got {frame}")
    per = out.setdefault(vid, {})
    if frame in per:
        raise InputError(f"{where}: vehicle {vid} has two boxes in frame {frame}")
    per[frame] = box
    count[0] += 1
    if count[0] > MAX_TRACK_BOXES:
        raise InputError(f"tracks: more than {MAX_TRACK_BOXES} boxes; split the file")


def _tracks_json(data: Any, name: str) -> TrackBoxes:
    rows = data.get("detections") if isinstance(data, dict) else data
    if not isinstance(rows, list):
        raise InputError(
            f"tracks {name}: JSON must be a list of detections "
            '{"frame", "id", "box": [x1, y1, x2, y2]} (or {"detections": [...]})'
        )
    out: TrackBoxes = {}
    count = [0]
    for i, row in enumerate(rows):
        where = f"tracks {name}: detection {i}"
        if not isinstance(row, dict):
            raise InputError(f"{where}: must be an object with frame, id and box")
        missing = [k for k in ("frame", "id") if k not in row]
        if "box" not in row and not all(k in row for k in ("x1", "y1", "x2", "y2")):
            missing.append("box")
        if missing:
            raise InputError(f"{where}: missing {', '.join(missing)}")
        raw = row["box"] if "box" in row else [row[k] for k in ("x1", "y1", "x2", "y2")]
        _add(
            out,
            _int(row["id"], "id", where),
            _int(row["frame"], "frame", where),
            _box(raw, where),
            where,
            count,
        )
    return out


def _tracks_csv(text: str, name: str) -> TrackBoxes:
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise InputError(f"tracks {name}: the file has no rows")
    first = [c.strip().lower() for c in next(csv.reader([lines[0]]))]
    out: TrackBoxes = {}
    count = [0]
    if first and first[0] and not _is_number(first[0]):
        cols = {c: i for i, c in enumerate(first)}
        if {"x1", "y1", "x2", "y2"} <= set(cols):
            form = "corners"
        elif {"x", "y", "w", "h"} <= set(cols):
            form = "xywh"
        else:
            raise InputError(
                f"tracks {name}: CSV header needs frame, id and x1, y1, x2, y2 "
                f"(or x, y, w, h), got {', '.join(first)}"
            )
        for need in ("frame", "id"):
            if need not in cols:
                raise InputError(f"tracks {name}: CSV header has no {need!r} column")
        body, offset, mot = lines[1:], 2, False
    else:  # MOTChallenge: frame (1-based), id, left, top, width, height, ...
        cols = {"frame": 0, "id": 1, "x": 2, "y": 3, "w": 4, "h": 5}
        form, body, offset, mot = "xywh", lines, 1, True
    for k, row in enumerate(csv.reader(body)):
        where = f"tracks {name}: line {k + offset}"
        try:
            vals = [row[cols[c]] for c in ("frame", "id")]
            if form == "corners":
                box = _box([row[cols[c]] for c in ("x1", "y1", "x2", "y2")], where)
            else:
                x, y, w, h = (float(row[cols[c]]) for c in ("x", "y", "w", "h"))
                box = _box([x, y, x + w, y + h], where)
        except IndexError:
            raise InputError(f"{where}: too few columns") from None
        except InputError:
            raise
        except ValueError:
            raise InputError(f"{where}: box values must be numbers") from None
        frame = _int(vals[0], "frame", where) - (1 if mot else 0)
        _add(out, _int(vals[1], "id", where), frame, box, where, count)
    return out


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_tracks(path: str | os.PathLike[str]) -> TrackBoxes:
    """Read vehicle boxes given by another detector / tracker.

    Formats (see ``docs/radar.md``):

    - JSON: a list of ``{"frame": 0, "id": 3, "box": [x1, y1, x2, y2]}`` (or the object
      ``{"detections": [...]}``; ``x1, y1, x2, y2`` may be given as keys instead of ``box``);
    - CSV with a header naming ``frame, id, x1, y1, x2, y2`` or ``frame, id, x, y, w, h``;
    - CSV without header in the MOTChallenge layout ``frame, id, left, top, width, height,
      ...`` (frames counted from 1 there, from 0 everywhere else).

    Returns
    -------
    ``{id: {frame: (x1, y1, x2, y2)}}``, frames counted from 0, pixels.

    Raises
    ------
    InputError
        Missing, too large or malformed file (the message names the line or detection).
    """
    _check_path(path, "tracks file")
    p = check_regular_file(path, "tracks file")
    size = p.stat().st_size
    if size > MAX_TRACKS_BYTES:
        raise InputError(f"tracks file {p} is {size} bytes; the limit is {MAX_TRACKS_BYTES}")
    text = read_text_file(p, what="tracks file")
    if p.suffix.lower() == ".json" or text.lstrip()[:1] in ("[", "{"):
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InputError(f"tracks {p.name}: not valid JSON ({exc})") from None
        out = _tracks_json(data, p.name)
    else:
        out = _tracks_csv(text, p.name)
    if not out:
        raise InputError(f"tracks {p.name}: no boxes in the file")
    return out


def _check_tracks(tracks: Mapping[int, Mapping[int, Any]]) -> TrackBoxes:
    out: TrackBoxes = {}
    for vid, per in tracks.items():
        out[int(vid)] = {
            int(f): _box(b, f"tracks: vehicle {vid} frame {f}") for f, b in per.items()
        }
    if not any(out.values()):
        raise InputError("tracks: no boxes given")
    return out


# --------------------------------------------------------------------------- video
def _single_frame(
    path: str | os.PathLike[str], need: str = "speeds need a video of the moving vehicles"
) -> InputError:
    """The error for a video of one frame (a still image): ``need`` says what needs more."""
    return InputError(f"video {path} has a single frame (a still image?): {need}")


def _check_path(path: object, what: str) -> None:
    """An :class:`InputError` when ``path`` is not a ``str`` or ``os.PathLike``."""
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(f"{what}: give a file path, not {type(path).__name__}")


def _open_video(
    path: str | os.PathLike[str], need: str | None = None
) -> tuple[Any, int, int, float | None, int]:
    import cv2

    _check_path(path, "video")
    p = check_regular_file(path, "video")
    if p.stat().st_size == 0:
        raise InputError(f"cannot open video {p}: the file is empty (0 bytes)")
    cap = cv2.VideoCapture(str(p))
    if not cap.isOpened():
        raise InputError(f"cannot open video {p}: not a video file OpenCV can read")
    w = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH))
    h = int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT))
    fps = float(cap.get(cv2.CAP_PROP_FPS) or 0.0)
    n = int(cap.get(cv2.CAP_PROP_FRAME_COUNT) or 0)
    if w <= 0 or h <= 0:
        cap.release()
        raise InputError(f"cannot read video {p}: it states no frame size")
    if n == 1:  # OpenCV reads a photo as a video of one frame
        cap.release()
        raise _single_frame(p) if need is None else _single_frame(p, need)
    if w * h > MAX_VIDEO_PIXELS:
        cap.release()
        raise InputError(
            f"video {p} frames are {w}x{h}; the supported limit is "
            f"{MAX_VIDEO_PIXELS / 1e6:.1f} megapixels (4K UHD)"
        )
    return cap, w, h, (fps if math.isfinite(fps) and 0.5 <= fps <= 1000.0 else None), max(n, 0)


def probe_video(
    video_path: str | os.PathLike[str],
    *,
    image_size: tuple[int, int] | None = None,
    need: str | None = None,
) -> tuple[int, int, float | None, int]:
    """Width, height, stated frame rate (None: none usable) and frame count of a video.

    Cheap (reads the header only): front ends call it before calibrating, to refuse a bad
    video at once. ``need``: what a still image's error says needs a video (default: the
    speeds).

    Raises
    ------
    InputError
        Missing or unreadable video, too large frames, or (with ``image_size``) frames of
        another size than the scene's image.
    """
    cap, w, h, fps, n = _open_video(video_path, need)
    cap.release()
    if image_size is not None:
        _check_size(video_path, (w, h), image_size)
    return w, h, fps, n


def _check_size(
    video_path: str | os.PathLike[str], size: tuple[int, int], image_size: tuple[int, int]
) -> None:
    if tuple(size) != tuple(image_size):
        raise InputError(
            f"video {video_path} is {size[0]}x{size[1]} but the scene's image is "
            f"{image_size[0]}x{image_size[1]}: annotate a frame of this video"
        )


def _background_init(cap: Any, n_frames: int, scale: float, max_frames: int) -> Any:
    """Median of frames sampled over the video (reduced, colour), or None."""
    import cv2

    if n_frames < 10:
        return None
    last = min(n_frames, max_frames) - 1
    frames: list[Any] = []
    for _attempt in range(2):
        idx = np.unique(np.linspace(0, last, _BG_SAMPLES).astype(int))
        frames, failed_at = [], None
        for i in idx:
            ok = bool(cap.set(cv2.CAP_PROP_POS_FRAMES, int(i)))
            frame = cap.read()[1] if ok else None
            if frame is None:
                failed_at = int(i)
                break
            frames.append(_reduce(frame, scale))
        if len(frames) >= 5 or failed_at is None or failed_at < 10:
            break
        # a truncated file states more frames than it holds: sample before the first that
        # failed (the video's lines had no background at all, the radar its first frame)
        last = failed_at - 1
    cap.set(cv2.CAP_PROP_POS_FRAMES, 0)
    if len(frames) < 5:
        return None
    return np.median(np.stack(frames), axis=0).astype(np.uint8)


def _reduce(frame: Any, scale: float) -> Any:
    """The frame (colour: a car may have the road's grey level) reduced by ``scale``."""
    import cv2

    if scale == 1.0:
        return frame
    h, w = frame.shape[:2]
    return cv2.resize(frame, (round(w * scale), round(h * scale)), interpolation=cv2.INTER_AREA)


# --------------------------------------------------------------------------- tracking
@dataclass
class _Track:
    vid: int
    box: Box
    velocity: tuple[float, float] = (0.0, 0.0)
    missed: int = 0
    coasting: int = 0
    frames: list[int] = field(default_factory=list)
    boxes: list[Box] = field(default_factory=list)
    contacts: list[tuple[float, float]] = field(default_factory=list)
    kinds: list[str] = field(default_factory=list)
    klt: list[tuple[float, float]] = field(default_factory=list)
    border: list[bool] = field(default_factory=list)
    occluded: list[bool] = field(default_factory=list)
    points: Any = None  # KLT features (N, 1, 2) float32 in the previous frame
    absorbed: bool = False  # a fragment of another track's vehicle, joined to it

    def predicted(self) -> Box:
        dx, dy = self.velocity
        x1, y1, x2, y2 = self.box
        return (x1 + dx, y1 + dy, x2 + dx, y2 + dy)


def _iou(a: Box, b: Box) -> float:
    ix = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    iy = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = ix * iy
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return inter / union if union > 0 else 0.0


def _overlap(a: Box, b: Box) -> float:
    """Area of the intersection of two boxes over the area of the first."""
    ix = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    iy = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    area = (a[2] - a[0]) * (a[3] - a[1])
    return ix * iy / area if area > 0 else 0.0


def _blobs(
    fg: Any, scale: float, min_area: int
) -> tuple[list[Box], list[list[int]], Any, list[Box], list[int]]:
    """Connected components of the foreground.

    Returns the boxes (full-resolution pixels) of the ``_MAX_BLOBS`` largest, at least
    ``min_area`` reduced pixels large, their labels (one each), the label image, and the
    boxes and labels of the smaller pieces (``_MIN_PIECE_PX`` and up: a wheel or a panel of
    a vehicle whose colour is the road's, joined by :func:`_join_fragments` to the vehicle
    whose predicted box holds it).
    """
    import cv2

    n, labels, stats, _ = cv2.connectedComponentsWithStats(fg, connectivity=8)
    areas = stats[:, cv2.CC_STAT_AREA]
    keep = [i for i in range(1, n) if areas[i] >= min_area]
    keep.sort(key=lambda i: -int(areas[i]))
    keep = keep[:_MAX_BLOBS]
    small = [i for i in range(1, n) if _MIN_PIECE_PX <= areas[i] < min_area][: 4 * _MAX_BLOBS]

    def box(i: int) -> Box:
        x, y, w, h = (int(v) for v in stats[i, :4])
        return (x / scale, y / scale, (x + w) / scale, (y + h) / scale)

    return [box(i) for i in keep], [[i] for i in keep], labels, [box(i) for i in small], small


def _part_of(piece: _Track, whole: _Track) -> bool:
    """True when ``piece`` is a fragment of ``whole``: its predicted box lies inside the
    other's (80 %), it is smaller, and it moves the same way (image velocities within 30 %
    of the vehicle's + 1 px a frame)."""
    a, b = piece.predicted(), whole.predicted()
    if _overlap(a, b) < 0.8 or (a[2] - a[0]) * (a[3] - a[1]) >= (b[2] - b[0]) * (b[3] - b[1]):
        return False
    dv = math.hypot(piece.velocity[0] - whole.velocity[0], piece.velocity[1] - whole.velocity[1])
    return dv <= 0.3 * math.hypot(*whole.velocity) + 1.0


def _join_fragments(
    tracks: list[_Track],
    blobs: list[Box],
    ids: list[list[int]],
    small: list[Box],
    small_ids: list[int],
) -> tuple[list[Box], list[list[int]]]:
    """Join the pieces of one vehicle (a road-grey car's cabin, lower body and wheels fall
    apart under the foreground threshold) by its motion.

    An established track's box moved by its motion (KLT) is the prediction; the blobs and
    small pieces lying mostly (80 %) inside it, grown by 15 % on every side, and inside no
    other track's, are one vehicle: their boxes are united and their labels kept together
    (the contact is the lowest corner of the union). The union may not outgrow the
    prediction by more than half its area (that would be another vehicle beside it).
    """
    if not tracks or not (blobs or small):
        return blobs, ids
    pieces = [*blobs, *small]
    piece_ids = [*ids, *[[i] for i in small_ids]]
    grown: list[Box | None] = []
    for t in tracks:
        if len(t.frames) < _MIN_DETECTED_FRAMES or t.missed:
            grown.append(None)
            continue
        x1, y1, x2, y2 = t.predicted()
        gx, gy = 0.15 * (x2 - x1), 0.15 * (y2 - y1)
        grown.append((x1 - gx, y1 - gy, x2 + gx, y2 + gy))
    inside = np.zeros((len(tracks), len(pieces)), dtype=bool)
    for k, g in enumerate(grown):
        if g is not None:
            inside[k] = [_overlap(b, g) >= 0.8 for b in pieces]
    taken: set[int] = set()
    joined: list[tuple[Box, list[int]]] = []
    for k in range(len(tracks)):
        if grown[k] is None:
            continue
        parts = [m for m in range(len(tracks)) if m != k and _part_of(tracks[m], tracks[k])]
        if any(_part_of(tracks[k], other) for other in tracks if other is not tracks[k]):
            continue  # itself a fragment: its vehicle joins it
        rivals = [m for m in range(len(tracks)) if m != k and m not in parts]
        mine = [j for j in np.flatnonzero(inside[k]) if not inside[rivals, j].any()]
        if len(mine) < 2 or not any(j < len(blobs) for j in mine):
            continue
        pred = tracks[k].predicted()
        mine.sort(key=lambda j: -(pieces[j][2] - pieces[j][0]) * (pieces[j][3] - pieces[j][1]))
        u: Box = pieces[mine[0]]
        # no faster growth than a vehicle coming nearer (or than its largest piece)
        max_w = max(1.1 * (pred[2] - pred[0]) + 3.0, u[2] - u[0])
        max_h = max(1.1 * (pred[3] - pred[1]) + 3.0, u[3] - u[1])
        chosen = [mine[0]]
        for j in mine[1:]:  # largest first; a piece that would outgrow the vehicle stays out
            b = pieces[j]
            v = (min(u[0], b[0]), min(u[1], b[1]), max(u[2], b[2]), max(u[3], b[3]))
            if v[2] - v[0] <= max_w and v[3] - v[1] <= max_h:
                u = v
                chosen.append(j)
        mine = chosen
        if len(mine) < 2 or mine[0] >= len(blobs):
            continue
        big = pieces[mine[0]]
        if (big[2] - big[0]) * (big[3] - big[1]) < 0.3 * (u[2] - u[0]) * (u[3] - u[1]):
            continue  # a vehicle is one main piece and its loose parts, not a crowd
        if any(
            _overlap(pieces[j], other.predicted()) > 0.2
            for j in mine
            for m, other in enumerate(tracks)
            if m != k and not _part_of(other, tracks[k])
        ):
            continue  # a piece another vehicle may own
        taken.update(int(j) for j in mine)
        for m in parts:  # a fragment's own track ends here: its vehicle's track goes on
            tracks[m].absorbed = True
        joined.append((u, [i for j in mine for i in piece_ids[j]]))
    if not joined:
        return blobs, ids
    out = [b for j, b in enumerate(blobs) if j not in taken]
    out_ids = [i for j, i in enumerate(ids) if j not in taken]
    return out + [b for b, _ in joined], out_ids + [i for _, i in joined]


def _associate(
    tracks: list[_Track], blobs: list[Box]
) -> tuple[dict[int, int], list[int], set[int]]:
    """Match tracks to blobs (Hungarian on 1 - IoU with the predicted boxes).

    Returns track index -> blob index, the blobs that start new tracks, and the tracks hidden
    in a merged blob (one blob covering at least 30 % of two or more established tracks'
    predicted boxes: vehicles passing each other). Those coast on their prediction and the
    merged blob is used by none.
    """
    from scipy.optimize import linear_sum_assignment

    if not tracks or not blobs:
        return {}, list(range(len(blobs))), set()
    preds = [t.predicted() for t in tracks]
    cover = np.zeros((len(tracks), len(blobs)))
    cost = np.ones((len(tracks), len(blobs)))
    for i, pred in enumerate(preds):
        area = max(1e-9, (pred[2] - pred[0]) * (pred[3] - pred[1]))
        for j, b in enumerate(blobs):
            ix = max(0.0, min(pred[2], b[2]) - max(pred[0], b[0]))
            iy = max(0.0, min(pred[3], b[3]) - max(pred[1], b[1]))
            cover[i, j] = ix * iy / area
            cost[i, j] = 1.0 - _iou(pred, b)
    established = np.array([len(t.frames) >= _MIN_DETECTED_FRAMES for t in tracks])
    covering = (cover > 0.3) & established[:, None]
    merged_blobs = {j for j in range(len(blobs)) if covering[:, j].sum() >= 2}
    hidden = {i for j in merged_blobs for i in np.flatnonzero(covering[:, j]).tolist()}
    cost[list(hidden), :] = 1.0
    cost[:, list(merged_blobs)] = 1.0
    rows, cols = linear_sum_assignment(cost)
    match = {int(r): int(c) for r, c in zip(rows, cols, strict=True) if cost[r, c] < 0.9}
    used = set(match.values()) | merged_blobs
    for i in hidden:  # a hidden track overlapping the merged blob only: keep it coasting
        match.pop(i, None)
    return match, [j for j in range(len(blobs)) if j not in used], hidden


def _contact(
    fg: Any, box: Box, scale: float, labels: Any = None, own: list[int] | None = None
) -> tuple[tuple[float, float], str]:
    """Ground-contact pixel of a vehicle in ``box``: lowest silhouette corner or box.

    ``labels`` and ``own``: the label image of the foreground and the vehicle's own labels
    (a detected vehicle, perhaps in pieces); all of them make its silhouette. Without
    them (given boxes) the silhouette is the box's largest foreground region.
    """
    import cv2

    x1, y1, x2, y2 = box
    bottom_centre = ((x1 + x2) / 2.0, y2)
    if fg is not None:
        h, w = fg.shape
        c0, r0 = max(0, int(x1 * scale)), max(0, int(y1 * scale))
        c1, r1 = min(w, math.ceil(x2 * scale)), min(h, math.ceil(y2 * scale))
        if c1 - c0 >= 2 and r1 - r0 >= 2:
            roi = fg[r0:r1, c0:c1]
            if labels is not None and own:
                roi = np.where(np.isin(labels[r0:r1, c0:c1], own), 255, 0).astype(np.uint8)
            contours, _ = cv2.findContours(roi, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
            if contours:
                parts = (
                    list(contours)
                    if labels is not None and own
                    else [max(contours, key=cv2.contourArea)]
                )
                area = sum(cv2.contourArea(c) for c in parts)
                low = max(c[:, 0, 1].max() for c in parts)
                # the silhouette must fill the box reasonably and reach its bottom
                if area >= 0.25 * roi.size and low >= 0.85 * (r1 - r0) - 1:
                    one = np.zeros_like(roi)
                    cv2.drawContours(one, parts, -1, 255, -1)
                    corner = _lowest_corner(one)
                    if corner is not None:
                        u, v = corner
                        return ((u + c0) / scale, (v + r0) / scale), "silhouette"
    return bottom_centre, "box"


def _lowest_corner(mask: Any) -> tuple[float, float] | None:
    """Sub-pixel lowest corner ``(u, v)`` of a silhouette (binary mask, one component).

    On a shallow bottom outline (two nearly collinear bottom edges, far away) many pixels
    share the lowest row: taking any one of them slides the contact along the vehicle by
    up to metres and biases the speed. The outline's lowest part is instead fitted with two
    lines meeting at a corner (a hinge: least squares over the bottom profile of the
    columns, the corner's column searched), and the corner is their meeting point.
    """
    cols = np.flatnonzero(mask.any(axis=0))
    if len(cols) < 3:
        return None
    h = mask.shape[0]
    bottom = h - np.argmax(mask[::-1, cols] > 0, axis=0).astype(np.float64)  # lower edges
    low = float(bottom.max())
    band = max(3.0, 0.2 * float(h))
    k = int(np.argmax(bottom))
    lo, hi = k, k
    while lo > 0 and bottom[lo - 1] >= low - band:
        lo -= 1
    while hi < len(cols) - 1 and bottom[hi + 1] >= low - band:
        hi += 1
    x = cols[lo : hi + 1].astype(np.float64) + 0.5
    y = bottom[lo : hi + 1]
    if len(x) < 5:
        return float(cols[k]) + 0.5, low
    best: tuple[float, float, float] | None = None
    for x0 in np.linspace(x[0], x[-1], min(len(x), 80)):
        a = np.column_stack([np.ones_like(x), np.minimum(x - x0, 0.0), np.maximum(x - x0, 0.0)])
        coef, *_ = np.linalg.lstsq(a, y, rcond=None)
        sse = float(np.sum((a @ coef - y) ** 2))
        if best is None or sse < best[0]:
            best = (sse, float(x0), float(coef[0]))
    assert best is not None
    return best[1], min(best[2], low)


def _klt_step(
    prev: Any, grey: Any, tracks: list[_Track], boxes: dict[int, Box]
) -> dict[int, tuple[float, float]]:
    """Track every vehicle's features from ``prev`` to ``grey``; median lower-half motion."""
    import cv2

    pts, owners = [], []
    guess = []
    for k, t in enumerate(tracks):
        if t.points is not None and len(t.points) and k in boxes:
            pts.append(t.points)
            owners.extend([k] * len(t.points))
            guess.append(t.points + np.asarray(t.velocity, np.float32))
    if not pts:
        return {}
    p0 = np.concatenate(pts).astype(np.float32)
    p1, status, _err = cv2.calcOpticalFlowPyrLK(
        prev,
        grey,
        p0,
        np.concatenate(guess).astype(np.float32),
        winSize=(15, 15),
        maxLevel=3,
        flags=cv2.OPTFLOW_USE_INITIAL_FLOW,
        criteria=(cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 20, 0.03),
    )
    own = np.asarray(owners)
    ok = status.ravel() == 1
    out: dict[int, tuple[float, float]] = {}
    for k in set(owners):
        sel = (own == k) & ok
        a, b = p0[sel, 0], p1[sel, 0]
        x1, y1, x2, y2 = boxes[k]
        inside = (
            (b[:, 0] >= x1 - 2) & (b[:, 0] <= x2 + 2) & (b[:, 1] >= y1 - 2) & (b[:, 1] <= y2 + 2)
        )
        a, b = a[inside], b[inside]
        tracks[k].points = b.reshape(-1, 1, 2) if len(b) else None
        if len(a) >= 3:
            d = b - a
            lower = a[:, 1] >= np.median(a[:, 1])
            use = d[lower] if lower.sum() >= 3 else d
            out[k] = (float(np.median(use[:, 0])), float(np.median(use[:, 1])))
    return out


def _seed_features(grey: Any, fg_full: Any, box: Box) -> Any:
    import cv2

    h, w = grey.shape
    x1, y1, x2, y2 = box
    mx, my = 0.1 * (x2 - x1), 0.1 * (y2 - y1)
    c0, r0 = max(0, int(x1 + mx)), max(0, int(y1 + my))
    c1, r1 = min(w, int(x2 - mx)), min(h, int(y2 - my))
    if c1 - c0 < 6 or r1 - r0 < 6:
        return None
    mask = None if fg_full is None else fg_full[r0:r1, c0:c1]
    if mask is not None and cv2.countNonZero(mask) < 0.1 * mask.size:
        mask = None  # no foreground here (given boxes on a background-less frame)
    pts = cv2.goodFeaturesToTrack(
        grey[r0:r1, c0:c1], _MAX_FEATURES, 0.01, 3, mask=mask, blockSize=5
    )
    if pts is None:
        return None
    return (pts + np.asarray([c0, r0], np.float32)).astype(np.float32)


# --------------------------------------------------------------------------- fitting
def _segments(t: _Track, fps: float, width: int, height: int) -> tuple[list[int], list[int]]:
    """Indices of the records used and their segment labels (split where the contact jumps)."""
    use, labels = [], []
    seg = -1
    prev: int | None = None
    for i in range(len(t.frames)):
        if t.border[i] or t.occluded[i]:
            prev = None
            continue
        if prev is None or t.frames[i] - t.frames[prev] > _MAX_MISSED + 1:
            seg += 1
        else:
            x1, y1, x2, y2 = t.boxes[i]
            thr = max(4.0, 0.15 * (y2 - y1), 0.08 * (x2 - x1))
            dm = np.subtract(t.contacts[i], t.contacts[prev])
            k = t.klt[i]
            if t.kinds[i] != t.kinds[prev]:
                seg += 1
            elif math.isfinite(k[0]) and t.frames[i] - t.frames[prev] == 1:
                if math.hypot(dm[0] - k[0], dm[1] - k[1]) > thr:
                    seg += 1
            elif math.hypot(*dm) > 3 * thr * (t.frames[i] - t.frames[prev]):
                seg += 1
        use.append(i)
        labels.append(seg)
        prev = i
    # segments shorter than 3 frames carry no velocity: drop them
    counts = {s: labels.count(s) for s in set(labels)}
    keep = [j for j, s in enumerate(labels) if counts[s] >= 3]
    return [use[j] for j in keep], [labels[j] for j in keep]


def _still_segments(t: _Track, use: list[int], labels: list[int]) -> set[int]:
    """Segments whose contact stands still while the vehicle's features move.

    A patch of foreground that stays put (the background model wrong there, a mark on the
    road) joined to a passing vehicle's blob becomes the lowest corner of its silhouette: the
    contact then stands still for a while (a development track read 49 % slow). Over a
    segment of at least 5 frames whose features (KLT) moved at least ``_STILL_KLT_PX`` in
    all, the contact must have moved at least ``_STILL_RATIO`` as far along their motion (a
    contact on the vehicle moves as far as its features, or farther: they stand higher).
    """
    out: set[int] = set()
    for s in set(labels):
        idx = [i for i, lab in zip(use, labels, strict=True) if lab == s]
        if len(idx) < 5:
            continue
        motion = np.array([t.klt[i] for i in idx[1:]], dtype=np.float64)
        motion = motion[np.all(np.isfinite(motion), axis=1)]
        if len(motion) < 0.5 * (len(idx) - 1):
            continue
        steps = np.diff([t.frames[i] for i in idx])
        along = np.median(motion, axis=0) * float(np.sum(steps))
        reach = float(np.hypot(*along))
        if reach < _STILL_KLT_PX:
            continue
        moved = np.subtract(t.contacts[idx[-1]], t.contacts[idx[0]])
        if float(moved @ along) / reach**2 < _STILL_RATIO:
            out.add(s)
    return out


def _design(times: FloatArray, labels: list[int]) -> FloatArray:
    segs = sorted(set(labels))
    a = np.zeros((len(times), 1 + len(segs)))
    a[:, 0] = times - times.mean()
    for j, s in enumerate(labels):
        a[j, 1 + segs.index(s)] = 1.0
    return a


def _irls(
    a: FloatArray, g: FloatArray, prior: FloatArray | None = None
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Huber IRLS of ``g ≈ a @ coef``; returns the solve matrix, weights and residuals.

    ``prior``: each row's weight (inverse variance, any scale) before the Huber down-weighting;
    the residuals are compared in units of each row's own sigma.
    """
    p = np.ones(len(g)) if prior is None else np.asarray(prior, np.float64)
    w = p.copy()
    for _ in range(4):
        sw = np.sqrt(w)[:, None]
        solve = np.linalg.pinv(a * sw) * sw.T
        res = g - a @ (solve @ g)
        r = np.linalg.norm(res, axis=1) * np.sqrt(p)
        s = 1.4826 * float(np.median(r)) + 1e-9
        w = p * np.where(r <= 2.0 * s, 1.0, 2.0 * s / np.maximum(r, 1e-12))
    sw = np.sqrt(w)[:, None]
    solve = np.linalg.pinv(a * sw) * sw.T
    res = g - a @ (solve @ g)
    return np.asarray(solve, np.float64), np.asarray(w, np.float64), res


def _merge_segments(
    times: FloatArray, labels: list[int], ground: FloatArray, prior: FloatArray
) -> list[int]:
    """Segment labels with the segments whose contacts lie on one line of travel merged.

    A track is split into segments wherever its contact may have jumped (a gap while it
    coasted through a merged blob, a jump away from its features' motion), and each segment
    gets its own offset: only the motion *within* segments measures the speed. When a
    vehicle spends most of its track merged with others, that leaves a few short, noisy
    segments (a van read 13 % fast from four of 3-7 frames, over 3 s of track). Two
    segments adjacent in time whose contacts fit one offset are merged, so the time between
    them measures the speed too: the pair whose merge raises the weighted squared residuals
    least (same weights as the joint fit) is merged while that rise stays below
    ``_SEGMENT_MERGE_CHI2`` times the fit's residual variance (a contact that moved to
    another corner of the vehicle, a metre or more away, raises it far more); refitted after
    each merge.
    """
    labels = list(labels)
    while len(set(labels)) > 1:
        a = _design(times, labels)
        dof = 2 * (len(times) - a.shape[1])
        if dof < 2:
            break
        solve, w, res = _irls(a, ground, prior)
        rss = float(np.sum(w[:, None] * res**2))
        s2 = max(rss / dof, 1e-12)
        coef = solve @ ground
        # the rise of the weighted residuals when two offsets are made one (a linear
        # constraint c @ coef = 0 on the weighted fit): (c @ coef)^2 / (c M^-1 c), M = A'WA
        m_inv = np.linalg.pinv(a.T @ (w[:, None] * a))
        segs = sorted(set(labels))
        first: dict[int, float] = {}
        for s, t in zip(labels, times, strict=True):
            first[s] = min(first.get(s, math.inf), float(t))
        order = sorted(first, key=lambda s: first[s])
        best: tuple[float, int, int] | None = None
        for keep, gone in itertools.pairwise(order):
            i, j = 1 + segs.index(keep), 1 + segs.index(gone)
            var = float(m_inv[i, i] + m_inv[j, j] - 2.0 * m_inv[i, j])
            if var <= 0:
                continue
            rise = float(np.sum((coef[i] - coef[j]) ** 2)) / var / s2
            if best is None or rise < best[0]:
                best = (rise, keep, gone)
        if best is None or best[0] > _SEGMENT_MERGE_CHI2:
            break
        _rise, keep, gone = best
        labels = [keep if s == gone else s for s in labels]
    return _merge_wander(times, labels, ground, prior)


def _merge_wander(
    times: FloatArray, labels: list[int], ground: FloatArray, prior: FloatArray
) -> list[int]:
    """Segment labels with adjacent segments whose offsets lie within ``_CONTACT_WANDER_M``
    of each other on the road merged (the closest pair first, refitted after each merge).

    A contact that wanders on its corner (the silhouette's lowest corner creeping back
    along the rear edge, then snapping forward) is split at every snap, and with an offset
    per segment only the creeps are left to measure the speed: it reads slow. A jump shorter
    than the distance to any other corner of a vehicle is that wander, and the time across
    it measures the speed too. (:func:`_merge_segments` merges by the fit's noise, which near
    the camera is centimetres: a 0.3 m snap never passed it.)
    """
    labels = list(labels)
    while len(set(labels)) > 1:
        a = _design(times, labels)
        if a.shape[0] <= a.shape[1]:
            break
        solve, _w, _res = _irls(a, ground, prior)
        coef = solve @ ground
        segs = sorted(set(labels))
        first: dict[int, float] = {}
        for s, t in zip(labels, times, strict=True):
            first[s] = min(first.get(s, math.inf), float(t))
        order = sorted(first, key=lambda s: first[s])
        best: tuple[float, int, int] | None = None
        for keep, gone in itertools.pairwise(order):
            jump = float(np.linalg.norm(coef[1 + segs.index(keep)] - coef[1 + segs.index(gone)]))
            if best is None or jump < best[0]:
                best = (jump, keep, gone)
        if best is None or best[0] >= _CONTACT_WANDER_M:
            break
        _jump, keep, gone = best
        labels = [keep if s == gone else s for s in labels]
    return labels


def _fit_track(
    t: _Track,
    calibration: CalibrationResult,
    fps: float,
    width: int,
    height: int,
    min_track_s: float,
    n_samples: int,
    seed: int,
    detect_scale: float = 1.0,
    given: bool = False,
) -> VehicleSpeed:
    first, last = t.frames[0], t.frames[-1]
    kinds = set(t.kinds)
    contact = kinds.pop() if len(kinds) == 1 else "mixed"

    def skipped(reason: str, n: int = 0, dur: float = math.nan) -> VehicleSpeed:
        nan = math.nan
        return VehicleSpeed(
            t.vid, "skipped", nan, nan, first, last, n, dur, nan, nan, contact, 0, reason
        )

    span_s = (last - first) / fps
    if span_s < min_track_s:
        return skipped(f"tracked for only {span_s:.2f} s (< {min_track_s:g} s)", len(t.frames))
    if all(t.border):
        return skipped("never wholly inside the frame (its box touches the image border)")
    if all(b or o for b, o in zip(t.border, t.occluded, strict=True)):
        return skipped("never clear of other vehicles' boxes while wholly inside the frame")
    use, labels = _segments(t, fps, width, height)
    if not use:
        return skipped("its ground contact jumps in every frame (occlusions or merged vehicles)")
    still = _still_segments(t, use, labels)
    if still:
        kept = [(i, s) for i, s in zip(use, labels, strict=True) if s not in still]
        if not kept:
            return skipped(
                "its ground contact stands still while the vehicle's features move (a patch "
                "of the background joined to it)"
            )
        use, labels = [i for i, _s in kept], [s for _i, s in kept]
    pixels = np.array([t.contacts[i] for i in use], dtype=np.float64)
    frames = np.array([t.frames[i] for i in use])
    cam = calibration.camera
    # the camera drawn as a whole (focal length, principal point, orientation and centre with
    # the fit's correlations, as `camloc measure` draws it): before session 37 the rotation
    # and principal point were held while the centre and focal length moved, and the
    # draws lost the tilt that compensates them
    centres, focals, rotations, px = _draws_posed(calibration, pixels, n_samples, 0.0, seed)
    rays = _rays(px, focals, cam.principal_point, rotations)
    ground = _ground(centres, rays)[..., :2]
    ok = np.all(np.isfinite(ground[0]), axis=1)
    if ok.sum() < 3:
        return skipped("its ground contact is at or above the horizon")
    ground, frames = ground[:, ok], frames[ok]
    labels = [s for s, k in zip(labels, ok, strict=True) if k]
    # a contact pixel far away covers metres of road, near by centimetres: each frame is
    # weighted by the inverse of its ground position's variance (a pixel's footprint on
    # the road, _CONTACT_PX pixels of noise, plus a floor for the contact's own wander)
    base = px[0][ok]
    rot = cam.cam_from_world_rotation
    foot = np.zeros(len(base))
    for step in ((1.0, 0.0), (0.0, 1.0)):
        moved = _ground(
            centres[:1], _rays((base + step)[None], focals[:1], cam.principal_point, rot)
        )
        foot += np.sum((moved[0, :, :2] - ground[0]) ** 2, axis=1)
    foot = np.where(np.isfinite(foot), foot, np.inf)
    # far away a detection pixel covers metres of road: the contact moves in steps of a
    # pixel and stalls between them, and no weighting makes that a measurement (held-out
    # vehicles 80-150 m away read 14-21 % slow): such frames are not used
    res_m = np.sqrt(foot) / detect_scale
    near = res_m <= _MAX_GROUND_PER_PX_M
    ground, frames, base, foot = ground[:, near], frames[near], base[near], foot[near]
    labels = [s for s, k in zip(labels, near, strict=True) if k]
    counts = {s: labels.count(s) for s in set(labels)}
    keep = np.array([counts[s] >= 3 for s in labels], dtype=bool)
    ground, frames, base, foot = ground[:, keep], frames[keep], base[keep], foot[keep]
    labels = [s for s, k in zip(labels, keep, strict=True) if k]
    times = frames / fps
    dur = float(times.max() - times.min()) if len(times) else 0.0
    if len(times) < 3 or dur < min_track_s:
        if not near.all():
            finite = res_m[np.isfinite(res_m)]
            worst = f"up to {float(np.max(finite)):.1f} m" if len(finite) else "metres"
            return skipped(
                f"too far from the camera: a detection pixel at its ground contact covers "
                f"{worst} of road (> {_MAX_GROUND_PER_PX_M:g} m in a usable frame), "
                f"leaving {dur:.2f} s (< {min_track_s:g} s)",
                len(times),
                dur,
            )
        return skipped(
            f"only {dur:.2f} s of usable frames wholly inside the image (< {min_track_s:g} s)",
            len(times),
            dur,
        )
    var_m2 = _CONTACT_PX**2 * foot + _CONTACT_FLOOR_M**2
    labels = _merge_segments(times, labels, ground[0], 1.0 / var_m2)
    a = _design(times, labels)
    solve, weights, res = _irls(a, ground[0], 1.0 / var_m2)
    coef = solve @ ground[0]
    vel = coef[0]
    speed = float(np.linalg.norm(vel))
    if speed * dur < 1.0:
        return skipped(f"stationary (moved {speed * dur:.2f} m in {dur:.1f} s)", len(times), dur)
    # fit standard error along the direction of travel
    unit = vel / speed
    sigma_fit = math.sqrt(_along_track_var(solve, weights, res, unit))
    # calibration: refit with every drawn camera
    draws = np.einsum("n,snd->sd", solve[0], ground[1:])
    sp = np.linalg.norm(draws, axis=1)
    sp = sp[np.isfinite(sp)]
    sigma_cal = float(np.std(sp, ddof=1)) if len(sp) >= 2 else 0.0
    # the contact's height is unknown between the road (a tyre) and the body's lower edge
    # (0-0.25 m): a point h up casts onto the ground H / (H - h) farther from the camera's
    # foot, and so does its velocity (H: the camera's height). Not corrected (a detected
    # silhouette's lowest point is often its shadow on the road); its error is one-sided,
    # and the term is its root mean square for a height uniform over the range
    height_m = max(1.0, float(cam.center_in_world[2]))
    contact_sigma_m = _CONTACT_HEIGHT_SIGMA_M if given else _DETECTED_CONTACT_SIGMA_M
    sigma_contact = speed * contact_sigma_m / height_m
    # a silhouette lower than any vehicle standing on its contact is a piece of one (a
    # road-grey car's cabin and roof): its lowest corner may be the body's top edge, up
    # to a metre above the road
    boxes = np.array([t.boxes[i] for i in use], dtype=np.float64)[ok][near][keep]
    tall_m = _apparent_height_m(cam, ground[0], base, boxes)
    if tall_m < _MIN_VEHICLE_HEIGHT_M:
        sigma_contact = speed * _PIECE_CONTACT_SIGMA_M / height_m
    kinds_used = np.array([t.kinds[i] for i in use])[ok][near][keep]
    on_silhouette = float(np.mean(kinds_used == "silhouette"))
    # the track's own consistency: its two halves in time, fitted apart, must agree within
    # their noise; what they disagree by beyond it (a contact that followed another vehicle
    # through a merge, a corner sliding along the body) is model error
    sigma_model = _halves_disagreement(times, labels, ground[0], weights, unit)
    # its segments, fitted apart, must agree too: where they disagree beyond their noise
    # (near the camera the lowest corner slides from the body's edge to a tyre, a metre in
    # a second, and those frames weigh most) the standard error of their random-effects
    # mean (each weighed by its variance plus theirs between them) is model error. The
    # speed stays the joint fit's: with a calibration a few per cent off, the ground
    # speed varies along the track and the segments disagree for that, and their mean
    # moved speeds by up to 9 % (development seed 211, focal +4.7 %)
    pooled = _segments_pooled(times, labels, ground[0], weights, unit)
    if pooled is not None:
        sigma_model = max(sigma_model, pooled[1])
    # without a silhouette (given boxes only), refine with a cuboid moving at constant
    # velocity whose image box matches the boxes: a box's bottom centre is no fixed point
    refined = (
        _cuboid_fit(cam, boxes, times, ground[0], labels, solve, vel)
        if on_silhouette < 0.5
        else None
    )
    if refined is not None:
        vel_c, sigma_c = refined
        speed_c = float(np.linalg.norm(vel_c))
        if speed_c * dur >= 1.0:  # the cuboid's speed is reported; the two disagree by
            sigma_model = max(sigma_model, abs(speed_c - speed) / 2.0)  # the model's error
            sigma_cal *= speed_c / speed
            sigma_contact *= speed_c / speed
            vel, speed, sigma_fit = vel_c, speed_c, sigma_c
    sigma = math.sqrt(sigma_fit**2 + sigma_cal**2 + sigma_model**2 + sigma_contact**2)
    log.debug(
        "vehicle %d: %.2f m/s; sigma fit %.3f, calibration %.3f, contact %.3f, model %.3f",
        t.vid,
        speed,
        sigma_fit,
        sigma_cal,
        sigma_contact,
        sigma_model,
    )
    heading = math.degrees(math.atan2(vel[0], vel[1])) % 360.0
    heading = 0.0 if heading >= 359.99995 else heading
    world = [(int(f), float(x), float(y)) for f, (x, y) in zip(frames, ground[0], strict=True)]
    warning = _uncertainty_warning(
        speed,
        {
            "fit": sigma_fit,
            "calibration": sigma_cal,
            "model": sigma_model,
            "contact": sigma_contact,
        },
        tall_m < _MIN_VEHICLE_HEIGHT_M,
    )
    return VehicleSpeed(
        t.vid,
        "measured",
        speed * 3.6,
        sigma * 3.6,
        first,
        last,
        len(times),
        dur,
        speed * dur,
        heading,
        contact,
        len(set(labels)),
        None,
        world,
        warning,
    )


_CAUSES = {
    "fit": "its ground contact is noisy or seen over too short a time",
    "calibration": "the camera's calibration is uncertain",
    "model": "its track is inconsistent (it held other vehicles in merged blobs, or its "
    "contact slid along the body)",
    "contact": "its ground contact's height is unknown",
}


def _uncertainty_warning(speed: float, parts: dict[str, float], piece: bool) -> str | None:
    """A warning when the speed's sigma exceeds ``_UNCERTAIN_REL`` of it, naming the main
    cause (the largest term of ``parts``, m/s); None otherwise."""
    sigma = math.sqrt(sum(v**2 for v in parts.values()))
    if speed <= 0 or sigma <= _UNCERTAIN_REL * speed:
        return None
    main = max(parts, key=lambda k: parts[k])
    cause = (
        "only a piece of the vehicle was seen (its contact may be the body's top edge)"
        if main == "contact" and piece
        else _CAUSES[main]
    )
    return f"uncertain speed: sigma {100 * sigma / speed:.0f} % of it; {cause}"


def _apparent_height_m(
    cam: Any, ground: FloatArray, contacts_px: FloatArray, boxes: FloatArray
) -> float:
    """Median height (metres) of a track's boxes above their contacts: box top to contact
    pixel over the image length of a metre standing on the contact's ground point."""
    n = len(ground)
    up = cam.project(np.column_stack([ground, np.ones(n)]))[:, 1]
    metre_px = contacts_px[:, 1] - up
    tall = (contacts_px[:, 1] - boxes[:, 1]) / np.where(metre_px > 0.5, metre_px, np.nan)
    tall = tall[np.isfinite(tall)]
    return float(np.median(tall)) if len(tall) else math.nan


def _along_track_var(
    solve: FloatArray, weights: FloatArray, res: FloatArray, unit: FloatArray
) -> float:
    """Variance (m²/s²) of a weighted track fit's velocity along ``unit``: the residuals'
    weighted variance along it times the velocity row of the solve matrix (``solve[0]``)."""
    dof = max(1, len(res) - solve.shape[0])
    s2 = float(np.sum(weights * (res @ unit) ** 2) / dof)
    return s2 * float(np.sum(solve[0] ** 2 / np.maximum(weights, 1e-12)))


def _halves_disagreement(
    times: FloatArray, labels: list[int], ground: FloatArray, weights: FloatArray, unit: FloatArray
) -> float:
    """Half the speed difference (m/s) of a track's first and second halves in time, fitted
    apart (same weights), beyond 2 standard errors of that difference; 0 when a half has too
    few frames or too short a time to fit."""
    mid = float(np.median(times))
    fits = []
    for sel in (times <= mid, times > mid):
        if sel.sum() < 4:
            return 0.0
        lab = [s for s, k in zip(labels, sel, strict=True) if k]
        tt, w, g = times[sel], weights[sel], ground[sel]
        a = _design(tt, lab)
        if a.shape[0] <= a.shape[1] or float(np.ptp(tt)) <= 0:
            return 0.0
        sw = np.sqrt(w)[:, None]
        solve = np.asarray(np.linalg.pinv(a * sw) * sw.T, np.float64)
        res = g - a @ (solve @ g)
        fits.append((float((solve[0] @ g) @ unit), _along_track_var(solve, w, res, unit)))
    (v1, e1), (v2, e2) = fits
    return max(0.0, abs(v1 - v2) - 2.0 * math.sqrt(e1 + e2)) / 2.0


def _segments_pooled(
    times: FloatArray, labels: list[int], ground: FloatArray, weights: FloatArray, unit: FloatArray
) -> tuple[float, float] | None:
    """Random-effects mean (m/s) of a track's segments' speeds along ``unit``, and its
    standard error, when they disagree beyond their noise; None when they agree (or fewer
    than three segments of at least 5 frames and 0.2 s can be fitted: with two, a short
    stretch on another vehicle would weigh as much as a long true one).

    Each segment's velocity is fitted apart (same weights); their spread beyond their own
    standard errors (DerSimonian-Laird) is a variance between segments, added to each
    one's before they are averaged: a segment whose contact slid along the body no longer
    outweighs the others for being near the camera. Pooled only when the disagreement is
    significant (Cochran's Q above its chi-squared 99 % quantile). :func:`_fit_track` takes
    the standard error as model error and keeps the joint fit's speed (the mean follows a
    calibration's error along the track).
    """
    from scipy.special import chdtri  # chi-squared quantiles (scipy.stats: 1 s to import)

    speeds, variances = [], []
    lab = np.asarray(labels)
    for s in sorted(set(labels)):
        sel = lab == s
        tt = times[sel]
        if sel.sum() < 5 or float(np.ptp(tt)) < 0.2:
            continue
        a = _design(tt, [0] * int(sel.sum()))
        w, g = weights[sel], ground[sel]
        sw = np.sqrt(w)[:, None]
        solve = np.asarray(np.linalg.pinv(a * sw) * sw.T, np.float64)
        res = g - a @ (solve @ g)
        speeds.append(float((solve[0] @ g) @ unit))
        variances.append(max(_along_track_var(solve, w, res, unit), 1e-6))
    if len(speeds) < 3:
        return None  # two: their variance between them rests on one difference
    v, var = np.array(speeds), np.array(variances)
    w0 = 1.0 / var
    mean0 = float(np.sum(w0 * v) / np.sum(w0))
    q = float(np.sum(w0 * (v - mean0) ** 2))
    spread = float(np.sum(w0) - np.sum(w0**2) / np.sum(w0))
    if q <= float(chdtri(len(v) - 1, 0.01)):
        return None  # within their noise (99 %): the joint fit stands
    tau2 = max(0.0, (q - (len(v) - 1)) / spread) if spread > 0 else 0.0
    if tau2 <= 0.0:
        return None
    w1 = 1.0 / (var + tau2)
    return float(np.sum(w1 * v) / np.sum(w1)), float(math.sqrt(1.0 / np.sum(w1)))


_CAR_DIMS_M = np.array([4.5, 1.8, 1.5])
_MARGIN_PRIOR_PX = 5.0


def _cuboid_boxes(cam: Any, params: FloatArray, times: FloatArray) -> FloatArray:
    """Image boxes ``(N, 4)`` of a cuboid ``(x0, y0, vx, vy, log L, log W, log H[, margin])``.

    ``margin`` (pixels) widens the box on every side: detectors' and masks' boxes are
    looser or tighter than the object by a roughly constant number of pixels.
    """
    x0, y0, vx, vy = params[:4]
    length, width, height = np.exp(params[4:7])
    speed = math.hypot(vx, vy) or 1e-9
    fwd = np.array([vx, vy]) / speed
    left = np.array([-fwd[1], fwd[0]])
    centres = np.array([x0, y0]) + np.outer(times, [vx, vy])
    offs = np.array(
        [
            s * length / 2 * fwd + q * width / 2 * left
            for s, q in ((1, -1), (1, 1), (-1, 1), (-1, -1))
        ]
    )
    foot = centres[:, None, :] + offs[None]
    n = len(times)
    pts = np.concatenate(
        [
            np.concatenate([foot, np.zeros((n, 4, 1))], axis=2),
            np.concatenate([foot, np.full((n, 4, 1), height)], axis=2),
        ],
        axis=1,
    ).reshape(-1, 3)
    px = cam.project(pts).reshape(n, 8, 2)
    margin = params[7] if len(params) > 7 else 0.0
    return np.concatenate([px.min(axis=1) - margin, px.max(axis=1) + margin], axis=1)


def _cuboid_fit(
    cam: Any,
    boxes: FloatArray,
    times: FloatArray,
    ground: FloatArray,
    labels: list[int],
    solve: FloatArray,
    vel: FloatArray,
) -> tuple[FloatArray, float] | None:
    """Velocity and its sigma (m/s) of a constant-velocity cuboid fitted to the boxes.

    The contact-point fit gives the start (direction, speed, position); the cuboid's centre,
    velocity and dimensions (weak prior: a car, 4.5 × 1.8 × 1.5 m) are then fitted (soft-L1)
    to every frame's box. Returns None when the fit fails or is implausible.
    """
    from scipy.optimize import least_squares

    speed = float(np.linalg.norm(vel))
    if len(times) < 6 or speed <= 0:
        return None
    tc = times - times.mean()
    coef = solve @ ground
    seg0 = sorted(set(labels))
    mid = coef[1 : 1 + len(seg0)].mean(axis=0)
    start = np.concatenate([mid, vel, np.log(_CAR_DIMS_M), [0.0]])
    span = float(np.median(boxes[:, 3] - boxes[:, 1])) + 1.0

    def resid(p: FloatArray) -> FloatArray:
        pred = _cuboid_boxes(cam, p, tc)
        r = ((pred - boxes) / span * 20.0).ravel()
        prior = np.append((p[4:7] - np.log(_CAR_DIMS_M)) / 0.7, p[7] / _MARGIN_PRIOR_PX)
        out = np.concatenate([r, prior])
        return np.where(np.isfinite(out), out, 1e3)

    try:
        res = least_squares(resid, start, loss="soft_l1", f_scale=1.0, max_nfev=200)
    except (ValueError, np.linalg.LinAlgError):
        return None
    if not res.success:
        return None
    v = res.x[2:4]
    sp = float(np.linalg.norm(v))
    if not (0.5 * speed < sp < 2.0 * speed):
        return None
    try:
        jac = res.jac
        dof = max(1, len(res.fun) - len(res.x))
        s2 = 2.0 * res.cost / dof
        cov = np.linalg.pinv(jac.T @ jac) * s2
        u = v / sp
        var = float(u @ cov[2:4, 2:4] @ u)
    except np.linalg.LinAlgError:
        return None
    return v, math.sqrt(max(var, 0.0))


# --------------------------------------------------------------------------- main entry
def measure_speeds(
    calibration: CalibrationResult,
    video_path: str | os.PathLike[str],
    *,
    fps: float | None = None,
    tracks: str | os.PathLike[str] | Mapping[int, Mapping[int, Any]] | None = None,
    image_size: tuple[int, int] | None = None,
    min_track_s: float = 0.5,
    max_frames: int | None = None,
    detect_width_px: int = 640,
    n_samples: int = 200,
    seed: int = _SEED,
    progress: bool = False,
) -> RadarResult:
    """Speeds of the vehicles in a video from a calibrated camera (the virtual radar).

    Parameters
    ----------
    calibration
        The calibrated camera (:class:`camloc_geo.relative.CalibrationResult`) of the scene.
    video_path
        A video OpenCV can read, from the same camera, same framing and size as the scene.
    fps
        Frame rate; default: the one the file states (refused when it states none).
    tracks
        Boxes per frame from any detector: a file (:func:`read_tracks`) or
        ``{id: {frame: (x1, y1, x2, y2)}}``. Default: background subtraction finds vehicles.
    image_size
        ``(width, height)`` of the scene's image; the video's frames must be that size.
    min_track_s
        Shorter tracks are skipped (reported with the reason).
    max_frames
        Process only the first frames (default: all, up to :data:`MAX_VIDEO_FRAMES`).
    detect_width_px
        Background subtraction runs on frames reduced to at most this width.
    n_samples, seed
        Monte Carlo cameras for the calibration part of ``sigma_kmh``.
    progress
        Show a tqdm progress bar on stderr.

    Returns
    -------
    RadarResult
        Every vehicle with its speed (or why it has none). No vehicle at all is not an error:
        the result is empty with a warning (the CLI turns it into exit 2).

    Raises
    ------
    InputError
        Unreadable video, no usable frame rate, frame size different from the scene's image,
        too long or too large a video, malformed tracks.
    """
    t0 = time.perf_counter()
    if fps is not None and not (math.isfinite(fps) and 0.5 <= fps <= 1000.0):
        raise InputError(f"fps must be between 0.5 and 1000, not {fps}")
    if not (math.isfinite(min_track_s) and min_track_s > 0):
        raise InputError(f"min_track_s must be > 0, not {min_track_s}")
    given: TrackBoxes | None = None
    if tracks is not None:
        given = (
            read_tracks(tracks) if isinstance(tracks, (str, os.PathLike)) else _check_tracks(tracks)
        )
    cap, width, height, fps_file, n_file = _open_video(video_path)
    try:
        if image_size is not None:
            _check_size(video_path, (width, height), image_size)
        if fps is None and fps_file is None:
            raise InputError(f"video {video_path} states no frame rate: give it (--fps)")
        rate = float(fps if fps is not None else fps_file)  # type: ignore[arg-type]
        limit = MAX_VIDEO_FRAMES if max_frames is None else min(max_frames, MAX_VIDEO_FRAMES)
        if max_frames is not None and max_frames < 1:
            raise InputError(f"max_frames must be >= 1, not {max_frames}")
        if max_frames is None and n_file > MAX_VIDEO_FRAMES:
            raise InputError(
                f"video {video_path} has {n_file} frames; the limit is {MAX_VIDEO_FRAMES} "
                "(cut it, or process the first frames only with max_frames / --max-frames)"
            )
        result = _run(
            cap,
            calibration,
            width,
            height,
            rate,
            n_file,
            limit,
            given,
            detect_width_px,
            min_track_s,
            n_samples,
            seed,
            progress,
            str(video_path),
        )
    finally:
        cap.release()
    n_done, vehicles, noise = result
    if n_done == 0:
        raise InputError(f"cannot decode any frame of video {video_path}")
    if n_done == 1:  # a file stating no frame count, or a wrong one
        raise _single_frame(video_path)
    if given is not None and n_done < limit and max(max(p) for p in given.values() if p) >= n_done:
        log.warning("some track boxes are after the video's last frame (%d)", n_done - 1)
    info = VideoInfo(
        str(video_path),
        width,
        height,
        rate,
        "file" if fps is None else "given",
        fps_file,
        n_done,
    )
    warnings: list[str] = []
    if not vehicles:
        warnings.append(
            "no vehicle found in the video"
            if given is None
            else "no given track box falls within the video's frames"
        )
    elif not any(v.measured for v in vehicles):
        warnings.append("vehicles were found but none could be measured (see their reasons)")
    if max_frames is None and n_done >= MAX_VIDEO_FRAMES:
        warnings.append(
            f"stopped after {MAX_VIDEO_FRAMES} frames (the limit); the rest of the video is "
            "not measured"
        )
    return RadarResult(
        info,
        vehicles,
        "detection" if given is None else "tracks",
        time.perf_counter() - t0,
        noise,
        warnings,
        calibration_summary(calibration),
    )


def calibration_summary(calibration: CalibrationResult) -> dict[str, Any]:
    """The calibration's focal length, its sigma and the witnesses it used (JSON-ready).

    ``witnesses``: ``"annotators"`` always, ``"photo"`` where the scene photo's detected
    lines joined the fit (``photo_segments``), ``"video"`` where the video's lines did
    (``video_segments``, :func:`camloc_geo.sensors._video_lines.video_lines`).
    """
    out: dict[str, Any] = {"focal_px": round(float(calibration.camera.focal_px), 2)}
    if calibration.focal_sigma_px is not None:
        out["focal_sigma_px"] = round(float(calibration.focal_sigma_px), 2)
    witnesses = ["annotators"]
    photo = dict(getattr(calibration, "photo_segments", {}) or {})
    video = dict(getattr(calibration, "video_segments", {}) or {})
    if photo:
        witnesses.append("photo")
        out["photo_segments"] = photo
    if video:
        witnesses.append("video")
        out["video_segments"] = video
    out["witnesses"] = witnesses
    return out


def _run(
    cap: Any,
    calibration: CalibrationResult,
    width: int,
    height: int,
    fps: float,
    n_file: int,
    limit: int,
    given: TrackBoxes | None,
    detect_width_px: int,
    min_track_s: float,
    n_samples: int,
    seed: int,
    progress: bool,
    name: str,
) -> tuple[int, list[VehicleSpeed], int]:
    import cv2
    from tqdm import tqdm

    scale = min(1.0, detect_width_px / width)
    sw, sh = round(width * scale), round(height * scale)
    min_area = max(12, int(4e-4 * sw * sh))
    bg_init = _background_init(cap, n_file, scale, limit)
    background = None if bg_init is None else bg_init.astype(np.float32)
    max_coast = max(5, round(_MAX_COAST_S * fps))
    hidden: set[int] = set()
    near = _near_mask(calibration, sw, sh, scale) if given is None else None
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3))
    kernel_close = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (7, 7))
    active: list[_Track] = []
    vehicles: list[VehicleSpeed] = []
    noise = [0]
    last_given = {vid: max(per) for vid, per in given.items() if per} if given is not None else {}

    # detected tracks finished lately, with their vehicles' index: a later track of the same
    # vehicle (its fragment) is joined to them by its motion
    closed: list[tuple[_Track, int]] = []

    def fit(t: _Track) -> VehicleSpeed:
        return _fit_track(
            t,
            calibration,
            fps,
            width,
            height,
            min_track_s,
            n_samples,
            seed,
            scale,
            given=given is not None,
        )

    def finish(t: _Track) -> None:
        if t.absorbed:
            return  # a piece of a vehicle measured by its own track
        if given is None and len(t.frames) < _MIN_DETECTED_FRAMES:
            noise[0] += 1  # a flicker, not a vehicle
            return
        if not t.frames:
            return
        if given is not None:
            vehicles.append(fit(t))
            return
        for piece in _split_reversals(t):
            piece.points = None
            v = fit(piece)
            link = _fragment_of(closed, vehicles, piece, v, fps) if v.measured else None
            if link is not None:
                k, joinable = link
                earlier, index = closed[k]
                v_earlier = vehicles[index]
                if joinable:
                    both = _joined(earlier, piece)
                    v_both = fit(both)
                    if v_both.measured and v_both.sigma_kmh <= min(
                        v.sigma_kmh, v_earlier.sigma_kmh
                    ):
                        vehicles[index] = v_both
                        closed[k] = (both, index)
                        continue
                # not joined (the joined fit would be less sure than the better of the
                # two: a short, far fragment whose own segments disagree; or one repeats
                # the other's frames): the less sure of the two is the other's fragment
                if v.sigma_kmh < v_earlier.sigma_kmh:
                    vehicles[index] = _as_fragment(v_earlier, v)
                    del closed[k]
                else:
                    v = _as_fragment(v, v_earlier)
            vehicles.append(v)
            closed.append((piece, len(vehicles) - 1))

    def prune(frame: int) -> None:
        """Forget closed tracks no active or later track can be a fragment of."""
        gap = round(_LINK_MAX_GAP_S * fps)
        start = min([frame, *(t.frames[0] for t in active if t.frames)])
        closed[:] = [(t, k) for t, k in closed if t.frames[-1] + gap >= start]

    by_id: dict[int, _Track] = {}
    next_id = 1
    prev_grey = None
    total = min(n_file, limit) if n_file else None
    bar = tqdm(total=total, disable=not progress, file=sys.stderr, unit="frame", desc="radar")
    i = 0
    try:
        while i < limit:
            ok, frame = cap.read()
            if not ok:
                break
            if frame.shape[1] != width or frame.shape[0] != height:
                raise InputError(f"video {name}: frame {i} is not {width}x{height}")
            grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY) if frame.ndim == 3 else frame
            small = (
                frame if scale == 1.0 else cv2.resize(frame, (sw, sh), interpolation=cv2.INTER_AREA)
            )
            if background is None:
                background = small.astype(np.float32)
            diff = cv2.absdiff(small, background.astype(np.uint8))
            if diff.ndim == 3:  # largest channel difference (cv2: numpy's max is slow here)
                b, g, r = cv2.split(diff)
                level = cv2.max(cv2.max(b, g), r)
            else:
                level = diff
            fg = cv2.threshold(level, _FG_THRESHOLD, 255, cv2.THRESH_BINARY)[1]
            cv2.accumulateWeighted(small, background, _BG_RATE, mask=cv2.bitwise_not(fg))
            fg = _foreground(small, background, level, fg, near)
            fg = cv2.morphologyEx(fg, cv2.MORPH_OPEN, kernel)
            fg = cv2.morphologyEx(fg, cv2.MORPH_CLOSE, kernel_close)
            if given is None:
                blobs, blob_ids, labels, small, small_ids = _blobs(fg, scale, min_area)
                blobs, blob_ids = _join_fragments(active, blobs, blob_ids, small, small_ids)
                match, fresh, hidden = _associate(active, blobs)
                for k in hidden:  # coast on the prediction while merged with another
                    t = active[k]
                    t.box = t.predicted()
                    t.coasting += 1
                    t.points = None
                current: dict[int, Box] = {k: blobs[j] for k, j in match.items()}
                own = {k: blob_ids[j] for k, j in match.items()}
                for j in fresh:
                    t = _Track(next_id, blobs[j])
                    next_id += 1
                    active.append(t)
                    current[len(active) - 1] = blobs[j]
                    own[len(active) - 1] = blob_ids[j]
            else:
                current, own, labels = {}, {}, None
                for vid, per in given.items():
                    if i in per:
                        if vid not in by_id:
                            by_id[vid] = _Track(vid, per[i])
                            active.append(by_id[vid])
                        current[active.index(by_id[vid])] = _clip(per[i], width, height)
            shifts: dict[int, tuple[float, float]] = (
                _klt_step(prev_grey, grey, active, current) if prev_grey is not None else {}
            )
            fg_full = None
            for k, t in enumerate(active):
                if k not in current:
                    if given is not None or k not in hidden:
                        t.missed += 1
                    t.points = None
                    continue
                t.coasting = 0
                box = current[k]
                if k in shifts:  # the features' motion: robust to a blob that merges or splits
                    t.velocity = shifts[k]
                elif t.frames and not _resized(t.boxes[-1], box):
                    gap = max(1, i - t.frames[-1])
                    last = t.boxes[-1]
                    t.velocity = (
                        ((box[0] + box[2]) - (last[0] + last[2])) / 2 / gap,
                        ((box[1] + box[3]) - (last[1] + last[3])) / 2 / gap,
                    )
                # (a box that changed size, a merged blob that split or a blob that merged,
                # moved its centre by more than the vehicle did: the motion is kept)
                t.box = box
                t.missed = 0
                c, kind = _contact(fg, box, scale, labels, own.get(k))
                t.frames.append(i)
                t.boxes.append(box)
                t.contacts.append(c)
                t.kinds.append(kind)
                t.klt.append(shifts.get(k, (math.nan, math.nan)))
                t.border.append(
                    box[0] <= 1.0
                    or box[1] <= 1.0
                    or box[2] >= width - 1.0
                    or box[3] >= height - 1.0
                )
                # a given box overlapping another one's: the silhouette in it may be both
                # vehicles' (detected tracks are kept apart by the association instead)
                t.occluded.append(
                    given is not None
                    and any(_overlap(box, b) > 0.02 for j, b in current.items() if j != k)
                )
                if t.points is None or len(t.points) < 8 or len(t.frames) % 10 == 0:
                    if fg_full is None:
                        fg_full = (
                            fg
                            if scale == 1.0
                            else cv2.resize(fg, (width, height), interpolation=cv2.INTER_NEAREST)
                        )
                    t.points = _seed_features(grey, fg_full, box)
            still = []
            for t in active:
                if given is None:
                    over = t.missed > _MAX_MISSED or t.coasting > max_coast
                else:
                    over = i >= last_given[t.vid]
                if over:
                    finish(t)  # fitted now: a long video keeps only the active tracks
                else:
                    still.append(t)
            if len(still) != len(active):
                active = still
                if given is None:
                    prune(i)
                if given is not None:
                    by_id = {t.vid: t for t in active}
            prev_grey = grey
            i += 1
            bar.update(1)
    finally:
        bar.close()
    for t in active:
        finish(t)
    vehicles.sort(key=lambda v: (v.first_frame, v.vehicle_id))
    if given is None:  # number detected vehicles 1, 2, ... in order of appearance
        vehicles = [replace(v, vehicle_id=k + 1) for k, v in enumerate(vehicles)]
    return i, vehicles, noise[0]


def _split_reversals(t: _Track) -> list[_Track]:
    """Split a detected track where one vehicle left the frame and another came in.

    The blob of a vehicle leaving through an image border and the blob of one entering at
    the same place can be one track. Between two stretches wholly inside the image with a
    border-touching stretch between them, the track is cut when the image motion reverses.
    It is also cut where its features' motion turns back (:func:`_identity_switches`).
    """
    runs: list[tuple[int, int]] = []
    start = None
    for i, b in enumerate([*t.border, True]):
        if not b and start is None:
            start = i
        elif b and start is not None:
            runs.append((start, i))
            start = None
    cuts = []
    for (a0, a1), (b0, b1) in itertools.pairwise(runs):
        if a1 - a0 < 2 or b1 - b0 < 2:
            continue
        va = np.subtract(_centre(t.boxes[a1 - 1]), _centre(t.boxes[a0]))
        vb = np.subtract(_centre(t.boxes[b1 - 1]), _centre(t.boxes[b0]))
        if float(va @ vb) < 0:
            cuts.append((a1 + b0) // 2)
    cuts.extend(_identity_switches(t))
    cuts = sorted(set(cuts))
    if not cuts:
        return [t]
    pieces = []
    for lo, hi in zip([0, *cuts], [*cuts, len(t.frames)], strict=True):
        piece = _Track(t.vid, t.boxes[hi - 1])
        piece.frames, piece.boxes = t.frames[lo:hi], t.boxes[lo:hi]
        piece.contacts, piece.kinds = t.contacts[lo:hi], t.kinds[lo:hi]
        piece.klt, piece.border = t.klt[lo:hi], t.border[lo:hi]
        piece.occluded = t.occluded[lo:hi]
        pieces.append(piece)
    return pieces


def _identity_switches(t: _Track) -> list[int]:
    """Record indices where a detected track's features turn back: it now follows another
    vehicle (two vehicles passed each other in one blob and the track came out on the one
    driving the other way). The features' median image motion (KLT) of a vehicle changes
    smoothly; consecutive motions (at least 0.5 px a frame) at more than 120 degrees apart
    mark a switch."""
    cuts = []
    last: tuple[float, float] | None = None
    for i, (dx, dy) in enumerate(t.klt):
        if not (math.isfinite(dx) and math.isfinite(dy)) or math.hypot(dx, dy) < 0.5:
            continue
        if last is not None:
            cos = (dx * last[0] + dy * last[1]) / (math.hypot(dx, dy) * math.hypot(*last))
            if cos < -0.5:
                cuts.append(i)
        last = (dx, dy)
    return cuts


def _fragment_of(
    closed: list[tuple[_Track, int]],
    vehicles: list[VehicleSpeed],
    piece: _Track,
    fit: VehicleSpeed,
    fps: float,
) -> tuple[int, bool] | None:
    """The earlier track (index into ``closed``) of the vehicle ``piece`` is a fragment of,
    and whether the two can be joined into one track; None when it is no fragment.

    Two tracks are one vehicle when one's ground contacts (``track_world_m``) lie where the
    other's fitted motion (its speed and heading, anchored on the offset of its 10 frames
    nearest the other track in time) puts that vehicle at the same times: within
    ``_LINK_ALONG_M`` along the motion plus twice the extrapolation's sigma (that track's
    speed sigma times the time from its anchor), and ``_LINK_ACROSS_M`` across it (medians
    over the frames). Either track may carry the motion (the earlier forward, the later
    backward): a short far fragment's own speed is poor, its partner's extrapolates well.
    ``piece`` must start after the earlier track did and at most ``_LINK_MAX_GAP_S`` after
    it ended. The nearest such track is taken. The two can be joined when they share at
    most ``_LINK_MAX_OVERLAP`` frames and ``piece`` goes on for 3 frames past the earlier
    track's end; otherwise one repeats frames of the other.
    """
    if not fit.track_world_m:
        return None
    best: tuple[float, int, bool] | None = None
    for k, (earlier, index) in enumerate(closed):
        v = vehicles[index]
        if not v.measured or not v.track_world_m or earlier.frames[0] >= piece.frames[0]:
            continue
        if (piece.frames[0] - earlier.frames[-1]) / fps > _LINK_MAX_GAP_S:
            continue
        off = min(
            _off_motion(v, fit, fps, forward=True),
            _off_motion(fit, v, fps, forward=False),
        )
        if not math.isfinite(off):
            continue
        overlap = earlier.frames[-1] - piece.frames[0] + 1
        beyond = sum(1 for f in piece.frames if f > earlier.frames[-1])
        joinable = overlap <= _LINK_MAX_OVERLAP and beyond >= 3
        if best is None or off < best[0]:
            best = (off, k, joinable)
    return None if best is None else (best[1], best[2])


def _off_motion(mover: VehicleSpeed, other: VehicleSpeed, fps: float, *, forward: bool) -> float:
    """How far (metres) ``other``'s ground contacts lie from ``mover``'s fitted motion at the
    same times, or ``inf`` beyond the bounds of :func:`_fragment_of`.

    ``forward``: ``mover`` is the earlier track, anchored on its last 10 frames; otherwise
    the later one, anchored on its first 10.
    """
    theirs = np.array(mover.track_world_m, dtype=np.float64)
    mine = np.array(other.track_world_m, dtype=np.float64)
    head = math.radians(mover.heading_deg)
    unit = np.array([math.sin(head), math.cos(head)])
    vel = mover.speed_kmh / 3.6 * unit
    anchor = theirs[-10:] if forward else theirs[:10]
    origin = np.median(anchor[:, 1:] - np.outer(anchor[:, 0] / fps, vel), axis=0)
    res = mine[:, 1:] - (origin + np.outer(mine[:, 0] / fps, vel))
    along = float(np.median(res @ unit))
    across = float(np.median(res @ np.array([-unit[1], unit[0]])))
    span_s = abs(float(np.median(mine[:, 0]) - np.median(anchor[:, 0]))) / fps
    tol = _LINK_ALONG_M + 2.0 * (mover.sigma_kmh / 3.6) * span_s
    if abs(along) > tol or abs(across) > _LINK_ACROSS_M:
        return math.inf
    return math.hypot(along, across)


def _as_fragment(v: VehicleSpeed, whole: VehicleSpeed) -> VehicleSpeed:
    """``v`` reported as a fragment of the vehicle ``whole`` measured (skipped, no speed)."""
    return replace(
        v,
        status="skipped",
        speed_kmh=math.nan,
        sigma_kmh=math.nan,
        reason=(
            f"a fragment of the vehicle tracked over frames {whole.first_frame}-"
            f"{whole.last_frame}: its ground contact moves with that vehicle's (measured "
            "there)"
        ),
        warning=None,
    )


def _joined(earlier: _Track, later: _Track) -> _Track:
    """One track of a vehicle's two fragments: the earlier's records, then the later's past
    the earlier's last frame (the fit gives each its own offset where the contact jumps)."""
    keep = [k for k, f in enumerate(later.frames) if f > earlier.frames[-1]]
    out = _Track(earlier.vid, later.boxes[-1])
    for name in ("frames", "boxes", "contacts", "kinds", "klt", "border", "occluded"):
        setattr(out, name, getattr(earlier, name) + [getattr(later, name)[k] for k in keep])
    return out


def _weak_threshold(level: Any) -> float:
    """Weak foreground threshold (grey levels) of a frame's difference image ``level``.

    ``_FG_WEAK_NOISE`` times its median (most pixels are background: their difference is
    the noise), clipped to ``[_FG_WEAK_MIN, _FG_THRESHOLD]``: a noisy video keeps the
    strong threshold alone.
    """
    noise = float(np.median(level))
    return float(min(_FG_THRESHOLD, max(_FG_WEAK_MIN, _FG_WEAK_NOISE * noise)))


def _near_mask(calibration: CalibrationResult, sw: int, sh: int, scale: float) -> Any:
    """Mask (255) of the reduced pixels whose ray meets the road at most
    ``_MAX_GROUND_PER_PX_M`` of road per detection pixel away (what the fit uses, see
    :func:`_fit_track`); 0 farther and above the horizon."""
    cam = calibration.camera
    cols, rows = np.meshgrid(np.arange(sw), np.arange(sh))
    px = np.stack([(cols.ravel() + 0.5) / scale, (rows.ravel() + 0.5) / scale], axis=1)
    centre = np.asarray(cam.center_in_world, dtype=np.float64)[None]
    focal = np.array([cam.focal_px], dtype=np.float64)
    rot = cam.cam_from_world_rotation
    ground = _ground(centre, _rays(px[None], focal, cam.principal_point, rot))[0, :, :2]
    foot = np.zeros(len(px))
    for step in ((1.0, 0.0), (0.0, 1.0)):
        moved = _ground(centre, _rays((px + step)[None], focal, cam.principal_point, rot))
        foot += np.sum((moved[0, :, :2] - ground) ** 2, axis=1)
    with np.errstate(invalid="ignore"):
        near = np.isfinite(foot) & (
            np.sqrt(np.where(np.isfinite(foot), foot, 0.0)) / scale <= _MAX_GROUND_PER_PX_M
        )
    return near.reshape(sh, sw).astype(np.uint8) * 255


def _foreground(small: Any, background: Any, level: Any, strong: Any, near: Any = None) -> Any:
    """Foreground mask (255) before morphology: ``strong`` (above ``_FG_THRESHOLD``) and
    its weak bridges.

    Pixels above the weak threshold (:func:`_weak_threshold`) with strong foreground both
    above and below them in their column, each within ``_FG_BRIDGE_PX``, are foreground
    too: a vehicle whose colour is near the road's
    (silver, road-grey: its lit face 5-15 levels away) stays one blob down to its wheels
    and contact shadow instead of losing its lower body (whose loss put the contact on the
    body and read the speed fast). Bridges stay inside the strong silhouette's extent, so
    they never move its outline outward. Cast shadows (:func:`_shadows`) are removed from
    both layers first. ``near`` (:func:`_near_mask`, optional): bridges only there; far
    away, where a detection pixel covers more than ``_MAX_GROUND_PER_PX_M`` of road and
    no contact is used, they joined vehicles stacked in the image near the horizon.
    """
    import cv2

    if small.ndim == 3:
        not_shadow = cv2.bitwise_not(_shadows(small, background))
        strong = cv2.bitwise_and(strong, not_shadow)
    weak_level = _weak_threshold(level)
    if weak_level >= _FG_THRESHOLD or not strong.any():
        return strong
    weak = cv2.threshold(level, weak_level, 255, cv2.THRESH_BINARY)[1]
    if small.ndim == 3:
        weak = cv2.bitwise_and(weak, not_shadow)
    n = _FG_BRIDGE_PX
    # dilation with a one-sided vertical line: strong within n pixels below / above
    col = np.ones((n, 1), np.uint8)
    below = cv2.dilate(strong, col, anchor=(0, 0))
    above = cv2.dilate(strong, col, anchor=(0, n - 1))
    bridge = cv2.bitwise_and(below, above)
    if near is not None:  # far away: stacked vehicles would be bridged, and not measured
        bridge = cv2.bitwise_and(bridge, near)
    return cv2.bitwise_or(strong, cv2.bitwise_and(weak, bridge))


def _shadows(frame: Any, background: Any) -> Any:
    """Mask (255) of cast shadows: the background darkened, every channel by the same ratio,
    its texture kept.

    A shadow keeps the road's colour and dims it (ratio ``_SHADOW_RATIO``, spread below
    ``_SHADOW_SPREAD`` between channels); a vehicle changes the colour or is much darker.
    A grey vehicle on a grey road passes that test too: but a shadow keeps the road's
    texture (the frame correlates with the background, locally), a vehicle's panels hide
    it. Where the background has texture (local deviation above ``_TEXTURE_MIN``) a shadow
    must also correlate with it (normalised cross-correlation above ``_SHADOW_NCC``).
    """
    import cv2

    ratio = cv2.divide(frame.astype(np.float32), background + 1.0)
    b, g, r = cv2.split(ratio)
    lo = cv2.min(cv2.min(b, g), r)
    hi = cv2.max(cv2.max(b, g), r)
    dim = cv2.inRange(lo, _SHADOW_RATIO[0], _SHADOW_RATIO[1])
    grey = cv2.inRange(hi - lo, 0.0, _SHADOW_SPREAD)
    bright = cv2.inRange(hi, 0.0, _SHADOW_RATIO[1])
    shadow = cv2.bitwise_and(cv2.bitwise_and(dim, grey), bright)
    f = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY).astype(np.float32)
    bg = cv2.cvtColor(background, cv2.COLOR_BGR2GRAY)
    win = (5, 5)
    mf, mb = cv2.blur(f, win), cv2.blur(bg, win)
    cov = cv2.blur(f * bg, win) - mf * mb
    var_f = cv2.blur(f * f, win) - mf * mf
    var_b = cv2.blur(bg * bg, win) - mb * mb
    ncc = cov / np.sqrt(np.maximum(var_f * var_b, 1e-6))
    textured = var_b > _TEXTURE_MIN**2
    hidden = (textured & (ncc < _SHADOW_NCC)).astype(np.uint8) * 255
    return cv2.bitwise_and(shadow, cv2.bitwise_not(hidden))


def _resized(a: Box, b: Box) -> bool:
    """True when box ``b`` differs from ``a`` in width or height by more than 20 % + 2 px."""
    wa, ha, wb, hb = a[2] - a[0], a[3] - a[1], b[2] - b[0], b[3] - b[1]
    return abs(wb - wa) > 0.2 * wa + 2.0 or abs(hb - ha) > 0.2 * ha + 2.0


def _centre(box: Box) -> tuple[float, float]:
    return ((box[0] + box[2]) / 2.0, (box[1] + box[3]) / 2.0)


def _clip(box: Box, width: int, height: int) -> Box:
    x1, y1, x2, y2 = box
    return (max(0.0, x1), max(0.0, y1), min(float(width), x2), min(float(height), y2))
