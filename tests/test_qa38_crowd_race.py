"""Session 38 QA: concurrent annotations of one crowd task.

Eight annotators submitting at once to a task that needs three were all taken: the task
was checked for "collecting" before its annotations were counted, and it stays collecting
while the submission that completed it is being located, so every submission racing that
one was stored (the task ended with 8 annotations of 3) and each could set off another
locate. The count is now checked in the same transaction that stores the annotation.
"""

from __future__ import annotations

import asyncio
import copy
import json
from pathlib import Path
from typing import Any

import cv2
import httpx
import numpy as np

from camloc_geo.service import create_app
from camloc_geo.service.settings import Settings

REPO = Path(__file__).resolve().parents[1]
SCENE: dict[str, Any] = json.loads(
    (REPO / "sample_maps" / "sample_scene.json").read_text(encoding="utf-8")
)


def _annotator(i: int) -> dict[str, Any]:
    one = copy.deepcopy(SCENE)
    ann = one["annotations"][i % 3]
    ann["annotator"] = f"u{i}"
    ann["axes"]["origin"][0] += 0.25 * i  # each a different person's clicks
    one["annotations"] = [ann]
    return one


def test_a_task_takes_only_the_annotations_it_needs(tmp_path: Path) -> None:
    maps = tmp_path / "maps"
    maps.mkdir()
    (maps / "baltimore.osm.pbf").symlink_to(REPO / "sample_maps" / "baltimore.osm.pbf")
    app = create_app(Settings(data_dir=tmp_path / "d", map_dir=maps, workers=0))
    photo = cv2.imencode(".png", np.full((1080, 1920, 3), 128, np.uint8))[1].tobytes()

    async def calls() -> tuple[list[httpx.Response], dict[str, Any]]:
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(
            transport=transport, base_url="http://t", timeout=120
        ) as client:
            task = await client.post(
                "/v1/tasks?annotations=3", content=photo, headers={"content-type": "image/png"}
            )
            assert task.status_code == 201, task.text
            url = f"/v1/tasks/{task.json()['id']}"
            answers = await asyncio.gather(
                *(client.post(f"{url}/annotations", json=_annotator(i)) for i in range(8))
            )
            state = (await client.get(url)).json()
            return list(answers), state

    try:
        answers, state = asyncio.run(calls())
    finally:
        app.state.compute.shutdown()
    taken = [a for a in answers if a.status_code == 200]
    refused = [a for a in answers if a.status_code != 200]
    assert len(taken) == 3, [a.text for a in answers]
    assert sorted(a.json()["annotations"] for a in taken) == [1, 2, 3]
    assert {a.status_code for a in refused} == {422}
    assert all(a.json()["error"]["field"] == "task" for a in refused)
    assert all("all its annotations already" in a.json()["error"]["message"] for a in refused)
    assert state["annotations"] == 3
    assert state["status"] == "located"
    assert len(state["result"]["scene"]["annotations"]) == 3


def test_a_completing_submission_that_fails_can_be_sent_again(
    tmp_path: Path, monkeypatch: Any
) -> None:
    """The submission that completes a task is taken back when locating fails outside the
    library (a time limit, a lost worker): the task would otherwise be full for ever and
    never located, every later submission refused."""
    import camloc_geo.service.routers.crowd as crowd

    maps = tmp_path / "maps"
    maps.mkdir()
    (maps / "baltimore.osm.pbf").symlink_to(REPO / "sample_maps" / "baltimore.osm.pbf")
    app = create_app(Settings(data_dir=tmp_path / "d", map_dir=maps, workers=0))
    photo = cv2.imencode(".png", np.full((1080, 1920, 3), 128, np.uint8))[1].tobytes()
    real = crowd.crowd_work
    calls = {"n": 0}

    def flaky(*args: Any) -> Any:
        calls["n"] += 1
        if calls["n"] == 1:
            raise TimeoutError("a worker was lost")
        return real(*args)

    monkeypatch.setattr(crowd, "crowd_work", flaky)

    async def run() -> list[Any]:
        transport = httpx.ASGITransport(app=app, raise_app_exceptions=False)
        async with httpx.AsyncClient(
            transport=transport, base_url="http://t", timeout=120
        ) as client:
            task = await client.post(
                "/v1/tasks?annotations=2", content=photo, headers={"content-type": "image/png"}
            )
            url = f"/v1/tasks/{task.json()['id']}"
            first = await client.post(f"{url}/annotations", json=_annotator(0))
            failed = await client.post(f"{url}/annotations", json=_annotator(1))
            between = (await client.get(url)).json()
            again = await client.post(f"{url}/annotations", json=_annotator(1))
            return [first, failed, between, again, (await client.get(url)).json()]

    try:
        first, failed, between, again, state = asyncio.run(run())
    finally:
        app.state.compute.shutdown()
    assert first.status_code == 200
    assert failed.status_code >= 500
    assert (between["annotations"], between["status"]) == (1, "collecting")
    assert again.status_code == 200, again.text
    assert again.json()["status"] == "located"
    assert (state["annotations"], state["status"]) == (2, "located")


def test_a_task_full_but_not_located_at_start_up_is_reopened(tmp_path: Path) -> None:
    """The server died while locating the submission that completed a task: at the next
    start the task takes its last annotation back, so that a retry locates it (every
    submission was refused as full, the task never located)."""
    maps = tmp_path / "maps"
    maps.mkdir()
    (maps / "baltimore.osm.pbf").symlink_to(REPO / "sample_maps" / "baltimore.osm.pbf")
    settings = Settings(data_dir=tmp_path / "d", map_dir=maps, workers=0)
    photo = cv2.imencode(".png", np.full((1080, 1920, 3), 128, np.uint8))[1].tobytes()

    async def crashed() -> str:
        app = create_app(settings)
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://t") as client:
            task = await client.post(
                "/v1/tasks?annotations=2", content=photo, headers={"content-type": "image/png"}
            )
        task_id = str(task.json()["id"])
        store = app.state.store
        for i in range(2):  # stored, then the process died before the task's result
            store.add_annotation_once(task_id, _annotator(i), needed=2)
        app.state.compute.shutdown()
        return task_id

    async def restarted(task_id: str) -> list[Any]:
        app = create_app(settings)
        async with app.router.lifespan_context(app):
            transport = httpx.ASGITransport(app=app)
            async with httpx.AsyncClient(
                transport=transport, base_url="http://t", timeout=120
            ) as client:
                url = f"/v1/tasks/{task_id}"
                before = (await client.get(url)).json()
                retry = await client.post(f"{url}/annotations", json=_annotator(1))
                return [before, retry, (await client.get(url)).json()]

    task_id = asyncio.run(crashed())
    before, retry, after = asyncio.run(restarted(task_id))
    assert (before["annotations"], before["status"]) == (1, "collecting")
    assert retry.status_code == 200, retry.text
    assert (after["annotations"], after["status"]) == (2, "located")
