r"""Absolute localisation: where the camera stands on the map, as ranked candidates.

The relative pose (:mod:`camloc_geo.relative`) puts the camera in the car's world frame.
What remains is the 2-D similarity that carries the world frame onto a local east/north
frame (:class:`~camloc_geo.geodesy.LocalFrame`, pyproj): a rotation about the vertical, a
translation and a scale close to 1 (the car's true size is known only to about 5 %):

    p_enu = enu_from_world(p_world) = s · Rz(θ) · p_world + T

Hypotheses for ``enu_from_world`` (:class:`Similarity2D`) come from generators, one per
kind of evidence, each a ``method``:

``two_references``
    Two or more ground pixels with known lat/lon: a weighted similarity fit (scale
    regularised towards 1). With a right-handed world frame the fit is unique: the paper
    needed the left/right order of the pixels to choose between two circle intersections
    because its distance-only construction loses the handedness that the frame keeps.
    With three or more points the one that agrees least with the others (leave-one-out)
    is flagged, and the fit without it is a second hypothesis.
``one_reference``
    One known ground pixel plus a street bearing (from the scene, else the streets that
    pass near the reference in the map): the car's length axis is parallel to the street,
    in one of its two directions, so two candidates per street direction. The paper counted
    four because it did not know on which side of the length axis the width edge lies; the
    annotated width end (the sign of y in the right-handed world frame) fixes it.
``corners``
    One to four visible kerb corners, clockwise on screen, matched to the map's corners of
    the intersection, clockwise from above (on the ground, below the horizon, the two orders
    agree). Every cyclic assignment of the visible corners to consecutive map corners (and,
    at a lower prior, to order-preserving non-consecutive ones) is fitted. One visible corner
    falls back to the intersection's street bearings (the paper's 16 candidates at a 4-way
    junction).
``landmark``
    A named building's corners or face midpoints, as map points for the annotated pixels;
    one landmark pixel uses the street bearings like ``one_reference``.

Every hypothesis is then scored against *all* the scene's evidence under a Gaussian noise
model (:class:`LocateSettings`): the ground position of a pixel is uncertain through the
click noise (propagated through the pixel-to-ground Jacobian) and the relative scale error,
and a map point is uncertain by ``sigma_*_m``. The likelihood is multiplied by map
plausibility factors: the camera is not deep inside a building, the corners it sees are not
hidden behind buildings, it lies within the prior's radius, the car's length axis is
parallel to a nearby street. Scores are normalised to sum to 1; candidates closer than
``merge_distance_m`` with similar headings are merged. The leading candidates are refined
by one nonlinear least-squares fit of the whole pose (focal length, rotation, camera centre,
car-to-map similarity) to all annotations and matched map features together, which also
gives a position uncertainty in metres.

The pipeline, one function per stage (:func:`locate` reads as the list):

1. evidence (:func:`~camloc_geo.absolute._evidence.gather_evidence`): ground pixels as
   :class:`Observation`\ s with their map points in the local frame;
2. hypotheses (:func:`~camloc_geo.absolute._hypotheses.generate_hypotheses`): candidate
   ``enu_from_world`` :class:`Similarity2D`\ s, one generator per kind of evidence;
3. scores (:func:`~camloc_geo.absolute._pipeline.score_hypothesis`): likelihood, typed
   :class:`Match`\ es, plausibility and :class:`Flag`\ s;
4. prior gate (:func:`~camloc_geo.absolute._pipeline.prior_gate`);
5. refinement (:func:`~camloc_geo.absolute._pipeline.refine_leaders`);
6. ranking (:func:`~camloc_geo.absolute._pipeline.rank`): merged, normalised, ties named.
"""

from __future__ import annotations

from camloc_geo.absolute._cone import view_cone, view_cones
from camloc_geo.absolute._cues import (
    CUE_FLOOR,
    OFF_STREET_FACTOR,
    VIEW_SIGMA_DEG,
    WRONG_WAY_FACTOR,
    CueScore,
    cue_log_likelihood,
    view_log_factor,
)
from camloc_geo.absolute._model import (
    TIE_DISTANCE_M,
    TIE_SCORE_RATIO,
    Candidate,
    Flag,
    FlagKind,
    LocateResult,
    LocateSettings,
    Match,
    Observation,
    Tie,
)
from camloc_geo.absolute._pipeline import apply_cues, locate, mark_ties
from camloc_geo.absolute._similarity import Similarity2D

__all__ = [
    "CUE_FLOOR",
    "OFF_STREET_FACTOR",
    "TIE_DISTANCE_M",
    "TIE_SCORE_RATIO",
    "VIEW_SIGMA_DEG",
    "WRONG_WAY_FACTOR",
    "Candidate",
    "CueScore",
    "Flag",
    "FlagKind",
    "LocateResult",
    "LocateSettings",
    "Match",
    "Observation",
    "Similarity2D",
    "Tie",
    "apply_cues",
    "cue_log_likelihood",
    "locate",
    "mark_ties",
    "view_cone",
    "view_cones",
    "view_log_factor",
]
