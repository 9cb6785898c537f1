"""One network rule for every command, and fast failure when Overpass cannot be reached.

Never reaches the internet: the Overpass URLs are local closed ports or a local server.
"""

from __future__ import annotations

import http.server
import json
import socket
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from camloc_geo import MapDataError, MapSourceError
from camloc_geo.api import corners_near, locate_scene, streets_near
from camloc_geo.cli import main
from camloc_geo.osm import _load

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "sample_maps" / "sample_scene.json"
BALTIMORE = ROOT / "data" / "osm" / "baltimore.osm.pbf"
LAT, LON = "39.28558", "-76.59348"
POINT = ["--lat", LAT, "--lon", LON]


def one_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


def closed_port() -> int:
    """A local TCP port nobody listens on."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


# ------------------------------------------------------------------------------ --help
@pytest.mark.parametrize("command", ["locate", "corners", "streets"])
def test_every_map_command_states_the_network_rule(
    command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "with --osm EXTRACT the network is never used" in text
    assert "unless --no-network (or --offline)" in text
    assert "--no-network" in text


@pytest.mark.parametrize("command", ["calibrate", "vp", "summary-map"])
def test_commands_without_maps_say_they_stay_offline(
    command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    assert "never uses the network" in " ".join(capsys.readouterr().out.split()).lower()


def test_locate_help_lists_inline_and_offline(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["locate", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--inline" in text
    assert "--offline --no-network --inline" in text


# ------------------------------------------------------------------- no network, no map
@pytest.mark.parametrize("flag", ["--no-network", "--offline"])
@pytest.mark.parametrize(
    "argv",
    [["locate", str(SCENE)], ["corners", *POINT], ["streets", *POINT]],
    ids=["locate", "corners", "streets"],
)
def test_no_network_and_no_extract_fails_fast(
    argv: list[str], flag: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*argv, flag]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    line = one_line(captured.err)
    assert line.startswith(f"camloc {argv[0]}: error:")
    assert "--osm EXTRACT" in line


def test_no_network_fails_before_loading_any_map_code() -> None:
    code = (
        "import sys\n"
        "from camloc_geo.cli import main\n"
        "rc = main(['corners', '--no-network', '--lat', '1', '--lon', '2'])\n"
        "print('RC', rc, 'osmnx' in sys.modules, 'camloc_geo.osm' in sys.modules)\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True
    )
    assert proc.stdout.splitlines()[-1] == "RC 2 False False"


def test_online_is_a_no_op_and_conflicts_with_no_network(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["corners", "--online", "--osm", str(BALTIMORE), *POINT]) == 0
    with_online = json.loads(capsys.readouterr().out)
    assert main(["corners", "--osm", str(BALTIMORE), *POINT]) == 0
    assert json.loads(capsys.readouterr().out) == with_online
    assert main(["streets", "--online", "--no-network", *POINT]) == 2
    assert "contradicts" in one_line(capsys.readouterr().err)


def test_extract_is_used_even_with_network_on(monkeypatch: pytest.MonkeyPatch) -> None:
    def no_overpass(*args: object, **kwargs: object) -> None:
        raise AssertionError("Overpass queried although an extract was given")

    monkeypatch.setattr(_load, "read_overpass", no_overpass)
    monkeypatch.setattr("camloc_geo.osm._map.read_overpass", no_overpass)
    out = locate_scene(SCENE, map_source=BALTIMORE, network=True)
    assert out.result.candidates
    gj = corners_near(lat=float(LAT), lon=float(LON), map_source=BALTIMORE, network=True)
    assert gj["features"]


def test_api_without_source_and_network_off() -> None:
    with pytest.raises(MapDataError, match="--osm EXTRACT"):
        streets_near(lat=1.0, lon=2.0, network=False)
    with pytest.raises(MapDataError, match="--osm EXTRACT"):
        locate_scene(SCENE, network=False)


# ------------------------------------------------------------- unreachable Overpass
def test_closed_port_fails_at_once_with_a_hint(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    url = f"http://127.0.0.1:{closed_port()}/api"
    argv = ["--overpass-url", url, "--cache-folder", str(tmp_path / "cache")]
    assert main(["corners", *POINT, *argv]) == 1
    line = one_line(capsys.readouterr().err)
    assert line.startswith("camloc corners: failed: MapSourceError:")
    assert "connection refused" in line
    assert "--osm EXTRACT" in line
    assert main(["locate", str(SCENE), *argv]) == 1
    assert "--osm EXTRACT" in one_line(capsys.readouterr().err)


def test_closed_port_subprocess_exits_without_waiting(tmp_path: Path) -> None:
    """osmnx's rate-limit pause (60 s when the status page is unreachable) is skipped."""
    url = f"http://127.0.0.1:{closed_port()}/api"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "camloc_geo.cli",
            "streets",
            *POINT,
            "--overpass-url",
            url,
            "--cache-folder",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        timeout=40,  # a hang guard, far above the expected second
        check=False,
    )
    assert proc.returncode == 1
    assert "--osm EXTRACT" in one_line(proc.stderr)


def test_connect_timeout_fails_with_a_hint(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    seen: list[float] = []

    def silent(address: tuple[str, int], timeout: float) -> socket.socket:
        seen.append(timeout)
        raise TimeoutError("timed out")

    monkeypatch.setattr(socket, "create_connection", silent)
    with pytest.raises(MapSourceError, match=r"no answer in 5 s.*--osm EXTRACT"):
        streets_near(lat=float(LAT), lon=float(LON), radius_m=99.0, network=True)
    assert seen == [_load.CONNECT_TIMEOUT_S]


@pytest.mark.parametrize(
    ("url", "problem"),
    [
        ("http://127.0.0.1:{port}/api", "connection refused"),
        ("http:///api", "no host in the URL"),
        ("http://127.0.0.1:99999/api", "bad port in the URL"),
    ],
)
def test_probe_server_reasons(url: str, problem: str) -> None:
    assert _load.probe_server(url.format(port=closed_port()), 2.0) == problem


class _Status(http.server.BaseHTTPRequestHandler):
    def do_GET(self) -> None:
        self.send_response(503)
        self.end_headers()

    def log_message(self, format: str, *args: object) -> None:
        pass


@pytest.fixture
def local_server() -> Iterator[str]:
    srv = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _Status)
    thread = threading.Thread(target=srv.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{srv.server_address[1]}/api"
    srv.shutdown()
    srv.server_close()


def test_local_server_is_probed_ok(local_server: str) -> None:
    assert _load.probe_server(local_server, 2.0) is None


# ------------------------------------------------------------------ --inline / --offline
@pytest.mark.parametrize(
    ("flags", "inlined"),
    [(["--inline"], True), (["--offline"], True), (["--no-network"], False), ([], False)],
)
def test_page_inlining_is_its_own_flag(
    flags: list[str], inlined: bool, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from test_maps import remote_references

    page = tmp_path / "m.html"
    argv = ["locate", str(SCENE), "--osm", str(BALTIMORE), "--map", str(page), *flags]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["type"] == "FeatureCollection"
    text = page.read_text(encoding="utf-8")
    assert (remote_references(text) == []) is inlined
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.html"]


def test_overlays_go_into_the_existing_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    shots = tmp_path / "shots"
    shots.mkdir()
    page = tmp_path / "m.html"
    argv = ["locate", str(SCENE), "--osm", str(BALTIMORE), "--map", str(page)]
    assert main([*argv, "--overlays", str(shots), "-o", str(tmp_path / "c.geojson")]) == 0
    assert capsys.readouterr().out == ""
    pngs = sorted(p.name for p in shots.iterdir())
    assert pngs
    assert all(n.endswith(".png") and not n.startswith(".") for n in pngs)
    assert f"shots/{pngs[0]}" in page.read_text(encoding="utf-8")
