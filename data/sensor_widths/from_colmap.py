"""Regenerate ``camloc_geo/data/sensor_widths/sensor_widths.csv`` from COLMAP's camera table.

COLMAP (BSD 3-clause, https://github.com/colmap/colmap) keeps its sensor-width table as C++
source, ``src/colmap/sensor/specs.cc``: ``specs["make"]`` then
``make_specs.emplace_back("model", width_mm)`` lines, make and model lower case with spaces
and hyphens removed. This script turns it into the compact CSV that ``camloc_geo.exif`` reads:
``make,model,width_mm,aspect``, where a model written ``powershotg7x(4:3)`` (a width per
aspect ratio of the photo) becomes ``powershotg7x`` with aspect ``4:3``.

Usage::

    git -C colmap show <commit>:src/colmap/sensor/specs.cc > specs.cc
    python data/sensor_widths/from_colmap.py specs.cc <commit> \
        > camloc_geo/data/sensor_widths/sensor_widths.csv
"""

from __future__ import annotations

import csv
import io
import re
import sys
from pathlib import Path

_MAKE = re.compile(r'specs\["([^"]+)"\]')
_ROW = re.compile(r'emplace_back\("([^"]+)",\s*([0-9.]+)f?\)')
_ASPECT = re.compile(r"^(.*)\((\d+:\d+)\)$")


def convert(specs_cc: str, commit: str) -> str:
    """The CSV text of the table in ``specs_cc`` (COLMAP's ``specs.cc``)."""
    make = None
    rows: list[tuple[str, str, str, str]] = []
    seen: set[tuple[str, str, str, str]] = set()
    for line in specs_cc.splitlines():
        if m := _MAKE.search(line):
            make = m.group(1).replace("-", "").replace(" ", "")
            continue
        if (m := _ROW.search(line)) and make:
            model, width = m.group(1), float(m.group(2))
            aspect = ""
            if a := _ASPECT.match(model):
                model, aspect = a.group(1), a.group(2)
            row = (make, model, f"{width:g}", aspect)
            if row not in seen:  # a few rows are repeated verbatim
                seen.add(row)
                rows.append(row)
    head = [
        "# Sensor widths (mm) by camera make and model: COLMAP's src/colmap/sensor/specs.cc",
        f"# at commit {commit} (https://github.com/colmap/colmap), BSD 3-clause licence:",
        "# see NOTICE.md beside this file. Make and model: lower case, spaces and hyphens",
        "# removed. aspect: the width holds for photos of that aspect ratio only.",
        "make,model,width_mm,aspect",
    ]
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows(rows)  # quotes a model with a comma
    return "\n".join(head) + "\n" + out.getvalue()


if __name__ == "__main__":
    sys.stdout.write(convert(Path(sys.argv[1]).read_text(encoding="utf-8"), sys.argv[2]))
