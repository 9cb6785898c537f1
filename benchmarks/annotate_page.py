"""Benchmark the annotation page (``camloc annotate``): size and opening time.

Targets (issue 11): the page for a 1920x1080 JPEG stays under the image size + 1 MB and
opens in under 2 s in headless Chromium. The snapshot is the tests' synthetic Baltimore view
with photo-like grain (so the JPEG is as large as a real webcam frame); the page is built
with and without the junction map (``--osm``). Opening time: from navigation to the photo
decoded and drawn (``body[data-ready]``), median of ``--n`` loads in Debian Chromium, the
network blocked. Results: ``benchmarks/out/annotate_page.json`` and a screenshot
``benchmarks/out/annotate_page.png``::

    python benchmarks/annotate_page.py [--n 7]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from annotate_synthetic import BALTIMORE, located_case, render_snapshot  # noqa: E402

from camloc_geo.cli.annotate import junction_geojson  # noqa: E402
from camloc_geo.web import annotation_page_html  # noqa: E402

OUT = ROOT / "benchmarks" / "out"


def photo_like_jpeg() -> bytes:
    ls = located_case()
    img = cv2.imdecode(np.frombuffer(render_snapshot(ls), np.uint8), cv2.IMREAD_COLOR)
    rng = np.random.default_rng(0)
    grain = cv2.GaussianBlur(rng.normal(0, 18, img.shape).astype(np.float32), (3, 3), 0)
    img = np.clip(img.astype(np.float32) + grain, 0, 255).astype(np.uint8)
    ok, buf = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, 85])
    assert ok
    return bytes(buf)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=7)
    args = ap.parse_args()
    from playwright.sync_api import sync_playwright

    OUT.mkdir(parents=True, exist_ok=True)
    jpeg = photo_like_jpeg()
    prior = located_case().scene["prior"]
    corners = junction_geojson(lat=prior["lat"], lon=prior["lon"], map_source=str(BALTIMORE))
    results: dict[str, object] = {"image_bytes": len(jpeg), "image_size": [1920, 1080]}
    pages = {}
    for name, gj in (("plain", None), ("with_map", corners)):
        t0 = time.perf_counter()
        html = annotation_page_html(jpeg, image_name="snapshot.jpg", corners_geojson=gj)
        build_s = time.perf_counter() - t0
        path = OUT / f"annotate_page_{name}.html"
        path.write_text(html, encoding="utf-8")
        pages[name] = path
        size = len(html.encode())
        results[name] = {
            "page_bytes": size,
            "overhead_bytes": size - len(jpeg),
            "target_bytes": len(jpeg) + 1_000_000,
            "under_target": size < len(jpeg) + 1_000_000,
            "build_seconds": round(build_s, 3),
        }
    args_chromium = [
        "--no-sandbox",
        "--disable-gpu",
        "--disable-background-networking",
        "--disable-component-update",
        "--no-first-run",
        "--disable-sync",
    ]
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=args_chromium)
        for name, path in pages.items():
            times = []
            for _ in range(args.n):
                ctx = browser.new_context(viewport={"width": 1400, "height": 900})
                page = ctx.new_page()
                page.route(
                    "**/*",
                    lambda r: (
                        r.continue_() if r.request.url.startswith(("file:", "data:")) else r.abort()
                    ),
                )
                t0 = time.perf_counter()
                page.goto(path.as_uri(), wait_until="load")
                page.wait_for_selector("body[data-ready]", state="attached", timeout=10000)
                times.append(time.perf_counter() - t0)
                if name == "with_map" and len(times) == args.n:
                    page.screenshot(path=str(OUT / "annotate_page.png"))
                ctx.close()
            entry = results[name]
            assert isinstance(entry, dict)
            entry["open_seconds_median"] = round(statistics.median(times), 3)
            entry["open_seconds_max"] = round(max(times), 3)
            entry["open_target_seconds"] = 2.0
        browser.close()
    results["load_average"] = os.getloadavg()
    (OUT / "annotate_page.json").write_text(json.dumps(results, indent=2) + "\n")
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
