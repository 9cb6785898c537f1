"""Reading inputs and writing outputs safely (one rule for the library and every front end).

- Writes are atomic: the data go to a temporary file in the target's directory, which then
  replaces the target (:func:`os.replace`); a failure halfway leaves the old file (or none),
  never a truncated one.
- :func:`check_output_path` refuses a missing directory, a directory as a file, a directory
  nothing can be written in (read-only, no permission, ``/proc``) and an output that is one of
  the inputs, each with an :class:`~camloc_geo.InputError` of one line, before any work.
- :func:`read_json_file` reads JSON with the same error style for every command.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from camloc_geo._errors import InputError

__all__ = ["atomic_path", "check_output_path", "read_json_file", "write_text_atomic"]

PathLike = str | os.PathLike[str]


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return a.resolve() == b.resolve()


def check_output_path(
    path: PathLike,
    *,
    inputs: Iterable[PathLike | None] = (),
    option: str = "-o",
    directory: bool = False,
) -> Path:
    """Validate an output path before any work is done.

    Parameters
    ----------
    path
        The file (or, with ``directory``, the folder) to write.
    inputs
        Files the command reads; the output may be none of them.
    option
        The option naming the output, for the message (``-o``, ``--map``...).
    directory
        The output is a folder that must exist (``--overlays DIR``).

    Raises
    ------
    InputError
        The directory is missing (it is never created), the path is a directory (or, with
        ``directory``, not one), nothing can be written in the directory, or the output would
        overwrite an input.
    """
    p = Path(path)
    if directory:
        if not p.is_dir():
            what = "is not a directory" if p.exists() else "does not exist"
            raise InputError(f"{option} {p}: directory {what} (create it first)")
        _check_writable(p, f"{option} {p}")
        return p
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(
            f"{option} {p}: directory {parent} does not exist (create it first)"
            if not parent.exists()
            else f"{option} {p}: {parent} is not a directory"
        )
    if p.is_dir():
        raise InputError(f"{option} {p}: is a directory, give a file name")
    for src in inputs:
        if src is not None and _same_file(p, Path(src)):
            raise InputError(f"{option} {p}: would overwrite the input {src}; choose another file")
    _check_writable(parent, f"{option} {p}")
    return p


def _check_writable(folder: Path, what: str) -> None:
    """Refuse a folder nothing can be written in, by creating and removing an empty file there.

    :func:`os.access` is not enough: it says yes to root on a read-only file system or in
    ``/proc``; the outputs are written through a temporary file in the same folder
    (:func:`atomic_path`), so this is the very operation that must succeed.
    """
    try:
        fd, name = tempfile.mkstemp(prefix=".camloc-write-test.", dir=folder)
    except OSError as exc:
        raise InputError(
            f"{what}: cannot write in the directory {folder} ({exc.strerror or exc})"
        ) from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(name)


@contextlib.contextmanager
def atomic_path(path: PathLike) -> Iterator[Path]:
    """A temporary path next to ``path`` (same suffix); it replaces ``path`` on success.

    Write the file at the yielded path (any writer: ``open``, ``cv2.imwrite``...). When the
    block raises, or writes nothing, the temporary file is removed and ``path`` is untouched.
    """
    target = Path(path)
    fd, tmp_name = tempfile.mkstemp(
        prefix=f".{target.name}.", suffix=f".tmp{target.suffix}", dir=target.parent or "."
    )
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        if not tmp.exists() or tmp.stat().st_size == 0:
            raise OSError(f"nothing was written to {target}")
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, target)
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def write_text_atomic(path: PathLike, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; returns the path."""
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as fh:
        fh.write(text)
        fh.flush()
        os.fsync(fh.fileno())
    return Path(path)


def read_json_file(path: PathLike, *, what: str = "JSON file") -> Any:
    """Parse a JSON file; every failure is an :class:`InputError` naming the file.

    Raises
    ------
    InputError
        Missing, unreadable, not UTF-8 or not JSON (the message gives line and column).
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError as exc:
        raise InputError(f"{p}: no such file") from exc
    except IsADirectoryError as exc:
        raise InputError(f"{p}: is a directory, expected a {what}") from exc
    except UnicodeDecodeError as exc:
        raise InputError(f"{p}: not a {what} (not UTF-8 text)") from exc
    except OSError as exc:
        raise InputError(f"{p}: cannot read ({exc.strerror or exc})") from exc
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(
            f"{p}: not a {what} (line {exc.lineno} column {exc.colno}: {exc.msg})"
        ) from exc
