"""Virtual guide (camloc_geo.sensors.guide, ``camloc guide``) on synthetic walkers."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import camera_aimed_at_car, exact_scene

from camloc_geo._errors import InputError
from camloc_geo.absolute._similarity import Similarity2D
from camloc_geo.api import calibrate_scene, guide_scene
from camloc_geo.camera import Camera
from camloc_geo.cli import main
from camloc_geo.relative import CalibrationResult
from camloc_geo.sensors.guide import (
    AbsolutePose,
    GpsTrace,
    GuideResult,
    GuideSettings,
    PixelTrack,
    format_time,
    match_people,
    parse_time,
    pose_from_candidates_geojson,
    read_gps,
    read_tracks,
)
from camloc_geo.testing.synthetic_guide import GuideData, make_guide_data

DATA = Path(__file__).resolve().parents[1] / "data" / "osm"
SETTINGS = GuideSettings(gps_sigma_m=3.0)


@pytest.fixture(scope="module")
def camera() -> Camera:
    return camera_aimed_at_car(6.0, 20.0)


@pytest.fixture(scope="module")
def scene(camera: Camera) -> dict[str, Any]:
    return exact_scene(camera)


@pytest.fixture(scope="module")
def calibration(scene: dict[str, Any]) -> CalibrationResult:
    return calibrate_scene(scene)


@pytest.fixture(scope="module")
def data(camera: Camera) -> GuideData:
    return make_guide_data(
        camera,
        np.random.default_rng(2),
        n_people=4,
        n_without_phone=1,
        n_distractors=2,
        gps_sigma_m=3.0,
        duration_s=60.0,
    )


@pytest.fixture(scope="module")
def absolute(calibration: CalibrationResult, data: GuideData) -> GuideResult:
    pose = AbsolutePose(data.enu_from_world, data.frame, "truth")
    return match_people(calibration, data.tracks, data.traces, pose=pose, settings=SETTINGS)


# --------------------------------------------------------------------------- files


def write_tracks_json(path: Path, tracks: list[PixelTrack], start_s: float) -> None:
    """Nested JSON, times in seconds since the video start, boxes x,y,w,h around the foot."""
    doc = {
        "tracks": [
            {
                "id": t.id,
                "points": [
                    {"t": round(float(tt - start_s), 3), "box": [u - 20, v - 120, 40, 120]}
                    for tt, (u, v) in zip(t.times_s, t.foot_px, strict=True)
                ],
            }
            for t in tracks
        ]
    }
    path.write_text(json.dumps(doc), encoding="utf-8")


def write_gpx(path: Path, traces: list[GpsTrace]) -> None:
    trks = []
    for g in traces:
        pts = "".join(
            f'<trkpt lat="{lat:.8f}" lon="{lon:.8f}"><time>{format_time(t)}</time></trkpt>'
            for t, (lon, lat) in zip(g.times_s, g.lonlat, strict=True)
        )
        trks.append(f"<trk><name>{g.id}</name><trkseg>{pts}</trkseg></trk>")
    path.write_text(
        '<?xml version="1.0"?><gpx version="1.1" xmlns="http://www.topografix.com/GPX/1/1">'
        + "".join(trks)
        + "</gpx>",
        encoding="utf-8",
    )


def write_gps_csv(path: Path, traces: list[GpsTrace], shift_s: float = 0.0) -> None:
    with path.open("w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["id", "time", "lat", "lon"])
        for g in traces:
            for t, (lon, lat) in zip(g.times_s, g.lonlat, strict=True):
                w.writerow([g.id, format_time(t + shift_s), f"{lat:.8f}", f"{lon:.8f}"])


# --------------------------------------------------------------------------- matching


def test_absolute_assignment_and_timing(absolute: GuideResult, data: GuideData) -> None:
    for m in absolute.matches:
        assert m.gps == data.truth[m.track], m
    matched = [m for m in absolute.matches if m.gps is not None]
    assert len(matched) == 3
    for m in matched:
        assert m.certainty >= 0.99
        assert m.certain_after_s is not None
        # certain within the walk (60 s), after several seconds of common data
        assert 5.0 <= m.certain_after_s <= 45.0
        assert m.stable_after_s is not None
        assert m.stable_after_s <= m.certain_after_s
        assert m.median_distance_m is not None
        assert m.median_distance_m < 10.0
    no_phone = absolute.match_of("person4")
    assert no_phone.gps is None
    assert no_phone.reason
    others = {u["gps"] for u in absolute.unmatched_gps}
    assert others == {"other1", "other2"}
    doc = absolute.to_dict()
    assert {m["track"] for m in doc["matches"]} == {"person1", "person2", "person3"}
    assert doc["unmatched_tracks"][0]["track"] == "person4"
    assert doc["timeline"]
    assert doc["timeline"][-1]["assignment"]["person1"] == "phone1"
    json.dumps(doc, allow_nan=False)


def test_certainty_grows_with_time(absolute: GuideResult) -> None:
    for t in ("person1", "person2", "person3"):
        certs = [
            e["certainty"][t]
            for e in absolute.timeline
            if e["assignment"][t] == t.replace("person", "phone")
        ]
        assert certs[0] < 0.99 <= certs[-1]


def test_geojson_tracks_in_lat_lon(absolute: GuideResult, data: GuideData, camera: Camera) -> None:
    gj = absolute.to_geojson()
    tracks = [f for f in gj["features"] if f["properties"]["kind"] == "person_track"]
    assert {f["properties"]["track"]: f["properties"]["gps"] for f in tracks} == data.truth
    # the ground track lies where the true walker was (the calibration is exact here)
    tr = next(t for t in data.tracks if t.id == "person1")
    feat = next(f for f in tracks if f["properties"]["track"] == "person1")
    lonlat = np.asarray(feat["geometry"]["coordinates"])
    en = data.frame.points_enu_from_geographic(lonlat)
    truth_world = camera.ground_from_pixels(tr.foot_px)[:, :2]
    err = np.linalg.norm(en - data.enu_from_world.apply(truth_world), axis=1)
    assert np.median(err) < 0.5
    cam = next(f for f in gj["features"] if f["properties"]["kind"] == "camera")
    e, n = data.frame.enu_from_geographic(
        lat=cam["geometry"]["coordinates"][1], lon=cam["geometry"]["coordinates"][0]
    )
    assert np.hypot(*(np.array([e, n]) - data.enu_from_world.apply(camera.center_in_world[:2]))) < (
        0.5
    )


def test_relative_mode_solves_placement(
    calibration: CalibrationResult, data: GuideData, camera: Camera
) -> None:
    res = match_people(calibration, data.tracks, data.traces, settings=SETTINGS)
    assert res.mode == "relative"
    for m in res.matches:
        assert m.gps == data.truth[m.track]
    pose = res.solved_pose
    assert pose is not None
    true_en = data.enu_from_world.apply(camera.center_in_world[:2])
    e, n = data.frame.enu_from_geographic(lat=pose["lat"], lon=pose["lon"])
    err = float(np.hypot(e - true_en[0], n - true_en[1]))
    assert err < max(3.0 * pose["sigma_m"], 3.0)
    true_heading = camera.angles_deg[0] - math.degrees(data.enu_from_world.rotation_rad)
    d_heading = (pose["heading_deg"] - true_heading + 180.0) % 360.0 - 180.0
    assert abs(d_heading) < 10.0


def test_no_overlap_in_time(calibration: CalibrationResult, data: GuideData) -> None:
    late = [GpsTrace(g.id, g.times_s + 3600.0, g.lonlat) for g in data.traces]
    with pytest.raises(InputError, match="do not overlap the tracks in time"):
        match_people(calibration, data.tracks, late)


def test_pixel_above_horizon(calibration: CalibrationResult, data: GuideData) -> None:
    bad = data.tracks[0]
    px = bad.foot_px.copy()
    px[3] = [960.0, 5.0]  # the top of the image, above the horizon of a 6 m high camera
    tracks = [PixelTrack(bad.id, bad.times_s, px), *data.tracks[1:]]
    with pytest.raises(
        InputError, match=r"track person1: foot pixel \(960, 5\).*above the horizon"
    ):
        match_people(calibration, tracks, data.traces)


# --------------------------------------------------------------------------- formats


def test_read_tracks_formats(tmp_path: Path) -> None:
    start = "2026-01-01T00:00:00Z"
    t0 = parse_time(start)
    rows = [
        {"id": "a", "t": 0.0, "u": 10, "v": 20},
        {"id": "a", "t": 0.5, "x": 0, "y": 0, "w": 20, "h": 40},
        {"id": "b", "frame": 10, "x1": 0, "y1": 0, "x2": 20, "y2": 30},
    ]
    tr = read_tracks(rows, video_start=start, fps=5.0)
    a = next(t for t in tr if t.id == "a")
    b = next(t for t in tr if t.id == "b")
    np.testing.assert_allclose(a.times_s, [t0, t0 + 0.5])
    np.testing.assert_allclose(a.foot_px, [[10, 20], [10, 40]])
    np.testing.assert_allclose(b.times_s, [t0 + 2.0])
    np.testing.assert_allclose(b.foot_px, [[10, 30]])
    p = tmp_path / "t.csv"
    p.write_text("id,t,x,y,w,h\np,2026-01-01T00:00:01Z,100,100,10,50\n", encoding="utf-8")
    c = read_tracks(p)
    assert c[0].times_s[0] == t0 + 1.0
    assert c[0].foot_px.tolist() == [[105.0, 150.0]]
    with pytest.raises(InputError, match="give --video-start"):
        read_tracks([{"id": "a", "t": 1.0, "u": 1, "v": 2}])
    with pytest.raises(InputError, match="no position"):
        read_tracks([{"id": "a", "t": 1.0}], video_start=start)
    with pytest.raises(InputError, match="give --fps"):
        read_tracks([{"id": "a", "frame": 1, "u": 1, "v": 2}], video_start=start)
    bad = tmp_path / "bad.json"
    bad.write_text("{oops", encoding="utf-8")
    with pytest.raises(InputError, match=r"bad\.json: not JSON"):
        read_tracks(bad)


def test_read_gps_gpx_and_csv(tmp_path: Path, data: GuideData) -> None:
    gpx = tmp_path / "g.gpx"
    write_gpx(gpx, data.traces)
    got = {g.id: g for g in read_gps(gpx)}
    assert set(got) == {g.id for g in data.traces}
    g0 = data.traces[0]
    np.testing.assert_allclose(got[g0.id].times_s, g0.times_s, atol=1e-3)
    np.testing.assert_allclose(got[g0.id].lonlat, g0.lonlat, atol=1e-7)
    c = tmp_path / "g.csv"
    write_gps_csv(c, data.traces)
    np.testing.assert_allclose({g.id: g for g in read_gps(c)}[g0.id].lonlat, g0.lonlat, atol=1e-7)
    broken = tmp_path / "broken.gpx"
    broken.write_text("<gpx><trk><trkseg><trkpt lat='1' lon='2'>", encoding="utf-8")
    with pytest.raises(InputError, match=r"broken\.gpx: not valid GPX"):
        read_gps(broken)
    notime = tmp_path / "notime.gpx"
    notime.write_text("<gpx><trk><trkseg><trkpt lat='1' lon='2'/></trkseg></trk></gpx>", "utf-8")
    with pytest.raises(InputError, match="no <time>"):
        read_gps(notime)
    cols = tmp_path / "cols.csv"
    cols.write_text("name,when,y,x\n", encoding="utf-8")
    with pytest.raises(InputError, match="id,time,lat,lon"):
        read_gps(cols)


def test_pose_from_candidates_geojson(
    calibration: CalibrationResult, data: GuideData, camera: Camera
) -> None:
    """A locate candidate (lat, lon, heading, scale) rebuilds the pose from the calibration."""
    sim = data.enu_from_world
    cam_en = sim.camera(calibration.camera)
    lon, lat = data.frame.geographic_from_enu(*cam_en.center_in_world[:2])
    heading, pitch, _roll = cam_en.angles_deg
    props = {
        "kind": "candidate",
        "rank": 1,
        "lat": lat,
        "lon": lon,
        "heading_deg": heading % 360.0,
        "pitch_deg": pitch,
        "focal_px": cam_en.focal_px,
        "scale": 1.0,
    }
    doc = {"type": "FeatureCollection", "features": [{"type": "Feature", "properties": props}]}
    pose = pose_from_candidates_geojson(doc, calibration)
    pts = np.array([[3.0, -4.0], [25.0, 10.0]])
    a = data.frame.points_geographic_from_enu(sim.apply(pts))
    b = pose.frame.points_geographic_from_enu(pose.enu_from_world.apply(pts))
    en_a = data.frame.points_enu_from_geographic(a)
    en_b = data.frame.points_enu_from_geographic(b)
    assert np.abs(en_a - en_b).max() < 0.05
    props["focal_px"] = cam_en.focal_px * 1.5  # beyond what bundle adjustment moves (35 %)
    with pytest.raises(InputError, match="not computed from this scene"):
        pose_from_candidates_geojson(doc, calibration)
    with pytest.raises(InputError, match="no candidate of rank 2"):
        pose_from_candidates_geojson(doc, calibration, rank=2)


def test_guide_scene_without_absolute_pose(scene: dict[str, Any], data: GuideData) -> None:
    with pytest.raises(InputError, match="no absolute pose"):
        guide_scene(scene, data.tracks, data.traces, pose="absolute")
    res = guide_scene(scene, data.tracks, data.traces)  # auto: relative
    assert res.mode == "relative"


# --------------------------------------------------------------------------- CLI


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory, scene: dict[str, Any], data: GuideData) -> Any:
    d = tmp_path_factory.mktemp("guide")
    (d / "scene.json").write_text(json.dumps(scene), encoding="utf-8")
    write_tracks_json(d / "tracks.json", data.tracks, data.start_s)
    write_gpx(d / "traces.gpx", data.traces)
    write_gps_csv(d / "late.csv", data.traces, shift_s=7200.0)
    return d


def _guide(files: Path, *extra: str) -> list[str]:
    return [
        "guide",
        "--scene",
        str(files / "scene.json"),
        "--tracks",
        str(files / "tracks.json"),
        "--video-start",
        format_time(1_767_225_600.0),
        *extra,
    ]


def test_cli_relative_json(
    files: Path, data: GuideData, capsys: pytest.CaptureFixture[str]
) -> None:
    rc = main(
        [*_guide(files), "--gps", str(files / "traces.gpx"), "--no-network", "--gps-sigma-m", "3"]
    )
    out = capsys.readouterr()
    assert rc == 0, out.err
    doc = json.loads(out.out)
    assert doc["mode"] == "relative"
    assert {m["track"]: m["gps"] for m in doc["matches"]} == {
        k: v for k, v in data.truth.items() if v
    }
    assert all(m["certain_after_s"] is not None for m in doc["matches"])
    assert doc["solved_pose"]["sigma_m"] > 0


def test_cli_errors(files: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rc = main([*_guide(files), "--gps", str(files / "late.csv")])
    err = capsys.readouterr().err
    assert rc == 2
    assert "do not overlap the tracks in time" in err
    assert len(err.splitlines()) == 1
    rc = main([*_guide(files), "--gps", str(files / "traces.gpx"), "--pose", "absolute"])
    err = capsys.readouterr().err
    assert rc == 2
    assert "no absolute pose" in err
    assert len(err.splitlines()) == 1
    rc = main([*_guide(files), "--gps", str(files / "missing.gpx")])
    err = capsys.readouterr().err
    assert rc == 2
    assert "cannot read GPS traces" in err
    rc = main([*_guide(files), "--gps", str(files / "traces.gpx"), "--gps-sigma-m", "0"])
    assert rc == 2
    assert "--gps-sigma-m must be positive" in capsys.readouterr().err


def test_cli_located_scene_geojson(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A scene located on a real extract: ground tracks and traces in lat/lon, right matches."""
    from camloc_geo.osm import load_map
    from camloc_geo.testing.synthetic import make_located_scene

    osm = DATA / "fremantle.osm"
    m = load_map(osm, -32.036172, 115.755714, radius_m=250)
    inter = next(i for i in m.intersections if i.kind == "junction" and len(i.corners) >= 4)
    ls = make_located_scene(m, inter, np.random.default_rng(7), min_corners=3, n_references=2)
    assert ls is not None
    cw, ce = ls.camera_world, ls.camera_enu
    theta = math.radians(cw.angles_deg[0] - ce.angles_deg[0])
    t = ce.center_in_world[:2] - Similarity2D(theta).apply(cw.center_in_world[:2])
    true_sim = Similarity2D(theta, t, 1.0)
    data = make_guide_data(
        cw,
        np.random.default_rng(5),
        n_people=3,
        n_distractors=2,
        enu_from_world=true_sim,
        frame=m.frame,
    )
    (tmp_path / "scene.json").write_text(json.dumps(ls.scene), encoding="utf-8")
    write_tracks_json(tmp_path / "tracks.json", data.tracks, data.start_s)
    write_gps_csv(tmp_path / "traces.csv", data.traces)
    out = tmp_path / "guide.geojson"
    rc = main(
        [
            *_guide(tmp_path),
            "--gps",
            str(tmp_path / "traces.csv"),
            "--osm",
            str(osm),
            "--pose",
            "absolute",
            "-o",
            str(out),
        ]
    )
    assert rc == 0, capsys.readouterr().err
    gj = json.loads(out.read_text(encoding="utf-8"))
    tracks = [f for f in gj["features"] if f["properties"]["kind"] == "person_track"]
    assert {f["properties"]["track"]: f["properties"]["gps"] for f in tracks} == data.truth
    lon, lat = tracks[0]["geometry"]["coordinates"][0]
    assert abs(lat - ls.lat) < 0.001
    assert abs(lon - ls.lon) < 0.001
    assert gj["properties"]["mode"] == "absolute"
    # The same pose rebuilt from the candidate GeoJSON camloc locate writes: no map needed.
    cands = tmp_path / "cands.geojson"
    assert main(["locate", str(tmp_path / "scene.json"), "--osm", str(osm), "-o", str(cands)]) == 0
    out2 = tmp_path / "guide2.geojson"
    rc = main(
        [
            *_guide(tmp_path),
            "--gps",
            str(tmp_path / "traces.csv"),
            "--candidates",
            str(cands),
            "--no-network",
            "-o",
            str(out2),
        ]
    )
    assert rc == 0, capsys.readouterr().err
    gj2 = json.loads(out2.read_text(encoding="utf-8"))
    tracks2 = [f for f in gj2["features"] if f["properties"]["kind"] == "person_track"]
    assert {f["properties"]["track"]: f["properties"]["gps"] for f in tracks2} == data.truth
    a = np.asarray(tracks[0]["geometry"]["coordinates"])
    b = np.asarray(tracks2[0]["geometry"]["coordinates"])
    assert np.abs(a - b).max() < 5e-6  # the same ground track within ~0.5 m


def test_too_fine_a_grid_is_refused(calibration: CalibrationResult, data: GuideData) -> None:
    with pytest.raises(InputError, match="use a larger step"):
        match_people(calibration, data.tracks, data.traces, settings=GuideSettings(step_s=1e-4))


def test_traces_far_from_everybody(calibration: CalibrationResult, data: GuideData) -> None:
    """Traces ~700 m east of the view: nobody matched, each with its reason."""
    shift = np.array([0.01, 0.0])
    far = [GpsTrace(g.id, g.times_s, g.lonlat + shift) for g in data.traces]
    pose = AbsolutePose(data.enu_from_world, data.frame)
    res = match_people(calibration, data.tracks, far, pose=pose)
    assert all(m.gps is None for m in res.matches)
    assert all(m.reason == "no GPS trace stays close enough to it" for m in res.matches)
    assert all(m.certainty > 0.99 for m in res.matches)
    assert {u["gps"] for u in res.unmatched_gps} == {g.id for g in data.traces}
    kinds = [f["properties"]["kind"] for f in res.to_geojson()["features"]]
    assert kinds.count("person_track") == 4


def test_repr_leaves_out_the_per_point_arrays(absolute: GuideResult) -> None:
    """repr() printed every ground and GPS point: 80,437 characters for 4 people over 60 s."""
    text = repr(absolute)
    assert len(text) < 3000
    assert text.startswith("GuideResult(mode='absolute', matches=[GuideMatch(track='person1'")
    assert "array(" not in text.split("enu_from_world=")[0]
    assert absolute.ground_tracks_en  # the data are still there
