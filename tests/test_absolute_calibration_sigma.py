"""The calibration's own uncertainty reaches the candidates' position sigma.

``benchmarks/unseen_cities.py``: Stretford's Lacy Street, a synthetic camera 3.7 m high whose
calibration came out 62 % short in focal length (stated 1-sigma 28 %), was placed 26.6 m off
by two references at a stated sigma of 8.4 m, with no warning: the refinement's sigma held
the calibrated camera fixed and carried only the clicks and the map.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

OSM = Path(__file__).resolve().parents[1] / "data" / "osm"


def _two_reference_scene(  # type: ignore[no-untyped-def]
    extract: str, centre: tuple[float, float, float], oracle: tuple[float, float], i: int
):
    """``unseen_cities.py``'s ``i``-th camera of an extract (at the oracle junction
    ``oracle``), with two references and no intersection: (scene, map, calibration, truth)."""
    from camloc_geo.osm import load_map
    from camloc_geo.relative import calibrate
    from camloc_geo.scene import parse_scene
    from camloc_geo.testing.synthetic import NoiseModel, make_located_scene

    m = load_map(OSM / extract, *centre)
    inter, _w = m.match_intersection(lat=oracle[0], lon=oracle[1], max_distance_m=15.0)
    assert inter is not None
    ls = make_located_scene(
        m,
        inter,
        np.random.default_rng([0, i]),
        noise=NoiseModel(),
        corner_sigma_m=1.5,
        n_references=2,
        min_corners=1,
        max_corners=4,
    )
    assert ls is not None
    cal = calibrate(parse_scene(ls.scene))
    data = json.loads(json.dumps(ls.scene))
    refs = data.pop("references")
    data.pop("landmarks", None)
    data.pop("intersection", None)
    data["references"] = refs[:2]
    return parse_scene(data), m, cal, ls


STRETFORD = ("manchester_kingsway.osm", (53.4469, -2.3086, 800.0))


@pytest.fixture(scope="module")
def lacy_street():  # type: ignore[no-untyped-def]
    """Lacy Street's benchmark scene (Stretford's ninth camera)."""
    return _two_reference_scene(*STRETFORD, (53.4455847, -2.3062294), 9)


def test_two_references_sigma_carries_the_calibration(lacy_street) -> None:  # type: ignore[no-untyped-def]
    from camloc_geo.absolute import locate
    from camloc_geo.geodesy import distance_m

    scene, m, cal, ls = lacy_street
    # the calibration is far off, and says it is loose
    assert cal.camera.focal_px / ls.camera_enu.focal_px - 1.0 == pytest.approx(-0.62, abs=0.02)
    # (28 % as the linearised sigma; widened x3 since calibrate's profile finds a better fit
    # at a longer focal length: the fit stopped in a local minimum; 85 % until stop 39, now
    # 181 %: one annotator's 91 px width line carries the answer and disagrees with the other
    # lines, and the refit without it moves the focal length +160 %, onto the truth's +163 %)
    assert cal.focal_sigma_px / cal.camera.focal_px == pytest.approx(1.81, abs=0.05)
    assert any("carries the answer" in w for w in cal.warnings)
    res = locate(scene, m, calibration=cal)
    top = res.candidates[0]
    assert top.method == "two_references"
    err = distance_m(lat1=top.lat, lon1=top.lon, lat2=ls.lat, lon2=ls.lon)
    assert err == pytest.approx(26.6, abs=1.0)  # the placement itself is unchanged
    # was 8.4 m: the truth lay 3.2 sigma away
    assert top.sigma_m is not None
    assert 2.0 * top.sigma_m >= err
    assert top.sigma_m == pytest.approx(23.9, abs=2.0)  # 28.4 m with the 85 % focal sigma


def test_calibration_sigma_follows_the_focal_sigma(lacy_street) -> None:  # type: ignore[no-untyped-def]
    from camloc_geo.absolute import locate
    from camloc_geo.absolute._model import LocateSettings
    from camloc_geo.absolute._refine import calibration_covariance, calibration_sigmas_m
    from camloc_geo.relative import CalibrationSettings, calibrate
    from camloc_geo.scene import parse_scene

    scene, m, _cal, ls = lacy_street
    # The calibration before its discordant line widened it (85 %, not 181 %): the
    # propagation's scaling is checked where a tenth of the sigma is within its linear reach.
    cal = calibrate(parse_scene(ls.scene), CalibrationSettings(discordant_line_t=0.0))
    res = locate(scene, m, calibration=cal)
    top = res.candidates[0]
    ev = top.evidence
    settings = LocateSettings()
    (full,) = calibration_sigmas_m([top], cal, [ev], settings)
    assert full is not None
    assert full > 10.0
    # the stated marginals are the covariance's diagonal
    cov = calibration_covariance(cal)
    assert cov is not None
    assert cov.shape == (7, 7)
    assert math.sqrt(cov[0, 0]) == pytest.approx(cal.focal_sigma_px, rel=1e-9)
    # a calibration ten times as sure of everything moves the camera a tenth as far or less
    # (the camera moves faster than linearly with a focal length 28 % off: 16 m against 0.9)
    sure = replace(
        cal,
        focal_sigma_px=cal.focal_sigma_px / 10.0,
        rotation_sigma_deg=np.asarray(cal.rotation_sigma_deg) / 10.0,
        position_sigma_m=np.asarray(cal.position_sigma_m) / 10.0,
        principal_point_sigma_px=[s / 10.0 for s in cal.principal_point_sigma_px],
        parameter_covariance=np.asarray(cal.parameter_covariance) / 100.0,
    )
    (small,) = calibration_sigmas_m([top], sure, [ev], settings)
    assert small is not None
    assert 0.02 * full < small < 0.1 * full
    # a calibration stating nothing adds nothing
    none = replace(
        cal,
        focal_sigma_px=None,
        rotation_sigma_deg=None,
        position_sigma_m=None,
        principal_point_sigma_px=None,
        parameter_covariance=None,
    )
    assert calibration_sigmas_m([top], none, [ev], settings) == [None]


def _top_error(res, ls) -> float:  # type: ignore[no-untyped-def]
    from camloc_geo.geodesy import distance_m

    top = res.candidates[0]
    return float(distance_m(lat1=top.lat, lon1=top.lon, lat2=ls.lat, lon2=ls.lon))


def test_loose_calibration_is_warned(lacy_street) -> None:  # type: ignore[no-untyped-def]
    """Andorra's Av. Consell d'Europa x Av. Doctor Mitjavila: focal length 32 % short at a
    stated 17 %, the top candidate 21.5 m off; its sigma (7.0 m before, 9.5 m with the
    calibration's) still falls short of the truth, so only a warning keeps it from looking
    sure. Lacy Street (181 %) is warned too; a Stretford camera with a tight calibration
    (8 %) is not."""
    from camloc_geo.absolute import locate

    scene, m, cal, ls = _two_reference_scene(
        "andorra.osm.pbf", (42.5075, 1.5300, 1500.0), (42.5090898, 1.5295354), 29
    )
    assert cal.focal_sigma_px / cal.camera.focal_px == pytest.approx(0.17, abs=0.01)
    res = locate(scene, m, calibration=cal)
    assert _top_error(res, ls) == pytest.approx(21.5, abs=1.0)
    loose = [w for w in res.warnings if w.startswith("calibration: the focal length")]
    assert len(loose) == 1
    assert "uncertain by 17 %" in loose[0]
    assert "two references cannot correct it" in loose[0]
    # how far: a focal length 2 sigma shorter moves it 13 m, beyond its sigma_m of 9.5 m
    moved = re.search(
        r"2 sigma (shorter|longer) \((\d+) px against (\d+) px\) moves it (\d+) m", loose[0]
    )
    assert moved is not None
    assert moved.group(1) == "shorter"
    f_px = float(cal.camera.focal_px)
    assert int(moved.group(3)) == round(f_px)
    assert int(moved.group(2)) == round(f_px - 2.0 * float(cal.focal_sigma_px))
    assert res.candidates[0].sigma_m == pytest.approx(9.5, abs=0.5)
    assert int(moved.group(4)) == pytest.approx(13.0, abs=1.5)

    scene, m, cal, ls = lacy_street
    res = locate(scene, m, calibration=cal)
    assert any("uncertain by 181 %" in w for w in res.warnings)

    scene, m, cal, ls = _two_reference_scene(*STRETFORD, (53.4461281, -2.3075311), 0)
    assert cal.focal_sigma_px / cal.camera.focal_px < 0.1
    res = locate(scene, m, calibration=cal)
    assert _top_error(res, ls) < 5.0
    assert not any(w.startswith("calibration:") for w in res.warnings)


def test_sigma_point_rotations_match_rodrigues() -> None:
    from camloc_geo.absolute._refine import _rotations
    from camloc_geo.camera import rotation_from_rotvec

    v = np.random.default_rng(3).normal(size=(6, 3)) * 0.05
    v[0] = 0.0
    got = _rotations(v)
    for i in range(6):
        np.testing.assert_allclose(got[i], rotation_from_rotvec(v[i]), atol=1e-14)


def test_focal_moves_grow_with_the_focal_lengths_distance() -> None:
    """:func:`focal_moves_m` on Andorra's loose calibration (17 %): no move at 0 sigma, about
    twice the 1-sigma move at 2 sigmas, a shorter focal length moving the camera farther
    (the casting's nonlinearity), and the 1-sigma moves near the calibration's sigma."""
    from camloc_geo.absolute import LocateSettings
    from camloc_geo.absolute._refine import calibration_sigmas_m, focal_moves_m

    scene, m, cal, _ls = _two_reference_scene(
        "andorra.osm.pbf", (42.5075, 1.5300, 1500.0), (42.5090898, 1.5295354), 29
    )
    from camloc_geo.absolute import locate

    res = locate(scene, m, calibration=cal)
    top = res.candidates[0]
    ev = top.evidence
    settings = LocateSettings()
    zero = focal_moves_m(top, cal, ev, settings, 0.0)
    one = focal_moves_m(top, cal, ev, settings, 1.0)
    two = focal_moves_m(top, cal, ev, settings, 2.0)
    assert zero is not None
    assert one is not None
    assert two is not None
    assert max(zero) < 1e-6
    assert two[0] > one[0] > 3.0
    assert two[0] / one[0] == pytest.approx(2.0, abs=0.2)
    assert two[0] > two[1]  # shorter moves farther
    (sig_cal,) = calibration_sigmas_m([top], cal, [ev], settings)
    assert sig_cal is not None
    assert max(one) <= sig_cal * 1.5
