"""The annotation page (``camloc_geo.web``) opened from QGIS, its scene picked up by itself.

The page is the library's tested annotation tool (zoom, pan, undo, moving points, guided steps,
a live focal length). The plugin serves it in its *crowd* mode from a tiny HTTP server bound to
127.0.0.1 on a free port, under a random token; the page's **Submit** posts the scene to that
server, which hands it to the dock (through a Qt signal, on the GUI thread). Nothing is written
to disk by the server, and it stops with the dock.
"""

from __future__ import annotations

import json
import secrets
import threading
from collections.abc import Callable
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

MAX_SCENE_BYTES = 20 * 1024 * 1024


class PageServer:
    """Serves one annotation page and receives its scene.

    Parameters
    ----------
    on_scene
        Called (on the server's thread) with the posted scene dict; returns None to accept
        it, or the reason it is refused (shown on the page as "Not submitted: ...").
    """

    def __init__(self, on_scene: Callable[[dict[str, Any]], str | None]) -> None:
        self.on_scene = on_scene
        self.token = secrets.token_urlsafe(16)
        self.html = ""
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, format: str, *args: Any) -> None:
                pass  # quiet: QGIS's console is not a web log

            def _reply(self, code: int, body: bytes, ctype: str) -> None:
                self.send_response(code)
                self.send_header("Content-Type", ctype)
                self.send_header("Content-Length", str(len(body)))
                self.send_header("Cache-Control", "no-store")
                self.end_headers()
                self.wfile.write(body)

            def do_GET(self) -> None:
                if self.path.rstrip("/") != f"/camloc/{server.token}" or not server.html:
                    self._reply(404, b"not found", "text/plain")
                    return
                self._reply(200, server.html.encode("utf-8"), "text/html; charset=utf-8")

            def do_POST(self) -> None:
                if self.path != f"/camloc/{server.token}/scene":
                    self._reply(404, b"not found", "text/plain")
                    return
                n = int(self.headers.get("Content-Length") or 0)
                if n <= 0 or n > MAX_SCENE_BYTES:
                    self._reply(400, b"the scene is empty or too large", "text/plain")
                    return
                try:
                    scene = json.loads(self.rfile.read(n).decode("utf-8"))
                    if not isinstance(scene, dict):
                        raise ValueError("not a JSON object")
                except ValueError as exc:
                    self._reply(400, f"not a scene: {exc}".encode(), "text/plain")
                    return
                refused = server.on_scene(scene)
                if refused:
                    self._reply(400, refused.encode("utf-8"), "text/plain; charset=utf-8")
                else:
                    self._reply(200, b"received by QGIS", "text/plain")

        self._httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self._httpd.daemon_threads = True
        self._thread = threading.Thread(target=self._httpd.serve_forever, daemon=True)
        self._thread.start()

    @property
    def port(self) -> int:
        return int(self._httpd.server_address[1])

    @property
    def url(self) -> str:
        """The page's address."""
        return f"http://127.0.0.1:{self.port}/camloc/{self.token}"

    @property
    def submit_url(self) -> str:
        """Where the page posts its scene."""
        return f"{self.url}/scene"

    def stop(self) -> None:
        """Stop serving (idempotent)."""
        if self._thread.is_alive():
            self._httpd.shutdown()
            self._thread.join(timeout=5)
        self._httpd.server_close()
