"""Unseen cities: junctions, location and title geocoding in extracts camloc was never tuned on.

The six extracts listed under "Unseen cities" in ``data/osm/SOURCES.md`` (Rome centre,
Andorra, Harrisburg PA, Stretford/Manchester, Berlin's Großer Stern, Frederiksted USVI) are
held out: no threshold of camloc was chosen on them. Per city:

- **coverage**: osmnx's own graph of the whole extract (``benchmarks/junctions.py``'s
  oracle: :func:`osmnx.graph_from_xml`, ``street_count >= 3``, merged within 15 m) against
  camloc's intersections; an oracle junction is covered when a camloc intersection centre
  or member node lies within 15 m. Every miss is listed with its reason.
- **locate**: up to ``--n`` oracle junctions around the city's centre (nearest first, never
  camloc's own list) get a synthetic camera each, made as ``benchmarks/absolute.py`` makes
  them (:func:`camloc_geo.testing.synthetic.make_located_scene`, the same noise model, real
  kerbs 1.5 m off the map's corners, the oracle's lat/lon stated as the intersection), and
  are located with ``corners`` and ``two_references``. The car is stated as
  ``{"preset": "sedan"}``, as a user who does not know it would (since stop 40;
  ``--state-size``: the preset's numbers, taken by ``calibrate`` as the car's measured size).
  Reported: the closest candidate of ``corners`` under 10 / 15 m, its top candidate under
  10 m, the top of ``two_references`` under 12 m, refusals with their messages, scenes that
  could not be made (the junction is missing from camloc's model, or has no kerb corners),
  and **confidently wrong** answers: the top candidate more than 15 m off, not tied, no
  warning, and two ``sigma_m`` short of the truth.
- **geocode**: "Street A & Street B" titles made from osmnx's graph names
  (``tests/geocode_reference.py``, the same generator as ``benchmarks/geocode.py``):
  precision and recall within 30 m, negatives.

Fractions are over every scene attempted (a junction that could not be placed, a refusal or
an empty answer counts as a miss). Results go to ``benchmarks/out/unseen_cities.json`` and
``benchmarks/out/unseen_cities.png``::

    python benchmarks/unseen_cities.py [--n 12] [--city rome_centro.osm.pbf ...]
"""

from __future__ import annotations

import argparse
import json
import logging
import platform
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT = HERE / "out"
OSM = ROOT / "data" / "osm"
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT))

log = logging.getLogger("unseen_cities")

# (extract, lat, lon, radius_m): the area whose junctions get cameras.
CITIES = [
    ("rome_centro.osm.pbf", 41.8965, 12.4838, 350.0),
    ("andorra.osm.pbf", 42.5075, 1.5300, 1500.0),
    ("harrisburg.osm.pbf", 40.2605, -76.7967, 1500.0),
    ("manchester_kingsway.osm", 53.4469, -2.3086, 800.0),
    ("berlin_siegessaeule.osm.gz", 52.5145, 13.3502, 500.0),
    ("frederiksted.osm.pbf", 17.7125, -64.8820, 600.0),
]
METHODS = ("corners", "two_references")
CONFIDENT_M = 15.0
"""A top candidate farther than this from the truth is wrong."""
SIGMA_COVER = 2.0
"""A wrong top candidate whose ``SIGMA_COVER * sigma_m`` reaches the truth is not confident."""


def _entry(res: Any, lat: float, lon: float) -> dict[str, Any]:
    from camloc_geo.geodesy import distance_m

    if not res.candidates:
        return {"empty": (res.reason or "")[:300]}
    errs = [float(distance_m(lat1=c.lat, lon1=c.lon, lat2=lat, lon2=lon)) for c in res.candidates]
    top = res.candidates[0]
    warned = [w for w in res.warnings if not w.startswith("ambiguous:")]
    covered = top.sigma_m is not None and SIGMA_COVER * top.sigma_m >= errs[0]
    tied = bool(top.ambiguous_with) or bool(getattr(res, "leaders_tie", False))
    return {
        "n": len(errs),
        "top": round(errs[0], 2),
        "closest": round(min(errs), 2),
        "top_sigma_m": None if top.sigma_m is None else round(top.sigma_m, 2),
        "top_tied": tied,
        "warnings": [w[:200] for w in warned],
        "confidently_wrong": bool(
            errs[0] > CONFIDENT_M and not tied and not warned and not covered
        ),
    }


def locate_city(
    name: str,
    lat: float,
    lon: float,
    radius_m: float,
    junctions: list[dict[str, Any]],
    n: int,
    state_preset: bool = True,
) -> dict[str, Any]:
    """Synthetic cameras at up to ``n`` oracle junctions of one city, located two ways.

    ``state_preset``: the scenes state the car as ``{"preset": "sedan"}`` (default) or as the
    preset's numbers (``absolute.oracle_scene``).
    """
    from absolute import oracle_near, oracle_scene  # benchmarks/absolute.py: made alike

    from camloc_geo.absolute import apply_cues, locate
    from camloc_geo.osm import load_map
    from camloc_geo.relative import calibrate
    from camloc_geo.scene import parse_scene
    from camloc_geo.testing.synthetic import NoiseModel

    m = load_map(OSM / name, lat, lon, radius_m)
    chosen = oracle_near(junctions, m)[:n]
    noise = NoiseModel()
    rows: list[dict[str, Any]] = []
    for i, oj in enumerate(chosen):
        base = {"oracle": [round(oj["lat"], 7), round(oj["lon"], 7)], "streets": oj["streets"]}
        inter, ls, reason = oracle_scene(
            m, oj, np.random.default_rng([0, i]), noise, state_preset=state_preset
        )
        if inter is not None:
            base["intersection"] = inter.id
            base["kind"] = inter.kind
        if ls is None:
            rows.append({**base, "placed": False, "reason": reason})
            continue
        row: dict[str, Any] = {**base, "placed": True, "methods": {}}
        try:
            cal = calibrate(parse_scene(ls.scene))
        except ValueError as exc:
            row["calibration_error"] = str(exc)[:300]
            rows.append(row)
            continue
        # when both methods miss one scene, a poor calibration is the first suspect
        row["focal_err_rel"] = round(cal.camera.focal_px / ls.camera_enu.focal_px - 1.0, 4)
        row["height_m"] = round(ls.camera_enu.height_m, 2)
        for method in METHODS:
            data = json.loads(json.dumps(ls.scene))
            refs = data.pop("references", [])
            data.pop("landmarks", None)
            if method == "two_references":
                data.pop("intersection", None)
                data["references"] = refs[:2]
            sc = parse_scene(data)
            try:
                res = apply_cues(locate(sc, m, calibration=cal), sc, m)
            except ValueError as exc:
                row["methods"][method] = {"refused": f"{type(exc).__name__}: {exc}"[:300]}
                continue
            row["methods"][method] = _entry(res, ls.lat, ls.lon)
        rows.append(row)
    return {"scenes": rows, "summary": summarise(rows)}


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Fractions over every attempted scene (unplaced, refused and empty count as misses)."""
    total = len(rows)

    def frac(method: str, key: str, limit: float) -> float | None:
        if not total:
            return None
        hits = 0
        for r in rows:
            e = r.get("methods", {}).get(method, {})
            hits += bool(e.get("n")) and e[key] < limit
        return hits / total

    def count(method: str, what: str) -> int:
        return sum(1 for r in rows if what in r.get("methods", {}).get(method, {}))

    refusals = sorted(
        {
            e[k]
            for r in rows
            for e in r.get("methods", {}).values()
            for k in ("refused", "empty")
            if k in e
        }
    )
    return {
        "attempted": total,
        "unplaced": sum(1 for r in rows if not r.get("placed")),
        "unplaced_reasons": sorted({r["reason"] for r in rows if not r.get("placed")}),
        "calibration_errors": sum(1 for r in rows if "calibration_error" in r),
        "corners_closest_lt_10m": frac("corners", "closest", 10.0),
        "corners_closest_lt_15m": frac("corners", "closest", 15.0),
        "corners_top_lt_10m": frac("corners", "top", 10.0),
        "two_references_top_lt_12m": frac("two_references", "top", 12.0),
        "refused": {m: count(m, "refused") for m in METHODS},
        "empty": {m: count(m, "empty") for m in METHODS},
        "refusal_messages": refusals[:20],
        "confidently_wrong": {
            m: sum(
                1 for r in rows if r.get("methods", {}).get(m, {}).get("confidently_wrong", False)
            )
            for m in METHODS
        },
        "sigma": {m: _sigma_summary(rows, m) for m in METHODS},
    }


def _sigma_summary(rows: list[dict[str, Any]], method: str) -> dict[str, Any]:
    """How honest the top candidate's ``sigma_m`` is: the share whose two sigmas reach the
    truth (all tops, and those within :data:`CONFIDENT_M`: a wrong junction is a tie's
    business, not the sigma's), the median error over sigma and the median sigma."""
    tops = [
        (e["top"], e["top_sigma_m"])
        for r in rows
        for e in [r.get("methods", {}).get(method, {})]
        if e.get("n") and e.get("top_sigma_m")
    ]
    if not tops:
        return {"n": 0}
    right = [(t, s) for t, s in tops if t < CONFIDENT_M]
    return {
        "n": len(tops),
        "covered_2sigma": round(sum(SIGMA_COVER * s >= t for t, s in tops) / len(tops), 4),
        "right_covered_2sigma": round(
            sum(SIGMA_COVER * s >= t for t, s in right) / max(len(right), 1), 4
        ),
        "median_error_over_sigma": round(float(np.median([t / s for t, s in tops])), 3),
        "median_sigma_m": round(float(np.median([s for _t, s in tops])), 2),
        "warned": sum(
            1
            for r in rows
            if r.get("methods", {}).get(method, {}).get("n")
            and r["methods"][method].get("warnings")
        ),
    }


def geocode_city(name: str, max_junctions: int) -> dict[str, Any]:
    """Title geocoding precision/recall on titles made from osmnx's graph of the extract."""
    from geocode import _accuracy

    try:
        return _accuracy(OSM / name, max_junctions)
    except ValueError as exc:  # e.g. an extract with no named junction at all
        return {"extract": name, "error": f"{type(exc).__name__}: {exc}"}


def plot(result: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cities = [c["extract"].split(".")[0] for c in result["cities"]]
    series = [
        ("coverage", lambda c: c["coverage"]["coverage"]),
        ("corners closest < 10 m", lambda c: c["locate"]["summary"]["corners_closest_lt_10m"]),
        ("corners closest < 15 m", lambda c: c["locate"]["summary"]["corners_closest_lt_15m"]),
        ("corners top < 10 m", lambda c: c["locate"]["summary"]["corners_top_lt_10m"]),
        ("two refs top < 12 m", lambda c: c["locate"]["summary"]["two_references_top_lt_12m"]),
        ("geocode precision", lambda c: c["geocode"].get("precision")),
        ("geocode recall", lambda c: c["geocode"].get("recall")),
    ]
    fig, ax = plt.subplots(figsize=(12, 5))
    width = 0.8 / len(series)
    x = np.arange(len(cities))
    for k, (label, get) in enumerate(series):
        vals = [get(c) for c in result["cities"]]
        ax.bar(x + k * width, [v if v is not None else 0.0 for v in vals], width, label=label)
    ax.set_xticks(x + 0.4 - width / 2, cities, rotation=15)
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("fraction")
    ax.set_title("Unseen cities (held-out extracts; © OpenStreetMap contributors)")
    ax.legend(fontsize=8, ncol=4, loc="lower center")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; write JSON and PNG to benchmarks/out/."""
    from junctions import coverage, oracle_junctions

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--city", action="append", help="extract names (default: all six)")
    parser.add_argument("--n", type=int, default=12, help="junctions located per city")
    parser.add_argument("--max-junctions", type=int, default=60, help="geocode titles' junctions")
    parser.add_argument(
        "--state-size",
        action="store_true",
        help="the scenes state the car as the preset's numbers, taken by calibrate as its "
        'measured size (the scenes before stop 40); default: {"preset": "sedan"}',
    )
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(message)s")
    logging.getLogger("camloc_geo").setLevel(logging.ERROR)
    OUT.mkdir(parents=True, exist_ok=True)
    cities = [c for c in CITIES if not args.city or c[0] in args.city]
    out: list[dict[str, Any]] = []
    for name, lat, lon, radius_m in cities:
        t0 = time.perf_counter()
        cov = coverage(name)
        junctions, _g = oracle_junctions(OSM / name)
        loc = locate_city(
            name, lat, lon, radius_m, junctions, args.n, state_preset=not args.state_size
        )
        geo = geocode_city(name, args.max_junctions)
        s = loc["summary"]
        print(
            f"{name}: coverage {cov['covered']}/{cov['oracle_junctions']}"
            f" | corners closest<10 {s['corners_closest_lt_10m']} <15 {s['corners_closest_lt_15m']}"
            f" top<10 {s['corners_top_lt_10m']} | two refs<12 {s['two_references_top_lt_12m']}"
            f" | unplaced {s['unplaced']}/{s['attempted']} refused {s['refused']}"
            f" conf. wrong {s['confidently_wrong']}"
            f" | geocode P {geo.get('precision')} R {geo.get('recall')}"
            f" ({geo.get('junction_titles')} titles) | {time.perf_counter() - t0:.0f} s",
            flush=True,
        )
        out.append({"extract": name, "coverage": cov, "locate": loc, "geocode": geo})
    result = {
        "machine": platform.platform(),
        "python": platform.python_version(),
        "n_per_city": args.n,
        "car_stated": "size" if args.state_size else "preset",
        "cities": out,
    }
    (OUT / "unseen_cities.json").write_text(json.dumps(result, indent=2), encoding="utf-8")
    plot(result, OUT / "unseen_cities.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
