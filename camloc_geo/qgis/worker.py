"""Out-of-process worker for the QGIS plugin: ``python -m camloc_geo.qgis_worker JOB.json``.

QGIS loads the system GEOS and PROJ into its process, and the shapely/pyproj wheels crash
there (``docs/qgis.md``). The plugin therefore runs every computation in a separate Python
that can import ``camloc_geo``: it writes a job file, starts this module, reads progress from
its standard output and loads the layers it writes. This module imports no qgis and no Qt.

Job file (JSON object): ``task`` (``locate``, ``corners``, ``geocodelist``, ``measure``,
``check_scene``, ``probe``), ``out_dir`` (folder for the output layers) and the task's
parameters (see the ``_task_*`` functions).

Standard output: one JSON object per line,

- ``{"progress": 0..100, "message": "..."}`` while working;
- ``{"ok": true, "layers": {NAME: {"path": ..., "geometry": ..., "fields": [[name, type], ...]}},
  "warnings": [...], "info": {...}}`` at the end;
- ``{"ok": false, "error": "...", "kind": "SceneError"}`` on failure (exit status 2 for bad input,
  1 for anything else). Never a traceback for bad input.

Output layers are GeoJSON FeatureCollections in EPSG:4326 with flat, typed properties (no nested
objects): field types are ``int``, ``double``, ``string`` and ``bool``.
"""

from __future__ import annotations

import csv
import json
import math
import sys
import traceback
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from camloc_geo._errors import InputError
from camloc_geo.results import TIE_SCORE_RATIO  # the library's tie rule (stdlib-only module)

__all__ = [
    "CANDIDATE_FIELDS",
    "TIE_SCORE_RATIO",
    "candidate_rows",
    "main",
    "run_job",
]


Field = tuple[str, str]

CANDIDATE_FIELDS: list[Field] = [
    ("rank", "int"),
    ("score", "double"),
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
CONE_FIELDS: list[Field] = [("rank", "int"), ("score", "double"), ("tie", "bool")]
MATCH_FIELDS: list[Field] = [
    ("rank", "int"),
    ("label", "string"),
    ("match_kind", "string"),
    ("pixel_x", "double"),
    ("pixel_y", "double"),
    ("misfit_m", "double"),
    ("map_corner", "string"),
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
    ("sigma_m", "double"),
    ("tie", "bool"),
    ("n_candidates", "int"),
    ("height_m", "double"),
    ("heading_deg", "double"),
]
LIST_CANDIDATE_FIELDS: list[Field] = [("camera_id", "string"), *CANDIDATE_FIELDS]


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
    """Rank -> the other ranks it ties with (score within :data:`TIE_SCORE_RATIO` of the best)."""
    if not features:
        return {}
    given = {
        int(f["properties"]["rank"]): list(f["properties"]["ambiguous_with"])
        for f in features
        if isinstance(f["properties"].get("ambiguous_with"), list)
    }
    if given:
        return given
    best = max(float(f["properties"]["score"]) for f in features)
    tied = [
        int(f["properties"]["rank"])
        for f in features
        if float(f["properties"]["score"]) >= TIE_SCORE_RATIO * best
    ]
    if len(tied) < 2:
        return {}
    return {r: [o for o in tied if o != r] for r in tied}


def candidate_rows(gj: dict[str, Any]) -> list[tuple[dict[str, Any], dict[str, Any]]]:
    """Flat, typed rows of the candidate features of a locate GeoJSON (best first)."""
    cands = [f for f in gj["features"] if f["properties"].get("kind") == "candidate"]
    ties = _ties(cands)
    rows = []
    for f in cands:
        p = f["properties"]
        rank = int(p["rank"])
        others = ties.get(rank, [])
        rows.append(
            (
                f["geometry"],
                {
                    "rank": rank,
                    "score": _num(p.get("score")),
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


def _locate_layers(gj: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    rows = candidate_rows(gj)
    tie_by_rank = {props["rank"]: props["tie"] for _g, props in rows}
    feats = gj["features"]
    cones = [
        (
            f["geometry"],
            {
                "rank": f["properties"]["rank"],
                "score": _num(f["properties"].get("score")),
                "tie": tie_by_rank.get(f["properties"]["rank"], False),
            },
        )
        for f in feats
        if f["properties"].get("kind") == "view_cone"
    ]
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
                    "match_kind": p.get("match_kind"),
                    "pixel_x": _num(pixel[0]),
                    "pixel_y": _num(pixel[1]),
                    "misfit_m": _num(p.get("misfit_m")),
                    "map_corner": p.get("map_corner"),
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


def _opt_float(job: dict[str, Any], key: str) -> float | None:
    v = job.get(key)
    return None if v in (None, "") else float(v)


def _task_locate(job: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """``scene`` (path), ``osm`` (path or null), ``network``, ``radius_m``, ``max_candidates``."""
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
    return {
        "layers": _locate_layers(gj, out_dir),
        "warnings": list(props.get("warnings") or []),
        "info": {"n_candidates": props.get("n_candidates"), "reason": props.get("reason")},
    }


def _task_corners(job: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """``lat``, ``lon``, ``radius_m``, ``osm``, ``network``, ``streets`` (``"A & B"`` or null)."""
    from camloc_geo.api import corners_near

    _progress(5, "reading the map")
    gj = corners_near(
        lat=float(job["lat"]),
        lon=float(job["lon"]),
        radius_m=float(job.get("radius_m") or 150.0),
        map_source=job.get("osm") or None,
        network=bool(job.get("network", False)),
        streets=job.get("streets") or None,
    )
    _progress(80, "writing the layers")
    layer = _write_layer(
        out_dir, "corners", "Point", INTERSECTION_FIELDS, _intersection_rows(gj["features"])
    )
    return {"layers": {"corners": layer}, "warnings": [], "info": {"count": layer["count"]}}


# --- webcam lists ------------------------------------------------------------------------------

_ALIASES = {
    "id": ("id", "camera_id", "camera", "name"),
    "title": ("title", "description", "label"),
    "lat": ("lat", "latitude", "y"),
    "lon": ("lon", "lng", "long", "longitude", "x"),
    "radius_m": ("radius_m", "uncertainty_m", "radius"),
    "streets": ("streets", "street_pair", "intersection"),
    "scene": ("scene", "scene_file", "scene_path"),
}


def _pick(row: dict[str, Any], key: str) -> Any:
    low = {str(k).strip().lower(): v for k, v in row.items()}
    for alias in _ALIASES[key]:
        v = low.get(alias)
        if v not in (None, ""):
            return v
    return None


def _read_list(path: Path) -> list[dict[str, Any]]:
    """Rows of a camera list (CSV or GeoJSON) as plain dicts."""
    if not path.is_file():
        raise InputError(f"camera list not found: {path}")
    if path.suffix.lower() in (".geojson", ".json"):
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except ValueError as exc:
            raise InputError(f"camera list {path.name} is not valid JSON: {exc}") from exc
        rows = []
        for f in data.get("features", []):
            row = dict(f.get("properties") or {})
            geom = f.get("geometry") or {}
            if geom.get("type") == "Point":
                row.setdefault("lon", geom["coordinates"][0])
                row.setdefault("lat", geom["coordinates"][1])
            rows.append(row)
        return rows
    with path.open(newline="", encoding="utf-8-sig") as fh:
        return list(csv.DictReader(fh))


def _best_of(rows: list[tuple[dict[str, Any], dict[str, Any]]]) -> dict[str, Any]:
    if not rows:
        return {}
    p = rows[0][1]
    return {k: p[k] for k in ("lat", "lon", "score", "sigma_m", "tie", "height_m", "heading_deg")}


def _geocode_row(
    row: dict[str, Any], base: Path, job: dict[str, Any]
) -> tuple[dict[str, Any], list[tuple[dict[str, Any], dict[str, Any]]]]:
    """One camera with the library's ``locate_scene``: (camera properties, candidate rows)."""
    from camloc_geo.api import locate_scene, scene_from

    cam_id = str(_pick(row, "id") or "")
    props: dict[str, Any] = {"camera_id": cam_id, "title": _pick(row, "title")}
    scene_path = _pick(row, "scene")
    if not scene_path:
        return {**props, "status": "error", "reason": "no scene file in the row"}, []
    p = Path(str(scene_path))
    if not p.is_absolute():
        p = base / p
    try:
        sc = scene_from(p)
        data = sc.model_dump(mode="json", exclude_none=True)
        lat, lon = _pick(row, "lat"), _pick(row, "lon")
        if "prior" not in data and lat is not None and lon is not None:
            data["prior"] = {
                "lat": float(lat),
                "lon": float(lon),
                "radius_m": float(_pick(row, "radius_m") or 150.0),
            }
        streets = _pick(row, "streets")
        if streets and "intersection" in data and not data["intersection"].get("streets"):
            data["intersection"]["streets"] = [
                s.strip() for s in str(streets).replace("/", "&").split("&") if s.strip()
            ]
        out = locate_scene(
            data, map_source=job.get("osm") or None, network=bool(job.get("network", False))
        )
    except InputError as exc:
        return {**props, "status": "error", "reason": str(exc)}, []
    rows = [(g, {"camera_id": cam_id, **r}) for g, r in candidate_rows(out.to_geojson())]
    if not rows:
        reason = out.result.reason or "no candidates"
        return {**props, "status": "not_found", "reason": reason}, []
    best = _best_of(rows)
    status = "ambiguous" if best["tie"] else "ok"
    return {**props, **best, "status": status, "reason": None, "n_candidates": len(rows)}, rows


def _batch_module() -> Any | None:
    try:
        import camloc_geo.batch as batch  # type: ignore[import-not-found,unused-ignore]
    except ImportError:
        return None
    if not hasattr(batch, "geocode_camera") or not hasattr(batch, "read_camera_list"):
        return None
    return batch


_BATCH_STATUS = {
    "ok": "ok",
    "located": "ok",
    "title_only": "ok",
    "ambiguous": "ambiguous",
    "not_found": "not_found",
    "no_candidates": "not_found",
    "street_only": "not_found",
    "no_evidence": "not_found",
}
"""The batch engine's statuses as the plugin's (``ok``, ``ambiguous``, ``not_found``, else
``error``); the engine's own status leads the ``reason`` where it says more."""


def _batch_result(
    result: Any,
) -> tuple[dict[str, Any], list[tuple[dict[str, Any], dict[str, Any]]]]:
    """Camera properties and candidate rows from the batch engine's ``CameraResult``."""

    def get(key: str, default: Any = None) -> Any:
        if isinstance(result, dict):
            return result.get(key, default)
        return getattr(result, key, default)

    cam_id = str(get("id", None) or get("camera_id", "") or "")
    cands_gj = get("candidates", None) or []
    if hasattr(cands_gj, "to_geojson"):
        cands_gj = cands_gj.to_geojson()
    feats: list[dict[str, Any]] = []
    if isinstance(cands_gj, dict):
        feats = cands_gj.get("features", [])
    elif isinstance(cands_gj, list):
        feats = [
            f
            if isinstance(f, dict) and "properties" in f
            else {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [f["lon"], f["lat"]]},
                "properties": {"kind": "candidate", **f},
            }
            for f in (c if isinstance(c, dict) else c.__dict__ for c in cands_gj)
        ]
    rows = [
        (g, {"camera_id": cam_id, **r})
        for g, r in candidate_rows({"features": [f for f in feats if f]})
    ]
    best = _best_of(rows)
    batch_status = str(get("status", "located"))
    status = _BATCH_STATUS.get(batch_status, "error")
    if status == "ok" and get("tie", False):
        status = "ambiguous"
    reason = get("reason", None)
    if batch_status not in ("located", status):
        reason = f"{batch_status}: {reason}" if reason else batch_status
    props = {
        "camera_id": cam_id,
        "title": get("title", None),
        "status": status,
        "reason": reason,
        "n_candidates": len(rows),
        **best,
    }
    for key in ("lat", "lon", "score", "sigma_m"):
        if props.get(key) is None and get(key, None) is not None:
            props[key] = _num(get(key, None))
    if props.get("tie") is None and get("tie", None) is not None:
        props["tie"] = bool(get("tie", None))
    return props, rows


def _task_geocodelist(job: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """``list`` (CSV or GeoJSON camera list), ``osm``, ``network``, ``engine`` (auto|library)."""
    path = Path(job["list"])
    batch = _batch_module() if job.get("engine", "auto") == "auto" else None
    cameras: list[tuple[dict[str, Any] | None, dict[str, Any]]] = []
    candidates: list[tuple[dict[str, Any], dict[str, Any]]] = []
    if batch is not None:
        items: list[Any] = list(batch.read_camera_list(path))
        engine = "camloc_geo.batch"

        def one(item: Any) -> tuple[dict[str, Any], list[Any]]:
            try:
                return _batch_result(
                    batch.geocode_camera(
                        item, map_source=job.get("osm") or None, network=job.get("network", False)
                    )
                )
            except InputError as exc:
                return {
                    "camera_id": str(getattr(item, "id", "")),
                    "status": "error",
                    "reason": str(exc),
                }, []
    else:
        items = _read_list(path)
        engine = "camloc_geo.api.locate_scene"

        def one(item: Any) -> tuple[dict[str, Any], list[Any]]:
            return _geocode_row(item, path.parent, job)

    n = len(items)
    for i, item in enumerate(items):
        props, rows = one(item)
        geom = (
            {"type": "Point", "coordinates": [props["lon"], props["lat"]]}
            if props.get("lat") is not None and props.get("lon") is not None
            else None
        )
        cameras.append((geom, props))
        candidates.extend(rows)
        _progress(100.0 * (i + 1) / max(n, 1), f"camera {i + 1}/{n}: {props.get('status')}")
    return {
        "layers": {
            "cameras": _write_layer(out_dir, "cameras", "Point", CAMERA_FIELDS, cameras),
            "candidates": _write_layer(
                out_dir, "list_candidates", "Point", LIST_CANDIDATE_FIELDS, candidates
            ),
        },
        "warnings": [],
        "info": {"engine": engine, "n_cameras": n},
    }


def _task_measure(job: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """``scene``; ``pairs``: list of ``{"kind": "distance"|"height", "a": [x, y], "b": [x, y]}``."""
    import importlib

    from camloc_geo.api import calibrate_scene

    sensors: Any = importlib.import_module("camloc_geo.sensors")

    cal = calibrate_scene(job["scene"])
    rows: list[tuple[dict[str, Any] | None, dict[str, Any]]] = []
    for i, item in enumerate(job.get("pairs") or []):
        a, b = item["a"], item["b"]
        if item.get("kind", "distance") == "height":
            m = sensors.point_height(cal, a, b)
            value = getattr(m, "height_m", None)
        else:
            m = sensors.ground_distance(cal, [a, b])
            value = getattr(m, "distance_m", None)
        rows.append(
            (
                None,
                {
                    "index": i,
                    "kind": item.get("kind", "distance"),
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
        "warnings": [],
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
            "batch": _batch_module() is not None,
            "sensors": has_sensors,
        },
    }


_TASKS: dict[str, Callable[[dict[str, Any], Path], dict[str, Any]]] = {
    "locate": _task_locate,
    "corners": _task_corners,
    "geocodelist": _task_geocodelist,
    "measure": _task_measure,
    "check_scene": _task_check_scene,
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


def main(argv: list[str] | None = None) -> int:
    """Entry point: ``python -m camloc_geo.qgis_worker JOB.json`` (``-`` reads standard input)."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        _emit({"ok": False, "error": "usage: python -m camloc_geo.qgis_worker JOB.json"})
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
        _emit(run_job(job))
    except (InputError, KeyError) as exc:
        msg = f"missing job parameter {exc}" if isinstance(exc, KeyError) else str(exc)
        _emit({"ok": False, "error": msg, "kind": type(exc).__name__})
        return 2
    except Exception as exc:
        sys.stderr.write(traceback.format_exc())
        _emit({"ok": False, "error": f"{type(exc).__name__}: {exc}", "kind": type(exc).__name__})
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
