"""Run camloc_geo in a separate Python (``python -m camloc_geo.qgis.worker JOB.json``).

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
WORKER_MODULES = ("camloc_geo.qgis.worker", "camloc_geo.qgis_worker")
"""The worker's module, then its home before camloc_geo 0.x moved it (older installs)."""
DEFAULT_VENV = "~/.local/share/camloc-venv"
"""A venv the plugin looks in without configuration (its ``bin/python``)."""
PIP_PACKAGE = "camloc-geo"

_found: dict[str, tuple[str, str] | None] = {}


class WorkerError(Exception):
    """The worker failed; the message names the problem (shown as a Processing error).

    ``kind`` is the library's exception class name when the worker answered with one
    (``SceneError``, ``InputError``...), None when the worker itself failed or is missing.
    """

    def __init__(self, message: str, kind: str | None = None) -> None:
        super().__init__(message)
        self.kind = kind


class WorkerCanceledError(WorkerError):
    """The user canceled."""


def qgis_python() -> str:
    """The Python interpreter QGIS runs (the base of the venv the message suggests)."""
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


def _externally_managed() -> bool:
    """True for a distribution's Python that refuses pip installs (PEP 668, Debian bookworm)."""
    import sysconfig

    stdlib = sysconfig.get_paths().get("stdlib") or ""
    return bool(stdlib) and os.path.exists(os.path.join(stdlib, "EXTERNALLY-MANAGED"))


def install_commands() -> list[str]:
    """Shell commands that give the plugin a Python with camloc_geo, one per line.

    A venv in :data:`DEFAULT_VENV` (where the plugin looks without configuration), made from
    QGIS's own Python with ``--system-site-packages`` and numpy 1.24 (``docs/qgis.md``); on
    Windows the venv's ``Scripts`` folder. Never ``pip install`` into a distribution's Python
    (Debian and Ubuntu refuse it, PEP 668).
    """
    py = qgis_python()
    py = f'"{py}"' if " " in py else py
    if sys.platform.startswith("win"):
        venv = "%APPDATA%\\camloc-venv"
        return [
            f"{py} -m venv --system-site-packages {venv}",
            f'{venv}\\Scripts\\python -m pip install "numpy<2" {PIP_PACKAGE}',
            f"setx CAMLOC_PYTHON {venv}\\Scripts\\python.exe",
        ]
    return [
        f"{py} -m venv --system-site-packages {DEFAULT_VENV}",
        f'{DEFAULT_VENV}/bin/python -m pip install "numpy==1.24.2" {PIP_PACKAGE}',
    ]


def missing_message() -> str:
    """What to tell the user when no interpreter can import camloc_geo (several lines)."""
    return (
        "The camloc plugin needs the camloc_geo library, and no Python it tried can import "
        "it. Make a Python for it once, in a terminal:\n\n    "
        + "\n    ".join(install_commands())
        + "\n\nthen restart QGIS. The plugin looks in "
        + DEFAULT_VENV
        + " by itself; a Python elsewhere can be named by the environment variable "
        "CAMLOC_PYTHON or the setting camloc/python (docs/qgis.md)."
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


def _worker_module(python: str) -> str | None:
    """The worker module ``python`` can import (newest home first), or None."""
    for module in WORKER_MODULES:
        try:
            r = subprocess.run(
                [python, "-c", f"import {module}"],
                capture_output=True,
                timeout=60,
                env=_worker_env(),
            )
        except (OSError, subprocess.SubprocessError):
            return None
        if r.returncode == 0:
            return module
    return None


def _worker_env() -> dict[str, str]:
    env = dict(os.environ)
    # QGIS may run under another platform plugin; the worker needs none, and must not inherit
    # QGIS's own library path tweaks.
    for key in ("PYTHONHOME", "QT_PLUGIN_PATH"):
        env.pop(key, None)
    env.setdefault("PYTHONIOENCODING", "utf-8")
    return env


def _find(refresh: bool = False) -> tuple[str, str] | None:
    key = "|".join(_candidates())
    if refresh or key not in _found:
        _found[key] = None
        for c in _candidates():
            module = _worker_module(c)
            if module is not None:
                _found[key] = (c, module)
                break
    return _found[key]


def find_python(refresh: bool = False) -> str | None:
    """The first interpreter that can import camloc_geo (cached), or None."""
    found = _find(refresh)
    return found[0] if found else None


def run_worker(
    job: dict[str, Any],
    *,
    progress: Callable[[float, str], None] | None = None,
    canceled: Callable[[], bool] | None = None,
    log: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Run a job in the worker; its final message (``layers``, ``warnings``, ``info``).

    The job file and the worker's layer files live in a temporary folder removed before this
    returns: each layer's features come back in its description (``data``), so nothing is
    left behind in the temporary folder.

    Raises
    ------
    WorkerError
        No interpreter has camloc_geo, or the library reported an error (message kept).
    WorkerCanceledError
        ``canceled()`` became true; the worker process is killed.
    """
    found = _find()
    if found is None:
        raise WorkerError(missing_message())
    with tempfile.TemporaryDirectory(prefix="camloc_") as work:
        final = _run_in(found, job, work, progress=progress, canceled=canceled, log=log)
        for desc in (final.get("layers") or {}).values():
            path = desc.get("path")
            if path and os.path.isfile(path):
                with open(path, encoding="utf-8") as fh:
                    desc["data"] = json.load(fh)
            desc["path"] = None
    return final


PATH_KEYS = ("scene", "osm", "list", "image", "save_to")
"""Job fields that name a file or folder of the user's (the worker reads them)."""


def absolute_paths(job: dict[str, Any]) -> dict[str, Any]:
    """The job with its relative file paths made absolute against this process's folder.

    The worker runs in its own temporary folder, so a relative path (``qgis_process run
    camloc:locate --SCENE=scene.json``, relative to the shell's folder) would be looked for
    there and reported missing.
    """
    out = dict(job)
    for key in PATH_KEYS:
        value = out.get(key)
        if isinstance(value, str) and value and not os.path.isabs(value):
            out[key] = os.path.abspath(os.path.expanduser(value))
    return out


def _run_in(
    found: tuple[str, str],
    job: dict[str, Any],
    work: str,
    *,
    progress: Callable[[float, str], None] | None,
    canceled: Callable[[], bool] | None,
    log: Callable[[str], None] | None,
) -> dict[str, Any]:
    python, module = found
    job = {**absolute_paths(job), "out_dir": work}
    job_path = Path(work) / "job.json"
    job_path.write_text(json.dumps(job), encoding="utf-8")
    proc = subprocess.Popen(
        [python, "-m", module, str(job_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=_worker_env(),
        text=True,
        encoding="utf-8",
        cwd=work,
    )
    lines: queue.Queue[str | None] = queue.Queue()
    errors: list[str] = []

    def pump() -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            lines.put(line)
        lines.put(None)

    def pump_err() -> None:  # read stderr as it comes: a chatty worker never blocks on it
        assert proc.stderr is not None
        for line in proc.stderr:
            errors.append(line)
            del errors[:-200]

    readers = [threading.Thread(target=f, daemon=True) for f in (pump, pump_err)]
    for r in readers:
        r.start()
    final: dict[str, Any] | None = None
    while True:
        if canceled is not None and canceled():
            proc.kill()
            proc.wait()
            for r in readers:
                r.join(timeout=5)
            _close(proc)
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
    for r in readers:
        r.join(timeout=5)
    _close(proc)
    stderr = "".join(errors)
    if final is None:
        tail = stderr.strip().splitlines()[-3:]
        raise WorkerError(
            f"the camloc worker ({python}) stopped with status {rc} without an answer"
            + (": " + " | ".join(tail) if tail else "")
        )
    if not final.get("ok"):
        kind = final.get("kind")
        raise WorkerError(
            str(final.get("error") or "the camloc worker failed"),
            kind=str(kind) if kind else None,
        )
    if log and stderr.strip():
        for ln in stderr.strip().splitlines()[-20:]:
            log(ln)
    return final


def _close(proc: subprocess.Popen[str]) -> None:
    for stream in (proc.stdout, proc.stderr):
        if stream is not None:
            stream.close()


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
