"""Worker GeoJSON -> QGIS features (typed fields, EPSG:4326) and the default layer styles."""

from __future__ import annotations

import json
from typing import Any

from qgis.core import (
    QgsCoordinateReferenceSystem,
    QgsFeature,
    QgsFeatureSink,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsGraduatedSymbolRenderer,
    QgsPalLayerSettings,
    QgsPointXY,
    QgsProperty,
    QgsRendererRange,
    QgsSymbol,
    QgsSymbolLayer,
    QgsTextBufferSettings,
    QgsTextFormat,
    QgsVectorLayer,
    QgsVectorLayerSimpleLabeling,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QVariant
from qgis.PyQt.QtGui import QColor

WGS84 = "EPSG:4326"

_TYPES = {
    "int": QVariant.Int,
    "double": QVariant.Double,
    "string": QVariant.String,
    "bool": QVariant.Bool,
}
_WKB = {
    "Point": QgsWkbTypes.Point,
    "Polygon": QgsWkbTypes.Polygon,
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


def _geometry(geom: dict[str, Any] | None) -> QgsGeometry | None:
    if not geom:
        return None
    if geom["type"] == "Point":
        coords = geom.get("coordinates") or []
        if len(coords) < 2 or coords[0] is None or coords[1] is None:
            return None  # a camera that could not be placed: a row without geometry
        x, y = coords[:2]
        return QgsGeometry.fromPointXY(QgsPointXY(float(x), float(y)))
    if geom["type"] == "Polygon":
        rings = [
            [QgsPointXY(float(p[0]), float(p[1])) for p in ring] for ring in geom["coordinates"]
        ]
        return QgsGeometry.fromPolygonXY(rings)
    raise ValueError(f"unsupported geometry type {geom['type']}")


def features_of(desc: dict[str, Any], fields: QgsFields) -> list[QgsFeature]:
    """The features of a worker layer file, attributes in field order."""
    with open(desc["path"], encoding="utf-8") as fh:
        data = json.load(fh)
    names = [f.name() for f in fields]
    out = []
    for f in data["features"]:
        feat = QgsFeature(fields)
        g = _geometry(f.get("geometry"))
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


# --- default styles -------------------------------------------------------------------------

SCORE_CLASSES = [
    (0.0, 0.05, "#2c7bb6", "< 0.05"),
    (0.05, 0.15, "#abd9e9", "0.05 – 0.15"),
    (0.15, 0.3, "#fdae61", "0.15 – 0.30"),
    (0.3, 1.0001, "#d7191c", "≥ 0.30"),
]
"""Score classes of the candidate style: colour by score (red = most likely)."""

TIE_SHAPE_EXPR = "CASE WHEN \"tie\" THEN 'star' ELSE 'circle' END"
TIE_SIZE_EXPR = 'CASE WHEN "tie" THEN 6.5 ELSE 4 END'
RANK_LABEL_EXPR = (
    "concat('#', \"rank\", "
    "CASE WHEN \"tie\" THEN ' (tie ' || \"ambiguous_with\" || ')' ELSE '' END)"
)


def style_candidates(layer: QgsVectorLayer) -> None:
    """Candidates coloured by score, labelled by rank; ties drawn as stars and labelled."""
    ranges = []
    for lo, hi, colour, label in SCORE_CLASSES:
        sym = QgsSymbol.defaultSymbol(QgsWkbTypes.PointGeometry)
        sym.setColor(QColor(colour))
        sl = sym.symbolLayer(0)
        sl.setDataDefinedProperty(
            QgsSymbolLayer.PropertyName, QgsProperty.fromExpression(TIE_SHAPE_EXPR)
        )
        sl.setDataDefinedProperty(
            QgsSymbolLayer.PropertySize, QgsProperty.fromExpression(TIE_SIZE_EXPR)
        )
        sl.setStrokeColor(QColor("black"))
        ranges.append(QgsRendererRange(lo, hi, sym, label))
    layer.setRenderer(QgsGraduatedSymbolRenderer("score", ranges))
    _label(layer, RANK_LABEL_EXPR)
    layer.triggerRepaint()


def style_view_cones(layer: QgsVectorLayer) -> None:
    """Cones filled by score (the likely ones stand out), ties outlined in red."""
    from qgis.core import QgsSingleSymbolRenderer

    sym = QgsSymbol.defaultSymbol(QgsWkbTypes.PolygonGeometry)
    sym.setColor(QColor(255, 200, 0, 60))
    sl = sym.symbolLayer(0)
    sl.setStrokeColor(QColor(180, 120, 0))
    sl.setDataDefinedProperty(
        QgsSymbolLayer.PropertyFillColor,
        QgsProperty.fromExpression('color_rgba(255, 190, 0, 10 + 150 * coalesce("score", 0))'),
    )
    sl.setDataDefinedProperty(
        QgsSymbolLayer.PropertyStrokeColor,
        QgsProperty.fromExpression(
            "CASE WHEN \"tie\" THEN '#d7191c' "
            'ELSE color_rgba(180, 120, 0, 30 + 200 * coalesce("score", 0)) END'
        ),
    )
    layer.setRenderer(QgsSingleSymbolRenderer(sym))
    layer.triggerRepaint()


def style_points(layer: QgsVectorLayer, colour: str, label_expr: str | None = None) -> None:
    """Small points in one colour, optionally labelled."""
    from qgis.core import QgsSingleSymbolRenderer

    sym = QgsSymbol.defaultSymbol(QgsWkbTypes.PointGeometry)
    sym.setColor(QColor(colour))
    sym.setSize(2.6)
    layer.setRenderer(QgsSingleSymbolRenderer(sym))
    if label_expr:
        _label(layer, label_expr)
    layer.triggerRepaint()


def _label(layer: QgsVectorLayer, expr: str) -> None:
    pal = QgsPalLayerSettings()
    pal.fieldName = expr
    pal.isExpression = True
    fmt = QgsTextFormat()
    fmt.setSize(9)
    buf = QgsTextBufferSettings()
    buf.setEnabled(True)
    buf.setSize(1.0)
    fmt.setBuffer(buf)
    pal.setFormat(fmt)
    layer.setLabeling(QgsVectorLayerSimpleLabeling(pal))
    layer.setLabelsEnabled(True)


STYLES = {
    "candidates": style_candidates,
    "list_candidates": style_candidates,
    "view_cones": style_view_cones,
    "matched_corners": lambda lyr: style_points(
        lyr, "#7b3294", 'CASE WHEN "rank" = 1 THEN \'matched \' || "label" END'
    ),
    "intersection": lambda lyr: style_points(
        lyr,
        "#008837",
        'CASE WHEN "kind" = \'corner\' THEN \'corner \' || "order" ELSE "streets" END',
    ),
    "corners": lambda lyr: style_points(
        lyr,
        "#008837",
        'CASE WHEN "kind" = \'corner\' THEN \'corner \' || "order" ELSE "streets" END',
    ),
    "cameras": lambda lyr: style_points(lyr, "#d7191c", '"camera_id" || \' \' || "status"'),
}


def apply_style(layer: QgsVectorLayer, kind: str) -> None:
    """Apply the default style of a camloc output (``candidates``, ``view_cones``...)."""
    fn = STYLES.get(kind)
    if fn is not None and layer.isValid() and layer.isSpatial():
        fn(layer)
