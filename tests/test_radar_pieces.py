"""The radar's track repairs, on hand-made tracks and blobs (no video).

- a vehicle falling apart into pieces under the foreground threshold is joined by its motion,
  a neighbour is not;
- a track that comes out of a merge on a vehicle driving the other way is cut there;
- the model term of ``sigma_kmh``: a track whose halves disagree beyond their noise;
- a silhouette too low for a vehicle standing on its contact is recognised as a piece;
- a box that changes size (a merged blob splitting) is recognised, its centre's jump is no
  motion;
- an uncertain speed (sigma above 5 % of it) carries a warning naming its main cause;
- segments of a track whose contacts lie on one line of travel are merged, a contact on
  another corner is not;
- a contact that creeps back and snaps forward on its corner (split at every snap) is one
  segment, its speed not slow;
- a segment whose contact stands still while the vehicle's features move is recognised;
- segments whose speeds disagree beyond their noise are pooled (random effects), and the
  pooled speed's error is widened.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camloc_geo.camera import Camera, rotation_from_angles
from camloc_geo.sensors.radar import (
    _apparent_height_m,
    _design,
    _halves_disagreement,
    _identity_switches,
    _irls,
    _join_fragments,
    _merge_segments,
    _resized,
    _segments_pooled,
    _still_segments,
    _Track,
    _uncertainty_warning,
)


def _track(box: tuple[float, float, float, float], velocity: tuple[float, float]) -> _Track:
    t = _Track(1, box, velocity=velocity)
    t.frames = [0, 1, 2, 3, 4]
    return t


def test_pieces_of_one_vehicle_are_joined() -> None:
    # last frame's box moved by (-10, 5): the cabin and the lower body fall inside
    car = _track((110.0, 195.0, 230.0, 295.0), (-10.0, 5.0))
    cabin, lower, wheel = (
        (130.0, 200.0, 210.0, 240.0),
        (100.0, 240.0, 222.0, 300.0),
        (96.0, 280.0, 104.0, 290.0),
    )
    far = (600.0, 50.0, 640.0, 80.0)
    blobs, ids = _join_fragments([car], [lower, cabin, far], [[1], [2], [3]], [wheel], [4])
    assert far in blobs
    assert ids[blobs.index(far)] == [3]
    joined = [b for b in blobs if b != far]
    assert len(joined) == 1
    assert joined[0] == (96.0, 200.0, 222.0, 300.0)
    assert sorted(ids[blobs.index(joined[0])]) == [1, 2, 4]


def test_neighbour_is_not_joined() -> None:
    a = _track((100.0, 200.0, 200.0, 260.0), (5.0, 0.0))
    b = _track((210.0, 200.0, 300.0, 260.0), (-5.0, 0.0))
    blobs_in = [(105.0, 200.0, 205.0, 260.0), (205.0, 200.0, 295.0, 260.0)]
    blobs, ids = _join_fragments([a, b], blobs_in, [[1], [2]], [], [])
    assert blobs == blobs_in
    assert ids == [[1], [2]]


def test_union_may_not_outgrow_a_vehicle() -> None:
    # a second vehicle just below: joined, the box would be 60 % taller than predicted
    car = _track((100.0, 100.0, 200.0, 150.0), (0.0, 0.0))
    blobs_in = [(100.0, 100.0, 200.0, 150.0), (110.0, 148.0, 190.0, 160.0)]
    blobs, _ = _join_fragments([car], blobs_in, [[1], [2]], [], [])
    assert blobs == blobs_in


def test_fragment_track_is_absorbed() -> None:
    car = _track((100.0, 200.0, 220.0, 300.0), (-8.0, 4.0))
    cabin_track = _track((130.0, 200.0, 200.0, 240.0), (-8.5, 4.2))
    cabin_track.vid = 2
    blobs_in = [(92.0, 244.0, 212.0, 304.0), (122.0, 204.0, 192.0, 244.0)]
    blobs, ids = _join_fragments([car, cabin_track], blobs_in, [[1], [2]], [], [])
    assert len(blobs) == 1
    assert sorted(ids[0]) == [1, 2]
    assert cabin_track.absorbed
    assert not car.absorbed


def test_identity_switch_cut_where_motion_turns_back() -> None:
    t = _track((0.0, 0.0, 10.0, 10.0), (0.0, 0.0))
    nan = (math.nan, math.nan)
    t.klt = [nan, (-1.1, 0.8), (-1.0, 0.7), nan, nan, (0.1, 0.0), (0.6, -0.2), (1.2, -0.5)]
    assert _identity_switches(t) == [6]
    t.klt = [(-1.0, 0.5), (-1.2, 0.4), (-0.9, 0.6)]
    assert _identity_switches(t) == []


def test_halves_disagreement() -> None:
    rng = np.random.default_rng(3)
    times = np.arange(40) / 20.0
    labels = [0] * 40
    unit = np.array([1.0, 0.0])
    w = np.ones(40)
    steady = np.column_stack([10.0 * times, np.zeros(40)]) + rng.normal(0, 0.05, (40, 2))
    assert _halves_disagreement(times, labels, steady, w, unit) < 0.3
    # the second half follows a vehicle at 6 m/s: 2 m/s of model error, at least
    turn = steady.copy()
    turn[20:, 0] = turn[19, 0] + 6.0 * (times[20:] - times[19])
    assert _halves_disagreement(times, labels, turn, w, unit) > 1.5


def test_apparent_height_tells_a_piece() -> None:
    cam = Camera.from_center(
        800.0, (480.0, 270.0), rotation_from_angles(0.0, 25.0, 0.0), np.array([0.0, -20.0, 7.0])
    )
    ground = np.array([[0.0, 0.0], [1.0, 0.5]])
    contacts = cam.project(np.column_stack([ground, np.zeros(2)]))
    tops = cam.project(np.column_stack([ground, np.full(2, 1.45)]))
    whole = np.column_stack([contacts[:, 0] - 40, tops[:, 1], contacts[:, 0] + 40, contacts[:, 1]])
    assert abs(_apparent_height_m(cam, ground, contacts, whole) - 1.45) < 0.05
    mids = cam.project(np.column_stack([ground, np.full(2, 0.6)]))
    piece = whole.copy()
    piece[:, 1] = mids[:, 1]
    assert abs(_apparent_height_m(cam, ground, contacts, piece) - 0.6) < 0.05


def test_resized_box() -> None:
    car = (100.0, 50.0, 140.0, 80.0)
    assert not _resized(car, (103.0, 51.0, 144.0, 82.0))  # moved, a little nearer
    assert _resized((60.0, 50.0, 140.0, 80.0), car)  # a merged neighbour split off
    assert _resized(car, (100.0, 40.0, 140.0, 80.0))  # taller by a third


def test_uncertainty_warning_names_the_cause() -> None:
    parts = {"fit": 0.1, "calibration": 0.1, "model": 0.2, "contact": 0.2}
    assert _uncertainty_warning(15.0, parts, False) is None  # sigma 2.2 %
    merged = {**parts, "model": 1.5}
    text = _uncertainty_warning(15.0, merged, False)
    assert text is not None
    assert "sigma 10 %" in text
    assert "merged" in text
    piece = {**parts, "contact": 1.2}
    text = _uncertainty_warning(15.0, piece, True)
    assert text is not None
    assert "piece" in text


def test_segments_on_one_line_are_merged() -> None:
    rng = np.random.default_rng(5)
    # four stretches of one contact at 8 m/s with gaps between them (coasting in merges)
    times = np.concatenate([np.arange(a, a + 0.3, 0.05) for a in (0.0, 1.0, 2.0, 3.0)])
    labels = [int(t) for t in times]
    ground = np.column_stack([8.0 * times, np.full(len(times), -5.0)])
    ground += rng.normal(0.0, 0.1, ground.shape)
    prior = np.ones(len(times))
    assert len(set(_merge_segments(times, labels, ground, prior))) == 1
    # the last stretch on another corner, 2 m ahead: kept apart
    moved = ground.copy()
    moved[np.array(labels) == 3, 0] += 2.0
    merged = _merge_segments(times, labels, moved, prior)
    assert len(set(merged)) == 2
    assert merged[-1] != merged[0]


def test_contact_wander_is_not_another_corner() -> None:
    """Development seed 721's receding SUV near the camera: its lowest corner crept back
    along the rear edge 6 cm a frame and snapped 0.3 m forward every 5 frames; split at
    each snap, with an offset per segment, only the creeps measured the speed: -5.7 %."""
    fps, speed = 20.0, 15.5  # m/s
    frames = np.arange(60)
    times = frames / fps
    wander = -0.06 * (frames % 5)  # creep back, snap forward every 5 frames
    rng = np.random.default_rng(3)
    ground = np.column_stack([speed * times + wander, np.full(60, -3.9)])
    ground += rng.normal(0.0, 0.01, ground.shape)  # near the camera: centimetres
    labels = [int(f // 5) for f in frames]  # split at every snap
    prior = np.full(60, 1.0 / 0.05**2)

    def fitted(lab: list[int]) -> float:
        solve, _w, _res = _irls(_design(times, lab), ground, prior)
        return float(np.linalg.norm(solve[0] @ ground))

    assert fitted(labels) < 0.93 * speed  # the creeps alone: 7.7 % slow
    merged = _merge_segments(times, labels, ground, prior)
    assert len(set(merged)) == 1
    assert fitted(merged) == pytest.approx(speed, rel=0.01)
    # a jump to another corner (a tyre 0.9 m behind the bumper) is still a new segment
    moved = ground.copy()
    moved[frames >= 30, 0] -= 0.9
    kept = _merge_segments(times, labels, moved, prior)
    assert kept[29] != kept[30]


def test_still_contact_segment_is_found() -> None:
    t = _Track(1, (0.0, 0.0, 10.0, 10.0))
    for i in range(20):
        t.frames.append(i)
        t.klt.append((2.0, 1.0))  # the vehicle's features move 2.2 px a frame
        # the first 10 frames a patch of the road holds the lowest corner: still
        t.contacts.append((100.0, 200.0) if i < 10 else (100.0 + 2.0 * i, 200.0 + i))
    use = list(range(20))
    labels = [0] * 10 + [1] * 10
    assert _still_segments(t, use, labels) == {0}
    # features that barely move tell nothing: nothing is left out
    t.klt = [(0.1, 0.0)] * 20
    assert _still_segments(t, use, labels) == set()


def test_disagreeing_segments_are_pooled() -> None:
    rng = np.random.default_rng(8)
    unit = np.array([1.0, 0.0])
    times = np.concatenate([np.arange(a, a + 0.8, 0.05) for a in (0.0, 2.0, 4.0)])
    labels = [int(t // 2) for t in times]
    speed = np.where(np.array(labels) == 2, 8.4, 7.4)  # the last, near, segment slides
    ground = np.column_stack([speed * times, np.zeros(len(times))])
    noise = np.where(np.array(labels) == 2, 0.01, 0.1)
    ground[:, 0] += rng.normal(0.0, 1.0, len(times)) * noise
    weights = 1.0 / noise**2  # the near segment weighs 100 times more
    pooled = _segments_pooled(times, labels, ground, weights, unit)
    assert pooled is not None
    mean, sigma = pooled
    assert 7.4 < mean < 8.1  # not the near segment's 8.4
    assert sigma > 0.2  # the disagreement is in the error
    # segments that agree: nothing to pool, the joint fit stands
    ground[:, 0] = 7.4 * times + rng.normal(0.0, 1.0, len(times)) * noise
    assert _segments_pooled(times, labels, ground, weights, unit) is None
