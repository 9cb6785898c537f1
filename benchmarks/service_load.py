"""Load test of the HTTP service on loopback: requests per second and latency of /v1/locate.

Starts ``camloc serve`` (``--workers`` processes) with the bundled Baltimore extract, warms the
map cache, then sends a bounded number of requests (``--requests``, ``--concurrency`` at a
time, ``--max-seconds`` at most) and writes ``benchmarks/out/service_load.json`` and a latency
histogram PNG. Only 127.0.0.1 is contacted.

    python benchmarks/service_load.py --workers 2 --requests 2000 --concurrency 16
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import httpx
import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT = HERE / "out"


def _port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


async def _load(url: str, body: bytes, n: int, conc: int, max_s: float) -> tuple[list[float], int]:
    lat: list[float] = []
    errors = 0
    sent = 0
    t_end = time.perf_counter() + max_s
    async with httpx.AsyncClient(base_url=url, timeout=30.0) as client:

        async def one() -> None:
            nonlocal sent, errors
            while sent < n and time.perf_counter() < t_end:
                sent += 1
                t0 = time.perf_counter()
                r = await client.post(
                    "/v1/locate", content=body, headers={"content-type": "application/json"}
                )
                lat.append(time.perf_counter() - t0)
                if r.status_code != 200:
                    errors += 1

        await asyncio.gather(*(one() for _ in range(conc)))
    return lat, errors


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--requests", type=int, default=2000)
    ap.add_argument("--concurrency", type=int, default=16)
    ap.add_argument("--max-seconds", type=float, default=120.0)
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
        body = (ROOT / "sample_maps" / "sample_scene.json").read_bytes()
        for _ in range(4 * args.workers):  # every worker loads its map
            httpx.post(
                url + "/v1/locate",
                content=body,
                headers={"content-type": "application/json"},
                timeout=120,
            )
        t0 = time.perf_counter()
        lat, errors = asyncio.run(
            _load(url, body, args.requests, args.concurrency, args.max_seconds)
        )
        wall = time.perf_counter() - t0
    finally:
        proc.terminate()
        proc.wait(timeout=20)
        shutil.rmtree(tmp, ignore_errors=True)
    ms = np.array(lat) * 1000.0
    result = {
        "workers": args.workers,
        "concurrency": args.concurrency,
        "requests": len(lat),
        "errors": errors,
        "seconds": round(wall, 3),
        "requests_per_s": round(len(lat) / wall, 1),
        "p50_ms": round(float(np.percentile(ms, 50)), 1),
        "p90_ms": round(float(np.percentile(ms, 90)), 1),
        "p99_ms": round(float(np.percentile(ms, 99)), 1),
        "aim": "≥ 100 requests/s, p99 < 150 ms on two cores",
        "cpu_count": os.cpu_count(),
    }
    (OUT / "service_load.json").write_text(json.dumps(result, indent=2))
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
        fig.savefig(OUT / "service_load.png", dpi=110)
    except ImportError:
        pass
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
