"""The virtual radar on videos of the second generator (camloc_geo.testing.traffic_render).

Two-box cars with 0.2 m ground clearance, a van and a road-grey car with a cast shadow: not
the radar's own cuboid model. Stated bounds (docs/radar.md, benchmarks/radar_render.py): with
the true camera, each vehicle within 4 % of its true speed and within 2.5 sigma, no reading
biased fast by the body's clearance; with the true boxes given, within 4 % too.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from camloc_geo.api import calibrate_scene
from camloc_geo.relative import CalibrationResult
from camloc_geo.sensors.radar import RadarResult, measure_speeds
from camloc_geo.testing.traffic_render import (
    COLOURS,
    SHAPES,
    RenderedVideo,
    StreetVehicle,
    render_street,
    street_camera,
)

SIZE = (640, 360)


@pytest.fixture(scope="module")
def video(tmp_path_factory: pytest.TempPathFactory) -> RenderedVideo:
    cam = street_camera(7.5, image_size=SIZE)
    vehicles = [  # one after the other, both ways, passing x = 8 at start_s
        StreetVehicle((8.0, -3.0), 0.0, 40.0, 1.2, SHAPES["sedan"], COLOURS["road_grey"]),
        StreetVehicle((8.0, -8.5), 180.0, 55.0, 3.4, SHAPES["van"], COLOURS["white"]),
        StreetVehicle((8.0, -5.5), 0.0, 30.0, 5.6, SHAPES["hatchback"], COLOURS["red"]),
    ]
    path = tmp_path_factory.mktemp("twobox") / "street.avi"
    return render_street(
        path, cam, vehicles, fps=20.0, duration_s=7.0, seed=11, texture_m_per_px=0.05
    )


@pytest.fixture(scope="module")
def true_calibration(video: RenderedVideo) -> CalibrationResult:
    cal = calibrate_scene(video.scene)
    return replace(
        cal,
        camera=video.camera,
        position_sigma_m=np.zeros(3),
        focal_sigma_px=0.0,
        rotation_sigma_deg=None,
        principal_point_sigma_px=None,
    )


@pytest.fixture(scope="module")
def detected(video: RenderedVideo, true_calibration: CalibrationResult) -> RadarResult:
    return measure_speeds(true_calibration, video.path)


def _by_vehicle(video: RenderedVideo, result: RadarResult) -> dict[int, list[tuple[float, float]]]:
    """Measured (speed, sigma) per true vehicle (nearest footprint centre to the track)."""
    out: dict[int, list[tuple[float, float]]] = {}
    for v in result.measured:
        f, x, y = np.array(v.track_world_m).T
        dists = [
            float(
                np.median(
                    np.hypot(
                        *(np.array([veh.centre_at(t) for t in f / video.fps]).T - np.array([x, y]))
                    )
                )
            )
            for veh in video.vehicles
        ]
        out.setdefault(int(np.argmin(dists)), []).append((v.speed_kmh, v.sigma_kmh))
    return out


def test_detection_on_two_box_cars(
    video: RenderedVideo, true_calibration: CalibrationResult
) -> None:
    result = measure_speeds(true_calibration, video.path)
    got = _by_vehicle(video, result)
    assert set(got) == {0, 1, 2}, got
    for k, readings in got.items():
        true = video.vehicles[k].speed_kmh
        speed, sigma = max(readings, key=lambda r: -r[1])  # the best-determined reading
        assert abs(speed - true) <= 0.04 * true, (k, speed, true)
        assert abs(speed - true) <= 2.5 * sigma, (k, speed, sigma, true)
        assert sigma < 0.05 * true


def test_road_grey_car_is_whole(video: RenderedVideo, detected: RadarResult) -> None:
    # before: its panels were taken for shadow and its contact was its waist, 11-13 % fast
    got = _by_vehicle(video, detected)
    speed, _sigma = min(got[0], key=lambda r: r[1])
    assert speed == pytest.approx(40.0, rel=0.04)


def test_given_true_boxes(video: RenderedVideo, true_calibration: CalibrationResult) -> None:
    result = measure_speeds(true_calibration, video.path, tracks=video.boxes)
    assert {v.vehicle_id for v in result.measured} == {0, 1, 2}
    for v in result.measured:
        true = video.vehicles[v.vehicle_id].speed_kmh
        assert v.speed_kmh == pytest.approx(true, rel=0.04)


def test_contact_term_by_source(
    video: RenderedVideo, true_calibration: CalibrationResult, detected: RadarResult
) -> None:
    """The contact's height term (session 37): given boxes cut the silhouette at a tyre or
    the body's edge up to 0.2 m up (RMS 0.115 m over the 7.5 m camera height, 1.54 %); a
    detected silhouette's lowest corner was measured within a few centimetres (0.03 m: 0.4 %)
    on renders drawn where the camera projects. With the true camera, the given boxes'
    sigmas hold at least that term; the detected ones are below the old 0.144 m term alone
    (1.92 %), which covered the old renderer's half-pixel shift."""
    given = measure_speeds(true_calibration, video.path, tracks=video.boxes)
    for v in given.measured:
        assert v.sigma_kmh >= v.speed_kmh * 0.2 / np.sqrt(3.0) / 7.5 * 0.999
    best = [min(r, key=lambda x: x[1]) for r in _by_vehicle(video, detected).values()]
    assert np.median([sigma / speed for speed, sigma in best]) < 0.0192


def test_video_is_small(video: RenderedVideo) -> None:
    assert Path(video.path).stat().st_size < 20_000_000
    assert video.n_frames == 140
