"""Placing a webcam title on the map: :func:`geocode_title`.

How names match (:func:`match_name`), best first:

- ``exact``: the same words once case, accents and punctuation are set aside (score 1);
- ``abbreviation``: the same canonical tokens (St = Street, Str. = Straße, 5th = Fifth...;
  score 0.97);
- ``partial``: the same core (street types, directionals and articles dropped) without a
  conflicting directional: ``Milton`` -> ``North Milton Avenue``, ``S Broadway St`` ->
  ``South Broadway`` (score 0.88, 0.75 when the street types disagree);
- ``fuzzy``: a typo, corrected token by token against the map's own words, or the whole
  core within :data:`FUZZY_MIN_RATIO` (rapidfuzz ``ratio``) of a map name (score up to 0.8).

A junction's score is the product of its two names' scores. Two names first look for a
junction of the model (:attr:`MapData.intersections`); where the model has none (named
``service`` streets, pedestrian segments, bends where the name changes), the two streets'
own lines are intersected (``geometric``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import shapely
import shapely.ops
from shapely.geometry import LineString, MultiLineString, mapping

from camloc_geo._errors import InputError, MapDataError
from camloc_geo.geocode._index import GeocodeIndex, Landmark, index_for
from camloc_geo.geocode._normalize import (
    STREET_TYPES,
    core_tokens,
    directionals_of,
    fold,
    name_tokens,
    types_of,
)
from camloc_geo.geocode._parse import ParsedTitle, parse_title
from camloc_geo.geodesy import great_circle_m

if TYPE_CHECKING:
    from camloc_geo.osm import Intersection, MapData

__all__ = [
    "FUZZY_MIN_RATIO",
    "PLACED_STATUSES",
    "STATUSES",
    "NameHit",
    "TitleMatch",
    "geocode_title",
    "match_name",
]

STATUSES = ("junction", "street", "address", "landmark", "ambiguous", "not_found")
PLACED_STATUSES = frozenset({"junction", "address", "landmark", "ambiguous"})
"""Statuses that come with a point (an ``address`` without an OSM point has none)."""
FUZZY_MIN_RATIO = 88.0
"""Least rapidfuzz ``ratio`` (0-100) of a whole name core to count as a fuzzy match."""
TOKEN_MIN_RATIO = 80.0
"""Least ``ratio`` for correcting one word of five letters or more to a word of the map."""
SAME_JUNCTION_M = 60.0
"""Candidates of one name pair closer than this are one junction."""
GEOMETRIC_GAP_M = 15.0
"""Two streets whose lines pass this close without touching meet there (geometric)."""
MAX_MATCHES = 5

_LONG_TYPES = sorted(k for k in STREET_TYPES if len(k) >= 5)
_SCORES = {"exact": 1.0, "abbreviation": 0.97, "partial": 0.88}
_M_PER_DEG = 111_320.0


@dataclass(frozen=True)
class NameHit:
    """One OSM name a title's name matched.

    Attributes
    ----------
    tokens
        The OSM name's canonical tokens (the index key).
    display
        The OSM name as tagged.
    kind
        ``"exact"``, ``"abbreviation"``, ``"partial"`` or ``"fuzzy"``.
    score
        In (0, 1]; fuzzy: rapidfuzz ratio / 100 times 0.8.
    """

    tokens: tuple[str, ...]
    display: str
    kind: str
    score: float


@dataclass
class TitleMatch:
    """One place a title may name.

    Attributes
    ----------
    status
        ``junction``, ``street`` (one name: the street's geometry, no point), ``address``
        (OSM ``addr:*`` point, else the street's geometry), ``landmark`` (a named OSM
        feature), ``ambiguous`` (one of several equally good junctions, all returned) or
        ``not_found``.
    lat, lon
        The point, degrees WGS 84, or None (street, not found).
    uncertainty_m
        Radius within which the camera's junction lies (the junction's size), or None.
    intersection
        The junction of the map's model, or None (geometric junction, street, landmark).
    names_read
        The names read from the title.
    names_matched
        The OSM name each matched ("" where none).
    match_kinds
        How each matched: ``exact``, ``abbreviation``, ``partial``, ``fuzzy`` or ``none``.
    name_scores
        Each name's score in [0, 1].
    score
        The match's score in [0, 1] (product of the names' scores).
    reason
        What was done or what failed, in words.
    geometry
        GeoJSON geometry (a Point, or the street's MultiLineString), or None.
    title
        The title as given.
    parsed
        The parsed title.
    source
        The map's source (extract path).
    """

    status: str
    lat: float | None = None
    lon: float | None = None
    uncertainty_m: float | None = None
    intersection: Intersection | None = field(default=None, repr=False)
    names_read: list[str] = field(default_factory=list)
    names_matched: list[str] = field(default_factory=list)
    match_kinds: list[str] = field(default_factory=list)
    name_scores: list[float] = field(default_factory=list)
    score: float = 0.0
    reason: str = ""
    geometry: dict[str, Any] | None = field(default=None, repr=False)
    title: str = ""
    parsed: ParsedTitle | None = field(default=None, repr=False)
    source: str = ""
    suggestions: dict[str, list[str]] = field(default_factory=dict)

    @property
    def placed(self) -> bool:
        """Whether the match has a point."""
        return self.lat is not None and self.lon is not None

    def to_properties(self) -> dict[str, Any]:
        """JSON-ready properties (everything but the geometry)."""
        parsed = self.parsed
        inter = self.intersection
        return {
            "title": self.title,
            "status": self.status,
            "lat": self.lat,
            "lon": self.lon,
            "uncertainty_m": None if self.uncertainty_m is None else round(self.uncertainty_m, 1),
            "score": round(self.score, 4),
            "names_read": list(self.names_read),
            "names_matched": list(self.names_matched),
            "match_kinds": list(self.match_kinds),
            "name_scores": [round(s, 4) for s in self.name_scores],
            "intersection_id": inter.id if inter is not None else None,
            "osm_nodes": list(inter.osm_nodes) if inter is not None else [],
            "intersection_streets": list(inter.street_names) if inter is not None else [],
            "reason": self.reason,
            "suggestions": {k: list(v) for k, v in self.suggestions.items()},
            "camera_number": parsed.camera_number if parsed else None,
            "house_number": parsed.house_number if parsed else None,
            "view_bearing_deg": parsed.view_bearing_deg if parsed else None,
            "compass_text": parsed.compass_text if parsed else None,
            "notes": list(parsed.notes) if parsed else [],
            "source": self.source,
        }

    def to_feature(self) -> dict[str, Any]:
        """A GeoJSON Feature: the point (or the street's lines, or no geometry)."""
        geometry = self.geometry
        if self.placed:
            geometry = {"type": "Point", "coordinates": [self.lon, self.lat]}
        return {"type": "Feature", "geometry": geometry, "properties": self.to_properties()}


# -- name matching -----------------------------------------------------------------------


def _fuzzy_token(tok: str, index: GeocodeIndex, last: bool) -> tuple[str, float] | None:
    """The map word (or street type) a misspelt word stands for, with its ratio."""
    from rapidfuzz import fuzz, process
    from rapidfuzz.distance import Levenshtein

    if tok.isdigit():
        return None
    if len(tok) >= 5:
        best = process.extractOne(tok, index.vocab, scorer=fuzz.ratio, score_cutoff=TOKEN_MIN_RATIO)
        typ = process.extractOne(tok, _LONG_TYPES, scorer=fuzz.ratio, score_cutoff=TOKEN_MIN_RATIO)
        if typ is not None and (best is None or typ[1] > best[1]):
            return STREET_TYPES[str(typ[0])], float(typ[1])  # "Aveida" -> avenue
        if best is not None:
            return str(best[0]), float(best[1])
    if last and 2 <= len(tok) <= 4:
        # a misspelt street type at the end ("Stb", "Avw")
        options = [k for k in STREET_TYPES if abs(len(k) - len(tok)) <= 1 and len(k) >= 2]
        close = [k for k in options if Levenshtein.distance(tok, k) <= 1]
        if len(close) >= 1:
            k = min(close, key=lambda k: (Levenshtein.distance(tok, k), -len(k)))
            return STREET_TYPES[k], 75.0
    return None


def _compatible(q_toks: tuple[str, ...], m_toks: tuple[str, ...]) -> float | None:
    """Score factor for a core match, None when the directionals disagree."""
    qd, md = directionals_of(q_toks), directionals_of(m_toks)
    if qd and md and qd != md:
        return None
    if qd and not md and core_tokens(m_toks) == m_toks:
        return None  # "North X" asked, the map's X has no directional: another street
    qt, mt = types_of(q_toks), types_of(m_toks)
    if qt and mt and not (qt & mt):
        return 0.75 / 0.88
    return 1.0


def _lookup(
    toks: tuple[str, ...], raw: str, index: GeocodeIndex, kind_cap: str | None = None
) -> list[NameHit]:
    hits: dict[tuple[str, ...], NameHit] = {}
    raw_fold = fold(raw)
    if toks in index.displays:
        for shown in index.displays[toks]:
            kind = "exact" if fold(shown) == raw_fold else "abbreviation"
            hit = NameHit(toks, shown, kind, _SCORES[kind])
            if toks not in hits or hits[toks].score < hit.score:
                hits[toks] = hit
    core = core_tokens(toks)
    same_core = index.by_core.get(core, ())
    q_types = types_of(toks)
    # The title names a street type the map has for this core ("2nd Avenue", and the map has
    # a 2nd Avenue): a name of that core with only other types ("South 2nd Street") is
    # another street, not a loose spelling of it.
    typed_exists = bool(q_types) and any(types_of(full) & q_types for full in same_core)
    for full in same_core:
        if full in hits:
            continue
        if typed_exists and types_of(full) and not (types_of(full) & q_types):
            continue
        factor = _compatible(toks, full)
        if factor is None:
            continue
        hits[full] = NameHit(full, index.display(full), "partial", _SCORES["partial"] * factor)
    out = list(hits.values())
    if kind_cap is not None:
        out = [NameHit(h.tokens, h.display, kind_cap, h.score * 0.85) for h in out]
    return out


def match_name(name: str, index: GeocodeIndex) -> list[NameHit]:
    """The OSM street names a name read from a title matches, best first.

    Parameters
    ----------
    name
        A street name as written in a title ("E Biddle St", "Karl-Liebknecht-Str.").
    index
        The map's name index (:func:`~camloc_geo.geocode._index.index_for`).

    Returns
    -------
    Hits, best score first; empty when nothing is close enough.
    """
    key = ("name", name)
    cached = index.cache.get(key)
    if cached is not None:
        return list(cached)
    toks = name_tokens(name)
    hits = _lookup(toks, name, index) if toks else []
    if not hits and toks:
        hits = _fuzzy(toks, name, index)
    hits.sort(key=lambda h: (-h.score, h.display))
    with index.lock:
        if len(index.cache) > 200_000:
            index.cache.clear()
        index.cache[key] = tuple(hits)
    return hits


def _fuzzy(toks: tuple[str, ...], name: str, index: GeocodeIndex) -> list[NameHit]:
    from rapidfuzz import fuzz, process

    vocab = index.vocab_set
    # 1. word by word against the map's words
    fixed = list(toks)
    ratios: list[float] = []
    changed = False
    for i, tok in enumerate(toks):
        if tok in vocab or tok in STREET_TYPES.values() or tok.isdigit():
            continue
        if tok in {"north", "south", "east", "west", "saint", "sainte"}:
            continue
        best = _fuzzy_token(tok, index, last=i == len(toks) - 1)
        if best is not None:
            fixed[i] = best[0]
            ratios.append(best[1])
            changed = True
    if changed:
        hits = _lookup(tuple(fixed), name, index)
        if hits:
            ratio = min(ratios) / 100.0
            return [NameHit(h.tokens, h.display, "fuzzy", h.score * ratio * 0.85) for h in hits]
    core = " ".join(core_tokens(toks))
    if len(core) < 6:
        return []  # one edit in a short name is another name
    out: list[NameHit] = []
    # 2. the whole name, spaces dropped, against the map's names ("Münzsraße")
    compact = "".join(toks)
    for choice, ratio, _i in process.extract(
        compact, index.compact_choices, scorer=fuzz.ratio, score_cutoff=FUZZY_MIN_RATIO, limit=3
    ):
        full = index.compact_full[str(choice)]
        factor = _compatible(toks, full)
        if factor is not None:
            out.append(NameHit(full, index.display(full), "fuzzy", 0.8 * ratio / 100.0 * factor))
    # 3. the core against the map's cores (the street type or directional differs too)
    for choice, ratio, _i in process.extract(
        core, index.core_choices, scorer=fuzz.ratio, score_cutoff=FUZZY_MIN_RATIO, limit=5
    ):
        for full in index.by_core.get(tuple(str(choice).split()), ()):
            factor = _compatible(toks, full)
            if factor is None:
                continue
            out.append(NameHit(full, index.display(full), "fuzzy", 0.8 * ratio / 100.0 * factor))
    by_name: dict[tuple[str, ...], NameHit] = {}
    for hit in out:
        if hit.tokens not in by_name or by_name[hit.tokens].score < hit.score:
            by_name[hit.tokens] = hit
    return list(by_name.values())


def suggestions_for(name: str, index: GeocodeIndex, n: int = 5) -> list[str]:
    """The map's names closest in spelling to a name (for ``not_found`` messages).

    Kept in the index's cache: a batch asks again for every title naming the street, in
    every extract that lacks it.
    """
    from rapidfuzz import fuzz, process

    query = " ".join(name_tokens(name))
    if not query or not index.full_choices:
        return []
    key = ("suggest", query, n)
    cached = index.cache.get(key)
    if cached is not None:
        return list(cached)
    found = process.extract(query, index.full_choices, scorer=fuzz.WRatio, limit=n)
    out = [index.display(tuple(str(c).split())) for c, _s, _i in found]
    with index.lock:
        if len(index.cache) > 200_000:
            index.cache.clear()
        index.cache[key] = tuple(out)
    return out


def _landmark_hits(name: str, index: GeocodeIndex) -> list[tuple[Landmark, str, float]]:
    """Named OSM features a name reads as, best first.

    A name with a street type ("Bar Ave", "Foo St") names a street: it matches a feature
    only by its whole name (a feature called "Bar Avenue"), never by its core, so that a bar
    called "Bar" never stands in for "Bar Ave".
    """
    from rapidfuzz import fuzz, process

    toks = name_tokens(name)
    if not toks or not any(len(t) >= 3 and not t.isdigit() for t in core_tokens(toks)):
        return []  # a landmark needs a word: "2", "St" name nothing
    out: list[tuple[Landmark, str, float]] = []
    raw_fold = fold(name)
    for mark in index.landmarks.get(toks, ()):
        kind = "exact" if fold(mark.name) == raw_fold else "abbreviation"
        out.append((mark, kind, _SCORES[kind]))
    if types_of(toks):
        return out  # a street's name: the feature's whole name or nothing
    if not out:
        for full in index.landmark_core.get(core_tokens(toks), ()):
            for mark in index.landmarks.get(full, ()):
                out.append((mark, "partial", _SCORES["partial"]))
    if not out and len(" ".join(toks)) >= 5:
        for choice, ratio, _i in process.extract(
            " ".join(toks),
            index.landmark_choices,
            scorer=fuzz.ratio,
            score_cutoff=FUZZY_MIN_RATIO,
            limit=3,
        ):
            for mark in index.landmarks.get(tuple(str(choice).split()), ()):
                out.append((mark, "fuzzy", 0.8 * ratio / 100.0))
    return out


# -- geometry helpers ----------------------------------------------------------------------


def _dist_m(lat0: float, lon0: float, lat: float, lon: float) -> float:
    return great_circle_m(lat1=lat0, lon1=lon0, lat2=lat, lon2=lon)


def _junction_size_m(inter: Intersection, map_data: MapData, index: GeocodeIndex) -> float:
    key = ("size", inter.id)
    cached: float | None = index.cache.get(key)
    if cached is not None:
        return cached
    G = map_data.graph
    spread = 0.0
    for n in inter.osm_nodes:
        if n in G:
            node = G.nodes[n]
            spread = max(spread, _dist_m(inter.lat, inter.lon, node["y"], node["x"]))
    half_width = max((s.width_m for s in inter.streets), default=10.0) / 2.0
    size = max(8.0, spread + half_width)
    index.cache[key] = size
    return size


def _street_geometry(lines: list[LineString]) -> dict[str, Any] | None:
    if not lines:
        return None
    merged = shapely.line_merge(MultiLineString([list(line.coords) for line in lines]))
    return dict(mapping(merged))


# -- the geocoder ------------------------------------------------------------------------


@dataclass
class _Candidate:
    lat: float
    lon: float
    score: float
    hits: tuple[NameHit, ...]
    intersection: Intersection | None
    uncertainty_m: float
    how: str
    dist_m: float = 0.0


def _junction_candidates(
    a: list[NameHit], b: list[NameHit], index: GeocodeIndex, map_data: MapData
) -> list[_Candidate]:
    inters = index.intersections
    best_a: dict[int, dict[int, NameHit]] = {}
    for hit in a:
        for i, j in index.junctions.get(hit.tokens, ()):
            slot = best_a.setdefault(i, {})
            if j not in slot or slot[j].score < hit.score:
                slot[j] = hit
    out: list[_Candidate] = []
    best_b: dict[int, dict[int, NameHit]] = {}
    for hit in b:
        for i, j in index.junctions.get(hit.tokens, ()):
            if i not in best_a:
                continue
            slot = best_b.setdefault(i, {})
            if j not in slot or slot[j].score < hit.score:
                slot[j] = hit
    for i, slot_b in best_b.items():
        slot_a = best_a[i]
        best: tuple[float, NameHit, NameHit] | None = None
        for ja, ha in slot_a.items():
            for jb, hb in slot_b.items():
                if ja == jb or ha.tokens == hb.tokens:
                    continue
                s = ha.score * hb.score
                if best is None or s > best[0]:
                    best = (s, ha, hb)
        if best is None:
            continue
        inter = inters[i]
        size = _junction_size_m(inter, map_data, index)
        lat, lon = inter.lat, inter.lon
        how = "junction of the map's model"
        if len(inter.osm_nodes) > 1:
            # a consolidated cluster: the nodes the two streets share inside it, if any
            shared = [
                (x, y)
                for x, y in _vertices(best[1].tokens, index) & _vertices(best[2].tokens, index)
                if _dist_m(inter.lat, inter.lon, y, x) <= size
            ]
            if shared:
                lon = sum(x for x, _y in shared) / len(shared)
                lat = sum(y for _x, y in shared) / len(shared)
                how += ", at the nodes the two streets share"
        out.append(
            _Candidate(
                lat=lat,
                lon=lon,
                score=best[0],
                hits=(best[1], best[2]),
                intersection=inter,
                uncertainty_m=size,
                how=how,
            )
        )
    return out


def _vertices(tokens: tuple[str, ...], index: GeocodeIndex) -> frozenset[tuple[float, float]]:
    """The street's vertices (lon, lat rounded to 1e-7 deg), cached in the index."""
    key = ("vertices", tokens)
    found: frozenset[tuple[float, float]] | None = index.cache.get(key)
    if found is None:
        found = frozenset(
            (round(x, 7), round(y, 7))
            for line in index.lines.get(tokens, ())
            for x, y in line.coords
        )
        index.cache[key] = found
    return found


def _shapes(tokens: tuple[str, ...], index: GeocodeIndex) -> tuple[Any, Any, float]:
    """The street's lines as one geometry, its line ends, metres per degree of longitude."""
    key = ("shapes", tokens)
    found: tuple[Any, Any, float] | None = index.cache.get(key)
    if found is None:
        lines = index.lines.get(tokens, [])
        geom = shapely.multilinestrings(lines)
        ends = shapely.multipoints([p for line in lines for p in (line.coords[0], line.coords[-1])])
        kx = _M_PER_DEG * math.cos(math.radians(lines[0].coords[0][1])) if lines else _M_PER_DEG
        found = (geom, ends, kx)
        index.cache[key] = found
    return found


def _geometric_candidates(
    a: list[NameHit], b: list[NameHit], index: GeocodeIndex
) -> list[_Candidate]:
    """Where the two streets' own lines share a node, or one ends next to the other.

    A shared OSM node is a junction whatever the junction model made of it (named
    ``service`` streets, pedestrian segments, a bend where the name changes). Lines that
    merely cross (a bridge over a street) share no node and do not count; a street that
    ends within :data:`GEOMETRIC_GAP_M` of the other (a way cut at the extract's edge, a
    gap in the data) does.
    """
    out: list[_Candidate] = []
    for ha in a:
        lines_a = index.lines.get(ha.tokens)
        if not lines_a:
            continue
        verts_a = _vertices(ha.tokens, index)
        for hb in b:
            if hb.tokens == ha.tokens:
                continue
            lines_b = index.lines.get(hb.tokens)
            if not lines_b:
                continue
            s = ha.score * hb.score
            shared = verts_a & _vertices(hb.tokens, index)
            points: list[tuple[float, float, float]] = [(x, y, 0.0) for x, y in shared]
            if not points:
                geom_a, ends_a, kx = _shapes(ha.tokens, index)
                geom_b, ends_b, _kx = _shapes(hb.tokens, index)
                if geom_a.distance(geom_b) * kx > GEOMETRIC_GAP_M * 1.5:
                    continue
                pa, pb = shapely.ops.nearest_points(geom_a, geom_b)
                gap = _dist_m(pa.y, pa.x, pb.y, pb.x)
                near_end = min(ends_a.distance(pa), ends_b.distance(pb)) * kx < 1.0
                if gap <= GEOMETRIC_GAP_M and near_end:
                    points.append(((pa.x + pb.x) / 2.0, (pa.y + pb.y) / 2.0, gap))
            for lon, lat, gap in points:
                out.append(
                    _Candidate(
                        lat=lat,
                        lon=lon,
                        score=s,
                        hits=(ha, hb),
                        intersection=None,
                        uncertainty_m=15.0 + gap,
                        how=(
                            "a node the two streets share (the junction model lacks it)"
                            if gap == 0.0
                            else f"where one street ends {gap:.0f} m from the other "
                            "(the junction model lacks it)"
                        ),
                    )
                )
    return out


def _group(cands: list[_Candidate]) -> list[_Candidate]:
    """One candidate per place: those of one name pair within :data:`SAME_JUNCTION_M` of the
    group's best merge.

    The merged candidate keeps the best member's junction (a model junction before a
    geometric one) and sits at the members' mean position (the two clusters of a dual
    carriageway crossing become its centre).
    """
    groups: list[list[_Candidate]] = []
    for c in cands:
        pair = frozenset(h.tokens for h in c.hits)
        for g in groups:
            if (
                frozenset(h.tokens for h in g[0].hits) == pair
                and _dist_m(g[0].lat, g[0].lon, c.lat, c.lon) < SAME_JUNCTION_M
            ):
                g.append(c)
                break
        else:
            groups.append([c])
    out: list[_Candidate] = []
    for g in groups:
        best = g[0]
        if len(g) > 1:
            model = [c for c in g if c.intersection is not None] or g
            best = model[0]
            lat = sum(c.lat for c in model) / len(model)
            lon = sum(c.lon for c in model) / len(model)
            spread = max(_dist_m(lat, lon, c.lat, c.lon) for c in model)
            best = _Candidate(
                lat=lat,
                lon=lon,
                score=max(c.score for c in g),
                hits=best.hits,
                intersection=best.intersection,
                uncertainty_m=max(c.uncertainty_m for c in model) + spread,
                how=best.how + (f" ({len(model)} nodes merged)" if len(model) > 1 else ""),
                dist_m=best.dist_m,
            )
        out.append(best)
    return out


def _base(parsed: ParsedTitle, title: str, map_data: MapData) -> dict[str, Any]:
    return {"title": title, "parsed": parsed, "source": str(map_data.source or "")}


def _not_found(
    parsed: ParsedTitle, title: str, map_data: MapData, reason: str, **extra: Any
) -> TitleMatch:
    return TitleMatch(
        status="not_found",
        reason=reason,
        names_read=list(parsed.streets),
        **extra,
        **_base(parsed, title, map_data),
    )


def check_near(near: object, radius_m: object) -> tuple[tuple[float, float] | None, float | None]:
    """``near`` as a ``(lat, lon)`` pair of floats and ``radius_m`` as a float, or an
    :class:`InputError` naming the one that is wrong."""
    point: tuple[float, float] | None = None
    if near is not None:
        try:
            lat0, lon0 = (float(v) for v in near)  # type: ignore[attr-defined]
        except (TypeError, ValueError):
            raise InputError(f"near must be (lat, lon) in degrees, got {near!r}") from None
        if not (-90.0 <= lat0 <= 90.0 and -180.0 <= lon0 <= 180.0):
            raise InputError(f"near must be (lat, lon) in degrees, got {near!r}")
        point = (lat0, lon0)
    radius: float | None = None
    if radius_m is not None:
        try:
            radius = float(radius_m)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            radius = math.nan
        if isinstance(radius_m, bool) or not (math.isfinite(radius) and radius > 0):
            raise InputError(f"radius_m must be a positive number of metres, got {radius_m!r}")
    return point, radius


def check_map(map_data: object, name: str) -> None:
    """A :class:`MapDataError` when ``map_data`` is not a loaded map."""
    from camloc_geo.osm import MapData

    if not isinstance(map_data, MapData):
        raise MapDataError(
            f"{name} must be a MapData (camloc_geo.osm.load_map or "
            f"camloc_geo.geocode.whole_map), not {type(map_data).__name__}"
        )


def geocode_title(
    title: str,
    *,
    map_data: MapData,
    near: tuple[float, float] | None = None,
    radius_m: float | None = None,
    area: str | None = None,
) -> list[TitleMatch]:
    """Place a webcam title at the junction (street, address, landmark) it names.

    Parameters
    ----------
    title
        The title as published ("625 - Milton & E Biddle St", "N POTOMAC ST @ E FAYETTE ST",
        "Karl-Liebknecht-Str. / Wadzeckstr."); see :func:`parse_title`.
    map_data
        The map (:func:`camloc_geo.osm.load_map`; for a whole extract
        ``load_map(path, lat, lon, radius_m=None)``). Its name index is built on the first
        call and cached on it.
    near
        ``(lat, lon)``: rank by distance from it; with ``radius_m`` keep only what lies
        within that radius.
    radius_m
        Search radius around ``near`` (or the map's point), metres; None: the whole map.
    area
        A named area of the map (a place, a district, a landmark) to search around when no
        ``near`` is given (within ``radius_m``, default 1500 m).

    Returns
    -------
    Matches, best first; never empty (at least one ``not_found`` saying why).

    Raises
    ------
    InputError
        ``near`` not a ``(lat, lon)`` pair of numbers in range, ``radius_m`` not a positive
        number.
    MapDataError
        ``map_data`` is not a :class:`~camloc_geo.osm.MapData`, or ``area`` is not a named
        place of the map.
    """
    near, radius_m = check_near(near, radius_m)
    check_map(map_data, "map_data")
    index = index_for(map_data)
    if area and near is None:
        marks = _landmark_hits(area, index)
        if not marks:
            raise MapDataError(f"area {area!r} is not a named place of the map {map_data.source}")
        mark = max(marks, key=lambda m: m[2])[0]
        near = (mark.lat, mark.lon)
        radius_m = radius_m or 1500.0
    if near is None and radius_m is not None:
        near = (map_data.frame.lat0, map_data.frame.lon0)
    parsed = parse_title(title)
    title_text = title if isinstance(title, str) else str(title)
    names = parsed.streets
    if not names:
        why = _why_no_street(parsed, title)
        return [_not_found(parsed, title_text, map_data, f"no street name in the title ({why})")]
    hits = [match_name(n, index) for n in names]
    if len(names) >= 2:
        return _two_names(parsed, title_text, names, hits, index, map_data, near, radius_m)
    return _one_name(parsed, title_text, names[0], hits[0], index, map_data, near, radius_m)


def _why_no_street(parsed: ParsedTitle, title: Any) -> str:
    """Why a title gave no street name: said for what the title holds (a title ``5`` said
    "empty title" though it is not empty)."""
    if parsed.notes:
        return parsed.notes[-1]
    raw = parsed.raw.strip()
    if not raw:
        return "empty title"
    kind = "" if isinstance(title, str) else f"the title is not text ({type(title).__name__}); "
    if parsed.camera_number and raw == parsed.camera_number:
        return f"{kind}it holds only a number, {raw!r}, read as a camera number"
    if parsed.compass_text:
        return f"{kind}it holds only a view direction, {parsed.compass_text!r}"
    return f"{kind}nothing name-like in {raw!r}"


def _filter_rank(
    cands: list[_Candidate], near: tuple[float, float] | None, radius_m: float | None
) -> list[_Candidate]:
    if near is not None:
        for c in cands:
            c.dist_m = _dist_m(near[0], near[1], c.lat, c.lon)
        if radius_m is not None:
            cands = [c for c in cands if c.dist_m <= radius_m]
    if near is not None:
        cands.sort(key=lambda c: (-round(c.score, 6), c.dist_m, c.intersection is None))
    else:
        cands.sort(key=lambda c: (-round(c.score, 6), c.intersection is None, c.lat, c.lon))
    return cands


def _two_names(
    parsed: ParsedTitle,
    title: str,
    names: list[str],
    hits: list[list[NameHit]],
    index: GeocodeIndex,
    map_data: MapData,
    near: tuple[float, float] | None,
    radius_m: float | None,
) -> list[TitleMatch]:
    pairs = [(i, j) for i in range(len(names)) for j in range(i + 1, len(names))]
    cands: list[tuple[int, int, _Candidate]] = []
    beyond: list[_Candidate] = []  # junctions of the names outside radius_m of near
    for i, j in pairs:
        if not hits[i] or not hits[j]:
            continue
        # the model's junctions first, then nodes the streets share that it lacks
        found = _junction_candidates(hits[i], hits[j], index, map_data)
        found += _geometric_candidates(hits[i], hits[j], index)
        kept = _filter_rank(found, near, radius_m)
        if near is not None and radius_m is not None and len(kept) < len(found):
            beyond.extend(c for c in found if c.dist_m > radius_m)
        cands.extend((i, j, c) for c in _group(kept))
    base = _base(parsed, title, map_data)
    if cands:
        cands.sort(key=lambda r: (-round(r[2].score, 6), r[2].dist_m))
        top = cands[0][2].score
        ties = [r for r in cands if abs(r[2].score - top) < 1e-9]
        ambiguous = len(ties) >= 2 and (
            near is None or abs(ties[1][2].dist_m - ties[0][2].dist_m) < SAME_JUNCTION_M
        )
        out: list[TitleMatch] = []
        for rank, (i, j, c) in enumerate(cands[:MAX_MATCHES]):
            status = "ambiguous" if ambiguous and abs(c.score - top) < 1e-9 else "junction"
            reason = c.how
            if status == "ambiguous":
                reason = f"{len(ties)} junctions match equally well; " + c.how
            elif rank > 0:
                reason = "alternative: " + c.how
            out.append(
                TitleMatch(
                    status=status,
                    lat=c.lat,
                    lon=c.lon,
                    uncertainty_m=c.uncertainty_m,
                    intersection=c.intersection,
                    names_read=[names[i], names[j]],
                    names_matched=[h.display for h in c.hits],
                    match_kinds=[h.kind for h in c.hits],
                    name_scores=[h.score for h in c.hits],
                    score=c.score,
                    reason=reason,
                    **base,
                )
            )
        return out
    # no junction: a landmark among the names (next to the other, named street), or say
    # what failed
    missing = [n for n, h in zip(names, hits, strict=True) if not h]
    if len(missing) < len(names):
        for n in missing:
            streets = [h for k, h in enumerate(hits) if h and names[k] != n]
            marks = _landmarks_by_street(_landmark_hits(n, index), streets, index)
            if marks:
                return _landmark_matches(parsed, title, n, marks, map_data, near, radius_m, index)
    suggestions = {n: suggestions_for(n, index) for n in missing}
    if missing:
        reason = "; ".join(
            f"{n!r} is not a street name of this map (closest: "
            + (", ".join(suggestions[n]) or "none")
            + ")"
            for n in missing
        )
    else:
        shown = [hits[k][0].display for k in range(len(names))]
        where = "" if radius_m is None else f" within {radius_m:.0f} m"
        reason = f"{' and '.join(repr(s) for s in shown)} do not meet in this map{where}"
        if beyond:
            nearest = min(beyond, key=lambda c: c.dist_m)
            reason += (
                f" of the point; they meet {nearest.dist_m:.0f} m away, at "
                f"{nearest.lat:.5f},{nearest.lon:.5f} (is the point or its radius off?)"
            )
    return [
        _not_found(
            parsed,
            title,
            map_data,
            reason,
            names_matched=[h[0].display if h else "" for h in hits],
            match_kinds=[h[0].kind if h else "none" for h in hits],
            name_scores=[h[0].score if h else 0.0 for h in hits],
            suggestions=suggestions,
        )
    ]


LANDMARK_STREET_M = 100.0
"""A title's landmark must lie this close to the street the title names with it."""


def _landmarks_by_street(
    marks: list[tuple[Landmark, str, float]], streets: list[list[NameHit]], index: GeocodeIndex
) -> list[tuple[Landmark, str, float]]:
    """The landmarks within :data:`LANDMARK_STREET_M` of a street the title also names.

    "Broadway @ City Hall" is the City Hall on Broadway; a feature that merely shares a name
    with a word of the title, away from its street, is not the place.
    """
    if not marks or not streets:
        return []
    out = []
    for mark, kind, score in marks:
        point = shapely.Point(mark.lon, mark.lat)
        kx = _M_PER_DEG * math.cos(math.radians(mark.lat))
        for hits in streets:
            geom = _shapes(hits[0].tokens, index)[0]
            if not geom.is_empty and geom.distance(point) * kx <= LANDMARK_STREET_M:
                out.append((mark, kind, score * hits[0].score))
                break
    return out


def _landmark_matches(
    parsed: ParsedTitle,
    title: str,
    name: str,
    marks: list[tuple[Landmark, str, float]],
    map_data: MapData,
    near: tuple[float, float] | None,
    radius_m: float | None,
    index: GeocodeIndex,
) -> list[TitleMatch]:
    rows = []
    for mark, kind, score in marks:
        d = 0.0 if near is None else _dist_m(near[0], near[1], mark.lat, mark.lon)
        if near is not None and radius_m is not None and d > radius_m:
            continue
        rows.append((-score, d, mark, kind, score))
    if not rows:
        return [_not_found(parsed, title, map_data, f"landmark {name!r} not within the radius")]
    rows.sort(key=lambda r: (r[0], r[1], r[2].osm_id))
    out = []
    seen: set[str] = set()
    for _s, _d, mark, kind, score in rows:
        if mark.osm_id in seen:
            continue
        seen.add(mark.osm_id)
        out.append(
            TitleMatch(
                status="landmark",
                lat=mark.lat,
                lon=mark.lon,
                uncertainty_m=25.0,
                names_read=[name],
                names_matched=[mark.name],
                match_kinds=[kind],
                name_scores=[score],
                score=score,
                reason=f"named OSM feature {mark.osm_id} ({mark.kind})",
                **_base(parsed, title, map_data),
            )
        )
        if len(out) >= MAX_MATCHES:
            break
    return out


def _one_name(
    parsed: ParsedTitle,
    title: str,
    name: str,
    hits: list[NameHit],
    index: GeocodeIndex,
    map_data: MapData,
    near: tuple[float, float] | None,
    radius_m: float | None,
) -> list[TitleMatch]:
    base = _base(parsed, title, map_data)
    if parsed.house_number and hits:
        number = fold(parsed.house_number).replace(" ", "")
        for hit in hits:
            addrs = index.addresses.get((hit.tokens, number), [])
            if addrs:
                mark = addrs[0]
                return [
                    TitleMatch(
                        status="address",
                        lat=mark.lat,
                        lon=mark.lon,
                        uncertainty_m=15.0,
                        names_read=[name],
                        names_matched=[hit.display],
                        match_kinds=[hit.kind],
                        name_scores=[hit.score],
                        score=hit.score,
                        reason=f"OSM address {mark.osm_id} ({mark.name})",
                        **base,
                    )
                ]
    street_best = hits[0].score if hits else 0.0
    marks = _landmark_hits(name, index)
    if marks and (not hits or max(m[2] for m in marks) > street_best):
        return _landmark_matches(parsed, title, name, marks, map_data, near, radius_m, index)
    if hits:
        out = []
        for hit in hits[:MAX_MATCHES]:
            lines = index.lines.get(hit.tokens, [])
            if near is not None and radius_m is not None:
                kx = _M_PER_DEG * math.cos(math.radians(near[0]))
                centre = shapely.Point(near[1], near[0])
                lines = [ln for ln in lines if ln.distance(centre) * kx <= radius_m]
                if not lines:
                    continue
            if parsed.house_number:
                status = "address"
                reason = (
                    f"house number {parsed.house_number} is not an OSM address of "
                    f"{hit.display}: the street's geometry, no point"
                )
            else:
                status = "street"
                reason = "one street name: the street's geometry, no point"
            out.append(
                TitleMatch(
                    status=status,
                    names_read=[name],
                    names_matched=[hit.display],
                    match_kinds=[hit.kind],
                    name_scores=[hit.score],
                    score=hit.score,
                    reason=reason,
                    geometry=_street_geometry(lines),
                    **base,
                )
            )
        if out:
            return out
    suggestions = {name: suggestions_for(name, index)}
    return [
        _not_found(
            parsed,
            title,
            map_data,
            f"{name!r} is neither a street nor a named feature of this map (closest: "
            + (", ".join(suggestions[name]) or "none")
            + ")",
            suggestions=suggestions,
            names_matched=[""],
            match_kinds=["none"],
            name_scores=[0.0],
        )
    ]
