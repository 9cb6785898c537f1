"""The typed values of absolute localisation: settings, observations, matches, flags, results."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from camloc_geo._ties import TIE_DISTANCE_M, TIE_SCORE_RATIO
from camloc_geo.absolute._similarity import Similarity2D
from camloc_geo.camera import Camera
from camloc_geo.geodesy import LocalFrame
from camloc_geo.relative import CalibrationResult

if TYPE_CHECKING:
    from camloc_geo.osm import Intersection

__all__ = [
    "TIE_DISTANCE_M",
    "TIE_SCORE_RATIO",
    "Candidate",
    "Flag",
    "FlagKind",
    "LocateResult",
    "LocateSettings",
    "Match",
    "Observation",
    "Tie",
]

FloatArray = npt.NDArray[np.float64]
EvidenceKind = Literal["reference", "corner", "landmark"]


@dataclass(frozen=True)
class LocateSettings:
    """Noise model and ranking knobs of :func:`locate` (defaults are what the benchmark runs).

    Attributes
    ----------
    sigma_pixel_rel
        Click noise of a ground pixel, fraction of the image diagonal (0.15 %: 3.3 px at 1080p).
    scale_sigma_rel
        Relative error of the world frame's scale (the car's true size vs its preset).
    sigma_reference_m, sigma_corner_m, sigma_landmark_corner_m, sigma_face_midpoint_m
        Map-side uncertainty of each kind of point, metres (kerb corners modelled from
        centre lines and widths are off by a metre or two).
    non_consecutive_prior
        Prior weight of assigning visible corners to non-consecutive map corners.
    merge_distance_m, merge_heading_deg
        Candidates closer than this (and with headings this close) are merged.
    max_candidates
        At most this many candidates are returned (the rest's score is dropped, the
        remaining scores renormalised).
    refine_top
        How many leading candidates get the full nonlinear refinement.
    bearing_sigma_deg
        Spread of the car's heading around a street's bearing (the car-parallel-to-street
        prior); ``parallel_floor`` is the prior weight of a car not parallel to any street.
    view_cone_range_m
        How far the ``view_cone`` features of the candidate GeoJSON reach, metres.
    fit_gate
        A candidate whose matched points' mean squared Mahalanobis misfit exceeds this is
        flagged ``poor_fit``; when every candidate is, none is returned (the evidence fits
        no hypothesis). 16: four standard deviations RMS (the noise model is generous: on
        the benchmark the right candidate's mean stays below 10).
    prior_gate_radii
        Hypotheses farther than this many ``prior.radius_m`` from the prior are dropped;
        when all are, none is returned (the evidence contradicts the prior).
    bundle_adjust
        Re-fit the leading candidates' cameras to the annotations and their matched map
        points together (:mod:`camloc_geo.absolute._bundle`); their rank and score stay.
    tie_score_ratio, tie_distance_m
        Candidates tie (``ambiguous_with``) when the weaker scores at least
        ``tie_score_ratio`` of the stronger (:data:`TIE_SCORE_RATIO`) and
        they stand more than ``tie_distance_m`` apart (closer ones are one answer at the
        accuracy the tool aims at: 10 m).
    """

    sigma_pixel_rel: float = 0.0015
    scale_sigma_rel: float = 0.05
    sigma_reference_m: float = 1.0
    sigma_corner_m: float = 1.5
    sigma_landmark_corner_m: float = 2.0
    sigma_face_midpoint_m: float = 4.0
    non_consecutive_prior: float = 0.25
    merge_distance_m: float = 2.0
    merge_heading_deg: float = 15.0
    max_candidates: int = 32
    refine_top: int = 3
    bearing_sigma_deg: float = 10.0
    parallel_floor: float = 0.15
    inside_building_factor: float = 0.15
    occluded_corner_factor: float = 0.5
    street_search_m: float = 25.0
    view_cone_range_m: float = 60.0
    fit_gate: float = 16.0
    prior_gate_radii: float = 3.0
    bundle_adjust: bool = True
    tie_score_ratio: float = TIE_SCORE_RATIO
    tie_distance_m: float = TIE_DISTANCE_M


@dataclass(frozen=True)
class Observation:
    """A ground pixel with its possible map positions.

    Attributes
    ----------
    kind
        ``reference``, ``corner`` or ``landmark``.
    label
        Where it came from in the scene (``references[0]``, ``intersection.corners[1]``...).
    pixel
        Image pixel.
    world_xy
        Its ground position in the world frame (from the relative pose).
    cov_world
        2×2 covariance of ``world_xy`` from click noise and scale error, m².
    sigma_map_m
        Map-side uncertainty, metres.
    """

    kind: EvidenceKind
    label: str
    pixel: tuple[float, float]
    world_xy: FloatArray
    cov_world: FloatArray
    sigma_map_m: float


@dataclass(frozen=True)
class Match:
    """An annotated ground pixel matched to a map point by one candidate.

    Attributes
    ----------
    kind
        ``reference``, ``corner`` or ``landmark``.
    label
        The scene's label of the pixel (``intersection.corners[1]``...).
    pixel
        The annotated pixel.
    map_en
        The matched map point in the local frame, metres.
    misfit_m
        Distance between the pixel's ground point (under the candidate) and the map point.
    mahalanobis2
        The same misfit, squared and in units of the noise model.
    map_corner, order
        For corners: the map corner's id (``<intersection>:<order>``) and its order.

    Subscripting by field name (``match["label"]``) is kept for older callers.
    """

    kind: EvidenceKind
    label: str
    pixel: tuple[float, float]
    map_en: FloatArray
    misfit_m: float
    mahalanobis2: float
    map_corner: str | None = None
    order: int | None = None

    def __getitem__(self, key: str) -> Any:
        if key not in self.as_dict():
            raise KeyError(key)
        return getattr(self, key)

    def __contains__(self, key: object) -> bool:
        return key in self.as_dict()

    def get(self, key: str, default: Any = None) -> Any:
        """Like ``dict.get``."""
        return self.as_dict().get(key, default)

    def as_dict(self) -> dict[str, Any]:
        """The match as the dict of earlier versions (``map_en`` as a list)."""
        out: dict[str, Any] = {
            "kind": self.kind,
            "label": self.label,
            "pixel": list(self.pixel),
            "map_en": np.asarray(self.map_en).tolist(),
        }
        if self.map_corner is not None:
            out["map_corner"] = self.map_corner
            out["order"] = self.order
        out["misfit_m"] = self.misfit_m
        out["mahalanobis2"] = self.mahalanobis2
        return out


class FlagKind(str, Enum):
    """What a candidate's flag says (its string form is the GeoJSON's ``flags`` entry)."""

    INSIDE_BUILDING = "inside_building"
    OCCLUDED = "occluded"
    OUTSIDE_PRIOR = "outside_prior"
    CAR_OFF_STREET = "car_off_street"
    CAR_NOT_PARALLEL_TO_STREET = "car_not_parallel_to_street"
    WORST_REFERENCE = "worst_reference"
    POOR_FIT = "poor_fit"
    UNMATCHED = "unmatched"
    CUE = "cue"
    """A tie-breaking cue's note (``cue: view_hint ...``), see :mod:`camloc_geo.absolute._cues`."""


@dataclass(frozen=True)
class Flag:
    """A candidate's flag: a kind and, for some kinds, the scene label it concerns.

    Its string form is ``kind`` or ``kind:label`` (``occluded:intersection.corners[2]``), and
    a flag compares equal to that string, so ``"poor_fit" in candidate.flags`` works.
    """

    kind: FlagKind
    label: str | None = None

    def __str__(self) -> str:
        return self.kind.value if self.label is None else f"{self.kind.value}:{self.label}"

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Flag):
            return self.kind == other.kind and self.label == other.label
        if isinstance(other, str):
            return str(self) == other
        return NotImplemented

    def __hash__(self) -> int:
        return hash(str(self))

    @classmethod
    def parse(cls, text: str) -> Flag:
        """The flag of a string form (``occluded:intersection.corners[2]``)."""
        kind, sep, label = text.partition(":")
        return cls(FlagKind(kind), label if sep else None)


@dataclass
class Candidate:
    """One candidate camera position.

    ``enu_from_world`` carries the car's world frame onto the map's local frame; ``camera``
    is the camera posed in the local frame (x east, y north, z up).
    """

    method: str
    enu_from_world: Similarity2D
    camera: Camera
    lat: float = math.nan
    lon: float = math.nan
    log_likelihood: float = 0.0
    prior: float = 1.0
    score: float = 0.0
    rank: int = 0
    residual_m: float = math.nan
    sigma_m: float | None = None
    matches: list[Match] = field(default_factory=list)
    flags: list[Flag] = field(default_factory=list)
    refined: bool = False
    merged: int = 1
    corner_assignment: tuple[int, ...] | None = None  # map corner per visible corner, -1 = none
    ambiguous_with: list[int] = field(default_factory=list)
    intersection_id: str | None = None  # the junction a corners hypothesis stands at
    log_prior_odds: float = 0.0  # the hypothesis' prior odds (an alternative reading), in
    # log_likelihood: kept when the candidate is refined and scored again
    rival: str | None = None  # what kind of rival reading it is, for the tie's words
    unrefined_log_weight: float | None = None  # a refined candidate's weight before it was
    # refined (the tie rule weighs an unrefined rival against it)
    evidence: Any = field(default=None, repr=False, compare=False)  # what it was scored on

    @property
    def theta_rad(self) -> float:
        """Rotation of ``enu_from_world``."""
        return self.enu_from_world.rotation_rad

    @property
    def translation_en(self) -> FloatArray:
        """Translation of ``enu_from_world``, metres."""
        return self.enu_from_world.translation_m

    @property
    def scale(self) -> float:
        """Scale of ``enu_from_world``."""
        return self.enu_from_world.scale

    @property
    def east_north(self) -> FloatArray:
        """Camera position in the local frame, metres."""
        return np.asarray(self.camera.center_in_world[:2], dtype=np.float64)

    @property
    def heading_deg(self) -> float:
        """Camera heading, degrees clockwise from north (grid north of the local frame).

        ``camera.angles_deg[0]`` (the same numbers), without the pitch and roll.
        """
        forward = np.asarray(self.camera.cam_from_world_rotation, dtype=float).reshape(3, 3)[2]
        if math.hypot(forward[0], forward[1]) < 1e-12:
            return 0.0  # looking straight down or up: no heading
        return math.degrees(math.atan2(forward[0], forward[1])) % 360.0


@dataclass
class Tie:
    """Candidates the evidence cannot tell apart, decided by the core's one tie rule.

    Attributes
    ----------
    ranks
        The ranks that tie with each other (a group linked by the rule), ascending.
    text
        What the tie means, one sentence (the leaders' tie gives the odds and the distance).
    why
        The explanation alone: what would decide it.
    """

    ranks: list[int]
    text: str
    why: str


@dataclass
class LocateResult:
    """Candidates, best first, and how they were found."""

    candidates: list[Candidate]
    frame: LocalFrame
    calibration: CalibrationResult
    methods_tried: list[str]
    reason: str | None = None
    intersection: Intersection | None = None
    observations: list[Observation] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    scene_id: str = "scene"
    image_size: tuple[int, int] = (0, 0)
    view_cone_range_m: float = 60.0  # LocateSettings.view_cone_range_m of the run
    cues_applied: bool = False  # the scene's cues (camloc_geo.absolute._cues) are in the scores
    ties: list[Tie] = field(default_factory=list)  # groups of tied candidates (mark_ties)
    leaders_tie: bool = False  # candidates 1 and 2 tie: the best point is not decided

    def __repr__(self) -> str:
        """One line for a notebook: the scene, candidates, the best, ties, warnings.

        (The dataclass' own repr printed every candidate, observation and the calibration:
        ~28,000 characters.)
        """
        parts = [f"scene_id={self.scene_id!r}", f"candidates={len(self.candidates)}"]
        if self.candidates:
            best = self.candidates[0]
            parts.append(f"best=(lat={best.lat:.6f}, lon={best.lon:.6f}, score={best.score:.3f})")
        elif self.reason:
            parts.append(f"reason={self.reason!r}")
        parts.append(f"methods_tried={self.methods_tried!r}")
        if self.ties:
            parts.append(f"ties={len(self.ties)}")
        if self.warnings:
            parts.append(f"warnings={len(self.warnings)}")
        return f"LocateResult({', '.join(parts)})"
