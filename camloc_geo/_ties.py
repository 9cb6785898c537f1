"""The one tie rule of the core: when two candidate positions are one answer, or a tie.

Pure arithmetic and the standard library only, so that every layer (the absolute stages,
``results``, the QGIS worker) reads the same rule without importing the heavy engine;
:func:`camloc_geo.absolute.mark_ties` applies it to a result's candidates and records the
outcome as data (``Candidate.ambiguous_with``, ``LocateResult.ties``).
"""

from __future__ import annotations

__all__ = ["TIE_DISTANCE_M", "TIE_MIN_SCORE", "TIE_SCORE_RATIO", "is_tie"]

TIE_SCORE_RATIO = 0.1
"""Two candidates tie when the weaker scores at least this fraction of the stronger.

The scores are posterior weights, so their ratio is the odds the evidence gives one over the
other: under 10 to 1 is no strong evidence (Jeffreys' scale). On the absolute benchmark a
top candidate that is wrong while another is right names that one as tied in 96 % of the
scenes at 0.1 (87 % at 0.8: noise often favours a symmetric junction's mirror by 2-30 to 1).
"""
TIE_DISTANCE_M = 10.0
"""Tied candidates stand more than this far apart, metres (closer ones are one answer at the
accuracy the tool aims at)."""

TIE_MIN_SCORE = 0.01
"""Candidates scoring less than this tie with nobody (a tie of two negligible ones says nothing)."""


def is_tie(
    score_a: float,
    score_b: float,
    gap_m: float,
    *,
    score_ratio: float = TIE_SCORE_RATIO,
    distance_m: float = TIE_DISTANCE_M,
    merge_distance_m: float = 0.0,
) -> bool:
    """Whether two candidates tie: both fit the evidence, yet they stand apart.

    The weaker scores at least ``score_ratio`` of the stronger (odds under 1/``score_ratio``
    to 1) and at least :data:`TIE_MIN_SCORE`, and the two stand more than ``distance_m`` (and
    twice the merge distance) apart.
    """
    lo, hi = sorted((score_a, score_b))
    return (
        lo >= score_ratio * hi
        and lo >= TIE_MIN_SCORE
        and gap_m > max(distance_m, 2.0 * merge_distance_m)
    )
