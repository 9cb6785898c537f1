"""``--verdict-url`` on ``camloc summary-map`` and ``camloc batch --map``: the same URL check as
``camloc locate`` (exit 2 before any work) and, in headless Chromium, the summary page opened
from a file reading the verdicts of a real loopback service (CORS origin ``null``) and saying
so when the service refuses the page's origin."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import httpx
import pytest
from test_service import Server
from test_service_verdicts import KEY, kserver, needs_browser  # noqa: F401 (a fixture)

CANDS = {
    "type": "FeatureCollection",
    "properties": {"scene": "cam-a"},
    "features": [
        {
            "type": "Feature",
            "geometry": {"type": "Point", "coordinates": [-76.61, 39.29]},
            "properties": {
                "kind": "candidate",
                "rank": 1,
                "lat": 39.29,
                "lon": -76.61,
                "score": 0.8,
                "heading_deg": 90.0,
            },
        }
    ],
}


def _cfg(html_text: str) -> dict[str, Any]:
    found = re.search(r"var cfg = (\{.*?\});\n", html_text)
    assert found is not None
    cfg: dict[str, Any] = json.loads(found.group(1))
    return cfg


@pytest.fixture
def cands(tmp_path: Path) -> Path:
    path = tmp_path / "cam-a.geojson"
    path.write_text(json.dumps(CANDS), encoding="utf-8")
    return path


BAD_URLS = (
    ("ftp://h", "give the service's http:// or https:// address"),
    ("http://h:99999", "not a URL"),
    ("http://h/?x=1", "no query"),
)


def test_summary_map_verdict_url_option(
    cands: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from camloc_geo.cli import main

    out = tmp_path / "summary.html"
    assert main(["summary-map", str(cands), "-o", str(out), "--inline"]) == 0
    assert _cfg(out.read_text(encoding="utf-8"))["service"] is None
    args = ["summary-map", str(cands), "-o", str(out), "--inline", "--verdict-url"]
    assert main([*args, "http://127.0.0.1:8000/camloc/"]) == 0
    cfg = _cfg(out.read_text(encoding="utf-8"))
    assert cfg["service"] == "http://127.0.0.1:8000/camloc/v1/verdicts"
    capsys.readouterr()
    missing = tmp_path / "no-such.geojson"
    for url, said in BAD_URLS:  # checked before the inputs are read: no "no such file"
        code = main(
            ["summary-map", str(missing), "-o", str(tmp_path / "x.html"), "--verdict-url", url]
        )
        assert code == 2
        err = capsys.readouterr().err
        assert f"--verdict-url {url!r}: {said}" in err
        assert "no-such" not in err
    assert not (tmp_path / "x.html").exists()


def test_batch_verdict_url_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from camloc_geo.cli import main

    calls: list[dict[str, Any]] = []

    def fake_run_batch(list_path: Any, **kw: Any) -> Any:
        calls.append(kw)
        raise SystemExit(0)

    monkeypatch.setattr("camloc_geo.batch.run_batch", fake_run_batch)
    gpkg = tmp_path / "out.gpkg"
    listing = tmp_path / "list.csv"
    listing.write_text("id,title,lat,lon\n1,A & B,39.29,-76.61\n", encoding="utf-8")
    for url, said in BAD_URLS:
        args = ["batch", str(listing), "-o", str(gpkg), "--map", str(tmp_path / "m.html")]
        assert main([*args, "--verdict-url", url]) == 2
        assert f"--verdict-url {url!r}: {said}" in capsys.readouterr().err
    assert main(["batch", str(listing), "-o", str(gpkg), "--verdict-url", "http://h"]) == 2
    assert "--verdict-url needs --map" in capsys.readouterr().err
    assert calls == []
    assert not gpkg.exists()
    args = ["batch", str(listing), "-o", str(gpkg), "--map", str(tmp_path / "m.html")]
    with pytest.raises(SystemExit):
        main([*args, "--verdict-url", "https://reviews.example.org"])
    assert calls[0]["verdict_service"] == "https://reviews.example.org/v1/verdicts"


def test_batch_page_carries_the_service(tmp_path: Path) -> None:
    """The batch page writer (offline and online) passes the endpoint to the page."""
    from camloc_geo.batch import _run

    class _J:
        pass

    items = [("cam-a", CANDS)]
    orig = _run._summary_items
    try:
        _run._summary_items = lambda journal: items  # type: ignore[assignment]
        for offline in (True, False):
            page = _run._write_summary_map(
                _J(),  # type: ignore[arg-type]
                tmp_path / f"m{offline}.html",
                offline=offline,
                verdict_service="http://127.0.0.1:9/v1/verdicts",
            )
            assert _cfg(page.read_text(encoding="utf-8"))["service"] == (
                "http://127.0.0.1:9/v1/verdicts"
            )
    finally:
        _run._summary_items = orig  # type: ignore[assignment]


@pytest.mark.browser
@needs_browser
@pytest.mark.parametrize("command", ["summary-map", "batch"])
def test_summary_page_from_a_file_shares_with_the_service(
    browser: Any,
    kserver: Server,  # noqa: F811 (the fixture imported above)
    cands: Path,
    tmp_path: Path,
    command: str,
) -> None:
    """``camloc summary-map --verdict-url``'s and ``camloc batch --map --verdict-url``'s page
    (a real one-camera batch on the sample extract) opened from a file (origin null) reads the
    service's verdicts, asks for the key on the 401 and lands the verdict with it; served from
    an origin the service does not allow, it says so."""
    from camloc_geo.cli import main

    out = tmp_path / "summary.html"
    if command == "summary-map":
        args = ["summary-map", str(cands), "-o", str(out), "--inline", "--no-cluster"]
    else:
        listing = tmp_path / "list.csv"
        listing.write_text(
            "id,title,lat,lon\na,Eastern Ave & S Broadway,39.2848,-76.5934\n", encoding="utf-8"
        )
        extract = Path(kserver.env["CAMLOC_MAP_DIR"]) / "baltimore.osm.pbf"
        args = ["batch", str(listing), "-o", str(tmp_path / "out.gpkg"), "--osm", str(extract)]
        args += ["--workers", "1", "--no-progress", "--map", str(out)]
    assert main([*args, "--verdict-url", kserver.url]) == 0
    page_html = out.read_text(encoding="utf-8")
    cfg = _cfg(page_html)
    assert cfg["service"] == kserver.url + "/v1/verdicts"
    client = httpx.Client(base_url=kserver.url, timeout=60.0)
    other = "http://localhost:8766"
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    page = context.new_page()
    sent: list[str] = []
    blocked: list[str] = []
    errors: list[str] = []

    def route(r: Any) -> None:
        u = r.request.url
        if u == other + "/summary.html":
            r.fulfill(status=200, body=page_html, content_type="text/html; charset=utf-8")
        elif u.startswith(("file:", "data:")):
            r.continue_()
        elif u.startswith(kserver.url + "/"):
            sent.append(f"{r.request.method} {u}")
            r.continue_()
        else:
            blocked.append(u)
            r.abort()

    page.route("**/*", route)
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    share = ".camloc-vshare"
    try:
        page.goto(out.as_uri(), wait_until="load")
        page.wait_for_function(
            f"document.querySelector('{share}').textContent.startsWith('shared')", timeout=30000
        )
        assert any(s.startswith("GET ") and "/v1/verdicts/summary/" in s for s in sent), sent
        page.locator('.camloc-summary-marker [data-verdict-mark="c0"]').click()
        box = page.locator(".leaflet-popup-content .camloc-verdict")
        box.locator('button[data-verdict="no"]').wait_for(timeout=30000)
        box.locator('button[data-verdict="no"]').click()
        keybox = page.locator(".camloc-verdicts form.camloc-vkey")
        keybox.wait_for(state="visible", timeout=60000)  # the 401 reached the page
        keybox.locator("input").fill(KEY)
        keybox.locator("button").click()
        page.wait_for_function(
            f"document.querySelector('{share}').textContent.startsWith('shared')", timeout=30000
        )
        items = client.get(f"/v1/verdicts/summary/{cfg['identity']}").json()["items"]
        assert [(k, v["verdict"]) for k, v in items.items()] == [("c0", "no")]
        # the same page from an origin the service does not allow: refused, and said
        page.goto(other + "/summary.html", wait_until="load")
        page.wait_for_function(
            f"document.querySelector('{share}').textContent.startsWith('not shared')",
            timeout=30000,
        )
        text = page.locator(share).inner_text()
        assert f"this page's origin ({other}) in its CAMLOC_CORS_ORIGINS?" in text, text
        assert blocked == []
        assert errors == []
    finally:
        context.close()
        client.close()
