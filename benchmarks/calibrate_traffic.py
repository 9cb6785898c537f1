"""``calibrate``'s focal length on the street scenes of the second video generator (issue 28).

Each scene is what :func:`camloc_geo.testing.traffic_render.render_street` annotates for a
:func:`~camloc_geo.testing.traffic_render.random_street` camera (960x540, 6-9 m up, the
parked reference sedan annotated by 3 annotators with 1 px click and line noise, each also
drawing one or two of the street's painted lane lines,
:func:`camloc_geo.testing.road_lines.street_scene`); no video is rendered (the scene does
not depend on the frames). The sets per seed:

- ``traffic``: that scene, the annotators' noise drawn as ``render_street`` draws it;
- ``traffic_photo``: the same scene with the street's background frame as its
  ``image.path`` (:func:`~camloc_geo.testing.traffic_render.street_photo`, what
  ``render_street`` writes beside the video), so ``calibrate`` adds the photo's painted
  lines to the annotators' (``photo_lines``, the default): the scene a radar user has;
- ``car_only``: the same annotation without the lane lines (``render_street``'s scene
  before issue 28: the car alone);
- ``traffic_draws``: the same camera with ``--draws`` more noise draws (the spread of the
  focal error per camera: bias vs scatter);
- ``noise_free``: the same camera annotated without noise (the method's own bias);
- ``road_lines``: :func:`camloc_geo.testing.road_lines.road_line_scene` (a street camera
  6-9 m up whose annotators also drew one long lane line each);
- with ``--video``: ``traffic_video`` and ``car_only_video``, the ``traffic`` and
  ``car_only`` scenes calibrated with the video's own lines too
  (:func:`camloc_geo.sensors._video_lines.video_lines` on the street video
  ``render_street`` makes for the seed: 10 vehicles, 20 s; what ``camloc radar`` does by
  default), and with ``--draws`` also ``traffic_video_draws`` and
  ``car_only_video_draws`` (the same video, ``--draws`` more noise draws of the
  annotators). Rendering and reading a video take ~30 s of CPU each; with ``--video-dir``
  both are kept (``s{seed}.avi``, ``s{seed}_lines.npz``) and reused.

Per scene: the focal error ``f / f_true - 1``, the stated ``focal_sigma_px`` and ``z`` =
error / sigma, and the same for the camera's height (``height_error``,
``height_sigma_rel``, ``height_z``); per set also the 1- and 2-sigma coverage and the
median ``|z|`` (a Gaussian: 68 %, 95 %, 0.67). Writes ``benchmarks/out/calibrate_traffic.json`` and
``benchmarks/out/calibrate_traffic.png`` (focal error per seed with the stated 2-sigma).

Usage: ``python benchmarks/calibrate_traffic.py [--first-seed 300] [--seeds 20] [--draws 5]
[--video [--video-dir DIR]]``
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from camloc_geo import InputError
from camloc_geo.api import calibrate_scene
from camloc_geo.camera import Camera
from camloc_geo.relative import CalibrationSettings
from camloc_geo.testing.road_lines import road_line_scene, street_noise, street_scene
from camloc_geo.testing.synthetic import make_scene
from camloc_geo.testing.traffic_render import random_street, render_street, street_photo

OUT_DIR = Path(__file__).parent / "out"
IMAGE_SIZE = (960, 540)


def traffic_scene(
    seed: int,
    *,
    noise_seed: int | None = None,
    click_px: float = 1.0,
    lane_lines: bool = True,
    photo_dir: Path | None = None,
) -> Any:
    """The camera and annotated scene ``render_street`` makes for ``random_street(seed)``.

    Parameters
    ----------
    seed
        The video's seed (camera from ``default_rng(seed)``, as ``benchmarks/radar_render.py``).
    noise_seed
        Seed of the annotators' noise (default ``seed``: ``render_street``'s own draw).
    click_px
        Click and line-endpoint noise, pixels (0: exact).
    lane_lines
        The annotators also draw the painted lane lines (as ``render_street``); False: the
        car alone.
    photo_dir
        Write the street's background frame there (``street_photo``, as ``render_street``
        writes it beside the video) and name it as the scene's ``image.path``. None: no
        photo.

    Returns
    -------
    SyntheticScene
        Its ``camera`` is the true camera, ``scene`` the annotated scene dict.
    """
    cam, _ = random_street(np.random.default_rng(seed), n_vehicles=10, duration_s=20.0)
    base = seed if noise_seed is None else noise_seed
    if lane_lines:
        syn = street_scene(cam, base, click_px=click_px, image_size=IMAGE_SIZE)
    else:
        rng = np.random.default_rng(base + 7)
        syn = make_scene(
            cam, rng, noise=street_noise(click_px), n_annotators=3, image_size=IMAGE_SIZE
        )
    if photo_dir is not None:
        path = street_photo(cam, seed, Path(photo_dir) / f"street_{seed}.png")
        syn.scene["image"]["path"] = str(path)
    return syn


def street_video_lines(seed: int, video_dir: Path) -> Any:
    """The video witness lines of ``render_street``'s video for ``random_street(seed)``
    (rendered into ``video_dir`` unless ``s{seed}.avi`` is there already; the lines are kept
    beside it as ``s{seed}_lines.npz`` and read from there when it is newer than the video
    and the code that finds them, so a second run skips both passes)."""
    from camloc_geo.sensors import _video_lines as vl_mod
    from camloc_geo.sensors._video_lines import video_lines

    path = video_dir / f"s{seed}.avi"
    if not path.is_file():
        cam, vehicles = random_street(np.random.default_rng(seed), n_vehicles=10, duration_s=20.0)
        render_street(path, cam, vehicles, duration_s=20.0, seed=seed)
    kept = video_dir / f"s{seed}_lines.npz"
    newest = max(path.stat().st_mtime, Path(vl_mod.__file__).stat().st_mtime)
    if kept.is_file() and kept.stat().st_mtime > newest:
        return load_lines(kept)
    lines = video_lines(path, image_size=IMAGE_SIZE)
    save_lines(kept, lines)
    return lines


def save_lines(path: Path, lines: Any) -> None:
    """Keep a :class:`~camloc_geo.sensors._video_lines.VideoLines` as ``.npz`` (no pickle)."""
    np.savez(
        path,
        size=np.array(lines.image_size),
        segments=lines.segments,
        labels=lines.labels,
        vanishing_points=lines.vanishing_points,
        n_frames=lines.n_frames,
        counts=json.dumps(lines.counts),
    )


def load_lines(path: Path) -> Any:
    """The :class:`~camloc_geo.sensors._video_lines.VideoLines` :func:`save_lines` kept."""
    from camloc_geo.sensors._video_lines import VideoLines

    with np.load(path) as z:
        return VideoLines(
            (int(z["size"][0]), int(z["size"][1])),
            z["segments"],
            z["labels"],
            z["vanishing_points"],
            int(z["n_frames"]),
            json.loads(str(z["counts"])),
        )


def focal_row(
    scene: dict[str, Any], truth: Camera, settings: CalibrationSettings | None = None
) -> dict[str, Any] | None:
    """Focal and camera-height errors, their stated sigmas and z (error / sigma) of one
    scene, or None when ``calibrate`` refuses it."""
    try:
        res = calibrate_scene(scene, settings=settings)
    except InputError:
        return None
    f_true = truth.focal_px
    err = res.camera.focal_px / f_true - 1.0
    sigma = (res.focal_sigma_px or float("nan")) / f_true
    h_true = float(truth.center_in_world[2])
    h_err = float(res.camera.center_in_world[2]) / h_true - 1.0
    h_sigma = float(res.position_sigma_m[2]) / h_true if res.position_sigma_m is not None else 0.0
    return {
        "focal_error": round(float(err), 5),
        "focal_sigma_rel": round(float(sigma), 5),
        "z": round(float(err / sigma), 3) if sigma > 0 else None,
        "height_m": round(h_true, 2),
        "height_error": round(h_err, 5),
        "height_sigma_rel": round(h_sigma, 5),
        "height_z": round(h_err / h_sigma, 3) if h_sigma > 0 else None,
        "warnings": len(res.warnings),
        **({"video_segments": res.video_segments} if settings is not None else {}),
    }


def summary(rows: list[dict[str, Any] | None]) -> dict[str, Any]:
    """Median, mean, spread and tails of the focal errors of a set."""
    ok = [r for r in rows if r is not None]
    e = np.array([r["focal_error"] for r in ok])
    z = np.array([r["z"] for r in ok if r["z"] is not None])
    if e.size == 0:
        return {"n": 0, "failed": len(rows)}
    return {
        "n": int(e.size),
        "failed": len(rows) - len(ok),
        "median_signed": round(float(np.median(e)), 4),
        "mean_signed": round(float(e.mean()), 4),
        "sd": round(float(e.std()), 4),
        "median_abs": round(float(np.median(np.abs(e))), 4),
        "max_abs": round(float(np.abs(e).max()), 4),
        "within_3pct": round(float(np.mean(np.abs(e) < 0.03)), 3),
        "within_6pct": round(float(np.mean(np.abs(e) < 0.06)), 3),
        "median_sigma_rel": round(float(np.median([r["focal_sigma_rel"] for r in ok])), 4),
        "cover_2sigma": round(float(np.mean(np.abs(z) < 2.0)), 3) if z.size else None,
        "median_abs_z": round(float(np.median(np.abs(z))), 3) if z.size else None,
        "lines_left_out": int(sum(r["warnings"] for r in ok)),
        **_height_summary(ok),
    }


def _height_summary(ok: list[dict[str, Any]]) -> dict[str, Any]:
    """The camera height's error and its stated sigma over a set's rows (as the focal's)."""
    e = np.array([r["height_error"] for r in ok if "height_error" in r])
    z = np.array([r["height_z"] for r in ok if r.get("height_z") is not None])
    if e.size == 0:
        return {}
    return {
        "height_median_abs": round(float(np.median(np.abs(e))), 4),
        "height_max_abs": round(float(np.abs(e).max()), 4),
        "height_cover_1sigma": round(float(np.mean(np.abs(z) < 1.0)), 3) if z.size else None,
        "height_cover_2sigma": round(float(np.mean(np.abs(z) < 2.0)), 3) if z.size else None,
        "height_median_abs_z": round(float(np.median(np.abs(z))), 3) if z.size else None,
        "cover_1sigma": round(
            float(np.mean([abs(r["z"]) < 1.0 for r in ok if r["z"] is not None])), 3
        ),
    }


def plot(result: dict[str, Any], path: Path) -> None:
    """Focal error per seed with the stated 2-sigma, per set."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 4.5))
    styles = {
        "traffic": ("C0", 0.0),
        "traffic_photo": ("C4", 0.08),
        "car_only": ("C3", -0.15),
        "noise_free": ("C2", 0.15),
        "road_lines": ("C1", 0.3),
        "traffic_video": ("C5", 0.22),
        "car_only_video": ("C6", -0.22),
    }
    for name, (colour, dx) in styles.items():
        if name not in result["scenes"]:
            continue
        rows = result["scenes"][name]
        seeds = [r["seed"] for r in rows if r["focal_error"] is not None]
        err = [100 * r["focal_error"] for r in rows if r["focal_error"] is not None]
        sig = [200 * r["focal_sigma_rel"] for r in rows if r["focal_error"] is not None]
        ax.errorbar(
            np.array(seeds) + dx,
            err,
            yerr=sig,
            fmt="o",
            ms=4,
            color=colour,
            capsize=2,
            label=f"{name} (median |err| {100 * result['summary'][name]['median_abs']:.1f} %)",
        )
    ax.axhspan(-3, 3, color="0.9", zorder=0, label="±3 %")
    ax.axhline(0, color="0.5", lw=0.8)
    ax.set_xlabel("seed")
    ax.set_ylabel("focal error, % (bars: stated 2σ)")
    ax.set_title("calibrate on street scenes, 960x540, 3 annotators, 1 px")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--first-seed", type=int, default=300)
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--draws", type=int, default=5, help="extra noise draws per camera")
    ap.add_argument("--out", type=Path, default=OUT_DIR)
    ap.add_argument("--video", action="store_true", help="also the sets with the video's lines")
    ap.add_argument("--video-dir", type=Path, help="keep (and reuse) the rendered videos here")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    scenes: dict[str, list[dict[str, Any]]] = {
        "traffic": [],
        "traffic_photo": [],
        "car_only": [],
        "traffic_draws": [],
        "noise_free": [],
        "road_lines": [],
    }
    if args.video:
        scenes["traffic_video"] = []
        scenes["car_only_video"] = []
        if args.draws:
            scenes["traffic_video_draws"] = []
            scenes["car_only_video_draws"] = []
    empty = {"focal_error": None, "focal_sigma_rel": None, "z": None}
    photo_dir = Path(tempfile.mkdtemp(prefix="camloc-calibrate-traffic-"))
    for seed in range(args.first_seed, args.first_seed + args.seeds):
        syn = traffic_scene(seed)
        scenes["traffic"].append({"seed": seed, **(focal_row(syn.scene, syn.camera) or empty)})
        shot = traffic_scene(seed, photo_dir=photo_dir)
        scenes["traffic_photo"].append(
            {"seed": seed, **(focal_row(shot.scene, shot.camera) or empty)}
        )
        car = traffic_scene(seed, lane_lines=False)
        scenes["car_only"].append({"seed": seed, **(focal_row(car.scene, car.camera) or empty)})
        exact = traffic_scene(seed, click_px=0.0)
        scenes["noise_free"].append(
            {"seed": seed, **(focal_row(exact.scene, exact.camera) or empty)}
        )
        for k in range(args.draws):
            draw = traffic_scene(seed, noise_seed=10_000 * seed + k)
            scenes["traffic_draws"].append(
                {"seed": seed, "draw": k, **(focal_row(draw.scene, draw.camera) or empty)}
            )
        road = road_line_scene(seed)
        scenes["road_lines"].append({"seed": seed, **(focal_row(road.scene, road.camera) or empty)})
        if args.video:
            video_dir = args.video_dir or photo_dir
            video_dir.mkdir(parents=True, exist_ok=True)
            with_video = CalibrationSettings(video_lines=street_video_lines(seed, video_dir))
            for name, base in (("traffic_video", syn), ("car_only_video", car)):
                row = focal_row(base.scene, base.camera, with_video) or empty
                scenes[name].append({"seed": seed, **row})
            for k in range(args.draws):  # the same video, other annotators' noise
                for name, lanes in (("traffic_video_draws", True), ("car_only_video_draws", False)):
                    draw = traffic_scene(seed, noise_seed=10_000 * seed + k, lane_lines=lanes)
                    row = focal_row(draw.scene, draw.camera, with_video) or empty
                    scenes[name].append({"seed": seed, "draw": k, **row})
    shutil.rmtree(photo_dir, ignore_errors=True)
    result: dict[str, Any] = {
        "seeds": [args.first_seed, args.first_seed + args.seeds - 1],
        "draws": args.draws,
        "summary": {
            name: summary([None if r["focal_error"] is None else r for r in rows])
            for name, rows in scenes.items()
        },
        "scenes": scenes,
        "seconds": round(time.perf_counter() - t0, 1),
    }
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "calibrate_traffic.json").write_text(json.dumps(result, indent=1))
    plot(result, args.out / "calibrate_traffic.png")
    print(f"calibrate on street scenes, seeds {result['seeds']}, {result['seconds']} s")
    print(
        f"{'set':14s} {'n':>4s} {'median':>7s} {'mean':>7s} {'sd':>6s} {'med|e|':>7s} "
        f"{'max|e|':>7s} {'<3%':>5s} {'<6%':>5s} {'sigma':>6s} {'2σcov':>6s} {'|z|':>5s} "
        f"{'drop':>4s} {'h max':>6s} {'h 2σ':>5s} {'h|z|':>5s}"
    )
    for name, s in result["summary"].items():
        if not s["n"]:
            print(f"{name:14s} " + ("all failed" if s.get("failed") else "no scenes"))
            continue
        print(
            f"{name:14s} {s['n']:4d} {100 * s['median_signed']:+6.2f}% "
            f"{100 * s['mean_signed']:+6.2f}% "
            f"{100 * s['sd']:5.2f}% {100 * s['median_abs']:6.2f}% {100 * s['max_abs']:6.2f}% "
            f"{100 * s['within_3pct']:4.0f}% {100 * s['within_6pct']:4.0f}% "
            f"{100 * s['median_sigma_rel']:5.2f}% {100 * (s['cover_2sigma'] or 0):5.0f}% "
            f"{s['median_abs_z'] or 0:5.2f} {s['lines_left_out']:4d} "
            f"{100 * s.get('height_max_abs', 0):5.2f}% "
            f"{100 * (s.get('height_cover_2sigma') or 0):4.0f}% "
            f"{s.get('height_median_abs_z') or 0:5.2f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
