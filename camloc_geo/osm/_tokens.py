"""The one street-name normaliser and abbreviation table (map layer, title geocoding alike).

A name becomes a tuple of canonical tokens (:func:`name_tokens`):

1. NFKC, transliterated to ASCII by :func:`anyascii.anyascii` (accents, ``ß`` -> ``ss``,
   Cyrillic -> Latin: ``улица`` -> ``ulitsa``), case folded;
2. a German suffix glued to the name is split off (``Wadzeckstr.`` -> ``wadzeck strasse``),
   ``c/`` (Spanish *calle*) expanded, apostrophes dropped, other punctuation is a space;
3. every token is mapped to a canonical word: USPS Publication 28 street suffixes and
   directionals (``St``, ``Ave``, ``Blvd``, ``N``, ``NE``...), French (``R.``, ``Bd``,
   ``Av.``, ``St``/``Ste`` = saint/sainte), Spanish and Portuguese (``Av.``, ``C.``,
   ``R.``, ``Prol.``), German (``Str.``), Russian (``ул.``, ``просп.``, ``пер.``);
   the same word in several languages maps to one canonical token (``avenida``,
   ``avenue`` -> ``avenue``; ``rua``, ``rue`` -> ``rue``), so the two sides of a
   comparison agree whichever language either was written in;
4. numbered streets become digits (``Fifth``, ``5th``, ``5e``, ``5.`` -> ``5``).

``St`` is *street* when it ends the name (or only directionals follow), *saint* otherwise
(``St Paul St`` = ``Saint Paul Street``, ``R. St-Maur`` = ``Rue Saint-Maur``).

The *core* of a name drops street types, directionals and articles
(``North Collington Avenue`` -> ``collington``): a title that leaves out the N/S half or the
suffix, or doubles it (``S Broadway St``), still finds the street through it.
"""

from __future__ import annotations

import re
import unicodedata
from functools import lru_cache

from anyascii import anyascii

__all__ = [
    "ARTICLES",
    "DIRECTIONALS",
    "STREET_TYPES",
    "core_tokens",
    "fold",
    "name_tokens",
]

DIRECTIONALS: dict[str, str] = {
    "n": "north",
    "s": "south",
    "e": "east",
    "w": "west",
    "ne": "northeast",
    "nw": "northwest",
    "se": "southeast",
    "sw": "southwest",
    "north": "north",
    "south": "south",
    "east": "east",
    "west": "west",
    "northeast": "northeast",
    "northwest": "northwest",
    "southeast": "southeast",
    "southwest": "southwest",
}
"""Directional abbreviations (USPS) -> canonical directional."""

# canonical street type: its spellings (USPS Publication 28 C1 street suffixes, the common
# ones, then French, Spanish/Portuguese/Catalan/Italian, German and transliterated Russian)
_TYPE_TABLE = """
alley: aly ally alley allee
annex: anx annex
arcade: arc arcade
avenue: av ave aven avenu avn avnue avenue avenida avda avd avinguda avgda
bayou: byu bayou
beach: bch beach
bend: bnd bend
bluff: blf bluff
boulevard: blvd blv boul boulv bd bvd bld blvr boulevard bulevar bulvar bul
branch: brnch branch
bridge: brg brdge bridge
brook: brk brook
bypass: byp bypa bypas byps bypass
causeway: cswy causwa causeway
center: ctr cen cent centr cnter cntr center centre
circle: cir circ circl crcl crcle circle
cliff: clf cliff
common: cmn common
corner: cor corner
court: ct crt court
cove: cv cove
creek: crk creek
crescent: cres crsent crsnt crescent
crossing: xing crssng crossing
curve: curv curve
drive: dr drv driv drive
expressway: expy expr express expw expressway
extension: ext extn extension
ferry: fry ferry
field: fld field
freeway: fwy frwy frway freewy freeway
garden: gdn gardn grden grdn garden gdns gardens
gateway: gtwy gatewy gatway gateway
glen: gln glen
green: grn green
grove: grv grov grove
harbor: hbr harb harbr harbor harbour
heights: hts ht heights
highway: hwy hiway hiwy hway highwy highway
hill: hl hill
hollow: holw hollow
junction: jct jction junction
lane: ln lane
landing: lndg lndng landing
loop: loop loops
mall: mall
manor: mnr manor
meadow: mdw meadow mdws meadows
mews: mews
mount: mt mnt mount
motorway: mtwy motorway
mountain: mtn mntain mountain
overpass: opas overpass
park: prk park
parkway: pkwy pky pkway parkwy pkwys parkway parkways
passage: psge pass pas pje passage pasaje passagem
path: path
pike: pike pikes
place: pl plz plza pza place plaza platz piazza praca pca ploshchad
point: pt point
port: prt port
ramp: ramp
ridge: rdg rdge ridge
road: rd road
route: rte route
row: row
run: run
skyway: skwy skyway
spur: spur
square: sq sqr sqre squ square
station: sta stn statn station
street: street strt stre
summit: smt sumit summit
terrace: ter terr tce terrace
throughway: trwy throughway
trace: trce trace
track: trak track
trail: trl trail
tunnel: tunl tunnel
turnpike: tpke trnpk turnpike
underpass: upas underpass
valley: vly valley
viaduct: viaduct
view: vw view
village: vlg village
walk: walk walks
way: way wy
rue: r rue rua
impasse: imp impasse
quai: qu qua quai
chemin: ch chem chemin
cours: crs cours
faubourg: fbg fg faubourg
promenade: prom promenade
calle: c cl cll calle carrer via
callejon: cjon callejon
carretera: carr ctra carretera
prolongacion: prol prolong prolongacion
calzada: calz calzada
travessa: tv trav travessa
alameda: alameda
largo: lgo largo
privada: priv privada
strasse: str strasse strase
weg: weg
gasse: gasse
damm: damm
ufer: ufer
ring: ring
chaussee: chaussee
ulitsa: ul ulitsa ulica
prospekt: pr prosp prospekt
pereulok: per pereulok
proezd: proezd
shosse: sh shosse
naberezhnaya: nab naberezhnaya
bulvar: bulvar
"""

STREET_TYPES: dict[str, str] = {}
"""Spelling -> canonical street type (every canonical type maps to itself)."""
for _line in _TYPE_TABLE.strip().splitlines():
    _canon, _spellings = _line.split(":")
    STREET_TYPES[_canon.strip()] = _canon.strip()
    for _sp in _spellings.split():
        STREET_TYPES.setdefault(_sp, _canon.strip())

_TYPE_VALUES = frozenset(STREET_TYPES.values())
_DIRECTIONAL_VALUES = frozenset(DIRECTIONALS.values())

_TITLES: dict[str, str] = {
    "ste": "sainte",
    "saint": "saint",
    "sainte": "sainte",
    "sankt": "saint",
    "mt": "mount",
    "ft": "fort",
    "dr": "doctor",
    "docteur": "doctor",
    "doctor": "doctor",
    "gen": "general",
    "gral": "general",
    "gal": "general",
    "pres": "president",
    "pdt": "president",
    "mal": "marechal",
    "jr": "junior",
    "sr": "senior",
    "mlk": "martin luther king",
}
"""Words inside names (not types)."""

ARTICLES: frozenset[str] = frozenset(
    [
        "the",
        "of",
        "de",
        "la",
        "le",
        "les",
        "du",
        "des",
        "d",
        "l",
        "del",
        "da",
        "do",
        "dos",
        "das",
        "der",
        "die",
        "den",
        "am",
        "an",
        "al",
        "el",
        "y",
        "et",
        "und",
    ]
)
"""Articles and particles dropped from a name's core."""

_ORDINAL_WORDS: dict[str, int] = {
    w: i + 1
    for i, w in enumerate(
        [
            "first",
            "second",
            "third",
            "fourth",
            "fifth",
            "sixth",
            "seventh",
            "eighth",
            "ninth",
            "tenth",
            "eleventh",
            "twelfth",
            "thirteenth",
            "fourteenth",
            "fifteenth",
            "sixteenth",
            "seventeenth",
            "eighteenth",
            "nineteenth",
            "twentieth",
        ]
    )
}
_ORDINAL_WORDS.update(
    {"thirtieth": 30, "fortieth": 40, "fiftieth": 50, "sixtieth": 60, "seventieth": 70}
)
_ORDINAL_WORDS.update({"eightieth": 80, "ninetieth": 90, "hundredth": 100})
_TENS: dict[str, int] = {
    "twenty": 20,
    "thirty": 30,
    "forty": 40,
    "fifty": 50,
    "sixty": 60,
    "seventy": 70,
    "eighty": 80,
    "ninety": 90,
}
_ORDINAL_RE = re.compile(r"^(\d{1,4})(?:st|nd|rd|th|e|er|eme|re|a|o|ra|ro|ya|yy|ja)?$")

_GLUED_STR_RE = re.compile(r"([a-z])(?:strasse|strase|str)\b")
_CALLE_RE = re.compile(r"\bc/\s*")
_APOSTROPHE_RE = re.compile(r"['\u2019`\u00b4]")
_NON_WORD_RE = re.compile(r"[^a-z0-9]+")


def fold(text: str) -> str:
    """ASCII, case-folded, punctuation-free form (for telling exact from abbreviated)."""
    text = anyascii(unicodedata.normalize("NFKC", text)).casefold()
    text = _APOSTROPHE_RE.sub("", text)
    return " ".join(_NON_WORD_RE.sub(" ", text).split())


def _canonical(tokens: list[str]) -> list[str]:
    out: list[str] = []
    n = len(tokens)
    i = 0
    while i < n:
        tok = tokens[i]
        rest = tokens[i + 1 :]
        if tok == "st":
            # street at the end (or before directionals only), saint elsewhere
            out.append("street" if all(t in DIRECTIONALS for t in rest) else "saint")
        elif tok in _TENS and rest and rest[0] in _ORDINAL_WORDS and _ORDINAL_WORDS[rest[0]] < 10:
            out.append(str(_TENS[tok] + _ORDINAL_WORDS[rest[0]]))
            i += 1
        elif tok in _ORDINAL_WORDS:
            out.append(str(_ORDINAL_WORDS[tok]))
        elif tok in DIRECTIONALS:
            out.append(DIRECTIONALS[tok])
        elif tok == "dr" and not rest and i > 0:
            out.append("drive")
        elif tok in _TITLES:
            out.extend(_TITLES[tok].split())
        elif tok in STREET_TYPES:
            out.append(STREET_TYPES[tok])
        else:
            m = _ORDINAL_RE.match(tok)
            out.append(str(int(m.group(1))) if m else tok)
        i += 1
    return out


@lru_cache(maxsize=65536)
def name_tokens(name: str) -> tuple[str, ...]:
    """Canonical tokens of a street name (see the module docstring).

    Examples
    --------
    >>> name_tokens("E Biddle St")
    ('east', 'biddle', 'street')
    >>> name_tokens("Karl-Liebknecht-Str.") == name_tokens("Karl-Liebknecht-Straße")
    True
    >>> name_tokens("Av. de la Republique") == name_tokens("Avenue de la République")
    True
    >>> name_tokens("Fifth Avenue") == name_tokens("5th Ave")
    True
    >>> name_tokens("Zhongshan N. Rd. Sec. 2") == name_tokens("Section 2, Zhongshan North Road")
    True
    """
    text = anyascii(unicodedata.normalize("NFKC", name)).casefold()
    text = _CALLE_RE.sub("calle ", text)
    text = _APOSTROPHE_RE.sub("", text)
    text = _GLUED_STR_RE.sub(r"\1 strasse", text)
    tokens = _NON_WORD_RE.sub(" ", text).split()
    return _section_last(_canonical(tokens))


def _section_last(tokens: list[str]) -> tuple[str, ...]:
    """Taiwanese road sections at the end, however written: OSM's ``Section 2, Zhongshan
    North Road`` and the signs' ``Zhongshan N. Rd. Sec. 2`` both end ``section 2``."""
    for i, tok in enumerate(tokens[:-1]):
        if tok in ("sec", "section") and tokens[i + 1].isdigit() and len(tokens) > 2:
            return (*tokens[:i], *tokens[i + 2 :], "section", tokens[i + 1])
    return tuple(tokens)


def core_tokens(tokens: tuple[str, ...]) -> tuple[str, ...]:
    """The name without directionals, articles and the street types at its ends.

    Types are stripped from both ends while another word remains, so ``Port Street`` keeps
    ``port`` and ``Rue du Faubourg Saint-Antoine`` keeps ``saint antoine``.

    Examples
    --------
    >>> core_tokens(name_tokens("North Collington Avenue"))
    ('collington',)
    >>> core_tokens(name_tokens("South Port Street"))
    ('port',)
    >>> core_tokens(name_tokens("North Avenue"))
    ('avenue',)
    """
    core = [t for t in tokens if t not in _DIRECTIONAL_VALUES and t not in ARTICLES]
    while len(core) > 1 and core[-1] in _TYPE_VALUES:
        core.pop()
    while len(core) > 1 and core[0] in _TYPE_VALUES:
        core.pop(0)
    return tuple(core) or tokens


def directionals_of(tokens: tuple[str, ...]) -> frozenset[str]:
    """The directionals among a name's tokens."""
    return frozenset(t for t in tokens if t in _DIRECTIONAL_VALUES)


def types_of(tokens: tuple[str, ...]) -> frozenset[str]:
    """The street types among a name's tokens."""
    return frozenset(t for t in tokens if t in _TYPE_VALUES)
