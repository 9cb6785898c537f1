"""Reviewers' verdicts shared through the service: one small SQLite file.

A review or summary page served by the service (``/v1/maps``, ``/v1/tasks/{id}/map``) sends
each verdict its reviewer gives to ``POST /v1/verdicts/{page}/{identity}`` and reads the
others' with ``GET``; a page opened from a file keeps them in its browser only. Each
candidate's (or camera's) verdict is one row keyed by the page's kind, its identity (16 hex
digits, see docs/candidates.md) and the candidate's key on the page (``"3"`` for rank 3 of a
review page, ``"c12"`` for a summary page's 13th camera); the latest ``time`` wins.
"""

from __future__ import annotations

import sqlite3
import threading
import time
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from camloc_geo.service.store import SqliteFile

__all__ = [
    "VERDICTS_FILE",
    "VerdictStore",
    "VerdictStoreError",
    "check_verdict_folder",
    "export_csv",
    "export_geojson",
    "export_rows",
]

VERDICTS_FILE = "camloc-verdicts.sqlite"
"""The file's name in the verdicts folder (``CAMLOC_VERDICT_DIR``, else ``CAMLOC_DATA_DIR``)."""

_SCHEMA = """
CREATE TABLE IF NOT EXISTS verdicts (
    page TEXT NOT NULL, identity TEXT NOT NULL, key TEXT NOT NULL,
    verdict TEXT, rank INTEGER, note TEXT NOT NULL, reviewer TEXT NOT NULL,
    time TEXT NOT NULL, camera TEXT NOT NULL DEFAULT '', lat REAL, lon REAL,
    received REAL NOT NULL,
    PRIMARY KEY (page, identity, key)
);
"""

_FIELDS = ("verdict", "rank", "note", "reviewer", "time", "camera", "lat", "lon")
_DEFAULTS = {"note": "", "reviewer": "", "camera": ""}


class VerdictStoreError(Exception):
    """The verdicts file cannot be read or written (a read-only folder, a full disk, a file
    another process holds locked): the service answers 503 ``verdicts_unavailable``."""


def check_verdict_folder(folder: Path, name: str = "CAMLOC_VERDICT_DIR") -> Path:
    """The verdicts folder, refused at once where it cannot hold the verdicts file.

    Parameters
    ----------
    folder
        The folder (made later if missing).
    name
        What set it (``CAMLOC_VERDICT_DIR``, ``--verdict-dir``...), for the message.

    Raises
    ------
    InputError
        ``folder`` (or the verdicts file in it) is not a folder (a file), its parent is not a
        folder, or it exists and cannot be written.
    """
    import os

    from camloc_geo._errors import InputError

    folder = Path(folder).expanduser()
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{name} {folder}: not a folder (the reviewers' verdicts go there)")
    if folder.is_dir():
        target = folder / VERDICTS_FILE
        if target.exists() and not target.is_file():
            raise InputError(f"{name} {folder}: {VERDICTS_FILE} in it is not a file")
        writable = os.access(target if target.exists() else folder, os.W_OK)
        if not writable:
            raise InputError(f"{name} {folder}: cannot write there (read-only)")
    else:
        parent = next((p for p in folder.parents if p.exists()), None)
        if parent is not None and not parent.is_dir():
            raise InputError(f"{name} {folder}: {parent} is a file, not a folder")
    return folder


class VerdictStore(SqliteFile):
    """The verdicts of every page the service's reviewers marked (thread-safe; WAL mode).

    Parameters
    ----------
    folder
        Where the SQLite file lives (made if missing).
    max_rows
        Most verdicts kept over all pages (a post that would pass it is refused).
    """

    def __init__(self, folder: Path, max_rows: int) -> None:
        from camloc_geo._errors import InputError

        self.folder = check_verdict_folder(Path(folder), "verdicts folder")
        self.path = self.folder / VERDICTS_FILE
        self.max_rows = int(max_rows)
        self._local = threading.local()
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            self._db().executescript(_SCHEMA)
        except (OSError, sqlite3.Error) as exc:
            raise InputError(f"verdicts folder {self.folder}: cannot use it: {exc}") from None

    @contextmanager
    def _unavailable(self) -> Iterator[None]:
        """An SQLite or OS failure as a :class:`VerdictStoreError` naming the file."""
        try:
            yield
        except (sqlite3.Error, OSError) as exc:
            raise VerdictStoreError(
                f"the server cannot use its verdicts file {self.path.name}: {exc}"
            ) from None

    def page(self, page: str, identity: str) -> dict[str, Any]:
        """``{"page", "identity", "items": {key: {verdict, rank, note, reviewer, time,
        camera, lat, lon}}}``;
        an item whose ``verdict`` is None was withdrawn (kept so that the withdrawal reaches
        the other reviewers' pages)."""
        with self._unavailable():
            rows = self._db().execute(
                "SELECT key, verdict, rank, note, reviewer, time, camera, lat, lon FROM verdicts "
                "WHERE page = ? AND identity = ? ORDER BY key",
                (page, identity),
            )
            items = {str(r["key"]): {f: r[f] for f in _FIELDS} for r in rows}
        return {"page": page, "identity": identity, "items": items}

    def merge(
        self, page: str, identity: str, items: Mapping[str, Mapping[str, Any]]
    ) -> tuple[dict[str, Any], list[str]]:
        """Take the items newer than (or as new as) the stored ones.

        Parameters
        ----------
        items
            ``key → {verdict, rank, note, reviewer, time, camera, lat, lon}``, ``time`` an
            ISO 8601 UTC string
            as :func:`camloc_geo.service.models.utc_text` writes it (they compare as
            text).

        Returns
        -------
        tuple
            The page's items after the merge (as :meth:`page`) and the keys taken.

        Raises
        ------
        LimitError
            The store would hold more than ``max_rows`` verdicts.
        VerdictStoreError
            The file cannot be written (read-only, full disk, locked over 30 s).
        """
        from camloc_geo.service.work import LimitError

        taken: list[str] = []
        now = time.time()
        with self._unavailable(), self._tx() as db:
            stored = {
                str(r["key"]): str(r["time"])
                for r in db.execute(
                    "SELECT key, time FROM verdicts WHERE page = ? AND identity = ?",
                    (page, identity),
                )
            }
            new_keys = sum(1 for k in items if k not in stored)
            if new_keys:
                (total,) = db.execute("SELECT COUNT(*) FROM verdicts").fetchone()
                if total + new_keys > self.max_rows:
                    raise LimitError(
                        f"this server keeps at most {self.max_rows} verdicts "
                        f"(CAMLOC_MAX_VERDICTS); it has {total}",
                        "items",
                    )
            for key, it in items.items():
                if key in stored and str(it["time"]) < stored[key]:
                    continue  # an older verdict than the stored one: the stored stays
                db.execute(
                    "INSERT OR REPLACE INTO verdicts "
                    "(page, identity, key, verdict, rank, note, reviewer, time, camera, lat, "
                    "lon, received) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                    (page, identity, key, *(it.get(f, _DEFAULTS.get(f)) for f in _FIELDS), now),
                )
                taken.append(key)
        return self.page(page, identity), taken

    def pages(self, limit: int = 1000) -> list[dict[str, Any]]:
        """The pages with verdicts, latest first: ``page``, ``identity``, ``verdicts`` (how many
        candidates or cameras have one), ``latest`` (time of the latest change)."""
        with self._unavailable():
            rows = (
                self._db()
                .execute(
                    "SELECT page, identity, SUM(verdict IS NOT NULL) AS n, MAX(time) AS latest "
                    "FROM verdicts GROUP BY page, identity ORDER BY latest DESC LIMIT ?",
                    (int(limit),),
                )
                .fetchall()
            )
        return [
            {
                "page": str(r["page"]),
                "identity": str(r["identity"]),
                "verdicts": int(r["n"] or 0),
                "latest": str(r["latest"]),
            }
            for r in rows
        ]


def _cell(value: Any) -> str:
    """A CSV cell as the pages write it: a text starting ``= + - @`` (or a tab or CR) gets a
    leading ``'`` so that a spreadsheet does not run it as a formula."""
    if value is None:
        return ""
    text = str(value)
    if isinstance(value, str) and text[:1] in ("=", "+", "-", "@", "\t", "\r"):
        text = "'" + text
    return text


def export_rows(doc: Mapping[str, Any]) -> list[dict[str, Any]]:
    """A page's verdicts (:meth:`VerdictStore.page`) as the rows of the page's own export,
    in key order; withdrawn ones left out. ``rank`` is the stored one, else (review page) the
    key's."""
    from camloc_geo.maps import VERDICT_FIELDS

    def order(key: str) -> tuple[int, str]:
        digits = key.lstrip("c")
        return (int(digits) if digits.isdigit() else 0, key)

    rows = []
    for key in sorted(doc["items"], key=order):
        it = doc["items"][key]
        if not it.get("verdict"):
            continue
        rank = it.get("rank")
        if rank is None and doc["page"] == "candidates" and key.isdigit():
            rank = int(key)
        row = {
            **it,
            "rank": rank,
            "page": doc["page"],
            "identity": doc["identity"],
        }
        rows.append({f: row.get(f) for f in VERDICT_FIELDS})
    return rows


def export_csv(doc: Mapping[str, Any]) -> str:
    """The page's export as CSV: UTF-8 with a BOM, CRLF, the formula guard (as the pages)."""
    import csv
    import io

    from camloc_geo.maps import VERDICT_FIELDS

    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\r\n")
    writer.writerow(VERDICT_FIELDS)
    for row in export_rows(doc):
        writer.writerow([_cell(row[f]) for f in VERDICT_FIELDS])
    return "\ufeff" + buf.getvalue()


def export_geojson(doc: Mapping[str, Any]) -> dict[str, Any]:
    """The page's export as GeoJSON (``format: camloc-verdicts/1``), as the pages write it."""
    import datetime

    feats = []
    for row in export_rows(doc):
        lat, lon = row.get("lat"), row.get("lon")
        geom = None if lat is None or lon is None else {"type": "Point", "coordinates": [lon, lat]}
        feats.append({"type": "Feature", "properties": row, "geometry": geom})
    exported = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="milliseconds")
    return {
        "type": "FeatureCollection",
        "properties": {
            "format": "camloc-verdicts/1",
            "page": doc["page"],
            "identity": doc["identity"],
            "exported": exported.replace("+00:00", "Z"),
        },
        "features": feats,
    }
