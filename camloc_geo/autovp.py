"""Automatic vanishing points, focal length and camera tilt from one image.

This is the "CamLoc-Auto" step: when nobody has drawn lines, find the three mutually
orthogonal (Manhattan) vanishing points from the picture itself.

Pipeline
--------
1. Line segments: OpenCV's LSD (``cv2.createLineSegmentDetector``) when available, else
   Canny plus ``cv2.HoughLinesP``, on the image without uniform border bars (letterbox)
   and shrunk to at most 1024 px. Short segments are dropped, the longest 500 kept.
2. Hypotheses (RANSAC, length-weighted sampling): two segments give a first vanishing
   point; either two more segments give a second one and, through orthogonality, the
   focal length, or a third segment plus a focal-length sample give the second one.
   The third vanishing direction is the cross product of the first two. Hypotheses are
   scored by the length-weighted consensus of the segments (truncated quadratic of the
   distance of a segment's end points to the line joining its midpoint and the
   vanishing point), first on a subset, then the best tenth on the 150 longest
   segments; a mild log-normal prior on the focal length breaks near ties.
3. Refinement: ``scipy.optimize.least_squares`` (soft-L1 loss) over the rotation and the
   focal length (principal point at the image centre unless given or asked for), on the
   inliers of the three best distinct hypotheses, with relabelling; the best refined
   model wins.
4. Checks: at least two directions must each be supported by three distinct lines and
   the vanishing points must explain 20 % of the segments' length, else
   :class:`~camloc_geo.NotEnoughStructureError`. The confidence is roughly the
   probability that the focal length is within 10 %: that of the stated Gaussian sigma,
   times the chance that the Manhattan frame is the photo's (it falls with fewer than
   about 60 distinct lines), times the explained share and lines per direction; a focal
   length the image cannot fix is flagged (``focal_source`` ``"prior"`` or ``"bound"``).

5. Lens distortion (on by default): the division-model ``k1`` is fitted with the rotation
   and the focal length on the labelled segments (a long edge bowed by a wide-angle lens
   is broken by LSD into pieces that agree on one vanishing point only for the right
   ``k1``), a few rounds with relabelling; kept when it differs from 0 by more than twice
   its standard deviation. A known ``k1`` is applied instead when given. Where it is kept,
   how far it moved the focal length from the straight-lens reading (k1 = 0) joins the
   focal sigma as a model term (edges that are not straight pose as lens bowing), warned of
   above 10 % (``_K1_MOVE_TERM``).
6. Honest uncertainty: a direction supported by fewer than 6 distinct lines is left out of
   the final fit; ``focal_std_rel`` adds to the least-squares sigma how far the focal
   length moves when each direction's segments are turned by :data:`BIAS_DEG` (a
   systematic bias: residual distortion, edge detection), which is large where the
   geometry leaves the focal length loose (a level camera looking down a street), and
   how far it moves when a horizontal direction's lines on either side of the horizon are
   left out (``_split_horizon_logf_std``: paths or paving not parallel to the facades),
   and takes the larger of the least-squares sigma and a delete-one-line jackknife over
   the directions of fewer than 24 distinct lines (``_line_jackknife_logf_std``: a roof
   slope or a shadow that lines up with a vanishing point by chance). Where no focal
   length or prior is given and the photo leaves the focal length loose (sigma over
   10 %), the default prior joins (``_with_default_prior``: log-normal around the longer
   side, sigma 0.35, what cameras are), the photo's reading counted as a wrong frame's,
   which says nothing, with the frame's chance of being wrong (the confidence's model term,
   at most 0.17): a loose reading far from the default moves the answer less, and the
   stated sigma is the mixture's (``_WRONG_FRAME_MIXTURE``). An EXIF
   focal length (or any ``focal_prior_px``) is a prior in the fit. ``warnings`` say when
   the focal length is loose, the vertical is weakly supported or ambiguous.
   ``pitch_std_deg`` and ``roll_std_deg`` take the larger of the least-squares part and the
   same delete-one-line jackknife, the systematic part, the principal point's, how far the
   frame moves where a direction of few lines or either half of a direction's lines is
   left out and that move exceeds its noise (``_split_tilt_deg``), and where no line is
   vertical and a horizontal direction has fewer than 24 lines, how far pitch and roll
   move to the level reading (``_level_reading_move_deg``: what the lines cannot fix; a
   warning says what the horizon rests on).

Measured on the 102 York Urban photos (``benchmarks/vp_yud.py``, focal length not
given): focal length within 10 % on 92 % of the photos, median vanishing-direction
error 0.9 degrees against the orthogonalised ground truth, horizon AUC 95 %, about 75 ms
of CPU per 640x480 photo. On 216 real photos with published calibrations
(``benchmarks/vp_real.py``): within 10 % on 91 %, the stated focal sigma covers 76 % at
1 sigma and 96 % at 2 sigma, ROC AUC of the confidence for a focal error over 10 % 0.90.

Conventions (see ``spec/SCENE.md``): image pixels are continuous, origin at the
top-left corner, x right, y down, the centre of the top-left pixel is ``(0.5, 0.5)``;
the camera frame is x right, y down, z forward. Vanishing points are kept homogeneous
throughout (``[x, y, w]`` in pixels), so points at infinity (``w = 0``) never cause a
division by zero; in pixel form they are reported as ``None``.

The vertical vanishing point is the one of the world's up axis. It is identified as the
vanishing direction closest to the image's vertical axis, with a penalty for
interpretations in which the camera looks up steeply (see ``_vertical_cost``): street
cameras and photos are seldom rolled by more than 45 degrees, and a camera that looks
down steeply is likelier than one that looks up steeply. That prior gives way to the
lines (``_vertical_index``): a rival direction within 65 degrees of the image's vertical
axis with twice the distinct lines, tilting the camera by at most 15 degrees more, is the
vertical (a photo looking up 50 degrees at a building is otherwise read as looking down 40
degrees, resting on a few courses of a side wall), and a comparably supported rival is
named in a warning. Beyond that (looking up 60-80 degrees is the frame of looking down
30-10) the prior may keep the looking-down reading, but a rival with twice the lines that
would make the camera look up steeply is then named in a warning and the confidence is
halved (``_steep_up_rival``). Neither counts a rival that would roll the camera more than
10 degrees beyond the kept reading (``_rolls_more``): cameras rarely roll, and a street
camera's lane markings, seen at an angle, converge off the image's vertical axis, where a
facade's verticals seen looking up do not.
"""

from __future__ import annotations

import itertools
import logging
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from camloc_geo._errors import DegenerateGeometryError, InputError, NotEnoughStructureError

# Focal length bounds, as multiples of the longer image side, searched when unknown (EXIF's
# plausibility check reads the same range).
from camloc_geo._limits import FOCAL_BOUNDS_REL

__all__ = [
    "AutoVPResult",
    "detect_segments",
    "detect_vanishing_points",
    "draw_segments",
    "horizon_from_up",
    "load_image",
    "pitch_roll_from_up",
    "segments_for_axis",
]

log = logging.getLogger(__name__)

FloatArray = npt.NDArray[np.float64]

#: A vanishing direction this close (degrees) to the image plane is reported at infinity.
INFINITY_TOL_DEG = 0.05
#: Prior on the focal length (relative to the longer side): log-normal centre and sigma.
_F_PRIOR_REL = 1.0
_F_PRIOR_SIGMA = 1.0
_PP_SIGMA_REL = 0.03
#: Uncertainty of an assumed (image-centre) principal point, relative to the longer side,
#: put into the pitch sigma (York Urban's lies 2.7 % from the centre, Strecha's 0.6 %).
_PP_TILT_SIGMA_REL = 0.015
#: Uncertainty of an assumed (image-centre) principal point, relative to the longer side,
#: put into the focal length's sigma (``_pp_logf_std``): phones and compact cameras lie
#: within about 1 % of the centre, York Urban's camera 2.7 %, Strecha's 0.6 %.
_PP_FOCAL_SIGMA_REL = 0.01
#: Number of distinct best hypotheses refined; the frame kept is the best of the first
#: :data:`_N_KEPT_FROM` of them.
_N_REFINED = 6
#: The frame is chosen among this many of the refined hypotheses (as before stop 40); all
#: :data:`_N_REFINED` are modes for the rival frames (:func:`_rival_logf_std`): with 3,
#: whether a rival mode was among them hinged on RANSAC's draws, and a grey level's change
#: in the photo moved the stated sigma (issue 24: a dome photo -53 % at a stated 23 %,
#: warned, or -26 % at 7 %, its rival unseen). Choosing among all 6 moved York Urban
#: P1040822 from +17 % at 14 %, warned, to +26 % at 7.6 %, confidently wrong.
_N_KEPT_FROM = 3
#: Inlier distance (px per 800 px of image diagonal) of segment end points.
_TAU_PER_800 = 1.5
#: Final labelling: distance (in inlier distances) and angle limits.
_LABEL_TAU = 1.5
_LABEL_ANGLE_DEG = 3.0
_MIN_SEGMENTS = 6
_MIN_SUPPORT = 3  # inlier segments needed by each of the two best-supported VPs
#: Annotated axes may pick a frame whose support is at least this share of the best one.
_HINT_MIN_SCORE_SHARE = 0.8
#: Prior standard deviation of the distortion k1 when it is estimated.
_K1_PRIOR_SIGMA = 0.2
#: Rounds of the distortion estimate (each refits, relabels and undistorts again).
_K1_ROUNDS = 3
#: Where a fitted k1 is applied, how far it moves the focal length from the fit at k1 = 0
#: goes into the focal sigma (``focal_std_parts["distortion"]``): bowed edges and lens
#: bowing look alike, and on real photos the k1 fit moves the focal length far beyond the
#: sigma of k1 (benchmarks/README.md, "Stop 41: the k1 fit and the focal sigma").
_K1_MOVE_TERM = True
#: A move by k1 larger than this (|log|) is also warned of.
_K1_MOVE_WARN = 0.10
#: A direction with fewer distinct lines than this is left out of the final fit.
_WEAK_LINES = 6
#: A direction with fewer distinct lines than this (but at least ``_WEAK_LINES``) is kept,
#: but checked: where it pulls the focal length away from the other two directions by more
#: than ``_FEW_LINES_SHIFT_Z`` sigmas of that pull and ``_FEW_LINES_MIN_SHIFT`` (relative),
#: the pull goes into the focal sigma, and where the other two leave the focal length loose
#: a warning is given and the confidence halved. On real photos 8 of 43 outdoor photos
#: whose weakest direction had 6-11 lines were off by more than 10 % (a gable, a side wall
#: or a niche that is not square to the rest), against 1 of 63 with 12 or more; the pull
#: of the wrong ones was 2.7-4.7 sigmas, of right ones with such a direction at most 1.3
#: (benchmarks/vp_real.py).
_FEW_LINES = 12
_FEW_LINES_SHIFT_Z = 2.0
_FEW_LINES_MIN_SHIFT = 0.03
#: Where the focal length rests on two directions alone (the third has no line) and the
#: weaker has ``_WEAK_LINES`` to ``_FEW_LINES`` - 1 distinct lines, nothing checks that
#: direction's pull (``_FEW_LINES_SHIFT_Z``): this standard deviation of ``log(focal)``
#: goes into the sigma (its ``few_lines`` part). It is what such a direction pulls, beyond
#: its noise, where a third direction does check it: the root mean square over 97 photos
#: of York Urban, Strecha, Lund and the street photos is 0.14 (0.13 without the street
#: photos; heavy-tailed: most pull nothing, a gable or a roof slope 20-60 %). A phone
#: photo looking up at a block over palm trees (verticals and 8 lines of floors) was
#: +10.9 % at a stated 4.9 %, no warning (issue 24).
_UNCHECKED_FEW_STD = 0.13
#: A direction with fewer distinct lines than this has its lines left out one at a time
#: (a delete-one-line jackknife of the focal length, ``_line_jackknife_logf_std``).
_JACKKNIFE_LINES = 24
#: A direction of ``_WEAK_LINES`` to ``_JACKKNIFE_LINES`` distinct lines of which at least this
#: share of segments are tangent pieces of a curve (``_curve_share``) is not established
#: (``_curve_direction``).
_CURVE_SHARE = 0.45
#: A half of a direction's lines whose leaving out moves pitch or roll by more than this
#: many of its standard deviations is another family (``_split_tilt_deg``).
_SPLIT_TILT_Z = 2.0
#: Above this focal sigma the photo does not fix the focal length (a default is used).
_PRIOR_ONLY_STD = 0.25
#: Where no focal length or prior is given, the photo's estimate is combined with what
#: cameras are: log-normal, centred on :data:`_F_PRIOR_REL` times the longer side (a 35 mm
#: equivalent of about 35 mm), with this sigma of ``log(focal)`` (0.7-1.4 times at 1 sigma,
#: 0.5-2 at 2: phones' main cameras 0.72-0.75, webcams 0.5-0.9, compact and kit zooms
#: 0.55-2). Only where the photo leaves the focal length loose (its own sigma over
#: :data:`_LOOSE_FOCAL_STD`, which is warned of): a frontal facade (one finite horizontal
#: vanishing point, a vertical one far off) then gets the default, or near it, rather than
#: a random value out of a loose fit. A photo that fixes its focal length keeps its own.
_F_DEFAULT_SIGMA = 0.35
#: The default prior weighs a loose photo's own reading as a two-part likelihood
#: (``_with_default_prior``): with the chance of a wrong Manhattan frame,
#: ``(_MODEL_ERROR_LINES / distinct lines) ** 3`` (the confidence's model term, measured on
#: 216 real photos, not fitted here; capped at :data:`_WRONG_FRAME_MAX`), the reading says
#: nothing about the focal length (uniform over the searched bounds); otherwise it is
#: Gaussian with its stated
#: sigma. A loose reading far from what cameras are then moves the answer less than the
#: Gaussian blend did, and the stated sigma is the mixture's, so it covers both. Off: the
#: Gaussian blend alone (stop 41). Street photos, EXIF stripped, with the default prior
#: centred on each truth (``vp_real.py --prior-at-truth``, 146 photos): within 10 %
#: 71.2 -> 74.7 %; the plain headline 50.7 -> 52.1 %; York Urban and Strecha unchanged
#: within 10 % (18 and 24 loose photos moved by less than 2 points).
_WRONG_FRAME_MIXTURE = True
#: At most this chance of a wrong frame in that mixture: the rate measured at the low end
#: of the measured range (17 % of the photos of 40-60 distinct lines had a wrong frame;
#: ``_MODEL_ERROR_LINES``). Below 40 lines the cube is an extrapolation that reaches 1 at
#: 25, where a street camera's lane markings and kerbs may be all it has, and right: a cap
#: of 0.5 pulled such a camera at 0.78 times the longer side from +4.6 to +11 % (pitch 30
#: degrees read 27.6), this one to +6.2 % (28.6).
_WRONG_FRAME_MAX = 0.17
#: Frames wider than this (longer over shorter side) are no common sensor shape (4:3, 3:2,
#: 16:9): a band cut out of a frame (the focal length still near the longer side) or a
#: wide-angle camera whose shorter side spans what a 16:9 frame's would (the focal length
#: near :data:`_WIDE_SHORT_REL` times the shorter side). KITTI's 1242x375 frames are the
#: second kind: 0.58 times the longer side, where the default put 1.0. The default prior
#: then sits between the two readings (their geometric mean) and its sigma takes in half
#: their log-ratio (``_default_focal_prior``).
_WIDE_ASPECT = 1.9
_WIDE_SHORT_REL = 16.0 / 9.0
#: Largest focal sigma stated for an estimate that rests on a weak direction.
_MAX_STATED_STD = 1.0
#: Above this relative standard deviation of the focal length a warning is given.
_LOOSE_FOCAL_STD = 0.10
#: A focal prior read from EXIF and the photo's own well-fixed reading disagree where they
#: lie more than this many combined sigmas apart (``check_focal_prior``).
_PRIOR_CHECK_Z = 2.0
#: Systematic bias of segment directions (degrees) put into the focal length's sigma.
BIAS_DEG = 0.3
#: Two readings of the vertical whose costs (``_vertical_cost``) differ by less than this
#: are ambiguous (a warning says so).
_VERTICAL_MARGIN_DEG = 25.0
#: A direction this close (degrees) to the image's vertical axis may be the vertical ...
_VERTICAL_CANDIDATE_DEG = 65.0
#: ... and is taken when it has this many times the distinct lines of the likeliest one
#: and tilts the camera by at most this much more (degrees); a street camera looking down
#: 30 degrees at lane markings (many) and a few poles is not read as looking up 60.
_VERTICAL_SUPPORT_RATIO = 2.0
_VERTICAL_RIVAL_TILT_DEG = 15.0
#: A rival reading of the vertical that looks up by at least ``_STEEP_UP_MIN_DEG`` (and
#: tilts the camera by less than ``_STEEP_UP_MAX_DEG``) with ``_VERTICAL_SUPPORT_RATIO``
#: times the lines of the kept one (which has fewer than ``_FEW_LINES``) loses to the prior
#: only (looking up 60-80 degrees at a building is read as looking down 30-10): it is named
#: in a warning and the confidence is halved (``_steep_up_rival``).
_STEEP_UP_MIN_DEG = 45.0
_STEEP_UP_MAX_DEG = 82.0
#: A rival reading of the vertical that rolls the camera by more than this (degrees) beyond
#: the kept reading's roll is no evidence of looking up: cameras rarely roll. A street camera
#: looking down 15-40 degrees across or along a road at an angle (yaw 10-25 degrees) sees
#: its lane markings converge to a point off the image's vertical axis: read as the
#: vertical they roll it 20-70 degrees (rendered traffic frames: 50-69). A facade seen
#: looking up at an angle is the other way round: its verticals roll it 0 degrees, the
#: looking-down reading 10-28 (``_rolls_more``).
_ROLL_MARGIN_DEG = 10.0
#: Distinct lines (all directions) at which the chance of a wrong Manhattan frame is 1:
#: it falls as the cube of this over the number of lines (see ``_finish``).
_MODEL_ERROR_LINES = 25.0
#: Rival Manhattan frames: among the refined hypotheses, those whose weight (support times
#: the focal-length prior) after one round is at least this share of the kept frame's are
#: refined as far as the kept one, and their focal lengths go into the sigma, each counted
#: with the probability that it is the better supported frame (``_rival_logf_std``). On
#: the 268 real photos of benchmarks/vp_real.py: 1 / 2 sigma coverage of the focal sigma
#: 79 / 96 -> 84 / 98 %, median error/sigma 0.55 -> 0.51, confidently wrong 3 -> 2, within
#: 10 % 85.4 -> 86.9 %; driving frames held out: confidently wrong 2 of 15 -> 0. Counting
#: only what lies beyond the kept frame's own sigma: 1 / 2 sigma 84 / 98 -> 82 / 98 %.
_RIVAL_SHARE = 0.9
#: Residual noise (in inlier distances) that scales a focal-length prior's weight.
_PRIOR_NOISE_PX = 0.5


# --------------------------------------------------------------------------- images


def load_image(image: str | os.PathLike[str] | npt.NDArray[Any]) -> npt.NDArray[np.uint8]:
    """Return an 8-bit grayscale image from a path or an array.

    Parameters
    ----------
    image
        A path to an image file, or an array: ``(H, W)`` gray, ``(H, W, 3)`` BGR or
        ``(H, W, 4)`` BGRA, any numeric dtype (8- and 16-bit integers span their dtype's
        range; 32- and 64-bit integers are read as 8-bit values when they are at most 255,
        16-bit ones up to 65535, else scaled by their maximum; floats are taken in
        ``[0, 1]`` when their maximum is at most 1, else in ``[0, 255]``).
        Files are decoded by OpenCV, which applies the EXIF orientation
        (:func:`camloc_geo._io.read_image_gray`).

    Raises
    ------
    InputError
        The file cannot be read or decoded (the message names the file and why), or the
        array is not an image.
    """
    import cv2

    if isinstance(image, (str, os.PathLike)):
        from camloc_geo._io import read_image_gray

        return np.asarray(read_image_gray(image), dtype=np.uint8)
    arr = np.asarray(image)
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[:, :, 0]
    if arr.ndim not in (2, 3) or (arr.ndim == 3 and arr.shape[2] not in (3, 4)):
        raise InputError(f"image array must be (H, W), (H, W, 3) or (H, W, 4), got {arr.shape}")
    if min(arr.shape[:2]) < 8:
        raise InputError(f"image is too small: {arr.shape[1]}x{arr.shape[0]} pixels")
    if arr.dtype != np.uint8:
        if not (np.issubdtype(arr.dtype, np.number) or arr.dtype == np.bool_):
            raise InputError(f"image array must be numeric, got dtype {arr.dtype}")
        a = arr.astype(np.float64)
        if not np.all(np.isfinite(a)):
            raise InputError("image array contains NaN or infinite values")
        if arr.dtype == np.bool_:
            a = a * 255.0
        elif np.issubdtype(arr.dtype, np.integer) and arr.dtype.itemsize >= 4:
            # a wide integer array holds 8- or 16-bit values (img.astype(int), np.array(pil,
            # int)), not values spanning 2**31 or 2**63: by its dtype's range it was black
            top = float(a.max()) if a.size else 0.0
            a = a * (1.0 if top <= 255.0 else 255.0 / 65535.0 if top <= 65535.0 else 255.0 / top)
        elif np.issubdtype(arr.dtype, np.integer):
            a = a * (255.0 / float(np.iinfo(arr.dtype.str).max))  # e.g. 16-bit images
        elif a.size and a.max() <= 1.0:
            a = a * 255.0
        arr = np.clip(np.rint(a), 0, 255).astype(np.uint8)
    if arr.ndim == 3:
        code = cv2.COLOR_BGR2GRAY if arr.shape[2] == 3 else cv2.COLOR_BGRA2GRAY
        arr = cv2.cvtColor(np.ascontiguousarray(arr), code)
    return np.ascontiguousarray(arr, dtype=np.uint8)


# ------------------------------------------------------------------------- segments


def detect_segments(
    image: str | os.PathLike[str] | npt.NDArray[Any],
    *,
    min_length_px: float | None = None,
    max_segments: int = 500,
    max_side_px: int = 1024,
    method: str = "auto",
    mask: npt.NDArray[Any] | None = None,
    trim_borders: bool = True,
) -> FloatArray:
    """Detect straight line segments.

    Parameters
    ----------
    image
        Path or array (see :func:`load_image`).
    min_length_px
        Shortest segment kept, in pixels of the input image. Default: 2.5 % of the image
        diagonal, at least 12 px.
    max_segments
        Keep at most this many segments, the longest first.
    max_side_px
        Larger images are shrunk to this longer side for detection (the segments are
        scaled back to the input's pixels).
    method
        ``"auto"`` (LSD when available, else Hough), ``"lsd"`` or ``"hough"``.
    mask
        Optional ``(H, W)`` boolean array, True where segments may lie (both end points
        and the midpoint); use it to ignore time stamps, logos and other overlays.
    trim_borders
        Ignore uniform bars along the image borders (letterboxing, black frames), whose
        edges would otherwise pose as long horizontal or vertical lines.

    Returns
    -------
    numpy.ndarray
        ``(N, 4)`` rows ``x1, y1, x2, y2`` in continuous pixel coordinates (the centre of
        the top-left pixel is ``(0.5, 0.5)``), longest first. Possibly empty.
    """
    return _detect_segments(
        image,
        min_length_px=min_length_px,
        max_segments=max_segments,
        max_side_px=max_side_px,
        method=method,
        mask=mask,
        trim_borders=trim_borders,
    )[0]


def _detect_segments(
    image: str | os.PathLike[str] | npt.NDArray[Any],
    *,
    min_length_px: float | None = None,
    max_segments: int = 500,
    max_side_px: int = 1024,
    method: str = "auto",
    mask: npt.NDArray[Any] | None = None,
    trim_borders: bool = True,
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """:func:`detect_segments`, and which of the segments are pieces of a curve
    (:func:`_curve_pieces`, looked for among all the detector's pieces, short ones
    included)."""
    import cv2

    gray = load_image(image)
    full_h, full_w = gray.shape
    if mask is not None:
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != gray.shape:
            raise InputError(f"mask shape {mask.shape} differs from the image's {gray.shape}")
    x0, y0, x1, y1 = _content_box(gray) if trim_borders else (0, 0, full_w, full_h)
    gray = np.ascontiguousarray(gray[y0:y1, x0:x1])
    h, w = gray.shape
    scale = 1.0
    if max(h, w) > max_side_px:
        scale = max_side_px / max(h, w)
        small = cv2.resize(gray, (round(w * scale), round(h * scale)), interpolation=cv2.INTER_AREA)
        gray = np.asarray(small, dtype=np.uint8)
    if min_length_px is None:
        min_length_px = max(12.0, 0.025 * math.hypot(full_w, full_h))
    segs = np.zeros((0, 4))
    if method not in ("auto", "lsd", "hough"):
        raise InputError(f"method must be 'auto', 'lsd' or 'hough', got {method!r}")
    lsd_failed = False
    if method in ("auto", "lsd"):
        try:
            lsd = cv2.createLineSegmentDetector(cv2.LSD_REFINE_STD)
            lsd_out = lsd.detect(gray)[0]
            if lsd_out is not None:
                segs = np.asarray(lsd_out, dtype=np.float64).reshape(-1, 4)
        except (cv2.error, AttributeError) as exc:  # LSD missing from some builds
            if method == "lsd":
                raise
            log.debug("LSD unavailable (%s); using Canny + HoughLinesP", exc)
            lsd_failed = True
    if method == "hough" or lsd_failed:
        edges = cv2.Canny(gray, 50, 150, L2gradient=True)
        hough_out = cv2.HoughLinesP(
            edges,
            1,
            np.pi / 360,
            threshold=30,
            minLineLength=max(4.0, min_length_px * scale),
            maxLineGap=3,
        )
        if hough_out is not None:
            segs = np.asarray(hough_out, dtype=np.float64).reshape(-1, 4)
    # OpenCV's segment end points are in pixel-index coordinates (centre of the
    # top-left pixel at 0, 0): shift to the continuous convention, then undo the shrink.
    segs = (segs + 0.5) / scale + np.array([x0, y0, x0, y0], dtype=np.float64)
    if len(segs) == 0:
        return np.zeros((0, 4)), np.zeros(0, dtype=bool)
    if trim_borders:
        segs = segs[~_along_border(segs, (x0, y0, x1, y1), _BORDER_EDGE_PX / scale)]
    curve = _curve_pieces(segs, _CURVE_NOISE_PX / scale, _CURVE_GAP_PX / scale)
    if mask is not None:
        pts = [segs[:, 0:2], segs[:, 2:4], 0.5 * (segs[:, 0:2] + segs[:, 2:4])]
        inside = np.ones(len(segs), dtype=bool)
        for p in pts:
            ix = np.clip(np.floor(p[:, 0]).astype(np.int64), 0, full_w - 1)
            iy = np.clip(np.floor(p[:, 1]).astype(np.int64), 0, full_h - 1)
            inside &= mask[iy, ix]
        segs, curve = segs[inside], curve[inside]
    lengths = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
    keep = lengths >= min_length_px
    segs, lengths, curve = segs[keep], lengths[keep], curve[keep]
    order = np.argsort(-lengths, kind="stable")[:max_segments]
    return np.ascontiguousarray(segs[order]), np.ascontiguousarray(curve[order])


#: Segments whose two end points lie this close (pixels of the detection image) to the
#: same side of the image are the frame's own edge: a dark or bright first row or column
#: that a video codec or a sensor leaves (seen on dash-camera frames), not a scene line.
_BORDER_EDGE_PX = 2.5


def _along_border(
    segs: FloatArray, box: tuple[int, int, int, int], edge_px: float
) -> npt.NDArray[np.bool_]:
    """Whether each segment runs along a side of ``box`` (``x0, y0, x1, y1``).

    Parameters
    ----------
    segs
        ``(N, 4)`` rows ``x1, y1, x2, y2``, pixels.
    box
        The image (or its content without uniform bars), ``x0, y0, x1, y1`` in pixels.
    edge_px
        Both end points within this distance of the same side.

    Returns
    -------
    numpy.ndarray
        ``(N,)`` booleans.
    """
    x0, y0, x1, y1 = box
    xs, ys = segs[:, [0, 2]], segs[:, [1, 3]]
    return (
        np.all(xs - x0 <= edge_px, axis=1)
        | np.all(x1 - xs <= edge_px, axis=1)
        | np.all(ys - y0 <= edge_px, axis=1)
        | np.all(y1 - ys <= edge_px, axis=1)
    )


#: Pieces of curves (:func:`_curve_pieces`): a detected segment continued at both of its
#: ends by another piece of the detector, each turned the same way (a convex outline) by
#: at least twice the turn's noise and :data:`_CURVE_TURN_DEG`\\ [0] degrees, at most
#: :data:`_CURVE_TURN_DEG`\\ [1], is a chord of a curve; so are the pieces that continue
#: it bending its way (the curve's flatter stretch and its ends). End point scatter of a
#: piece across its line (pixels of the detection image), and the largest gap between two
#: pieces' ends.
_CURVE_NOISE_PX = 0.25
#: What :func:`detect_vanishing_points` does with the chords of curves it detects:
#: ``"refit"`` (read the photo again without them where a direction leans on them,
#: :func:`_curve_directions`), ``"drop"`` (always leave them out: moves many photos by
#: chance, as any change of the segments moves RANSAC) or ``"keep"`` (before stop 39).
_CURVE_MODE = "refit"
#: A direction with at least this many chords of curves among its segments, making at
#: least this share of them, leans on curves (:func:`_curve_directions`).
_CURVE_MIN_CHORDS = 3
_CURVE_CHORD_SHARE = 0.15
_CURVE_GAP_PX = 6.0
_CURVE_TURN_DEG = (1.5, 25.0)
#: Pieces shorter than this (pixels of the detection image) are too noisy to be links.
_CURVE_MIN_PIECE_PX = 6.0
#: How many pieces a curve is followed beyond its chords, each way.
_CURVE_FOLLOW = 8
#: Segments at least this long (detection pixels), and at least this many, measure a
#: photo's line scatter (:func:`_line_scatter_deg`).
_SCATTER_MIN_PX = 60.0
_SCATTER_MIN_N = 8


def _curve_pieces(segs: FloatArray, noise_px: float, gap_px: float) -> npt.NDArray[np.bool_]:
    """Which segments are chords of a curved outline (a ring, a dome, a basin's rim).

    A line detector cuts a curve into straight pieces; near where the curve runs along a
    vanishing direction its pieces point at that vanishing point and pose as lines of it
    (the rings of a rotunda as both horizontal directions: a confidently wrong focal
    length). A straight edge cut into pieces continues straight; a corner turns by more
    than :data:`_CURVE_TURN_DEG`\\ [1]. So a piece continued end to end at *both* its ends,
    turned the same way at each by a few degrees (see :data:`_CURVE_TURN_DEG`), is a
    chord of a curve. The curve is then followed piece by piece (up to
    :data:`_CURVE_FOLLOW` each way) while each next piece turns its way, however little:
    the flat front of a ring seen from below, where the turns are under their noise, and
    the curve's ends.

    Parameters
    ----------
    segs
        ``(N, 4)`` segments ``x1, y1, x2, y2`` (all the detector's pieces).
    noise_px
        Scatter of the end points across a piece's line, in the same pixels.
    gap_px
        Largest distance between two pieces' ends that still continue each other.

    Returns
    -------
    numpy.ndarray
        ``(N,)`` booleans, True for the chords of a curve.
    """
    from scipy.spatial import cKDTree

    n = len(segs)
    out = np.zeros(n, dtype=bool)
    if n < 3:
        return out
    p = np.asarray(segs, dtype=np.float64).reshape(n, 2, 2)
    d = p[:, 1] - p[:, 0]
    length = np.hypot(d[:, 0], d[:, 1])
    u = d / np.where(length > 0, length, 1.0)[:, None]
    ends = np.concatenate([p[:, 0], p[:, 1]])  # row k: segment k % n, its end k // n
    pairs = cKDTree(ends).query_pairs(gap_px, output_type="ndarray")
    if len(pairs) == 0:
        return out
    a, b = pairs[:, 0], pairs[:, 1]
    si, sj, ei, ej = a % n, b % n, a // n, b // n
    ok = (si != sj) & (length[si] >= _CURVE_MIN_PIECE_PX) & (length[sj] >= _CURVE_MIN_PIECE_PX)
    a, b, si, sj, ei, ej = a[ok], b[ok], si[ok], sj[ok], ei[ok], ej[ok]
    # walking out of i through end a, then along j away from end b
    out_i = np.where((ei == 1)[:, None], u[si], -u[si])
    along_j = np.where((ej == 0)[:, None], u[sj], -u[sj])
    turn = np.arctan2(
        out_i[:, 0] * along_j[:, 1] - out_i[:, 1] * along_j[:, 0], np.sum(out_i * along_j, axis=1)
    )
    gap = np.hypot(*(ends[a] - ends[b]).T)
    # end to end, not overlapping or side by side: the far ends lie further apart than
    # either piece is long, and j starts on i's line (up to the turn over the gap)
    far = np.hypot(*(ends[(a + n) % (2 * n)] - ends[(b + n) % (2 * n)]).T)
    step = ends[b] - ends[a]
    lateral = np.abs(out_i[:, 0] * step[:, 1] - out_i[:, 1] * step[:, 0])
    sigma = math.sqrt(2.0) * noise_px * np.hypot(1.0 / length[si], 1.0 / length[sj])
    lo = np.maximum(math.radians(_CURVE_TURN_DEG[0]), 2.0 * sigma)
    ok = (
        (np.abs(turn) >= lo)
        & (np.abs(turn) <= math.radians(_CURVE_TURN_DEG[1]))
        & (far > np.maximum(length[si], length[sj]))
        & (lateral <= 4.0 * noise_px + gap * np.abs(np.sin(turn)))
    )
    cont = (
        (np.abs(turn) <= math.radians(_CURVE_TURN_DEG[1]))
        & (far > np.maximum(length[si], length[sj]))
        & (lateral <= 4.0 * noise_px + gap * np.abs(np.sin(turn)))
    )
    # the sense of the bend in each piece's own forward direction: walking forward out of
    # end 1 it is the turn's; walking backward out of end 0, a curve bending the same way
    # turns the other way round
    sense_i = np.where(ei == 1, 1.0, -1.0) * np.sign(turn)
    sense_j = np.where(ej == 1, -1.0, 1.0) * np.sign(turn)
    # the nearest continuation at each end decides that end
    bent = np.zeros((n, 2))  # sense of a significant bend at end 0 and end 1, else 0
    sense = np.zeros((n, 2))  # sense of the turn into the continuation, however small
    nbr = np.full((n, 2), -1, dtype=np.int64)
    nbr_end = np.zeros((n, 2), dtype=np.int64)
    for k in np.argsort(gap, kind="stable"):
        if not cont[k]:
            continue
        for s_, e_, sn, other, other_e in (
            (si[k], ei[k], sense_i[k], sj[k], ej[k]),
            (sj[k], ej[k], sense_j[k], si[k], ei[k]),
        ):
            if nbr[s_, e_] >= 0:
                continue
            nbr[s_, e_], nbr_end[s_, e_], sense[s_, e_] = other, other_e, sn
            if ok[k]:
                bent[s_, e_] = sn
    out = (bent[:, 0] != 0) & (bent[:, 0] == bent[:, 1])
    curl = np.where(out, bent[:, 1], 0.0)  # each chord's sense of bending
    # follow each curve beyond its chords: a piece continuing a chord where the chord bends
    # its way, and bending the same way into the chord, belongs to the curve (its flatter
    # stretch, where the turns are under their noise, and its ends)
    frontier = np.flatnonzero(out)
    for _ in range(_CURVE_FOLLOW):
        nxt = []
        for i in frontier:
            for e_ in range(2):
                j = nbr[i, e_]
                if j < 0 or out[j] or sense[i, e_] != curl[i]:
                    continue
                ej_ = nbr_end[i, e_]
                if nbr[j, ej_] != i:
                    continue
                # (the same turn, seen from j: its sense of bending in its own direction)
                out[j], curl[j] = True, sense[j, ej_]
                nxt.append(j)
        if not nxt:
            break
        frontier = np.array(nxt)
    return out


#: Overhead wires (:func:`_sky_wires`): a thin line is a dark ridge of the grey levels at
#: most about ``2 * _WIRE_CORE_PX`` wide (pixels of the detection image), its two sides
#: (sampled :data:`_WIRE_SIDE_PX` away) alike: it is darker than their mean by more than
#: :data:`_WIRE_CONTRAST` grey levels and by more than :data:`_WIRE_SIDE_RATIO` times
#: their difference, on at least :data:`_WIRE_SAMPLE_SHARE` of
#: :data:`_WIRE_SAMPLES` places along it.
_WIRE_CORE_PX = 2.0
_WIRE_SIDE_PX = (3.5, 5.5)
_WIRE_CONTRAST = 8.0
_WIRE_SIDE_RATIO = 1.5
_WIRE_SAMPLE_SHARE = 0.6
_WIRE_SAMPLES = 24
#: The skyline at a place is the top of the vertical direction's inliers within this share
#: of the image width; a wire runs above it, by this share of the image height or more
#: (a line at the foot of a short post is not in the sky), at this many places along it,
#: this share of them (:func:`_sky_wires`).
_WIRE_SKYLINE_MARGIN = 0.05
_WIRE_POINTS = 8
_WIRE_SKY_SHARE = 0.75
_WIRE_CLEARANCE = 0.03
_WIRE_STEP_MARGIN = 0.015
#: A horizontal direction with at least this many wires among its segments, making at
#: least this share of them, leans on wires (:func:`_wire_directions`).
_WIRE_MIN_LINES = 3
_WIRE_SHARE = 1.0 / 3.0


def _thin_lines(gray: npt.NDArray[np.uint8], segs_px: FloatArray) -> npt.NDArray[np.bool_]:
    """Which segments are thin dark lines: a dark ridge of the grey levels with like sides.

    A wire or a cable against the sky is a dark line a few pixels wide with sky on both
    sides; a building's edge is a step (its sides differ). Sampled across each segment at
    :data:`_WIRE_SAMPLES` places along it (see :data:`_WIRE_CORE_PX`).

    Parameters
    ----------
    gray
        The photo, grey levels, full size.
    segs_px
        ``(N, 4)`` segments in the photo's pixels (continuous convention).

    Returns
    -------
    numpy.ndarray
        ``(N,)`` booleans.
    """
    import cv2

    n = len(segs_px)
    if n == 0:
        return np.zeros(0, dtype=bool)
    h, w = gray.shape
    px_per_det = max(1.0, max(h, w) / 1024.0)  # detect_segments works at most 1024 px wide
    t = np.linspace(0.1, 0.9, _WIRE_SAMPLES)
    side = np.linspace(_WIRE_SIDE_PX[0], _WIRE_SIDE_PX[1], 3)
    core = np.linspace(-_WIRE_CORE_PX, _WIRE_CORE_PX, 5)
    offs_px = np.r_[-side[::-1], core, side] * px_per_det
    d = segs_px[:, 2:4] - segs_px[:, 0:2]
    u = d / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)[:, None]
    nrm = np.stack([-u[:, 1], u[:, 0]], axis=1)
    mid = segs_px[:, None, 0:2] + t[None, :, None] * d[:, None, :]  # (N, T, 2)
    # continuous pixel coordinates -> OpenCV's (pixel centres at integers)
    map_x = mid[:, :, None, 0] + offs_px[None, None, :] * nrm[:, None, None, 0] - 0.5
    map_y = mid[:, :, None, 1] + offs_px[None, None, :] * nrm[:, None, None, 1] - 0.5
    v = cv2.remap(
        np.ascontiguousarray(gray, dtype=np.float32),
        map_x.reshape(n, -1).astype(np.float32),
        map_y.reshape(n, -1).astype(np.float32),
        cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_REPLICATE,
    ).reshape(n, len(t), len(offs_px))
    side_a = v[:, :, 0:3].mean(axis=2)
    side_b = v[:, :, 8:11].mean(axis=2)
    centre = v[:, :, 3:8]
    mean_side = 0.5 * (side_a + side_b)
    ridge = mean_side - centre.min(axis=2)  # dark on its sides
    ok = (ridge > _WIRE_CONTRAST) & (ridge > _WIRE_SIDE_RATIO * np.abs(side_a - side_b))
    return np.asarray(np.mean(ok, axis=1) >= _WIRE_SAMPLE_SHARE)


def _sky_wires(
    segs_px: FloatArray,
    thin: npt.NDArray[np.bool_],
    labels: npt.NDArray[np.int64],
    kv: int,
    image_size: tuple[float, float],
    merge_px: float,
) -> npt.NDArray[np.bool_]:
    """Which segments are overhead wires: thin lines (:func:`_thin_lines`) not labelled
    vertical that run above the skyline, the top of the vertical lines below them, and the
    thin lines on the same image line (:func:`_line_groups`: the wire's pieces in front of
    a facade).

    Wires and cables hang over streets; they are nearly straight, nearly horizontal and
    long, so a line detector finds them and a vanishing-point fit may take them for a
    principal direction of the street (the catenary's sag also poses as lens distortion).
    At :data:`_WIRE_POINTS` places along a segment, the skyline is the topmost end of the
    vertical direction's inliers within :data:`_WIRE_SKYLINE_MARGIN` of the image width;
    the segment is a wire where at least :data:`_WIRE_SKY_SHARE` of the places lie above
    it by :data:`_WIRE_CLEARANCE` of the image height or more and no edge but thin or
    vertical lines lies above it within that margin (a place with no vertical line near it
    is not counted as sky). Shortcut: "above" is
    along the image's y axis (handheld roll is a few degrees); without a vertical line
    nothing is a wire.
    """
    width_px, height_px = image_size
    out = np.zeros(len(segs_px), dtype=bool)
    vert = segs_px[labels == kv]
    if len(vert) == 0:
        return out
    vx = 0.5 * (vert[:, 0] + vert[:, 2])
    vtop = np.minimum(vert[:, 1], vert[:, 3])
    margin = _WIRE_SKYLINE_MARGIN * width_px
    clear_px = _WIRE_CLEARANCE * height_px
    step_margin = _WIRE_STEP_MARGIN * width_px
    t = np.linspace(0.0, 1.0, _WIRE_POINTS)
    # points of the edges that are neither thin lines nor vertical (steps: a roof line, a
    # lamp, a cornice; the vertical ones are the skyline's)
    steps = segs_px[~thin & (labels != kv)]
    step_x = (steps[:, None, 0] + t[None, :] * (steps[:, None, 2] - steps[:, None, 0])).ravel()
    step_y = (steps[:, None, 1] + t[None, :] * (steps[:, None, 3] - steps[:, None, 1])).ravel()
    for i in np.flatnonzero(thin & (labels != kv)):
        x0, y0, x1, y1 = segs_px[i]
        xs, ys = x0 + t * (x1 - x0), y0 + t * (y1 - y0)
        near = np.abs(vx[None, :] - xs[:, None]) <= margin  # (points, verticals)
        top = np.where(near, vtop[None, :], np.inf).min(axis=1)
        # nothing but thin lines above it: the sky (a ceiling has its lamps, a facade its
        # top)
        near_step = np.abs(step_x[None, :] - xs[:, None]) <= step_margin
        open_above = ~np.any(near_step & (step_y[None, :] < ys[:, None]), axis=1)
        sky = np.isfinite(top) & (ys < top - clear_px) & open_above
        out[i] = np.count_nonzero(sky) >= _WIRE_SKY_SHARE * len(t)
    if np.any(out):
        cand = np.flatnonzero(thin & (labels != kv))
        groups = _line_groups(segs_px[cand], merge_px)
        out[cand] = np.isin(groups, groups[out[cand]])
    return out


def _wire_directions(
    segs_px: FloatArray,
    labels: npt.NDArray[np.int64],
    wires: npt.NDArray[np.bool_],
    merge_px: float,
) -> list[int]:
    """The directions that lean on overhead wires (:func:`_sky_wires`): at least
    :data:`_WIRE_MIN_LINES` distinct lines (:func:`_n_distinct_lines`) of their segments
    are wires, making at least :data:`_WIRE_SHARE` of their segments."""
    out = []
    for k in range(3):
        sel = labels == k
        n_wire = int(np.count_nonzero(wires & sel))
        n_wire_lines = _n_distinct_lines(segs_px[wires & sel], merge_px) if n_wire else 0
        if n_wire_lines >= _WIRE_MIN_LINES and n_wire >= _WIRE_SHARE * np.count_nonzero(sel):
            out.append(k)
    return out


def _curve_directions(labels: npt.NDArray[np.int64], chords: npt.NDArray[np.bool_]) -> list[int]:
    """The directions (0..2) that lean on chords of curves: at least
    :data:`_CURVE_MIN_CHORDS` of their segments, and :data:`_CURVE_CHORD_SHARE` of them, are
    chords (:func:`_curve_pieces`)."""
    out = []
    for k in range(3):
        sel = labels == k
        n_chords = int(np.count_nonzero(chords & sel))
        if n_chords >= _CURVE_MIN_CHORDS and n_chords >= _CURVE_CHORD_SHARE * np.count_nonzero(sel):
            out.append(k)
    return out


def _line_scatter_deg(res_px: FloatArray, length_px: FloatArray) -> float:
    """How far the long inliers turn about their vanishing points beyond their noise.

    ``res_px`` are the end points' distances to the line through the midpoint and the
    vanishing point, ``length_px`` the segments' lengths (detection pixels); a segment's
    turn is ``res / (L / 2)``, its noise ``_CURVE_NOISE_PX / (L / 2)``. Root mean square
    of the excess over segments at least :data:`_SCATTER_MIN_PX` long, in degrees (NaN
    with fewer than :data:`_SCATTER_MIN_N`).
    """
    long_ = length_px >= _SCATTER_MIN_PX
    if np.count_nonzero(long_) < _SCATTER_MIN_N:
        return float("nan")
    half = 0.5 * length_px[long_]
    turn2 = (res_px[long_] / half) ** 2 - (_CURVE_NOISE_PX / half) ** 2
    return float(np.degrees(math.sqrt(max(0.0, float(np.mean(turn2))))))


def _content_box(gray: npt.NDArray[np.uint8], tol: float = 3.0) -> tuple[int, int, int, int]:
    """``x0, y0, x1, y1`` of the image without uniform bars along its borders."""
    h, w = gray.shape
    g = gray.astype(np.float32)
    flat_rows = g.std(axis=1) < tol
    flat_cols = g.std(axis=0) < tol

    def run(flags: npt.NDArray[np.bool_]) -> int:
        idx = np.flatnonzero(~flags)
        return int(idx[0]) if len(idx) else len(flags)

    y0, y1 = run(flat_rows), h - run(flat_rows[::-1])
    x0, x1 = run(flat_cols), w - run(flat_cols[::-1])
    if y1 - y0 < 8 or x1 - x0 < 8:
        return 0, 0, w, h
    return x0, y0, x1, y1


# ------------------------------------------------------------------------ geometry


def _unit(v: FloatArray, axis: int = -1) -> FloatArray:
    n = np.linalg.norm(v, axis=axis, keepdims=True)
    return np.asarray(v / np.where(n > 0, n, 1.0), dtype=np.float64)


@dataclass
class _Segs:
    """Segments in normalised image coordinates: ``(pixel - pp) / scale``."""

    mid: FloatArray  # (N, 2)
    dirn: FloatArray  # (N, 2) unit
    length_px: FloatArray  # (N,)
    lines: FloatArray  # (N, 3) homogeneous lines, unit normal
    weight: FloatArray  # (N,)


def _prepare(segs_px: FloatArray, pp: FloatArray, scale: float) -> _Segs:
    p1 = (segs_px[:, 0:2] - pp) / scale
    p2 = (segs_px[:, 2:4] - pp) / scale
    d = p2 - p1
    length = np.hypot(d[:, 0], d[:, 1])
    dirn = d / length[:, None]
    ones = np.ones((len(p1), 1))
    lines = np.cross(np.hstack([p1, ones]), np.hstack([p2, ones]))
    lines = lines / np.hypot(lines[:, 0], lines[:, 1])[:, None]
    return _Segs(
        mid=0.5 * (p1 + p2),
        dirn=dirn,
        length_px=length * scale,
        lines=lines,
        weight=length * scale,
    )


def _endpoint_residual(vps: FloatArray, s: _Segs) -> FloatArray:
    """Distance in pixels of a segment's end points to the line (midpoint, VP).

    ``vps`` is ``(..., 3)`` homogeneous in normalised coordinates; the result broadcasts
    to ``(..., N)``. Signed; well defined for VPs at infinity.
    """
    vx = vps[..., 0:1]
    vy = vps[..., 1:2]
    vw = vps[..., 2:3]
    dx = vx - vw * s.mid[:, 0]
    dy = vy - vw * s.mid[:, 1]
    cross = s.dirn[:, 0] * dy - s.dirn[:, 1] * dx
    norm = np.sqrt(dx * dx + dy * dy) + 1e-12
    return np.asarray(0.5 * s.length_px * cross / norm, dtype=np.float64)


def _vps_from_rotation(R: FloatArray, f_n: float) -> FloatArray:
    """Rows: homogeneous VPs (normalised coords) of the columns of ``R``."""
    K = np.diag([f_n, f_n, 1.0])
    return np.asarray((K @ R).T, dtype=np.float64)


# ---------------------------------------------------------------------- hypotheses


def _hypotheses(
    s: _Segs,
    rng: np.random.Generator,
    n_hyp: int,
    f_fixed: float | None,
    f_bounds: tuple[float, float],
) -> tuple[FloatArray, FloatArray]:
    """Random Manhattan hypotheses: ``(H, 3, 3)`` camera directions (rows) and ``(H,)`` focal."""
    n = len(s.mid)
    p = s.weight / s.weight.sum()
    dirs_all: list[FloatArray] = []
    f_all: list[FloatArray] = []
    lo, hi = f_bounds
    if f_fixed is None:
        # Type A: two VPs from four segments; orthogonality gives the focal length.
        m = 4 * n_hyp
        idx = rng.choice(n, size=(m, 4), p=p)
        v1 = np.cross(s.lines[idx[:, 0]], s.lines[idx[:, 1]])
        v2 = np.cross(s.lines[idx[:, 2]], s.lines[idx[:, 3]])
        den = v1[:, 2] * v2[:, 2]
        num = -(v1[:, 0] * v2[:, 0] + v1[:, 1] * v2[:, 1])
        ok = np.abs(den) > 1e-12 * (np.linalg.norm(v1, axis=1) * np.linalg.norm(v2, axis=1))
        f2 = np.full(m, -1.0)
        f2[ok] = num[ok] / den[ok]
        ok &= (f2 > lo * lo) & (f2 < hi * hi)
        ok &= (idx[:, 0] != idx[:, 1]) & (idx[:, 2] != idx[:, 3])
        sel = np.flatnonzero(ok)[: n_hyp // 2 + 1]
        if len(sel):
            fa = np.sqrt(f2[sel])
            d1 = _unit(np.column_stack([v1[sel, 0] / fa, v1[sel, 1] / fa, v1[sel, 2]]))
            d2 = _unit(np.column_stack([v2[sel, 0] / fa, v2[sel, 1] / fa, v2[sel, 2]]))
            d2 = _unit(d2 - np.sum(d1 * d2, axis=1, keepdims=True) * d1)
            dirs_all.append(np.stack([d1, d2, np.cross(d1, d2)], axis=1))
            f_all.append(fa)
        n_b = n_hyp - sum(len(x) for x in f_all)
    else:
        n_b = n_hyp
    # Type B: one VP from two segments, a third segment and a focal length give the rest.
    idx = rng.choice(n, size=(n_b, 3), p=p)
    if f_fixed is None:
        fb = np.exp(rng.uniform(math.log(lo), math.log(hi), size=n_b))
    else:
        fb = np.full(n_b, f_fixed)
    v1 = np.cross(s.lines[idx[:, 0]], s.lines[idx[:, 1]])
    d1 = _unit(np.column_stack([v1[:, 0] / fb, v1[:, 1] / fb, v1[:, 2]]))
    l3 = s.lines[idx[:, 2]]
    n3 = _unit(np.column_stack([l3[:, 0] * fb, l3[:, 1] * fb, l3[:, 2]]))  # K^T l
    d2 = np.cross(n3, d1)
    nd2 = np.linalg.norm(d2, axis=1)
    good = (nd2 > 1e-6) & (idx[:, 0] != idx[:, 1]) & (np.linalg.norm(v1, axis=1) > 1e-12)
    d1, d2, fb = d1[good], _unit(d2[good]), fb[good]
    dirs_all.append(np.stack([d1, d2, np.cross(d1, d2)], axis=1))
    f_all.append(fb)
    return np.concatenate(dirs_all), np.concatenate(f_all)


def _score(dirs: FloatArray, f_n: FloatArray, s: _Segs, tau_px: float) -> FloatArray:
    """Length-weighted truncated-quadratic consensus of hypotheses, ``(H,)``.

    Computed in float32: it only ranks hypotheses.
    """
    f32 = np.float32
    vps = dirs.astype(f32)
    vps[..., 0] *= f_n[:, None].astype(f32)
    vps[..., 1] *= f_n[:, None].astype(f32)
    mx, my = s.mid[:, 0].astype(f32), s.mid[:, 1].astype(f32)
    ux, uy = s.dirn[:, 0].astype(f32), s.dirn[:, 1].astype(f32)
    hl2 = ((0.5 * s.length_px / tau_px) ** 2).astype(f32)
    vx, vy, vw = vps[..., 0:1], vps[..., 1:2], vps[..., 2:3]
    dx = vx - vw * mx
    dy = vy - vw * my
    cross = ux * dy - uy * dx
    cost = np.square(cross)
    cost *= hl2
    cost /= dx * dx + dy * dy + f32(1e-12)
    best = np.maximum(f32(0.0), f32(1.0) - cost.min(axis=1))
    return np.asarray(best @ s.weight.astype(f32), dtype=np.float64)


def _subset(s: _Segs, idx: Any) -> _Segs:
    return _Segs(s.mid[idx], s.dirn[idx], s.length_px[idx], s.lines[idx], s.weight[idx])


# --------------------------------------------------------------------- refinement


@dataclass
class _Model:
    R: FloatArray  # columns = unit vanishing directions in the camera frame
    f_n: float
    labels: npt.NDArray[np.int64]
    score: float
    logf_std: float = float("nan")
    tilt_sys_deg: tuple[float, float] = (0.0, 0.0)
    # delete-one-line jackknife of pitch and roll (degrees) over thinly supported directions
    tilt_jack_deg: tuple[float, float] = (0.0, 0.0)
    # what the lines cannot fix (degrees): how far pitch and roll move to the level reading
    # where the vertical has no lines and the horizon rests on a thin horizontal direction
    tilt_consider_deg: tuple[float, float] = (0.0, 0.0)
    horizon_rests_on: int = 0  # lines of that thin direction (a warning)
    # how far pitch and roll move (degrees) when either half of a direction's lines is left
    # out, where the halves disagree beyond their noise (two families taken for one)
    tilt_split_deg: tuple[float, float] = (0.0, 0.0)
    # spread of pitch and roll (degrees) over the rival frames (``_rival_logf_std``)
    tilt_rival_deg: tuple[float, float] = (0.0, 0.0)
    weak_only: int = 0  # the focal length rests on a direction with this few lines
    # the focal length rests on a direction with this few lines (at least _WEAK_LINES, fewer
    # than _FEW_LINES) that pulls it away from the other two directions (a warning)
    rests_on_few: int = 0
    few_shift: float = 0.0  # |log| pull of the focal length by such a direction (in sigma)
    # the focal length rests on two directions alone, the weaker of this few lines (at least
    # _WEAK_LINES, fewer than _FEW_LINES), which no third direction checks (a warning)
    unchecked_few: int = 0
    # a third horizontal direction whose pairing with one of the frame's gives another focal
    # length, clearly (``_third_horizontal``), and the nearest such move of log(focal)
    third: Any = None
    third_move: float = 0.0
    # the focal length rests on a direction of this many lines, tangent pieces of curves
    # (``_curve_direction``: a warning)
    thin_only: int = 0
    n_lines: tuple[int, int, int] | None = None  # distinct lines of each column of R
    # the photo's own estimate (normalised) and sigma of log(focal), before the default prior
    f_data_n: float = float("nan")
    data_logf_std: float = float("nan")
    # the terms of the focal sigma (``log(focal)``), by name: see AutoVPResult.focal_std_parts
    sigma_parts: dict[str, float] = field(default_factory=dict)
    residual_rms_px: float = float("nan")  # inliers' end-point residual (detection pixels)
    scatter_deg: float = float("nan")  # long inliers' turn about their VPs beyond noise


def _label_scores(
    R: FloatArray, f_n: float, s: _Segs, tau_px: float, max_angle_deg: float
) -> tuple[npt.NDArray[np.int64], FloatArray]:
    """The vanishing direction each segment is an inlier of (``-1``: none) and what it
    adds to the frame's score (its length, less as it lies off: 0 for an outlier)."""
    vps = _vps_from_rotation(R, f_n)
    r = np.abs(_endpoint_residual(vps, s))  # (3, N)
    sin_a = r / (0.5 * s.length_px)
    k = r.argmin(axis=0)
    rk = r[k, np.arange(r.shape[1])]
    ok = (rk < tau_px) & (sin_a[k, np.arange(r.shape[1])] < math.sin(math.radians(max_angle_deg)))
    labels = np.where(ok, k, -1).astype(np.int64)
    return labels, np.maximum(0.0, 1.0 - (rk / tau_px) ** 2) * s.weight * ok


def _labels(
    R: FloatArray, f_n: float, s: _Segs, tau_px: float, max_angle_deg: float
) -> tuple[npt.NDArray[np.int64], float]:
    labels, scores = _label_scores(R, f_n, s, tau_px, max_angle_deg)
    return labels, float(np.sum(scores))


def _refine(
    R0: FloatArray,
    f0: float,
    s: _Segs,
    labels: npt.NDArray[np.int64],
    tau_px: float,
    f_free: bool,
    f_prior: float,
    f_bounds: tuple[float, float],
    pp_sigma: float | None = None,
    prior_w: float | None = None,
    max_nfev: int = 40,
    info: dict[str, Any] | None = None,
) -> tuple[FloatArray, float, float, FloatArray]:
    inl = labels >= 0
    ss = _Segs(
        mid=s.mid[inl],
        dirn=s.dirn[inl],
        length_px=s.length_px[inl],
        lines=s.lines[inl],
        weight=s.weight[inl],
    )
    lab = labels[inl]
    cols = np.arange(len(lab))
    n_par = 3 + int(f_free) + (2 if pp_sigma else 0)
    lo, hi = f_bounds
    i_pp = 3 + int(f_free)
    step = 1e-7
    w_prior = 0.05 * tau_px if prior_w is None else prior_w

    def batch(X: FloatArray) -> FloatArray:
        """Residuals ``(k, M)`` for ``k`` parameter vectors."""
        Rs = Rotation.from_rotvec(X[:, :3]).as_matrix() @ R0  # (k, 3, 3)
        fk = np.clip(f0 * np.exp(X[:, 3]), lo, hi) if f_free else np.full(len(X), f0)
        vps = np.swapaxes(Rs, 1, 2).copy()  # rows = directions
        vps[..., 0] *= fk[:, None]
        vps[..., 1] *= fk[:, None]
        if pp_sigma:
            # principal point shifted by delta (normalised): VPs move by delta * w
            vps[..., 0] += X[:, i_pp, None] * vps[..., 2]
            vps[..., 1] += X[:, i_pp + 1, None] * vps[..., 2]
        res = _endpoint_residual(vps, ss)[:, lab, cols]
        if f_free:
            # A weak prior keeps the focal length finite when the image cannot fix it.
            res = np.hstack([res, (w_prior * np.log(fk / f_prior))[:, None]])
        if pp_sigma:
            res = np.hstack([res, tau_px * X[:, i_pp : i_pp + 2] / pp_sigma])
        return res

    def fun(x: FloatArray) -> FloatArray:
        return batch(x[None, :])[0]

    def jac(x: FloatArray) -> FloatArray:
        X = np.vstack([x, x + step * np.eye(n_par)])
        r = batch(X)
        return np.asarray(((r[1:] - r[0]) / step).T, dtype=np.float64)

    def unpack(x: FloatArray) -> tuple[FloatArray, float]:
        R = Rotation.from_rotvec(x[:3]).as_matrix() @ R0
        f = min(max(f0 * math.exp(x[3]), lo), hi) if f_free else f0
        return R, f

    # Unbounded trust region (much cheaper than the bounded one); the focal length is
    # clamped to its bounds inside the model instead.
    x0 = np.zeros(n_par)
    sol = least_squares(
        fun,
        x0,
        jac=jac,
        loss="soft_l1",
        f_scale=tau_px,
        max_nfev=max_nfev,
        xtol=1e-7,
        ftol=1e-7,
    )
    R, f = unpack(sol.x)
    logf_std = float("nan")
    if f_free or info is not None:
        J = sol.jac
        # Covariance of the parameters with the robust loss folded into the Jacobian.
        dof = max(1, len(sol.fun) - len(sol.x))
        sigma2 = max(float(2.0 * sol.cost / dof), (0.3) ** 2)
        try:
            cov = np.linalg.inv(J.T @ J) * sigma2
            if f_free:
                logf_std = float(math.sqrt(max(cov[3, 3], 0.0)))
            if info is not None:
                info["cov_rot"] = cov[:3, :3]  # rotation vector applied on the left (camera)
        except np.linalg.LinAlgError:
            logf_std = float("inf")
    delta = np.asarray(sol.x[i_pp : i_pp + 2] if pp_sigma else np.zeros(2), dtype=np.float64)
    return R, f, logf_std, delta


def _undistorted_segs(s: _Segs, scale: float, k1: float, radius_n: float) -> _Segs:
    """Segments (normalised coordinates) with their end points undistorted (division model)."""
    half = 0.5 * s.length_px[:, None] / scale * s.dirn
    p1, p2 = s.mid - half, s.mid + half
    p1 = p1 / (1.0 + k1 * np.sum(p1 * p1, axis=1, keepdims=True) / radius_n**2)
    p2 = p2 / (1.0 + k1 * np.sum(p2 * p2, axis=1, keepdims=True) / radius_n**2)
    d = p2 - p1
    length = np.hypot(d[:, 0], d[:, 1])
    dirn = d / np.maximum(length, 1e-300)[:, None]
    nrm = np.column_stack([-dirn[:, 1], dirn[:, 0]])
    mid = 0.5 * (p1 + p2)
    lines = np.column_stack([nrm, -np.sum(nrm * mid, axis=1)])
    return _Segs(mid=mid, dirn=dirn, length_px=length * scale, lines=lines, weight=s.weight)


def _refine_distortion(
    m: _Model,
    s: _Segs,
    scale: float,
    radius_n: float,
    tau_px: float,
    f_free: bool,
    f_prior: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
) -> tuple[float, float, float]:
    """Fit the division-model ``k1`` with the rotation and the focal length.

    The segments keep their labels; straight lines broken into pieces along a bowed edge
    then agree on one vanishing point only for the right ``k1``. A Gaussian prior
    (sigma :data:`_K1_PRIOR_SIGMA`) keeps ``k1`` near 0 where the photo says little.

    Returns
    -------
    k1, its standard deviation, and the standard deviation of ``log(focal)`` with ``k1``
    free.
    """
    inl = m.labels >= 0
    ss = _subset(s, inl)
    lab = m.labels[inl]
    cols = np.arange(len(lab))
    lo, hi = f_bounds
    w_prior = 0.05 * tau_px if prior_w is None else prior_w
    n_par = 4 + int(f_free)
    i_k = n_par - 1

    def fun(x: FloatArray) -> FloatArray:
        R = Rotation.from_rotvec(x[:3]).as_matrix() @ m.R
        f = min(max(m.f_n * math.exp(x[3]), lo), hi) if f_free else m.f_n
        su = _undistorted_segs(ss, scale, float(x[i_k]), radius_n)
        res = _endpoint_residual(_vps_from_rotation(R, f), su)[lab, cols]
        extra = [tau_px * float(x[i_k]) / _K1_PRIOR_SIGMA]
        if f_free:
            extra.append(w_prior * math.log(f / f_prior))
        return np.concatenate([res, extra])

    sol = least_squares(
        fun, np.zeros(n_par), loss="soft_l1", f_scale=tau_px, max_nfev=60, x_scale=1.0
    )
    dof = max(1, len(sol.fun) - len(sol.x))
    sigma2 = max(float(2.0 * sol.cost / dof), 0.3**2)
    try:
        cov = np.linalg.inv(sol.jac.T @ sol.jac) * sigma2
    except np.linalg.LinAlgError:
        return 0.0, float("inf"), float("inf")
    k1_std = math.sqrt(max(cov[i_k, i_k], 0.0))
    logf_std = math.sqrt(max(cov[3, 3], 0.0)) if f_free else float("nan")
    return float(sol.x[i_k]), k1_std, logf_std


def _rotated_groups(s: _Segs, angle_rad: FloatArray) -> _Segs:
    """Segments each turned about its midpoint by its own angle (radians)."""
    c, sn = np.cos(angle_rad), np.sin(angle_rad)
    d = np.column_stack(
        [c * s.dirn[:, 0] - sn * s.dirn[:, 1], sn * s.dirn[:, 0] + c * s.dirn[:, 1]]
    )
    nrm = np.column_stack([-d[:, 1], d[:, 0]])
    lines = np.column_stack([nrm, -np.sum(nrm * s.mid, axis=1)])
    return _Segs(mid=s.mid, dirn=d, length_px=s.length_px, lines=lines, weight=s.weight)


def _systematic_logf_std(
    m: _Model,
    s: _Segs,
    tau_px: float,
    f_prior: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
    bias_deg: float,
    f_free: bool = True,
) -> float:
    """How far a systematic bias of the segments' directions moves ``log(focal)``.

    Real photos bend and bias line directions coherently (residual lens distortion,
    edge detectors on blurred or shaded edges, mislabelled lines): for each vanishing
    point, all its segments are turned by ``bias_deg`` the same way, then in opposite
    ways on either side of their centroid (a change of their convergence, e.g. of the
    lean of the verticals), and the focal length refitted. The root sum of squares of
    the moves is the systematic part of the focal length's standard deviation: it is
    large exactly where the geometry leaves the focal length loose, e.g. a level camera
    looking down a street, where only one horizontal vanishing point is finite and the
    focal length rests on how far off the vertical one lies.
    """
    delta = math.radians(bias_deg)
    total = 0.0
    kv = _vertical_index(m.R.T, m.n_lines)[0]
    p0, r0 = pitch_roll_from_up(_up_sign(m.R[:, kv]))
    tilt2 = np.zeros(2)
    for k in range(3):
        sel = m.labels == k
        if np.count_nonzero(sel) < 2:
            continue
        signs = np.where(s.dirn[sel] @ s.dirn[sel][0] >= 0, 1.0, -1.0)
        mean_dir = s.dirn[sel].T @ signs
        mean_dir = mean_dir / (np.linalg.norm(mean_dir) + 1e-300)
        rel = s.mid - s.mid[sel].mean(axis=0)
        side = np.sign(rel[:, 0] * mean_dir[1] - rel[:, 1] * mean_dir[0])
        for pattern in (np.ones(len(sel)), side):
            ang = np.where(sel, delta * pattern, 0.0)
            R, f, _, _ = _refine(
                m.R,
                m.f_n,
                _rotated_groups(s, ang),
                m.labels,
                tau_px,
                f_free,
                f_prior,
                f_bounds,
                prior_w=prior_w,
                max_nfev=20,
            )
            total += math.log(f / m.f_n) ** 2
            p1, r1 = pitch_roll_from_up(_up_sign(R[:, kv]))
            tilt2 += np.array([(p1 - p0) ** 2, (r1 - r0) ** 2])
    m.tilt_sys_deg = (float(math.sqrt(tilt2[0])), float(math.sqrt(tilt2[1])))
    return math.sqrt(total)


def _shifted_segs(s: _Segs, delta_n: FloatArray) -> _Segs:
    """Segments as seen from a principal point moved by ``delta_n`` (normalised)."""
    mid = s.mid - delta_n
    nrm = s.lines[:, :2]
    lines = np.column_stack([nrm, -np.sum(nrm * mid, axis=1)])
    return _Segs(mid=mid, dirn=s.dirn, length_px=s.length_px, lines=lines, weight=s.weight)


def _pp_logf_std(
    m: _Model,
    s: _Segs,
    tau_px: float,
    f_prior: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
    pp_sigma_n: float,
) -> float:
    """How far an unknown principal point moves ``log(focal)``.

    The principal point is assumed at the image centre; a real one lies up to a few per
    cent of the longer side off it. The principal point is moved by ``pp_sigma_n``
    (relative to the longer side) each way along each image axis, the focal length
    refitted (labels kept), and the root mean square of the two moves per axis summed
    in quadrature. Small where three vanishing points are finite; large for a level camera
    looking down a street, where the focal length is the square root of the horizon's
    offset from the principal point times the vertical vanishing point's distance: a
    principal point as far off as the horizon's offset moves it by a factor of 1.4 or
    more (rendered street photos, ``benchmarks/vp_real.py --sets street-synth-dev``).
    Finite differences, not the least-squares covariance: the response is far from linear
    there.
    """
    if not pp_sigma_n > 0.0:
        return 0.0
    total = 0.0
    for axis in (0, 1):
        moves2 = 0.0
        for sign in (1.0, -1.0):
            delta = np.zeros(2)
            delta[axis] = sign * pp_sigma_n
            _, f, _, _ = _refine(
                m.R,
                m.f_n,
                _shifted_segs(s, delta),
                m.labels,
                tau_px,
                True,
                f_prior,
                f_bounds,
                prior_w=prior_w,
                max_nfev=20,
            )
            moves2 += math.log(f / m.f_n) ** 2
        total += 0.5 * moves2
    return math.sqrt(total)


def _refit_without(
    m: _Model,
    s: _Segs,
    labels: npt.NDArray[np.int_],
    tau_px: float,
    f_free: bool,
    f_prior: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
    info: dict[str, Any] | None = None,
) -> tuple[FloatArray, float]:
    """Rotation and focal length refitted from ``m`` (up to 20 evaluations) with the
    segments ``labels`` marks ``-1`` left out: every leave-out term's refit."""
    R, f, _, _ = _refine(
        m.R,
        m.f_n,
        s,
        labels,
        tau_px,
        f_free,
        f_prior,
        f_bounds,
        prior_w=prior_w,
        max_nfev=20,
        info=info,
    )
    return R, f


def _tilt_move_deg(R: FloatArray, kv: int, p0: float, r0: float) -> tuple[float, float]:
    """Pitch and roll of the rotation ``R`` (vertical axis ``kv``) less ``p0`` and ``r0``,
    degrees; the roll's move wrapped into [-180, 180)."""
    p1, r1 = pitch_roll_from_up(_up_sign(R[:, kv]))
    return p1 - p0, (r1 - r0 + 180.0) % 360.0 - 180.0


def _logf_move(
    m: _Model,
    s: _Segs,
    labels: npt.NDArray[np.int_],
    tau_px: float,
    f_prior: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
) -> float:
    """``log(f / m.f_n)``: how far the focal length moves when refitted (from ``m``, up to
    20 evaluations) with the segments ``labels`` marks ``-1`` left out."""
    _, f = _refit_without(m, s, labels, tau_px, True, f_prior, f_bounds, prior_w)
    return math.log(f / m.f_n)


def _split_horizon_logf_std(
    m: _Model,
    s: _Segs,
    segs_px: FloatArray,
    merge_px: float,
    tau_px: float,
    f_prior: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
) -> float:
    """How much ``log(focal)`` disagrees between the two sides of the horizon.

    A horizontal direction's lines above the horizon (facades) and below it (kerbs,
    paving, steps, a lawn's paths) should meet at one vanishing point; paving joints,
    paths or shadows that are not quite parallel to the buildings pull it, the focal
    length with it, and the least-squares sigma cannot see it. For each horizontal
    direction with at least :data:`_MIN_SUPPORT` distinct lines on both sides, each side
    is left out in turn and the focal length refitted; the result is half the root sum
    of squares of the moves (a grouped jackknife over the two halves would take
    ``1/sqrt(2)``; each half also carries its own noise, already in the sigma).

    On 216 real photos this took the 1 / 2 sigma coverage of the stated focal sigma from
    69 / 92 % to 76 / 96 % (median error/sigma 0.60 -> 0.54) and the photos confidently
    wrong from 6 to 4 (``benchmarks/vp_real.py``).
    """
    kv = _vertical_index(m.R.T, m.n_lines)[0]
    up = _up_sign(m.R[:, kv])
    ray = np.column_stack([s.mid, np.full(len(s.mid), m.f_n)])
    above = ray @ up > 0.0
    total = 0.0
    for k in range(3):
        if k == kv:
            continue
        sel = m.labels == k
        n_up = _n_distinct_lines(segs_px[sel & above], merge_px)
        n_down = _n_distinct_lines(segs_px[sel & ~above], merge_px)
        if min(n_up, n_down) < _MIN_SUPPORT:
            continue
        for side in (above, ~above):
            labels = np.where(sel & side, -1, m.labels)
            total += _logf_move(m, s, labels, tau_px, f_prior, f_bounds, prior_w) ** 2
    return 0.5 * math.sqrt(total)


def _line_jackknife_logf_std(
    m: _Model,
    s: _Segs,
    segs_px: FloatArray,
    merge_px: float,
    tau_px: float,
    f_prior: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
    f_free: bool = True,
) -> float:
    """Delete-one-line jackknife of ``log(focal)``, pitch and roll over the lines of thinly
    supported directions.

    Where a direction has fewer than :data:`_JACKKNIFE_LINES` distinct lines, each of its
    lines (all the segments on it) is left out in turn and the model refitted; the
    jackknife variance ``(n - 1) / n * sum((theta_i - mean) ** 2)`` of each such direction
    is summed. A roof slope, a shadow on the ground or a gable's edge that lines up with a
    horizontal vanishing point by chance, in a direction that fixes the focal length with
    a dozen lines, moves it by itself; the least-squares sigma, which takes every line for
    a true one, cannot see that. The same refits give the jackknife of pitch and roll,
    stored in ``m.tilt_jack_deg`` (a horizon resting on a handful of lines across a road
    tilts with each of them).

    Returns
    -------
    float
        The jackknife standard deviation of ``log(focal)`` (0 when ``f_free`` is False).
    """
    total = 0.0
    tilt_total = np.zeros(2)
    kv = _vertical_index(m.R.T, m.n_lines)[0]
    p0, r0 = pitch_roll_from_up(_up_sign(m.R[:, kv]))
    for k in range(3):
        sel = np.flatnonzero(m.labels == k)
        if len(sel) == 0:
            continue
        groups = _line_groups(segs_px[sel], merge_px)
        n = int(groups.max()) + 1
        if not (_MIN_SUPPORT <= n < _JACKKNIFE_LINES):
            continue
        theta = np.empty((n, 3))
        for g in range(n):
            labels = m.labels.copy()
            labels[sel[groups == g]] = -1
            R, f = _refit_without(m, s, labels, tau_px, f_free, f_prior, f_bounds, prior_w)
            theta[g] = (math.log(f / m.f_n), *_tilt_move_deg(R, kv, p0, r0))
        spread = (n - 1) / n * np.sum((theta - theta.mean(axis=0)) ** 2, axis=0)
        total += float(spread[0])
        tilt_total += spread[1:]
    m.tilt_jack_deg = (float(math.sqrt(tilt_total[0])), float(math.sqrt(tilt_total[1])))
    return math.sqrt(total) if f_free else 0.0


def _rival_logf_std(
    best: _Model,
    models: Sequence[_Model],
    weight: Any,
    s: _Segs,
    tau_px: float,
    own_logf_std: float = 0.0,
) -> tuple[float, tuple[float, float]]:
    """Spread of ``log(focal)`` over the Manhattan frames the photo supports about as well.

    The hypotheses refined (:data:`_N_REFINED` distinct frames) are modes of the fit; the
    one of largest ``weight`` (its score, the segments' support, times the focal-length
    prior) is kept. Where another's weight is as large within the noise of the segments,
    which one is kept is close to a coin toss, and the photo fixes the focal length no
    better than the modes agree: a few short or curved lines across the street, or the
    slanted members of a structure, meet where another frame's lines would, and each
    frame fits its own lines tightly, so neither the least-squares sigma nor a jackknife
    over the kept frame's lines sees the other (nuScenes CAM_FRONT_RIGHT: +38 % at a stated
    5 %, its rival frame 3 % off the truth with as much support).

    The noise is that of a paired difference: each segment adds to either frame's score
    (:func:`_label_scores`), and the standard error of the difference of the two sums is
    ``sqrt(N)`` times the standard deviation of the segments' differences. A rival ``z``
    standard errors below the kept frame counts with ``Phi(-z)`` (the chance that it is the
    better supported one), the kept frame with 1; the result is the root of the weighted
    mean of the squared ``log`` ratios of their focal lengths to the kept one's (the
    expected squared error were the truth one of the modes), each less the kept frame's
    own variance: a rival whose focal length lies within the kept frame's own sigma is the
    same answer, whose spread that sigma already states, and adding it in full counted it
    twice. (The weights are calibrated as a whole: on the 268 real photos of
    ``benchmarks/vp_real.py``, of the 117 rivals beyond the kept frame's own sigma the
    mixture puts the truth at the rival for 9.3, and 8 lie nearer the truth than the kept
    frame; for 14 on the driving frames 2.0 and 4.)

    Parameters
    ----------
    best
        The frame kept.
    models
        The rival frames (``best`` among them is skipped), refined as far as ``best``.
    weight
        ``weight(model) -> float``: what the frame was chosen by.
    s, tau_px
        The segments and the inlier distance the frames are scored with.
    own_logf_std
        The kept frame's own standard deviation of ``log(focal)`` (all its other terms):
        what of each rival's squared log ratio lies within it is not counted again.

    Returns
    -------
    float
        Standard deviation of ``log(focal)`` across the modes beyond ``own_logf_std`` (0
        when no rival is close), to add to it in quadrature.
    tuple of float
        The same of pitch and roll (degrees; each rival's vertical is its direction
        nearest the kept frame's): a rival frame tilts the horizon too.
    """
    return _rival_spread(_rival_modes(best, models, weight, s, tau_px), own_logf_std)


#: A third horizontal direction among the frame's outliers counts when it has at least this
#: many distinct lines (as many as a direction needs not to count as "few lines":
#: :data:`_FEW_LINES`) and lies at least :data:`_THIRD_APART_DEG` from both horizontal
#: directions of the frame.
_THIRD_MIN_LINES = _FEW_LINES
_THIRD_APART_DEG = 10.0
_THIRD_HORIZONTAL = True


@dataclass
class _ThirdHorizontal:
    """A third horizontal direction (:func:`_third_horizontal`)."""

    n_lines: int  # its distinct lines
    n_paired: int  # distinct lines of the weaker of the frame's two horizontal directions
    log_moves: list[float]  # log(f_alt / f) of each pairing with a real focal length
    log_move_stds: list[float]  # how well its lines fix each
    pair_k: list[int] = field(default_factory=list)  # the frame's direction of each pairing


def _third_horizontal(
    best: _Model,
    s: _Segs,
    segs_px: FloatArray,
    merge_px: float,
    tau_px: float,
    f_bounds: tuple[float, float],
) -> _ThirdHorizontal | None:
    """A third horizontal direction among the frame's outliers, and the focal lengths it
    gives paired with either horizontal direction of the frame.

    A Manhattan frame takes its two horizontal directions to be square to each other. Two
    buildings at an angle (a campus, a square, a street that bends, a facade and a house
    turned to it) give more than two horizontal directions, and the frame pairs the two
    best supported, square or not: the focal length follows from that pairing (``f^2 =
    -(v_a . v_b)`` for horizontal vanishing points ``v_a``, ``v_b`` about the principal
    point), its lines fit it tightly, and no sigma of the frame sees that another pairing
    was possible (issue 24: a 653 px campus photo +101 % at a stated 8 %, two buildings at
    an angle; the road's own direction, square to one of them, among the outliers).

    Every line of a horizontal direction passes through its vanishing point on the horizon,
    that of ``cos t h1 + sin t h2`` (``h1``, ``h2`` the frame's horizontal directions), so
    each outlier line names one ``t``; the ``t`` whose vanishing point holds the most
    outlier length within the inlier distance is taken (lines through the vertical
    vanishing point left out: verticals a little off), its ``t`` refined by least squares
    over those lines, and its standard error from their residuals (at least a quarter of
    the inlier distance). Paired with each of the frame's horizontal vanishing points, it
    gives the focal length at which the two would be square, with the standard deviation
    that error carries into it; a pairing with no real focal length within ``f_bounds``
    (both on one side of the principal point) is none.

    Returns
    -------
    _ThirdHorizontal or None
        None when the outliers hold no such direction of :data:`_THIRD_MIN_LINES` lines.
    """
    R, f = best.R, best.f_n
    labels = best.labels
    kv = int(np.argmax(np.abs(R[1])))  # the direction nearest the image's vertical
    kh = [k for k in range(3) if k != kv]
    out = np.flatnonzero(labels < 0)
    if len(out) < _THIRD_MIN_LINES or not f > 0:
        return None
    so = _subset(s, out)
    vps = _vps_from_rotation(R, f)
    near_vert = np.abs(_endpoint_residual(vps[kv][None], so)[0]) < 2.0 * tau_px
    h1, h2 = R[:, kh[0]], R[:, kh[1]]
    n_cam = so.lines * np.array([f, f, 1.0])  # K^T l: the plane of the line
    t = np.arctan2(-(n_cam @ h1), n_cam @ h2) % np.pi  # each line's direction, from h1
    apart = math.radians(_THIRD_APART_DEG)
    cand = np.flatnonzero(
        ~near_vert & (np.minimum(t, np.pi - t) > apart) & (np.abs(t - 0.5 * np.pi) > apart)
    )
    if len(cand) < _THIRD_MIN_LINES:
        return None

    def vp_of(tt: FloatArray) -> FloatArray:
        d = np.cos(tt)[:, None] * h1 + np.sin(tt)[:, None] * h2
        return np.column_stack([f * d[:, 0], f * d[:, 1], d[:, 2]])

    sc = _subset(so, cand)
    inl = np.abs(_endpoint_residual(vp_of(t[cand]), sc)) < tau_px  # (C, C)
    i = int(np.argmax(inl.astype(float) @ sc.weight))
    members = inl[i]
    n3 = _n_distinct_lines(segs_px[out[cand[members]]], merge_px)
    if n3 < _THIRD_MIN_LINES:
        return None
    sm = _subset(sc, members)
    t3, step = float(t[cand[i]]), 1e-5
    for _ in range(3):  # Gauss-Newton on the end points' residuals
        r0 = _endpoint_residual(vp_of(np.array([t3])), sm)[0]
        jac = (_endpoint_residual(vp_of(np.array([t3 + step])), sm)[0] - r0) / step
        jj = float(jac @ jac)
        if not jj > 0.0:
            break
        t3 -= float(jac @ r0) / jj
    r0 = _endpoint_residual(vp_of(np.array([t3])), sm)[0]
    jac = (_endpoint_residual(vp_of(np.array([t3 + step])), sm)[0] - r0) / step
    jj = float(jac @ jac)
    noise = max(float(np.sqrt(np.sum(r0**2) / max(1, len(r0) - 1))), 0.25 * tau_px)
    t_std = noise / math.sqrt(jj) if jj > 0.0 else math.inf
    lo, hi = f_bounds

    def pair_logf(tt: float, vk: FloatArray) -> float:
        v3 = vp_of(np.array([tt]))[0]
        den = v3[2] * vk[2]
        if abs(den) < 1e-12:
            return math.nan
        f2 = -(v3[0] * vk[0] + v3[1] * vk[1]) / den  # normalised: f^2 of the pair square
        return 0.5 * math.log(f2) if lo * lo < f2 < hi * hi else math.nan

    moves, move_stds, pair_k = [], [], []
    for k in kh:
        m0 = pair_logf(t3, vps[k])
        dm = (pair_logf(t3 + 1e-4, vps[k]) - pair_logf(t3 - 1e-4, vps[k])) / 2e-4
        if math.isfinite(m0):
            moves.append(m0 - math.log(f))
            move_stds.append(abs(dm) * t_std if math.isfinite(dm) else math.inf)
            pair_k.append(k)
    n_h = [_n_distinct_lines(segs_px[labels == k], merge_px) for k in kh]
    log.debug(
        "third horizontal direction: %d lines (the frame's %s) at %.1f deg; pairings move "
        "log focal by %s",
        n3,
        n_h,
        math.degrees(t3),
        ", ".join(f"{m:+.3f} (+/- {e:.3f})" for m, e in zip(moves, move_stds, strict=True))
        or "nothing",
    )
    return _ThirdHorizontal(n3, min(n_h), moves, move_stds, pair_k)


def _vertical_pairing_logf(
    best: _Model,
    k_pair: int,
    s: _Segs,
    tau_px: float,
    f_prior: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
    bias_deg: float,
) -> tuple[float, float]:
    """The focal length the vertical gives with one horizontal direction, and its sigma.

    Both pairings of a third horizontal direction (:func:`_third_horizontal`) keep the
    vertical square to every horizontal direction: the vertical vanishing point and the
    horizon fix the focal length on their own (``f^2`` = the horizon's offset from the
    principal point times the vertical point's distance), whichever two horizontal
    directions are square. The frame is fitted again with its vertical and its horizontal
    direction ``k_pair`` only (the one both pairings share); the sigma of ``log(focal)``
    takes in least squares, the segments' systematic bias (:func:`_systematic_logf_std`)
    and the principal point (:func:`_pp_logf_std`), as the frame's own does. Loose where
    the vertical vanishing point lies far off (a level camera): there the vertical cannot
    tell the pairings apart.

    Returns
    -------
    float
        ``log(focal)`` (normalised) of the vertical and direction ``k_pair``.
    float
        Its standard deviation (``inf`` where the fit cannot say).
    """
    kv = int(np.argmax(np.abs(best.R[1])))
    labels = np.where((best.labels == kv) | (best.labels == k_pair), best.labels, -1)
    if np.count_nonzero(labels == kv) < 2 or np.count_nonzero(labels == k_pair) < 2:
        return math.nan, math.inf
    R, f, ls_std, _ = _refine(
        best.R, best.f_n, s, labels, tau_px, True, f_prior, f_bounds, prior_w=prior_w
    )
    if not (f > 0 and math.isfinite(ls_std)):
        return math.nan, math.inf
    m2 = _Model(R=R, f_n=f, labels=labels, score=best.score, n_lines=best.n_lines)
    sys_std = _systematic_logf_std(m2, s, tau_px, f_prior, f_bounds, prior_w, bias_deg)
    pp_std = _pp_logf_std(m2, s, tau_px, f_prior, f_bounds, prior_w, _PP_FOCAL_SIGMA_REL)
    return math.log(f), math.sqrt(ls_std**2 + sys_std**2 + pp_std**2)


#: The vertical rules a third direction's pairing out where the focal length it gives with
#: the shared horizontal direction lies beyond this many sigmas from the pairing's and
#: within as many of the frame's (:func:`_vertical_rules_out`).
_THIRD_VERTICAL_Z = 2.0

#: A third direction pairs only with a horizontal direction of the frame that has at least
#: this many distinct lines: one of fewer is left out of the fit (:data:`_WEAK_LINES`), its
#: vanishing point the cross product of the other two, not a direction the photo shows.
_THIRD_PAIR_MIN_LINES = _WEAK_LINES


def _vertical_rules_out(
    logf: float, log_move: float, log_move_std: float, logf_v: float, logf_v_std: float
) -> bool:
    """Whether the vertical tells the frame's pairing from a third direction's.

    ``logf`` is the frame's ``log(focal)``, ``logf + log_move`` (sigma ``log_move_std``)
    the rival pairing's, ``logf_v`` (sigma ``logf_v_std``) what the vertical gives with
    the horizontal direction both share (:func:`_vertical_pairing_logf`). The rival is
    ruled out where the vertical lies more than :data:`_THIRD_VERTICAL_Z` sigmas (the two
    together) from it and within as many of the frame's: stairs, floor joints or an oblique
    wing of a photo whose vertical fixes the focal length. Where the vertical agrees with
    neither, or is too loose to choose, the rival stands.
    """
    if not (math.isfinite(logf_v) and math.isfinite(logf_v_std) and logf_v_std > 0.0):
        return False
    z_rival = abs(logf + log_move - logf_v) / math.hypot(log_move_std, logf_v_std)
    z_frame = abs(logf - logf_v) / logf_v_std
    log.debug(
        "third direction: the vertical gives log focal %+.3f (+/- %.3f): the rival pairing "
        "%.1f sigma off, the frame %.1f",
        logf_v - logf,
        logf_v_std,
        z_rival,
        z_frame,
    )
    return z_rival > _THIRD_VERTICAL_Z and z_frame <= _THIRD_VERTICAL_Z


def _rival_pairings(
    best: _Model,
    third: _ThirdHorizontal,
    n_lines: Sequence[int],
    own_std: float,
    s: _Segs,
    tau_px: float,
    f_prior: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
    bias_deg: float,
) -> list[float]:
    """The moves of ``log(focal)`` of a third direction's pairings that rival the frame's.

    A pairing counts where its lines fix its focal length as a photo must to be believed
    (:data:`_LOOSE_FOCAL_STD`) and it lies clearly apart from the kept one (beyond twice
    their two sigmas together, the frame's own ``own_std``), unless it pairs with a frame
    direction of fewer than :data:`_THIRD_PAIR_MIN_LINES` distinct lines (``n_lines``: the
    cross product of the other two, not a direction the photo shows; Strecha's Herz-Jesus
    photos, read right, had confidence 0.00 from such a pairing) or the vertical rules it
    out (:func:`_vertical_pairing_logf`, :func:`_vertical_rules_out`).
    """
    alt = []
    for m_alt, e_alt, k_pair in zip(
        third.log_moves, third.log_move_stds, third.pair_k, strict=True
    ):
        if not (e_alt <= _LOOSE_FOCAL_STD and abs(m_alt) > 2.0 * math.hypot(e_alt, own_std)):
            continue
        if n_lines[k_pair] < _THIRD_PAIR_MIN_LINES:
            continue
        logf_v, std_v = _vertical_pairing_logf(
            best, k_pair, s, tau_px, f_prior, f_bounds, prior_w, bias_deg
        )
        if not _vertical_rules_out(math.log(best.f_n), m_alt, e_alt, logf_v, std_v):
            alt.append(m_alt)
    return alt


def _curve_share(segs_px: FloatArray, sel: npt.NDArray[np.bool_], diag_rel: float = 0.006) -> float:
    """Share of the selected segments continued at an end by a segment bent by 2-25 degrees."""
    if not sel.any():
        return float("nan")
    w = float(np.ptp(segs_px[:, [0, 2]])) or 1.0
    h = float(np.ptp(segs_px[:, [1, 3]])) or 1.0
    tol = max(3.0, diag_rel * math.hypot(w, h))
    d = segs_px[:, 2:] - segs_px[:, :2]
    ang = np.arctan2(d[:, 1], d[:, 0])
    ends = np.concatenate([segs_px[:, :2], segs_px[:, 2:]])  # 2N x 2
    owner = np.concatenate([np.arange(len(segs_px))] * 2)
    hits = 0
    idx = np.flatnonzero(sel)
    for i in idx:
        e = np.stack([segs_px[i, :2], segs_px[i, 2:]])
        dist = np.min(np.linalg.norm(ends[:, None, :] - e[None, :, :], axis=2), axis=1)
        near = owner[(dist < tol) & (owner != i)]
        if near.size == 0:
            continue
        da = np.abs((ang[near] - ang[i] + np.pi / 2) % np.pi - np.pi / 2)
        if np.any((da > math.radians(2.0)) & (da < math.radians(25.0))):
            hits += 1
    return hits / len(idx)


def _curve_direction(
    m: _Model,
    s: _Segs,
    segs_px: FloatArray,
    n_lines: Sequence[int],
    tau: float,
    f_prior: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
) -> _Model:
    """Check that a direction of few lines is not made of tangent pieces of curves.

    A direction of :data:`_WEAK_LINES` to :data:`_JACKKNIFE_LINES` distinct lines at least
    :data:`_CURVE_SHARE` of whose segments are continued, end to end, by a segment turned by
    2-25 degrees (:func:`_curve_share`) is the near-straight stretches of round things (a
    basin's rim, steps, an arch): its lines meet wherever the curves' tangents do. The focal
    length is fitted again without it:

    - where the other two then leave it loose (a sigma over :data:`_LOOSE_FOCAL_STD`: a
      frontal scene, whose focal length rests on that direction), the photo is said not to
      fix it: the stated sigma is at least that of the fit without it (at most
      :data:`_MAX_STATED_STD`), the default focal length joins in where it is over 10 %, and
      a warning names the direction (``thin_only``);
    - where they fix it and the direction pulls it away from them by more than
      :data:`_FEW_LINES_MIN_SHIFT` and :data:`_FEW_LINES_SHIFT_Z` times the sigma of the
      pull, the direction is left out (the model returned is the fit without it).

    Otherwise ``m`` is returned as it is.
    """
    for k in range(3):
        if not _WEAK_LINES <= n_lines[k] < _JACKKNIFE_LINES:
            continue
        if _curve_share(segs_px, m.labels == k) < _CURVE_SHARE:
            continue
        labels = np.where(m.labels == k, -1, m.labels)
        R, f, logf_std, _ = _refine(
            m.R, m.f_n, s, labels, tau, True, f_prior, f_bounds, prior_w=prior_w
        )
        if math.isfinite(logf_std) and logf_std <= _LOOSE_FOCAL_STD:
            shift = abs(math.log(m.f_n / f)) if f > 0 else math.inf
            base_std = m.logf_std if math.isfinite(m.logf_std) else 0.0
            shift_std = math.sqrt(max(0.0, logf_std**2 - base_std**2))
            if shift > max(_FEW_LINES_MIN_SHIFT, _FEW_LINES_SHIFT_Z * shift_std):
                U, _, Vt = np.linalg.svd(R)
                log.debug(
                    "direction %d (%d lines, pieces of curves) left out: it pulls the focal "
                    "length by %.3f (+/- %.3f)",
                    k,
                    n_lines[k],
                    shift,
                    shift_std,
                )
                return replace(m, R=U @ Vt, f_n=f, labels=labels, logf_std=logf_std)
            continue
        m.logf_std = max(
            m.logf_std if math.isfinite(m.logf_std) else 0.0,
            min(logf_std, _MAX_STATED_STD) if math.isfinite(logf_std) else _MAX_STATED_STD,
        )
        m.thin_only = int(n_lines[k])
        log.debug("focal length rests on direction %d (%d lines, pieces of curves)", k, n_lines[k])
        return m
    return m


def _rival_modes(
    best: _Model, models: Sequence[_Model], weight: Any, s: _Segs, tau_px: float
) -> list[tuple[float, float, FloatArray]]:
    """The rival frames of :func:`_rival_logf_std` as ``(weight, log focal ratio, tilt
    move)``: ``Phi(-z)``, ``log(f_rival / f_kept)`` and the (pitch, roll) move in degrees."""
    w_best = float(weight(best))
    if not (w_best > 0.0 and math.isfinite(w_best) and best.score > 0.0):
        return []
    up_best = _up_sign(best.R[:, _vertical_index(best.R.T)[0]])
    p0, r0 = pitch_roll_from_up(up_best)
    _, c_best = _label_scores(best.R, best.f_n, s, tau_px * _LABEL_TAU, _LABEL_ANGLE_DEG)
    c_best = c_best * (w_best / best.score)  # with the focal-length prior's factor
    n = len(c_best)
    modes = []
    for m in models:
        if m is best or not (m.f_n > 0.0 and best.f_n > 0.0 and m.score > 0.0):
            continue
        _, c = _label_scores(m.R, m.f_n, s, tau_px * _LABEL_TAU, _LABEL_ANGLE_DEG)
        diff = c_best - c * (float(weight(m)) / m.score)
        se = math.sqrt(n) * float(np.std(diff))
        total = float(np.sum(diff))
        # (where every segment differs alike: a tie, or a frame better everywhere)
        z = max(0.0, total / se) if se > 0.0 else (0.0 if total <= 0.0 else math.inf)
        w = 0.5 * math.erfc(z / math.sqrt(2.0))  # Phi(-z)
        kv = int(np.argmax(np.abs(m.R.T @ up_best)))
        d = math.log(m.f_n / best.f_n)
        modes.append((w, d, np.asarray(_tilt_move_deg(m.R, kv, p0, r0), dtype=float)))
        log.debug("rival frame: %.2f standard errors below, weight %.2f, log focal %+.3f", z, w, d)
    return modes


def _rival_spread(
    modes: Sequence[tuple[float, float, FloatArray]], own_logf_std: float = 0.0
) -> tuple[float, tuple[float, float]]:
    """Weighted root mean square of the rival modes' moves (:func:`_rival_logf_std`)."""
    num, den, tilt_num = 0.0, 1.0, np.zeros(2)
    for w, d, tilt_move in modes:
        # only what lies beyond the kept frame's own sigma: a rival within it is the same
        # answer, whose spread that sigma already states
        num += w * max(0.0, d**2 - own_logf_std**2)
        den += w
        tilt_num += w * np.square(tilt_move)
    tilt = np.sqrt(tilt_num / den)
    return math.sqrt(num / den), (float(tilt[0]), float(tilt[1]))


def _level_reading_move_deg(m: _Model, segs_px: FloatArray, merge_px: float) -> None:
    """Where no line is vertical, how far pitch and roll move to the level reading.

    With no vertical line (over a highway, a dash camera's road), up is the cross product
    of the two horizontal directions, and the roll rests on where the weaker of them
    lies; where that is a few lines across a road (a car's edges, a guard rail, shadows:
    not the ground's family, or not horizontal), the horizon tilts with them, and neither
    the least-squares sigma nor a jackknife (the lines agree with each other) can see it:
    BrnoCompSpeed's traffic cameras were rolled 17-27 degrees at a stated 0.3-1.6. Leave
    that direction out and the lines fix only the stronger direction: the rest is the
    prior that cameras rarely roll, i.e. the camera turned until it is level about the
    horizontal direction nearer the optical axis (the street's). How far pitch and roll
    move to that reading is what the data cannot fix; it is stored in
    ``m.tilt_consider_deg`` (and the direction's lines in ``m.horizon_rests_on``) where
    the vertical has fewer than :data:`_MIN_SUPPORT` distinct lines and the weaker
    horizontal direction fewer than :data:`_JACKKNIFE_LINES`.
    """
    nl = m.n_lines
    if nl is None:
        return
    kv = _vertical_index(m.R.T, nl)[0]
    hor = [k for k in range(3) if k != kv]
    if nl[kv] >= _MIN_SUPPORT or min(nl[k] for k in hor) >= _JACKKNIFE_LINES:
        return
    # the direction kept is the one nearer the optical axis (the street's: its vanishing
    # point fixes the pitch, and turning about it rolls the camera); one across the image
    # (near its x axis) fixes the roll by its own slope, and turning about it only pitches
    keep = max(hor, key=lambda k: abs(float(m.R[2, k])))
    weak = min(hor, key=lambda k: nl[k])
    d = m.R[:, keep]
    # level: up perpendicular to the strong direction and to the camera's x axis
    up_level = np.cross(d, np.array([1.0, 0.0, 0.0]))
    if np.linalg.norm(up_level) < 1e-9:
        return
    up = _up_sign(m.R[:, kv])
    p0, r0 = pitch_roll_from_up(up)
    p1, r1 = pitch_roll_from_up(_up_sign(_unit(up_level)))
    m.tilt_consider_deg = (abs(p1 - p0), abs((r1 - r0 + 180.0) % 360.0 - 180.0))
    m.horizon_rests_on = int(nl[weak])


def _tilt_jacobian(up: FloatArray) -> FloatArray:
    """``(2, 3)`` derivative of (pitch, roll) in degrees by a small rotation vector applied
    on the left (camera frame) to ``up``."""
    p0, r0 = pitch_roll_from_up(up)
    eps = 1e-6
    J = np.zeros((2, 3))
    for i in range(3):
        rv = np.zeros(3)
        rv[i] = eps
        p1, r1 = pitch_roll_from_up(Rotation.from_rotvec(rv).as_matrix() @ up)
        J[:, i] = [(p1 - p0) / eps, (r1 - r0) / eps]
    return J


def _split_tilt_deg(
    m: _Model,
    s: _Segs,
    segs_px: FloatArray,
    merge_px: float,
    tau_px: float,
    f_free: bool,
    f_prior: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
    cov_rot: FloatArray | None,
) -> None:
    """Whether part of a direction's lines tilts the frame beyond its noise.

    Two tests, each a refit with some lines left out:

    - a direction of fewer than :data:`_FEW_LINES` distinct lines (the other two keeping
      :data:`_MIN_SUPPORT` or more) is left out whole: a handful of lines that are not of
      the frame (kerbs at an angle, a car, a sign) tilt the horizon through it;
    - a direction's lines are split by where they lie (either side of their centroid,
      across their mean image direction: left and right for the verticals, above and
      below for a horizontal one), and each half is left out in turn (two families taken
      for one: leaning pillars among a building's verticals).

    Where a move of pitch or roll exceeds :data:`_SPLIT_TILT_Z` times its own standard
    deviation (that of the refit less that of the full fit: what is left carries its own
    noise), it goes into ``m.tilt_split_deg`` (a whole direction's move in full, the two
    halves' root mean square). Photos whose lines agree keep their sigma. nuScenes
    CAM_FRONT_LEFT (the horizon through a direction of 6 short lines) was 4 degrees off in
    roll at a stated 0.3.
    """
    if cov_rot is None or not np.all(np.isfinite(cov_rot)):
        return
    kv = _vertical_index(m.R.T, m.n_lines)[0]
    up = _up_sign(m.R[:, kv])
    p0, r0 = pitch_roll_from_up(up)
    J = _tilt_jacobian(up)
    var_full = np.diag(J @ cov_rot @ J.T)
    n_lines = [_n_distinct_lines(segs_px[m.labels == k], merge_px) for k in range(3)]

    def move_of(left_out: npt.NDArray[np.bool_]) -> FloatArray | None:
        """Significant move (degrees, 0 where not) of pitch and roll without those lines."""
        labels = np.where(left_out, -1, m.labels)
        info: dict[str, Any] = {}
        R, _ = _refit_without(m, s, labels, tau_px, f_free, f_prior, f_bounds, prior_w, info)
        cov = info.get("cov_rot")
        if cov is None or not np.all(np.isfinite(cov)):
            return None
        move = np.array(_tilt_move_deg(R, kv, p0, r0))
        sd = np.sqrt(np.maximum(np.diag(J @ cov @ J.T) - var_full, 0.0))
        return np.where(np.abs(move) > _SPLIT_TILT_Z * sd, move, 0.0)

    total = np.zeros(2)
    for k in range(3):
        sel = m.labels == k
        rest = [n_lines[i] for i in range(3) if i != k]
        if _MIN_SUPPORT <= n_lines[k] < _FEW_LINES and min(rest) >= _MIN_SUPPORT:
            mv = move_of(sel)
            if mv is not None:
                total += mv**2
        if n_lines[k] < 2 * _MIN_SUPPORT:
            continue
        signs = np.where(s.dirn[sel] @ s.dirn[sel][0] >= 0, 1.0, -1.0)
        mean_dir = _unit(s.dirn[sel].T @ signs)
        rel = s.mid - s.mid[sel].mean(axis=0)
        side = rel[:, 0] * mean_dir[1] - rel[:, 1] * mean_dir[0] > 0
        halves = []
        for half in (side, ~side):
            if _n_distinct_lines(segs_px[sel & ~half], merge_px) < _MIN_SUPPORT:
                break
            mv = move_of(sel & half)
            if mv is None:
                break
            halves.append(mv)
        if len(halves) == 2:
            total += 0.5 * (halves[0] ** 2 + halves[1] ** 2)
    m.tilt_split_deg = (float(math.sqrt(total[0])), float(math.sqrt(total[1])))


def _up_sign(d: FloatArray) -> FloatArray:
    """The direction pointing image-up (``y < 0``)."""
    return np.asarray(-d if d[1] > 0 else d, dtype=np.float64)


def _tilt_std_deg(
    m: _Model, cov_rot: FloatArray | None, pp_sigma_n: float = 0.0
) -> tuple[float, float]:
    """1-sigma of pitch and roll (degrees): the larger of least squares and the
    delete-one-line jackknife (``m.tilt_jack_deg``), the systematic part, what the lines
    cannot fix where no line is vertical (``m.tilt_consider_deg``), the spread over rival
    frames (``m.tilt_rival_deg``) and, when the principal
    point is assumed rather than known, its uncertainty (``pp_sigma_n`` in normalised
    units: pitch is measured from the optical axis through it)."""
    kv = _vertical_index(m.R.T, m.n_lines)[0]
    up = _up_sign(m.R[:, kv])
    p0, _ = pitch_roll_from_up(up)
    var = np.array([m.tilt_sys_deg[0] ** 2, m.tilt_sys_deg[1] ** 2])
    stat = np.zeros(2)
    if cov_rot is not None and np.all(np.isfinite(cov_rot)):
        J = _tilt_jacobian(up)
        stat = np.diag(J @ cov_rot @ J.T)
    # the jackknife measures the same sampling spread as least squares, lines that pose
    # as the direction's included: the larger of the two
    var = var + np.maximum(stat, np.square(m.tilt_jack_deg))
    var = var + np.square(m.tilt_consider_deg) + np.square(m.tilt_split_deg)
    var = var + np.square(m.tilt_rival_deg)
    if pp_sigma_n > 0:
        # an offset of the principal point turns the optical axis: by its full angle in
        # pitch, and about the vertical, which shows as roll in proportion to the pitch
        pp_deg = math.degrees(math.atan(pp_sigma_n / m.f_n))
        var[0] += pp_deg**2
        var[1] += (pp_deg * math.sin(math.radians(p0))) ** 2
    return float(math.sqrt(var[0])), float(math.sqrt(var[1]))


# ------------------------------------------------------------------------- result


def _jsonable_float(x: float | None, nd: int = 4) -> float | None:
    if x is None or not math.isfinite(x):
        return None
    return round(float(x), nd)


@dataclass
class AutoVPResult:
    """Vanishing points, intrinsics and tilt found in one image.

    Attributes
    ----------
    vanishing_points
        ``(3, 3)`` homogeneous vanishing points in pixels (rows ``[x, y, w]``), ordered
        ``[vertical, horizontal-1, horizontal-2]`` (horizontal-1 has the most support).
    directions_in_cam
        ``(3, 3)`` unit vanishing directions in the camera frame, same order; the first
        points up in the world, the others point forward (``z >= 0``).
    focal_px, principal_point
        Intrinsics used (given, or estimated).
    focal_source
        ``"given"``, ``"estimated"`` (fixed by the image) or ``"prior"`` (the image could
        not fix it, a default was used; see ``focal_std_rel``).
    focal_std_rel
        Standard deviation of ``log(focal)``, i.e. relative uncertainty, when estimated.
    pitch_deg, roll_deg
        Optical axis angle below the horizon, and rotation about the optical axis
        (positive when image-right tilts downward).
    pitch_std_deg, roll_std_deg
        Their 1-sigma (degrees): least squares or a delete-one-line jackknife, the
        systematic part (segments turned by :data:`BIAS_DEG`), the assumed principal
        point, a direction (or half of one) of few lines that tilts the frame beyond its
        noise, and where no line is vertical, the move to the level reading. On York
        Urban 1 / 2 sigma cover 66 / 91 % of the pitch errors, 77 / 91 % of the roll ones
        (``benchmarks/vp_real.py``).
    horizon
        ``a, b, c`` of the horizon ``a x + b y + c = 0`` with ``a^2 + b^2 = 1``.
    segments, labels
        ``(N, 4)`` detected segments and the index (0..2) of the VP each supports, -1
        for outliers. Where a direction leaned on chords of curves or on overhead wires
        and the photo was read again without them (:func:`_curve_directions`,
        :func:`_wire_directions`), those segments are not among them.
    confidence
        0..1: roughly the probability that the focal length is within 10 % (when it is
        estimated): that of the stated Gaussian ``focal_std_rel``, times the chance that
        the Manhattan frame is the photo's (falling with fewer than about 60 distinct
        lines), times the structure's support (explained share of the segments' length,
        lines per direction), times, where a third horizontal direction would pair
        otherwise (:func:`_third_horizontal`, warned; not where the vertical rules that
        pairing out, :func:`_vertical_rules_out`), the weaker kept direction's share of the
        two rival directions' lines. On 216 real photos its ROC AUC for an error over 10 %
        is 0.90 (``benchmarks/vp_real.py``; stop 40: York Urban 0.95, Strecha 0.90, the 82
        street photos 0.83).
    vertical_identified
        False when another direction could be the vertical one nearly as well (e.g. a
        camera pitched 60 degrees down and one pitched 30 degrees up see the same frame).
    n_inliers, n_lines
        Supporting segments, and distinct straight lines, of each vanishing point.
    inlier_share
        Share of the total segment length that supports one of the vanishing points.
    image_size
        ``(width, height)`` in pixels.
    focal_std_parts
        The terms of the photo's own ``focal_std_rel`` (standard deviations of
        ``log(focal)``, by name: ``least_squares``, ``jackknife`` (the larger of the two is
        taken), ``systematic`` (segments turned by :data:`BIAS_DEG`), ``split_horizon``,
        ``few_lines`` (the pull of a direction of few lines, or :data:`_UNCHECKED_FEW_STD`
        where nothing checks it), ``principal_point``, ``rival``), before a default or EXIF prior
        joins, and ``distortion`` (how far the fitted k1 moved the focal length from k1 = 0;
        it joins the stated sigma last, after any prior); empty when the focal length was
        given. For diagnosis
        (``benchmarks/vp_real.py`` reports which term decides the sigma, set by set); not
        in the command line's JSON.
    line_residual_rms_px
        Root mean square distance of the inlier segments' end points to the lines through
        their midpoints and vanishing points, in the detection image's pixels (at most
        1024 px on the longer side); NaN when the focal length was given. For diagnosis.
    line_scatter_deg
        How far the long inliers (60 detection pixels or more) turn about their vanishing
        points beyond their end points' noise, root mean square in degrees; NaN with fewer
        than 8 of them or when the focal length was given. For diagnosis: it does not
        tell a photo's coherent line bias (``benchmarks/README.md``, vp_real, stop 39).
    """

    vanishing_points: FloatArray
    directions_in_cam: FloatArray
    focal_px: float
    principal_point: tuple[float, float]
    focal_source: str
    focal_std_rel: float
    pitch_deg: float
    roll_deg: float
    horizon: FloatArray
    segments: FloatArray
    labels: npt.NDArray[np.int64]
    confidence: float
    vertical_identified: bool
    image_size: tuple[int, int]
    n_inliers: tuple[int, int, int] = field(default=(0, 0, 0))
    n_lines: tuple[int, int, int] = field(default=(0, 0, 0))
    inlier_share: float = 0.0
    warnings: list[str] = field(default_factory=list)
    distortion: float = 0.0
    distortion_std: float = float("nan")
    pitch_std_deg: float = float("nan")
    roll_std_deg: float = float("nan")
    focal_std_parts: dict[str, float] = field(default_factory=dict)
    line_residual_rms_px: float = float("nan")
    line_scatter_deg: float = float("nan")

    @property
    def street_index(self) -> int:
        """Index (1 or 2) of the horizontal vanishing point taken for the street.

        The horizontal direction nearer the optical axis: a street camera or a photo taken
        in a street looks along it more than across it. Except where only one of the two is
        a direction the photo shows (at least :data:`_WEAK_LINES` distinct lines, the other
        fewer: the cross product of the other two): a street shows its own direction (kerbs,
        lane markings, facades), so that one is the street. A level phone photo down a
        street whose kerbs and lane lines meet off the frame took the unsupported point
        nearer the centre for the street (stop 40).
        """
        n1, n2 = (int(n) for n in self.n_lines[1:3])
        if (n1 >= _WEAK_LINES) != (n2 >= _WEAK_LINES):
            return 1 if n1 >= _WEAK_LINES else 2
        d = self.directions_in_cam
        return 1 if abs(float(d[1, 2])) >= abs(float(d[2, 2])) else 2

    @property
    def vanishing_points_px(self) -> list[list[float] | None]:
        """``[x, y]`` of each vanishing point, ``None`` where it is at infinity."""
        out: list[list[float] | None] = []
        tol = math.sin(math.radians(INFINITY_TOL_DEG))
        for d, v in zip(self.directions_in_cam, self.vanishing_points, strict=True):
            if abs(d[2]) < tol or v[2] == 0.0:
                out.append(None)
            else:
                out.append([float(v[0] / v[2]), float(v[1] / v[2])])
        return out

    @property
    def up_in_cam(self) -> FloatArray:
        """Unit world-up direction in the camera frame."""
        return np.asarray(self.directions_in_cam[0], dtype=np.float64)

    @property
    def horizon_endpoints(self) -> list[list[float]] | None:
        """The horizon at the left (x = 0) and right (x = width) image borders, or None."""
        a, b, c = (float(x) for x in self.horizon)
        if abs(b) < 1e-9:
            return None
        w = float(self.image_size[0])
        return [[0.0, -c / b], [w, -(a * w + c) / b]]

    def to_json(self) -> dict[str, Any]:
        """The JSON object ``camloc vp`` prints."""
        vps_px = self.vanishing_points_px
        ep = self.horizon_endpoints
        return {
            "vanishing_points": [
                None if v is None else [_jsonable_float(v[0], 3), _jsonable_float(v[1], 3)]
                for v in vps_px
            ],
            "vanishing_point_roles": ["vertical", "horizontal", "horizontal"],
            "vanishing_point_names": [
                "vertical",
                *(
                    ["street", "across the street"]
                    if self.street_index == 1
                    else ["across the street", "street"]
                ),
            ],
            "street_vanishing_point": self.street_index,
            # which vanishing points no line supports: implied by the other two and the focal
            # length (orthogonality), not seen (stop 42)
            "vanishing_point_implied": [int(n) == 0 for n in self.n_inliers],
            "vanishing_points_homogeneous": [
                [float(x) for x in _unit(np.asarray(v, dtype=np.float64))]
                for v in self.vanishing_points
            ],
            "directions_in_cam": [[round(float(x), 8) for x in d] for d in self.directions_in_cam],
            "focal_px": _jsonable_float(self.focal_px, 3),
            "focal_source": self.focal_source,
            "focal_std_rel": _jsonable_float(self.focal_std_rel, 4),
            "principal_point": [float(self.principal_point[0]), float(self.principal_point[1])],
            "horizon": {
                "line": [float(x) for x in self.horizon],
                "endpoints": None
                if ep is None
                else [[_jsonable_float(p[0], 3), _jsonable_float(p[1], 3)] for p in ep],
            },
            "pitch_deg": _jsonable_float(self.pitch_deg, 4),
            "roll_deg": _jsonable_float(self.roll_deg, 4),
            "pitch_std_deg": _jsonable_float(self.pitch_std_deg, 4),
            "roll_std_deg": _jsonable_float(self.roll_std_deg, 4),
            "confidence": _jsonable_float(self.confidence, 4),
            "vertical_identified": bool(self.vertical_identified),
            "n_segments": len(self.segments),
            "n_inliers": [int(n) for n in self.n_inliers],
            "n_lines": [int(n) for n in self.n_lines],
            "inlier_share": _jsonable_float(self.inlier_share, 4),
            "warnings": list(self.warnings),
            "distortion": {
                "model": "division",
                "k1": _jsonable_float(self.distortion, 6),
                "k1_std": _jsonable_float(self.distortion_std, 6),
            },
            "image_size": [int(self.image_size[0]), int(self.image_size[1])],
        }


def pitch_roll_from_up(up_in_cam: FloatArray) -> tuple[float, float]:
    """Pitch and roll (degrees) of a camera from the world-up direction in its frame.

    Pitch is the optical axis angle below the horizon; roll is
    ``atan2(r . d0, r . r0)`` with ``r`` the camera x axis, ``r0 = unit(z x up)`` and
    ``d0 = z x r0`` (positive when image-right tilts downward).

    >>> pitch_roll_from_up(np.array([0.0, -1.0, 0.0]))
    (0.0, 0.0)
    """
    u = _unit(np.asarray(up_in_cam, dtype=np.float64))
    pitch = math.degrees(math.asin(float(np.clip(-u[2], -1.0, 1.0))))
    fwd = np.array([0.0, 0.0, 1.0])
    r0 = np.cross(fwd, u)
    if np.linalg.norm(r0) < 1e-12:
        return pitch, 0.0
    r0 = _unit(r0)
    d0 = np.cross(fwd, r0)
    roll = math.degrees(math.atan2(float(d0[0]), float(r0[0])))
    return pitch + 0.0, roll + 0.0


def horizon_from_up(
    up_in_cam: FloatArray, focal_px: float, principal_point: tuple[float, float]
) -> FloatArray:
    """Horizon line ``[a, b, c]`` (``a x + b y + c = 0``, ``a^2 + b^2 = 1``) in pixels."""
    u = np.asarray(up_in_cam, dtype=np.float64)
    cx, cy = principal_point
    line = np.array([u[0], u[1], focal_px * u[2] - cx * u[0] - cy * u[1]])
    n = math.hypot(line[0], line[1])
    if n < 1e-15:  # camera looking straight up or down: no horizon in the image
        return np.array([0.0, 0.0, 1.0])
    line = line / n
    if line[1] < 0 or (line[1] == 0 and line[0] < 0):
        line = -line
    return np.asarray(line, dtype=np.float64)


# ---------------------------------------------------------------------- main entry


def detect_vanishing_points(
    image: str | os.PathLike[str] | npt.NDArray[Any] | None,
    *,
    focal_px: float | None = None,
    principal_point: tuple[float, float] | None = None,
    seed: int = 0,
    max_iterations: int = 2000,
    segments: FloatArray | None = None,
    image_size: tuple[int, int] | None = None,
    inlier_px: float | None = None,
    focal_bounds_rel: tuple[float, float] = FOCAL_BOUNDS_REL,
    estimate_principal_point: bool = False,
    mask: npt.NDArray[Any] | None = None,
    min_inlier_share: float = 0.2,
    axes_hint: Sequence[tuple[npt.ArrayLike, npt.ArrayLike]] | None = None,
    focal_prior_px: float | None = None,
    focal_prior_sigma_rel: float = 0.05,
    focal_prior_source: str = "prior-given",
    use_exif: bool = False,
    bias_deg: float | None = None,
    distortion_k1: float | None = None,
    estimate_distortion: bool = True,
    default_focal_prior: bool = True,
    check_focal_prior: bool | None = None,
) -> AutoVPResult:
    """Find three orthogonal vanishing points, the focal length, pitch and roll.

    Parameters
    ----------
    image
        Path or array (BGR or gray); ignored for detection when ``segments`` is given
        (pass ``None`` then, with ``image_size``).
    focal_px
        Known focal length in pixels; estimated when None.
    principal_point
        Known principal point ``[x, y]`` in pixels; the image centre when None.
    seed
        Random seed (the result is deterministic for a given seed).
    max_iterations
        Number of RANSAC hypotheses.
    segments
        Use these ``(N, 4)`` segments instead of detecting them.
    image_size
        ``(width, height)``; needed only when ``image`` is None.
    inlier_px
        Inlier distance of a segment end point to the line joining its midpoint and the
        vanishing point. Default: 1.5 px per 800 px of image diagonal, at least 1 px.
    focal_bounds_rel
        Range of focal lengths searched, as multiples of the longer image side.
    estimate_principal_point
        Also refine the principal point (when not given), with a Gaussian prior around
        the image centre (sigma 3 % of the longer side). Off by default: on York Urban it
        lowers the direction error a little but does not find the true principal point
        (the estimates scatter around the centre), and it costs focal accuracy.
    mask
        ``(H, W)`` boolean array, True where segments may lie (see
        :func:`detect_segments`); ignored when ``segments`` is given.
    min_inlier_share
        Refuse (``NotEnoughStructureError``) when the vanishing points explain less than
        this share of the segments' total length (York Urban photos: 62 % or more;
        random lines or blobs: 20 to 40 %, which also get a confidence near 0).
    axes_hint
        Up to three image axes ``(origin_px, end_px)`` known to be parallel to distinct
        orthogonal world directions, e.g. a car's annotated length, width and height
        edges: among the Manhattan frames the image supports, the one whose vanishing
        points these axes point at (within a few degrees) is preferred, so that the
        result is aligned with the annotated object rather than, say, a building at an
        angle to it.
    focal_prior_px, focal_prior_sigma_rel, focal_prior_source
        A prior on the focal length (pixels, relative standard deviation, and the name
        ``focal_source`` reports), e.g. from EXIF. The vanishing points refine it where
        they fix the focal length better; where they leave it loose, the prior decides.
    use_exif
        When ``image`` is a path and neither ``focal_px`` nor ``focal_prior_px`` is
        given, read the focal length from the photo's EXIF (:mod:`camloc_geo.exif`) and
        use it as the prior (``focal_source`` then names the EXIF source; where two EXIF
        readings contradict each other, ``exif-conflict``, its warning comes first in
        ``warnings``).
    bias_deg
        Systematic bias of segment directions (degrees) propagated into the focal
        length's standard deviation (see ``_systematic_logf_std``); default
        :data:`BIAS_DEG`, calibrated on real photos (``benchmarks/vp_real.py``).
    distortion_k1
        Known radial distortion of the photo (division model,
        :class:`camloc_geo.camera.RadialDistortion`, radius in half image diagonals):
        the segment end points are undistorted before the fit, so the vanishing points,
        focal length and horizon are those of the pinhole camera; ``segments`` in the
        result stay in the photo's pixels.
    estimate_distortion
        (Default on.) When ``distortion_k1`` is not given, also fit ``k1`` (division model) with the
        rotation and the focal length, from the bowing of long edges that LSD breaks
        into pieces. It is kept when it differs from 0 by more than twice its standard
        deviation (then the segments are undistorted and the fit redone); the result
        reports it with its sigma either way (``distortion``, ``distortion_std``).
    default_focal_prior
        (Default on.) Where no focal length or prior is given and the photo leaves the
        focal length loose (warned), combine it with what cameras are (log-normal around
        the longer side) and refit the rotation there. Off: the photo's own vanishing
        points and focal length, with their loose sigma (what a caller that has its own
        focal length, such as ``calibrate`` lending the photo's lines to the annotators'
        fit, needs: the default would move the vanishing points the lines are labelled
        with).
    check_focal_prior
        Also read the photo's own focal length without the prior (a second fit on the
        same segments, the default prior as usual) and, where that reading is well fixed
        (:data:`_LOOSE_FOCAL_STD` and the prior's sigma or tighter, not decided by the
        default prior) and disagrees with the prior beyond their combined sigma
        (``|log(f_photo / f_prior)| > 2 sqrt(sigma_photo^2 + sigma_prior^2)``), state the
        prior's and the photo's readings as an equal mixture (:func:`_mix_readings`: the
        focal length between them, its sigma covering both, the confidence lower) and warn
        naming both. Where they agree nothing changes. Default
        (None): where the prior was read from EXIF (``use_exif``), not where the caller
        gave ``focal_prior_px``. A maker's tag can be wrong (a OnePlus 5T's 35 mm tag 12 %
        low: ``benchmarks/README.md``, stop 40).

    Returns
    -------
    AutoVPResult

    Raises
    ------
    NotEnoughStructureError
        Too few straight lines, or no two directions supported by enough of them.
    InputError
        The image cannot be read.
    """
    if image is not None:
        gray = load_image(image)
        h, w = gray.shape
    elif image_size is not None:
        w, h = int(image_size[0]), int(image_size[1])
        gray = None
    else:
        raise InputError("give an image, or segments with image_size")
    if focal_px is not None and not (math.isfinite(focal_px) and focal_px > 0):
        raise InputError(f"focal_px must be a positive number, got {focal_px!r}")
    if focal_px is not None and not 1e-3 <= focal_px / max(w, h) <= 1e3:
        raise InputError(
            f"focal_px {focal_px:g} is not a focal length for a {w}x{h} image (give "
            f"{1e-3 * max(w, h):g} to {1e3 * max(w, h):g} px)"
        )
    if isinstance(seed, bool) or not (isinstance(seed, (int, np.integer)) and seed >= 0):
        raise InputError(f"seed must be a non-negative integer, got {seed!r}")
    if focal_prior_px is not None and not (math.isfinite(focal_prior_px) and focal_prior_px > 0):
        raise InputError(f"focal_prior_px must be a positive number, got {focal_prior_px!r}")
    if not (math.isfinite(focal_prior_sigma_rel) and focal_prior_sigma_rel > 0):
        raise InputError(
            f"focal_prior_sigma_rel must be a positive number, got {focal_prior_sigma_rel!r}"
        )
    prior_from_exif = False
    exif_warnings: tuple[str, ...] = ()  # EXIF readings that contradict each other
    if (
        use_exif
        and focal_px is None
        and focal_prior_px is None
        and isinstance(image, (str, os.PathLike))
    ):
        from camloc_geo.exif import focal_from_exif

        ex = focal_from_exif(image)
        if ex is not None:
            prior_from_exif = True
            focal_prior_px, focal_prior_sigma_rel, focal_prior_source = (
                ex.focal_px,
                ex.sigma_rel,
                ex.source,
            )
            log.info("focal length prior from EXIF (%s): %.1f px", ex.source, ex.focal_px)
            exif_warnings = ex.warnings
    if principal_point is not None and not (
        np.shape(principal_point) == (2,) and np.all(np.isfinite(principal_point))
    ):
        raise InputError(f"principal_point must be two finite numbers, got {principal_point!r}")
    if max_iterations < 1:
        raise InputError(f"max_iterations must be positive, got {max_iterations}")
    if segments is None:
        assert gray is not None
        segs_px, curve = _detect_segments(gray, mask=mask)
        segs_detected = segs_px
        if _CURVE_MODE == "drop" and np.any(curve) and np.count_nonzero(~curve) >= _MIN_SEGMENTS:
            segs_px, curve = segs_px[~curve], curve[~curve]
            segs_detected = segs_px
    else:
        segs_px = np.asarray(segments, dtype=np.float64).reshape(-1, 4)
        ln = np.hypot(segs_px[:, 2] - segs_px[:, 0], segs_px[:, 3] - segs_px[:, 1])
        segs_px = segs_px[np.isfinite(ln) & (ln > 1e-6)]
        segs_detected, curve = segs_px, np.zeros(len(segs_px), dtype=bool)
    if len(segs_px) < _MIN_SEGMENTS:
        raise NotEnoughStructureError(
            f"not enough structure: {len(segs_px)} straight line segments found "
            f"(at least {_MIN_SEGMENTS} needed)"
        )
    pp = np.array(principal_point if principal_point is not None else (w / 2.0, h / 2.0), float)
    scale = float(max(w, h))
    segs_photo = segs_px
    if distortion_k1:
        from camloc_geo.camera import RadialDistortion, undistort_points_px

        try:
            dist = RadialDistortion.for_image(distortion_k1, w, h)
        except DegenerateGeometryError as exc:
            raise InputError(f"distortion_k1: {exc}") from exc
        pp_t = (float(pp[0]), float(pp[1]))
        und = undistort_points_px(segs_px.reshape(-1, 2), dist, pp_t).reshape(-1, 4)
        ok = np.all(np.isfinite(und), axis=1)
        segs_px, segs_photo = und[ok], segs_px[ok]
        segs_detected, curve = segs_detected[ok], curve[ok]
    hints = _prepare_hints(axes_hint, pp, scale)
    if axes_hint:
        # An annotated axis is a straight line of the image too: fit it with the segments
        # (first, so that it is among the segments hypotheses are scored on).
        axis_segs = np.array(
            [
                np.r_[np.ravel(np.asarray(o, float)), np.ravel(np.asarray(e, float))]
                for o, e in axes_hint
            ]
        )
        segs_px = np.vstack([axis_segs, segs_px])
    diag = math.hypot(w, h)
    tau = inlier_px if inlier_px is not None else max(1.0, _TAU_PER_800 * diag / 800.0)
    s = _prepare(segs_px, pp, scale)
    f_bounds = (focal_bounds_rel[0], focal_bounds_rel[1])
    f_fixed = None if focal_px is None else focal_px / scale
    f_prior = _F_PRIOR_REL if f_fixed is None else f_fixed
    prior_sigma = _F_PRIOR_SIGMA
    prior_w: float | None = None
    has_prior = f_fixed is None and focal_prior_px is not None
    check_prior = has_prior and (
        prior_from_exif if check_focal_prior is None else bool(check_focal_prior)
    )
    if has_prior:
        assert focal_prior_px is not None
        f_prior = focal_prior_px / scale
        prior_sigma = focal_prior_sigma_rel
        prior_w = _PRIOR_NOISE_PX * tau / focal_prior_sigma_rel

    rng = np.random.default_rng(seed)
    # Score hypotheses on the longest segments (they are sorted longest first).
    s_sc = _subset(s, slice(0, 150))
    dirs, fs = _hypotheses(s_sc, rng, max_iterations, f_fixed, f_bounds)
    if len(dirs) == 0:
        raise NotEnoughStructureError("not enough structure: no vanishing point hypothesis")
    # Preemptive scoring: all hypotheses on a spread subset of segments, the best tenth
    # on the 150 longest.
    n_sc = len(s_sc.mid)
    sub = np.unique(np.linspace(0, n_sc - 1, min(n_sc, 48)).round().astype(int))
    prior = _focal_prior(fs, f_prior, 2.0 * prior_sigma) if f_fixed is None else np.ones(len(fs))
    if hints is not None:
        prior = prior * _hint_factor(dirs, fs, hints)
    scores = _score(dirs, fs, _subset(s_sc, sub), tau) * prior
    keep = np.argsort(-scores, kind="stable")[: max(20, len(dirs) // 10)]
    scores = _score(dirs[keep], fs[keep], s_sc, tau) * prior[keep]
    order = keep[np.argsort(-scores, kind="stable")]

    # Refine the best few distinct hypotheses; keep the best refined model.
    models: list[_Model] = []
    tried: list[FloatArray] = []
    for i in order[:40]:
        R0 = dirs[i].T
        if any(_same_frame(R0, Rt) for Rt in tried):
            continue
        tried.append(R0)
        # one round each: enough to rank the candidates
        models.append(
            _fit(R0, float(fs[i]), s, tau, f_fixed is None, f_prior, f_bounds, 1, prior_w=prior_w)
        )
        # (with annotated axes the frame is theirs, and a caller without the default focal
        # prior, such as calibrate lending the photo's lines to the annotators' fit, weighs
        # the photo's sigma against its own: for both the rivals are the few the frame was
        # chosen from, as before stop 40. More modes added rivals better supported than the
        # frame the axes chose (a hinted photo: 657 px at 4 % became 711 px at 22 %), and
        # widened the photo's sigma where calibrate tells a user that the photo's lines
        # disagree with the annotators' focal length: York Urban's Corolla lost that warning.)
        n_refined = _N_REFINED if hints is None and default_focal_prior else _N_KEPT_FROM
        if len(tried) >= n_refined:
            break

    def model_weight(m: _Model) -> float:
        wgt = m.score
        if f_fixed is None:
            wgt *= float(_focal_prior(np.array([m.f_n]), f_prior, 2.0 * prior_sigma)[0])
        if hints is not None:
            wgt *= float(_hint_factor(m.R.T[None], np.array([m.f_n]), hints)[0])
        return wgt

    best = max(models[:_N_KEPT_FROM], key=model_weight)
    if hints is not None:
        # The axes choose among frames the photo supports about as well; they do not
        # overrule a frame the photo supports clearly better.
        best_img = max(models[:_N_KEPT_FROM], key=lambda m: m.score)
        if best.score < _HINT_MIN_SCORE_SHARE * best_img.score:
            best = best_img
    rivals = [
        m for m in models if m is not best and model_weight(m) >= _RIVAL_SHARE * model_weight(best)
    ]
    best = _fit(
        best.R,
        best.f_n,
        s,
        tau,
        f_fixed is None,
        f_prior,
        f_bounds,
        rounds=2,
        labels0=best.labels,
        prior_w=prior_w,
    )
    n_axes = len(segs_px) - len(segs_detected)  # annotated axes, first
    chords = np.r_[np.zeros(n_axes, dtype=bool), curve]
    curve_dirs = _curve_directions(best.labels, chords) if _CURVE_MODE == "refit" else []
    wire_dirs: list[int] = []
    drop = curve if curve_dirs else np.zeros(len(segs_detected), dtype=bool)
    if gray is not None and segments is None and len(segs_detected):
        # Overhead wires against the sky (_sky_wires): where a direction of the frame
        # leans on them, they go too.
        labels_det = best.labels[n_axes:]
        kv = int(np.argmax(np.abs(best.R[1])))  # the direction nearest the image's vertical
        merge_wire = max(4.0, 0.01 * diag)
        thin = _thin_lines(gray, segs_detected)
        wires = _sky_wires(segs_detected, thin, labels_det, kv, (float(w), float(h)), merge_wire)
        wire_dirs = _wire_directions(segs_detected, labels_det, wires, merge_wire)
        if wire_dirs:
            # the wires, and the thin lines of the directions that lean on them (the
            # wires' pieces in front of facades, nowhere in the sky)
            drop = drop | wires | (thin & np.isin(labels_det, wire_dirs))
    curve_only = False
    if curve_dirs or wire_dirs:
        # A direction of the frame leans on chords of curves (a rotunda's rings, a dome:
        # _curve_pieces) or on overhead wires: they are not lines of the scene. The photo
        # is read again without them (once: given segments are not looked at again).
        log.debug(
            "%d segments are chords of curves, %d overhead wires: read again without them",
            int(np.count_nonzero(curve & drop)),
            int(np.count_nonzero(drop & ~curve)),
        )
        try:
            return detect_vanishing_points(
                None,
                focal_px=focal_px,
                principal_point=principal_point,
                seed=seed,
                max_iterations=max_iterations,
                segments=segs_detected[~drop],
                image_size=(w, h),
                inlier_px=inlier_px,
                focal_bounds_rel=focal_bounds_rel,
                estimate_principal_point=estimate_principal_point,
                min_inlier_share=min_inlier_share,
                axes_hint=axes_hint,
                focal_prior_px=focal_prior_px,
                focal_prior_sigma_rel=focal_prior_sigma_rel,
                focal_prior_source=focal_prior_source,
                bias_deg=bias_deg,
                distortion_k1=distortion_k1,
                estimate_distortion=estimate_distortion,
                default_focal_prior=default_focal_prior,
                check_focal_prior=check_prior,
            )
        except NotEnoughStructureError:
            # too little is left without them: this reading stands, but its focal length
            # rests on the curves (said below)
            curve_only = bool(curve_dirs)
    rival_tilt = (0.0, 0.0)
    rival_modes: list[tuple[float, float, FloatArray]] = []
    if f_fixed is None and rivals:
        # frames the photo supports about as well, refined as far as the kept one: a mode
        # each, whose focal lengths go into the sigma
        rivals = [
            _fit(m.R, m.f_n, s, tau, True, f_prior, f_bounds, 2, m.labels, prior_w) for m in rivals
        ]
        rival_modes = _rival_modes(best, [best, *rivals], model_weight, s, tau)
        rival_tilt = _rival_spread(rival_modes)[1]
    if estimate_principal_point and principal_point is None:
        # Free the principal point around the image centre (a Gaussian prior), on the
        # final inliers.
        R, f, logf_std, delta = _refine(
            best.R,
            best.f_n,
            s,
            best.labels,
            tau,
            f_fixed is None,
            f_prior,
            f_bounds,
            pp_sigma=_PP_SIGMA_REL,
            prior_w=prior_w,
        )
        pp = pp + delta * scale
        s = _prepare(segs_px, pp, scale)
        labels, score = _labels(R, f, s, tau * _LABEL_TAU, _LABEL_ANGLE_DEG)
        best = _Model(R=R, f_n=f, labels=labels, score=score, logf_std=logf_std)
    k1_est, k1_std = 0.0, float("nan")
    k1_move = 0.0  # |log| move of the focal length from k1 = 0 to the fitted k1 (in sigma)
    if estimate_distortion and not distortion_k1:
        f_n_straight = best.f_n
        from camloc_geo.camera import RadialDistortion, undistort_points_px

        radius_n = 0.5 * diag / scale
        pp_t = (float(pp[0]), float(pp[1]))
        segs_orig = segs_px
        k_total = 0.0
        for _ in range(_K1_ROUNDS):
            dk, k1_std, logf_std_k = _refine_distortion(
                best, s, scale, radius_n, tau, f_fixed is None, f_prior, f_bounds, prior_w
            )
            if not abs(dk) > max(0.5 * k1_std, 0.002):
                break
            # small division-model corrections compose nearly additively
            k_try = k_total + dk
            if not abs(k_try) < 0.9:
                break
            dist = RadialDistortion.for_image(k_try, w, h)
            und = undistort_points_px(segs_orig.reshape(-1, 2), dist, pp_t).reshape(-1, 4)
            if not np.all(np.isfinite(und)):
                break
            k_total = k_try
            segs_px = und
            s = _prepare(segs_px, pp, scale)
            best = _fit(
                best.R, best.f_n, s, tau, f_fixed is None, f_prior, f_bounds, 2, prior_w=prior_w
            )
            if math.isfinite(logf_std_k):
                best.logf_std = max(best.logf_std, logf_std_k)
        if abs(k_total) > 2.0 * k1_std:
            k1_est = k_total
            segs_photo = segs_orig
            # The fit cannot tell a lens's bowing from edges that are not straight or
            # not square (a catenary, a curved kerb, phones that correct their lens in the
            # camera): the k1 fit trades off with the focal length far beyond k1's stated
            # sigma on real photos (a compact at -43 % with k1 = +0.086 +/- 0.004, -5 % at
            # k1 = 0). How far k1 moves the focal length from the straight-line reading
            # goes into the focal sigma as a model term (``_K1_MOVE_TERM``).
            if _K1_MOVE_TERM and f_fixed is None:
                k1_move = min(abs(math.log(best.f_n / f_n_straight)), _MAX_STATED_STD)
            log.debug(
                "distortion k1 %.4f +/- %.4f applied: focal length moves by %.3f",
                k1_est,
                k1_std,
                k1_move,
            )
        elif k_total:
            # not significant: back to the photo's segments
            segs_px = segs_orig
            s = _prepare(segs_px, pp, scale)
            best = _fit(
                best.R, best.f_n, s, tau, f_fixed is None, f_prior, f_bounds, 2, prior_w=prior_w
            )
    # A direction supported by a few lines only (paving joints, shadows, a roof slope) is
    # left out: it would pull the focal length and the horizon wherever it lies.
    merge_px = max(4.0, 0.01 * diag)
    n_lines = [_n_distinct_lines(segs_px[best.labels == k], merge_px) for k in range(3)]
    weak = int(np.argmin(n_lines))
    others = sorted(n_lines)[1:]
    if 0 < n_lines[weak] < _WEAK_LINES and min(others) >= _MIN_SUPPORT:
        labels = np.where(best.labels == weak, -1, best.labels)
        R, f, logf_std, _ = _refine(
            best.R, best.f_n, s, labels, tau, f_fixed is None, f_prior, f_bounds, prior_w=prior_w
        )
        loose = not (math.isfinite(logf_std) and logf_std <= _PRIOR_ONLY_STD)
        if f_fixed is None and not has_prior and loose:
            # Without it the photo does not fix the focal length at all: its estimate
            # beats the default, but it is stated with the sigma of the fit without it.
            best.logf_std = max(
                best.logf_std if math.isfinite(best.logf_std) else 0.0,
                min(logf_std, _MAX_STATED_STD) if math.isfinite(logf_std) else _MAX_STATED_STD,
            )
            best.weak_only = n_lines[weak]
            log.debug("focal length rests on direction %d (%d lines)", weak, n_lines[weak])
        else:
            U, _, Vt = np.linalg.svd(R)
            best = _Model(R=U @ Vt, f_n=f, labels=labels, score=best.score, logf_std=logf_std)
            log.debug("direction %d left out: %d distinct lines", weak, n_lines[weak])
    elif (
        f_fixed is None
        and _WEAK_LINES <= n_lines[weak] < _FEW_LINES
        and min(others) >= _MIN_SUPPORT
        and math.isfinite(best.logf_std)
    ):
        labels = np.where(best.labels == weak, -1, best.labels)
        R, f, logf_std, _ = _refine(
            best.R, best.f_n, s, labels, tau, True, f_prior, f_bounds, prior_w=prior_w
        )
        # Where a direction of few lines pulls the focal length away from what the other
        # two (and the prior, if any) say (a gable, a side wall or a niche not square to
        # the rest), the pull goes into the sigma; where the other two leave the focal
        # length loose, the pull is also warned of. The fit with it is the one without plus
        # its lines: the variance of the difference is that of the fit without less that of
        # the fit with.
        shift = abs(math.log(best.f_n / f)) if f > 0 else math.inf
        shift_std = (
            math.sqrt(max(0.0, logf_std**2 - best.logf_std**2))
            if math.isfinite(logf_std)
            else math.inf
        )
        if has_prior and shift > max(_FEW_LINES_MIN_SHIFT, _FEW_LINES_SHIFT_Z * shift_std):
            # with a prior (EXIF) the focal length does not need it: it goes
            U, _, Vt = np.linalg.svd(R)
            best = _Model(R=U @ Vt, f_n=f, labels=labels, score=best.score, logf_std=logf_std)
            log.debug(
                "direction %d (%d lines) left out: it pulls the focal length from the prior "
                "by %.3f (+/- %.3f)",
                weak,
                n_lines[weak],
                shift,
                shift_std,
            )
        elif shift > max(_FEW_LINES_MIN_SHIFT, _FEW_LINES_SHIFT_Z * shift_std):
            best.few_shift = min(shift, _MAX_STATED_STD)
            if not (math.isfinite(logf_std) and logf_std <= _LOOSE_FOCAL_STD):
                best.rests_on_few = n_lines[weak]
            log.debug(
                "direction %d (%d lines) pulls the focal length by %.3f (+/- %.3f)%s",
                weak,
                n_lines[weak],
                shift,
                shift_std,
                ": it rests on it" if best.rests_on_few else "",
            )
    if f_fixed is None and not has_prior and not best.weak_only:
        best = _curve_direction(best, s, segs_px, n_lines, tau, f_prior, f_bounds, prior_w)
    if curve_only and f_fixed is None and not has_prior and not best.weak_only:
        # without the chords of curves the photo has too few lines to fix anything
        k_curve = max(range(3), key=lambda k: int(np.count_nonzero(chords & (best.labels == k))))
        best.thin_only = max(1, _n_distinct_lines(segs_px[best.labels == k_curve], merge_px))
        best.logf_std = _MAX_STATED_STD
        log.debug("focal length rests on direction %d, chords of curves", k_curve)
    nl = [_n_distinct_lines(segs_px[best.labels == k], merge_px) for k in range(3)]
    best.n_lines = (nl[0], nl[1], nl[2])
    # With no line left in one direction (no building over a highway: no vertical; or a
    # direction of a few lines left out above), the focal length rests on the other two
    # alone; where the weaker of them has a few lines only (a car's edges, a guard rail: a
    # traffic camera's "across the road"), the photo does not fix the focal length: say so
    # (BrnoCompSpeed session4_left: -54 % at a stated 11 %, on 4 lines).
    lined = [nl[k] for k in range(3) if nl[k] > 0]
    if (
        len(lined) == 2
        and f_fixed is None
        and not has_prior
        and not best.weak_only
        and min(lined) < _WEAK_LINES
    ):
        best.weak_only = min(lined)
        best.logf_std = _MAX_STATED_STD
        log.debug("one direction without lines: the focal length rests on %d", min(lined))
    elif (
        len(lined) == 2
        and f_fixed is None
        and not has_prior
        and not best.weak_only
        and not best.thin_only
        and min(lined) < _FEW_LINES
    ):
        # The same with a direction of a few more lines: kept, but where a third direction
        # would check its pull (a roof slope, a gable taken for a horizontal direction),
        # none does; what such pulls are goes into the sigma (``_UNCHECKED_FEW_STD``).
        best.unchecked_few = min(lined)
        best.few_shift = math.hypot(best.few_shift, _UNCHECKED_FEW_STD)
        log.debug("two directions alone: the focal length rests on %d lines", min(lined))
    bias = BIAS_DEG if bias_deg is None else bias_deg
    if f_fixed is None and math.isfinite(best.logf_std):
        sys_std = _systematic_logf_std(best, s, tau, f_prior, f_bounds, prior_w, bias)
        split_std = _split_horizon_logf_std(
            best, s, segs_px, merge_px, tau, f_prior, f_bounds, prior_w
        )
        jack_std = _line_jackknife_logf_std(
            best, s, segs_px, merge_px, tau, f_prior, f_bounds, prior_w
        )
        pp_std = (
            _pp_logf_std(best, s, tau, f_prior, f_bounds, prior_w, _PP_FOCAL_SIGMA_REL)
            if principal_point is None and not estimate_principal_point
            else 0.0
        )
        # the jackknife measures the same sampling spread as the least-squares sigma,
        # outliers that pose as lines included: the larger of the two
        stat_std = max(best.logf_std, jack_std)
        own_std = math.sqrt(stat_std**2 + sys_std**2 + split_std**2 + best.few_shift**2 + pp_std**2)
        rival_std = _rival_spread(rival_modes, own_std)[0]
        if _THIRD_HORIZONTAL and not has_prior:
            third = _third_horizontal(best, s, segs_px, merge_px, tau, f_bounds)
            alt = (
                _rival_pairings(best, third, nl, own_std, s, tau, f_prior, f_bounds, prior_w, bias)
                if third is not None
                else []
            )
            if third is not None and alt:
                best.third = third
                best.third_move = min(alt, key=abs)
        inl = best.labels >= 0
        if np.any(inl):
            res_px = _endpoint_residual(_vps_from_rotation(best.R, best.f_n), s)
            res_in = res_px[best.labels[inl], np.flatnonzero(inl)]
            # in the detection image's pixels (detect_segments works at most 1024 px wide)
            det = min(1.0, 1024.0 / scale)  # detection pixels per photo pixel
            best.residual_rms_px = float(np.sqrt(np.mean(res_in**2))) * det
            best.scatter_deg = _line_scatter_deg(res_in * det, s.length_px[inl] * det)
        best.sigma_parts = {
            "least_squares": float(best.logf_std),
            "jackknife": float(jack_std),
            "systematic": float(sys_std),
            "split_horizon": float(split_std),
            "few_lines": float(best.few_shift),
            "principal_point": float(pp_std),
            "rival": float(rival_std),
            "distortion": float(k1_move),
        }
        best.logf_std = math.sqrt(own_std**2 + rival_std**2)
        if best.weak_only or best.thin_only:
            best.logf_std = min(best.logf_std, _MAX_STATED_STD)
    elif f_fixed is not None:
        _systematic_logf_std(best, s, tau, f_prior, f_bounds, prior_w, bias, f_free=False)
        _line_jackknife_logf_std(
            best, s, segs_px, merge_px, tau, f_prior, f_bounds, prior_w, f_free=False
        )
    best.f_data_n, best.data_logf_std = best.f_n, best.logf_std
    if (
        has_prior
        and math.isfinite(best.logf_std)
        and best.logf_std > prior_sigma
        and not best.weak_only
        and not best.thin_only
    ):
        # The prior (EXIF, or given) enters the fit as one residual against hundreds of
        # segments whose noise the fit takes as independent, so a loose photo (a ramp's
        # railings taken for the street, reflections on a wet road) can pull the focal length
        # far from it (+21 % at a stated 17 % from a 35 mm tag). The photo's estimate, with
        # the sigma it states (systematic terms included), and the prior are combined as two
        # Gaussians in log(focal) instead, as for the default prior. Shortcut: the photo's
        # estimate is the fit with the prior, which counts the prior a little twice.
        best = _with_default_prior(best, s, tau, f_bounds, prior_w, (f_prior, prior_sigma))
    clash: tuple[float, float, float] | None = None  # the photo's own px, its sigma, delta
    if check_prior and math.isfinite(best.logf_std):
        assert focal_prior_px is not None
        try:
            own = detect_vanishing_points(
                None,
                principal_point=principal_point,
                seed=seed,
                max_iterations=max_iterations,
                segments=segs_detected,
                image_size=(w, h),
                inlier_px=inlier_px,
                focal_bounds_rel=focal_bounds_rel,
                estimate_principal_point=estimate_principal_point,
                min_inlier_share=min_inlier_share,
                axes_hint=axes_hint,
                bias_deg=bias_deg,
                distortion_k1=distortion_k1,
                estimate_distortion=estimate_distortion,
                check_focal_prior=False,
            )
        except NotEnoughStructureError:
            own = None
        if own is not None:
            d_logf = math.log(own.focal_px / focal_prior_px)
            combined = math.hypot(own.focal_std_rel, prior_sigma)
            # well fixed: not loose, not decided by the default prior, and at least as
            # tight as the prior (lines looser than the tag do not overrule it: the fit
            # above weighed them already)
            fixed = own.focal_source == "estimated" and own.focal_std_rel <= min(
                _LOOSE_FOCAL_STD, prior_sigma
            )
            log.debug(
                "prior check: photo %.1f px +/- %.3f, prior %.1f px +/- %.3f: %.3f (%s)",
                own.focal_px,
                own.focal_std_rel,
                focal_prior_px,
                prior_sigma,
                d_logf,
                "fixed" if fixed else "loose",
            )
            if fixed and abs(d_logf) > _PRIOR_CHECK_Z * combined:
                best = _mix_readings(
                    best,
                    (f_prior, prior_sigma),
                    (own.focal_px / scale, own.focal_std_rel),
                    s,
                    tau,
                    f_bounds,
                    prior_w,
                )
                clash = (own.focal_px, own.focal_std_rel, d_logf)
    if (
        default_focal_prior
        and f_fixed is None
        and not has_prior
        and not best.logf_std <= _LOOSE_FOCAL_STD
    ):
        # the photo leaves the focal length loose (warned): what cameras are joins in, the
        # photo's reading counted as a wrong frame's with the frame's chance of being wrong
        best = _with_default_prior(
            best,
            s,
            tau,
            f_bounds,
            prior_w,
            _default_focal_prior(float(w), float(h)),
            _wrong_frame_chance(best.n_lines) if _WRONG_FRAME_MIXTURE else 0.0,
        )
    if k1_move and math.isfinite(best.logf_std):
        # The k1 term joins the stated sigma last: it says how far the answer would move
        # were the bowing not the lens's, so it neither weighs the rival frames nor calls in
        # the default prior (which would pull a right k1 fit's answer toward what cameras
        # are: a -0.15 barrel lens's focal length from +4 % to +10 %). It widens the sigma
        # up to the default prior's (what cameras are) at most: a move beyond it says no
        # more (a photo of 2-4 lines in two directions moved by the bounds).
        cap = max(best.logf_std, _default_focal_prior(float(w), float(h))[1])
        best.logf_std = min(math.hypot(best.logf_std, k1_move), cap, _MAX_STATED_STD)
    info: dict[str, Any] = {}
    if np.count_nonzero(best.labels >= 0) >= 4:
        _refine(
            best.R,
            best.f_n,
            s,
            best.labels,
            tau,
            f_fixed is None,
            f_prior,
            f_bounds,
            prior_w=prior_w,
            max_nfev=1,
            info=info,
        )
    pp_sigma_n = 0.0 if principal_point is not None else _PP_TILT_SIGMA_REL
    _level_reading_move_deg(best, segs_px, merge_px)
    _split_tilt_deg(
        best,
        s,
        segs_px,
        merge_px,
        tau,
        f_fixed is None,
        f_prior,
        f_bounds,
        prior_w,
        info.get("cov_rot"),
    )
    best.tilt_rival_deg = rival_tilt
    pitch_std, roll_std = _tilt_std_deg(best, info.get("cov_rot"), pp_sigma_n)
    result = _finish(
        best,
        s,
        segs_px,
        pp,
        scale,
        (w, h),
        f_fixed is None,
        f_bounds,
        min_inlier_share,
        prior_source=focal_prior_source if has_prior else None,
        prior_sigma=prior_sigma if has_prior else None,
    )
    result.distortion_std = k1_std
    if clash is not None:
        assert focal_prior_px is not None
        result.warnings.append(
            f"the {focal_prior_source} focal length ({focal_prior_px:.0f} px +/- "
            f"{100 * prior_sigma:.0f} %) and the photo's own lines ({clash[0]:.0f} px +/- "
            f"{100 * clash[1]:.0f} %) disagree by {100 * (math.exp(clash[2]) - 1):+.0f} % "
            "(a maker's tag can be wrong, or the lines mislead): both readings are kept, "
            f"{result.focal_px:.0f} px +/- {100 * result.focal_std_rel:.0f} %; give "
            "--focal-px if it is known"
        )
    result.pitch_std_deg, result.roll_std_deg = pitch_std, roll_std
    result.focal_std_parts = dict(best.sigma_parts)
    result.line_residual_rms_px = best.residual_rms_px
    result.line_scatter_deg = best.scatter_deg
    if best.horizon_rests_on:
        result.warnings.append(
            f"no vertical line: the horizon rests on {best.horizon_rests_on} lines of one "
            f"horizontal direction (a car, a guard rail or shadows may pose as one): roll "
            f"+/- {roll_std:.1f} degrees, pitch +/- {pitch_std:.1f}"
        )
    if k1_est:
        result.segments = segs_photo
        result.distortion = k1_est
        if k1_move > _K1_MOVE_WARN:
            result.warnings.append(
                f"the lens distortion fitted (k1 = {k1_est:+.3f}) moves the focal length by "
                f"{100 * math.expm1(k1_move):.0f} % from the straight-lens reading (k1 = 0), "
                "which the sigma includes: edges that are not straight can pose as lens "
                "distortion; "
                "give --distortion 0 for a phone (which corrects its lens), or "
                "--distortion K1 or --focal-px if known"
            )
    if distortion_k1:
        n_ax = len(segs_px) - len(segs_photo)  # annotated axes are not distorted pixels
        result.segments = np.vstack([segs_px[:n_ax], segs_photo]) if n_ax else segs_photo
        result.distortion = float(distortion_k1)
    result.warnings[:0] = exif_warnings
    return result


def _prepare_hints(
    axes_hint: Sequence[tuple[npt.ArrayLike, npt.ArrayLike]] | None,
    pp: FloatArray,
    scale: float,
) -> tuple[FloatArray, FloatArray] | None:
    """Hint axes as normalised origins ``(K, 2)`` and unit directions ``(K, 2)``."""
    if not axes_hint:
        return None
    if len(axes_hint) > 3:
        raise InputError(f"axes_hint: at most 3 axes, got {len(axes_hint)}")
    origins, units = [], []
    for i, (o, e) in enumerate(axes_hint):
        o_arr = np.asarray(o, dtype=np.float64).reshape(-1)
        e_arr = np.asarray(e, dtype=np.float64).reshape(-1)
        if o_arr.shape != (2,) or e_arr.shape != (2,):
            raise InputError(f"axes_hint[{i}]: origin and end must be [x, y] pixels")
        d = e_arr - o_arr
        n = float(np.hypot(*d))
        if not (np.all(np.isfinite(d)) and n > 1e-9):
            raise InputError(f"axes_hint[{i}]: origin and end must be distinct finite pixels")
        origins.append((o_arr - pp) / scale)
        units.append(d / n)
    return np.array(origins), np.array(units)


def _hint_factor(
    dirs: FloatArray, f_n: FloatArray, hints: tuple[FloatArray, FloatArray], sigma_deg: float = 5.0
) -> FloatArray:
    """``(H,)`` agreement of hypotheses with hint axes, each axis to its own VP."""
    origins, units = hints
    vps = dirs.copy()
    vps[..., 0] *= f_n[:, None]
    vps[..., 1] *= f_n[:, None]
    # (H, K hints, 3 VPs): image direction towards each VP at each hint's origin
    dx = vps[:, None, :, 0] - vps[:, None, :, 2] * origins[None, :, 0, None]
    dy = vps[:, None, :, 1] - vps[:, None, :, 2] * origins[None, :, 1, None]
    cross = np.abs(units[None, :, 0, None] * dy - units[None, :, 1, None] * dx)
    sin = cross / (np.hypot(dx, dy) + 1e-12)
    ang = np.degrees(np.arcsin(np.clip(sin, 0.0, 1.0)))
    k = ang.shape[1]
    best = np.full(len(dirs), np.inf)
    for perm in itertools.permutations(range(3), k):
        total = sum(ang[:, i, perm[i]] ** 2 for i in range(k))
        best = np.minimum(best, total)
    # beyond 30 degrees per axis a hypothesis simply disagrees; the image decides then
    best = np.minimum(best, k * 30.0**2)
    return np.asarray(np.exp(-0.5 * best / sigma_deg**2), dtype=np.float64)


def _vertical_cost(dirs: FloatArray) -> FloatArray:
    """How unlikely each direction is to be the world's vertical (degrees-like cost).

    The angle between the direction and the image's vertical axis, plus a penalty for
    the camera looking up by more than 20 degrees were it the vertical: a camera pitched
    down 50 degrees (a mast-mounted street camera) and one pitched up 40 degrees see the
    same Manhattan frame; the first is the likelier.
    """
    ay = np.clip(np.abs(dirs[:, 1]), 0.0, 1.0)
    angle = np.degrees(np.arccos(ay))
    up = dirs * -np.sign(dirs[:, 1:2] + 1e-300)  # each candidate pointing image-up
    pitch = np.degrees(np.arcsin(np.clip(-up[:, 2], -1.0, 1.0)))
    return np.asarray(angle + np.maximum(0.0, -pitch - 20.0), dtype=np.float64)


def _vertical_index(
    dirs: FloatArray, n_lines: Sequence[int] | None = None
) -> tuple[int, bool, int]:
    """Which of three directions (rows) is the world's vertical.

    The likeliest by :func:`_vertical_cost` (a prior: near the image's vertical axis, and
    rather looking down than up steeply). But where another direction could be the
    vertical too (within :data:`_VERTICAL_CANDIDATE_DEG` of the image's vertical axis, and
    tilting the camera by at most :data:`_VERTICAL_RIVAL_TILT_DEG` more: looking up 50
    degrees at a building and looking down 40 degrees see the same frame), the one
    supported by at least :data:`_VERTICAL_SUPPORT_RATIO` times as many distinct lines
    wins: a building's edges are many, while the other reading would rest on a few roof
    slopes, paving joints or a side wall's courses. That is then not a clear
    identification. Beyond that tilt (looking up 55-60 degrees, read as looking down
    30-35) the prior stands, unless its vertical has fewer than :data:`_MIN_SUPPORT`
    distinct lines, and the ambiguity is only stated. A rival that would roll the camera
    more than :data:`_ROLL_MARGIN_DEG` beyond the likeliest reading does not win
    (:func:`_rolls_more`).

    Returns
    -------
    index, whether it is identified clearly, and the runner-up's index.
    """
    cost = _vertical_cost(dirs)
    order = np.argsort(cost, kind="stable")
    kv, k2 = int(order[0]), int(order[1])
    identified = bool(cost[k2] - cost[kv] > _VERTICAL_MARGIN_DEG)
    if n_lines is None:
        return kv, identified, k2
    angle = np.degrees(np.arccos(np.clip(np.abs(dirs[:, 1]), 0.0, 1.0)))
    rivals = [
        k
        for k in range(3)
        if k != kv
        and angle[k] < _VERTICAL_CANDIDATE_DEG
        and n_lines[k] >= _VERTICAL_SUPPORT_RATIO * max(1, n_lines[kv])
        # a vertical with hardly any lines of its own does not hold against them
        and (angle[k] < angle[kv] + _VERTICAL_RIVAL_TILT_DEG or n_lines[kv] < _MIN_SUPPORT)
        and not _rolls_more(dirs, k, kv)
    ]
    if rivals:
        k_new = max(rivals, key=lambda k: n_lines[k])
        return k_new, False, kv
    # a comparably supported reading that pitches the camera less than 60 degrees
    near = [k for k in range(3) if k != kv and angle[k] < 60.0 and 2 * n_lines[k] >= n_lines[kv]]
    if near and identified:
        return kv, False, near[0]
    return kv, identified, k2


def _rolls_more(dirs: FloatArray, k: int, kv: int) -> bool:
    """Whether reading direction ``k`` as the vertical rolls the camera by more than
    :data:`_ROLL_MARGIN_DEG` beyond reading ``kv`` so.

    Cameras rarely roll (webcams are mounted level, photos are held level); a rival reading
    that needs a roll the kept one does not is no evidence for itself. (Lane markings seen
    from a street camera looking down at a road at an angle converge off the image's
    vertical axis; a facade's verticals seen looking up do not.)

    Parameters
    ----------
    dirs
        ``(3, 3)`` unit directions (rows) in the camera frame.
    k, kv
        Indices of the rival and of the kept reading.
    """
    roll_k = abs(pitch_roll_from_up(_up_sign(dirs[k]))[1])
    roll_kv = abs(pitch_roll_from_up(_up_sign(dirs[kv]))[1])
    return roll_k > roll_kv + _ROLL_MARGIN_DEG


def _steep_up_rival(dirs: FloatArray, n_lines: Sequence[int], kv: int) -> int | None:
    """A better-supported direction that would make the camera look up steeply, or None.

    Looking up 60 degrees at a facade and looking down 30 degrees at a street see the same
    Manhattan frame; :func:`_vertical_index` keeps the likelier reading (looking down)
    unless the other tilts the camera little more. Where the kept vertical has fewer than
    :data:`_FEW_LINES` distinct lines and the rival :data:`_VERTICAL_SUPPORT_RATIO` times as
    many (and at least :data:`_WEAK_LINES`), the prior alone decided: the caller says so.
    (A level camera down a corridor or a street, its verticals many, is left alone: the
    street's lines would have it look up 75-90 degrees.) A rival that would roll the camera
    more than :data:`_ROLL_MARGIN_DEG` beyond the kept reading is not counted
    (:func:`_rolls_more`: a street camera's lane markings, seen at an angle).

    Parameters
    ----------
    dirs
        ``(3, 3)`` unit directions (rows) in the camera frame.
    n_lines
        Distinct lines of each direction.
    kv
        Index of the direction taken as the vertical.
    """
    kept_pitch = pitch_roll_from_up(_up_sign(dirs[kv]))[0]
    best: int | None = None
    for k in range(3):
        if k == kv:
            continue
        pitch = pitch_roll_from_up(_up_sign(dirs[k]))[0]
        if (
            -_STEEP_UP_MAX_DEG < pitch <= -_STEEP_UP_MIN_DEG < kept_pitch
            and n_lines[kv] < _FEW_LINES
            and n_lines[k] >= max(_WEAK_LINES, _VERTICAL_SUPPORT_RATIO * max(1, n_lines[kv]))
            and not _rolls_more(dirs, k, kv)
            and (best is None or n_lines[k] > n_lines[best])
        ):
            best = k
    return best


def _n_distinct_lines(segs: FloatArray, merge_px: float = 4.0) -> int:
    """Number of distinct straight lines among segments (greedy, longest first)."""
    groups = _line_groups(segs, merge_px)
    return int(groups.max()) + 1 if len(groups) else 0


def _line_groups(segs: FloatArray, merge_px: float = 4.0) -> npt.NDArray[np.int64]:
    """The distinct straight line (0, 1, ...) each segment lies on (greedy, longest first:
    a segment joins the first longer one it is collinear with, within ``merge_px`` and 3
    degrees)."""
    groups = np.full(len(segs), -1, dtype=np.int64)
    if len(segs) == 0:
        return groups
    p1, p2 = segs[:, :2], segs[:, 2:]
    d = p2 - p1
    ln = np.hypot(d[:, 0], d[:, 1])
    u = d / ln[:, None]
    mid = 0.5 * (p1 + p2)
    n = 0
    for i in np.argsort(-ln):
        if groups[i] >= 0:
            continue
        rel = mid - mid[i]
        dist = np.abs(u[i, 0] * rel[:, 1] - u[i, 1] * rel[:, 0])
        same = (dist < merge_px) & (np.abs(u @ u[i]) > math.cos(math.radians(3.0)))
        groups[same & (groups < 0)] = n
        n += 1
    return groups


def _focal_prior(f_n: FloatArray, f_prior: float, sigma: float = _F_PRIOR_SIGMA) -> FloatArray:
    """Log-normal preference for the prior focal length (mild by default: near ties only)."""
    return np.asarray(np.exp(-0.5 * (np.log(f_n / f_prior) / sigma) ** 2), dtype=np.float64)


def _same_frame(Ra: FloatArray, Rb: FloatArray, tol_deg: float = 3.0) -> bool:
    c = np.abs(Ra.T @ Rb)  # |cos| between all pairs of directions
    return bool(np.all(c.max(axis=1) > math.cos(math.radians(tol_deg))))


def _fit(
    R0: FloatArray,
    f0: float,
    s: _Segs,
    tau: float,
    f_free: bool,
    f_prior: float,
    f_bounds: tuple[float, float],
    rounds: int = 3,
    labels0: npt.NDArray[np.int64] | None = None,
    prior_w: float | None = None,
) -> _Model:
    R, f = R0, f0
    logf_std = float("nan")
    if labels0 is None:
        labels, score = _labels(R, f, s, 2.0 * tau, 5.0)
    else:
        labels, score = labels0, 0.0
    for _ in range(rounds):
        if np.count_nonzero(labels >= 0) < 4:
            break
        R, f, logf_std, _ = _refine(
            R, f, s, labels, tau, f_free, f_prior, f_bounds, prior_w=prior_w
        )
        new_labels, score = _labels(R, f, s, tau * _LABEL_TAU, _LABEL_ANGLE_DEG)
        if np.array_equal(new_labels, labels):
            break
        labels = new_labels
    # re-orthonormalise against numerical drift
    U, _, Vt = np.linalg.svd(R)
    R = U @ Vt
    return _Model(R=R, f_n=f, labels=labels, score=score, logf_std=logf_std)


def _finish(
    m: _Model,
    s: _Segs,
    segs_px: FloatArray,
    pp: FloatArray,
    scale: float,
    size: tuple[int, int],
    f_free: bool,
    f_bounds: tuple[float, float],
    min_inlier_share: float,
    prior_source: str | None = None,
    prior_sigma: float | None = None,
) -> AutoVPResult:
    dirs = m.R.T.copy()  # rows
    support = np.array([s.weight[m.labels == k].sum() for k in range(3)])
    counts = np.array([np.count_nonzero(m.labels == k) for k in range(3)])
    # Count distinct lines (both edges of a drawn line, or a broken edge, are one line).
    merge_px = max(4.0, 0.01 * math.hypot(*size))
    distinct = np.array([_n_distinct_lines(segs_px[m.labels == k], merge_px) for k in range(3)])
    srt = np.sort(distinct)[::-1]
    if srt[1] < _MIN_SUPPORT:
        raise NotEnoughStructureError(
            "not enough structure: fewer than two line directions are supported by "
            f"{_MIN_SUPPORT} or more distinct lines (support {srt.tolist()})"
        )
    kv, vertical_identified, k_alt = _vertical_index(dirs, [int(x) for x in distinct])
    k_steep = _steep_up_rival(dirs, [int(x) for x in distinct], kv)
    if k_steep is not None:
        vertical_identified, k_alt = False, k_steep
    others = [k for k in range(3) if k != kv]
    others.sort(key=lambda k: -support[k])
    perm = [kv, *others]
    alt_pitch = pitch_roll_from_up(_up_sign(dirs[k_alt]))[0]
    dirs = dirs[perm]
    if dirs[0, 1] > 0:  # up points to image-up (-y)
        dirs[0] = -dirs[0]
    for k in (1, 2):
        if dirs[k, 2] < 0 or (dirs[k, 2] == 0 and dirs[k, 0] < 0):
            dirs[k] = -dirs[k]
    inv = np.full(4, -1, dtype=np.int64)
    for new, old in enumerate(perm):
        inv[old] = new
    labels = np.where(m.labels >= 0, inv[np.clip(m.labels, 0, 2)], -1)
    counts = counts[perm]
    support = support[perm]

    f_px = m.f_n * scale
    K = np.array([[f_px, 0.0, pp[0]], [0.0, f_px, pp[1]], [0.0, 0.0, 1.0]])
    vps = (K @ dirs.T).T
    pitch, roll = pitch_roll_from_up(dirs[0])
    pp_t = (float(pp[0]), float(pp[1]))
    horizon = horizon_from_up(dirs[0], f_px, pp_t)

    # Confidence: share of segment length explained, number of supporting segments,
    # and, when estimated, how well the image fixes the focal length.
    explained = float(s.weight[labels >= 0].sum() / s.weight.sum())
    if explained < min_inlier_share:
        raise NotEnoughStructureError(
            f"not enough structure: the vanishing points explain {100 * explained:.0f} % of "
            f"the line segments' length (at least {100 * min_inlier_share:.0f} % needed)"
        )
    # (on York Urban at least 62 % of the segment length is explained; on random lines
    # or blobs 20 to 40 %)
    c_support = float(np.clip((explained - 0.3) / 0.35, 0.0, 1.0))
    c_count = min(1.0, float(srt[1]) / 8.0) * (0.5 + 0.5 * min(1.0, srt.sum() / 20.0))
    c_vert = 1.0 if distinct[perm[0]] >= _MIN_SUPPORT else 0.6
    if k_steep is not None:
        c_vert *= 0.5
    focal_source = "given"
    c_focal = 1.0
    logf_std = m.logf_std
    warnings: list[str] = []
    if f_free:
        lo_b, hi_b = f_bounds
        f_data = m.f_n if math.isnan(m.f_data_n) else m.f_data_n
        at_bound = not (lo_b * 1.02 < f_data < hi_b / 1.02)
        # the photo's own sigma decides whether it fixes the focal length (a default
        # prior, where one was combined, only narrows the stated one)
        data_std = logf_std if math.isnan(m.data_logf_std) else m.data_logf_std
        # How likely the focal length is within 10 %, as the stated sigma says (a default
        # the photo cannot fix is no likelier to be right than its sigma says): the
        # probability of |log error| < log(1.1) under the stated Gaussian.
        c_focal = (
            math.erf(math.log(1.1) / (math.sqrt(2.0) * logf_std))
            if math.isfinite(logf_std) and logf_std > 0
            else (1.0 if logf_std == 0 else 0.02)
        )
        if prior_source is not None:
            focal_source = prior_source
        elif at_bound:
            focal_source = "bound"
            c_focal = min(c_focal, 0.25)
        elif m.weak_only:
            focal_source = "estimated"
            warnings.append(
                f"the focal length rests on a direction of only {m.weak_only} lines (a roof "
                f"slope, paving or shadows may pose as one): +/- {100 * logf_std:.0f} %; give "
                "--focal-px if it is known"
            )
        elif m.rests_on_few:
            focal_source = "estimated"
            c_focal *= 0.5
            warnings.append(
                f"the focal length rests on a direction of only {m.rests_on_few} lines that "
                "pulls it away from the other two (a gable, a side wall or a niche that is "
                f"not square to the rest may pose as one): +/- {100 * logf_std:.0f} %; give "
                "--focal-px if it is known"
            )
        elif m.unchecked_few and math.isfinite(data_std) and data_std <= _PRIOR_ONLY_STD:
            focal_source = "estimated"
            warnings.append(
                f"the focal length rests on two directions alone, one of only "
                f"{m.unchecked_few} lines, and no third direction checks it (a roof slope or "
                f"a gable may pose as a horizontal direction): +/- {100 * logf_std:.0f} %; "
                "give --focal-px if it is known"
            )
        elif not math.isfinite(data_std) or data_std > _PRIOR_ONLY_STD:
            focal_source = "prior"
        else:
            focal_source = "estimated"
        n_finite = sum(abs(float(d[2])) > 0.05 for d in dirs[1:])
        one_finite = n_finite < 2 and abs(float(dirs[0, 2])) < 0.15
        if focal_source in ("bound", "prior"):
            why_default = (
                " (only one horizontal vanishing point is finite and the vertical one lies "
                "far off: a level camera looking along a street or at a facade)"
                if one_finite
                else " (its vanishing points leave it loose: far outside the photo, or few lines)"
            )
            warnings.append(
                f"the photo does not fix the focal length{why_default}: a default was used; "
                "give --focal-px or a photo with EXIF"
            )
        elif (
            math.isfinite(data_std)
            and data_std > _LOOSE_FOCAL_STD
            and not m.weak_only
            and not m.rests_on_few
            and not m.unchecked_few
            and not m.thin_only
        ):
            why = (
                "only one horizontal vanishing point is finite and the vertical one lies far off"
                if one_finite
                else "the vanishing points leave it loose"
            )
            if prior_source is not None and logf_std < data_std:
                # the prior (EXIF) decides: the photo's lines alone would leave it loose
                warnings.append(
                    f"the photo's lines leave the focal length loose (+/- {100 * data_std:.0f} % "
                    f"on their own: {why}); the {prior_source} focal length decides "
                    f"(+/- {100 * logf_std:.0f} %)"
                )
            else:
                warnings.append(
                    f"the focal length is uncertain (+/- {100 * logf_std:.0f} %): {why}; give "
                    "--focal-px if it is known"
                )
    if m.thin_only and f_free:
        warnings.append(
            f"the focal length rests on a direction of {m.thin_only} lines that are pieces of "
            "curves (a round rim, steps or an arch may pose as one): the photo does not fix it "
            f"(+/- {100 * data_std:.0f} % without a default); give --focal-px if it is known"
        )
    c_pairing = 1.0
    if m.third is not None and f_free:
        # Which two horizontal directions are square the lines do not say: the frame's
        # pairing is as likely as its weaker direction's share of the lines the two rival
        # directions hold.
        th = m.third
        c_pairing = th.n_paired / (th.n_paired + th.n_lines)
        f_alt_px = (m.f_n if math.isnan(m.f_data_n) else m.f_data_n) * scale
        f_alt_px *= math.exp(m.third_move)
        warnings.append(
            f"a third horizontal direction ({th.n_lines} lines, against {th.n_paired} of the "
            "weaker one kept): where two buildings stand at an angle or the street bends, the "
            "focal length rests on which two directions are square; paired with the third it "
            f"would be {f_alt_px:.0f} px; give --focal-px if it is known"
        )
    if distinct[perm[0]] < _MIN_SUPPORT:
        warnings.append(
            f"few vertical lines ({int(distinct[perm[0]])}): the vertical direction, pitch and "
            "roll are weakly supported"
        )
    if not vertical_identified:
        warnings.append(
            "another vanishing direction could be the vertical one nearly as well: the "
            f"camera looks {_updown(pitch)} ({int(distinct[perm[0]])} vertical lines), or "
            f"{_updown(alt_pitch)} ({int(distinct[k_alt])} lines); check pitch and roll"
        )
    # The stated sigma holds only if the Manhattan frame is the photo's: with few distinct
    # lines a non-orthogonal facade, a roof slope or paving may have been taken for a
    # direction. Share of such model errors measured on 216 real photos: 17 % with 40-60
    # distinct lines, 4 % with 60-80, none above 80 (benchmarks/vp_real.py).
    c_model = 1.0 - _model_error_chance(float(srt.sum()))
    confidence = float(
        np.clip(c_support * c_count * c_vert * c_focal * c_model * c_pairing, 0.0, 1.0)
    )
    log.debug(
        "confidence parts: explained %.2f distinct %s focal %.2f model %.2f",
        explained,
        distinct.tolist(),
        c_focal,
        c_model,
    )
    log.debug(
        "autovp: f=%.1f px (%s, std %.3f) support=%s explained=%.2f confidence=%.2f",
        f_px,
        focal_source,
        logf_std,
        counts.tolist(),
        explained,
        confidence,
    )
    return AutoVPResult(
        vanishing_points=vps,
        directions_in_cam=dirs,
        focal_px=float(f_px),
        principal_point=pp_t,
        focal_source=focal_source,
        focal_std_rel=float(logf_std),
        pitch_deg=pitch,
        roll_deg=roll,
        horizon=horizon,
        segments=segs_px,
        labels=labels,
        confidence=confidence,
        vertical_identified=vertical_identified,
        image_size=(int(size[0]), int(size[1])),
        n_inliers=(int(counts[0]), int(counts[1]), int(counts[2])),
        n_lines=(int(distinct[perm[0]]), int(distinct[perm[1]]), int(distinct[perm[2]])),
        inlier_share=explained,
        warnings=warnings,
    )


def _default_focal_prior(width_px: float, height_px: float) -> tuple[float, float]:
    """What cameras are, for a frame of this shape: the centre (relative to the longer side)
    and the sigma of ``log(focal)`` of the default prior.

    Parameters
    ----------
    width_px, height_px
        The image's size.

    Returns
    -------
    tuple of float
        :data:`_F_PRIOR_REL` and :data:`_F_DEFAULT_SIGMA` for the common sensor shapes (up
        to :data:`_WIDE_ASPECT`); for wider frames the geometric mean of the two readings
        (the longer side kept; a wide-angle camera whose shorter side spans a 16:9 frame's)
        and :data:`_F_DEFAULT_SIGMA` with half their log-ratio added in quadrature.
    """
    aspect = max(width_px, height_px) / max(min(width_px, height_px), 1e-9)
    if not aspect > _WIDE_ASPECT:
        return _F_PRIOR_REL, _F_DEFAULT_SIGMA
    wide_rel = _WIDE_SHORT_REL / aspect  # relative to the longer side
    half_gap = 0.5 * abs(math.log(_F_PRIOR_REL / wide_rel))
    return math.sqrt(_F_PRIOR_REL * wide_rel), math.hypot(_F_DEFAULT_SIGMA, half_gap)


def _wrong_frame_chance(n_lines: Sequence[int] | None) -> float:
    """The chance that the Manhattan frame is not the photo's, from its distinct lines.

    ``(_MODEL_ERROR_LINES / lines) ** 3``: one less the confidence's model term
    (:func:`_finish`), measured on 40-80 lines; at most :data:`_WRONG_FRAME_MAX` (on fewer
    lines the cube is an extrapolation). 0 where the lines are not counted yet.
    """
    if n_lines is None:
        return 0.0
    return min(_WRONG_FRAME_MAX, _model_error_chance(float(sum(n_lines))))


def _model_error_chance(n_distinct_lines: float) -> float:
    """``(_MODEL_ERROR_LINES / lines) ** 3``, at most 1: the chance of a wrong Manhattan
    frame on so many distinct lines (the confidence's model term is one less it)."""
    return min(1.0, (_MODEL_ERROR_LINES / max(1.0, n_distinct_lines)) ** 3)


def _with_default_prior(
    m: _Model,
    s: _Segs,
    tau: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
    default: tuple[float, float] = (_F_PRIOR_REL, _F_DEFAULT_SIGMA),
    wrong_frame: float = 0.0,
) -> _Model:
    """The photo's focal length combined with the default prior (:data:`_F_DEFAULT_SIGMA`).

    A posterior in ``log(focal)``: the photo's estimate weighs by its stated sigma (least
    squares and the systematic terms), the default (``default``: the centre relative to the
    longer side and the sigma, :func:`_default_focal_prior`; for the common sensor shapes
    :data:`_F_PRIOR_REL` times the longer side and :data:`_F_DEFAULT_SIGMA`). Where the
    focal length moves by more than 0.5 %, the rotation is refitted with the focal length
    held there (the vanishing points and the horizon follow). ``f_data_n`` and
    ``data_logf_std`` keep the photo's own.

    With ``wrong_frame`` = 0 both are Gaussian and so is the posterior. Otherwise the
    photo's reading is, with probability ``wrong_frame``, that of a wrong Manhattan frame
    (a roof slope, paving or a ramp taken for a direction) and says nothing (a uniform
    density over ``f_bounds`` in ``log(focal)``), and Gaussian with its sigma otherwise
    (:data:`_WRONG_FRAME_MIXTURE`). The posterior is then a mixture of the Gaussian blend
    and the prior, weighted by how well each explains the reading: a reading near the
    prior keeps nearly the Gaussian blend, one far from it moves the answer less. The
    answer is the mixture's mean and the stated sigma its standard deviation.
    """
    centre, sigma = default
    sd = m.logf_std if math.isfinite(m.logf_std) and m.logf_std > 0 else math.inf
    w_data = 0.0 if math.isinf(sd) else 1.0 / sd**2
    w_prior = 1.0 / sigma**2
    if not w_data + w_prior > 0.0:
        return m
    var = 1.0 / (w_data + w_prior)
    log_c = math.log(centre)
    log_f = var * (w_data * math.log(m.f_n) + w_prior * log_c)
    std = math.sqrt(var)
    if wrong_frame > 0.0 and w_data > 0.0 and math.isfinite(sigma):
        # evidence of the reading under each part: Gaussian about the prior (the reading's
        # sigma and the prior's), or uniform over the searched range
        s_pred = math.sqrt(sd**2 + sigma**2)
        z = math.log(m.f_n) - log_c
        right = (1.0 - min(wrong_frame, 1.0)) * math.exp(-0.5 * (z / s_pred) ** 2)
        right /= s_pred * math.sqrt(2.0 * math.pi)
        wrong = min(wrong_frame, 1.0) / math.log(f_bounds[1] / f_bounds[0])
        p_right = right / (right + wrong)
        mean = p_right * log_f + (1.0 - p_right) * log_c
        std = math.sqrt(
            p_right * (var + (log_f - mean) ** 2)
            + (1.0 - p_right) * (sigma**2 + (log_c - mean) ** 2)
        )
        log_f = mean
    f_post = min(max(math.exp(log_f), f_bounds[0]), f_bounds[1])
    return _hold_focal(m, f_post, std, s, tau, f_bounds, prior_w)


def _hold_focal(
    m: _Model,
    f_n: float,
    logf_std: float,
    s: _Segs,
    tau: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
) -> _Model:
    """Set ``m``'s focal length to ``f_n`` (sigma ``logf_std`` in ``log(focal)``), its rotation
    refitted with the focal length held there where it moved by more than 0.5 %
    (:func:`_with_default_prior`, :func:`_mix_readings`)."""
    R = m.R
    if abs(math.log(f_n / m.f_n)) > 0.005 and np.count_nonzero(m.labels >= 0) >= 4:
        R, _, _, _ = _refine(
            m.R, f_n, s, m.labels, tau, False, f_n, f_bounds, prior_w=prior_w, max_nfev=20
        )
        U, _, Vt = np.linalg.svd(R)
        R = U @ Vt
    m.R, m.f_n, m.logf_std = R, f_n, logf_std
    return m


def _mix_readings(
    m: _Model,
    reading_a: tuple[float, float],
    reading_b: tuple[float, float],
    s: _Segs,
    tau: float,
    f_bounds: tuple[float, float],
    prior_w: float | None,
) -> _Model:
    """Two readings of the focal length that disagree, stated as an equal mixture.

    ``reading_a`` and ``reading_b`` (each the focal length normalised by the longer side
    and the sigma of ``log(focal)``; here the prior's and the photo's own, without it) each
    weigh one half: the focal length of ``m`` goes to the mixture's mean in ``log(focal)``
    (their geometric mean) and its sigma to the mixture's, ``sqrt((s1^2 + s2^2) / 2 +
    (d / 2)^2)`` for readings ``d`` apart, so that it covers both. The rotation is refitted
    with the focal length held there (as in :func:`_with_default_prior`). Which reading is
    right the photo does not say: equal weights are an assumption.
    """
    (f_a, s1), (f_b, s2) = reading_a, reading_b
    d = math.log(f_b / f_a)
    f_mix = min(max(f_a * math.exp(0.5 * d), f_bounds[0]), f_bounds[1])
    std = math.sqrt(0.5 * (s1**2 + s2**2) + (0.5 * d) ** 2)
    return _hold_focal(m, f_mix, std, s, tau, f_bounds, prior_w)


def _updown(pitch_deg: float) -> str:
    """``"down 40 degrees"`` / ``"up 50 degrees"`` for a pitch (positive looking down)."""
    return f"{'down' if pitch_deg >= 0 else 'up'} {abs(pitch_deg):.0f} degrees"


# --------------------------------------------------------------------- axis helper


def segments_for_axis(
    res: AutoVPResult,
    origin_px: npt.ArrayLike,
    end_px: npt.ArrayLike,
    min_segments: int = 2,
    *,
    max_angle_deg: float = 10.0,
) -> FloatArray:
    """Segments of the vanishing point that an annotated axis points at.

    Parameters
    ----------
    res
        Result of :func:`detect_vanishing_points`.
    origin_px, end_px
        The axis as annotated, e.g. a car's ground corner and the end of its length edge.
    min_segments
        Fewest segments to return.
    max_angle_deg
        Largest angle between the axis and the image direction, at ``origin_px``,
        towards the vanishing point.

    Returns
    -------
    numpy.ndarray
        ``(M, 4)`` segments ``x1, y1, x2, y2`` supporting that vanishing point.

    Raises
    ------
    NotEnoughStructureError
        No vanishing point within ``max_angle_deg`` of the axis, two of them equally
        close, or fewer than ``min_segments`` segments support it.
    """
    o = np.asarray(origin_px, dtype=np.float64).reshape(2)
    e = np.asarray(end_px, dtype=np.float64).reshape(2)
    axis = e - o
    if not (np.all(np.isfinite(axis)) and np.hypot(*axis) > 1e-9):
        raise InputError("axis origin and end must be two distinct finite pixels")
    axis = axis / np.hypot(*axis)
    angles = np.full(3, np.inf)
    for k, v in enumerate(res.vanishing_points):
        d = v[:2] - v[2] * o
        n = float(np.hypot(*d))
        # Skip a VP that lies (nearly) on the origin: no direction there.
        if n <= 1e-9 * max(1.0, float(np.linalg.norm(v))) or (v[2] != 0 and n / abs(v[2]) < 1.0):
            continue
        c = abs(float(axis @ d) / n)
        angles[k] = math.degrees(math.acos(min(1.0, c)))
    order = np.argsort(angles)
    k = int(order[0])
    if not angles[k] <= max_angle_deg:
        raise NotEnoughStructureError(
            f"not enough structure: no vanishing point within {max_angle_deg:g} deg of the "
            f"axis (closest {angles[k]:.1f} deg)"
        )
    second = float(angles[order[1]])
    if second <= max_angle_deg and second - angles[k] < 2.0:
        raise NotEnoughStructureError(
            "not enough structure: the axis is ambiguous between two vanishing points "
            f"({angles[k]:.1f} and {second:.1f} deg)"
        )
    segs = res.segments[res.labels == k]
    if len(segs) < min_segments:
        raise NotEnoughStructureError(
            f"not enough structure: {len(segs)} segments support the axis' vanishing point "
            f"({min_segments} needed)"
        )
    return np.asarray(segs, dtype=np.float64)


# ------------------------------------------------------------------------- drawing


def draw_segments(
    image: str | os.PathLike[str] | npt.NDArray[Any],
    res: AutoVPResult,
    out_path: str | os.PathLike[str],
) -> None:
    """Write a PNG of the image with segments coloured by vanishing point.

    Red: vertical, green: horizontal-1, blue: horizontal-2, grey: outliers; the horizon
    is drawn in yellow. A legend in the top-left corner names the colours and which
    horizontal vanishing point is taken for the street (:attr:`AutoVPResult.street_index`).
    """
    import cv2

    gray = load_image(image)
    canvas = cv2.cvtColor((gray // 2 + 64).astype(np.uint8), cv2.COLOR_GRAY2BGR)
    colours = {-1: (160, 160, 160), 0: (0, 0, 255), 1: (0, 200, 0), 2: (255, 64, 0)}
    shift = 4  # sub-pixel drawing
    for seg, lab in zip(res.segments, res.labels, strict=True):
        p = np.rint((seg - 0.5) * (1 << shift)).astype(np.int64)
        cv2.line(
            canvas,
            (int(p[0]), int(p[1])),
            (int(p[2]), int(p[3])),
            colours[int(lab)],
            1 if lab < 0 else 2,
            cv2.LINE_AA,
            shift,
        )
    ep = res.horizon_endpoints
    if ep is not None and all(math.isfinite(c) and abs(c) < 1e6 for pt in ep for c in pt):
        cv2.line(
            canvas,
            (round(ep[0][0]), round(ep[0][1])),
            (round(ep[1][0]), round(ep[1][1])),
            (0, 220, 255),
            1,
            cv2.LINE_AA,
        )
    # Legend: what each colour is, with the role of each horizontal vanishing point.
    names = {1: "horizontal-1", 2: "horizontal-2"}
    names[res.street_index] += " (street)"
    names[3 - res.street_index] += " (across)"
    # A direction no line supports was drawn in the legend as if seen: it is implied by the
    # other two and the focal length (orthogonality), so the legend says so (stop 42, qa6).
    vnames = {0: "vertical", 1: names[1], 2: names[2]}
    for k in range(3):
        if int(res.n_inliers[k]) == 0:
            vnames[k] += ": no lines, implied"
    entries = [
        ((0, 0, 255), vnames[0]),
        ((0, 200, 0), vnames[1]),
        ((255, 64, 0), vnames[2]),
        ((160, 160, 160), "outliers"),
        ((0, 220, 255), "horizon"),
    ]
    h_img = canvas.shape[0]
    fs = max(0.35, min(1.2, h_img / 1000.0))
    line_h = round(22 * fs / 0.5)
    text_w = max(
        cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, fs, 1)[0][0] for _, text in entries
    )
    box_w = max(round(250 * fs / 0.5), 16 + line_h + text_w + 8)
    cv2.rectangle(canvas, (4, 4), (4 + box_w, 8 + line_h * len(entries)), (0, 0, 0), -1)
    for i, (col, text) in enumerate(entries):
        y = 4 + line_h * (i + 1) - line_h // 3
        cv2.line(canvas, (10, y), (10 + line_h, y), col, 2, cv2.LINE_AA)
        cv2.putText(
            canvas,
            text,
            (16 + line_h, y + line_h // 4),
            cv2.FONT_HERSHEY_SIMPLEX,
            fs,
            (255, 255, 255),
            1,
            cv2.LINE_AA,
        )
    ok = cv2.imwrite(str(out_path), canvas)
    if not ok:
        raise InputError(f"cannot write {str(out_path)!r}")
