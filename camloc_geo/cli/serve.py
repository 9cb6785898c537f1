"""``camloc serve``: the HTTP service under uvicorn (settings from ``CAMLOC_*`` variables)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


def register(subparsers: Any) -> None:
    """Add the ``serve`` command."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "serve",
        help="run the HTTP service (FastAPI + uvicorn)",
        description=(
            "Serve the camloc HTTP API. Configuration comes from environment variables: "
            "CAMLOC_MAP_DIR (folder of OSM extracts), CAMLOC_API_KEY (key for write endpoints), "
            "CAMLOC_DATA_DIR (jobs and tasks database; default: the user's data folder, e.g. "
            "~/.local/share/camloc/service), CAMLOC_VERDICT_DIR (reviewers' verdicts; default: "
            "CAMLOC_DATA_DIR), CAMLOC_NETWORK (allow Overpass), and the limits "
            "documented in docs/service.md. Interactive API docs at /docs (offline)."
        ),
    )
    p.add_argument("--host", default="127.0.0.1", help="address to listen on (127.0.0.1)")
    p.add_argument("--port", type=int, default=8000, help="port (8000)")
    p.add_argument(
        "--workers",
        type=int,
        default=1,
        help=(
            "worker processes for the CPU work (1); one process serves HTTP and hands every "
            "request to a free worker (sets CAMLOC_WORKERS)"
        ),
    )
    p.add_argument(
        "--verdict-dir",
        metavar="DIR",
        default=None,
        help=(
            "folder of the reviewers' shared verdicts (camloc-verdicts.sqlite, made if "
            "missing; sets CAMLOC_VERDICT_DIR; default: CAMLOC_DATA_DIR)"
        ),
    )
    p.add_argument("--log-level", default="info", help="uvicorn log level")
    p.add_argument(
        "--loop",
        choices=("auto", "asyncio", "uvloop"),
        default="auto",
        help="event loop (auto: uvloop when installed, from the service extra; else asyncio)",
    )
    p.add_argument(
        "--http",
        choices=("auto", "h11", "httptools"),
        default="auto",
        help="HTTP parser (auto: httptools when installed, from the service extra; else h11)",
    )
    p.add_argument(
        "--no-access-log",
        dest="access_log",
        action="store_false",
        help="no line per request on the log (the access log is on by default)",
    )
    p.set_defaults(func=run)


def _settings_error(exc: Exception) -> str:
    """One line naming each bad ``CAMLOC_*`` variable, its value and what is wrong.

    pydantic's own text ("1 validation error for Settings / max_request_bytes / Input
    should be ... [type=..., input_value=..., input_type=str] / For further information
    visit https://errors.pydantic.dev/...") named the field, not the variable.
    """
    errors = getattr(exc, "errors", None)
    if not callable(errors):
        return f"invalid CAMLOC_* setting: {' '.join(str(exc).split())}"
    parts = []
    for err in errors():
        loc = err.get("loc") or ()
        name = f"CAMLOC_{str(loc[0]).upper()}" if loc else "CAMLOC_*"
        msg = str(err.get("msg", "invalid"))
        msg = msg.removeprefix("Value error, ")
        if name in msg:  # the service's own checks already name the variable
            parts.append(msg)
        else:
            parts.append(f"{name}={str(err.get('input', ''))[:60]!r}: {msg}")
    return "; ".join(parts) or f"invalid CAMLOC_* setting: {' '.join(str(exc).split())}"


def run(args: argparse.Namespace) -> int:
    """Run the command."""
    from camloc_geo._errors import InputError

    try:
        import uvicorn
    except ImportError:
        raise InputError(
            'the service needs its extra: python -m pip install "camloc-geo[service]"'
        ) from None
    if not (0 < args.port < 65536):
        raise InputError(f"--port must be 1-65535, not {args.port}")
    if args.workers < 1:
        raise InputError("--workers must be at least 1")
    for option, module in (("loop", "uvloop"), ("http", "httptools")):
        if getattr(args, option) == module and not _importable(module):
            raise InputError(
                f"--{option} {module}: {module} is not installed "
                f'(python -m pip install "camloc-geo[service]")'
            )
    import os

    from camloc_geo.service.settings import Settings

    os.environ["CAMLOC_WORKERS"] = str(args.workers)
    if args.verdict_dir is not None:
        folder = Path(args.verdict_dir).expanduser()
        if folder.exists() and not folder.is_dir():
            raise InputError(f"--verdict-dir {folder}: not a folder")
        if not folder.exists() and not folder.parent.is_dir():
            raise InputError(f"--verdict-dir {folder}: its parent folder does not exist")
        os.environ["CAMLOC_VERDICT_DIR"] = str(folder.resolve())
    try:
        settings = Settings()
    except Exception as exc:  # pydantic ValidationError: a bad CAMLOC_* variable
        raise InputError(_settings_error(exc)) from None
    from camloc_geo.service.verdicts import check_verdict_folder

    # a verdicts folder that is a file or read-only: one line now, not a traceback at start-up
    if args.verdict_dir is not None:
        check_verdict_folder(Path(args.verdict_dir), "--verdict-dir")
    elif settings.verdict_dir is not None:
        check_verdict_folder(settings.verdict_dir, "CAMLOC_VERDICT_DIR")
    else:
        check_verdict_folder(settings.data_dir, "CAMLOC_DATA_DIR")
    _check_listen(args.host, args.port)
    try:
        uvicorn.run(
            "camloc_geo.service:app_from_env",
            factory=True,
            host=args.host,
            port=args.port,
            log_level=args.log_level,
            loop=args.loop,
            http=args.http,
            access_log=args.access_log,
        )
    except SystemExit as exc:  # uvicorn's own exit (3: the server could not start)
        if exc.code in (None, 0):
            return 0
        raise RuntimeError(f"the server stopped (uvicorn status {exc.code}); see above") from None
    return 0


def _check_listen(host: str, port: int) -> None:
    """Refuse at once a host that does not resolve or a port another server holds.

    uvicorn found out only after starting the application, among its INFO lines, and exited
    with its own status 3 (``[Errno 98] ... address already in use``).
    """
    import socket

    from camloc_geo._errors import InputError

    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError) as exc:
        raise InputError(f"--host {host}: not an address of this machine ({exc})") from None
    family, kind, proto, _name, address = infos[0]
    with socket.socket(family, kind, proto) as sock:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn binds
        try:
            sock.bind(address)
        except OSError as exc:
            import errno

            reason = exc.strerror or str(exc)
            if exc.errno == errno.EADDRINUSE:
                raise InputError(
                    f"--port {port}: cannot listen on {host}:{port}: {reason} (another server "
                    "there? pick another --port)"
                ) from None
            raise InputError(f"--host {host}: cannot listen on {host}:{port}: {reason}") from None


def _importable(module: str) -> bool:
    from importlib.util import find_spec

    return find_spec(module) is not None
