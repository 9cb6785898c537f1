"""A rendered test video is the same whatever ran before it in the process.

The generators' sensor noise comes from OpenCV's RNG, one per thread for the whole process:
without a reset, a video's noise depended on how many draws earlier tests made, and
``test_radar_twobox`` read the van 5.5 % uncertain (its bound: 5 %) after
``test_video_lines`` and ``test_radar`` had rendered theirs.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from camloc_geo.testing._video import write_video


def _frames(path: Path) -> list[np.ndarray]:
    cap = cv2.VideoCapture(str(path))
    out = []
    ok, frame = cap.read()
    while ok:
        out.append(frame)
        ok, frame = cap.read()
    cap.release()
    return out


def test_noise_does_not_depend_on_earlier_draws(tmp_path: Path) -> None:
    def grey(_t: float) -> np.ndarray:
        return np.full((48, 64, 3), 120, np.uint8)

    write_video(
        tmp_path / "a.avi",
        grey,
        fps=10.0,
        n_frames=3,
        size=(64, 48),
        fourcc="FFV1",
        noise_sigma=5.0,
    )
    cv2.randn(np.empty((100, 100), np.float32), 0.0, 1.0)  # another user of the RNG
    write_video(
        tmp_path / "b.avi",
        grey,
        fps=10.0,
        n_frames=3,
        size=(64, 48),
        fourcc="FFV1",
        noise_sigma=5.0,
    )
    a, b = _frames(tmp_path / "a.avi"), _frames(tmp_path / "b.avi")
    assert len(a) == len(b) == 3
    assert any(np.any(f != 120) for f in a)  # the noise is there
    for fa, fb in zip(a, b, strict=True):
        np.testing.assert_array_equal(fa, fb)
