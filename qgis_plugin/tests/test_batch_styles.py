"""Session 40 QA: a ``camloc batch`` GeoPackage opened in QGIS looks as the plugin's layers.

The batch writes QGIS's ``layer_styles`` table (its layers' default styles, made from the
plugin's by ``qgis_plugin/make_batch_styles.py``); before, QGIS drew each layer in one random
colour. The batch runs in its own process (camloc_geo's wheels stay out of QGIS's).
"""

from __future__ import annotations

import subprocess
import sys

from conftest import SAMPLE_OSM, SAMPLE_SCENE
from qgis.core import QgsRuleBasedRenderer, QgsVectorLayer


def test_a_batch_geopackage_opens_styled(tmp_path):
    lst = tmp_path / "cams.csv"
    lst.write_text(f"id,title,scene\ns1,,{SAMPLE_SCENE}\nc1,Eastern Ave & S Broadway,\n")
    out = tmp_path / "cams.gpkg"
    cmd = [sys.executable, "-m", "camloc_geo.cli", "batch", str(lst), "-o", str(out)]
    r = subprocess.run(
        [*cmd, "--osm", str(SAMPLE_OSM), "--workers", "1", "--no-progress"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    seen = {}
    for name in ("cameras", "candidates", "view_cones"):
        layer = QgsVectorLayer(f"{out}|layername={name}", name, "ogr")
        assert layer.isValid()
        renderer = layer.renderer()
        assert isinstance(renderer, QgsRuleBasedRenderer), (name, type(renderer))
        seen[name] = [rule.label() for rule in renderer.rootRule().children()]
        if name != "view_cones":
            assert layer.labelsEnabled(), name
    assert seen["candidates"][0].startswith("★ tie:")
    assert seen["candidates"][1:] == ["a camera's best candidate", "other candidates"]
    from camloc.layers import CAMERA_TIE_WORDS

    # a camera at a tied candidate is drawn apart (session 41 QA: every camera was one red
    # triangle labelled 'a located', a tied one as sure-looking as any)
    assert seen["cameras"] == [CAMERA_TIE_WORDS, "camera placed"]
    cams = QgsVectorLayer(f"{out}|layername=cameras", "k", "ogr")
    assert _drawn_by(cams) == {"s1": CAMERA_TIE_WORDS, "c1": "camera placed"}
    assert _labels(cams) == {"s1": "s1 located ≈ tie", "c1": "c1 title_only"}
    # the sample's tie (ranks 1-5; 5 a junction a block away, stop 41) is drawn by the star
    # rule, the rest by the others
    layer = QgsVectorLayer(f"{out}|layername=candidates", "c", "ogr")
    root = layer.renderer().rootRule()
    tie_rule = root.children()[0]
    from qgis.core import QgsExpression, QgsExpressionContext, QgsExpressionContextUtils

    ctx = QgsExpressionContext(QgsExpressionContextUtils.globalProjectLayerScopes(layer))
    expr = QgsExpression(tie_rule.filterExpression())
    starred = []
    for f in layer.getFeatures():
        ctx.setFeature(f)
        if expr.evaluate(ctx):
            starred.append((f["id"], f["rank"]))
    assert sorted(starred) == [("s1", 1), ("s1", 2), ("s1", 3), ("s1", 4), ("s1", 5)]
    # Only the leading candidates get a cone: every cone of every candidate drew one orange
    # blob around the sample's camera (12 cones, scores down to 1e-22; session 40 desktop).
    cones = QgsVectorLayer(f"{out}|layername=view_cones", "v", "ogr")
    rules = cones.renderer().rootRule().children()
    assert [r.label() for r in rules] == ["view cone of a leading candidate (faded by score)"]
    ctx = QgsExpressionContext(QgsExpressionContextUtils.globalProjectLayerScopes(cones))
    expr = QgsExpression(rules[0].filterExpression())
    drawn, left = [], []
    for f in cones.getFeatures():
        ctx.setFeature(f)
        (drawn if expr.evaluate(ctx) else left).append((f["id"], f["rank"]))
    assert not expr.hasEvalError(), expr.evalErrorString()
    assert sorted(drawn) == [("s1", 1), ("s1", 2), ("s1", 3), ("s1", 4), ("s1", 5)]
    assert len(left) >= 6
    assert all(r > 5 for _, r in left)
    # the plugin's one cone style (session 41: make_batch_styles.py drew a copy without the
    # tie's red outline): a tied candidate's cone is outlined red, the others brown
    from qgis.core import QgsSymbolLayer

    stroke = (
        rules[0]
        .symbol()
        .symbolLayer(0)
        .dataDefinedProperties()
        .property(QgsSymbolLayer.PropertyStrokeColor)
    )
    assert stroke.isActive()
    outline = {}
    for f in cones.getFeatures():
        ctx.setFeature(f)
        outline[f["rank"]] = str(stroke.value(ctx, "")[0])
    assert {outline[r] for r in (1, 2, 3, 4)} == {"#d7191c"}
    assert all(outline[r] != "#d7191c" for _, r in left)


def test_a_service_job_geopackage_opens_styled(tmp_path):
    """The service's job result (``format=gpkg``) carries its own styles: its ties are JSON
    text (``"[2]"``, ``"[]"`` without one), read by its candidates' star rule."""
    out = tmp_path / "job.gpkg"
    code = (
        "import sys; from camloc_geo.results import job_result_geojson, job_result_geopackage\n"
        "def c(rank, tie): return {'type': 'Feature', 'geometry': {'type': 'Point', "
        "'coordinates': [-76.5935 + rank * 1e-4, 39.2855]}, 'properties': {'kind': "
        "'candidate', 'rank': rank, 'score': 0.4 / rank, 'ambiguous_with': tie}}\n"
        "cam = {'id': 'k1', 'row': 1, 'status': 'located', 'lat': 39.2855, 'lon': -76.5935,"
        " 'ambiguous': True, 'candidates': [c(1, [2]), c(2, [1]), c(3, [])]}\n"
        "open(sys.argv[1], 'wb').write(job_result_geopackage(job_result_geojson('j', [cam])))\n"
    )
    subprocess.run([sys.executable, "-c", code, str(out)], check=True, timeout=300)
    layer = QgsVectorLayer(f"{out}|layername=candidates", "c", "ogr")
    assert layer.isValid()
    assert isinstance(layer.renderer(), QgsRuleBasedRenderer)
    rules = layer.renderer().rootRule().children()
    assert rules[0].label().startswith("★ tie:")
    from qgis.core import QgsExpression, QgsExpressionContext, QgsExpressionContextUtils

    ctx = QgsExpressionContext(QgsExpressionContextUtils.globalProjectLayerScopes(layer))
    drawn_by = {}
    for f in layer.getFeatures():
        ctx.setFeature(f)
        for rule in rules:
            if rule.isElse() or QgsExpression(rule.filterExpression()).evaluate(ctx):
                drawn_by[f["rank"]] = rule.label()[:12]
                break
    assert drawn_by == {1: "★ tie: anoth", 2: "★ tie: anoth", 3: "other candid"}
    cams = QgsVectorLayer(f"{out}|layername=cameras", "k", "ogr")
    assert isinstance(cams.renderer(), QgsRuleBasedRenderer)
    assert cams.labelsEnabled()
    # the job's tie is its camera's 'ambiguous' (session 41 QA)
    from camloc.layers import CAMERA_TIE_WORDS

    assert _drawn_by(cams) == {"k1": CAMERA_TIE_WORDS}
    assert _labels(cams) == {"k1": "k1 located ≈ tie"}


def _drawn_by(layer):
    """Camera id -> the label of the first rule that draws it."""
    from qgis.core import QgsExpression, QgsExpressionContext, QgsExpressionContextUtils

    ctx = QgsExpressionContext(QgsExpressionContextUtils.globalProjectLayerScopes(layer))
    out = {}
    for f in layer.getFeatures():
        ctx.setFeature(f)
        for rule in layer.renderer().rootRule().children():
            if rule.isElse() or QgsExpression(rule.filterExpression()).evaluate(ctx):
                out[f["id"]] = rule.label()
                break
    return out


def _labels(layer):
    """Camera id -> its label's text."""
    from qgis.core import QgsExpression, QgsExpressionContext, QgsExpressionContextUtils

    expr = QgsExpression(layer.labeling().settings().fieldName)
    ctx = QgsExpressionContext(QgsExpressionContextUtils.globalProjectLayerScopes(layer))
    out = {}
    for f in layer.getFeatures():
        ctx.setFeature(f)
        out[f["id"]] = expr.evaluate(ctx)
    return out
