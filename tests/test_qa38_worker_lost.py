"""Session 38 QA: a service request whose worker process dies.

``kill -9`` of ``camloc serve``'s worker during a ``POST /v1/locate`` answered 500
"internal error" (logged as a bug); the service started a new worker and the next request
was fine. A lost worker is a transient condition of the server: 503 ``worker_lost``, which
a client may retry.
"""

from __future__ import annotations

import asyncio
import os
from pathlib import Path
from typing import Any

import pytest

from camloc_geo.service.compute import Compute
from camloc_geo.service.errors import WorkerLostError, error_response_for
from camloc_geo.service.mapstore import MapStore
from camloc_geo.service.settings import Settings


def _die(_maps: Any) -> int:
    os._exit(9)  # as a worker killed by the OOM killer or kill -9


def _pid(_maps: Any) -> int:
    return os.getpid()


def test_a_lost_worker_is_a_503_and_the_next_request_is_served(tmp_path: Path) -> None:
    settings = Settings(data_dir=tmp_path / "d", workers=1)
    compute = Compute(settings, MapStore(settings))
    try:
        first = asyncio.run(compute.run(_pid))
        with pytest.raises(WorkerLostError) as info:
            asyncio.run(compute.run(_die))
        answer = error_response_for(info.value, "r1")
        assert answer.status_code == 503
        assert b'"worker_lost"' in answer.body
        assert b"send the request again" in answer.body
        second = asyncio.run(compute.run(_pid))
        assert second != first  # a new worker
    finally:
        compute.shutdown()
