"""``camloc_geo.api.vanishing_points(path, use_exif=True)`` reads the photo's EXIF (stop 41).

The function loaded the photo into an array before the fit, and an array carries no EXIF:
``use_exif=True`` passed through it did nothing (a rendered street photo tagged with its true
focal length came back at +12 %, ``focal_source`` ``"prior"``). The tags are now read from
the file before it is loaded, as ``detect_vanishing_points`` reads them given the path.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from camloc_geo import api
from camloc_geo.autovp import detect_vanishing_points
from camloc_geo.testing.street_photo_render import StreetPhoto, render_street_photo

_EXIF_IFD = 0x8769
_FOCAL_35MM = 0xA405


@pytest.fixture(scope="module")
def tagged(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, StreetPhoto]:
    """A rendered street photo (development seed 29) saved as a JPEG whose
    ``FocalLengthIn35mmFilm`` is its true focal length."""
    photo = render_street_photo(29)
    h, w = photo.image.shape[:2]
    f35 = round(photo.focal_px * math.hypot(36.0, 24.0) / math.hypot(w, h))
    im = Image.fromarray(np.ascontiguousarray(photo.image[:, :, ::-1]))
    exif = im.getexif()
    exif.get_ifd(_EXIF_IFD)[_FOCAL_35MM] = f35
    path = tmp_path_factory.mktemp("exif") / "street.jpg"
    im.save(path, exif=exif, quality=95)
    return path, photo


def test_use_exif_reaches_the_fit(tagged: tuple[Path, StreetPhoto]) -> None:
    path, photo = tagged
    res = api.vanishing_points(path, use_exif=True)
    assert res.focal_source == "exif-35mm"
    assert abs(math.log(res.focal_px / photo.focal_px)) < 0.03
    # the fit's own reading of the path: the same answer, tag check included
    direct = detect_vanishing_points(str(path), use_exif=True)
    assert res.focal_px == pytest.approx(direct.focal_px, rel=1e-9)
    assert res.focal_std_rel == pytest.approx(direct.focal_std_rel, rel=1e-9)
    assert res.warnings == direct.warnings
    # without the option the tag is not used
    assert api.vanishing_points(path).focal_source != "exif-35mm"


def test_a_given_prior_or_focal_length_wins_over_the_tag(
    tagged: tuple[Path, StreetPhoto],
) -> None:
    path, photo = tagged
    res = api.vanishing_points(
        path, use_exif=True, focal_prior_px=1.2 * photo.focal_px, focal_prior_source="mine"
    )
    assert res.focal_source == "mine"
    fixed = api.vanishing_points(path, use_exif=True, focal_px=900.0)
    assert fixed.focal_px == pytest.approx(900.0)


def test_an_array_has_no_exif_to_read(tagged: tuple[Path, StreetPhoto]) -> None:
    _path, photo = tagged
    res = api.vanishing_points(photo.image, use_exif=True)
    assert not res.focal_source.startswith("exif")
