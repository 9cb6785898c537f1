"""Session 38 QA: ``camloc batch``'s worker processes end when the batch process is killed.

``kill -9`` of ``camloc batch`` (or the OOM killer) left its pool's workers running for ever,
orphaned, each waiting on a queue nobody writes to, holding its maps and the journal's file
handles. The workers now watch the process that started them and exit when it is gone.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

REPO = Path(__file__).resolve().parents[1]

_SCRIPT = """
import os, sys, time
from camloc_geo.batch._run import _local_executor

def nap(_):
    time.sleep(0.5)
    return os.getpid()

if __name__ == "__main__":
    ex = _local_executor(2)
    pids = sorted(set(ex.map(nap, range(4))))
    print(" ".join(str(p) for p in pids), flush=True)
    time.sleep(600)
"""


def _gone(pid: int) -> bool:
    try:
        return psutil.Process(pid).status() == psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return True


@pytest.mark.parametrize("method", ["fork", "forkserver", "spawn"])
def test_workers_exit_when_the_batch_process_is_killed(tmp_path: Path, method: str) -> None:
    script = tmp_path / "pool.py"
    script.write_text(_SCRIPT, encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(REPO), "CAMLOC_BATCH_START_METHOD": method}
    proc = subprocess.Popen(
        [sys.executable, str(script)], env=env, stdout=subprocess.PIPE, text=True
    )
    worker_pids: list[int] = []
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        worker_pids = [int(p) for p in line.split()]
        assert worker_pids
        assert proc.pid not in worker_pids
        assert not any(_gone(p) for p in worker_pids)  # alive before the kill
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and not all(_gone(p) for p in worker_pids):
            time.sleep(0.1)
        left = [p for p in worker_pids if not _gone(p)]
        assert left == [], f"workers {left} outlived the killed batch process"
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(timeout=30)
        if proc.stdout is not None:
            proc.stdout.close()
        for p in worker_pids:
            if not _gone(p):
                os.kill(p, signal.SIGKILL)
