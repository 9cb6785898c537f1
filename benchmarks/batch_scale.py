"""``camloc batch`` at scale: memory over time on a long title-only list (issue 26, item 5).

Generates a CSV list of ``--rows`` title-only cameras (``id,title``; titles written from the
junctions of real extracts, in the listing styles of :mod:`camloc_geo.testing.camera_list`)
into a temporary folder, streamed to disk row by row, then runs the command line as a user
would::

    camloc batch LIST.csv -o OUT.gpkg --osm FOLDER --workers 2 --no-progress

in a child process, sampling the resident memory of that process and all its workers
(psutil) and the cameras recorded in the journal every ``--every`` seconds. Bounded memory
means the RSS reaches a plateau while the cameras done keep growing.

Writes ``benchmarks/out/batch_scale.json`` (rate, RSS at each decile of the cameras done,
the peak, the slope of RSS against cameras done over the second half of the run) and
``benchmarks/out/batch_scale.png`` (RSS and cameras done against time)::

    python benchmarks/batch_scale.py --rows 100000 [--workers 2] [--chunk-size 64]

A million rows at this machine's rate takes hours; ``--max-s`` stops the run after that many
seconds (the list stays a million rows long: reading, grouping and journalling are the
streaming parts under test), and the JSON says so and extrapolates the whole list's time from
the measured rate.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import json
import os
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
OUT = REPO / "benchmarks" / "out"
EXTRACTS = (REPO / "data" / "osm" / "baltimore.osm.pbf", REPO / "sample_maps" / "fremantle.osm")
PAPER_S_PER_IMAGE = 0.41


def _junction_names(extracts: tuple[Path, ...]) -> list[tuple[str, str]]:
    """Street-name pairs of real junctions of the extracts (whole-extract maps)."""
    from camloc_geo.osm import load_map
    from camloc_geo.osm._catalogue import extract_bounds as _bounds
    from camloc_geo.testing.camera_list import _junctions

    pairs: list[tuple[str, str]] = []
    for e in extracts:
        s, w, n, east = _bounds(str(e))
        m = load_map(str(e), (s + n) / 2, (w + east) / 2, radius_m=None)
        for x in _junctions(m):
            names = sorted({n for n in x.street_names if n and not n.startswith("(")})
            pairs.append((names[0], names[1]))
    return pairs


def write_title_list(
    path: Path, rows: int, pairs: list[tuple[str, str]], *, distinct: bool = False
) -> None:
    """``rows`` title-only cameras, written one row at a time (never held in memory).

    The titles cycle through the junctions and four listing styles, so a title comes back
    every ``4 × len(pairs)`` rows (as a city's cameras share junctions); ``distinct`` puts
    the camera's own number first (``"123456 - A & B"``), so no two rows share a title and
    no answer is reused (the worst case for the batch).
    """
    styles = ("{a} & {b}", "{n} - {a} / {b} looking north", "{a} at {b}", "{A} @ {B}")
    if distinct:
        styles = ("{i} - {a} & {b}", "{i} - {a} / {b} looking north", "{i} - {a} at {b}")
    with path.open("w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["id", "title"])
        for i in range(rows):
            a, b = pairs[i % len(pairs)]
            style = styles[(i // len(pairs)) % len(styles)]
            title = style.format(a=a, b=b, A=a.upper(), B=b.upper(), n=100 + i % 900, i=i + 1)
            w.writerow([f"cam{i + 1:07d}", title])


_CPU_SEEN: dict[int, float] = {}


def _tree_rss_mb(proc: Any) -> tuple[float, float, int, float]:
    """RSS of a process and its children (MiB): total, the largest one, how many; and the
    CPU seconds the tree has used so far (workers that ended keep their last reading)."""
    import psutil

    total, largest, n = 0, 0, 0
    with contextlib.suppress(psutil.Error):
        for p in [proc, *proc.children(recursive=True)]:
            with contextlib.suppress(psutil.Error):
                rss = p.memory_info().rss
                total += rss
                largest = max(largest, rss)
                n += 1
                t = p.cpu_times()
                _CPU_SEEN[p.pid] = t.user + t.system
    return total / 2**20, largest / 2**20, n, sum(_CPU_SEEN.values())


def _journal_count(path: Path) -> int:
    if not path.exists():
        return 0
    try:
        db = sqlite3.connect(f"file:{path}?mode=ro", uri=True, timeout=1.0)
        try:
            return int(db.execute("SELECT COUNT(*) FROM done").fetchone()[0])
        finally:
            db.close()
    except sqlite3.Error:
        return -1


_HWM = """
def _HWM():  # this process's peak RSS, MiB (ru_maxrss would count the parent's, from fork)
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024
"""
_RESUME_OLD = (
    _HWM
    + """
import sys
from camloc_geo.batch._journal import Journal
j = Journal(__import__("pathlib").Path(sys.argv[1]))
done = j.done_rows(retry=("failed",))
print(len(done), _HWM())
"""
)
_RESUME_NEW = (
    _HWM
    + """
import sys
from camloc_geo.batch._journal import Journal
from camloc_geo.batch._run import _RowBits
j = Journal(__import__("pathlib").Path(sys.argv[1]))
done = _RowBits()
n = 0
for row, _id in j.iter_done(retry=("failed",)):
    done.add(row)
    n += 1
print(n, _HWM())
"""
)
_RESUME_BASE = (
    _HWM
    + """
from camloc_geo.batch._journal import Journal
from camloc_geo.batch._run import _RowBits
print(0, _HWM())
"""
)


def resume_check_memory(rows: int) -> dict[str, Any]:
    """Peak RSS of the resume check on a journal of ``rows`` finished cameras.

    ``done_rows`` (the dictionary the run held before) against the streamed walk
    (:meth:`Journal.iter_done` into one bit per row), each in a fresh interpreter, next to
    the interpreter with the same imports and no journal read.
    """
    from camloc_geo.batch._journal import Journal

    with tempfile.TemporaryDirectory(prefix="camloc-resume-") as tmp_s:
        path = Path(tmp_s) / "j.camloc-batch.sqlite"
        j = Journal(path)
        try:
            j.db.execute("BEGIN")
            j.db.executemany(
                "INSERT INTO done VALUES (?, ?, ?, ?)",
                ((r, f"cam{r:07d}", "located", "{}") for r in range(1, rows + 1)),
            )
            j.db.execute("COMMIT")
        finally:
            j.close()
        env = dict(os.environ, PYTHONPATH=str(REPO))
        out: dict[str, Any] = {"journal_rows": rows}
        for key, code in (
            ("imports_only", _RESUME_BASE),
            ("dict", _RESUME_OLD),
            ("walk", _RESUME_NEW),
        ):
            proc = subprocess.run(
                [sys.executable, "-c", code, str(path)],
                env=env,
                capture_output=True,
                text=True,
                check=True,
            )
            n, peak = proc.stdout.split()
            out[f"{key}_peak_rss_mb"] = round(float(peak), 1)
            if key != "imports_only":
                out[f"{key}_rows_seen"] = int(n)
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rows", type=int, default=100_000, help="rows of the list (100000)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--chunk-size", type=int, default=64)
    ap.add_argument("--every", type=float, default=1.0, help="sampling period, seconds")
    ap.add_argument("--max-s", type=float, default=None, help="stop the run after this long")
    ap.add_argument("--label", default="", help="a note kept in the JSON")
    ap.add_argument(
        "--distinct-titles",
        action="store_true",
        help="every row its own title (a camera number first): no answer reused",
    )
    ap.add_argument(
        "--resume-rows",
        type=int,
        default=1_000_000,
        help="journal rows for the resume-check memory comparison (0: skip)",
    )
    ns = ap.parse_args(argv)
    import psutil

    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="camloc-batch-scale-") as tmp_s:
        tmp = Path(tmp_s)
        folder = tmp / "osm"
        folder.mkdir()
        for e in EXTRACTS:
            (folder / e.name).symlink_to(e)
        t = time.perf_counter()
        pairs = _junction_names(EXTRACTS)
        lst = tmp / "titles.csv"
        write_title_list(lst, ns.rows, pairs, distinct=ns.distinct_titles)
        gen_s = time.perf_counter() - t
        out = tmp / "out.gpkg"
        journal = out.with_name(out.stem + ".camloc-batch.sqlite")
        cmd = [
            sys.executable,
            "-m",
            "camloc_geo.cli",
            "batch",
            str(lst),
            "-o",
            str(out),
            "--osm",
            str(folder),
            "--workers",
            str(ns.workers),
            "--chunk-size",
            str(ns.chunk_size),
            "--no-progress",
        ]
        env = dict(os.environ, PYTHONPATH=str(REPO))
        log_path = tmp / "batch.log"
        samples: list[dict[str, float]] = []
        t0 = time.perf_counter()
        stopped = False
        with log_path.open("w") as log_f:
            child = subprocess.Popen(
                cmd,
                env=env,
                stdout=log_f,
                stderr=subprocess.STDOUT,
                start_new_session=True,  # its own process group: Ctrl-C reaches the workers
                # a shell's background job ignores SIGINT, and a child would inherit that
                preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
            )
            ps = psutil.Process(child.pid)
            while child.poll() is None:
                now = time.perf_counter() - t0
                total, largest, n, cpu_s = _tree_rss_mb(ps)
                samples.append(
                    {
                        "t_s": round(now, 2),
                        "rss_mb": round(total, 1),
                        "largest_mb": round(largest, 1),
                        "procs": n,
                        "done": _journal_count(journal),
                        "cpu_s": round(cpu_s, 1),
                        "load1": round(os.getloadavg()[0], 2),
                    }
                )
                if ns.max_s is not None and now > ns.max_s:
                    stopped = True
                    os.killpg(child.pid, signal.SIGINT)  # Ctrl-C: the batch and its workers
                    with contextlib.suppress(subprocess.TimeoutExpired):
                        child.wait(timeout=60)
                    if child.poll() is None:
                        child.kill()
                    break
                time.sleep(ns.every)
            with contextlib.suppress(ProcessLookupError):
                os.killpg(child.pid, signal.SIGKILL)  # no worker outlives the run
        wall = time.perf_counter() - t0
        rc = child.wait()
        done = _journal_count(journal)
        tail = log_path.read_text(errors="replace")[-2000:]
        list_mb = lst.stat().st_size / 2**20
    samples = [s for s in samples if s["done"] >= 0]
    working = [s for s in samples if s["done"] > 0]
    # the rate while cameras are computed: the GeoPackage is built after the last one (the
    # batch alone, without workers) and counts apart, in after_last_camera_s
    computing = [s for s in working if s["procs"] > 1]
    rate_span = computing if len(computing) >= 2 else working
    rate = 0.0
    if len(rate_span) >= 2 and rate_span[-1]["t_s"] > rate_span[0]["t_s"]:
        rate = (rate_span[-1]["done"] - rate_span[0]["done"]) / (
            rate_span[-1]["t_s"] - rate_span[0]["t_s"]
        )
    deciles = []
    for q in range(1, 11):
        want = done * q / 10
        hit = next((s for s in samples if s["done"] >= want), None)
        if hit is not None:
            deciles.append({"done": hit["done"], "rss_mb": hit["rss_mb"], "t_s": hit["t_s"]})
    # the slope while cameras are computed
    half = [s for s in computing if s["done"] >= computing[-1]["done"] / 2] if computing else []
    slope = None
    if len(half) >= 2 and half[-1]["done"] > half[0]["done"]:
        slope = (half[-1]["rss_mb"] - half[0]["rss_mb"]) / (half[-1]["done"] - half[0]["done"])
    # CPU per camera while computing (a shared machine's load stretches the wall time, not
    # this), and the machine's load meanwhile
    cpu_per_cam_ms = None
    if len(computing) >= 2 and computing[-1]["done"] > computing[0]["done"]:
        cpu_per_cam_ms = (
            1000
            * (computing[-1]["cpu_s"] - computing[0]["cpu_s"])
            / (computing[-1]["done"] - computing[0]["done"])
        )
    loads = sorted(s["load1"] for s in samples)
    gpkg_s = None
    if computing and samples and not stopped:
        gpkg_s = round(samples[-1]["t_s"] - computing[-1]["t_s"], 1)
    result: dict[str, Any] = {
        "label": ns.label,
        "rows": ns.rows,
        "workers": ns.workers,
        "chunk_size": ns.chunk_size,
        "title_only": True,
        "distinct_titles": ns.distinct_titles,
        "extracts": [e.name for e in EXTRACTS],
        "junction_titles": len(pairs),
        "list_generation_s": round(gen_s, 1),
        "list_mb": round(list_mb, 1),
        "exit_code": rc,
        "stopped_at_max_s": stopped,
        "cameras_done": done,
        "wall_s": round(wall, 1),
        "cameras_per_s": round(rate, 1),
        "cpu_ms_per_camera_all_processes": (
            round(cpu_per_cam_ms, 3) if cpu_per_cam_ms is not None else None
        ),
        "load1_median": loads[len(loads) // 2] if loads else None,
        "after_last_camera_s": gpkg_s,
        "extrapolated_compute_s_all_rows": round(ns.rows / rate, 0) if rate else None,
        "extrapolated_compute_s_million": round(1e6 / rate, 0) if rate else None,
        "paper_s_per_image": PAPER_S_PER_IMAGE,
        "peak_rss_mb": max((s["rss_mb"] for s in samples), default=None),
        "rss_mb_by_decile_of_done": deciles,
        "rss_mb_per_1000_cameras_second_half": (
            round(1000 * slope, 3) if slope is not None else None
        ),
        "log_tail": tail if rc not in (0, None) and not stopped else "",
        "samples": samples,
    }
    if ns.resume_rows:
        result["resume_check"] = resume_check_memory(ns.resume_rows)
    name = "batch_scale" if not ns.label else f"batch_scale_{ns.label}"
    (OUT / f"{name}.json").write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    brief = {k: v for k, v in result.items() if k != "samples"}
    print(json.dumps(brief, indent=2))
    _plot(samples, OUT / f"{name}.png", result)
    return 0 if rc == 0 or stopped else 1


def _plot(samples: list[dict[str, float]], path: Path, result: dict[str, Any]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4))
    ts = [s["t_s"] for s in samples]
    ax.plot(ts, [s["rss_mb"] for s in samples], color="tab:blue", label="RSS, batch + workers")
    ax.plot(ts, [s["largest_mb"] for s in samples], color="tab:cyan", label="largest process")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("RSS (MiB)")
    ax.set_ylim(bottom=0)
    ax2 = ax.twinx()
    ax2.plot(ts, [s["done"] for s in samples], color="tab:orange", label="cameras done")
    ax2.set_ylabel("cameras done (journal)")
    ax2.set_ylim(bottom=0)
    lines = ax.get_lines() + ax2.get_lines()
    ax.legend(lines, [str(ln.get_label()) for ln in lines], loc="lower right")
    ax.set_title(
        f"camloc batch, {result['rows']:,} title-only rows, {result['workers']} workers: "
        f"{result['cameras_per_s']} cam/s"
    )
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
