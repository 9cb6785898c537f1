"""Size limits on untrusted input, and the checks that enforce them before any work is done.

Scenes and images may come from strangers (the crowd, the future web service): every size
that drives time or memory is bounded here, and every refusal names the limit.
"""

from __future__ import annotations

import os
import re
import stat
import warnings
from pathlib import Path

from camloc_geo._errors import InputError

__all__ = [
    "FOCAL_BOUNDS_REL",
    "MAX_ANNOTATORS",
    "MAX_IMAGE_PIXELS",
    "MAX_LANDMARKS",
    "MAX_LINES_PER_AXIS",
    "MAX_REFERENCES",
    "MAX_SCENE_BYTES",
    "MAX_TRACKS_BYTES",
    "MAX_TRACK_BOXES",
    "MAX_VIDEO_FRAMES",
    "MAX_VIDEO_PIXELS",
    "MAX_WEIGHT",
    "MIN_WEIGHT",
    "check_image_file",
    "check_regular_file",
]

MAX_SCENE_BYTES = 10_000_000
"""Largest scene file read (bytes)."""

MAX_ANNOTATORS = 200
"""Most annotators in one scene."""

MAX_LINES_PER_AXIS = 200
"""Most vanishing-line segments one annotator may draw for one axis."""

MAX_REFERENCES = 1000
"""Most reference pixels in one scene."""

MAX_LANDMARKS = 1000
"""Most landmarks (and intersection corners) in one scene."""

MIN_WEIGHT = 1e-6
MAX_WEIGHT = 1e6
"""Range of a reference's relative weight."""

FOCAL_BOUNDS_REL = (0.3, 6.0)
"""Focal lengths searched when unknown, and plausible ones (an EXIF tag outside is broken),
as multiples of the longer image side."""

MAX_IMAGE_PIXELS = 50_000_000
"""Largest image decoded (width × height), checked from the file header before decoding."""

MAX_VIDEO_PIXELS = 3840 * 2160
"""Largest video frame processed by the radar (width × height): 4K UHD."""

MAX_VIDEO_FRAMES = 180_000
"""Most frames the radar processes in one run (2 h at 25 fps); longer videos are refused."""

MAX_TRACKS_BYTES = 200_000_000
"""Largest ``--tracks`` file read (bytes)."""

MAX_TRACK_BOXES = 2_000_000
"""Most boxes in one ``--tracks`` file."""


def check_regular_file(path: str | os.PathLike[str], what: str = "file") -> Path:
    """``path`` as a :class:`Path` if it is a regular file; never opens it.

    A FIFO, a device or a directory would block or fail on reading, so it is refused.

    Raises
    ------
    InputError
        Missing, or not a regular file.
    """
    p = Path(path)
    try:
        mode = p.stat().st_mode
    except FileNotFoundError:
        raise InputError(f"{what} not found, cannot read it: {p}") from None
    except OSError as exc:
        raise InputError(f"cannot read {what} {p}: {exc.strerror or exc}") from None
    if not stat.S_ISREG(mode):
        raise InputError(f"{what} {p} is not a regular file")
    return p


def check_image_file(path: str | os.PathLike[str]) -> tuple[int, int]:
    """Width and height of an image file, read from its header; refuses over-large images.

    Raises
    ------
    InputError
        Not a regular file, or more than :data:`MAX_IMAGE_PIXELS` pixels.
    """
    p = check_regular_file(path, "image")
    try:
        from PIL import Image
    except ImportError:  # pragma: no cover - Pillow is a dependency
        return (0, 0)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # Pillow's own bomb warning: we check below
            with Image.open(p) as im:
                width, height = im.size
    except Image.DecompressionBombError as exc:  # far above our limit too
        found = re.search(r"\((\d+) pixels\)", str(exc))
        size = f" ({int(found.group(1)) / 1e6:.0f} MP)" if found else ""
        raise InputError(
            f"image {p} is too large{size}; the supported limit is "
            f"{MAX_IMAGE_PIXELS / 1e6:g} megapixels"
        ) from None
    except Exception:  # not a format Pillow reads: OpenCV decodes it or says so
        return (0, 0)
    if width * height > MAX_IMAGE_PIXELS:
        raise InputError(
            f"image {p} is {width}x{height} pixels ({width * height / 1e6:.0f} MP); "
            f"the supported limit is {MAX_IMAGE_PIXELS / 1e6:g} megapixels"
        )
    return int(width), int(height)
