"""Street and building name normalisation for tolerant look-ups.

Names are compared after :func:`normalize_name`: Unicode case folding, accents kept,
``ß`` folded to ``ss``, punctuation dropped, and common abbreviations expanded token by
token (``St``/``Street``, ``Ave``/``Avenue``, ``N``/``North``, ``Str.``/``Straße``...). A
leading ``St`` is read as *Saint* (``St Paul St`` = ``Saint Paul Street``).
"""

from __future__ import annotations

import difflib
import re
import unicodedata
from collections.abc import Iterable, Sequence

__all__ = ["close_matches", "names_match", "normalize_name", "split_street_query"]

_ABBREVIATIONS: dict[str, str] = {
    "st": "street",
    "str": "strasse",
    "ave": "avenue",
    "av": "avenue",
    "avn": "avenue",
    "rd": "road",
    "blvd": "boulevard",
    "bd": "boulevard",
    "bvd": "boulevard",
    "dr": "drive",
    "ln": "lane",
    "pl": "place",
    "ct": "court",
    "cir": "circle",
    "hwy": "highway",
    "pkwy": "parkway",
    "sq": "square",
    "ter": "terrace",
    "tce": "terrace",
    "cres": "crescent",
    "expy": "expressway",
    "fwy": "freeway",
    "mt": "mount",
    "n": "north",
    "s": "south",
    "e": "east",
    "w": "west",
    "ne": "northeast",
    "nw": "northwest",
    "se": "southeast",
    "sw": "southwest",
    "r": "rue",
}

_SPLIT_RE = re.compile(r"\s*(?:&|/|×|\+|\s+and\s+|\s+x\s+|\s+at\s+)\s*", re.IGNORECASE)
_PUNCT_RE = re.compile(r"[^\w\s]", re.UNICODE)


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
    text = unicodedata.normalize("NFKC", name).casefold().replace("ß", "ss")
    # glued German suffix: "Hauptstr." -> "hauptstrasse"
    text = re.sub(r"(\w)str\b\.?", r"\1strasse", text)
    text = _PUNCT_RE.sub(" ", text)
    tokens = text.split()
    out: list[str] = []
    for i, tok in enumerate(tokens):
        if tok == "st" and i == 0 and len(tokens) > 1:
            out.append("saint")
        else:
            out.append(_ABBREVIATIONS.get(tok, tok))
    return " ".join(out)


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
    hits = difflib.get_close_matches(norm_query, list(by_norm), n=n, cutoff=0.6)
    # also offer names that contain the query's tokens ("Broadway" -> "South Broadway")
    q_tokens = set(norm_query.split())
    for norm, _cand in by_norm.items():
        if len(hits) >= n:
            break
        if q_tokens and q_tokens <= set(norm.split()) and norm not in hits:
            hits.append(norm)
    return [by_norm[h] for h in hits]
