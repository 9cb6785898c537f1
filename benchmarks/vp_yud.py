"""Benchmark automatic vanishing points on the York Urban DB, side by side with lu-vp-detect.

Usage::

    python benchmarks/vp_yud.py [--yud PATH] [--limit N] [--lu-python PYTHON] [--no-lu]

Reports, for camloc_geo.autovp without the focal length (and with it), and for PyPI
``lu-vp-detect`` given the true focal length and a wrong one (1.5x):

- focal-length relative error (share within 10 %), for ours;
- vanishing-direction angular error, each estimated direction matched to a ground-truth
  one up to sign and permutation (median over all directions, and over images of the
  per-image mean);
- horizon error: the largest vertical distance between estimated and true horizon over
  the image width, divided by the image height, and its AUC up to 0.25 (the cumulative
  histogram's area normalised to 1, as in Barinova et al., Lezama et al.);
- wall time and process CPU time per image (CPU time is less sensitive to other load on
  the machine; both single-image, one process).

``lu-vp-detect`` needs ``opencv-contrib-python<5``; it runs in a subprocess with another
interpreter (``--lu-python``, default ``benchmarks/.venv/bin/python`` when present). Make
that venv with ``python -m venv benchmarks/.venv && benchmarks/.venv/bin/pip install
lu-vp-detect 'opencv-contrib-python<5'``.

Writes ``benchmarks/out/vp_yud.json`` and PNG plots next to it. The York Urban DB is used
for testing only; nothing of it is copied (set ``CAMLOC_YUD_DIR`` to its folder).
"""

from __future__ import annotations

import argparse
import itertools
import json
import logging
import math
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import scipy.io as sio

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout

from camloc_geo import NotEnoughStructureError
from camloc_geo.autovp import detect_vanishing_points, horizon_from_up

log = logging.getLogger("vp_yud")

HERE = Path(__file__).resolve().parent
DEFAULT_YUD = Path(
    os.environ.get(
        "CAMLOC_YUD_DIR", str(HERE.parents[1] / "shared" / "data" / "yud" / "YorkUrbanDB")
    )
)
F_TRUE = 6.05317059 / 0.00896875  # 674.918 px

_LU_SCRIPT = r"""
import json, sys, time
import cv2, numpy as np
from lu_vp_detect import VPDetection
items = json.loads(sys.stdin.read())
out = []
for it in items:
    img = cv2.imread(it["path"], cv2.IMREAD_COLOR)
    rec = {"name": it["name"]}
    for tag, f in it["focals"].items():
        det = VPDetection(length_thresh=30, principal_point=None, focal_length=f, seed=1)
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            vps = det.find_vps(img)
            rec[tag] = {"dirs": np.asarray(vps, float).tolist(),
                        "time_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0}
        except Exception as exc:  # report, keep going
            rec[tag] = {"error": repr(exc), "time_s": time.perf_counter() - t0,
                        "cpu_s": time.process_time() - c0}
    out.append(rec)
print(json.dumps(out))
"""


def load_yud(root: Path) -> list[dict[str, Any]]:
    """Names, image paths and ground truth (camera y down, our pixel frame)."""
    cam = sio.loadmat(str(root / "cameraParameters.mat"))
    f = float(cam["focal"][0, 0] / cam["pixelSize"][0, 0])
    pp = cam["pp"][0].astype(float) - 0.5  # MATLAB 1-based pixel centres -> continuous
    names_raw = sio.loadmat(str(root / "Manhattan_Image_DB_Names.mat"))["Manhattan_Image_DB_Names"]
    names = [str(c[0]).rstrip("\\") for c in names_raw.ravel()]
    out = []
    for n in names:
        gt = sio.loadmat(str(root / n / f"{n}GroundTruthVP_CamParams.mat"))
        dirs = (np.diag([1.0, -1.0, 1.0]) @ gt["vp"]).T  # rows, camera y down
        dirs = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
        orth = sio.loadmat(str(root / n / f"{n}GroundTruthVP_Orthogonal_CamParams.mat"))
        dirs_orth = (np.diag([1.0, -1.0, 1.0]) @ orth["vp_orthogonal"]).T
        dirs_orth = dirs_orth / np.linalg.norm(dirs_orth, axis=1, keepdims=True)
        out.append(
            {
                "name": n,
                "path": str(root / n / f"{n}.jpg"),
                "dirs": dirs,
                "dirs_orth": dirs_orth,
                "f": f,
                "pp": pp,
            }
        )
    return out


def direction_errors(est: np.ndarray, gt: np.ndarray) -> list[float]:
    """Angles (deg) between est and gt directions, best permutation, up to sign."""
    c = np.clip(np.abs(est @ gt.T), 0.0, 1.0)
    ang = np.degrees(np.arccos(c))
    best = min(itertools.permutations(range(3)), key=lambda p: sum(ang[i, p[i]] for i in range(3)))
    return [float(ang[i, best[i]]) for i in range(3)]


def up_of(dirs: np.ndarray) -> np.ndarray:
    k = int(np.argmax(np.abs(dirs[:, 1])))
    u = dirs[k]
    return u if u[1] < 0 else -u


def gt_horizon(gt: dict[str, Any], mode: str = "hvps") -> np.ndarray:
    """Ground-truth horizon line in pixels.

    ``hvps``: the line through the two horizontal ground-truth vanishing points (the
    definition of the horizon; the ground-truth ``vp`` are measured independently and are
    not exactly orthogonal). ``vertical``: the vanishing line of the plane orthogonal to
    the ground-truth vertical direction. ``orthogonal``: the same with the
    orthogonalised ground truth (``vp_orthogonal``).
    """
    d = gt["dirs"]
    kv = int(np.argmax(np.abs(d[:, 1])))
    pp = (float(gt["pp"][0]), float(gt["pp"][1]))
    if mode == "vertical":
        return horizon_from_up(up_of(d), gt["f"], pp)
    if mode == "orthogonal":
        return horizon_from_up(up_of(gt["dirs_orth"]), gt["f"], pp)
    h1, h2 = (d[k] for k in range(3) if k != kv)
    up = np.cross(h1, h2)
    up = up / np.linalg.norm(up)
    return horizon_from_up(up if up[1] < 0 else -up, gt["f"], pp)


def horizon_error(
    up_est: np.ndarray,
    f_est: float,
    pp_est: tuple[float, float],
    gt: dict[str, Any],
    w: int,
    h: int,
    mode: str = "hvps",
) -> float:
    le = horizon_from_up(up_est, f_est, pp_est)
    lg = gt_horizon(gt, mode)
    if abs(le[1]) < 1e-9 or abs(lg[1]) < 1e-9:
        return math.inf
    errs = []
    for x in (0.0, float(w)):
        ye = -(le[0] * x + le[2]) / le[1]
        yg = -(lg[0] * x + lg[2]) / lg[1]
        errs.append(abs(ye - yg))
    return max(errs) / h


def horizon_auc(errors: list[float], cutoff: float = 0.25) -> float:
    e = np.sort(np.asarray(errors, dtype=float))
    n = len(e)
    if n == 0:
        return float("nan")
    xs = np.concatenate([[0.0], np.minimum(e[e <= cutoff], cutoff), [cutoff]])
    ys = np.concatenate([[0.0], np.arange(1, np.count_nonzero(e <= cutoff) + 1) / n])
    ys = np.append(ys, ys[-1])
    # area under the cumulative step curve
    area = float(np.sum(np.diff(xs) * ys[:-1]))
    return area / cutoff


def summarise(rows: list[dict[str, Any]], with_focal: bool) -> dict[str, Any]:
    ok = [r for r in rows if "dir_err" in r]
    all_err = [e for r in ok for e in r["dir_err"]]
    hz = [r.get("hz_err", math.inf) for r in rows]
    out: dict[str, Any] = {
        "n_images": len(rows),
        "n_failed": len(rows) - len(ok),
        "dir_err_median_deg": float(np.median(all_err)) if all_err else None,
        "dir_err_mean_of_image_means_deg": float(np.mean([np.mean(r["dir_err"]) for r in ok]))
        if ok
        else None,
        "dir_err_median_of_image_means_deg": float(np.median([np.mean(r["dir_err"]) for r in ok]))
        if ok
        else None,
        "share_dir_err_below_2deg": float(np.mean([max(r["dir_err"]) < 2 for r in ok]))
        if ok
        else None,
        "dir_err_orth_median_deg": float(np.median([e for r in ok for e in r["dir_err_orth"]]))
        if ok
        else None,
        "horizon_err_median": float(np.median(hz)),
        "horizon_auc_pct": 100.0 * horizon_auc(hz),
        "horizon_auc_vertical_gt_pct": 100.0
        * horizon_auc([r.get("hz_err_vertical", math.inf) for r in rows]),
        "horizon_auc_orthogonal_gt_pct": 100.0
        * horizon_auc([r.get("hz_err_orthogonal", math.inf) for r in rows]),
        "time_median_ms": 1000.0 * float(np.median([r["time_s"] for r in rows])),
        "time_mean_ms": 1000.0 * float(np.mean([r["time_s"] for r in rows])),
        "cpu_time_median_ms": 1000.0 * float(np.median([r["cpu_s"] for r in rows])),
    }
    if with_focal:
        fe = [abs(r["f"] - F_TRUE) / F_TRUE if "f" in r else math.inf for r in rows]
        out["focal_rel_err_median"] = float(np.median(fe))
        out["share_focal_within_10pct"] = float(np.mean(np.asarray(fe) <= 0.10))
        out["share_focal_within_15pct"] = float(np.mean(np.asarray(fe) <= 0.15))
        z = [
            abs(math.log(r["f"] / F_TRUE)) / r["focal_std_rel"]
            for r in rows
            if "f" in r and r.get("focal_std_rel")
        ]
        if z:
            out["focal_sigma_cover_1"] = float(np.mean(np.asarray(z) <= 1))
            out["focal_sigma_cover_2"] = float(np.mean(np.asarray(z) <= 2))
            out["focal_median_err_over_sigma"] = float(np.median(z))
    return out


def run_ours(
    data: list[dict[str, Any]], focal: float | None, **kwargs: Any
) -> list[dict[str, Any]]:
    import cv2

    rows = []
    for gt in data:
        img = cv2.imread(gt["path"], cv2.IMREAD_COLOR)
        if img is None:
            raise SystemExit(f"{gt['path']}: cannot read the photo")
        h, w = img.shape[:2]
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            res = detect_vanishing_points(img, focal_px=focal, seed=0, **kwargs)
        except NotEnoughStructureError as exc:
            rows.append(
                {
                    "name": gt["name"],
                    "error": str(exc),
                    "time_s": time.perf_counter() - t0,
                    "cpu_s": time.process_time() - c0,
                }
            )
            continue
        dt, dc = time.perf_counter() - t0, time.process_time() - c0
        rows.append(
            {
                "name": gt["name"],
                "time_s": dt,
                "cpu_s": dc,
                "f": res.focal_px,
                "focal_source": res.focal_source,
                "confidence": res.confidence,
                "focal_std_rel": res.focal_std_rel,
                "dir_err": direction_errors(res.directions_in_cam, gt["dirs"]),
                "hz_err": horizon_error(res.up_in_cam, res.focal_px, res.principal_point, gt, w, h),
                "hz_err_vertical": horizon_error(
                    res.up_in_cam, res.focal_px, res.principal_point, gt, w, h, "vertical"
                ),
                "hz_err_orthogonal": horizon_error(
                    res.up_in_cam, res.focal_px, res.principal_point, gt, w, h, "orthogonal"
                ),
                "dir_err_orth": direction_errors(res.directions_in_cam, gt["dirs_orth"]),
            }
        )
    return rows


def run_lu(data: list[dict[str, Any]], python: str) -> dict[str, list[dict[str, Any]]]:
    items = [
        {"name": g["name"], "path": g["path"], "focals": {"true": F_TRUE, "x1.5": 1.5 * F_TRUE}}
        for g in data
    ]
    proc = subprocess.run(
        [python, "-c", _LU_SCRIPT],
        input=json.dumps(items),
        capture_output=True,
        text=True,
        check=False,
    )
    if proc.returncode != 0:
        raise RuntimeError(f"lu-vp-detect run failed: {proc.stderr.strip()[-2000:]}")
    raw = json.loads(proc.stdout)
    out: dict[str, list[dict[str, Any]]] = {"true": [], "x1.5": []}
    for gt, rec in zip(data, raw, strict=True):
        for tag, f in (("true", F_TRUE), ("x1.5", 1.5 * F_TRUE)):
            r = rec[tag]
            row: dict[str, Any] = {"name": gt["name"], "time_s": r["time_s"], "cpu_s": r["cpu_s"]}
            if "dirs" in r:
                d = np.asarray(r["dirs"], float)
                d = d / np.linalg.norm(d, axis=1, keepdims=True)
                row["dir_err"] = direction_errors(d, gt["dirs"])
                row["dir_err_orth"] = direction_errors(d, gt["dirs_orth"])
                row["hz_err"] = horizon_error(up_of(d), f, (320.0, 240.0), gt, 640, 480)
                row["hz_err_vertical"] = horizon_error(
                    up_of(d), f, (320.0, 240.0), gt, 640, 480, "vertical"
                )
                row["hz_err_orthogonal"] = horizon_error(
                    up_of(d), f, (320.0, 240.0), gt, 640, 480, "orthogonal"
                )
            else:
                row["error"] = r["error"]
            out[tag].append(row)
    return out


def plots(results: dict[str, list[dict[str, Any]]], out_dir: Path) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        log.warning("matplotlib missing: no plots")
        return
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for name, rows in results.items():
        hz = np.sort([r.get("hz_err", math.inf) for r in rows])
        ax.step(
            np.concatenate([[0], hz]),
            np.arange(len(hz) + 1) / len(hz),
            where="post",
            label=f"{name} (AUC {100 * horizon_auc(list(hz)):.1f} %)",
        )
    ax.set_xlim(0, 0.25)
    ax.set_ylim(0, 1)
    ax.set_xlabel("horizon error / image height")
    ax.set_ylabel("share of images")
    ax.set_title("York Urban DB: horizon error")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out_dir / "vp_yud_horizon.png", dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 4.5))
    for name, rows in results.items():
        e = np.sort([x for r in rows for x in r.get("dir_err", [math.inf] * 3)])
        ax.step(np.concatenate([[0], e]), np.arange(len(e) + 1) / len(e), where="post", label=name)
    ax.set_xlim(0, 10)
    ax.set_ylim(0, 1)
    ax.set_xlabel("vanishing direction error (deg)")
    ax.set_ylabel("share of directions")
    ax.set_title("York Urban DB: vanishing direction error")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out_dir / "vp_yud_directions.png", dpi=120)
    plt.close(fig)

    ours = results.get("ours (focal unknown)")
    if ours:
        fe = [100 * (r["f"] - F_TRUE) / F_TRUE for r in ours if "f" in r]
        fig, ax = plt.subplots(figsize=(6, 4.5))
        ax.hist(np.clip(fe, -60, 60), bins=48, range=(-60, 60))
        ax.axvspan(-10, 10, color="g", alpha=0.15)
        ax.set_xlabel("focal length error (%)")
        ax.set_ylabel("images")
        ax.set_title("York Urban DB: estimated focal length (truth 674.9 px)")
        fig.tight_layout()
        fig.savefig(out_dir / "vp_yud_focal.png", dpi=120)
        plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--yud", type=Path, default=DEFAULT_YUD)
    ap.add_argument("--limit", type=int, default=None)
    ap.add_argument("--out", type=Path, default=HERE / "out")
    default_lu = HERE / ".venv" / "bin" / "python"
    ap.add_argument(
        "--lu-python", default=str(default_lu) if default_lu.exists() else sys.executable
    )
    ap.add_argument("--no-lu", action="store_true")
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    if not args.yud.exists():
        log.error("York Urban DB not found at %s", args.yud)
        return 2
    data = load_yud(args.yud)[: args.limit]
    # Warm up OpenCV / numpy so the first image's time is not the import time.
    detect_vanishing_points(data[0]["path"])
    results: dict[str, list[dict[str, Any]]] = {}
    results["ours (focal unknown)"] = run_ours(data, None)
    results["ours (true focal given)"] = run_ours(data, F_TRUE)
    results["ours (f unknown, pp refined)"] = run_ours(data, None, estimate_principal_point=True)
    results["ours (f unknown, no k1)"] = run_ours(data, None, estimate_distortion=False)
    if not args.no_lu:
        lu = run_lu(data, args.lu_python)
        results["lu-vp-detect (true focal)"] = lu["true"]
        results["lu-vp-detect (focal x1.5)"] = lu["x1.5"]
    summary = {
        name: summarise(rows, with_focal=name.startswith("ours (f"))
        for name, rows in results.items()
    }
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "vp_yud.json", "w", encoding="utf-8") as fh:
        json.dump({"summary": summary, "per_image": results}, fh, indent=1, default=float)
    plots(results, args.out)
    keys = [
        ("dir_err_median_deg", "dir med (deg)", "{:.2f}"),
        ("dir_err_median_of_image_means_deg", "img-mean med", "{:.2f}"),
        ("dir_err_orth_median_deg", "dir-orth med", "{:.2f}"),
        ("horizon_auc_pct", "hz AUC %", "{:.1f}"),
        ("horizon_auc_vertical_gt_pct", "hzAUC vertGT", "{:.1f}"),
        ("horizon_auc_orthogonal_gt_pct", "hzAUC orthGT", "{:.1f}"),
        ("horizon_err_median", "hz med", "{:.4f}"),
        ("share_focal_within_10pct", "f<=10%", "{:.2f}"),
        ("focal_rel_err_median", "f med err", "{:.3f}"),
        ("focal_sigma_cover_1", "1sig cov", "{:.2f}"),
        ("focal_sigma_cover_2", "2sig cov", "{:.2f}"),
        ("focal_median_err_over_sigma", "med err/sig", "{:.2f}"),
        ("time_median_ms", "ms/img", "{:.0f}"),
        ("cpu_time_median_ms", "cpu ms/img", "{:.0f}"),
        ("n_failed", "failed", "{}"),
    ]
    head = f"{'method':28s} " + " ".join(f"{k[1]:>13s}" for k in keys)
    lines = [head]
    for name, s in summary.items():
        cells = []
        for k, _, fmt in keys:
            v = s.get(k)
            cells.append(f"{'-' if v is None else fmt.format(v):>13s}")
        lines.append(f"{name:28s} " + " ".join(cells))
    log.info("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
