"""Benchmark ``camloc vp`` on real photographs with independent truth.

Usage::

    python benchmarks/vp_real.py [--strecha DIR] [--sceaux DIR] [--lund DIR] [--yud DIR]
                                 [--limit N]
                                 [--sets strecha,sceaux,perrot,lund,street-photos,exif,yud]
                                 (lund-dev, lund-held-out: one half of the Lund scenes;
                                  street-photos-dev, street-photos-held-out: one half of
                                  the handheld street photos; street-photos-held-out-2,
                                  street-photos-held-out-3, street-photos-held-out-4,
                                  street-photos-held-out-5: the fresh batches 8, 9, 10
                                  and 11, each only when named;
                                  drive, drive-dev, drive-held-out: the driving frames)
    python benchmarks/vp_real.py --sets street [--street-frames 30]
    python benchmarks/vp_real.py --sets street-photos --prior-at-truth [--no-exif-kept]
                                 (also the EXIF-stripped photos with the default focal
                                  prior centred on each one's truth: a simulation of a
                                  camera the default prior matches, its own labelled run)
    python benchmarks/vp_real.py --sets street-synth-dev [--synth-photos 40]

The photos (none of them is in this repository; their licences keep them out):

``strecha``
    Strecha et al., "On benchmarking camera calibration and multi-view stereo for high
    resolution imagery" (CVPR 2008): 103 outdoor photos of buildings (castle-P19,
    castle-P30, entry-P10, fountain-P11, Herz-Jesu-P8, Herz-Jesu-P25; 3072x2048,
    radially undistorted). Truth: the published calibration (``gt_dense_cameras``),
    focal length and principal point; the zenith from the published rotation (the
    frame of the laser scan, whose z axis is vertical). A copy is in the public
    repository ``openMVG/SfM_quality_evaluation``
    (``git clone https://github.com/openMVG/SfM_quality_evaluation``); point
    ``CAMLOC_STRECHA_DIR`` (or ``--strecha``) at its ``Benchmarking_Camera_Calibration_2008``
    folder.
``sceaux``
    11 photos of the Chateau de Sceaux (Kodak Z612, 2832x2128, EXIF kept), published
    calibration ``images/K.txt`` (f = 2905.88 px) in ``openMVG/ImageDataset_SceauxCastle``
    (``CAMLOC_SCEAUX_DIR`` or ``--sceaux``: the repository's ``images`` folder). These
    are run with and without their EXIF.
``perrot``
    ``rperrot/ReconstructionDataSet`` (R. Perrot, the openMVG image list's "HIGH-RES"
    sets; ``git clone https://github.com/rperrot/ReconstructionDataSet``, a few GB; or
    ``CAMLOC_PERROT_DIR`` / ``--perrot``): about 530 outdoor photos of churches, doors,
    facades and a statue on a facade, taken with a Canon DSLR, EXIF kept. Truth: the focal
    length from EXIF (``FocalLength`` with the focal-plane resolution, or a sensor table
    through ``CAMLOC_SENSOR_DB``; ``FocalLengthIn35mmFilm`` last), so it is as good as the
    camera's rounding of the focal length to whole millimetres (about 2-3 %). No gravity
    or horizon truth. Run with and without the EXIF.
``lund`` (``lund-dev``, ``lund-held-out``: one half of its scenes, see :data:`LUND_DEV`)
    The photo sets of Lund University's computer-vision course (Structure from Motion
    assignment; copies in the public repositories ``erik-norlin/Structure-From-Motion`` and
    ``ziyong-was-taken/Structure-From-Motion``, no licence given: kept out, fetched by
    ``benchmarks/fetch_real_photos.sh``; ``CAMLOC_LUND_DIR`` or ``--lund``: the ``data``
    folder). The outdoor building sets only, 52 photos: 1 Kronan (a brick tower, 2), 2 a
    courtyard corner (9), 3 a cathedral's side gate (12), 4 a fountain in a stone niche (14),
    6 a statue niche of the Landhaus in Graz (8), 7 Heidelberg castle's facade (7); left
    out: 5 (a golden statue indoors), 8 (a stone relief: no straight edges to speak of) and
    9 (a toy on a poster). Nikon D60 (1936x1296) and Coolpix 4200 (2272x1704), EXIF
    kept. Truth: ``FocalLength`` (mm) over the sensor width of openMVG's
    CameraSensorSizeDatabase (D60 23.6 mm, Coolpix 4200 7.11 mm) times the long side, as
    good as the whole-millimetre focal length (1.5-3.5 %); it agrees with the course's own
    calibration (``f35 / 35 * long side``) within 1.1 %. No gravity truth. Run with and
    without the EXIF (the EXIF prior is the 35 mm tag, 2.7 % below the truth on the D60).
``street-photos`` (``street-photos-dev``, ``street-photos-held-out``)
    Ordinary handheld photos taken standing on a street or square (a street receding,
    facades, a church front on a square, a phone box on a pavement), compact cameras and
    phones, EXIF kept: 40 photos listed in ``benchmarks/street_photos.json`` (file,
    sha256, repository, commit, path, camera, what it shows, batch, half). Batch 1 (12):
    ``ianare/exif-samples`` (6 photos of the streets and squares of Arezzo, Nikon Coolpix
    P6000, 640x480; one Nikon D70s photo between apartment blocks) and
    ``drewnoakes/metadata-extractor-images`` (BlackBerry Z10, Samsung SM-J327T1, Nikon
    D40, Panasonic DMC-LX3, Canon PowerShot S30). Batch 2 (14, stop 38): the test data of
    ``Exiv2/exiv2``, ``MikeKovarik/exifr``, ``hMatoba/Piexif``, ``photoprism/photoprism``,
    ``h2non/bimg`` and more of ``drewnoakes/metadata-extractor-images`` (phones: Samsung
    Galaxy S5, S7, S7 edge, Note 3, Huawei P30, Xiaomi Mi A1, iPhone XS; compacts and
    DSLRs). Batch 3 (1): a church front from ``ethanhe42/3D-reconstruction`` (Casio
    EX-Z55). Batch 4 (3): ``beauwoods/photo-portfolio`` (photos at their camera's full
    native size only: not cropped). Batch 5 (3): ``Megu09mi/megu`` (a builder's website:
    resized, not cropped). Batch 6 (4): ``saryCast/grafital`` (iPhone 4S photos of an
    apartment complex). Batch 7 (3): ``BrendanJohn/backbayfens`` (iPhone 6) and one more
    of ``saryCast/grafital``. EXIF test collections, library test data, a portfolio and a
    website, so no licence is given for the photos themselves: kept out, copied by
    ``benchmarks/fetch_real_photos.sh`` (from a local mirror, else GitHub's raw files).
    Chosen by what they show before any result on them was read; the halves by a rule
    fixed then, batch by batch: sorted by sha256, every other one dev (22 dev, 18 held
    out). Truth: the EXIF focal length as for
    ``perrot``; no gravity truth. Run with and without the EXIF.
``street-photos-held-out-2`` (only when ``--sets`` names it; ``street-photos`` never loads it)
    Batch 8 of ``benchmarks/street_photos.json`` (stop 39): 42 more photos of streets,
    squares and buildings that no one had run ``camloc vp`` on, all held out, to be
    measured once (files under ``street-photos-held-out-2/``). Each has a ``view`` read
    from the photo before any result ("level", "looking-up", "looking-down"); the run
    also summarises each view (``street-photos-held-out-2 / looking-up``).
``street-photos-held-out-3`` (only when ``--sets`` names it)
    Batch 9 (stop 40): a further fresh batch held out whole in the same way (files under
    ``street-photos-held-out-3/``), phones first, to be measured once; summarised by view.
``street-photos-held-out-4`` (only when ``--sets`` names it)
    Batch 10 (stop 41): 40 more photos no one has run ``camloc vp`` on, held out whole
    (files under ``street-photos-held-out-4/``): compacts, DSLRs and phones (a Galaxy S8's
    in-camera 1:1 mode at 1.0 times the side), to be measured once; summarised by view.
    Eight of them carry a lens focal length but no 35 mm tag and no focal-plane
    resolution: their manifest ``truth`` (the lens over a sensor width of openMVG's table)
    is their truth, with or without ``CAMLOC_SENSOR_DB``.
``street-photos-held-out-5`` (only when ``--sets`` names it)
    Batch 11 (stop 42): 34 more photos no one has run ``camloc vp`` on, held out whole
    (files under ``street-photos-held-out-5/``): phones (iPhone 4S photos of the SPHP
    stitching set at 0.94 times the longer side), compacts near 1.0, DSLRs and a
    mirrorless, to be measured once; summarised by view.
``exif``
    Any further folders of outdoor photos whose EXIF gives the focal length
    (``--exif-dir DIR``, repeatable, or ``CAMLOC_EXIF_PHOTO_DIRS``, ``os.pathsep``
    separated): each is a set named by its folder, truth from EXIF as for ``perrot``,
    run with and without it. Photos without a usable EXIF focal length are skipped
    (counted in the log).
``street-synth`` (``street-synth-dev``, ``street-synth-held-out``; not photographs, only
when ``--sets`` names it)
    ``--synth-photos`` (40) synthetic handheld street photos per half
    (:mod:`camloc_geo.testing.street_photo_render`: a phone 1.4-1.8 m up looking down a
    street between two rows of facades, yaw 0-25 degrees, pitch -5..+10, roll within 2,
    focal length 0.7-1.3 times the longer side, principal point up to 1.5 % off centre,
    division-model k1 in [-0.06, 0.02], JPEG). Development seeds 0-39, held-out seeds
    5000-5039, fixed before any result. Truth: focal length, principal point, gravity.
``street`` (not photographs; only when ``--sets`` names it)
    ``--street-frames`` (30) rendered traffic frames
    (:mod:`camloc_geo.testing.traffic_render`: a pole camera 6-9 m up looking down 15-23
    degrees at a road with lane markings, a parked car and traffic; no building, so no
    vertical line but the cars' edges). The product's main case with exact truth: the
    steep looking-up warning must stay silent there.
``drive`` (``drive-dev``, ``drive-held-out``: one half, split by sequence)
    Street-level frames from a car looking along the road, truth in
    ``benchmarks/street_truth.json`` (file, sha256, calibration, sequence, half): 12
    frames of Udacity's Advanced Lane Finding project (a dash camera on a highway,
    1280x720, not undistorted; ``jeremy-shannon/CarND-Advanced-Lane-Lines``), truth the
    camera's own chessboard calibration (OpenCV on the repository's 20 ``camera_cal``
    photos: fx 1156.5, fy 1151.3 px); 2 KITTI road frames (``Phoenix8215/FCN_KITTI``,
    ``um_000000`` of training and of testing, 1242x375) and 2 KITTI object frames
    (``open-mmlab/mmdetection3d``'s demo ``000008`` and test ``000000``) with their
    published ``P2``; the 6 cameras of nuScenes scene-0061's first sample (mmdetection3d's
    demo, 1600x900, published ``cam2img``; gravity from ``ego2global`` and ``cam2ego``,
    so these have horizon and pitch truth). The development half (fixed before any result
    was read): the 8 frames of the project video, the 2 KITTI object frames, nuScenes
    CAM_FRONT, CAM_FRONT_LEFT and CAM_BACK; held out: the 3 challenge-video frames, the
    harder-challenge frame, the 2 KITTI road frames and the other 3 nuScenes cameras.
    And 15 traffic cameras over a highway, looking down 9-26 degrees along it
    (BrnoCompSpeed, Sochor et al. 2018, sessions 0-4, left, centre and right; 1920x1080;
    ``marikhu/BrnoCompSpeed``): truth the dataset's reference calibration
    (``system_dubska_optimal_calib.json``: the two road vanishing points and the image
    centre as principal point, so the focal length is ``sqrt(-(vp1 - pp).(vp2 - pp))`` and
    the up direction their cross product); development half sessions 0, 2 and 4, held out
    1 and 3. Fetched by ``benchmarks/fetch_real_photos.sh`` (KITTI, nuScenes and
    BrnoCompSpeed: non-commercial; the Udacity frames: no licence given).
``yud``
    The York Urban DB (102 photos, indoor and outdoor, 640x480; focal length from the
    published calibration, horizon from the ground-truth vanishing points; research use
    only: ``CAMLOC_YUD_DIR``).

Reported per set and over all photos (focal length not given, EXIF ignored unless the
row says so):

- the focal-length error distribution (signed, relative; percentiles, share within 10
  and 20 %);
- the horizon error (largest vertical distance over the image width / image height) and
  its AUC up to 0.25, where the truth gives a zenith;
- how often the stated ``focal_std_rel`` covers the truth at 1 and 2 sigma, and the
  median |log error| / sigma;
- the ROC AUC of ``1 - confidence`` as a predictor of a focal error over 10 %;
- "confidently wrong": off by more than 10 % and more than twice the stated sigma, with
  no warning and confidence at least 0.5;
- whether the rival frames' weights are calibrated (``rival_calibration``): each photo's
  rival Manhattan frames are recorded as found by ``camloc_geo.autovp`` (its weight
  ``Phi(-z)`` and log focal ratio to the kept frame, and the kept frame's own sigma, by
  wrapping two private helpers while the photo runs); over the rivals whose focal length
  lies beyond the kept frame's own sigma (and 3 %), how often the mixture puts the truth at
  the rival (``expected_at_rival``, the sum of ``w / (1 + sum w)``) against how many lie
  nearer the truth than the kept frame (``observed_nearer``);
- how often the steep looking-up warning ("..., or up 60 degrees ...") is given
  (``n_warned_looking_up``), and where the truth gives gravity, on photos that do not look
  up 45 degrees (``n_warned_looking_up_wrongly``);
- the share of photos with the pitch within 5 degrees, where the truth gives gravity,
  and the same figures for the outdoor photos looking up by more than 5 degrees (the
  Strecha photos: looking up 5 to 15 degrees; none of the sets looks up steeply, so the
  steep case, 40-80 degrees, is checked on synthetic facades only, as segments and drawn
  into images, ``tests/test_autovp_failure_modes.py``);
- where the truth gives gravity (or, for BrnoCompSpeed, the road plane's normal; for
  nuScenes the car body's up: its localisation is 2-D plus yaw, so the vehicle's pitch and
  roll on the road are not in it), how often the stated ``pitch_std_deg`` and
  ``roll_std_deg`` cover the error at 1 and 2 sigma and the median error / sigma
  (``pitch_sigma_cover_1`` ... ``roll_median_err_over_sigma``, and the median absolute
  errors ``pitch_abs_err_median_deg``, ``roll_abs_err_median_deg``);
- which term decides the photos' own focal sigma (``sigma_terms``, from
  ``AutoVPResult.focal_std_parts``: on how many photos each term is the largest, each
  term's median and share of the variance);
- where the truth gives gravity, the coherent bias of the vertical lines against the true
  vertical vanishing point (``vertical_turn_rms_deg``, ``vertical_convergence_rms_deg``,
  :func:`vertical_bias_deg`): what the sigma's systematic term assumes to be
  ``autovp.BIAS_DEG`` (0.3 degrees). ``--bias-deg`` runs with another value.

Writes ``benchmarks/out/vp_real.json`` and ``vp_real_*.png``.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import math
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout
sys.path.insert(0, str(Path(__file__).resolve().parent))

from vp_yud import horizon_auc, load_yud

from camloc_geo import NotEnoughStructureError, autovp
from camloc_geo.autovp import (
    detect_vanishing_points,
    horizon_from_up,
    load_image,
    pitch_roll_from_up,
)

log = logging.getLogger("vp_real")

HERE = Path(__file__).resolve().parent
# Photos kept out of the repository by their licence: benchmarks/fetch_real_photos.sh clones
# openMVG's public sets here; York Urban (research use only) is looked for beside the checkout.
PHOTOS = Path(
    os.environ.get("CAMLOC_PHOTOS_DIR", str(Path.home() / ".cache" / "camloc_geo" / "photos"))
)
DEFAULT_STRECHA = Path(
    os.environ.get(
        "CAMLOC_STRECHA_DIR",
        str(PHOTOS / "SfM_quality_evaluation" / "Benchmarking_Camera_Calibration_2008"),
    )
)
DEFAULT_SCEAUX = Path(
    os.environ.get("CAMLOC_SCEAUX_DIR", str(PHOTOS / "ImageDataset_SceauxCastle" / "images"))
)
DEFAULT_PERROT = Path(os.environ.get("CAMLOC_PERROT_DIR", str(PHOTOS / "ReconstructionDataSet")))
DEFAULT_LUND = Path(
    os.environ.get("CAMLOC_LUND_DIR", str(PHOTOS / "Structure-From-Motion" / "data"))
)
_YORK_URBAN_BESIDE = HERE.parents[1] / "shared" / "data" / "yud" / "YorkUrbanDB"
DEFAULT_YUD = Path(os.environ.get("CAMLOC_YUD_DIR", str(_YORK_URBAN_BESIDE)))

#: Photos whose true pitch looks up by more than this (degrees) are also summarised apart.
LOOKING_UP_DEG = 5.0

HOW_TO_GET = (
    "benchmarks/fetch_real_photos.sh, or: "
    "git clone https://github.com/openMVG/SfM_quality_evaluation and set CAMLOC_STRECHA_DIR "
    "to its Benchmarking_Camera_Calibration_2008 folder; git clone "
    "https://github.com/openMVG/ImageDataset_SceauxCastle and set CAMLOC_SCEAUX_DIR to its "
    "images folder; git clone https://github.com/rperrot/ReconstructionDataSet and set "
    "CAMLOC_PERROT_DIR to it; the Lund course photos: the data folder of "
    "https://github.com/erik-norlin/Structure-From-Motion in CAMLOC_LUND_DIR; "
    "CAMLOC_YUD_DIR: the York Urban DB (York University); the driving frames (drive): "
    "benchmarks/fetch_real_photos.sh"
)


def load_strecha(root: Path) -> list[dict[str, Any]]:
    """Photos and truth of the Strecha 2008 sets (``gt_dense_cameras`` files)."""
    out = []
    for cam_dir in sorted(root.glob("*/gt_dense_cameras")):
        for cam in sorted(cam_dir.glob("*.jpg.camera")):
            rows = [ln.split() for ln in cam.read_text(encoding="ascii").splitlines()]
            vals = [[float(x) for x in r] for r in rows if r]
            K = np.array(vals[0:3])
            R_world_from_cam = np.array(vals[4:7])
            w, h = (int(v) for v in vals[8])
            up = -R_world_from_cam[2]  # world z in the camera frame; camera y is down
            if up[1] > 0:
                up = -up
            out.append(
                {
                    "set": "strecha",
                    "name": f"{cam_dir.parent.name}/{cam.name[:-7]}",
                    "path": str(cam_dir.parent / "images" / cam.name[:-7]),
                    "f": 0.5 * (K[0, 0] + K[1, 1]),
                    "pp": (float(K[0, 2]), float(K[1, 2])),
                    "up": up / np.linalg.norm(up),
                    "size": (w, h),
                }
            )
    return out


def load_sceaux(root: Path) -> list[dict[str, Any]]:
    """Photos and the published calibration of the Sceaux castle set."""
    K = np.loadtxt(root / "K.txt")
    out = []
    for p in sorted(root.glob("*.JPG")):
        out.append(
            {
                "set": "sceaux",
                "name": f"sceaux/{p.stem}",
                "path": str(p),
                "f": float(K[0, 0]),
                "pp": (float(K[0, 2]), float(K[1, 2])),
                "up": None,
                "size": (2832, 2128),
                "exif": True,
            }
        )
    return out


_PHOTO_SUFFIXES = {".jpg", ".jpeg"}


def _stored_size(path: Path) -> tuple[int, int]:
    """The photo's ``(width, height)`` as stored (before the EXIF orientation)."""
    from PIL import Image

    with Image.open(path) as im:
        return int(im.size[0]), int(im.size[1])


def exif_focal_truth(path: Path) -> tuple[Any, tuple[int, int]] | None:
    """The focal-length truth of a photo from its EXIF, and its stored size.

    The focal length from the focal-plane resolution or the ``CAMLOC_SENSOR_DB`` table
    (:func:`camloc_geo.exif.focal_from_tags` without ``FocalLengthIn35mmFilm`` and without
    the bundled table the EXIF prior reads) is preferred to the 35 mm tag on the photo's
    diagonal (a whole number of millimetres, and the crop it assumes).

    Parameters
    ----------
    path
        A JPEG photo.

    Returns
    -------
    tuple or None
        The :class:`camloc_geo.exif.ExifFocal` and ``(width, height)`` as stored (before
        the EXIF orientation: the focal length in pixels is the same either way); None
        where the photo cannot be read or its EXIF gives no usable focal length.
    """
    from PIL import Image

    from camloc_geo.exif import FULL_FRAME_DIAGONAL_MM, ExifFocal, focal_from_tags

    try:
        with Image.open(path) as im:
            w, h = im.size
            exif = im.getexif()
            tags: dict[int, Any] = dict(exif)
            tags.update(exif.get_ifd(0x8769))
    except (OSError, ValueError, SyntaxError):
        return None
    no35 = {k: v for k, v in tags.items() if k != 0xA405}
    # The camera's own tags only, as before the sensor table was bundled (stop 41): the
    # prior reads that table, so a truth from it would grade the prior against itself.
    ex = focal_from_tags(no35, w, h, bundled_table=False)
    f35 = tags.get(0xA405)
    if ex is None and isinstance(f35, (int, float)) and 8 <= f35 <= 2000:
        # the 35 mm tag on the photo's own diagonal, not exif.py's frame reading
        ex = ExifFocal(f35 * math.hypot(w, h) / FULL_FRAME_DIAGONAL_MM, 0.04, "exif-35mm")
    return None if ex is None else (ex, (w, h))


def load_exif_folder(root: Path, set_name: str) -> list[dict[str, Any]]:
    """Photos under ``root`` (recursively) whose EXIF gives the focal length: the truth.

    The focal length from the focal-plane resolution or a sensor table is preferred to
    ``FocalLengthIn35mmFilm`` (a whole number of millimetres, and the crop it assumes).
    """
    out = []
    skipped = 0
    for p in sorted(q for q in root.rglob("*") if q.suffix.lower() in _PHOTO_SUFFIXES):
        if any(part.startswith(".") for part in p.relative_to(root).parts):
            continue
        got = exif_focal_truth(p)
        if got is None:
            skipped += 1
            continue
        ex, (w, h) = got
        out.append(
            {
                "set": set_name,
                "name": f"{set_name}/{p.relative_to(root).as_posix()}",
                "path": str(p),
                "f": ex.focal_px,
                "f_source": ex.source,
                "pp": (w / 2.0, h / 2.0),
                "up": None,
                "size": (w, h),
                "exif": True,
            }
        )
    if skipped:
        log.info("%s: %d photos without a usable EXIF focal length skipped", set_name, skipped)
    return out


def load_perrot(root: Path) -> list[dict[str, Any]]:
    """The ReconstructionDataSet photos, truth from their EXIF."""
    return load_exif_folder(root, "perrot")


#: The Lund course's outdoor building sets: folder number -> scene.
LUND_SCENES = {
    1: "kronan",
    2: "courtyard",
    3: "cathedral-gate",
    4: "fountain",
    6: "landhaus-graz",
    7: "heidelberg-castle",
}
#: Sets summarised by scene too (the second part of a photo's name).
SCENE_SETS = (  # and the fresh street photos by view
    "lund",
    "street-photos-held-out-2",
    "street-photos-held-out-3",
    "street-photos-held-out-4",
    "street-photos-held-out-5",
)
#: The Lund scenes split by building, so that a change tuned on some is checked on others:
#: the development half (looked at, its debug drawings read) and the held-out half (only
#: its summary figures are read). Each half has one scene where the focal length is loose
#: (a frontal gate; a curved niche) and one or two that read well.
LUND_DEV = (1, 3, 6)  # Kronan, the cathedral gate, the Landhaus in Graz: 22 photos
LUND_HELD_OUT = (2, 4, 7)  # the courtyard, the fountain niche, Heidelberg castle: 30 photos
#: Sensor widths (mm) of the Lund photos' cameras, EXIF ``Model`` -> width, from openMVG's
#: CameraSensorSizeDatabase (``sensor_database.csv``: "Nikon D60,23.6", "Nikon Coolpix
#: 4200,7.11").
LUND_SENSOR_WIDTH_MM = {"NIKON D60": 23.6, "E4200": 7.11}


def load_lund(root: Path) -> list[dict[str, Any]]:
    """The Lund course's outdoor building photos; truth from EXIF focal length and sensor width.

    Parameters
    ----------
    root
        The ``data`` folder (sub-folders ``1`` .. ``9``); only the scenes of
        :data:`LUND_SCENES` are read.

    Returns
    -------
    list of dict
        One truth record a photo (``set`` ``"lund"``); photos whose EXIF lacks the focal
        length, or whose camera is not in :data:`LUND_SENSOR_WIDTH_MM`, are skipped (logged).
    """
    from PIL import Image, ImageOps

    out = []
    skipped = 0
    for number, scene in LUND_SCENES.items():
        for p in sorted((root / str(number)).glob("*.[jJ][pP][gG]")):
            try:
                with Image.open(p) as im:
                    exif = im.getexif()
                    tags: dict[int, Any] = dict(exif)
                    tags.update(exif.get_ifd(0x8769))
                    # OpenCV, which decodes the photo for `camloc vp`, applies the orientation
                    w, h = ImageOps.exif_transpose(im).size
            except (OSError, ValueError, SyntaxError):
                skipped += 1
                continue
            width_mm = LUND_SENSOR_WIDTH_MM.get(str(tags.get(0x0110, "")).strip())
            try:
                f_mm = float(tags[0x920A])
            except (KeyError, TypeError, ValueError, ZeroDivisionError):
                f_mm = math.nan
            if width_mm is None or not math.isfinite(f_mm) or f_mm <= 0:
                skipped += 1
                continue
            out.append(
                {
                    "set": "lund",
                    "name": f"lund/{number}-{scene}/{p.name}",
                    "path": str(p),
                    "f": f_mm / width_mm * max(w, h),
                    "f_source": "exif-focal-mm+sensor-width",
                    "pp": (w / 2.0, h / 2.0),
                    "up": None,
                    "size": (w, h),
                    "exif": True,
                }
            )
    if skipped:
        log.info("lund: %d photos without a usable focal length skipped", skipped)
    return out


def _lund_number(row: dict[str, Any]) -> int:
    """The Lund scene number of a row or truth record (``"lund/3-cathedral-gate/..."`` -> 3)."""
    return int(row["name"].split("/")[1].split("-")[0])


def load_street_set(n_frames: int) -> list[dict[str, Any]]:
    """Rendered traffic frames: ``n_frames`` pole cameras 6-9 m up looking down 15-23
    degrees at a road (lane markings, kerbs, a parked car, traffic), as
    :mod:`camloc_geo.testing.traffic_render` draws its videos' frames (seeds 0, 1, ...).

    Not photographs: the product's main case (a street webcam looking down at a road)
    with exact truth, where the steep looking-up warning must stay silent. Truth: the
    camera's focal length, principal point and gravity.
    """
    from camloc_geo.testing import traffic_render as tr

    out = []
    for seed in range(n_frames):
        rng = np.random.default_rng(seed)
        cam, vehicles = tr.random_street(rng, n_vehicles=6, duration_s=10.0)
        w, h = round(2 * cam.principal_point[0]), round(2 * cam.principal_point[1])
        img = tr._background(cam, (w, h), rng, 0.025)
        sedan = tr.PRESETS["sedan"]
        parked = tr.StreetVehicle(
            (sedan.length_m / 2, sedan.width_m / 2), 0.0, 0.0, shape=tr.SHAPES["sedan"]
        )
        t_s = float(rng.uniform(0.0, 10.0))
        for veh in [parked, *vehicles]:
            tr._draw(img, cam, veh, t_s, True)
        img = np.clip(img + rng.normal(0.0, 2.0, img.shape), 0, 255).astype(np.uint8)
        up = cam.cam_from_world_rotation @ np.array([0.0, 0.0, 1.0])
        out.append(
            {
                "set": "street",
                "name": f"street/seed{seed}",
                "path": img,
                "f": float(cam.img_from_cam[0, 0]),
                "pp": (float(cam.principal_point[0]), float(cam.principal_point[1])),
                "up": up if up[1] < 0 else -up,
                "size": (w, h),
            }
        )
    return out


#: The halves of the synthetic handheld street photos (set ``street-synth``): their seeds,
#: fixed before any result was read (:mod:`camloc_geo.testing.street_photo_render`).
STREET_SYNTH_HALVES = ("dev", "held-out")


def load_street_synth(
    halves: tuple[str, ...], n_per_half: int, focal_rel: float | None = None
) -> list[dict[str, Any]]:
    """Synthetic handheld street photos (:mod:`camloc_geo.testing.street_photo_render`).

    A level-ish phone camera 1.4-1.8 m up looking down a street between two rows of
    facades, with exact truth (focal length, principal point, gravity). ``halves`` picks
    the development seeds (0, 1, ...) and/or the held-out ones (5000, 5001, ...), the first
    ``n_per_half`` of each. ``focal_rel``: every photo's focal length that many times the
    longer side (0.97: issue 24's phone) instead of the seed's 0.7-1.3.
    """
    from camloc_geo.testing import street_photo_render as spr

    out = []
    for half in halves:
        seeds = spr.DEV_SEEDS if half == "dev" else spr.HELD_OUT_SEEDS
        for seed in list(seeds)[:n_per_half]:
            ph = spr.render_street_photo(seed, focal_rel)
            up = ph.up_in_cam
            out.append(
                {
                    "set": "street-synth",
                    "name": f"street-synth/seed{seed}",
                    "half": half,
                    "path": ph.image,
                    "f": ph.focal_px,
                    "pp": ph.principal_point,
                    "up": up if up[1] < 0 else -up,
                    "size": ph.size,
                    "k1_true": ph.k1,
                }
            )
    return out


#: Truth of the street-level driving frames (sets ``drive``, ``drive-dev``, ``drive-held-out``).
STREET_TRUTH = HERE / "street_truth.json"
#: The halves of the driving frames, fixed by sequence before any result was read.
DRIVE_HALVES = ("dev", "held-out")
#: The sets of the driving frames (the ``set`` of :data:`STREET_TRUTH`'s frames).
DRIVE_SETS = ("udacity-lane", "kitti", "nuscenes", "brno")


def load_drive_set(
    photos: Path, truth_path: Path = STREET_TRUTH, halves: tuple[str, ...] = DRIVE_HALVES
) -> list[dict[str, Any]]:
    """Street-level driving frames and their published (or chessboard) calibration.

    Parameters
    ----------
    photos
        The folder ``benchmarks/fetch_real_photos.sh`` fills (each frame's ``file`` is
        relative to it).
    truth_path
        The truth file (:data:`STREET_TRUTH`): ``cameras`` (a calibration shared by the
        frames that name it) and ``frames`` (file, sha256, size, ``half``, either
        ``camera`` or their own ``focal_px`` / ``principal_point``, and where the dataset
        gives the vehicle's pose, ``up_in_cam``: the world's up in the camera frame, x
        right, y down, z forward).
    halves
        Which halves to load (``"dev"``, ``"held-out"``).

    Returns
    -------
    list of dict
        One truth record a frame present with the content the truth file pins; a frame
        missing or whose sha256 differs is skipped and counted in the log.

    Raises
    ------
    ValueError
        If the truth file is malformed (a frame without a focal length, an unknown
        camera, a focal length that is not a positive number, an ``up_in_cam`` that is
        not a 3-vector).
    """
    import hashlib

    doc = json.loads(truth_path.read_text(encoding="utf-8"))
    cameras = doc.get("cameras", {})
    out = []
    missing = changed = 0
    for fr in doc["frames"]:
        if fr.get("half") not in halves:
            continue
        cam = fr
        if "camera" in fr:
            if fr["camera"] not in cameras:
                raise ValueError(
                    f"{truth_path}: frame {fr['file']}: unknown camera {fr['camera']!r}"
                )
            cam = cameras[fr["camera"]]
        try:
            fx, fy = (float(v) for v in cam["focal_px"])
            cx, cy = (float(v) for v in cam["principal_point"])
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(
                f"{truth_path}: frame {fr.get('file')}: no usable focal_px / principal_point"
            ) from exc
        if not (fx > 0 and fy > 0 and math.isfinite(fx) and math.isfinite(fy)):
            raise ValueError(
                f"{truth_path}: frame {fr['file']}: focal length {fx}, {fy} is not positive"
            )
        path = photos / fr["file"]
        if not path.is_file():
            missing += 1
            continue
        if hashlib.sha256(path.read_bytes()).hexdigest() != fr["sha256"]:
            changed += 1
            continue
        w, h = (int(v) for v in fr["size"])
        up = None
        if fr.get("up_in_cam") is not None:
            up = np.asarray(fr["up_in_cam"], dtype=float)
            if up.shape != (3,) or not np.all(np.isfinite(up)) or np.linalg.norm(up) < 0.5:
                raise ValueError(f"{truth_path}: frame {fr['file']}: up_in_cam is not a 3-vector")
            up = up / np.linalg.norm(up)
            up = up if up[1] < 0 else -up
        out.append(
            {
                "set": fr["set"],
                "name": f"{fr['set']}/{fr['sequence']}/{Path(fr['file']).name}",
                "path": str(path),
                "f": 0.5 * (fx + fy),
                "pp": (cx, cy),
                "up": up,
                "size": (w, h),
                "half": fr["half"],
            }
        )
    if missing or changed:
        log.info(
            "drive: %d frames missing, %d with another content than the truth file pins, skipped",
            missing,
            changed,
        )
    return out


#: Handheld street photos (sets ``street-photos``, ``street-photos-dev``,
#: ``street-photos-held-out``, ``street-photos-held-out-2`` ... ``street-photos-held-out-5``):
#: file, sha256, source, half; truth from their EXIF, or from the lens focal length and the
#: sensor's published width where the manifest gives a ``truth`` (see
#: :func:`sensor_focal_truth_px`).
STREET_PHOTOS = HERE / "street_photos.json"
#: The halves of the street photos of batches 1-7 (set ``street-photos``), fixed by a rule
#: before any result was read.
STREET_PHOTO_HALVES = ("dev", "held-out")
#: The ``--prior-at-truth`` run's name: EXIF stripped, the default focal prior centred on
#: each photo's truth (a simulation of a camera the default prior matches, not a headline).
PRIOR_AT_TRUTH_RUN = "SIMULATION prior at truth, no EXIF"
#: Issue 24's EXIF-stripped bars judged on that run (``vp_real.json``'s summary key).
SIM_BARS = "issue 24 bars, SIMULATION prior at truth"
#: Fresh held-out batches, each its own set (``street-photos-<half>``), loaded only when
#: ``--sets`` names that set (never by ``street-photos``): batch 8 (stop 39), 42 photos no
#: one had run ``camloc vp`` on, measured once at the end of stop 39 (development since), and
#: batch 9 (stop 40, ``held-out-3``), measured once at the end of stop 40, and batch 10
#: (stop 41, ``held-out-4``), measured once at the end of stop 41, and batch 11 (stop 42,
#: ``held-out-5``), fresh again, to be measured once.
STREET_PHOTO_FRESH_HALVES = ("held-out-2", "held-out-3", "held-out-4", "held-out-5")


def sensor_focal_truth_px(focal_mm: float, sensor_width_mm: float, size: tuple[int, int]) -> float:
    """The focal length in pixels from the lens focal length and the sensor's width.

    The truth for a photo whose ``FocalLengthIn35mmFilm`` does not fit its frame: a phone's
    16:9 mode crops the top and bottom of a 4:3 sensor, while the tag (a 35 mm equivalent
    on the diagonal) is written for the 4:3 frame, so the diagonal rule
    (``f35 * diagonal_px / 43.27``) reads it about 8 % low. The photo's longer side spans
    the sensor's full width either way (a 16:9 crop of a 4:3 sensor, a natively 16:9
    sensor, a 4:3 photo; resized or not, as long as it is not cropped).

    Parameters
    ----------
    focal_mm
        The lens focal length (EXIF ``FocalLength``), millimetres.
    sensor_width_mm
        The width of the sensor area the photo spans (published pixel pitch times the
        sensor's pixel columns at that width), millimetres.
    size
        The photo as stored, ``(width, height)`` in pixels (either orientation).

    Returns
    -------
    float
        Focal length in pixels of the stored photo.
    """
    if not (focal_mm > 0.0 and sensor_width_mm > 0.0):
        raise ValueError(f"focal_mm and sensor_width_mm must be > 0: {focal_mm}, {sensor_width_mm}")
    return focal_mm / sensor_width_mm * float(max(size))


def street_photo_set(half: str) -> str:
    """The set a street photo of this half belongs to.

    Parameters
    ----------
    half
        The manifest's ``half`` (``"dev"``, ``"held-out"``, ``"held-out-2"``, ...).

    Returns
    -------
    str
        ``"street-photos"`` for the halves of :data:`STREET_PHOTO_HALVES`, else
        ``"street-photos-<half>"`` (a fresh batch is a set of its own).
    """
    return "street-photos" if half in STREET_PHOTO_HALVES else f"street-photos-{half}"


def street_photo_halves(wanted: set[str]) -> tuple[str, ...]:
    """The street-photo halves the names in ``--sets`` ask for.

    ``street-photos`` means both halves of :data:`STREET_PHOTO_HALVES`;
    ``street-photos-<half>`` that half, a fresh one of :data:`STREET_PHOTO_FRESH_HALVES`
    included (which ``street-photos`` never loads).
    """
    both = tuple(h for h in STREET_PHOTO_HALVES if {"street-photos", f"street-photos-{h}"} & wanted)
    fresh = tuple(h for h in STREET_PHOTO_FRESH_HALVES if f"street-photos-{h}" in wanted)
    return both + fresh


def load_street_photos(
    photos: Path,
    manifest: Path = STREET_PHOTOS,
    halves: tuple[str, ...] = STREET_PHOTO_HALVES,
) -> list[dict[str, Any]]:
    """Handheld photos taken on a street or square, truth from their EXIF focal length.

    Parameters
    ----------
    photos
        The folder ``benchmarks/fetch_real_photos.sh`` fills (each photo's ``file`` is
        relative to it).
    manifest
        :data:`STREET_PHOTOS`: ``photos`` (file, sha256, repository, commit, path,
        camera, scene, ``half``; optionally ``truth``: ``focal_mm`` and
        ``sensor_width_mm`` with their ``source``, which replaces the EXIF truth by
        :func:`sensor_focal_truth_px`).
    halves
        Which halves to load (``"dev"``, ``"held-out"``, ``"held-out-2"``,
        ``"held-out-3"``, ``"held-out-4"``, ``"held-out-5"``).

    Returns
    -------
    list of dict
        One truth record a photo present with the content the manifest pins (set
        :func:`street_photo_set` of its half, ``half`` kept; a photo with a ``view`` tag,
        "level", "looking-up" or "looking-down", keeps it, and in a fresh set its name
        carries it: ``street-photos-held-out-2/looking-up/IMG_8729.JPG``, so the run
        summarises each view; ``f_source`` is ``"exif-focal-mm+sensor-width"`` where the
        manifest gives the truth); a photo missing, with another content or without a usable
        EXIF focal length and no manifest ``truth`` is skipped and counted in the log (one
        with a lens focal length alone, no 35 mm tag and no focal-plane resolution, loads
        when the manifest gives its ``truth``).
    """
    import hashlib

    doc = json.loads(manifest.read_text(encoding="utf-8"))
    out = []
    missing = changed = no_exif = 0
    for ph in doc["photos"]:
        if ph.get("half") not in halves:
            continue
        path = photos / ph["file"]
        if not path.is_file():
            missing += 1
            continue
        if hashlib.sha256(path.read_bytes()).hexdigest() != ph["sha256"]:
            changed += 1
            continue
        got = exif_focal_truth(path)
        if got is None and not ph.get("truth"):
            no_exif += 1
            continue
        if got is None:  # a lens focal length alone (no 35 mm tag, no focal-plane resolution)
            w, h = _stored_size(path)
            f_px, f_source = 0.0, ""
        else:
            ex, (w, h) = got
            f_px, f_source = ex.focal_px, ex.source
        if ph.get("truth"):  # the lens and the sensor, where the 35 mm tag does not fit
            t = ph["truth"]
            f_px = sensor_focal_truth_px(float(t["focal_mm"]), float(t["sensor_width_mm"]), (w, h))
            f_source = "exif-focal-mm+sensor-width"
        set_name = street_photo_set(ph["half"])
        view = ph.get("view")
        fresh = set_name != "street-photos" and view
        rec: dict[str, Any] = {
            "set": set_name,
            "name": f"{set_name}/{view}/{Path(ph['file']).name}"
            if fresh
            else f"{set_name}/{Path(ph['file']).name}",
            "path": str(path),
            "f": f_px,
            "f_source": f_source,
            "pp": (w / 2.0, h / 2.0),
            "up": None,
            "size": (w, h),
            "exif": True,
            "half": ph["half"],
        }
        if view:
            rec["view"] = view
        out.append(rec)
    if missing or changed or no_exif:
        log.info(
            "street-photos: %d missing, %d with another content than the manifest pins, "
            "%d without a usable EXIF focal length, skipped",
            missing,
            changed,
            no_exif,
        )
    return out


def load_yud_set(root: Path) -> list[dict[str, Any]]:
    out = []
    for g in load_yud(root):
        d = g["dirs_orth"]
        k = int(np.argmax(np.abs(d[:, 1])))
        up = d[k] if d[k, 1] < 0 else -d[k]
        out.append(
            {
                "set": "yud",
                "name": f"yud/{g['name']}",
                "path": g["path"],
                "f": g["f"],
                "pp": (float(g["pp"][0]), float(g["pp"][1])),
                "up": up,
                "size": (640, 480),
            }
        )
    return out


def horizon_err(
    up_est: np.ndarray, f_est: float, pp_est: tuple[float, float], t: dict[str, Any]
) -> float | None:
    if t["up"] is None:
        return None
    w, h = t["size"]
    le = horizon_from_up(up_est, f_est, pp_est)
    lg = horizon_from_up(t["up"], t["f"], t["pp"])
    if abs(le[1]) < 1e-9 or abs(lg[1]) < 1e-9:
        return math.inf
    e = []
    for x in (0.0, float(w)):
        e.append(abs(-(le[0] * x + le[2]) / le[1] + (lg[0] * x + lg[2]) / lg[1]))
    return max(e) / h


def vertical_bias_deg(res: Any, t: dict[str, Any]) -> tuple[float, float] | None:
    """The coherent bias of the photo's vertical lines against the true vertical vanishing
    point: what ``autovp``'s systematic sigma term (:data:`camloc_geo.autovp.BIAS_DEG`)
    stands for, measured where the truth gives gravity.

    Each vertical inlier segment (undistorted with the run's ``k1``) is compared with the
    line from its midpoint to the true vertical vanishing point ``K up`` (true focal length
    and principal point): its signed angle, in degrees.

    Returns
    -------
    tuple of float or None
        ``(turn, convergence)``: the length-weighted mean angle (all the lines turned the
        same way: a roll of the lines) and half the difference of the means right and left
        of their centroid (a change of their lean, which moves the vertical vanishing point
        and, for a level camera, the focal length); None without gravity truth or with
        fewer than 4 vertical segments (2 a side for the convergence: NaN).
    """
    if t.get("up") is None:
        return None
    from camloc_geo.camera import RadialDistortion, undistort_points_px

    segs = np.asarray(res.segments, dtype=float)[np.asarray(res.labels) == 0]
    if len(segs) < 4:
        return None
    if res.distortion:
        w, h = res.image_size
        dist = RadialDistortion.for_image(res.distortion, w, h)
        pts = undistort_points_px(segs.reshape(-1, 2), dist, res.principal_point)
        segs = pts.reshape(-1, 4)
        segs = segs[np.all(np.isfinite(segs), axis=1)]
        if len(segs) < 4:
            return None
    f, (cx, cy) = float(t["f"]), t["pp"]
    up = np.asarray(t["up"], dtype=float)
    vp = np.array([f * up[0] + cx * up[2], f * up[1] + cy * up[2], up[2]])
    mid = 0.5 * (segs[:, :2] + segs[:, 2:])
    d = segs[:, 2:] - segs[:, :2]
    length = np.hypot(d[:, 0], d[:, 1])
    d = d / np.maximum(length, 1e-12)[:, None]
    to_vp = vp[None, :2] - vp[2] * mid
    to_vp = to_vp / np.maximum(np.linalg.norm(to_vp, axis=1, keepdims=True), 1e-12)
    d = d * np.where(np.sum(d * to_vp, axis=1) < 0, -1.0, 1.0)[:, None]
    ang = np.degrees(
        np.arctan2(d[:, 0] * to_vp[:, 1] - d[:, 1] * to_vp[:, 0], np.sum(d * to_vp, axis=1))
    )
    turn = float(np.average(ang, weights=length))
    right = mid[:, 0] > np.average(mid[:, 0], weights=length)
    conv = math.nan
    if right.sum() >= 2 and (~right).sum() >= 2:
        conv = 0.5 * float(
            np.average(ang[right], weights=length[right])
            - np.average(ang[~right], weights=length[~right])
        )
    return turn, conv


class _RivalRecorder:
    """Records the rival frames of one ``detect_vanishing_points`` call (weight and log
    focal ratio of each, and the kept frame's own sigma) by wrapping ``autovp``'s
    ``_rival_modes`` and ``_rival_spread`` while it runs."""

    def __init__(self) -> None:
        self.modes: list[tuple[float, float]] = []
        self.own_logf_std: float | None = None

    def __enter__(self) -> _RivalRecorder:
        self._modes, self._spread = autovp._rival_modes, autovp._rival_spread

        def modes(*args: Any, **kwargs: Any) -> Any:
            out = self._modes(*args, **kwargs)
            self.modes = [(float(w), float(d)) for w, d, _ in out]
            return out

        def spread(modes_: Any, own_logf_std: float | None = None) -> Any:
            if own_logf_std is None:
                return self._spread(modes_)
            self.own_logf_std = float(own_logf_std)
            return self._spread(modes_, own_logf_std)

        vars(autovp)["_rival_modes"] = modes  # (typed as the originals are not)
        vars(autovp)["_rival_spread"] = spread
        return self

    def __exit__(self, *exc: object) -> None:
        autovp._rival_modes, autovp._rival_spread = self._modes, self._spread


def rival_calibration(rows: list[dict[str, Any]], min_d: float = 0.03) -> dict[str, Any]:
    """How often the rival frames beyond the kept frame's own sigma are nearer the truth,
    against how often the sigma's mixture puts the truth there."""
    n, expected, observed = 0, 0.0, 0
    for r in rows:
        own = r.get("own_logf_std")
        rivals = r.get("rivals") or []
        if "f" not in r or own is None or not rivals:
            continue
        e = math.log1p(r["focal_err"])  # log(f_kept / f_true)
        den = 1.0 + sum(w for w, _ in rivals)
        for w, d in rivals:
            if abs(d) <= max(own, min_d):
                continue
            n += 1
            expected += w / den
            observed += int(abs(e + d) < abs(e))  # log(f_rival / f_true) = e + d
    return {"n_beyond_own": n, "expected_at_rival": expected, "observed_nearer": observed}


class _PriorAtTruth:
    """Centres ``autovp``'s default focal prior on one photo's true focal length while a
    ``detect_vanishing_points`` call runs (a diagnostic: ``--prior-at-truth``).

    Both the wide prior the hypotheses are scored with (``_F_PRIOR_REL``) and the default
    prior a loose photo is combined with (``_default_focal_prior``: its centre only, the
    sigma kept) are moved. What misses remain are the ones the photo's lines make: a
    simulation of a camera whose focal length the default prior matches (issue 24's phone
    at 0.97 times the longer side sits near ``_F_PRIOR_REL`` = 1.0), never a headline.
    """

    def __init__(self, focal_rel: float) -> None:
        self.focal_rel = float(focal_rel)

    def __enter__(self) -> _PriorAtTruth:
        self._rel, self._default = autovp._F_PRIOR_REL, autovp._default_focal_prior
        focal_rel, default = self.focal_rel, self._default

        def at_truth(width_px: float, height_px: float) -> tuple[float, float]:
            return focal_rel, default(width_px, height_px)[1]

        vars(autovp)["_F_PRIOR_REL"] = focal_rel
        vars(autovp)["_default_focal_prior"] = at_truth
        return self

    def __exit__(self, *exc: object) -> None:
        vars(autovp)["_F_PRIOR_REL"] = self._rel
        vars(autovp)["_default_focal_prior"] = self._default


def run(
    data: list[dict[str, Any]], use_exif: bool, prior_at_truth: bool = False, **options: Any
) -> list[dict[str, Any]]:
    """Run ``detect_vanishing_points`` on each photo and compare it with the truth.

    Parameters
    ----------
    data
        Truth records (the loaders').
    use_exif
        Read the photo's EXIF focal length as a prior.
    prior_at_truth
        Centre the default focal prior on each photo's true focal length (same sigma;
        :class:`_PriorAtTruth`): a diagnostic that leaves only the misses the lines make.
    **options
        Passed to ``detect_vanishing_points``.

    Returns
    -------
    list of dict
        One row a photo.
    """
    rows = []
    for t in data:
        t0 = time.perf_counter()
        row: dict[str, Any] = {
            "set": t["set"],
            "name": t["name"],
            "f_true": t["f"],
            "has_horizon_truth": t["up"] is not None,
        }
        if "half" in t:
            row["half"] = t["half"]
        if t["up"] is not None:
            row["pitch_true_deg"] = pitch_roll_from_up(t["up"])[0]
        size = t.get("size")
        if prior_at_truth and size is None:
            size = load_image(t["path"]).shape[1::-1]
        focal_rel = t["f"] / max(size) if prior_at_truth and size is not None else None
        try:
            with _RivalRecorder() as rec, contextlib.ExitStack() as stack:
                if focal_rel is not None:
                    stack.enter_context(_PriorAtTruth(focal_rel))
                res = detect_vanishing_points(t["path"], seed=0, use_exif=use_exif, **options)
        except NotEnoughStructureError as exc:
            row.update(error=str(exc), time_s=time.perf_counter() - t0)
            rows.append(row)
            continue
        row.update(
            time_s=time.perf_counter() - t0,
            f=res.focal_px,
            focal_err=(res.focal_px - t["f"]) / t["f"],
            focal_std_rel=res.focal_std_rel,
            focal_source=res.focal_source,
            confidence=res.confidence,
            warnings=list(getattr(res, "warnings", [])),
            hz_err=horizon_err(res.up_in_cam, res.focal_px, res.principal_point, t),
            pitch_deg=res.pitch_deg,
            n_lines=list(res.n_lines),
            k1=res.distortion,
            k1_std=res.distortion_std,
            pitch_std_deg=res.pitch_std_deg,
            roll_std_deg=res.roll_std_deg,
            rivals=rec.modes,
            own_logf_std=rec.own_logf_std,
            focal_std_parts=dict(getattr(res, "focal_std_parts", {}) or {}),
            line_residual_rms_px=getattr(res, "line_residual_rms_px", math.nan),
            line_scatter_deg=getattr(res, "line_scatter_deg", math.nan),
        )
        if t["up"] is not None:
            p_true, r_true = pitch_roll_from_up(t["up"])
            row.update(pitch_err_deg=res.pitch_deg - p_true, roll_err_deg=res.roll_deg - r_true)
            vb = vertical_bias_deg(res, t)
            if vb is not None:
                row.update(vertical_turn_deg=vb[0], vertical_convergence_deg=vb[1])
        rows.append(row)
    return rows


def roc_auc(score: np.ndarray, positive: np.ndarray) -> float | None:
    """Area under the ROC curve of ``score`` predicting ``positive`` (Mann-Whitney)."""
    pos, neg = score[positive], score[~positive]
    if len(pos) == 0 or len(neg) == 0:
        return None
    gt = (pos[:, None] > neg[None, :]).sum() + 0.5 * (pos[:, None] == neg[None, :]).sum()
    return float(gt / (len(pos) * len(neg)))


def _tilt_coverage(ok: list[dict[str, Any]]) -> dict[str, Any]:
    """1/2-sigma coverage and median error/sigma of the stated pitch and roll sigmas."""
    out: dict[str, Any] = {}
    for k in ("pitch", "roll"):
        z = np.array(
            [
                abs(r[f"{k}_err_deg"]) / r[f"{k}_std_deg"]
                for r in ok
                if f"{k}_err_deg" in r and r.get(f"{k}_std_deg")
            ]
        )
        if len(z):
            out[f"{k}_sigma_cover_1"] = float(np.mean(z <= 1))
            out[f"{k}_sigma_cover_2"] = float(np.mean(z <= 2))
            out[f"{k}_median_err_over_sigma"] = float(np.median(z))
            errs = [abs(r[f"{k}_err_deg"]) for r in ok if f"{k}_err_deg" in r]
            out[f"{k}_abs_err_median_deg"] = float(np.median(errs))
    return out


def _warned_up(row: dict[str, Any]) -> bool:
    """Whether the steep looking-up warning ("..., or up 60 degrees (...)") was given."""
    return any(" or up " in w for w in row.get("warnings", []))


#: Issue 24's bars on handheld street photos: with the EXIF stripped, the focal length
#: within 10 % on this share and confidently wrong on at most this share (1 in 29); with the
#: EXIF kept, within 10 % on this share.
ISSUE24_STRIPPED_WITHIN_10 = 0.75
ISSUE24_STRIPPED_CONFIDENTLY_WRONG = 1.0 / 29.0
ISSUE24_KEPT_WITHIN_10 = 0.95


def issue24_bars(stripped: dict[str, Any] | None, kept: dict[str, Any] | None) -> dict[str, Any]:
    """Issue 24's main check on a set of street photos, from two :func:`summarise` results.

    Parameters
    ----------
    stripped, kept
        The summaries of the runs with the EXIF ignored and with it as the prior (either
        may be None: that bar is then not judged).

    Returns
    -------
    dict
        For each bar its measured value, the bar and ``met`` (None where not judged).
    """

    def bar(value: float | None, limit: float, at_least: bool) -> dict[str, Any]:
        met = None if value is None else (value >= limit if at_least else value <= limit)
        return {"value": value, "bar": limit, "met": met}

    cw = None
    if stripped and stripped.get("n_images"):
        cw = stripped["n_confidently_wrong"] / stripped["n_images"]
    return {
        "stripped_within_10pct": bar(
            stripped.get("share_focal_within_10pct") if stripped else None,
            ISSUE24_STRIPPED_WITHIN_10,
            True,
        ),
        "stripped_confidently_wrong_share": bar(cw, ISSUE24_STRIPPED_CONFIDENTLY_WRONG, False),
        "kept_within_10pct": bar(
            kept.get("share_focal_within_10pct") if kept else None,
            ISSUE24_KEPT_WITHIN_10,
            True,
        ),
    }


def sigma_terms(rows: list[dict[str, Any]]) -> dict[str, Any] | None:
    """Which term decides the photos' own focal sigma (``AutoVPResult.focal_std_parts``).

    Returns
    -------
    dict or None
        ``median``: the median of each term (standard deviations of ``log(focal)``);
        ``decides``: on how many photos each term is the largest (``least_squares`` and
        ``jackknife`` counted as one, ``statistical``: the larger of the two is taken);
        ``share_of_variance``: each term's share of the summed variance over the photos.
        None when no photo has the terms (the focal length given, or an EXIF prior).
    """
    parts = [r["focal_std_parts"] for r in rows if r.get("focal_std_parts")]
    if not parts:
        return None
    names = [k for k in parts[0] if k not in ("least_squares", "jackknife")]
    table = {
        "statistical": [max(p["least_squares"], p["jackknife"]) for p in parts],
        **{k: [p.get(k, 0.0) for p in parts] for k in names},
    }
    arr = {
        k: np.nan_to_num(np.array(v, dtype=float), nan=0.0, posinf=1.0) for k, v in table.items()
    }
    keys = list(arr)
    stacked = np.vstack([arr[k] for k in keys])
    largest = np.argmax(stacked, axis=0)
    var = (stacked**2).sum(axis=1)
    return {
        "n": len(parts),
        "median": {k: float(np.median(arr[k])) for k in keys},
        "decides": {k: int(np.sum(largest == i)) for i, k in enumerate(keys)},
        "share_of_variance": {
            k: float(var[i] / var.sum()) if var.sum() > 0 else 0.0 for i, k in enumerate(keys)
        },
    }


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    ok = [r for r in rows if "f" in r]
    n = len(rows)
    fe = np.array([r["focal_err"] for r in ok])
    ale = np.abs(np.log1p(fe)) if len(fe) else np.zeros(0)
    sig = np.array([r["focal_std_rel"] if r["focal_std_rel"] else math.nan for r in ok])
    sig = np.where(np.isfinite(sig) & (sig > 0), sig, np.inf)
    z = ale / sig
    conf = np.array([r["confidence"] for r in ok])
    bad = np.abs(fe) > 0.10
    warned = np.array([bool(r["warnings"]) for r in ok])
    confidently_wrong = bad & (ale > 2 * sig) & ~warned & (conf >= 0.5)
    hz = [r["hz_err"] for r in rows if r.get("hz_err") is not None] + [
        math.inf for r in rows if "f" not in r and r["has_horizon_truth"]
    ]
    with_up = [r for r in rows if "pitch_true_deg" in r]
    all_abs = np.concatenate([np.abs(fe), np.full(n - len(ok), np.inf)])
    out: dict[str, Any] = {
        "n_images": n,
        "n_refused": n - len(ok),
        "share_focal_within_10pct": float(np.mean(all_abs <= 0.10)) if n else None,
        "share_focal_within_20pct": float(np.mean(all_abs <= 0.20)) if n else None,
        "focal_err_pct_percentiles_5_25_50_75_95": (
            [float(100 * np.percentile(fe, q)) for q in (5, 25, 50, 75, 95)] if len(fe) else None
        ),
        "focal_abs_err_median_pct": float(100 * np.median(all_abs)) if n else None,
        "sigma_cover_1": float(np.mean(z <= 1)) if len(z) else None,
        "sigma_cover_2": float(np.mean(z <= 2)) if len(z) else None,
        "median_err_over_sigma": float(np.median(z)) if len(z) else None,
        "median_focal_std_rel": float(np.median(sig[np.isfinite(sig)]))
        if np.isfinite(sig).any()
        else None,
        "roc_auc_confidence_vs_err10": roc_auc(1.0 - conf, bad) if len(ok) else None,
        "n_confidently_wrong": int(confidently_wrong.sum()),
        "n_warned": int(warned.sum()),
        # the steep looking-up warning ("... or up 60 degrees ..."), and where the truth
        # gives gravity, how often it fires on a photo that does not look up 45 degrees
        "n_warned_looking_up": int(sum(_warned_up(r) for r in ok)),
        "n_warned_looking_up_wrongly": int(
            sum(_warned_up(r) and r.get("pitch_true_deg", -90.0) > -45.0 for r in with_up)
        ),
        **_tilt_coverage(ok),
        "n_with_horizon_truth": len(hz),
        "horizon_auc_pct": 100.0 * horizon_auc(hz) if hz else None,
        "horizon_err_median": float(np.median(hz)) if hz else None,
        "share_pitch_within_5deg": (
            float(np.mean([abs(r.get("pitch_err_deg", math.inf)) <= 5.0 for r in with_up]))
            if with_up
            else None
        ),
        "time_median_s": float(np.median([r["time_s"] for r in rows])) if rows else None,
        "rival_calibration": rival_calibration(rows),
        "sigma_terms": sigma_terms(ok),
        "line_scatter": line_scatter(ok, z),
        **_vertical_bias_rms(ok),
    }
    return out


def line_scatter(ok: list[dict[str, Any]], z: np.ndarray) -> dict[str, Any] | None:
    """The photos' line scatter (``AutoVPResult.line_scatter_deg``) and the median
    error/sigma of the focal length by its terciles: would the scatter tell the photos whose
    sigma is too wide or too narrow (issue 24 item 4)?

    Returns
    -------
    dict or None
        ``median_deg``, ``tercile_edges_deg`` and ``median_err_over_sigma_by_tercile``
        (low, middle, high); None with fewer than 6 photos that have it.
    """
    sc = np.array([r.get("line_scatter_deg", math.nan) for r in ok], dtype=float)
    has = np.isfinite(sc) & np.isfinite(z)
    if np.count_nonzero(has) < 6:
        return None
    lo, hi = np.percentile(sc[has], [100.0 / 3.0, 200.0 / 3.0])
    bins = [has & (sc <= lo), has & (sc > lo) & (sc <= hi), has & (sc > hi)]
    return {
        "median_deg": float(np.median(sc[has])),
        "tercile_edges_deg": [float(lo), float(hi)],
        "median_err_over_sigma_by_tercile": [float(np.median(z[b])) for b in bins],
    }


def _vertical_bias_rms(ok: list[dict[str, Any]]) -> dict[str, Any]:
    """Root mean square of :func:`vertical_bias_deg`'s turn and convergence over the photos
    with gravity truth (degrees; against ``autovp.BIAS_DEG``, which the sigma assumes for
    both), and how many photos had them."""
    turn = np.array([r["vertical_turn_deg"] for r in ok if "vertical_turn_deg" in r])
    conv = np.array([r.get("vertical_convergence_deg", math.nan) for r in ok])
    conv = conv[np.isfinite(conv)]
    if not len(turn):
        return {}
    return {
        "n_vertical_bias": len(turn),
        "vertical_turn_rms_deg": float(np.sqrt(np.mean(turn**2))),
        "vertical_convergence_rms_deg": float(np.sqrt(np.mean(conv**2))) if len(conv) else None,
    }


def plots(runs: dict[str, list[dict[str, Any]]], out_dir: Path) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        log.warning("matplotlib missing: no plots")
        return
    rows = runs["no EXIF"]
    sets = sorted({r["set"] for r in rows})
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for s in sets:
        fe = [100 * r["focal_err"] for r in rows if r["set"] == s and "f" in r]
        ax.hist(np.clip(fe, -60, 60), bins=48, range=(-60, 60), alpha=0.5, label=s)
    ax.axvspan(-10, 10, color="g", alpha=0.1)
    ax.set_xlabel("focal length error (%), focal length not given, EXIF ignored")
    ax.set_ylabel("photos")
    ax.set_title("Real photos: focal length error")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out_dir / "vp_real_focal.png", dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for s in sets:
        hz = np.sort(
            [r.get("hz_err") or math.inf for r in rows if r["set"] == s and r["has_horizon_truth"]]
        )
        if not len(hz):
            continue
        ax.step(
            np.concatenate([[0], hz]),
            np.arange(len(hz) + 1) / len(hz),
            where="post",
            label=f"{s} (AUC {100 * horizon_auc(list(hz)):.1f} %)",
        )
    ax.set_xlim(0, 0.25)
    ax.set_ylim(0, 1)
    ax.set_xlabel("horizon error / image height")
    ax.set_ylabel("share of photos")
    ax.set_title("Real photos: horizon error")
    if ax.get_legend_handles_labels()[0]:  # no set with horizon truth: no legend
        ax.legend()
    fig.tight_layout()
    fig.savefig(out_dir / "vp_real_horizon.png", dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ok = [r for r in rows if "f" in r]
    z = np.sort(
        [
            abs(math.log1p(r["focal_err"])) / r["focal_std_rel"] if r["focal_std_rel"] else math.inf
            for r in ok
        ]
    )
    ax.step(z, np.arange(1, len(z) + 1) / len(z), where="post", label="measured")
    from scipy.stats import halfnorm

    xs = np.linspace(0, 4, 200)
    ax.plot(xs, halfnorm.cdf(xs), "k--", label="Gaussian")
    ax.set_xlim(0, 4)
    ax.set_xlabel("|log focal error| / stated focal_std_rel")
    ax.set_ylabel("share of photos")
    ax.set_title("Real photos: calibration of the stated focal sigma")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out_dir / "vp_real_sigma.png", dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--strecha", type=Path, default=DEFAULT_STRECHA)
    ap.add_argument("--sceaux", type=Path, default=DEFAULT_SCEAUX)
    ap.add_argument("--yud", type=Path, default=DEFAULT_YUD)
    ap.add_argument("--perrot", type=Path, default=DEFAULT_PERROT)
    ap.add_argument("--lund", type=Path, default=DEFAULT_LUND)
    ap.add_argument(
        "--exif-dir",
        type=Path,
        action="append",
        default=[
            Path(d) for d in os.environ.get("CAMLOC_EXIF_PHOTO_DIRS", "").split(os.pathsep) if d
        ],
        help="a folder of outdoor photos whose EXIF gives the focal length (repeatable)",
    )
    ap.add_argument("--limit", type=int, default=None, help="at most N photos per set")
    ap.add_argument(
        "--bias-deg",
        type=float,
        default=None,
        help="the systematic line bias of the focal sigma (degrees; default autovp.BIAS_DEG): "
        "how far the sigma's size rests on it",
    )
    ap.add_argument("--sets", default="strecha,sceaux,perrot,lund,street-photos,exif,yud")
    ap.add_argument("--out", type=Path, default=HERE / "out")
    ap.add_argument(
        "--street-frames",
        type=int,
        default=30,
        help="rendered traffic frames in the 'street' set (not run unless --sets has it)",
    )
    ap.add_argument(
        "--synth-photos",
        type=int,
        default=40,
        help="synthetic street photos per half in 'street-synth' (not run unless --sets has it)",
    )
    ap.add_argument(
        "--synth-focal-rel",
        type=float,
        default=None,
        help="the synthetic street photos' focal length in longer sides (0.97: issue 24's "
        "phone) instead of each seed's 0.7-1.3",
    )
    ap.add_argument(
        "--no-distortion", action="store_true", help="do not fit the lens distortion k1"
    )
    ap.add_argument(
        "--drive-photos",
        type=Path,
        default=PHOTOS,
        help="the folder the driving frames' 'file' paths are relative to",
    )
    ap.add_argument("--drive-truth", type=Path, default=STREET_TRUTH)
    ap.add_argument(
        "--street-photos",
        type=Path,
        default=STREET_PHOTOS,
        help="the handheld street photos' manifest (files relative to --drive-photos)",
    )
    ap.add_argument(
        "--prior-at-truth",
        action="store_true",
        help="also run EXIF stripped with the default focal prior centred on each photo's "
        "true focal length (same sigma): a diagnostic simulation of a camera the default "
        "prior matches (issue 24's phone), leaving the misses the lines make; its own row, "
        "never the headline",
    )
    ap.add_argument(
        "--no-exif-kept",
        action="store_true",
        help="skip the run with the EXIF prior (only the EXIF-stripped runs)",
    )
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    wanted = set(args.sets.split(","))
    data: list[dict[str, Any]] = []
    for name, root, loader in (
        ("strecha", args.strecha, load_strecha),
        ("sceaux", args.sceaux, load_sceaux),
        ("perrot", args.perrot, load_perrot),
        ("lund", args.lund, load_lund),
        ("yud", args.yud, load_yud_set),
    ):
        halves = {"lund-dev": LUND_DEV, "lund-held-out": LUND_HELD_OUT} if name == "lund" else {}
        numbers = {n for h, ns in halves.items() if h in wanted for n in ns}
        if name not in wanted and not numbers:
            continue
        if not root.exists():
            log.warning("%s: not found at %s (%s)", name, root, HOW_TO_GET)
            continue
        loaded = loader(root)
        if name not in wanted:
            loaded = [t for t in loaded if _lund_number(t) in numbers]
        data.extend(loaded[: args.limit])
    if "street" in wanted:
        data.extend(load_street_set(args.street_frames))
    drive_halves = tuple(h for h in DRIVE_HALVES if "drive" in wanted or f"drive-{h}" in wanted)
    if drive_halves:
        drive = load_drive_set(args.drive_photos, args.drive_truth, drive_halves)
        if not drive:
            log.warning(
                "drive: no frames found in %s (run benchmarks/fetch_real_photos.sh)",
                args.drive_photos,
            )
        data.extend(drive[: args.limit])
    synth_halves = tuple(
        h for h in STREET_SYNTH_HALVES if {"street-synth", f"street-synth-{h}"} & wanted
    )
    if synth_halves:
        data.extend(load_street_synth(synth_halves, args.synth_photos, args.synth_focal_rel))
    street_halves = street_photo_halves(wanted)
    if street_halves:
        street = load_street_photos(args.drive_photos, args.street_photos, street_halves)
        if not street:
            log.warning(
                "street-photos: none found in %s (run benchmarks/fetch_real_photos.sh)",
                args.drive_photos,
            )
        data.extend(street[: args.limit])
    for d in args.exif_dir if "exif" in wanted else []:
        if not d.is_dir():
            log.warning("--exif-dir %s: not a folder", d)
            continue
        data.extend(load_exif_folder(d, d.name)[: args.limit])
    if not data:
        log.error("no photos found: %s", HOW_TO_GET)
        return 2
    opts: dict[str, Any] = {"estimate_distortion": False} if args.no_distortion else {}
    if args.bias_deg is not None:
        opts["bias_deg"] = args.bias_deg
    runs = {"no EXIF": run(data, use_exif=False, **opts)}
    if args.prior_at_truth:
        runs[PRIOR_AT_TRUTH_RUN] = run(data, use_exif=False, prior_at_truth=True, **opts)
    exif_data = [t for t in data if t.get("exif")] if not args.no_exif_kept else []
    if exif_data:
        runs["EXIF prior"] = run(exif_data, use_exif=True, **opts)
    summary: dict[str, Any] = {}
    for tag, rows in runs.items():
        summary[tag] = {"all": summarise(rows)}
        for s in sorted({r["set"] for r in rows}):
            summary[tag][s] = summarise([r for r in rows if r["set"] == s])
            if s == "lund":  # the development and the held-out halves
                for half, scenes in (("dev", LUND_DEV), ("held-out", LUND_HELD_OUT)):
                    part = [r for r in rows if r["set"] == s and _lund_number(r) in scenes]
                    if part:
                        summary[tag][f"lund {half} {scenes}"] = summarise(part)
            if s in DRIVE_SETS:  # the driving frames' development and held-out halves
                for half in DRIVE_HALVES:
                    part = [r for r in rows if r["set"] == s and r.get("half") == half]
                    if part:
                        summary[tag][f"{s} {half}"] = summarise(part)
            if s in ("street-photos", "street-synth"):  # development and held-out halves
                for half in STREET_PHOTO_HALVES:
                    part = [r for r in rows if r["set"] == s and r.get("half") == half]
                    if part:
                        summary[tag][f"{s} {half}"] = summarise(part)
            if s in SCENE_SETS:  # and by scene ("lund/7-heidelberg-castle/...")
                for scene in sorted({r["name"].split("/")[1] for r in rows if r["set"] == s}):
                    summary[tag][f"{s} / {scene}"] = summarise(
                        [r for r in rows if r["set"] == s and r["name"].split("/")[1] == scene]
                    )
        for half in DRIVE_HALVES:
            part = [r for r in rows if r["set"] in DRIVE_SETS and r.get("half") == half]
            if part:
                summary[tag][f"drive {half} (all driving sets)"] = summarise(part)
        outdoor = [r for r in rows if r["set"] not in ("yud", "street", "street-synth")]
        if outdoor and len(outdoor) != len(rows):
            summary[tag]["outdoor (all but yud)"] = summarise(outdoor)
        # photos looking up at a building, where the truth gives gravity
        up = [r for r in outdoor if r.get("pitch_true_deg", 0.0) < -LOOKING_UP_DEG]
        if up:
            summary[tag][f"outdoor looking up > {LOOKING_UP_DEG:.0f} deg"] = summarise(up)
    # issue 24's bars, on the street photos and on any --exif-dir folder (a user's own
    # street photos, e.g. the issue's 29)
    exif_sets = {d.name for d in args.exif_dir} if "exif" in wanted else set()
    bars = {}
    for key in sorted(summary.get("no EXIF", {})):
        if key.startswith(("street-photos", "street-synth")) or key in exif_sets:
            bars[key] = issue24_bars(
                summary["no EXIF"].get(key), summary.get("EXIF prior", {}).get(key)
            )
    if bars:
        summary["issue 24 bars"] = bars
    # the same bars on the simulation (EXIF stripped only), under its own label
    sim_bars = {
        key: issue24_bars(summary[PRIOR_AT_TRUTH_RUN].get(key), None)
        for key in bars
        if PRIOR_AT_TRUTH_RUN in summary
    }
    if sim_bars:
        summary[SIM_BARS] = sim_bars
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "vp_real.json", "w", encoding="utf-8") as fh:
        json.dump({"summary": summary, "per_image": runs}, fh, indent=1, default=float)
    plots(runs, args.out)
    keys = [
        ("n_images", "n", "{}"),
        ("share_focal_within_10pct", "f<=10%", "{:.2f}"),
        ("focal_abs_err_median_pct", "|f err| med%", "{:.1f}"),
        ("sigma_cover_1", "1sig cov", "{:.2f}"),
        ("sigma_cover_2", "2sig cov", "{:.2f}"),
        ("median_err_over_sigma", "med err/sig", "{:.2f}"),
        ("roc_auc_confidence_vs_err10", "ROC AUC", "{:.2f}"),
        ("n_confidently_wrong", "conf.wrong", "{}"),
        ("n_warned", "warned", "{}"),
        ("n_warned_looking_up", "warned up", "{}"),
        ("horizon_auc_pct", "hz AUC %", "{:.1f}"),
        ("share_pitch_within_5deg", "pitch<=5deg", "{:.2f}"),
        ("pitch_sigma_cover_1", "pitch 1sig", "{:.2f}"),
        ("pitch_sigma_cover_2", "pitch 2sig", "{:.2f}"),
        ("pitch_median_err_over_sigma", "p err/sig", "{:.2f}"),
        ("roll_sigma_cover_1", "roll 1sig", "{:.2f}"),
        ("roll_sigma_cover_2", "roll 2sig", "{:.2f}"),
        ("roll_median_err_over_sigma", "r err/sig", "{:.2f}"),
        ("n_refused", "refused", "{}"),
    ]
    lines = [f"{'run / set':60s} " + " ".join(f"{k[1]:>12s}" for k in keys)]
    for tag, per in summary.items():
        if tag in ("issue 24 bars", SIM_BARS):
            continue
        for s, sm in per.items():
            cells = []
            for k, _, fmt in keys:
                v = sm.get(k)
                cells.append(f"{'-' if v is None else fmt.format(v):>12s}")
            lines.append(f"{(tag + ' / ' + s):60s} " + " ".join(cells))
    for s, sm in summary.get("no EXIF", {}).items():
        if sm.get("n_vertical_bias"):
            conv_rms = sm.get("vertical_convergence_rms_deg")
            lines.append(
                f"vertical lines' bias / {s}: turn rms {sm['vertical_turn_rms_deg']:.3f} deg, "
                f"convergence rms {'-' if conv_rms is None else f'{conv_rms:.3f}'} deg "
                f"({sm['n_vertical_bias']} photos; the sigma assumes {autovp.BIAS_DEG} for both)"
            )
        ls = sm.get("line_scatter")
        if ls:
            zt = ls["median_err_over_sigma_by_tercile"]
            lines.append(
                f"line scatter / {s}: median {ls['median_deg']:.3f} deg; median err/sigma by "
                f"tercile {zt[0]:.2f} / {zt[1]:.2f} / {zt[2]:.2f}"
            )
        st = sm.get("sigma_terms")
        if st:
            lines.append(
                f"sigma terms / {s}: largest on "
                + ", ".join(f"{k} {v}" for k, v in st["decides"].items() if v)
                + "; median "
                + ", ".join(f"{k} {v:.3f}" for k, v in st["median"].items())
            )
    for label, judged_bars in (("issue 24 bar", bars), ("issue 24 bar, SIMULATION", sim_bars)):
        for key, judged in judged_bars.items():
            for name, b in judged.items():
                if b["value"] is None:
                    continue
                verdict = "met" if b["met"] else "NOT met"
                lines.append(
                    f"{label} / {key} / {name}: {b['value']:.3f} (bar {b['bar']:.3f}) {verdict}"
                )
    log.info("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
