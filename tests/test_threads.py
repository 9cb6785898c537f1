"""``locate_scene`` from several threads on one MapData gives exactly the serial results."""

from __future__ import annotations

import json
import threading
from pathlib import Path
from typing import Any

import numpy as np

from camloc_geo.api import locate_scene, map_for_scene
from camloc_geo.osm import MapData, clear_cache
from camloc_geo.testing.synthetic import NoiseModel, make_located_scene

REPO = Path(__file__).resolve().parents[1]
EXTRACT = REPO / "sample_maps" / "baltimore.osm.pbf"
SCENE = REPO / "sample_maps" / "sample_scene.json"
N_THREADS = 8


def _scenes(m: MapData) -> list[dict[str, Any]]:
    """The sample scene and synthetic ones: corners, corners + references, a landmark."""
    scenes = [json.loads(SCENE.read_text())]
    junctions = [i for i in m.intersections if i.kind == "junction" and len(i.corners) >= 3]
    for k, kw in enumerate([{}, {"n_references": 2}, {"n_landmarks": 1}]):
        for inter in junctions[k:]:
            ls = make_located_scene(
                m, inter, np.random.default_rng(k), noise=NoiseModel(), max_tries=100, **kw
            )
            if ls is not None:
                scenes.append(ls.scene)
                break
    assert len(scenes) >= 3
    return scenes


def _run(scene: dict[str, Any], m: MapData) -> str:
    return json.dumps(locate_scene(scene, map_source=m).to_geojson(), sort_keys=True)


def test_locate_from_eight_threads_matches_serial() -> None:
    clear_cache()
    serial_map = map_for_scene(SCENE, map_source=EXTRACT)
    assert serial_map is not None
    scenes = _scenes(serial_map)
    serial = [_run(s, serial_map) for s in scenes]
    # A fresh map, so that the threads also race to build its projected streets and indexes.
    clear_cache()
    shared = map_for_scene(SCENE, map_source=EXTRACT)
    assert shared is not None
    assert shared is not serial_map
    barrier = threading.Barrier(N_THREADS)
    got: dict[tuple[int, int], str] = {}
    errors: list[BaseException] = []

    def work(t: int) -> None:
        try:
            barrier.wait()
            for j in range(len(scenes)):
                i = (j + t) % len(scenes)  # each thread starts on a different scene
                got[(t, i)] = _run(scenes[i], shared)
        except BaseException as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(t,)) for t in range(N_THREADS)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert not errors, errors
    assert len(got) == N_THREADS * len(scenes)
    for (_t, i), text in got.items():
        assert text == serial[i], f"scene {i} differs from the serial result"
    assert any('"kind": "candidate"' in s for s in serial)


def test_map_cache_survives_pickling() -> None:
    """The per-map cache and its lock do not stop a map from going to another process."""
    import pickle

    m = map_for_scene(SCENE, map_source=EXTRACT)
    assert m is not None
    n = len(m.street_index)
    copy = pickle.loads(pickle.dumps(m))
    assert len(copy.street_index) == n
    assert len(copy.building_index) == len(m.building_index)
