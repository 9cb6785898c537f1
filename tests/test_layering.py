"""The package's layers (``docs/architecture.md``): no import cycle, nothing imports upwards.

Imports are read with :mod:`ast` from every module of ``camloc_geo`` (module level and inside
functions alike, a module's ``__getattr__`` included; ``if TYPE_CHECKING:`` blocks are left
out: they never run). Output shapes that moved up a layer (``candidates_geojson``,
``intersections_geojson``, ``streets_json``) are imported from ``camloc_geo.results`` only.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "camloc_geo"

FRONT_ENDS = (
    "camloc_geo.cli",
    "camloc_geo.service",
    "camloc_geo.batch",
    "camloc_geo.maps",
    "camloc_geo.overlay",
    "camloc_geo.web",
    "camloc_geo.qgis_worker",
    "camloc_geo.qgis",
)
"""Layer 1: parse input, call the API, present the result."""

API = ("camloc_geo.api", "camloc_geo.results", "camloc_geo.cameras")
"""Layer 2: the entry points, the camera-list engine, the output shapes."""

TESTING = ("camloc_geo.testing",)
"""Generators of test and benchmark data: nothing in the package imports them."""

CORE_PACKAGE_INIT = "camloc_geo"
"""The package's ``__init__`` re-exports the API lazily; it is not core code."""


def _module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


MODULES = {
    _module_name(p): p for p in sorted(PACKAGE.rglob("*.py")) if "__pycache__" not in p.parts
}


def _in(name: str, prefixes: tuple[str, ...]) -> bool:
    return any(name == p or name.startswith(p + ".") for p in prefixes)


def _layer(name: str) -> str:
    if name == CORE_PACKAGE_INIT:
        return "package"
    if _in(name, FRONT_ENDS):
        return "front end"
    if _in(name, API):
        return "api"
    if _in(name, TESTING):
        return "testing"
    return "core"


def _is_type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _walk(nodes: list[ast.stmt], top: bool) -> Iterator[ast.AST]:
    for node in nodes:
        if isinstance(node, ast.If) and _is_type_checking(node):
            yield from _walk(node.orelse, top)
            continue
        yield node
        for field in ("body", "orelse", "finalbody", "handlers"):
            children = getattr(node, field, None)
            if isinstance(children, list) and children and isinstance(children[0], ast.AST):
                yield from _walk(children, top=False)  # type: ignore[arg-type]


def _resolve(target: str) -> str | None:
    """The module of the package an import names (the longest known prefix)."""
    parts = target.split(".")
    while parts:
        name = ".".join(parts)
        if name in MODULES:
            return name
        parts.pop()
    return None


def _imports(name: str, path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    is_pkg = path.name == "__init__.py"
    out: set[str] = set()
    for node in _walk(tree.body, top=True):
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".")
                if not is_pkg:
                    base = base[:-1]
                base = base[: len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            # ``from X import y``: the submodule X.y when there is one, else X itself
            targets = [f"{mod}.{a.name}" for a in node.names]
        for t in targets:
            resolved = _resolve(t) if t.startswith("camloc_geo") else None
            if resolved is not None and resolved != name:
                out.add(resolved)
    return out


GRAPH = {name: _imports(name, path) for name, path in MODULES.items()}


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_graph_is_read() -> None:
    assert len(MODULES) > 60
    assert "camloc_geo.absolute._model" in GRAPH["camloc_geo.absolute._pipeline"]
    assert "camloc_geo.osm._catalogue" in GRAPH["camloc_geo.osm"]


def test_no_import_cycle() -> None:
    assert _cycles(GRAPH) == []


def test_the_cycle_finder_finds_one() -> None:
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


_ALLOWED = {
    "core": {"core"},
    "api": {"core", "api"},
    "front end": {"core", "api", "front end", "package"},
    "testing": {"core", "api", "front end", "testing", "package"},
    "package": {"core", "api", "package"},
}


@pytest.mark.parametrize("name", sorted(GRAPH))
def test_nothing_imports_upwards(name: str) -> None:
    """Core never imports the API, results, the camera engine or a front end; the API never
    imports a front end; nothing but ``testing`` imports ``testing``."""
    layer = _layer(name)
    wrong = sorted(t for t in GRAPH[name] if _layer(t) not in _ALLOWED[layer])
    assert wrong == [], f"{name} ({layer}) imports {wrong}"


def test_core_imports_no_front_end_framework() -> None:
    banned = ("qgis", "PyQt5", "PyQt6", "fastapi", "starlette", "uvicorn", "argparse", "click")
    banned += ("folium", "playwright")
    bad = []
    for name, path in MODULES.items():
        if _layer(name) != "core":
            continue
        for node in _walk(ast.parse(path.read_text(encoding="utf-8")).body, top=True):
            mods = []
            if isinstance(node, ast.Import):
                mods = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and not node.level:
                mods = [node.module or ""]
            bad += [f"{name}: {m}" for m in mods if m.split(".")[0] in banned]
    assert bad == []
