"""Writing a rendered video: one loop for every traffic generator of ``camloc_geo.testing``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import numpy.typing as npt

__all__ = ["write_video"]


def write_video(
    path: Path,
    frame_at: Callable[[float], npt.NDArray[np.uint8]],
    *,
    fps: float,
    n_frames: int,
    size: tuple[int, int],
    fourcc: str,
    noise_sigma: float,
) -> None:
    """Write ``n_frames`` frames ``frame_at(t_s)`` (BGR uint8, ``size`` = (w, h)) to ``path``.

    Each frame gets Gaussian sensor noise of ``noise_sigma`` grey levels (OpenCV's RNG, as the
    generators always used, reset to a fresh process's state first: the same video whatever
    was rendered before it). Raises RuntimeError when OpenCV cannot write ``fourcc`` there.
    """
    import cv2

    w, h = size
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*fourcc), fps, (w, h))
    if not writer.isOpened():
        raise RuntimeError(f"OpenCV cannot write {fourcc} video to {path}")
    noise = np.empty((h, w, 3), np.float32)
    # OpenCV's RNG is one per thread for the whole process: reset it to the state a fresh
    # process starts with (seed 0 is that state), so a video's noise does not depend on what
    # was rendered before it (a test's video differed with the tests run before it).
    cv2.setRNGSeed(0)
    try:
        for i in range(n_frames):
            frame = frame_at(i / fps)
            if noise_sigma > 0:
                cv2.randn(noise, 0.0, float(noise_sigma))  # type: ignore[call-overload]
                frame = np.clip(frame + noise, 0, 255).astype(np.uint8)
            writer.write(frame)
    finally:
        writer.release()
