"""Build the installable QGIS plugin archive: ``python qgis_plugin/build_zip.py [-o DIR]``.

Writes ``DIR/camloc.zip`` (default: ``qgis_plugin/dist``) holding the folder ``camloc/`` as
QGIS's "Install from ZIP" expects; caches and tests are left out. Prints the archive's path.
"""

from __future__ import annotations

import argparse
import sys
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
PLUGIN = HERE / "camloc"
SKIP_DIRS = {"__pycache__", "tests", ".mypy_cache", ".ruff_cache"}
SKIP_SUFFIXES = {".pyc", ".pyo"}


def plugin_files() -> list[Path]:
    """The files that go into the archive, sorted."""
    return sorted(
        p
        for p in PLUGIN.rglob("*")
        if p.is_file()
        and not SKIP_DIRS.intersection(p.relative_to(PLUGIN).parts)
        and p.suffix not in SKIP_SUFFIXES
    )


def build_zip(out_dir: Path) -> Path:
    """Write ``out_dir/camloc.zip``; its path."""
    if not (PLUGIN / "metadata.txt").is_file():
        raise SystemExit(f"error: {PLUGIN / 'metadata.txt'} is missing")
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / "camloc.zip"
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as zf:
        for p in plugin_files():
            info = zipfile.ZipInfo(
                str(Path("camloc") / p.relative_to(PLUGIN)), (2020, 1, 1, 0, 0, 0)
            )
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            zf.writestr(info, p.read_bytes())
    return target


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description="Build the camloc QGIS plugin archive (camloc.zip).")
    ap.add_argument("-o", "--out-dir", default=str(HERE / "dist"), help="folder for camloc.zip")
    args = ap.parse_args(argv)
    print(build_zip(Path(args.out_dir)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
