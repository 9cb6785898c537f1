"""Street and building name normalisation for tolerant look-ups.

Names are compared after :func:`normalize_name`, the canonical tokens of the one normaliser
(:func:`camloc_geo.osm._tokens.name_tokens`, shared with title geocoding): transliterated to
ASCII and case folded, punctuation dropped, abbreviations expanded by one table (USPS street
suffixes and directionals, French, Spanish, Portuguese, German, Russian: ``St``/``Street``,
``Ave``/``Avenue``, ``N``/``North``, ``Str.``/``Straße``...), numbered streets as digits.
``St`` is *Saint* unless it ends the name (``St Paul St`` = ``Saint Paul Street``). Close
names are found with rapidfuzz.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence

from camloc_geo.osm._tokens import name_tokens

__all__ = [
    "close_matches",
    "misspelling_matches",
    "names_match",
    "normalize_name",
    "split_street_query",
]

_SPLIT_RE = re.compile(r"\s*(?:&|/|×|\+|\s+and\s+|\s+x\s+|\s+at\s+)\s*", re.IGNORECASE)


def normalize_name(name: str) -> str:
    """Normalise a street or building name for comparison.

    Parameters
    ----------
    name
        A name as written by a person or tagged in OSM.

    Returns
    -------
    The lower-case, abbreviation-expanded form, tokens separated by one space.

    Examples
    --------
    >>> normalize_name("S. Broadway")
    'south broadway'
    >>> normalize_name("St Paul St") == normalize_name("Saint Paul Street")
    True
    >>> normalize_name("Hauptstr.") == normalize_name("Hauptstraße")
    True
    """
    return " ".join(name_tokens(name))


def names_match(query: str, name: str) -> bool:
    """Whether a normalised query equals a normalised name."""
    return normalize_name(query) == normalize_name(name)


def split_street_query(query: str | Sequence[str]) -> list[str]:
    """Split ``"A & B"`` (also ``/``, ``×``, ``+``, `` and ``, `` x ``, `` at ``) into names.

    Examples
    --------
    >>> split_street_query("Eastern Avenue & South Broadway")
    ['Eastern Avenue', 'South Broadway']
    >>> split_street_query(["Eastern Ave", " S Broadway "])
    ['Eastern Ave', 'S Broadway']
    """
    parts = _SPLIT_RE.split(query) if isinstance(query, str) else list(query)
    return [p.strip() for p in parts if p and p.strip()]


def close_matches(query: str, candidates: Iterable[str], n: int = 5) -> list[str]:
    """Candidates whose normalised form is close to the query's (best first)."""
    by_norm: dict[str, str] = {}
    for cand in candidates:
        by_norm.setdefault(normalize_name(cand), cand)
    norm_query = normalize_name(query)
    from rapidfuzz import fuzz, process

    found = process.extract(norm_query, list(by_norm), scorer=fuzz.ratio, limit=n, score_cutoff=60)
    hits = [name for name, _score, _i in found]
    # also offer names that contain the query's tokens ("Broadway" -> "South Broadway")
    q_tokens = set(norm_query.split())
    for norm, _cand in by_norm.items():
        if len(hits) >= n:
            break
        if q_tokens and q_tokens <= set(norm.split()) and norm not in hits:
            hits.append(norm)
    return [by_norm[h] for h in hits]


MISSPELLING_MIN_RATIO = 85.0
"""rapidfuzz's ``fuzz.ratio`` (0-100) of two normalised names at least this for one to be
read as a misspelling of the other: one letter dropped, added or two swapped in a name of
ten letters scores 90-95, in one of six 85-90."""


def misspelling_matches(query: str, candidates: Iterable[str], n: int = 3) -> list[str]:
    """Candidates the query may be a misspelling of: normalised names within
    :data:`MISSPELLING_MIN_RATIO` of it with the same numbers (``1st`` is never read as
    ``2nd``), best first; empty when the query is itself one of them.

    Examples
    --------
    >>> misspelling_matches("Eastrn Ave", ["Eastern Avenue", "Western Avenue", "Easton Road"])
    ['Eastern Avenue', 'Western Avenue']
    >>> misspelling_matches("1st Street", ["2nd Street"])
    []
    """
    by_norm: dict[str, str] = {}
    for cand in candidates:
        by_norm.setdefault(normalize_name(cand), cand)
    q = normalize_name(query)
    if not q or q in by_norm:
        return []
    from rapidfuzz import fuzz, process

    digits = [t for t in q.split() if any(ch.isdigit() for ch in t)]
    found = process.extract(
        q, list(by_norm), scorer=fuzz.ratio, limit=None, score_cutoff=MISSPELLING_MIN_RATIO
    )
    out = []
    for norm, _score, _i in found:
        if [t for t in norm.split() if any(ch.isdigit() for ch in t)] == digits:
            out.append(by_norm[norm])
    return out[:n]
