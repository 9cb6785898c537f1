"""Typed outputs (:mod:`camloc_geo.results`): schemas, one attribution, names, ties."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import jsonschema
import numpy as np
import pytest

from camloc_geo.absolute import TIE_SCORE_RATIO, LocateSettings
from camloc_geo.api import calibrate_scene, locate_scene, map_for_scene
from camloc_geo.geodesy import distance_m
from camloc_geo.osm import MapData
from camloc_geo.results import (
    ATTRIBUTION,
    candidates_geojson,
    intersections_geojson,
    output_json_schema,
)

REPO = Path(__file__).resolve().parents[1]
EXTRACT = REPO / "sample_maps" / "baltimore.osm.pbf"
SCENE = REPO / "sample_maps" / "sample_scene.json"


@pytest.fixture(scope="module")
def baltimore() -> MapData:
    m = map_for_scene(SCENE, map_source=EXTRACT)
    assert m is not None
    return m


@pytest.fixture(scope="module")
def located(baltimore: MapData) -> Any:
    return locate_scene(SCENE, map_source=baltimore)


def _props(doc: dict[str, Any], kind: str) -> list[dict[str, Any]]:
    return [f["properties"] for f in doc["features"] if f["properties"]["kind"] == kind]


def _validate(doc: dict[str, Any], kind: Any) -> None:
    schema = output_json_schema(kind)
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.validate(doc, schema, cls=jsonschema.Draft202012Validator)


def test_candidates_validate_against_their_schema(located: Any) -> None:
    doc = located.to_geojson()
    _validate(doc, "candidates")
    kinds = {f["properties"]["kind"] for f in doc["features"]}
    assert {"candidate", "view_cone", "matched_point", "intersection", "corner"} <= kinds


def test_calibration_validates_against_its_schema() -> None:
    _validate(calibrate_scene(SCENE).to_dict(), "calibration")


def test_corners_validate_against_their_schema(baltimore: MapData) -> None:
    _validate(intersections_geojson(baltimore.intersections[:20]), "corners")


def test_a_bad_document_fails_its_schema(located: Any) -> None:
    doc = located.to_geojson()
    doc["features"][0]["properties"]["score"] = "high"
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(doc, output_json_schema("candidates"))
    with pytest.raises(ValueError, match="unknown output"):
        output_json_schema("nonsense")  # type: ignore[arg-type]


def test_one_attribution_everywhere(located: Any, baltimore: MapData) -> None:
    assert located.to_geojson()["properties"]["attribution"] == ATTRIBUTION
    assert intersections_geojson(baltimore.intersections[:3])["attribution"] == ATTRIBUTION
    from camloc_geo import maps

    assert maps.OSM_ATTRIBUTION == ATTRIBUTION
    # No other spelling of it left in the library.
    for path in (REPO / "camloc_geo").rglob("*.py"):
        for line in path.read_text(encoding="utf-8").splitlines():
            if re.search(r"[\"'].*OpenStreetMap contributors", line):
                assert path.name == "results.py" or "help" in line or "ODbL)" in line, (
                    path,
                    line,
                )


def test_intersection_kind_has_both_names(located: Any, baltimore: MapData) -> None:
    docs = [located.to_geojson(), intersections_geojson(baltimore.intersections[:20])]
    for doc in docs:
        inters = [
            f["properties"] for f in doc["features"] if f["properties"]["kind"] == "intersection"
        ]
        assert inters
        for p in inters:
            assert p["kind_detail"] == p["intersection_kind"]
            assert (
                p["kind_detail"] in {"junction", "roundabout", "unmodelled", "dead_end", "bend"}
                or p["kind_detail"]
            )


def test_view_cone_range_comes_from_the_settings(baltimore: MapData) -> None:
    for range_m in (20.0, 90.0):
        out = locate_scene(
            SCENE, map_source=baltimore, settings=LocateSettings(view_cone_range_m=range_m)
        )
        doc = out.to_geojson()
        cands = {
            f["properties"]["rank"]: f
            for f in doc["features"]
            if f["properties"]["kind"] == "candidate"
        }
        far = 0.0
        for f in doc["features"]:
            if f["properties"]["kind"] != "view_cone":
                continue
            lon0, lat0 = cands[f["properties"]["rank"]]["geometry"]["coordinates"]
            for lon, lat in f["geometry"]["coordinates"][0]:
                far = max(far, float(distance_m(lat1=lat0, lon1=lon0, lat2=lat, lon2=lon)))
        assert far <= range_m + 0.01
        assert far > 0.5 * range_m


def test_ambiguous_with_names_the_ties(located: Any) -> None:
    doc = located.to_geojson()
    props = _props(doc, "candidate")
    by_rank = {p["rank"]: p for p in props}
    for p in props:
        for other in p["ambiguous_with"]:
            assert p["rank"] in by_rank[other]["ambiguous_with"]  # symmetric
            lo, hi = sorted((p["score"], by_rank[other]["score"]))
            assert lo >= TIE_SCORE_RATIO * hi
    warned = any(
        w.startswith("ambiguous: candidates 1 and 2") for w in doc["properties"]["warnings"]
    )
    assert warned == (2 in by_rank[1]["ambiguous_with"] if len(props) > 1 else False)


def test_symmetric_twins_are_ambiguous_with_each_other() -> None:
    """An exact 4-way junction seen with two corners has twins; they name each other."""
    from camloc_geo.absolute import locate
    from camloc_geo.osm import load_map
    from camloc_geo.scene import parse_scene
    from camloc_geo.testing.synthetic import NoiseModel, make_located_scene

    m = load_map(REPO / "data" / "osm" / "baltimore.osm.pbf", 39.2851, -76.5934, radius_m=300)
    found = False
    for k, inter in enumerate(i for i in m.intersections if len(i.corners) == 4):
        ls = make_located_scene(
            m,
            inter,
            np.random.default_rng(k),
            noise=NoiseModel.exact(),
            corner_sigma_m=0.0,
            min_corners=2,
            max_corners=2,
        )
        if ls is None:
            continue
        res = locate(parse_scene(ls.scene), m)
        if any(w.startswith("ambiguous") for w in res.warnings):
            assert 2 in res.candidates[0].ambiguous_with
            assert 1 in res.candidates[1].ambiguous_with
            doc = candidates_geojson(res)
            first = next(f for f in doc["features"] if f["properties"]["kind"] == "candidate")
            assert 2 in first["properties"]["ambiguous_with"]
            found = True
            break
        if k > 12:
            break
    assert found


def test_schema_command_prints_each_output_schema(capsys: pytest.CaptureFixture[str]) -> None:
    from camloc_geo.cli import main

    for kind in ("candidates", "calibration", "corners"):
        assert main(["schema", kind]) == 0
        schema = json.loads(capsys.readouterr().out)
        assert schema["title"] == f"camloc {kind} output"
        assert schema == output_json_schema(kind)  # type: ignore[arg-type]


def test_batched_view_cones_match_one_call_per_camera(located: Any) -> None:
    from camloc_geo.absolute import view_cone, view_cones
    from camloc_geo.camera import Camera, RadialDistortion

    cams = [c.camera for c in located.result.candidates]
    rng = np.random.default_rng(3)
    for _ in range(20):  # random poses, some looking up, with and without distortion
        q, _r = np.linalg.qr(rng.normal(size=(3, 3)))
        rot = q * np.sign(np.linalg.det(q))
        center = np.array([*rng.uniform(-40, 40, 2), rng.uniform(2, 12)])
        dist = RadialDistortion(float(rng.uniform(-0.3, 0.1)), 700.0) if _ % 2 else None
        cams.append(Camera(float(rng.uniform(400, 1500)), (640.0, 360.0), rot, -rot @ center, dist))
    assert len(cams) > 20
    batched = view_cones(cams, (1280, 720), 45.0)
    for cam, ring in zip(cams, batched, strict=True):
        one = view_cone(cam, (1280, 720), 45.0)
        assert ring.shape == one.shape
        assert np.array_equal(ring, one)  # the same numbers to the last bit
    assert view_cones([], (1280, 720), 45.0) == []


def test_one_bearing_wraps_as_the_array_formula() -> None:
    from camloc_geo.geodesy import normalize_bearing_deg

    rng = np.random.default_rng(5)
    edge = [0.0, -0.0, -1e-20, -1e-300, 360.0, -360.0, 359.99999999999994, 720.5, 1e308]
    values = [*edge, *rng.uniform(-1e4, 1e4, 500).tolist()]
    arr = normalize_bearing_deg(np.asarray(values))
    one = [normalize_bearing_deg(v) for v in values]
    assert all(type(v) is float for v in one)
    assert np.array_equal(np.asarray(one), arr)
    assert all(0.0 <= v < 360.0 for v in one)
    assert math.isnan(normalize_bearing_deg(float("nan")))


def test_candidate_flags_are_their_string_forms(located: Any) -> None:
    import dataclasses

    from camloc_geo.absolute import Flag, FlagKind
    from camloc_geo.results import candidates_collection

    res = located.result
    flags = [Flag(FlagKind.OCCLUDED, "intersection.corners[2]"), Flag(FlagKind.POOR_FIT)]
    cands = [dataclasses.replace(res.candidates[0], flags=flags), *res.candidates[1:]]
    coll = candidates_collection(dataclasses.replace(res, candidates=cands))
    got = [f.properties.flags for f in coll.features if f.properties.kind == "candidate"]
    assert got[0] == ["occluded:intersection.corners[2]", "poor_fit"]
    assert got[1:] == [[str(f) for f in c.flags] for c in res.candidates[1:]]
