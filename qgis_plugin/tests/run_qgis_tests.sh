#!/usr/bin/env bash
# The QGIS plugin's tests in real QGIS, headless (pytest-qgis, QT_QPA_PLATFORM=offscreen).
#
# Needs Debian's qgis and python3-qgis. Makes (once) a venv from Debian's /usr/bin/python3 with
# --system-site-packages, so that it sees qgis, PyQt5 and osgeo, with numpy 1.24.2 (numpy 2
# breaks osgeo on bookworm), pytest-qgis and this repository (editable). The plugin's worker runs
# camloc_geo in that venv's Python, outside the QGIS process (docs/qgis.md).
# Usage: qgis_plugin/tests/run_qgis_tests.sh [pytest args] [test files]   (venv: $CAMLOC_QGIS_VENV
# or .venv-qgis); with no test file among the arguments it runs the whole of qgis_plugin/tests.
set -euo pipefail
cd "$(dirname "$0")/../.."
VENV="${CAMLOC_QGIS_VENV:-.venv-qgis}"
if ! /usr/bin/python3 -c "import qgis.core" >/dev/null 2>&1; then
  echo "error: Debian's python3-qgis is not installed (apt-get install qgis python3-qgis)" >&2
  exit 1
fi
if [ ! -x "$VENV/bin/python" ]; then
  /usr/bin/python3 -m venv --system-site-packages "$VENV"
fi
"$VENV/bin/python" -m pip install -q "numpy==1.24.2" "pytest>=8" "pytest-qgis>=2" -e .
export QT_QPA_PLATFORM=offscreen
unset PYTHONPATH
# Test files or node ids among the arguments run alone; otherwise the whole folder.
TARGETS=(qgis_plugin/tests)
for arg in "$@"; do
  case "$arg" in
    -*) ;;
    *) if [ -e "${arg%%::*}" ]; then TARGETS=(); break; fi ;;
  esac
done
exec "$VENV/bin/python" -m pytest -q "${TARGETS[@]}" "$@"
