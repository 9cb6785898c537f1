"""Worker GeoJSON -> QGIS features (typed fields, EPSG:4326) and the default layer styles."""

from __future__ import annotations

import json
from typing import Any

from qgis.core import (
    NULL,
    QgsCoordinateReferenceSystem,
    QgsCoordinateTransformContext,
    QgsExpression,
    QgsExpressionContext,
    QgsExpressionContextUtils,
    QgsFeature,
    QgsFeatureSink,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsLayerTreeGroup,
    QgsLayerTreeLayer,
    QgsPalLayerSettings,
    QgsPointXY,
    QgsProperty,
    QgsRectangle,
    QgsRuleBasedRenderer,
    QgsSymbol,
    QgsSymbolLayer,
    QgsTextBufferSettings,
    QgsTextFormat,
    QgsVectorFileWriter,
    QgsVectorLayer,
    QgsVectorLayerSimpleLabeling,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QVariant
from qgis.PyQt.QtGui import QColor, QFontMetricsF

WGS84 = "EPSG:4326"

_TYPES = {
    "int": QVariant.Int,
    "double": QVariant.Double,
    "string": QVariant.String,
    "bool": QVariant.Bool,
}
_WKB = {
    "Point": QgsWkbTypes.Point,
    "LineString": QgsWkbTypes.MultiLineString,
    "Polygon": QgsWkbTypes.MultiPolygon,
    "None": QgsWkbTypes.NoGeometry,
}


def wgs84() -> QgsCoordinateReferenceSystem:
    """EPSG:4326, the CRS of every camloc layer."""
    return QgsCoordinateReferenceSystem(WGS84)


def fields_of(desc: dict[str, Any]) -> QgsFields:
    """QgsFields from a worker layer description (``fields``: ``[[name, type], ...]``)."""
    fields = QgsFields()
    for name, typ in desc["fields"]:
        fields.append(QgsField(name, _TYPES[typ]))
    return fields


def wkb_of(desc: dict[str, Any]) -> int:
    """The layer's WKB type."""
    return _WKB[desc["geometry"]]


def _ring(ring: list[Any]) -> list[QgsPointXY]:
    return [QgsPointXY(float(p[0]), float(p[1])) for p in ring]


def _geometry(geom: dict[str, Any] | None, wkb: int) -> QgsGeometry | None:
    if not geom:
        return None
    kind = geom["type"]
    coords = geom.get("coordinates") or []
    if kind == "Point":
        if len(coords) < 2 or coords[0] is None or coords[1] is None:
            return None  # a camera that could not be placed: a row without geometry
        return QgsGeometry.fromPointXY(QgsPointXY(float(coords[0]), float(coords[1])))
    if kind == "LineString":
        g = QgsGeometry.fromMultiPolylineXY([_ring(coords)])
    elif kind == "MultiLineString":
        g = QgsGeometry.fromMultiPolylineXY([_ring(line) for line in coords])
    elif kind == "Polygon":
        g = QgsGeometry.fromPolygonXY([_ring(r) for r in coords])
        if wkb == QgsWkbTypes.MultiPolygon:
            g.convertToMultiType()
    elif kind == "MultiPolygon":
        g = QgsGeometry.fromMultiPolygonXY([[_ring(r) for r in poly] for poly in coords])
    else:
        raise ValueError(f"unsupported geometry type {kind}")
    return g


def _data(desc: dict[str, Any]) -> dict[str, Any]:
    data = desc.get("data")
    if data is None:  # a description straight from the worker (its file still there)
        with open(desc["path"], encoding="utf-8") as fh:
            data = json.load(fh)
    return data


def features_of(desc: dict[str, Any], fields: QgsFields) -> list[QgsFeature]:
    """The features of a worker layer (inline ``data`` or its file), attributes in field order."""
    names = [f.name() for f in fields]
    wkb = wkb_of(desc)
    out = []
    for f in _data(desc)["features"]:
        feat = QgsFeature(fields)
        g = _geometry(f.get("geometry"), wkb)
        if g is not None:
            feat.setGeometry(g)
        props = f.get("properties") or {}
        feat.setAttributes([props.get(n) for n in names])
        out.append(feat)
    return out


def write_to_sink(sink: QgsFeatureSink, desc: dict[str, Any], fields: QgsFields) -> int:
    """Add the layer's features to a Processing sink; how many."""
    feats = features_of(desc, fields)
    for feat in feats:
        sink.addFeature(feat, QgsFeatureSink.FastInsert)
    return len(feats)


def write_gpkg_layer(gpkg: str, layer_name: str, desc: dict[str, Any]) -> str:
    """Write (or replace) one layer of a GeoPackage; its ``path|layername=`` URI.

    Safe off the GUI thread (no project access), so a QgsTask can call it.

    Raises
    ------
    OSError
        The GeoPackage cannot be written (the message names it).
    """
    import os

    fields = fields_of(desc)
    opts = QgsVectorFileWriter.SaveVectorOptions()
    opts.driverName = "GPKG"
    opts.layerName = layer_name
    opts.actionOnExistingFile = (
        QgsVectorFileWriter.CreateOrOverwriteLayer
        if os.path.exists(gpkg)
        else QgsVectorFileWriter.CreateOrOverwriteFile
    )
    writer = QgsVectorFileWriter.create(
        gpkg, fields, wkb_of(desc), wgs84(), QgsCoordinateTransformContext(), opts
    )
    if writer.hasError() != QgsVectorFileWriter.NoError:
        raise OSError(f"cannot write {layer_name} to {gpkg}: {writer.errorMessage()}")
    for feat in features_of(desc, fields):
        writer.addFeature(feat, QgsFeatureSink.FastInsert)
    del writer  # closes the file
    return f"{gpkg}|layername={layer_name}"


# --- default styles -------------------------------------------------------------------------

KIND_PROPERTY = "camloc/kind"
"""Custom layer property naming a camloc output (``candidates``, ``view_cones``...)."""

DRAW_ORDER = [
    "cameras",
    "candidates",
    "list_candidates",
    "matched_corners",
    "intersection",
    "corners",
    "view_cones",
    "context_buildings",
    "context_streets",
]
"""Top to bottom: points people read above the areas and lines that give them context."""

TIE_WORDS = (
    "tie: another candidate fits the evidence nearly as well (odds under 10 to 1) "
    "more than 10 m away; add a viewing direction or a landmark to decide"
)
"""The legend's words for a tie: the core's rule (camloc_geo.results.TIE_SCORE_RATIO,
TIE_DISTANCE_M), read by the plugin from the ``tie`` field, never from scores."""

LEADING_EXPR = '"rank" = 1 OR "tie" OR coalesce("score", 0) >= 0.05'
"""A candidate worth a view cone (the worker's ``leading``: best, tied, or score >= 0.05)."""

_NO_TIE = 'NOT coalesce("tie", false)'

RANK_LABEL_EXPR = (
    "concat('#', \"rank\", ' ', coalesce(\"score_text\", ''), "
    "CASE WHEN \"tie\" THEN ' (tie with #' || replace(\"ambiguous_with\", ',', ', #') || ')' "
    "ELSE '' END)"
)


def _marker(colour: str, shape: str, size: float, opacity: float = 1.0) -> QgsSymbol:
    sym = QgsSymbol.defaultSymbol(QgsWkbTypes.PointGeometry)
    sym.setColor(QColor(colour))
    sym.setSize(size)
    sym.setOpacity(opacity)
    sl = sym.symbolLayer(0)
    if hasattr(sl, "setShape"):
        from qgis.core import QgsSimpleMarkerSymbolLayerBase

        sl.setShape(getattr(QgsSimpleMarkerSymbolLayerBase, shape))
    sl.setStrokeColor(QColor("black"))
    return sym


def _rules(layer: QgsVectorLayer, rules: list[tuple[str, str | None, QgsSymbol]]) -> None:
    """A rule-based renderer: (legend label, filter or None for else, symbol); the filters
    must exclude each other (every matching rule draws)."""
    root = QgsRuleBasedRenderer.Rule(None)
    for label, expr, sym in rules:
        rule = QgsRuleBasedRenderer.Rule(sym, 0, 0, expr or "", label)
        if expr is None:
            rule.setIsElse(True)
        root.appendChild(rule)
    layer.setRenderer(QgsRuleBasedRenderer(root))


def style_candidates(layer: QgsVectorLayer) -> None:
    """Ties as stars, the best as a large red dot, the rest by score (the unlikely faded)."""
    _rules(
        layer,
        [
            ("★ " + TIE_WORDS, '"tie"', _marker("#d7191c", "Star", 7.0)),
            ("best candidate (#1)", _NO_TIE + ' AND "rank" = 1', _marker("#d7191c", "Circle", 5.0)),
            (
                "score ≥ 0.30",
                _NO_TIE + ' AND "rank" > 1 AND "score" >= 0.3',
                _marker("#fdae61", "Circle", 4.2),
            ),
            (
                "score 0.05 – 0.30",
                _NO_TIE + ' AND "rank" > 1 AND "score" >= 0.05 AND "score" < 0.3',
                _marker("#abd9e9", "Circle", 3.6),
            ),
            ("score < 0.05 (unlikely)", None, _marker("#2c7bb6", "Circle", 2.6, 0.55)),
        ],
    )
    # labels for the leading candidates only: the unlikely ones stay quiet
    _label(layer, f"CASE WHEN {LEADING_EXPR} THEN {RANK_LABEL_EXPR} END", priority=8)
    layer.triggerRepaint()


def style_list_candidates(layer: QgsVectorLayer, tie_expr: str = '"tie"') -> None:
    """A list's candidates: small, unlabelled but for ties, under the cameras' labels.

    ``tie_expr`` is a QGIS expression true for a tied candidate: the plugin's ``"tie"``; the
    batch GeoPackage's and the job result's read their ``ambiguous_with``
    (``qgis_plugin/make_batch_styles.py``).
    """
    # the plugin's boolean may be NULL; the GeoPackages' expressions never are (and their SLD
    # export can say NOT (...), not coalesce)
    no_tie = _NO_TIE if tie_expr == '"tie"' else f"NOT ({tie_expr})"
    _rules(
        layer,
        [
            ("★ " + TIE_WORDS, tie_expr, _marker("#d7191c", "Star", 5.0)),
            (
                "a camera's best candidate",
                no_tie + ' AND "rank" = 1',
                _marker("#fdae61", "Circle", 3.2),
            ),
            ("other candidates", None, _marker("#2c7bb6", "Circle", 2.2, 0.6)),
        ],
    )
    _label(
        layer, f'CASE WHEN "rank" > 1 OR ({tie_expr}) THEN concat(\'#\', "rank") END', priority=1
    )
    layer.triggerRepaint()


VIEW_CONE_TIE_EXPR = '"tie"'
"""The plugin's view cones' tie column (a boolean); :func:`style_view_cones` takes another."""


def leading_expr(tie_expr: str = VIEW_CONE_TIE_EXPR) -> str:
    """A candidate worth a view cone: best, tied (``tie_expr``), or score >= 0.05."""
    return f'"rank" = 1 OR ({tie_expr}) OR coalesce("score", 0) >= 0.05'


def style_view_cones(layer: QgsVectorLayer, tie_expr: str = VIEW_CONE_TIE_EXPR) -> None:
    """Cones of the leading candidates only (best, tied, score >= 0.05), faded by score.

    Parameters
    ----------
    layer
        The cones layer (``rank``, ``score`` and the tie column ``tie_expr`` reads).
    tie_expr
        A QGIS expression true for a tied candidate's cone: the plugin's ``"tie"``; the batch
        GeoPackage's ``"ambiguous_with" IS NOT NULL`` (``qgis_plugin/make_batch_styles.py``
        draws its cones with this one style, the tie's red outline included).
    """
    sym = QgsSymbol.defaultSymbol(QgsWkbTypes.PolygonGeometry)
    sym.setColor(QColor(255, 190, 0, 70))
    sl = sym.symbolLayer(0)
    sl.setStrokeColor(QColor(180, 120, 0, 160))  # as the expression's ELSE (the SLD's colour)
    sl.setDataDefinedProperty(
        QgsSymbolLayer.PropertyFillColor,
        QgsProperty.fromExpression(
            'color_rgba(255, 190, 0, 25 + 90 * min(1, coalesce("score", 0) / 0.5))'
        ),
    )
    sl.setDataDefinedProperty(
        QgsSymbolLayer.PropertyStrokeColor,
        QgsProperty.fromExpression(
            f"CASE WHEN {tie_expr} THEN '#d7191c' ELSE color_rgba(180, 120, 0, 160) END"
        ),
    )
    _rules(
        layer,
        [("view cone of a leading candidate (faded by score)", leading_expr(tie_expr), sym)],
    )
    layer.triggerRepaint()


def style_corners(layer: QgsVectorLayer) -> None:
    """Intersections (large green squares, their streets) apart from kerb corners (orange)."""
    _rules(
        layer,
        [
            ("intersection", "\"kind\" = 'intersection'", _marker("#008837", "Square", 4.5)),
            (
                "kerb corner (clockwise from 0)",
                "\"kind\" = 'corner'",
                _marker("#ff7f00", "Circle", 2.4),
            ),
        ],
    )
    _label(
        layer,
        'CASE WHEN "kind" = \'corner\' THEN \'corner \' || "order" ELSE "streets" END',
        priority=3,
    )
    # the intersection's streets win over every other label: at the zoom the dock sets after a
    # run its long label lost to the kerb corners' and matched points' and was not drawn (seen
    # on the desktop's screenshot; the green square unnamed)
    labeling = layer.labeling()
    pal = QgsPalLayerSettings(labeling.settings())
    props = pal.dataDefinedProperties()
    props.setProperty(
        QgsPalLayerSettings.Priority,
        QgsProperty.fromExpression("CASE WHEN \"kind\" = 'intersection' THEN 10 ELSE 3 END"),
    )
    pal.setDataDefinedProperties(props)
    layer.setLabeling(QgsVectorLayerSimpleLabeling(pal))
    layer.triggerRepaint()


def style_matched(layer: QgsVectorLayer) -> None:
    """Map points the best candidate matched, labelled with the analyst's own words."""
    _rules(
        layer,
        [
            ("matched by the best candidate", '"rank" = 1', _marker("#7b3294", "Diamond", 3.4)),
            ("matched by other candidates", None, _marker("#c2a5cf", "Diamond", 2.0, 0.5)),
        ],
    )
    _label(layer, 'CASE WHEN "rank" = 1 THEN coalesce("what", "label") END', priority=4)
    layer.triggerRepaint()


CAMERA_TIE_EXPR = '"tie"'
"""A list's camera whose best candidate ties with another: the plugin's and the batch
GeoPackage's ``tie``; the service job's GeoPackage calls it ``ambiguous``."""

CAMERA_TIE_WORDS = "camera placed at a tied candidate (≈): another fits nearly as well"
"""The legend's words for a tied camera (the candidates' stars say which)."""


def style_cameras(
    layer: QgsVectorLayer, id_field: str = "camera_id", tie_expr: str = CAMERA_TIE_EXPR
) -> None:
    """A list's cameras: their labels win over the candidates' (highest priority).

    A camera placed at a tied candidate is drawn apart (a hollow triangle, "≈ tie" after its
    status): all cameras were one red triangle labelled "a located", so a camera whose best
    candidate ties with one 61 m away looked as sure as any (session 41 QA, the QGIS desktop).

    Parameters
    ----------
    layer
        The cameras layer.
    id_field
        The camera's id column (the batch GeoPackage's and the job's is ``id``).
    tie_expr
        A QGIS expression true for a tied camera: :data:`CAMERA_TIE_EXPR` (the plugin's and
        the batch GeoPackage's ``tie``); the job result's reads ``ambiguous``. A camera it is
        not true for (false, NULL) is drawn by the "camera placed" rule, an ELSE rule.
    """
    tied = _marker("#ffffff", "Triangle", 4.5)
    tied.symbolLayer(0).setStrokeColor(QColor("#d7191c"))
    tied.symbolLayer(0).setStrokeWidth(0.6)
    _rules(
        layer,
        [
            (CAMERA_TIE_WORDS, tie_expr, tied),
            ("camera placed", None, _marker("#d7191c", "Triangle", 4.5)),
        ],
    )
    _label(
        layer,
        f"\"{id_field}\" || ' ' || \"status\" || CASE WHEN {tie_expr} THEN ' ≈ tie' ELSE '' END",
        priority=10,
        size=10,
    )
    layer.triggerRepaint()


def style_context_streets(layer: QgsVectorLayer) -> None:
    """The map model's streets, grey, as wide as the model thinks they are."""
    from qgis.core import QgsSingleSymbolRenderer, QgsUnitTypes

    sym = QgsSymbol.defaultSymbol(QgsWkbTypes.LineGeometry)
    sym.setColor(QColor(150, 150, 150, 140))
    sym.setWidthUnit(QgsUnitTypes.RenderMetersInMapUnits)
    sym.symbolLayer(0).setDataDefinedProperty(
        QgsSymbolLayer.PropertyStrokeWidth,
        QgsProperty.fromExpression('coalesce("width_m", 8)'),
    )
    layer.setRenderer(QgsSingleSymbolRenderer(sym))
    _label(layer, '"name"', priority=0, size=8)
    layer.triggerRepaint()


def style_context_buildings(layer: QgsVectorLayer) -> None:
    """The map model's buildings, light fill."""
    from qgis.core import QgsSingleSymbolRenderer

    sym = QgsSymbol.defaultSymbol(QgsWkbTypes.PolygonGeometry)
    sym.setColor(QColor(210, 200, 190, 160))
    sym.symbolLayer(0).setStrokeColor(QColor(160, 150, 140))
    layer.setRenderer(QgsSingleSymbolRenderer(sym))
    layer.triggerRepaint()


def _label(layer: QgsVectorLayer, expr: str, priority: int = 5, size: float = 9) -> None:
    pal = QgsPalLayerSettings()
    pal.fieldName = expr
    pal.isExpression = True
    pal.priority = priority
    if layer.geometryType() == QgsWkbTypes.PointGeometry:
        # beside the marker, not on it: around the point at distance 0 put '#1 0.38' under the
        # 7 mm tie star (seen in the canvas screenshot)
        pal.placement = QgsPalLayerSettings.OrderedPositionsAroundPoint
        pal.offsetType = QgsPalLayerSettings.FromSymbolBounds
        pal.dist = 0.8  # mm from the symbol's edge
    fmt = QgsTextFormat()
    fmt.setSize(size)
    buf = QgsTextBufferSettings()
    buf.setEnabled(True)
    buf.setSize(1.0)
    fmt.setBuffer(buf)
    pal.setFormat(fmt)
    layer.setLabeling(QgsVectorLayerSimpleLabeling(pal))
    layer.setLabelsEnabled(True)


STYLES = {
    "candidates": style_candidates,
    "list_candidates": style_list_candidates,
    "view_cones": style_view_cones,
    "matched_corners": style_matched,
    "intersection": style_corners,
    "corners": style_corners,
    "cameras": style_cameras,
    "context_streets": style_context_streets,
    "context_buildings": style_context_buildings,
}


CANDIDATE_MARKER_MM = 7.0
"""The largest candidate marker (the tie star), for the room its labels need."""


def label_room_px(layer: QgsVectorLayer, dpi: float) -> tuple[float, float]:
    """Room (x, y in pixels at ``dpi``) the layer's point labels take beside their markers.

    x: the widest label the layer draws (its label expression evaluated on each feature; NULL
    draws nothing) plus the gap from the marker's edge and half the largest marker; y: a
    label's height plus half the marker. (0, 0) when the layer draws no labels.
    """
    labeling = layer.labeling()
    if not layer.labelsEnabled() or labeling is None or not hasattr(labeling, "settings"):
        return 0.0, 0.0
    settings = labeling.settings()
    fmt = settings.format()
    font = fmt.toQFont()
    font.setPixelSize(max(1, round(fmt.size() * dpi / 72.0)))  # the format's size is in points
    metrics = QFontMetricsF(font)
    ctx = QgsExpressionContext(QgsExpressionContextUtils.globalProjectLayerScopes(layer))
    expr = QgsExpression(settings.fieldName if settings.isExpression else f'"{settings.fieldName}"')
    expr.prepare(ctx)
    widest = 0.0
    for feature in layer.getFeatures():
        ctx.setFeature(feature)
        text = expr.evaluate(ctx)
        if text is not None and text != NULL and str(text):
            widest = max(widest, metrics.boundingRect(str(text)).width())
    if widest == 0.0:
        return 0.0, 0.0
    mm = dpi / 25.4
    marker = 0.5 * CANDIDATE_MARKER_MM * mm
    buffer = 2 * fmt.buffer().size() * mm if fmt.buffer().enabled() else 0.0
    return widest + settings.dist * mm + marker + buffer, metrics.height() + marker + buffer


def extent_with_room(
    extent: QgsRectangle, width_px: int, height_px: int, room_px: tuple[float, float]
) -> QgsRectangle:
    """An extent of the canvas's shape around ``extent`` leaving ``room_px`` (x, y) on each
    side for labels (at most 35 % of the canvas each side, so a narrow canvas still shows the
    points)."""
    room_x = min(room_px[0], 0.35 * width_px)
    room_y = min(room_px[1], 0.35 * height_px)
    per_px = max(
        extent.width() / max(1.0, width_px - 2 * room_x),
        extent.height() / max(1.0, height_px - 2 * room_y),
    )
    if per_px <= 0:
        return QgsRectangle(extent)
    centre = extent.center()
    half_w, half_h = 0.5 * per_px * width_px, 0.5 * per_px * height_px
    return QgsRectangle(
        centre.x() - half_w, centre.y() - half_h, centre.x() + half_w, centre.y() + half_h
    )


def apply_style(layer: QgsVectorLayer, kind: str) -> None:
    """Apply the default style of a camloc output (``candidates``, ``view_cones``...)."""
    fn = STYLES.get(kind)
    if fn is not None and layer.isValid() and layer.isSpatial():
        fn(layer)
    layer.setCustomProperty(KIND_PROPERTY, kind)
    _score_columns(layer)


STYLE_NAME = "camloc"
"""Name of the default style camloc stores in a GeoPackage (its ``layer_styles`` table)."""


def save_style_in_gpkg(layer: QgsVectorLayer, kind: str) -> str:
    """Apply ``kind``'s default style to a GeoPackage layer and store it there as default.

    QGIS then draws the layer styled wherever it is opened (Add Layer, the Browser, another
    project). Main thread only (symbols and fonts). Returns an error message, empty on success.
    """
    if not layer.isValid():
        return "the layer cannot be opened"
    provider = layer.dataProvider()
    if provider is None or not provider.isSaveAndLoadStyleToDatabaseSupported():
        return "its format cannot hold a style"
    apply_style(layer, kind)
    return store_default_style(layer, kind)


def store_default_style(layer: QgsVectorLayer, kind: str) -> str:
    """Store a styled GeoPackage layer's style there as its default; an error, empty if none."""
    provider = layer.dataProvider()
    if provider is None or not provider.isSaveAndLoadStyleToDatabaseSupported():
        return "its format cannot hold a style"
    return str(layer.saveStyleToDatabase(STYLE_NAME, f"camloc {kind}", True, "") or "")


def style_qml(kind: str, desc: dict[str, Any]) -> str:
    """The QML of ``kind``'s default style for a layer of ``desc``'s fields and geometry.

    Made on a memory layer (main thread only: symbols and fonts), so that no layer of the
    GeoPackage is opened for it. Empty when QGIS cannot export it.
    """
    from qgis.PyQt.QtXml import QDomDocument

    geometry = {"Point": "Point", "LineString": "MultiLineString", "Polygon": "MultiPolygon"}
    uri = geometry.get(str(desc.get("geometry")), "None") + f"?crs={WGS84}"
    layer = QgsVectorLayer(uri, kind, "memory")
    if not layer.isValid():
        return ""
    layer.dataProvider().addAttributes(fields_of(desc).toList())
    layer.updateFields()
    apply_style(layer, kind)
    doc = QDomDocument()
    error = layer.exportNamedStyle(doc)
    return "" if error else str(doc.toString())


_STYLE_FIELDS = (
    ("f_table_catalog", "String", 256),
    ("f_table_schema", "String", 256),
    ("f_table_name", "String", 256),
    ("f_geometry_column", "String", 256),
    ("styleName", "String", 30),
    ("styleQML", "String", 0),
    ("styleSLD", "String", 0),
    ("useAsDefault", "Integer", 0),
    ("description", "String", 0),
    ("owner", "String", 30),
    ("ui", "String", 30),
    ("update_time", "DateTime", 0),
)
"""The ``layer_styles`` table as QGIS makes it in a GeoPackage (QgsOgrProviderUtils)."""


def write_gpkg_styles(gpkg: str, styles: dict[str, tuple[str, str]]) -> str:
    """Store default styles in a GeoPackage's ``layer_styles`` table, as QGIS's "Save as
    Default" does, through a GDAL handle of its own that is closed on return.

    ``styles`` maps a table name to ``(kind, QML)``. Each table's earlier camloc style is
    replaced and any other default of it unset. Returns an error message, empty if none.

    Why not ``QgsVectorLayer.saveStyleToDatabase`` on the loaded layers: it opens the
    GeoPackage in update mode through the OGR provider's shared dataset, which stays open
    with the layers; the next run's writer (another handle, in the task's thread) then
    replaced the tables under it, and saving the next style hung QGIS (seen in
    test_dock's background run: "unable to open database file", then no return). Here the
    GeoPackage is written only while none of the run's layers is open.
    """
    from osgeo import gdal, ogr

    if not styles:
        return ""
    try:  # (GDAL raises RuntimeError when a plugin turned its exceptions on)
        ds = ogr.Open(gpkg, 1)
        if ds is None:
            return f"cannot open {gpkg} to store the styles: {gdal.GetLastErrorMsg()}"
        try:
            return _write_styles(ds, gpkg, styles)
        finally:
            ds = None  # closes the file
    except RuntimeError as exc:
        return f"cannot store the styles in {gpkg}: {exc}"


def _write_styles(ds: Any, gpkg: str, styles: dict[str, tuple[str, str]]) -> str:
    import datetime

    from osgeo import gdal, ogr

    table = ds.GetLayerByName("layer_styles")
    if table is None:
        table = ds.CreateLayer("layer_styles", geom_type=ogr.wkbNone)
        if table is None:
            return f"cannot make layer_styles in {gpkg}: {gdal.GetLastErrorMsg()}"
        for name, kind_name, width in _STYLE_FIELDS:
            field = ogr.FieldDefn(name, getattr(ogr, "OFT" + kind_name))
            if width:
                field.SetWidth(width)
            if name == "useAsDefault":
                field.SetSubType(ogr.OFSTBoolean)
            table.CreateField(field)
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y/%m/%d %H:%M:%S")
    ds.StartTransaction()
    for name, (kind, qml) in styles.items():
        src = ds.GetLayerByName(name)
        geom_col = src.GetGeometryColumn() if src is not None else ""
        quoted = name.replace("'", "''")
        table.SetAttributeFilter(f"f_table_name = '{quoted}'")
        old = [(f.GetFID(), f.GetField("styleName")) for f in table]
        table.SetAttributeFilter(None)
        for fid, style_name in old:
            if style_name == STYLE_NAME:
                table.DeleteFeature(fid)
            else:  # another style of the table stays, no longer the default
                other = table.GetFeature(fid)
                other.SetField("useAsDefault", 0)
                table.SetFeature(other)
        f = ogr.Feature(table.GetLayerDefn())
        for key, value in (
            ("f_table_catalog", ""),
            ("f_table_schema", ""),
            ("f_table_name", name),
            ("f_geometry_column", geom_col),
            ("styleName", STYLE_NAME),
            ("styleQML", qml),
            ("styleSLD", ""),
            ("useAsDefault", 1),
            ("description", f"camloc {kind}"),
            ("owner", ""),
            ("ui", ""),
            ("update_time", now),
        ):
            f.SetField(key, value)
        if table.CreateFeature(f) != 0:
            ds.RollbackTransaction()
            return f"cannot store the style of {name}: {gdal.GetLastErrorMsg()}"
    if ds.CommitTransaction() != 0:
        return f"cannot store the styles in {gpkg}: {gdal.GetLastErrorMsg()}"
    return ""


def _score_columns(layer: QgsVectorLayer) -> None:
    """The attribute table shows ``score_text`` next to ``score``, wide enough for 1.2e-15."""
    fields = layer.fields()
    if fields.indexOf("score_text") >= 0:
        layer.setFieldAlias(fields.indexOf("score_text"), "score (readable)")
    if fields.indexOf("score") < 0:
        return
    config = layer.attributeTableConfig()
    config.update(fields)
    columns = config.columns()
    for col in columns:
        if col.name in ("score", "score_text"):
            col.width = 190  # the full double, exponent included (the default cut it)
    config.setColumns(columns)
    layer.setAttributeTableConfig(config)


def order_camloc_layers(group: QgsLayerTreeGroup) -> None:
    """Re-stack the camloc layers of a layer-tree group in :data:`DRAW_ORDER`, in place.

    Only camloc layers move: they are gathered, in that order, where the topmost of them
    was, so a basemap under them stays under them.
    """
    slots: list[int] = []  # where camloc layers are now
    nodes: list[QgsLayerTreeLayer] = []
    for i, node in enumerate(group.children()):
        if isinstance(node, QgsLayerTreeLayer) and node.layer() is not None:
            kind = node.layer().customProperty(KIND_PROPERTY)
            if kind in DRAW_ORDER:
                slots.append(i)
                nodes.append(node)
    wanted = sorted(nodes, key=lambda n: DRAW_ORDER.index(n.layer().customProperty(KIND_PROPERTY)))
    if wanted == nodes:
        return
    # clones go in before the originals leave: a layer whose last node leaves the tree is
    # removed from the project by the tree's registry bridge
    first = slots[0]
    for k, node in enumerate(wanted):
        group.insertChildNode(first + k, node.clone())
    for node in nodes:
        group.removeChildNode(node)


def use_local_crs(project: Any) -> str | None:
    """Give a project of camloc layers alone, drawn in EPSG:4326, the UTM zone of its place.

    The plugin's layers are in EPSG:4326, and QGIS gives an empty project the first layer's
    CRS: a plate carrée that, at Helsinki (60° N), draws the map twice as wide as it is
    tall, so a view cone facing 45° looked to face 63° and round cones were ellipses (session
    42 QA, the QGIS desktop under Xvfb). A project with any other layer, or another CRS, is
    left as it is (the analyst's choice).

    Parameters
    ----------
    project : QgsProject
        The project the layers were added to.

    Returns
    -------
    str or None
        The CRS set (``EPSG:326zz`` north, ``EPSG:327zz`` south), or None where none was.
    """
    crs = project.crs()
    if crs.isValid() and crs.authid() != "EPSG:4326":
        return None
    layers = list(project.mapLayers().values())
    if not layers or any(not lyr.customProperty(KIND_PROPERTY) for lyr in layers):
        return None
    centre = None
    for lyr in layers:
        if lyr.isSpatial() and lyr.crs().authid() == "EPSG:4326" and not lyr.extent().isEmpty():
            centre = lyr.extent().center()
            break
    if centre is None:
        return None
    lon, lat = centre.x(), centre.y()
    if not (-180.0 <= lon <= 180.0 and -80.0 <= lat <= 84.0):  # UTM's range
        return None
    zone = int((lon + 180.0) // 6.0) % 60 + 1
    authid = f"EPSG:{(32600 if lat >= 0 else 32700) + zone}"
    project.setCrs(QgsCoordinateReferenceSystem(authid))
    return authid
