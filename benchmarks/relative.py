"""Benchmark of the relative pose (``camloc_geo.relative.calibrate``) on synthetic scenes.

Draws ``--n`` synthetic scenes with :mod:`camloc_geo.testing.synthetic` (noise model in
``benchmarks/README.md``), calibrates each with the joint robust fit (the default) and with
the paper's cluster baseline (``CalibrationSettings(joint_fit=False)``), and writes

- ``benchmarks/out/relative.json``: error percentiles, the fractions of scenes under the
  paper's thresholds (position < 5 m / < 10 m, height < 1 m / < 3 m), focal length errors,
  failures, and the timing of ``calibrate`` for five-annotator scenes;
- ``benchmarks/out/relative.png``: CDFs of the position and height errors of both methods
  with the paper's figures marked.

Usage::

    python benchmarks/relative.py --n 300

A scene that ``calibrate`` refuses (an error) counts as a failure with infinite error, so the
fractions are over all scenes drawn.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import platform
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from camloc_geo import InputError
from camloc_geo.camera import Camera
from camloc_geo.objects import PRESETS
from camloc_geo.relative import CalibrationSettings, calibrate
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import NoiseModel, make_scene, random_camera

OUT_DIR = Path(__file__).parent / "out"
IMAGE_SIZES = ((1280, 720), (1920, 1080))
PAPER = {"position_error_m": {5.0: 0.80, 10.0: 0.95}, "height_error_m": {1.0: 0.80, 3.0: 0.95}}
METHODS = {
    "joint_fit": CalibrationSettings(),
    "cluster_baseline": CalibrationSettings(joint_fit=False),
}
PERCENTILES = (50, 80, 90, 95, 99)


def draw_scene(
    rng: np.random.Generator,
    index: int,
    noise: NoiseModel,
    n_annotators: int | None = None,
    pp_sigma_rel: float | None = None,
) -> Any:
    """One synthetic scene: image size, annotator count, side of the width edge, camera.

    The principal point lies uniformly within ±1 % of the width off centre per axis; with
    ``pp_sigma_rel``, Gaussian instead, that fraction of the diagonal per axis.
    """
    size = IMAGE_SIZES[int(rng.integers(len(IMAGE_SIZES)))]
    n_ann = int(rng.integers(3, 8)) if n_annotators is None else n_annotators
    ws = 1.0 if rng.random() < 0.5 else -1.0
    cam = random_camera(
        rng,
        image_size=size,
        height_m=(2.0, 15.0),
        distance_m=(8.0, 40.0),
        roll_deg=4.0,
        pp_offset_px=0.01 * size[0],
        width_sign=ws,
    )
    if pp_sigma_rel is not None:
        offset = rng.normal(0.0, pp_sigma_rel * math.hypot(*size), 2)
        pp = (size[0] / 2.0 + float(offset[0]), size[1] / 2.0 + float(offset[1]))
        cam = Camera.from_center(cam.focal_px, pp, cam.cam_from_world_rotation, cam.center_in_world)
    syn = make_scene(
        cam,
        rng,
        preset=PRESETS["sedan"],
        noise=noise,
        n_annotators=n_ann,
        image_size=size,
        width_sign=ws,
        scene_id=f"bench-{index:04d}",
    )
    # The scene states only the preset's name, as a user who does not know the car would.
    syn.scene["object"] = {"preset": "sedan"}
    return syn, size, n_ann


def parse_settings(text: str) -> dict[str, Any]:
    """``NAME=VALUE[,NAME=VALUE]`` (a benchmark's ``--settings``): CalibrationSettings fields,
    each value read as its default's type (``inf`` for a float; ``true``/``false``)."""
    defaults = CalibrationSettings()
    out: dict[str, Any] = {}
    for item in filter(None, (t.strip() for t in text.split(","))):
        name, _, value = item.partition("=")
        if not hasattr(defaults, name):
            raise SystemExit(f"--settings: CalibrationSettings has no field {name!r}")
        kind = type(getattr(defaults, name))
        out[name] = value.lower() in ("1", "true", "yes") if kind is bool else kind(value)
    return out


def add_settings_options(parser: argparse.ArgumentParser) -> None:
    """The calibrate-settings options the sigma benchmarks share (``calibrate_coverage``,
    ``crowd_slips``): ``--jackknife-leverage``, ``--class-prior``, ``--settings``; read them
    back with :func:`settings_from_args`."""
    parser.add_argument(
        "--jackknife-leverage",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="the jackknife's leverage correction, CalibrationSettings.jackknife_leverage "
        "(default on since stop 38; --no-jackknife-leverage: stop 37's default)",
    )
    parser.add_argument(
        "--class-prior",
        type=float,
        default=CalibrationSettings().car_class_prior,
        help="CalibrationSettings.car_class_prior, the prior odds per other car preset "
        "(default %(default)s; 0: stop 37's sigmas, no class mixture)",
    )
    parser.add_argument(
        "--settings",
        default="",
        help="more CalibrationSettings fields, NAME=VALUE[,NAME=VALUE] (a diagnostic: e.g. "
        "jackknife_leverage_max_move=inf)",
    )


def settings_from_args(args: argparse.Namespace, **fields: Any) -> CalibrationSettings:
    """The CalibrationSettings of :func:`add_settings_options`' options, with ``fields``
    (a benchmark's own options) under ``--settings``."""
    return CalibrationSettings(
        **{"jackknife_leverage": args.jackknife_leverage, "car_class_prior": args.class_prior}
        | fields
        | parse_settings(args.settings)
    )


def _has_lines(scene: dict[str, Any]) -> bool:
    """At least one annotator drew two or more segments of every axis."""
    return any(
        all(len(ann["vp_lines"][axis]) >= 2 for axis in ("length", "width", "height"))
        for ann in scene["annotations"]
    )


def _percentiles(values: np.ndarray) -> dict[str, float | None]:
    finite = np.where(np.isfinite(values), values, np.inf)
    out: dict[str, float | None] = {}
    for p in PERCENTILES:
        v = float(np.percentile(finite, p)) if len(finite) else math.inf
        out[f"p{p}"] = v if math.isfinite(v) else None  # None: beyond the failures
    return out


def _summary(rows: list[dict[str, Any]], method: str) -> dict[str, Any]:
    pos = np.array([r[method]["position_error_m"] for r in rows], float)
    hgt = np.array([r[method]["height_error_m"] for r in rows], float)
    foc = np.array([r[method]["focal_rel_error"] for r in rows], float)
    failures: dict[str, int] = {}
    for r in rows:
        err = r[method].get("error")
        if err:
            failures[err] = failures.get(err, 0) + 1
    n = len(rows)
    outliers_true = sum(r["n_wrong_corner"] for r in rows)
    caught = sum(r[method].get("wrong_corner_caught", 0) for r in rows)
    flagged = sum(r[method].get("n_flagged", 0) for r in rows)
    warned = [bool(r[method].get("focal_limit_warning")) for r in rows]
    return {
        "n_scenes": n,
        "n_focal_limit_warnings": int(sum(warned)),
        "n_focal_limit_warnings_with_position_error_gt_10m": int(
            sum(w and p >= 10.0 for w, p in zip(warned, pos, strict=True))
        ),
        "n_failures": int(np.sum(~np.isfinite(pos))),
        "failures_by_error": failures,
        "position_error_m": _percentiles(pos),
        "height_error_m": _percentiles(hgt),
        "focal_rel_error": _percentiles(foc),
        "fraction_position_lt_5m": float(np.mean(pos < 5.0)),
        "fraction_position_lt_10m": float(np.mean(pos < 10.0)),
        "fraction_height_lt_1m": float(np.mean(hgt < 1.0)),
        "fraction_height_lt_3m": float(np.mean(hgt < 3.0)),
        "fraction_focal_lt_5pct": float(np.mean(foc < 0.05)),
        "fraction_focal_lt_10pct": float(np.mean(foc < 0.10)),
        "relative_position_error": _percentiles(pos / np.array([r["distance_m"] for r in rows])),
        "wrong_corner_annotators": {
            "total": outliers_true,
            "flagged_correctly": caught,
            "flagged_total": flagged,
        },
    }


def run_scene(syn: Any, method: str) -> dict[str, Any]:
    """Errors of one method on one scene."""
    truth = syn.camera
    try:
        res = calibrate(parse_scene(syn.scene), METHODS[method])
    except InputError as exc:
        return {
            "position_error_m": math.inf,
            "height_error_m": math.inf,
            "focal_rel_error": math.inf,
            "error": type(exc).__name__,
            "message": str(exc)[:200],
        }
    cam = res.camera
    wrong = {f"w{i + 1}" for i, w in enumerate(syn.wrong_corner) if w}
    return {
        "position_error_m": float(np.linalg.norm(cam.center_in_world - truth.center_in_world)),
        "height_error_m": float(abs(cam.height_m - truth.height_m)),
        "focal_rel_error": float(abs(cam.focal_px - truth.focal_px) / truth.focal_px),
        "intrinsics_method": res.intrinsics_method,
        "method": res.method,
        # An annotator who marked the wrong corner is caught when the fit names them: as a
        # corner mistake (the joint fit re-interprets their clicks) or as an outlier.
        "wrong_corner_caught": len(
            wrong & (set(res.outlier_annotators) | set(res.corner_mistakes))
        ),
        "n_flagged": len(set(res.outlier_annotators) | set(res.corner_mistakes)),
        "focal_limit_warning": any("focal length" in w and "limit" in w for w in res.warnings),
    }


def time_calibrate(seed: int, n_scenes: int = 20, repeats: int = 5) -> dict[str, Any]:
    """Median wall time of ``calibrate`` (joint fit) as a library call, five annotators."""
    rng = np.random.default_rng(seed + 1)
    scenes: list[Any] = []
    while len(scenes) < n_scenes:
        syn, _size, _n = draw_scene(rng, len(scenes), NoiseModel(), n_annotators=5)
        scene = parse_scene(syn.scene)
        try:
            calibrate(scene)  # warm-up, and skip scenes the method refuses
        except InputError:
            continue
        scenes.append(scene)
    load_before = os.getloadavg()
    per_scene = []
    all_ms = []
    cpu_ms = []
    for scene in scenes:
        times = []
        for _ in range(repeats):
            t0, c0 = time.perf_counter(), time.process_time()
            calibrate(scene)
            times.append((time.perf_counter() - t0) * 1000.0)
            cpu_ms.append((time.process_time() - c0) * 1000.0)
        per_scene.append(float(np.median(times)))
        all_ms += times
    cluster_ms = []
    for scene in scenes:
        t0 = time.perf_counter()
        calibrate(scene, METHODS["cluster_baseline"])
        cluster_ms.append((time.perf_counter() - t0) * 1000.0)
    load_after = os.getloadavg()
    return {
        "n_annotators": 5,
        "n_scenes": n_scenes,
        "repeats": repeats,
        "median_ms": float(np.median(all_ms)),
        "median_cpu_ms": float(np.median(cpu_ms)),
        "min_ms": float(np.min(all_ms)),
        "p90_ms": float(np.percentile(all_ms, 90)),
        "per_scene_median_ms_range": [float(min(per_scene)), float(max(per_scene))],
        "cluster_baseline_median_ms": float(np.median(cluster_ms)),
        "target_ms": 20.0,
        "loadavg_before": [round(x, 2) for x in load_before],
        "loadavg_after": [round(x, 2) for x in load_after],
        "cpu_count": os.cpu_count(),
    }


def plot(rows: list[dict[str, Any]], path: Path) -> None:
    """CDFs of position and height errors for both methods, the paper's figures marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    labels = {
        "joint_fit": "joint robust fit (ours)",
        "cluster_baseline": "cluster centroid (paper's method)",
    }
    for ax, key, xmax, unit in (
        (axes[0], "position_error_m", 20.0, "camera position error (m)"),
        (axes[1], "height_error_m", 5.0, "camera height error (m)"),
    ):
        for method, style in (("joint_fit", "-"), ("cluster_baseline", "--")):
            err = np.sort(np.array([r[method][key] for r in rows], float))
            frac = np.arange(1, len(err) + 1) / len(err)
            ax.step(np.minimum(err, 1e9), frac, style, where="post", label=labels[method])
        for x, y in PAPER[key].items():
            ax.plot([x], [y], "k*", markersize=11)
            ax.annotate(
                f"paper: {y:.0%} < {x:g} m", (x, y), textcoords="offset points", xytext=(6, -14)
            )
        ax.set_xlim(0, xmax)
        ax.set_ylim(0, 1.0)
        ax.set_xlabel(unit)
        ax.set_ylabel("fraction of scenes")
        ax.grid(alpha=0.3)
        ax.legend(loc="lower right", fontsize=8)
    fig.suptitle(
        f"Relative pose on {len(rows)} synthetic scenes (failures count as infinite error)"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=300, help="number of scenes (default 300)")
    parser.add_argument("--seed", type=int, default=20261122, help="random seed")
    parser.add_argument("--out", type=Path, default=OUT_DIR, help="output folder")
    parser.add_argument("--no-timing", action="store_true", help="skip the timing runs")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.ERROR)
    args.out.mkdir(parents=True, exist_ok=True)
    noise = NoiseModel()
    rng = np.random.default_rng(args.seed)
    rows = []
    t_start = time.perf_counter()
    redrawn = 0
    for i in range(args.n):
        syn, size, n_ann = draw_scene(rng, i, noise)
        while not _has_lines(syn.scene):
            # The camera sees fewer than two segments of an axis in all: not a valid scene.
            redrawn += 1
            syn, size, n_ann = draw_scene(rng, i, noise)
        row: dict[str, Any] = {
            "index": i,
            "image_size": list(size),
            "n_annotators": n_ann,
            "n_wrong_corner": int(sum(syn.wrong_corner)),
            "distance_m": float(np.linalg.norm(syn.camera.center_in_world)),
            "height_m": syn.camera.height_m,
            "focal_px": syn.camera.focal_px,
        }
        for method in METHODS:
            row[method] = run_scene(syn, method)
        rows.append(row)
    elapsed = time.perf_counter() - t_start
    summary = {method: _summary(rows, method) for method in METHODS}
    by_annotators = {
        str(k): {
            method: float(
                np.mean(
                    [r[method]["position_error_m"] < 5.0 for r in rows if r["n_annotators"] == k]
                )
            )
            for method in METHODS
        }
        for k in sorted({r["n_annotators"] for r in rows})
    }
    result = {
        "benchmark": "relative",
        "seed": args.seed,
        "n_scenes": args.n,
        "noise_model": {k: getattr(noise, k) for k in noise.__dataclass_fields__},
        "scene_distribution": {
            "image_sizes": [list(s) for s in IMAGE_SIZES],
            "annotators": [3, 7],
            "camera_height_m": [2.0, 15.0],
            "horizontal_distance_m": [8.0, 40.0],
            "horizontal_fov_deg": [30.0, 90.0],
            "roll_deg": [-4.0, 4.0],
            "principal_point_offset": "uniform within ±1 % of the image width per axis",
            "width_side": "+y or -y with equal probability",
            "object": (
                'scene says {"preset": "sedan"} (4.60 × 1.80 × 1.45 m); the true size differs by '
                "noise_model.size_rel per dimension"
            ),
        },
        "paper": {
            "position_lt_5m": 0.80,
            "position_lt_10m": 0.95,
            "height_lt_1m": 0.80,
            "height_lt_3m": 0.95,
        },
        "summary": summary,
        "fraction_position_lt_5m_by_annotators": by_annotators,
        "redrawn_scenes_without_lines": redrawn,
        "wall_time_s": round(elapsed, 1),
        "python": platform.python_version(),
        "scenes": _finite_or_none(rows),
    }
    if not args.no_timing:
        result["timing"] = time_calibrate(args.seed)
    (args.out / "relative.json").write_text(
        json.dumps(result, indent=1, allow_nan=False, default=_json_default) + "\n"
    )
    plot(rows, args.out / "relative.png")
    _print(result)
    return 0


def _finite_or_none(value: Any) -> Any:
    """Infinite errors (failures) as JSON null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite_or_none(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite_or_none(v) for v in value]
    return value


def _json_default(value: Any) -> Any:
    raise TypeError(f"not JSON serialisable: {value!r}")


def _print(result: dict[str, Any]) -> None:
    out = sys.stdout
    out.write(
        f"relative pose, {result['n_scenes']} scenes, seed {result['seed']}, "
        f"{result['wall_time_s']} s\n"
    )
    out.write(
        f"{'':18s}{'pos<5m':>8s}{'pos<10m':>8s}{'h<1m':>8s}{'h<3m':>8s}{'f<5%':>8s}{'fail':>6s}\n"
    )
    p = result["paper"]
    out.write(
        f"{'paper':18s}{p['position_lt_5m']:8.0%}{p['position_lt_10m']:8.0%}"
        f"{p['height_lt_1m']:8.0%}{p['height_lt_3m']:8.0%}{'':>8s}{'':>6s}\n"
    )
    for method, s in result["summary"].items():
        out.write(
            f"{method:18s}{s['fraction_position_lt_5m']:8.1%}{s['fraction_position_lt_10m']:8.1%}"
            f"{s['fraction_height_lt_1m']:8.1%}{s['fraction_height_lt_3m']:8.1%}"
            f"{s['fraction_focal_lt_5pct']:8.1%}{s['n_failures']:6d}\n"
        )
    t = result.get("timing")
    if t:
        out.write(
            f"calibrate (joint fit, 5 annotators): median {t['median_ms']:.1f} ms wall, "
            f"{t['median_cpu_ms']:.1f} ms CPU, min {t['min_ms']:.1f} ms "
            f"(target {t['target_ms']:.0f} ms); "
            f"cluster baseline {t['cluster_baseline_median_ms']:.1f} ms; "
            f"load average {t['loadavg_before'][0]} -> {t['loadavg_after'][0]} "
            f"on {t['cpu_count']} CPUs\n"
        )


if __name__ == "__main__":
    sys.exit(main())
