"""Jobs and crowd tasks in SQLite (standard library): they survive a restart of the server.

Each camera of a job is claimed, processed and committed on its own, so a killed server
loses at most the cameras it was working on; those are claimed again after a restart.
"""

from __future__ import annotations

import json
import os
import sqlite3
import threading
import time
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

__all__ = ["SqliteFile", "Store", "TaskFullError"]

_SCHEMA = """
CREATE TABLE IF NOT EXISTS jobs (
    id TEXT PRIMARY KEY, created REAL NOT NULL, total INTEGER NOT NULL,
    status TEXT NOT NULL DEFAULT 'queued'
);
CREATE TABLE IF NOT EXISTS job_cameras (
    job_id TEXT NOT NULL, idx INTEGER NOT NULL, camera TEXT NOT NULL,
    state TEXT NOT NULL DEFAULT 'pending', claimed_by TEXT, claimed_at REAL, result TEXT,
    PRIMARY KEY (job_id, idx)
);
CREATE TABLE IF NOT EXISTS tasks (
    id TEXT PRIMARY KEY, created REAL NOT NULL, image_file TEXT NOT NULL, image_type TEXT NOT NULL,
    width INTEGER NOT NULL, height INTEGER NOT NULL, needed INTEGER NOT NULL,
    base_scene TEXT NOT NULL, status TEXT NOT NULL DEFAULT 'collecting', result TEXT
);
CREATE TABLE IF NOT EXISTS annotations (
    task_id TEXT NOT NULL, n INTEGER NOT NULL, created REAL NOT NULL, scene TEXT NOT NULL,
    PRIMARY KEY (task_id, n)
);
"""
_STALE_CLAIM_S = 300.0


class SqliteFile:
    """One SQLite file (WAL mode), a connection per thread, ``BEGIN IMMEDIATE`` transactions.

    Subclasses set ``path`` and ``_local`` (a :class:`threading.local`) before the first
    :meth:`_db` call.
    """

    path: Path
    _local: threading.local

    def _db(self) -> sqlite3.Connection:
        db = getattr(self._local, "db", None)
        if db is None:
            db = sqlite3.connect(self.path, timeout=30.0, isolation_level=None)
            db.execute("PRAGMA journal_mode=WAL")
            db.execute("PRAGMA synchronous=NORMAL")
            db.row_factory = sqlite3.Row
            self._local.db = db
        return db

    @contextmanager
    def _tx(self) -> Iterator[sqlite3.Connection]:
        db = self._db()
        db.execute("BEGIN IMMEDIATE")
        try:
            yield db
            db.execute("COMMIT")
        except BaseException:
            if db.in_transaction:  # (a failed COMMIT too: the connection is reused)
                db.execute("ROLLBACK")
            raise


class TaskFullError(Exception):
    """A crowd task has all the annotations it needs."""


class Store(SqliteFile):
    """The service's SQLite database under ``data_dir`` (one file, WAL mode)."""

    def __init__(self, data_dir: Path) -> None:
        self.data_dir = Path(data_dir)
        self.data_dir.mkdir(parents=True, exist_ok=True)
        (self.data_dir / "snapshots").mkdir(exist_ok=True)
        self.path = self.data_dir / "camloc-service.sqlite"
        self._local = threading.local()
        self.worker_id = f"{os.getpid()}-{uuid.uuid4().hex[:8]}"
        self._db().executescript(_SCHEMA)

    # --- jobs ----------------------------------------------------------------------------
    def create_job(self, cameras: list[dict[str, Any]]) -> str:
        """Store a job's cameras; returns its id."""
        job_id = uuid.uuid4().hex
        with self._tx() as db:
            db.execute(
                "INSERT INTO jobs (id, created, total) VALUES (?, ?, ?)",
                (job_id, time.time(), len(cameras)),
            )
            db.executemany(
                "INSERT INTO job_cameras (job_id, idx, camera) VALUES (?, ?, ?)",
                [(job_id, i, json.dumps(c)) for i, c in enumerate(cameras)],
            )
        return job_id

    def claim_camera(self) -> tuple[str, int, dict[str, Any]] | None:
        """Claim the oldest pending camera of any job (or a stale claim); None when idle."""
        now = time.time()
        with self._tx() as db:
            row = db.execute(
                "SELECT c.job_id, c.idx, c.camera FROM job_cameras c "
                "JOIN jobs j ON j.id = c.job_id "
                "WHERE c.state = 'pending' OR (c.state = 'running' AND c.claimed_at < ?) "
                "ORDER BY j.created, c.idx LIMIT 1",
                (now - _STALE_CLAIM_S,),
            ).fetchone()
            if row is None:
                return None
            db.execute(
                "UPDATE job_cameras SET state = 'running', claimed_by = ?, claimed_at = ? "
                "WHERE job_id = ? AND idx = ?",
                (self.worker_id, now, row["job_id"], row["idx"]),
            )
            db.execute("UPDATE jobs SET status = 'running' WHERE id = ?", (row["job_id"],))
        return str(row["job_id"]), int(row["idx"]), json.loads(row["camera"])

    def release_own_claims(self) -> None:
        """At start-up: cameras claimed by a process that is gone go back to pending."""
        with self._tx() as db:
            db.execute(
                "UPDATE job_cameras SET state = 'pending', claimed_by = NULL "
                "WHERE state = 'running' AND (claimed_by IS NULL OR claimed_by NOT LIKE ?)",
                (f"{os.getpid()}-%",),
            )

    def reopen_full_tasks(self) -> int:
        """At start-up: a crowd task that has its annotations but no result (the server
        died while locating it) takes its last one back, so that the annotator's retry
        locates it; otherwise every submission was refused as full and the task never
        located. Returns how many tasks were reopened."""
        with self._tx() as db:
            full = db.execute(
                "SELECT t.id, t.needed FROM tasks t WHERE t.status = 'collecting' AND "
                "(SELECT COUNT(*) FROM annotations a WHERE a.task_id = t.id) >= t.needed"
            ).fetchall()
            for task_id, needed in full:
                db.execute(
                    "DELETE FROM annotations WHERE task_id = ? AND n >= ?",
                    (task_id, max(int(needed) - 1, 0)),
                )
        return len(full)

    def finish_camera(self, job_id: str, idx: int, result: dict[str, Any]) -> None:
        """Commit one camera's result (exactly once)."""
        with self._tx() as db:
            db.execute(
                "UPDATE job_cameras SET state = 'done', result = ? WHERE job_id = ? AND idx = ?",
                (json.dumps(result), job_id, idx),
            )
            left = db.execute(
                "SELECT COUNT(*) FROM job_cameras WHERE job_id = ? AND state != 'done'", (job_id,)
            ).fetchone()[0]
            if left == 0:
                db.execute("UPDATE jobs SET status = 'done' WHERE id = ?", (job_id,))

    def job(self, job_id: str) -> dict[str, Any] | None:
        """A job's status and progress, or None."""
        db = self._db()
        row = db.execute("SELECT * FROM jobs WHERE id = ?", (job_id,)).fetchone()
        if row is None:
            return None
        counts = dict(
            db.execute(
                "SELECT state, COUNT(*) FROM job_cameras WHERE job_id = ? GROUP BY state", (job_id,)
            ).fetchall()
        )
        failed = db.execute(
            "SELECT COUNT(*) FROM job_cameras WHERE job_id = ? AND state = 'done' "
            "AND json_extract(result, '$.status') NOT IN ('located', 'title_only')",
            (job_id,),
        ).fetchone()[0]
        return {
            "id": job_id,
            "status": row["status"],
            "created": row["created"],
            "total": row["total"],
            "done": counts.get("done", 0),
            "running": counts.get("running", 0),
            "pending": counts.get("pending", 0),
            "not_located": failed,
        }

    def job_results(self, job_id: str) -> list[dict[str, Any]]:
        """The finished cameras' results, in list order."""
        rows = self._db().execute(
            "SELECT idx, result FROM job_cameras WHERE job_id = ? AND state = 'done' ORDER BY idx",
            (job_id,),
        )
        from camloc_geo.cameras import normalize_status

        out = []
        for rec in rows:
            r = json.loads(rec["result"])
            if isinstance(r, dict):
                # the camera's row of the list (from 1): it tells apart cameras sharing an id
                r.setdefault("row", int(rec["idx"]) + 1)
                if isinstance(r.get("status"), str):  # stored by an older server: its words
                    r["status"] = normalize_status(r["status"])
            out.append(r)
        return out

    # --- crowd tasks ---------------------------------------------------------------------
    def create_task(
        self,
        *,
        image: bytes,
        image_type: str,
        width: int,
        height: int,
        needed: int,
        base_scene: dict[str, Any],
    ) -> str:
        """Store a snapshot and its task; returns the task id."""
        task_id = uuid.uuid4().hex
        name = f"{task_id}.{image_type}"
        (self.data_dir / "snapshots" / name).write_bytes(image)
        with self._tx() as db:
            db.execute(
                "INSERT INTO tasks (id, created, image_file, image_type, width, height, needed, "
                "base_scene) VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
                (
                    task_id,
                    time.time(),
                    name,
                    image_type,
                    width,
                    height,
                    needed,
                    json.dumps(base_scene),
                ),
            )
        return task_id

    def task(self, task_id: str) -> dict[str, Any] | None:
        """A task's record (with its annotation count), or None."""
        db = self._db()
        row = db.execute("SELECT * FROM tasks WHERE id = ?", (task_id,)).fetchone()
        if row is None:
            return None
        n = db.execute("SELECT COUNT(*) FROM annotations WHERE task_id = ?", (task_id,)).fetchone()
        out = dict(row)
        out["base_scene"] = json.loads(out["base_scene"])
        out["result"] = json.loads(out["result"]) if out["result"] else None
        out["annotations"] = int(n[0])
        return out

    def task_image(self, task: dict[str, Any]) -> bytes:
        """The snapshot of a task."""
        return (self.data_dir / "snapshots" / str(task["image_file"])).read_bytes()

    def add_annotation(self, task_id: str, scene: dict[str, Any]) -> int:
        """Store one annotator's scene; returns how many the task has now."""
        with self._tx() as db:
            n = db.execute(
                "SELECT COUNT(*) FROM annotations WHERE task_id = ?", (task_id,)
            ).fetchone()[0]
            db.execute(
                "INSERT INTO annotations (task_id, n, created, scene) VALUES (?, ?, ?, ?)",
                (task_id, n, time.time(), json.dumps(scene)),
            )
        return int(n) + 1

    def add_annotation_once(
        self, task_id: str, scene: dict[str, Any], *, needed: int | None = None
    ) -> tuple[int, bool]:
        """Store one annotator's scene unless the task has the very same one already.

        Returns how many the task has now and whether this one was new: a client's retry
        (a lost answer, a double click on Submit) must not count as another annotator.

        Raises
        ------
        TaskFullError
            The task has ``needed`` annotations already (checked in the same transaction:
            submissions racing the one that completed the task, while it was being
            located, were all stored and counted).
        """
        with self._tx() as db:
            rows = db.execute(
                "SELECT scene FROM annotations WHERE task_id = ?", (task_id,)
            ).fetchall()
            if any(json.loads(r["scene"]) == scene for r in rows):
                return len(rows), False
            if needed is not None and len(rows) >= needed:
                raise TaskFullError(task_id)
            db.execute(
                "INSERT INTO annotations (task_id, n, created, scene) VALUES (?, ?, ?, ?)",
                (task_id, len(rows), time.time(), json.dumps(scene)),
            )
        return len(rows) + 1, True

    def remove_annotation(self, task_id: str, n: int) -> None:
        """Take back the ``n``-th annotation (from 1) of a task: the submission that
        completed the task failed to locate it (a time limit, a worker lost), so it may be
        sent again rather than leave the task full and never located."""
        with self._tx() as db:
            db.execute("DELETE FROM annotations WHERE task_id = ? AND n = ?", (task_id, n - 1))

    def annotations(self, task_id: str) -> list[dict[str, Any]]:
        """Every annotator's scene of a task, in arrival order."""
        rows = self._db().execute(
            "SELECT scene FROM annotations WHERE task_id = ? ORDER BY n", (task_id,)
        )
        return [json.loads(r["scene"]) for r in rows]

    def set_task_result(self, task_id: str, status: str, result: dict[str, Any]) -> None:
        """Record a task's outcome."""
        with self._tx() as db:
            db.execute(
                "UPDATE tasks SET status = ?, result = ? WHERE id = ?",
                (status, json.dumps(result), task_id),
            )
