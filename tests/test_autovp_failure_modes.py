"""Failure modes of automatic vanishing points on real photos (issue 24), on synthetic
segments: a photo looking up steeply at a building, roof slopes and paving joints posing
as a principal direction, a lens' barrel distortion."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from camloc_geo import autovp
from camloc_geo.autovp import detect_vanishing_points, pitch_roll_from_up


def cam_from_world(yaw_deg: float, pitch_deg: float) -> np.ndarray:
    """Rows: camera right, down, forward in a z-up world; pitch positive looking down."""
    ps, th = math.radians(yaw_deg), math.radians(pitch_deg)
    fwd = np.array([math.cos(ps) * math.cos(th), math.sin(ps) * math.cos(th), -math.sin(th)])
    right = np.cross(fwd, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    return np.array([right, np.cross(fwd, right), fwd])


def facade_segments(
    pitch_deg: float,
    *,
    f_px: float = 800.0,
    size: tuple[int, int] = (1024, 768),
    n_vertical: int = 60,
    n_rows: int = 50,
    n_side: int = 6,
    facade_yaw_deg: float = 25.0,
    seed: int = 0,
    noise_px: float = 0.3,
    camera_height_m: float = 1.6,
    side_skew_deg: float = 0.0,
) -> tuple[np.ndarray, tuple[int, int]]:
    """Segments of a tall facade 18 m off, seen from a camera ``camera_height_m`` up.

    Its vertical edges (``n_vertical``) and window rows (``n_rows``) are many; the third
    direction, the courses of a side wall running away from the camera, has ``n_side``
    (a side wall ``side_skew_deg`` off square to the facade).
    """
    rng = np.random.default_rng(seed)
    w, h = size
    R = cam_from_world(0.0, pitch_deg)
    a = math.radians(facade_yaw_deg)
    along = np.array([math.sin(a), -math.cos(a), 0.0])  # the facade's horizontal
    b = a + math.radians(side_skew_deg)
    normal = np.array([math.cos(b), math.sin(b), 0.0])  # towards the side wall's depth
    up = np.array([0.0, 0.0, 1.0])
    origin = np.array([18.0, 0.0, -camera_height_m])  # a point of the facade, street level
    segs: list[list[float]] = []

    def add(p: np.ndarray, q: np.ndarray) -> None:
        pc, qc = R @ p, R @ q
        if pc[2] < 0.5 or qc[2] < 0.5:
            return
        a_px = f_px * pc[:2] / pc[2] + (w / 2, h / 2)
        b_px = f_px * qc[:2] / qc[2] + (w / 2, h / 2)
        ok = all(0 <= v[0] <= w and 0 <= v[1] <= h for v in (a_px, b_px))
        if ok and np.hypot(*(b_px - a_px)) > 25:
            segs.append([*a_px, *b_px])

    tries = 0
    while len(segs) < n_vertical and tries < 20000:
        tries += 1
        p = origin + along * rng.uniform(-25, 25) + up * rng.uniform(0, 60)
        add(p, p + up * rng.uniform(2, 10))
    n0, tries = len(segs), 0
    while len(segs) < n0 + n_rows and tries < 20000:
        tries += 1
        p = origin + along * rng.uniform(-25, 20) + up * rng.uniform(0, 60)
        add(p, p + along * rng.uniform(2, 8))
    n0, tries = len(segs), 0
    while len(segs) < n0 + n_side and tries < 20000:
        tries += 1
        p = origin + along * 22.0 + up * rng.uniform(0, 60) + normal * rng.uniform(0, 10)
        add(p, p + normal * rng.uniform(2, 6))
    out = np.array(segs)
    return out + rng.normal(0.0, noise_px, out.shape), (w, h)


@pytest.mark.parametrize("pitch_deg", [-40.0, -50.0, -55.0, -58.0])
def test_photo_looking_up_steeply_at_a_building_is_not_read_as_looking_down(
    pitch_deg: float,
) -> None:
    """Looking up 40-58 degrees at a facade sees the same Manhattan frame as looking down
    50-30 degrees (it was read so). The building's many vertical edges decide (the other
    reading would rest on a side wall's few courses), and the ambiguity is stated. (At 60
    degrees and more the looking-down reading may still win: see docs/cli.md.)"""
    segs, size = facade_segments(pitch_deg)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    assert res.pitch_deg == pytest.approx(pitch_deg, abs=1.0)
    assert abs(res.focal_px / 800.0 - 1.0) < 0.05
    assert not res.vertical_identified
    assert any("looks up" in w and "or down" in w for w in res.warnings)


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("pitch_deg", [-60.0, -65.0, -70.0, -75.0, -80.0])
def test_photo_looking_up_60_degrees_or_more_is_right_or_warned(
    pitch_deg: float, seed: int
) -> None:
    """Looking up 60-80 degrees at a facade is the Manhattan frame of looking down 30-10
    degrees; the prior (street cameras look down) may keep the looking-down reading, but
    then never silently: a warning names the looking-up reading, and the confidence is
    below one half. (It was read as looking down 27 degrees at a confidence of 0.92 with no
    warning, and at 65-80 degrees up only "few vertical lines" was said, at 0.42.)"""
    segs, size = facade_segments(pitch_deg, seed=seed)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    if abs(res.pitch_deg - pitch_deg) <= 1.0:
        return  # got it right
    assert res.pitch_deg > 0.0  # read as looking down ...
    assert not res.vertical_identified
    assert res.confidence < 0.5
    said = [m for w in res.warnings for m in re.findall(r"or up (\d+) degrees", w)]
    assert len(said) == 1  # ... and the warning names the true reading, to the degree
    assert float(said[0]) == pytest.approx(abs(pitch_deg), abs=1.0)


@pytest.mark.parametrize("facade_yaw_deg", [0.0, 10.0])
@pytest.mark.parametrize("pitch_deg", [-60.0, -70.0, -80.0])
def test_square_on_facade_looking_up_steeply_is_still_warned(
    pitch_deg: float, facade_yaw_deg: float
) -> None:
    """Seen square-on (or 10 degrees off), a facade looking up 60-80 degrees is read as
    looking down 30-10 degrees; the roll test (cameras do not roll) leaves it warned: its
    verticals roll the camera 0 degrees, the looking-down reading 0-12. Where that reading
    leaves the focal length loose (70-80 degrees up: its vertical has 0-5 lines), the
    focal length is near the default (1.0 times the longer side, the true one is 0.78), so
    both readings' pitch are 1-4 degrees off; looking up 80 degrees, 10 degrees off
    square, the looking-up reading would then be 83 degrees up, past the looking-up
    check's 82: the answer says instead that the photo does not fix the focal length and
    has few vertical lines."""
    segs, size = facade_segments(pitch_deg, facade_yaw_deg=facade_yaw_deg)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    if abs(res.pitch_deg - pitch_deg) <= 1.0:
        return  # got it right
    loose = res.focal_std_rel > 0.25
    assert res.pitch_deg == pytest.approx(90.0 + pitch_deg, abs=5.0 if loose else 2.5)
    assert res.confidence < 0.5
    said = [m for w in res.warnings for m in re.findall(r"or up (\d+) degrees", w)]
    if loose and not said:
        assert any("does not fix the focal length" in w for w in res.warnings)
        assert any("few vertical lines" in w for w in res.warnings)
        return
    assert not res.vertical_identified
    assert [float(x) for x in said] == [pytest.approx(-pitch_deg, abs=5.0 if loose else 2.0)]


@pytest.mark.parametrize("roll_deg", [5.0, 10.0])
@pytest.mark.parametrize("pitch_deg", [-60.0, -70.0, -80.0])
def test_rolled_photo_of_a_facade_looking_up_steeply_is_right_or_warned(
    pitch_deg: float, roll_deg: float
) -> None:
    """A handheld photo, rolled 5-10 degrees, of a facade 25 degrees off square looking up
    60-80 degrees: read right or warned. (Before the roll test 7 of these 12, seeds 0-1,
    were read as looking down with no warning; at a roll of 15-20 degrees 8 of 12 still
    are, as before.)"""
    segs, (w, h) = facade_segments(pitch_deg, seed=1)
    c, s = math.cos(math.radians(roll_deg)), math.sin(math.radians(roll_deg))
    rot, centre = np.array([[c, -s], [s, c]]), np.array([w / 2, h / 2])
    segs = np.hstack(
        [(segs[:, :2] - centre) @ rot.T + centre, (segs[:, 2:] - centre) @ rot.T + centre]
    )
    res = detect_vanishing_points(None, segments=segs, image_size=(w, h))
    if abs(res.pitch_deg - pitch_deg) <= 1.5:
        return
    assert res.confidence < 0.5
    said = [m for w in res.warnings for m in re.findall(r"or up (\d+) degrees", w)]
    assert [float(x) for x in said] == [pytest.approx(-pitch_deg, abs=2.0)]


def test_rolls_more_compares_the_two_readings_rolls() -> None:
    """Reading a direction 30 degrees off the image's vertical axis as the vertical rolls
    the camera 30 degrees: more than 10 beyond a reading that rolls it 0, not beyond one
    that rolls it 25."""
    t = math.radians(30.0)
    level = np.array([0.0, -1.0, 0.0])  # rolls 0
    rolled = np.array([math.sin(t), -math.cos(t), 0.0])  # rolls 30
    rolled_25 = np.array([math.sin(math.radians(25.0)), -math.cos(math.radians(25.0)), 0.0])
    dirs = np.array([level, rolled, [0.0, 0.0, 1.0]])
    assert autovp._rolls_more(dirs, 1, 0)
    assert not autovp._rolls_more(dirs, 0, 1)
    assert not autovp._rolls_more(np.array([rolled_25, rolled, [0.0, 0.0, 1.0]]), 1, 0)


def test_steep_up_rival_is_named_with_the_lines_it_has() -> None:
    """The -60 degree facade (seed 0) was read as looking down 27 degrees with no warning:
    the reading kept and the rival's lines are stated."""
    segs, size = facade_segments(-60.0, seed=0)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    assert res.pitch_deg == pytest.approx(26.8, abs=1.5)
    (said,) = [w for w in res.warnings if "or up" in w]
    assert "looks down 27 degrees (6 vertical lines), or up 60 degrees (34 lines)" in said
    assert res.confidence < 0.5


def test_street_camera_over_lane_markings_is_not_read_as_looking_up() -> None:
    """A camera looking down 30 degrees along a road: many lane markings along it, a few
    poles. Reading the markings as the vertical would look up 60 degrees: not taken."""
    rng = np.random.default_rng(3)
    f_px, (w, h) = 800.0, (1024, 768)
    R = cam_from_world(10.0, 30.0)
    centre = np.array([0.0, 0.0, 8.0])
    segs = []
    for p, q in [
        *[
            (np.array([x, y, 0.0]), np.array([x + rng.uniform(3, 9), y, 0.0]))
            for x, y in zip(rng.uniform(8, 60, 60), rng.uniform(-8, 8, 60), strict=True)
        ],  # lane markings and kerbs along the road (+x)
        *[
            (np.array([x, y, 0.0]), np.array([x, y + rng.uniform(3, 6), 0.0]))
            for x, y in zip(rng.uniform(10, 40, 15), rng.uniform(-8, 4, 15), strict=True)
        ],  # stop lines across
        *[
            (np.array([x, s, 0.0]), np.array([x, s, rng.uniform(4, 7)]))
            for x, s in zip(rng.uniform(12, 50, 10), rng.choice([-9.0, 9.0], 10), strict=True)
        ],  # poles
    ]:
        pc, qc = R @ (p - centre), R @ (q - centre)
        if pc[2] < 0.5 or qc[2] < 0.5:
            continue
        a, b = f_px * pc[:2] / pc[2] + (w / 2, h / 2), f_px * qc[:2] / qc[2] + (w / 2, h / 2)
        if all(0 <= v[0] <= w and 0 <= v[1] <= h for v in (a, b)) and np.hypot(*(b - a)) > 20:
            segs.append([*a, *b])
    arr = np.array(segs) + rng.normal(0.0, 0.3, (len(segs), 4))
    res = detect_vanishing_points(None, segments=arr, image_size=(w, h))
    assert res.n_lines[0] < res.n_lines[1] / 2  # the poles are few
    assert res.pitch_deg == pytest.approx(30.0, abs=1.0)


def lane_marking_segments(
    pitch_deg: float,
    yaw_deg: float,
    *,
    n_poles: int,
    seed: int,
    f_px: float = 800.0,
    size: tuple[int, int] = (1024, 768),
    height_m: float = 8.0,
) -> np.ndarray:
    """A street camera ``height_m`` up, looking down ``pitch_deg`` and ``yaw_deg`` off a
    road along +x: 60 lane markings and kerbs along it, 15 stop lines across, ``n_poles``
    poles (the only vertical lines)."""
    rng = np.random.default_rng(seed)
    w, h = size
    R = cam_from_world(yaw_deg, pitch_deg)
    centre = np.array([0.0, 0.0, height_m])
    pairs = [
        *[
            (np.array([x, y, 0.0]), np.array([x + rng.uniform(3, 9), y, 0.0]))
            for x, y in zip(rng.uniform(8, 60, 60), rng.uniform(-8, 8, 60), strict=True)
        ],
        *[
            (np.array([x, y, 0.0]), np.array([x, y + rng.uniform(3, 6), 0.0]))
            for x, y in zip(rng.uniform(10, 40, 15), rng.uniform(-8, 4, 15), strict=True)
        ],
        *[
            (np.array([x, s, 0.0]), np.array([x, s, rng.uniform(4, 7)]))
            for x, s in zip(
                rng.uniform(12, 50, n_poles), rng.choice([-9.0, 9.0], n_poles), strict=True
            )
        ],
    ]
    segs = []
    for p, q in pairs:
        pc, qc = R @ (p - centre), R @ (q - centre)
        if pc[2] < 0.5 or qc[2] < 0.5:
            continue
        a, b = f_px * pc[:2] / pc[2] + (w / 2, h / 2), f_px * qc[:2] / qc[2] + (w / 2, h / 2)
        if all(0 <= v[0] <= w and 0 <= v[1] <= h for v in (a, b)) and np.hypot(*(b - a)) > 20:
            segs.append([*a, *b])
    return np.array(segs) + rng.normal(0.0, 0.3, (len(segs), 4))


@pytest.mark.parametrize(
    ("pitch_deg", "yaw_deg", "n_poles", "seed"),
    [(30.0, 10.0, 4, 0), (30.0, 25.0, 8, 1), (20.0, 25.0, 4, 0), (15.0, 10.0, 8, 1)],
)
def test_street_camera_looking_down_at_a_road_at_an_angle_is_not_warned_as_looking_up(
    pitch_deg: float, yaw_deg: float, n_poles: int, seed: int
) -> None:
    """A street camera looking down 15-30 degrees at a road 10-25 degrees off its axis, its
    lane markings many and its poles few (4-8): read as the vertical, the markings would
    have it look up 60-75 degrees and roll 20-60. Cameras do not roll, so that is no
    evidence: no looking-up warning, the vertical identified. (Before, every one of these
    was warned, its confidence halved; at 30 degrees down they were read as looking up
    52-58 degrees.)"""
    segs = lane_marking_segments(pitch_deg, yaw_deg, n_poles=n_poles, seed=seed)
    res = detect_vanishing_points(None, segments=segs, image_size=(1024, 768))
    # 1.5 degrees: the focal length is loose here (no vertical line) and the default prior
    # (1024 px) joins; since stop 42 it weighs the reading as a wrong frame's with a chance
    # of 0.17 (``_WRONG_FRAME_MAX``), which pulls this 800 px camera's 837 px to 850 px and
    # its 30 degrees from 29.0 to 28.6 read (29.1 to 28.8 at 25 degrees of yaw)
    assert res.pitch_deg == pytest.approx(pitch_deg, abs=1.5)
    assert not [w for w in res.warnings if "or up" in w]
    assert res.n_lines[0] < 12  # few poles: the old rule's case


def test_rendered_traffic_frame_is_not_warned_as_looking_up() -> None:
    """A frame of the rendered traffic videos (a pole camera 6-9 m up looking down 15-23
    degrees at a road with lane markings and parked cars, no building): its vertical comes
    from the two ground directions, and each would have the camera look up 50-60 degrees
    with a roll of 50-70. All 30 frames of ``benchmarks/vp_real.py``'s street set were
    warned as looking up before; this one (seed 0) is not, its pitch within 1 degree."""
    pytest.importorskip("cv2")
    from camloc_geo.testing import traffic_render as tr

    rng = np.random.default_rng(0)
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
    up_in_cam = cam.cam_from_world_rotation @ np.array([0.0, 0.0, 1.0])
    pitch_true = pitch_roll_from_up(up_in_cam)[0]
    res = detect_vanishing_points(img, seed=0)
    assert pitch_true > 10.0
    assert res.pitch_deg == pytest.approx(pitch_true, abs=1.0)
    assert not [w for w in res.warnings if "or up" in w]


def test_mast_camera_looking_down_steeply_stays_looking_down() -> None:
    """A camera looking down 50 degrees at a facade with as many courses running away as
    vertical edges: the likelier reading (looking down) is kept."""
    segs, size = facade_segments(
        50.0, n_vertical=40, n_rows=40, n_side=40, camera_height_m=40.0, facade_yaw_deg=40.0
    )
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    assert res.pitch_deg == pytest.approx(50.0, abs=1.0)
    up_true = cam_from_world(0.0, 50.0) @ np.array([0.0, 0.0, 1.0])
    assert pitch_roll_from_up(up_true)[0] == pytest.approx(50.0)


def street_segments(
    *,
    n_vertical: int = 30,
    n_joints: int = 0,
    joint_deg: float = 90.0,
    n_roof: int = 0,
    roof_deg: float = 60.0,
    f_px: float = 800.0,
    seed: int = 0,
) -> tuple[np.ndarray, tuple[int, int]]:
    """A level camera (1.6 m up, pitch 2 degrees) looking down a street (along +x).

    Buildings line both sides (``n_vertical`` edges and 16 window rows each); paving
    joints (``n_joints``, short, on the ground) run ``joint_deg`` off the street, 90
    being square to it; roof slopes (``n_roof``) rise ``roof_deg`` along the facades.
    """
    rng = np.random.default_rng(seed)
    w, h = 1024, 768
    R = cam_from_world(8.0, 2.0)
    centre = np.array([0.0, 0.0, 1.6])
    segs: list[list[float]] = []

    def add(p: np.ndarray, q: np.ndarray) -> None:
        pc, qc = R @ (p - centre), R @ (q - centre)
        if pc[2] < 0.5 or qc[2] < 0.5:
            return
        a_px = f_px * pc[:2] / pc[2] + (w / 2, h / 2)
        b_px = f_px * qc[:2] / qc[2] + (w / 2, h / 2)
        ok = all(0 <= v[0] <= w and 0 <= v[1] <= h for v in (a_px, b_px))
        if ok and np.hypot(*(b_px - a_px)) > 20:
            segs.append([*a_px, *b_px])

    for side in (-8.0, 8.0):
        for x in rng.uniform(8, 90, n_vertical):
            add(np.array([x, side, 0.5]), np.array([x, side, rng.uniform(5, 14)]))
        for z in rng.uniform(0.5, 12, 16):
            x0 = rng.uniform(8, 40)
            add(np.array([x0, side, z]), np.array([x0 + rng.uniform(8, 40), side, z]))
    a = math.radians(joint_deg)
    for _ in range(n_joints):
        p = np.array([rng.uniform(6, 20), rng.uniform(-5, 5), 0.0])
        add(p, p + np.array([math.cos(a), math.sin(a), 0.0]) * rng.uniform(1.5, 4))
    r = math.radians(roof_deg)
    for i in range(n_roof):
        p = np.array([rng.uniform(15, 60), 8.0 if i % 2 else -8.0, 14.0])
        add(p, p + np.array([math.cos(r), 0.0, math.sin(r)]) * rng.uniform(3, 6))
    out = np.array(segs)
    return out + rng.normal(0.0, 0.3, out.shape), (w, h)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_paving_joints_off_square_do_not_make_a_confident_focal_length(seed: int) -> None:
    """A level camera looking down a street: the across-street direction comes only from
    10 short paving joints laid 6 degrees off square. The focal length then rests on them
    (it is 23-26 % off): the result must say so (a warning, confidence under 0.5) with a
    sigma that covers the error within 3 sigma, not state a few per cent."""
    segs, size = street_segments(n_joints=10, joint_deg=84.0, seed=seed)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    err = abs(math.log(res.focal_px / 800.0))
    assert res.warnings
    assert res.confidence < 0.5
    assert err <= 3.0 * res.focal_std_rel
    # the tilt does not rest on them
    assert res.pitch_deg == pytest.approx(2.0, abs=1.0)
    assert abs(res.roll_deg) < 0.5


@pytest.mark.parametrize("roof_deg", [55.0, 70.0])
def test_roof_slopes_do_not_pose_as_the_vertical(roof_deg: float) -> None:
    """Few building edges (3 a side, trees stand for the rest) and 10 steep roof slopes:
    the vertical stays the buildings', pitch and roll within half a degree."""
    segs, size = street_segments(n_vertical=3, n_roof=10, roof_deg=roof_deg, seed=1)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    assert res.pitch_deg == pytest.approx(2.0, abs=0.5)
    assert abs(res.roll_deg) < 0.5
    assert abs(res.directions_in_cam[0] @ (cam_from_world(8.0, 2.0) @ [0, 0, 1.0])) > math.cos(
        math.radians(1.0)
    )


def corner_segments(
    n_paths: int, path_deg: float, seed: int = 0, f_px: float = 700.0
) -> tuple[np.ndarray, tuple[int, int]]:
    """A building corner 20 m off seen level (yaw 45, pitch 3 degrees, 1.6 m up), and
    ``n_paths`` long straight paths on the lawn below the horizon, ``path_deg`` off the
    first facade's direction (as on York Urban's campus)."""
    rng = np.random.default_rng(seed)
    w, h = 1024, 768
    R = cam_from_world(45.0, 3.0)
    centre = np.array([0.0, 0.0, 1.6])
    segs: list[list[float]] = []

    def add(p: list[float] | np.ndarray, q: list[float] | np.ndarray) -> None:
        pc, qc = R @ (np.asarray(p) - centre), R @ (np.asarray(q) - centre)
        if pc[2] < 0.5 or qc[2] < 0.5:
            return
        a_px = f_px * pc[:2] / pc[2] + (w / 2, h / 2)
        b_px = f_px * qc[:2] / qc[2] + (w / 2, h / 2)
        ok = all(0 <= v[0] <= w and 0 <= v[1] <= h for v in (a_px, b_px))
        if ok and np.hypot(*(b_px - a_px)) > 20:
            segs.append([*a_px, *b_px])

    d = 20.0
    for _ in range(25):
        x, y = rng.uniform(5, 30, 2)
        add([x, d, 0.0], [x, d, rng.uniform(3, 15)])
        add([d, y, 0.0], [d, y, rng.uniform(3, 15)])
        z, x0 = rng.uniform(2, 15), rng.uniform(5, 25)
        add([x0, d, z], [x0 + rng.uniform(5, 12), d, z])
        z, y0 = rng.uniform(2, 15), rng.uniform(5, 25)
        add([d, y0, z], [d, y0 + rng.uniform(5, 12), z])
    a = math.radians(path_deg)
    for _ in range(n_paths):
        p = np.array([rng.uniform(3, 15), rng.uniform(3, 20), 0.0])
        add(p, p + np.array([math.cos(a), math.sin(a), 0.0]) * rng.uniform(4, 10))
    out = np.array(segs)
    return out + rng.normal(0.0, 0.3, out.shape), (w, h)


@pytest.mark.parametrize("seed", [0, 2, 3])
def test_paths_below_the_horizon_that_disagree_with_the_facades_widen_the_sigma(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Paths on a lawn 6 degrees off a facade's direction pull its vanishing point (focal
    length 3-5 % low). Leaving out either side of the horizon moves the focal length, so
    the stated sigma grows to cover the error (2.2-2.6 % were stated without that check,
    the error 1.4-1.9 sigma); with the same paths parallel to the facade it stays small.
    (The default focal prior, which joins where the stated sigma passes 10 %, is off here:
    it would pull this 700 px camera towards 1024 px and hide what is tested.)"""
    monkeypatch.setattr(autovp, "_F_DEFAULT_SIGMA", math.inf)
    segs, size = corner_segments(12, 6.0, seed)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    err = abs(math.log(res.focal_px / 700.0))
    assert 0.02 < err < 0.06
    assert res.focal_std_rel > 0.035
    assert err <= 1.3 * res.focal_std_rel
    aligned, _ = corner_segments(12, 0.0, seed)
    res0 = detect_vanishing_points(None, segments=aligned, image_size=size)
    assert abs(math.log(res0.focal_px / 700.0)) < 0.01
    assert res0.focal_std_rel < 0.03


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_side_wall_off_square_with_few_lines_widens_the_focal_sigma(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A facade seen looking up 20 degrees, its side wall 5 degrees off square and drawn
    by 7 lines only (as Heidelberg castle's and Herz-Jesu's gables, 10-12 % off on real
    photos): the side wall pulls the focal length 6-8 % low. The pull (the focal length
    with and without that direction) goes into the sigma, which then covers the error
    within one sigma; without that check it was 1.3-1.6 sigmas on three of the four. (The
    default focal prior is off: the check's sigma passes 10 % on one seed, where the prior
    would then join and move the focal length the check itself leaves alone.)"""
    monkeypatch.setattr(autovp, "_F_DEFAULT_SIGMA", math.inf)
    segs, size = facade_segments(-20.0, n_side=9, side_skew_deg=5.0, facade_yaw_deg=10.0, seed=seed)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    err = abs(math.log(res.focal_px / 800.0))
    assert 0.05 < err < 0.09
    assert err <= 1.0 * res.focal_std_rel
    assert res.pitch_deg == pytest.approx(-20.0, abs=1.5)  # the wall pulls it 1.3 degrees
    monkeypatch.setattr(autovp, "_FEW_LINES", autovp._WEAK_LINES)  # the check off
    res_off = detect_vanishing_points(None, segments=segs, image_size=size)
    assert res_off.focal_px == pytest.approx(res.focal_px, rel=1e-6)
    assert res_off.focal_std_rel < res.focal_std_rel - 0.01


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_side_wall_of_few_lines_that_disagrees_with_the_exif_prior_is_left_out(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same off-square side wall with an EXIF focal length (4 %): the wall pulls the
    focal length 5-7 % away from the prior and the facade (as on a real Heidelberg castle
    photo, -17 % with its EXIF kept); it is left out and the focal length stays within 1 %."""
    segs, size = facade_segments(-20.0, n_side=9, side_skew_deg=5.0, facade_yaw_deg=10.0, seed=seed)
    res = detect_vanishing_points(
        None, segments=segs, image_size=size, focal_prior_px=800.0, focal_prior_sigma_rel=0.04
    )
    assert abs(math.log(res.focal_px / 800.0)) < 0.01
    assert res.n_lines[2] == 0  # the side wall is out
    assert res.focal_source == "prior-given"
    monkeypatch.setattr(autovp, "_FEW_LINES", autovp._WEAK_LINES)  # the check off
    res_off = detect_vanishing_points(
        None, segments=segs, image_size=size, focal_prior_px=800.0, focal_prior_sigma_rel=0.04
    )
    # the prior combined with the photo's own estimate at its full sigma (stop 38) keeps the
    # focal length near the prior even so; without that too, the wall pulls it away
    assert abs(math.log(res_off.focal_px / 800.0)) < 0.03
    assert res_off.focal_std_rel <= 0.04
    monkeypatch.setattr(autovp, "_with_default_prior", lambda m, *args, **kwargs: m)
    res_raw = detect_vanishing_points(
        None, segments=segs, image_size=size, focal_prior_px=800.0, focal_prior_sigma_rel=0.04
    )
    assert abs(math.log(res_raw.focal_px / 800.0)) > 0.04


@pytest.mark.parametrize("pitch_deg", [-60.0, -65.0, -70.0, -75.0])
def test_rendered_facade_looking_up_steeply_is_right_or_warned(pitch_deg: float) -> None:
    """The facade drawn into an image (so the line detector runs too): looking up 60-65
    degrees it is read right; at 70-75 it is read as looking down 18-14 degrees, and then
    the warning names the looking-up reading and the confidence is below 0.2."""
    cv2 = pytest.importorskip("cv2")
    segs, (w, h) = facade_segments(pitch_deg, seed=0, noise_px=0.0)
    img = np.full((h, w, 3), 235, np.uint8)
    for x0, y0, x1, y1 in np.round(segs * 16).astype(int):
        cv2.line(img, (x0, y0), (x1, y1), (40, 40, 40), 3, cv2.LINE_AA, shift=4)
    res = detect_vanishing_points(img, seed=0)
    if pitch_deg > -66.0:
        assert res.pitch_deg == pytest.approx(pitch_deg, abs=1.0)
        assert abs(res.focal_px / 800.0 - 1.0) < 0.03
        return
    assert res.pitch_deg == pytest.approx(90.0 + pitch_deg - 2.0, abs=2.0)  # 18 / 14 down
    assert res.confidence < 0.2
    said = [m for w in res.warnings for m in re.findall(r"or up (\d+) degrees", w)]
    assert [float(x) for x in said] == [pytest.approx(-pitch_deg, abs=1.0)]


def street_with_rival_frame_segments(
    n_across: int, n_skew: int, seed: int = 0, f_px: float = 700.0, skew_deg: float = 15.0
) -> tuple[np.ndarray, tuple[int, int]]:
    """A level camera (1.6 m up, pitch 2 degrees) looking 45 degrees off a street: kerbs
    and facade courses along the street, 25 poles and edges, ``n_across`` short edges
    square across the street, and ``n_skew`` short edges of another structure
    ``skew_deg`` off square (as the curved building over nuScenes CAM_FRONT_RIGHT). Only
    the street's vanishing point and one of the two across it fix the focal length: the
    square one gives 700 px, the skewed one about 900 (+29 %)."""
    rng = np.random.default_rng(seed)
    w, h = 1024, 768
    R = cam_from_world(45.0, 2.0)
    centre = np.array([0.0, 0.0, 1.6])
    segs: list[list[float]] = []

    def add(p: np.ndarray, q: np.ndarray) -> bool:
        pc, qc = R @ (p - centre), R @ (q - centre)
        if pc[2] < 0.5 or qc[2] < 0.5:
            return False
        a_px = f_px * pc[:2] / pc[2] + (w / 2, h / 2)
        b_px = f_px * qc[:2] / qc[2] + (w / 2, h / 2)
        ok = all(0 <= v[0] <= w and 0 <= v[1] <= h for v in (a_px, b_px))
        if ok and np.hypot(*(b_px - a_px)) > 20:
            segs.append([*a_px, *b_px])
            return True
        return False

    a = math.radians(skew_deg)
    along, across = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    skew = np.array([-math.sin(a), math.cos(a), 0.0])
    up = np.array([0.0, 0.0, 1.0])

    def street() -> tuple[np.ndarray, np.ndarray]:
        y = rng.choice([-6.0, -4.0, 4.0, 6.0, 12.0]) + rng.normal(0.0, 0.5)
        p = np.array([rng.uniform(5, 40), y, rng.choice([0.0, rng.uniform(0, 10)])])
        return p, p + along * rng.uniform(3, 10)

    def pole() -> tuple[np.ndarray, np.ndarray]:
        p = np.array([rng.uniform(5, 40), rng.uniform(-10, 30), 0.0])
        return p, p + up * rng.uniform(2, 8)

    def short(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p = np.array([rng.uniform(8, 30), rng.uniform(-5, 25), rng.uniform(0, 8)])
        return p, p + d * rng.uniform(1.5, 4)

    for n, gen in (
        (60, street),
        (25, pole),
        (n_across, lambda: short(across)),
        (n_skew, lambda: short(skew)),
    ):
        k = tries = 0
        while k < n and tries < 20000:
            tries += 1
            k += add(*gen())
    out = np.array(segs)
    return out + rng.normal(0.0, 0.3, out.shape), (w, h)


@pytest.mark.parametrize(("n_across", "seed"), [(16, 5), (17, 5)])
def test_rival_frame_of_a_structure_off_square_widens_the_focal_sigma(
    n_across: int, seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two families across the street, one square to it and one 15 degrees off, supported
    about as well: which frame is kept is near a coin toss. Here the skewed one is kept
    (+29 %); its lines agree with each other, so least squares, the jackknife and the
    systematic terms stated 3 % (a confidence of 0.7, no warning: confidently wrong). The
    square frame, nearly as well supported, is a rival mode: its focal length goes into
    the sigma, which then passes 10 % (warned, confidence 0.5 or less). With no skewed
    structure the focal length is right and its sigma stays tight. (The default focal
    prior is off: it would pull this 700 px camera towards 1024 px.)"""
    monkeypatch.setattr(autovp, "_F_DEFAULT_SIGMA", math.inf)
    segs, size = street_with_rival_frame_segments(n_across, 12, seed)
    res = detect_vanishing_points(None, segments=segs, image_size=size)
    err = abs(math.log(res.focal_px / 700.0))
    assert err > 0.2  # the skewed frame is the one kept
    assert res.focal_std_rel > 0.10
    assert res.confidence < 0.6
    assert any("uncertain" in w for w in res.warnings)
    clean, _ = street_with_rival_frame_segments(n_across, 0, seed)
    res0 = detect_vanishing_points(None, segments=clean, image_size=size)
    assert abs(math.log(res0.focal_px / 700.0)) < 0.03
    assert res0.focal_std_rel < 0.05


def test_rival_logf_std_counts_a_rival_by_the_chance_it_is_the_better_frame(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A rival frame as well supported as the kept one (a tie: Phi(0) = 1/2) adds
    ``sqrt(1/2 * d**2 / (1 + 1/2))`` of its focal length's log-distance ``d``, and so of its
    roll; one the segments clearly support less adds nothing; the kept frame itself is
    skipped."""
    n = 100
    per_frame = {
        1.0: np.ones(n),  # the kept frame
        1.3: np.where(np.arange(n) % 2 == 0, 1.5, 0.5),  # the same total: a tie
        0.7: np.full(n, 0.5) + 0.01 * np.arange(n) / n,  # clearly less support
    }

    def fake_scores(R: np.ndarray, f_n: float, *_: object) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros(n, dtype=np.int64), per_frame[round(f_n, 3)]

    monkeypatch.setattr(autovp, "_label_scores", fake_scores)
    s = autovp._prepare(np.array([[0.0, 0.0, 10.0, 0.0]]), np.zeros(2), 100.0)

    def model(f_n: float) -> autovp._Model:
        score = float(per_frame[f_n].sum())
        return autovp._Model(R=np.eye(3), f_n=f_n, labels=np.zeros(n, np.int64), score=score)

    best, tie, weak = model(1.0), model(1.3), model(0.7)

    def weight(m: autovp._Model) -> float:
        return m.score

    roll = math.radians(5.0)  # the tie also rolls the camera 5 degrees
    tie.R = np.array(
        [[math.cos(roll), -math.sin(roll), 0.0], [math.sin(roll), math.cos(roll), 0.0], [0, 0, 1]]
    )
    d = math.log(1.3)
    logf_std, (pitch_std, roll_std) = autovp._rival_logf_std(best, [best, tie], weight, s, 1.0)
    assert logf_std == pytest.approx(math.sqrt(0.5 * d**2 / 1.5))
    assert roll_std == pytest.approx(math.sqrt(0.5 * 5.0**2 / 1.5), rel=1e-3)
    assert pitch_std < 1e-6
    logf_std, tilt = autovp._rival_logf_std(best, [best, weak], weight, s, 1.0)
    assert logf_std < 1e-6
    assert max(tilt) < 1e-4
    same = model(1.0)
    assert autovp._rival_logf_std(best, [best, same], weight, s, 1.0) == (0.0, (0.0, 0.0))


def test_rival_logf_std_counts_only_what_lies_beyond_the_kept_frames_own_sigma(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A rival mode whose focal length lies within the kept frame's own sigma is the same
    answer, whose spread that sigma already states: it adds nothing. One beyond it adds
    the excess of its squared log-distance over the own variance, at the same weight."""
    n = 100
    per_frame = {
        1.0: np.ones(n),  # the kept frame
        1.03: np.where(np.arange(n) % 2 == 0, 1.5, 0.5),  # a tie 3 % off
        1.3: np.where(np.arange(n) % 2 == 0, 1.5, 0.5),  # a tie 30 % off
    }

    def fake_scores(R: np.ndarray, f_n: float, *_: object) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros(n, dtype=np.int64), per_frame[round(f_n, 3)]

    monkeypatch.setattr(autovp, "_label_scores", fake_scores)
    s = autovp._prepare(np.array([[0.0, 0.0, 10.0, 0.0]]), np.zeros(2), 100.0)

    def model(f_n: float) -> autovp._Model:
        score = float(per_frame[f_n].sum())
        return autovp._Model(R=np.eye(3), f_n=f_n, labels=np.zeros(n, np.int64), score=score)

    def weight(m: autovp._Model) -> float:
        return m.score

    best, near, far = model(1.0), model(1.03), model(1.3)
    own = 0.05
    near_std = autovp._rival_logf_std(best, [best, near], weight, s, 1.0, own_logf_std=own)[0]
    assert near_std == 0.0  # 3 % off, inside a 5 % sigma
    assert autovp._rival_logf_std(best, [best, near], weight, s, 1.0)[0] > 0.01  # not so at 0
    d = math.log(1.3)
    far_std = autovp._rival_logf_std(best, [best, far], weight, s, 1.0, own_logf_std=own)[0]
    assert far_std == pytest.approx(math.sqrt(0.5 * (d**2 - own**2) / 1.5))
