"""Benchmark: the slips real crowds make, one at a time, over many synthetic scenes.

Each scene is drawn like ``benchmarks/relative.py``'s (its ``draw_scene``: image size,
camera, car; here 3-5 annotators) with the crowd noise model, then ONE slip is injected
into one annotator (or, where that is how crowds fail, into all of them), and the scene is
calibrated with the defaults (``calibrate(parse_scene(scene))``). Every outcome is one of

- ``ok``: within the paper's bars (camera position relative to the car < 5 m, height
  < 1 m, focal length within 10 %);
- ``flagged``: outside a bar, but said: a warning naming the slipped annotator (or any
  warning when every annotator slipped), the annotator reported as an outlier, a corner
  mistake or left out, or every quantity outside its bar within 2 stated sigmas of the
  truth; a refusal (an ``InputError`` with its message) counts here too;
- ``confidently_wrong``: outside a bar, outside 2 sigma, and nothing said.

Writes ``benchmarks/out/crowd_slips.json`` (per slip: the shares, the confidently wrong
scenes' errors; per scene rows) and ``benchmarks/out/crowd_slips.png`` (stacked bars).

Usage::

    python benchmarks/crowd_slips.py --n 40            # 40 scenes per slip
    python benchmarks/crowd_slips.py --n 20 --slips tyre_contact_all,swap_edges
    python benchmarks/crowd_slips.py --n 40 --settings discordant_line_t=0   # stop 38's sigmas

``--settings NAME=VALUE,...`` sets any ``CalibrationSettings`` field (a diagnostic).
"""

from __future__ import annotations

import argparse
import copy
import json
import logging
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from relative import _has_lines, add_settings_options, draw_scene, settings_from_args

from camloc_geo import InputError
from camloc_geo.objects import PRESETS
from camloc_geo.relative import CalibrationSettings, calibrate
from camloc_geo.scene import parse_scene
from camloc_geo.testing.synthetic import NoiseModel, SyntheticScene

OUT_DIR = Path(__file__).parent / "out"
BARS = {"position_m": 5.0, "height_m": 1.0, "focal_rel": 0.10}
AXES = ("length", "width", "height")

Slip = Callable[[SyntheticScene, np.random.Generator], "tuple[str, int | None]"]


# --------------------------------------------------------------------------- helpers
def _ann(syn: SyntheticScene, i: int) -> dict[str, Any]:
    ann: dict[str, Any] = syn.scene["annotations"][i]
    return ann


def _pick(syn: SyntheticScene, rng: np.random.Generator) -> int:
    """A random annotator who marked the right corner (the slip is the only mistake)."""
    good = [i for i, w in enumerate(syn.wrong_corner) if not w] or [0]
    return int(rng.choice(good))


def _size(syn: SyntheticScene) -> tuple[float, float, float]:
    t = syn.true_size
    return t.length_m, syn.width_sign * t.width_m, t.height_m


def _clip_px(syn: SyntheticScene, p: np.ndarray) -> list[float]:
    w, h = syn.scene["image"]["width"], syn.scene["image"]["height"]
    return [float(np.clip(p[0], 0.0, w)), float(np.clip(p[1], 0.0, h))]


def _project(syn: SyntheticScene, pts: Any, rng: np.random.Generator) -> list[list[float]]:
    pix = syn.camera.project(np.asarray(pts, float)) + rng.normal(0.0, 2.0, (len(pts), 2))
    return [_clip_px(syn, p) for p in pix]


def _segment(
    syn: SyntheticScene, a: np.ndarray, b: np.ndarray, rng: np.random.Generator
) -> list[float] | None:
    from camloc_geo.testing.synthetic import _visible_segment

    w, h = syn.scene["image"]["width"], syn.scene["image"]["height"]
    seg = _visible_segment(syn.camera, a, b, (w, h))
    if seg is None or math.hypot(seg[2] - seg[0], seg[3] - seg[1]) < 25.0:
        return None
    seg = seg + rng.normal(0.0, 1.0, 4)
    return [*_clip_px(syn, seg[:2]), *_clip_px(syn, seg[2:])]


# --------------------------------------------------------------------------- slips
def none(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """No slip: the control."""
    return "no slip", None


def swap_edges(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """1. The length and width edge ends exchanged (the labels swapped), lines right."""
    i = _pick(syn, rng)
    axes = _ann(syn, i)["axes"]
    axes["length"], axes["width"] = axes["width"], axes["length"]
    return "length and width edges swapped", i


def swap_edges_and_lines(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """1b. Length and width exchanged in both the edges and the lines (a consistent relabel)."""
    i = _pick(syn, rng)
    ann = _ann(syn, i)
    ann["axes"]["length"], ann["axes"]["width"] = ann["axes"]["width"], ann["axes"]["length"]
    vl = ann["vp_lines"]
    vl["length"], vl["width"] = vl["width"], vl["length"]
    return "length and width swapped, edges and lines", i


def _tyre_points(syn: SyntheticScene, rng: np.random.Generator) -> np.ndarray:
    """The tyre contacts under the corner and the two edge ends, and the roof above."""
    L, W, H = _size(syn)
    s = 1.0 if W > 0 else -1.0
    over = float(rng.uniform(0.6, 1.0))  # overhang: bumper to the wheel's contact
    inset = float(rng.uniform(0.1, 0.25))  # body side to the tyre's contact
    return np.array(
        [
            [over, s * inset, 0.0],
            [L - over, s * inset, 0.0],
            [over, W - s * inset, 0.0],
            [over, s * inset, H],
        ]
    )


def _set_axes(ann: dict[str, Any], pix: list[list[float]]) -> None:
    for k, p in zip(("origin", "length", "width", "height"), pix, strict=True):
        ann["axes"][k] = p


def tyre_contact(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """2. One annotator clicks the tyre contacts, not the ground under the body's corners."""
    i = _pick(syn, rng)
    _set_axes(_ann(syn, i), _project(syn, _tyre_points(syn, rng), rng))
    return "ground corners at the tyre contacts", i


def tyre_contact_all(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """2b. Every annotator clicks the tyre contacts (the crowd's shared reading)."""
    for i in range(len(syn.scene["annotations"])):
        if not syn.wrong_corner[i]:
            _set_axes(_ann(syn, i), _project(syn, _tyre_points(syn, rng), rng))
    return "every annotator at the tyre contacts", None


def reversed_length(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """3. The length edge drawn from its far end: origin and length end exchanged."""
    i = _pick(syn, rng)
    axes = _ann(syn, i)["axes"]
    axes["origin"], axes["length"] = axes["length"], axes["origin"]
    return "length edge drawn from the far end", i


def reversed_height(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """3b. The height edge drawn from the roof: origin and height end exchanged."""
    i = _pick(syn, rng)
    axes = _ann(syn, i)["axes"]
    axes["origin"], axes["height"] = axes["height"], axes["origin"]
    return "height edge drawn from the roof", i


def mirrored_width(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """4. The width edge drawn to the other side (the mirrored box)."""
    i = _pick(syn, rng)
    _L, W, _H = _size(syn)
    _ann(syn, i)["axes"]["width"] = _project(syn, [[0.0, -W, 0.0]], rng)[0]
    return "width edge to the other side", i


def lines_wrong_axis(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """5. One annotator's lines all filed under the wrong axis (length <-> width)."""
    i = _pick(syn, rng)
    vl = _ann(syn, i)["vp_lines"]
    vl["length"], vl["width"] = vl["width"], vl["length"]
    return "length and width lines filed under each other", i


def lines_rotated_axes(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """5b. All three axes' lines shifted one slot (length->width->height->length)."""
    i = _pick(syn, rng)
    vl = _ann(syn, i)["vp_lines"]
    vl["length"], vl["width"], vl["height"] = vl["height"], vl["length"], vl["width"]
    return "every axis' lines under the next axis", i


def stray_line(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """5c. One line of another axis slipped into an axis."""
    i = _pick(syn, rng)
    vl = _ann(syn, i)["vp_lines"]
    src, dst = rng.choice(3, 2, replace=False)
    if not vl[AXES[src]]:
        return "stray line (none to move)", i
    seg = vl[AXES[src]].pop(int(rng.integers(len(vl[AXES[src]]))))
    vl[AXES[dst]].append(seg)
    return f"a {AXES[src]} line filed under {AXES[dst]}", i


def _scaled(ann: dict[str, Any], k: float) -> None:
    for key in ("origin", "length", "width", "height"):
        ann["axes"][key] = [v * k for v in ann["axes"][key]]
    for axis in AXES:
        ann["vp_lines"][axis] = [[v * k for v in s] for s in ann["vp_lines"][axis]]


def resized_half(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """6. One annotator clicked on a half-size copy (every coordinate x0.5)."""
    i = _pick(syn, rng)
    _scaled(_ann(syn, i), 0.5)
    return "clicks on a half-size copy", i


def resized_1280(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """6b. One annotator clicked on a 1280-wide copy of a 1920-wide photo (x2/3)."""
    i = _pick(syn, rng)
    _scaled(_ann(syn, i), 1280.0 / 1920.0)
    return "clicks on a 2/3-size copy", i


def nonparallel_line(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """7. A line along something 5-15 deg off the axis (a kerb curve, a slanted roof edge)."""
    i = _pick(syn, rng)
    vl = _ann(syn, i)["vp_lines"]
    for _ in range(50):
        axis = int(rng.integers(3))
        off = math.radians(rng.uniform(5.0, 15.0)) * rng.choice([-1.0, 1.0])
        c, s = math.cos(off), math.sin(off)
        if axis == 0:  # a kerb curving away from the street's direction
            d = np.array([c, s, 0.0])
            a = np.array([rng.uniform(-20, 5), rng.uniform(-10, 10), 0.0])
            b = a + d * rng.uniform(8, 25)
        elif axis == 1:  # a stop line at an angle
            d = np.array([-s, c, 0.0])
            a = np.array([rng.uniform(-15, 20), rng.uniform(-10, -2), 0.0])
            b = a + d * rng.uniform(4, 12)
        else:  # a slanted edge taken for an upright
            d = np.array([s, 0.0, c]) if rng.random() < 0.5 else np.array([0.0, s, c])
            a = np.array([rng.uniform(-20, 25), rng.uniform(-15, 15), 0.0])
            b = a + d * rng.uniform(3, 12)
        seg = _segment(syn, a, b, rng)
        if seg is None:
            continue
        lines = vl[AXES[axis]]
        if len(lines) > 2:
            lines[int(rng.integers(len(lines)))] = seg
        else:
            lines.append(seg)
        return f"a {AXES[axis]} line {math.degrees(abs(off)):.0f} deg off", i
    return "non-parallel line (none visible)", i


def _other_class(syn: SyntheticScene, rng: np.random.Generator, name: str) -> None:
    """Re-annotate the scene's car as a ``name`` of the preset's class (crowd noise kept)."""
    from camloc_geo.testing.synthetic import make_scene

    n = len(syn.scene["annotations"])
    w, h = syn.scene["image"]["width"], syn.scene["image"]["height"]
    true = PRESETS[name]
    new = make_scene(
        syn.camera,
        rng,
        preset=PRESETS["sedan"],
        noise=NoiseModel(),
        n_annotators=n,
        image_size=(w, h),
        width_sign=syn.width_sign,
        scene_id=syn.scene["id"],
        true_size=true,
    )
    syn.scene["annotations"] = new.scene["annotations"]
    syn.wrong_corner[:] = new.wrong_corner
    syn.true_size = true


def roof_suv(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """8. The car is an SUV (1.70 m roof) and the scene says sedan (1.45 m)."""
    _other_class(syn, rng, "suv")
    return "an SUV called a sedan", None


def roof_van(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """8b. The car is a van (2.30 m roof, 5.30 m long) and the scene says sedan."""
    _other_class(syn, rng, "van")
    return "a van called a sedan", None


def roof_van_one(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """8c. One annotator clicks the height edge to a van's roof (2.30 m) behind the sedan."""
    i = _pick(syn, rng)
    _L, _W, H = _size(syn)
    _ann(syn, i)["axes"]["height"] = _project(syn, [[0.0, 0.0, H * 2.3 / 1.45]], rng)[0]
    return "one height click at a van's roof", i


def duplicate(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """9. The same submission twice (same name)."""
    i = _pick(syn, rng)
    syn.scene["annotations"].append(copy.deepcopy(_ann(syn, i)))
    syn.wrong_corner.append(syn.wrong_corner[i])
    return "a submission duplicated", i


def duplicate_sloppy(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """9b. The same submission three times (same name)."""
    i = _pick(syn, rng)
    for _ in range(2):
        syn.scene["annotations"].append(copy.deepcopy(_ann(syn, i)))
        syn.wrong_corner.append(syn.wrong_corner[i])
    return "a submission three times", i


def near_empty(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """9c. A near-empty annotator: the corner only (edge ends left at it), no lines."""
    i = _pick(syn, rng)
    ann = _ann(syn, i)
    o = ann["axes"]["origin"]
    for k in ("length", "width", "height"):
        ann["axes"][k] = list(o)
    ann["vp_lines"] = {a: [] for a in AXES}
    return "corner only", i


def no_lines(syn: SyntheticScene, rng: np.random.Generator) -> tuple[str, int | None]:
    """9d. An annotator who clicked the box but drew no lines."""
    i = _pick(syn, rng)
    _ann(syn, i)["vp_lines"] = {a: [] for a in AXES}
    return "box only, no lines", i


SLIPS: dict[str, Slip] = {
    "none": none,
    "swap_edges": swap_edges,
    "swap_edges_and_lines": swap_edges_and_lines,
    "tyre_contact": tyre_contact,
    "tyre_contact_all": tyre_contact_all,
    "reversed_length": reversed_length,
    "reversed_height": reversed_height,
    "mirrored_width": mirrored_width,
    "lines_wrong_axis": lines_wrong_axis,
    "lines_rotated_axes": lines_rotated_axes,
    "stray_line": stray_line,
    "resized_half": resized_half,
    "resized_1280": resized_1280,
    "nonparallel_line": nonparallel_line,
    "roof_suv": roof_suv,
    "roof_van": roof_van,
    "roof_van_one": roof_van_one,
    "duplicate": duplicate,
    "duplicate_x3": duplicate_sloppy,
    "near_empty": near_empty,
    "no_lines": no_lines,
}


# --------------------------------------------------------------------------- scoring
def names_annotator(warning: str, who: str, index: int) -> bool:
    """Whether ``warning`` names the annotator ``who`` at ``annotations[index]``.

    A warning names an annotator either by its id, quoted (``'w2'``) or in brackets
    (``(w2)``), or by its place in the scene (``annotations[1]``, ``annotations[1].vp_lines``);
    either counts. ``annotations[1]`` does not name ``annotations[10]``.

    Parameters
    ----------
    warning : str
        One of the calibration's warnings.
    who : str
        The annotator's id (``"anonymous"`` where the scene gives none).
    index : int
        The annotator's index in the scene's ``annotations``.

    Returns
    -------
    bool
        True where the warning names this annotator.
    """
    if f"'{who}'" in warning or f"({who})" in warning:
        return True
    return f"annotations[{index}]" in warning


def classify(syn: SyntheticScene, slipped: int | None) -> dict[str, Any]:
    """Calibrate the slipped scene and sort the outcome (see the module docstring)."""
    names = [a.get("annotator", "anonymous") for a in syn.scene["annotations"]]
    try:
        res = calibrate(parse_scene(syn.scene), SETTINGS)
    except InputError as exc:
        return {"outcome": "flagged", "refused": True, "message": str(exc)[:200]}
    truth = syn.camera
    cam = res.camera
    d = cam.center_in_world - truth.center_in_world
    pos = float(np.linalg.norm(d))
    hgt = float(abs(cam.height_m - truth.height_m))
    foc = float(abs(cam.focal_px - truth.focal_px) / truth.focal_px)
    row: dict[str, Any] = {
        "position_error_m": pos,
        "height_error_m": hgt,
        "focal_rel_error": foc,
        "n_warnings": len(res.warnings),
    }
    outside = {
        "position_m": pos >= BARS["position_m"],
        "height_m": hgt >= BARS["height_m"],
        "focal_rel": foc >= BARS["focal_rel"],
    }
    named = set(res.outlier_annotators) | set(res.corner_mistakes)
    named |= {e["annotator"] for e in res.excluded_annotators}
    if slipped is None:
        said = bool(res.warnings)
    else:
        who = names[slipped]
        said = (
            who in named
            or any(e.get("index") == slipped for e in res.excluded_annotators)
            or any(names_annotator(w, who, slipped) for w in res.warnings)
        )
    row["warned"] = said
    if not any(outside.values()):
        row["outcome"] = "ok"
        return row
    sig = res.position_sigma_m
    fs = res.focal_sigma_px
    covered = {
        "position_m": sig is not None and pos <= 2.0 * float(np.linalg.norm(sig)),
        "height_m": sig is not None and hgt <= 2.0 * float(sig[2]),
        "focal_rel": fs is None or abs(cam.focal_px - truth.focal_px) <= 2.0 * fs,
    }
    row["sigma_covers"] = all(covered[k] for k, out in outside.items() if out)
    row["warnings"] = [w[:160] for w in res.warnings]
    row["outcome"] = "flagged" if said or row["sigma_covers"] else "confidently_wrong"
    return row


def run(slips: list[str], n: int, seed: int) -> dict[str, Any]:
    """``n`` scenes per slip; the same scenes (seeds) for every slip."""
    noise = NoiseModel()
    out: dict[str, Any] = {}
    for name in slips:
        rows = []
        for k in range(n):
            rng = np.random.default_rng([seed, k])
            syn, _size, _n = draw_scene(rng, k, noise, n_annotators=int(rng.integers(3, 6)))
            while not _has_lines(syn.scene):
                syn, _size, _n = draw_scene(rng, k, noise, n_annotators=int(rng.integers(3, 6)))
            slip_rng = np.random.default_rng([seed, k, 7])
            what, who = SLIPS[name](syn, slip_rng)
            row = classify(syn, who)
            row.update({"scene": k, "slip": what, "annotator": who})
            rows.append(row)
        counts = {o: sum(r["outcome"] == o for r in rows) for o in OUTCOMES}
        out[name] = {
            "doc": (SLIPS[name].__doc__ or "").strip(),
            "n": n,
            "share": {o: counts[o] / n for o in OUTCOMES},
            "refused": sum(bool(r.get("refused")) for r in rows),
            # the slip said (the annotator named, or any warning for a crowd-wide slip),
            # whatever the outcome: what a crowd's quality control sees
            "said": sum(bool(r.get("warned") or r.get("refused")) for r in rows) / n,
            "confidently_wrong_scenes": [
                {
                    k: r[k]
                    for k in ("scene", "position_error_m", "height_error_m", "focal_rel_error")
                }
                for r in rows
                if r["outcome"] == "confidently_wrong"
            ],
            "rows": rows,
        }
    return out


OUTCOMES = ("ok", "flagged", "confidently_wrong")
# calibrate's settings for every scene (``--no-jackknife-leverage``, ``--class-prior``).
SETTINGS = CalibrationSettings()


def plot(result: dict[str, Any], path: Path) -> None:
    """Stacked bars: ok / flagged / confidently wrong per slip."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(result["slips"])
    fig, ax = plt.subplots(figsize=(11, 0.35 * len(names) + 1.5))
    left = np.zeros(len(names))
    colours = {"ok": "#4c9a2a", "flagged": "#e0a800", "confidently_wrong": "#c0392b"}
    for o in OUTCOMES:
        v = np.array([result["slips"][s]["share"][o] for s in names])
        ax.barh(names, v, left=left, color=colours[o], label=o.replace("_", " "))
        left += v
    ax.invert_yaxis()
    ax.set_xlim(0, 1)
    ax.set_xlabel("share of scenes")
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(
        f"calibrate with one crowd slip, {result['n_per_slip']} scenes per slip "
        "(bars: position 5 m, height 1 m, focal 10 %)"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("--n", type=int, default=40, help="scenes per slip (default 40)")
    parser.add_argument("--seed", type=int, default=20261124, help="random seed")
    parser.add_argument("--slips", default="", help="comma-separated slips (default: all)")
    parser.add_argument("--out", type=Path, default=OUT_DIR, help="output folder")
    add_settings_options(parser)
    args = parser.parse_args(argv)
    global SETTINGS
    SETTINGS = settings_from_args(args)
    logging.basicConfig(level=logging.CRITICAL)
    logging.getLogger("camloc_geo").setLevel(logging.CRITICAL)
    slips = [s for s in args.slips.split(",") if s] or list(SLIPS)
    unknown = [s for s in slips if s not in SLIPS]
    if unknown:
        parser.error(f"unknown slip(s) {', '.join(unknown)}; known: {', '.join(SLIPS)}")
    t0 = time.perf_counter()
    per_slip = run(slips, args.n, args.seed)
    result = {
        "benchmark": "crowd_slips",
        "seed": args.seed,
        "n_per_slip": args.n,
        "bars": BARS,
        "jackknife_leverage": args.jackknife_leverage,
        "car_class_prior": args.class_prior,
        "settings": args.settings,
        "wall_time_s": round(time.perf_counter() - t0, 1),
        "slips": per_slip,
    }
    args.out.mkdir(parents=True, exist_ok=True)
    name = "crowd_slips" if not args.slips else "crowd_slips_subset"
    (args.out / f"{name}.json").write_text(json.dumps(result, indent=1) + "\n")
    plot(result, args.out / f"{name}.png")
    w = sys.stdout.write
    w(f"crowd slips, {args.n} scenes per slip, seed {args.seed}, {result['wall_time_s']} s\n")
    w(f"{'slip':22s}{'ok':>7s}{'flagged':>9s}{'conf.wrong':>12s}{'refused':>9s}{'said':>7s}\n")
    for s, v in per_slip.items():
        sh = v["share"]
        w(
            f"{s:22s}{sh['ok']:7.0%}{sh['flagged']:9.0%}{sh['confidently_wrong']:12.0%}"
            f"{v['refused']:9d}{v['said']:7.0%}\n"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
