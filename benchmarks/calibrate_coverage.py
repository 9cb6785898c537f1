"""Do ``calibrate``'s stated sigmas cover the truth like a Gaussian sigma?

Draws ``--n`` synthetic scenes per set (``benchmarks/relative.py``'s scene distribution,
principal point up to 1 % of the width off centre) and calibrates each with the defaults:

- ``noise_free``: ``NoiseModel.exact()`` (no click, line or size noise);
- ``noise_free_size_given``: the same scenes stating the car's true size (the preset's
  5 % size term, a user's ignorance of the car that no click shows, is then off);
- ``noise_free_pp_prior``: noise-free, the principal point drawn from the Gaussian that
  ``calibrate`` assumes (``CalibrationSettings.principal_point_sigma_rel`` of the diagonal
  per axis) instead of the uniform box: noise-free errors come from the principal point
  (and the preset's size), so this set tells the sigmas' propagation from the box's shape;
- ``crowd``: ``NoiseModel()``, the crowd noise model of ``benchmarks/README.md``;
- ``crowd_pp_prior``: the crowd noise model, the principal point drawn from ``calibrate``'s
  own Gaussian (as ``noise_free_pp_prior``): the uniform box of the other sets is narrower
  than the spread ``calibrate`` assumes (its standard deviation 0.58 % of the width against
  0.80 %), and its sigmas over-cover there by construction (stop 40).

For each stated sigma (focal length; the principal point, ``principal_point_sigma_px``;
camera position x, y, z and height; rotation about the camera's x, y, z axes) it reports
the fraction of scenes whose error is within 1σ and 2σ, the median error/σ and the tails
(``tails``: how many scenes are more than ``TAIL_Z`` = 3 stated sigmas off). A Gaussian
sigma covers 68 % and 95 %, median error/σ 0.67; issue 24 asks for 55-80 % at 1σ, 90-98 %
at 2σ, median 0.5-1.0. Writes ``benchmarks/out/calibrate_coverage.json`` and
``benchmarks/out/calibrate_coverage.png`` (the CDF of error/σ per quantity and set, the
Gaussian's for reference) and ``benchmarks/out/calibrate_coverage_hist.png`` (histograms of
error/σ of the scenes not exact, per set, against the half-normal density).

``--located N`` adds ``N`` scenes of ``benchmarks/absolute.py``'s scene maker
(:func:`camloc_geo.testing.synthetic.make_located_scene` at camloc's junctions of Monaco,
Heidelberg and Baltimore, round-robin; crowd noise, a sedan 5 % off the preset per
dimension), each calibrated twice: as made (the scene states the preset's numbers, which
``calibrate`` takes as the known size) and stating ``{"preset": "sedan"}``. Per variant:
the focal length's 1σ / 2σ coverage and median error/σ, the share more than 10 % off, and of
those the share outside 2σ and outside 2σ with no warning (the note that annotators marked
different corners does not count as one).

``--no-jackknife-leverage`` calibrates with ``CalibrationSettings(jackknife_leverage=False)``
and ``--class-prior 0`` with ``car_class_prior=0`` (both together: stop 37's sigmas; the
leverage correction and the car-class mixture are on by default since stop 38;
``--jackknife-leverage`` is accepted, the default).
``--terms`` files each scene under the term that decides each of its sigmas (the fit's
covariance, the ground-corner, preset-shape, car-line, principal-point, size or car-class
term, or the jackknife where it is the larger) and reports the coverage per term (``by_term`` in the
JSON).

``--parts`` (implies ``--terms``; the crowd sets) calibrates each scene three more times with
the same clicks and lines, stating the car's true size, the true principal point, and both,
and compares each part of the error (the size's, the principal point's, the clicks' and
lines' own) with the covariance terms that state it (``by_part`` in the JSON; stop 41).
``--sets crowd`` runs only the named sets (comma-separated); ``--variance-groups`` turns on
``CalibrationSettings.variance_groups`` (one residual variance factor per row group, off by
default); ``--settings NAME=VALUE,...`` sets any other ``CalibrationSettings`` field (a
diagnostic, e.g. ``discordant_line_t=0`` for stop 38's sigmas).

Usage::

    python benchmarks/calibrate_coverage.py --n 60 [--located 400] [--no-jackknife-leverage]
    python benchmarks/calibrate_coverage.py --n 60 --sets crowd --settings discordant_line_t=0
    python benchmarks/calibrate_coverage.py --n 60 --sets crowd --parts
"""

from __future__ import annotations

import argparse
import copy
import json
import logging
import math
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from relative import _has_lines, add_settings_options, draw_scene, settings_from_args
from scipy.spatial.transform import Rotation

from camloc_geo import InputError
from camloc_geo.relative import CalibrationSettings, calibrate
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import NoiseModel

OUT_DIR = Path(__file__).parent / "out"
SETS = {
    "noise_free": NoiseModel.exact(),
    "noise_free_size_given": NoiseModel.exact(),
    "noise_free_pp_prior": NoiseModel.exact(),
    "crowd": NoiseModel(),
    "crowd_pp_prior": NoiseModel(),
}
# Sets whose principal point is drawn from calibrate's own Gaussian prior (per axis, a
# fraction of the diagonal) rather than uniformly within ±1 % of the width.
PP_PRIOR = {
    name: CalibrationSettings().principal_point_sigma_rel
    for name in ("noise_free_pp_prior", "crowd_pp_prior")
}
# Sets whose scenes state the car's true size (length, width, height) instead of the preset's
# name: the preset's size term (a user's ignorance of the car, which no click shows) is off.
SIZE_GIVEN = {"noise_free_size_given"}
QUANTITIES = ("focal", "pp_x", "pp_y", "x", "y", "z", "height", "rot_x", "rot_y", "rot_z")
WANT = {"cover_1sigma": (0.55, 0.80), "cover_2sigma": (0.90, 0.98), "median_z": (0.5, 1.0)}
TAIL_Z = 3.0
"""A scene whose error is more than this many stated sigmas is a tail (a Gaussian: 0.27 %)."""
# calibrate's settings for every scene (``--no-jackknife-leverage``, ``--class-prior``).
SETTINGS = CalibrationSettings()


# ``--terms``: each sigma's terms, recorded by wrapping two of calibrate's private helpers
# (a diagnostic: the library does not report them). Index in the 9-vector of
# ``parameter_covariance``: focal 0, rotation 3-5 (rad), centre 6-8.
TERM_NAMES = (
    "fit",
    "ground_corner",
    "preset_shape",
    "car_lines",
    "principal_point",
    "size",
    "car_class",
)
TERM_QUANTITIES = {"focal": 0, "rot_x": 3, "rot_y": 4, "rot_z": 5, "x": 6, "y": 7, "z": 8}
_TERMS: dict[int, dict[str, list[float]]] = {}


def _record_terms() -> None:
    """Wrap ``_output_covariance`` to record each term's variances (its diagonal)."""
    from camloc_geo import relative as rel

    out_cov: Any = rel._output_covariance
    gc_sens: Any = rel._ground_corner_sensitivity

    def output_covariance(*args: Any, **kwargs: Any) -> Any:
        full = out_cov(*args, **kwargs)
        if full is None:
            return full
        names = ("sigma_pp_px", "size_rel", "car_lines", "size_shape_rel", "class_shifts")
        given = dict(zip(names, args[8:], strict=False)) | kwargs
        off = {
            "sigma_pp_px": 0.0,
            "size_rel": 0.0,
            "car_lines": None,
            "size_shape_rel": 0.0,
            "class_shifts": None,
        }

        def diag(on: str | None) -> Any:
            keep: dict[str, Any] = {
                k: (given.get(k, off[k]) if k == on else v) for k, v in off.items()
            }
            if on == "class_shifts":  # the class mixture moves through the shape columns
                keep["size_shape_rel"] = given.get("size_shape_rel", 0.0)
            rel._ground_corner_sensitivity = gc_sens if on == "gc" else (lambda *a, **k: None)
            try:
                return np.diag(out_cov(*args[:8], **keep))
            finally:
                rel._ground_corner_sensitivity = gc_sens

        fit = diag(None)
        on = ("gc", "size_shape_rel", "car_lines", "sigma_pp_px", "size_rel", "class_shifts")
        terms = {"fit": fit} | {
            name: diag(k) - fit for name, k in zip(TERM_NAMES[1:], on, strict=True)
        }
        # The class term alone: with the shape columns on, less the shape term itself.
        terms["car_class"] = terms["car_class"] - terms["preset_shape"]
        _TERMS[id(full)] = {k: v.tolist() for k, v in terms.items()}
        return full

    rel._output_covariance = output_covariance


def _dominant_terms(res: Any) -> dict[str, str] | None:
    """Per quantity of ``TERM_QUANTITIES``: the term that decides its stated sigma."""
    terms = _TERMS.get(id(res.parameter_covariance))
    if terms is None:
        return None
    pos_jack = res.position_sigma_jackknife_m
    rot_fits = res.rotation_sigma_fit_deg
    out: dict[str, str] = {}
    for q, k in TERM_QUANTITIES.items():
        var = {t: max(terms[t][k], 0.0) for t in TERM_NAMES}
        name = max(var, key=lambda t: var[t])
        cov_sd = math.sqrt(sum(var.values()))
        # The jackknife decided where the stated sigma exceeds the covariance's.
        stated: float | None = None
        cov = 0.0
        if q == "focal":
            stated, cov = res.focal_sigma_px, cov_sd
        elif q in ("x", "y", "z") and pos_jack is not None:
            stated, cov = float(pos_jack[k - 6]), cov_sd
        elif q.startswith("rot") and rot_fits is not None and res.rotation_sigma_deg is not None:
            stated, cov = float(res.rotation_sigma_deg[k - 3]), float(rot_fits[k - 3])
        if stated is not None and stated > 1.0001 * cov:
            name = "jackknife"
        out[q] = name
    return out


def scene_errors(syn: Any, terms: bool = True) -> dict[str, Any] | None:
    """Errors and stated sigmas of one scene, or None when ``calibrate`` refuses it
    (``terms`` False: the ``--terms`` record is left for the caller's own scene)."""
    if not terms:
        saved = dict(_TERMS)
    try:
        res = calibrate(parse_scene(syn.scene), SETTINGS)
    except InputError:
        return None
    finally:
        if not terms:
            _TERMS.clear()
            _TERMS.update(saved)
    truth = syn.camera
    cam = res.camera
    out: dict[str, Any] = {"method": res.intrinsics_method}
    err = {
        "focal": cam.focal_px - truth.focal_px,
        "height": cam.height_m - truth.height_m,
    }
    for k, name in enumerate("xyz"):
        err[name] = float(cam.center_in_world[k] - truth.center_in_world[k])
    turn = Rotation.from_matrix(
        cam.cam_from_world_rotation @ truth.cam_from_world_rotation.T
    ).as_rotvec()
    for k, name in enumerate(("rot_x", "rot_y", "rot_z")):
        err[name] = math.degrees(float(turn[k]))
    sig: dict[str, float | None] = {"focal": res.focal_sigma_px, "height": None}
    # The main sigmas include the principal point's uncertainty (the *_with_principal_point
    # fields are their aliases).
    pos_sigma, rot_sigma = res.position_sigma_m, res.rotation_sigma_deg
    if pos_sigma is not None:
        for k, name in enumerate("xyz"):
            sig[name] = float(pos_sigma[k])
        sig["height"] = float(pos_sigma[2])
    if rot_sigma is not None:
        for k, name in enumerate(("rot_x", "rot_y", "rot_z")):
            sig[name] = float(rot_sigma[k])
    pp_err = np.subtract(cam.principal_point, truth.principal_point)
    err["pp_x"], err["pp_y"] = float(pp_err[0]), float(pp_err[1])
    pp_sigma = res.principal_point_sigma_px
    sig["pp_x"] = None if pp_sigma is None else float(pp_sigma[0])
    sig["pp_y"] = None if pp_sigma is None else float(pp_sigma[1])
    out["error"] = {k: float(v) for k, v in err.items()}
    out["sigma"] = sig
    if _TERMS:
        out["dominant_term"] = _dominant_terms(res)
        if PARTS:
            terms = _TERMS.get(id(res.parameter_covariance))
            out["term_variance"] = terms
        _TERMS.clear()
    out["principal_point_error_px"] = float(np.hypot(*pp_err))
    return out


PARTS = False
"""``--parts``: each crowd scene calibrated again with the truth stated (see :func:`parts`)."""
PARTS_SETS = ("crowd", "crowd_pp_prior")
PART_SCENES = {
    "size_given": (True, False),
    "pp_given": (False, True),
    "both_given": (True, True),
}


def part_errors(syn: Any) -> dict[str, dict[str, float] | None]:
    """The scene's errors when it states the car's true size, the true principal point, or
    both (the same clicks and lines): ``{variant: {quantity: error} or None}``."""
    out: dict[str, dict[str, float] | None] = {}
    scene = syn.scene
    for name, (size, pp) in PART_SCENES.items():
        stated = copy.deepcopy(scene)
        if size:
            t = syn.true_size
            stated["object"] = {
                "length_m": t.length_m,
                "width_m": t.width_m,
                "height_m": t.height_m,
            }
        if pp:
            stated["camera"] = {"principal_point": [float(v) for v in syn.camera.principal_point]}
        syn.scene = stated
        try:
            row = scene_errors(syn, terms=False)
        finally:
            syn.scene = scene
        out[name] = None if row is None else row["error"]
    return out


PART_TERMS = {
    # part: (its error, the terms of the full scene's covariance that state it)
    "size": ("preset_shape", "size", "car_class"),
    "principal_point": ("principal_point",),
    "noise": ("fit", "ground_corner", "car_lines"),
    "noise_fit_only": ("fit",),
}


def parts(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """``--parts``: each part of the error against the terms that state it.

    Per scene, the error of the car's size (the full scene's error less that of the same
    clicks stating the true size), of the principal point (less that stating the true
    principal point) and of the clicks and lines (the error stating both) is compared with
    the full scene's covariance terms for it (``PART_TERMS``): 1σ / 2σ coverage and the
    median error/σ per quantity of ``TERM_QUANTITIES``. The jackknife is in none of them.
    """
    out: dict[str, Any] = {}
    for q, k in TERM_QUANTITIES.items():
        unit = math.degrees(1.0) if q.startswith("rot") else 1.0
        z: dict[str, list[float]] = {p: [] for p in PART_TERMS}
        for r in rows:
            tv, pe = r.get("term_variance"), r.get("parts")
            if not tv or not pe or any(v is None for v in pe.values()):
                continue
            e = r["error"][q]
            err = {
                "size": e - pe["size_given"][q],
                "principal_point": e - pe["pp_given"][q],
                "noise": pe["both_given"][q],
                "noise_fit_only": pe["both_given"][q],
            }
            for p, names in PART_TERMS.items():
                var = sum(max(tv[n][k], 0.0) for n in names)
                if var > 0.0:
                    z[p].append(abs(err[p]) / (math.sqrt(var) * unit))
        out[q] = {
            p: {
                "n": len(v),
                "cover_1sigma": float(np.mean(np.array(v) <= 1.0)),
                "cover_2sigma": float(np.mean(np.array(v) <= 2.0)),
                "median_z": float(np.median(v)),
            }
            for p, v in z.items()
            if v
        }
    return out


def is_exact(row: dict[str, Any]) -> bool:
    """The answer is exact to round-off (focal length and principal point within 1e-3 px)."""
    return bool(abs(row["error"]["focal"]) < 1e-3 and row["principal_point_error_px"] < 1e-3)


def coverage(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Per quantity: 1σ and 2σ coverage, the median error/σ, how many had a sigma."""
    out: dict[str, Any] = {}
    for q in QUANTITIES:
        z = np.array(
            [
                abs(r["error"][q]) / r["sigma"][q]
                for r in rows
                if r["sigma"].get(q) is not None and r["sigma"][q] > 0
            ]
        )
        if len(z) == 0:
            out[q] = None
            continue
        out[q] = {
            "n": len(z),
            "cover_1sigma": float(np.mean(z <= 1.0)),
            "cover_2sigma": float(np.mean(z <= 2.0)),
            "median_z": float(np.median(z)),
            "tails": int(np.sum(z > TAIL_Z)),
        }
    pp = np.array([r["principal_point_error_px"] for r in rows])
    out["principal_point_error_px"] = {
        "p50": float(np.median(pp)),
        "p90": float(np.percentile(pp, 90)),
    }
    return out


def coverage_by_term(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Per quantity and deciding term (``--terms``): scenes, 1σ / 2σ coverage, median."""
    out: dict[str, Any] = {}
    for q in TERM_QUANTITIES:
        groups: dict[str, list[float]] = {}
        for r in rows:
            term = (r.get("dominant_term") or {}).get(q)
            if term is None or not r["sigma"].get(q):
                continue
            groups.setdefault(term, []).append(abs(r["error"][q]) / r["sigma"][q])
        out[q] = {
            t: {
                "n": len(z),
                "cover_1sigma": float(np.mean(np.array(z) <= 1.0)),
                "cover_2sigma": float(np.mean(np.array(z) <= 2.0)),
                "median_z": float(np.median(z)),
            }
            for t, z in sorted(groups.items())
        }
    return out


def plot(by_set: dict[str, list[dict[str, Any]]], path: Path) -> None:
    """CDF of |error| / σ per quantity, one panel per set, the Gaussian's dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy.stats import norm

    fig, axes = plt.subplots(1, len(by_set), figsize=(6 * len(by_set), 4.4))
    xs = np.linspace(0, 4, 200)
    for ax, (name, rows) in zip(np.atleast_1d(axes), by_set.items(), strict=True):
        for q in QUANTITIES:
            z = np.sort(
                [
                    abs(r["error"][q]) / r["sigma"][q]
                    for r in rows
                    if r["sigma"].get(q) is not None and r["sigma"][q] > 0
                ]
            )
            if len(z):
                ax.step(z, np.arange(1, len(z) + 1) / len(z), where="post", label=q)
        ax.plot(xs, 2 * norm.cdf(xs) - 1, "k--", label="Gaussian")
        ax.set_xlim(0, 4)
        ax.set_ylim(0, 1)
        ax.set_xlabel("|error| / stated sigma")
        ax.set_ylabel("fraction of scenes")
        ax.set_title(f"{name} ({len(rows)} scenes)")
        ax.axvline(1, color="grey", lw=0.5)
        ax.axvline(2, color="grey", lw=0.5)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=2, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


HIST_QUANTITIES = ("focal", "pp_x", "rot_x", "rot_z", "height")


def plot_hist(by_set: dict[str, list[dict[str, Any]]], path: Path) -> None:
    """Histograms of |error| / σ (scenes not exact), one row per set, the half-normal's line."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy.stats import norm

    n_q = len(HIST_QUANTITIES)
    fig, axes = plt.subplots(
        len(by_set), n_q, figsize=(3.2 * n_q, 2.4 * len(by_set)), squeeze=False
    )
    bins = np.arange(0.0, 4.01, 0.25)
    xs = np.linspace(0, 4, 200)
    for row, (name, rows) in zip(axes, by_set.items(), strict=True):
        rows = [r for r in rows if not is_exact(r)]
        for ax, q in zip(row, HIST_QUANTITIES, strict=True):
            z = np.array(
                [
                    abs(r["error"][q]) / r["sigma"][q]
                    for r in rows
                    if r["sigma"].get(q) is not None and r["sigma"][q] > 0
                ]
            )
            if len(z):
                ax.hist(np.clip(z, 0, 3.99), bins=bins, density=True, color="tab:blue")
            ax.plot(xs, 2 * norm.pdf(xs), "k--", lw=1)
            ax.set_xlim(0, 4)
            ax.axvline(1, color="grey", lw=0.5)
            ax.axvline(2, color="grey", lw=0.5)
            ax.set_title(f"{name}: {q} ({len(z)})", fontsize=8)
            ax.tick_params(labelsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("|error| / stated sigma (last bin: >= 3.75)", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


LOCATED_PLACES = [
    ("monaco.osm.pbf", 43.7384, 7.4246, 900.0),
    ("heidelberg_altstadt.osm.pbf", 49.4120, 8.7080, 800.0),
    ("baltimore.osm.pbf", 39.2851, -76.5934, 1200.0),
]
_INFO_NOTE = "annotators marked different corners"


def located_coverage(n: int, seed: int) -> dict[str, Any]:
    """Focal coverage on ``n`` scenes of ``absolute.py``'s scene maker, two size statements."""
    from camloc_geo.osm import load_map
    from camloc_geo.testing.synthetic import make_located_scene

    osm = Path(__file__).resolve().parent.parent / "data" / "osm"
    maps = [load_map(osm / name, lat, lon, r) for name, lat, lon, r in LOCATED_PLACES]
    junctions = [
        [j for j in m.intersections if j.kind == "junction" and len(j.corners) >= 3] for m in maps
    ]
    rows: dict[str, list[dict[str, Any]]] = {"as_made": [], "preset": []}
    for i in range(n):
        k = i % len(maps)
        rng = np.random.default_rng([seed, i])
        inter = junctions[k][int(rng.integers(len(junctions[k])))]
        ls = make_located_scene(maps[k], inter, rng, n_references=2, max_corners=4)
        if ls is None:
            continue
        true_f = ls.camera_enu.focal_px
        for variant in rows:
            scene = dict(ls.scene)
            if variant == "preset":
                scene["object"] = {"preset": "sedan"}
            try:
                res = calibrate(parse_scene(scene), SETTINGS)
            except InputError:
                continue
            if res.focal_sigma_px is None:
                continue
            rows[variant].append(
                {
                    "index": i,
                    "focal_err_rel": res.camera.focal_px / true_f - 1.0,
                    "z": abs(res.camera.focal_px - true_f) / res.focal_sigma_px,
                    "sigma_rel": res.focal_sigma_px / res.camera.focal_px,
                    "height_m": ls.camera_enu.height_m,
                    "warned": any(not w.startswith(_INFO_NOTE) for w in res.warnings),
                }
            )
    out: dict[str, Any] = {"n": n, "seed": seed, "places": [p[0] for p in LOCATED_PLACES]}
    for variant, rs in rows.items():
        z = np.array([r["z"] for r in rs])
        off = [r for r in rs if abs(r["focal_err_rel"]) > 0.10]
        outside = [r for r in off if r["z"] > 2.0]
        silent = [r for r in outside if not r["warned"]]
        out[variant] = {
            "scenes": len(rs),
            "cover_1sigma": float(np.mean(z <= 1.0)),
            "cover_2sigma": float(np.mean(z <= 2.0)),
            "median_z": float(np.median(z)),
            "off_10pct": len(off),
            "off_10pct_outside_2sigma": len(outside),
            "off_10pct_outside_2sigma_silent": len(silent),
            "silent_scenes": [
                {k: round(v, 3) if isinstance(v, float) else v for k, v in r.items()}
                for r in silent
            ],
        }
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=60, help="scenes per set (default 60)")
    parser.add_argument("--seed", type=int, default=20261125, help="random seed")
    parser.add_argument("--out", type=Path, default=OUT_DIR, help="output folder")
    parser.add_argument(
        "--plain",
        action="store_true",
        help="accepted for old command lines; no effect (the main sigmas now include the "
        "principal point's uncertainty, the *_with_principal_point fields are aliases)",
    )
    parser.add_argument(
        "--located",
        type=int,
        default=0,
        help="also N scenes of absolute.py's scene maker (focal coverage; default 0: none)",
    )
    add_settings_options(parser)
    parser.add_argument(
        "--terms",
        action="store_true",
        help="also file each scene under the term that decides each sigma (fit, ground "
        "corner, preset shape, car lines, principal point, size, jackknife) and report the "
        "coverage per term (a diagnostic: wraps a private helper of calibrate)",
    )
    parser.add_argument(
        "--parts",
        action="store_true",
        help="also calibrate each crowd scene again stating the true size, the true principal "
        "point and both, and compare each part of the error with the terms that state it "
        "(implies --terms; ~4x the crowd sets' time)",
    )
    parser.add_argument(
        "--variance-groups",
        action=argparse.BooleanOptionalAction,
        default=CalibrationSettings().variance_groups,
        help="CalibrationSettings.variance_groups: the fit's covariance with one residual "
        "variance factor per group of rows (segments, corner clicks, edge-end clicks; off "
        "by default: one pooled factor)",
    )
    parser.add_argument(
        "--sets",
        default=",".join(SETS),
        help="comma-separated sets to run (default: all, %(default)s)",
    )
    args = parser.parse_args(argv)
    sets = [s.strip() for s in args.sets.split(",") if s.strip()]
    unknown = sorted(set(sets) - set(SETS))
    if unknown:
        parser.error(f"unknown set(s) {', '.join(unknown)}; known: {', '.join(SETS)}")
    global PARTS
    PARTS = args.parts
    if args.terms or args.parts:
        _record_terms()
    global SETTINGS
    SETTINGS = settings_from_args(args, variance_groups=args.variance_groups)
    logging.basicConfig(level=logging.ERROR)
    args.out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    by_set: dict[str, list[dict[str, Any]]] = {}
    refused: dict[str, int] = {}
    for name in sets:
        noise = SETS[name]
        rng = np.random.default_rng(args.seed)
        rows: list[dict[str, Any]] = []
        refused[name] = 0
        pp_sigma = PP_PRIOR.get(name)
        for i in range(args.n):
            syn, _size, _n = draw_scene(rng, i, noise, pp_sigma_rel=pp_sigma)
            while not _has_lines(syn.scene):
                syn, _size, _n = draw_scene(rng, i, noise, pp_sigma_rel=pp_sigma)
            if name in SIZE_GIVEN:
                true = syn.true_size
                syn.scene["object"] = {
                    "length_m": true.length_m,
                    "width_m": true.width_m,
                    "height_m": true.height_m,
                }
            row = scene_errors(syn)
            if row is None:
                refused[name] += 1
                continue
            if PARTS and name in PARTS_SETS:
                row["parts"] = part_errors(syn)
            row["index"] = i
            rows.append(row)
        by_set[name] = rows
    summary = {name: coverage(rows) for name, rows in by_set.items()}
    # Exact answers (a freed principal point on noise-free lines: errors and sigmas at
    # round-off) say nothing of a sigma's calibration; the coverage without them:
    inexact = {name: [r for r in rows if not is_exact(r)] for name, rows in by_set.items()}
    for name, rows in inexact.items():
        summary[name]["n_exact"] = len(by_set[name]) - len(rows)
        summary[name]["without_exact"] = coverage(rows) if rows else None
    result = {
        "benchmark": "calibrate_coverage",
        "seed": args.seed,
        "n_per_set": args.n,
        "want": WANT,
        "sigmas": "main fields (with the principal point's uncertainty)",
        "jackknife_leverage": args.jackknife_leverage,
        "car_class_prior": args.class_prior,
        "variance_groups": args.variance_groups,
        "settings": args.settings,
        "refused": refused,
        "summary": summary,
        "wall_time_s": round(time.perf_counter() - t0, 1),
        "cpu_count": os.cpu_count(),
        "rows": by_set,
    }
    if args.terms or args.parts:
        result["by_term"] = {name: coverage_by_term(rows) for name, rows in by_set.items()}
    if args.parts:
        result["by_part"] = {
            name: parts(rows) for name, rows in by_set.items() if name in PARTS_SETS
        }
    if args.located > 0:
        result["located"] = located_coverage(args.located, args.seed)
    (args.out / "calibrate_coverage.json").write_text(json.dumps(result, indent=1))
    plot(by_set, args.out / "calibrate_coverage.png")
    plot_hist(by_set, args.out / "calibrate_coverage_hist.png")
    for name, cov in summary.items():
        print(
            f"{name}: {len(by_set[name])} scenes, {refused[name]} refused, "
            f"{cov['n_exact']} exact (right: without them)"
        )
        head = f"{'1σ':>6s} {'2σ':>6s} {'med z':>6s}"
        print(f"  {'':8s} {head}   {head}   tails > {TAIL_Z:g}σ")
        rest = cov["without_exact"] or {}
        for q in QUANTITIES:
            cells = []
            for c in (cov[q], rest.get(q)):
                cells.append(
                    "   (no sigma)        "
                    if c is None
                    else f"{c['cover_1sigma']:6.0%} {c['cover_2sigma']:6.0%} {c['median_z']:6.2f}"
                )
            tails = "" if cov[q] is None else f"   {cov[q]['tails']}"
            print(f"  {q:8s} {cells[0]}   {cells[1]}{tails}")
        pp = cov["principal_point_error_px"]
        print(f"  principal point error p50 {pp['p50']:.1f} px, p90 {pp['p90']:.1f} px")
    for name, per_q in result.get("by_term", {}).items():
        print(f"{name}: error/sigma by the term that decides the sigma (n, 1σ, 2σ, median)")
        for q, groups in per_q.items():
            line = "; ".join(
                f"{t} {g['n']}, {g['cover_1sigma']:.0%} / {g['cover_2sigma']:.0%}, "
                f"{g['median_z']:.2f}"
                for t, g in groups.items()
            )
            print(f"  {q:6s} {line}")
    for name, per_q in result.get("by_part", {}).items():
        print(f"{name}: each part of the error against the terms that state it (1σ, 2σ, median)")
        for q, groups in per_q.items():
            line = "; ".join(
                f"{p} {g['cover_1sigma']:.0%} / {g['cover_2sigma']:.0%}, {g['median_z']:.2f}"
                for p, g in groups.items()
            )
            print(f"  {q:6s} {line}")
    for variant in ("as_made", "preset"):
        if "located" not in result:
            break
        v = result["located"][variant]
        print(
            f"located ({variant}): {v['scenes']} scenes, focal 1σ {v['cover_1sigma']:.1%} "
            f"2σ {v['cover_2sigma']:.1%} median z {v['median_z']:.2f}; >10 % off "
            f"{v['off_10pct']}, of those outside 2σ {v['off_10pct_outside_2sigma']}, "
            f"silent {v['off_10pct_outside_2sigma_silent']}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
