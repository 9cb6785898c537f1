"""A user's typed script type-checks cleanly against the public API (``py.typed`` is shipped).

mypy ``--strict`` runs on a small notebook-style script, with the package's own modules
followed silently (as for an installed package): only what a user meets is checked.
"""

from __future__ import annotations

import ast
import textwrap
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

USER_SCRIPT = """
from __future__ import annotations

from pathlib import Path

import numpy as np

import camloc_geo
from camloc_geo import InputError, calibrate_scene, locate_scene
from camloc_geo.api import (
    LocateOutput,
    corners_near,
    crowd_scene,
    locate_camera,
    scene_from,
    streets_within,
    vanishing_points,
)
from camloc_geo.scene import Scene

path = Path("scene.json")
focal: float = calibrate_scene(path).camera.focal_px
out: LocateOutput = locate_scene(str(path), map_source=Path("x.osm.pbf"), max_candidates=3)
best_lat: float = out.result.candidates[0].lat
doc: dict[str, object] = out.to_geojson()
sc: Scene = scene_from({"format": "camloc-scene/1"})
corners = corners_near(lat=np.float64(39.28), lon=np.float32(-76.59), radius_m=np.float32(80))
streets = streets_within(lat=39.28, lon=-76.59)
status: str = locate_camera({"id": "c1", "title": "A & B"}, map_source="maps").status
vp = vanishing_points(np.zeros((10, 10), dtype=np.uint8), focal_px=np.float32(900.0))
merged = crowd_scene([path, "b.json", sc])
version: str = camloc_geo.__version__
errors: tuple[type[Exception], ...] = (InputError,)
"""


def test_lazy_entry_points_are_typed() -> None:
    """Every name ``camloc_geo.__getattr__`` serves lazily is imported for type checkers."""
    tree = ast.parse((REPO / "camloc_geo" / "__init__.py").read_text())
    lazy = next(
        node.value
        for node in tree.body
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == "_API"
    )
    served = {e.value for e in lazy.elts}  # type: ignore[attr-defined]
    typed = {
        alias.name
        for node in tree.body
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
        for sub in node.body
        if isinstance(sub, ast.ImportFrom)
        for alias in sub.names
    }
    assert served
    assert served <= typed, f"untyped lazy names: {sorted(served - typed)}"


def test_user_script_type_checks_strict(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    mypy_api = pytest.importorskip("mypy.api")
    script = tmp_path / "user.py"
    script.write_text(textwrap.dedent(USER_SCRIPT))
    monkeypatch.setenv("MYPYPATH", str(REPO))
    stdout, stderr, status = mypy_api.run(
        [
            "--strict",
            "--follow-imports=silent",
            "--no-incremental",
            "--cache-dir",
            str(tmp_path / "cache"),
            "--config-file",
            "",
            str(script),
        ]
    )
    assert status == 0, stdout + stderr


def test_every_api_function_documents_parameters_returns_raises() -> None:
    """``help()`` of each public entry point: numpydoc sections naming every parameter."""
    import inspect

    from camloc_geo import api

    gaps = []
    for name in api.__all__:
        func = getattr(api, name)
        if not inspect.isfunction(func):
            continue
        doc = inspect.getdoc(func) or ""
        sections = ("Parameters", "Returns", "Raises")
        gaps += [f"{name}: {s}" for s in sections if s + "\n---" not in doc]
        gaps += [f"{name}: {p}" for p in inspect.signature(func).parameters if p not in doc]
    assert gaps == []


def test_dir_lists_the_lazy_entry_points() -> None:
    """Tab completion (``dir(camloc_geo)``) did not offer calibrate_scene & co."""
    import camloc_geo

    names = dir(camloc_geo)
    assert {"calibrate_scene", "locate_scene", "corners_near", "InputError"} <= set(names)
    assert set(camloc_geo.__all__) <= set(names)
