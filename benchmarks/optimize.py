"""Benchmark the soft-L1 solvers of :mod:`camloc_geo._optimize` on real calibration problems.

Every joint fit that :func:`camloc_geo.relative.calibrate` runs on synthetic scenes (real
intersections of ``data/osm``) is recorded, then solved again by the home-made
Levenberg-Marquardt loop (``method="lm"``) and by ``scipy.optimize.least_squares(
loss="soft_l1")`` (``method="scipy"``) from the same start. Reported: time per fit, residual
evaluations, and how far apart the two minima are (cost, parameters). Results go to
``benchmarks/out/optimize.json`` (and ``optimize.png`` when matplotlib is installed)::

    python benchmarks/optimize.py [--scenes 12] [--seed 0]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from camloc_geo import relative
from camloc_geo._optimize import soft_l1_least_squares
from camloc_geo.osm import load_map
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import NoiseModel, make_located_scene

HERE = Path(__file__).resolve().parent
OSM = HERE.parent / "data" / "osm"


def record_problems(n_scenes: int, seed: int) -> list[tuple[Any, ...]]:
    """The joint-fit problems calibrate() solves on ``n_scenes`` synthetic scenes."""
    problems: list[tuple[Any, ...]] = []
    original = relative._fit

    def spy(prob: Any, x0: Any, R0: Any, pp: Any, f: Any, **kw: Any) -> Any:
        problems.append((prob, np.array(x0, float), R0, pp, f, kw))
        return original(prob, x0, R0, pp, f, **kw)

    m = load_map(OSM / "baltimore.osm.pbf", 39.2851, -76.5934, radius_m=300)
    rng = np.random.default_rng(seed)
    junctions = [i for i in m.intersections if i.kind == "junction" and len(i.corners) >= 3]
    relative._fit = spy  # type: ignore[assignment]
    try:
        for inter in junctions[:n_scenes]:
            ls = make_located_scene(m, inter, rng, noise=NoiseModel(), max_tries=100)
            if ls is not None:
                relative.calibrate(parse_scene(ls.scene))
    finally:
        relative._fit = original  # type: ignore[assignment]
    return problems


def solve(problem: tuple[Any, ...], method: str, repeat: int) -> tuple[Any, float]:
    prob, x0, R0, pp, f, kw = problem
    weights = prob.weights.copy()

    def clamp(x: Any) -> Any:
        x = x.copy()
        x[0] = float(np.clip(x[0], *prob.log_f_bounds))
        return x

    best = float("inf")
    res = None
    for _ in range(repeat):
        prob.weights = weights
        t = time.perf_counter()
        res = soft_l1_least_squares(
            lambda x: prob.residuals(x, R0, pp, f),
            lambda x: prob.jacobian(x, R0, pp, f),
            x0,
            f_scale=relative._F_SCALE,
            project=clamp if f is None else None,
            method=method,  # type: ignore[arg-type]
            tol=kw.get("tol", 1e-10),
            max_nfev=kw.get("max_nfev", 200),
        )
        best = min(best, time.perf_counter() - t)
    return res, best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", type=int, default=12)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", type=Path, default=HERE / "out")
    args = ap.parse_args()
    problems = record_problems(args.scenes, args.seed)
    rows = []
    for p in problems:
        lm, t_lm = solve(p, "lm", args.repeat)
        sp, t_sp = solve(p, "scipy", args.repeat)
        rows.append(
            {
                "n_params": len(p[1]),
                "n_residuals": len(lm.fun),
                "lm_ms": 1e3 * t_lm,
                "scipy_ms": 1e3 * t_sp,
                "lm_nfev": lm.nfev,
                "scipy_nfev": sp.nfev,
                "lm_cost": lm.cost,
                "scipy_cost": sp.cost,
                "cost_rel_diff": (lm.cost - sp.cost) / max(sp.cost, 1e-12),
                "x_max_abs_diff": float(np.max(np.abs(lm.x - sp.x))),
            }
        )
    lm_ms = np.array([r["lm_ms"] for r in rows])
    sp_ms = np.array([r["scipy_ms"] for r in rows])
    rel = np.array([r["cost_rel_diff"] for r in rows])
    summary = {
        "fits": len(rows),
        "lm_ms_median": float(np.median(lm_ms)),
        "scipy_ms_median": float(np.median(sp_ms)),
        "speedup_median": float(np.median(sp_ms / lm_ms)),
        "lm_total_s": float(lm_ms.sum() / 1e3),
        "scipy_total_s": float(sp_ms.sum() / 1e3),
        "cost_rel_diff_median": float(np.median(rel)),
        "cost_rel_diff_max": float(np.max(rel)),
        "lm_worse_by_1e-3": int(np.sum(rel > 1e-3)),
        "scipy_worse_by_1e-3": int(np.sum(rel < -1e-3)),
    }
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "optimize.json").write_text(
        json.dumps({"summary": summary, "fits": rows}, indent=1)
    )
    print(json.dumps(summary, indent=1))
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.scatter(sp_ms, lm_ms, s=10)
    lim = max(sp_ms.max(), lm_ms.max())
    ax.plot([0, lim], [0, lim], "k--", lw=0.8)
    ax.set_xlabel("scipy least_squares(soft_l1) ms")
    ax.set_ylabel("home-made LM ms")
    ax.set_title(f"{len(rows)} calibration fits")
    fig.tight_layout()
    fig.savefig(args.out / "optimize.png", dpi=100)


if __name__ == "__main__":
    main()
