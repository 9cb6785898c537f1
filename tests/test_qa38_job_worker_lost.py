"""Session 38 QA: a job camera whose worker process dies is computed again.

The job runner recorded such a camera ``failed`` ("internal error (BrokenProcessPool)") for
good, though a server restart does the cameras in flight again; the camera now gets one
more try on a new worker (a camera that kills its worker twice is ``failed``).
"""

from __future__ import annotations

import time
from concurrent.futures import Future
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any

from camloc_geo.service.routers.jobs import JobRunner
from camloc_geo.service.settings import Settings
from camloc_geo.service.store import Store


class _FlakyCompute:
    """Its first ``losses`` submissions lose their worker; later ones answer."""

    def __init__(self, losses: int) -> None:
        self.losses = losses
        self.calls = 0

    def submit(self, _fn: Any, camera: Any, _settings: Any) -> Future[Any]:
        self.calls += 1
        fut: Future[Any] = Future()
        if self.calls <= self.losses:
            fut.set_exception(BrokenProcessPool("a worker died"))
        else:
            fut.set_result({"id": camera["id"], "status": "title_only", "reason": "ok"})
        return fut


def _run_job(tmp_path: Path, losses: int) -> tuple[dict[str, Any], int]:
    store = Store(tmp_path / "d")
    job_id = store.create_job([{"id": "c1", "title": "Eastern Ave & S Broadway"}])
    compute = _FlakyCompute(losses)
    runner = JobRunner(store, compute, Settings(data_dir=tmp_path / "d"))  # type: ignore[arg-type]
    runner.start()
    try:
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and (store.job(job_id) or {}).get("status") != "done":
            time.sleep(0.05)
    finally:
        runner.stop()
    (result,) = store.job_results(job_id)
    return result, compute.calls


def test_a_camera_whose_worker_died_is_computed_again(tmp_path: Path) -> None:
    result, calls = _run_job(tmp_path, losses=1)
    assert calls == 2
    assert result["status"] == "title_only"


def test_a_camera_that_loses_its_worker_twice_is_failed(tmp_path: Path) -> None:
    result, calls = _run_job(tmp_path, losses=2)
    assert calls == 2
    assert result["status"] == "failed"
    assert "BrokenProcessPool" in result["reason"]
