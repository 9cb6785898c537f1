"""Where the service's CPU work runs: worker processes, each with its own maps, or threads.

With ``CAMLOC_WORKERS`` = N ≥ 1 (``camloc serve --workers N``) one process serves HTTP and
N worker processes compute: every request goes to whichever worker is free, so N cores share
the load whatever connections the clients keep open (uvicorn's own worker processes each keep
the connections they accepted: with keep-alive clients one of two took 99.5 % of the work).
Each worker loads a map at most once. With 0 the work runs in threads of the serving process.

A worker keeps its maps out of the garbage collector's way: after a request that loaded a
map (or built a map's derived data), the objects alive then are frozen (:func:`gc.freeze`),
so that the full collections the requests' garbage triggers no longer walk the map's
hundreds of thousands of objects (measured in process: 2.7 ms per request on average, and
single pauses of ~100 ms, the tail of the latency).

A task is a module-level function ``fn(maps, *args)`` (picklable); its arguments are already
validated models, sent as they are.
"""

from __future__ import annotations

import asyncio
import gc
import logging
import multiprocessing
import os
import threading
from collections.abc import Callable
from concurrent.futures import Executor, Future, ProcessPoolExecutor, ThreadPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

from starlette.responses import Response

from camloc_geo.service.errors import TimeLimitError, WorkerLostError
from camloc_geo.service.mapstore import MapStore
from camloc_geo.service.settings import Settings

__all__ = ["Compute"]

log = logging.getLogger(__name__)
T = TypeVar("T")

_worker_maps: MapStore | None = None
_frozen_at_loads = -1


def _init_worker(settings: Settings, parent_pid: int) -> None:
    global _worker_maps
    _worker_maps = MapStore(settings)
    import camloc_geo.absolute
    import camloc_geo.api
    import camloc_geo.osm
    import camloc_geo.relative  # noqa: F401  (imported once here, not in a first request)

    def watch() -> None:  # a killed server must not leave its workers behind
        while True:
            if os.getppid() != parent_pid:
                os._exit(0)
            threading.Event().wait(1.0)

    threading.Thread(target=watch, name="camloc-parent-watch", daemon=True).start()


def _started(_maps: MapStore) -> None:
    threading.Event().wait(0.5)  # busy long enough that the next one needs another process


def _as_json(maps: MapStore, fn: Callable[..., Any], *args: Any) -> bytes:
    from pydantic_core import to_json

    return to_json(fn(maps, *args))  # the writer FastAPI itself uses, here off the event loop


def _in_worker(fn: Callable[..., T], args: tuple[Any, ...]) -> T:
    assert _worker_maps is not None
    try:
        return fn(_worker_maps, *args)
    finally:
        _freeze_maps()


def _freeze_maps() -> None:
    """Move what lives now (the maps) out of the garbage collector's reach, when the maps
    changed since the last time: the first request after a map load also builds the map's
    indexes, so freezing after it keeps those out too."""
    global _frozen_at_loads
    from camloc_geo.osm import map_loads

    loads = map_loads()
    if loads != _frozen_at_loads:
        gc.unfreeze()  # maps dropped since: let a full collection reclaim them
        gc.collect()
        gc.freeze()
        _frozen_at_loads = loads


class Compute:
    """The service's CPU pool (see the module docstring).

    Parameters
    ----------
    settings
        ``workers`` processes (0: threads) and ``request_timeout_s``.
    maps
        The serving process's maps (used by the threads when there are no processes).
    """

    def __init__(self, settings: Settings, maps: MapStore) -> None:
        self.settings, self.maps = settings, maps
        self.threads = ThreadPoolExecutor(max_workers=4, thread_name_prefix="camloc")
        self._processes: ProcessPoolExecutor | None = None
        self._lock = threading.Lock()

    def start(self) -> None:
        """Start every worker process now (each loads its maps on first need)."""
        if self.settings.workers > 0:
            for _ in range(self.settings.workers):  # processes are started on demand
                self.submit(_started)

    def _pool(self) -> ProcessPoolExecutor:
        with self._lock:
            if self._processes is None:
                self._processes = ProcessPoolExecutor(
                    max_workers=self.settings.workers,
                    mp_context=multiprocessing.get_context("spawn"),
                    initializer=_init_worker,
                    initargs=(self.settings, os.getpid()),
                )
            return self._processes

    def shutdown(self) -> None:
        """Stop the threads and processes (work in flight is dropped)."""
        self.threads.shutdown(wait=False, cancel_futures=True)
        if self._processes is not None:
            self._processes.shutdown(wait=False, cancel_futures=True)

    def submit(self, fn: Callable[..., T], *args: Any) -> Future[T]:
        """Run ``fn(maps, *args)`` on a worker; a pool whose worker died is replaced."""
        if self.settings.workers == 0:
            return self.threads.submit(fn, self.maps, *args)
        pool = self._pool()
        try:
            return pool.submit(_in_worker, fn, args)
        except BrokenProcessPool:
            log.error("a worker process died: starting new ones")
            with self._lock:
                if self._processes is pool:
                    self._processes = None
            return self._pool().submit(_in_worker, fn, args)

    async def run(self, fn: Callable[..., T], *args: Any) -> T:
        """``fn(maps, *args)`` on a worker, under the request time limit.

        Raises
        ------
        TimeLimitError
            Longer than ``CAMLOC_REQUEST_TIMEOUT_S`` (HTTP 503).
        """
        limit_s = self.settings.request_timeout_s
        try:
            return await asyncio.wait_for(
                asyncio.wrap_future(self.submit(fn, *args)), timeout=limit_s
            )
        except asyncio.TimeoutError:
            raise TimeLimitError(f"processing took longer than {limit_s:g} s") from None
        except BrokenProcessPool:
            with self._lock:
                self._processes = None
            # a 503 the client may retry (it was a logged 500 "internal error", as for a bug)
            raise WorkerLostError(
                "the worker process computing this request stopped (killed or out of "
                "memory); a new one is started: send the request again"
            ) from None

    async def run_bytes(self, fn: Callable[..., Any], *args: Any) -> bytes:
        """:meth:`run`, the answer written as JSON by the worker (the serving process only
        sends the bytes: no nested dict to copy between processes or to serialise)."""
        return await self.run(_as_json, fn, *args)

    async def run_json(self, fn: Callable[..., Any], *args: Any) -> Response:
        """:meth:`run_bytes` as a JSON response."""
        return Response(await self.run_bytes(fn, *args), media_type="application/json")

    def executor(self) -> Executor:
        """The thread pool (for work that needs no map: parsing, the database)."""
        return self.threads
