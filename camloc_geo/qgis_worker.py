"""Old home of the QGIS plugin's worker, kept for one release: use :mod:`camloc_geo.qgis.worker`.

``python -m camloc_geo.qgis_worker JOB.json`` still works (plugins of the previous release
call it).
"""

from __future__ import annotations

from camloc_geo.qgis.worker import CANDIDATE_FIELDS, candidate_rows, main, run_job

__all__ = ["CANDIDATE_FIELDS", "candidate_rows", "main", "run_job"]

if __name__ == "__main__":
    raise SystemExit(main())
