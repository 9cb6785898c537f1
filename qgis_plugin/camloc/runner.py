"""Run camloc_geo in a separate Python (``python -m camloc_geo.qgis_worker JOB.json``).

QGIS loads the system GEOS/PROJ into its own process and the shapely/pyproj wheels that
camloc_geo needs crash there, so nothing heavy is imported in QGIS: the plugin finds an
interpreter that can ``import camloc_geo`` and talks to it through a job file and JSON lines.

The interpreter is the first that can import camloc_geo of: the environment variable
``CAMLOC_PYTHON``, the plugin setting ``camloc/python`` (QgsSettings), QGIS's own Python, the venv
``~/.local/share/camloc-venv``, then ``python3``/``python`` on ``PATH``.
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
DEFAULT_VENV = "~/.local/share/camloc-venv"
"""A venv the plugin looks in without configuration (its ``bin/python``)."""
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
    py = f'"{py}"' if " " in py else py
    return f"{py} -m pip install {PIP_PACKAGE}"


def _externally_managed() -> bool:
    """True for a distribution's Python that refuses pip installs (PEP 668, Debian bookworm)."""
    import sysconfig

    stdlib = sysconfig.get_paths().get("stdlib") or ""
    return bool(stdlib) and os.path.exists(os.path.join(stdlib, "EXTERNALLY-MANAGED"))


def missing_message() -> str:
    """What to tell the user when no interpreter can import camloc_geo."""
    msg = (
        "The camloc plugin needs the camloc_geo library, and no Python found can import it. "
        f"Install it into QGIS's Python with:  {pip_command()}"
    )
    if _externally_managed() or sys.platform.startswith("linux"):
        msg += (
            f"  — or, where that Python refuses pip (Debian, Ubuntu):  python3 -m venv "
            f"{DEFAULT_VENV} && {DEFAULT_VENV}/bin/python -m pip install {PIP_PACKAGE}"
        )
    return msg + (
        "  The plugin also uses the Python named by the environment variable CAMLOC_PYTHON or the "
        "setting camloc/python. Then restart QGIS."
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
    venv = Path(os.path.expanduser(DEFAULT_VENV))
    for rel in ("bin/python", "Scripts/python.exe"):
        if (venv / rel).exists():
            out.append(str(venv / rel))
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
