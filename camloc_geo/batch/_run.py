"""``run_batch``: a camera list through :func:`geocode_camera`, locally or on Dask.

Work flows as chunks of cameras of one area (same map): the list is streamed, cameras are
grouped by area in a bounded window, each full chunk goes to a worker (a local process pool
by default, or a Dask ``Client``), and each finished chunk is written to the journal in one
transaction. At the end the GeoPackage (``cameras``, ``candidates``, ``view_cones``,
``errors``) and the optional summary map are built from the journal, in row order, so the
output does not depend on where or in which order the work ran.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import math
import multiprocessing
import os
import sys
import threading
import time
from collections import OrderedDict, defaultdict
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Executor, Future, ProcessPoolExecutor
from concurrent.futures import wait as cf_wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from camloc_geo._errors import InputError
from camloc_geo._io import is_lat_lon
from camloc_geo.batch._journal import Journal, journal_path
from camloc_geo.cameras import (
    RETRY_STATUSES,
    CameraResult,
    CameraRow,
    geocode_camera,
    read_camera_list,
)
from camloc_geo.cameras._camera import area_of_row
from camloc_geo.cameras._list import count_camera_rows
from camloc_geo.osm import Area, MapPlan, area_map, map_plan

__all__ = ["BatchSummary", "duplicate_id_warnings", "process_chunk", "run_batch"]

log = logging.getLogger(__name__)

DEFAULT_CHUNK_SIZE = 16
_NAMED_DUPLICATE_IDS = 10  # ids named in the warning line
_MAX_DUPLICATE_IDS = 100_000  # ids whose rows get an ``errors`` row in the GeoPackage
_WINDOW_ROWS = 1024


@dataclass
class BatchSummary:
    """What a batch run did.

    Attributes
    ----------
    total
        Cameras in the list.
    computed
        Cameras computed by this run.
    skipped
        Cameras already done by an earlier run (taken from the journal).
    statuses
        Cameras per status (all rows of the list).
    out_gpkg, summary_map, journal
        Files written.
    stage_s
        Seconds per stage: ``read_list``, ``map_load`` and ``geocode`` (summed over
        workers; ``geocode_cpu`` is the workers' CPU time in it, which a busy machine does
        not inflate), ``journal``, ``gpkg``, ``summary_map``.
    elapsed_s
        Wall time of the run.
    repeats
        Cameras computed by this run whose listing (no scene) a worker had already geocoded:
        its answer was reused.
    warnings
        What the run noticed about the list without refusing it, one line each (a camera id
        used on more than one row). Also in the GeoPackage's ``errors`` layer (stage
        ``list``) and, from ``camloc batch``, on stderr.
    """

    total: int
    computed: int
    skipped: int
    statuses: dict[str, int]
    out_gpkg: Path
    journal: Path
    summary_map: Path | None = None
    stage_s: dict[str, float] = field(default_factory=dict)
    elapsed_s: float = 0.0
    repeats: int = 0
    warnings: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-able summary."""
        return {
            "total": self.total,
            "computed": self.computed,
            "skipped": self.skipped,
            "statuses": dict(sorted(self.statuses.items())),
            "out_gpkg": str(self.out_gpkg),
            "journal": str(self.journal),
            "summary_map": str(self.summary_map) if self.summary_map else None,
            "stage_s": {k: round(v, 3) for k, v in self.stage_s.items()},
            "elapsed_s": round(self.elapsed_s, 3),
            "repeats": self.repeats,
            "warnings": list(self.warnings),
        }


def process_chunk(
    plan: MapPlan, area: Area, rows: list[CameraRow]
) -> tuple[list[dict[str, Any]], dict[str, float]]:
    """Geocode cameras of one area (a worker's task); returns records and stage seconds.

    Never raises for a camera: each gets a record with its status.
    """
    t0 = time.perf_counter()
    if area[0] in ("file", "cell", "net"):
        try:
            area_map(area)  # load (or find) the area's map once, timed apart
        except Exception as exc:  # every camera reports it below
            log.debug("map of %s failed: %s", area, exc)
    elif area[0] == "search":
        for f in area[1]:
            try:
                area_map(("file", f))
            except Exception as exc:
                log.debug("map of %s failed: %s", f, exc)
    t1 = time.perf_counter()
    c1 = time.process_time()
    out = []
    hits = 0
    for r in rows:
        key = _memo_key(plan, area, r)
        rec = _MEMO.get(key) if key is not None else None
        if key is not None and rec is not None:
            _MEMO.move_to_end(key)
            out.append({**rec, "row": r.row, "id": r.id})
            hits += 1
            continue
        rec = geocode_camera(r, plan=plan, area=area).to_dict()
        out.append(rec)
        if key is not None and _memoizable(rec):
            _MEMO[key] = rec
            if len(_MEMO) > _MEMO_SIZE:
                _MEMO.popitem(last=False)
    t2 = time.perf_counter()
    times = {"map_load": t1 - t0, "geocode": t2 - t1, "geocode_cpu": time.process_time() - c1}
    return out, {**times, "repeats": float(hits)}


# A camera without a scene is a pure function of its listing (title, street pair, point,
# radius, view, area, the row's problems) and its area's map: a list that repeats a listing
# (the same junction's cameras, a city's list re-checked) is geocoded once per worker.
_MEMO: OrderedDict[tuple[Any, ...], dict[str, Any]] = OrderedDict()
_MEMO_SIZE = 8192


def _memo_key(plan: MapPlan, area: Area, row: CameraRow) -> tuple[Any, ...] | None:
    """The key of a camera's answer in the memo; None for a camera that is not memoized."""
    if row.has_scene:
        return None  # a scene file may change under the same path; a scene's cost is locate
    return (
        plan,
        area,
        row.title,
        row.streets,
        row.lat,
        row.lon,
        row.radius_m,
        row.view,
        row.area,
        row.problems,
    )


def row_fingerprint(row: CameraRow) -> str:
    """What the list says of a camera, as a short digest: its fields, and for a scene file
    its size and modification time (a scene annotated again under the same name)."""
    parts: list[Any] = [
        row.id,
        row.title,
        row.lat,
        row.lon,
        row.radius_m,
        row.streets,
        row.scene,
        row.view,
        row.area,
        row.problems,
        row.scene_data,
    ]
    if row.scene:
        try:
            st = os.stat(row.scene)
            parts.append([st.st_size, st.st_mtime_ns])
        except OSError:
            parts.append(None)
    text = json.dumps(parts, sort_keys=True, default=str)
    return hashlib.blake2b(text.encode("utf-8"), digest_size=12).hexdigest()


def _memoizable(rec: dict[str, Any]) -> bool:
    """False for answers a rerun computes again (a map that failed may load next time)."""
    if rec.get("status") in RETRY_STATUSES:
        return False
    return not any(e.get("stage") in ("map", "internal") for e in rec.get("errors") or ())


class _InlineExecutor(Executor):
    """Runs each task when submitted (``workers=1``)."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future[Any]:
        fut: Future[Any] = Future()
        try:
            fut.set_result(fn(*args, **kwargs))
        except BaseException as exc:
            if isinstance(exc, KeyboardInterrupt):
                raise
            fut.set_exception(exc)
        return fut


def _local_executor(workers: int) -> Executor:
    if workers <= 1:
        return _InlineExecutor()
    methods = multiprocessing.get_all_start_methods()
    # fork is cheap and shares what the parent imported; only safe without threads
    method = os.environ.get("CAMLOC_BATCH_START_METHOD", "")
    if method not in methods:
        method = "fork" if "fork" in methods and threading.active_count() == 1 else "spawn"
        if method != "fork" and "forkserver" in methods:
            method = "forkserver"
    return ProcessPoolExecutor(
        max_workers=workers,
        mp_context=multiprocessing.get_context(method),
        initializer=_worker_signals,
    )


def _worker_signals() -> None:
    """A worker ends on SIGTERM (a forked worker inherited the CLI's handler, which turns
    SIGTERM into an exception that the pool's task loop catches: the worker lived on), and
    when the process that started it is gone (``kill -9`` of ``camloc batch``, the OOM
    killer): the pool's queue never closes then, and its workers waited on it for ever,
    each holding its maps and the journal's file handles."""
    import signal

    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    # the batch process's sentinel: readable once it is gone, whatever the start method (a
    # forkserver's worker is the forkserver's child, and the forkserver lives as long as its
    # workers do, so the worker's own parent never changes)
    parent = multiprocessing.parent_process()
    if parent is None:
        return

    def watch() -> None:
        from multiprocessing.connection import wait

        wait([parent.sentinel])
        os._exit(1)

    threading.Thread(target=watch, name="camloc-parent-watch", daemon=True).start()


class _DaskRunner:
    def __init__(self, scheduler: Any) -> None:
        from distributed import Client

        if isinstance(scheduler, str):
            try:
                self.client = Client(scheduler, set_as_default=False)
            except ValueError as exc:  # an address Dask cannot parse: the user's input
                raise InputError(
                    f"--scheduler {scheduler!r} is not a Dask scheduler address "
                    f"(tcp://HOST:PORT): {exc}"
                ) from None
            except OSError as exc:  # nothing answers there (Dask's "Timed out trying to
                # connect to tcp://...:9999 after 30 s" was all the user read)
                raise OSError(
                    f"no Dask scheduler answered at {scheduler} ({exc}): start one there "
                    "(dask scheduler), check the address and port, or leave --scheduler out "
                    "to run on local processes"
                ) from None
            self.own = True
        else:
            self.client = scheduler
            self.own = False
        self.pending: set[Any] = set()
        self._lock = threading.Lock()  # done callbacks come from the client's thread

    def submit(self, fn: Callable[..., Any], *args: Any) -> Any:
        fut = self.client.submit(fn, *args, pure=False)
        with self._lock:
            self.pending.add(fut)
        fut.add_done_callback(self._forget)
        return fut

    def _forget(self, fut: Any) -> None:
        with self._lock:
            self.pending.discard(fut)

    def wait_one(self, futures: set[Any]) -> set[Any]:
        from distributed import wait

        # distributed.wait asks for the default client, and the client camloc batch makes
        # for --scheduler is not the default (set_as_default=False): 'ValueError: No
        # clients found' on the first wait; as_current makes it the one asked for
        with self.client.as_current():
            done, _ = wait(list(futures), return_when="FIRST_COMPLETED")
        return set(done)

    def close(self, cancel: bool = False) -> None:
        with self._lock:
            pending = list(self.pending)
            self.pending.clear()
        if cancel and pending:
            # an interruption: the chunks still queued or running on the cluster are
            # cancelled (they went on computing for nobody, on a cluster shared with others)
            self.client.cancel(pending)
        if self.own:
            self.client.close()


class _LocalRunner:
    def __init__(self, workers: int) -> None:
        self.ex = _local_executor(workers)

    def submit(self, fn: Callable[..., Any], *args: Any) -> Any:
        return self.ex.submit(fn, *args)

    def wait_one(self, futures: set[Any]) -> set[Any]:
        done, _ = cf_wait(futures, return_when=FIRST_COMPLETED)
        return set(done)

    def close(self, cancel: bool = False) -> None:
        if cancel:
            # an interruption (Ctrl-C, SIGTERM): the workers' running chunks are not waited
            # for (a chunk searching every extract takes tens of seconds; the interpreter's
            # exit joined them, and a SIGTERM left them orphaned); what is not in the
            # journal is computed again by the rerun
            self._stop_workers()
        self.ex.shutdown(wait=not cancel, cancel_futures=cancel)

    def _stop_workers(self) -> None:
        stop = getattr(self.ex, "terminate_workers", None)  # Python >= 3.14
        if stop is not None:
            stop()
            return
        processes = getattr(self.ex, "_processes", None) or {}
        for proc in list(processes.values()):
            if proc.is_alive():
                proc.terminate()


class _Counted:
    """An iterable of rows that counts what it hands out."""

    def __init__(self, rows: Iterable[CameraRow]) -> None:
        self.rows = rows
        self.n = 0
        self.last = 0  # the last row number handed out

    def __iter__(self) -> Iterator[CameraRow]:
        for row in self.rows:
            self.n += 1
            self.last = max(self.last, row.row)
            yield row


def _count_rows(path: Path) -> int:
    """Rows of a list for the progress bar: CSV records counted by the csv module alone."""
    import csv

    if path.suffix.lower() not in (".csv", ".tsv", ".txt"):
        return count_camera_rows(path)
    csv.field_size_limit(max(csv.field_size_limit(), 1 << 20))
    with open(path, encoding="utf-8-sig", newline="") as fh:
        sample = fh.read(8192)
        fh.seek(0)
        delimiter = "\t" if path.suffix.lower() == ".tsv" else ","
        if delimiter == ",":
            try:
                delimiter = csv.Sniffer().sniff(sample, delimiters=",;\t|").delimiter
            except csv.Error:
                delimiter = ","
        reader = csv.reader(fh, delimiter=delimiter)
        if next(reader, None) is None:
            return 0
        return sum(1 for rec in reader if rec)


class _RowBits:
    """A set of non-negative row numbers as a bit array (one bit per row up to the largest)."""

    def __init__(self) -> None:
        self._bits = bytearray()

    def add(self, row: int) -> None:
        byte = row >> 3
        if byte >= len(self._bits):
            self._bits.extend(bytes(max(byte + 1 - len(self._bits), len(self._bits))))
        self._bits[byte] |= 1 << (row & 7)

    def __contains__(self, row: object) -> bool:
        if not isinstance(row, int) or row < 0:
            return False
        byte = row >> 3
        return byte < len(self._bits) and bool(self._bits[byte] >> (row & 7) & 1)


def _chunks(
    rows: Iterable[CameraRow], plan: MapPlan, chunk_size: int
) -> Iterator[tuple[Area, list[CameraRow]]]:
    """Rows grouped by area into chunks, within a bounded window of the list."""
    pending: dict[Area, list[CameraRow]] = defaultdict(list)
    held = 0
    # a row without a point is searched in the extracts its area names: the same area for
    # every such row of an area name (area_of stats each extract's size per call)
    search_areas: dict[str | None, Area] = {}
    for row in rows:
        if row.has_point:
            area = plan.area_of(row)
        elif row.has_scene:  # at its scene's point (one scene read per such row)
            area = area_of_row(plan, row)
        else:
            area = search_areas.get(row.area) or search_areas.setdefault(
                row.area, plan.area_of(row)
            )
        group = pending[area]
        group.append(row)
        held += 1
        if len(group) >= chunk_size:
            yield area, group
            held -= len(group)
            pending[area] = []
        if held >= _WINDOW_ROWS:
            for a, g in pending.items():
                if g:
                    yield a, g
            pending.clear()
            held = 0
    for a, g in pending.items():
        if g:
            yield a, g


def _looks_like_json(path: Path) -> bool:
    """Whether the file's first character past blanks and a byte-order mark is ``{``."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096)
    except OSError:
        return False
    return head.lstrip(b"\xef\xbb\xbf").lstrip()[:1] == b"{"


def _check_has_cameras(list_p: Path) -> None:
    """Refuse a list without a single camera (as ``POST /v1/jobs`` does): an empty file, a
    header alone, or a file that is no list (a photo, a text) used to end in an empty
    GeoPackage and exit 0, as if every camera had been done."""
    rows = read_camera_list(list_p)
    try:
        first = next(rows, None)
    finally:
        close = getattr(rows, "close", None)  # a generator: let it close its file now
        if close is not None:
            close()
    if first is None:
        size = list_p.stat().st_size
        what = "an empty file" if size == 0 else "no row under its header"
        if size and _looks_like_json(list_p):  # a GeoJSON list has no header (session 41 QA)
            what = "no feature in its FeatureCollection"
        raise InputError(
            f"the camera list {list_p.name} holds no camera ({what}); a list is CSV with a "
            "header (id,title and optional lat,lon,radius_m,streets,scene) or GeoJSON"
        )
    if any(p.startswith("the list has no title column") for p in first.problems):
        _check_has_evidence_columns(list_p)


#: How many rows of a CSV without a title column are looked at for a street pair or a scene.
_EVIDENCE_ROWS = 1000


def _check_has_evidence_columns(list_p: Path) -> None:
    """Refuse a CSV none of whose columns can place a camera (no title, street pair or scene
    column): a file of titles without a header row (its first title read as the header),
    another table. Every camera of it was ``no_evidence``, exit 0."""
    import itertools

    rows = read_camera_list(list_p)
    try:
        for row in itertools.islice(rows, _EVIDENCE_ROWS):
            if row.title or row.streets or row.scene or row.scene_data is not None:
                return
    finally:
        close = getattr(rows, "close", None)
        if close is not None:
            close()
    with open(list_p, "rb") as fh:
        header = fh.readline(400).decode("utf-8", "replace").strip()
    raise InputError(
        f"the camera list {list_p.name} has no column a camera can be placed by (title, "
        f"name, streets, street1+street2, scene, ...): its header row is {header[:80]!r}; "
        "a list is CSV with a header row (id,title and optional lat,lon,radius_m,streets,"
        "scene) or GeoJSON"
    )


def run_batch(
    list_path: str | os.PathLike[str],
    *,
    out_gpkg: str | os.PathLike[str],
    map_source: str | os.PathLike[str] | None = None,
    network: bool = False,
    scheduler: Any = None,
    summary_map: str | os.PathLike[str] | None = None,
    progress: bool = True,
    workers: int | None = None,
    area: str | None = None,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    restart: bool = False,
    offline_map: bool = True,
    on_chunk: Callable[[int], None] | None = None,
    verdict_service: str | None = None,
) -> BatchSummary:
    """Geocode every camera of a list into a GeoPackage (resumable).

    Parameters
    ----------
    list_path
        CSV or GeoJSON camera list (columns in ``docs/batch.md``).
    out_gpkg
        The GeoPackage to write (replaced at the end of each run); the journal
        ``OUT.camloc-batch.sqlite`` next to it records finished cameras.
    map_source
        An OSM extract or a folder of extracts (each camera uses the one covering it).
    network
        Without ``map_source``: fetch each area's map from Overpass.
    scheduler
        None: this machine, ``workers`` processes. A ``tcp://HOST:PORT`` address or a
        ``dask.distributed.Client``: the same chunks run on that Dask cluster (its workers
        must see the extracts at the same paths).
    summary_map
        Also write this HTML summary map (clustered markers; self-contained unless
        ``offline_map`` is False).
    progress
        Show a progress bar (tqdm, on stderr) with rate and time left.
    workers
        Local processes (default: the machine's cores); 1 runs in this process.
    area
        Only search titles without a point in extracts whose file name contains this.
    chunk_size
        Cameras per task and per journal transaction.
    restart
        Forget the journal and compute every camera again.
    on_chunk
        Called with the number of cameras done after each journal write.
    verdict_service
        With ``summary_map``: the verdicts endpoint (``.../v1/verdicts``, see
        :func:`camloc_geo.cli.locate.verdict_url`) the page shares its verdicts with, from a
        file too (docs/service.md, "Verdicts").

    Raises
    ------
    InputError
        Unreadable list, missing extract, a journal from a different run or list.
    """
    t_start = time.perf_counter()
    list_p = Path(list_path).expanduser()
    out = Path(out_gpkg).expanduser()
    if list_p.is_dir():
        raise InputError(f"camera list {list_p} is a folder; give the list's file (CSV or GeoJSON)")
    if list_p.exists() and not list_p.is_file():
        raise InputError(f"camera list {list_p} is not a regular file (a device or a pipe)")
    if not list_p.is_file():
        raise InputError(f"camera list not found: {list_p}")
    if chunk_size < 1:
        raise InputError("chunk_size must be at least 1")
    _check_has_cameras(list_p)
    if map_source is not None and Path(map_source).expanduser().is_file():
        # one extract named: one that cannot be a map (another suffix, empty) is the user's
        # mistake, refused before any work; it used to end every camera as map_error/no_map
        from camloc_geo.osm._load import _check_extract_path

        _check_extract_path(Path(map_source).expanduser())
    plan = map_plan(map_source, network=network, area=area)
    stage: dict[str, float] = defaultdict(float)
    counts: dict[str, int] = defaultdict(int)
    lock = OutputLock(out)  # one run per output: a second one is refused at once
    try:
        journal = Journal(journal_path(out))
    except BaseException:
        lock.release()
        raise
    try:
        journal.check_options(
            {
                "list": str(list_p.resolve()),
                "map_source": str(Path(map_source).resolve()) if map_source else None,
                "network": bool(network),
                "area": area,
            },
            restart,
        )
        t = time.perf_counter()
        total = 0
        skipped = 0
        # the list and the journal are both in row order: walk them side by side, keeping
        # one bit per row done (125 kB per million rows), never a row-to-id dict
        done = _RowBits()
        recorded = journal.iter_done_fingerprints(retry=RETRY_STATUSES)
        nxt = next(recorded, None)
        changed: list[tuple[int, str]] = []  # the first few rows the list changed
        n_changed = 0
        # nothing to resume: no first pass over the list (the rows are counted as they are
        # computed; the progress bar alone needs the count up front, and counts lines)
        first_pass = nxt is not None
        if not first_pass and progress:
            total = _count_rows(list_p)
        last_row = 0  # the list's last row: the journal's rows past it left the list
        for row in read_camera_list(list_p) if first_pass else ():
            total += 1
            last_row = max(last_row, row.row)
            while nxt is not None and nxt[0] < row.row:
                nxt = next(recorded, None)
            if nxt is not None and nxt[0] == row.row:
                if nxt[1] != row.id:
                    raise InputError(
                        f"row {row.row} of {list_p.name} is camera {row.id!r} but the journal "
                        f"recorded {nxt[1]!r}: the list changed; use --restart"
                    )
                if nxt[2] is not None and nxt[2] != row_fingerprint(row):
                    # the same camera, another listing (a title corrected, a scene file
                    # edited): computed again, never its old answer under the new title
                    n_changed += 1
                    if len(changed) < _NAMED_DUPLICATE_IDS:
                        changed.append((row.row, row.id))
                    continue
                done.add(row.row)
                skipped += 1
        del recorded
        stage["read_list"] += time.perf_counter() - t
        todo = (r for r in read_camera_list(list_p) if r.row not in done)
        counted = _Counted(todo)
        computed = _run_chunks(
            counted,
            plan,
            journal,
            stage,
            counts=counts,
            scheduler=scheduler,
            workers=workers or os.cpu_count() or 1,
            chunk_size=chunk_size,
            progress=progress,
            total=total,
            initial=skipped,
            on_chunk=on_chunk,
        )
        if not first_pass:
            total = counted.n
        # rows cut from the end of the list: their cameras stayed in the GeoPackage, and the
        # summary said "2 cameras ... 3 title_only" (session 39)
        n_gone, gone = journal.drop_after(max(last_row, counted.last))
        dups = journal.duplicate_ids(limit=_MAX_DUPLICATE_IDS)
        warnings = _duplicate_warnings(dups, journal.n_duplicate_ids(), list_p.name)
        if n_gone:
            named = ", ".join(f"row {r} ({i!r})" for r, i in gone)
            more = f" and {n_gone - len(gone)} more" if n_gone > len(gone) else ""
            warnings.append(
                f"{list_p.name}: {n_gone} camera(s) {journal.path.name} recorded are no longer "
                f"in the list, left out of the output: {named}{more}"
            )
        if n_changed:
            named = ", ".join(f"row {r} ({i!r})" for r, i in changed)
            more = f" and {n_changed - len(changed)} more" if n_changed > len(changed) else ""
            warnings.append(
                f"{list_p.name}: {n_changed} row(s) changed since {journal.path.name} recorded "
                f"them, computed again: {named}{more}"
            )
        t = time.perf_counter()
        _write_gpkg(journal, out, duplicates=dups)
        stage["gpkg"] += time.perf_counter() - t
        map_path = None
        if summary_map is not None:
            t = time.perf_counter()
            map_path = _write_summary_map(
                journal,
                Path(summary_map),
                offline=offline_map,
                verdict_service=verdict_service,
                map_source=plan,
            )
            stage["summary_map"] += time.perf_counter() - t
        statuses = journal.status_counts()
        if map_source is None and not network and statuses.get("no_map"):
            # a list run without any map: every camera no_map, exit 0, the one reason given
            # per camera only (session 41 QA, camloc batch and QGIS's geocodelist)
            warnings.append(
                f"{statuses['no_map']} camera(s) no_map: this run had no map (no extract, "
                "the network off): give --osm EXTRACT_OR_FOLDER or allow --network"
            )
    finally:
        journal.close()
        lock.release()
    return BatchSummary(
        total=total,
        computed=computed,
        skipped=skipped,
        statuses=statuses,
        out_gpkg=out,
        journal=journal.path,
        summary_map=map_path,
        stage_s=dict(stage),
        elapsed_s=time.perf_counter() - t_start,
        repeats=counts["repeats"],
        warnings=warnings,
    )


def duplicate_id_warnings(ids: Iterable[Any]) -> list[str]:
    """The warning naming camera ids used on more than one row of a list held in memory (a
    service job's), as ``camloc batch`` words it; ``ids`` in row order (rows from 1; None: a
    row without an id, never a duplicate)."""
    rows: dict[str, list[int]] = {}
    for n, cid in enumerate(ids, start=1):
        if cid is not None:
            rows.setdefault(str(cid), []).append(n)
    dups = {k: v for k, v in rows.items() if len(v) > 1}
    return _duplicate_warnings(dups, len(dups), "the list")


def _duplicate_warnings(dups: dict[str, list[int]], n_dups: int, list_name: str) -> list[str]:
    """The one line naming the camera ids used on more than one row (none: no line)."""
    if not dups:
        return []
    shown = list(dups.items())[:_NAMED_DUPLICATE_IDS]
    named = "; ".join(f"{cid!r} on rows {', '.join(str(r) for r in rows)}" for cid, rows in shown)
    more = f" (and {n_dups - len(shown)} more)" if n_dups > len(shown) else ""
    return [
        f"{list_name}: {n_dups} camera id(s) used on more than one row: {named}{more}; each "
        "row is geocoded and kept (rows tell them apart), but anything joining on id will "
        "mix them up: give each camera its own id"
    ]


def _run_chunks(
    todo: Iterable[CameraRow],
    plan: MapPlan,
    journal: Journal,
    stage: dict[str, float],
    *,
    counts: dict[str, int],
    scheduler: Any,
    workers: int,
    chunk_size: int,
    progress: bool,
    total: int,
    initial: int,
    on_chunk: Callable[[int], None] | None,
) -> int:
    runner: _LocalRunner | _DaskRunner
    if scheduler is not None:
        runner = _DaskRunner(scheduler)
        n_slots = max(2, len(runner.client.nthreads()) if hasattr(runner.client, "nthreads") else 2)
    else:
        runner = _LocalRunner(workers)
        n_slots = workers
    max_inflight = 2 * n_slots + 1
    from tqdm import tqdm

    bar = tqdm(
        total=total,
        initial=initial,
        unit="cam",
        desc="camloc batch",
        file=sys.stderr,
        disable=not progress,
        dynamic_ncols=True,
        smoothing=0.1,
    )
    computed = 0
    done_count = initial
    inflight: set[Any] = set()
    fingerprints: dict[Any, dict[int, str]] = {}

    def collect(futs: set[Any]) -> None:
        nonlocal computed, done_count
        for fut in futs:
            records, times = fut.result()
            for k, v in times.items():
                if k == "repeats":
                    counts["repeats"] += int(v)
                else:
                    stage[k] += v
            t = time.perf_counter()
            n = journal.write(records, fingerprints.pop(fut, None))
            stage["journal"] += time.perf_counter() - t
            computed += n
            done_count += n
            bar.update(n)
            if on_chunk is not None:
                on_chunk(done_count)

    cancel = False
    try:
        t_read = time.perf_counter()
        for area, rows in _chunks(todo, plan, chunk_size):
            stage["read_list"] += time.perf_counter() - t_read
            fut = runner.submit(process_chunk, plan, area, rows)
            fingerprints[fut] = {r.row: row_fingerprint(r) for r in rows}
            inflight.add(fut)
            while len(inflight) >= max_inflight:
                finished = runner.wait_one(inflight)
                inflight -= finished
                collect(finished)
            t_read = time.perf_counter()
        while inflight:
            finished = runner.wait_one(inflight)
            inflight -= finished
            collect(finished)
    except BaseException:
        cancel = True
        raise
    finally:
        bar.close()
        runner.close(cancel=cancel)
    return computed


# ------------------------------------------------------------------------ GeoPackage
_CAMERA_COLUMNS: dict[str, str] = {
    "row": "int64",
    "id": "object",
    "title": "object",
    "status": "object",
    "reason": "object",
    "lat": "float64",
    "lon": "float64",
    "score": "float64",
    "uncertainty_m": "float64",
    "tie": "bool",
    "method": "object",
    "n_candidates": "int64",
    "match_status": "object",
    "match_score": "float64",
    "names_read": "object",
    "names_matched": "object",
    "match_kinds": "object",
    "view_text": "object",
    "view_bearing_deg": "float64",
    "heading_deg": "float64",
    "height_m": "float64",
    "extract": "object",
    "list_lat": "float64",
    "list_lon": "float64",
    "n_errors": "int64",
}
_CANDIDATE_COLUMNS: dict[str, str] = {
    "row": "int64",
    "id": "object",
    "rank": "int64",
    "source": "object",
    "status": "object",
    "score": "float64",
    "match_score": "float64",
    "lat": "float64",
    "lon": "float64",
    "uncertainty_m": "float64",
    "heading_deg": "float64",
    "height_m": "float64",
    "residual_m": "float64",
    "method": "object",
    "detail": "object",
    "intersection": "object",
    "extract": "object",
    "ambiguous_with": "object",
}
_CONE_COLUMNS = {
    "row": "int64",
    "id": "object",
    "rank": "int64",
    "source": "object",
    "score": "float64",
    "ambiguous_with": "object",
}
_ERROR_COLUMNS = {
    "row": "int64",
    "id": "object",
    "status": "object",
    "stage": "object",
    "message": "object",
}


def _frame(rows: list[dict[str, Any]], columns: dict[str, str], geoms: list[Any] | None) -> Any:
    import geopandas as gpd
    import pandas as pd

    df = pd.DataFrame({c: [r.get(c) for r in rows] for c in columns})
    for c, dtype in columns.items():
        if dtype == "float64":
            df[c] = pd.to_numeric(df[c], errors="coerce").astype("float64")
        elif dtype in ("int64", "bool"):
            df[c] = df[c].fillna(0).astype(dtype)
        else:
            df[c] = df[c].astype(object).where(df[c].notna(), None)
    if geoms is None:
        return df
    return gpd.GeoDataFrame(df, geometry=gpd.GeoSeries(geoms, crs="EPSG:4326"), crs="EPSG:4326")


def _best_ties(r: dict[str, Any]) -> list[int]:
    """The ranks the camera's best candidate ties with (journals of older runs: rank 2)."""
    cands = r.get("candidates") or []
    if cands and "ambiguous_with" in cands[0]:
        return [int(o) for o in cands[0].get("ambiguous_with") or []]
    return [2] if r.get("tie") and r.get("status") == "located" else []


def _first_place(r: dict[str, Any]) -> tuple[float, float] | None:
    """``(lat, lon)`` of an ambiguous camera's first candidate (None: not ambiguous, placed
    already, or no candidate with a point)."""
    if r.get("status") != "ambiguous" or r.get("lat") is not None:
        return None
    for c in r.get("candidates") or []:
        lat, lon = c.get("lat"), c.get("lon")
        numbers = isinstance(lat, (int, float)) and isinstance(lon, (int, float))
        if numbers and math.isfinite(lat) and math.isfinite(lon):
            return float(lat), float(lon)
    return None


def _best_residual_m(r: dict[str, Any]) -> float | None:
    """The camera's best located candidate's ``residual_m`` (None: a title's place, or a
    journal of a run before stop 41, whose candidates did not keep it)."""
    cands = r.get("candidates") or []
    if not cands or cands[0].get("source") != "locate":
        return None
    value = cands[0].get("residual_m")
    return float(value) if isinstance(value, (int, float)) and math.isfinite(value) else None


def _ranks_text(ranks: list[Any]) -> str | None:
    """A candidate's tie ranks as GeoPackage text (``"2,4"``), None without a tie."""
    return ",".join(str(int(o)) for o in ranks) or None


def _points(lonlat: list[tuple[Any, Any]]) -> Any:
    """Point geometries of ``(lon, lat)`` pairs in one vectorised call; None where missing."""
    import numpy as np
    import shapely

    if not lonlat:
        return np.empty(0, dtype=object)
    xy = np.array([(np.nan, np.nan) if x is None or y is None else (x, y) for x, y in lonlat])
    geoms = shapely.points(xy)
    geoms[np.isnan(xy).any(axis=1)] = None
    return geoms


def _duplicate_error(r: dict[str, Any], duplicates: dict[str, list[int]]) -> dict[str, Any] | None:
    """The ``errors`` row of a camera whose id another row of the list uses too."""
    rows = duplicates.get(str(r.get("id")))
    if not rows or len(rows) < 2:
        return None
    others = ", ".join(str(o) for o in rows if o != r.get("row"))
    return {
        "stage": "list",
        "message": f"camera id {r.get('id')!r} is also used by row(s) {others} of the list",
    }


def _layers_of(
    records: list[dict[str, Any]], duplicates: dict[str, list[int]] | None = None
) -> dict[str, Any]:
    from shapely.geometry import Polygon

    cams, cands, cones, cone_g, errs = [], [], [], [], []
    cam_xy: list[tuple[Any, Any]] = []
    cand_xy: list[tuple[Any, Any]] = []
    for r in records:
        cam = {k: r.get(k) for k in _CAMERA_COLUMNS}
        for k in ("names_read", "names_matched", "match_kinds"):
            cam[k] = " | ".join(r.get(k) or []) or None
        errors = list(r.get("errors") or [])
        dup = _duplicate_error(r, duplicates or {})
        if dup is not None:
            errors.append(dup)
        cam["n_errors"] = len(errors)
        cams.append(cam)
        cam_xy.append((r.get("lon"), r.get("lat")))
        for c in r.get("candidates") or []:
            if not is_lat_lon(c.get("lat"), c.get("lon")):
                # a title that names no place in the map (not_found): the camera's row says
                # so; a point layer's row without a point read as a candidate (QGIS and the
                # service give none)
                continue
            ties = c.get("ambiguous_with") or []
            cands.append({**c, "row": r["row"], "id": r["id"], "ambiguous_with": _ranks_text(ties)})
            cand_xy.append((c.get("lon"), c.get("lat")))
        # a cone's ties are its candidate's (the core's rule), for the one cone style's red
        # outline and "leading" rule (``layers.style_view_cones``)
        ties_of = {
            (c.get("source"), c.get("rank")): c.get("ambiguous_with") or []
            for c in r.get("candidates") or []
        }
        for c in r.get("cones") or []:
            tie_text = _ranks_text(ties_of.get((c.get("source"), c.get("rank")), []))
            cones.append({**c, "row": r["row"], "id": r["id"], "ambiguous_with": tie_text})
            cone_g.append(Polygon(c["lonlat"]))
        for e in errors:
            errs.append({**e, "row": r["row"], "id": r["id"], "status": r["status"]})
    cam_g, cand_g = _points(cam_xy), _points(cand_xy)
    return {
        "cameras": _frame(cams, _CAMERA_COLUMNS, cam_g),
        "candidates": _frame(cands, _CANDIDATE_COLUMNS, cand_g),
        "view_cones": _frame(cones, _CONE_COLUMNS, cone_g),
        "errors": _frame(errs, _ERROR_COLUMNS, None),
    }


_GEOM_TYPES = {"cameras": "Point", "candidates": "Point", "view_cones": "Polygon"}

GPKG_VERSION = "1.2"
"""The GeoPackage version written. pyogrio's GDAL (3.7+) writes 1.4 by default, which the GDAL
3.6 of QGIS 3.22 on Debian bookworm (and its ``ogrinfo``) reads with a warning on every open
("user_version ... v1.4.0 may only be partially supported"); 1.2 is what that QGIS writes."""


class OutputLock:
    """An exclusive hold on a batch output while a run writes it (``OUT.camloc-batch.lock``).

    Two ``camloc batch`` runs with one ``-o`` computed every camera twice, and the first to
    finish lost its GeoPackage to the other's temporary file ("failed: FileNotFoundError:
    'cams.part.gpkg' -> 'cams.gpkg'", exit 1). The second is now refused at once. The lock is
    the operating system's (``flock``; ``msvcrt.locking`` on Windows), so a run killed with
    ``kill -9`` holds nothing; the file is removed when the run ends.

    Parameters
    ----------
    out
        The output GeoPackage.

    Raises
    ------
    InputError
        Another run holds the output.
    """

    def __init__(self, out: Path) -> None:
        self.path = out.with_name(out.stem + ".camloc-batch.lock")
        out.parent.mkdir(parents=True, exist_ok=True)
        self._fd: int | None = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            _lock_fd(self._fd)
        except OSError:
            os.close(self._fd)
            self._fd = None
            raise InputError(
                f"another camloc batch is writing {out} (it holds {self.path.name}): wait for "
                "it to end, or give another -o"
            ) from None

    def release(self) -> None:
        """Remove the lock file and let go (again: nothing)."""
        if self._fd is None:
            return
        with contextlib.suppress(OSError):
            self.path.unlink()
        os.close(self._fd)  # closing the descriptor releases the lock
        self._fd = None


def _lock_fd(fd: int) -> None:
    """Lock ``fd`` for this process without waiting; ``OSError`` when another holds it."""
    if sys.platform == "win32":
        import msvcrt

        msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
    else:
        import fcntl

        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)


def _write_gpkg(
    journal: Journal,
    out: Path,
    page: int = 5000,
    duplicates: dict[str, list[int]] | None = None,
) -> None:
    """Build the GeoPackage from the journal, a page of cameras at a time, then swap it in.

    ``duplicates`` (``{id: rows}``, :meth:`Journal.duplicate_ids`) adds a ``list`` stage row
    to the ``errors`` layer for each camera whose id another row uses too.
    """
    import pyogrio

    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(out.stem + ".part" + (out.suffix or ".gpkg"))
    if tmp.exists():
        tmp.unlink()
    started: set[str] = set()
    buf: list[dict[str, Any]] = []

    def flush(final: bool) -> None:
        layers = _layers_of(buf, duplicates)
        for name, df in layers.items():
            if len(df) == 0 and (name in started or not final):
                continue
            kwargs: dict[str, Any] = {"driver": "GPKG", "layer": name}
            if name in _GEOM_TYPES:
                kwargs["geometry_type"] = _GEOM_TYPES[name]
            if not started:
                kwargs["dataset_options"] = {"VERSION": GPKG_VERSION}
            pyogrio.write_dataframe(df, str(tmp), append=name in started, **kwargs)
            started.add(name)
        buf.clear()

    try:
        for rec in journal.records():
            buf.append(rec)
            if len(buf) >= page:
                flush(False)
        flush(False)
        for name in ("cameras", "candidates", "view_cones", "errors"):
            if name not in started:
                buf.clear()
                df = _layers_of([])[name]
                kwargs: dict[str, Any] = {"driver": "GPKG", "layer": name}
                if name in _GEOM_TYPES:
                    kwargs["geometry_type"] = _GEOM_TYPES[name]
                if not started:  # no camera at all: this layer creates the file
                    kwargs["dataset_options"] = {"VERSION": GPKG_VERSION}
                pyogrio.write_dataframe(df, str(tmp), append=name in started, **kwargs)
                started.add(name)
        _write_layer_styles(tmp)
        os.replace(tmp, out)
    except BaseException:
        # Ctrl-C, SIGTERM or a failure while writing: the previous GeoPackage stays, and no
        # half-written OUT.part.gpkg is left behind (it was)
        for left in (tmp, *(tmp.with_name(tmp.name + x) for x in ("-journal", "-wal", "-shm"))):
            left.unlink(missing_ok=True)
        raise


STYLED_LAYERS = ("cameras", "candidates", "view_cones")
"""The layers whose default QGIS style the GeoPackage carries (QGIS's ``layer_styles``:
``camloc_geo/data/qgis_styles/batch_<layer>.qml`` and ``.sld``, made from the plugin's styles
by ``qgis_plugin/make_batch_styles.py``; :func:`camloc_geo.results.write_layer_styles`)."""


def _write_layer_styles(gpkg: Path) -> None:
    """The batch GeoPackage's QGIS styles (it had none: QGIS drew every layer in one random
    colour, ties and ranks alike)."""
    from camloc_geo.results import write_layer_styles

    write_layer_styles(gpkg, {name: f"batch_{name}" for name in STYLED_LAYERS})


# ------------------------------------------------------------------------ summary map
_MAX_MAP_MARKERS = 50_000


def _summary_items(journal: Journal) -> Iterator[tuple[str, dict[str, Any]]]:
    n = 0
    for r in journal.records():
        label = f"{r['id']} {r.get('title') or ''}".strip()
        first = _first_place(r)
        if first is not None:
            # ambiguous: drawn at its first place, tied (dashed ring), as the service's job
            # page draws it; it was listed "without candidates" though it had them (qa7)
            r = {**r, "lat": first[0], "lon": first[1], "tie": True}
        if r.get("lat") is None or r.get("lon") is None:
            yield (
                label,
                {
                    "features": [],
                    "properties": {"reason": f"{r['status']}: {r.get('reason') or ''}"},
                },
            )
            continue
        n += 1
        if n > _MAX_MAP_MARKERS:
            continue
        heading = r.get("heading_deg")
        if heading is None:
            heading = r.get("view_bearing_deg")
        props = {
            "kind": "candidate",
            "rank": 1,
            "lat": r["lat"],
            "lon": r["lon"],
            "score": r.get("score") or 0.0,
            "method": f"{r.get('method')} ({r['status']})",
            "heading_deg": heading,
            "height_m": r.get("height_m"),
            # the best located candidate's misfit (the camera's row has none): "—" before
            "residual_m": _best_residual_m(r),
            "sigma_m": r.get("uncertainty_m"),
            "flags": ([r["status"]] + (["tie"] if r.get("tie") else [])),
            # the best candidate's ties, as the engine decided them (the core's rule)
            "ambiguous_with": _best_ties(r),
        }
        best = {
            "type": "Feature",
            "geometry": {"type": "Point", "coordinates": [r["lon"], r["lat"]]},
            "properties": props,
        }
        yield (
            label,
            {
                "features": [
                    best,
                    *(_other_candidates(r) if props["ambiguous_with"] or r.get("tie") else []),
                ],
                "properties": {"reason": r.get("reason")},
            },
        )


def _other_candidates(r: dict[str, Any]) -> list[dict[str, Any]]:
    """A tied camera's candidates after its best, with a point: the page's "or the camera is
    candidate…" list (the job page had it; this page's popup promised it and had none, qa7)."""
    out = []
    for c in (r.get("candidates") or [])[1:]:
        lat, lon, rank = c.get("lat"), c.get("lon"), c.get("rank")
        numbers = isinstance(lat, (int, float)) and isinstance(lon, (int, float))
        if not (numbers and math.isfinite(lat) and math.isfinite(lon)) or rank is None:
            continue
        out.append(
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [lon, lat]},
                "properties": {
                    "kind": "candidate",
                    "rank": int(rank),
                    "lat": lat,
                    "lon": lon,
                    "score": c.get("score") or 0.0,
                    "method": str(c.get("method") or ""),
                    "heading_deg": c.get("heading_deg"),
                    "height_m": c.get("height_m"),
                    "sigma_m": c.get("uncertainty_m"),
                },
            }
        )
    return out


def _markercluster_assets() -> tuple[str, str]:
    """Kept for callers of the old private copy: :func:`camloc_geo.maps.markercluster_assets`."""
    from camloc_geo.maps import markercluster_assets

    return markercluster_assets()


def _write_summary_map(
    journal: Journal,
    path: Path,
    *,
    offline: bool,
    verdict_service: str | None = None,
    map_source: Any = None,
) -> Path:
    """The summary map: one marker per placed camera, clustered (offline: inlined plug-in).

    The offline page is :func:`camloc_geo.maps.summary_page`'s (the service's job page without
    a basemap): the same bytes this module used to assemble with its own copy of the
    cluster-inlining code. With ``map_source`` (the run's catalogue) its extracts' streets
    and buildings around the cameras are drawn under them (never the network).
    """
    from camloc_geo._io import write_text_atomic
    from camloc_geo.maps import build_summary_map, summary_page

    if offline:
        page = summary_page(
            _summary_items(journal), verdict_service=verdict_service, map_source=map_source
        )
    else:
        fmap = build_summary_map(
            _summary_items(journal),
            offline=False,
            tiles="OpenStreetMap",
            verdict_service=verdict_service,
        )
        page = fmap.get_root().render()
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, page)
    return path


def results_from_journal(out_gpkg: str | os.PathLike[str]) -> list[CameraResult]:
    """Every camera recorded for an output so far (row order)."""
    j = Journal(journal_path(Path(out_gpkg)))
    try:
        return [CameraResult.from_dict(r) for r in j.records()]
    finally:
        j.close()
