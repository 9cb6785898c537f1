"""``camloc calibrate`` on the hand-annotated real cars of ``tests/data/real_car/``.

Each scene is calibrated through the command line twice: with its clicks alone (``image.path``
removed) and with its photo (York Urban under ``CAMLOC_YUD_DIR``; the street photos under
``CAMLOC_PHOTOS_DIR`` or ``~/.cache/camloc_geo/photos``, ``benchmarks/fetch_real_photos.sh``);
a missing photo skips that row. The focal length and camera height truths are the ones
``tests/test_real_car.py`` and ``tests/test_real_car_street.py`` state (benchmarks/README.md,
*real_car*).

Usage::

    PYTHONPATH=$PWD python benchmarks/real_car.py [--json OUT]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
DATA = HERE.parent / "tests" / "data" / "real_car"
YUD = Path(
    os.environ.get(
        "CAMLOC_YUD_DIR", str(HERE.parents[1] / "shared" / "data" / "yud" / "YorkUrbanDB")
    )
)
PHOTOS = Path(
    os.environ.get("CAMLOC_PHOTOS_DIR", str(Path.home() / ".cache" / "camloc_geo" / "photos"))
)

#: scene file stem -> (photo root, focal length truth px, camera height truth m or None)
CARS: dict[str, tuple[Path, float, float | None]] = {
    "yud_P1020171_pickup": (YUD, 674.9, None),
    "yud_P1020822_corolla": (YUD, 674.9, 2.55),
    "yud_P1080031_camry_taxi": (YUD, 674.9, 2.35),
    "street_I1_STD_0034_corolla_altis": (PHOTOS, 5201.27, 1.1),
    "street_kyoto_street_honda_today": (PHOTOS, 3091.53, 1.40),
}


def run_one(stem: str, with_photo: bool, workdir: Path) -> dict[str, Any] | None:
    """One ``camloc calibrate`` run; its row, or None where the photo is missing."""
    root, focal_px, height_m = CARS[stem]
    scene = json.loads((DATA / f"{stem}.json").read_text(encoding="utf-8"))
    if with_photo:
        photo = root / scene["image"]["path"]
        if not photo.is_file():
            return None
        scene["image"]["path"] = str(photo)
    else:
        del scene["image"]["path"]
    path = workdir / f"{stem}.json"
    path.write_text(json.dumps(scene), encoding="utf-8")
    proc = subprocess.run(
        [sys.executable, "-m", "camloc_geo.cli", "calibrate", str(path)],
        capture_output=True,
        text=True,
        check=False,
    )
    row: dict[str, Any] = {"car": stem, "photo": with_photo, "exit": proc.returncode}
    if proc.returncode != 0:
        return row
    out = json.loads(proc.stdout)
    f, s = float(out["focal_px"]), out.get("focal_sigma_px")
    row.update(
        focal_px=f,
        focal_sigma_px=s,
        focal_err_rel=f / focal_px - 1.0,
        focal_err_sigmas=abs(f - focal_px) / s if s else None,
        height_m=out["height_m"],
        height_sigma_m=out.get("height_sigma_m"),
        height_err_m=None if height_m is None else out["height_m"] - height_m,
        photo_segments=out.get("photo_segments"),
        warnings=out.get("warnings", []),
    )
    return row


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, help="write the rows here")
    args = ap.parse_args(argv)
    workdir = Path(os.environ.get("TMPDIR", "/tmp")) / f"camloc_real_car_{os.getpid()}"
    workdir.mkdir(parents=True, exist_ok=True)
    rows = []
    for stem in CARS:
        for with_photo in (False, True):
            row = run_one(stem, with_photo, workdir)
            if row is None:
                print(f"{stem:36s} {'photo' if with_photo else 'clicks':6s} photo missing")
                continue
            rows.append(row)
            if row["exit"] != 0:
                print(f"{stem:36s} {'photo' if with_photo else 'clicks':6s} exit {row['exit']}")
                continue
            z = row["focal_err_sigmas"]
            h = row["height_err_m"]
            print(
                f"{stem:36s} {'photo' if with_photo else 'clicks':6s} "
                f"{row['focal_px']:7.1f} ± {row['focal_sigma_px']:6.1f} px "
                f"({100 * row['focal_err_rel']:+6.1f} %, {z:5.2f} sigma)  "
                f"height {row['height_m']:.2f} ± {row['height_sigma_m']:.2f} m"
                + ("" if h is None else f" ({h:+.2f})")
                + f"  warnings {len(row['warnings'])}  photo_segments {row['photo_segments']}"
            )
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
