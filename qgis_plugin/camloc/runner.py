"""Run camloc_geo in a separate Python (``python -m camloc_geo.qgis_worker JOB.json``).

QGIS loads the system GEOS/PROJ into its own process and the shapely/pyproj wheels that
camloc_geo needs crash there, so nothing heavy is imported in QGIS: the plugin finds an
interpreter that can ``import camloc_geo`` and talks to it through a job file and JSON lines.

The interpreter is, in order: the environment variable ``CAMLOC_PYTHON``, the plugin setting
``camloc/python`` (QgsSettings), QGIS's own Python, then ``python3``/``python`` on ``PATH``.
"""

from __future__ import annotations

import json
import os
import queue
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

SETTING_KEY = "camloc/python"
PIP_PACKAGE = "camloc-geo"

_found: dict[str, str | None] = {}


class WorkerError(Exception):
    """The worker failed; the message names the problem (shown as a Processing error)."""


class WorkerCanceledError(WorkerError):
    """The user canceled."""


def qgis_python() -> str:
    """The Python interpreter QGIS runs (for the pip command shown to the user)."""
    exe = Path(sys.executable)
    if exe.name.lower().startswith("python"):
        return str(exe)
    prefix = Path(sys.exec_prefix)
    for cand in (
        prefix / "python3.exe",
        prefix / "python.exe",
        prefix / "bin" / "python3",
        Path("/usr/bin/python3"),
    ):
        if cand.exists():
            return str(cand)
    return "python3"


def pip_command() -> str:
    """The command that installs camloc_geo into QGIS's Python."""
    py = qgis_python()
    extra = " --user" if sys.platform.startswith("linux") and py.startswith("/usr/") else ""
    return (
        f'"{py}" -m pip install{extra} {PIP_PACKAGE}'
        if " " in py
        else (f"{py} -m pip install{extra} {PIP_PACKAGE}")
    )


def missing_message() -> str:
    """What to tell the user when no interpreter can import camloc_geo."""
    return (
        "The camloc plugin needs the camloc_geo library, and no Python interpreter found can "
        f"import it. Install it into QGIS's Python with:  {pip_command()}  "
        "(or set the environment variable CAMLOC_PYTHON, or the setting camloc/python, to a "
        "Python that has camloc_geo) and restart QGIS."
    )


def _setting() -> str | None:
    try:
        from qgis.core import QgsSettings

        value = QgsSettings().value(SETTING_KEY, "")
    except Exception:
        return None
    return str(value) if value else None


def _candidates() -> list[str]:
    out: list[str] = []
    env = os.environ.get("CAMLOC_PYTHON")
    if env:
        out.append(env)
    s = _setting()
    if s:
        out.append(s)
    out.append(qgis_python())
    for name in ("python3", "python"):
        w = shutil.which(name)
        if w:
            out.append(w)
    seen: list[str] = []
    for c in out:
        if c not in seen:
            seen.append(c)
    return seen


def _can_import(python: str) -> bool:
    try:
        r = subprocess.run(
            [python, "-c", "import camloc_geo.qgis_worker"],
            capture_output=True,
            timeout=60,
            env=_worker_env(),
        )
    except (OSError, subprocess.SubprocessError):
        return False
    return r.returncode == 0


def _worker_env() -> dict[str, str]:
    env = dict(os.environ)
    # QGIS may run under another platform plugin; the worker needs none, and must not inherit
    # QGIS's own library path tweaks.
    for key in ("PYTHONHOME", "QT_PLUGIN_PATH"):
        env.pop(key, None)
    env.setdefault("PYTHONIOENCODING", "utf-8")
    return env


def find_python(refresh: bool = False) -> str | None:
    """The first interpreter that can import camloc_geo (cached), or None."""
    key = "|".join(_candidates())
    if refresh or key not in _found:
        _found[key] = next((c for c in _candidates() if _can_import(c)), None)
    return _found[key]


def run_worker(
    job: dict[str, Any],
    *,
    progress: Callable[[float, str], None] | None = None,
    canceled: Callable[[], bool] | None = None,
    log: Callable[[str], None] | None = None,
    out_dir: str | None = None,
) -> dict[str, Any]:
    """Run a job in the worker; its final message (``layers``, ``warnings``, ``info``).

    Raises
    ------
    WorkerError
        No interpreter has camloc_geo, or the library reported an error (message kept).
    WorkerCanceledError
        ``canceled()`` became true; the worker process is killed.
    """
    python = find_python()
    if python is None:
        raise WorkerError(missing_message())
    work = out_dir or tempfile.mkdtemp(prefix="camloc_")
    job = {**job, "out_dir": job.get("out_dir") or work}
    job_path = Path(work) / "job.json"
    job_path.write_text(json.dumps(job), encoding="utf-8")
    proc = subprocess.Popen(
        [python, "-m", "camloc_geo.qgis_worker", str(job_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=_worker_env(),
        text=True,
        encoding="utf-8",
    )
    lines: queue.Queue[str | None] = queue.Queue()

    def pump() -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            lines.put(line)
        lines.put(None)

    reader = threading.Thread(target=pump, daemon=True)
    reader.start()
    final: dict[str, Any] | None = None
    while True:
        if canceled is not None and canceled():
            proc.kill()
            proc.wait()
            for stream in (proc.stdout, proc.stderr):
                if stream is not None:
                    stream.close()
            raise WorkerCanceledError("canceled")
        try:
            line = lines.get(timeout=0.1)
        except queue.Empty:
            continue
        if line is None:
            break
        try:
            msg = json.loads(line)
        except ValueError:
            if log:
                log(line.rstrip())
            continue
        if "progress" in msg:
            if progress:
                progress(float(msg["progress"]), str(msg.get("message", "")))
        elif "ok" in msg:
            final = msg
    rc = proc.wait()
    stderr = proc.stderr.read() if proc.stderr else ""
    for stream in (proc.stdout, proc.stderr):
        if stream is not None:
            stream.close()
    if final is None:
        tail = stderr.strip().splitlines()[-3:]
        raise WorkerError(
            f"the camloc worker ({python}) stopped with status {rc} without an answer"
            + (": " + " | ".join(tail) if tail else "")
        )
    if not final.get("ok"):
        raise WorkerError(str(final.get("error") or "the camloc worker failed"))
    if log and stderr.strip():
        for ln in stderr.strip().splitlines()[-20:]:
            log(ln)
    return final


def probe(timeout_s: float = 60.0) -> dict[str, Any]:
    """What the worker offers (``version``, ``batch``, ``sensors``); empty when unavailable."""
    if find_python() is None:
        return {}
    t0 = time.monotonic()
    try:
        res = run_worker({"task": "probe"}, canceled=lambda: time.monotonic() - t0 > timeout_s)
    except WorkerError:
        return {}
    return dict(res.get("info") or {})
