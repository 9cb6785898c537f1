"""Session 37 QA: ``camloc batch --map``'s offline summary page is ``maps.summary_page``'s.

The batch module used to assemble the page with its own copy of the cluster-inlining code;
it now calls :func:`camloc_geo.maps.summary_page`. These tests pin that the page is the
same (bytes, up to folium's random element ids) and that it works in Chromium: two close
cameras cluster, the plug-in is inlined, the page asks for nothing.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from camloc_geo import maps

REPO = Path(__file__).resolve().parents[1]
BALTIMORE = REPO / "sample_maps" / "baltimore.osm.pbf"
needs_browser = pytest.mark.skipif(
    not Path("/usr/bin/chromium").exists(), reason="Debian chromium is not installed"
)

LIST = """id,title,lat,lon
c1,Eastern Ave & S Broadway,39.2851,-76.5930
c2,Fleet St & S Broadway,39.2846,-76.5934
c3,Nonsense title,39.2851,-76.5930
"""


def _ids_out(page: str) -> str:
    return re.sub(r"[0-9a-f]{32}", "ID", page)


@pytest.fixture(scope="module")
def batch_page(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    base = tmp_path_factory.mktemp("qa37-batch")
    lst = base / "cams.csv"
    lst.write_text(LIST, encoding="utf-8")
    out = base / "out.gpkg"
    page = base / "summary.html"
    cmd = [sys.executable, "-m", "camloc_geo.cli", "batch", str(lst), "-o", str(out)]
    cmd += ["--map", str(page), "--osm", str(BALTIMORE), "--no-progress", "--workers", "1"]
    proc = subprocess.run(
        cmd,
        capture_output=True,
        text=True,
        timeout=600,
        cwd=base,
    )
    assert proc.returncode == 0, proc.stderr
    return {"out": out, "page": page}


def test_batch_page_is_summary_page(batch_page: dict[str, Path]) -> None:
    from camloc_geo.batch._journal import Journal
    from camloc_geo.batch._run import _summary_items

    journal = Journal(batch_page["out"].with_suffix(".camloc-batch.sqlite"))
    try:
        # session 38: the batch's extract is drawn under the cameras as a vector basemap
        expected = maps.summary_page(_summary_items(journal), map_source=BALTIMORE)
    finally:
        journal.close()
    written = batch_page["page"].read_text(encoding="utf-8")
    assert _ids_out(written) == _ids_out(expected)
    # self-contained: the cluster plug-in inlined, no CDN script or stylesheet
    assert "L.markerClusterGroup" in written
    assert ".marker-cluster-small" in written
    assert not re.search(r"<script[^>]+src=\"https?:", written)
    assert not re.search(r"<link[^>]+href=\"https?:", written)


@pytest.mark.browser
@needs_browser
def test_batch_page_clusters_in_chromium(batch_page: dict[str, Path], browser: Any) -> None:
    from test_browser_maps import _Page

    tab = _Page(browser)
    try:
        tab.open(batch_page["page"], ".leaflet-container")
        page = tab.page
        # c1 and c2 are 110 m apart: two markers at the page's first zoom (17), one cluster
        # of 2 once zoomed out
        page.wait_for_selector(".leaflet-marker-icon", timeout=30000)
        assert page.locator(".marker-cluster").count() == 0
        page.evaluate(
            "Object.keys(window).filter(k => k.startsWith('map_'))"
            ".forEach(k => window[k].setZoom(13, {animate: false}))"
        )
        page.wait_for_selector(".marker-cluster", timeout=30000)
        counts = page.locator(".marker-cluster span").all_inner_texts()
        assert "2" in [c.strip() for c in counts]
        assert tab.blocked == []
        assert tab.errors == []
    finally:
        tab.close()
