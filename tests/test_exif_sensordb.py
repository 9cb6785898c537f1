"""camloc_geo.exif: the bundled sensor-width table, make/model matching and readings that
disagree (stop 41)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from test_exif import _jpeg  # a grey JPEG with chosen EXIF tags (Make/Model in IFD0)

from camloc_geo.exif import (
    FULL_FRAME_DIAGONAL_MM,
    SIGMA_35MM,
    SIGMA_SENSOR_TABLE,
    focal_from_exif,
    focal_from_tags,
    sensor_width_mm,
)

pytest.importorskip("PIL.Image")

FOCAL, F35, MAKE, MODEL = 0x920A, 0xA405, 0x010F, 0x0110


@pytest.fixture(autouse=True)
def _no_user_table(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("CAMLOC_SENSOR_DB", raising=False)


def test_a_photo_with_only_focal_length_and_model_gets_the_bundled_width(tmp_path: Path) -> None:
    # before: no table bundled, so no prior at all
    p = _jpeg(tmp_path / "a.jpg", (1632, 1224), {FOCAL: 4.15, MAKE: "Apple", MODEL: "iPhone 6"})
    ex = focal_from_exif(p)
    assert ex is not None
    assert ex.source == "exif-sensor-table"
    assert ex.focal_px == pytest.approx(4.15 / 4.89 * 1632)
    assert ex.sigma_rel == pytest.approx(SIGMA_SENSOR_TABLE)
    assert focal_from_exif(p, bundled_table=False) is None


@pytest.mark.parametrize(
    ("make", "model", "width_mm"),
    [
        ("NIKON CORPORATION", "NIKON D40", 23.7),  # company name, make repeated in the model
        ("Canon", "Canon Canon EOS 5D", 35.8),  # the make written twice
        ("CASIO COMPUTER CO.,LTD.", "EX-Z55 ", 5.735),  # exz55 5.72, exilimexz55 5.75: mean
        ("apple", "IPHONE  6", 4.89),  # case, double space
        ("Apple\x00", "iPhone 6\x00", 4.89),  # NUL-padded strings
        ("EASTMAN KODAK COMPANY", "KODAK EASYSHARE C875 ZOOM DIGITAL CAMERA", 7.11),  # suffix
        ("SAMSUNG", "SAMSUNG-Galaxy-Note8", 5.72),
        ("LG Electronics", "Nexus 5", 4.54),  # table make "lge"
        ("Apple", "iPhone SE (2nd generation)", 4.89),
        ("Panasonic", "DMC-TZ2", 6.08),  # the table's "lumixdmctz2": series name added
        ("CASIO COMPUTER CO.,LTD.", "EX-Z850   ", 7.11),  # the table's "exilimexz850"
    ],
)
def test_make_and_model_variants_match(make: str, model: str, width_mm: float) -> None:
    got = sensor_width_mm(make, model)
    assert got is not None
    assert got[0] == pytest.approx(width_mm)
    assert got[1] == "bundled table"


@pytest.mark.parametrize(
    ("make", "model"),
    [
        ("Apple", "iPhone 99"),  # unknown model of a known make
        ("Foo Optics", "Bar 1"),  # unknown make
        ("Apple", "iPhone"),  # a prefix of many models is not one of them
        ("NIKON CORPORATION", "NIKON D7"),  # exact only: not D70, D700, D7000, ...
        ("Apple", ""),
    ],
)
def test_unknown_models_give_no_width(
    make: str, model: str, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level("INFO", logger="camloc_geo.exif")
    assert sensor_width_mm(make, model) is None
    if model:
        assert "not in the sensor table" in caplog.text


def test_an_ambiguous_model_gives_no_width_and_a_warning(caplog: pytest.LogCaptureFixture) -> None:
    # the table lists the Olympus E-20 twice: 8.8 and 9.15 mm (4 % apart)
    assert sensor_width_mm("OLYMPUS OPTICAL CO.,LTD", "E-20") is None
    assert "ambiguous in the sensor table (8.8, 9.15 mm)" in caplog.text
    tags = {FOCAL: 9.0, MAKE: "OLYMPUS OPTICAL CO.,LTD", MODEL: "E-20"}
    assert focal_from_tags(tags, 2560, 1920) is None


@pytest.mark.parametrize(
    ("size", "width_mm"),
    [((4000, 3000), 11.77), ((3000, 2000), 12.73), ((4000, 2250), 12.15), ((3000, 3000), None)],
)
def test_a_width_per_aspect_ratio_follows_the_photo(
    size: tuple[int, int], width_mm: float | None
) -> None:
    # COLMAP lists the PowerShot G7 X's width for 3:2, 4:3 and 16:9 photos, and a 13.2 mm
    # sensor width besides: only the photo's own aspect counts
    got = sensor_width_mm("Canon", "Canon PowerShot G7 X", size)
    assert (None if got is None else got[0]) == (
        None if width_mm is None else pytest.approx(width_mm)
    )


def test_the_user_table_takes_precedence(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    db = tmp_path / "sensors.txt"
    db.write_text("Apple iPhone 6;5.5\n", encoding="utf-8")
    monkeypatch.setenv("CAMLOC_SENSOR_DB", str(db))
    tags = {FOCAL: 4.15, MAKE: "Apple", MODEL: "iPhone 6"}
    assert sensor_width_mm("Apple", "iPhone 6") == (pytest.approx(5.5), "CAMLOC_SENSOR_DB")
    ex = focal_from_tags(tags, 1600, 1200)
    assert ex is not None
    assert ex.focal_px == pytest.approx(4.15 / 5.5 * 1600)
    # a camera the user's table lacks: the bundled one
    assert sensor_width_mm("NIKON CORPORATION", "NIKON D40") == (
        pytest.approx(23.7),
        "bundled table",
    )
    # an explicit sensor_db beats the environment
    other = tmp_path / "other.csv"
    other.write_text("CameraMaker,CameraModel,SensorWidth(mm)\nApple,iPhone 6,6.0\n", "utf-8")
    ex2 = focal_from_tags(tags, 1600, 1200, sensor_db=str(other))
    assert ex2 is not None
    assert ex2.focal_px == pytest.approx(4.15 / 6.0 * 1600)


def test_agreeing_readings_keep_the_lens_and_sensor(tmp_path: Path) -> None:
    # iPhone 6: 4.15 mm on 4.89 mm gives 0.849 x the longer side, its 29 mm tag 0.838
    p = _jpeg(
        tmp_path / "b.jpg",
        (3264, 2448),
        {FOCAL: 4.15, F35: 29, MAKE: "Apple", MODEL: "iPhone 6"},
    )
    ex = focal_from_exif(p)
    assert ex is not None
    assert ex.source == "exif-sensor-table"
    assert ex.focal_px == pytest.approx(4.15 / 4.89 * 3264)
    assert ex.sigma_rel == pytest.approx(SIGMA_SENSOR_TABLE)
    assert [r[0] for r in ex.readings] == ["exif-sensor-table", "exif-35mm"]
    assert ex.readings[1][1] == pytest.approx(29 * 4080 / FULL_FRAME_DIAGONAL_MM)
    assert ex.warnings == ()


def test_disagreeing_readings_give_a_prior_that_covers_both(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    # iPhone 4 (batch 9): 3.85 mm on its 4.54 mm sensor gives 2198 px, its 35 mm tag of
    # 35 mm 2617 px, 19 % apart: before, the tag alone at +/- 4 %
    w, h = 2592, 1936
    p = _jpeg(tmp_path / "c.jpg", (w, h), {FOCAL: 3.85, F35: 35, MAKE: "Apple", MODEL: "iPhone 4"})
    ex = focal_from_exif(p)
    assert ex is not None
    f_lens = 3.85 / 4.54 * w
    f_tag = 35 * math.hypot(w, h) / FULL_FRAME_DIAGONAL_MM
    d = math.log(f_tag / f_lens)
    assert ex.source == "exif-conflict"
    assert ex.focal_px == pytest.approx(math.sqrt(f_lens * f_tag))
    assert ex.sigma_rel == pytest.approx(
        math.sqrt(0.5 * (SIGMA_SENSOR_TABLE**2 + SIGMA_35MM**2) + (0.5 * d) ** 2)
    )
    for f in (f_lens, f_tag):  # each reading within 1.1 sigma of the prior
        assert abs(math.log(f / ex.focal_px)) < 1.1 * ex.sigma_rel
    assert len(ex.warnings) == 1
    assert "the EXIF tags disagree" in ex.warnings[0]
    assert "2198 px" in ex.warnings[0]
    assert "2617 px" in ex.warnings[0]
    assert "the EXIF tags disagree" in caplog.text


def test_a_16_9_photo_of_a_4_3_sensor_reads_the_tag_on_the_4_3_frame() -> None:
    # an iPhone 6 photo in 16:9: the tag's crop factor (29 / 4.15) on the 4.89 mm sensor
    # is a 4:3 frame's, so the tag is read on it, not on the photo's own diagonal (9 % low)
    w, h = 3264, 1836
    tags = {FOCAL: 4.15, F35: 29, MAKE: "Apple", MODEL: "iPhone 6"}
    ex = focal_from_tags(tags, w, h)
    assert ex is not None
    tag = {s: f for s, f, _ in ex.readings}["exif-35mm"]
    assert tag == pytest.approx(29 * w * 1.25 / FULL_FRAME_DIAGONAL_MM)
    assert tag / ex.focal_px == pytest.approx(1.0, abs=0.02)
    assert any("4:3 frame" in n for n in ex.notes)
    assert ex.warnings == ()


def test_a_16_9_photo_of_an_unknown_sensor_reads_the_tag_both_ways() -> None:
    w, h = 1920, 1080
    tags = {FOCAL: 4.0, F35: 26, MAKE: "Acme", MODEL: "Phone 1"}
    ex = focal_from_tags(tags, w, h)
    assert ex is not None
    assert ex.source == "exif-35mm"
    f_own = 26 * math.hypot(w, h) / FULL_FRAME_DIAGONAL_MM
    f_43 = 26 * w * 1.25 / FULL_FRAME_DIAGONAL_MM
    assert ex.focal_px == pytest.approx(math.sqrt(f_own * f_43))
    assert ex.sigma_rel == pytest.approx(math.hypot(SIGMA_35MM, 0.5 * math.log(f_43 / f_own)))
    assert ex.sigma_rel > 0.055
    assert any("4:3 frame" in n for n in ex.notes)
    assert ex.warnings == ()
    # a 4:3 photo's tag is read on its own diagonal, as before
    ex43 = focal_from_tags(tags, 1600, 1200)
    assert ex43 is not None
    assert ex43.focal_px == pytest.approx(26 * 2000 / FULL_FRAME_DIAGONAL_MM)
    assert ex43.sigma_rel == pytest.approx(SIGMA_35MM)


def test_a_near_square_photo_gets_no_table_reading() -> None:
    # a 1:1 crop of a 4:3 sensor: its longer side is the sensor's height, not its width
    tags = {FOCAL: 4.15, MAKE: "Apple", MODEL: "iPhone 6"}
    assert focal_from_tags(tags, 2448, 2448) is None
    assert focal_from_tags(tags, 3264, 2448) is not None


def test_a_camera_the_table_lists_twice_gets_the_tag_alone(
    caplog: pytest.LogCaptureFixture,
) -> None:
    # COLMAP's table lists the Panasonic DMC-LX3 as "dmclx3" (6.51 mm) and as
    # "lumixdmclx3" (7.85 mm): no width is taken, the 24 mm tag decides
    tags = {FOCAL: 5.1, F35: 24, MAKE: "Panasonic", MODEL: "DMC-LX3"}
    ex = focal_from_tags(tags, 3776, 2520)
    assert ex is not None
    assert ex.source == "exif-35mm"
    assert ex.focal_px == pytest.approx(24 * math.hypot(3776, 2520) / FULL_FRAME_DIAGONAL_MM)
    assert "ambiguous in the sensor table (6.51, 7.85 mm)" in caplog.text


def test_a_wrong_table_width_is_a_conflict_not_a_prior(tmp_path: Path) -> None:
    # a user's table with the LX3's wrong 6.51 mm puts 5.1 mm at 0.78 x the longer side;
    # its 24 mm tag says 0.67: neither is taken alone
    db = tmp_path / "sensors.txt"
    db.write_text("Panasonic DMC-LX3;6.51\n", encoding="utf-8")
    tags = {FOCAL: 5.1, F35: 24, MAKE: "Panasonic", MODEL: "DMC-LX3"}
    ex = focal_from_tags(tags, 3776, 2520, sensor_db=str(db))
    assert ex is not None
    assert ex.source == "exif-conflict"
    assert ex.sigma_rel > 0.08
    assert [r[0] for r in ex.readings] == ["exif-sensor-table", "exif-35mm"]


def test_the_bundled_table_is_attributed() -> None:
    from importlib import resources

    folder = resources.files("camloc_geo") / "data" / "sensor_widths"
    csv_head = folder.joinpath("sensor_widths.csv").read_text("utf-8")[:400]
    notice = folder.joinpath("NOTICE.md").read_text("utf-8")
    assert "5d968cf38aa2574fd284b0dc86c3d58d124940b3" in csv_head
    assert "5d968cf38aa2574fd284b0dc86c3d58d124940b3" in notice
    assert "BSD 3-clause" in notice
    assert "ETH Zurich and UNC Chapel Hill" in notice
    assert "Camera Sensor Size Database authors" in notice  # openMVG's MIT notice


def test_the_conflict_reaches_the_vanishing_point_result(tmp_path: Path) -> None:
    # detect_vanishing_points(use_exif=True) names the conflict in focal_source and puts its
    # warning first among the result's warnings (the JSON's, not only the log)
    from test_autovp_failure_modes import corner_segments

    from camloc_geo.autovp import detect_vanishing_points

    segs, (w, h) = corner_segments(0, 0.0, seed=0)  # a corner seen at 700 px
    f_lens_mm = round(0.9 * 700.0 / max(w, h) * 4.54, 2)  # 0.9 x on the iPhone 4's sensor
    f35 = round(1.12 * 700.0 * FULL_FRAME_DIAGONAL_MM / math.hypot(w, h))  # 1.12 x
    tags = {FOCAL: f_lens_mm, F35: f35, MAKE: "Apple", MODEL: "iPhone 4"}
    p = _jpeg(tmp_path / "corner.jpg", (w, h), tags)
    res = detect_vanishing_points(p, segments=segs, use_exif=True)
    assert res.focal_source == "exif-conflict"
    assert res.warnings[0].startswith("the EXIF tags disagree")
    assert abs(math.log(res.focal_px / 700.0)) < 2.0 * res.focal_std_rel
    plain = detect_vanishing_points(p, segments=segs, use_exif=False)
    assert not any("EXIF tags" in x for x in plain.warnings)


def test_the_converter_reads_colmaps_table() -> None:
    # data/sensor_widths/from_colmap.py: per-aspect models split, a model with a comma
    # quoted, a repeated row kept once
    import csv
    import importlib.util

    path = Path(__file__).parents[1] / "data" / "sensor_widths" / "from_colmap.py"
    spec = importlib.util.spec_from_file_location("from_colmap", path)
    assert spec is not None
    assert spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    specs_cc = """
    {
      auto& make_specs = specs["konica-minolta"];
      make_specs.emplace_back("dimage7", 8.8000f);
      make_specs.emplace_back("dimage7", 8.8000f);
    }
    {
      auto& make_specs = specs["apple"];
      make_specs.emplace_back("iphone4,1", 4.5700f);
      make_specs.emplace_back("powershotg7x(4:3)", 11.7700f);
    }
    """
    text = mod.convert(specs_cc, "abc123")
    assert "abc123" in text.splitlines()[1]
    rows = list(csv.reader(ln for ln in text.splitlines() if not ln.startswith("#")))
    assert rows == [
        ["make", "model", "width_mm", "aspect"],
        ["konicaminolta", "dimage7", "8.8", ""],
        ["apple", "iphone4,1", "4.57", ""],
        ["apple", "powershotg7x", "11.77", "4:3"],
    ]
