"""Session 38 QA: ``camloc vp --focal-px nan`` names the value as given.

The message said ``got [nan]`` (the value wrapped in the list it was checked in).
"""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from camloc_geo._errors import InputError
from camloc_geo.api import vanishing_points


@pytest.mark.parametrize("focal", [math.nan, math.inf, "abc"])
def test_a_focal_length_that_is_no_number_is_named_as_given(tmp_path: Path, focal: object) -> None:
    photo = tmp_path / "p.png"
    cv2.imwrite(str(photo), np.full((64, 64, 3), 128, np.uint8))
    with pytest.raises(InputError) as info:
        vanishing_points(photo, focal_px=focal)  # type: ignore[arg-type]
    assert str(info.value) == f"focal_px must be a positive number of pixels, got {focal!r}"
