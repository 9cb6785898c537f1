"""The second traffic-video generator (camloc_geo.testing.traffic_render): geometry and truth."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from camloc_geo.api import calibrate_scene
from camloc_geo.testing.traffic_render import (
    COLOURS,
    SHAPES,
    RenderedVideo,
    StreetVehicle,
    random_street,
    render_street,
    street_camera,
)

SIZE = (480, 270)


@pytest.fixture(scope="module")
def video(tmp_path_factory: pytest.TempPathFactory) -> RenderedVideo:
    cam = street_camera(7.0, image_size=SIZE)
    vehicles = [
        StreetVehicle((8.0, -3.0), 0.0, 40.0, start_s=0.5, colour=COLOURS["road_grey"]),
        StreetVehicle((8.0, -8.5), 180.0, 30.0, start_s=0.5, shape=SHAPES["van"]),
    ]
    path = tmp_path_factory.mktemp("render") / "street.avi"
    return render_street(path, cam, vehicles, fps=10.0, duration_s=1.0, seed=3)


def test_two_box_geometry_with_clearance() -> None:
    veh = StreetVehicle((0.0, 0.0), 90.0, 36.0)  # north at 10 m/s
    parts = veh.parts_at(1.0)
    body, cabin, contacts = parts["body"], parts["cabin"], parts["contacts"]
    shape = SHAPES["sedan"]
    # wheels on the road, the body's lower edge 0.2 m up
    np.testing.assert_allclose(contacts[:, 2], 0.0, atol=1e-12)
    np.testing.assert_allclose(body[:4, 2], 0.2, atol=1e-12)
    assert min(w[:, 2].min() for w in parts["wheels"]) == pytest.approx(0.0, abs=0.01)
    # moved 10 m north; the body spans the length along y and the width along x
    np.testing.assert_allclose(body[:, :2].mean(axis=0), [0.0, 10.0], atol=1e-9)
    assert np.ptp(body[:, 1]) == pytest.approx(shape.length_m)
    assert np.ptp(body[:, 0]) == pytest.approx(shape.width_m)
    # cabin narrower and shorter, on the body, up to the roof
    assert np.ptp(cabin[:, 0]) == pytest.approx(shape.cabin_width * shape.width_m)
    assert np.ptp(cabin[:4, 1]) == pytest.approx(shape.cabin_length * shape.length_m)
    assert np.ptp(cabin[4:, 1]) < np.ptp(cabin[:4, 1])
    assert cabin[:, 2].max() == pytest.approx(shape.height_m)
    # contacts inside the body's sides, at the track width
    assert np.ptp(contacts[:, 0]) == pytest.approx(shape.track * shape.width_m)
    assert np.ptp(contacts[:, 0]) < shape.width_m


def test_truth_boxes_and_contacts(video: RenderedVideo) -> None:
    assert video.n_frames == 10
    assert video.image_size == SIZE
    cam = video.camera
    for k, per in video.boxes.items():
        assert per, f"vehicle {k} never wholly in view"
        for i, box in per.items():
            px = cam.project(video.vehicles[k].points_at(i / video.fps))
            np.testing.assert_allclose(box, [*px.min(axis=0), *px.max(axis=0)], atol=1e-9)
            # the wheel contacts are on the true track, below the box's bottom at most
            c = video.contacts_world_m[k][i]
            np.testing.assert_allclose(
                c.mean(axis=0), video.vehicles[k].centre_at(i / video.fps), atol=1e-9
            )


def test_frames_show_the_vehicles(video: RenderedVideo) -> None:
    cap = cv2.VideoCapture(str(video.path))
    frames = []
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        frames.append(frame.astype(np.float32))
    cap.release()
    assert len(frames) == video.n_frames
    assert frames[0].shape == (SIZE[1], SIZE[0], 3)
    # the van (vehicle 1) in frame 5: its box differs from an empty road; the sky is sky
    x1, y1, x2, y2 = (int(v) for v in video.boxes[1][5])
    diff = np.abs(frames[5] - frames[0])[y1:y2, x1:x2]
    assert float(np.mean(diff.max(axis=2) > 30)) > 0.3
    # the road-grey car's lit body differs from the asphalt by less than 30 levels
    grey = np.array(COLOURS["road_grey"], float)
    assert float(np.abs(grey - 92.0).max()) < 30


def test_scene_calibrates_to_the_camera(video: RenderedVideo) -> None:
    cal = calibrate_scene(video.scene)
    assert cal.camera.focal_px == pytest.approx(video.camera.focal_px, rel=0.05)
    assert np.linalg.norm(cal.camera.center_in_world - video.camera.center_in_world) < 1.0
    assert len(video.scene["annotations"]) == 3


def test_random_street_draws() -> None:
    cam, vehicles = random_street(np.random.default_rng(5))
    assert 6.0 <= cam.center_in_world[2] <= 9.0
    assert len(vehicles) == 10
    assert all(20.0 <= v.speed_kmh <= 70.0 for v in vehicles)
    assert {v.direction_deg for v in vehicles} == {0.0, 180.0}


def test_bad_writer(tmp_path: Path) -> None:
    cam = street_camera(image_size=SIZE)
    with pytest.raises(RuntimeError, match="cannot write"):
        render_street(tmp_path / "no" / "dir" / "x.avi", cam, [], duration_s=0.1)
