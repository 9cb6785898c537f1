"""The camloc Processing algorithms: thin wrappers over ``camloc_geo`` run out of process."""

from __future__ import annotations

import json
import os
from typing import Any

from qgis.core import (
    QgsDistanceArea,
    QgsPointXY,
    QgsProcessing,
    QgsProcessingAlgorithm,
    QgsProcessingContext,
    QgsProcessingException,
    QgsProcessingFeedback,
    QgsProcessingLayerPostProcessorInterface,
    QgsProcessingOutputLayerDefinition,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterDefinition,
    QgsProcessingParameterExtent,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFile,
    QgsProcessingParameterNumber,
    QgsProcessingParameterPoint,
    QgsProcessingParameterString,
    QgsProperty,
    QgsVectorLayer,
)
from qgis.PyQt import sip
from qgis.PyQt.QtCore import QTimer

from .layers import (
    TIE_WORDS,
    apply_style,
    fields_of,
    order_camloc_layers,
    save_style_in_gpkg,
    use_local_crs,
    wgs84,
    wkb_of,
    write_to_sink,
)
from .runner import WorkerCanceledError, WorkerError, run_worker

OSM_FILTER = "OSM extracts (*.osm *.pbf *.osm.pbf *.bz2 *.gz);;All files (*.*)"
SCENE_FILTER = "camloc scenes (*.json);;All files (*.*)"

_post_processors: dict[str, QgsProcessingLayerPostProcessorInterface] = {}


class _Styler(QgsProcessingLayerPostProcessorInterface):
    """Applies a camloc default style to an output layer loaded on completion."""

    def __init__(self, kind: str) -> None:
        super().__init__()
        self.kind = kind
        self.title = ""
        self.rename = True

    def postProcessLayer(self, layer, context, feedback):
        apply_style(layer, self.kind)
        # which camera (scene) or list the layer is of; not over a model's output, which keeps
        # the name its author gave it
        if self.title and self.rename:
            layer.setName(self.title)
        # Processing adds each output on top as it loads it: re-stack the camloc layers so
        # candidates are drawn above cones whatever the loading order
        project = context.project()
        if project is not None:
            node = project.layerTreeRoot().findLayer(layer.id())
            if node is not None and node.parent() is not None:
                order_camloc_layers(node.parent())
            # a project of camloc layers alone: its place's UTM zone, not a stretched 4326;
            # again once the event loop runs (the QGIS desktop gives an empty project its
            # first layer's CRS after the layers are loaded, undoing it)
            use_local_crs(project)
            QTimer.singleShot(0, lambda: use_local_crs(project))


def _gpkg_path(dest: str) -> str | None:
    """The GeoPackage file of an output destination (``x.gpkg|layername=t``), else None."""
    path = str(dest).split("|")[0]
    return path if path.lower().endswith(".gpkg") and os.path.isfile(path) else None


def _dest_text(value: Any, context: QgsProcessingContext) -> str:
    """An output parameter's destination as text (a path or a URI), without side effects."""
    if isinstance(value, QgsProcessingOutputLayerDefinition):
        value = value.sink
    if isinstance(value, QgsProperty):
        return str(value.valueAsString(context.expressionContext())[0] or "")
    return str(value or "")


def _scene_id(candidates: dict[str, Any], scene_path: str) -> str:
    """The scene's id as its candidates carry it, else the scene file's name."""
    try:
        data = candidates.get("data")
        if data is None:
            with open(candidates["path"], encoding="utf-8") as fh:
                data = json.load(fh)
        for feat in data.get("features") or []:
            sid = (feat.get("properties") or {}).get("scene")
            if sid:
                return str(sid)
    except (OSError, ValueError, KeyError, AttributeError):
        pass
    return os.path.basename(scene_path)


CANCELED_TEXT = "camloc: canceled; the worker was stopped, no output was written"
"""What a canceled run says in the Processing log (before QGIS's "Execution failed")."""

LABEL_MAX_CHARS = 48
"""A parameter's label fits the Processing dialog as QGIS first opens it (688 px): longer ones
widened the form past it, hiding the file pickers' browse buttons; details go in the help."""


def _helped(param: Any, text: str) -> Any:
    """``param`` with ``text`` as its help (a tooltip in the dialog; QGIS 3.16+)."""
    if hasattr(param, "setHelp"):
        param.setHelp(text)
    return param


def _option_bool(name: str, label: str) -> QgsProcessingParameterBoolean:
    """A yes/no option, default no, that a model may leave unset.

    QGIS 3.22's model validation (``QgsProcessingModelAlgorithm.validateChildAlgorithm``) calls
    every parameter of a child algorithm that is not optional and has no value source in the
    model "mandatory", whatever its default: a model built in Python or saved before an option
    existed was refused ("Parameter NETWORK is mandatory"), native:buffer's DISSOLVE likewise.
    Optional, it reads as its default (no) when unset, in a model, ``qgis_process`` and Python.
    """
    return QgsProcessingParameterBoolean(name, label, defaultValue=False, optional=True)


# QgsProcessingParameterNumber's minimum/maximum when none was given (-DBL_MAX, DBL_MAX)
_UNBOUNDED = 1e300


def _number_range_text(param: QgsProcessingParameterNumber) -> str:
    """The values ``param`` takes, in words: 'a whole number of at least 1', 'at least 10'."""
    low, high = param.minimum(), param.maximum()
    whole = param.dataType() == QgsProcessingParameterNumber.Integer
    kind = "a whole number" if whole else "a number"
    if low > -_UNBOUNDED and high < _UNBOUNDED:
        return f"{kind} from {low:g} to {high:g}"
    if low > -_UNBOUNDED:
        return f"{kind} of at least {low:g}"
    if high < _UNBOUNDED:
        return f"{kind} of at most {high:g}"
    return kind


def number_out_of_range(param: QgsProcessingParameterNumber, value: Any) -> str | None:
    """Why ``value`` is refused for ``param``, naming it and its range; None when it is taken.

    QGIS's own check says only "Incorrect parameter value for MAX_CANDIDATES" (qgis_process,
    ``processing.run``): this names the parameter, its label, the range and the value given.
    Unset values and model expressions (``QgsProperty``) are left to QGIS.
    """
    if value is None or value == "" or isinstance(value, QgsProperty):
        return None
    rng = _number_range_text(param)
    where = f"camloc: {param.name()} ({param.description()}) must be {rng}"
    try:
        number = float(value)
    except (TypeError, ValueError):
        return f"{where}; got {value!r}"
    whole = param.dataType() == QgsProcessingParameterNumber.Integer
    if (
        number != number  # NaN
        or number < param.minimum()
        or number > param.maximum()
        or (whole and not number.is_integer())
    ):
        return f"{where}; got {value}"
    return None


def file_parameter_problem(param: QgsProcessingParameterFile, value: Any) -> str | None:
    """Why a file parameter's value is refused, naming the parameter; None when it is taken.

    A folder given where one file is wanted (``--OSM=data/osm`` to ``camloc:locate`` or
    ``camloc:corners``, as ``camloc locate --osm FOLDER`` and ``camloc:geocodelist`` take it)
    was QGIS's "Incorrect parameter value for OSM", with no word of what is wrong.
    """
    if value is None or value == "" or isinstance(value, QgsProperty):
        return None
    if param.behavior() != QgsProcessingParameterFile.File or not isinstance(value, str):
        return None
    if not os.path.isdir(value):
        return None
    where = f"camloc: {param.name()} ({param.description()})"
    if param.name() == "OSM":
        return (
            f"{where} is a folder, {value}: this algorithm takes one extract file (.osm, "
            ".osm.pbf, .osm.bz2, .osm.gz): give the extract covering the place (camloc:"
            "geocodelist and camloc batch take a folder)"
        )
    return f"{where} is a folder, {value}: give a file"


def sink_folder_problem(param: QgsProcessingParameterFeatureSink, value: Any) -> str | None:
    """Why an output's destination cannot be written, before any work; None when it can.

    An output in a folder that does not exist (``--CANDIDATES=/nonexistent/c.gpkg``) was
    refused by QGIS only after the whole computation ("Could not create layer ...:
    sqlite3_open(...) failed: unable to open database file").
    """
    if isinstance(value, QgsProcessingOutputLayerDefinition):
        value = value.sink.staticValue() if hasattr(value.sink, "staticValue") else None
    if not isinstance(value, str) or not value or value.startswith(("memory:", "ogr:")):
        return None
    if value.startswith(("postgres:", "spatialite:", "TEMPORARY_OUTPUT", "postgis:")):
        return None
    path = value.split("|", 1)[0]
    folder = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(folder):
        return None
    return (
        f"camloc: {param.name()} ({param.description()}): the folder {folder} does not "
        "exist: make it first or write the output elsewhere"
    )


class _CamlocAlgorithm(QgsProcessingAlgorithm):
    """Shared parts: group, help, the worker call and the typed sinks."""

    _name = ""
    _display = ""
    _help = ""

    def name(self) -> str:
        return self._name

    def displayName(self) -> str:
        return self._display

    def group(self) -> str:
        return "Camera location"

    def groupId(self) -> str:
        return "camloc"

    def shortHelpString(self) -> str:
        return self._help

    def createInstance(self):
        return type(self)()

    def checkParameterValues(
        self, parameters: dict[str, Any], context: QgsProcessingContext
    ) -> tuple[bool, str]:
        """Refuse a number out of its range with a message naming it and the range, a folder
        given for a file and an output in a folder that does not exist, naming them."""
        for param in self.parameterDefinitions():
            value = parameters.get(param.name())
            message = None
            if isinstance(param, QgsProcessingParameterNumber):
                message = number_out_of_range(param, value)
            elif isinstance(param, QgsProcessingParameterFile):
                message = file_parameter_problem(param, value)
            elif isinstance(param, QgsProcessingParameterFeatureSink):
                message = sink_folder_problem(param, value)
            if message:
                return False, message
        return super().checkParameterValues(parameters, context)

    def _add_map_params(self, folder: bool = False) -> None:
        if folder:
            # Processing's File parameter refuses folders (QGIS 3.22) and its Folder parameter
            # takes files: OSM takes both, as camloc batch --osm does; OSM_FILE is the file
            # picker for the dialog
            self.addParameter(
                _helped(
                    QgsProcessingParameterFile(
                        "OSM",
                        "OSM extracts: a folder, or one extract",
                        behavior=QgsProcessingParameterFile.Folder,
                        optional=True,
                    ),
                    "Each camera uses the extract covering it, as camloc batch --osm does; "
                    "empty: Overpass, if allowed below",
                )
            )
            self.addParameter(
                _helped(
                    QgsProcessingParameterFile(
                        "OSM_FILE",
                        "Or one OSM extract file",
                        behavior=QgsProcessingParameterFile.File,
                        fileFilter=OSM_FILTER,
                        optional=True,
                    ),
                    "The same as OSM with a file picker (.osm, .osm.pbf, .osm.bz2, .osm.gz); "
                    "give OSM or this, not both",
                )
            )
        else:
            self.addParameter(
                _helped(
                    QgsProcessingParameterFile(
                        "OSM",
                        "OSM extract (empty: Overpass if allowed)",
                        behavior=QgsProcessingParameterFile.File,
                        fileFilter=OSM_FILTER,
                        optional=True,
                    ),
                    ".osm, .osm.pbf, .osm.bz2 or .osm.gz; empty: Overpass, if allowed below",
                )
            )
        self.addParameter(
            _helped(
                _option_bool("NETWORK", "Allow fetching OSM data from Overpass"),
                "Download the map from the Overpass API when no extract covers the place; "
                "unticked or unset (in a model): no network",
            )
        )

    def _run(self, job: dict[str, Any], feedback: QgsProcessingFeedback) -> dict[str, Any] | None:
        def progress(pct: float, message: str) -> None:
            feedback.setProgress(pct)
            if message:
                feedback.setProgressText(message)

        try:
            res = run_worker(
                job, progress=progress, canceled=feedback.isCanceled, log=feedback.pushDebugInfo
            )
        except WorkerCanceledError:
            # the log said only "canceled", then QGIS's "Execution failed"
            feedback.reportError(CANCELED_TEXT, fatalError=False)
            return None
        except WorkerError as exc:
            raise QgsProcessingException(f"camloc: {exc}") from None
        for w in res.get("warnings") or []:
            feedback.pushWarning(str(w)) if hasattr(feedback, "pushWarning") else feedback.pushInfo(
                f"Warning: {w}"
            )
        return res

    def _sink(
        self,
        parameters: dict[str, Any],
        name: str,
        desc: dict[str, Any],
        kind: str,
        context: QgsProcessingContext,
        results: dict[str, Any],
    ) -> int:
        fields = fields_of(desc)
        parameters = self._own_gpkg_tables(parameters, context)
        sink, dest = self.parameterAsSink(parameters, name, context, fields, wkb_of(desc), wgs84())
        if sink is None:
            # optional output skipped: None from the dialog and qgis_process; an output
            # definition with an empty destination from the batch dialog's empty cell (each
            # such row failed: "Could not create destination layer for VIEW_CONES")
            param = self.parameterDefinition(name)
            optional = param is not None and bool(
                param.flags() & QgsProcessingParameterDefinition.FlagOptional
            )
            if parameters.get(name) is None or (
                optional and not _dest_text(parameters.get(name), context)
            ):
                return 0
            raise QgsProcessingException(self.invalidSinkError(parameters, name))
        n = write_to_sink(sink, desc, fields)
        del sink
        if context.willLoadLayerOnCompletion(dest):
            # QGIS deletes a post-processor once it has run: a second run into the same
            # output (Run again in the dialog, the file kept) reused the deleted one and
            # failed with "wrapped C/C++ object of type _Styler has been deleted"
            styler = _post_processors.get(dest)
            if styler is None or sip.isdeleted(styler):
                styler = _post_processors[dest] = _Styler(kind)
            styler.kind = kind
            of = self.__dict__.get("_layers_of", "")
            param = self.parameterDefinition(name)
            styler.title = f"{param.description()} ({of})" if of and param is not None else ""
            details = context.layerToLoadOnCompletionDetails(dest)
            # a direct run (Toolbox, batch, runAndLoadResults) names the output after the
            # parameter, a model after its output ('candidates'); QGIS then uses the file's
            # name instead when "prefer output filename" is set (its default on the desktop)
            styler.rename = param is not None and details.name in ("", param.description())
            details.setPostProcessor(styler)
        results[name] = dest
        if kind and _gpkg_path(dest):
            self.__dict__.setdefault("_style_later", []).append((dest, kind))
        return n

    def _own_gpkg_tables(
        self, parameters: dict[str, Any], context: QgsProcessingContext
    ) -> dict[str, Any]:
        """``parameters`` where outputs naming one plain ``.gpkg`` file each get a table.

        QGIS writes a plain ``out.gpkg`` destination as a new file: two outputs given the same
        file (``--CANDIDATES=out.gpkg --VIEW_CONES=out.gpkg``) left only the last one, the
        candidates silently lost. Each such output now goes to its own table, named after
        the output in lower case (``candidates``, ``view_cones``).
        """
        paths: dict[str, list[str]] = {}
        for param in self.destinationParameterDefinitions():
            value = parameters.get(param.name())
            if not isinstance(param, QgsProcessingParameterFeatureSink) or value in (None, ""):
                continue
            # not parameterAsOutputLayer: with a destination project it registers the output
            # to load on completion afresh, dropping the post-processor (the style) an earlier
            # sink of this run had set: of four outputs into named .gpkg/.shp/.geojson files,
            # only the last came up styled in runAndLoadResults and the Toolbox dialog
            dest = _dest_text(value, context)
            if dest and dest.lower().endswith(".gpkg") and "'" not in dest:
                paths.setdefault(os.path.abspath(dest), []).append(param.name())
        shared = {n: p for p, names in paths.items() if len(names) > 1 for n in names}
        if not shared:
            return parameters
        out = dict(parameters)
        for name, path in shared.items():
            uri = f"ogr:dbname='{path}' table=\"{name.lower()}\" (geom)"
            value = parameters[name]
            if isinstance(value, QgsProcessingOutputLayerDefinition):
                new = QgsProcessingOutputLayerDefinition(
                    QgsProperty.fromValue(uri), value.destinationProject
                )
                new.destinationName = value.destinationName
                new.createOptions = value.createOptions
                out[name] = new
            else:
                out[name] = uri
        return out

    def postProcessAlgorithm(
        self, context: QgsProcessingContext, feedback: QgsProcessingFeedback
    ) -> dict[str, Any]:
        """Store each GeoPackage output's default style in the GeoPackage itself.

        The styles were applied only to layers QGIS loaded at the end of a run: a GeoPackage
        written by ``qgis_process`` or opened later (Layer › Add Layer, the Browser) showed
        plain dots, no labels, a cone for every candidate. Runs on the main thread.
        """
        for dest, kind in self.__dict__.pop("_style_later", []):
            layer = QgsVectorLayer(dest, kind, "ogr")
            error = save_style_in_gpkg(layer, kind)
            if error:
                feedback.pushInfo(f"camloc: the style of {dest} was not saved: {error}")
        return {}

    def _osm(self, parameters: dict[str, Any], context: QgsProcessingContext) -> str | None:
        path = self.parameterAsFile(parameters, "OSM", context)
        other = (
            self.parameterAsFile(parameters, "OSM_FILE", context)
            if self.parameterDefinition("OSM_FILE") is not None
            else ""
        )
        if path and other:
            raise QgsProcessingException("camloc: give OSM or OSM_FILE, not both")
        return path or other or None


class LocateAlgorithm(_CamlocAlgorithm):
    """``camloc:locate``: candidate camera positions from a scene file and an OSM extract."""

    _name = "locate"
    _display = "Locate camera from a scene"
    _help = (
        "Candidate absolute positions of the camera that took a snapshot, from its camloc scene "
        "file (car annotations, intersection corners, landmarks) and OpenStreetMap. Outputs: "
        "candidates (best first; rank, score, tie, height, heading...), their view cones (drawn "
        "for the leading candidates only), the map points each candidate matched, the "
        "intersection used and, on request, the map model's streets and buildings. Layers are "
        "in EPSG:4326. A star marks a " + TIE_WORDS + ": the library's rule "
        "(camloc_geo.results), carried in each candidate's ambiguous_with."
    )

    def initAlgorithm(self, config=None):
        self.addParameter(
            QgsProcessingParameterFile(
                "SCENE", "Scene file (camloc-scene/1 JSON)", fileFilter=SCENE_FILTER
            )
        )
        self._add_map_params()
        self.addParameter(
            _helped(
                QgsProcessingParameterNumber(
                    "MAX_CANDIDATES",
                    "At most this many candidates",
                    type=QgsProcessingParameterNumber.Integer,
                    minValue=1,
                    optional=True,
                ),
                "Empty: every candidate found (at most 32), best first",
            )
        )
        self.addParameter(
            _helped(
                QgsProcessingParameterNumber(
                    "RADIUS_M",
                    "Map radius around the scene (m)",
                    type=QgsProcessingParameterNumber.Double,
                    minValue=10,
                    optional=True,
                ),
                "Empty: the scene's prior radius + 200 m",
            )
        )
        self.addParameter(
            _helped(
                _option_bool("CONTEXT", "Also output the map model"),
                "The streets and buildings locate matched the scene against "
                "(CONTEXT_STREETS, CONTEXT_BUILDINGS); unticked or unset (in a model): not written",
            )
        )
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                "CANDIDATES", "Camera candidates", QgsProcessing.TypeVectorPoint
            )
        )
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                "VIEW_CONES", "View cones", QgsProcessing.TypeVectorPolygon, optional=True
            )
        )
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                "MATCHED_CORNERS",
                "Matched map corners",
                QgsProcessing.TypeVectorPoint,
                optional=True,
            )
        )
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                "INTERSECTION",
                "Intersection and its corners",
                QgsProcessing.TypeVectorPoint,
                optional=True,
            )
        )
        for name, title, typ in (
            ("CONTEXT_STREETS", "Map model: streets", QgsProcessing.TypeVectorLine),
            ("CONTEXT_BUILDINGS", "Map model: buildings", QgsProcessing.TypeVectorPolygon),
        ):
            self.addParameter(
                QgsProcessingParameterFeatureSink(
                    name, title, typ, optional=True, createByDefault=False
                )
            )

    def processAlgorithm(self, parameters, context, feedback):
        scene = self.parameterAsFile(parameters, "SCENE", context)
        if not scene:
            raise QgsProcessingException("camloc: no scene file given")
        job: dict[str, Any] = {
            "task": "locate",
            "scene": scene,
            "osm": self._osm(parameters, context),
            "network": self.parameterAsBool(parameters, "NETWORK", context),
            "context": self.parameterAsBool(parameters, "CONTEXT", context),
        }
        if parameters.get("MAX_CANDIDATES") not in (None, ""):
            job["max_candidates"] = self.parameterAsInt(parameters, "MAX_CANDIDATES", context)
        if parameters.get("RADIUS_M") not in (None, ""):
            job["radius_m"] = self.parameterAsDouble(parameters, "RADIUS_M", context)
        res = self._run(job, feedback)
        if res is None:
            return {}
        layers = res["layers"]
        # the loaded layers say which camera: 'Camera candidates (baltimore-eastern-broadway)'
        self._layers_of = _scene_id(layers["candidates"], scene)
        results: dict[str, Any] = {}
        n = self._sink(
            parameters, "CANDIDATES", layers["candidates"], "candidates", context, results
        )
        self._sink(parameters, "VIEW_CONES", layers["view_cones"], "view_cones", context, results)
        self._sink(
            parameters,
            "MATCHED_CORNERS",
            layers["matched_corners"],
            "matched_corners",
            context,
            results,
        )
        self._sink(
            parameters, "INTERSECTION", layers["intersection"], "intersection", context, results
        )
        for name, kind in (
            ("CONTEXT_STREETS", "context_streets"),
            ("CONTEXT_BUILDINGS", "context_buildings"),
        ):
            if kind in layers:
                self._sink(parameters, name, layers[kind], kind, context, results)
        info = res.get("info") or {}
        feedback.pushInfo(f"{n} candidate(s)")
        if not n and info.get("reason"):
            feedback.reportError(f"camloc: no candidates: {info['reason']}", fatalError=False)
        results["N_CANDIDATES"] = n
        return results


class CornersAlgorithm(_CamlocAlgorithm):
    """``camloc:corners``: intersections and kerb corners around a point or in an extent."""

    _name = "corners"
    _display = "Intersections and kerb corners"
    _help = (
        "Road intersections with their kerb corners (clockwise order from above, starting at 0) "
        "from OpenStreetMap, around a point (with a radius) or in an extent (for example the "
        "map canvas extent). Give STREETS ('A & B') to keep only that intersection."
    )

    def initAlgorithm(self, config=None):
        self.addParameter(
            _helped(
                QgsProcessingParameterPoint("POINT", "Around this point", optional=True),
                "Click on the canvas (any project CRS); with RADIUS_M. Empty: give EXTENT",
            )
        )
        self.addParameter(
            _helped(
                QgsProcessingParameterExtent("EXTENT", "Or in this extent (canvas)", optional=True),
                "Used when POINT is empty; at most 10 km across. The extent of one point "
                "(a layer of one feature) is that point with RADIUS_M",
            )
        )
        self.addParameter(
            _helped(
                QgsProcessingParameterNumber(
                    "RADIUS_M",
                    "Radius around the point (m)",
                    type=QgsProcessingParameterNumber.Double,
                    defaultValue=150.0,
                    minValue=1.0,
                    optional=True,  # unset in a model: 150 m (see _option_bool)
                ),
                "Used with POINT, or an extent of one point; empty: 150 m",
            )
        )
        self.addParameter(
            _helped(
                QgsProcessingParameterString(
                    "STREETS", "Only the intersection of 'A & B'", optional=True
                ),
                "Two street names joined by '&' (any script: 中山北路二段 & 南京東路一段); "
                "empty: every intersection found",
            )
        )
        self._add_map_params()
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                "CORNERS", "Intersections and corners", QgsProcessing.TypeVectorPoint
            )
        )

    def processAlgorithm(self, parameters, context, feedback):
        crs = wgs84()
        if parameters.get("POINT") not in (None, ""):
            pt = self.parameterAsPoint(parameters, "POINT", context, crs)
            radius = self.parameterAsDouble(parameters, "RADIUS_M", context)
        elif parameters.get("EXTENT") not in (None, ""):
            ext = self.parameterAsExtent(parameters, "EXTENT", context, crs)
            if ext.isNull():
                raise QgsProcessingException(
                    "camloc: the extent is empty (a layer without features, or none with a "
                    "geometry): give a layer with features, an extent, or a point"
                )
            pt = ext.center()
            da = QgsDistanceArea()
            da.setEllipsoid("WGS84")
            radius = 0.5 * da.measureLine(
                QgsPointXY(ext.xMinimum(), ext.yMinimum()),
                QgsPointXY(ext.xMaximum(), ext.yMaximum()),
            )
            if ext.isEmpty():
                # one point (a layer of one feature: the best candidate kept by a filter, a
                # one-camera list) or points in a line: that point with RADIUS_M (it was
                # refused, "the extent is empty"); a wider extent keeps its own size
                radius = max(radius, self.parameterAsDouble(parameters, "RADIUS_M", context))
            if radius > 5000:
                raise QgsProcessingException(
                    f"camloc: the extent is {2 * radius / 1000:.1f} km across; zoom in "
                    "(at most 10 km) or give a point and a radius"
                )
        else:
            raise QgsProcessingException("camloc: give a point (POINT) or an extent (EXTENT)")
        job = {
            "task": "corners",
            "lat": pt.y(),
            "lon": pt.x(),
            "radius_m": radius,
            "streets": self.parameterAsString(parameters, "STREETS", context) or None,
            "osm": self._osm(parameters, context),
            "network": self.parameterAsBool(parameters, "NETWORK", context),
        }
        res = self._run(job, feedback)
        if res is None:
            return {}
        results: dict[str, Any] = {}
        n = self._sink(parameters, "CORNERS", res["layers"]["corners"], "corners", context, results)
        feedback.pushInfo(f"{n} feature(s)")
        return results


class GeocodeListAlgorithm(_CamlocAlgorithm):
    """``camloc:geocodelist``: one best location per camera of a webcam list."""

    _name = "geocodelist"
    _display = "Geocode a webcam list"
    _help = (
        "A list of cameras (CSV or GeoJSON: id, title, lat/lon, radius_m, streets, scene) in; "
        "one point per camera with the status and reason of camloc batch (located, title_only, "
        "ambiguous, street_only, not_found, no_candidates, no_evidence, no_map, scene_error, "
        "map_error, failed), and every candidate with its camera id. The list runs through "
        "camloc_geo.batch, the engine of camloc batch, so the answers are the same. OSM may be "
        "one extract or a folder of extracts (as camloc batch --osm takes)."
    )

    def initAlgorithm(self, config=None):
        self.addParameter(
            QgsProcessingParameterFile(
                "LIST",
                "Camera list (CSV or GeoJSON)",
                fileFilter="Camera lists (*.csv *.geojson *.json);;All files (*.*)",
            )
        )
        self._add_map_params(folder=True)
        self.addParameter(
            QgsProcessingParameterFeatureSink("CAMERAS", "Cameras", QgsProcessing.TypeVectorPoint)
        )
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                "CANDIDATES", "All candidates", QgsProcessing.TypeVectorPoint, optional=True
            )
        )

    def processAlgorithm(self, parameters, context, feedback):
        job = {
            "task": "geocodelist",
            "list": self.parameterAsFile(parameters, "LIST", context),
            "osm": self._osm(parameters, context),
            "network": self.parameterAsBool(parameters, "NETWORK", context),
        }
        res = self._run(job, feedback)
        if res is None:
            return {}
        layers = res["layers"]
        self._layers_of = os.path.basename(job["list"] or "")  # 'Cameras (cams.csv)'
        results: dict[str, Any] = {}
        n = self._sink(parameters, "CAMERAS", layers["cameras"], "cameras", context, results)
        self._sink(
            parameters, "CANDIDATES", layers["candidates"], "list_candidates", context, results
        )
        feedback.pushInfo(f"{n} camera(s), engine {res.get('info', {}).get('engine')}")
        return results


class MeasureAlgorithm(_CamlocAlgorithm):
    """``camloc:measure``: ground distances and heights with a calibrated camera."""

    _name = "measure"
    _display = "Measure distances and heights in a snapshot"
    _help = (
        "Ground distances and heights from pixel pairs of a calibrated scene. PAIRS is JSON: "
        '[{"kind": "distance"|"height", "a": [x, y], "b": [x, y]}, ...].'
    )

    def initAlgorithm(self, config=None):
        self.addParameter(
            QgsProcessingParameterFile("SCENE", "Scene file", fileFilter=SCENE_FILTER)
        )
        self.addParameter(
            _helped(
                QgsProcessingParameterString("PAIRS", "Pixel pairs (JSON)", multiLine=True),
                'A JSON list: [{"kind": "distance" or "height", "a": [x, y], "b": [x, y]}, ...] '
                "in the snapshot's pixels",
            )
        )
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                "MEASUREMENTS", "Measurements", QgsProcessing.TypeVector
            )
        )

    def processAlgorithm(self, parameters, context, feedback):
        try:
            pairs = json.loads(self.parameterAsString(parameters, "PAIRS", context) or "[]")
        except ValueError as exc:
            raise QgsProcessingException(f"camloc: PAIRS is not valid JSON: {exc}") from None
        job = {
            "task": "measure",
            "scene": self.parameterAsFile(parameters, "SCENE", context),
            "pairs": pairs,
        }
        res = self._run(job, feedback)
        if res is None:
            return {}
        results: dict[str, Any] = {}
        self._sink(parameters, "MEASUREMENTS", res["layers"]["measurements"], "", context, results)
        return results
