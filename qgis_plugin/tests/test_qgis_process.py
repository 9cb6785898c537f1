"""How a user's QGIS sees the plugin: the built zip in a fresh profile, run by qgis_process."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zipfile

import pytest
from conftest import PLUGIN_ROOT, SAMPLE_OSM, SAMPLE_SCENE, metres_between, truth

QGIS_PROCESS = shutil.which("qgis_process.bin") or "/usr/bin/qgis_process.bin"


@pytest.fixture(scope="module")
def profile_home(tmp_path_factory):
    """HOME with a default profile that has the built camloc.zip installed and enabled."""
    home = tmp_path_factory.mktemp("home")
    dist = tmp_path_factory.mktemp("dist")
    r = subprocess.run(
        [sys.executable, str(PLUGIN_ROOT / "build_zip.py"), "-o", str(dist)],
        capture_output=True,
        text=True,
        check=True,
    )
    archive = r.stdout.strip()
    assert archive.endswith("camloc.zip")
    with zipfile.ZipFile(archive) as zf:
        names = zf.namelist()
        assert "camloc/metadata.txt" in names
        assert "camloc/icon.png" in names
        assert not [n for n in names if "__pycache__" in n or "/tests/" in n]
        profile = home / ".local/share/QGIS/QGIS3/profiles/default"
        zf.extractall(profile / "python" / "plugins")
    (profile / "QGIS").mkdir(parents=True)
    (profile / "QGIS" / "QGIS3.ini").write_text("[PythonPlugins]\ncamloc=true\n")
    return home


def _env(home) -> dict[str, str]:
    env = {
        k: v
        for k, v in os.environ.items()
        if not k.startswith(("QGIS_", "PYTHON")) and k != "QT_QPA_PLATFORM"
    }
    env.update(HOME=str(home), QT_QPA_PLATFORM="offscreen", CAMLOC_PYTHON=sys.executable)
    return env


def test_qgis_process_lists_the_camloc_algorithms(profile_home):
    r = subprocess.run(
        [QGIS_PROCESS, "list"], capture_output=True, text=True, env=_env(profile_home), timeout=300
    )
    assert r.returncode == 0, r.stderr
    for alg in ("camloc:locate", "camloc:corners", "camloc:geocodelist"):
        assert alg in r.stdout


def test_qgis_process_runs_locate_on_the_sample(profile_home, tmp_path):
    out = tmp_path / "candidates.gpkg"
    r = subprocess.run(
        [
            QGIS_PROCESS,
            "run",
            "camloc:locate",
            f"--SCENE={SAMPLE_SCENE}",
            f"--OSM={SAMPLE_OSM}",
            f"--CANDIDATES={out}",
            f"--VIEW_CONES={tmp_path / 'cones.gpkg'}",
        ],
        capture_output=True,
        text=True,
        env=_env(profile_home),
        timeout=300,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    assert "N_CANDIDATES:\t13" in r.stdout
    from osgeo import ogr

    ds = ogr.Open(str(out))
    layer = ds.GetLayer(0)
    assert layer.GetFeatureCount() == 13
    defn = layer.GetLayerDefn()
    types = {
        defn.GetFieldDefn(i).GetName(): defn.GetFieldDefn(i).GetTypeName()
        for i in range(defn.GetFieldCount())
    }
    assert types["rank"] == "Integer"
    assert types["score"] == "Real"
    t = truth()
    best = min(
        metres_between(f.GetGeometryRef().GetY(), f.GetGeometryRef().GetX(), t["lat"], t["lon"])
        for f in layer
    )
    assert best < 5.0


def test_qgis_process_reports_a_bad_scene_as_an_error(profile_home, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "camloc-scene/9"}')
    r = subprocess.run(
        [
            QGIS_PROCESS,
            "run",
            "camloc:locate",
            f"--SCENE={bad}",
            f"--OSM={SAMPLE_OSM}",
            f"--CANDIDATES={tmp_path / 'c.gpkg'}",
        ],
        capture_output=True,
        text=True,
        env=_env(profile_home),
        timeout=300,
    )
    assert r.returncode != 0
    assert "unknown format version" in r.stdout + r.stderr


def test_qgis_process_geocodelist_takes_a_folder_of_extracts(profile_home, tmp_path):
    """As ``camloc batch --osm data/osm/``: a list spanning extracts, made-up titles not placed."""
    data_osm = PLUGIN_ROOT.parent / "data" / "osm"
    lst = tmp_path / "cams.csv"
    lst.write_text(
        "id,title\n"
        "foo,Foo St & Bar Ave\n"
        "milton,N Milton Ave & E Biddle St\n"
        "main,Quenthorpe Lane\n"
        "berlin,Karl-Liebknecht-Str. / Wadzeckstr.\n"
    )
    out = tmp_path / "cams.gpkg"
    r = subprocess.run(
        [
            QGIS_PROCESS,
            "run",
            "camloc:geocodelist",
            "--",
            f"LIST={lst}",
            f"OSM={data_osm}/",
            f"CAMERAS={out}",
        ],
        capture_output=True,
        text=True,
        env=_env(profile_home),
        timeout=600,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    from qgis.core import QgsVectorLayer

    layer = QgsVectorLayer(str(out), "cams", "ogr")
    assert layer.isValid()
    rows = {f["camera_id"]: (f["status"], f["n_candidates"]) for f in layer.getFeatures()}
    assert rows["foo"] == ("not_found", 0)
    assert rows["main"] == ("not_found", 0)
    assert rows["milton"][0] == "title_only"
    assert rows["berlin"][0] == "title_only"  # another extract of the folder


def test_qgis_process_reads_relative_paths_from_the_shell_folder(profile_home, tmp_path):
    """``--SCENE=scene.json`` is the shell's file (was: "scene file not found", the worker
    looked in its own temporary folder); the same for OSM and LIST."""
    shutil.copy(SAMPLE_SCENE, tmp_path / "scene.json")
    shutil.copy(SAMPLE_OSM, tmp_path / "extract.osm.pbf")
    (tmp_path / "cams.csv").write_text("id,title\nc1,Eastern Ave & S Broadway\n")
    runs = {
        "locate": [
            "camloc:locate",
            "--SCENE=scene.json",
            "--OSM=extract.osm.pbf",
            "--CANDIDATES=cand.gpkg",
        ],
        "list": [
            "camloc:geocodelist",
            "--LIST=cams.csv",
            "--OSM=extract.osm.pbf",
            "--CAMERAS=cams.gpkg",
        ],
    }
    for what, args in runs.items():
        r = subprocess.run(
            [QGIS_PROCESS, "run", *args],
            capture_output=True,
            text=True,
            env=_env(profile_home),
            cwd=tmp_path,
            timeout=300,
        )
        assert r.returncode == 0, (what, r.stdout + r.stderr)
    from osgeo import ogr

    cand_ds = ogr.Open(str(tmp_path / "cand.gpkg"))  # keep the dataset: its layer needs it
    assert cand_ds.GetLayer(0).GetFeatureCount() == 13
    cams_ds = ogr.Open(str(tmp_path / "cams.gpkg"))
    assert [f.GetField("status") for f in cams_ds.GetLayer(0)] == ["title_only"]


@pytest.mark.parametrize("options", [True, False], ids=["options-set", "options-unset"])
def test_qgis_process_runs_a_model_chaining_camloc_algorithms(
    profile_home, provider, tmp_path, options
):
    # the designer's use: locate's candidates feed corners (their extent) and a native filter;
    # options-unset: camloc's yes/no options and corners' radius have no value in the model
    # (QGIS 3.22 refused it: "Parameter NETWORK is mandatory")
    from conftest import chain_model

    model = tmp_path / "chain.model3"
    assert chain_model(options=options).toFile(str(model))
    r = subprocess.run(
        [
            QGIS_PROCESS,
            "run",
            str(model),
            f"--scene={SAMPLE_SCENE}",
            f"--osm={SAMPLE_OSM}",
            f"--locate:candidates={tmp_path / 'c.gpkg'}",
            f"--corners:corners={tmp_path / 'k.gpkg'}",
            f"--best:best={tmp_path / 'b.gpkg'}",
        ],
        capture_output=True,
        text=True,
        env=_env(profile_home),
        timeout=300,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    assert "Executed 3 algorithms" in r.stdout
    from osgeo import ogr

    def rows(name):
        ds = ogr.Open(str(tmp_path / name))
        return [f.items() for f in ds.GetLayer(0)], ds

    cands, ds = rows("c.gpkg")
    assert len(cands) == 13
    assert ds.GetLayerByName("layer_styles").GetFeatureCount() == 1  # camloc's default style
    best, _ = rows("b.gpkg")
    first = next(c for c in cands if c["rank"] == 1)
    assert [(b["rank"], b["lat"], b["lon"]) for b in best] == [(1, first["lat"], first["lon"])]
    corners, _ = rows("k.gpkg")
    assert [c["kind"] for c in corners].count("intersection") >= 1


def test_qgis_process_names_a_number_out_of_range(profile_home, tmp_path):
    # stop 41: "Incorrect parameter value for MAX_CANDIDATES", no range
    r = subprocess.run(
        [
            QGIS_PROCESS,
            "run",
            "camloc:locate",
            f"--SCENE={SAMPLE_SCENE}",
            f"--OSM={SAMPLE_OSM}",
            f"--CANDIDATES={tmp_path / 'c.gpkg'}",
            "--MAX_CANDIDATES=0",
        ],
        capture_output=True,
        text=True,
        env=_env(profile_home),
        timeout=300,
    )
    assert r.returncode != 0
    assert (
        "camloc: MAX_CANDIDATES (At most this many candidates) must be a whole number of at "
        "least 1; got 0" in r.stdout + r.stderr
    )
    assert not (tmp_path / "c.gpkg").exists()
