"""Speed of ``calibrate`` with its uncertainty, and the one-step jackknife against refits.

Draws ``--n`` held-out five-annotator crowd scenes (``benchmarks/relative.py``'s scene
distribution and noise model, a seed of their own) and, per scene, measures the CPU time
(``time.process_time``, median of ``--repeats`` calls after a warm-up, the methods taken in
turn call by call) of

- ``closed_form``: the paper's method, ``CalibrationSettings(joint_fit=False)``
  (``camloc calibrate --no-joint-fit``);
- ``joint_fit``: the joint fit without the leave-one-annotator-out spread
  (``jackknife=False``);
- ``default``: ``calibrate(scene)``, the joint fit with its uncertainty (the one-step
  jackknife);
- ``refit_jackknife``: the uncertainty by full refits (``jackknife_method="refit"``), the
  reference the one-step jackknife is checked against;
- with ``--no-focal-check``, also ``default_no_focal_check``: the default with the focal
  local-minimum check (``camloc_geo.relative._focal_profile_widening``) switched off, what
  the check costs (calibrate before it, commit 4d58b77).

It also compares the two jackknives' sigmas (the camera position's leave-one-out spread in x,
y, z and the rotation sigma about the camera's x, y, z) and the annotators they flag
(influence above three times the median annotator's). Writes

- ``benchmarks/out/calibrate_speed.json``: per-method median CPU times and their ratio to
  the closed form (the ratio of the medians, and the median over scenes of each scene's own
  ratio: paired, so a drift of the machine's speed between scenes does not enter it), sigma
  ratios (median, fraction within 10 %), flag agreement, one row per scene; with
  ``--profile``, the top functions of a cProfile of the default calibrate;
- ``benchmarks/out/calibrate_speed.png``: the CPU time per scene of each method, and the
  one-step sigmas against the refits' with the ±10 % band.

With ``--dump PATH`` it only writes every output of the default and the refit ``calibrate``
on the scenes (the camera, every sigma, the covariance, influences, proportions, warnings)
to ``PATH`` (JSON), and with ``--compare PATH`` it compares them with such a dump, field by
field, to ``1e-9`` relative (with ``--exact``, bit for bit): the check that a speed change
left the answers as they were (run it on the tree before the change, then after).

Usage::

    python benchmarks/calibrate_speed.py --n 30 [--profile] [--no-focal-check]
    python benchmarks/calibrate_speed.py --n 40 --dump before.json   # on the old tree
    python benchmarks/calibrate_speed.py --n 40 --compare before.json --exact  # on the new one
"""

from __future__ import annotations

import argparse
import cProfile
import dataclasses
import gc
import io
import json
import logging
import math
import os
import pstats
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from relative import draw_scene

from camloc_geo import InputError
from camloc_geo.relative import CalibrationResult, CalibrationSettings, calibrate
from camloc_geo.scene import Scene, parse_scene
from camloc_geo.testing.synthetic import NoiseModel

OUT_DIR = Path(__file__).parent / "out"
METHODS = {
    "closed_form": CalibrationSettings(joint_fit=False),
    "joint_fit": CalibrationSettings(jackknife=False),
    "default": CalibrationSettings(),
    "refit_jackknife": CalibrationSettings(jackknife_method="refit"),
}
NO_FOCAL_CHECK = "default_no_focal_check"
TARGET_RATIO = 1.5
SIGMA_TOLERANCE = 0.10


def flagged(influence: list[float | None]) -> list[int]:
    """Annotators who move the camera more than three times the median annotator."""
    vals = np.array([np.nan if v is None else v for v in influence], dtype=float)
    if not np.any(np.isfinite(vals)):
        return []
    med = float(np.nanmedian(vals))
    return [i for i, v in enumerate(vals) if np.isfinite(v) and v > 3.0 * med]


def cpu_ms(scene: Scene, settings: CalibrationSettings, repeats: int) -> float:
    """Median CPU milliseconds of ``calibrate(scene, settings)``."""
    times = []
    for _ in range(repeats):
        c0 = time.process_time()
        calibrate(scene, settings)
        times.append((time.process_time() - c0) * 1000.0)
    return float(np.median(times))


def cpu_ms_no_focal_check(scene: Scene) -> float:
    """CPU milliseconds of one default ``calibrate(scene)`` without the focal check."""
    import camloc_geo.relative as rel

    check = rel._focal_profile_widening
    rel._focal_profile_widening = lambda result, widen_flat=False: None
    try:
        return cpu_ms(scene, METHODS["default"], 1)
    finally:
        rel._focal_profile_widening = check


def interleaved_cpu_ms(
    scene: Scene, repeats: int, no_focal_check: bool = False
) -> dict[str, float]:
    """Median CPU milliseconds of each method on one scene, the methods taken in turn.

    ``repeats`` rounds of one call of each fast method (the closed form, the joint fit, the
    default), then one refit call: the methods compared meet the same state of the machine
    (a drift of its speed, a collection of the garbage another call left) instead of one
    method's calls running back to back. The garbage is collected before the scene.
    ``no_focal_check``: the default without the focal check joins the fast methods.
    """
    gc.collect()
    fast = [m for m in METHODS if m != "refit_jackknife"]
    times: dict[str, list[float]] = {m: [] for m in METHODS}
    if no_focal_check:
        times[NO_FOCAL_CHECK] = []
    for _ in range(repeats):
        for method in fast:
            times[method].append(cpu_ms(scene, METHODS[method], 1))
        if no_focal_check:
            times[NO_FOCAL_CHECK].append(cpu_ms_no_focal_check(scene))
    times["refit_jackknife"].append(cpu_ms(scene, METHODS["refit_jackknife"], 1))
    return {m: float(np.median(t)) for m, t in times.items()}


def sigmas(result: CalibrationResult) -> list[float] | None:
    """The position's jackknife spread and the rotation sigmas, or None when missing.

    The position's own sigma is the larger of the fit's covariance and the jackknife spread,
    so the spread is compared itself.
    """
    if result.position_sigma_jackknife_m is None or result.rotation_sigma_deg is None:
        return None
    return [*result.position_sigma_jackknife_m.tolist(), *result.rotation_sigma_deg.tolist()]


def draw_scenes(seed: int, n: int) -> list[Scene]:
    """``n`` five-annotator scenes that every method accepts."""
    rng = np.random.default_rng(seed)
    scenes: list[Scene] = []
    while len(scenes) < n:
        syn, _size, _n = draw_scene(rng, len(scenes), NoiseModel(), n_annotators=5)
        scene = parse_scene(syn.scene)
        try:
            for settings in METHODS.values():
                calibrate(scene, settings)  # warm-up, and skip scenes a method refuses
        except InputError:
            continue
        scenes.append(scene)
    return scenes


COMPARE_REL_TOL = 1e-9


def to_record(value: Any, depth: int = 0) -> Any:
    """JSON-ready copy of a result: dataclasses field by field, arrays as lists."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        return value.item()
    if isinstance(value, np.ndarray):
        return to_record(value.tolist(), depth + 1)
    if isinstance(value, dict):
        return {str(k): to_record(v, depth + 1) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_record(v, depth + 1) for v in value]
    if dataclasses.is_dataclass(value) and not isinstance(value, type) and depth < 5:
        return {
            f.name: to_record(getattr(value, f.name), depth + 1)
            for f in dataclasses.fields(value)
            if f.name != "joint_state"  # the fit's internals, not an output
        }
    return repr(value)


def dump_outputs(scenes: list[Scene]) -> list[dict[str, Any]]:
    """Every output of the default and the refit ``calibrate`` on each scene."""
    rows = []
    for scene in scenes:
        row = {}
        for method in ("default", "refit_jackknife"):
            result = calibrate(scene, METHODS[method])
            record = to_record(result)
            record["parameter_covariance"] = to_record(result.parameter_covariance)
            row[method] = record
        rows.append(row)
    return rows


def differences(before: Any, after: Any, path: str = "", *, exact: bool = False) -> list[str]:
    """Where two dumps differ: numbers beyond ``COMPARE_REL_TOL`` relative (and 1e-12
    absolute), or with ``exact`` any number not equal bit for bit (JSON keeps a float's
    every digit); anything else unequal."""
    if isinstance(before, dict) and isinstance(after, dict):
        if set(before) != set(after):
            return [f"{path}: keys {sorted(set(before) ^ set(after))}"]
        return [
            d for k in before for d in differences(before[k], after[k], f"{path}.{k}", exact=exact)
        ]
    if isinstance(before, list) and isinstance(after, list):
        if len(before) != len(after):
            return [f"{path}: length {len(before)} -> {len(after)}"]
        return [
            d
            for i, (b, a) in enumerate(zip(before, after, strict=True))
            for d in differences(b, a, f"{path}[{i}]", exact=exact)
        ]
    numbers = (int, float)
    if (
        isinstance(before, numbers)
        and isinstance(after, numbers)
        and not isinstance(before, bool)
        and not isinstance(after, bool)
    ):
        if before == after or (math.isnan(before) and math.isnan(after)):
            return []
        if exact:
            return [f"{path}: {before!r} -> {after!r}"]
        gap = abs(before - after)
        if gap <= 1e-12 or gap <= COMPARE_REL_TOL * max(abs(before), abs(after)):
            return []
        return [f"{path}: {before!r} -> {after!r}"]
    return [] if before == after else [f"{path}: {before!r} -> {after!r}"]


def profile_default(scenes: list[Scene], top: int = 25) -> str:
    """The cumulative-time table of a cProfile of the default ``calibrate``."""
    prof = cProfile.Profile()
    prof.enable()
    for scene in scenes:
        calibrate(scene)
    prof.disable()
    buf = io.StringIO()
    pstats.Stats(prof, stream=buf).sort_stats("cumulative").print_stats(top)
    return buf.getvalue()


def plot(rows: list[dict[str, Any]], summary: dict[str, Any], path: Path) -> None:
    """CPU time per scene and method; one-step against refit sigmas."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    ax = axes[0]
    order = np.argsort([r["cpu_ms"]["closed_form"] for r in rows])
    for method, style in (
        ("closed_form", "o-"),
        ("joint_fit", "s-"),
        ("default", "^-"),
        ("refit_jackknife", "x--"),
    ):
        ys = [rows[i]["cpu_ms"][method] for i in order]
        med = summary["median_cpu_ms"][method]
        ax.plot(range(len(ys)), ys, style, ms=4, label=f"{method} (median {med:.1f} ms)")
    closed = [rows[i]["cpu_ms"]["closed_form"] for i in order]
    ax.plot(
        range(len(closed)),
        [TARGET_RATIO * c for c in closed],
        "k:",
        label=f"target: {TARGET_RATIO}x the closed form",
    )
    ax.set_yscale("log")
    ax.set_xlabel("scene (sorted by the closed form's time)")
    ax.set_ylabel("CPU time per calibrate (ms)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    ax = axes[1]
    names = ["x m", "y m", "z m", "rot x°", "rot y°", "rot z°"]
    for k, name in enumerate(names):
        pairs = np.array(
            [(r["sigma_refit"][k], r["sigma_one_step"][k]) for r in rows if r["sigma_refit"]]
        )
        if len(pairs):
            ax.loglog(pairs[:, 0], pairs[:, 1], ".", label=name)
    lo, hi = ax.get_xlim()
    xs = np.array([lo, hi])
    ax.plot(xs, xs, "k-", lw=0.8)
    ax.plot(xs, xs * (1 + SIGMA_TOLERANCE), "k:", lw=0.8)
    ax.plot(xs, xs * (1 - SIGMA_TOLERANCE), "k:", lw=0.8, label="±10 %")
    ax.set_xlabel("sigma, full leave-one-annotator-out refits")
    ax.set_ylabel("sigma, one-step jackknife")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    fig.suptitle(
        f"calibrate on {len(rows)} held-out 5-annotator crowd scenes: "
        f"default {summary['ratio_to_closed_form']['default']:.2f}x the closed form, "
        f"refits {summary['ratio_to_closed_form']['refit_jackknife']:.2f}x"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=30, help="number of scenes (default 30)")
    parser.add_argument("--seed", type=int, default=20261124, help="random seed")
    parser.add_argument("--repeats", type=int, default=3, help="timed calls per scene")
    parser.add_argument("--profile", action="store_true", help="add a cProfile table")
    parser.add_argument(
        "--no-focal-check",
        action="store_true",
        help="also time the default without the focal local-minimum check",
    )
    parser.add_argument("--out", type=Path, default=OUT_DIR, help="output folder")
    parser.add_argument(
        "--dump", type=Path, help="only write every output of calibrate to this JSON file"
    )
    parser.add_argument(
        "--compare",
        type=Path,
        help="only compare every output of calibrate with a --dump file (exit 1 if any differs)",
    )
    parser.add_argument(
        "--exact",
        action="store_true",
        help="with --compare: every number equal bit for bit, not to 1e-9 relative",
    )
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.ERROR)
    args.out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    load_before = os.getloadavg()
    scenes = draw_scenes(args.seed, args.n)
    if args.dump is not None or args.compare is not None:
        outputs = dump_outputs(scenes)
        if args.dump is not None:
            args.dump.write_text(json.dumps(outputs))
            print(f"{len(outputs)} scenes' outputs written to {args.dump}")
        if args.compare is not None:
            diffs = differences(json.loads(args.compare.read_text()), outputs, exact=args.exact)
            beyond = "in any digit" if args.exact else f"beyond {COMPARE_REL_TOL:g} relative"
            print(
                f"{len(outputs)} scenes against {args.compare}: {len(diffs)} differences {beyond}"
            )
            for line in diffs[:20]:
                print("  " + line)
            return 1 if diffs else 0
        return 0
    rows: list[dict[str, Any]] = []
    for i, scene in enumerate(scenes):
        row: dict[str, Any] = {"index": i, "cpu_ms": {}}
        row["cpu_ms"] = interleaved_cpu_ms(scene, args.repeats, args.no_focal_check)
        fast = calibrate(scene)
        slow = calibrate(scene, METHODS["refit_jackknife"])
        row["sigma_one_step"] = sigmas(fast)
        row["sigma_refit"] = sigmas(slow)
        row["flagged_one_step"] = flagged(fast.annotator_influence_m)
        row["flagged_refit"] = flagged(slow.annotator_influence_m)
        rows.append(row)
    load_after = os.getloadavg()
    timed = [*METHODS, *([NO_FOCAL_CHECK] if args.no_focal_check else [])]
    med = {m: float(np.median([r["cpu_ms"][m] for r in rows])) for m in timed}
    both = [r for r in rows if r["sigma_one_step"] and r["sigma_refit"]]
    ratio = np.array([np.divide(r["sigma_one_step"], r["sigma_refit"]) for r in both])
    within = np.abs(ratio - 1.0) <= SIGMA_TOLERANCE
    summary: dict[str, Any] = {
        "median_cpu_ms": med,
        "ratio_to_closed_form": {m: med[m] / med["closed_form"] for m in timed},
        # the same per scene, then its median over the scenes (paired: robust to drift)
        "ratio_to_closed_form_per_scene_median": {
            m: float(np.median([r["cpu_ms"][m] / r["cpu_ms"]["closed_form"] for r in rows]))
            for m in timed
        },
        "target_ratio": TARGET_RATIO,
        "sigma_components": [
            "jackknife_x_m",
            "jackknife_y_m",
            "jackknife_z_m",
            "rot_x_deg",
            "rot_y_deg",
            "rot_z_deg",
        ],
        "sigma_ratio_median": np.median(ratio, axis=0).tolist() if len(ratio) else None,
        "sigma_within_10pct_fraction": within.mean(axis=0).tolist() if len(ratio) else None,
        "scenes_all_sigmas_within_10pct": float(np.mean(np.all(within, axis=1)))
        if len(ratio)
        else None,
        "flagged_same_fraction": float(
            np.mean([r["flagged_one_step"] == r["flagged_refit"] for r in rows])
        ),
    }
    result: dict[str, Any] = {
        "benchmark": "calibrate_speed",
        "seed": args.seed,
        "n_scenes": len(rows),
        "n_annotators": 5,
        "repeats": args.repeats,
        "summary": summary,
        "wall_time_s": round(time.perf_counter() - t_start, 1),
        "loadavg_before": [round(x, 2) for x in load_before],
        "loadavg_after": [round(x, 2) for x in load_after],
        "cpu_count": os.cpu_count(),
        "rows": rows,
    }
    if args.profile:
        result["profile_default"] = profile_default(scenes)
    (args.out / "calibrate_speed.json").write_text(json.dumps(result, indent=1))
    plot(rows, summary, args.out / "calibrate_speed.png")
    print(
        f"calibrate speed, {len(rows)} scenes, seed {args.seed}, load "
        f"{load_before[0]:.2f} -> {load_after[0]:.2f} on {os.cpu_count()} CPUs\n"
        + "\n".join(
            f"  {m:22s} median CPU {med[m]:7.1f} ms  ({summary['ratio_to_closed_form'][m]:.2f}x,"
            f" per scene {summary['ratio_to_closed_form_per_scene_median'][m]:.2f}x)"
            for m in timed
        )
        + f"\n  one-step vs refit sigmas: median ratio "
        f"{np.round(summary['sigma_ratio_median'], 3).tolist()}, within 10 % "
        f"{np.round(summary['sigma_within_10pct_fraction'], 2).tolist()}, all six within "
        f"10 % in {summary['scenes_all_sigmas_within_10pct']:.0%} of scenes; same annotators "
        f"flagged in {summary['flagged_same_fraction']:.0%}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
