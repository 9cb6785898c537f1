"""Benchmark of the virtual guide (``camloc_geo.sensors.guide``) on synthetic walkers.

Each trial draws a noisy scene (same camera and annotation-noise model as
``benchmarks/relative.py``), calibrates it, and lets people walk in the true camera's view
for 40 s or 120 s (:func:`camloc_geo.testing.synthetic_guide.make_guide_data`: foot pixels with 2 px
noise at 5 Hz; phones log at 1 Hz with time-correlated noise, correlation 10 s, per-axis sigma
``gps_sigma_m``; with 4 or more people one has no phone; two distractor phones walk 15-60 m
away, unseen). The guide runs with the calibrated camera

- **absolute**: the true ``enu_from_world`` (as if located exactly; the calibration's own
  error remains);
- **relative**: no pose, the transform solved from the traces.

Per configuration (40 s walks: GPS sigma 2/4/6/8 m with 4 people, 2/4/8 people with 4 m;
and 120 s walks, 4 people, 4 m): assignment
accuracy (tracks whose final outcome, trace or none, is right), fraction certain, fraction
*certain and wrong*, time to certain (from the person's first appearance) of the right
certain matches, time after which the right match no longer changes whatever its certainty
(``stable_after_s``, the paper's "bootstrapping time"), and in relative mode the solved
camera position's error and how often it is within 2 sigma. The paper: 4 volunteers, all
matched after at most 2 s.

Writes ``benchmarks/out/guide.json`` and ``guide.png`` (when matplotlib is available).

Usage::

    python benchmarks/guide.py --n 20
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from camloc_geo import InputError
from camloc_geo.relative import calibrate
from camloc_geo.scene import parse_scene
from camloc_geo.sensors.guide import AbsolutePose, GuideSettings, match_people
from camloc_geo.testing.synthetic_guide import make_guide_data

sys.path.insert(0, str(Path(__file__).parent))
from relative import draw_scene

from camloc_geo.testing.synthetic import NoiseModel

OUT_DIR = Path(__file__).parent / "out"
CONFIGS = [
    (2.0, 4, 40.0),
    (4.0, 4, 40.0),
    (6.0, 4, 40.0),
    (8.0, 4, 40.0),
    (4.0, 2, 40.0),
    (4.0, 8, 40.0),
    (4.0, 4, 120.0),
]
"""(GPS sigma per axis in metres, people, seconds of walking)."""


def _pct(values: list[float], p: float) -> float | None:
    return float(np.percentile(values, p)) if values else None


def _trial(
    rng: np.random.Generator,
    index: int,
    gps_sigma_m: float,
    n_people: int,
    duration_s: float,
    modes: list[str],
) -> list[dict[str, Any]]:
    syn, size, _n_ann = draw_scene(rng, index, NoiseModel())
    try:
        cal = calibrate(parse_scene(syn.scene))
    except InputError as exc:
        return [{"mode": m, "error": str(exc)} for m in modes]
    data = make_guide_data(
        syn.camera,
        rng,
        n_people=n_people,
        n_without_phone=1 if n_people >= 4 else 0,
        n_distractors=2,
        gps_sigma_m=gps_sigma_m,
        image_size=size,
        duration_s=duration_s,
    )
    settings = GuideSettings(gps_sigma_m=gps_sigma_m)
    rows = []
    for mode in modes:
        pose = AbsolutePose(data.enu_from_world, data.frame) if mode == "absolute" else None
        t0 = time.perf_counter()
        try:
            res = match_people(cal, data.tracks, data.traces, pose=pose, settings=settings)
        except InputError as exc:
            rows.append({"mode": mode, "error": str(exc)})
            continue
        row: dict[str, Any] = {"mode": mode, "seconds": time.perf_counter() - t0, "tracks": []}
        for m in res.matches:
            right = m.gps == data.truth[m.track]
            certain = m.certain_after_s is not None
            row["tracks"].append(
                {
                    "track": m.track,
                    "has_phone": data.truth[m.track] is not None,
                    "right": right,
                    "certain": certain,
                    "certainty": m.certainty,
                    "certain_after_s": m.certain_after_s,
                    "stable_after_s": m.stable_after_s,
                }
            )
        if mode == "relative" and res.solved_pose is not None:
            true_en = data.enu_from_world.apply(syn.camera.center_in_world[:2])
            e, n = data.frame.enu_from_geographic(
                lat=res.solved_pose["lat"], lon=res.solved_pose["lon"]
            )
            err = float(math.hypot(e - true_en[0], n - true_en[1]))
            row["position_error_m"] = err
            row["position_sigma_m"] = res.solved_pose["sigma_m"]
        rows.append(row)
    return rows


def _summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    ok = [r for r in rows if "error" not in r]
    tracks = [t for r in ok for t in r["tracks"]]
    phones = [t for t in tracks if t["has_phone"]]
    ttc = [t["certain_after_s"] for t in phones if t["right"] and t["certain"]]
    stable = [t["stable_after_s"] for t in phones if t["right"]]
    out: dict[str, Any] = {
        "n_trials": len(rows),
        "n_failures": len(rows) - len(ok),
        "n_tracks": len(tracks),
        "accuracy": float(np.mean([t["right"] for t in tracks])) if tracks else None,
        "accuracy_with_phone": float(np.mean([t["right"] for t in phones])) if phones else None,
        "fraction_certain": float(np.mean([t["certain"] for t in tracks])) if tracks else None,
        "fraction_certain_and_wrong": (
            float(np.mean([t["certain"] and not t["right"] for t in tracks])) if tracks else None
        ),
        "time_to_certain_s": {"p50": _pct(ttc, 50), "p90": _pct(ttc, 90), "max": _pct(ttc, 100)},
        "stable_after_s": {
            "p50": _pct(stable, 50),
            "p90": _pct(stable, 90),
            "max": _pct(stable, 100),
        },
        "seconds_per_trial": float(np.mean([r["seconds"] for r in ok])) if ok else None,
    }
    pos = [r for r in ok if "position_error_m" in r]
    if pos:
        errs = [r["position_error_m"] for r in pos]
        out["position_error_m"] = {"p50": _pct(errs, 50), "p90": _pct(errs, 90)}
        out["position_within_2sigma"] = float(
            np.mean([r["position_error_m"] <= 2 * r["position_sigma_m"] for r in pos])
        )
    return out


def _plot(results: list[dict[str, Any]]) -> None:
    """``guide.png``: accuracy / certain fraction and times vs GPS noise (4 people)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for mode, style, colour in (("absolute", "o-", "C0"), ("relative", "s--", "C1")):
        sel = [
            r
            for r in results
            if r["mode"] == mode and r["n_people"] == 4 and r.get("duration_s", 40.0) == 40.0
        ]
        if not sel:
            continue
        xs = [r["gps_sigma_m"] for r in sel]
        axes[0].plot(xs, [r["accuracy"] for r in sel], style, color=colour, label=f"{mode}: right")
        axes[0].plot(
            xs,
            [r["fraction_certain"] for r in sel],
            style,
            color=colour,
            alpha=0.4,
            label=f"{mode}: certain (0.99)",
        )
        for key, alpha, what in (
            ("time_to_certain_s", 1.0, "certain"),
            ("stable_after_s", 0.4, "stable"),
        ):
            ys = [r[key]["p50"] for r in sel]
            axes[1].plot(xs, ys, style, color=colour, alpha=alpha, label=f"{mode}: {what}, median")
    axes[0].set_xlabel("GPS sigma per axis (m), 4 people")
    axes[0].set_ylabel("fraction of tracks")
    axes[0].legend(fontsize=8)
    axes[1].axhline(2.0, color="grey", lw=0.8, label="paper: all matched after 2 s")
    axes[1].set_xlabel("GPS sigma per axis (m), 4 people")
    axes[1].set_ylabel("seconds after the person appears")
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT_DIR / "guide.png", dpi=100)


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=20, help="trials per configuration")
    ap.add_argument("--seed", type=int, default=15)
    ap.add_argument("--modes", default="absolute,relative")
    ap.add_argument("--plot-only", action="store_true", help="redraw guide.png from guide.json")
    args = ap.parse_args(argv)
    if args.plot_only:
        _plot(json.loads((OUT_DIR / "guide.json").read_text())["configs"])
        return 0
    modes = args.modes.split(",")
    results: list[dict[str, Any]] = []
    for c, (gps_sigma, n_people, duration) in enumerate(CONFIGS):
        rng = np.random.default_rng(args.seed * 1000 + c)
        rows: list[dict[str, Any]] = []
        for i in range(args.n):
            rows += _trial(rng, i, gps_sigma, n_people, duration, modes)
        for mode in modes:
            summary = _summarise([r for r in rows if r["mode"] == mode])
            results.append(
                {
                    "mode": mode,
                    "gps_sigma_m": gps_sigma,
                    "n_people": n_people,
                    "duration_s": duration,
                    **summary,
                }
            )
            print(json.dumps(results[-1]), flush=True)
    OUT_DIR.mkdir(exist_ok=True)
    doc = {
        "paper": "4 volunteers, all GPS traces matched after at most 2 s",
        "trials_per_config": args.n,
        "configs": results,
    }
    (OUT_DIR / "guide.json").write_text(json.dumps(doc, indent=2))
    _plot(results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
