"""Reviewers' verdicts shared through the service: ``/v1/verdicts`` on a real ``camloc
serve`` process (loopback, httpx), the store's merge rule, and in headless Chromium a review
page served by the service sharing one reviewer's verdicts with another's browser."""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from test_service import SCENE, Server

from camloc_geo.service.models import VerdictItem, utc_text
from camloc_geo.service.verdicts import VERDICTS_FILE, VerdictStore
from camloc_geo.service.work import LimitError

IDENT = "0123456789abcdef"
URL = f"/v1/verdicts/candidates/{IDENT}"


@pytest.fixture(scope="module")
def vserver(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    tmp = tmp_path_factory.mktemp("vservice")
    # a busy machine: the first page request loads the map and locates (20 s by default)
    srv = Server(
        tmp, CAMLOC_VERDICT_DIR=str(tmp / "shared-verdicts"), CAMLOC_REQUEST_TIMEOUT_S="300"
    )
    srv.start()
    yield srv
    srv.stop()


@pytest.fixture(scope="module")
def vclient(vserver: Server) -> Iterator[httpx.Client]:
    with httpx.Client(base_url=vserver.url, timeout=60.0) as c:
        yield c


# ---------------------------------------------------------------------------- the store
def test_store_merge_latest_wins_and_limit(tmp_path: Path) -> None:
    store = VerdictStore(tmp_path / "v", max_rows=3)
    assert (tmp_path / "v" / VERDICTS_FILE).is_file()
    item = {"verdict": "yes", "rank": None, "note": "kerb", "reviewer": "Ana"}
    doc, taken = store.merge(
        "candidates", IDENT, {"2": {**item, "time": "2026-11-25T01:00:00.000Z"}}
    )
    assert taken == ["2"]
    assert doc["items"]["2"]["verdict"] == "yes"
    # an older verdict does not replace a newer one; as new or newer does
    older = {**item, "verdict": "no", "time": "2026-11-25T00:59:59.999Z"}
    _doc, taken = store.merge("candidates", IDENT, {"2": older})
    assert taken == []
    newer = {**item, "verdict": None, "reviewer": "Bo", "time": "2026-11-25T01:00:00.001Z"}
    doc, taken = store.merge("candidates", IDENT, {"2": newer})
    assert taken == ["2"]
    assert doc["items"]["2"] == {
        "verdict": None,
        "rank": None,
        "note": "kerb",
        "reviewer": "Bo",
        "time": "2026-11-25T01:00:00.001Z",
        "camera": "",
        "lat": None,
        "lon": None,
    }
    # other pages are apart; the store holds at most max_rows
    assert store.page("summary", IDENT)["items"] == {}
    store.merge("summary", IDENT, {"c0": {**item, "time": "2026-11-25T02:00:00.000Z"}})
    with pytest.raises(LimitError, match="at most 3 verdicts"):
        store.merge("summary", IDENT, {"c1": {**item, "time": "t"}, "c2": {**item, "time": "t"}})
    assert [p["page"] for p in store.pages()] == ["summary", "candidates"]
    assert [p["verdicts"] for p in store.pages()] == [1, 0]


def test_verdict_item_time_rules() -> None:
    from datetime import datetime, timezone

    now = datetime(2026, 11, 25, 2, 0, tzinfo=timezone.utc)
    given = VerdictItem.model_validate({"verdict": "no", "time": "2026-11-25T03:00:00+02:00"})
    assert given.stored(now)["time"] == "2026-11-25T01:00:00.000Z"
    naive = VerdictItem.model_validate({"verdict": "no", "time": "2026-11-25T01:30:00"})
    assert naive.stored(now)["time"] == "2026-11-25T01:30:00.000Z"
    future = VerdictItem.model_validate({"verdict": "no", "time": "2027-01-01T00:00:00Z"})
    assert future.stored(now)["time"] == utc_text(now)  # a clock far ahead: taken as now
    assert VerdictItem.model_validate({}).stored(now)["time"] == "2026-11-25T02:00:00.000Z"


# ----------------------------------------------------------------------------- the API
def test_verdicts_endpoints_share_and_persist(vserver: Server, vclient: httpx.Client) -> None:
    r = vclient.get(URL)
    assert r.status_code == 200, r.text
    assert r.json() == {"page": "candidates", "identity": IDENT, "items": {}}
    body = {
        "items": {
            "1": {
                "verdict": "no",
                "note": "wrong street",
                "reviewer": "Ana",
                "time": "2026-11-25T01:00:00.000Z",
            },
            "2": {"verdict": "yes", "reviewer": "Ana", "time": "2026-11-25T01:00:01.000Z"},
        }
    }
    r = vclient.post(URL, json=body)
    assert r.status_code == 200, r.text
    assert sorted(r.json()["taken"]) == ["1", "2"]
    # another reviewer, later: withdraws 2; an out-of-date copy of 1 is not taken
    r = vclient.post(
        URL,
        json={
            "items": {
                "2": {"verdict": None, "reviewer": "Bo", "time": "2026-11-25T01:05:00Z"},
                "1": {"verdict": "unsure", "reviewer": "Bo", "time": "2026-11-25T00:00:00Z"},
            }
        },
    )
    assert r.status_code == 200, r.text
    assert r.json()["taken"] == ["2"]
    items = vclient.get(URL).json()["items"]
    assert {k: (v["verdict"], v["reviewer"], v["note"]) for k, v in items.items()} == {
        "1": ("no", "Ana", "wrong street"),
        "2": (None, "Bo", ""),
    }
    assert items["2"]["time"] == "2026-11-25T01:05:00.000Z"
    pages = vclient.get("/v1/verdicts").json()["pages"]
    assert {
        "page": "candidates",
        "identity": IDENT,
        "verdicts": 1,
        "latest": "2026-11-25T01:05:00.000Z",
    } in pages
    # kept in the folder named by CAMLOC_VERDICT_DIR, and across a restart
    folder = Path(vserver.env["CAMLOC_VERDICT_DIR"])
    assert (folder / VERDICTS_FILE).is_file()
    vserver.stop()
    vserver.start()
    with httpx.Client(base_url=vserver.url, timeout=60.0) as again:
        assert again.get(URL).json()["items"] == items


def test_verdicts_export_reads_back(vclient: httpx.Client, tmp_path: Path) -> None:
    """``?format=csv|geojson``: the page's own export, which read_verdicts (and so
    summary-map/locate --verdicts) takes."""
    from camloc_geo import maps

    url = "/v1/verdicts/summary/00000000000000aa"
    item = {"reviewer": "Ana", "camera": "=cam 7", "lat": -32.05, "lon": 115.74}
    r = vclient.post(
        url,
        json={
            "items": {
                "c10": {**item, "verdict": "yes", "rank": 3, "note": 'kerb, "the" tree'},
                "c2": {**item, "verdict": "no", "rank": 1, "camera": "cam 2", "lat": None},
                "c3": {**item, "verdict": None, "camera": "cam 3"},
            }
        },
    )
    assert r.status_code == 200, r.text
    r = vclient.get(url, params={"format": "csv"})
    assert r.status_code == 200, r.text
    assert r.headers["content-type"].startswith("text/csv")
    assert 'filename="verdicts-summary-00000000.csv"' in r.headers["content-disposition"]
    assert r.content.startswith(b"\xef\xbb\xbf")  # a BOM, as the pages write
    assert "'=cam 7" in r.text  # the formula guard
    path = tmp_path / "server.csv"
    path.write_bytes(r.content)
    rows = maps.read_verdicts(path)
    assert [(x["camera"], x["rank"], x["verdict"], x["lat"]) for x in rows] == [
        ("cam 2", 1, "no", None),  # key order c2, c10; the withdrawn c3 left out
        ("=cam 7", 3, "yes", -32.05),
    ]
    assert rows[1]["note"] == 'kerb, "the" tree'
    assert rows[1]["page"] == "summary"
    assert rows[1]["identity"] == "00000000000000aa"
    r = vclient.get(url, params={"format": "geojson"})
    assert r.status_code == 200, r.text
    doc = r.json()
    assert doc["properties"]["format"] == "camloc-verdicts/1"
    assert doc["features"][0]["geometry"] is None
    assert doc["features"][1]["geometry"]["coordinates"] == [115.74, -32.05]
    gpath = tmp_path / "server.geojson"
    gpath.write_bytes(r.content)
    assert maps.read_verdicts(gpath) == rows


@pytest.mark.parametrize(
    ("method", "path", "body", "field"),
    [
        ("GET", "/v1/verdicts/review/0123456789abcdef", None, "page"),
        ("GET", "/v1/verdicts/candidates/0123", None, "identity"),
        ("GET", "/v1/verdicts/candidates/0123456789ABCDEF", None, "identity"),
        ("POST", URL, {"items": {"rank2": {"verdict": "yes"}}}, "items.rank2.[key]"),
        ("POST", URL, {"items": {"2": {"verdict": "maybe"}}}, "items.2.verdict"),
        ("POST", URL, {"items": {"2": {"verdict": "yes", "note": "x" * 201}}}, "items.2.note"),
        ("POST", URL, {"items": {"2": {"verdict": "yes", "mood": "ok"}}}, "items.2.mood"),
        ("POST", URL, {"items": {"2": {"time": "yesterday"}}}, "items.2.time"),
        ("POST", URL, {"items": {"2": {"rank": 0}}}, "items.2.rank"),
        ("POST", URL, {"items": {"2": {"note": "\ud800"}}}, "items.2.note"),
        ("POST", URL, {"items": []}, "items"),
        ("POST", URL, [1, 2], "request"),
        ("GET", "/v1/verdicts?limit=0", None, "limit"),
        ("GET", URL + "?format=xml", None, "format"),
        ("POST", URL, {"items": {"2": {"lat": 95}}}, "items.2.lat"),
        ("POST", URL, {"items": {"2": {"camera": "x" * 301}}}, "items.2.camera"),
    ],
)
def test_verdicts_bad_input_is_a_clear_422(
    vclient: httpx.Client, method: str, path: str, body: Any, field: str
) -> None:
    # (ASCII JSON: a lone surrogate goes as its escape, as a browser may send it)
    content = None if body is None else json.dumps(body, ensure_ascii=True).encode()
    r = vclient.request(method, path, content=content, headers={"content-type": "application/json"})
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["type"] == "invalid_input"
    assert err["field"] == field, err


def test_verdicts_bad_bodies(vclient: httpx.Client) -> None:
    r = vclient.post(
        URL, content=b'{"items": {"2": {"lat": NaN}}}', headers={"content-type": "application/json"}
    )
    assert r.status_code == 422, r.text
    assert r.json()["error"]["field"] == "items.2.lat"
    r = vclient.post(URL, content=b"{not json", headers={"content-type": "application/json"})
    assert r.status_code == 422, r.text
    assert "JSON" in r.json()["error"]["message"]
    r = vclient.post(URL, content=b"items", headers={"content-type": "text/plain"})
    assert 400 <= r.status_code < 500, r.text
    r = vclient.put(URL, json={"items": {}})
    assert r.status_code == 405
    assert r.json()["error"]["type"] == "method_not_allowed"


def test_serve_verdict_dir_option(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from camloc_geo.cli import main

    afile = tmp_path / "a-file"
    afile.write_text("x", encoding="utf-8")
    assert main(["serve", "--verdict-dir", str(afile)]) == 2
    assert f"--verdict-dir {afile}: not a folder" in capsys.readouterr().err
    assert main(["serve", "--verdict-dir", str(tmp_path / "no" / "such")]) == 2
    assert "its parent folder does not exist" in capsys.readouterr().err


# ---------------------------------------------------------------------------- browser
needs_browser = pytest.mark.skipif(
    not Path("/usr/bin/chromium").exists(), reason="Debian chromium is not installed"
)


def _click_for_popup(marker: Any, popup: Any) -> None:
    """Click a marker for its popup; once more if that popup did not come within 3 s.

    Under a loaded machine (7 sessions on 2 CPUs) the click on rank 1 while rank 2's popup
    was open once opened nothing in 30 s (as test_browser_maps' click_for_popup says of
    freshly loaded pages). What the popup does is asserted as before.
    """
    marker.click()
    try:
        popup.wait_for(timeout=3000)
    except Exception:  # playwright's TimeoutError
        if popup.count() == 0:
            marker.click()


class _Reviewer:
    """One reviewer's browser (own storage) on a page served at the service's origin; any
    request to another origin is aborted and recorded."""

    def __init__(self, browser: Any, origin: str, html_text: str, name: str) -> None:
        self.context = browser.new_context(viewport={"width": 1400, "height": 900})
        self.page = self.context.new_page()
        self.origin = origin
        self.url = origin + "/review-page-test"
        self.html = html_text
        self.blocked: list[str] = []
        self.errors: list[str] = []
        self.sent: list[str] = []
        self.page.route("**/*", self._route)
        self.page.on("pageerror", lambda exc: self.errors.append(f"pageerror: {exc}"))
        self.page.on("request", lambda req: self.sent.append(f"{req.method} {req.url}"))
        self.name = name

    def _route(self, route: Any) -> None:
        url = route.request.url
        if url == self.url:  # the page as the service served it (POST /v1/maps)
            route.fulfill(status=200, body=self.html, content_type="text/html; charset=utf-8")
        elif url.startswith((self.origin + "/", "data:")):
            route.continue_()
        else:
            self.blocked.append(url)
            route.abort()

    def open(self) -> None:
        self.page.goto(self.url, wait_until="load")
        self.page.wait_for_selector(".camloc-verdicts .camloc-vshare", timeout=30000)
        self.page.wait_for_function(
            "document.querySelector('.camloc-vshare').textContent.startsWith('shared')",
            timeout=30000,
        )

    def close(self) -> None:
        self.context.close()


@pytest.fixture(scope="module")
def served_page(vclient: httpx.Client) -> str:
    r = vclient.post("/v1/maps", json=SCENE)
    assert r.status_code == 200, r.text
    assert '"service": "/v1/verdicts"' in r.text
    return r.text


@pytest.mark.browser
@needs_browser
def test_served_page_shares_verdicts_between_reviewers(
    browser: Any, vserver: Server, vclient: httpx.Client, served_page: str, tmp_path: Path
) -> None:
    found = re.search(r"var cfg = (\{.*?\});\n", served_page)
    assert found is not None
    cfg = json.loads(found.group(1))
    url = f"/v1/verdicts/candidates/{cfg['identity']}"
    ana = _Reviewer(browser, vserver.url, served_page, "Ana")
    bo = _Reviewer(browser, vserver.url, served_page, "Bo")
    try:
        ana.open()
        page = ana.page
        page.locator(".camloc-verdicts button.camloc-vfold").click()  # unfold if folded
        if not page.locator(".camloc-verdicts input").is_visible():
            page.locator(".camloc-verdicts button.camloc-vfold").click()
        page.locator(".camloc-verdicts input").fill("Ana")
        page.locator('.camloc-candidate [data-rank="2"]').click()
        box = page.locator(".leaflet-popup-content .camloc-verdict")
        box.locator('button[data-verdict="yes"]').wait_for(timeout=30000)
        box.locator('button[data-verdict="yes"]').click()
        box.locator("input").fill("lamp post")
        page.wait_for_function(
            "document.querySelector('.camloc-vshare').textContent === "
            "'shared with the service (1 there)'",
            timeout=30000,
        )
        deadline_items: dict[str, Any] = {}
        for _ in range(50):  # the note goes 600 ms after the last key
            deadline_items = vclient.get(url).json()["items"]
            if deadline_items.get("2", {}).get("note") == "lamp post":
                break
            page.wait_for_timeout(100)
        assert deadline_items["2"]["verdict"] == "yes"
        assert deadline_items["2"]["reviewer"] == "Ana"
        assert deadline_items["2"]["note"] == "lamp post"
        # Bo's browser (no storage of Ana's) sees it; his "no" on 1 reaches the service
        bo.open()
        n = len(cfg["order"])
        bo.page.wait_for_function(
            f"document.querySelector('.camloc-vcount').textContent === '1 of {n} candidates "
            "reviewed'",
            timeout=30000,
        )
        assert (
            bo.page.locator('.camloc-candidate [data-verdict-mark="2"]').get_attribute(
                "data-verdict"
            )
            == "yes"
        )
        bo.page.locator('.camloc-candidate [data-rank="1"]').click()
        bbox = bo.page.locator(".leaflet-popup-content .camloc-verdict")
        bbox.locator('button[data-verdict="no"]').wait_for(timeout=30000)
        bbox.locator('button[data-verdict="no"]').click()
        marked_no = (
            "document.querySelector('.camloc-candidate [data-verdict-mark=\"1\"]')"
            ".getAttribute('data-verdict') === 'no'"
        )
        try:
            bo.page.wait_for_function(marked_no, timeout=5000)
        except Exception:  # playwright's TimeoutError
            # a click on a freshly loaded page is now and then lost on a loaded machine (as
            # test_browser_maps' click_for_popup says; once in a clean-clone CI run here):
            # once more only if the verdict did not take
            if not bo.page.evaluate(marked_no):
                bbox.locator('button[data-verdict="no"]').click()
        bo.page.wait_for_function(
            "document.querySelector('.camloc-vshare').textContent === "
            "'shared with the service (2 there)'",
            timeout=30000,
        )
        assert vclient.get(url).json()["items"]["1"]["verdict"] == "no"
        # the service's export is the page's: the camera and the candidates' points came along
        from camloc_geo import maps

        csv_path = tmp_path / "team.csv"
        csv_path.write_bytes(vclient.get(url, params={"format": "csv"}).content)
        rows = maps.read_verdicts(csv_path)
        assert [(r["camera"], r["rank"], r["verdict"], r["reviewer"]) for r in rows] == [
            (cfg["items"]["1"]["camera"], 1, "no", ""),
            (cfg["items"]["2"]["camera"], 2, "yes", "Ana"),
        ]
        assert rows[1]["lat"] == pytest.approx(cfg["items"]["2"]["lat"], abs=1e-9)
        assert rows[1]["lon"] == pytest.approx(cfg["items"]["2"]["lon"], abs=1e-9)
        # Ana's page takes Bo's verdict when she comes back to it
        page.evaluate("window.dispatchEvent(new Event('focus'))")
        page.wait_for_function(
            "document.querySelector('[data-verdict-mark=\"1\"]').getAttribute('data-verdict')"
            " === 'no'",
            timeout=30000,
        )
        page.screenshot(path=str(tmp_path / "shared.png"))
        for r in (ana, bo):
            assert r.blocked == []
            assert r.errors == []
            assert all(
                s.startswith(("GET " + vserver.url, "POST " + vserver.url)) for s in r.sent
            ), r.sent
    finally:
        ana.close()
        bo.close()


@pytest.mark.browser
@needs_browser
def test_served_page_saved_as_a_file_makes_no_request(
    browser: Any, served_page: str, tmp_path: Path
) -> None:
    from test_browser_maps import _Page

    path = tmp_path / "review.html"
    path.write_text(served_page, encoding="utf-8")
    t = _Page(browser)
    try:
        t.open(path, ".camloc-verdicts .camloc-vcount")
        page = t.page
        page.locator('.camloc-candidate [data-rank="1"]').click()
        box = page.locator(".leaflet-popup-content .camloc-verdict")
        box.locator('button[data-verdict="no"]').wait_for(timeout=30000)
        box.locator('button[data-verdict="no"]').click()
        page.wait_for_timeout(300)
        assert page.locator(".camloc-vcount").inner_text().startswith("1 of ")
        assert page.locator(".camloc-vshare").count() == 0
        assert t.blocked == []
        assert t.errors == []
    finally:
        t.close()


@pytest.mark.browser
@needs_browser
def test_verdicts_given_before_the_service_was_reached_are_sent(
    browser: Any, vserver: Server, vclient: httpx.Client, served_page: str
) -> None:
    """A browser that already holds verdicts of the page (given while the service was not
    reachable) sends them when it reads the service's; an older one the service has newer
    is taken from the service instead."""
    found = re.search(r"var cfg = (\{.*?\});\n", served_page)
    assert found is not None
    cfg = json.loads(found.group(1))
    url = f"/v1/verdicts/candidates/{cfg['identity']}"
    r = vclient.post(
        url,
        json={"items": {"5": {"verdict": "no", "reviewer": "Bo", "time": "2026-11-25T01:00:00Z"}}},
    )
    assert r.status_code == 200, r.text
    key = f"camloc-verdicts/v1/candidates/{cfg['identity']}"
    local = {
        "items": {
            "4": {"verdict": "unsure", "note": "offline", "time": "2026-11-25T01:30:00.000Z"},
            "5": {"verdict": "yes", "time": "2026-11-24T00:00:00.000Z"},  # older than Bo's
        }
    }
    cy = _Reviewer(browser, vserver.url, served_page, "Cy")
    try:
        cy.page.add_init_script(
            f"window.localStorage.setItem({json.dumps(key)}, {json.dumps(json.dumps(local))});"
        )
        cy.open()
        items: dict[str, Any] = {}
        for _ in range(50):
            items = vclient.get(url).json()["items"]
            if "4" in items:
                break
            cy.page.wait_for_timeout(100)
        assert items["4"]["verdict"] == "unsure"
        assert items["4"]["note"] == "offline"
        assert items["4"]["time"] == "2026-11-25T01:30:00.000Z"
        assert items["5"]["verdict"] == "no"  # the service's newer one stays
        cy.page.wait_for_function(
            "document.querySelector('[data-verdict-mark=\"5\"]').getAttribute('data-verdict')"
            " === 'no'",
            timeout=30000,
        )
        assert cy.blocked == []
        assert cy.errors == []
    finally:
        cy.close()


# ------------------------------------------------------------- a job's summary page
@pytest.fixture(scope="module")
def job_page(vclient: httpx.Client) -> dict[str, Any]:
    import time

    cams = [
        {"id": "good", "scene": SCENE},
        {"id": "c1", "title": "Eastern Ave & S Broadway", "lat": 39.2856, "lon": -76.5935},
        {"id": "nothing"},
    ]
    r = vclient.post("/v1/jobs", json={"cameras": cams})
    assert r.status_code == 202, r.text
    job_id = r.json()["id"]
    deadline = time.monotonic() + 90
    st: dict[str, Any] = {}
    while time.monotonic() < deadline:
        st = vclient.get(f"/v1/jobs/{job_id}").json()
        if st["status"] == "done":
            break
        time.sleep(0.3)
    assert st["status"] == "done", st
    assert st["map_url"] == f"/v1/jobs/{job_id}/map"
    r = vclient.get(st["map_url"])
    assert r.status_code == 200, r.text
    assert r.headers["content-type"].startswith("text/html")
    found = re.search(r"var cfg = (\{.*?\});\n", r.text)
    assert found is not None
    return {"html": r.text, "cfg": json.loads(found.group(1)), "job": job_id}


def test_job_map_is_a_shared_summary_page(vclient: httpx.Client, job_page: dict[str, Any]) -> None:
    cfg = job_page["cfg"]
    assert cfg["kind"] == "summary"
    assert cfg["service"] == "/v1/verdicts"
    cameras = {it["camera"]: it for it in cfg["items"].values()}
    assert set(cameras) == {"good", "c1 Eastern Ave & S Broadway"}  # 'nothing' has no point
    assert cameras["good"]["others"]  # the good camera's other candidates to pick from
    assert "1 without candidates" in job_page["html"]
    from test_maps import remote_references

    assert remote_references(job_page["html"]) == []  # an offline page
    # clustered (session 37): the cluster plug-in is inlined, not fetched; no basemap
    html_text = job_page["html"]
    assert "L.markerClusterGroup(" in html_text
    assert "markercluster" not in " ".join(re.findall(r'(?:src|href)="([^"]+)"', html_text))
    assert "MarkerClusterGroup" in html_text.split("L.markerClusterGroup(")[0]  # inlined JS
    assert "marker-cluster-small" in html_text  # its stylesheet too
    assert "maxZoom: 22" in html_text  # (the cluster plug-in needs one without tiles)
    assert "L.tileLayer(" not in html_text
    r = vclient.get("/v1/jobs/" + "0" * 32 + "/map")
    assert r.status_code == 404
    assert r.json()["error"]["type"] == "not_found"


def _show_marker(page: Any, key: str) -> None:
    """Zoom the summary page's cluster layer until camera ``key``'s marker is out of its
    cluster (its cameras are clustered at the page's first view when they lie close)."""
    page.evaluate(
        """(key) => new Promise((done) => {
            const name = Object.keys(window).find(
                (k) => k.startsWith("map_") && window[k] instanceof L.Map);
            window[name].eachLayer((group) => {
                if (typeof group.zoomToShowLayer !== "function") { return; }
                const m = group.getLayers().find((l) => (l.options.icon.options.html || "")
                    .includes('data-verdict-mark="' + key + '"'));
                if (m) { group.zoomToShowLayer(m, done); }
            });
        })""",
        key,
    )
    page.locator(f'.camloc-summary-marker [data-verdict-mark="{key}"]').wait_for(timeout=30000)


@pytest.mark.browser
@needs_browser
def test_job_map_reviewers_share_a_pick(
    browser: Any, vserver: Server, vclient: httpx.Client, job_page: dict[str, Any], tmp_path: Path
) -> None:
    cfg = job_page["cfg"]
    key = next(k for k, it in cfg["items"].items() if it["camera"] == "good")
    third = next(o for o in cfg["items"][key]["others"] if o[0] == 3)
    ana = _Reviewer(browser, vserver.url, job_page["html"], "Ana")
    bo = _Reviewer(browser, vserver.url, job_page["html"], "Bo")
    try:
        ana.open()
        _show_marker(ana.page, key)
        marker = ana.page.locator(f'.camloc-summary-marker [data-verdict-mark="{key}"]')
        marker.click()
        box = ana.page.locator(".leaflet-popup-content .camloc-verdict")
        box.locator("select").wait_for(timeout=30000)
        box.locator("select").select_option("3")
        ana.page.wait_for_function(
            "document.querySelector('.camloc-vshare').textContent === "
            "'shared with the service (1 there)'",
            timeout=30000,
        )
        bo.open()
        bo.page.wait_for_function(
            "document.querySelector('.camloc-vcount').textContent === '1 of 2 cameras reviewed'",
            timeout=30000,
        )
        _show_marker(bo.page, key)
        bo.page.locator(f'.camloc-summary-marker [data-verdict-mark="{key}"]').click()
        bbox = bo.page.locator(".leaflet-popup-content .camloc-verdict")
        bbox.locator("select").wait_for(timeout=30000)
        assert bbox.locator("select").input_value() == "3"  # Ana's pick, on Bo's page
        bo.page.wait_for_timeout(600)  # (the popup's fade-in and pan, for the screenshot)
        bo.page.screenshot(path=str(tmp_path / "job-map.png"))
        csv_path = tmp_path / "job.csv"
        url = f"/v1/verdicts/summary/{cfg['identity']}"
        csv_path.write_bytes(vclient.get(url, params={"format": "csv"}).content)
        from camloc_geo import maps

        rows = maps.read_verdicts(csv_path)
        assert [(r["camera"], r["rank"], r["verdict"]) for r in rows] == [("good", 3, "yes")]
        assert rows[0]["lat"] == pytest.approx(third[1], abs=1e-9)
        assert rows[0]["lon"] == pytest.approx(third[2], abs=1e-9)
        for r in (ana, bo):
            assert r.blocked == []
            assert r.errors == []
    finally:
        ana.close()
        bo.close()


@pytest.mark.browser
@needs_browser
def test_job_map_clusters_count_the_verdicts(
    browser: Any, vserver: Server, vclient: httpx.Client, job_page: dict[str, Any], tmp_path: Path
) -> None:
    """The served job page clusters its cameras, the cluster icon counting the verdicts
    inside (as ``camloc batch --map``'s page), with no request but the service's."""
    cfg = job_page["cfg"]
    key = next(k for k, it in cfg["items"].items() if it["camera"].startswith("c1 "))
    mapvar = re.search(r"var (map_[0-9a-f]+) = L\.map\(", job_page["html"])
    assert mapvar is not None
    ana = _Reviewer(browser, vserver.url, job_page["html"], "Ana")
    try:
        ana.open()
        page = ana.page
        # session 38: the two cameras (tens of metres apart) are two markers at the page's
        # first view, not one cluster a reviewer must click; zoomed out they cluster (below)
        cluster = page.locator(".marker-cluster.camloc-cluster")
        page.locator(".camloc-summary-marker").first.wait_for(timeout=30000)
        assert cluster.count() == 0
        assert page.locator(".camloc-summary-marker").count() == 2
        _show_marker(page, key)
        page.locator(f'.camloc-summary-marker [data-verdict-mark="{key}"]').click()
        box = page.locator(f'.leaflet-popup-content .camloc-verdict[data-verdict-key="{key}"]')
        box.locator('button[data-verdict="no"]').wait_for(timeout=30000)
        box.locator('button[data-verdict="no"]').click()
        page.wait_for_function(
            "document.querySelector('.camloc-vshare').textContent.startsWith("
            "'shared with the service')",
            timeout=30000,
        )
        page.evaluate(f"{mapvar.group(1)}.closePopup(); {mapvar.group(1)}.setZoom(11)")
        cluster.first.wait_for(timeout=30000)
        assert cluster.count() == 1
        assert cluster.locator("div > span").inner_text() == "2"
        badge = cluster.locator(".camloc-cbadge")
        page.wait_for_function(
            "(document.querySelector('.camloc-cluster .camloc-cbadge') || {}).textContent"
            " && document.querySelector('.camloc-cluster .camloc-cbadge').textContent"
            ".includes('\u27171')",
            timeout=30000,
        )
        assert "\u27171" in badge.inner_text()  # c1's "no"
        # (inside the cluster: gone once the zoom's animation is over)
        page.locator(".camloc-summary-marker").first.wait_for(state="detached", timeout=30000)
        page.screenshot(path=str(tmp_path / "job-clusters.png"))
        # zoomed in again, the marker comes back with its badge
        _show_marker(page, key)
        mark = page.locator(f'.camloc-summary-marker [data-verdict-mark="{key}"]')
        assert mark.get_attribute("data-verdict") == "no"
        assert ana.blocked == []
        assert ana.errors == []
    finally:
        ana.close()


TILES = "https://tiles.example.test/{z}/{x}/{y}.png"
_CAMS = [
    {
        "id": f"t{i}",
        "title": f"title {i}",
        "lat": 39.2856 + 0.0004 * i,
        "lon": -76.5935,
        "status": "title_only",
        "method": "title",
        "score": 0.4,
    }
    for i in range(4)
] + [{"id": "none", "status": "no_candidates", "reason": "no junction"}]


def test_job_summary_page_basemap_only_when_configured(monkeypatch: pytest.MonkeyPatch) -> None:
    from camloc_geo.service.routers.jobs import job_summary_page
    from camloc_geo.service.settings import Settings

    plain = job_summary_page(_CAMS)
    assert "L.tileLayer(" not in plain
    assert "tiles.example" not in plain
    page = job_summary_page(_CAMS, TILES, "© Tiles & Co <b>")
    assert page.count("L.tileLayer(") == 1
    assert json.dumps(TILES) in page
    # the attribution is text, not markup (escaped, then written as JSON)
    assert '"attribution": "\\u00a9 Tiles \\u0026amp; Co \\u0026lt;b\\u0026gt;"' in page
    assert "L.markerClusterGroup(" in page
    srcs = re.findall(r'<(?:script|link)\b[^>]*(?:src|href)="([^"]+)"', page)
    assert srcs == []  # Leaflet and the cluster plug-in inlined: the tiles are the requests
    assert "basemap: tiles.example.test" in job_summary_page(_CAMS, TILES)  # default credit
    monkeypatch.setenv("CAMLOC_TILE_URL", TILES)
    assert Settings().tile_url == TILES
    monkeypatch.delenv("CAMLOC_TILE_URL")
    assert Settings().tile_url is None  # the default: no basemap
    for bad, said in (
        ("tiles.example.test/{z}/{x}/{y}.png", "must start with https://"),
        ("https://tiles.example.test/{z}/{x}.png", "missing {y}"),
        ('https://t.example/{z}/{x}/{y}.png"', "not a URL template"),
    ):
        monkeypatch.setenv("CAMLOC_TILE_URL", bad)
        with pytest.raises(ValueError, match=re.escape(said)):
            Settings()


@pytest.mark.browser
@needs_browser
def test_job_summary_page_basemap_in_chromium(browser: Any, tmp_path: Path) -> None:
    """With a tile URL the page asks for its tiles there, and for nothing else."""
    import base64

    from camloc_geo.service.routers.jobs import job_summary_page

    png = base64.b64decode(
        "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg=="
    )
    path = tmp_path / "job.html"
    path.write_text(job_summary_page(_CAMS, TILES), encoding="utf-8")
    context = browser.new_context(viewport={"width": 1000, "height": 700})
    page = context.new_page()
    tiles: list[str] = []
    other: list[str] = []
    errors: list[str] = []

    def route(r: Any) -> None:
        url = r.request.url
        if url.startswith("https://tiles.example.test/"):
            tiles.append(url)
            r.fulfill(status=200, body=png, content_type="image/png")
        elif url.startswith(("file:", "data:")):
            r.continue_()
        else:
            other.append(url)
            r.abort()

    page.route("**/*", route)
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    try:
        page.goto(path.as_uri(), wait_until="load")
        page.wait_for_selector(".leaflet-tile-loaded", timeout=30000)
        assert tiles
        assert all(re.fullmatch(r"https://tiles\.example\.test/\d+/\d+/\d+\.png", u) for u in tiles)
        assert (
            "basemap: tiles.example.test"
            in page.locator(".leaflet-control-attribution").inner_text()
        )
        assert other == []
        assert errors == []
    finally:
        context.close()


# ------------------------------------------------------ session 37: changes need the key
KEY = "s3cret-key"
PAGES = "http://localhost:8765"  # the origin kserver lets share verdicts (and null: files)


@pytest.fixture(scope="module")
def kserver(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    """A server with ``CAMLOC_API_KEY``: verdict changes need ``X-API-Key``."""
    tmp = tmp_path_factory.mktemp("kservice")
    srv = Server(
        tmp,
        CAMLOC_API_KEY=KEY,
        CAMLOC_REQUEST_TIMEOUT_S="300",
        CAMLOC_CORS_ORIGINS=f"{PAGES},null",
    )
    srv.start()
    yield srv
    srv.stop()


def test_verdict_changes_need_the_key_reads_stay_open(kserver: Server) -> None:
    body = {"items": {"3": {"verdict": "yes", "reviewer": "Ana"}}}
    with httpx.Client(base_url=kserver.url, timeout=60.0) as c:
        for headers in ({}, {"X-API-Key": "wrong"}, {"X-API-Key": ""}):
            r = c.post(URL, json=body, headers=headers)
            assert r.status_code == 401, (headers, r.text)
            assert r.json()["error"] == {
                "type": "unauthorized",
                "message": "missing or wrong X-API-Key",
                "field": "X-API-Key",
            }
        assert c.get(URL).json()["items"] == {}  # nothing was stored
        r = c.post(URL, json=body, headers={"X-API-Key": KEY})
        assert r.status_code == 200, r.text
        assert r.json()["taken"] == ["3"]
        # reads need no key: the page, its export, the list
        assert c.get(URL).json()["items"]["3"]["verdict"] == "yes"
        assert c.get(URL, params={"format": "csv"}).status_code == 200
        assert c.get("/v1/verdicts").status_code == 200
        # the refusal comes before the body is looked at: a bad body without the key is 401
        assert c.post(URL, json={"items": {"x": 1}}).status_code == 401
        spec = c.get("/openapi.json").json()
        op = spec["paths"]["/v1/verdicts/{page}/{identity}"]["post"]
        assert any(p["name"].lower() == "x-api-key" for p in op["parameters"])
        assert "401" in op["responses"]


@pytest.mark.browser
@needs_browser
def test_served_page_asks_for_the_key_once_and_says_a_refusal(
    browser: Any, kserver: Server, served_page: str, tmp_path: Path
) -> None:
    """A reviewer on a server with a key: the first change is refused (401) and the page
    says so and asks for the key; with a wrong key it asks again; with the right one the
    verdict given before reaches the service, and the next change goes without asking."""
    found = re.search(r"var cfg = (\{.*?\});\n", served_page)
    assert found is not None
    cfg = json.loads(found.group(1))
    url = f"/v1/verdicts/candidates/{cfg['identity']}"
    client = httpx.Client(base_url=kserver.url, timeout=60.0)
    ana = _Reviewer(browser, kserver.url, served_page, "Ana")
    try:
        ana.open()
        page = ana.page
        share = page.locator(".camloc-vshare")
        keybox = page.locator(".camloc-verdicts form.camloc-vkey")
        assert not keybox.is_visible()  # not asked before a change is refused
        page.locator('.camloc-candidate [data-rank="2"]').click()
        box = page.locator(".leaflet-popup-content .camloc-verdict")
        box.locator('button[data-verdict="yes"]').wait_for(timeout=30000)
        box.locator('button[data-verdict="yes"]').click()
        keybox.wait_for(state="visible", timeout=30000)
        text = share.inner_text()
        assert "refused (401: missing or wrong X-API-Key)" in text, text
        assert "kept in this browser only" in text
        assert share.get_attribute("class") == "camloc-vshare bad"
        assert "needs its API key" in keybox.inner_text()
        assert client.get(url).json()["items"] == {}
        page.screenshot(path=str(tmp_path / "asks-key.png"))
        # a wrong key: refused again, asked again
        keybox.locator("input").fill("nope")
        keybox.locator("button").click()
        page.wait_for_function(
            "document.querySelector('.camloc-vkey').textContent.includes('refused that key')",
            timeout=30000,
        )
        assert keybox.is_visible()
        assert client.get(url).json()["items"] == {}
        # the right key: the verdict given before is sent
        keybox.locator("input").fill(KEY)
        keybox.locator("button").click()
        page.wait_for_function(
            "document.querySelector('.camloc-vshare').textContent === "
            "'shared with the service (1 there)'",
            timeout=30000,
        )
        assert not keybox.is_visible()
        assert client.get(url).json()["items"]["2"]["verdict"] == "yes"
        # the next change goes at once, with the key kept for the session
        box1 = page.locator('.leaflet-popup-content .camloc-verdict[data-verdict-key="1"]')
        _click_for_popup(page.locator('.camloc-candidate [data-rank="1"]'), box1)
        box1.locator('button[data-verdict="no"]').wait_for(timeout=30000)
        box1.locator('button[data-verdict="no"]').click()
        page.wait_for_function(
            "document.querySelector('.camloc-vshare').textContent === "
            "'shared with the service (2 there)'",
            timeout=30000,
        )
        assert not keybox.is_visible()
        assert client.get(url).json()["items"]["1"]["verdict"] == "no"
        stored = "window.localStorage.getItem('camloc-verdicts/v1/service-key')"
        assert page.evaluate(stored) is None  # the session's only
        assert ana.blocked == []
        assert ana.errors == []
    finally:
        ana.close()
        client.close()


# ------------------------------------------- session 37: a CLI page pointed at a service
def test_cors_for_the_configured_origins_on_the_verdict_paths_only(
    kserver: Server, vserver: Server
) -> None:
    pre = {
        "Access-Control-Request-Method": "POST",
        "Access-Control-Request-Headers": "content-type,x-api-key",
    }
    with httpx.Client(base_url=kserver.url, timeout=60.0) as c:
        for origin in (PAGES, "null"):
            r = c.options(URL, headers={"Origin": origin, **pre})
            assert r.status_code == 200, r.text
            assert r.headers["access-control-allow-origin"] == origin
            assert "x-api-key" in r.headers["access-control-allow-headers"].lower()
            assert "POST" in r.headers["access-control-allow-methods"]
            r = c.get(URL, headers={"Origin": origin})
            assert r.headers["access-control-allow-origin"] == origin
            r = c.post(URL, json={"items": {}}, headers={"Origin": origin})
            assert r.status_code == 401  # the key is still needed, and the page can read why
            assert r.headers["access-control-allow-origin"] == origin
        # another origin: refused preflight, no CORS header
        r = c.options(URL, headers={"Origin": "http://evil.example", **pre})
        assert r.status_code == 400
        assert "access-control-allow-origin" not in r.headers
        assert (
            "access-control-allow-origin"
            not in c.get(URL, headers={"Origin": "http://evil.example"}).headers
        )
        # the other endpoints have no CORS, from the allowed origin either
        r = c.get("/healthz", headers={"Origin": PAGES})
        assert r.status_code == 200
        assert "access-control-allow-origin" not in r.headers
        r = c.options("/v1/locate", headers={"Origin": PAGES, **pre})
        assert "access-control-allow-origin" not in r.headers
    # a server without CAMLOC_CORS_ORIGINS: none anywhere
    with httpx.Client(base_url=vserver.url, timeout=60.0) as c:
        r = c.get(URL, headers={"Origin": PAGES})
        assert r.status_code == 200
        assert "access-control-allow-origin" not in r.headers


def test_cors_origins_setting_is_checked(monkeypatch: pytest.MonkeyPatch) -> None:
    from camloc_geo.service.settings import Settings

    monkeypatch.setenv("CAMLOC_CORS_ORIGINS", " https://r.example , null,http://[::1]:8080")
    assert Settings().cors_origin_list == ["https://r.example", "null", "http://[::1]:8080"]
    for bad, said in (
        ("*", "name the origins"),
        ("https://r.example/", "is not an origin"),
        ("r.example", "is not an origin"),
    ):
        monkeypatch.setenv("CAMLOC_CORS_ORIGINS", bad)
        with pytest.raises(ValueError, match=re.escape(said)):
            Settings()


@pytest.fixture(scope="module")
def cli_page(kserver: Server, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A review page written by ``camloc locate --map ... --verdict-url`` (not served)."""
    from camloc_geo.cli import main

    tmp = tmp_path_factory.mktemp("cli-page")
    scene = tmp / "scene.json"
    scene.write_text(json.dumps(SCENE), encoding="utf-8")
    out = tmp / "review.html"
    maps_dir = Path(kserver.env["CAMLOC_MAP_DIR"])
    args = ["locate", str(scene), "--osm", str(maps_dir / "baltimore.osm.pbf"), "--map", str(out)]
    assert main([*args, "--inline", "--verdict-url", kserver.url + "/"]) == 0
    return out


def test_locate_map_verdict_url_option(
    kserver: Server, cli_page: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from camloc_geo.cli import main

    page = cli_page.read_text(encoding="utf-8")
    found = re.search(r"var cfg = (\{.*?\});\n", page)
    assert found is not None
    assert json.loads(found.group(1))["service"] == kserver.url + "/v1/verdicts"
    capsys.readouterr()
    scene = cli_page.parent / "scene.json"
    for url, said in (
        ("ftp://h", "give the service's http:// or https:// address"),
        ("http://h:99999", "not a URL"),
        ("http://h/?x=1", "no query"),
    ):
        code = main(["locate", str(scene), "--map", str(tmp_path / "x.html"), "--verdict-url", url])
        assert code == 2
        assert f"--verdict-url {url!r}: {said}" in capsys.readouterr().err
    assert main(["locate", str(scene), "--verdict-url", "http://h"]) == 2
    assert "--verdict-url needs --map" in capsys.readouterr().err
    assert not (tmp_path / "x.html").exists()


@pytest.mark.browser
@needs_browser
def test_cli_page_from_a_file_shares_with_the_service(
    browser: Any, kserver: Server, cli_page: Path
) -> None:
    """The CLI's page opened from a file (origin null) reads and, with the key, changes the
    service's verdicts; served from an origin the service does not allow, it says so."""
    page_html = cli_page.read_text(encoding="utf-8")
    found = re.search(r"var cfg = (\{.*?\});\n", page_html)
    assert found is not None
    cfg = json.loads(found.group(1))
    url = f"/v1/verdicts/candidates/{cfg['identity']}"
    client = httpx.Client(base_url=kserver.url, timeout=60.0)
    other = "http://localhost:8766"
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    page = context.new_page()
    sent: list[str] = []
    blocked: list[str] = []
    errors: list[str] = []

    def route(r: Any) -> None:
        u = r.request.url
        if u == other + "/review.html":
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
        page.goto(cli_page.as_uri(), wait_until="load")
        page.wait_for_function(
            f"document.querySelector('{share}').textContent.startsWith('shared')", timeout=30000
        )
        # rank 5 (stop 41: the rival junction a block away) stands clear; 3 sits under 1
        page.locator('.camloc-candidate [data-rank="5"]').click()
        box = page.locator('.leaflet-popup-content .camloc-verdict[data-verdict-key="5"]')
        box.locator('button[data-verdict="unsure"]').wait_for(timeout=30000)
        box.locator('button[data-verdict="unsure"]').click()
        keybox = page.locator(".camloc-verdicts form.camloc-vkey")
        try:
            keybox.wait_for(state="visible", timeout=60000)  # the 401 reached the page
        except Exception as exc:  # say what the page sent and showed, for a rare miss
            status = page.locator(share).inner_text()
            raise AssertionError(f"no key field: sent={sent} share={status!r}") from exc
        keybox.locator("input").fill(KEY)
        keybox.locator("button").click()
        page.wait_for_function(
            f"document.querySelector('{share}').textContent.startsWith('shared')", timeout=30000
        )
        assert client.get(url).json()["items"]["5"]["verdict"] == "unsure"
        assert any(s.startswith("POST ") for s in sent)
        # the same page from an origin the service does not allow: refused, and said
        page.goto(other + "/review.html", wait_until="load")
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


# ------------------------------------------------------- session 36 QA: the store's failures
def test_verdict_folder_that_cannot_hold_the_file_is_one_clear_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from camloc_geo import InputError
    from camloc_geo.cli import main

    afile = tmp_path / "a-file"
    afile.write_text("x", encoding="utf-8")
    with pytest.raises(InputError, match="not a folder"):
        VerdictStore(afile, max_rows=10)  # was FileExistsError: [Errno 17] at start-up
    with pytest.raises(InputError, match=f"{afile} is a file, not a folder"):
        VerdictStore(afile / "sub", max_rows=10)
    clash = tmp_path / "clash"
    (clash / VERDICTS_FILE).mkdir(parents=True)
    with pytest.raises(InputError, match=f"{VERDICTS_FILE} in it is not a file"):
        VerdictStore(clash, max_rows=10)
    # a read-only folder (as root every folder is writable: os.access says what a user sees)
    ro = tmp_path / "ro"
    ro.mkdir()
    with monkeypatch.context() as m:
        m.setattr("os.access", lambda path, mode: False)
        with pytest.raises(InputError, match=r"ro: cannot write there \(read-only\)"):
            VerdictStore(ro, max_rows=10)
    # camloc serve: exit 2 with one line naming the variable (was exit 1, 'failed: FileExists')
    monkeypatch.setenv("CAMLOC_VERDICT_DIR", str(afile))
    assert main(["serve", "--port", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"camloc serve: error: CAMLOC_VERDICT_DIR {afile}: not a folder (the reviewers' "
        "verdicts go there)"
    ]


def test_a_store_that_cannot_write_answers_verdicts_unavailable(tmp_path: Path) -> None:
    import sqlite3

    from camloc_geo.service.errors import error_response_for
    from camloc_geo.service.verdicts import VerdictStoreError

    store = VerdictStore(tmp_path / "v", max_rows=10)
    item = {"verdict": "yes", "rank": None, "note": "", "reviewer": "Ana"}
    store.merge("candidates", IDENT, {"1": {**item, "time": "2026-11-25T01:00:00.000Z"}})
    # the file read-only (as root, chmod does not stop a write: a read-only connection does)
    ro = sqlite3.connect(f"file:{store.path}?mode=ro", uri=True, isolation_level=None)
    ro.row_factory = sqlite3.Row
    store._local.db = ro
    with pytest.raises(VerdictStoreError, match=r"cannot use its verdicts file.*readonly"):
        store.merge("candidates", IDENT, {"2": {**item, "time": "2026-11-25T01:00:01.000Z"}})
    assert not ro.in_transaction  # the connection is not left inside a transaction
    assert list(store.page("candidates", IDENT)["items"]) == ["1"]  # reads still work
    answer = error_response_for(VerdictStoreError("the server cannot use ..."), "rid")
    assert answer.status_code == 503
    assert json.loads(bytes(answer.body))["error"]["type"] == "verdicts_unavailable"


def test_concurrent_merges_from_threads_all_land(tmp_path: Path) -> None:
    from concurrent.futures import ThreadPoolExecutor

    store = VerdictStore(tmp_path / "v", max_rows=1000)

    def post(i: int) -> list[str]:
        item = {"verdict": "yes", "rank": None, "note": "", "reviewer": f"r{i}"}
        when = f"2026-11-25T01:00:{i:02d}.000Z"
        return store.merge("candidates", IDENT, {str(i + 1): {**item, "time": when}})[1]

    with ThreadPoolExecutor(8) as pool:
        taken = list(pool.map(post, range(64)))
    assert taken == [[str(i + 1)] for i in range(64)]
    items = store.page("candidates", IDENT)["items"]
    assert len(items) == 64
    assert {it["reviewer"] for it in items.values()} == {f"r{i}" for i in range(64)}
