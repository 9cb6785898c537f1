"""Reading a webcam title: camera number, district prefix, street names, compass words.

See :func:`parse_title`.
"""

from __future__ import annotations

import html
import re
import unicodedata
from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Any

from anyascii import anyascii

__all__ = ["MAX_TITLE_CHARS", "ParsedTitle", "parse_compass_words", "parse_title"]

MAX_TITLE_CHARS = 300
"""Titles are cut to this many characters (a note says so); no real title is longer."""

_POINTS: dict[str, float] = {
    "n": 0.0,
    "nne": 22.5,
    "ne": 45.0,
    "ene": 67.5,
    "e": 90.0,
    "ese": 112.5,
    "se": 135.0,
    "sse": 157.5,
    "s": 180.0,
    "ssw": 202.5,
    "sw": 225.0,
    "wsw": 247.5,
    "w": 270.0,
    "wnw": 292.5,
    "nw": 315.0,
    "nnw": 337.5,
}
_WORDS: dict[str, str] = {
    "north": "n",
    "south": "s",
    "east": "e",
    "west": "w",
    "northeast": "ne",
    "northwest": "nw",
    "southeast": "se",
    "southwest": "sw",
    "nord": "n",
    "sud": "s",
    "sued": "s",
    "ost": "e",
    "est": "e",
    "ouest": "w",
    "norte": "n",
    "sur": "s",
    "este": "e",
    "oeste": "w",
    "sever": "n",
    "yug": "s",
    "vostok": "e",
    "zapad": "w",
    "nordost": "ne",
    "nordwest": "nw",
    "suedost": "se",
    "sudost": "se",
    "suedwest": "sw",
    "sudwest": "sw",
    "nordest": "ne",
    "nordouest": "nw",
    "sudest": "se",
    "sudouest": "sw",
    "noreste": "ne",
    "noroeste": "nw",
    "sureste": "se",
    "suroeste": "sw",
    "norden": "n",
    "sueden": "s",
    "suden": "s",
    "osten": "e",
    "westen": "w",
    # Finnish (read after anyascii: pohjoiseen, etelään, itään, länteen)
    "pohjoinen": "n",
    "pohjoiseen": "n",
    "etela": "s",
    "etelaan": "s",
    "ita": "e",
    "itaan": "e",
    "lansi": "w",
    "lanteen": "w",
    # Chinese (北向, 南向, 東向/东向, 西向: "facing north"...)
    "beixiang": "n",
    "nanxiang": "s",
    "dongxiang": "e",
    "xixiang": "w",
}
_BOUND = {"nb": "n", "sb": "s", "eb": "e", "wb": "w"}
_CUES = (
    "looking|facing|view|viewing|views|towards|toward|heading|direction|dir|vers|richtung|blick"
    "|hacia|sentido|para|na"
)
_DIR_ALT = "|".join(sorted([*_WORDS, *_POINTS], key=len, reverse=True))
_CUE_RE = re.compile(
    rf"\b(?:{_CUES})\s*(?:to\s+the\s+|to\s+|the\s+|(?:el|al|la|le|nach|au|du)\s+)?[:\-]?\s*"
    rf"({_DIR_ALT})(?:ward|wards|bound)?\b",
    re.IGNORECASE,
)
_BOUND_RE = re.compile(
    rf"\b(?:(nb|sb|eb|wb)|({'|'.join(_WORDS)})[\s-]?bound)\b(?:\s+(?:lanes?|traffic|view))?",
    re.IGNORECASE,
)
_DIR_WORD_RE = re.compile(
    rf"^\s*(?:(?:{_CUES})\s*)?({_DIR_ALT})(?:[\s-]?(?:side|ward|wards|bound|view|facing|cam|camera))?\s*$",
    re.IGNORECASE,
)
_PAREN_RE = re.compile(r"[(\[{]([^()\[\]{}]*)[)\]}]")
_CAMERA_PREFIX_RE = re.compile(
    r"^\s*(?:(?:cam(?:era)?|cctv|webcam|kamera|camara|camera|камера)\s*(?:no\.?|nr\.?|#)?\s*)?"
    r"#?(\d{1,6}[a-z]?)\s*(?:[-–—:|.]\s*|\s+-\s*)(?=\D)",
    re.IGNORECASE,
)
_CAMERA_WORD_RE = re.compile(
    r"^\s*(?:cam(?:era)?|cctv|webcam|kamera|camara|камера)\s*(?:no\.?|nr\.?|#)?\s*(\d{1,6}[a-z]?)\b\s*",
    re.IGNORECASE,
)
_SEGMENT_RE = re.compile(r"\s+[-–—|]+\s+|\s*[–—|]\s*|\s*:\s+")
_SEPARATOR_RE = re.compile(
    r"\s*(?:&|@|\+|×|/|\\|"
    r"(?<=\s)(?:and|at|y|et|und|x|near|esq\.?|esquina|ecke|con)(?=\s)|"
    r"\s(?:и)\s)\s*",
    re.IGNORECASE,
)
_SCRIPT_RE = re.compile(
    r"<\s*(script|style)\b[^>]*>.*?(?:<\s*/\s*\1\s*>|$)", re.IGNORECASE | re.DOTALL
)
_TAG_RE = re.compile(r"</?[a-z][a-z0-9]*\b[^<>]{0,300}>|<!--.*?-->", re.IGNORECASE | re.DOTALL)
_ENTITY_RE = re.compile(r"&(?:#\d{1,7}|#x[0-9a-f]{1,6}|[a-z]{2,8});", re.IGNORECASE)
_CALLE_SLASH_RE = re.compile(r"\bc/", re.IGNORECASE)
_FRACTION_RE = re.compile(r"(?<=\d)/(?=\d)")
_NUMBER_ONLY_RE = re.compile(r"#?\d{1,6}[a-z]?", re.IGNORECASE)
_MALCOLM_RE = re.compile(r"\bmalcolm\s+x\b", re.IGNORECASE)
_HOUSE_FIRST_RE = re.compile(
    r"^\s*(\d{1,6}(?:[-/]\d{1,4})?[a-z]?)\s+(?:block\s+(?:of\s+)?)?(?=[^\W\d])", re.IGNORECASE
)
_HOUSE_LAST_RE = re.compile(r"^(.*\D)\s+(\d{1,5}[a-z]?)\s*$", re.IGNORECASE)
_ORDINAL_START_RE = re.compile(r"^\s*\d+\s*(?:st|nd|rd|th)\b", re.IGNORECASE)
_CONTROL_RE = re.compile(r"[\x00-\x1f\x7f-\x9f\u200b-\u200f\u2028-\u202e\ufeff]")
_WORD_RE = re.compile(r"\w", re.UNICODE)
_ROUTE_WORDS = re.compile(
    r"\b(?:route|rte|hwy|highway|interstate|i|us|sr|md|ca|ny|state|county|road|rd|exit|km)\s*$",
    re.IGNORECASE,
)


@dataclass
class ParsedTitle:
    """What a webcam title says.

    Attributes
    ----------
    raw
        The title as given.
    streets
        The street (or landmark) names read, in title order, abbreviations as written.
    house_number
        A house number before (``1200 N Charles St``) or after (``Hauptstraße 12``) a
        single street name, or None.
    camera_number
        A leading camera number (``625 - ...``, ``204-E Baltimore St``, ``Cam 12:``), or None.
    view_bearing_deg
        Viewing or travel direction from compass words, degrees clockwise from north, or None.
    compass_text
        The words that gave ``view_bearing_deg``.
    notes
        What else was read and set aside (district prefixes, parentheses, cut text).
    """

    raw: str
    streets: list[str] = field(default_factory=list)
    house_number: str | None = None
    camera_number: str | None = None
    view_bearing_deg: float | None = None
    compass_text: str | None = None
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict of the fields."""
        return {
            "raw": self.raw,
            "streets": list(self.streets),
            "house_number": self.house_number,
            "camera_number": self.camera_number,
            "view_bearing_deg": self.view_bearing_deg,
            "compass_text": self.compass_text,
            "notes": list(self.notes),
        }


def _bearing_of(word: str) -> float | None:
    w = anyascii(word).casefold().replace("-", "").replace(" ", "")
    w = _WORDS.get(w, w)
    return _POINTS.get(w)


def parse_compass_words(text: str) -> float | None:
    """Bearing of a text that is only compass words ("looking north", "NB", "(Eastside)").

    Returns None when the text is not just a direction.

    Examples
    --------
    >>> parse_compass_words("looking north"), parse_compass_words("NB")
    (0.0, 0.0)
    >>> parse_compass_words("facing SW"), parse_compass_words("Eastside")
    (225.0, 90.0)
    >>> parse_compass_words("Broadway") is None
    True
    """
    t = anyascii(text).strip()
    m = _DIR_WORD_RE.match(t)
    if m:
        return _bearing_of(m.group(1))
    m2 = _BOUND_RE.fullmatch(t.strip())
    if m2:
        return _bearing_of(_BOUND.get((m2.group(1) or "").lower(), m2.group(2) or ""))
    m3 = _CUE_RE.fullmatch(t)
    if m3:
        return _bearing_of(m3.group(1))
    return None


def _clean(title: str, notes: list[str]) -> str:
    text = unicodedata.normalize("NFKC", title)
    if "<" in text or "&" in text:
        text = _markup_removed(text, notes)
    if _CONTROL_RE.search(text):
        text = _CONTROL_RE.sub(" ", text)
        notes.append("control characters removed")
    if len(text) > MAX_TITLE_CHARS:
        text = text[:MAX_TITLE_CHARS]
        notes.append(f"title cut to its first {MAX_TITLE_CHARS} characters")
    return " ".join(text.split())


def _markup_removed(text: str, notes: list[str]) -> str:
    """A title scraped from a web page, without its HTML: script and style elements with
    their content and every tag are removed, entities (``&amp;``) read."""
    stripped = _SCRIPT_RE.sub(" ", text)
    stripped = _TAG_RE.sub(" ", stripped)
    if _ENTITY_RE.search(stripped):
        stripped = html.unescape(stripped)
    if stripped != text:
        notes.append("HTML markup removed")
    return stripped


def _split_names(segment: str) -> list[str]:
    # control characters were removed: \x01 and \x02 stand for protected spaces and slashes
    protected = _MALCOLM_RE.sub(lambda m: m.group(0).replace(" ", "\x01"), segment)
    protected = _CALLE_SLASH_RE.sub("c\x02", protected)  # Spanish calle
    protected = _FRACTION_RE.sub("\x02", protected)  # fractions: 5 1/2 Street
    parts = _SEPARATOR_RE.split(protected)
    return [
        p.replace("\x01", " ").replace("\x02", "/").strip(" ,;.-")
        for p in parts
        if p and p.strip(" ,;.-")
    ]


def _has_separator(segment: str) -> bool:
    return len(_split_names(segment)) > 1


def parse_title(title: str) -> ParsedTitle:
    """Read a webcam title.

    Camera numbers (``625 - ``, ``204-``, ``Cam 12:``) and district prefixes
    (``221 Broadway - `` before a junction) are stripped; the junction's names are split at
    ``&``, ``@``, ``at``, ``and``, ``/``, `` - ``, ``x``, ``y``, ``et``, ``und``, ``и``
    (also ``+``, ``×``); compass words and travel directions (``looking north``, ``NB``,
    ``facing SW``, ``(Eastside)``, a lone ``west``) give ``view_bearing_deg``; other
    parentheses are set aside as notes; a number before or after a single street name is a
    house number.

    Parameters
    ----------
    title
        The title as published. Control characters are removed and text beyond
        :data:`MAX_TITLE_CHARS` characters is ignored (a note says so).

    Returns
    -------
    The parsed title; ``streets`` is empty when nothing name-like is left.

    Examples
    --------
    >>> parse_title("625 - Milton & E Biddle St").streets
    ['Milton', 'E Biddle St']
    >>> p = parse_title("221 Broadway - Fleet/Broadway (Eastside)")
    >>> p.streets, p.view_bearing_deg
    (['Fleet', 'Broadway'], 90.0)
    >>> parse_title("204-E Baltimore St - S Ann St").streets
    ['E Baltimore St', 'S Ann St']
    >>> p = parse_title("1200 N Charles St")
    >>> p.streets, p.house_number
    (['N Charles St'], '1200')
    """
    if not isinstance(title, str):
        title = "" if title is None else str(title)
    # a batch reads the same titles again and again (each camera's title is parsed for the
    # listing and once per extract searched): parse each once, hand out copies
    cached = _parse_title_cached(title)
    return replace(cached, streets=list(cached.streets), notes=list(cached.notes))


@lru_cache(maxsize=8192)
def _parse_title_cached(title: str) -> ParsedTitle:
    """:func:`parse_title` itself (the cached original; callers get copies)."""
    notes: list[str] = []
    parsed = ParsedTitle(raw=title, notes=notes)
    text = _clean(title, notes)
    if not _WORD_RE.search(text):
        if text:
            notes.append("no letters or digits in the title")
        return parsed
    compass: list[tuple[str, float]] = []

    # parentheses: compass words or notes
    def paren(m: re.Match[str]) -> str:
        inner = m.group(1).strip()
        brg = parse_compass_words(inner) if inner else None
        if brg is not None:
            compass.append((inner, brg))
        elif inner:
            notes.append(f"set aside: ({inner})")
        return " "

    text = _PAREN_RE.sub(paren, text)
    text = text.replace("(", " ").replace(")", " ")

    # cue phrases and travel directions anywhere
    def cue(m: re.Match[str]) -> str:
        brg = _bearing_of(m.group(1))
        if brg is not None:
            compass.append((m.group(0).strip(), brg))
            return " "
        return m.group(0)

    text = _CUE_RE.sub(cue, text)

    def bound(m: re.Match[str]) -> str:
        word = _BOUND.get((m.group(1) or "").lower()) or m.group(2) or ""
        brg = _bearing_of(word)
        if brg is not None:
            compass.append((m.group(0).strip(), brg))
            return " "
        return m.group(0)

    text = _BOUND_RE.sub(bound, text)
    text = " ".join(text.split())

    # camera number
    m = _CAMERA_WORD_RE.match(text) or _CAMERA_PREFIX_RE.match(text)
    if m and not _ORDINAL_START_RE.match(text):
        parsed.camera_number = m.group(1)
        text = text[m.end() :].lstrip(" -–—:|.#")

    # segments: " - ", "|", ":"; then commas as notes
    segments = [s.strip(" ,;.") for s in _SEGMENT_RE.split(text) if s.strip(" ,;.-")]
    kept: list[str] = []
    for seg in segments:
        brg = parse_compass_words(seg)
        if brg is not None:
            compass.append((seg, brg))
        elif _NUMBER_ONLY_RE.fullmatch(seg):
            if parsed.camera_number is None and not kept:
                parsed.camera_number = seg.lstrip("#")
            else:
                notes.append(f"set aside: {seg}")
        else:
            kept.append(seg)
    # trailing comma parts of the junction segment (a city, an area) are notes
    cleaned: list[str] = []
    for seg in kept:
        parts = [p.strip() for p in seg.split(",") if p.strip()]
        if len(parts) > 1:
            main = next((p for p in parts if _has_separator(p)), parts[0])
            for p in parts:
                if p is main:
                    continue
                brg = parse_compass_words(p)
                if brg is not None:
                    compass.append((p, brg))
                else:
                    notes.append(f"set aside: {p}")
            cleaned.append(main)
        elif parts:
            cleaned.append(parts[0])
    # with a junction segment, the segments before it are district prefixes
    junction_idx = [i for i, seg in enumerate(cleaned) if _has_separator(seg)]
    if junction_idx:
        first = junction_idx[0]
        for seg in cleaned[:first]:
            notes.append(f"district prefix: {seg}")
        for seg in cleaned[first + 1 :]:
            notes.append(f"set aside: {seg}")
        names = _split_names(cleaned[first])
    else:
        names = [n for seg in cleaned for n in _split_names(seg)]
    # a lone compass word among the names ("Main St & 5th Ave west" is kept as is)
    final: list[str] = []
    for name in names:
        brg = parse_compass_words(name) if len(names) > 1 else None
        if brg is not None:
            compass.append((name, brg))
        elif _WORD_RE.search(name):
            final.append(" ".join(name.split()))
    if len(final) == 1:
        m1 = _HOUSE_FIRST_RE.match(final[0])
        if m1 and not _ORDINAL_START_RE.match(final[0]):
            parsed.house_number = m1.group(1)
            final[0] = final[0][m1.end() :].strip()
        else:
            m2 = _HOUSE_LAST_RE.match(final[0])
            if m2 and not _ROUTE_WORDS.search(m2.group(1)):
                parsed.house_number = m2.group(2)
                final[0] = m2.group(1).strip(" ,")
    parsed.streets = [n for n in final if n]
    if compass:
        parsed.compass_text = "; ".join(t for t, _b in compass)
        parsed.view_bearing_deg = compass[0][1]
    return parsed
