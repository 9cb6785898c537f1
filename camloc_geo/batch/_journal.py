"""The batch journal: a SQLite file next to the output recording every finished camera.

Each finished chunk of cameras is written in one transaction (WAL mode), keyed by the
list's row number, so an interruption at any point (Ctrl-C, ``kill -9``) loses nothing
finished and a rerun computes each remaining camera exactly once. The GeoPackage is built
from the journal at the end of every run.
"""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

from camloc_geo._errors import InputError

__all__ = ["Journal", "journal_path"]

_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS done (
    row INTEGER PRIMARY KEY,
    id TEXT NOT NULL,
    status TEXT NOT NULL,
    record TEXT NOT NULL
);
"""


def journal_path(out_gpkg: str | Path) -> Path:
    """The journal of an output: ``OUT.gpkg`` -> ``OUT.camloc-batch.sqlite``."""
    p = Path(out_gpkg)
    return p.with_name(p.stem + ".camloc-batch.sqlite")


class Journal:
    """Rows done so far, and their results (JSON records)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        path.parent.mkdir(parents=True, exist_ok=True)
        try:
            self.db = sqlite3.connect(str(path), timeout=30.0, isolation_level=None)
            self.db.execute("PRAGMA journal_mode=WAL")
            self.db.execute("PRAGMA synchronous=NORMAL")
            self.db.executescript(_SCHEMA)
            # each row's fingerprint (what the list said): a journal of an older release
            # has none, and its rows are taken as they are
            cols = {str(r[1]) for r in self.db.execute("PRAGMA table_info(done)")}
            if "fp" not in cols:
                self.db.execute("ALTER TABLE done ADD COLUMN fp TEXT")
        except sqlite3.DatabaseError as exc:
            raise InputError(
                f"cannot use the batch journal {path}: {exc} (delete it to start again)"
            ) from None

    def close(self) -> None:
        """Close the database."""
        self.db.close()

    def check_options(self, options: dict[str, Any], restart: bool) -> None:
        """Remember the run's options; refuse to resume a run made with other options."""
        text = json.dumps(options, sort_keys=True)
        cur = self.db.execute("SELECT value FROM meta WHERE key = 'options'")
        row = cur.fetchone()
        if restart:
            self.db.execute("BEGIN")
            self.db.execute("DELETE FROM done")
            self.db.execute("INSERT OR REPLACE INTO meta VALUES ('options', ?)", (text,))
            self.db.execute("COMMIT")
            return
        if row is None:
            self.db.execute("INSERT INTO meta VALUES ('options', ?)", (text,))
        elif row[0] != text:
            raise InputError(
                f"{self.path.name} holds a run made with other options ({row[0]}); "
                "rerun with the same options, or --restart to start again"
            )

    def done_rows(self, retry: Iterable[str] = ()) -> dict[int, str]:
        """``{row: id}`` of the cameras finished (statuses in ``retry`` excluded)."""
        retry = tuple(retry)
        q = "SELECT row, id FROM done"
        if retry:
            q += " WHERE status NOT IN (" + ",".join("?" * len(retry)) + ")"
        return {int(r): str(i) for r, i in self.db.execute(q, retry)}

    def iter_done(self, retry: Iterable[str] = (), page: int = 10_000) -> Iterator[tuple[int, str]]:
        """``(row, id)`` of the cameras finished, in row order, read a page at a time.

        The streaming form of :meth:`done_rows`: memory stays one page whatever the length of
        the journal (a million rows as a dict held about 150 MB).
        """
        for r, i, _fp in self.iter_done_fingerprints(retry, page):
            yield r, i

    def iter_done_fingerprints(
        self, retry: Iterable[str] = (), page: int = 10_000
    ) -> Iterator[tuple[int, str, str | None]]:
        """``(row, id, fingerprint)`` of the cameras finished, in row order, a page at a time
        (:meth:`iter_done` with each row's fingerprint as written; None from older runs)."""
        retry = tuple(retry)
        q = "SELECT row, id, fp FROM done WHERE row > ?"
        if retry:
            q += " AND status NOT IN (" + ",".join("?" * len(retry)) + ")"
        q += " ORDER BY row LIMIT ?"
        last = -(1 << 62)
        while True:
            rows = self.db.execute(q, (last, *retry, page)).fetchall()
            if not rows:
                return
            for r, i, fp in rows:
                yield int(r), str(i), None if fp is None else str(fp)
            last = int(rows[-1][0])

    def write(
        self,
        records: Iterable[dict[str, Any]],
        fingerprints: Mapping[int, str] | None = None,
    ) -> int:
        """Record finished cameras in one transaction; returns how many.

        ``fingerprints``: each row's fingerprint of what the list said (``{row: text}``), so
        that a rerun computes a row the list changed again.
        """
        fps = fingerprints or {}
        rows = [
            (
                int(r["row"]),
                str(r["id"]),
                str(r["status"]),
                json.dumps(r, allow_nan=False),
                fps.get(int(r["row"])),
            )
            for r in records
        ]
        self.db.execute("BEGIN IMMEDIATE")
        try:
            self.db.executemany(
                "INSERT OR REPLACE INTO done (row, id, status, record, fp) VALUES (?, ?, ?, ?, ?)",
                rows,
            )
            self.db.execute("COMMIT")
        except BaseException:
            self.db.execute("ROLLBACK")
            raise
        return len(rows)

    def drop_after(self, last_row: int, limit: int = 20) -> tuple[int, list[tuple[int, str]]]:
        """Forget the cameras recorded past ``last_row`` (rows the list no longer has).

        Returns
        -------
        tuple
            How many were dropped, and the first ``limit`` of them as ``(row, id)``.
        """
        named = [
            (int(r), str(i))
            for r, i in self.db.execute(
                "SELECT row, id FROM done WHERE row > ? ORDER BY row LIMIT ?", (last_row, limit)
            )
        ]
        if not named:
            return 0, []
        self.db.execute("BEGIN IMMEDIATE")
        try:
            n = self.db.execute("DELETE FROM done WHERE row > ?", (last_row,)).rowcount
            self.db.execute("COMMIT")
        except BaseException:
            self.db.execute("ROLLBACK")
            raise
        return int(n), named

    def duplicate_ids(self, limit: int = 20) -> dict[str, list[int]]:
        """Camera ids recorded on more than one row: ``{id: [row, ...]}``, at most ``limit`` ids.

        Counted by SQLite (an index-free ``GROUP BY``), so memory stays bounded whatever the
        length of the list.
        """
        out: dict[str, list[int]] = {}
        for i, rows in self.db.execute(
            "SELECT id, group_concat(row) FROM (SELECT id, row FROM done ORDER BY row) "
            "GROUP BY id HAVING COUNT(*) > 1 ORDER BY MIN(row) LIMIT ?",
            (int(limit),),
        ):
            out[str(i)] = sorted(int(r) for r in str(rows).split(","))
        return out

    def n_duplicate_ids(self) -> int:
        """How many camera ids are recorded on more than one row."""
        return int(
            self.db.execute(
                "SELECT COUNT(*) FROM (SELECT id FROM done GROUP BY id HAVING COUNT(*) > 1)"
            ).fetchone()[0]
        )

    def count(self) -> int:
        """Cameras recorded."""
        return int(self.db.execute("SELECT COUNT(*) FROM done").fetchone()[0])

    def status_counts(self) -> dict[str, int]:
        """Cameras per status."""
        return {
            str(s): int(n)
            for s, n in self.db.execute("SELECT status, COUNT(*) FROM done GROUP BY status")
        }

    def records(self, page: int = 2000) -> Iterator[dict[str, Any]]:
        """Every record in row order, read a page at a time."""
        last = -(1 << 62)
        while True:
            rows = self.db.execute(
                "SELECT row, record FROM done WHERE row > ? ORDER BY row LIMIT ?", (last, page)
            ).fetchall()
            if not rows:
                return
            for _r, rec in rows:
                yield rescaled_title_scores(json.loads(rec))
            last = rows[-1][0]


def rescaled_title_scores(record: dict[str, Any]) -> dict[str, Any]:
    """A camera's record of a journal written before session 41, its title candidates'
    scores put on the candidates' scale (as :mod:`camloc_geo.cameras` now writes them).

    A title candidate's ``score`` was the name-match score (an ambiguous title's two
    junctions 1.0 each; a located camera's title junction 1.0 beside its best 0.48); it is
    now the candidate's share of the camera's evidence and the match score ``match_score``.
    A resumed run rebuilds its GeoPackage and summary map from every record, old ones
    included, so they are rescaled when read. Records that have ``match_score`` are returned
    as they are.
    """
    cands = record.get("candidates") or []
    title = [c for c in cands if isinstance(c, dict) and c.get("source") == "title"]
    if not title or any("match_score" in c for c in title):
        return record
    from camloc_geo.cameras._camera import _share_title_scores

    cands = [dict(c) if isinstance(c, dict) else c for c in cands]
    title = [c for c in cands if isinstance(c, dict) and c.get("source") == "title"]
    for c in title:
        c["match_score"] = c.get("score")
    out = {**record, "candidates": cands, "match_score": title[0]["match_score"]}
    if any(isinstance(c, dict) and c.get("source") == "locate" for c in cands):
        for c in title:
            c["score"] = 0.0
        return out
    _share_title_scores(title)
    if out.get("method") == "title":
        out["score"] = cands[0]["score"] if isinstance(cands[0], dict) else out.get("score")
        out["cones"] = [
            {**k, "score": out["score"]}
            if isinstance(k, dict) and k.get("source") == "title"
            else k
            for k in out.get("cones") or []
        ]
    return out
