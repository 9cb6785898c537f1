"""Start-up time of the ``camloc`` command line (whole processes, measured from outside).

Runs each command several times under ``/usr/bin/time -v`` (user + system CPU seconds, wall
seconds, peak RSS) and once under ``python -X importtime`` (which modules the command
imports, and the slowest of them), and writes ``benchmarks/out/startup.json``.

The results of earlier runs are kept under their ``--label`` (``before`` / ``after``), so one
file holds both sides of a change::

    git archive BASE | tar -x -C /tmp/base     # the code before the change
    python benchmarks/startup.py --label before --root /tmp/base
    python benchmarks/startup.py --label after

Targets (issue 9): ``camloc --help`` under 0.2 s, ``camloc calibrate`` on the sample under
0.6 s, ``camloc locate`` on the bundled sample with its extract under 1 s of CPU. Issue 26
states the target relative to the machine: ``camloc locate`` at most 1.5 times the CPU of
``python -c "import numpy, scipy.optimize"`` (the ``baseline`` row, run in turn with the
commands so both see the same machine); ``ratio_to_baseline`` is each command's median CPU
over the baseline's. ``benchmarks/out/startup.png`` plots the CPU of every label side by side.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "out"

COMMANDS: dict[str, list[str]] = {
    "help": ["--help"],
    "calibrate": ["calibrate", "sample_maps/sample_scene.json"],
    "locate": [
        "locate",
        "sample_maps/sample_scene.json",
        "--osm",
        "sample_maps/baltimore.osm.pbf",
        "--offline",
    ],
}
TARGETS_S = {"help": ("wall_s", 0.2), "calibrate": ("wall_s", 0.6), "locate": ("cpu_s", 1.0)}
BASELINE = [sys.executable, "-c", "import numpy, scipy.optimize"]
"""The reference start-up of issue 26: ``camloc locate`` ≤ 1.5 × its CPU."""
RATIO_TARGET = {"locate": 1.5}
HEAVY = ("numpy", "scipy", "osmnx", "geopandas", "cv2", "folium", "pandas", "networkx", "shapely")


CODE = ROOT  # the checkout whose code is measured (--root)


def _camloc(args: list[str]) -> list[str]:
    return [sys.executable, "-m", "camloc_geo.cli", *args]


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(CODE)
    env.pop("PYTHONPROFILEIMPORTTIME", None)
    return env


def time_once(cmd: list[str]) -> dict[str, float]:
    """One run under ``/usr/bin/time -v``: CPU, wall and peak memory."""
    with tempfile.NamedTemporaryFile("r", suffix=".txt") as tf:
        proc = subprocess.run(
            ["/usr/bin/time", "-v", "-o", tf.name, *cmd],
            cwd=CODE,
            env=_env(),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            check=False,
        )
        text = Path(tf.name).read_text()
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited {proc.returncode}: {proc.stderr[-500:]!r}")

    def grab(label: str) -> str:
        m = re.search(rf"{re.escape(label)}: (.+)", text)
        if not m:
            raise RuntimeError(f"/usr/bin/time gave no {label!r}")
        return m.group(1).strip()

    user, system = float(grab("User time (seconds)")), float(grab("System time (seconds)"))
    wall = 0.0
    for part in grab("Elapsed (wall clock) time (h:mm:ss or m:ss)").split(":"):
        wall = wall * 60 + float(part)
    return {
        "cpu_s": user + system,
        "wall_s": wall,
        "max_rss_mb": int(grab("Maximum resident set size (kbytes)")) / 1024,
    }


def import_profile(cmd: list[str], top: int = 12) -> dict[str, Any]:
    """``python -X importtime``: total import time, the slowest modules, heavy ones present."""
    proc = subprocess.run(
        [cmd[0], "-X", "importtime", *cmd[1:]],
        cwd=CODE,
        env=_env(),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        check=False,
    )
    rows = []
    for line in proc.stderr.splitlines():
        m = re.match(r"import time:\s+(\d+) \|\s+(\d+) \|(\s*)(\S+)", line)
        if m:
            rows.append((int(m.group(1)), int(m.group(2)), len(m.group(3)), m.group(4)))
    names = {r[3] for r in rows}
    total_us = sum(r[1] for r in rows if r[2] == 1)  # top-level imports, cumulative
    slow = sorted(rows, key=lambda r: -r[1])
    return {
        "modules": len(rows),
        "import_total_s": total_us / 1e6,
        "heavy_imported": [h for h in HEAVY if h in names],
        "slowest_cumulative": [{"module": r[3], "s": r[1] / 1e6} for r in slow[:top]],
    }


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--label", default="after", help="key in startup.json (before / after)")
    ap.add_argument("--runs", type=int, default=7, help="counted runs per command (7)")
    ap.add_argument("--root", type=Path, default=ROOT, help="checkout to measure (this one)")
    ns = ap.parse_args(argv)
    global CODE
    CODE = ns.root.resolve()

    OUT.mkdir(parents=True, exist_ok=True)
    out_path = OUT / "startup.json"
    doc: dict[str, Any] = json.loads(out_path.read_text()) if out_path.exists() else {}
    res: dict[str, Any] = {"python": sys.version.split()[0], "root": str(CODE), "commands": {}}
    base_runs: list[dict[str, float]] = []
    for name, args in COMMANDS.items():
        cmd = _camloc(args)
        time_once(cmd)  # warm-up (page cache, .pyc)
        runs = []
        for _ in range(ns.runs):  # in turn with the baseline, so both see the same machine
            runs.append(time_once(cmd))
            base_runs.append(time_once(BASELINE))
        key, target = TARGETS_S[name]
        med = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
        base_cpu = statistics.median(r["cpu_s"] for r in base_runs[-ns.runs :])
        ratio = med["cpu_s"] / base_cpu
        res["commands"][name] = {
            "argv": ["camloc", *args],
            "median": med,
            "min": {k: min(r[k] for r in runs) for k in runs[0]},
            "target": {key: target},
            "meets_target": med[key] < target,
            "baseline_cpu_s": base_cpu,
            "ratio_to_baseline": ratio,
            "ratio_target": RATIO_TARGET.get(name),
            "imports": import_profile(cmd),
        }
        print(
            f"{ns.label:7s} {name:10s} wall {med['wall_s']:.3f} s  cpu {med['cpu_s']:.3f} s  "
            f"rss {med['max_rss_mb']:.0f} MB  {ratio:.2f}x baseline ({base_cpu:.3f} s)  "
            f"(target {key} < {target})"
        )
    res["baseline"] = {
        "argv": BASELINE[1:],
        "median": {k: statistics.median(r[k] for r in base_runs) for k in base_runs[0]},
    }
    doc[ns.label] = res
    tmp = out_path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(doc, indent=2) + "\n")
    os.replace(tmp, out_path)
    print(f"wrote {out_path}")
    _plot(doc, OUT / "startup.png")
    return 0


def _plot(doc: dict[str, Any], path: Path) -> None:
    """Median CPU of each command per label, and the baseline import, as grouped bars."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    labels = [k for k in doc if isinstance(doc[k], dict) and "commands" in doc[k]]
    names = [*COMMANDS, "baseline"]
    fig, ax = plt.subplots(figsize=(7, 3.5))
    width = 0.8 / max(len(labels), 1)
    for i, label in enumerate(labels):
        cmds = doc[label]["commands"]
        base = doc[label].get("baseline", {}).get("median", {}).get("cpu_s", float("nan"))
        vals = [cmds[n]["median"]["cpu_s"] if n in cmds else base for n in names]
        xs = [j + i * width for j in range(len(names))]
        ax.bar(xs, vals, width, label=label)
    ax.set_xticks([j + 0.4 - width / 2 for j in range(len(names))], names)
    ax.set_ylabel("CPU s (median, whole process)")
    ax.set_title("camloc start-up; baseline = import numpy, scipy.optimize")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    print(f"wrote {path}")


if __name__ == "__main__":
    sys.exit(main())
