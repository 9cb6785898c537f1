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
