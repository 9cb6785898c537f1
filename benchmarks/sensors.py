"""Benchmark of the virtual scale and clinometer (``camloc_geo.sensors``) on noisy scenes.

Draws ``--n`` synthetic scenes (same camera and annotation-noise model as
``benchmarks/relative.py``: crowd clicks of 2 px, lines of 1 px, 10 % wrong corners, 10 %
sloppy annotators, car size ±5 % while the scene states only the ``sedan`` preset),
calibrates each, and measures with the calibrated camera:

- scale: two ground points visible in the image (random pixels below the horizon, at least
  2 m apart), clicked with ``--click-sigma-px`` noise; error = |measured - true| / true;
- clinometer: a ground point and the point ``3-25 m`` above it (a building's roof edge), both
  visible, clicked with the same noise; error = |measured - true| / true.

The calibration's orientation error about the camera's axes is compared with its
``rotation_sigma_deg`` (fraction within 2 sigma per axis).

Writes ``benchmarks/out/sensors.json`` (percentiles, fraction within 2 sigma, the paper's
targets: scale < 20 %, building height < 25 % at p90) and ``sensors.png`` (CDFs) when
matplotlib is available. A scene whose calibration fails counts as an infinite error.

Usage::

    python benchmarks/sensors.py --n 200
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from camloc_geo import InputError
from camloc_geo.camera import Camera
from camloc_geo.relative import calibrate
from camloc_geo.scene import parse_scene
from camloc_geo.sensors import ground_distance, point_height

sys.path.insert(0, str(Path(__file__).parent))
from relative import draw_scene

from camloc_geo.testing.synthetic import NoiseModel

OUT_DIR = Path(__file__).parent / "out"
PAPER_P90 = {"scale_rel_error": 0.20, "height_rel_error": 0.25}
PERCENTILES = (50, 80, 90, 95)


def _ground_pixel(cam: Camera, size: tuple[int, int], rng: np.random.Generator) -> np.ndarray:
    w, h = size
    for _ in range(100):
        px = np.array([rng.uniform(0.05 * w, 0.95 * w), rng.uniform(0.05 * h, 0.95 * h)])
        p = cam.ground_from_pixels(px)
        if np.all(np.isfinite(p)) and np.linalg.norm(p[:2] - cam.center_in_world[:2]) < 150:
            return px
    raise RuntimeError("no ground in view")


def _targets(
    cam: Camera, size: tuple[int, int], rng: np.random.Generator
) -> tuple[np.ndarray, float, np.ndarray, float]:
    """Two ground pixels and their distance; base/top pixels and the height."""
    w, h = size
    while True:
        a, b = _ground_pixel(cam, size, rng), _ground_pixel(cam, size, rng)
        pa, pb = cam.ground_from_pixels(np.array([a, b]))
        dist = float(np.linalg.norm(pa - pb))
        if dist >= 2.0:
            break
    for _ in range(1000):
        base = _ground_pixel(cam, size, rng)
        g = cam.ground_from_pixels(base)
        height = float(rng.uniform(3.0, 25.0))
        top = cam.project(g + np.array([0.0, 0.0, height]))
        if np.all(np.isfinite(top)) and 0 <= top[0] <= w and 0 <= top[1] <= h:
            return np.array([a, b]), dist, np.array([base, top]), height
    raise RuntimeError("no building fits in view")


def _pct(values: np.ndarray) -> dict[str, float | None]:
    out: dict[str, float | None] = {}
    for p in PERCENTILES:
        v = float(np.percentile(values, p))
        out[f"p{p}"] = v if math.isfinite(v) else None
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--seed", type=int, default=15)
    ap.add_argument("--click-sigma-px", type=float, default=1.5)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    noise = NoiseModel()
    rows: list[dict[str, Any]] = []
    for i in range(args.n):
        syn, size, n_ann = draw_scene(rng, i, noise)
        cam = syn.camera
        ground_px, dist, vert_px, height = _targets(cam, size, rng)
        row: dict[str, Any] = {"scene": i, "n_annotators": n_ann, "true_distance_m": dist}
        row["true_height_m"] = height
        click = rng.normal(0.0, args.click_sigma_px, (4, 2))
        try:
            cal = calibrate(parse_scene(syn.scene))
            d = ground_distance(cal, ground_px + click[:2], click_sigma_px=args.click_sigma_px)
            hm = point_height(cal, *(vert_px + click[2:]), click_sigma_px=args.click_sigma_px)
        except InputError as exc:
            row.update(error=str(exc), scale_rel_error=math.inf, height_rel_error=math.inf)
            rows.append(row)
            continue
        row.update(
            distance_m=d.value_m,
            distance_sigma_m=d.sigma_m,
            height_m=hm.value_m,
            height_sigma_m=hm.sigma_m,
            scale_rel_error=abs(d.value_m - dist) / dist,
            height_rel_error=abs(hm.value_m - height) / height,
            distance_within_2sigma=abs(d.value_m - dist) <= 2 * d.sigma_m,
            height_within_2sigma=abs(hm.value_m - height) <= 2 * hm.sigma_m,
        )
        if cal.rotation_sigma_deg is not None:
            # Orientation error about the camera's axes: rotvec(R_cal · R_trueᵀ), degrees.
            turn = Rotation.from_matrix(
                cal.camera.cam_from_world_rotation @ cam.cam_from_world_rotation.T
            ).as_rotvec()
            if np.linalg.norm(turn) < math.radians(30.0):  # else another frame
                row["rotation_error_deg"] = np.degrees(turn).tolist()
                row["rotation_sigma_deg"] = cal.rotation_sigma_deg.tolist()
        rows.append(row)
    ok = [r for r in rows if "error" not in r]
    summary: dict[str, Any] = {"n_scenes": len(rows), "n_failures": len(rows) - len(ok)}
    summary["click_sigma_px"] = args.click_sigma_px
    for key, cover in (
        ("scale_rel_error", "distance_within_2sigma"),
        ("height_rel_error", "height_within_2sigma"),
    ):
        vals = np.array([r[key] for r in rows], float)
        pct = _pct(vals)
        p90 = pct["p90"]
        summary[key] = {
            **pct,
            "mean_of_finite": float(np.mean(vals[np.isfinite(vals)])),
            "paper_p90_target": PAPER_P90[key],
            "meets_target": p90 is not None and p90 < PAPER_P90[key],
            "fraction_within_2sigma": float(np.mean([r[cover] for r in ok])) if ok else None,
        }
    rot = [r for r in ok if "rotation_error_deg" in r]
    if rot:
        z = np.abs([r["rotation_error_deg"] for r in rot]) / np.array(
            [r["rotation_sigma_deg"] for r in rot]
        )
        summary["rotation_within_2sigma_xyz"] = (z <= 2.0).mean(axis=0).tolist()
        summary["rotation_error_deg_p90_xyz"] = np.percentile(
            np.abs([r["rotation_error_deg"] for r in rot]), 90, axis=0
        ).tolist()
    OUT_DIR.mkdir(exist_ok=True)
    for r in rows:
        for k, v in r.items():
            if isinstance(v, float) and not math.isfinite(v):
                r[k] = None
    (OUT_DIR / "sensors.json").write_text(
        json.dumps({"summary": summary, "scenes": rows}, indent=2, default=bool)
    )
    print(json.dumps(summary, indent=2))
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return 0
    fig, ax = plt.subplots(figsize=(6, 4))
    for key, label in (("scale_rel_error", "scale"), ("height_rel_error", "height")):
        v = np.sort([r[key] if r[key] is not None else np.inf for r in rows])
        ax.step(100 * v, np.arange(1, len(v) + 1) / len(v), label=label)
        ax.plot(100 * PAPER_P90[key], 0.9, "*", ms=12, label=f"paper {label} p90")
    ax.set_xlim(0, 50)
    ax.set_xlabel("relative error (%)")
    ax.set_ylabel("fraction of scenes")
    ax.legend()
    fig.tight_layout()
    fig.savefig(OUT_DIR / "sensors.png", dpi=100)
    return 0


if __name__ == "__main__":
    sys.exit(main())
