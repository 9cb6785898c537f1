"""Out-of-process worker for the QGIS plugin: ``python -m camloc_geo.qgis.worker JOB.json``.

QGIS loads the system GEOS and PROJ into its process, and the shapely/pyproj wheels crash
there (``docs/qgis.md``). The plugin therefore runs every computation in a separate Python
that can import ``camloc_geo``: it writes a job file, starts this module, reads progress from
its standard output and loads the layers it writes. This module imports no qgis and no Qt,
and only the library's public API.

Job file (JSON object): ``task`` (``locate``, ``corners``, ``geocodelist``, ``measure``,
``check_scene``, ``annotation_page``, ``probe``), ``out_dir`` (folder for the output layers)
and the task's parameters (see the ``_task_*`` functions).

Standard output: one JSON object per line,

- ``{"progress": 0..100, "message": "..."}`` while working;
- ``{"ok": true, "layers": {NAME: {"path": ..., "geometry": ..., "fields": [[name, type], ...]}},
  "warnings": [...], "info": {...}}`` at the end;
- ``{"ok": false, "error": "...", "kind": "SceneError"}`` on failure (exit status 2 for bad input,
  1 for anything else). Never a traceback for bad input.

Output layers are GeoJSON FeatureCollections in EPSG:4326 with flat, typed properties (no nested
objects): field types are ``int``, ``double``, ``string`` and ``bool``.

Ties are the library's, carried as data: a candidate's ``ambiguous_with`` (the ranks it ties
with, decided by :data:`camloc_geo.results.TIE_SCORE_RATIO` and
:data:`camloc_geo.results.TIE_DISTANCE_M`); nothing here reads warning text or compares scores.
"""

from __future__ import annotations

import json
import math
import re
import sys
import traceback
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from camloc_geo import InputError, MapDataError
from camloc_geo.results import TIE_DISTANCE_M, TIE_SCORE_RATIO

__all__ = [
    "CANDIDATE_FIELDS",
    "TIE_DISTANCE_M",
    "TIE_SCORE_RATIO",
    "candidate_rows",
    "main",
    "run_job",
    "score_text",
    "user_words",
]


Field = tuple[str, str]

CANDIDATE_FIELDS: list[Field] = [
    ("rank", "int"),
    ("score", "double"),
    ("score_text", "string"),
    ("tie", "bool"),
    ("ambiguous_with", "string"),
    ("lat", "double"),
    ("lon", "double"),
    ("height_m", "double"),
    ("heading_deg", "double"),
    ("pitch_deg", "double"),
    ("roll_deg", "double"),
    ("focal_px", "double"),
    ("method", "string"),
    ("residual_m", "double"),
    ("sigma_m", "double"),
    ("scale", "double"),
    ("refined", "bool"),
    ("merged", "int"),
    ("n_matches", "int"),
    ("flags", "string"),
    ("scene", "string"),
]
CONE_FIELDS: list[Field] = [
    ("rank", "int"),
    ("score", "double"),
    ("score_text", "string"),
    ("tie", "bool"),
    ("leading", "bool"),
    ("scene", "string"),
]
MATCH_FIELDS: list[Field] = [
    ("rank", "int"),
    ("label", "string"),
    ("what", "string"),
    ("match_kind", "string"),
    ("pixel_x", "double"),
    ("pixel_y", "double"),
    ("misfit_m", "double"),
    ("map_corner", "string"),
    ("scene", "string"),
]
INTERSECTION_FIELDS: list[Field] = [
    ("kind", "string"),
    ("intersection", "string"),
    ("streets", "string"),
    ("order", "int"),
    ("intersection_kind", "string"),
]
CAMERA_FIELDS: list[Field] = [
    ("camera_id", "string"),
    ("title", "string"),
    ("status", "string"),
    ("reason", "string"),
    ("lat", "double"),
    ("lon", "double"),
    ("score", "double"),
    ("score_text", "string"),
    ("sigma_m", "double"),
    ("tie", "bool"),
    ("n_candidates", "int"),
    ("height_m", "double"),
    ("heading_deg", "double"),
    ("method", "string"),
    ("names_matched", "string"),
    ("match_score", "double"),
    ("extract", "string"),
]
LIST_CANDIDATE_FIELDS: list[Field] = [
    ("camera_id", "string"),
    ("rank", "int"),
    ("score", "double"),
    ("score_text", "string"),
    ("tie", "bool"),
    ("ambiguous_with", "string"),
    ("lat", "double"),
    ("lon", "double"),
    ("height_m", "double"),
    ("heading_deg", "double"),
    ("method", "string"),
    ("sigma_m", "double"),
    ("flags", "string"),
    ("source", "string"),
    ("match_score", "double"),
    ("extract", "string"),
]
STREET_FIELDS: list[Field] = [
    ("name", "string"),
    ("highway", "string"),
    ("width_m", "double"),
    ("oneway", "bool"),
]
BUILDING_FIELDS: list[Field] = [
    ("building_id", "string"),
    ("name", "string"),
    ("building", "string"),
    ("height_m", "double"),
]
LEADING_MIN_SCORE = 0.05
"""A candidate is *leading* (its view cone drawn at full strength) when it is the best, ties
with another, or scores at least this (candidate scores sum to 1 over a scene)."""


def _emit(obj: dict[str, Any]) -> None:
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()


def _progress(pct: float, message: str = "") -> None:
    _emit({"progress": round(float(pct), 1), "message": message})


def _num(value: Any) -> float | None:
    if value is None:
        return None
    v = float(value)
    return None if math.isnan(v) else v


def score_text(score: float | None) -> str | None:
    """A score as people read it: ``0.37``, ``0.0021``, ``1.2e-15`` (never cut to digits)."""
    if score is None or not math.isfinite(score):
        return None
    if score == 0.0:
        return "0"
    if abs(score) >= 0.01:
        return f"{score:.2f}"
    if abs(score) >= 1e-4:
        return f"{score:.2g}"
    return f"{score:.1e}"


_LABEL_WORDS = [
    (re.compile(r"^intersection\.corners\[(\d+)\]$"), "your kerb corner {0}"),
    (re.compile(r"^references\[(\d+)\]$"), "your reference point {0}"),
    (re.compile(r"^landmarks\[(\d+)\]$"), "your landmark {0}"),
]


def user_words(label: str | None) -> str | None:
    """A scene label in the analyst's words (``intersection.corners[0]``: kerb corner 0)."""
    if not label:
        return label
    prefix = ""
    if ":" in label:
        prefix, label = label.split(":", 1)
        prefix = prefix + " "
    for pattern, words in _LABEL_WORDS:
        m = pattern.match(label)
        if m:
            return prefix + words.format(*m.groups())
    return prefix + label


def _write_layer(
    out_dir: Path,
    name: str,
    geometry: str,
    fields: list[Field],
    features: Iterable[tuple[dict[str, Any] | None, dict[str, Any]]],
) -> dict[str, Any]:
    """Write ``(geometry, properties)`` pairs as GeoJSON; the layer's description for the plugin."""
    names = [f for f, _t in fields]
    feats = [
        {"type": "Feature", "geometry": geom, "properties": {k: props.get(k) for k in names}}
        for geom, props in features
    ]
    path = out_dir / f"{name}.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": feats}), encoding="utf-8")
    return {
        "path": str(path),
        "geometry": geometry,
        "fields": [list(f) for f in fields],
        "count": len(feats),
    }


def _ties(features: list[dict[str, Any]]) -> dict[int, list[int]]:
    """Rank -> the other ranks it ties with: the library's ``ambiguous_with``, nothing else."""
    out: dict[int, list[int]] = {}
    for f in features:
        p = f["properties"]
        given = p.get("ambiguous_with")
        if isinstance(given, list) and given:
            out[int(p["rank"])] = [int(o) for o in given]
    return out


def candidate_rows(gj: dict[str, Any]) -> list[tuple[dict[str, Any], dict[str, Any]]]:
    """Flat, typed rows of the candidate features of a locate GeoJSON (best first)."""
    cands = [f for f in gj["features"] if f["properties"].get("kind") == "candidate"]
    ties = _ties(cands)
    rows = []
    for f in cands:
        p = f["properties"]
        rank = int(p["rank"])
        others = ties.get(rank, [])
        score = _num(p.get("score"))
        rows.append(
            (
                f["geometry"],
                {
                    "rank": rank,
                    "score": score,
                    "score_text": score_text(score),
                    "tie": bool(others),
                    "ambiguous_with": ",".join(str(o) for o in others) or None,
                    "lat": _num(p.get("lat")),
                    "lon": _num(p.get("lon")),
                    "height_m": _num(p.get("height_m")),
                    "heading_deg": _num(p.get("heading_deg")),
                    "pitch_deg": _num(p.get("pitch_deg")),
                    "roll_deg": _num(p.get("roll_deg")),
                    "focal_px": _num(p.get("focal_px")),
                    "method": p.get("method"),
                    "residual_m": _num(p.get("residual_m")),
                    "sigma_m": _num(p.get("sigma_m")),
                    "scale": _num(p.get("scale")),
                    "refined": bool(p.get("refined")),
                    "merged": int(p.get("merged") or 0),
                    "n_matches": len(p.get("matches") or []),
                    "flags": ",".join(p.get("flags") or []) or None,
                    "scene": p.get("scene"),
                },
            )
        )
    return rows


def _leading(props: dict[str, Any]) -> bool:
    return bool(props["rank"] == 1 or props["tie"] or (props["score"] or 0.0) >= LEADING_MIN_SCORE)


def _locate_layers(gj: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    rows = candidate_rows(gj)
    by_rank = {props["rank"]: props for _g, props in rows}
    feats = gj["features"]
    cones = []
    for f in feats:
        if f["properties"].get("kind") != "view_cone":
            continue
        cand = by_rank.get(f["properties"]["rank"])
        score = _num(f["properties"].get("score"))
        cones.append(
            (
                f["geometry"],
                {
                    "rank": f["properties"]["rank"],
                    "score": score,
                    "score_text": score_text(score),
                    "tie": bool(cand and cand["tie"]),
                    "leading": bool(cand and _leading(cand)),
                    "scene": cand.get("scene") if cand else None,
                },
            )
        )
    matches = []
    for f in feats:
        p = f["properties"]
        if p.get("kind") != "matched_point":
            continue
        pixel = p.get("pixel") or [None, None]
        matches.append(
            (
                f["geometry"],
                {
                    "rank": p.get("rank"),
                    "label": p.get("label"),
                    "what": user_words(p.get("label")),
                    "match_kind": p.get("match_kind"),
                    "pixel_x": _num(pixel[0]),
                    "pixel_y": _num(pixel[1]),
                    "misfit_m": _num(p.get("misfit_m")),
                    "map_corner": p.get("map_corner"),
                    "scene": (by_rank.get(p.get("rank")) or {}).get("scene"),
                },
            )
        )
    return {
        "candidates": _write_layer(out_dir, "candidates", "Point", CANDIDATE_FIELDS, rows),
        "view_cones": _write_layer(out_dir, "view_cones", "Polygon", CONE_FIELDS, cones),
        "matched_corners": _write_layer(out_dir, "matched_corners", "Point", MATCH_FIELDS, matches),
        "intersection": _write_layer(
            out_dir, "intersection", "Point", INTERSECTION_FIELDS, _intersection_rows(feats)
        ),
    }


def _intersection_rows(feats: list[dict[str, Any]]) -> list[tuple[dict[str, Any], dict[str, Any]]]:
    rows = []
    for f in feats:
        p = f["properties"]
        kind = p.get("kind")
        if kind == "intersection":
            streets = list(dict.fromkeys(p.get("streets") or []))
            rows.append(
                (
                    f["geometry"],
                    {
                        "kind": "intersection",
                        "intersection": p.get("id"),
                        "streets": " & ".join(streets) or None,
                        "order": None,
                        "intersection_kind": p.get("intersection_kind") or p.get("kind_detail"),
                    },
                )
            )
        elif kind == "corner":
            rows.append(
                (
                    f["geometry"],
                    {
                        "kind": "corner",
                        "intersection": p.get("intersection"),
                        "streets": " & ".join(p.get("streets") or []) or None,
                        "order": p.get("order"),
                        "intersection_kind": None,
                    },
                )
            )
    return rows


def _context_layers(map_data: Any, out_dir: Path) -> dict[str, Any]:
    """The map model's streets and buildings (what locate matched against), for context."""
    from shapely.geometry import mapping

    streets = [
        (
            dict(mapping(s.geometry)),
            {
                "name": s.name or None,
                "highway": s.highway,
                "width_m": s.width_m,
                "oneway": s.oneway,
            },
        )
        for s in map_data.streets
    ]
    buildings = [
        (
            dict(mapping(b.footprint)),
            {
                "building_id": b.id,
                "name": b.name,
                "building": b.building,
                "height_m": _num(b.height_m),
            },
        )
        for b in map_data.buildings
    ]
    return {
        "context_streets": _write_layer(
            out_dir, "context_streets", "LineString", STREET_FIELDS, streets
        ),
        "context_buildings": _write_layer(
            out_dir, "context_buildings", "Polygon", BUILDING_FIELDS, buildings
        ),
    }


def _opt_float(job: dict[str, Any], key: str) -> float | None:
    v = job.get(key)
    return None if v in (None, "") else float(v)


def _task_locate(job: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """``scene`` (path or dict), ``osm`` (path or null), ``network``, ``radius_m``,
    ``max_candidates``, ``context`` (also the map model's streets and buildings)."""
    from camloc_geo.api import locate_scene

    _progress(5, "reading the scene and the map")
    max_c = job.get("max_candidates")
    out = locate_scene(
        job["scene"],
        map_source=job.get("osm") or None,
        network=bool(job.get("network", False)),
        radius_m=_opt_float(job, "radius_m"),
        max_candidates=int(max_c) if max_c else None,
    )
    _progress(80, "writing the layers")
    gj = out.to_geojson()
    props = gj.get("properties", {})
    layers = _locate_layers(gj, out_dir)
    if job.get("context") and out.map_data is not None:
        layers.update(_context_layers(out.map_data, out_dir))
    return {
        "layers": layers,
        "warnings": list(props.get("warnings") or []),
        "info": {"n_candidates": props.get("n_candidates"), "reason": props.get("reason")},
    }


_EXTRACT_COVERS = re.compile(
    r"is outside the extract .*cover lat (-?[\d.]+)\.\.(-?[\d.]+), lon (-?[\d.]+)\.\.(-?[\d.]+)\)"
)


def swapped_point_hint(message: str, lat: float, lon: float) -> str | None:
    """The hint for a point given as lat,lon where QGIS reads x,y (lon,lat), or None.

    ``qgis_process run camloc:corners --POINT="39.2857,-76.5933 [EPSG:4326]"`` (lat first, as
    people write a place) reached the library as lat -76.59, lon 39.29 and was refused as
    "outside the extract" with no word that the two were swapped (session 41 QA). Where the
    library's message says the point is outside an extract and the point with its latitude and
    longitude swapped is inside it, this names the point as QGIS wants it.

    Parameters
    ----------
    message : str
        The library's error (``camloc_geo.osm``'s "point lat=..., lon=... is outside the
        extract NAME (its streets and buildings cover lat S..N, lon W..E)").
    lat, lon : float
        The point as the job gave it (degrees).

    Returns
    -------
    str or None
        The hint, or None where the message is another or the swapped point is outside too.
    """
    m = _EXTRACT_COVERS.search(message)
    if m is None:
        return None
    south, north, west, east = (float(v) for v in m.groups())
    if not (south <= lon <= north and west <= lat <= east):
        return None
    return (
        f"latitude and longitude swapped? A POINT is x,y, longitude first: "
        f"'{lat:.6f},{lon:.6f} [EPSG:4326]' is lat={lon:.6f}, lon={lat:.6f}, inside the extract"
    )


def _task_corners(job: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """``lat``, ``lon``, ``radius_m``, ``osm``, ``network``, ``streets`` (``"A & B"`` or null)."""
    from camloc_geo.api import corners_near

    _progress(5, "reading the map")
    lat, lon = float(job["lat"]), float(job["lon"])
    try:
        gj = corners_near(
            lat=lat,
            lon=lon,
            radius_m=float(job.get("radius_m") or 150.0),
            map_source=job.get("osm") or None,
            network=bool(job.get("network", False)),
            streets=job.get("streets") or None,
        )
    except MapDataError as exc:
        hint = swapped_point_hint(str(exc), lat, lon)
        if hint is None:
            raise
        raise MapDataError(f"{exc}; {hint}") from exc
    _progress(80, "writing the layers")
    layer = _write_layer(
        out_dir, "corners", "Point", INTERSECTION_FIELDS, _intersection_rows(gj["features"])
    )
    return {"layers": {"corners": layer}, "warnings": [], "info": {"count": layer["count"]}}


# --- webcam lists: the library's camera-list engine (camloc_geo.batch) ----------------------


def _camera_rows(result: Any) -> tuple[dict[str, Any], list[tuple[dict[str, Any], dict[str, Any]]]]:
    """The cameras-layer properties and candidate rows of one ``CameraResult`` of the batch."""
    cam_id = str(result.id)
    rows: list[tuple[dict[str, Any], dict[str, Any]]] = []
    for c in result.candidates:
        lat, lon = _num(c.get("lat")), _num(c.get("lon"))
        if lat is None or lon is None:
            continue  # a title match without a point (a street, a name not found)
        others = [int(o) for o in c.get("ambiguous_with") or []]
        score = _num(c.get("score"))
        rows.append(
            (
                {"type": "Point", "coordinates": [lon, lat]},
                {
                    "camera_id": cam_id,
                    "rank": int(c.get("rank") or len(rows) + 1),
                    "score": score,
                    "score_text": score_text(score),
                    "tie": bool(others),
                    "ambiguous_with": ",".join(str(o) for o in others) or None,
                    "lat": lat,
                    "lon": lon,
                    "height_m": _num(c.get("height_m")),
                    "heading_deg": _num(c.get("heading_deg")),
                    "method": c.get("method"),
                    "sigma_m": _num(c.get("uncertainty_m")),
                    "flags": c.get("detail"),
                    "source": c.get("source"),
                    "match_score": _num(c.get("match_score")),
                    "extract": c.get("extract"),
                },
            )
        )
    score = _num(result.score)
    props = {
        "camera_id": cam_id,
        "title": result.title or None,
        "status": result.status,
        # (the library's hints in the dialog's words: "give --osm EXTRACT_OR_FOLDER" named
        # an option the Processing dialog does not have)
        "reason": processing_words(result.reason) if result.reason else result.reason,
        "lat": _num(result.lat),
        "lon": _num(result.lon),
        "score": score,
        "score_text": score_text(score),
        "sigma_m": _num(result.uncertainty_m),
        "tie": bool(result.tie),
        "n_candidates": int(result.n_candidates),  # the engine's count, as camloc batch
        "height_m": _num(result.height_m),
        "heading_deg": _num(result.heading_deg),
        "method": result.method,
        "names_matched": " & ".join(result.names_matched) or None,
        "match_score": _num(getattr(result, "match_score", None)),
        "extract": result.extract,
    }
    return props, rows


def _task_geocodelist(job: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """``list`` (CSV or GeoJSON camera list), ``osm`` (an extract or a folder), ``network``.

    The list runs through :func:`camloc_geo.batch.run_batch`, the engine of ``camloc batch``,
    in this process: the same rows, statuses and answers as the command line.
    """
    from camloc_geo.batch import read_camera_list, results_from_journal, run_batch

    path = Path(job["list"])
    if not path.is_file():
        raise InputError(f"camera list not found: {path}")
    osm = job.get("osm") or None
    if osm and not Path(osm).exists():
        raise InputError(f"OSM extract or folder not found: {osm}")
    n = sum(1 for _row in read_camera_list(path))
    _progress(2, f"{n} camera(s) in {path.name}")
    work = out_dir / "batch"
    work.mkdir(parents=True, exist_ok=True)
    out_gpkg = work / "cameras.gpkg"

    def on_chunk(done: int) -> None:
        _progress(5 + 90.0 * done / max(n, 1), f"camera {done}/{n}")

    summary = run_batch(
        path,
        out_gpkg=out_gpkg,
        map_source=osm,
        network=bool(job.get("network", False)),
        progress=False,
        workers=1,
        chunk_size=max(1, min(50, n // 20 or 1)),
        restart=True,
        on_chunk=on_chunk,
    )
    cameras: list[tuple[dict[str, Any] | None, dict[str, Any]]] = []
    candidates: list[tuple[dict[str, Any], dict[str, Any]]] = []
    for result in results_from_journal(out_gpkg):
        props, rows = _camera_rows(result)
        geom = (
            {"type": "Point", "coordinates": [props["lon"], props["lat"]]}
            if props["lat"] is not None and props["lon"] is not None
            else None
        )
        cameras.append((geom, props))
        candidates.extend(rows)
    statuses: dict[str, int] = {}
    for _g, p in cameras:
        statuses[p["status"]] = statuses.get(p["status"], 0) + 1
    return {
        "layers": {
            "cameras": _write_layer(out_dir, "cameras", "Point", CAMERA_FIELDS, cameras),
            "candidates": _write_layer(
                out_dir, "list_candidates", "Point", LIST_CANDIDATE_FIELDS, candidates
            ),
        },
        # what camloc batch says on stderr (camera ids used on more than one row)
        "warnings": list(summary.warnings),
        "info": {"engine": "camloc_geo.batch", "n_cameras": len(cameras), "statuses": statuses},
    }


_MEASURE_KINDS = ("distance", "height")


def _measure_pairs(pairs: Any) -> list[dict[str, Any]]:
    """``PAIRS`` checked item by item: a clear one-line error naming the item and the fault."""
    example = '[{"kind": "distance", "a": [x, y], "b": [x, y]}]'
    if not isinstance(pairs, list) and pairs is not None:
        raise InputError(f"PAIRS must be a JSON list like {example}")
    if not pairs:
        # (an empty PAIRS wrote an empty measurements table without a word)
        raise InputError(f"PAIRS has no pair: nothing to measure; give a JSON list like {example}")
    out: list[dict[str, Any]] = []
    for i, item in enumerate(pairs):
        if not isinstance(item, dict):
            raise InputError(f"PAIRS item {i}: must be an object like {example}")
        kind = item.get("kind", "distance")
        if kind not in _MEASURE_KINDS:
            raise InputError(
                f"PAIRS item {i}: kind {kind!r} is not one of {', '.join(_MEASURE_KINDS)}"
            )
        ends = []
        for end in ("a", "b"):
            px = item.get(end)
            if (
                not isinstance(px, list)
                or len(px) != 2
                or not all(
                    isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                    for v in px
                )
            ):
                raise InputError(
                    f"PAIRS item {i}: '{end}' must be a pixel [x, y] of two numbers, got {px!r}"
                )
            ends.append([float(v) for v in px])
        out.append({"kind": kind, "a": ends[0], "b": ends[1]})
    return out


def _task_measure(job: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """``scene``; ``pairs``: list of ``{"kind": "distance"|"height", "a": [x, y], "b": [x, y]}``."""
    import importlib

    from camloc_geo.api import calibrate_scene

    sensors: Any = importlib.import_module("camloc_geo.sensors")

    pairs = _measure_pairs(job.get("pairs"))
    cal = calibrate_scene(job["scene"])
    rows: list[tuple[dict[str, Any] | None, dict[str, Any]]] = []
    pair_warnings: list[str] = []
    for i, item in enumerate(pairs):
        a, b = item["a"], item["b"]
        try:
            if item["kind"] == "height":
                m = sensors.point_height(cal, a, b)
            else:
                m = sensors.ground_distance(cal, [a, b])
        except InputError as exc:
            # which pair: "ground: pixel (1e+308, 631) is far outside..." named none
            raise type(exc)(f"PAIRS item {i}: {exc}") from None
        # a pair near the horizon: its sigma is a lower bound (Measurement.warnings)
        pair_warnings += [f"PAIRS item {i}: {w}" for w in getattr(m, "warnings", ())]
        # the library's Measurement holds ``value_m`` (``to_dict`` names it distance_m or
        # height_m); reading those names as attributes gave a null value in every row
        value = m.value_m
        rows.append(
            (
                None,
                {
                    "index": i,
                    "kind": item["kind"],
                    "value_m": _num(value),
                    "sigma_m": _num(getattr(m, "sigma_m", None)),
                },
            )
        )
    fields: list[Field] = [
        ("index", "int"),
        ("kind", "string"),
        ("value_m", "double"),
        ("sigma_m", "double"),
    ]
    return {
        "layers": {"measurements": _write_layer(out_dir, "measurements", "None", fields, rows)},
        # the calibration's (a missing photo, an annotator left out, a loose focal length):
        # what the measurements rest on; the Processing log had none of them
        "warnings": [*cal.warnings, *pair_warnings],
        "info": {},
    }


def _task_check_scene(job: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """``scene`` (dict or path): validate (``info.scene``: normalised); ``save_to``: write it."""
    from camloc_geo.api import scene_from

    sc = scene_from(job["scene"])
    data = sc.model_dump(mode="json", exclude_none=True)
    if job.get("save_to"):
        # the scene as given (only what the analyst set), once it validates
        given = job["scene"] if isinstance(job["scene"], dict) else data
        Path(job["save_to"]).write_text(json.dumps(given, indent=1) + "\n", encoding="utf-8")
    return {"layers": {}, "warnings": [], "info": {"scene": data}}


def _task_annotation_page(job: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """``image``; ``submit_url``; optional ``scene`` (to correct), ``lat``/``lon``, ``osm``,
    ``radius_m``, ``streets``: the annotation page (crowd mode: Submit posts the scene to
    ``submit_url``) as ``info.html``."""
    from camloc_geo.web import annotation_page_html

    lat, lon = _opt_float(job, "lat"), _opt_float(job, "lon")
    corners = None
    notes: list[str] = []
    if job.get("osm") and lat is not None and lon is not None:
        from camloc_geo.cli.annotate import junction_geojson

        try:
            corners = junction_geojson(
                lat=lat,
                lon=lon,
                map_source=job["osm"],
                radius_m=_opt_float(job, "radius_m") or 150.0,
                streets=job.get("streets") or None,
            )
        except InputError as exc:  # no junction there: the page works without its map
            notes.append(f"no junction map on the page: {exc}")
    page = annotation_page_html(
        job["image"],
        scene=job.get("scene") or None,
        mode="crowd",
        submit_url=job["submit_url"],
        corners_geojson=corners,
        prior=(lat, lon) if lat is not None and lon is not None else None,
        title=job.get("title") or None,
    )
    return {"layers": {}, "warnings": notes, "info": {"html": page}}


def _presets() -> list[str]:
    from camloc_geo.objects import DEFAULT_PRESET, PRESETS

    return [DEFAULT_PRESET, *sorted(k for k in PRESETS if k != DEFAULT_PRESET)]


def _task_probe(job: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """What this interpreter offers: version and optional engines."""
    import camloc_geo

    try:
        import camloc_geo.sensors  # type: ignore[import-not-found,unused-ignore]

        has_sensors = True
    except ImportError:
        has_sensors = False
    return {
        "layers": {},
        "warnings": [],
        "info": {
            "version": getattr(camloc_geo, "__version__", None),
            "python": sys.executable,
            "batch": True,
            "presets": _presets(),
            "tie_score_ratio": TIE_SCORE_RATIO,
            "tie_distance_m": TIE_DISTANCE_M,
            "sensors": has_sensors,
        },
    }


_TASKS: dict[str, Callable[[dict[str, Any], Path], dict[str, Any]]] = {
    "locate": _task_locate,
    "corners": _task_corners,
    "geocodelist": _task_geocodelist,
    "measure": _task_measure,
    "check_scene": _task_check_scene,
    "annotation_page": _task_annotation_page,
    "probe": _task_probe,
}


def run_job(job: dict[str, Any]) -> dict[str, Any]:
    """Run one job dict and return the final message (raises the library's errors)."""
    task = job.get("task")
    if task not in _TASKS:
        raise InputError(f"unknown task {task!r}; known: {', '.join(sorted(_TASKS))}")
    out_dir = Path(job.get("out_dir") or ".")
    out_dir.mkdir(parents=True, exist_ok=True)
    return {"ok": True, **_TASKS[task](job, out_dir)}


_CLI_HINTS = (
    (
        "give --osm EXTRACT (map_source=...)",
        "give OSM (an OSM extract) or allow Overpass (NETWORK)",
    ),
    ("give --osm EXTRACT (a local OSM extract)", "give OSM (a local OSM extract)"),
    (
        "give --osm EXTRACT_OR_FOLDER or allow --network",
        "give OSM (an extract or a folder of them) or allow Overpass (NETWORK)",
    ),
    ("give --osm EXTRACT_OR_FOLDER", "give OSM (an extract or a folder of them)"),
    ("give --osm EXTRACT", "give OSM (an OSM extract)"),
)
"""The command line's words in the library's hints, and the Processing parameters' for them:
QGIS users read "give --osm EXTRACT (map_source=...)", options their dialog does not have."""


def processing_words(text: str) -> str:
    """``text`` with the command line's option names put as the Processing parameters'."""
    for cli, qgis in _CLI_HINTS:
        text = text.replace(cli, qgis)
    return text


def main(argv: list[str] | None = None) -> int:
    """Entry point: ``python -m camloc_geo.qgis.worker JOB.json`` (``-`` reads standard input)."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        _emit({"ok": False, "error": "usage: python -m camloc_geo.qgis.worker JOB.json"})
        return 2
    try:
        text = sys.stdin.read() if args[0] == "-" else Path(args[0]).read_text(encoding="utf-8")
        job = json.loads(text)
        if not isinstance(job, dict):
            raise InputError("the job must be a JSON object")
    except (OSError, ValueError) as exc:
        _emit({"ok": False, "error": f"cannot read the job: {exc}", "kind": "InputError"})
        return 2
    try:
        result = run_job(job)
        if result.get("warnings"):
            result["warnings"] = [processing_words(str(w)) for w in result["warnings"]]
        _emit(result)
    except (InputError, KeyError) as exc:
        msg = f"missing job parameter {exc}" if isinstance(exc, KeyError) else str(exc)
        _emit({"ok": False, "error": processing_words(msg), "kind": type(exc).__name__})
        return 2
    except Exception as exc:
        sys.stderr.write(traceback.format_exc())
        _emit({"ok": False, "error": f"{type(exc).__name__}: {exc}", "kind": type(exc).__name__})
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
