"""CPU the HTTP layer of the service adds to a request, without the science.

``POST /v1/locate`` through the whole ASGI app in this process (httpx's ASGI transport):
middleware, routing, the API key check, parsing and validating the five-annotator scene,
the map lookup and writing the answer; the library's ``locate`` is replaced by a canned
answer (the real 58 kB candidate GeoJSON of the sample), so what is measured is what the
service itself costs. Writes ``benchmarks/out/service_overhead[-LABEL].json``.

    python benchmarks/service_overhead.py --label after
    PYTHONPATH=OLD_CHECKOUT python benchmarks/service_overhead.py --label before
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import httpx

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT = HERE / "out"
sys.path.insert(0, str(HERE))

from service_load import scene_bodies  # noqa: E402


class _Canned:
    def __init__(self, gj: dict[str, Any]) -> None:
        self.gj = gj

    def to_geojson(self) -> dict[str, Any]:
        return self.gj


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--requests", type=int, default=300)
    ap.add_argument("--label", default="")
    args = ap.parse_args()
    import camloc_geo.service.work as work
    from camloc_geo.api import locate_scene
    from camloc_geo.service import Settings, create_app

    tmp = Path(tempfile.mkdtemp(prefix="camloc-overhead-"))
    (tmp / "maps").mkdir()
    shutil.copy(ROOT / "sample_maps" / "baltimore.osm.pbf", tmp / "maps")
    bodies = scene_bodies(args.requests)
    extract = ROOT / "sample_maps" / "baltimore.osm.pbf"
    canned = _Canned(locate_scene(json.loads(bodies[0]), map_source=extract).to_geojson())
    real = work.locate_body

    def fake(data: Any, maps: Any, *, max_candidates: int | None = None) -> tuple[Any, Any]:
        from camloc_geo.api import scene_from

        scene = scene_from(data)  # what the real one does before locating
        anchor = (scene.prior.lat, scene.prior.lon) if scene.prior else (0.0, 0.0)
        return canned, maps.map_for_point(lat=anchor[0], lon=anchor[1])

    for mod in list(sys.modules.values()):
        if getattr(mod, "locate_body", None) is real:
            mod.locate_body = fake  # type: ignore[attr-defined]
    app = create_app(Settings(map_dir=tmp / "maps", data_dir=tmp / "data"))

    async def run() -> float:
        transport = httpx.ASGITransport(app=app)
        async with (
            httpx.AsyncClient(transport=transport, base_url="http://t") as client,
            app.router.lifespan_context(app),
        ):
            for b in bodies[:5]:  # map loaded, imports done
                r = await client.post(
                    "/v1/locate", content=b, headers={"content-type": "application/json"}
                )
                assert r.status_code == 200, r.text
            prof = None
            if os.environ.get("CAMLOC_PROFILE"):
                import cProfile

                prof = cProfile.Profile()
                prof.enable()
            t0 = time.process_time()
            for b in bodies:
                r = await client.post(
                    "/v1/locate", content=b, headers={"content-type": "application/json"}
                )
                assert r.status_code == 200
            took = time.process_time() - t0
            if prof is not None:
                import pstats

                prof.disable()
                pstats.Stats(prof).sort_stats("tottime").print_stats(25)
            return took

    cpu_s = asyncio.run(run())
    shutil.rmtree(tmp, ignore_errors=True)
    result = {
        "label": args.label,
        "requests": args.requests,
        "http_layer_cpu_ms_per_request": round(cpu_s / args.requests * 1000.0, 2),
        "response_bytes": len(json.dumps(canned.gj)),
        "load_average_1min": round(os.getloadavg()[0], 2),
    }
    OUT.mkdir(exist_ok=True)
    stem = f"service_overhead-{args.label}" if args.label else "service_overhead"
    (OUT / f"{stem}.json").write_text(json.dumps(result, indent=2))
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
