"""Witness lines of a street video: the moving vehicles' edges and tracks, per axis.

Traffic engineers calibrate a street camera from its video (Dubská et al. 2014, 2015;
the BrnoCompSpeed reference calibrations): the vehicles' motion converges on the street's
vanishing point, and the edges of the moving vehicles (fronts, backs and roof edges across
the road; the bodies' uprights) give the across-street and the vertical points, gathered
over hundreds of frames. :func:`video_lines` returns those segments and the three
vanishing points they meet at; :func:`camloc_geo.relative.calibrate` takes them as one more
witness group beside the annotators (``CalibrationSettings.video_lines``).

Only moving foreground counts, by three tests: a segment must lie on the frame's
foreground (a difference of at least ``_FG_THRESHOLD`` grey levels from the video's median
background, cast shadows removed, as the radar finds vehicles); it must not lie on an edge
of that background (a static edge a vehicle passes in front of, e.g. the street's end
against the sky); and a track must move (``_MIN_TRACK_PX``). Static scenery is in the
median background, so its edges never pass the first two tests.

The groups are found without the camera: the tracks (KLT features followed over up to
``_TRACK_FRAMES`` frames, straight to ``_TRACK_RMS_PX``) meet at the street's point; of
the edges that do not, those within ``_UPRIGHT_DEG`` of the image's vertical meet at the
vertical point, and the rest at the across-street point (each by RANSAC, then a weighted
least-squares refinement on the inliers). Which axis of the scene each group serves is the
calibration's decision (the nearest of its fitted axes).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from camloc_geo._errors import InputError

__all__ = ["GROUPS", "VideoLines", "video_lines"]

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int_]

GROUPS = ("street", "across", "vertical")

_FG_THRESHOLD = 30  # grey levels (largest channel) from the background: foreground
_FG_INSIDE = 0.9  # fraction of a segment's samples on the (dilated) foreground
_STATIC_MAX = 0.3  # fraction of a segment's samples allowed on a background edge
_MIN_EDGE_PX = 15.0  # shorter edges are not used
_EDGE_STRIDE = 2  # edges from every this many frames
_MAX_FRAMES = 600  # frames read at most (30 s at 20 fps)
_TRACK_FRAMES = 8  # a feature is followed over this many frames at most
_TRACK_RMS_PX = 0.7  # a track this far (RMS, px) from its straight line is not straight
_MIN_TRACK_PX = 30.0  # a track must move this far
_MAX_FEATURES = 200  # features seeded per frame on the foreground
_UPRIGHT_DEG = 25.0  # an edge within this of the image's vertical is an upright candidate
_INLIER_PX = 1.0  # a segment's end within this of the line from its middle to the point
_RANSAC_ITER = 400
_MIN_GROUP = 12  # a group's point needs this many segments
_SEED = 20261125
_NEED = "its lines need a video of the moving vehicles"


@dataclass(frozen=True)
class VideoLines:
    """Witness segments of a video per group (street, across, vertical).

    Attributes
    ----------
    image_size
        The video's frame size ``(width, height)``, pixels.
    segments
        ``(N, 4)`` segments ``[x1, y1, x2, y2]``, pixels (the frames' own: no distortion
        model applied).
    labels
        ``(N,)`` index into :data:`GROUPS` (0 street, 1 across, 2 vertical).
    vanishing_points
        ``(3, 3)`` homogeneous vanishing point per group (unit norm; a row of NaN where a
        group has too few segments).
    n_frames
        Frames read.
    counts
        Segments per group name, and ``"tracks"``, ``"edges"`` examined.
    """

    image_size: tuple[int, int]
    segments: FloatArray
    labels: IntArray
    vanishing_points: FloatArray
    n_frames: int
    counts: dict[str, int] = field(default_factory=dict)

    def __hash__(self) -> int:  # settings holding it stay hashable
        return id(self)

    def __eq__(self, other: object) -> bool:
        return self is other

    def has_groups(self) -> bool:
        """True when at least one group has a vanishing point (the video gave lines)."""
        return bool(np.any(np.all(np.isfinite(self.vanishing_points), axis=1)))

    def group(self, name: str) -> FloatArray:
        """The segments of one group (``"street"``, ``"across"`` or ``"vertical"``)."""
        return np.asarray(self.segments[self.labels == GROUPS.index(name)], dtype=float)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (counts and points, not the segments)."""
        vps: dict[str, list[float] | None] = {}
        for k, name in enumerate(GROUPS):
            v = self.vanishing_points[k]
            if np.all(np.isfinite(v)) and abs(v[2]) > 1e-12:
                vps[name] = [round(float(v[0] / v[2]), 1), round(float(v[1] / v[2]), 1)]
            else:
                vps[name] = None
        return {"frames": self.n_frames, "segments": dict(self.counts), "vanishing_px": vps}


def video_lines(
    video_path: str | os.PathLike[str],
    *,
    image_size: tuple[int, int] | None = None,
    max_frames: int = _MAX_FRAMES,
) -> VideoLines:
    """Witness segments of the moving vehicles in a street video, per group.

    Parameters
    ----------
    video_path
        The video (any format OpenCV reads).
    image_size
        The scene's image size: the video must have it.
    max_frames
        Read at most this many frames (the first ones; the median background is sampled
        within them too). Default ``_MAX_FRAMES`` (600, 30 s at 20 fps); the cost is about
        linear in the frames read.

    Returns
    -------
    VideoLines
        Segments, their group and each group's vanishing point. A video too short for a
        background (under 10 frames) or without moving vehicles gives no group: every row
        of ``vanishing_points`` NaN (:meth:`VideoLines.has_groups` False).

    Raises
    ------
    InputError
        Missing or unreadable video, a still image, no frame that decodes, ``max_frames``
        under 1, or frames of another size than ``image_size``.
    """
    from camloc_geo.sensors.radar import (
        _background_init,
        _check_size,
        _open_video,
    )

    if isinstance(max_frames, bool) or not isinstance(max_frames, (int, np.integer)):
        raise InputError(f"max_frames must be a whole number, not {max_frames!r}")
    if max_frames < 1:
        raise InputError(f"max_frames must be >= 1, not {max_frames}")
    limit = int(max_frames)
    cap, width, height, _fps, n_file = _open_video(video_path, need=_NEED)
    try:
        if image_size is not None:
            _check_size(video_path, (width, height), image_size)
        bg = _background_init(cap, n_file, 1.0, limit)
        edges: list[FloatArray] = []
        tracks: list[FloatArray] = []
        n_read = _scan(cap, bg, limit, width, height, edges, tracks)
    finally:
        cap.release()
    if n_read == 0:
        raise InputError(f"cannot decode any frame of video {video_path}")
    seg_edges = np.vstack(edges) if edges else np.zeros((0, 4))
    seg_tracks = np.vstack(tracks) if tracks else np.zeros((0, 4))
    return _group(seg_edges, seg_tracks, (width, height), n_read)


def _scan(
    cap: Any,
    bg: Any,
    limit: int,
    width: int,
    height: int,
    edges: list[FloatArray],
    tracks: list[FloatArray],
) -> int:
    """Read the frames: foreground edges into ``edges``, straight tracks into ``tracks``.

    Without a background (``bg`` None: too short a video) only the first frame is read, to
    tell a video that decodes from one that does not; returns the frames read.
    """
    import cv2

    if bg is None:
        ok, _frame = cap.read()
        return 1 if ok else 0

    from camloc_geo.sensors.radar import _shadows

    bg_f = bg.astype(np.float32)
    bg_grey = cv2.cvtColor(bg, cv2.COLOR_BGR2GRAY) if bg.ndim == 3 else bg
    static = cv2.dilate(
        cv2.Canny(bg_grey, 40, 120), cv2.getStructuringElement(cv2.MORPH_RECT, (5, 5))
    )
    lsd = cv2.createLineSegmentDetector() if hasattr(cv2, "createLineSegmentDetector") else None
    k3 = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3))
    k7 = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (7, 7))
    prev_grey = None
    live: list[list[tuple[float, float]]] = []  # per live feature: its positions
    pts = None
    i = 0
    while i < limit:
        ok, frame = cap.read()
        if not ok:
            break
        if frame.shape[1] != width or frame.shape[0] != height:
            raise InputError(f"video: frame {i} is not {width}x{height}")
        grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY) if frame.ndim == 3 else frame
        diff = cv2.absdiff(frame, bg)
        if diff.ndim == 3:
            b, g, r = cv2.split(diff)
            level = cv2.max(cv2.max(b, g), r)
        else:
            level = diff
        fg = cv2.threshold(level, _FG_THRESHOLD, 255, cv2.THRESH_BINARY)[1]
        fg = cv2.morphologyEx(fg, cv2.MORPH_OPEN, k3)
        # The work below is done in the foreground's bounding box only (+ a margin).
        bx, by, bw, bh = cv2.boundingRect(fg)
        has_fg = bool(bw * bh > 0 and cv2.countNonZero(fg) > 50)
        x0, y0 = max(bx - 8, 0), max(by - 8, 0)
        x1, y1 = min(bx + bw + 8, width), min(by + bh + 8, height)
        if has_fg and frame.ndim == 3:
            box = (slice(y0, y1), slice(x0, x1))
            shadow = _shadows(np.ascontiguousarray(frame[box]), np.ascontiguousarray(bg_f[box]))
            fg[box] = cv2.bitwise_and(fg[box], cv2.bitwise_not(shadow))
        fg = cv2.morphologyEx(fg, cv2.MORPH_CLOSE, k7)
        if has_fg and i % _EDGE_STRIDE == 0:
            fg_near = cv2.dilate(fg[y0:y1, x0:x1], k7)
            found = _frame_edges(grey[y0:y1, x0:x1], fg_near, static[y0:y1, x0:x1], lsd)
            edges.append(found + np.array([x0, y0, x0, y0], dtype=float))
        # Tracks: KLT features on the foreground, followed while they stay straight.
        if prev_grey is not None and pts is not None and len(pts):
            none: Any = None
            nxt, st, _err = cv2.calcOpticalFlowPyrLK(
                prev_grey, grey, pts, none, winSize=(15, 15), maxLevel=3
            )
            back, st2, _e2 = cv2.calcOpticalFlowPyrLK(
                grey, prev_grey, nxt, none, winSize=(15, 15), maxLevel=3
            )
            fb = np.linalg.norm((back - pts).reshape(-1, 2), axis=1)
            good = (st.ravel() == 1) & (st2.ravel() == 1) & (fb < 0.5)
            keep_live = []
            for k, p in enumerate(nxt.reshape(-1, 2)):
                if good[k] and 0 <= p[0] < width and 0 <= p[1] < height:
                    keep_live.append([*live[k], (float(p[0]), float(p[1]))])
                else:
                    _finish(live[k], tracks)
            live = keep_live
            for t in live:
                if len(t) >= _TRACK_FRAMES:
                    _finish(t, tracks)
            live = [t for t in live if len(t) < _TRACK_FRAMES]
            keep_pts = [t[-1] for t in live]
            pts = np.array(keep_pts, dtype=np.float32).reshape(-1, 1, 2) if keep_pts else None
        if has_fg and (pts is None or len(pts) < _MAX_FEATURES // 2):
            mask = cv2.erode(fg, k7)
            if pts is not None:
                for x, y in pts.reshape(-1, 2):
                    cv2.circle(mask, (int(x), int(y)), 5, 0, -1)
            new = cv2.goodFeaturesToTrack(
                np.ascontiguousarray(grey[y0:y1, x0:x1]),
                _MAX_FEATURES,
                0.01,
                5,
                mask=np.ascontiguousarray(mask[y0:y1, x0:x1]),
                blockSize=5,
            )
            if new is not None:
                new = (new.reshape(-1, 1, 2) + np.array([x0, y0])).astype(np.float32)
                live += [[(float(x), float(y))] for x, y in new.reshape(-1, 2)]
                pts = new if pts is None else np.vstack([pts, new])
        prev_grey = grey
        i += 1
    for t in live:
        _finish(t, tracks)
    return i


def _finish(track: list[tuple[float, float]], out: list[FloatArray]) -> None:
    """A track long and straight enough becomes a segment (its total least-squares line
    between its first and last positions' projections)."""
    if len(track) < 4:
        return
    p = np.asarray(track, dtype=float)
    if float(np.linalg.norm(p[-1] - p[0])) < _MIN_TRACK_PX:
        return
    c = p.mean(axis=0)
    _u, s, vt = np.linalg.svd(p - c, full_matrices=False)
    rms = float(s[1]) / math.sqrt(len(p))
    if rms > _TRACK_RMS_PX:
        return
    d = vt[0]
    a, b = float((p[0] - c) @ d), float((p[-1] - c) @ d)
    out.append(np.array([[*(c + a * d), *(c + b * d)]]))


def _frame_edges(grey: Any, fg: Any, static: Any, lsd: Any) -> FloatArray:
    """Line segments of one frame on its foreground and off the background's edges."""
    import cv2

    if lsd is not None:
        found = lsd.detect(grey)[0]
        segs = np.zeros((0, 4)) if found is None else found.reshape(-1, 4).astype(float)
    else:  # builds without the LSD: Canny and the probabilistic Hough transform
        canny = cv2.bitwise_and(cv2.Canny(grey, 50, 150), fg)
        found = cv2.HoughLinesP(canny, 1, np.pi / 360, 15, minLineLength=15, maxLineGap=2)
        segs = np.zeros((0, 4)) if found is None else found.reshape(-1, 4).astype(float)
    if len(segs) == 0:
        return segs
    length = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
    segs = segs[length >= _MIN_EDGE_PX]
    if len(segs) == 0:
        return segs
    t = np.linspace(0.0, 1.0, 9)
    xs = segs[:, 0:1] + t[None, :] * (segs[:, 2:3] - segs[:, 0:1])
    ys = segs[:, 1:2] + t[None, :] * (segs[:, 3:4] - segs[:, 1:2])
    h, w = fg.shape[:2]
    xi = np.clip(xs.astype(int), 0, w - 1)
    yi = np.clip(ys.astype(int), 0, h - 1)
    on_fg = (fg[yi, xi] > 0).mean(axis=1)
    on_static = (static[yi, xi] > 0).mean(axis=1)
    keep = (on_fg >= _FG_INSIDE) & (on_static <= _STATIC_MAX)
    return np.asarray(segs[keep], dtype=float)


# --------------------------------------------------------------------------- grouping
def _lines(segs: FloatArray, scale: float, centre: FloatArray) -> FloatArray:
    """Unit homogeneous lines of segments in conditioned coordinates."""
    p = np.column_stack([(segs[:, 0:2] - centre) / scale, np.ones(len(segs))])
    q = np.column_stack([(segs[:, 2:4] - centre) / scale, np.ones(len(segs))])
    ln = np.cross(p, q)
    return np.asarray(ln / np.linalg.norm(ln, axis=1, keepdims=True), dtype=float)


def _residual_px(segs: FloatArray, vp: FloatArray) -> FloatArray:
    """Distance (px) of each segment's end from the line through its middle and ``vp``
    (homogeneous, pixels): the calibration's own segment residual."""
    mid = np.column_stack([(segs[:, 0:2] + segs[:, 2:4]) / 2.0, np.ones(len(segs))])
    ln = np.cross(mid, np.broadcast_to(vp, mid.shape))
    norm = np.hypot(ln[:, 0], ln[:, 1])
    end = np.column_stack([segs[:, 0:2], np.ones(len(segs))])
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.abs(np.sum(ln * end, axis=1)) / norm
    return np.where(norm > 1e-12, r, np.inf)


def _vanishing_point(
    segs: FloatArray, size: tuple[int, int], rng: np.random.Generator
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """RANSAC vanishing point of segments (homogeneous pixels, unit norm) and its inliers.

    The point with the most inlier length (each end within ``_INLIER_PX`` of the line from
    the segment's middle to it), refined by weighted least squares on the inliers.
    """
    n = len(segs)
    nan = np.full(3, np.nan)
    if n < 2:
        return nan, np.zeros(n, dtype=bool)
    centre = np.array([size[0] / 2.0, size[1] / 2.0])
    scale = float(max(size))
    lines = _lines(segs, scale, centre)
    length = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
    prob = length / length.sum()
    to_px = np.array([[scale, 0.0, centre[0]], [0.0, scale, centre[1]], [0.0, 0.0, 1.0]])
    best, best_score = None, -1.0
    for _ in range(_RANSAC_ITER):
        i, j = rng.choice(n, 2, replace=False, p=prob)
        v = np.cross(lines[i], lines[j])
        if not np.all(np.isfinite(v)) or np.linalg.norm(v) < 1e-12:
            continue
        v_px = to_px @ (v / np.linalg.norm(v))
        score = float(length[_residual_px(segs, v_px) <= _INLIER_PX].sum())
        if score > best_score:
            best, best_score = v_px, score
    if best is None:
        return nan, np.zeros(n, dtype=bool)
    vp = best
    for _ in range(3):
        inl = _residual_px(segs, vp) <= _INLIER_PX
        if inl.sum() < 2:
            break
        ln = lines[inl] * np.sqrt(length[inl])[:, None]
        _u, _s, vt = np.linalg.svd(ln, full_matrices=False)
        vp = to_px @ vt[-1]
    vp = vp / np.linalg.norm(vp)
    return np.asarray(vp, dtype=float), _residual_px(segs, vp) <= _INLIER_PX


def _group(
    edges: FloatArray, tracks: FloatArray, size: tuple[int, int], n_frames: int
) -> VideoLines:
    """Street, across and vertical groups of the video's tracks and edges."""
    rng = np.random.default_rng(_SEED)
    vps = np.full((3, 3), np.nan)
    segs: list[FloatArray] = []
    labels: list[IntArray] = []
    rest = edges
    if len(tracks) >= _MIN_GROUP:
        vp, inl = _vanishing_point(tracks, size, rng)
        if inl.sum() >= _MIN_GROUP:
            vps[0] = vp
            street_edges = _residual_px(rest, vp) <= _INLIER_PX if len(rest) else np.zeros(0, bool)
            segs += [tracks[inl], rest[street_edges]]
            labels += [np.zeros(int(inl.sum()) + int(street_edges.sum()), dtype=int)]
            rest = rest[~street_edges]
    if len(rest):
        angle = np.degrees(
            np.arctan2(np.abs(rest[:, 2] - rest[:, 0]), np.abs(rest[:, 3] - rest[:, 1]))
        )
        upright = angle <= _UPRIGHT_DEG
        for k, pick in ((2, upright), (1, ~upright)):
            cand = rest[pick]
            if len(cand) < _MIN_GROUP:
                continue
            vp, inl = _vanishing_point(cand, size, rng)
            if inl.sum() >= _MIN_GROUP:
                vps[k] = vp
                segs.append(cand[inl])
                labels.append(np.full(int(inl.sum()), k, dtype=int))
    all_segs = np.vstack(segs) if segs else np.zeros((0, 4))
    all_labels = np.concatenate(labels) if labels else np.zeros(0, dtype=int)
    counts = {name: int(np.sum(all_labels == k)) for k, name in enumerate(GROUPS)}
    counts["tracks"] = len(tracks)
    counts["edges"] = len(edges)
    return VideoLines(size, all_segs, all_labels, vps, n_frames, counts)
