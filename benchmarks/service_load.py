"""Load test of the HTTP service on loopback: requests per second and latency of /v1/locate.

Starts ``camloc serve`` (``--workers`` processes) with the bundled Baltimore extract, warms the
map cache, then sends a bounded number of requests (``--requests``, ``--concurrency`` at a
time, ``--max-seconds`` at most) and writes ``benchmarks/out/service_load.json`` and a latency
histogram PNG. Only 127.0.0.1 is contacted.

Every request is a different five-annotator scene: the bundled sample's three annotators
and two more drawn from them, every point moved by up to a pixel (seeded), so no cache of
answers or parsed bodies can help. ``--check`` answers are compared with the library's
``locate_scene`` on the same extract (what ``camloc locate`` prints).

    python benchmarks/service_load.py --workers 2 --requests 600 --concurrency 8
    python benchmarks/service_load.py --client raw --serve-args "--loop asyncio --http h11"

The server's CPU per request is split between the serving process and the workers, and the
load client's own CPU is quoted apart (``--client raw``: a minimal keep-alive client on
asyncio streams, lighter than httpx on two shared cores).
"""

from __future__ import annotations

import argparse
import asyncio
import gc
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import httpx
import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT = HERE / "out"


def _port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _server_cpu_s(pid: int) -> dict[int, float]:
    """User + system CPU seconds so far of the server process and of each of its workers."""
    import psutil

    out: dict[int, float] = {}
    root = psutil.Process(pid)
    for p in [root, *root.children(recursive=True)]:
        try:
            t = p.cpu_times()
        except psutil.NoSuchProcess:
            continue
        out[p.pid] = t.user + t.system
    return out


def _jitter(value: Any, rng: np.random.Generator) -> Any:
    if isinstance(value, list) and value and all(isinstance(v, float) for v in value):
        return [round(v + float(rng.uniform(-1.0, 1.0)), 2) for v in value]
    if isinstance(value, list):
        return [_jitter(v, rng) for v in value]
    if isinstance(value, dict):
        return {k: _jitter(v, rng) for k, v in value.items()}
    return value


def scene_bodies(n: int, seed: int = 0) -> list[bytes]:
    """``n`` different five-annotator scenes around the bundled sample (JSON bodies)."""
    base = json.loads((ROOT / "sample_maps" / "sample_scene.json").read_text())
    anns = base["annotations"]
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        five = []
        for k in range(5):
            ann = _jitter(anns[k % len(anns)], rng)
            ann["annotator"] = f"a{k}"
            five.append(ann)
        out.append(json.dumps({**base, "id": f"load-{i}", "annotations": five}).encode())
    return out


async def _load(
    url: str, bodies: list[bytes], n: int, conc: int, max_s: float, kind: str = "httpx"
) -> tuple[list[float], int, dict[int, Any]]:
    if kind == "raw":
        return await _load_raw(url, bodies, n, conc, max_s)
    lat: list[float] = []
    answers: dict[int, Any] = {}
    errors = 0
    sent = 0
    t_end = time.perf_counter() + max_s
    async with httpx.AsyncClient(base_url=url, timeout=30.0) as client:

        async def one() -> None:
            nonlocal sent, errors
            while sent < n and time.perf_counter() < t_end:
                k = sent % len(bodies)
                sent += 1
                t0 = time.perf_counter()
                r = await client.post(
                    "/v1/locate", content=bodies[k], headers={"content-type": "application/json"}
                )
                lat.append(time.perf_counter() - t0)
                if r.status_code != 200:
                    errors += 1
                elif k not in answers:
                    answers[k] = r.json()

        await asyncio.gather(*(one() for _ in range(conc)))
    return lat, errors, answers


async def _post_raw(
    reader: asyncio.StreamReader, writer: asyncio.StreamWriter, head: bytes, body: bytes
) -> tuple[int, bytes]:
    """One keep-alive POST on an open connection: ``(status, body)`` (Content-Length only)."""
    writer.write(head + str(len(body)).encode() + b"\r\n\r\n" + body)
    status_line = await reader.readline()
    status = int(status_line.split(b" ", 2)[1])
    length = 0
    while True:
        line = await reader.readline()
        if line in (b"\r\n", b"\n", b""):
            break
        name, _, value = line.partition(b":")
        if name.strip().lower() == b"content-length":
            length = int(value)
    return status, await reader.readexactly(length)


async def _load_raw(
    url: str, bodies: list[bytes], n: int, conc: int, max_s: float, keep: int = 50
) -> tuple[list[float], int, dict[int, Any]]:
    """:func:`_load` with a minimal HTTP/1.1 client on asyncio streams (keep-alive, one
    connection per concurrent client), so that on two shared cores the load client takes
    less from the server it measures; only the first ``keep`` answers are parsed (to check)."""
    host, port = url.rsplit("/", 1)[-1].split(":")
    head = (
        f"POST /v1/locate HTTP/1.1\r\nHost: {host}:{port}\r\n"
        "Content-Type: application/json\r\nContent-Length: "
    ).encode()
    lat: list[float] = []
    answers: dict[int, Any] = {}
    errors = 0
    sent = 0
    t_end = time.perf_counter() + max_s

    async def one() -> None:
        nonlocal sent, errors
        reader, writer = await asyncio.open_connection(host, int(port), limit=1 << 24)
        try:
            while sent < n and time.perf_counter() < t_end:
                k = sent % len(bodies)
                sent += 1
                t0 = time.perf_counter()
                status, data = await _post_raw(reader, writer, head, bodies[k])
                lat.append(time.perf_counter() - t0)
                if status != 200:
                    errors += 1
                elif k not in answers and len(answers) < keep:
                    answers[k] = json.loads(data)
        finally:
            writer.close()

    await asyncio.gather(*(one() for _ in range(conc)))
    return lat, errors, answers


def _best(gj: dict[str, Any]) -> tuple[float, float] | None:
    for f in gj["features"]:
        if f["properties"].get("kind") == "candidate":
            return f["properties"]["lat"], f["properties"]["lon"]
    return None


def check_answers(bodies: list[bytes], answers: dict[int, Any], n_check: int) -> dict[str, Any]:
    """Compare ``n_check`` answers with the library's (best candidate, metres apart)."""
    from camloc_geo.api import locate_scene
    from camloc_geo.geodesy import distance_m

    extract = ROOT / "sample_maps" / "baltimore.osm.pbf"
    gaps = []
    same_count = 0
    for k in sorted(answers)[:n_check]:
        lib = locate_scene(json.loads(bodies[k]), map_source=extract, network=False).to_geojson()
        a, b = _best(answers[k]), _best(lib)
        n_srv = sum(f["properties"].get("kind") == "candidate" for f in answers[k]["features"])
        n_lib = sum(f["properties"].get("kind") == "candidate" for f in lib["features"])
        same_count += n_srv == n_lib
        if a is None or b is None:
            gaps.append(0.0 if a == b else float("inf"))
        else:
            gaps.append(float(distance_m(lat1=a[0], lon1=a[1], lat2=b[0], lon2=b[1])))
    return {
        "checked": len(gaps),
        "same_candidate_count": same_count,
        "best_gap_m_max": round(max(gaps), 4) if gaps else None,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--requests", type=int, default=600)
    ap.add_argument("--concurrency", type=int, default=8)
    ap.add_argument("--max-seconds", type=float, default=60.0)
    ap.add_argument("--check", type=int, default=10, help="answers compared with the library")
    ap.add_argument("--label", default="", help="name of this run in the JSON (e.g. before)")
    ap.add_argument(
        "--client",
        choices=("httpx", "raw"),
        default="httpx",
        help="load client: httpx, or a minimal keep-alive client on asyncio streams",
    )
    ap.add_argument(
        "--serve-args",
        default="",
        help="more camloc serve options, e.g. '--loop asyncio --http h11' (the old stack)",
    )
    ap.add_argument(
        "--client-gc",
        action="store_true",
        help="keep the load client's garbage collector on (its pauses then count as latency)",
    )
    args = ap.parse_args()
    OUT.mkdir(exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix="camloc-load-"))
    (tmp / "maps").mkdir()
    shutil.copy(ROOT / "sample_maps" / "baltimore.osm.pbf", tmp / "maps")
    port = _port()
    url = f"http://127.0.0.1:{port}"
    env = dict(os.environ, CAMLOC_MAP_DIR=str(tmp / "maps"), CAMLOC_DATA_DIR=str(tmp / "data"))
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "camloc_geo.cli",
            "serve",
            "--port",
            str(port),
            "--workers",
            str(args.workers),
            "--log-level",
            "warning",
            *args.serve_args.split(),
        ],
        env=env,
    )
    try:
        for _ in range(300):
            try:
                if httpx.get(url + "/healthz", timeout=1).status_code == 200:
                    break
            except httpx.HTTPError:
                time.sleep(0.2)
        bodies = scene_bodies(max(args.requests, 1))
        # every worker loads its map: requests at once, so that each worker gets some, until
        # a round has no error (a map load may outlast the server's time limit)
        warm_end = time.perf_counter() + 300.0
        while time.perf_counter() < warm_end:
            _l, warm_errors, _a = asyncio.run(
                _load(url, bodies, 4 * args.workers, 2 * args.workers, 120.0)
            )
            if warm_errors == 0:
                break
        cpu0 = _server_cpu_s(proc.pid)
        # The load client's own garbage collector stalls every request in flight for
        # 250-300 ms now and then (it holds the bodies and the parsed answers): measured, it
        # made the httpx client's p99 391-466 ms where the server's own p99 is ~180 ms. A load
        # generator must not time its own pauses, so the client runs with its collector off
        # (--client-gc keeps it on, to see the difference).
        if not args.client_gc:
            gc.collect()
            gc.freeze()
            gc.disable()
        t0, client0 = time.perf_counter(), time.process_time()
        try:
            lat, errors, answers = asyncio.run(
                _load(url, bodies, args.requests, args.concurrency, args.max_seconds, args.client)
            )
        finally:
            gc.enable()
            gc.unfreeze()
        wall, client_cpu_s = time.perf_counter() - t0, time.process_time() - client0
        cpu1 = _server_cpu_s(proc.pid)
        per_process = {k: v - cpu0.get(k, 0.0) for k, v in cpu1.items()}
        server_cpu_s = sum(per_process.values())
    finally:
        proc.terminate()
        proc.wait(timeout=20)
        shutil.rmtree(tmp, ignore_errors=True)
    ms = np.array(lat) * 1000.0
    result: dict[str, Any] = {
        "label": args.label,
        "scenes": "five annotators, every request a different scene",
        "workers": args.workers,
        "concurrency": args.concurrency,
        "requests": len(lat),
        "errors": errors,
        "seconds": round(wall, 3),
        "requests_per_s": round(len(lat) / wall, 1),
        # CPU the server spent per request: robust to other load on the machine; the rate two
        # idle cores could serve is 2 / this
        "server_cpu_ms_per_request": round(server_cpu_s / max(len(lat), 1) * 1000.0, 1),
        # of which the serving process (HTTP, routing, the pool's dispatch) and the workers
        "serving_cpu_ms_per_request": round(
            per_process.get(proc.pid, 0.0) / max(len(lat), 1) * 1000.0, 2
        ),
        "worker_cpu_ms_per_request": round(
            (server_cpu_s - per_process.get(proc.pid, 0.0)) / max(len(lat), 1) * 1000.0, 2
        ),
        # the load client's own CPU (it shares the cores with the server)
        "client": args.client,
        "client_gc": bool(args.client_gc),
        "client_cpu_ms_per_request": round(client_cpu_s / max(len(lat), 1) * 1000.0, 2),
        "capacity_2_cores_per_s": round(2.0 / max(server_cpu_s / max(len(lat), 1), 1e-9), 1),
        "load_average_1min": round(os.getloadavg()[0], 2),
        # how the work fell on the processes (supervisor and workers), share of the CPU
        "cpu_share_per_process": sorted(
            (round(v / max(server_cpu_s, 1e-9), 3) for v in per_process.values()), reverse=True
        ),
        "p50_ms": round(float(np.percentile(ms, 50)), 1),
        "p90_ms": round(float(np.percentile(ms, 90)), 1),
        "p99_ms": round(float(np.percentile(ms, 99)), 1),
        "aim": "≥ 100 requests/s, p99 < 150 ms on two cores",
        "cpu_count": os.cpu_count(),
        "answers": check_answers(bodies, answers, args.check),
    }
    stem = f"service_load-{args.label}" if args.label else "service_load"
    (OUT / f"{stem}.json").write_text(json.dumps(result, indent=2))
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.hist(ms, bins=60)
        for q, c in ((50, "g"), (99, "r")):
            ax.axvline(np.percentile(ms, q), color=c, label=f"p{q}")
        ax.set_xlabel("latency of POST /v1/locate (ms)")
        ax.set_ylabel("requests")
        ax.set_title(f"{result['requests_per_s']} req/s, {args.workers} workers")
        ax.legend()
        fig.tight_layout()
        fig.savefig(OUT / f"{stem}.png", dpi=110)
    except ImportError:
        pass
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
