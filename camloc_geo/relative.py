"""Relative pose: from a scene's annotations to the camera in the object's world frame.

Two stages, both reported:

1. **Per-annotator closed form** (the paper). For each annotator: a vanishing point per
   axis from their segments, intrinsics from the vanishing points
   (:func:`camloc_geo.vanishing.estimate_intrinsics`), the rotation from the vanishing
   directions with signs fixed by the annotated axes, and the translation from the origin
   pixel and one known dimension, solved separately with the length end and with the width
   end (the paper's two estimates) and with the height end as a check. All candidates are
   clustered by distance; the largest cluster's centroid is the paper's answer.
2. **Joint robust fit** (bundle adjustment). One pose and focal length fitted to every
   annotator's segments and axis pixels at once (Levenberg-Marquardt)
   and a soft-L1 loss, annotators re-weighted by their residuals (iteratively reweighted,
   Cauchy weights) so that a careless one is down-weighted and reported, and one who marked
   another corner of the car is re-interpreted (their clicks are that corner's edges).
   The principal point is fixed (given, else the image centre) unless freeing it improves
   the fit by more than the BIC penalty. The covariance of the fit gives uncertainties.

Noise model used for weighting (and documented for the benchmarks): a clicked point is
off by ``sigma_point_px`` (default 0.15 % of the image diagonal, 3.3 px at 1080p), a drawn
segment's endpoints by ``sigma_line_px`` (0.1 %), and a preset object's size is off by
``size_sigma_rel`` (5 %, added to the position uncertainty when the size is a preset).
"""

from __future__ import annotations

import copy
import functools
import logging
import math
import re
import threading
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from camloc_geo._errors import DegenerateGeometryError, InputError, SceneError
from camloc_geo._optimize import soft_l1_cost
from camloc_geo.camera import Camera, rotvec_from_rotation
from camloc_geo.objects import PRESETS, ObjectSize
from camloc_geo.scene import Annotation, Scene, line_photo, pixel_problem
from camloc_geo.vanishing import (
    AXES,
    IntrinsicsEstimate,
    VanishingPoint,
    _vector_norm,
    direction_sign,
    estimate_intrinsics,
    fit_vanishing_point,
    rotation_from_vanishing_directions,
    segment_residuals_px,
)

if TYPE_CHECKING:
    from pathlib import Path

    from camloc_geo._optimize import LeastSquaresResult

__all__ = [
    "AnnotatorSolution",
    "CalibrationResult",
    "CalibrationSettings",
    "calibrate",
    "implausibility",
    "solve_annotator",
]

log = logging.getLogger(__name__)
FloatArray = npt.NDArray[np.float64]

_AXIS_INDEX = {"length": 0, "width": 1, "height": 2}


@dataclass(frozen=True)
class CalibrationSettings:
    """Tuning of :func:`calibrate`; the defaults are what the benchmarks measure.

    Attributes
    ----------
    joint_fit
        Run the joint robust fit (else the paper's cluster centroid is the answer).
    sigma_point_rel, sigma_line_rel
        Annotation noise, as fractions of the image diagonal.
    size_sigma_rel
        Relative error of a preset object size (added to the uncertainty).
    preset_shape
        Where the size is a preset's, its length, width and height are each off by
        ``size_sigma_rel``, the same for every annotator: the focal length's, principal
        point's and rotation's move under each (:func:`_size_shape_sensitivity`) enters
        their sigmas as a consider covariance. False: not (the old sigmas).
    focal_profile_flat
        The fit is always repeated with the focal length held 2 sigmas either side
        (:func:`_focal_profile_widening`); where that fits the annotations *better* (a local
        minimum) the focal sigma is widened x3 and a warning says so. True: also where the
        cost rises less than a 2-sigma step should (a flat side), the sigma is widened to
        that side's log-normal half-width (off by default: it changes other terms' tests).
    focal_prior_width, focal_prior_sigma_log
        A weak log-normal prior on the focal length: median ``focal_prior_width`` image
        widths (0.75: a 67° horizontal field of view), ``focal_prior_sigma_log`` its spread
        in natural log units (0.5: a factor 1.65 at one sigma, so 35-110° lie within one
        sigma). It is used only where the annotations alone leave the focal length loose
        (its 1-sigma relative uncertainty above ``focal_prior_when_sigma_log``, 10 %: a
        vanishing point near infinity), so well-determined fits are unbiased; 0 turns it off.
    focal_prior_when_sigma_log, focal_prior_basin_widths
        When the prior is used: the focal length's relative 1-sigma above the first, or a
        focal length above the second (image widths) that a fit started at the prior's
        focal length beats in a MAP comparison (see ``_focal_prior``).
    cluster_threshold_rel, cluster_threshold_min_m
        Candidates closer than ``max(min_m, rel × median camera distance)`` are linked.
    outlier_weight
        Annotators whose final weight falls below this are reported as outliers.
    principal_point_sigma_rel
        How far a real camera's principal point may lie from the image centre (1-sigma per
        axis, fraction of the diagonal; 0.7 %: 15 px at 1080p). Where the fit assumes the
        centre, this uncertainty is propagated into every sigma of
        :class:`CalibrationResult` (and its ``parameter_covariance``); 0 turns it off.
    jackknife, jackknife_method
        Add the leave-one-annotator-out spread to the uncertainty (2-12 annotators; the
        photo's lines, where they joined the fit, are left out in turn as one more group).
        ``one_step``: per left-out annotator, the Newton step of the infinitesimal
        jackknife from the joint solution and one Gauss-Newton step more, on the fit's own
        residuals and Jacobian (no refits; ~2 ms; all six of the position's and rotation's
        sigmas within 10 % of the refits' in 100 % of 20 crowd scenes,
        ``benchmarks/calibrate_speed.py``); ``refit``: the whole calibration repeated
        without each annotator (the reference, ~5x one fit). Both scale the moves by the
        leverage correction below (the refits since stop 40).
    jackknife_leverage, jackknife_leverage_max_move
        Scale each leave-out's move by its annotator's leverage
        (:func:`_leverage_factors`, the "CR2" correction of the delete-one jackknife, which
        over-states the spread of an answer resting unevenly on its annotators); on by
        default since stop 38. The factor is the normal equations' at the joint solution: a
        leave-out that moves the focal length or the camera's distance from the car by more
        than ``jackknife_leverage_max_move`` (10 %) keeps its whole move (the guard, for a
        move beyond that linearisation). Crowd set (seed 7, 240 scenes): focal 1 sigma
        82 -> 80 %, median error/sigma 0.50 -> 0.56; ``benchmarks/README.md``,
        calibrate_coverage. Stop 40 measured the factor where such leave-outs land: 1.05x
        the joint solution's (median), so the guard widens what the correction would state
        (crowd focal 1 sigma 81 -> 82 %, 4 development seeds); it stays because without it
        slips whose sigma it widens look sure (crowd_slips confidently wrong 15 -> 19 of
        3,360; ``inf`` turns it off).
    car_class_prior
        Where the size is a car preset's, the prior odds (per other preset) that the car is of
        that class instead. Each class whose proportions fit the clicked box better than the
        stated one's gets its posterior weight (:func:`_class_mixture`), and the answer's
        move were it that car enters the stated sigmas with that weight. An SUV whose clicks
        look like a sedan's within their noise is then no longer stated with a sedan's
        sigmas (``crowd_slips`` ``roof_suv``, 4 development seeds x 40 scenes: confidently
        wrong 10 -> 3). 0 turns it off (stop 37's sigmas); a clearly better class is still
        warned by name (``_likely_class``).
    ground_corner_sigma_rel
        Where on a rounded body the car's clicks fall: the ground corner is the ground under
        the body's corner (bumper), but annotators also click the tyre contact, 0.5-1 m
        inside. Each of the car's four clicks gets this 1-sigma (a fraction of the car's
        length along its length edge and of its width along its width edge; 2.5 %: 11 cm and
        4.5 cm for a sedan), in pixels that fraction of the clicked edges; the parameters'
        move under it enters the stated sigmas as a consider covariance
        (:func:`_ground_corner_sensitivity`), scaled by the evidence for it: the clicks'
        scatter beyond the annotators' own precision on their lines, clipped to
        ``[0.1, 1]`` of the term (:func:`_ground_corner_evidence`); 0 turns it off.
    ground_corner_click_ratio
        How much less precise than a line end the ground-corner evidence takes a click to
        be (a ratio of sigmas): the clicks' scatter is an offset only beyond this many
        times the line ends' own. None (default): the settings' own ratio,
        ``sigma_point_rel / sigma_line_rel`` (1.5); 1.0: stop 41's comparison at equal
        precision, which counted the clicks' assumed extra noise as corner offsets (crowd
        set, ``benchmarks/README.md``, stop 42: the stated sigmas within a point, no
        estimate moved).
    car_line_sigma_deg, car_line_share_warn, car_line_axes
        The car's own lines (both ends on the car box's image outline) are, on a rounded
        body, silhouettes of curved surfaces: they read a few degrees off the car's axes,
        all the lines of one face the same way, which no residual shows. Where one face of
        the car carries at least ``car_line_share_warn`` of what an axis' lines decide
        (:func:`_car_line_sensitivity`; only the axes in ``car_line_axes``), a warning
        names the axis and the shared 3-D direction error of each face's lines of that
        axis (1-sigma ``car_line_sigma_deg`` toward each of the two other axes; 3°: what
        the rear faces of the hand-annotated York Urban taxi and Corolla need, 2.0-4.1°)
        enters the stated sigmas as a consider covariance. ``car_line_sigma_deg`` 0 turns
        the term off (the warning stays). The height axis is left out by default: no real
        car's uprights were measured; tumblehome leans a face's two sides toward each other
        (their lines meet above the car, not a shared turn, which this term does not
        describe); and the synthetic box's corner edges would trip it on 23 % of the high
        street cameras of ``tests/test_calibrate_traffic.py``.
    variance_groups
        The fit's own covariance with one residual variance factor per group of rows (the
        segments, the car's corner clicks, its edge-end clicks) instead of one pooled factor
        (:func:`_fit_covariance`); the estimator stays the fit's, so the covariance is the
        sandwich. Every row keeps the pooled factor where a group has too little redundancy
        for its own (one annotator: the clicks' misfit is then the only sign of a leaning
        line) or where the clicked box is not the stated car's (the proportions disagree,
        or another class fits better: the misfit is the model's). With it, the car-class
        mixture weighs the clicked box's proportions with the clicks' measured noise
        (:meth:`_Proportions.with_click_scale`). Off by default: on the crowd set it moves
        the stated focal coverage 82 -> 81 % (the pooled factor is not what over-covers
        there), and the pooled factor lets the clicks' misfit widen what the lines decide,
        which keeps a loose calibration and a few slips from looking sure (stop 42: the
        absolute benchmark's Andorra scene, 32 % short, stated 17 % -> 14.6 % and no longer
        warned; ``crowd_slips`` roof_suv seed 11 scene 0; benchmarks/README.md).
    discordant_line_t, discordant_line_move
        An annotator's line that carries its axis pulls the fit onto itself, so its own
        residual stays small (a height line 9° off, its axis' only long line: residual 0.3
        line sigmas, the focal length +11.7 % at a stated 5 %). With its leverage ``h`` taken
        out, its studentized residual ``r / (s √(1 − h))`` (``s²`` the segments' variance
        factor) shows the disagreement. Where that exceeds ``discordant_line_t`` (3) and the
        line's removal (the linear deleted-row move, then a refit without it) shifts the
        focal length or the camera's height by more than ``discordant_line_move`` (1) of
        their stated sigmas, a warning names the line and its annotator, and the refit's move
        enters the stated sigmas (and ``parameter_covariance``) at one sigma: with or without
        the line, both answers are within them (:func:`_widen_for_discordant_lines`).
        ``crowd_slips`` nonparallel_line, 4 seeds x 40: confidently wrong 7 -> 4; 10 of 239
        clean crowd scenes are named (a sloppy annotator's long line). 0 for either turns the
        check off.
    photo_lines
        Where the scene carries its photo (``image.path``), segments detected in it
        (:mod:`camloc_geo.autovp`) that agree with the annotators' fit (within
        ``PHOTO_SEGMENT_TOL`` line sigmas of one axis' vanishing point, and clearly off the
        others) join the final fit with a small weight: each at ``PHOTO_SEGMENT_SIGMA``
        line sigmas, per axis at most as much as the annotators' average lines of that axis
        count, under the fit's robust loss (:func:`_add_photo_segments`). The jackknife
        leaves the photo's lines out in turn like one more annotator (they share their
        biases), so the stated sigmas include how much the answer leans on them. Lines that
        disagree are not used (a clear disagreement is a warning); False: never. Also where
        the annotations cannot fix the focal length: the photo's trustworthy one is used
        (:func:`calibrate`); False: the refusal stands.
    video_lines
        Witness segments of the scene's video (a ``VideoLines`` of
        :func:`camloc_geo.sensors._video_lines.video_lines`: the moving vehicles' tracks
        and edges, grouped by their own vanishing points; ``calibrate_scene(video=...)``
        reads it). Each
        group whose point is nearest one of the fit's axes (within ``PHOTO_AXIS_NEAR_DEG``)
        and whose segments agree with that axis' vanishing point (median residual within
        ``VIDEO_AGREE`` line sigmas) joins the final fit, each segment at
        ``VIDEO_SEGMENT_SIGMA`` line sigmas, the street group's tracks held to a direction
        known to ``VIDEO_DIRECTION_FLOOR_DEG`` (:func:`_video_direction_floor`), the edge
        groups to at most as much as ``VIDEO_GROUP_CAP`` annotators say on that axis by
        their number of lines (:func:`_video_group_widening`), under the fit's robust loss
        (:func:`_add_video_segments`). A group that clearly disagrees is a warning and is
        not used. The jackknife leaves the video's segments out in turn as one more group
        (like the photo's). None (default): no video.
    principal_point_prior_sigma_rel
        When the principal point is fitted (``free_principal_point``), a Gaussian prior
        holds it near the image centre with this 1-sigma, a fraction of the image diagonal
        (3 %: 66 px at 1080p; cameras crop little, and a freed principal point otherwise
        trades off against the focal length); 0 turns it off. Where the lines fit better
        than the noise model (residual variance factor ``s² < 1``) the prior is widened by
        ``1/s``, as the posterior weighs such data more.
    """

    joint_fit: bool = True
    sigma_point_rel: float = 0.0015
    sigma_line_rel: float = 0.0010
    size_sigma_rel: float = 0.05
    preset_shape: bool = True
    focal_profile_flat: bool = False
    focal_prior_width: float = 0.75
    focal_prior_sigma_log: float = 0.5
    focal_prior_when_sigma_log: float = 0.1
    focal_prior_basin_widths: float = 4.0
    cluster_threshold_rel: float = 0.15
    cluster_threshold_min_m: float = 1.5
    outlier_weight: float = 0.3
    free_principal_point: bool | None = None  # None = decided by BIC
    principal_point_prior_sigma_rel: float = 0.03
    principal_point_sigma_rel: float = 0.007
    reassign_corners: bool = True
    ground_corner_sigma_rel: float = 0.025
    ground_corner_click_ratio: float | None = None
    car_line_sigma_deg: float = 3.0
    car_line_share_warn: float = 0.9
    car_line_axes: tuple[str, ...] = ("length", "width")
    jackknife: bool = True
    jackknife_method: Literal["one_step", "refit"] = "one_step"
    jackknife_leverage: bool = True
    jackknife_leverage_max_move: float = 0.1
    car_class_prior: float = 0.05
    variance_groups: bool = False
    discordant_line_t: float = 3.0
    discordant_line_move: float = 1.0
    photo_lines: bool = True
    video_lines: Any = None


@dataclass
class AnnotatorSolution:
    """The paper's closed-form solution from one annotator's work."""

    index: int
    annotator: str
    vanishing_points: dict[str, VanishingPoint]
    intrinsics: IntrinsicsEstimate | None = None
    camera: Camera | None = None
    width_sign: float = 1.0
    candidates: dict[str, FloatArray] = field(default_factory=dict)
    height_check: float | None = None
    error: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        out: dict[str, Any] = {"index": self.index, "annotator": self.annotator}
        if self.error:
            out["error"] = self.error
        out["vanishing_points"] = {
            k: (None if v.pixel is None else v.pixel.tolist())
            for k, v in self.vanishing_points.items()
        }
        out["vp_rms_px"] = {k: v.rms_px for k, v in self.vanishing_points.items()}
        if self.intrinsics is not None:
            out["focal_px"] = self.intrinsics.focal_px
            out["principal_point"] = list(self.intrinsics.principal_point)
            out["intrinsics_method"] = self.intrinsics.method
        if self.camera is not None:
            out["camera_in_world"] = self.camera.center_in_world.tolist()
            out["height_m"] = self.camera.height_m
        out["width_sign"] = self.width_sign
        out["candidates"] = {k: v.tolist() for k, v in self.candidates.items()}
        if self.height_check is not None:
            out["height_check_ratio"] = float(self.height_check)  # never a numpy scalar
        return out


@dataclass(frozen=True)
class JointState:
    """The joint fit's problem at its solution, for fits that add more evidence.

    :mod:`camloc_geo.absolute`'s bundle adjustment re-fits the camera with the annotations
    and the matched map points together; it needs the annotations' residuals in the fit's
    internal frame. A world point ``p`` of the calibration's output frame is
    ``internal_from_output @ p + internal_origin`` in that frame.

    Attributes
    ----------
    problem
        The stacked annotation residuals (``_JointProblem``).
    x
        The solution's parameter vector.
    rotation0
        Reference rotation of the rotation-vector parameterisation.
    principal_point
        The fixed principal point, or None when it is a parameter.
    focal_px
        The given focal length, or None when it is a parameter.
    weights
        The annotators' final robust weights.
    internal_from_output, internal_origin
        The output frame (origin at the chosen corner) in the internal frame.
    """

    problem: Any
    x: FloatArray
    rotation0: FloatArray
    principal_point: tuple[float, float] | None
    focal_px: float | None
    weights: FloatArray
    internal_from_output: FloatArray
    internal_origin: FloatArray


@dataclass
class CalibrationResult:
    """Everything :func:`calibrate` found.

    Attributes
    ----------
    camera
        The final camera (joint fit, or the cluster answer when the fit is off or failed).
    method
        ``joint_fit`` or ``cluster_centroid``.
    intrinsics_method, intrinsics_reason
        Which intrinsics fallback was used and why.
    annotators
        Per-annotator closed-form solutions.
    cluster
        Members (``(annotator index, dimension)``), centroid and threshold of the largest
        cluster of candidates.
    annotator_weights
        Final weight of each annotator in the joint fit (1 = fully trusted).
    outlier_annotators
        Names of annotators reported as outliers.
    position_sigma_m
        1-sigma uncertainty of the camera centre (x, y, z) in the world frame: the larger of
        the fit's covariance and, with 2-12 annotators, their jackknife spread, per axis; with
        a preset's size error (``size_sigma_rel / √3`` of the distance) added.
    position_sigma_fit_m
        The fit's covariance part alone (when the jackknife was added).
    position_sigma_jackknife_m
        The annotators' leave-one-out spread alone; ``position_sigma_m`` is the larger of it
        and ``position_sigma_fit_m``, per axis (both estimate the same sampling spread).
    rotation_sigma_deg
        1-sigma uncertainty of the orientation, degrees: small-angle rotations about the
        **camera's** x (right), y (down) and z (optical) axes, i.e. the perturbed rotation is
        ``exp([ε]×) · cam_from_world_rotation`` with ``ε ~ N(0, diag(σ²))``. Like
        ``position_sigma_m``: the larger of the fit's covariance and the jackknife spread,
        per axis.
    focal_sigma_px
        1-sigma of the focal length, pixels (None when given in the scene).
    rotation_sigma_fit_deg
        The fit's covariance part alone (when the jackknife was added).
    parameter_covariance
        Joint covariance ``(9, 9)`` of the answer before the jackknife: focal length (px),
        principal point x, y (px), small rotation about the camera's x, y, z axes (rad, as in
        ``rotation_sigma_deg``), camera centre x, y, z (m). It keeps the correlations the
        per-axis sigmas lose: a principal point off by ``δ`` pixels turns the fitted
        orientation by about ``δ / f`` while the pixels' rays barely move, so measurements
        through the camera (:mod:`camloc_geo.sensors`) draw all of them together.
    focal_sigma_with_principal_point_px, position_sigma_with_principal_point_m
        Aliases of ``focal_sigma_px`` and ``position_sigma_m``;
        ``rotation_sigma_with_principal_point_deg`` of ``rotation_sigma_deg``. Every sigma
        includes the principal point's own uncertainty where the fit held it at the image
        centre (``CalibrationSettings.principal_point_sigma_rel``) as a consider covariance:
        how far the answer may be from the truth (``benchmarks/calibrate_coverage.py``).
    principal_point_sigma_px
        1-sigma of the principal point (x, y): from the fit when fitted, the assumed spread
        when held at the image centre; None when given in the scene.
    excluded_annotators
        ``{annotator, index, reason}`` of each annotator left out.
    clamped_clicks
        Clicks up to the margin outside the image, moved onto it.
    annotator_influence_m
        Per annotation, how far the camera moves when it is left out (None: not computed, or
        no comparable answer without it).
    photo_segments
        Segments detected in the scene's photo that joined the fit, per axis
        (``CalibrationSettings.photo_lines``); empty when none did.
    object_proportions
        The trusted annotators' clicked edges measured back through the fitted camera,
        against the stated size (joint fit only): ``scale`` per axis (clicked / stated,
        median over the annotators), ``chi2`` and ``spread_log`` of their disagreement,
        ``disagrees`` (chi-square above 5.99 and spread above 0.2: a warning, and the
        position sigmas include half the spread of the camera's distance). A car of another
        class than the preset, or ground corners at the tyre contacts, shows here.
    """

    camera: Camera
    method: str
    intrinsics_method: str
    intrinsics_reason: str
    annotators: list[AnnotatorSolution]
    cluster: dict[str, Any]
    annotator_weights: list[float]
    outlier_annotators: list[str]
    position_sigma_m: FloatArray | None = None
    focal_sigma_px: float | None = None
    rms_residual_px: float | None = None
    width_signs: list[float] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    annotator_corners: list[str] = field(default_factory=list)
    width_sign: float = 1.0
    excluded_annotators: list[dict[str, Any]] = field(default_factory=list)
    clamped_clicks: int = 0
    annotator_influence_m: list[float | None] = field(default_factory=list)
    position_sigma_fit_m: FloatArray | None = None
    rotation_sigma_deg: FloatArray | None = None
    rotation_sigma_fit_deg: FloatArray | None = None
    position_sigma_jackknife_m: FloatArray | None = None
    principal_point_sigma_px: list[float] | None = None
    parameter_covariance: FloatArray | None = field(default=None, repr=False, compare=False)
    joint_state: JointState | None = field(default=None, repr=False, compare=False)
    photo_segments: dict[str, int] = field(default_factory=dict)
    video_segments: dict[str, int] = field(default_factory=dict)
    object_proportions: dict[str, Any] | None = None

    @property
    def focal_sigma_with_principal_point_px(self) -> float | None:
        """Alias of ``focal_sigma_px`` (which now includes the principal point's uncertainty)."""
        return self.focal_sigma_px

    @property
    def position_sigma_with_principal_point_m(self) -> FloatArray | None:
        """Alias of ``position_sigma_m`` (which now includes the principal point's)."""
        return self.position_sigma_m

    @property
    def rotation_sigma_with_principal_point_deg(self) -> FloatArray | None:
        """Alias of ``rotation_sigma_deg`` (which now includes the principal point's)."""
        return self.rotation_sigma_deg

    @property
    def height_m(self) -> float:
        """Camera height above the ground."""
        return self.camera.height_m

    def __repr__(self) -> str:
        """One line for a notebook: focal length, height, method, annotators, warnings.

        (The dataclass' own repr printed every array and per-annotator solution: ~6,000
        characters.) ``to_dict()`` gives everything.
        """
        cam = self.camera
        f_sigma = "" if self.focal_sigma_px is None else f" ± {self.focal_sigma_px:.1f}"
        parts = [
            f"focal_px={cam.focal_px:.1f}{f_sigma}",
            f"height_m={cam.height_m:.2f}",
            f"method={self.method!r}",
            f"intrinsics={self.intrinsics_method!r}",
            f"annotators={len(self.annotators)}",
        ]
        if self.warnings:
            parts.append(f"warnings={len(self.warnings)}")
        return f"CalibrationResult({', '.join(parts)})"

    @property
    def corner_mistakes(self) -> list[str]:
        """Annotators who marked another corner of the car than the world origin.

        The joint fit re-interprets their clicks (they still count); this names them for
        crowd quality control.
        """
        names = [a.annotator for a in self.annotators]
        return [
            n
            for n, c in zip(names, self.annotator_corners, strict=False)
            if c not in ("origin", "excluded")
        ]

    def to_dict(self) -> dict[str, Any]:
        """The JSON that ``camloc calibrate`` prints."""
        cam = self.camera
        _heading, pitch, roll = cam.angles_deg
        out: dict[str, Any] = {
            "focal_px": cam.focal_px,
            "principal_point": list(cam.principal_point),
            "height_m": cam.height_m,
            "camera_in_world": cam.center_in_world.tolist(),
            "pitch_deg": pitch,
            "roll_deg": roll,
            "cam_from_world": cam.cam_from_world.tolist(),
            "rotation": cam.cam_from_world_rotation.tolist(),
            "method": self.method,
            "intrinsics_method": self.intrinsics_method,
            "fallback": self.intrinsics_method,
            "intrinsics_reason": self.intrinsics_reason,
            "distance_to_origin_m": float(np.linalg.norm(cam.center_in_world)),
        }
        if self.position_sigma_m is not None:
            out["camera_in_world_sigma_m"] = self.position_sigma_m.tolist()
            out["height_sigma_m"] = float(self.position_sigma_m[2])
        if self.focal_sigma_px is not None:
            out["focal_sigma_px"] = self.focal_sigma_px
        if self.rotation_sigma_deg is not None:
            out["rotation_sigma_deg"] = self.rotation_sigma_deg.tolist()
        if self.focal_sigma_with_principal_point_px is not None:
            out["focal_sigma_with_principal_point_px"] = self.focal_sigma_with_principal_point_px
        if self.position_sigma_with_principal_point_m is not None:
            out["camera_in_world_sigma_with_principal_point_m"] = (
                self.position_sigma_with_principal_point_m.tolist()
            )
        if self.rotation_sigma_with_principal_point_deg is not None:
            out["rotation_sigma_with_principal_point_deg"] = (
                self.rotation_sigma_with_principal_point_deg.tolist()
            )
        if self.principal_point_sigma_px is not None:
            out["principal_point_sigma_px"] = list(self.principal_point_sigma_px)
        if self.rms_residual_px is not None:
            out["rms_residual_px"] = self.rms_residual_px
        out["width_sign"] = self.width_sign
        out["annotator_weights"] = self.annotator_weights
        if self.annotator_corners:
            out["annotator_corners"] = self.annotator_corners
            out["corner_mistakes"] = self.corner_mistakes
        out["outlier_annotators"] = self.outlier_annotators
        out["excluded_annotators"] = [
            {"annotator": e["annotator"], "index": e["index"], "reason": e["reason"]}
            for e in self.excluded_annotators
        ]
        out["clamped_clicks"] = self.clamped_clicks
        if self.annotator_influence_m:
            out["annotator_influence_m"] = self.annotator_influence_m
        if self.position_sigma_fit_m is not None:
            out["camera_in_world_sigma_fit_m"] = self.position_sigma_fit_m.tolist()
        if self.position_sigma_jackknife_m is not None:
            out["camera_in_world_sigma_jackknife_m"] = self.position_sigma_jackknife_m.tolist()
        if self.photo_segments:
            out["photo_segments"] = dict(self.photo_segments)
        if self.video_segments:
            out["video_segments"] = dict(self.video_segments)
        if self.object_proportions is not None:
            out["object_proportions"] = self.object_proportions
        out["cluster"] = self.cluster
        out["annotators"] = [a.to_dict() for a in self.annotators]
        if self.warnings:
            out["warnings"] = self.warnings
        return out


# --------------------------------------------------------------------------- closed form
def _segments(ann: Annotation, axis: str) -> FloatArray:
    return np.asarray(getattr(ann.vp_lines, axis), dtype=float).reshape(-1, 4)


def _check_axes_geometry(ann: Annotation, where: str) -> None:
    o = np.asarray(ann.axes.origin, float)
    steps = {k: np.asarray(getattr(ann.axes, k), float) - o for k in AXES}
    # np.linalg.norm of a vector is sqrt(x.dot(x)): the same, without its dispatch.
    norms = {k: np.sqrt(s.dot(s)) for k, s in steps.items()}
    for k in steps:
        if norms[k] < 1.0:
            raise DegenerateGeometryError(
                f"{where}.axes.{k}: coincides with the origin pixel (less than 1 px away)"
            )
    for a, b in (("length", "width"), ("length", "height"), ("width", "height")):
        sa, sb = steps[a], steps[b]
        sin = abs(sa[0] * sb[1] - sa[1] * sb[0]) / (norms[a] * norms[b])
        if sin < math.sin(math.radians(1.0)) and float(sa @ sb) > 0:
            raise DegenerateGeometryError(
                f"{where}.axes: the {a} and {b} edges are collinear in the image"
            )


def _vanishing_directions(
    vps: dict[str, VanishingPoint], intr: IntrinsicsEstimate
) -> tuple[FloatArray, dict[str, FloatArray]]:
    """``cam_from_img`` of the intrinsics and the unit direction of each vanishing point."""
    f = intr.focal_px
    cx, cy = intr.principal_point
    cam_from_img = np.array([[1 / f, 0, -cx / f], [0, 1 / f, -cy / f], [0, 0, 1.0]])
    dirs = {}
    for k, v in vps.items():
        d = cam_from_img @ v.homogeneous
        dirs[k] = d / _vector_norm(d)
    return cam_from_img, dirs


def _cross3(a: FloatArray, b: FloatArray) -> FloatArray:
    """``np.cross`` of two 3-vectors, written out: the same products and differences (so the
    same bits) without its axis handling, which costs ~10 us a call on 3-vectors."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def _origin_depth_terms(
    cam_from_img: FloatArray, ann: Annotation, R: FloatArray, ends: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Least-squares terms of the origin's depth from each edge end (length, width, height).

    With ``m0`` the origin's ray (z = 1) and ``mk`` the unit ray of an edge end, the end
    ``λ0 m0 + R e`` must lie on ``mk``: ``λ0 (mk × m0) = -(mk × R e)``. Returns the numerators
    ``-(a·b)`` and denominators ``a·a`` (``a = mk × m0``, ``b = mk × R e``) per axis, so that
    ``λ0 = num / den`` for one axis and ``Σnum / Σden`` for several.
    """
    m0 = cam_from_img @ np.array([*ann.axes.origin, 1.0])
    nums, dens = np.zeros(3), np.zeros(3)
    for i, k in enumerate(AXES):
        mk = cam_from_img @ np.array([*getattr(ann.axes, k), 1.0])
        mk /= _vector_norm(mk)
        a = _cross3(mk, m0)
        b = _cross3(mk, R @ ends[_AXIS_INDEX[k] + 1])
        nums[i] = -float(a @ b)
        dens[i] = float(a @ a)
    return nums, dens


def solve_annotator(
    scene: Scene,
    index: int,
    segments: dict[str, FloatArray],
    *,
    size: ObjectSize,
) -> AnnotatorSolution:
    """The paper's closed-form solution for one annotator (raises on degenerate input)."""
    ann = scene.annotations[index]
    where = f"annotations[{index}]"
    width, height = scene.image_size
    diag = math.hypot(width, height)
    _check_axes_geometry(ann, where)
    vps = {
        axis: fit_vanishing_point(segments[axis], scale_px=diag, name=f"{where}.vp_lines.{axis}")
        for axis in AXES
    }
    sol = AnnotatorSolution(index, ann.annotator, vps)
    try:
        intr = estimate_intrinsics(
            {k: v.homogeneous for k, v in vps.items()},
            (width, height),
            focal_px=scene.camera.focal_px,
            principal_point=scene.camera.principal_point,
        )
    except DegenerateGeometryError as exc:
        raise DegenerateGeometryError(f"{where}.vp_lines: {exc}") from None
    sol.intrinsics = intr
    f = intr.focal_px
    cx, cy = intr.principal_point
    cam_from_img, dirs = _vanishing_directions(vps, intr)
    # Orthogonality of the vanishing directions (collinear axes end here).
    for a, b in (("length", "width"), ("length", "height"), ("width", "height")):
        ang = math.degrees(math.acos(min(1.0, abs(float(dirs[a] @ dirs[b])))))
        if ang < 30.0:
            raise DegenerateGeometryError(
                f"{where}.vp_lines: the {a} and {b} vanishing directions are only {ang:.1f}° "
                "apart; they must be orthogonal (are the lines drawn for the right axes?)"
            )
    origin = np.asarray(ann.axes.origin, float)
    m0 = cam_from_img @ np.array([*origin, 1.0])
    signs = {}
    for k in ("length", "height"):
        s = direction_sign(dirs[k], m0, np.asarray(getattr(ann.axes, k), float) - origin)
        if s == 0.0:
            raise DegenerateGeometryError(
                f"{where}.axes.{k}: the edge is perpendicular to its vanishing direction in "
                "the image, so its sign is ambiguous; check the axis annotations"
            )
        signs[k] = s
    d_len = signs["length"] * dirs["length"]
    d_up = signs["height"] * dirs["height"]
    y_ref = _cross3(d_up, d_len)
    d_wid = dirs["width"] if float(dirs["width"] @ y_ref) >= 0 else -dirs["width"]
    s_w = direction_sign(d_wid, m0, np.asarray(ann.axes.width, float) - origin)
    if s_w == 0.0:
        raise DegenerateGeometryError(
            f"{where}.axes.width: the edge is perpendicular to its vanishing direction in the "
            "image, so its side is ambiguous"
        )
    sol.width_sign = s_w
    R = rotation_from_vanishing_directions({"length": d_len, "width": d_wid, "height": d_up})
    ends = _object_points(size, s_w)
    nums, dens = _origin_depth_terms(cam_from_img, ann, R, ends)
    lam: dict[str, float] = {}
    for i, k in enumerate(AXES):
        if dens[i] < 1e-18:
            raise DegenerateGeometryError(f"{where}.axes.{k}: end pixel on the origin's ray")
        lam[k] = nums[i] / dens[i]
    num_total, den_total = float(nums.sum()), float(dens.sum())
    for k in AXES:
        if not lam[k] > 0:
            raise DegenerateGeometryError(
                f"{where}.axes.{k}: puts the object behind the camera; check that the axis "
                "end pixels match the vanishing lines"
            )
    for k in ("length", "width", "height"):
        t = lam[k] * m0
        sol.candidates[k] = np.asarray(-R.T @ t, dtype=np.float64)
    lam_all = num_total / den_total
    sol.height_check = lam["height"] / (0.5 * (lam["length"] + lam["width"]))
    sol.camera = Camera(f, (cx, cy), R, lam_all * m0)
    return sol


_CORNER_NAMES = ("origin", "far_length", "far_width", "diagonal")


def _corner_points(size: ObjectSize, width_sign: float, corner: int) -> FloatArray:
    """World points of the four clicks of an annotator who started at ``corner``.

    The car's footprint is ``[0, L] × [0, width_sign·W]``; corner 0 = (0, 0), 1 = (L, 0),
    2 = (0, width_sign·W), 3 = (L, width_sign·W). Rows: origin, length end, width end,
    height end.
    """
    L, W, H = size.length_m, width_sign * size.width_m, size.height_m
    x0 = L if corner in (1, 3) else 0.0
    y0 = W if corner in (2, 3) else 0.0
    return np.array([[x0, y0, 0.0], [L - x0, y0, 0.0], [x0, W - y0, 0.0], [x0, y0, H]], dtype=float)


def _frame_at_corner(
    size: ObjectSize, width_sign: float, corner: int
) -> tuple[FloatArray, FloatArray, float]:
    """The frame whose origin is ``corner`` of the common frame's footprint.

    Returns ``M`` (rotation, common-from-new), the new origin in the common frame and the
    new frame's width sign: ``p_common = M p_new + origin``. The new x axis runs along the
    length edge from that corner, z stays up, y = z × x.
    """
    L, W = size.length_m, width_sign * size.width_m
    x0 = L if corner in (1, 3) else 0.0
    y0 = W if corner in (2, 3) else 0.0
    sx = -1.0 if corner in (1, 3) else 1.0
    M = np.diag([sx, sx, 1.0])
    # The width edge runs from y0 to W - y0 in the common frame; in the new frame y' = sx·(y - y0).
    ws_new = float(np.sign(sx * ((W - y0) - y0))) or 1.0
    return M, np.array([x0, y0, 0.0]), ws_new


def _relabel_corner(corner: int, origin_corner: int) -> int:
    """A corner's index relative to a frame whose origin is ``origin_corner``."""
    # Corners are (length bit, width bit); moving the origin flips the bits it differs in.
    return corner ^ origin_corner


def _object_points(size: ObjectSize, width_sign: float) -> FloatArray:
    """World points: origin, length end, width end, height end."""
    return np.array(
        [
            [0.0, 0.0, 0.0],
            [size.length_m, 0.0, 0.0],
            [0.0, width_sign * size.width_m, 0.0],
            [0.0, 0.0, size.height_m],
        ]
    )


def _single_linkage_labels(pts: FloatArray, threshold: float) -> npt.NDArray[np.int64]:
    """Cluster labels (1, 2, ...) of single-linkage clustering cut at ``threshold``.

    The flat clusters of single linkage at a distance are the connected components of the
    graph joining points at most that far apart (scipy's ``fcluster(linkage(pts, "single"),
    t, "distance")``, without importing scipy.cluster: over a second on a busy machine).
    """
    n = len(pts)
    parent = np.arange(n)

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = int(parent[i])
        return i

    d = np.linalg.norm(pts[:, None, :] - pts[None, :, :], axis=2)
    for i, j in zip(*np.nonzero(np.triu(d <= threshold, k=1)), strict=True):
        ri, rj = root(int(i)), root(int(j))
        if ri != rj:
            parent[max(ri, rj)] = min(ri, rj)
    roots = np.array([root(i) for i in range(n)])
    _u, labels = np.unique(roots, return_inverse=True)
    return np.asarray(labels.reshape(-1) + 1, dtype=np.int64)


def _cluster(
    candidates: list[tuple[int, str, FloatArray]], settings: CalibrationSettings
) -> dict[str, Any]:
    pts = np.array([c[2] for c in candidates])
    dist_scale = float(np.median(np.linalg.norm(pts, axis=1)))
    threshold = max(settings.cluster_threshold_min_m, settings.cluster_threshold_rel * dist_scale)
    labels = _single_linkage_labels(pts, threshold)
    best_label, best_key = None, None
    for lab in np.unique(labels):
        members = pts[labels == lab]
        spread = float(np.mean(np.linalg.norm(members - members.mean(axis=0), axis=1)))
        n_annot = len({candidates[i][0] for i in np.flatnonzero(labels == lab)})
        key = (n_annot, len(members), -spread)
        if best_key is None or key > best_key:
            best_key, best_label = key, lab
    idx = np.flatnonzero(labels == best_label)
    centroid = pts[idx].mean(axis=0)
    return {
        "threshold_m": threshold,
        "members": [{"annotator": candidates[i][0], "dimension": candidates[i][1]} for i in idx],
        "centroid": centroid.tolist(),
        "n_candidates": len(pts),
        "n_clusters": len(np.unique(labels)),
    }


# ----------------------------------------------------------------------------- joint fit
def _robust_normal_matrix(
    prob: _JointProblem,
    x: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float] | None,
    f_fixed: float | None,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """At ``x``: the residuals ``r``, the soft-L1-weighted Jacobian ``W J`` and the robust
    Gauss-Newton normal matrix ``H = Jᵀ W J`` (the sensitivities' ``−H⁻¹ Jᵀ W dr``)."""
    r, J = prob.residuals_and_jacobian(x, R0, pp_fixed, f_fixed)
    w = 1.0 / np.sqrt(1.0 + (r / _F_SCALE) ** 2)
    JW = J * w[:, None]
    return r, JW, J.T @ JW


def _ground_corner_sensitivity(
    prob: _JointProblem,
    x: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float] | None,
    f_fixed: float | None,
) -> FloatArray | None:
    """How the fitted parameters move with the ground-corner ambiguity: ``D`` ``(len(x), k)``.

    A rounded car has no corner on the ground: the click meant is the ground under the
    body's corner, but it may land anywhere from there to the tyre contact. Each of an
    annotator's four clicks is taken as off, independently, along the car's length edge by
    ``prob.ground_corner_sigma_rel`` of the clicked length edge (pixels) and along its width
    edge by that fraction of the width edge. A click moved by ``δ`` changes its residuals by
    ``−scale·δ``; the fit's parameters then move by ``−H⁻¹ Jᵀ W dr`` (robust Gauss-Newton at
    the solution). Each column is one such 1-sigma move, so the consider covariance is
    ``D Dᵀ`` (not scaled by the residual variance: a systematic offset the residuals of one
    fit do not show). None when off or the Hessian is singular.
    """
    rel = prob.ground_corner_sigma_rel
    if rel <= 0.0:
        return None
    r, JW, H = _robust_normal_matrix(prob, x, R0, pp_fixed, f_fixed)
    n_seg, n_pt = len(prob.segments), len(prob.pt_pix)
    steps, live = prob.ground_corner_steps()
    if not np.any(live):
        return None
    # Jᵀ W dr, dr nonzero only at the click's u and v rows: one column per (click, edge)
    ju = JW[n_seg : n_seg + n_pt] * prob._pt_scale[:, None]  # (n_pt, n)
    jv = JW[n_seg + n_pt : n_seg + 2 * n_pt] * prob._pt_scale[:, None]
    cols = -(steps[:, :, 0:1] * ju[:, None, :] + steps[:, :, 1:2] * jv[:, None, :])
    cols = cols[live]  # (k, n)
    factor = _ground_corner_evidence(prob, r)
    try:
        D = -factor * np.linalg.solve(H, cols.T)
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(D)):
        return None
    return np.asarray(D, dtype=np.float64)


def _size_shape_sensitivity(
    prob: _JointProblem,
    x: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float] | None,
    f_fixed: float | None,
    size_sigma_rel: float,
    *,
    centre: bool = False,
) -> FloatArray | None:
    """How the focal length, principal point and rotation move with a preset's size error:
    ``D`` ``(len(x), 3)``, one column per dimension (length, width, height).

    A preset's length, width and height are each off by ``size_sigma_rel`` (1-sigma),
    independently, and that error is the *same car's* for every annotator: their edge-end
    clicks all meet the same wrong box. Where the vanishing points leave the focal length
    loose (a low camera, a direction near the image plane), the box's proportions decide
    it, and a wrong proportion moves the answer by far more than the per-click share
    (``_JointProblem``'s point sigmas, averaged over the annotators) or the jackknife (which
    cannot see an error every annotator shares) state. Each column is the fit's move
    ``−H⁻¹ Jᵀ W dr`` when one dimension is ``1 + size_sigma_rel`` times the preset's (the
    world points scaled along that axis; robust Gauss-Newton at the solution). The camera
    centre's rows are zero: the distance's share of the size error is stated separately
    (``size_rel`` of :func:`_output_covariance`); ``centre``: they are kept (the car-class
    mixture's moves). None when off or singular.
    """
    if size_sigma_rel <= 0.0:
        return None
    _r, JW, H = _robust_normal_matrix(prob, x, R0, pp_fixed, f_fixed)
    n_seg, n_pt = len(prob.segments), len(prob.pt_pix)
    f, pp, R, C = prob.unpack(x, R0, pp_fixed, f_fixed)
    cam = Camera.from_center(f, pp, R, C)
    base = cam.project(prob.pt_world)
    ju = JW[n_seg : n_seg + n_pt] * prob._pt_scale[:, None]  # (n_pt, n)
    jv = JW[n_seg + n_pt : n_seg + 2 * n_pt] * prob._pt_scale[:, None]
    cols = np.zeros((3, len(x)))
    for d in range(3):
        pts = prob.pt_world.copy()
        pts[:, d] *= 1.0 + size_sigma_rel
        dp = cam.project(pts) - base  # a click meeting the bigger box: residual + scale·dp
        if not np.all(np.isfinite(dp)):
            return None
        cols[d] = dp[:, 0] @ ju + dp[:, 1] @ jv
    try:
        D = -np.linalg.solve(H, cols.T)
    except np.linalg.LinAlgError:
        return None
    if not centre:
        D[-3:] = 0.0  # the centre: size_rel's term
    if not np.all(np.isfinite(D)):
        return None
    return np.asarray(D, dtype=np.float64)


GROUND_CORNER_FLOOR = 0.1  # the ground-corner term's least share (of its 1-sigma)


def _ground_corner_evidence(prob: _JointProblem, r: FloatArray) -> float:
    """How much of the ground-corner term the clicks' residuals support, in ``[floor, 1]``.

    A click off the ground corner (the tyre contact, a bumper's overhang) does not fit the
    car's box as the lines place it, so the axis clicks scatter more than the annotators'
    own precision. That precision is measured on their lines: a segment's residual is half
    the difference of its two ends' offsets, so ``2 × mean(d²)`` estimates an end's
    variance per axis. The clicks' excess over it (their pixel residuals' mean square per
    coordinate minus that variance times ``ground_corner_click_ratio`` squared: the
    settings assume clicks that much less precise than line ends, 1.5x; stop 41 compared
    them at equal precision) is compared with the term's own mean square per coordinate
    (``(rel·|length edge|)² + (rel·|width edge|)²`` over two): the term's sigma is scaled
    by ``√(excess / term)``, clipped to ``[GROUND_CORNER_FLOOR, 1]``. Annotators' weights
    weigh both means. Clicks as precise as the settings assume (noise-free scenes; the
    street scenes' 1 px clicks and lines) keep the floor; clicks off by a size mismatch or a tyre
    contact keep the whole term. The floor keeps a tenth of it for offsets the residuals
    cannot show (an annotator who clicks every corner the same way, absorbed by the
    preset's size uncertainty).
    """
    n_seg, n_pt = len(prob.segments), len(prob.pt_pix)
    w_seg, w_pt = prob._w_seg, prob._w_pt
    if not (np.all(w_seg > 0.0) and np.all(w_pt > 0.0)):
        return 1.0
    # pixel residuals, the annotators' weights taken out (they weigh the means below)
    d_seg = r[:n_seg] / w_seg * prob.sigma_line
    d_u = r[n_seg : n_seg + n_pt] / w_pt * prob._sigma_pt_each
    d_v = r[n_seg + n_pt : n_seg + 2 * n_pt] / w_pt * prob._sigma_pt_each
    a_seg, a_pt = w_seg**2, w_pt**2  # the annotators' weights per row
    line_end_var = 2.0 * float(a_seg @ d_seg**2) / max(float(a_seg.sum()) - 6.0, 1.0)
    # A click's own variance as the settings assume it: the line ends' times the settings'
    # click-to-line-end precision ratio squared (1.5: clicks are worse than line ends).
    line_end_var *= prob.ground_corner_click_ratio**2
    click_var = float(a_pt @ (d_u**2 + d_v**2)) / max(2.0 * float(a_pt.sum()) - 3.0, 1.0)
    edge_sq = prob.ground_corner_edge_sq()  # per annotator: |length edge|² + |width edge|², px²
    a_ann = a_pt[::4]  # per annotator: the weighted mean of edge_sq (np.average's arithmetic)
    term_var = prob.ground_corner_sigma_rel**2 * float((edge_sq * a_ann).sum() / a_ann.sum()) / 2.0
    if term_var <= 0.0:
        return 1.0
    excess = max(click_var - line_end_var, 0.0)
    return float(np.clip(math.sqrt(excess / term_var), GROUND_CORNER_FLOOR, 1.0))


# The car's own lines (issue 24): a rounded body's "edges" are silhouettes of curved
# surfaces, not 3-D segments along the car's axes; the lines of one face share one error.
CAR_LINE_MARGIN_REL = 0.05  # of the car's image size: a line end this far outside is still on it
CAR_LINE_MARGIN_MIN_PX = 2.0
CAR_LINE_HINTS = {
    "length": "a kerb, lane line or building edge along the car",
    "width": "a stop line, crossing or building edge across it",
    "height": "a building edge, pole or door frame",
}
# The box faces at x = 0, x = L, y = 0, y = W, z = 0, z = H of the fit's frame (the origin
# corner is the clicked one, the nearest to the camera).
_FACE_NAMES = ("near end", "far end", "near side", "far side", "underside", "roof")
#: Face ``n_axis * 2 + side``: its four box corners (index ``4 i + 2 j + k`` of the corner
#: at bits ``(i, j, k)``, :func:`_car_faces`) in cyclic order, and the axis it is normal to.
_FACE_CORNERS = np.array(
    [
        [4 * i + 2 * j + k for i, j, k in cyc]
        for n_axis in range(3)
        for side in (0, 1)
        for cyc in [
            [
                tuple(side if d == n_axis else uv[(d - n_axis - 1) % 3] for d in range(3))
                for uv in ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0))
            ]
        ]
    ]
)
_FACE_NORMAL_AXIS = np.repeat(np.arange(3), 2)


def _convex_hull(points: FloatArray) -> FloatArray:
    """Counter-clockwise convex hull (Andrew's monotone chain) of 2-D ``points``."""
    pts = sorted({(float(p[0]), float(p[1])) for p in points})
    if len(pts) < 3:
        return np.asarray(pts, dtype=float).reshape(-1, 2)

    def half(seq: list[tuple[float, float]]) -> list[tuple[float, float]]:
        out: list[tuple[float, float]] = []
        for p in seq:
            while (
                len(out) >= 2
                and (out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])
                <= 0.0
            ):
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.asarray(lower[:-1] + upper[:-1], dtype=float)


def _inside_hull(segments: FloatArray, hull: FloatArray, margin: float) -> npt.NDArray[np.bool_]:
    """Which ``segments`` ``(k, 4)`` have both ends inside the counter-clockwise ``hull`` or
    within ``margin`` pixels of it."""
    if len(hull) < 3 or not len(segments):
        return np.zeros(len(segments), dtype=bool)
    edge = np.roll(hull, -1, axis=0) - hull
    normal = np.column_stack([edge[:, 1], -edge[:, 0]])  # outward for a CCW outline
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    offset = np.einsum("kd,kd->k", normal, hull)
    inside = np.ones(len(segments), dtype=bool)
    for end in (segments[:, 0:2], segments[:, 2:4]):
        inside &= (end @ normal.T - offset).max(axis=1) <= margin
    return inside


def _car_faces(
    prob: _JointProblem,
    x: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float] | None,
    f_fixed: float | None,
    segments: FloatArray,
    axis_of: npt.NDArray[np.int_],
) -> npt.NDArray[np.int_]:
    """Which face of the car each segment lies on: ``-1`` a scene line, ``0-5`` the box's
    faces (``_FACE_NAMES``), ``6`` on the car but on no face parallel to its axis.

    A line is the car's when both its ends lie on the car box's image outline (the convex
    hull of its 8 corners projected with the camera of ``x``), or within a margin
    (``CAR_LINE_MARGIN_REL`` of the outline's bounding-box diagonal, at least
    ``CAR_LINE_MARGIN_MIN_PX``); lines elsewhere (kerbs, buildings, lane lines, poles) are
    scene lines. A car line parallel to axis ``a`` lies on one of the four faces that
    contain that direction: of those whose image quad holds it, the nearest to the camera
    (the one seen). Where a box corner lies behind the camera, the outline is the hull of
    the boxes the annotators' four clicks span, and the faces are not told apart (``6``).
    """
    segments = np.asarray(segments, dtype=float).reshape(-1, 4)
    out = np.full(len(segments), -1, dtype=int)
    if not len(segments):
        return out
    f, pp, R, C = prob.unpack(x, R0, pp_fixed, f_fixed)
    s = prob.size
    ext = np.array([s.length_m, prob.ws_common * s.width_m, s.height_m])
    bits = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=float)
    box = bits * ext
    pc = (box - C) @ R.T
    projected = bool(np.all(pc[:, 2] > 0.1))
    if projected:
        pts = pc[:, :2] / pc[:, 2:3] * f + np.asarray(pp, dtype=float)
    else:
        clicks = prob.pt_pix.reshape(-1, 4, 2)
        o, e = clicks[:, :1], clicks[:, 1:] - clicks[:, :1]  # (n, 1, 2), (n, 3, 2)
        pts = (o + np.einsum("kj,njd->nkd", bits, e)).reshape(-1, 2)
    hull = _convex_hull(pts)
    if len(hull) < 3:
        return out
    span = hull.max(axis=0) - hull.min(axis=0)
    margin = max(CAR_LINE_MARGIN_MIN_PX, CAR_LINE_MARGIN_REL * float(np.hypot(*span)))
    on_car = _inside_hull(segments, hull, margin)
    out[on_car] = 6
    car = np.flatnonzero(on_car)
    if not projected or not len(car):
        return out
    # All six faces at once: each face's image quad (its corners in cyclic order, turned
    # counter-clockwise), which car lines it holds, and the nearest such face per line.
    quads = pts[_FACE_CORNERS]  # (6, 4, 2)
    edge = np.roll(quads, -1, axis=1) - quads
    area2 = np.einsum("fk,fk->f", quads[:, :, 0], np.roll(quads[:, :, 1], -1, axis=1)) - (
        np.einsum("fk,fk->f", quads[:, :, 1], np.roll(quads[:, :, 0], -1, axis=1))
    )
    normal = np.stack([edge[:, :, 1], -edge[:, :, 0]], axis=2) * np.sign(area2)[:, None, None]
    normal /= np.maximum(np.linalg.norm(normal, axis=2, keepdims=True), 1e-12)
    offset = np.einsum("fkd,fkd->fk", normal, quads)
    seg = segments[car]
    holds = np.ones((6, len(car)), dtype=bool)
    for end in (seg[:, 0:2], seg[:, 2:4]):
        holds &= (np.einsum("fkd,sd->fsk", normal, end) - offset[:, None, :]).max(axis=2) <= margin
    # a face seen edge-on (no area) holds nothing; nor a face parallel to the line's axis' normal
    holds &= (np.abs(area2) > 1e-9)[:, None]
    holds &= _FACE_NORMAL_AXIS[:, None] != axis_of[car][None, :]
    depth = pc[_FACE_CORNERS, 2].mean(axis=1)  # (6,)
    masked = np.where(holds, depth[:, None], np.inf)
    face = np.argmin(masked, axis=0)
    seen = np.isfinite(masked[face, np.arange(len(car))])
    out[car[seen]] = face[seen]
    return out


def _segment_offsets_px(segments: FloatArray, vp: FloatArray) -> FloatArray:
    """Signed distance (px) of each segment's first end from the line through its midpoint
    and its vanishing point (homogeneous, ``(3,)`` or one per segment ``(k, 3)``): the joint
    fit's segment residual."""
    seg = np.asarray(segments, dtype=float).reshape(-1, 4)
    v = np.broadcast_to(np.asarray(vp, dtype=float), (len(seg), 3))
    mx, my = (seg[:, 0] + seg[:, 2]) / 2.0, (seg[:, 1] + seg[:, 3]) / 2.0
    # the line mid × v, written out (np.cross costs more on small arrays)
    la = my * v[:, 2] - v[:, 1]
    lb = v[:, 0] - mx * v[:, 2]
    lc = mx * v[:, 1] - my * v[:, 0]
    num = la * seg[:, 0] + lb * seg[:, 1] + lc
    return np.asarray(num / np.maximum(np.hypot(la, lb), 1e-300), dtype=np.float64)


@dataclass
class _CarLines:
    """The car's own lines in the joint fit (:func:`_car_line_sensitivity`).

    Attributes
    ----------
    D
        Consider columns ``(len(x), k)`` of the car faces' line turns, or None.
    share
        Per axis with lines: the largest share one face of the car has in what that axis'
        lines decide (``[0, 1]``).
    face
        Per axis: the name of that face.
    n_car, n_all
        Per axis: the car's lines and all lines (annotators' and the photo's).
    """

    D: FloatArray | None
    share: dict[str, float]
    face: dict[str, str]
    n_car: dict[str, int]
    n_all: dict[str, int]

    def axes_on_car(self, share_min: float) -> list[str]:
        """Axes whose lines are (almost) all on one face of the car: share ``>= share_min``."""
        return [a for a in AXES if self.n_car.get(a, 0) and self.share.get(a, 0.0) >= share_min]


def _car_line_sensitivity(
    prob: _JointProblem,
    x: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float] | None,
    f_fixed: float | None,
    sigma_deg: float,
    share_min: float = 0.0,
    axes: tuple[str, ...] = AXES,
) -> _CarLines:
    """How the fitted parameters move with a shared direction error of the car's own lines.

    The car's lines and the face each lies on come from :func:`_car_faces`. On a rounded
    body a face's "edges" (trunk lip, bumper, taillights, chrome strips, pillars) are
    silhouettes of one curved surface, off the car's axes by a few degrees, and all the
    same way: more of them do not average it out. For an axis and a face, the 3-D
    direction that face's lines of that axis vanish to is turned by ``sigma_deg`` toward
    each of the two other axes (two columns; other faces, scene lines, clicks and the
    photo's segments stay): a row's residual changes by ``dr``, and the parameters move by
    ``−H⁻¹ Jᵀ W dr`` (robust Gauss-Newton at the solution, as
    :func:`_ground_corner_sensitivity`). Faces turn independently. ``share``: per axis, the
    largest such move of one face against the move when every line of the axis turns
    (``√(tr(Bᵀ H⁻¹ B))``, the Fisher metric), in ``[0, 1]``: how far that axis rests on
    one face of the car. Columns are given for the axes whose share is at least
    ``share_min``; where scene lines or other faces witness the axis too, they shrink by
    themselves.
    """
    r, J = prob.residuals_and_jacobian(x, R0, pp_fixed, f_fixed)
    f, pp, R, _C = prob.unpack(x, R0, pp_fixed, f_fixed)
    K = np.array([[f, 0.0, pp[0]], [0.0, f, pp[1]], [0.0, 0.0, 1.0]])
    n_seg, n_pt = len(prob.segments), len(prob.pt_pix)
    n_photo = len(prob.photo_segments)
    segs = np.vstack([prob.segments, prob.photo_segments]) if n_photo else prob.segments
    axis_of = np.concatenate([prob.seg_axis, prob.photo_axis]) if n_photo else prob.seg_axis
    rows = np.concatenate([np.arange(n_seg), n_seg + 2 * n_pt + np.arange(n_photo)])
    scale = np.concatenate([prob._w_seg / prob.sigma_line, prob._photo_scale[:n_photo]])
    considered = np.zeros(len(AXES), dtype=bool)
    considered[[AXES.index(a) for a in axes]] = True
    considered = considered[axis_of]
    faces = np.full(len(segs), -1, dtype=int)
    faces[considered] = _car_faces(
        prob, x, R0, pp_fixed, f_fixed, segs[considered], axis_of[considered]
    )
    out = _CarLines(None, {}, {}, {}, {})
    for a, name in enumerate(AXES):
        sel = axis_of == a
        if name in axes and np.any(sel):
            out.n_all[name], out.n_car[name] = int(sel.sum()), int((faces[sel] >= 0).sum())
            out.share[name], out.face[name] = 0.0, ""
    if not np.any(faces >= 0):
        return out  # no car lines: nothing to turn
    w = 1.0 / np.sqrt(1.0 + (r / _F_SCALE) ** 2)
    JW = J * w[:, None]
    try:
        H_inv = np.linalg.inv(J.T @ JW)
    except np.linalg.LinAlgError:
        return out
    h = 1e-6
    cols = []
    for a, name in enumerate(AXES):
        sel = np.flatnonzero(axis_of == a)
        car = faces[sel] >= 0
        if name not in axes or not np.any(car):
            continue
        seg_a = segs[sel]
        k_a = len(sel)
        others = [b for b in range(3) if b != a]
        # the axis' vanishing point and the two turned ones, each for every segment: one call
        vps = K @ np.column_stack([R[:, a]] + [R[:, a] + h * R[:, b] for b in others])
        offsets = _segment_offsets_px(np.tile(seg_a, (3, 1)), np.repeat(vps.T, k_a, axis=0))
        base = offsets[:k_a]
        # (len(sel), 2): each row's residual per radian of turn toward the other two axes
        G = (offsets[k_a:].reshape(2, k_a).T - base[:, None]) / h * scale[sel, None]
        JW_a = JW[rows[sel]]
        b_all = JW_a.T @ G  # (n, 2): Jᵀ W dr when every line of the axis turns
        m_all = float(np.trace(b_all.T @ H_inv @ b_all))
        groups = {}
        best, best_face = 0.0, ""
        for g in np.unique(faces[sel][car]):
            on = faces[sel] == g
            b_g = JW_a[on].T @ G[on]  # ... when the lines of face g turn
            groups[int(g)] = b_g
            m_g = float(np.trace(b_g.T @ H_inv @ b_g))
            share = math.sqrt(m_g / m_all) if m_all > 0.0 else 0.0
            if share > best:
                best, best_face = min(share, 1.0), (_FACE_NAMES[g] if g < 6 else "body")
        out.share[name], out.face[name] = best, best_face
        if sigma_deg > 0.0 and best >= share_min:
            cols += [b_g * math.radians(sigma_deg) for b_g in groups.values()]
    if cols:
        D = -H_inv @ np.hstack(cols)
        if np.all(np.isfinite(D)):
            out.D = np.asarray(D, dtype=np.float64)
    return out


class _JointProblem:
    """Stacked residuals of all annotators for one pose + intrinsics."""

    def __init__(
        self,
        scene: Scene,
        segments: list[dict[str, FloatArray]],
        indices: list[int],
        width_signs: list[float],
        size: ObjectSize,
        settings: CalibrationSettings,
        size_sigma_rel: float = 0.0,
    ) -> None:
        width, height = scene.image_size
        diag = math.hypot(width, height)
        self.sigma_pt = settings.sigma_point_rel * diag
        self.sigma_line = settings.sigma_line_rel * diag
        seg_rows, seg_axis, seg_ann = [], [], []
        pt_world, pt_pix, pt_ann = [], [], []
        worlds = {ws: _object_points(size, ws) for ws in set(width_signs)}
        for slot, (i, segs, ws) in enumerate(zip(indices, segments, width_signs, strict=True)):
            axes = scene.annotations[i].axes
            for axis in AXES:
                s = segs[axis]
                seg_rows.append(s)
                seg_axis += [_AXIS_INDEX[axis]] * len(s)
                seg_ann += [slot] * len(s)
            pt_world.append(worlds[ws])
            pt_pix += [axes.origin, axes.length, axes.width, axes.height]
            pt_ann += [slot] * 4
        self.size = size
        self.ws_common = 1.0 if sum(width_signs) >= 0 else -1.0
        # _corner_points of each corner (4, 4, 3), for set_corners and best_corners
        self._corner_table = np.stack([_corner_points(size, self.ws_common, c) for c in range(4)])
        self.corners = np.zeros(len(indices), dtype=int)
        self.segments = np.vstack(seg_rows)
        self.seg_axis = np.asarray(seg_axis)
        self.seg_ann = np.asarray(seg_ann)
        self.pt_world = np.vstack(pt_world)
        self.pt_pix = np.asarray(pt_pix, float)
        self.pt_ann = np.asarray(pt_ann)
        # An edge end's pixel is uncertain by the click noise and, along the edge, by the
        # object's size uncertainty (a preset's 5 % of the edge's length in pixels).
        clicks = self.pt_pix.reshape(-1, 4, 2)
        edge_px = np.zeros((len(clicks), 4))
        edge_px[:, 1:] = np.linalg.norm(clicks[:, 1:] - clicks[:, :1], axis=2)
        self._sigma_pt_each = np.sqrt(
            self.sigma_pt**2 + (size_sigma_rel * edge_px.reshape(-1)) ** 2
        )
        self.ground_corner_sigma_rel = settings.ground_corner_sigma_rel
        ratio = settings.ground_corner_click_ratio
        if ratio is None:  # the settings' own ratio of click to line-end sigmas
            line_rel = settings.sigma_line_rel
            ratio = settings.sigma_point_rel / line_rel if line_rel > 0.0 else 1.0
        self.ground_corner_click_ratio = ratio
        self.variance_groups = settings.variance_groups
        self.n_annotators = len(indices)
        self._z_min = 0.05
        seg = self.segments
        self._a = np.column_stack([seg[:, 0:2], np.ones(len(seg))])
        self._mid = np.column_stack([(seg[:, 0:2] + seg[:, 2:4]) / 2.0, np.ones(len(seg))])
        # segment_residuals_px's numerator is V · n for a vanishing point V = (x, y, w).
        x1, y1, mxs, mys = seg[:, 0], seg[:, 1], self._mid[:, 0], self._mid[:, 1]
        self._seg_n = np.column_stack([y1 - mys, mxs - x1, x1 * mys - y1 * mxs])
        self._seg_nT = np.ascontiguousarray(self._seg_n.T)
        self._mid_x, self._mid_y = self._mid[:, 0].copy(), self._mid[:, 1].copy()
        # Segments detected in the scene's photo (set_photo_segments): their rows follow the
        # clicks' (owned by no annotator, like the priors), with their own fixed sigma.
        self._seg_axis_all = self.seg_axis
        self._seg_op = self._segment_operator()
        self._photo_scale = np.zeros(0)
        self.photo_segments = np.zeros((0, 4))
        self.photo_axis = np.zeros(0, dtype=int)
        # Which witness each of those rows is: 0 the photo's, 1 the video's.
        self.photo_source = np.zeros(0, dtype=int)
        self.video_warnings: list[str] = []
        # The photo's vanishing point (pixels, homogeneous) lending each axis its segments.
        self.photo_axis_vp: dict[int, FloatArray] = {}
        self.weights = np.ones(self.n_annotators)
        self.f_bounds = (0.15 * width, 15.0 * width)
        # A weak log-normal prior on the focal length (settings.focal_prior_sigma_log; 0 = none).
        self.log_f_prior = math.log(settings.focal_prior_width * width)
        self.log_f_prior_sigma = 0.0  # switched on by _joint where the data leave f loose
        self.log_f_bounds = (math.log(self.f_bounds[0]), math.log(self.f_bounds[1]))
        self.image_wh = (float(width), float(height))
        # A Gaussian prior on a fitted principal point, at the image centre.
        self.pp_prior = np.array([width / 2.0, height / 2.0])
        self.pp_prior_sigma = settings.principal_point_prior_sigma_rel * math.hypot(width, height)
        # The last few evaluations: the covariance, the score test, the jackknife and the
        # annotators' RMS all look again at points the fits have just evaluated. They are
        # remembered with every annotator's weight 1 (the weights scale whole rows): a fit
        # after a reweighting starts from the point the last one ended at without a new
        # evaluation.
        self._memo: dict[tuple[Any, ...], _Evaluation] = {}
        self._jtj_inverse: tuple[FloatArray, FloatArray] | None = None  # see _jtj_inverse
        self._ground_corner_steps: tuple[FloatArray, npt.NDArray[np.bool_]] | None = None
        self._ground_corner_edge_sq: FloatArray | None = None

    def _memo_key(
        self,
        x: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> tuple[Any, ...]:
        return (
            np.asarray(x, dtype=float).tobytes(),
            np.asarray(R0, dtype=float).tobytes(),
            pp_fixed,
            f_fixed,
            self.corners.tobytes(),
            self.log_f_prior_sigma,
            self.pp_prior_sigma,
        )

    def _remember(self, key: tuple[Any, ...], r: FloatArray, J: FloatArray | None) -> _Evaluation:
        if len(self._memo) >= _MEMO_SIZE:
            self._memo.pop(next(iter(self._memo)))
        ev = _Evaluation(r, J)
        self._memo[key] = ev
        return ev

    def _weighted(self, ev: _Evaluation) -> _Evaluation:
        """``ev`` (unweighted) at the current weights; the same arrays while they hold."""
        w_ev = ev.weighted
        current = w_ev is not None and ev.weights_version == self._weights_version
        if current and w_ev is not None and (w_ev.J is not None or ev.J is None):
            return w_ev
        w = self._row_weights(len(ev.r))
        w_ev = _Evaluation(ev.r * w, None if ev.J is None else ev.J * w[:, None])
        ev.weighted, ev.weights_version = w_ev, self._weights_version
        return w_ev

    def _row_weights(self, n_rows: int) -> FloatArray:
        """√weight of each of ``n_rows`` residual rows: an annotation row its annotator's,
        the photo's segments and the priors 1."""
        w = self._row_w.get(n_rows)
        if w is None:
            w = np.ones(n_rows)
            w[: len(self._row_w_ann)] = self._row_w_ann
            self._row_w[n_rows] = w
        return w

    def _unit_residuals_batch(
        self,
        X: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> FloatArray:
        """:meth:`residuals_batch` with every annotator's weight 1."""
        return self._residuals_batch_scaled(
            X, R0, pp_fixed, f_fixed, self._seg_scale_unit, self._pt_scale_unit
        )

    def _segment_operator(self) -> FloatArray:
        """``(9, 3 S)``: ``KR.reshape(P, 9) @ op`` gives every segment's residual numerator
        ``V · n`` and the two components of its line's normal, ``(mx w − x, my w − y)``-wise,
        for the vanishing point ``V = K R e_a`` of its axis ``a`` (``S`` segments, the photo's
        after the annotations').

        One small matrix product per batch instead of a gather and ten element-wise
        operations on ``(P, S)`` arrays (numpy's per-call overhead is the cost there).
        """
        n_all = len(self._seg_axis_all)
        op = np.zeros((9, 3 * n_all))
        cols = np.arange(n_all)
        axis = np.asarray(self._seg_axis_all, dtype=int)
        for k in range(3):  # row k of K R, column a: index 3 k + a of KR.reshape(P, 9)
            op[3 * k + axis, cols] = self._seg_nT[k]
        op[axis, n_all + cols] = 1.0  # px − mx pw
        op[6 + axis, n_all + cols] = -self._mid_x
        op[3 + axis, 2 * n_all + cols] = -1.0  # my pw − py
        op[6 + axis, 2 * n_all + cols] = self._mid_y
        return op

    def ground_corner_steps(self) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
        """1-sigma moves of each click along its annotator's length and width edges
        (pixels): ``steps (n_pt, 2, 2)`` for click j, edge e, and which are ``live`` (a zero
        edge gives no column). Fixed by the clicks: computed once."""
        if self._ground_corner_steps is None:
            clicks = self.pt_pix.reshape(-1, 4, 2)
            edges = np.stack([clicks[:, 1] - clicks[:, 0], clicks[:, 2] - clicks[:, 0]], axis=1)
            steps = np.repeat(self.ground_corner_sigma_rel * edges, 4, axis=0)
            live = np.repeat(np.linalg.norm(edges, axis=2) > 0.0, 4, axis=0)
            self._ground_corner_steps = (steps, live)
        return self._ground_corner_steps

    def ground_corner_edge_sq(self) -> FloatArray:
        """Per annotator ``|length edge|² + |width edge|²`` of the clicks, pixels²."""
        if self._ground_corner_edge_sq is None:
            clicks = self.pt_pix.reshape(-1, 4, 2)
            self._ground_corner_edge_sq = np.sum(
                (clicks[:, 1] - clicks[:, 0]) ** 2, axis=1
            ) + np.sum((clicks[:, 2] - clicks[:, 0]) ** 2, axis=1)
        return self._ground_corner_edge_sq

    def add_video_segments(
        self, segments: npt.ArrayLike, axes: npt.ArrayLike, sigma_px: npt.ArrayLike
    ) -> None:
        """Add the video's witness segments after the photo's (``photo_source`` 1)."""
        segs = np.asarray(segments, dtype=float).reshape(-1, 4)
        sigma = np.broadcast_to(np.asarray(sigma_px, float), (len(segs),))
        n_photo = len(self.photo_segments)
        source = np.concatenate([self.photo_source[:n_photo], np.ones(len(segs), dtype=int)])
        self.set_photo_segments(
            np.vstack([self.photo_segments, segs]),
            np.concatenate([self.photo_axis, np.asarray(axes, dtype=int).reshape(-1)]),
            np.concatenate([1.0 / self._photo_scale[:n_photo], sigma]),
        )
        self.photo_source = source

    def set_photo_segments(
        self, segments: npt.ArrayLike, axes: npt.ArrayLike, sigma_px: npt.ArrayLike
    ) -> None:
        """Add segments detected in the photo: ``(k, 4)``, their axis index, 1-sigma (px)."""
        photo = np.asarray(segments, dtype=float).reshape(-1, 4)
        self.photo_source = np.zeros(len(photo), dtype=int)
        self.photo_segments = photo
        self.photo_axis = np.asarray(axes, dtype=int).reshape(-1)
        self._photo_scale = 1.0 / np.broadcast_to(np.asarray(sigma_px, float), (len(photo),))
        seg = np.vstack([self.segments, photo])
        self._seg_axis_all = np.concatenate([self.seg_axis, self.photo_axis])
        self._mid = np.column_stack([(seg[:, 0:2] + seg[:, 2:4]) / 2.0, np.ones(len(seg))])
        x1, y1, mxs, mys = seg[:, 0], seg[:, 1], self._mid[:, 0], self._mid[:, 1]
        self._seg_n = np.column_stack([y1 - mys, mxs - x1, x1 * mys - y1 * mxs])
        self._seg_nT = np.ascontiguousarray(self._seg_n.T)
        self._mid_x, self._mid_y = self._mid[:, 0].copy(), self._mid[:, 1].copy()
        self._seg_op = self._segment_operator()
        self._set_weights(self._weights)  # the scales of all segment rows
        self._memo.clear()

    def set_corners(self, corners: npt.ArrayLike) -> None:
        """Which ground corner of the car each annotator marked as the origin.

        0 is the common frame's origin, 1 the far end of its length edge, 2 the far end of
        its width edge, 3 the diagonal corner; the edges an annotator marks start at their
        corner, so their four clicks are the world points :func:`_corner_points` gives.
        """
        self.corners = np.asarray(corners, dtype=int)
        self.pt_world = self._corner_table[self.corners].reshape(-1, 3)

    def best_corners(
        self,
        x: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> npt.NDArray[np.int_]:
        """For each annotator, the corner hypothesis whose points best explain their clicks."""
        f, (cx, cy), R, C = self.unpack(x, R0, pp_fixed, f_fixed)
        pc = (self._corner_table.reshape(-1, 3) - C) @ R.T  # the 4 hypotheses' 4 points
        z = np.maximum(pc[:, 2], self._z_min)
        proj = (pc[:, :2] / z[:, None] * f + np.array([cx, cy])).reshape(4, 4, 2)
        clicks = self.pt_pix.reshape(-1, 4, 2)  # (n_annotators, 4, 2)
        err = np.linalg.norm(clicks[:, None, :, :] - proj[None, :, :, :], axis=3).sum(axis=2)
        return np.asarray(np.argmin(err, axis=1), dtype=int)

    def unpack(
        self,
        x: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> tuple[float, tuple[float, float], FloatArray, FloatArray]:
        """Focal length, principal point, rotation and camera centre of a parameter vector.

        As :meth:`_unpack_batch` of the one vector, in Python floats where that is cheaper.
        """
        xs = np.asarray(x, dtype=float).tolist()
        k = 0
        if f_fixed is None:
            f = math.exp(min(max(xs[0], self.log_f_bounds[0]), self.log_f_bounds[1]))
            k = 1
        else:
            f = float(f_fixed)
        if pp_fixed is None:
            pp = (float(xs[k]), float(xs[k + 1]))
            k += 2
        else:
            pp = (float(pp_fixed[0]), float(pp_fixed[1]))
        R = np.array(_rotvec_rows(*xs[k : k + 3])) @ R0
        return f, pp, R, np.array(xs[k + 3 : k + 6])

    def _unpack_batch(
        self,
        X: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        P = len(X)
        k = 0
        if f_fixed is None:
            f = np.exp(np.clip(X[:, 0], self.log_f_bounds[0], self.log_f_bounds[1]))
            k = 1
        else:
            f = np.full(P, float(f_fixed))
        if pp_fixed is None:
            pp = X[:, k : k + 2]
            k += 2
        else:
            pp = np.array([pp_fixed], dtype=float)  # (1, 2): broadcasts over the batch
        R = _rotvec_matrices(X[:, k : k + 3]) @ R0
        C = X[:, k + 3 : k + 6]
        return f, pp, R, C

    def residuals(
        self,
        x: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> FloatArray:
        """Normalised residuals (segments, then point u, then point v)."""
        x = np.asarray(x, dtype=float)
        key = self._memo_key(x, R0, pp_fixed, f_fixed)
        ev = self._memo.get(key)
        if ev is None:
            r = self._unit_residuals_batch(x[None, :], R0, pp_fixed, f_fixed)[0]
            ev = self._remember(key, r, None)
        return self._weighted(ev).r

    def unweighted_residuals(
        self,
        x: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> FloatArray:
        """The annotation residuals (segments, point u, point v) with every weight 1.

        From a remembered evaluation where there is one (they are remembered unweighted),
        else evaluated.
        """
        n_rows = len(self.segments) + 2 * len(self.pt_pix)
        x = np.asarray(x, dtype=float)
        key = self._memo_key(x, R0, pp_fixed, f_fixed)
        ev = self._memo.get(key)
        if ev is None:
            r = self._unit_residuals_batch(x[None, :], R0, pp_fixed, f_fixed)[0]
            ev = self._remember(key, r, None)
        return ev.r[:n_rows]

    def jacobian(
        self,
        x: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> FloatArray:
        """Forward-difference Jacobian from one batched evaluation."""
        return self.residuals_and_jacobian(x, R0, pp_fixed, f_fixed)[1]

    def residuals_and_jacobian(
        self,
        x: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> tuple[FloatArray, FloatArray]:
        """The residuals and their forward-difference Jacobian from one batched evaluation."""
        x = np.asarray(x, dtype=float)
        key = self._memo_key(x, R0, pp_fixed, f_fixed)
        ev = self._memo.get(key)
        if ev is None or ev.J is None:
            n = len(x)
            h = 1e-7 * np.maximum(1.0, np.abs(x))
            X = np.empty((n + 1, n))
            X[:] = x
            X[1:] += np.diag(h)
            Rb = self._unit_residuals_batch(X, R0, pp_fixed, f_fixed)
            J = np.asarray(((Rb[1:] - Rb[0]) / h[:, None]).T.reshape(-1, n), dtype=np.float64)
            ev = self._remember(key, np.asarray(Rb[0], dtype=np.float64), J)
        w_ev = self._weighted(ev)
        assert w_ev.J is not None
        return w_ev.r, w_ev.J

    def residuals_batch(
        self,
        X: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> FloatArray:
        """Residuals of a batch of parameter vectors ``(P, n)`` → ``(P, m)``."""
        return self._residuals_batch_scaled(
            X, R0, pp_fixed, f_fixed, self._seg_scale, self._pt_scale
        )

    @staticmethod
    def _f_rows(f: FloatArray) -> FloatArray:
        """``(P, 3, 1)``: ``f``, ``f``, 1 per row of ``R`` (the diagonal of ``K``)."""
        out = np.ones((len(f), 3, 1))
        out[:, :2, 0] = f[:, None]
        return out

    def _residuals_batch_scaled(
        self,
        X: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
        seg_scale: FloatArray,
        pt_scale: FloatArray,
    ) -> FloatArray:
        """:meth:`residuals_batch` with the rows scaled by ``seg_scale`` (every segment's,
        the photo's after the annotations') and ``pt_scale`` (every click's)."""
        f, pp, R, C = self._unpack_batch(X, R0, pp_fixed, f_fixed)
        return self._residuals_of_parts(f, pp, R, C, pp_fixed, f_fixed, seg_scale, pt_scale)

    def residuals_of_unpacked(
        self,
        f: FloatArray,
        pp: FloatArray,
        R: FloatArray,
        C: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> FloatArray:
        """:meth:`residuals_batch` of a batch already unpacked by :meth:`_unpack_batch`
        (``f`` ``(P,)``, ``pp`` ``(P, 2)`` or ``(1, 2)``, ``R`` ``(P, 3, 3)``, ``C``
        ``(P, 3)``): the same rows, for a caller that unpacks a larger batch once."""
        return self._residuals_of_parts(
            f, pp, R, C, pp_fixed, f_fixed, self._seg_scale, self._pt_scale
        )

    def _residuals_of_parts(
        self,
        f: FloatArray,
        pp: FloatArray,
        R: FloatArray,
        C: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
        seg_scale: FloatArray,
        pt_scale: FloatArray,
    ) -> FloatArray:
        # Vanishing point of world axis i: K R e_i, column i of KR = [f R₀ + cx R₂; f R₁ + cy R₂;
        # R₂] (rows of R); each segment takes its axis' column: KRs (P, 3, n_seg + n_photo).
        KR = R * self._f_rows(f)
        KR[:, :2, :] += pp[:, :, None] * R[:, 2:3, :]
        # Line through the midpoint (mx, my, 1) and the vanishing point (px, py, pw); the
        # first endpoint's distance from it: its numerator is linear in the point, V · n (n
        # precomputed), and so are the line normal's components (px − mx pw, my pw − py):
        # all three from one product with _segment_operator's matrix.
        n_all = len(self._seg_axis_all)
        lin = KR.reshape(len(KR), 9) @ self._seg_op
        num = lin[:, :n_all]
        norm = np.hypot(lin[:, 2 * n_all :], lin[:, n_all : 2 * n_all])
        r_all = num / np.maximum(norm, 1e-300) * seg_scale
        n_seg = len(self.segments)
        r_seg = r_all[:, :n_seg]
        pc = (self.pt_world[None, :, :] - C[:, None, :]) @ np.swapaxes(R, 1, 2)
        z = np.maximum(pc[:, :, 2:3], self._z_min)
        # u and v at once: (P, n_pt, 2)
        uv = (pc[:, :, :2] / z * f[:, None, None] + (pp[:, None, :] - self.pt_pix)) * pt_scale[
            :, None
        ]
        u, v = uv[:, :, 0], uv[:, :, 1]
        parts = [r_seg, u, v]
        if len(self.photo_segments):
            parts.append(r_all[:, n_seg:])
        if f_fixed is None and self.log_f_prior_sigma > 0.0:
            parts.append((np.log(f) - self.log_f_prior)[:, None] / self.log_f_prior_sigma)
        if pp_fixed is None and self.pp_prior_sigma > 0.0:
            parts.append((pp - self.pp_prior) / self.pp_prior_sigma)
        return np.concatenate(parts, axis=1)

    @property
    def weights(self) -> FloatArray:
        return self._weights

    @weights.setter
    def weights(self, value: FloatArray) -> None:
        new = np.array(value, dtype=float)  # a copy: the version below holds
        old = getattr(self, "_weights", None)
        if old is not None and old.shape == new.shape and bool(np.array_equal(old, new)):
            # The same weights (a save-and-restore around a step at the fit's own weights):
            # every scale below, and the memo's weighted copies, hold as they are.
            return
        self._set_weights(new)

    def _set_weights(self, new: FloatArray) -> None:
        """The weights and every row scale derived from them (a new weights version)."""
        self._weights = new
        self._w_seg = np.sqrt(self._weights[self.seg_ann])
        self._w_pt = np.sqrt(self._weights[self.pt_ann])
        self._seg_scale = np.concatenate([self._w_seg / self.sigma_line, self._photo_scale])
        self._pt_scale = self._w_pt / self._sigma_pt_each
        self._row_w_ann = np.concatenate([self._w_seg, self._w_pt, self._w_pt])
        self._row_w: dict[int, FloatArray] = {}
        self._weights_version = getattr(self, "_weights_version", 0) + 1
        n_seg = len(self.segments)
        self._seg_scale_unit = np.concatenate(
            [np.full(n_seg, 1.0 / self.sigma_line), self._photo_scale]
        )
        self._pt_scale_unit = 1.0 / self._sigma_pt_each

    def per_annotator_rms(
        self,
        x: FloatArray,
        R0: FloatArray,
        pp_fixed: tuple[float, float] | None,
        f_fixed: float | None,
    ) -> FloatArray:
        r = self.unweighted_residuals(x, R0, pp_fixed, f_fixed)
        n_seg, n_pt = len(self.segments), len(self.pt_pix)
        sq_seg = r[:n_seg] ** 2
        sq_pt = r[n_seg : n_seg + n_pt] ** 2 + r[n_seg + n_pt : n_seg + 2 * n_pt] ** 2
        num = np.bincount(self.seg_ann, sq_seg, self.n_annotators) + np.bincount(
            self.pt_ann, sq_pt, self.n_annotators
        )
        den = np.bincount(self.seg_ann, None, self.n_annotators) + 2 * np.bincount(
            self.pt_ann, None, self.n_annotators
        )
        return np.asarray(np.sqrt(num / np.maximum(den, 1)), dtype=np.float64)


_MEMO_SIZE = 8  # evaluations a _JointProblem remembers


class _Evaluation:
    """A remembered evaluation: residuals ``r``, Jacobian ``J`` (or None), and the same at
    the weights of ``weights_version`` (``weighted``), kept for the next call."""

    __slots__ = ("J", "r", "weighted", "weights_version")

    def __init__(self, r: FloatArray, J: FloatArray | None) -> None:
        self.r, self.J = r, J
        self.weighted: _Evaluation | None = None
        self.weights_version = -1


_F_SCALE = 2.5  # soft-L1 scale of the normalised residuals (in sigmas)
_GOOD_SEED_SCORE = 1.0  # median annotator RMS (in sigmas) at which a seed's fit is good


def _rotvec_matrices(rotvecs: FloatArray) -> FloatArray:
    """Rotation matrices ``(P, 3, 3)`` of rotation vectors ``(P, 3)`` (Rodrigues, vectorised).

    The joint fit evaluates a batch of nearby parameter vectors per Jacobian; scipy's
    ``Rotation.from_rotvec`` costs more in its per-call checks than the formula itself. The
    matrices are small, so numpy's per-call overhead is the cost: up to
    ``_ROTVEC_SCALAR_MAX`` vectors (one evaluation and its Jacobian) go through
    :func:`_rotvec_rows` in Python floats and one array construction (19 -> 2 µs for one
    vector, 20 -> 12 µs for eight); larger batches through the array formula.
    """
    w = np.asarray(rotvecs, dtype=float)
    if len(w) <= _ROTVEC_SCALAR_MAX:
        return np.array([_rotvec_rows(x, y, z) for x, y, z in w.tolist()]).reshape(-1, 3, 3)
    theta2 = np.einsum("pi,pi->p", w, w)
    theta = np.sqrt(theta2)
    small = theta2 < 1e-12
    safe = np.where(small, 1.0, theta)
    # sin θ / θ and (1 - cos θ) / θ², with their Taylor series near zero.
    a = np.where(small, 1.0 - theta2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - theta2 / 24.0, (1.0 - np.cos(safe)) / (safe * safe))
    K = np.zeros((len(w), 3, 3))
    K[:, 0, 1], K[:, 0, 2] = -w[:, 2], w[:, 1]
    K[:, 1, 0], K[:, 1, 2] = w[:, 2], -w[:, 0]
    K[:, 2, 0], K[:, 2, 1] = -w[:, 1], w[:, 0]
    return np.asarray(
        np.eye(3)[None] + a[:, None, None] * K + b[:, None, None] * (K @ K), dtype=np.float64
    )


_ROTVEC_SCALAR_MAX = 12  # batches up to this size: Python floats (see _rotvec_matrices)


def _rotvec_rows(x: float, y: float, z: float) -> list[list[float]]:
    """The rotation matrix of one rotation vector ``(x, y, z)`` as nested lists.

    ``R = I + a K + b K²`` (as :func:`_rotvec_matrices`), with ``K² = w wᵀ − θ² I``.
    """
    t2 = x * x + y * y + z * z
    if t2 < 1e-12:
        a, b = 1.0 - t2 / 6.0, 0.5 - t2 / 24.0
    else:
        t = math.sqrt(t2)
        a, b = math.sin(t) / t, (1.0 - math.cos(t)) / t2
    bx, by, bz = b * x, b * y, b * z
    return [
        [1.0 - (by * y + bz * z), bx * y - a * z, bx * z + a * y],
        [bx * y + a * z, 1.0 - (bx * x + bz * z), by * z - a * x],
        [bx * z - a * y, by * z + a * x, 1.0 - (bx * x + by * y)],
    ]


def _small_rotvec(R: FloatArray) -> FloatArray:
    """Rotation vector of a rotation matrix turned by less than ~170° (the log map).

    For the small turns between nearby fits; scipy's ``Rotation.from_matrix`` costs ~50 µs
    a call in its checks. Near 180° (never met here) the axis is ill-conditioned, so
    :func:`camloc_geo.camera.rotvec_from_rotation` takes over there.
    """
    R = np.asarray(R, dtype=float)
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R.tolist()  # Python floats: cheaper
    cos_t = min(max((r00 + r11 + r22 - 1.0) / 2.0, -1.0), 1.0)
    theta = math.acos(cos_t)
    v = np.array([r21 - r12, r02 - r20, r10 - r01])
    if theta < 1e-6:
        return np.asarray(0.5 * v, dtype=np.float64)  # sin θ ≈ θ
    if theta > math.radians(170.0):
        return rotvec_from_rotation(R)  # the quaternion route, stable near 180°
    return np.asarray(theta / (2.0 * math.sin(theta)) * v, dtype=np.float64)


# Every fit stops once its next Gauss-Newton step would move the answer by less than this
# fraction of its own 1-sigma (the Newton decrement, soft_l1_least_squares's sigma_tol).
_SIGMA_TOL = 0.01
# The seeds' fits only rank the seeds and start the reweighting: a sigma is close enough
# (0.3 -> 1.0: evaluations 6.8 -> 4.2 a seed; relative.py --n 100 the same figures, every
# camera within 0.16 of its sigma of the fits to the tolerances alone, 99 % within 0.023).
_SEED_SIGMA_TOL = 1.0
_RW_SIGMA_TOL = 0.1  # the reweighting and corner refits


def _fit(
    prob: _JointProblem,
    x0: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float] | None,
    f_fixed: float | None,
    *,
    tol: float = 1e-10,
    max_nfev: int = 200,
    method: Literal["lm", "scipy"] = "lm",
    sigma_tol: float | None = _SIGMA_TOL,
) -> LeastSquaresResult:
    """One robust fit (soft-L1) by :func:`camloc_geo._optimize.soft_l1_least_squares`
    (``method="lm"``: its loop's steps by ``soft_l1_least_squares_small``).

    The focal length is clamped to plausible fields of view inside the parameterisation.
    """
    from camloc_geo._optimize import soft_l1_least_squares, soft_l1_least_squares_small

    lo, hi = prob.log_f_bounds

    def clamp_focal(x: FloatArray) -> FloatArray:
        v = float(x[0])
        if lo <= v <= hi:
            return x  # the usual case: no copy (the solver never changes x in place)
        x = x.copy()
        x[0] = min(max(v, lo), hi)
        return x

    project = clamp_focal if f_fixed is None else None
    # Every fit starts near its minimum (a closed-form seed, or the previous fit): a light
    # initial damping takes fewer steps (the seed's fit 13.0 -> 12.7 evaluations, the
    # reweighting fits 5.1 -> 4.1, the final 3.4 -> 2.1).
    if method == "lm":  # the same steps as soft_l1_least_squares's loop, cheaper a step
        return soft_l1_least_squares_small(
            lambda x: prob.residuals_and_jacobian(x, R0, pp_fixed, f_fixed),
            x0,
            f_scale=_F_SCALE,
            project=project,
            tol=tol,
            max_nfev=max_nfev,
            damping=1e-4,
            sigma_tol=sigma_tol,
        )
    return soft_l1_least_squares(
        lambda x: prob.residuals(x, R0, pp_fixed, f_fixed),
        lambda x: prob.jacobian(x, R0, pp_fixed, f_fixed),
        x0,
        f_scale=_F_SCALE,
        project=project,
        method=method,
        tol=tol,
        max_nfev=max_nfev,
        fun_and_jac=lambda x: prob.residuals_and_jacobian(x, R0, pp_fixed, f_fixed),
        damping=1e-4,
        sigma_tol=sigma_tol,
    )


def _score_test(
    prob: _JointProblem,
    x_fixed: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float],
    f_fixed: float | None,
) -> float:
    """Expected cost drop from freeing the principal point (Rao score statistic).

    Evaluated at the fixed-principal-point solution: with ``g`` the gradient and ``H`` the
    Gauss-Newton Hessian of the full model, ``gᵀ H⁻¹ g`` approximates how much the cost
    would fall, at the price of one Jacobian.
    """
    # The parameters with the principal point inserted, as _pinned_pp_sensitivity builds
    # them (the same evaluation serves both).
    x1 = _with_pp(x_fixed, int(f_fixed is None), pp_fixed)
    r, J = prob.residuals_and_jacobian(x1, R0, None, f_fixed)
    # Robust (soft-L1) weights at the current residuals, as the fit sees them.
    z = (r / _F_SCALE) ** 2
    w = 1.0 / np.sqrt(1.0 + z)
    Jw = J * np.sqrt(w)[:, None]
    g = Jw.T @ (r * np.sqrt(w))
    try:
        return float(g @ _sym_inverse(Jw.T @ Jw) @ g)
    except np.linalg.LinAlgError:
        return 0.0


def _with_pp(x: npt.ArrayLike, k: int, pp: npt.ArrayLike) -> FloatArray:
    """``x`` with the principal point's two entries inserted at ``k`` (``np.insert``)."""
    x = np.asarray(x, dtype=float)
    return np.concatenate([x[:k], np.asarray(pp, dtype=float).reshape(2), x[k:]])


def _sym_inverse(A: FloatArray) -> FloatArray:
    """Inverse of a symmetric positive semi-definite matrix: Cholesky where it is well
    conditioned (~4x cheaper than an SVD on these 7-9 parameter problems), else the
    pseudo-inverse (a singular direction gets no variance, as before)."""
    d = np.sqrt(np.clip(np.diag(A), 1e-300, None))
    As = A / d[:, None] / d[None, :]
    try:
        L = np.linalg.cholesky(As)
    except np.linalg.LinAlgError:
        return np.asarray(np.linalg.pinv(A), dtype=np.float64)
    if float(np.min(np.diag(L))) ** 2 < 1e-10:  # nearly singular: as the pseudo-inverse
        return np.asarray(np.linalg.pinv(A), dtype=np.float64)
    L_inv = np.linalg.inv(L)
    return np.asarray((L_inv.T @ L_inv) / d[:, None] / d[None, :], dtype=np.float64)


def _pack(
    f: float, pp: tuple[float, float], C: FloatArray, free_f: bool, free_pp: bool
) -> FloatArray:
    parts: list[float] = []
    if free_f:
        parts.append(math.log(f))
    if free_pp:
        parts += [pp[0], pp[1]]
    return np.array([*parts, 0.0, 0.0, 0.0, *C], dtype=float)


# ------------------------------------------------------------------------------- driver
def _gather_segments(scene: Scene, index: int) -> tuple[dict[str, FloatArray], list[str]]:
    """An annotator's segments per axis, completed from the image where it lacks some.

    Returns the segments and the names of the axes that still have fewer than two.
    """
    ann = scene.annotations[index]
    out = {axis: _segments(ann, axis) for axis in AXES}
    short = [axis for axis in AXES if len(out[axis]) < 2]
    if short:
        filled = _auto_segments(scene, index, short)
        for axis, segs in filled.items():
            if len(segs) >= 2:
                out[axis] = segs
        short = [axis for axis in AXES if len(out[axis]) < 2]
    return out, short


def _check_segment_counts(
    scene: Scene, shorts: list[list[str]], segs: list[dict[str, FloatArray]]
) -> list[str]:
    """Raise if an axis cannot be determined at all; warnings for annotators that lack lines.

    A crowd annotator who drew fewer than two lines for an axis gets no closed-form
    solution of their own, but their lines and axis pixels still count in the joint fit.
    The scene is rejected only when the pooled lines of an axis are fewer than two; when no
    annotator has a closed form of their own, the pooled lines seed the joint fit.
    """
    warnings = []
    for axis in AXES:
        total = sum(len(s[axis]) for s in segs)
        if total < 2:
            i = next(i for i, sh in enumerate(shorts) if axis in sh)
            raise SceneError(
                f"needs at least 2 segments parallel to the {axis} axis, got "
                f"{len(segs[i][axis])}"
                + ("" if scene.image_file() else " (and the scene has no image to detect them in)"),
                f"annotations[{i}].vp_lines.{axis}",
            )
    for i, sh in enumerate(shorts):
        for axis in sh:
            warnings.append(
                f"annotations[{i}].vp_lines.{axis}: fewer than 2 segments; this annotator has "
                "no closed-form solution and counts only in the joint fit"
            )
    return warnings


@functools.lru_cache(maxsize=4)
def _detect_vps(
    path: str,
    _mtime_ns: int,
    _size: int,
    distortion_k1: float | None = None,
    principal_point: tuple[float, float] | None = None,
) -> Any:
    """The image's detected vanishing points, cached per file version (thread-safe).

    With a ``distortion_k1`` (the scene's ``camera.distortion``) the detector undistorts
    its segments about ``principal_point`` (the image centre when None) before the fit:
    the vanishing points are the pinhole camera's, the segments stay in the photo's pixels
    (:func:`_photo_segments_px` maps them).
    """
    from camloc_geo import autovp

    # The photo's own vanishing points: the default focal prior of a photo that leaves its
    # focal length loose would turn them about (the annotators' fit has its own focal
    # length), and its lines would then seem to disagree with the fit.
    return autovp.detect_vanishing_points(
        path,
        distortion_k1=distortion_k1,
        principal_point=principal_point,
        default_focal_prior=False,
    )


def _scene_lens(scene: Scene) -> tuple[float | None, tuple[float, float] | None]:
    """The scene's distortion ``k1`` (None without one) and the point it is centred on."""
    dist = scene.camera.distortion
    if dist is None or dist.k1 == 0.0:
        return None, None
    pp = scene.camera.principal_point
    return float(dist.k1), (None if pp is None else (float(pp[0]), float(pp[1])))


_DETECT_LOCKS: dict[tuple[Any, ...], threading.Lock] = {}
_DETECT_LOCKS_GUARD = threading.Lock()


def _detect_scene_vps(scene: Scene, path: Path) -> Any:
    """:func:`_detect_vps` of ``path`` (an existing file) with ``scene``'s lens.

    Threads asking for the same photo at once wait for the first one's detection (the
    cache would otherwise miss in each of them: 4 threads, 4 detections of one photo).
    """
    stat = path.stat()
    k1, pp = _scene_lens(scene)
    key = (str(path.resolve()), stat.st_mtime_ns, stat.st_size, k1, pp)
    with _DETECT_LOCKS_GUARD:
        lock = _DETECT_LOCKS.get(key)
        if lock is None:
            if len(_DETECT_LOCKS) >= 64:  # bounded: a lock dropped here costs a detection
                _DETECT_LOCKS.clear()
            lock = _DETECT_LOCKS[key] = threading.Lock()
    with lock:
        return _detect_vps(*key)


def _photo_segments_px(scene: Scene, segments: npt.ArrayLike) -> FloatArray:
    """The photo's ``(N, 4)`` segments in the scene's pinhole pixels (``camera.distortion``).

    The same mapping as :meth:`camloc_geo.scene.Scene.undistorted` (about
    ``camera.principal_point``, else the image centre); a segment the model maps through
    infinity is NaN. Without a distortion the segments themselves.
    """
    segs = np.asarray(segments, dtype=np.float64).reshape(-1, 4)
    k1, pp = _scene_lens(scene)
    if k1 is None or len(segs) == 0:
        return segs
    from camloc_geo.camera import RadialDistortion, undistort_points_px

    w, h = scene.image_size
    centre = pp if pp is not None else (w / 2.0, h / 2.0)
    und = undistort_points_px(segs.reshape(-1, 2), RadialDistortion.for_image(k1, w, h), centre)
    return np.asarray(und.reshape(-1, 4), dtype=np.float64)


def _auto_segments(scene: Scene, index: int, axes: list[str]) -> dict[str, FloatArray]:
    """Segments for axes an annotator drew no lines for, from the image (if any)."""
    path = line_photo(scene)  # not a scaled copy: its pixels are the annotations'
    if path is None or not path.is_file():  # is_file: a FIFO or a device would block
        return {}
    try:
        from camloc_geo import autovp
    except ImportError:  # pragma: no cover - autovp ships with the package
        return {}
    try:
        res = _detect_scene_vps(scene, path)
    except InputError as exc:
        log.warning("image.path: no lines detected in %s: %s", path, exc)
        return {}
    ann = scene.annotations[index]
    out = {}
    for axis in axes:
        try:
            segs = _photo_segments_px(
                scene, autovp.segments_for_axis(res, ann.axes.origin, getattr(ann.axes, axis))
            )
            out[axis] = segs[np.all(np.isfinite(segs), axis=1)]
            log.info("annotations[%d]: %s segments detected in the image", index, axis)
        except InputError as exc:
            log.info("annotations[%d]: no %s segments in the image: %s", index, axis, exc)
    return out


# ------------------------------------------------------------------ crowd input screening
PLAUSIBLE_HEIGHT_M = (0.3, 300.0)
"""A mounted camera stands between these heights above the car's ground plane (metres)."""
PLAUSIBLE_DISTANCE_M = 1000.0
"""A camera farther than this from the car (horizontally, metres) cannot resolve it."""
PLAUSIBLE_FOCAL_DIAG = (0.15, 20.0)
"""Plausible focal lengths, as multiples of the image diagonal (fish-eye to long zoom)."""
MIN_SEGMENT_PX = 2.0
"""Segments shorter than this are degenerate: dropped, with a warning."""
_MAX_LEAVE_OUT = 12
_MAX_JACKKNIFE = 12


@dataclass
class _Screening:
    """What :func:`_screen_annotations` kept, clamped and left out."""

    scene: Scene
    kept: list[int]
    excluded: list[dict[str, Any]]
    clamped_clicks: int
    warnings: list[str]
    dropped: list[_DroppedSegment] = field(default_factory=list)


@dataclass(frozen=True)
class _DroppedSegment:
    """A segment the screen left out: whose (scene index), which axis and position, why."""

    index: int
    axis: str
    position: int
    segment: tuple[float, ...]
    warning: str


def _screen_annotation(
    scene: Scene, index: int, margin: float
) -> tuple[Annotation | None, str | None, int, list[str]]:
    """One annotator's work, clamped onto the image, or the reason it is unusable."""
    ann = scene.annotations[index]
    w, h = scene.image_size
    clamped = 0
    notes: list[str] = []
    axes: dict[str, tuple[float, ...]] = {}
    for name in ("origin", "length", "width", "height"):
        problem, values, n = pixel_problem(getattr(ann.axes, name), w, h, margin)
        if problem is not None:
            return None, f"axes.{name}: {problem}", 0, []
        axes[name], clamped = values, clamped + n
    lines: dict[str, list[tuple[float, ...]]] = {}
    for axis in AXES:
        kept_segs = []
        for j, seg in enumerate(getattr(ann.vp_lines, axis)):
            problem, values, n = pixel_problem(seg, w, h, margin)
            if problem is not None:
                return None, f"vp_lines.{axis}[{j}]: {problem}", 0, []
            clamped += n
            if math.hypot(values[2] - values[0], values[3] - values[1]) < MIN_SEGMENT_PX:
                notes.append(
                    f"annotations[{index}].vp_lines.{axis}[{j}] ({ann.annotator}): shorter than "
                    f"{MIN_SEGMENT_PX:g} px; left out"
                )
                continue
            kept_segs.append(values)
        lines[axis] = kept_segs
    new = ann.model_copy(
        update={
            "axes": ann.axes.model_copy(update=axes),
            "vp_lines": ann.vp_lines.model_copy(update=lines),
        }
    )
    try:
        _check_axes_geometry(new, "annotation")
    except DegenerateGeometryError as exc:
        return None, str(exc).removeprefix("annotation."), 0, []
    if len({tuple(np.round(getattr(new.axes, k), 6)) for k in ("length", "width", "height")}) < 3:
        return None, "axes: two edge ends on the same pixel", 0, []
    return new, None, clamped, notes


def _work_key(ann: Annotation) -> tuple[float, ...]:
    """An annotator's clicks and lines, rounded to 0.01 px (the annotator's name left out)."""
    values: list[float] = []
    for name in ("origin", "length", "width", "height"):
        values += getattr(ann.axes, name)
    for axis in AXES:
        values.append(-1.0)  # separates the axes' lines
        for seg in getattr(ann.vp_lines, axis):
            values += seg
    return tuple(round(float(v), 2) for v in values)


def _screen_annotations(scene: Scene, sigma_line_rel: float = 0.001) -> _Screening:
    """Clamp slips onto the image; leave out annotators and hints that cannot be used.

    An annotator is left out (with a warning naming them and the reason) when a click is not
    finite or lies farther outside the image than the margin
    (:attr:`~camloc_geo.scene.Scene.pixel_margin_px`), when their axes are degenerate (an
    edge end on the origin, two edges collinear), or when their clicks and lines are another
    annotator's (a duplicated submission, under any name). Clicks within the margin are
    clamped and counted. Camera hints outside plausible ranges are ignored with a warning.
    """
    margin = scene.pixel_margin_px
    kept: list[int] = []
    anns: list[Annotation] = []
    excluded: list[dict[str, Any]] = []
    warnings: list[str] = list(scene.input_warnings)
    clamped = 0
    seen: dict[tuple[float, ...], int] = {}
    for i, ann in enumerate(scene.annotations):
        new, reason, n, notes = _screen_annotation(scene, i, margin)
        first = None if new is None else seen.setdefault(_work_key(new), i)
        if new is not None and first is not None and first != i:
            # The same work submitted twice is one witness: counted twice it halves the
            # annotators' spread and doubles its own weight (benchmarks/crowd_slips.py).
            new, reason = (
                None,
                (
                    f"annotator: the same clicks and lines as annotations[{first}] "
                    f"({scene.annotations[first].annotator!r}); a duplicated submission counts once"
                ),
            )
        if new is None:
            geometry = not (reason or "").split(": ", 1)[-1].startswith("pixel")
            excluded.append(
                {"annotator": ann.annotator, "index": i, "reason": reason, "geometry": geometry}
            )
            warnings.append(f"annotator {ann.annotator!r} (annotations[{i}]) left out: {reason}")
            continue
        warnings += notes
        kept.append(i)
        anns.append(new)
        clamped += n
    if clamped:
        log.info("%d click(s) just outside the image clamped onto it", clamped)
    dropped: list[_DroppedSegment] = []
    anns, kept = _screen_segments(scene, anns, kept, excluded, warnings, dropped, sigma_line_rel)
    update: dict[str, Any] = {"annotations": anns}
    hints: dict[str, Any] = {}
    w, h = scene.image_size
    diag = math.hypot(w, h)
    f = scene.camera.focal_px
    lo, hi = PLAUSIBLE_FOCAL_DIAG
    if f is not None and not lo * diag <= f <= hi * diag:
        hints["focal_px"] = None
        excluded_value = (
            f"camera.focal_px: {f:g} px is implausible for a {w}x{h} image "
            f"(plausible {lo * diag:.0f}-{hi * diag:.0f} px); ignored, estimated instead"
        )
        warnings.append(excluded_value)
    pp = scene.camera.principal_point
    if pp is not None and not (
        math.isfinite(pp[0]) and math.isfinite(pp[1]) and 0 <= pp[0] <= w and 0 <= pp[1] <= h
    ):
        hints["principal_point"] = None
        msg = (
            f"camera.principal_point: [{pp[0]:g}, {pp[1]:g}] is outside the {w}x{h} image; ignored"
        )
        warnings.append(msg)
    if hints:
        update["camera"] = scene.camera.model_copy(update=hints)
    kept_set = set(kept)
    dropped = [d for d in dropped if d.index in kept_set]
    return _Screening(scene.model_copy(update=update), kept, excluded, clamped, warnings, dropped)


def _residuals_to_many(segments: FloatArray, V: FloatArray) -> FloatArray:
    """:func:`segment_residuals_px` of every segment to every vanishing point: ``(P, n)``."""
    mx = (segments[:, 0] + segments[:, 2]) / 2.0
    my = (segments[:, 1] + segments[:, 3]) / 2.0
    px, py, pw = V[:, 0:1], V[:, 1:2], V[:, 2:3]
    la, lb = my * pw - py, px - mx * pw
    lc = mx * py - my * px
    out = (la * segments[:, 0] + lb * segments[:, 1] + lc) / np.maximum(np.hypot(la, lb), 1e-300)
    return np.asarray(out, dtype=np.float64)


def _consensus_residuals(
    segments: FloatArray, diag: float, sigma_px: float
) -> tuple[FloatArray, float] | None:
    """Residuals (px) of segments to their consensus vanishing point, and the noise scale.

    Every line is a witness in proportion to its information. A segment of length ``L``
    whose endpoints are off by ``σ`` misses a vanishing point ``θ`` away from its direction
    by ``r ≈ L/2 · sin θ``, so its standardised residual ``r / σ`` counts the sigmas of its
    own angular precision ``σ / L``: a 560 px road line 0.5° off a point is many sigmas out,
    a 30 px car edge is not, and a point the short edges merely tolerate cannot outvote the
    long lines. Candidates are the intersections of pairs of segments (all pairs up to 25
    segments; beyond, 300 seeded random pairs and every pair of the 12 longest). The noise
    scale is the least-median-of-squares one (at least ``sigma_px``), and each candidate is
    scored by the truncated cost ``Σ min(rᵢ², T²)`` (MSAC, ``T`` = three noise scales): the
    best-determined point, the one every line fits within its own noise, wins, not the one
    most lines happen to tolerate. It is refined by a fit to its inliers, and the inliers
    re-admitted against the refined point until they settle: a line that agrees with the
    final fit is not left out.

    Parameters
    ----------
    segments
        ``(n, 4)`` segments, pixels.
    diag
        Image diagonal, pixels.
    sigma_px
        Endpoint noise of a drawn segment, pixels.

    Returns
    -------
    ``(n,)`` absolute residuals and their robust scale (pixels, at least 0.2 % of the
    diagonal), or None when no pair of segments meets.
    """
    n = len(segments)
    lengths = np.hypot(segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1])
    # np.cross of (x1, y1, 1) and (x2, y2, 1), written out: the same products and
    # differences (y1 * 1 is y1 exactly), without its per-call axis handling.
    x1, y1, x2, y2 = segments[:, 0], segments[:, 1], segments[:, 2], segments[:, 3]
    lines = np.empty((n, 3))
    lines[:, 0], lines[:, 1], lines[:, 2] = y1 - y2, x2 - x1, x1 * y2 - y1 * x2
    lines /= np.maximum(np.linalg.norm(lines[:, :2], axis=1), 1e-12)[:, None]
    if n <= 25:
        pairs = np.array([(i, j) for i in range(n) for j in range(i + 1, n)])
    else:
        rng = np.random.default_rng(0)
        longest = np.argsort(-lengths)[:12]
        pairs = np.vstack(
            [
                rng.integers(0, n, (300, 2)),
                np.array([(a, b) for k, a in enumerate(longest) for b in longest[k + 1 :]]),
            ]
        )
        pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    if len(pairs) == 0:
        return None
    # Candidate vanishing points (P, 3): np.cross of the pairs' lines, written out.
    l0, l1 = lines[pairs[:, 0]], lines[pairs[:, 1]]
    V = np.empty((len(pairs), 3))
    V[:, 0] = l0[:, 1] * l1[:, 2] - l0[:, 2] * l1[:, 1]
    V[:, 1] = l0[:, 2] * l1[:, 0] - l0[:, 0] * l1[:, 2]
    V[:, 2] = l0[:, 0] * l1[:, 1] - l0[:, 1] * l1[:, 0]
    V = V[np.all(np.isfinite(V), axis=1) & (np.linalg.norm(V, axis=1) > 0)]
    if len(V) == 0:
        return None
    V /= np.linalg.norm(V, axis=1)[:, None]
    res = np.abs(_residuals_to_many(segments, V))
    noise = max(1.4826 * float(np.min(np.median(res, axis=1))), sigma_px)
    threshold = 3.0 * noise
    cost = np.sum(np.minimum(res, threshold) ** 2, axis=1)
    r = res[int(np.argmin(cost))]
    floor = max(sigma_px, 0.002 * diag)
    scale = max(noise, floor)
    inliers = r <= threshold
    for _ in range(5):
        if inliers.sum() < 2:
            break
        try:
            vp = fit_vanishing_point(segments[inliers], scale_px=diag, name="pooled")
        except (DegenerateGeometryError, np.linalg.LinAlgError):
            break
        r = np.abs(segment_residuals_px(segments, vp.homogeneous))
        scale = max(1.4826 * float(np.median(r[inliers])), floor)
        new_inliers = r <= 3.0 * scale
        if np.array_equal(new_inliers, inliers):
            break
        inliers = new_inliers
    return np.asarray(r, dtype=np.float64), scale


def _screen_segments(
    scene: Scene,
    anns: list[Annotation],
    kept: list[int],
    excluded: list[dict[str, Any]],
    warnings: list[str],
    dropped: list[_DroppedSegment],
    sigma_line_rel: float,
) -> tuple[list[Annotation], list[int]]:
    """Leave out segments that disagree grossly with everybody's vanishing point of their axis.

    Per axis, the consensus vanishing point of all annotators' segments pooled, each
    weighted by its information (:func:`_consensus_residuals`), is the reference; a segment
    farther from it than ``max(8 × the robust scale, 1 % of the image diagonal)``, or
    pointing more than 30° away from it and farther than 3 × the robust scale, is a slip (an
    end dragged away, a line drawn for another axis) and is dropped with a warning (and
    recorded in ``dropped``: :func:`calibrate` re-admits it if it agrees with the final
    fit). An annotator (of three or more) most of whose segments of an axis are such slips
    drew that axis wrong and is left out.
    """
    w, h = scene.image_size
    diag = math.hypot(w, h)
    gross: dict[tuple[int, str], npt.NDArray[np.bool_]] = {}
    for axis in AXES:
        segs = [np.asarray(getattr(a.vp_lines, axis), float).reshape(-1, 4) for a in anns]
        pooled = np.vstack(segs) if segs else np.zeros((0, 4))
        if len(pooled) < 5:  # too few to tell a slip from the others' noise
            continue
        found = _consensus_residuals(pooled, diag, sigma_line_rel * diag)
        if found is None:
            continue
        r, scale = found
        half = 0.5 * np.hypot(pooled[:, 2] - pooled[:, 0], pooled[:, 3] - pooled[:, 1])
        angle = np.degrees(np.arcsin(np.clip(r / np.maximum(half, 1e-9), 0.0, 1.0)))
        bad = (r > max(8.0 * scale, 0.01 * diag)) | ((angle > 30.0) & (r > 3.0 * scale))
        start = 0
        for slot, sg in enumerate(segs):
            gross[(slot, axis)] = bad[start : start + len(sg)]
            start += len(sg)
    out_anns: list[Annotation] = []
    out_kept: list[int] = []
    for slot, (ann, i) in enumerate(zip(anns, kept, strict=True)):
        reason = None
        lines: dict[str, list[Any]] = {}
        for axis in AXES:
            flags = gross.get((slot, axis))
            segs_list = list(getattr(ann.vp_lines, axis))
            if flags is None or not flags.any():
                lines[axis] = segs_list
                continue
            n_bad = int(flags.sum())
            if len(anns) >= 3 and n_bad >= 2 and n_bad * 2 > len(segs_list):
                reason = (
                    f"vp_lines.{axis}: {n_bad} of {len(segs_list)} segments disagree with "
                    "everybody else's (drawn for another axis?)"
                )
                break
            for j in np.flatnonzero(flags):
                text = (
                    f"annotations[{i}].vp_lines.{axis}[{j}] ({ann.annotator}): far from "
                    "everybody's vanishing point of that axis; left out"
                )
                warnings.append(text)
                dropped.append(_DroppedSegment(i, axis, int(j), tuple(segs_list[j]), text))
            lines[axis] = [sg for sg, f in zip(segs_list, flags, strict=True) if not f]
        if reason is not None:
            excluded.append(
                {"annotator": ann.annotator, "index": i, "reason": reason, "geometry": True}
            )
            warnings.append(f"annotator {ann.annotator!r} (annotations[{i}]) left out: {reason}")
            continue
        if lines != {axis: list(getattr(ann.vp_lines, axis)) for axis in AXES}:
            ann = ann.model_copy(update={"vp_lines": ann.vp_lines.model_copy(update=lines)})
        out_anns.append(ann)
        out_kept.append(i)
    return out_anns, out_kept


def implausibility(result: CalibrationResult, image_size: tuple[int, int]) -> str | None:
    """Why a calibration is physically impossible, or None when it is plausible.

    Checks the camera height (:data:`PLAUSIBLE_HEIGHT_M`), its horizontal distance from the
    car (:data:`PLAUSIBLE_DISTANCE_M`), the focal length (:data:`PLAUSIBLE_FOCAL_DIAG`) and
    that the principal point lies in the image.
    """
    cam = result.camera
    w, h = image_size
    diag = math.hypot(w, h)
    c = cam.center_in_world
    if not np.all(np.isfinite(c)) or not math.isfinite(cam.focal_px):
        return "the camera is not finite"
    z = float(c[2])
    if z < 0:
        return f"the camera is {-z:.1f} m below the ground"
    if z < PLAUSIBLE_HEIGHT_M[0]:
        return f"the camera is {z:.2f} m above the ground, lower than any mount"
    if z > PLAUSIBLE_HEIGHT_M[1]:
        top = PLAUSIBLE_HEIGHT_M[1]
        return f"the camera is {z:.0f} m above the ground (plausible up to {top:g} m)"
    dist = float(np.hypot(c[0], c[1]))
    if dist > PLAUSIBLE_DISTANCE_M:
        return (
            f"the camera is {dist / 1000:.1f} km from the car "
            f"(plausible up to {PLAUSIBLE_DISTANCE_M:g} m)"
        )
    lo, hi = PLAUSIBLE_FOCAL_DIAG
    if not lo * diag <= cam.focal_px <= hi * diag:
        return (
            f"the focal length {cam.focal_px:.0f} px is implausible "
            f"(plausible {lo * diag:.0f}-{hi * diag:.0f} px)"
        )
    px, py = cam.principal_point
    if not (0 <= px <= w and 0 <= py <= h):
        return f"the principal point [{px:.0f}, {py:.0f}] is outside the {w}x{h} image"
    return None


def _remap(
    result: CalibrationResult,
    kept: list[int],
    n_total: int,
    excluded: list[dict[str, Any]],
    names: list[str],
) -> CalibrationResult:
    """Express a result fitted on the kept annotators in the scene's own indices."""

    def fix(text: str) -> str:
        return re.sub(
            r"annotations\[(\d+)\]", lambda m: f"annotations[{kept[int(m.group(1))]}]", text
        )

    for sol in result.annotators:
        if 0 <= sol.index < len(kept):
            sol.index = kept[sol.index]
        if sol.error:
            sol.error = fix(sol.error)
    for member in result.cluster.get("members", []):
        if isinstance(member.get("annotator"), int) and 0 <= member["annotator"] < len(kept):
            member["annotator"] = kept[member["annotator"]]
    result.warnings = [fix(wn) for wn in result.warnings]
    weights = [0.0] * n_total
    for k, wgt in zip(kept, result.annotator_weights, strict=False):
        weights[k] = wgt
    result.annotator_weights = weights
    if result.annotator_influence_m:
        influence: list[float | None] = [None] * n_total
        for k, inf in zip(kept, result.annotator_influence_m, strict=False):
            influence[k] = inf
        result.annotator_influence_m = influence
    if result.annotator_corners:
        corners = ["excluded"] * n_total
        for k, c in zip(kept, result.annotator_corners, strict=False):
            corners[k] = c
        result.annotator_corners = corners
    by_index = {s.index: s for s in result.annotators}
    for ex in excluded:
        i = ex["index"]
        if i not in by_index:
            by_index[i] = AnnotatorSolution(i, names[i], {}, error=f"left out: {ex['reason']}")
    result.annotators = [by_index[i] for i in sorted(by_index) if i >= 0] + [
        s for s in result.annotators if s.index < 0
    ]
    return result


PHOTO_FOCAL_MIN_CONFIDENCE = 0.5  # autovp's confidence needed to take the photo's focal length


def calibrate(scene: Scene, settings: CalibrationSettings | None = None) -> CalibrationResult:
    """Camera intrinsics, orientation and position relative to the annotated object.

    Where the annotations cannot fix the focal length (no ``camera.focal_px`` and fewer than
    two finite, consistent vanishing points) and the scene carries its photo
    (``image.path``, ``CalibrationSettings.photo_lines`` on), the focal length comes from
    the photo's own vanishing points (:mod:`camloc_geo.autovp`) when they are trustworthy
    (:func:`_photo_focal`): ``intrinsics_method`` is then ``"photo_focal"``, a warning says
    so, ``focal_sigma_px`` is the photo's, and the position and rotation sigmas include its
    effect (the answer's move under a one-sigma change of the focal length). Otherwise the
    refusal stands. See :func:`_calibrate_annotations` for the rest.
    """
    settings = settings or CalibrationSettings()
    try:
        return _calibrate_annotations(scene, settings)
    except DegenerateGeometryError as exc:
        if (
            scene.camera.focal_px is not None
            or not settings.photo_lines
            or "give camera.focal_px" not in str(exc)
        ):
            raise
        photo = _photo_focal(scene)
        if photo is None:
            raise
        focal_px, std_rel = photo
        refusal = str(exc)
        try:
            result = _calibrate_annotations(_with_focal(scene, focal_px), settings)
            moved = _calibrate_annotations(
                _with_focal(scene, focal_px * math.exp(std_rel)), settings, quiet=True
            )
        except InputError:
            raise exc from None
    sigma_f = focal_px * std_rel
    result.focal_sigma_px = sigma_f
    dC = np.abs(moved.camera.center_in_world - result.camera.center_in_world)
    for name in ("position_sigma_m", "position_sigma_fit_m"):
        value = getattr(result, name)
        if value is not None:
            setattr(result, name, np.hypot(value, dC))
    dR = moved.camera.cam_from_world_rotation @ result.camera.cam_from_world_rotation.T
    d_angle = np.abs(
        np.degrees(np.array([dR[2, 1] - dR[1, 2], dR[0, 2] - dR[2, 0], dR[1, 0] - dR[0, 1]]) / 2.0)
    )
    for name in ("rotation_sigma_deg", "rotation_sigma_fit_deg"):
        value = getattr(result, name)
        if value is not None:
            setattr(result, name, np.hypot(value, d_angle))
    result.intrinsics_method = "photo_focal"
    result.intrinsics_reason = (
        f"the annotations could not fix the focal length ({refusal}); it comes from the photo's "
        f"vanishing points: {focal_px:.1f} +/- {sigma_f:.1f} px"
    )
    msg = (
        "the annotations could not fix the focal length; it came from the photo's vanishing "
        f"points (image.path): {focal_px:.0f} +/- {sigma_f:.0f} px "
        f"({100.0 * std_rel:.1f} %); give camera.focal_px if it is known"
    )
    log.warning("%s", msg)
    result.warnings.append(msg)
    return result


def _with_focal(scene: Scene, focal_px: float) -> Scene:
    """``scene`` with ``camera.focal_px`` set."""
    return scene.model_copy(
        update={"camera": scene.camera.model_copy(update={"focal_px": float(focal_px)})}
    )


def _photo_focal(scene: Scene) -> tuple[float, float] | None:
    """The photo's focal length and its relative sigma, when autovp's answer is trustworthy.

    Trustworthy: the photo's size is the scene's, autovp estimated it (or read it from EXIF;
    not its default or a bound), ``confidence`` at least ``PHOTO_FOCAL_MIN_CONFIDENCE``, a
    finite positive sigma, and no warning about the focal length. Otherwise None.
    """
    res = _photo_result(scene)
    if res is None or tuple(res.image_size) != tuple(scene.image_size):
        return None
    f, sd = float(res.focal_px), float(res.focal_std_rel)
    loose = any("focal length" in w for w in res.warnings)
    if (
        res.focal_source in ("prior", "bound", "given")
        or loose
        or float(res.confidence) < PHOTO_FOCAL_MIN_CONFIDENCE
        or not (math.isfinite(f) and f > 0.0 and math.isfinite(sd) and sd > 0.0)
    ):
        log.info(
            "image.path: the photo's focal length is not trustworthy (%s, confidence %.2f)",
            res.focal_source,
            float(res.confidence),
        )
        return None
    return f, sd


def _calibrate_annotations(
    scene: Scene, settings: CalibrationSettings, *, quiet: bool = False
) -> CalibrationResult:
    """:func:`calibrate` from the annotations (and the photo's agreeing lines) alone.

    Crowd input degrades gracefully: clicks just outside the image are clamped (counted in
    ``clamped_clicks``), annotators whose work is unusable are left out with a warning
    (``excluded_annotators``), and a physically impossible result (see
    :func:`implausibility`) is never returned: the fit is repeated without each annotator in
    turn and the best plausible one kept, naming the annotator left out.

    Parameters
    ----------
    scene
        A validated scene with at least one annotation.
    settings
        Tuning; defaults documented in :class:`CalibrationSettings`.
    quiet
        Log no warnings (they are still in the result): a sensitivity refit.

    Returns
    -------
    CalibrationResult

    Raises
    ------
    SceneError
        No annotations, no usable annotator left, or an axis without enough segments.
    DegenerateGeometryError
        When no annotator's work determines a camera (the first annotator's problem is named),
        or no plausible camera is found (the reason is named).
    """
    if not scene.annotations:
        raise SceneError("at least one annotation is needed to calibrate", "annotations")
    names = [a.annotator for a in scene.annotations]
    screening = _screen_annotations(scene, settings.sigma_line_rel)
    if not screening.kept:
        raise _no_usable_annotator(screening.excluded)
    clean = screening.scene.undistorted()  # camera.distortion: pinhole pixels from here on
    excluded = list(screening.excluded)
    kept = list(screening.kept)
    try:
        result = _calibrate_usable(clean, settings)
        if screening.dropped and result.method == "joint_fit":
            result, clean = _readmit_agreeing(result, clean, screening, settings)
    finally:
        # After the re-admission (its withdrawn warnings are not logged); before any error.
        for msg in screening.warnings[len(scene.input_warnings) :]:
            if not quiet:
                log.warning("%s", msg)  # the scene's own were logged when it was read
    problem = implausibility(result, scene.image_size)
    if problem is not None:
        result, dropped = _leave_one_out(clean, settings, result, problem)
        slot_name = clean.annotations[dropped].annotator
        reason = f"without this annotator the result is plausible (with: {problem})"
        msg = f"annotator {slot_name!r} (annotations[{kept[dropped]}]) left out: {reason}"
        if not quiet:
            log.warning("%s", msg)
        excluded.append({"annotator": slot_name, "index": kept[dropped], "reason": reason})
        screening.warnings.append(msg)
        # The result was fitted without the dropped slot: its indices skip it.
        kept = [k for j, k in enumerate(kept) if j != dropped]
        clean = clean.model_copy(
            update={"annotations": [a for j, a in enumerate(clean.annotations) if j != dropped]}
        )
    jackknife = settings.joint_fit and settings.jackknife and 2 <= len(kept) <= _MAX_JACKKNIFE
    if jackknife and (
        settings.jackknife_method == "refit"
        or result.joint_state is None
        or not _jackknife_one_step(result, settings)  # no answer without someone: refit
    ):
        _jackknife(result, clean, settings)
    result = _remap(result, kept, len(scene.annotations), excluded, names)
    if jackknife:
        result.warnings += _pivotal_annotators(result, kept, names)
    result.excluded_annotators = sorted(excluded, key=lambda e: int(e["index"]))
    result.clamped_clicks = screening.clamped_clicks
    result.warnings = screening.warnings + result.warnings
    result.outlier_annotators = list(
        dict.fromkeys([*result.outlier_annotators, *(e["annotator"] for e in excluded)])
    )
    for msg in _photo_disagreement(scene, result):
        if not quiet:
            log.warning("%s", msg)
        result.warnings.append(msg)
    profile = _focal_profile_widening(result, settings.focal_profile_flat)
    if profile is not None:
        factor, msg = profile
        assert result.focal_sigma_px is not None
        result.focal_sigma_px *= factor
        if result.parameter_covariance is not None:
            cov = np.array(result.parameter_covariance, dtype=float)
            cov[0, :] *= factor
            cov[:, 0] *= factor
            result.parameter_covariance = cov
        if msg:
            if not quiet:
                log.warning("%s", msg)
            result.warnings.append(msg)
    widen = _photo_focal_widening(scene, result)
    if widen is not None:
        factor, msg = widen
        _widen_sigmas(result, factor)
        if not quiet:
            log.warning("%s", msg)
        result.warnings.append(msg)
    if settings.discordant_line_t > 0.0 and settings.discordant_line_move > 0.0:
        for msg in _widen_for_discordant_lines(result, clean, settings, kept):
            if not quiet:
                log.warning("%s", msg)
            result.warnings.append(msg)
    for msg in _widen_for_border_clicks(result, kept):
        if not quiet:
            log.warning("%s", msg)
        result.warnings.append(msg)
    return result


DISCORDANT_LINE_MAX = 2  # at most this many lines widened and named
# The segments' residual sigma is taken as at least this (line sigmas): a sub-pixel miss of
# noise-free lines (a pinned principal point's misfit) is no evidence of a line off its axis.
DISCORDANT_LINE_S_MIN = 0.2


def _discordant_lines(
    result: CalibrationResult, t_min: float, move_min: float
) -> list[tuple[int, float, FloatArray, float]]:
    """Annotators' segments that disagree with the other lines and carry the answer.

    Per segment row ``i`` of the final fit (robust normal matrix ``H``, soft-L1 row weights
    ``w``): its leverage ``h = w Jᵢ H⁻¹ Jᵢᵀ``, its studentized residual
    ``t = rᵢ / (s √(1 − h))`` with ``s²`` the segments' variance factor (their weighted
    squares over their redundancy, at least ``DISCORDANT_LINE_S_MIN²``), and, where
    ``|t| > t_min``, the fit's linear move without it, ``Δx = H⁻¹ Jᵢᵀ wᵢ rᵢ / (1 − h)``
    (Sherman-Morrison). Kept where that moves the focal length or the camera's height by
    more than ``move_min`` of the stated sigmas. Returns ``(row, t, Δx, z)`` (``z`` the
    larger of the two moves in stated sigmas), the largest ``z`` first, at most
    ``DISCORDANT_LINE_MAX``.

    Clean crowd scenes (crowd_slips ``none``, 4 seeds x 40): of the lines whose removal
    moves the answer by more than 2 stated sigmas, one has ``|t|`` above 3 (4.2); single
    long lines 5-15° off their axis that carry it reach 3-7. On the crowd set (4 seeds x
    60) 10 of 239 scenes have a line named (with ``move_min`` 1), a sloppy annotator's.
    """
    state = result.joint_state
    sigma_c = result.position_sigma_m
    if state is None or sigma_c is None:
        return []
    prob = state.problem
    n_seg = len(prob.segments)
    x = np.asarray(state.x, dtype=float)
    saved = prob.weights
    prob.weights = state.weights
    try:
        r, J = prob.residuals_and_jacobian(
            x, state.rotation0, state.principal_point, state.focal_px
        )
    finally:
        prob.weights = saved
    w = 1.0 / np.sqrt(1.0 + (r / _F_SCALE) ** 2)
    try:
        H_inv = _sym_inverse(J.T @ (J * w[:, None]))
    except np.linalg.LinAlgError:
        return []
    J_s, r_s, w_s = J[:n_seg], r[:n_seg], w[:n_seg]
    h = w_s * np.einsum("ij,jk,ik->i", J_s, H_inv, J_s)
    redundancy = float(n_seg - h.sum())
    if redundancy < _VARIANCE_GROUP_MIN_REDUNDANCY:
        return []
    s2 = max(float(np.sum(w_s * r_s**2)) / redundancy, DISCORDANT_LINE_S_MIN**2)
    free = np.clip(1.0 - h, 1e-9, None)
    t = r_s / np.sqrt(s2 * free)
    rows = np.flatnonzero(np.abs(t) > t_min)
    if len(rows) == 0:
        return []
    moves = H_inv @ (J_s[rows] * (w_s[rows] * r_s[rows] / free[rows])[:, None]).T
    dc_out = np.asarray(state.internal_from_output, dtype=float).T @ moves[-3:]
    z = np.abs(dc_out[2]) / max(float(sigma_c[2]), 1e-12)
    if state.focal_px is None and result.focal_sigma_px:
        z_f = np.abs(moves[0]) * result.camera.focal_px / result.focal_sigma_px
        z = np.maximum(z, z_f)
    keep = np.flatnonzero(z > move_min)
    order = keep[np.argsort(-z[keep])][:DISCORDANT_LINE_MAX]
    return [(int(rows[k]), float(t[rows[k]]), moves[:, k], float(z[k])) for k in order]


def _without_segment(scene: Scene, slot: int, axis: str, seg: FloatArray) -> Scene | None:
    """``scene`` without annotator ``slot``'s ``axis`` segment ``seg`` (None: not found)."""
    ann = scene.annotations[slot]
    lines = list(getattr(ann.vp_lines, axis))
    arr = np.asarray(lines, dtype=float).reshape(-1, 4)
    hit = np.flatnonzero(np.all(np.abs(arr - seg) <= 1e-6, axis=1))
    if len(hit) != 1:
        return None
    del lines[int(hit[0])]
    vp = ann.vp_lines.model_copy(update={axis: lines})
    anns = list(scene.annotations)
    anns[slot] = ann.model_copy(update={"vp_lines": vp})
    return scene.model_copy(update={"annotations": anns})


def _refit_move(
    result: CalibrationResult, scene: Scene, settings: CalibrationSettings, row: int
) -> FloatArray | None:
    """The answer's move (output parameters, as :func:`_widen_for_discordant_lines`) when
    the fit is repeated without segment ``row``; None where that gives no comparable camera
    (the line not found, no answer, another frame)."""
    state = result.joint_state
    assert state is not None
    prob = state.problem
    slot, axis = int(prob.seg_ann[row]), AXES[int(prob.seg_axis[row])]
    sub = _without_segment(scene, slot, axis, prob.segments[row])
    if sub is None:
        return None
    free_pp = result.intrinsics_method == "joint_fit_free_principal_point"
    sub_settings = replace(
        settings,
        jackknife=False,
        free_principal_point=(
            free_pp if settings.free_principal_point is None else settings.free_principal_point
        ),
    )
    try:
        res = _calibrate_usable(sub, sub_settings)
    except (InputError, np.linalg.LinAlgError):
        return None
    if res.width_sign != result.width_sign or implausibility(res, scene.image_size):
        return None
    turn = rotvec_from_rotation(
        res.camera.cam_from_world_rotation @ result.camera.cam_from_world_rotation.T
    )
    if np.linalg.norm(turn) >= math.radians(30.0):
        return None
    m = np.zeros(9)
    m[0] = res.camera.focal_px - result.camera.focal_px
    m[1:3] = np.subtract(res.camera.principal_point, result.camera.principal_point)
    m[3:6] = turn
    m[6:9] = res.camera.center_in_world - result.camera.center_in_world
    return m


def _add_move_to_sigmas(result: CalibrationResult, m: FloatArray, free_pp: bool) -> None:
    """Widen a result's covariance and sigmas by one move of the answer it cannot rule out.

    ``m`` is the move in ``parameter_covariance``'s order (focal length in pixels, principal
    point in pixels, rotation vector in radians, camera centre in metres): ``m mᵀ`` joins the
    covariance and each stated sigma grows by its component in quadrature (the principal
    point's only where it was fitted, ``free_pp``). A discordant line's move
    (:func:`_widen_for_discordant_lines`) and border clicks' (:func:`_widen_for_border_clicks`).
    """
    if result.parameter_covariance is not None:
        result.parameter_covariance = np.asarray(
            result.parameter_covariance, dtype=float
        ) + np.outer(m, m)
    if result.focal_sigma_px is not None:
        result.focal_sigma_px = math.hypot(result.focal_sigma_px, m[0])
    if result.principal_point_sigma_px is not None and free_pp:
        result.principal_point_sigma_px = [
            math.hypot(float(sd), float(d))
            for sd, d in zip(result.principal_point_sigma_px, m[1:3], strict=True)
        ]
    if result.rotation_sigma_deg is not None:
        result.rotation_sigma_deg = np.hypot(result.rotation_sigma_deg, np.degrees(m[3:6]))
    if result.position_sigma_m is not None:
        result.position_sigma_m = np.hypot(result.position_sigma_m, m[6:9])


def _widen_for_discordant_lines(
    result: CalibrationResult, scene: Scene, settings: CalibrationSettings, kept: list[int]
) -> list[str]:
    """Widen the stated sigmas by each :func:`_discordant_lines` move; their warnings.

    Each flagged line's move is then measured by a refit without it (rare: one scene in
    240 clean crowd scenes is flagged), which replaces the linear move (it may be far
    beyond the linearisation: a loose focal length moved +86 % by the linear formula); a
    refit that moves neither the focal length nor the height by ``discordant_line_move``
    stated sigmas clears the line. Where the refit gives no comparable camera, the linear
    move stands. ``m mᵀ`` is added to ``parameter_covariance`` (focal length in pixels,
    principal point, rotation on the left, centre in the output frame) and the sigmas grow
    to match. ``scene`` is the one fitted (the kept annotators); ``kept`` maps its
    annotations to the user's scene's (the warnings name those).
    """
    t_min, move_min = settings.discordant_line_t, settings.discordant_line_move
    found = _discordant_lines(result, t_min, move_min)
    state = result.joint_state
    if not found or state is None:
        return []
    prob = state.problem
    x = np.asarray(state.x, dtype=float)
    f = result.camera.focal_px
    M = np.asarray(state.internal_from_output, dtype=float)
    n_f = int(state.focal_px is None)
    free_pp = state.principal_point is None
    sigma_f0, sigma_c0 = result.focal_sigma_px, result.position_sigma_m
    out = []
    for row, t, dx, z in found:
        m = np.zeros(9)
        if n_f:
            m[0] = f * dx[0]
        if free_pp:
            m[1:3] = dx[n_f : n_f + 2]
        m[3:6] = _so3_left_jacobian(x[-6:-3]) @ dx[-6:-3]
        m[6:9] = M.T @ dx[-3:]
        refit = _refit_move(result, scene, settings, row)
        if refit is not None:
            m = refit
            assert sigma_c0 is not None
            z = abs(m[8]) / max(float(sigma_c0[2]), 1e-12)
            if n_f and sigma_f0:
                z = max(z, abs(m[0]) / sigma_f0)
            if z <= move_min:
                continue
        _add_move_to_sigmas(result, m, free_pp)
        slot, axis = int(prob.seg_ann[row]), AXES[int(prob.seg_axis[row])]
        seg = ", ".join(str(round(float(v))) for v in prob.segments[row])
        focal = f" the focal length {100.0 * m[0] / f:+.0f} %," if n_f else ""
        out.append(
            f"annotator {scene.annotations[slot].annotator!r} (annotations[{kept[slot]}]): "
            f"the vp_lines.{axis} segment [{seg}] carries the answer and disagrees with the other "
            f"lines beyond their noise ({abs(t):.1f} sigmas, its own weight taken out): "
            f"without it{focal} the camera height {m[8]:+.2f} m ({z:.1f} sigmas); the sigmas "
            f"include that move. Is it parallel to the car's {axis} (not a kerb's curve, a "
            "roof's slope, a line at an angle)?"
        )
    return out


# A click within this many pixels of the image's edge is taken as on it (clamped, or an
# edge's end out of the frame clicked where the edge leaves it).
BORDER_CLICK_PX = 1.0
# A fit without the border clicks that moves the focal length or the height by more than
# this many stated sigmas widens the sigmas by that move and is warned.
BORDER_CLICK_MOVE = 1.0
_BORDER_CLICK_FREE = 1e6  # a border click's sigma in the refit, in its own sigmas


def _border_clicks(prob: _JointProblem) -> npt.NDArray[np.bool_]:
    """Which edge-end clicks (``prob.pt_pix``, not the ground corners) lie on the image's edge."""
    w, h = prob.image_wh
    u, v = prob.pt_pix[:, 0], prob.pt_pix[:, 1]
    on_edge = (
        (u <= BORDER_CLICK_PX)
        | (u >= w - BORDER_CLICK_PX)
        | (v <= BORDER_CLICK_PX)
        | (v >= h - BORDER_CLICK_PX)
    )
    end = np.arange(len(u)) % 4 != 0  # each annotator's origin, length, width, height
    return np.asarray(on_edge & end, dtype=bool)


def _widen_for_border_clicks(result: CalibrationResult, kept: list[int]) -> list[str]:
    """Widen the sigmas where edge ends clicked on the image's edge carry the answer.

    An edge whose far end lies outside the photo can only be clicked where it leaves the
    frame (or is clamped there when clicked outside): its length in pixels is then cut
    short, and with the car's size the fit reads that as a longer distance or another focal
    length. The joint fit cannot tell: every annotator clicks the same border point, so
    neither the residuals nor the jackknife show it (``benchmarks/calibrate_coverage.py``,
    seed 20261125, scene 13: a noise-free scene's width end on the right edge, the focal
    length 24 % short at a stated 4.4 %, 7.0 sigmas).

    The fit is repeated from the answer with those clicks set free (their sigma
    ``_BORDER_CLICK_FREE`` times theirs: the rest of the evidence decides). Where that moves
    the focal length or the camera's height by more than ``BORDER_CLICK_MOVE`` stated sigmas,
    the move ``m`` enters ``parameter_covariance`` as ``m mᵀ`` and the sigmas grow to match
    (as a discordant line's, :func:`_widen_for_discordant_lines`); the answer does not move.
    The warning names the clicks (``kept`` maps the fitted annotations to the user's scene's).
    Returns the warnings.
    """
    state = result.joint_state
    if state is None or result.position_sigma_m is None:
        return []
    prob = state.problem
    border = _border_clicks(prob)
    if not border.any():
        return []
    free = copy.copy(prob)  # the answer's problem stays as it is (absolute refits use it)
    sigma_each = np.array(prob._sigma_pt_each, dtype=float)
    sigma_each[border] *= _BORDER_CLICK_FREE
    free._sigma_pt_each = sigma_each
    free._memo = {}
    free._jtj_inverse = None
    free._ground_corner_steps = None
    free._ground_corner_edge_sq = None
    free._set_weights(np.asarray(state.weights, dtype=float))
    x = np.asarray(state.x, dtype=float)
    try:
        res = _fit(free, x.copy(), state.rotation0, state.principal_point, state.focal_px)
        f_b, pp_b, R_b, C_b = free.unpack(
            np.asarray(res.x, dtype=float), state.rotation0, state.principal_point, state.focal_px
        )
    except (np.linalg.LinAlgError, ValueError):
        return []
    M = np.asarray(state.internal_from_output, dtype=float)
    origin = np.asarray(state.internal_origin, dtype=float)
    c_b = M.T @ (np.asarray(C_b, dtype=float) - origin)
    turn = rotvec_from_rotation(
        (np.asarray(R_b, dtype=float) @ M) @ result.camera.cam_from_world_rotation.T
    )
    if not np.all(np.isfinite(c_b)) or _vector_norm(turn) >= math.radians(30.0):
        return []  # another frame: no comparable camera
    m = np.zeros(9)
    m[0] = float(f_b) - result.camera.focal_px
    m[1:3] = np.subtract(pp_b, result.camera.principal_point)
    m[3:6] = turn
    m[6:9] = c_b - result.camera.center_in_world
    sigma_c = result.position_sigma_m
    z = abs(m[8]) / max(float(sigma_c[2]), 1e-12)
    if state.focal_px is None and result.focal_sigma_px:
        z = max(z, abs(m[0]) / result.focal_sigma_px)
    if z <= BORDER_CLICK_MOVE:
        return []
    _add_move_to_sigmas(result, m, state.principal_point is None)
    names = ("origin", "length", "width", "height")
    where = sorted(
        {
            f"annotations[{kept[int(prob.pt_ann[k])]}].axes.{names[k % 4]}"
            for k in np.flatnonzero(border)
        }
    )
    shown = ", ".join(where[:4]) + (f" and {len(where) - 4} more" if len(where) > 4 else "")
    focal = (
        f" the focal length {100.0 * m[0] / result.camera.focal_px:+.0f} %,"
        if state.focal_px is None
        else ""
    )
    return [
        f"edge ends clicked on the image's edge ({shown}): the edge probably runs out of the "
        f"photo, so its length in pixels is cut short; without those clicks{focal} the "
        f"camera height {m[8]:+.2f} m ({z:.1f} sigmas); the sigmas include that move. Click "
        "an edge's end only where the car's corner is in the photo, or give camera.focal_px"
    ]


PHOTO_AXIS_TOL_DEG = 4.0  # a photo's direction this far from the fit's axis disagrees
PHOTO_AXIS_NEAR_DEG = 30.0  # ... when it is the photo's nearest direction to that axis
PHOTO_MIN_SEGMENTS = 6  # a detected direction needs this many segments to count


PHOTO_SEGMENT_TOL = 2.0  # a photo segment within this many line sigmas of an axis' VP agrees
PHOTO_SEGMENT_SIGMA = 2.0  # ... and joins the fit at this many line sigmas
PHOTO_SEGMENT_MIN_REL = 0.02  # ... if at least this long (fraction of the image diagonal)


def _photo_result(scene: Scene) -> Any | None:
    """The scene photo's detected vanishing points and segments (cached), or None."""
    path = line_photo(scene)  # not a scaled copy: its pixels are the annotations'
    if path is None or not path.is_file():  # is_file: a FIFO or a device would block
        return None
    try:
        return _detect_scene_vps(scene, path)
    except (InputError, ValueError) as exc:
        log.info("image.path: no vanishing points detected in %s: %s", path, exc)
        return None


def _add_photo_segments(
    scene: Scene,
    prob: _JointProblem,
    x: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float] | None,
    f_fixed: float | None,
) -> dict[str, int]:
    """Give ``prob`` the photo's segments that agree with the fit at ``x``; count per axis.

    A segment detected in the photo (:mod:`camloc_geo.autovp`, at least
    ``PHOTO_SEGMENT_MIN_REL`` of the diagonal long) agrees with an axis when its residual
    to that axis' vanishing point of the fit is within ``PHOTO_SEGMENT_TOL`` line sigmas
    (``sigma_line_rel``) and its residuals to the other two are beyond three times that.
    Each joins at ``PHOTO_SEGMENT_SIGMA`` line sigmas, widened where an axis has more of
    them than the annotators drew on average for it (their total weight then equals that
    many such segments): a small weight, under the fit's soft-L1 loss. Lines that disagree
    with the fit are never added (a clear disagreement is :func:`_photo_disagreement`'s
    warning). With a lens distortion (``camera.distortion``) the detector fits the pinhole
    camera's vanishing points and its segments are undistorted as the annotations are.
    Nothing without a photo or when the photo's size is not the scene's.
    """
    res = _photo_result(scene)
    if res is None or tuple(res.image_size) != tuple(scene.image_size):
        return {}
    segs = np.asarray(res.segments, dtype=float).reshape(-1, 4)
    labels = np.asarray(res.labels, dtype=int).reshape(-1)
    if len(segs) != len(labels):
        return {}
    segs = _photo_segments_px(scene, segs)  # camera.distortion: the annotations' pixels
    finite = np.all(np.isfinite(segs), axis=1)
    segs, labels = segs[finite], labels[finite]
    diag = math.hypot(*prob.image_wh)
    long_enough = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
    keep = (long_enough >= PHOTO_SEGMENT_MIN_REL * diag) & (labels >= 0)
    segs, labels = segs[keep], labels[keep]
    if len(segs) == 0:
        return {}
    f, pp, R, _C = prob.unpack(x, R0, pp_fixed, f_fixed)
    all_labels = np.asarray(res.labels, dtype=int).reshape(-1)  # as the warning counts them
    support = np.bincount(all_labels[all_labels >= 0], minlength=len(res.vanishing_points))
    K_inv = np.linalg.inv(np.array([[f, 0.0, pp[0]], [0.0, f, pp[1]], [0.0, 0.0, 1.0]]))
    off = [i for i, _deg in _photo_disagreeing_axes(res.vanishing_points, support, K_inv, R)]
    if off:
        # Two witnesses that clearly disagree on one axis (one of them is off, and which is
        # not known) do not make each other surer on the others: the photo lends nothing.
        log.info(
            "image.path: the photo's %s direction disagrees with the annotators' fit; its "
            "segments are not used",
            "/".join(AXES[i] for i in off),
        )
        return {}
    # Each of the photo's vanishing points (its own clustering: no choice by the fit) that
    # is within PHOTO_AXIS_TOL_DEG of one of the fit's axes, and the nearest to it, lends
    # that axis its segments.
    cluster_axis = {}
    for k, vp in enumerate(np.asarray(res.vanishing_points, dtype=float)):
        if np.count_nonzero(labels == k) < PHOTO_MIN_SEGMENTS:
            continue
        i = _photo_direction_axis(vp, f, pp, R)
        if i is not None:
            cluster_axis[k] = i
    if len(set(cluster_axis.values())) < len(cluster_axis):
        return {}  # two of the photo's directions on one axis: ambiguous
    take = np.isin(labels, list(cluster_axis))
    if not np.any(take):
        return {}
    segs = segs[take]
    axis = np.array([cluster_axis[int(k)] for k in labels[take]], dtype=int)
    sigma = np.full(len(segs), PHOTO_SEGMENT_SIGMA * prob.sigma_line)
    used: dict[str, int] = {}
    for name, i in _AXIS_INDEX.items():
        mine = axis == i
        k = int(mine.sum())
        if k == 0:
            continue
        per_annotator = max(float(np.sum(prob.seg_axis == i)) / prob.n_annotators, 2.0)
        if k > per_annotator:
            sigma[mine] *= math.sqrt(k / per_annotator)
        used[name] = k
    prob.set_photo_segments(segs, axis, sigma)
    vps = np.asarray(res.vanishing_points, dtype=float)
    prob.photo_axis_vp = {i: vps[k] for k, i in cluster_axis.items()}
    log.info("image.path: %s photo segments agree with the annotators' fit", used)
    return used


VIDEO_SEGMENT_SIGMA = 1.0  # a video segment joins the fit at this many line sigmas
VIDEO_GROUP_CAP = 3.0  # ... a group at most this many annotators' lines of its axis
VIDEO_AGREE = 3.0  # a group agrees: its median residual to the fit's point, line sigmas
VIDEO_MIN_SEGMENTS = 12  # a group needs this many segments to count


VIDEO_INFORMATION_GROUPS = ("street",)  # groups capped by information, not by count
VIDEO_INFO_FLOOR_REL = 0.05  # an annotator's lines of an axis count as at least 2 this long


def _line_information(segments: FloatArray, sigma_px: npt.ArrayLike) -> float:
    """Sum of ``(L / sigma)²`` over segments: what they tell about their vanishing point.

    A segment of length ``L`` whose ends are off by ``sigma`` fixes its direction to about
    ``2 sigma / L`` radians, so its information on the direction (and on a vanishing point
    far along it) grows as ``(L / sigma)²``: one 560 px road line says as much as a hundred
    56 px car edges of the same endpoint noise.
    """
    segs = np.asarray(segments, dtype=float).reshape(-1, 4)
    length_sq = (segs[:, 2] - segs[:, 0]) ** 2 + (segs[:, 3] - segs[:, 1]) ** 2
    return float(np.sum(length_sq / np.asarray(sigma_px, dtype=float) ** 2))


def _video_group_widening(
    prob: _JointProblem, segs: FloatArray, sigma_px: FloatArray, axis: int, information: bool
) -> float:
    """Variance factor (>= 1) that holds a video group to ``VIDEO_GROUP_CAP`` annotators.

    Since session 38 the street group is held to ``VIDEO_DIRECTION_FLOOR_DEG`` instead
    (:func:`_video_direction_floor`); a group named in ``VIDEO_INFORMATION_GROUPS`` and not
    there would be capped by information.

    ``information`` True (``VIDEO_INFORMATION_GROUPS``): the group's total
    information at its sigmas (:func:`_line_information`) is at most ``VIDEO_GROUP_CAP``
    times the annotators' average on that axis (each annotator's lines at the line sigma, at
    least two lines of ``VIDEO_INFO_FLOOR_REL`` of the image diagonal). False (the edge
    groups): the group counts at most as ``VIDEO_GROUP_CAP`` times the annotators' average
    number of lines of that axis (at least 2), whatever their lengths.

    Why the two (session 37, development seeds 0-11, 102, 103): the street group is the
    vehicles' KLT tracks, 60-90 px long (median) and straight to 0.7 px, and its vanishing
    point is within 0.1-0.4° of the truth on every seed; counted as 9-12 segments it was a
    hundredth of its information, and seed 102's focal length stayed 3.7 % off. The edge
    groups are the moving foreground's LSD edges, 16-26 px long, and their points are
    2-5° (across) and 0.4-24° (vertical) off the truth: given their information they
    pulled the camera's height 5-7 % off on seeds 0 and 4 (their short edges of two-box
    cars are not the body's axes), so they keep the count cap.
    """
    if information:
        mine = prob.segments[prob.seg_axis == axis]
        per_annotator = _line_information(mine, prob.sigma_line) / max(prob.n_annotators, 1)
        floor_px = VIDEO_INFO_FLOOR_REL * math.hypot(*prob.image_wh)
        per_annotator = max(per_annotator, 2.0 * (floor_px / prob.sigma_line) ** 2)
        have, cap = _line_information(segs, sigma_px), VIDEO_GROUP_CAP * per_annotator
    else:
        per_annotator = float(np.sum(prob.seg_axis == axis)) / max(prob.n_annotators, 1)
        have, cap = float(len(segs)), VIDEO_GROUP_CAP * max(per_annotator, 2.0)
    return max(have / cap, 1.0) if cap > 0.0 else 1.0


# Groups held to the accuracy of their vanishing direction instead of a cap on what they
# say relative to the annotators: no direction of the group's point is taken as known better
# than this many degrees (:func:`_video_direction_floor`). Groups not named here keep the cap
# (:func:`_video_group_widening`). The street group's tracks: session 38, below.
VIDEO_DIRECTION_FLOOR_DEG: dict[str, float] = {"street": 0.05}


def _signed_segment_residual_px(segments: FloatArray, vp: FloatArray) -> FloatArray:
    """Signed distance (px) of each segment's first end from the line through its middle
    and the homogeneous point ``vp`` (its magnitude is
    :func:`camloc_geo.sensors._video_lines._residual_px`, the fit's segment residual)."""
    mid = np.column_stack([(segments[:, 0:2] + segments[:, 2:4]) / 2.0, np.ones(len(segments))])
    ln = np.cross(mid, np.broadcast_to(vp, mid.shape))
    norm = np.hypot(ln[:, 0], ln[:, 1])
    end = np.column_stack([segments[:, 0:2], np.ones(len(segments))])
    return np.asarray(np.sum(ln * end, axis=1) / np.where(norm > 1e-12, norm, np.inf))


def _group_direction_information(
    segs: FloatArray, sigma_px: FloatArray, K: FloatArray, axis_cam: FloatArray
) -> FloatArray | None:
    """The segments' information (``2 x 2``, rad⁻²) on the direction they converge on.

    The direction is moved off ``axis_cam`` (a unit vector in the camera frame) in its
    tangent plane; three Gauss-Newton steps find where the segments meet, at ``sigma_px``
    and under the fit's soft-L1 weights, and the normal matrix there is returned. None where
    the steps fail.
    """
    t = np.array([1.0, 0.0, 0.0]) if abs(axis_cam[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(axis_cam, t)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis_cam, e1)
    step = 1e-6

    def resid(p: FloatArray) -> FloatArray:
        d = axis_cam + p[0] * e1 + p[1] * e2
        return _signed_segment_residual_px(segs, K @ d) / sigma_px

    p = np.zeros(2)
    H = np.zeros((2, 2))
    for _ in range(3):
        r = resid(p)
        J = np.column_stack([(resid(p + step * np.eye(2)[k]) - r) / step for k in range(2)])
        Jw = J / np.sqrt(1.0 + (r / _F_SCALE) ** 2)[:, None]
        H = Jw.T @ J
        try:
            p = p - np.linalg.solve(H + 1e-12 * float(np.trace(H)) * np.eye(2), Jw.T @ r)
        except np.linalg.LinAlgError:
            return None
    ok = np.all(np.isfinite(p)) and np.all(np.isfinite(H))
    return np.asarray(0.5 * (H + H.T)) if ok else None


def _video_direction_floor(
    segs: FloatArray, sigma_px: FloatArray, K: FloatArray, axis_cam: FloatArray, floor_deg: float
) -> float:
    """Variance factor (>= 1) that holds a video group's direction to ``floor_deg``.

    The group's information on its vanishing direction (:func:`_group_direction_information`)
    is scaled down until no direction of it is known better than ``floor_deg`` (its largest
    eigenvalue at most ``floor⁻²``): the group then says what its kind of witness is known to
    be accurate to, however many segments it has, and whatever the annotators drew.

    Why (session 38, development cameras 0-9 and 20-30 with 3 noise draws each, 63 scenes
    per set): the street group's tracks are the motion of rigid vehicles along the street,
    and their point is within 0.1-0.3° of the truth on every camera. Capped at 3 annotators'
    information on the length axis (session 37) they were held to 0.6-1.5° where the
    annotators drew the car alone (short length lines) and to about 0.05° where they drew
    the lane lines: the same witness weighed 10-30 times apart by what the others drew.
    Held to 0.05° instead: car only, focal sd 1.11 → 0.76 %, max 3.98 → 2.60 %, height sd
    2.12 → 1.39 %, max 6.04 → 3.97 %; with the lane lines unchanged (focal sd 0.79 → 0.77 %,
    height 1.39 → 1.37 %); 2σ coverage 95-98 % throughout. Floors of 0.03° did a little
    better still on these renders, 0.1° worse (the lane-line scenes' height sd 1.77 %);
    0.05° keeps a margin for real video (blur, rolling shutter, an unmodelled lens).
    1 where the group says less already, or the information cannot be found.
    """
    H = _group_direction_information(segs, sigma_px, K, axis_cam)
    if H is None:
        return 1.0
    top = float(np.max(np.linalg.eigvalsh(H)))
    factor = top * math.radians(floor_deg) ** 2
    return max(factor, 1.0) if np.isfinite(factor) else 1.0


def _add_video_segments(
    scene: Scene,
    video: Any,
    prob: _JointProblem,
    x: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float] | None,
    f_fixed: float | None,
) -> dict[str, int]:
    """Give ``prob`` the video's witness groups that agree with the fit at ``x``.

    ``video`` is a :class:`camloc_geo.sensors._video_lines.VideoLines`: segments of the moving
    vehicles (tracks along the street, edges across it and upright), grouped by their own
    vanishing points. A group serves the fit's axis nearest its point (within
    ``PHOTO_AXIS_NEAR_DEG``; two groups on one axis: neither), and joins where the median
    residual of its segments to that axis' vanishing point of the fit is within ``VIDEO_AGREE``
    line sigmas; otherwise a warning names the group, the axis and the residual
    (``prob.video_warnings``). Each segment joins at ``VIDEO_SEGMENT_SIGMA`` line sigmas,
    widened so that the street group (tracks) claims its direction to no better than
    ``VIDEO_DIRECTION_FLOOR_DEG`` (:func:`_video_direction_floor`), and an edge group
    counts at most as ``VIDEO_GROUP_CAP`` annotators' number of lines of its axis
    (:func:`_video_group_widening`). The video is one witness, however many frames it has:
    the jackknife leaves it out as one group.
    Returns the segments used per axis name. Nothing where the video's frame size is not the
    scene's, or the scene has a lens distortion (``camera.distortion``: the video's segments are
    the raw frames').
    """
    from camloc_geo.sensors._video_lines import GROUPS, _residual_px

    if tuple(video.image_size) != tuple(scene.image_size):
        prob.video_warnings.append(
            f"video: its frames are {video.image_size[0]}x{video.image_size[1]}, the scene's "
            f"image {scene.image_size[0]}x{scene.image_size[1]}; its lines are not used"
        )
        return {}
    if _scene_lens(scene)[0] is not None:
        log.info("video: the scene has a lens distortion; the video's lines are not used")
        return {}
    f, pp, R, _C = prob.unpack(x, R0, pp_fixed, f_fixed)
    K = np.array([[f, 0.0, pp[0]], [0.0, f, pp[1]], [0.0, 0.0, 1.0]])
    K_inv = np.linalg.inv(K)
    segs_all = np.asarray(video.segments, dtype=float).reshape(-1, 4)
    labels = np.asarray(video.labels, dtype=int).reshape(-1)
    group_axis: dict[int, int] = {}
    for k, vp in enumerate(np.asarray(video.vanishing_points, dtype=float)):
        if not np.all(np.isfinite(vp)) or np.count_nonzero(labels == k) < VIDEO_MIN_SEGMENTS:
            continue
        d = K_inv @ vp
        n = float(np.linalg.norm(d))
        if not (n > 0.0 and np.isfinite(n)):
            continue
        cosines = np.abs(R.T @ (d / n))
        i = int(np.argmax(cosines))
        angle = math.degrees(math.acos(min(1.0, float(cosines[i]))))
        if angle <= PHOTO_AXIS_NEAR_DEG:
            group_axis[k] = i
    taken = list(group_axis.values())
    used: dict[str, int] = {}
    segs_out: list[FloatArray] = []
    axes_out: list[FloatArray] = []
    sigma_out: list[FloatArray] = []
    axis_name = {i: name for name, i in _AXIS_INDEX.items()}
    for k, i in group_axis.items():
        if taken.count(i) > 1:
            continue  # two of the video's groups on one axis: ambiguous
        segs = segs_all[labels == k]
        resid = _residual_px(segs, K @ R[:, i])
        med = float(np.median(resid)) / prob.sigma_line
        if not med <= VIDEO_AGREE:
            prob.video_warnings.append(
                f"video: its {GROUPS[k]} lines ({len(segs)}) disagree with the annotators' "
                f"{axis_name[i]} axis (median residual {med:.1f} line sigmas); not used "
                f"(the annotators' {axis_name[i]} lines or the video's are off)"
            )
            continue
        sigma = np.full(len(segs), VIDEO_SEGMENT_SIGMA * prob.sigma_line)
        floor_deg = VIDEO_DIRECTION_FLOOR_DEG.get(GROUPS[k])
        if floor_deg is not None:
            factor = _video_direction_floor(segs, sigma, K, R[:, i], floor_deg)
        else:
            by_information = GROUPS[k] in VIDEO_INFORMATION_GROUPS
            factor = _video_group_widening(prob, segs, sigma, i, by_information)
        sigma *= math.sqrt(factor)
        segs_out.append(segs)
        axes_out.append(np.full(len(segs), i))
        sigma_out.append(sigma)
        used[axis_name[i]] = used.get(axis_name[i], 0) + len(segs)
    if not segs_out:
        return {}
    prob.add_video_segments(
        np.vstack(segs_out), np.concatenate(axes_out), np.concatenate(sigma_out)
    )
    log.info("video: %s segments agree with the annotators' fit", used)
    return used


def _photo_disagreement(scene: Scene, result: CalibrationResult) -> list[str]:
    """Warnings where the scene's photo and the annotators' fit clearly disagree.

    The photo's vanishing points (``autovp``, cached per file) are turned into directions
    with the fit's own intrinsics and compared, axis by axis, with the fit's world axes
    (length, width, up). A detected direction with at least ``PHOTO_MIN_SEGMENTS`` segments
    that is the nearest one to an axis, within ``PHOTO_AXIS_NEAR_DEG`` of it but more than
    ``PHOTO_AXIS_TOL_DEG`` off, is reported with the angle; so is an estimated photo focal
    length more than 10 % and three combined sigmas off the fit's. No photo, or no lines in
    it: nothing (``image.path``'s own warnings say so). With a lens distortion
    (``camera.distortion``) the photo's vanishing points are the pinhole camera's.
    """
    res = _photo_result(scene) if result.camera is not None else None
    if res is None:
        return []
    cam = result.camera
    R = np.asarray(cam.cam_from_world_rotation, dtype=float)
    K_inv = np.linalg.inv(np.asarray(cam.img_from_cam, dtype=float))
    support = np.bincount(np.asarray(res.labels)[np.asarray(res.labels) >= 0], minlength=3)
    out = [
        f"image.path: the photo's lines disagree with the annotators' fit: its "
        f"{AXES[i]} vanishing direction is {best:.1f} degrees from the fit's "
        f"(the annotators' lines or the photo's detected lines are off)"
        for i, best in _photo_disagreeing_axes(res.vanishing_points, support, K_inv, R)
    ]
    rel = _photo_focal_gap(res, result)
    if rel is not None:
        out.append(
            f"image.path: the photo's lines give a focal length of {float(res.focal_px):.0f} "
            f"px, {100.0 * (math.exp(rel) - 1.0):+.0f} % from the annotators' fit "
            f"({cam.focal_px:.0f} ± {result.focal_sigma_px:.0f} px)"
        )
    return out


def _photo_focal_gap(res: Any, result: CalibrationResult) -> float | None:
    """``log(f_photo / f)`` where the photo's own focal length estimate (``res``, autovp's)
    is more than 10 % and three combined sigmas from the annotators' fit; else None."""
    if res.focal_source != "estimated" or result.focal_sigma_px is None:
        return None
    f_fit = float(result.camera.focal_px)
    rel = math.log(float(res.focal_px) / f_fit)
    sd = math.hypot(float(res.focal_std_rel or 0.0), result.focal_sigma_px / f_fit)
    if abs(rel) > math.log(1.1) and abs(rel) > 3.0 * sd:
        return rel
    return None


def _photo_focal_widening(scene: Scene, result: CalibrationResult) -> tuple[float, str] | None:
    """How much to widen the stated sigmas where the photo's focal length disagrees.

    Where :func:`_photo_disagreement` reports the photo's focal length (``autovp``,
    estimated from the photo alone) more than 10 % and three combined sigmas from the
    annotators' fit, two independent witnesses disagree and the stated sigmas, which know
    only the clicks' scatter, cannot both be right. Measured on hand-annotated real cars
    (York Urban P1020822's Corolla, ``tests/test_real_car.py``): the car's rounded rear
    face reads nearly flat and both annotators clicked its far corner 7-9 px off, so the
    fit gave +37 % at a stated 4 %, while the photo gave +7 %; nothing in the clicks shows
    such a shared slip. The sigmas are then scaled (a variance inflation, all together, so
    the correlations of ``parameter_covariance`` are kept) until the photo's focal length
    lies within two of them: ``|log(f_photo / f)| / (2 σ_rel)``. The answer itself is not
    moved (which witness is wrong is not known); the warning says so.

    Returns
    -------
    (factor, warning) or None
        None where the photo agrees, is missing or has no estimate of its own.
    """
    if result.focal_sigma_px is None or result.focal_sigma_px <= 0.0:
        return None
    if result.intrinsics_method == "photo_focal":
        return None  # the focal length is the photo's own
    res = _photo_result(scene) if result.camera is not None else None
    if res is None:
        return None
    rel = _photo_focal_gap(res, result)
    if rel is None:
        return None
    f_fit = float(result.camera.focal_px)
    factor = abs(rel) / (2.0 * (result.focal_sigma_px / f_fit))
    if not factor > 1.0:
        return None
    return factor, (
        f"image.path: the photo and the annotators disagree on the focal length "
        f"({float(res.focal_px):.0f} against {f_fit:.0f} px); every stated sigma is "
        f"widened {factor:.1f}x so that both lie within two of them (one of the two is off: "
        "check the car's far corners and its shortest edges against the photo)"
    )


FOCAL_PROFILE_STEPS = 2.0
"""The profile check's focal lengths: this many stated sigmas either side (log scale)."""
FOCAL_PROFILE_MAX_WIDEN = 3.0
FOCAL_PROFILE_MIN_WIDEN = 1.1
"""A widening below this (10 %) is left out: the linearised sigma's own slack."""


FOCAL_PROFILE_STOP_GAIN = 4.0
""":func:`_held_focal_fit_drops` stops once its cost stands more than this many times the
Gauss-Newton step's predicted gain above the answer's (the full fits' last steps: 0.3
predicted, 0.3 gained; their first: 260 predicted, 950 gained)."""


def _held_focal_fit_drops(
    prob: _JointProblem,
    x0: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float] | None,
    f_held: float,
    target_cost: float,
    s2: float,
    *,
    max_nfev: int = 200,
) -> bool:
    """Whether the fit with the focal length held at ``f_held`` gets below ``target_cost``.

    :func:`_fit`'s steps (:func:`camloc_geo._optimize.soft_l1_least_squares_small`'s
    Levenberg-Marquardt, the same damping), from ``x0``, but only as far as the answer
    needs (its ``stop``): True as soon as a step's cost is below ``target_cost``; False
    once the cost stands above it by more than ``FOCAL_PROFILE_STOP_GAIN`` times the undamped
    Gauss-Newton step's predicted gain plus a hundredth of ``s2`` (the residual variance
    factor), or where the full fit would have stopped. A full fit ends below
    ``target_cost`` only through a step below it, so True matches it wherever the stop
    rule holds; the rule gives ~2 evaluations fewer a fit than the full one's 4-8.
    """
    from camloc_geo._optimize import soft_l1_least_squares_small

    def stop(cost: float, A: FloatArray, g: FloatArray) -> bool:
        if cost < target_cost:
            return True
        try:
            gain = 0.5 * float(g @ np.linalg.solve(A, g))  # the undamped step's prediction
        except np.linalg.LinAlgError:
            return False
        return bool(
            np.isfinite(gain)
            and cost - target_cost > FOCAL_PROFILE_STOP_GAIN * max(gain, 0.0) + 0.01 * s2
        )

    held = soft_l1_least_squares_small(
        lambda x: prob.residuals_and_jacobian(x, R0, pp_fixed, f_held),
        x0,
        f_scale=_F_SCALE,
        max_nfev=max_nfev,
        damping=1e-4,
        stop=stop,
    )
    return held.cost < target_cost


def _focal_profile_widening(
    result: CalibrationResult, widen_flat: bool = False
) -> tuple[float, str] | None:
    """Widen ``focal_sigma_px`` where the fit's cost is flatter than its sigma says.

    The stated focal sigma is a linearised one, symmetric in pixels; the focal length's
    likelihood is not (a low camera, a vanishing point near infinity: a longer focal length
    costs the fit less than a shorter one). The fit is repeated with the focal length held
    at ``exp(±FOCAL_PROFILE_STEPS σ)`` times the answer (σ the stated sigma, relative); the
    rise of its cost (``2·Δcost / s²``, ``s²`` the residual variance factor) should be at
    least ``FOCAL_PROFILE_STEPS²`` (4) if the stated sigma held on that side. Where it is
    less, the sigma of that side in log units is taken as ``FOCAL_PROFILE_STEPS / √rise``
    times the stated one, and the stated pixel sigma widened to that side's half-width
    ``f·|exp(±2σ') − 1| / 2`` (at most ``FOCAL_PROFILE_MAX_WIDEN`` times; less than
    ``FOCAL_PROFILE_MIN_WIDEN``: left as it is); where the held fit
    is *better* than the answer (the fit found a local minimum), the widening is the most
    and a warning says so. The flat sides' widening (no better fit, a rise below 4) only
    with ``widen_flat`` (``CalibrationSettings.focal_profile_flat``, default off). Only for the
    joint fit with a fitted focal length. Returns (factor, warning or "") or None.

    The answer's cost is its residuals (no re-fit). Without ``widen_flat`` only whether a
    held fit gets below it matters: :func:`_held_focal_fit_drops` stops each held fit as
    soon as that is decided, and only where one does get below are the full held fits run
    (the widening and the warning as before).
    """
    state = result.joint_state
    f = result.camera.focal_px
    if (
        state is None
        or state.focal_px is not None
        or result.focal_sigma_px is None
        or not 0.0 < result.focal_sigma_px < f
    ):
        return None
    prob = state.problem
    saved = prob.weights
    prob.weights = state.weights
    try:
        x = np.asarray(state.x, dtype=float)
        f0 = math.exp(float(x[0]))
        # The base cost at the answer itself: one (memoised) evaluation, no re-fit.
        fun0 = np.asarray(
            prob.residuals(x, state.rotation0, state.principal_point, None), dtype=float
        )
        cost0 = soft_l1_cost(fun0, _F_SCALE)
        s2 = max(2.0 * cost0 / max(len(fun0) - len(x), 1), 1e-12)
        sig_log = result.focal_sigma_px / f
        f_held = [f0 * math.exp(side * FOCAL_PROFILE_STEPS * sig_log) for side in (-1.0, 1.0)]
        prior_cost = [0.0, 0.0]
        if prob.log_f_prior_sigma > 0.0:  # the focal prior's row, as the free fit has it
            prior_cost = [
                soft_l1_cost(
                    np.array([(math.log(fh) - prob.log_f_prior) / prob.log_f_prior_sigma]),
                    _F_SCALE,
                )
                for fh in f_held
            ]
        if not widen_flat and not any(
            _held_focal_fit_drops(
                prob, x[1:], state.rotation0, state.principal_point, fh, cost0 - pc, s2
            )
            for fh, pc in zip(f_held, prior_cost, strict=True)
        ):
            return None  # neither held fit gets below the answer: no local minimum
        rises = []
        for fh, pc in zip(f_held, prior_cost, strict=True):
            held = _fit(prob, x[1:].copy(), state.rotation0, state.principal_point, fh)
            cost = soft_l1_cost(np.asarray(held.fun, dtype=float), _F_SCALE) + pc
            rises.append(2.0 * (cost - cost0) / s2)
    except (np.linalg.LinAlgError, ValueError):
        return None
    finally:
        prob.weights = saved
    rise = min(rises)
    want = FOCAL_PROFILE_STEPS**2
    if not math.isfinite(rise) or rise >= want:
        return None
    # Per side: the log-sigma that side's rise implies, as a half-width in pixels (the
    # longer side's exp(2σ) - 1 is wider than 2σ: the stated sigma is symmetric in pixels).
    factor = 1.0
    for side, r in zip((-1.0, 1.0), rises, strict=True):
        k = (
            FOCAL_PROFILE_MAX_WIDEN
            if r <= 0.0
            else min(max(FOCAL_PROFILE_STEPS / math.sqrt(r), 1.0), FOCAL_PROFILE_MAX_WIDEN)
        )
        half = abs(math.expm1(side * FOCAL_PROFILE_STEPS * sig_log * k)) / FOCAL_PROFILE_STEPS
        factor = max(factor, half / sig_log)
    factor = min(factor, FOCAL_PROFILE_MAX_WIDEN)
    if rise >= 0.0 and (not widen_flat or factor < FOCAL_PROFILE_MIN_WIDEN):
        return None  # no better fit elsewhere; flat sides only when asked
    msg = ""
    if rise < 0.0:
        longer = rises[1] < rises[0]
        f_alt = f * math.exp((1.0 if longer else -1.0) * FOCAL_PROFILE_STEPS * sig_log)
        msg = (
            f"the focal length is not well determined: a fit holding it at {f_alt:.0f} px "
            f"({'longer' if longer else 'shorter'} than the answer's {f:.0f} px) fits the "
            "annotations better; the focal sigma is widened "
            f"x{factor:.1f}; add lines along another direction (a kerb, a building edge)"
        )
    return factor, msg


def _widen_sigmas(result: CalibrationResult, factor: float) -> None:
    """Scale the stated sigmas (and ``parameter_covariance``) by ``factor``."""
    if result.focal_sigma_px is not None:
        result.focal_sigma_px *= factor
    if result.position_sigma_m is not None:
        result.position_sigma_m = np.asarray(result.position_sigma_m, dtype=float) * factor
    if result.rotation_sigma_deg is not None:
        result.rotation_sigma_deg = np.asarray(result.rotation_sigma_deg, dtype=float) * factor
    if result.parameter_covariance is not None:
        result.parameter_covariance = np.asarray(result.parameter_covariance) * factor**2


def _readmit_agreeing(
    result: CalibrationResult,
    clean: Scene,
    screening: _Screening,
    settings: CalibrationSettings,
) -> tuple[CalibrationResult, Scene]:
    """Give back the screened-out segments that agree with the joint fit, and refit.

    The screen judges a segment against a consensus of the lines alone; the joint fit also
    has the axis clicks and the other axes. A left-out segment whose residual to the fitted
    camera's vanishing point of its axis is within three times that axis' kept segments'
    robust residual scale (at least three times the line noise) agrees with the answer and
    is put back; its warning is withdrawn. The refit replaces the result only if it is
    plausible.
    """
    cam = result.camera
    K = np.linalg.inv(cam.cam_from_img)
    R = cam.cam_from_world_rotation
    w, h = clean.image_size
    sigma_line = settings.sigma_line_rel * math.hypot(w, h)
    slot_of = {k: j for j, k in enumerate(screening.kept)}
    back: list[_DroppedSegment] = []
    for axis in AXES:
        vp_h = K @ R[:, _AXIS_INDEX[axis]]
        kept_segs = [_segments(a, axis) for a in clean.annotations]
        pooled = np.vstack(kept_segs) if kept_segs else np.zeros((0, 4))
        r_kept = np.abs(segment_residuals_px(pooled, vp_h)) if len(pooled) else np.zeros(0)
        scale = max(1.4826 * float(np.median(r_kept)) if len(r_kept) else 0.0, sigma_line)
        for d in screening.dropped:
            if d.axis != axis or d.index not in slot_of:
                continue
            r = abs(float(segment_residuals_px(np.asarray(d.segment), vp_h)[0]))
            if r <= 3.0 * scale:
                back.append(d)
    if not back:
        return result, clean
    anns = list(clean.annotations)
    for slot in sorted({slot_of[d.index] for d in back}):
        ann = anns[slot]
        mine = [d for d in back if slot_of[d.index] == slot]
        lines = {}
        for axis in AXES:
            segs = [tuple(sg) for sg in getattr(ann.vp_lines, axis)]
            segs += [d.segment for d in mine if d.axis == axis]
            lines[axis] = segs
        anns[slot] = ann.model_copy(update={"vp_lines": ann.vp_lines.model_copy(update=lines)})
    new_clean = clean.model_copy(update={"annotations": anns})
    try:
        refit = _calibrate_usable(new_clean, settings)
    except (InputError, np.linalg.LinAlgError):
        return result, clean
    if refit.method != "joint_fit" or implausibility(refit, clean.image_size) is not None:
        return result, clean
    gone = {d.warning for d in back}
    screening.warnings[:] = [wn for wn in screening.warnings if wn not in gone]
    screening.dropped[:] = [d for d in screening.dropped if d.warning not in gone]
    log.info("%d screened-out segment(s) agree with the joint fit: re-admitted", len(back))
    return refit, new_clean


def _pivotal_annotators(result: CalibrationResult, kept: list[int], names: list[str]) -> list[str]:
    """Warnings naming kept annotators without whom no comparable camera was found.

    The jackknife (refitted where its one step found no camera) leaves each annotator out; a
    leave-out that gives another frame (the width edge on the other side) or an implausible
    camera has no place in the spread, so the stated sigmas cannot show how much the answer
    rests on that annotator. In a grazing view where the length and width edges run a few
    degrees apart on screen, one annotator's lines filed under the wrong axis carried the
    fit that way: 26 m off at a stated 2 m (``benchmarks/crowd_slips.py``,
    ``lines_wrong_axis``, seed 7, scene 32). No clean crowd scene of 60 had such a leave-out.
    """
    out = []
    for i in kept:
        if i < len(result.annotator_influence_m) and result.annotator_influence_m[i] is None:
            out.append(
                f"annotator {names[i]!r} (annotations[{i}]): without their work the fit finds "
                "no comparable camera (the car's width on the other side, or an implausible "
                "one): the answer rests on them and the stated sigmas cannot show how much; "
                "check their work"
            )
    return out


def _jackknife(result: CalibrationResult, scene: Scene, settings: CalibrationSettings) -> None:
    """Add the annotators' spread to the uncertainty: leave-one-annotator-out refits.

    The Gauss-Newton covariance trusts every click's noise model; crowd annotators also differ
    in ways the model does not know (a long line drawn a little off). The jackknife variance
    ``(n-1)/n Σ (C₋ᵢ - C̄)²`` of the camera centre over the refits without each annotator
    measures that, and is added to ``position_sigma_m`` (and, for the rotation turned onto the
    main fit's, ``ε = rotvec(R₋ᵢ · Rᵀ)``, to ``rotation_sigma_deg``); each annotator's
    influence (how far the camera moves without them) goes to ``annotator_influence_m``.
    Where the fit used lines detected in the scene's photo (``photo_segments``), the photo
    is one more witness: a refit without its lines (``photo_lines`` off) joins the spread.
    With ``jackknife_leverage`` each refit's move is scaled by its group's leverage, as the
    one-step jackknife's (:func:`_leverage_for_moves`): the two estimate the same spread.
    """
    n = len(scene.annotations)
    c = result.camera.center_in_world
    # The refits keep the main fit's model choices (principal point, corners): cheaper, and
    # the spread then measures the annotators, not the model selection.
    free_pp = result.intrinsics_method == "joint_fit_free_principal_point"
    sub_settings = replace(
        settings,
        jackknife=False,
        free_principal_point=(
            free_pp if settings.free_principal_point is None else settings.free_principal_point
        ),
        reassign_corners=settings.reassign_corners and bool(result.corner_mistakes),
    )
    centres: list[FloatArray] = []
    focals: list[float] = []
    turns: list[FloatArray] = []
    R = result.camera.cam_from_world_rotation
    influence: list[float | None] = []
    # Leave out each annotator in turn, then (where the fit used them) the photo's lines.
    leave_outs: list[tuple[Scene, CalibrationSettings]] = [
        (
            scene.model_copy(
                update={"annotations": [a for k, a in enumerate(scene.annotations) if k != j]}
            ),
            sub_settings,
        )
        for j in range(n)
    ]
    if result.photo_segments:
        leave_outs.append((scene, replace(sub_settings, photo_lines=False)))
    if result.video_segments:
        leave_outs.append((scene, replace(sub_settings, video_lines=None)))
    groups: list[int] = []  # each kept camera's group (as _leverage_factors numbers them)
    for k, (sub, sub_set) in enumerate(leave_outs):
        try:
            res = _calibrate_usable(sub, sub_set)
        except (InputError, np.linalg.LinAlgError):
            influence.append(None)
            continue
        if res.width_sign != result.width_sign or implausibility(res, scene.image_size):
            influence.append(None)  # another frame, or no answer without them
            continue
        groups.append(k)
        centres.append(res.camera.center_in_world)
        focals.append(res.camera.focal_px)
        turn = rotvec_from_rotation(res.camera.cam_from_world_rotation @ R.T)
        if np.linalg.norm(turn) < math.radians(30.0):  # else another frame: not a spread
            turns.append(turn)
        influence.append(float(np.linalg.norm(res.camera.center_in_world - c)))
    result.annotator_influence_m = influence[:n]  # the photo's is nobody's
    # The same estimator as the one-step jackknife: each refit's move scaled by its group's
    # leverage (stop 40; before, the refits' spread was the raw delete-one spread, so the
    # one-step sigmas were compared with another estimator, benchmarks/calibrate_speed.py).
    state = result.joint_state
    lev = None
    if settings.jackknife_leverage and state is not None and state.problem.n_annotators == n:
        lev = _leverage_for_moves(
            state, groups, focals, centres, result.camera, settings.jackknife_leverage_max_move
        )
    _add_jackknife_spread(result, centres, turns, focals, lev)


def _add_jackknife_spread(
    result: CalibrationResult,
    centres: list[FloatArray],
    turns: list[FloatArray],
    focals: list[float] | None = None,
    lev: FloatArray | None = None,
) -> None:
    """Add the jackknife variance of leave-one-out centres, turns (rotvecs) and focal lengths
    to the sigmas.

    ``lev`` ``(len(centres), 7)``: each leave-out's move is first scaled by its group's
    leverage factor per quantity (focal length, rotation x, y, z, centre x, y, z;
    :func:`_leverage_factors`); None (the refits of :func:`_jackknife`): unscaled.
    """
    if len(centres) < 2:
        return
    if lev is None or len(lev) != len(centres):
        lev = np.ones((len(centres), 7))
    if focals is not None and len(focals) >= 2 and result.focal_sigma_px is not None:
        f_arr = np.asarray(focals, dtype=float)
        m_f = len(f_arr)
        dev_f = (f_arr - f_arr.mean()) * (lev[:, 0] if m_f == len(lev) else 1.0)
        sigma_f_jack = math.sqrt((m_f - 1) / m_f * float(np.sum(dev_f**2)))
        # As for the position: the larger of the fit's and the annotators' spread.
        result.focal_sigma_px = max(result.focal_sigma_px, sigma_f_jack)
    arr = np.asarray(centres)
    m = len(arr)
    dev = (arr - arr.mean(axis=0)) * lev[:, 4:7]
    sigma_jack = np.sqrt((m - 1) / m * (dev**2).sum(axis=0))
    base = result.position_sigma_m if result.position_sigma_m is not None else np.zeros(3)
    result.position_sigma_fit_m = base
    result.position_sigma_jackknife_m = sigma_jack
    # The jackknife variance estimates the same sampling spread as the fit's covariance,
    # measured on the annotators instead of modelled: the larger of the two, not their sum
    # (which counted the spread twice).
    result.position_sigma_m = np.maximum(base, sigma_jack)
    if len(turns) < 2:
        return
    rot = np.asarray(turns)
    m_r = len(rot)
    lev_r = lev[:, 1:4] if m_r == len(lev) else 1.0  # a turn dropped: rows unknown
    dev_r = (rot - rot.mean(axis=0)) * lev_r
    rot_jack = np.degrees(np.sqrt((m_r - 1) / m_r * (dev_r**2).sum(axis=0)))
    base_r = result.rotation_sigma_deg if result.rotation_sigma_deg is not None else np.zeros(3)
    result.rotation_sigma_fit_deg = base_r
    # As for the position: the larger, not the root-sum-square, which counted the annotators'
    # spread twice (crowd rotation 1 sigma 87 / 87 / 90 % -> 83 / 82 / 77 %, calibrate_coverage).
    # base_r holds the preset's shared size error (_size_shape_sensitivity), which no
    # jackknife sees: where the jackknife is the larger, it outweighs that too.
    result.rotation_sigma_deg = np.maximum(base_r, rot_jack)


def _leave_one_out_steps(
    state: JointState,
    steps: int = 1,
    settings: CalibrationSettings | None = None,
    *,
    photo_group: bool = False,
) -> list[FloatArray | None]:
    """Parameter vectors of the joint fit without each annotator, by Gauss-Newton steps.

    At the joint solution ``x`` the robust (soft-L1, IRLS-weighted) normal equations are
    ``H = Σₐ Hₐ + H_prior`` and ``g = Σₐ gₐ ≈ 0``, summed over annotators' rows. Leaving
    annotator ``a`` out, one Newton step from ``x`` gives ``x₋ₐ = x − (H − Hₐ)⁻¹ (g − gₐ)``:
    the infinitesimal jackknife, warm-started at the answer, with every other annotator's
    weight, corner and the principal-point model as the joint fit chose them. ``steps > 1``
    repeats the step on the residuals at ``x₋ₐ``. None where the rest do not determine the
    camera (``H − Hₐ`` singular).

    With ``settings`` (and a fitted focal length), each leave-out also makes the focal
    prior's choice as a refit without that annotator would (:func:`_focal_prior`'s first
    case): the weak log-normal prior on the focal length is on where the rest leave the
    focal length loose (its data-only 1-sigma above ``focal_prior_when_sigma_log``), off
    where they fix it, whatever the joint fit chose. Where that differs from the joint fit,
    the annotator's steps are taken again with the prior switched. Without this, the one
    influential annotator whose absence leaves the focal length loose moved the camera by
    the data alone (e.g. 4.5 m where the refit, prior on, moves it 2.4 m).

    ``photo_group``: where the fit holds segments detected in the scene's photo
    (:func:`_add_photo_segments`), they are one more group, left out in turn like an
    annotator; its parameter vector is the last of the list (one more than
    ``problem.n_annotators``). Without it (or without photo segments) the photo's rows are
    nobody's: every leave-out keeps them.
    """
    prob = state.problem
    saved = prob.weights
    saved_prior = prob.log_f_prior_sigma
    prob.weights = state.weights
    try:
        args = (state.rotation0, state.principal_point, state.focal_px)
        owner_base = np.concatenate([prob.seg_ann, prob.pt_ann, prob.pt_ann])
        n_ann = prob.n_annotators
        n_photo = len(prob.photo_segments)
        if photo_group and n_photo:  # the photo's and the video's rows: a group each
            sources = sorted(set(prob.photo_source.tolist()))
            group = np.searchsorted(np.asarray(sources), prob.photo_source)
            owner_base = np.concatenate([owner_base, n_ann + group])
            n_ann += len(sources)
        x0 = np.asarray(state.x, dtype=float)
        h = 1e-7 * np.maximum(1.0, np.abs(x0))  # forward-difference steps
        r, J = prob.residuals_and_jacobian(x0, *args)
        w = 1.0 / np.sqrt(1.0 + (r / _F_SCALE) ** 2)
        Jw = J * w[:, None]
        # Rows a leave-out loses besides its own: the photo's segments of a direction that
        # agreed with the joint fit only (see below). None: none.
        lost: npt.NDArray[np.bool_] | None = None

        def own(n_rows: int) -> FloatArray:
            mask = _owner_mask(owner_base, n_rows, n_ann)
            if lost is not None:
                mask[:, : lost.shape[1]] = np.maximum(mask[:, : lost.shape[1]], lost)
            return mask

        # Per-annotator (and the photo's) blocks of the normal equations, all at once.
        mask = own(len(r))  # (n_ann, m)
        H_all = J.T @ Jw
        g_all = Jw.T @ r
        H_a = np.swapaxes(mask[:, :, None] * J[None], 1, 2) @ Jw  # (n_ann, n, n), batched BLAS
        g_a = mask @ (Jw * r[:, None])
        xs = _newton_steps(
            H_all[None] - H_a, g_all[None] - g_a, np.broadcast_to(x0, (n_ann, len(x0)))
        )
        if photo_group and n_photo and prob.photo_axis_vp:
            # The photo's segments joined because their direction agreed with the
            # annotators' own fit, which holds every annotator. A refit without annotator a
            # selects them again against the fit of the others' clicks: a direction that
            # agreed only through a's lines is lost with them. Without this the one-step
            # kept it, and it stood in for the annotator it had agreed with (development
            # seed 300: 2.7 % where the refits' spread is 10.2 %). The others' clicks
            # alone: every leave-out also without the photo's rows, two steps.
            first = len(owner_base) - n_photo
            lost = np.zeros((n_ann, len(owner_base)), dtype=bool)
            lost[: prob.n_annotators, first:] = True
            mask_c = own(len(r))
            H_c = np.swapaxes(mask_c[:, :, None] * J[None], 1, 2) @ Jw
            g_c = mask_c @ (Jw * r[:, None])
            xs_c = _newton_steps(
                H_all[None] - H_c, g_all[None] - g_c, np.broadcast_to(x0, (n_ann, len(x0)))
            )
            live_c = [a for a in range(prob.n_annotators) if xs_c[a] is not None]
            if live_c:
                _leave_one_out_step(prob, args, xs_c, live_c, mask_c, h)
            lost = _photo_rows_lost(prob, xs_c, args, len(owner_base))
            if lost is not None:
                mask = own(len(r))
                H_a = np.swapaxes(mask[:, :, None] * J[None], 1, 2) @ Jw
                g_a = mask @ (Jw * r[:, None])
                xs = _newton_steps(
                    H_all[None] - H_a, g_all[None] - g_a, np.broadcast_to(x0, (n_ann, len(x0)))
                )
        # The last normal equations of each live annotator: (annotators, J, r, row weights)
        last: tuple[list[int], FloatArray, FloatArray, FloatArray] = (
            list(range(n_ann)),
            np.broadcast_to(J, (n_ann, *J.shape)),
            np.broadcast_to(r, (n_ann, len(r))),
            (1.0 - mask) * w[None, :],
        )
        for _ in range(steps - 1):
            live = [a for a in range(n_ann) if xs[a] is not None]
            if not live:
                break
            last = _leave_one_out_step(prob, args, xs, live, mask, h)
        prior_sigma = settings.focal_prior_sigma_log if settings is not None else 0.0
        if state.focal_px is None and prior_sigma > 0.0:
            assert settings is not None
            last_has_prior = saved_prior > 0.0
            if saved_prior > 0.0:
                # The refit decides on its data-only fit: step there first (on copies).
                prob.log_f_prior_sigma = 0.0
                mask_d = own(len(r) - 1)  # without its row
                xs_d = list(xs)
                live = [a for a in range(n_ann) if xs_d[a] is not None]
                if live:
                    _leave_one_out_step(prob, args, xs_d, live, mask_d, h)
                    live = [a for a in live if xs_d[a] is not None]
                if live:  # the normal equations there only: no step is taken
                    last = _leave_one_out_step(prob, args, xs_d, live, mask_d, h, step=False)
                    last_has_prior = False
                prob.log_f_prior_sigma = saved_prior
            switch = _prior_switches(
                prob, last, settings.focal_prior_when_sigma_log, saved_prior > 0.0, last_has_prior
            )
            if switch:
                prob.log_f_prior_sigma = 0.0 if saved_prior > 0.0 else prior_sigma
                m = len(r) - 1 if saved_prior > 0.0 else len(r) + 1  # the focal prior's row
                mask_t = own(m)
                for _ in range(max(steps, 2)):
                    live = [a for a in switch if xs[a] is not None]
                    if not live:
                        break
                    _leave_one_out_step(prob, args, xs, live, mask_t, h)
        return xs
    finally:
        prob.weights = saved
        prob.log_f_prior_sigma = saved_prior


def _photo_direction_axis(
    vp_px: FloatArray, f: float, pp: tuple[float, float], R: FloatArray
) -> int | None:
    """The axis (index) a photo's vanishing point lends its segments to for the camera
    ``(f, pp, R)``: the nearest of the camera's world axes, if within ``PHOTO_AXIS_TOL_DEG``;
    None where none is (or the point gives no direction)."""
    K_inv = np.linalg.inv(np.array([[f, 0.0, pp[0]], [0.0, f, pp[1]], [0.0, 0.0, 1.0]]))
    d = K_inv @ np.asarray(vp_px, dtype=float)
    n = float(np.linalg.norm(d))
    if not (n > 0.0 and np.isfinite(n)):
        return None
    cosines = np.abs(R.T @ (d / n))  # against the world axes in the camera frame
    i = int(np.argmax(cosines))
    near = math.degrees(math.acos(min(1.0, float(cosines[i])))) <= PHOTO_AXIS_TOL_DEG
    return i if near else None


def _photo_disagreeing_axes(
    vps_px: npt.ArrayLike,
    support: npt.ArrayLike,
    K_inv: FloatArray,
    R: FloatArray,
) -> list[tuple[int, float]]:
    """The axes on which the photo clearly disagrees with a camera, and by how much.

    Among the photo's vanishing points with at least ``PHOTO_MIN_SEGMENTS`` segments
    (``support``, per point), the direction nearest an axis is within
    ``PHOTO_AXIS_NEAR_DEG`` of it but more than ``PHOTO_AXIS_TOL_DEG`` off
    (:func:`_photo_disagreement`'s warning; :func:`_add_photo_segments` then lends nothing).

    Parameters
    ----------
    vps_px
        The photo's vanishing points, ``(k, 3)`` homogeneous pixels.
    support
        Segments per vanishing point, ``(k,)``.
    K_inv
        The camera's inverse intrinsics, ``(3, 3)`` (pixels to camera rays).
    R
        Its ``cam_from_world`` rotation: column ``i`` is world axis ``i`` (length, width,
        up) in the camera frame.

    Returns
    -------
    list of (int, float)
        ``(axis index, angle in degrees)`` per disagreeing axis (0 length, 1 width,
        2 height), ascending; empty where none disagrees.
    """
    vps = np.asarray(vps_px, dtype=float).reshape(-1, 3)
    counts = np.asarray(support, dtype=float).reshape(-1)
    dirs = []
    for k, vp in enumerate(vps):
        if k >= len(counts) or counts[k] < PHOTO_MIN_SEGMENTS:
            continue
        d = K_inv @ vp
        n = float(np.linalg.norm(d))
        if n > 0.0 and np.isfinite(n):
            dirs.append(d / n)
    off = []
    for i in range(3):
        if not dirs:
            break
        a = R[:, i] / np.linalg.norm(R[:, i])
        best = min(math.degrees(math.acos(min(1.0, abs(float(a @ d))))) for d in dirs)
        if PHOTO_AXIS_TOL_DEG < best <= PHOTO_AXIS_NEAR_DEG:
            off.append((i, best))
    return off


def _photo_rows_lost(
    prob: _JointProblem,
    xs: list[FloatArray | None],
    args: tuple[FloatArray, tuple[float, float] | None, float | None],
    n_owned: int,
) -> npt.NDArray[np.bool_] | None:
    """Per leave-out, the photo's rows whose direction no longer agrees with its camera.

    ``(len(xs), n_owned)``: True on the photo's rows (the last ``len(prob.photo_segments)``
    of the first ``n_owned``) of an axis whose photo vanishing point
    (``prob.photo_axis_vp``) no longer lends it its segments at the annotator's
    leave-out ``xs[a]``; the photo's own group (the last, where present) and failed
    leave-outs lose nothing. None when no leave-out loses a row.
    """
    n_photo = len(prob.photo_segments)
    lost = np.zeros((len(xs), n_owned), dtype=bool)
    first = n_owned - n_photo
    for a in range(min(len(xs), prob.n_annotators)):
        x_a = xs[a]
        if x_a is None or not np.all(np.isfinite(x_a)):
            continue
        f, pp, R, _C = prob.unpack(x_a, *args)
        for axis, vp in prob.photo_axis_vp.items():
            if _photo_direction_axis(vp, f, pp, R) != axis:
                lost[a, first:] |= (prob.photo_axis == axis) & (prob.photo_source == 0)
    return lost if lost.any() else None


def _owner_mask(owner_base: npt.NDArray[np.int_], n_rows: int, n_ann: int) -> FloatArray:
    """``(n_ann, n_rows)``: 1 where a row is the group's own (an annotator's, or the photo's
    where ``owner_base`` names it); the rows after ``owner_base`` (the priors, and the
    photo's segments where it does not name them) are nobody's."""
    owner = np.concatenate([owner_base, np.full(n_rows - len(owner_base), -1)])
    return (owner[None, :] == np.arange(n_ann)[:, None]).astype(float)


def _leave_one_out_step(
    prob: _JointProblem,
    args: tuple[FloatArray, tuple[float, float] | None, float | None],
    xs: list[FloatArray | None],
    live: list[int],
    mask: FloatArray,
    h: FloatArray,
    *,
    step: bool = True,
) -> tuple[list[int], FloatArray, FloatArray, FloatArray]:
    """One Gauss-Newton step of each ``live`` leave-out (``xs`` updated in place).

    Every annotator's next step from one batched evaluation: each point and its forward
    differences (steps ``h``), ``len(live) × (n + 1)`` parameter vectors at once; each
    annotator's own rows (``mask``) get zero weight. Returns the live annotators, and at
    their points the Jacobians, residuals and row weights the step used. ``step=False``:
    only those (``xs`` unchanged, no Newton solve): the normal equations at the points.
    """
    pts = np.array([xs[a] for a in live])
    n = pts.shape[1]
    X = (pts[:, None, :] + np.vstack([np.zeros(n), np.diag(h)])[None, :, :]).reshape(-1, n)
    Rb = prob.residuals_batch(X, *args).reshape(len(live), n + 1, -1)
    r_k = Rb[:, 0, :]  # (L, m)
    J_k = np.swapaxes((Rb[:, 1:, :] - r_k[:, None, :]) / h[None, :, None], 1, 2)
    w_k = (1.0 - mask[live]) / np.sqrt(1.0 + (r_k / _F_SCALE) ** 2)
    if not step:
        return live, J_k, r_k, w_k
    Jw_k = J_k * w_k[:, :, None]  # (L, m, n)
    Hs = np.swapaxes(J_k, 1, 2) @ Jw_k
    gs = (np.swapaxes(Jw_k, 1, 2) @ r_k[:, :, None])[:, :, 0]
    for a, x_a in zip(live, _newton_steps(Hs, gs, pts), strict=True):
        xs[a] = x_a
    return live, J_k, r_k, w_k


def _prior_switches(
    prob: _JointProblem,
    last: tuple[list[int], FloatArray, FloatArray, FloatArray],
    sigma_log_when: float,
    prior_on: bool,
    has_prior_row: bool,
) -> list[int]:
    """The leave-outs whose focal prior a refit would choose otherwise than the joint fit.

    As :func:`_param_sigma` on a refit's data-only fit: the focal length's 1-sigma (its log,
    the first parameter) from the IRLS normal equations without the annotator's rows and
    the focal prior's row (``has_prior_row``), times ``2 cost / dof`` of the rows kept;
    ``prior_on``: the joint fit's choice.
    """
    live, J_k, r_k, w_k = last
    n_rows = len(prob.segments) + 2 * len(prob.pt_pix) + len(prob.photo_segments)
    keep = w_k > 0.0
    if has_prior_row:  # the focal prior's row: right after the photo's segments
        keep = keep.copy()
        keep[:, n_rows] = False
    w_d = np.where(keep, w_k, 0.0)
    H_d = np.swapaxes(J_k, 1, 2) @ (J_k * w_d[:, :, None])
    n = J_k.shape[2]
    c2 = _F_SCALE**2
    rho = 2.0 * c2 * (np.sqrt(1.0 + r_k * r_k / c2) - 1.0)
    dof = np.maximum(keep.sum(axis=1) - n, 1)
    s2 = np.maximum((rho * keep).sum(axis=1) / dof, 1e-12)
    # (H⁻¹)₀₀ of every leave-out at once, diagonally scaled; one by one if one is singular.
    d = np.sqrt(np.clip(np.diagonal(H_d, axis1=1, axis2=2), 1e-300, None))
    e0 = np.zeros((len(live), n, 1))
    e0[:, 0, 0] = 1.0 / d[:, 0]
    try:
        inv00 = np.linalg.solve(H_d / d[:, :, None] / d[:, None, :], e0)[:, 0, 0] / d[:, 0]
    except np.linalg.LinAlgError:
        inv00 = np.array([_sym_inverse(H)[0, 0] for H in H_d])
    var = inv00 * s2
    loose = ~(var >= 0.0) | (np.sqrt(np.abs(var)) > sigma_log_when)
    return [a for k, a in enumerate(live) if bool(loose[k]) != prior_on]


def _newton_steps(H: FloatArray, g: FloatArray, x: FloatArray) -> list[FloatArray | None]:
    """:func:`_newton_step` for a stack ``H (k, n, n)``, ``g (k, n)``, ``x (k, n)`` at once.

    ``H`` is symmetric (normal equations): the condition number of the diagonally scaled
    matrix comes from its eigenvalues (one batched call instead of an SVD per step).
    """
    d = np.sqrt(np.clip(np.diagonal(H, axis1=1, axis2=2), 1e-300, None))
    Hs = H / d[:, :, None] / d[:, None, :]
    out: list[FloatArray | None] = [None] * len(H)
    try:
        lam = np.abs(np.linalg.eigvalsh(Hs))  # its lower triangle: Hs is symmetric
    except np.linalg.LinAlgError:
        return [_newton_step(H[k], g[k], x[k]) for k in range(len(H))]
    with np.errstate(divide="ignore", invalid="ignore"):
        cond = lam.max(axis=1) / lam.min(axis=1)
    ok = np.isfinite(cond) & (cond <= 1e10)
    if ok.all():  # the usual case: no selection
        steps = np.linalg.solve(Hs, (g / d)[:, :, None])[:, :, 0] / d
        return list(np.asarray(x - steps, dtype=np.float64))
    if np.any(ok):
        steps = np.linalg.solve(Hs[ok], (g[ok] / d[ok])[:, :, None])[:, :, 0] / d[ok]
        for k, step in zip(np.flatnonzero(ok), x[ok] - steps, strict=True):
            out[int(k)] = np.asarray(step, dtype=np.float64)
    return out


def _newton_step(H: FloatArray, g: FloatArray, x: FloatArray) -> FloatArray | None:
    """``x − H⁻¹ g``, or None when ``H`` is (numerically) singular."""
    d = np.sqrt(np.clip(np.diag(H), 1e-300, None))
    Hs = H / d[:, None] / d[None, :]
    if np.linalg.cond(Hs) > 1e10:
        return None
    return np.asarray(x - np.linalg.solve(Hs, g / d) / d, dtype=np.float64)


def _jackknife_one_step(result: CalibrationResult, settings: CalibrationSettings) -> bool:
    """The leave-one-annotator-out spread of :func:`_jackknife` without refits.

    Each annotator's leave-out camera comes from two steps of :func:`_leave_one_out_steps`
    on the joint fit's state, the focal prior chosen per leave-out as a refit chooses it;
    where the photo's detected lines joined the fit, they are left out in turn as one more
    group (its camera joins the spread, not ``annotator_influence_m``: a detected segment
    set shares its biases, so the photo is one witness, issue 28). The spread and the
    influences are then as in :func:`_jackknife`. All six sigmas within
    10 % of the refits' in 90-100 % of held-out crowd scenes (benchmarks/README.md).

    Returns False, changing nothing, when the steps give no camera without some annotator:
    the linearisation does not reach that leave-out, which is then the one that matters (one
    annotator's single long line 5-15 degrees off its axis can carry the whole answer, and
    leaving it out moves the camera by tens of metres; ``benchmarks/crowd_slips.py``).
    :func:`_calibrate_annotations` then refits (:func:`_jackknife`).
    """
    state = result.joint_state
    assert state is not None
    prob = state.problem
    args = (state.rotation0, state.principal_point, state.focal_px)
    c = result.camera.center_in_world
    R = result.camera.cam_from_world_rotation
    M, origin = state.internal_from_output, state.internal_origin
    centres: list[FloatArray] = []
    focals: list[float] = []
    turns: list[FloatArray] = []
    influence: list[float | None] = []
    xs = _leave_one_out_steps(state, steps=2, settings=settings, photo_group=True)
    n_ann = prob.n_annotators  # xs[n_ann], where there is one: without the photo's lines
    live = [a for a, x in enumerate(xs) if x is not None and np.all(np.isfinite(x))]
    answers: dict[int, tuple[float, FloatArray, FloatArray]] = {}
    if live:  # every leave-out camera unpacked at once (as prob.unpack, one by one)
        f_b, _pp, R_b, C_b = prob._unpack_batch(np.array([xs[a] for a in live]), *args)
        c_b = (C_b - origin) @ M  # Mᵀ (C - origin), row by row
        turn_b = (R_b @ M) @ R.T
        answers = {a: (float(f_b[k]), c_b[k], turn_b[k]) for k, a in enumerate(live)}
    if any(a not in answers or answers[a][1][2] <= 0.0 for a in range(n_ann)):
        return False
    for a in range(len(xs)):
        if a not in answers or answers[a][1][2] <= 0.0:  # no answer without them
            if a < n_ann:
                influence.append(None)
            continue
        f_i, c_i, turn_matrix = answers[a]
        centres.append(c_i)
        focals.append(f_i)
        turn = _small_rotvec(turn_matrix)
        if _vector_norm(turn) < math.radians(30.0):
            turns.append(turn)
        if a < n_ann:
            influence.append(float(_vector_norm(c_i - c)))
        else:
            log.info(
                "without one witness group's lines (photo, video): focal length %+.1f %%, "
                "camera moved %.2f m",
                100.0 * (f_i / result.camera.focal_px - 1.0),
                float(_vector_norm(c_i - c)),
            )
    result.annotator_influence_m = influence
    lev = None
    if settings.jackknife_leverage:  # each leave-out's move shrunk by its group's leverage
        kept_groups = [a for a in range(len(xs)) if a in answers and answers[a][1][2] > 0.0]
        lev = _leverage_for_moves(
            state,
            kept_groups,
            focals,
            centres,
            result.camera,
            settings.jackknife_leverage_max_move,
        )
    _add_jackknife_spread(result, centres, turns, focals, lev)
    return True


def _leverage_for_moves(
    state: JointState,
    groups: list[int],
    focals: list[float],
    centres: list[FloatArray],
    camera: Camera,
    max_move: float,
) -> FloatArray | None:
    """:func:`_leverage_factors` of the leave-outs ``groups`` that landed at ``focals`` and
    ``centres`` (one each, in order), the answer being ``camera``.

    The leverage is the normal equations' at the joint solution: a leave-out that moves the
    focal length or the camera's distance from the car by more than ``max_move`` (a
    fraction) keeps its whole move (factor 1; see ``CalibrationSettings``: measured where
    such leave-outs land, the factor is about the joint solution's, so this widens). None
    where :func:`_leverage_factors` is.
    """
    lev = _leverage_factors(state, groups)
    if lev is None:
        return None
    c = camera.center_in_world
    f0 = camera.focal_px
    dist = max(float(_vector_norm(c)), 1e-9)
    for k, (f_a, c_a) in enumerate(zip(focals, centres, strict=True)):
        move = max(abs(f_a / f0 - 1.0), float(_vector_norm(c_a - c)) / dist)
        if move > max_move:
            lev[k] = 1.0
    return lev


def _leverage_factors(state: JointState, groups: list[int]) -> FloatArray | None:
    """How much of each leave-out's move is the group's own noise: ``(len(groups), 7)``.

    The delete-one jackknife over-states the spread of an answer that rests unevenly on its
    annotators (in regression, the "CR3" / HC3 covariance: each leave-out's move carries the
    factor ``(1 - h)⁻¹`` of its leverage ``h``). An annotator whose long lines carry 80 % of
    what fixes the focal length moves it, left out, by five times their share of its error;
    with 3-7 annotators drawing different lines that is common, and where the jackknife was
    the larger sigma it covered the crowd set's focal length 95 / 100 % at 1 / 2 sigma
    (median error/sigma 0.37, 83 of 240 scenes; one step and refits alike). Per quantity
    ``q = aᵀx`` (the focal length's log, the rotation about the camera's x, y, z, the centre's
    x, y, z in the output frame), the factor is ``√(1 − h) = √(aᵀH⁻¹a / aᵀ(H − Hₐ)⁻¹a)``
    (the robust Gauss-Newton normal matrix with and without the group's rows, at the joint
    solution), which scales the move back to the group's share as the "CR2"
    (Bell-McCaffrey) estimator does: exact for the mean of equal annotators (then
    ``h = 1/n`` and the spread is unchanged in expectation). ``groups``: the annotators
    (and the photo's or video's line groups, after them) whose leave-out kept a camera.

    None when a normal matrix is singular (the moves then stay as they are).
    """
    prob = state.problem
    saved = prob.weights
    prob.weights = state.weights
    try:
        args = (state.rotation0, state.principal_point, state.focal_px)
        x0 = np.asarray(state.x, dtype=float)
        r, J = prob.residuals_and_jacobian(x0, *args)
    finally:
        prob.weights = saved
    owner_base = np.concatenate([prob.seg_ann, prob.pt_ann, prob.pt_ann])
    n_ann = prob.n_annotators
    if len(prob.photo_segments):
        sources = sorted(set(prob.photo_source.tolist()))
        group = np.searchsorted(np.asarray(sources), prob.photo_source)
        owner_base = np.concatenate([owner_base, n_ann + group])
        n_ann += len(sources)
    w = 1.0 / np.sqrt(1.0 + (r / _F_SCALE) ** 2)
    Jw = J * w[:, None]
    mask = _owner_mask(owner_base, len(r), n_ann)
    H = J.T @ Jw
    H_a = np.swapaxes(mask[:, :, None] * J[None], 1, 2) @ Jw
    n = len(x0)
    A = np.zeros((n, 7))
    if state.focal_px is None:
        A[0, 0] = 1.0
    A[-6:-3, 1:4] = np.eye(3)
    A[-3:, 4:7] = state.internal_from_output
    try:
        v = np.einsum("ij,ij->j", A, np.linalg.solve(H, A))
        out = []
        for a in groups:
            va = np.einsum("ij,ij->j", A, np.linalg.solve(H - H_a[a], A))
            out.append(np.sqrt(np.clip(v / np.where(va > 0, va, np.inf), 0.0, 1.0)))
    except np.linalg.LinAlgError:
        return None
    return np.asarray(out, dtype=np.float64)


def _so3_left_jacobian(rotvec: FloatArray) -> FloatArray:
    """Left Jacobian of SO(3): ``exp(ω + dω) ≈ exp(J_l(ω)·dω)·exp(ω)``."""
    w = np.asarray(rotvec, dtype=float)
    theta = float(np.linalg.norm(w))
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    if theta < 1e-6:
        return np.asarray(np.eye(3) + 0.5 * K, dtype=float)
    a = (1.0 - math.cos(theta)) / theta**2
    b = (theta - math.sin(theta)) / theta**3
    return np.asarray(np.eye(3) + a * K + b * (K @ K), dtype=float)


def _no_usable_annotator(excluded: list[dict[str, Any]]) -> InputError:
    """The error when every annotator was left out: their reasons, one line."""
    parts = [f"annotations[{e['index']}].{e['reason']}" for e in excluded[:3]]
    more = f" (+{len(excluded) - 3} more)" if len(excluded) > 3 else ""
    geometric = all(e.get("geometry") for e in excluded)
    if len(excluded) == 1:
        text = parts[0]
    else:
        text = "no usable annotator: " + "; ".join(
            f"{p} ({e['annotator']})" for p, e in zip(parts, excluded, strict=False)
        )
    return (DegenerateGeometryError if geometric else SceneError)(text + more)


def _leave_one_out(
    scene: Scene, settings: CalibrationSettings, result: CalibrationResult, problem: str
) -> tuple[CalibrationResult, int]:
    """The best plausible fit without one annotator, and that annotator's slot.

    Annotators are tried from the least trusted (lowest weight in the implausible fit); the
    plausible refit with the smallest residual wins.

    Raises
    ------
    DegenerateGeometryError
        Naming ``problem`` when no annotator's removal gives a plausible camera.
    """
    n = len(scene.annotations)
    if n < 2:
        raise DegenerateGeometryError(
            f"no plausible camera: {problem}; the only usable annotator "
            f"({scene.annotations[0].annotator}) cannot be checked against others"
        )
    weights = result.annotator_weights if len(result.annotator_weights) == n else [1.0] * n
    order = sorted(range(n), key=lambda j: weights[j])[:_MAX_LEAVE_OUT]
    best: tuple[float, CalibrationResult, int] | None = None
    for j in order:
        sub = scene.model_copy(
            update={"annotations": [a for k, a in enumerate(scene.annotations) if k != j]}
        )
        try:
            res = _calibrate_usable(sub, settings)
        except InputError:
            continue
        if implausibility(res, scene.image_size) is not None:
            continue
        score = res.rms_residual_px if res.rms_residual_px is not None else 0.0
        if best is None or score < best[0]:
            best = (score, res, j)
    if best is None:
        raise DegenerateGeometryError(
            f"no plausible camera: {problem}, and leaving out any one annotator does not help"
        )
    return best[1], best[2]


def _calibrate_usable(scene: Scene, settings: CalibrationSettings) -> CalibrationResult:
    """:func:`calibrate` on annotations already screened."""
    settings = settings or CalibrationSettings()
    if not scene.annotations:
        raise SceneError("at least one annotation is needed to calibrate", "annotations")
    size = scene.object_size
    gathered = [_gather_segments(scene, i) for i in range(len(scene.annotations))]
    segs = [g[0] for g in gathered]
    shorts = [g[1] for g in gathered]
    count_warnings = _check_segment_counts(scene, shorts, segs)
    sols: list[AnnotatorSolution] = []
    first_error: DegenerateGeometryError | None = None
    for i in range(len(scene.annotations)):
        if shorts[i]:
            sols.append(
                AnnotatorSolution(
                    i,
                    scene.annotations[i].annotator,
                    {},
                    error=next(w for w in count_warnings if w.startswith(f"annotations[{i}]")),
                )
            )
            continue
        try:
            sols.append(solve_annotator(scene, i, segs[i], size=size))
        except DegenerateGeometryError as exc:
            if first_error is None:
                first_error = exc
            vps: dict[str, VanishingPoint] = {}
            sols.append(AnnotatorSolution(i, scene.annotations[i].annotator, vps, error=str(exc)))
            log.info("annotator %d skipped by the closed form: %s", i, exc)
    good = [s for s in sols if s.camera is not None]
    if not good:
        if first_error is None:
            first_error = DegenerateGeometryError(
                "no annotator drew at least 2 segments for every axis"
            )
        axes_problem = any(".axes" in (sl.error or "") for sl in sols)
        if not settings.joint_fit or axes_problem:
            raise first_error
        # No annotator alone determines a camera (their own lines are too few or too noisy);
        # everybody's lines pooled may still do. Degenerate axis clicks are not rescued.
        try:
            pooled = _pooled_seed(scene, segs, size)
        except DegenerateGeometryError:
            raise first_error from None
        pseudo = AnnotatorSolution(
            -1,
            "pooled",
            {},
            IntrinsicsEstimate(
                pooled.focal_px,
                pooled.principal_point,
                "pooled",
                f"every annotator's closed form failed (first: {first_error}); "
                "vanishing points of all annotators' lines pooled",
            ),
            camera=pooled,
        )
        cluster = {
            "threshold_m": None,
            "members": [],
            "centroid": pooled.center_in_world.tolist(),
            "n_candidates": 0,
            "n_clusters": 0,
        }
        result = _joint(scene, sols, segs, pseudo, cluster, pooled, size, settings)
        result.warnings = [
            *count_warnings,
            f"no closed-form solution: {first_error}",
            *result.warnings,
        ]
        return result
    candidates = [(s.index, k, s.candidates[k]) for s in good for k in ("length", "width")]
    cluster = _cluster(candidates, settings)
    centroid = np.asarray(cluster["centroid"])
    member_idx = sorted({m["annotator"] for m in cluster["members"]})
    # Seed: the cluster member whose combined camera is closest to the centroid.
    seed = min(
        (s for s in good if s.index in member_idx),
        key=lambda s: float(np.linalg.norm(s.camera.center_in_world - centroid)),  # type: ignore[union-attr]
    )
    assert seed.camera is not None
    assert seed.intrinsics is not None
    intr_method, intr_reason = seed.intrinsics.method, seed.intrinsics.reason
    cluster_camera = Camera.from_center(
        seed.camera.focal_px,
        seed.camera.principal_point,
        seed.camera.cam_from_world_rotation,
        centroid,
    )
    warnings: list[str] = list(count_warnings)

    def cluster_result() -> CalibrationResult:
        # The paper's answer: the centroid of the largest cluster, its members trusted.
        return CalibrationResult(
            cluster_camera,
            "cluster_centroid",
            intr_method,
            intr_reason,
            sols,
            cluster,
            [1.0 if s.index in member_idx else 0.0 for s in sols],
            [s.annotator for s in sols if s.index not in member_idx],
            width_signs=[s.width_sign for s in sols],
            warnings=warnings,
        )

    if not settings.joint_fit:
        return cluster_result()
    try:
        result = _joint(scene, sols, segs, seed, cluster, cluster_camera, size, settings)
        result.warnings = warnings + result.warnings
        return result
    except (DegenerateGeometryError, np.linalg.LinAlgError, ValueError) as exc:
        warnings.append(f"joint fit failed ({exc}); using the cluster centroid")
        log.warning("joint fit failed: %s", exc)
        return cluster_result()


def _width_signs_for(scene: Scene, indices: list[int], camera: Camera) -> list[float]:
    """Each annotator's width sign under ``camera``: the sign of the camera's world y axis
    that moves their origin click toward their width click (1 where ambiguous)."""
    y_axis = camera.cam_from_world_rotation[:, 1]
    cam_from_img = camera.cam_from_img
    out = []
    for i in indices:
        axes = scene.annotations[i].axes
        m0 = cam_from_img @ np.array([*axes.origin, 1.0])
        step = np.asarray(axes.width, float) - np.asarray(axes.origin)
        out.append(direction_sign(y_axis, m0, step) or 1.0)
    return out


def _robust_vp(segments: FloatArray, diag: float, name: str) -> VanishingPoint:
    """Vanishing point of pooled segments, dropping segments that disagree (3 × MAD)."""
    vp = fit_vanishing_point(segments, scale_px=diag, name=name)
    keep = np.ones(len(segments), bool)
    for _ in range(3):
        r = np.abs(segment_residuals_px(segments, vp.homogeneous))
        scale = max(1.4826 * float(np.median(r[keep])), 0.002 * diag)
        new_keep = r <= 3.0 * scale
        if new_keep.sum() < 2 or np.array_equal(new_keep, keep):
            break
        keep = new_keep
        vp = fit_vanishing_point(segments[keep], scale_px=diag, name=name)
    return vp


def _pooled_seed(scene: Scene, segs: list[dict[str, FloatArray]], size: ObjectSize) -> Camera:
    """Closed-form camera from all annotators' segments pooled per axis.

    Every annotator draws lines of the same three world directions in the same image, so
    pooling them gives one, much better determined, vanishing point per axis. Axis signs are
    a majority vote; the position is the coordinate-wise median over annotators.
    """
    width, height = scene.image_size
    diag = math.hypot(width, height)
    vps = {
        axis: _robust_vp(np.vstack([s[axis] for s in segs]), diag, f"vp_lines.{axis} (pooled)")
        for axis in AXES
    }
    intr = estimate_intrinsics(
        {k: v.homogeneous for k, v in vps.items()},
        (width, height),
        focal_px=scene.camera.focal_px,
        principal_point=scene.camera.principal_point,
    )
    f = intr.focal_px
    cx, cy = intr.principal_point
    cam_from_img, dirs = _vanishing_directions(vps, intr)
    votes = {"length": 0.0, "height": 0.0}
    for ann in scene.annotations:
        o = np.asarray(ann.axes.origin, float)
        m0 = cam_from_img @ np.array([*o, 1.0])
        for k in votes:
            votes[k] += direction_sign(dirs[k], m0, np.asarray(getattr(ann.axes, k), float) - o)
    d_len = (1.0 if votes["length"] >= 0 else -1.0) * dirs["length"]
    d_up = (1.0 if votes["height"] >= 0 else -1.0) * dirs["height"]
    y_ref = _cross3(d_up, d_len)
    d_wid = dirs["width"] if float(dirs["width"] @ y_ref) >= 0 else -dirs["width"]
    R = rotation_from_vanishing_directions({"length": d_len, "width": d_wid, "height": d_up})
    centres = []
    for ann in scene.annotations:
        o = np.asarray(ann.axes.origin, float)
        m0 = cam_from_img @ np.array([*o, 1.0])
        ws = direction_sign(R[:, 1], m0, np.asarray(ann.axes.width, float) - o) or 1.0
        ends = _object_points(size, ws)
        nums, dens = _origin_depth_terms(cam_from_img, ann, R, ends)
        ahead = nums / np.maximum(dens, 1e-18) > 0
        num, den = float(nums[ahead].sum()), float(dens[ahead].sum())
        if den > 0:
            centres.append(-R.T @ ((num / den) * m0))
    if not centres:
        raise DegenerateGeometryError("no annotator's axes put the object in front of the camera")
    return Camera.from_center(f, (cx, cy), R, np.median(np.asarray(centres), axis=0))


def _robust_cost(
    prob: _JointProblem,
    x: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float],
    f_fixed: float | None,
) -> float:
    """Soft-L1 cost of all residuals with every annotator weighted equally."""
    saved = prob.weights
    prob.weights = np.ones(prob.n_annotators)
    r = prob.residuals(x, R0, pp_fixed, f_fixed)
    prob.weights = saved
    return soft_l1_cost(r, _F_SCALE)


def _reassign_corners(
    prob: _JointProblem,
    x: FloatArray,
    R0: FloatArray,
    pp_fixed: tuple[float, float],
    f_fixed: float | None,
) -> FloatArray:
    """Re-interpret annotators who marked another corner of the car instead of dropping them.

    An annotator who started at the wrong corner still marked the car's edges; their clicks
    are the world points of that corner (:func:`_corner_points`). Starting from the
    reweighted fit, each down-weighted or poorly fitting annotator is moved to the corner
    that explains their clicks clearly better (by half, and by more than the click noise);
    the move is kept only if the refit lowers the total robust cost with every annotator
    weighted equally.
    """
    for _ in range(2):
        best = prob.best_corners(x, R0, pp_fixed, f_fixed)
        f, (cx, cy), R, C = prob.unpack(x, R0, pp_fixed, f_fixed)
        clicks = prob.pt_pix.reshape(-1, 4, 2)
        proposal = prob.corners.copy()
        for a in range(prob.n_annotators):
            if best[a] == prob.corners[a]:
                continue
            errs = []
            for c in (int(prob.corners[a]), int(best[a])):
                pts = prob._corner_table[c]
                pc = (pts - C) @ R.T
                z = np.maximum(pc[:, 2], prob._z_min)
                proj = pc[:, :2] / z[:, None] * f + np.array([cx, cy])
                errs.append(float(np.linalg.norm(proj - clicks[a], axis=1).mean()))
            if errs[1] < 0.5 * errs[0] and errs[0] - errs[1] > 3.0 * prob.sigma_pt:
                proposal[a] = best[a]
        if np.array_equal(proposal, prob.corners):
            return x
        before = _robust_cost(prob, x, R0, pp_fixed, f_fixed)
        saved_corners, saved_w = prob.corners.copy(), prob.weights.copy()
        prob.set_corners(proposal)
        prob.weights = np.ones(prob.n_annotators)
        x_new = _fit(
            prob, x, R0, pp_fixed, f_fixed, tol=1e-6, max_nfev=100, sigma_tol=_RW_SIGMA_TOL
        ).x
        prob.weights = _cauchy_weights(prob.per_annotator_rms(x_new, R0, pp_fixed, f_fixed))
        x_new = _fit(
            prob, x_new, R0, pp_fixed, f_fixed, tol=1e-6, max_nfev=100, sigma_tol=_RW_SIGMA_TOL
        ).x
        after = _robust_cost(prob, x_new, R0, pp_fixed, f_fixed)
        if after < before:
            x = x_new
            continue
        prob.set_corners(saved_corners)
        prob.weights = saved_w
        return x
    return x


def _jtj_inverse(prob: _JointProblem, jac: FloatArray) -> FloatArray:
    """``_sym_inverse(jac.T @ jac)``, remembered by ``prob`` for the last ``jac`` object
    (the focal prior's check and the covariance look at the same final fit)."""
    last = prob._jtj_inverse
    if last is not None and last[0] is jac:
        return last[1]
    inv = _sym_inverse(jac.T @ jac)
    prob._jtj_inverse = (jac, inv)
    return inv


def _param_sigma(prob: _JointProblem, res: Any, sl: slice) -> float | None:
    """Largest 1-sigma of a block of fitted parameters (Gauss-Newton covariance)."""
    dof = max(len(res.fun) - len(res.x), 1)
    s2 = max(2.0 * res.cost / dof, 1e-12)
    try:
        cov = _jtj_inverse(prob, res.jac) * s2
    except np.linalg.LinAlgError:
        return None
    return float(np.sqrt(np.max(np.clip(np.diag(cov)[sl], 0, None))))


def _weighted_cost(
    prob: _JointProblem, x: FloatArray, R0: FloatArray, pp_fixed: tuple[float, float] | None
) -> float:
    """Soft-L1 cost of the residuals as fitted (annotator weights and prior as set)."""
    return soft_l1_cost(prob.residuals(x, R0, pp_fixed, None), _F_SCALE)


def _focal_prior(
    prob: _JointProblem,
    res: Any,
    R0: FloatArray,
    pp_fixed: tuple[float, float],
    settings: CalibrationSettings,
) -> Any:
    """The fit with the weak focal-length prior where the annotations need it.

    Two cases, both leaving a well-determined fit untouched (no bias):

    - the annotations leave the focal length loose (1-sigma above
      ``focal_prior_when_sigma_log``): refit with the prior;
    - a second basin: a telephoto camera far away and a normal lens nearby can explain a car
      seen almost side-on equally well (one vanishing point near infinity), and the fit may
      sit tightly in the wrong one (measured: 14x the true focal length, "1 %" sigma). When
      the fit's focal length exceeds ``focal_prior_basin_widths`` image widths (a field of
      view under 14°), a fit started at the prior's focal length (the camera moved in
      proportion) is kept if it lands more than 20 % away and its cost with the prior (a
      MAP comparison) is lower.
    """
    sigma = settings.focal_prior_sigma_log
    sig_log_f = _param_sigma(prob, res, slice(0, 1))
    if sig_log_f is None or sig_log_f > settings.focal_prior_when_sigma_log:
        prob.log_f_prior_sigma = sigma
        return _fit(prob, res.x, R0, pp_fixed, None)
    if float(res.x[0]) < math.log(settings.focal_prior_basin_widths * prob.image_wh[0]):
        return res  # an ordinary lens, well determined: the data alone
    prob.log_f_prior_sigma = sigma
    cost_data_basin = _weighted_cost(prob, res.x, R0, pp_fixed)
    x_b = np.asarray(res.x, dtype=float).copy()
    x_b[0] = prob.log_f_prior
    x_b[-3:] *= math.exp(prob.log_f_prior - float(res.x[0]))
    try:
        res_b = _fit(prob, x_b, R0, pp_fixed, None)
    except (np.linalg.LinAlgError, ValueError):
        res_b = None
    if (
        res_b is not None
        and abs(float(res_b.x[0]) - float(res.x[0])) > 0.2
        and _weighted_cost(prob, res_b.x, R0, pp_fixed) < cost_data_basin
    ):
        return res_b
    prob.log_f_prior_sigma = 0.0
    return res


def _cauchy_weights(rms: FloatArray) -> FloatArray:
    scale = max(1.0, _median(rms))
    w = 1.0 / (1.0 + (rms / (2.0 * scale)) ** 2)
    return np.asarray(w / w.max(), dtype=np.float64)


def _median(values: FloatArray) -> float:
    """``np.median`` of a few values (the middle one, or the mean of the middle two), in
    Python floats: 1 µs instead of numpy's 12 µs of per-call overhead."""
    v = sorted(np.asarray(values, dtype=float).tolist())
    n = len(v)
    if n == 0 or any(x != x for x in v):  # empty or NaN: NaN, as numpy
        return math.nan
    mid = n // 2
    return float(v[mid]) if n % 2 else (v[mid - 1] + v[mid]) / 2.0


def _joint(
    scene: Scene,
    sols: list[AnnotatorSolution],
    segs: list[dict[str, FloatArray]],
    seed: AnnotatorSolution,
    cluster: dict[str, Any],
    cluster_camera: Camera,
    size: ObjectSize,
    settings: CalibrationSettings,
) -> CalibrationResult:
    assert seed.intrinsics is not None
    indices = list(range(len(scene.annotations)))
    f_fixed = scene.camera.focal_px
    pp_given = scene.camera.principal_point
    width, height = scene.image_size
    centre = (width / 2.0, height / 2.0)
    pp_fixed: tuple[float, float] = (
        (float(pp_given[0]), float(pp_given[1])) if pp_given is not None else centre
    )

    def pooled() -> Camera | None:
        try:
            return _pooled_seed(scene, segs, size)
        except DegenerateGeometryError as exc:
            log.info("pooled seed unavailable: %s", exc)
            return None

    # The closed form's cluster camera first (it is already paid for); the pooled seed
    # (~4 ms: robust vanishing points of everybody's lines) only when the cluster seed's fit
    # leaves the median annotator above 1 sigma. Measured on benchmarks/relative.py --n 60:
    # the same answers (4 scenes moved by <= 2 cm), -3 ms per calibrate.
    seeds: list[Any] = [cluster_camera, pooled]
    best: tuple[float, _JointProblem, Any, FloatArray, list[float]] | None = None
    best_key: tuple[bool, float] | None = None
    for seed_or_maker in seeds:
        if best_key is not None and not best_key[0] and best_key[1] <= _GOOD_SEED_SCORE:
            # the first seed already explains every annotator within the noise, with the
            # camera above the ground (a fit below it may be a mirror minimum of the cluster
            # seed: the pooled seed then gets its chance, as it always did before)
            break
        cam0 = seed_or_maker() if callable(seed_or_maker) else seed_or_maker
        if cam0 is None:
            continue
        width_signs = _width_signs_for(scene, indices, cam0)
        prob = _JointProblem(
            scene,
            segs,
            indices,
            width_signs,
            size,
            settings,
            size_sigma_rel=0.0 if _size_given(scene) else settings.size_sigma_rel,
        )
        R0 = cam0.cam_from_world_rotation
        x0 = _pack(cam0.focal_px, pp_fixed, cam0.center_in_world, f_fixed is None, False)
        prob.set_corners([0 if w == prob.ws_common else 2 for w in width_signs])
        prob.weights = _cauchy_weights(prob.per_annotator_rms(x0, R0, pp_fixed, f_fixed))
        res = _fit(
            prob, x0, R0, pp_fixed, f_fixed, tol=1e-4, max_nfev=60, sigma_tol=_SEED_SIGMA_TOL
        )
        score = _median(prob.per_annotator_rms(res.x, R0, pp_fixed, f_fixed))
        below_ground = bool(prob.unpack(res.x, R0, pp_fixed, f_fixed)[3][2] <= 0.0)
        if best_key is None or score < best_key[1]:
            best, best_key = (score, prob, res, R0, width_signs), (below_ground, score)
    assert best is not None
    _score, prob, res, R0, width_signs = best
    x0 = res.x
    for _ in range(3):  # iteratively reweighted over annotators
        new_w = _cauchy_weights(prob.per_annotator_rms(x0, R0, pp_fixed, f_fixed))
        if bool(np.all(np.abs(new_w - prob.weights) <= 0.02 + 1e-5 * np.abs(prob.weights))):
            # (np.allclose(new_w, prob.weights, atol=0.02) without its per-call overhead)
            break
        prob.weights = new_w
        x0 = _fit(
            prob, x0, R0, pp_fixed, f_fixed, tol=1e-6, max_nfev=100, sigma_tol=_RW_SIGMA_TOL
        ).x
    if settings.reassign_corners:
        x0 = _reassign_corners(prob, x0, R0, pp_fixed, f_fixed)
    res = _fit(prob, x0, R0, pp_fixed, f_fixed, tol=1e-8)
    photo_used: dict[str, int] = {}
    if settings.photo_lines:
        photo_used = _add_photo_segments(scene, prob, res.x, R0, pp_fixed, f_fixed)
        if photo_used:
            res = _fit(prob, res.x, R0, pp_fixed, f_fixed, tol=1e-8)
    video_used: dict[str, int] = {}
    if settings.video_lines is not None:
        video_used = _add_video_segments(
            scene, settings.video_lines, prob, res.x, R0, pp_fixed, f_fixed
        )
        if video_used:
            res = _fit(prob, res.x, R0, pp_fixed, f_fixed, tol=1e-8)
    if f_fixed is None and settings.focal_prior_sigma_log > 0.0:
        res = _focal_prior(prob, res, R0, pp_fixed, settings)
    chosen: tuple[Any, tuple[float, float] | None] = (res, pp_fixed)
    free_pp = settings.free_principal_point
    n_res = len(res.fun)
    worth_trying = free_pp is True or (
        free_pp is None
        and _score_test(prob, res.x, R0, pp_fixed, f_fixed)
        / max(2.0 * res.cost / max(n_res - len(res.x), 1), 1e-12)
        > 0.5 * (27.6 + 2.0 * math.log(n_res))
    )
    if pp_given is None and free_pp is not False and worth_trying:
        f0, _pp, R1, C1 = prob.unpack(res.x, R0, pp_fixed, f_fixed)
        x1 = _pack(f0, pp_fixed, C1, f_fixed is None, True)
        x1[-6:-3] = _small_rotvec(R1 @ R0.T)
        res_free = _fit(prob, x1, R0, None, f_fixed)
        cost_fixed, cost_free = 2.0 * res.cost, 2.0 * res_free.cost
        k_free = len(res_free.x)
        s2 = max(cost_free / max(n_res - k_free, 1), 1e-12)
        improvement = (cost_fixed - cost_free) / s2
        # Freeing the principal point must pay for itself clearly: a chi-square(2) jump at
        # p < 1e-6 (27.6) on top of the BIC penalty, and a well-determined result.
        pp_sigma = _param_sigma(
            prob, res_free, slice(int(f_fixed is None), int(f_fixed is None) + 2)
        )
        well_determined = pp_sigma is not None and pp_sigma < 0.02 * math.hypot(width, height)
        justified = improvement > 27.6 + 2.0 * math.log(n_res) and well_determined
        if free_pp or (justified and res_free.success):
            chosen = (_without_pp_prior(prob, res_free, R0, f_fixed), None)
    res, pp_model_or_none = chosen
    pp_model: tuple[float, float] | None = pp_model_or_none
    f, pp, R, C = prob.unpack(res.x, R0, pp_model, f_fixed)
    # The output frame: the corner the annotators chose; where they disagree, the one the
    # instructions ask for (the corner nearest to the camera).
    trusted = [
        int(c)
        for c, w in zip(prob.corners, prob.weights, strict=True)
        if w >= settings.outlier_weight
    ]
    chosen_corners = sorted(set(trusted or [int(c) for c in prob.corners]))
    corner_xyz = np.array([_corner_points(size, prob.ws_common, c)[0] for c in chosen_corners])
    out_corner = chosen_corners[int(np.argmin(np.linalg.norm(corner_xyz - C, axis=1)))]
    M, origin, ws_out = _frame_at_corner(size, prob.ws_common, out_corner)
    size_sigma = 0.0 if _size_given(scene) else settings.size_sigma_rel
    props = _box_proportions(
        prob, Camera.from_center(f, pp, R, C), size, size_sigma, settings.outlier_weight
    )
    R, C = R @ M, M.T @ (C - origin)
    camera = Camera.from_center(f, pp, R, C)
    corner_names = [_CORNER_NAMES[_relabel_corner(int(c), out_corner)] for c in prob.corners]
    # Uncertainty from the Gauss-Newton covariance, scaled by the residual variance, with
    # the principal point's own uncertainty where it was held at the image centre.
    sigma_pp_assumed = (
        settings.principal_point_sigma_rel * math.hypot(width, height)
        if pp_model is not None and pp_given is None
        else 0.0
    )
    size_rel = 0.0 if _size_given(scene) else settings.size_sigma_rel / math.sqrt(3.0)
    # A preset's length, width and height are each off by size_sigma_rel, independently; the
    # camera's distance scales with all three edges at once (the translation is solved from
    # the length, width and height ends together), so with their average: size_sigma_rel /
    # √3. (The full 5 % over-stated it: crowd position sigmas covered 88-90 % at 1 sigma,
    # median error/sigma 0.34-0.40, benchmarks/calibrate_coverage.py.)
    if props is not None and props.disagrees:
        # The clicked box is not the stated car: the answer's scale is off by up to the
        # spread of its edges' scales (half of it at one sigma; benchmarks/crowd_slips.py).
        size_rel = math.hypot(size_rel, 0.5 * props.spread)
    other_class = (
        _likely_class(props, size)
        if props is not None and size_sigma > 0.0 and not props.disagrees
        else None
    )
    if other_class is not None:
        # Another class's proportions fit the clicked box better: were it that car, the
        # answer's scale would be off by their mean log ratio (at one sigma).
        size_rel = math.hypot(size_rel, other_class[2])
    car_lines = _car_line_sensitivity(
        prob,
        np.asarray(res.x, dtype=float),
        R0,
        pp_model,
        f_fixed,
        settings.car_line_sigma_deg,
        settings.car_line_share_warn,
        settings.car_line_axes,
    )
    class_shifts = (
        _class_mixture(
            # With per-group factors the clicks' noise is the fit's measured one (as in the
            # covariance); with the pooled factor, the assumed one.
            props.with_click_scale(_measured_click_scale(prob, res))
            if settings.variance_groups
            else props,
            size,
            settings.car_class_prior,
        )
        if props is not None
        and size_sigma > 0.0
        and not props.disagrees
        and other_class is None
        and settings.car_class_prior > 0.0
        else []
    )
    cov_out = _output_covariance(
        prob,
        res,
        R0,
        pp_model,
        f_fixed,
        f,
        M,
        M.T @ (C - origin),
        sigma_pp_assumed,
        size_rel,
        car_lines.D,
        size_shape_rel=size_sigma if settings.preset_shape else 0.0,
        class_shifts=class_shifts,
        # The clicked box is not the stated car's: the clicks' misfit is the model's, and
        # every row shares it (the pooled factor), not the clicks alone.
        pooled=props is not None and (props.disagrees or other_class is not None),
    )
    sigma_c: FloatArray | None = None
    sigma_f: float | None = None
    sigma_r: FloatArray | None = None
    sigma_pp: list[float] | None = None
    if cov_out is not None:
        sd = np.sqrt(np.clip(np.diag(cov_out), 0.0, None))
        sigma_f = float(sd[0]) if f_fixed is None else None
        sigma_pp = sd[1:3].tolist() if pp_given is None else None
        sigma_r = np.degrees(sd[3:6])
        sigma_c = sd[6:9]
    weights = [float(w) for w in prob.weights]
    state = JointState(
        prob,
        np.asarray(res.x, dtype=float).copy(),
        R0,
        pp_model,
        f_fixed,
        np.asarray(prob.weights, dtype=float).copy(),
        np.asarray(M, dtype=float),
        np.asarray(origin, dtype=float),
    )
    outliers = [
        scene.annotations[i].annotator for i, w in enumerate(weights) if w < settings.outlier_weight
    ]
    r = prob.unweighted_residuals(res.x, R0, pp_model, f_fixed)
    prob.weights = np.ones(prob.n_annotators)
    n_seg = len(prob.segments)
    rms_seg = float(np.sqrt(np.mean(r[:n_seg] ** 2))) * prob.sigma_line
    rms_pt = float(np.sqrt(np.mean(r[n_seg : n_seg + 2 * len(prob.pt_pix)] ** 2))) * prob.sigma_pt
    if pp_model is None:
        method, reason = (
            "joint_fit_free_principal_point",
            (
                "principal point fitted with the focal length: freeing it improved the fit by more "
                "than the BIC penalty"
            ),
        )
    elif f_fixed is not None:
        method = "given" if pp_given is not None else "given_focal"
        reason = "focal length given in the scene; principal point " + (
            "given" if pp_given is not None else "at the image centre"
        )
    else:
        method = "joint_fit_centre_principal_point"
        reason = "focal length fitted to all vanishing lines; principal point " + (
            "given"
            if pp_given is not None
            else "at the image centre (freeing it was not justified by the data)"
        )
    result = CalibrationResult(
        camera,
        "joint_fit",
        method,
        f"{reason}; closed-form seed used {seed.intrinsics.method} ({seed.intrinsics.reason})",
        sols,
        cluster,
        weights,
        outliers,
        position_sigma_m=sigma_c,
        focal_sigma_px=sigma_f,
        rotation_sigma_deg=sigma_r,
        principal_point_sigma_px=sigma_pp,
        parameter_covariance=cov_out,
        rms_residual_px=float(math.hypot(rms_seg, rms_pt) / math.sqrt(2.0)),
        width_signs=width_signs,
        annotator_corners=corner_names,
        width_sign=ws_out,
        joint_state=state,
        photo_segments=photo_used,
        video_segments=video_used,
    )
    result.warnings.extend(prob.video_warnings)
    if len(chosen_corners) > 1:
        result.warnings.append(
            "annotators marked different corners of the car ("
            + ", ".join(
                f"{scene.annotations[i].annotator}: {n}" for i, n in enumerate(corner_names)
            )
            + "); the world origin is the corner nearest to the camera, as the instructions ask"
        )
    for axis in car_lines.axes_on_car(settings.car_line_share_warn):
        result.warnings.append(_car_line_warning(axis, car_lines, settings.car_line_sigma_deg))
    result.warnings += _segments_off(scene, prob, r[:n_seg])
    if props is not None:
        result.object_proportions = props.to_dict([a.annotator for a in scene.annotations])
        if props.disagrees:
            result.warnings.append(_proportion_warning(props, size))
        if other_class is not None:
            result.warnings.append(_class_warning(props, size, other_class, scene.object.preset))
        for slot, axis, ratio in props.odd:
            result.warnings.append(
                f"annotator {scene.annotations[slot].annotator!r} (annotations[{slot}]): their "
                f"{axis} edge is {ratio:.2f}x the other annotators' (measured through the "
                "fitted camera): a click at another car's roof or edge end, or the ground "
                "corners at the tyre contacts?"
            )
    lo, hi = prob.f_bounds
    if f_fixed is None and not lo * 1.001 < f < hi / 1.001:
        result.warnings.append(
            f"focal length {f:.0f} px is at the limit of the fit's range ({lo:.0f}-{hi:.0f} px): "
            "the lines do not determine it and the position is unreliable; give camera.focal_px"
        )
    return result


PROPORTION_CHI2 = 5.99  # chi-square(2) at p = 0.05: the clicked box's proportions disagree ...
PROPORTION_SPREAD = 0.2  # ... and its edges' scales spread by more than this (natural log)
PROPORTION_ODD_LOG = 0.25  # one annotator's edge this far (log) from the others' ...
PROPORTION_ODD_Z = 5.0  # ... and this many of its clicks' sigmas: named


@dataclass(frozen=True)
class _Proportions:
    """The clicked car's edges against the stated size (:func:`_box_proportions`)."""

    scale: dict[str, float]  # per axis: the clicked edge's length / the stated one (median)
    chi2: float  # of the three log scales' disagreement, 2 degrees of freedom
    spread: float  # largest minus smallest log scale
    n_annotators: int
    # (slot, axis, ratio): an annotator whose edge is ``ratio`` x the others' (median)
    odd: tuple[tuple[int, str, float], ...] = ()
    # per axis: the median log scale and its variance (the clicks' and the preset's)
    log_scale: tuple[float, float, float] = (0.0, 0.0, 0.0)
    log_var: tuple[float, float, float] = (1.0, 1.0, 1.0)
    # per axis: the clicks' share of log_var (the rest is the preset's)
    click_var: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def with_click_scale(self, k: float) -> _Proportions:
        """These proportions with the clicks' noise ``k`` times as large (their share of
        ``log_var`` times ``k²``; the chi-square and its verdicts are not recomputed)."""
        var = tuple(
            float(v + (k * k - 1.0) * c) for v, c in zip(self.log_var, self.click_var, strict=True)
        )
        return replace(self, log_var=var)  # type: ignore[arg-type]

    def class_fit(self, stated: ObjectSize, other: ObjectSize) -> float:
        """How much better ``other``'s proportions fit the clicked box than ``stated``'s:
        the drop of the chi-square (2 degrees of freedom, the common scale free)."""
        return float(self.class_fits(stated, [other])[0])

    def class_fits(self, stated: ObjectSize, others: list[ObjectSize]) -> FloatArray:
        """:meth:`class_fit` of each of ``others`` at once, ``(len(others),)``."""
        med = np.asarray(self.log_scale)
        w = 1.0 / np.asarray(self.log_var)
        dims = np.array([[o.length_m, o.width_m, o.height_m] for o in others], dtype=float)
        shift = np.log(dims / np.array([stated.length_m, stated.width_m, stated.height_m]))
        v = med[None, :] - shift
        mean = np.sum(w * v, axis=1) / np.sum(w)
        chi2_others = np.sum(w * (v - mean[:, None]) ** 2, axis=1)
        mean0 = float(np.sum(w * med) / np.sum(w))
        chi2_stated = float(np.sum(w * (med - mean0) ** 2))
        return np.asarray(chi2_stated - chi2_others, dtype=np.float64)

    @property
    def disagrees(self) -> bool:
        """True when the proportions are off beyond the clicks' and the preset's noise."""
        return self.chi2 > PROPORTION_CHI2 and self.spread > PROPORTION_SPREAD

    def to_dict(self, names: list[str]) -> dict[str, Any]:
        """JSON-ready: the scales, the test and its verdict (``names``: the annotators')."""
        return {
            "scale": {k: round(v, 4) for k, v in self.scale.items()},
            "chi2": round(self.chi2, 2),
            "spread_log": round(self.spread, 4),
            "annotators": self.n_annotators,
            "disagrees": self.disagrees,
            "odd_annotators": [
                {"annotator": names[slot], "axis": axis, "ratio": round(ratio, 3)}
                for slot, axis, ratio in self.odd
            ],
        }


def _box_proportions(
    prob: _JointProblem,
    camera: Camera,
    size: ObjectSize,
    size_sigma_rel: float,
    weight_min: float,
) -> _Proportions | None:
    """How long the trusted annotators' clicked edges are, in the fitted camera, vs ``size``.

    The fit holds the car at the stated size, so its scale is a compromise of the three
    edges; their lengths measured back through the fitted camera (the length and width
    ends cast onto the ground, the height end onto the vertical above the clicked corner)
    are proportional to the clicked box. A car of another class than the preset (a van
    called a sedan: its roof 1.6x higher, its length 1.15x), or ground corners clicked at
    the tyre contacts instead of the ground under the body's corners (the length edge
    ~1.5 m short), gives proportions the preset does not have; the scale of the whole
    answer (the camera's distance) is then off by up to their spread, with no residual to
    show it. Each axis' log scale (median over the annotators) has the clicks' noise
    (each click moved by ``sigma_pt`` in turn, through the camera: a ground edge seen end-on
    is long in metres for a few pixels; x1.25/sqrt(n) for the median) and the preset's
    ``size_sigma_rel``; their weighted disagreement is the chi-square. With three or more
    annotators, one whose edge differs from the others' median by more than
    ``PROPORTION_ODD_LOG`` and ``PROPORTION_ODD_Z`` sigmas of both is listed in ``odd``.
    None when no trusted annotator's clicks can be measured.
    """
    clicks = prob.pt_pix.reshape(-1, 4, 2)
    stated = np.array([size.length_m, size.width_m, size.height_m])
    # Each annotator's four clicks and, to carry their noise through the camera, the same
    # clicks with one coordinate moved by a click's sigma (8 more sets).
    steps = np.zeros((9, 4, 2))
    steps[1:].reshape(8, 8)[np.arange(8), np.arange(8)] = prob.sigma_pt
    # Every trusted annotator's 9 sets measured in one batch; an annotator any of whose
    # sets cannot be measured is left out.
    trusted = [slot for slot in range(prob.n_annotators) if prob.weights[slot] >= weight_min]
    if not trusted:
        return None
    sets = (clicks[trusted][:, None, :, :] + steps[None]).reshape(-1, 4, 2)
    measured, valid = _clicked_boxes(camera, sets)
    valid = np.all(valid.reshape(len(trusted), 9), axis=1)
    if not np.any(valid):
        return None
    slots = [slot for slot, ok in zip(trusted, valid.tolist(), strict=True) if ok]
    log_all = np.log(measured.reshape(len(trusted), 9, 3)[valid] / stated)
    log_arr = log_all[:, 0]
    sd_arr = np.sqrt(np.sum((log_all[:, 1:] - log_all[:, :1]) ** 2, axis=1))
    n = len(slots)
    med = _median_rows(log_arr)
    click_rel = _median_rows(sd_arr)
    click_var = (1.25 * click_rel) ** 2 / n
    var = click_var + size_sigma_rel**2
    w = 1.0 / var
    mean = float(np.sum(w * med) / np.sum(w))
    chi2 = float(np.sum(w * (med - mean) ** 2))
    scale = {axis: float(math.exp(v)) for axis, v in zip(AXES, med, strict=True)}
    odd: list[tuple[int, str, float]] = []
    if n >= 3:
        # One annotator's edge against the others' (the same car: no size term), in the
        # noise of both medians' clicks: a height click at another car's roof, one
        # annotator's corners at the tyre contacts.
        # All annotators at once: row k of ``others`` is the median without annotator k.
        without = np.array([[i for i in range(n) if i != k] for k in range(n)])
        others = _median_rows(log_arr[without])
        dev = log_arr - others
        sd = np.sqrt(sd_arr**2 + (1.25 * click_rel) ** 2 / (n - 1))
        worst = np.argmax(np.abs(dev) / sd, axis=1)
        for k, j in enumerate(worst.tolist()):
            d_kj, sd_kj = float(dev[k, j]), float(sd[k, j])
            if abs(d_kj) > PROPORTION_ODD_LOG and abs(d_kj) > PROPORTION_ODD_Z * sd_kj:
                odd.append((slots[k], AXES[j], math.exp(d_kj)))
    return _Proportions(
        scale,
        chi2,
        float(np.ptp(med)),
        n,
        tuple(odd),
        (float(med[0]), float(med[1]), float(med[2])),
        (float(var[0]), float(var[1]), float(var[2])),
        (float(click_var[0]), float(click_var[1]), float(click_var[2])),
    )


def _median_rows(values: FloatArray) -> FloatArray:
    """``np.median(values, axis=-2)`` of finite values, by one sort (no NaN check, no
    partition: ~5x faster on the few rows of :func:`_box_proportions`; the same numbers,
    the middle pair's mean taken as ``np.median`` takes it)."""
    rows = np.sort(values, axis=-2)
    m = rows.shape[-2]
    if m % 2:
        return np.asarray(rows[..., m // 2, :], dtype=np.float64)
    return np.asarray((rows[..., m // 2 - 1, :] + rows[..., m // 2, :]) / 2.0, dtype=np.float64)


def _clicked_boxes(camera: Camera, clicks: FloatArray) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """Length, width and height ``(m, 3)`` of ``m`` sets of an annotator's four clicks.

    The origin, length and width ends cast onto the ground; the height end's ray met with
    the vertical above the cast origin (closest points, as
    :meth:`~camloc_geo.camera.Camera.point_on_vertical`). Also ``(m,)`` whether each set
    is measured: False where a click does not reach the ground in front of the camera or an
    edge measures zero (that set's row is then meaningless). All sets in one batch (every
    annotator's at once, :func:`_box_proportions`).
    """
    m = len(clicks)
    with np.errstate(all="ignore"):  # the unmeasured sets' rows: NaN, never read
        ground = camera.ground_from_pixels(clicks[:, :3].reshape(-1, 2)).reshape(m, 3, 3)
        valid = np.all(np.isfinite(ground.reshape(m, 9)), axis=1)
        length = np.abs(ground[:, 1, 0] - ground[:, 0, 0])
        width = np.abs(ground[:, 2, 1] - ground[:, 0, 1])
        c = camera.center_in_world
        d = camera.rays_in_world(clicks[:, 3]).reshape(m, 3)
        w0 = c[None, :] - ground[:, 0]  # the ray c + s d against the vertical g + t z
        a = np.sum(d * d, axis=1)
        b = d[:, 2]
        denom = a - b**2
        valid &= denom > 1e-12
        top = (a * w0[:, 2] - b * np.sum(d * w0, axis=1)) / denom
        out = np.column_stack([length, width, top])
        valid &= np.all(np.isfinite(out) & (out > 0.0), axis=1)
    return np.asarray(out, dtype=np.float64), valid


CLASS_DELTA_CHI2 = 2.5  # another preset fits the clicked proportions this much better


def _preset_dims() -> FloatArray:
    """Length, width and height of every car preset, ``(len(PRESETS), 3)`` in its order."""
    return np.array([[o.length_m, o.width_m, o.height_m] for o in PRESETS.values()], dtype=float)


def _likely_class(props: _Proportions, size: ObjectSize) -> tuple[str, ObjectSize, float] | None:
    """The car preset whose proportions fit the clicked box clearly better than ``size``'s.

    A car of a neighbouring class (an SUV called a sedan: height x1.17, length x1.02, width
    x1.04) has proportions within a few of the preset's own 5 % sigmas, so the proportion
    test (:attr:`_Proportions.disagrees`) does not see it, yet every annotator clicks the
    same taller box and the answer's scale is off by the classes' mean ratio, which no
    jackknife sees. Each other preset of :data:`~camloc_geo.objects.PRESETS` is compared by
    its chi-square drop
    (:meth:`_Proportions.class_fit`, the common scale free); the best one whose drop exceeds
    ``CLASS_DELTA_CHI2`` (2.5: a likelihood ratio of e^1.25, the other class's proportions
    ~3.5x as likely as the stated one's) is returned as (name, size, the mean absolute log
    ratio of its edges to the stated ones). None: the stated class fits as well as any.
    The threshold trades the clean crowd's false alarms against the slips caught
    (``benchmarks/README.md``, crowd_slips: 2.0, 2.5, 3.0, 4.0 warn on 7, 4, 3.5, 2 % of
    clean crowd scenes). Not used where the proportions already disagree (their own
    warning and widening) or the size is stated in numbers.
    """
    stated = np.array([size.length_m, size.width_m, size.height_m])
    names = list(PRESETS)
    others = [PRESETS[name] for name in names]
    dims = np.array([[o.length_m, o.width_m, o.height_m] for o in others], dtype=float)
    shifts = np.log(dims / stated)  # every preset at once
    drops = props.class_fits(size, others).tolist()
    best: tuple[float, str, ObjectSize, float] | None = None
    for k, (name, other) in enumerate(zip(names, others, strict=True)):
        shift = shifts[k]
        if not np.any(shift):  # the stated size itself
            continue
        drop = drops[k]
        if drop > CLASS_DELTA_CHI2 and (best is None or drop > best[0]):
            best = (drop, name, other, abs(float(np.mean(shift))))
    if best is None:
        return None
    return best[1], best[2], best[3]


def _class_mixture(
    props: _Proportions, size: ObjectSize, prior: float
) -> list[tuple[float, FloatArray]]:
    """The car classes the clicked box may be, short of a warning: ``[(π, s), ...]``.

    :func:`_likely_class` names another preset only where its proportions fit clearly
    better (``CLASS_DELTA_CHI2``); an SUV whose clicked box looks like a sedan's within the
    clicks' noise is then called a sedan with the sedan's sigmas, and its height's 17 %
    moves the focal length and the distance (``benchmarks/crowd_slips.py`` ``roof_suv``:
    focal 5-37 % low, camera height 1.2-2.2 m off) by more than the preset's own 5 % per
    dimension covers. Each other preset whose proportions fit the clicked box better than
    the stated one's (a chi-square drop above 0, :meth:`_Proportions.class_fits`) gets its
    posterior weight: the prior odds ``prior`` (per preset, that the stated one is that
    class instead) times the likelihood ratio of its proportions, ``exp(drop / 2)``,
    normalised with the stated class's 1 (the sum over every other preset); ``s`` is its
    log size ratio per dimension (length, width, height). The stated sigmas then hold
    those classes' share of the mixture's second moment about the answer
    (:func:`_output_covariance`). A class the clicks do not favour adds nothing: with the
    whole prior mixture a noise-free sedan's position sigma grew 1.5-3x (a pickup's 20-30 %
    at 1-3 % weight) where its clicks show nothing of another class. Presets whose weight
    is below 1e-3 are left out too.
    """
    stated = np.array([size.length_m, size.width_m, size.height_m])
    # Every preset against the stated size in one isclose (np.allclose row by row: the same
    # test without its per-call overhead, ~15 us a preset).
    presets = list(PRESETS.values())
    same = np.all(np.isclose(_preset_dims(), stated), axis=1).tolist()
    others = [o for o, s in zip(presets, same, strict=True) if not s]
    if not others or prior <= 0.0:
        return []
    drops = np.clip(props.class_fits(size, others), -60.0, 60.0)
    odds = prior * np.exp(0.5 * drops)
    weights = odds / (1.0 + float(np.sum(odds)))
    out = []
    for o, weight, drop in zip(others, weights.tolist(), drops.tolist(), strict=True):
        if weight >= 1e-3 and drop > 0.0:  # only a class the clicks favour over the stated
            shift = np.log(np.array([o.length_m, o.width_m, o.height_m]) / stated)
            out.append((float(weight), shift))
    return out


def _class_warning(
    props: _Proportions,
    size: ObjectSize,
    other_class: tuple[str, ObjectSize, float],
    preset: str | None,
) -> str:
    """The warning naming the car class whose proportions fit the clicked box better."""
    name, other, shift = other_class
    parts = ", ".join(f"{axis} x{props.scale[axis]:.2f}" for axis in AXES)
    stated = f"the stated {preset}'s" if preset else "the stated size's"
    return (
        f"object: the clicked car's proportions ({parts} of {size.length_m:.2f} x "
        f"{size.width_m:.2f} x {size.height_m:.2f} m) fit a {name}'s ({other.length_m:.2f} x "
        f"{other.width_m:.2f} x {other.height_m:.2f} m) better than {stated}: is the car a "
        f"{name}? The camera's distance is uncertain by their difference ({100.0 * shift:.0f} "
        "%, included in the position sigmas); check object.preset"
    )


def _proportion_warning(props: _Proportions, size: ObjectSize) -> str:
    """The warning for a clicked box whose proportions are not the stated size's."""
    parts = ", ".join(f"{axis} x{props.scale[axis]:.2f}" for axis in AXES)
    return (
        f"object: the clicked car's edges do not have the stated size's proportions ({parts} "
        f"of {size.length_m:.2f} x {size.width_m:.2f} x {size.height_m:.2f} m): a car of another "
        "class than the preset (a van or an SUV called a sedan), or ground corners clicked at "
        "the tyre contacts instead of the ground under the body's corners (docs/annotate.md)? "
        f"The camera's distance is uncertain by their spread ({100.0 * props.spread:.0f} %, "
        "included in the position sigmas); check object.preset and the corner clicks"
    )


SEGMENT_OFF_SIGMA = 7.0  # an annotator's segment this many line sigmas off the fit: named
SEGMENT_OFF_MAX = 3  # ... at most this many warnings


def _segments_off(scene: Scene, prob: _JointProblem, r_seg: FloatArray) -> list[str]:
    """Warnings naming annotators' segments far off the final fit's vanishing point.

    A line drawn along something not parallel to the car's axis (a kerb's curve, a roof's
    slope, a stop line at an angle), 5-15 degrees off, is often kept by the line screen (its
    miss of the consensus point is within 1 % of the diagonal) and only down-weighted by the
    fit; its residual in the final fit is then ``SEGMENT_OFF_SIGMA`` line sigmas or more, which
    no clean crowd scene reached (99th percentile of the largest: 5.3; 150 scenes), and it
    belonged to the slipped annotator in every scene where it was
    (``benchmarks/crowd_slips.py``, ``nonparallel_line``). Named with the segment's pixels,
    the largest first.
    """
    off = np.flatnonzero(np.abs(r_seg) > SEGMENT_OFF_SIGMA)
    out = []
    for j in off[np.argsort(-np.abs(r_seg[off]))][:SEGMENT_OFF_MAX]:
        slot, axis = int(prob.seg_ann[j]), AXES[int(prob.seg_axis[j])]
        seg = ", ".join(str(round(float(v))) for v in prob.segments[j])
        out.append(
            f"annotator {scene.annotations[slot].annotator!r} (annotations[{slot}]): the "
            f"vp_lines.{axis} segment [{seg}] is {abs(float(r_seg[j])):.1f} line sigmas off the "
            f"fit's {axis} vanishing point: is it parallel to the car's {axis} (not a kerb's "
            "curve, a roof's slope, a line at an angle)?"
        )
    return out


def _car_line_warning(axis: str, car_lines: _CarLines, sigma_deg: float) -> str:
    """The warning for an axis whose lines rest on one face of the car."""
    share = car_lines.share.get(axis, 1.0)
    included = (
        f"the stated sigmas include a {sigma_deg:g} degree turn of them"
        if sigma_deg > 0.0
        else "the stated sigmas do not include it"
    )
    return (
        f"vp_lines.{axis}: the {axis} direction rests on the car's own edges "
        f"({car_lines.n_car.get(axis, 0)} of {car_lines.n_all.get(axis, 0)} lines; its "
        f"{car_lines.face.get(axis, 'body')} carries {100.0 * share:.0f} %): a rounded body's "
        f"edges are curved silhouettes that bias that direction and the focal length, all "
        f"the same way ({included}); draw {CAR_LINE_HINTS[axis]}"
    )


def _without_pp_prior(prob: _JointProblem, res: Any, R0: FloatArray, f_fixed: float | None) -> Any:
    """The freed principal point's fit with its prior weighed against the data's own noise.

    The fit weighs the residuals by the noise model (``sigma_point_rel``,
    ``sigma_line_rel``) and the prior (``principal_point_prior_sigma_rel``) in pixels. Where
    the lines fit far better than the noise model (residual variance factor ``s² < 1``),
    the posterior weighs the data by ``1/s²``: the same as widening the prior's sigma by
    ``1/s``. Without that the prior held a freed principal point 2-12 px from the truth on
    noise-free scenes at a stated 0.3-1.6 px (``benchmarks/calibrate_coverage.py``), as
    the covariance ``(JᵀJ)⁻¹ s²`` shrank the prior's information with the data's. A few
    refits until ``s²`` settles; the widened prior stays in ``prob`` (the covariance and the
    jackknife see the same model). Noisier data (``s² ≥ 1``) keep the prior as it is.
    """
    base = prob.pp_prior_sigma
    if base <= 0.0:
        return res
    n_x = len(res.x)
    for _ in range(4):
        r = np.asarray(res.fun, dtype=float)[:-2]  # the prior's two rows come last
        if len(prob.photo_segments):  # the annotations' variance alone (as the covariance)
            r = r[: len(prob.segments) + 2 * len(prob.pt_pix)]
        s2 = float(np.sum(r**2)) / max(len(r) - n_x, 1)
        widened = base / math.sqrt(min(max(s2, 1e-10), 1.0))
        if widened <= prob.pp_prior_sigma * 1.1:
            break
        saved = prob.pp_prior_sigma
        prob.pp_prior_sigma = widened
        refit = _fit(prob, np.asarray(res.x, dtype=float), R0, None, f_fixed)
        if not (refit.success and np.all(np.isfinite(refit.x))):
            prob.pp_prior_sigma = saved
            break
        res = refit
    return res


def _pinned_pp_sensitivity(
    prob: _JointProblem,
    x: FloatArray,
    R0: FloatArray,
    pp: tuple[float, float],
    f_fixed: float | None,
) -> FloatArray | None:
    """How the fitted parameters move with a pinned principal point: ``S`` ``(len(x), 2)``.

    The fit holds the principal point at ``pp``; were it really ``pp + δ``, the fitted
    parameters ``θ`` would move by ``S δ`` with ``S = −H_θθ⁻¹ H_θp`` (the robust
    Gauss-Newton Hessian of the model with the principal point free, at the solution). With
    ``δ ~ N(0, σ² I)`` the added covariance is ``σ² S Sᵀ`` (a "consider" covariance) and
    ``cov(θ, δ) = σ² S``. None when the Hessian is singular.
    """
    k = int(f_fixed is None)
    x1 = _with_pp(x, k, pp)
    r, J = prob.residuals_and_jacobian(x1, R0, None, f_fixed)
    if prob.pp_prior_sigma > 0.0:
        # the data's information alone (the prior's two rows come last); the prior is σ here
        r, J = r[:-2], J[:-2]
    w = 1.0 / np.sqrt(1.0 + (r / _F_SCALE) ** 2)
    H = J.T @ (J * w[:, None])
    pp_idx = [k, k + 1]
    rest = [i for i in range(len(x1)) if i not in pp_idx]
    try:
        S = -np.linalg.solve(H[np.ix_(rest, rest)], H[np.ix_(rest, pp_idx)])
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(S)):
        return None
    return np.asarray(S, dtype=np.float64)


def _output_covariance(
    prob: _JointProblem,
    res: Any,
    R0: FloatArray,
    pp_model: tuple[float, float] | None,
    f_fixed: float | None,
    f: float,
    M: FloatArray,
    c_out: FloatArray,
    sigma_pp_px: float,
    size_rel: float,
    car_lines: FloatArray | None = None,
    size_shape_rel: float = 0.0,
    class_shifts: list[tuple[float, FloatArray]] | None = None,
    pooled: bool = False,
) -> FloatArray | None:
    """Joint covariance ``(9, 9)`` of the answer, see ``CalibrationResult.parameter_covariance``.

    The Gauss-Newton covariance of the fitted parameters (scaled by the residual variance);
    where the principal point was held at ``pp_model`` with an assumed spread
    ``sigma_pp_px``, its consider covariance (:func:`_pinned_pp_sensitivity`) and its
    correlation with the rest; a preset's size error (``size_rel`` of the distance, along
    the camera's position vector ``c_out``); the ground-corner and the car lines' consider
    columns (``car_lines``, :func:`_car_line_sensitivity`); the car-class mixture
    (``class_shifts``, :func:`_class_mixture`: per other preset its posterior weight ``π``
    and log size ratio ``s``, adding ``π m mᵀ`` with ``m`` the answer's move were the car
    that preset: the shape sensitivity's columns, the centre's rows included, times
    ``s / size_shape_rel``; without them, ``preset_shape`` off, the distance times the
    mean of ``s``). Order: focal length (px),
    principal point x, y (px), small rotation about the camera's x, y, z axes (rad, on the left of
    ``cam_from_world_rotation``), camera centre x, y, z (m, output frame). None when the
    normal equations are singular.
    """
    J = res.jac
    x = np.asarray(res.x, dtype=float)
    try:
        cov = _fit_covariance(
            prob, np.asarray(res.fun, dtype=float), J, _jtj_inverse(prob, J), pooled=pooled
        )
    except np.linalg.LinAlgError:
        return None
    # Positions of x's entries in z = (log f, pp x, pp y, ω, C).
    z_of_x = ([0] if f_fixed is None else []) + ([1, 2] if pp_model is None else [])
    z_of_x += [3, 4, 5, 6, 7, 8]
    A = np.zeros((9, 9))
    block = np.ix_(z_of_x, z_of_x)
    A[block] = cov
    D = _ground_corner_sensitivity(prob, x, R0, pp_model, f_fixed)
    if D is not None:
        A[block] += D @ D.T
    D_full = _size_shape_sensitivity(
        prob, x, R0, pp_model, f_fixed, size_shape_rel, centre=bool(class_shifts)
    )
    D_size = None
    if D_full is not None:
        D_size = D_full.copy()
        D_size[-3:] = 0.0  # the centre: size_rel's term
        A[block] += D_size @ D_size.T
        for weight, shift in class_shifts or []:
            # The whole answer's move were the car that preset, the centre's included.
            move = D_full @ (np.asarray(shift, dtype=float) / size_shape_rel)
            A[block] += weight * np.outer(move, move)
    if car_lines is not None:
        A[block] += car_lines @ car_lines.T
    if pp_model is not None and sigma_pp_px > 0.0:
        S = _pinned_pp_sensitivity(prob, x, R0, pp_model, f_fixed)
        if S is not None:
            s2_pp = sigma_pp_px**2
            A[block] += s2_pp * (S @ S.T)
            A[np.ix_(z_of_x, [1, 2])] = s2_pp * S
            A[np.ix_([1, 2], z_of_x)] = s2_pp * S.T
            A[1, 1] = A[2, 2] = s2_pp
    # The rotation vector ω of R = exp(ω)·R0: a change dω turns R by J_l(ω)·dω on the left
    # (camera axes); the frame change R·M keeps left perturbations, C_out = Mᵀ (C - origin).
    T = np.zeros((9, 9))
    T[0, 0] = f
    T[1, 1] = T[2, 2] = 1.0
    T[3:6, 3:6] = _so3_left_jacobian(x[-6:-3])
    T[6:9, 6:9] = M.T
    out = T @ A @ T.T
    if size_rel > 0.0:
        out[6:9, 6:9] += size_rel**2 * np.outer(c_out, c_out)
    for weight, shift in class_shifts or [] if D_full is None else []:
        # Without the shape columns (``preset_shape`` off): the distance by the mean ratio.
        out[6:9, 6:9] += weight * float(np.mean(shift)) ** 2 * np.outer(c_out, c_out)
    out = 0.5 * (out + out.T)
    if not np.all(np.isfinite(out)):
        return None
    return np.asarray(out, dtype=np.float64)


_VARIANCE_GROUP_MIN_REDUNDANCY = 3.0  # a group's own factor needs this much redundancy


def _fit_covariance(
    prob: _JointProblem, fun: FloatArray, J: FloatArray, inv: FloatArray, *, pooled: bool = False
) -> FloatArray:
    """The fit's own covariance of its parameters, the residuals' variance measured on them.

    ``inv`` is ``(JᵀJ)⁻¹`` of the robustly weighted Jacobian ``J`` at the solution, ``fun``
    its residuals (segments, clicks u, clicks v, the photo's or video's segments, priors).
    One residual variance factor ``s²`` for every row (``prob.variance_groups`` off: the
    covariance before stop 39) scales the lines by the clicks' misfit: the assumed noise
    (``sigma_line_rel``, ``sigma_point_rel``) is not in the crowd's proportions (crowd
    scenes: the segments' mean square 0.19 of their assumed sigma², the car's corner clicks'
    0.51, the edge ends' 0.27, the pooled factor 0.34), so the focal length, which the
    lines decide, had a sigma ~1.3x too wide. With ``variance_groups`` each group (the
    segments, the corner clicks, the edge-end clicks) gets its own factor, its soft-L1
    squares over its redundancy ``Σ (1 - h_ii)`` (the hat matrix' diagonal), where that
    redundancy is at least ``_VARIANCE_GROUP_MIN_REDUNDANCY`` (else the pooled one); the
    photo's and video's segments take the segments' factor, the priors the pooled one (as
    before). The estimator is the fit's as it is (its weights unchanged), so the
    covariance is the sandwich ``inv Jᵀ diag(s²) J inv``; equal factors give ``s² inv``.
    """
    if pooled or not prob.variance_groups:
        return np.asarray(inv * _variance_factors(prob, fun, J, inv, pooled=True), dtype=np.float64)
    s2_row = _variance_factors(prob, fun, J, inv)
    if np.all(s2_row == s2_row[0]):  # every row pooled (a group without its own factor)
        return np.asarray(inv * s2_row[0], dtype=np.float64)
    meat = J.T @ (J * s2_row[:, None])
    return np.asarray(inv @ meat @ inv, dtype=np.float64)


def _variance_factors(
    prob: _JointProblem, fun: FloatArray, J: FloatArray, inv: FloatArray, *, pooled: bool = False
) -> Any:
    """The residual variance factor of each row of the fit (:func:`_fit_covariance`).

    ``pooled``: the one factor ``s²`` of every row (a float: the soft-L1 squares of the
    annotations' and priors' rows over their redundancy); else ``(len(fun),)``, one factor per
    row group (the segments, the corner clicks, the edge-end clicks; see
    :func:`_fit_covariance`).
    """
    n_x = inv.shape[0]
    n_seg, n_pt = len(prob.segments), len(prob.pt_pix)
    n_photo = len(prob.photo_segments)
    n_rows = len(fun)
    start = n_seg + 2 * n_pt
    # The residual variance factor of the annotations (and priors) alone: the photo's
    # segments join at a deliberately wide sigma, and their small residuals would shrink it.
    keep = np.ones(n_rows, dtype=bool)
    keep[start : start + n_photo] = False
    dof = max(int(keep.sum()) - n_x, 1)
    s2 = max(2.0 * soft_l1_cost(fun[keep], _F_SCALE) / dof, 1e-12)
    if pooled:
        return s2
    group = np.full(n_rows, -1)  # the priors: the pooled factor
    group[:n_seg] = 0
    corner = np.arange(n_pt) % 4 == 0  # each annotator's ground corner, then the edge ends
    group[n_seg : n_seg + n_pt] = np.where(corner, 1, 2)
    group[n_seg + n_pt : start] = np.where(corner, 1, 2)
    c2 = _F_SCALE**2
    rho2 = 2.0 * c2 * (np.sqrt(1.0 + fun * fun / c2) - 1.0)  # 2 ρ per row: r² when small
    h = np.einsum("ij,jk,ik->i", J, inv, J)
    s2_row = np.full(n_rows, s2)
    own = []
    for g in (0, 1, 2):
        rows = group == g
        redundancy = float(np.sum(1.0 - h[rows]))
        own.append((rows, redundancy, float(np.sum(rho2[rows]))))
    if all(red >= _VARIANCE_GROUP_MIN_REDUNDANCY for _rows, red, _sq in own):
        for rows, red, sq in own:
            s2_row[rows] = max(sq / red, 1e-12)
    else:
        return np.full(n_rows, s2)
    s2_row[start : start + n_photo] = s2_row[0] if n_seg else s2
    return s2_row


def _measured_click_scale(prob: _JointProblem, res: Any) -> float:
    """A click's sigma as the fit's residuals measure it, in the assumed one's: the square
    root of the corner clicks' residual variance factor (:func:`_variance_factors`)."""
    J = res.jac
    try:
        inv = _jtj_inverse(prob, J)
    except np.linalg.LinAlgError:
        return 1.0
    s2_row = _variance_factors(prob, np.asarray(res.fun, dtype=float), J, inv)
    return math.sqrt(float(s2_row[len(prob.segments)]))  # the first corner click's row


def _size_given(scene: Scene) -> bool:
    o = scene.object
    return o.length_m is not None and o.width_m is not None and o.height_m is not None
