"""The library entry points every front end calls (CLI, QGIS plugin, service, batch).

Each takes a scene as a path, a dict or a :class:`~camloc_geo.scene.Scene`, plus keyword-only
options, and returns typed results. Domain decisions (where to anchor the map, how far to
load it, whether a map is needed, when the network may be used) live here and nowhere in the
front ends.

Map sources (the same for every front end): ``map_source`` is an extract, a folder of
extracts, a :class:`~camloc_geo.osm.MapCatalogue` or an already loaded map. A folder or a
catalogue chooses the map for a point by the catalogue's one rule (the smallest extract
covering it, loaded whole or by cells; Overpass cells when the catalogue allows the network).

Network policy (one rule for every command): an extract or folder given as ``map_source`` is
always used and the network never is; without one, Overpass is queried through osmnx (cached)
when ``network`` is true, and a scene that needs a map fails with a :class:`MapDataError`
naming ``--osm EXTRACT`` when it is false.

Coordinates: scalars are keyword-only ``lat=`` / ``lon=`` (degrees WGS 84).
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, SupportsFloat, SupportsIndex, Union

from camloc_geo._errors import InputError, MapDataError, SceneError

if TYPE_CHECKING:
    from camloc_geo.absolute import LocateResult, LocateSettings
    from camloc_geo.autovp import AutoVPResult
    from camloc_geo.cameras import CameraResult, CameraRow
    from camloc_geo.osm import MapCatalogue, MapData
    from camloc_geo.relative import CalibrationResult, CalibrationSettings
    from camloc_geo.scene import Scene
    from camloc_geo.sensors.guide import GuideResult, GuideSettings
    from camloc_geo.sensors.radar import RadarResult

__all__ = [
    "DEFAULT_MIN_RADIUS_M",
    "MAX_MAP_RADIUS_M",
    "LocateOutput",
    "MapSource",
    "SceneLike",
    "calibrate_scene",
    "corners_near",
    "corners_within",
    "crowd_scene",
    "guide_scene",
    "locate_camera",
    "locate_scene",
    "map_around",
    "map_for_scene",
    "radar_scene",
    "read_camera_list",
    "scene_from",
    "streets_near",
    "streets_within",
    "vanishing_points",
]

SceneLike = Union["Scene", Mapping[str, Any], str, "os.PathLike[str]"]
"""A scene: a model, a ``camloc-scene/1`` dict, or the path of a scene file."""

MapSource = Union[str, "os.PathLike[str]", "MapData", "MapCatalogue", None]
"""A map: an extract or folder path, a :class:`~camloc_geo.osm.MapCatalogue`, an already
loaded :class:`~camloc_geo.osm.MapData`, or None."""

DEFAULT_MIN_RADIUS_M = 300.0
"""The smallest map radius loaded around a scene (metres)."""

_PRIOR_MARGIN_M = 200.0

MAX_MAP_RADIUS_M = 50_000.0
"""The largest map radius a caller may give (metres): the largest prior radius a scene may
have. Beyond it the map's local frame no longer holds (a radius of 30 000 km loaded the
extract and said it "holds buildings but no streets")."""


def _degrees(value: object, name: str) -> float:
    """``value`` as a float of degrees, or a :class:`MapDataError` naming ``name``."""
    if isinstance(value, bool):
        raise MapDataError(f"{name} must be a number of degrees, got {value!r}")
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise MapDataError(f"{name} must be a number of degrees, got {value!r}") from None


def _metres(value: object, name: str) -> float:
    """``value`` as a positive finite float of metres, or a :class:`MapDataError`."""
    import math

    try:
        out = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        out = math.nan
    if isinstance(value, bool) or not (math.isfinite(out) and out > 0):
        raise MapDataError(f"{name} must be a positive number of metres, got {value!r}")
    return out


def check_map_radius_m(value: object, name: str = "radius_m") -> float:
    """``value`` as a map radius in metres: positive, finite, at most :data:`MAX_MAP_RADIUS_M`.

    Parameters
    ----------
    value
        The radius given.
    name
        How the caller calls it in the message (``radius_m``, ``--radius-m``).

    Returns
    -------
    float
        The radius, metres.

    Raises
    ------
    MapDataError
        Not a positive finite number, or over the bound (the message names the bound).
    """
    radius_m = _metres(value, name)
    if radius_m > MAX_MAP_RADIUS_M:
        raise MapDataError(
            f"{name} {radius_m:g} m is over the largest map radius, {MAX_MAP_RADIUS_M:g} m "
            f"({MAX_MAP_RADIUS_M / 1000:g} km): give a point nearer the camera"
        )
    return radius_m


def _whole(value: object, name: str, error: type[InputError] = InputError) -> int:
    """``value`` as an int (an int, a numpy integer), or ``error`` naming ``name``."""
    import operator

    if isinstance(value, bool):
        raise error(f"{name} must be a whole number, got {value!r}")
    try:
        return operator.index(value)  # type: ignore[arg-type]
    except TypeError:
        raise error(f"{name} must be a whole number, got {value!r}") from None


def scene_from(scene: SceneLike) -> Scene:
    """A validated :class:`Scene` from a model, a dict or a path.

    Parameters
    ----------
    scene
        A :class:`~camloc_geo.scene.Scene` (returned as is), a ``camloc-scene/1`` dict (or
        any mapping), or the path (``str`` or ``os.PathLike``) of a scene file.

    Returns
    -------
    Scene
        The validated scene.

    Raises
    ------
    SceneError
        The scene does not validate, the file is missing or unreadable, or ``scene`` is of
        another type; the message names the field.
    """
    from camloc_geo.scene import Scene, load_scene, parse_scene

    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, Mapping):  # a dict, or any mapping (MappingProxyType, a frozen dict)
        return parse_scene(dict(scene))
    if isinstance(scene, (str, os.PathLike)):
        return load_scene(Path(scene))
    raise SceneError(f"a scene must be a path, a dict or a Scene, not {type(scene).__name__}")


def calibrate_scene(
    scene: SceneLike,
    *,
    settings: CalibrationSettings | None = None,
    joint_fit: bool = True,
    principal_point: str = "auto",
    video: str | os.PathLike[str] | None = None,
    video_max_frames: int | None = None,
) -> CalibrationResult:
    """Relative pose of the camera from the scene's annotations.

    Parameters
    ----------
    scene
        Path, dict or model (:func:`scene_from`).
    settings
        Full :class:`~camloc_geo.relative.CalibrationSettings`; when given, ``joint_fit`` and
        ``principal_point`` are ignored.
    joint_fit
        True: the joint robust fit of all annotators (default); False: the paper's
        per-annotator candidates and their largest cluster.
    principal_point
        ``"auto"`` (freed only when the data justify it), ``"centre"`` (or ``"center"``) or
        ``"free"``.
    video
        A video of the scene's camera (the scene image's size): the moving vehicles' tracks
        and edges join the fit as one more witness group
        (:func:`camloc_geo.sensors._video_lines.video_lines`,
        ``CalibrationSettings.video_lines``; ``video_segments`` in the result says how many
        per axis). Overrides ``settings.video_lines``. A video that gives no lines (too
        short, no moving vehicle) adds a warning and the fit is the scene's alone.
    video_max_frames
        Read at most this many of the video's first frames (default 600; the cost is about
        linear in the frames read).

    Returns
    -------
    CalibrationResult
        ``camera`` (``focal_px``, ``principal_point``, ``cam_from_world``, ``height_m``...), the
        per-annotator solutions, the uncertainties (``position_sigma_m``, ``focal_sigma_px``...)
        and ``warnings``; ``to_dict()`` is the JSON ``camloc calibrate`` prints.

    Raises
    ------
    SceneError
        The scene does not validate, or ``principal_point`` is none of the modes.
    InputError
        ``settings`` is not a ``CalibrationSettings``; the annotations cannot determine a
        camera (:class:`DegenerateGeometryError`, :class:`NotEnoughStructureError`).
    """
    from camloc_geo.relative import CalibrationSettings, calibrate

    sc = scene_from(scene)
    if settings is not None and not isinstance(settings, CalibrationSettings):
        raise InputError(f"settings must be a CalibrationSettings, not {type(settings).__name__}")
    if settings is None:
        modes = {"auto": None, "centre": False, "center": False, "free": True}
        if principal_point not in modes:
            raise SceneError(
                f"principal_point must be one of auto, centre, free, not {principal_point!r}"
            )
        settings = CalibrationSettings(
            joint_fit=joint_fit, free_principal_point=modes[principal_point]
        )
    if video is not None:
        from dataclasses import replace

        from camloc_geo.sensors._video_lines import video_lines

        if not isinstance(video, (str, os.PathLike)):
            raise InputError(f"video must be a file path, not {type(video).__name__}")
        kw: dict[str, Any] = {} if video_max_frames is None else {"max_frames": video_max_frames}
        lines = video_lines(video, image_size=(sc.image.width, sc.image.height), **kw)
        settings = replace(settings, video_lines=lines)
        result = calibrate(sc, settings)
        if not lines.has_groups():
            result.warnings.append(
                f"video {video}: no lines of moving vehicles ({lines.n_frames} frame(s) read: "
                "a video under 10 frames, a truncated file, or no vehicle moves); calibrated "
                "from the scene alone"
            )
        return result
    return calibrate(sc, settings)


def scene_needs_map(scene: Scene) -> bool:
    """True when the scene's evidence can only be used with map data (:attr:`Scene.needs_map`)."""
    return scene.needs_map


def scene_anchor(scene: Scene) -> tuple[float, float] | None:
    """``(lat, lon)`` to load the map around: prior, intersection, a reference or a landmark."""
    if scene.prior is not None:
        return scene.prior.lat, scene.prior.lon
    if scene.intersection is not None and scene.intersection.lat is not None:
        assert scene.intersection.lon is not None
        return scene.intersection.lat, scene.intersection.lon
    if scene.references:
        return scene.references[0].lat, scene.references[0].lon
    for lm in scene.landmarks:
        if lm.lat is not None and lm.lon is not None:
            return lm.lat, lm.lon
    return None


def scene_map_radius_m(scene: Scene, radius_m: float | None = None) -> float:
    """The map radius for a scene: ``radius_m``, or the prior's radius + 200 m (≥ 300 m)."""
    if radius_m is not None:
        return check_map_radius_m(radius_m)
    return max(
        DEFAULT_MIN_RADIUS_M, (scene.prior.radius_m if scene.prior else 0.0) + _PRIOR_MARGIN_M
    )


def _catalogue_of(map_source: MapSource) -> MapCatalogue | None:
    """The catalogue a map source chooses through: a catalogue itself, or a folder's."""
    if map_source is None:
        return None
    is_path = isinstance(map_source, (str, os.PathLike))
    if is_path and not Path(map_source).expanduser().is_dir():  # type: ignore[arg-type]
        return None
    from camloc_geo.osm import MapCatalogue

    if is_path:
        return MapCatalogue.from_source(map_source)  # type: ignore[arg-type]
    return map_source if isinstance(map_source, MapCatalogue) else None


def map_for_scene(
    scene: SceneLike,
    *,
    map_source: MapSource = None,
    network: bool = True,
    radius_m: float | None = None,
    cache_folder: str | os.PathLike[str] | None = None,
    overpass_url: str | None = None,
    required: bool | None = None,
) -> MapData | None:
    """The map data a scene needs, or None when it needs none and no extract was given.

    Parameters
    ----------
    scene
        Path, dict or model (:func:`scene_from`).
    map_source
        Extract, folder of extracts, :class:`~camloc_geo.osm.MapCatalogue` or a loaded map;
        None: Overpass when ``network`` allows it. A folder or catalogue gives the map
        covering the scene's anchor, or None when none covers it and the scene needs none.
    network
        May Overpass be queried (only when no ``map_source`` is given; a catalogue says
        itself whether it may).
    radius_m
        Map radius around the scene's anchor, metres (default :func:`scene_map_radius_m`).
    cache_folder, overpass_url
        Overpass's response cache folder and server (default: osmnx's).
    required
        Force loading (True) or skipping (False) the map; None: load when an extract is given
        or the scene needs one.

    Returns
    -------
    MapData or None
        The map (a loaded ``map_source`` is returned as is).

    Raises
    ------
    SceneError
        The scene does not validate, or it gives no point to load the map around.
    MapDataError
        ``map_source`` of an unknown kind, a missing or unreadable extract, no map covering the
        scene, or the network off when the scene needs a map.
    MapSourceError
        Overpass could not be reached or failed.
    """
    sc = scene_from(scene)
    _check_source(map_source)
    catalogue = _catalogue_of(map_source)
    loaded = catalogue is None and map_source is not None
    if loaded and not isinstance(map_source, (str, os.PathLike)):
        return map_source  # type: ignore[return-value]  # an already loaded MapData
    need = scene_needs_map(sc) if required is None else required
    if map_source is None and not need:
        return None
    centre = scene_anchor(sc)
    if catalogue is not None:
        if centre is None:
            if not need:
                return None
        else:
            area = catalogue.area_for_point(centre[0], centre[1])
            if area[0] != "none":
                return catalogue.map_for_area(area)
            if not need:
                return None
            raise MapDataError(
                "this scene needs a map (intersection corners, landmarks or street bearings) "
                f"and no map serves it: {area[1]}"
            )
    if centre is None:
        raise SceneError(
            "no location to load the map around: give prior (lat/lon), intersection lat/lon "
            "or references",
            "prior",
        )
    radius = scene_map_radius_m(sc, radius_m)
    if map_source is None and not network:
        raise MapDataError(
            "this scene needs a map (intersection corners, landmarks or street bearings) and "
            "the network is off: give --osm EXTRACT (map_source=...)"
        )
    from camloc_geo.osm import load_map

    if map_source is not None:
        return load_map(map_source, centre[0], centre[1], radius_m=radius)  # type: ignore[arg-type]
    return load_map(
        None,
        centre[0],
        centre[1],
        radius_m=radius,
        cache_folder=cache_folder,
        overpass_url=overpass_url,
    )


@dataclass(frozen=True, repr=False)
class LocateOutput:
    """What :func:`locate_scene` returns: the result and what it was computed from.

    Attributes
    ----------
    scene
        The validated scene.
    result
        The candidates, best first (``result.candidates``: ``lat``, ``lon``, ``score``,
        ``sigma_m``, ``flags``, ``ambiguous_with``...), ties, warnings and the reason when
        there is none.
    map_data
        The map used, or None when the scene needed none.
    """

    scene: Scene
    result: LocateResult
    map_data: MapData | None

    def __repr__(self) -> str:
        """One line for a notebook: the scene, how many candidates, the best, the map."""
        cands = self.result.candidates
        parts = [f"scene={self.scene.id!r}", f"candidates={len(cands)}"]
        if cands:
            best = cands[0]
            sigma = "" if best.sigma_m is None else f", sigma_m={best.sigma_m:.1f}"
            parts.append(
                f"best=(lat={best.lat:.6f}, lon={best.lon:.6f}, score={best.score:.3f}{sigma})"
            )
        elif self.result.reason:
            parts.append(f"reason={self.result.reason!r}")
        if self.result.ties:
            parts.append(f"ties={len(self.result.ties)}")
        if self.result.warnings:
            parts.append(f"warnings={len(self.result.warnings)}")
        parts.append(f"map={self.map_data!r}")
        return f"LocateOutput({', '.join(parts)})"

    @property
    def calibration(self) -> CalibrationResult:
        """The relative pose used."""
        return self.result.calibration

    def to_geojson(self) -> dict[str, Any]:
        """The candidate GeoJSON FeatureCollection (``docs/contract.md``)."""
        from camloc_geo.results import candidates_geojson

        return candidates_geojson(self.result)


def locate_scene(
    scene: SceneLike,
    *,
    map_source: MapSource = None,
    network: bool = True,
    radius_m: float | None = None,
    max_candidates: SupportsIndex | None = None,
    calibration: CalibrationResult | None = None,
    settings: LocateSettings | None = None,
    cache_folder: str | os.PathLike[str] | None = None,
    overpass_url: str | None = None,
) -> LocateOutput:
    """Candidate absolute camera positions for a scene, best first.

    Parameters
    ----------
    scene
        Path, dict or model.
    map_source, network, radius_m, cache_folder, overpass_url
        Where the map comes from (see :func:`map_for_scene` and the module's network policy).
    max_candidates
        At most this many candidates (≥ 1).
    calibration
        A relative pose computed before (default: :func:`calibrate_scene`).
    settings
        Noise model and ranking knobs (:class:`~camloc_geo.absolute.LocateSettings`).

    Returns
    -------
    LocateOutput
        ``result.candidates`` best first (``lat``, ``lon``, ``score``, ``sigma_m``,
        ``flags``, ``ambiguous_with``), ``result.ties``, the scene and the map used;
        ``to_geojson()`` is the candidate GeoJSON of ``docs/contract.md``.

    Raises
    ------
    SceneError, MapDataError, MapSourceError
        Bad scene or ``max_candidates``, unusable map, unreachable Overpass; each names the
        problem.
    InputError
        ``calibration`` or ``settings`` of the wrong type.
    """
    from dataclasses import replace

    from camloc_geo.absolute import LocateSettings, locate
    from camloc_geo.relative import CalibrationResult

    sc = scene_from(scene)
    if max_candidates is not None:
        max_candidates = _whole(max_candidates, "max_candidates", SceneError)
    if settings is not None and not isinstance(settings, LocateSettings):
        raise InputError(f"settings must be a LocateSettings, not {type(settings).__name__}")
    if calibration is not None and not isinstance(calibration, CalibrationResult):
        raise InputError(
            "calibration must be a CalibrationResult (from calibrate_scene), not "
            f"{type(calibration).__name__}"
        )
    map_data = map_for_scene(
        sc,
        map_source=map_source,
        network=network,
        radius_m=radius_m,
        cache_folder=cache_folder,
        overpass_url=overpass_url,
    )
    settings = settings or LocateSettings()
    if max_candidates is not None:
        if max_candidates < 1:
            raise SceneError("max_candidates must be at least 1", "max_candidates")
        settings = replace(settings, max_candidates=max_candidates)
    result = locate(sc, map_data, calibration=calibration, settings=settings)
    return LocateOutput(scene=sc, result=result, map_data=map_data)


def read_camera_list(path: str | os.PathLike[str]) -> Iterator[CameraRow]:
    """The cameras of a list (CSV or GeoJSON, column variants in ``docs/batch.md``), streamed.

    Parameters
    ----------
    path
        The list's file (``.csv``, ``.geojson``/``.json``).

    Returns
    -------
    Iterator[CameraRow]
        One :class:`~camloc_geo.cameras.CameraRow` per row, read as iterated.

    Raises
    ------
    InputError
        The list is missing or unreadable (a bad row is a :class:`CameraRow` with problems).
    """
    from camloc_geo.cameras import read_camera_list as _read

    return _read(path)


def locate_camera(
    camera: CameraRow | Mapping[str, Any],
    *,
    map_source: MapSource = None,
    network: bool = False,
    cache_folder: str | os.PathLike[str] | None = None,
    overpass_url: str | None = None,
) -> CameraResult:
    """Place one camera of a list: the camera-list engine every front end calls.

    Its title's junction, its rough point (a prior), its scene (a file or inline) and the
    view words, on the map the catalogue chooses for its point (a title without a point is
    searched in every extract). ``camloc batch``, the service's jobs and QGIS's
    ``camloc:geocodelist`` all call this, so one camera gets one answer.

    Parameters
    ----------
    camera
        A :class:`~camloc_geo.cameras.CameraRow` or a mapping with a list's columns (``id``,
        ``title``, ``lat``, ``lon``, ``radius_m``, ``scene`` and their aliases).
    map_source
        An extract, a folder of extracts, a :class:`~camloc_geo.osm.MapCatalogue` or a loaded
        map; None: Overpass when ``network`` allows it.
    network, cache_folder, overpass_url
        May Overpass be queried (off by default), its response cache folder and server.

    Returns
    -------
    CameraResult
        Never raised for a bad camera: its ``status`` and ``reason`` say what happened, in
        the vocabulary of ``docs/contract.md``; ``to_dict()`` for JSON.

    Raises
    ------
    InputError
        ``camera`` is neither a ``CameraRow`` nor a mapping; ``map_source`` of an unknown
        kind (:class:`MapDataError`).
    """
    from camloc_geo.cameras import CameraRow, geocode_camera, row_from_mapping
    from camloc_geo.osm import MapCatalogue, MapData

    if not isinstance(camera, (CameraRow, Mapping)):
        raise InputError(
            "camera must be a CameraRow or a mapping of a list's columns (id, title, lat, "
            f"lon, ...), not {type(camera).__name__}"
        )
    _check_source(map_source)
    row = camera if isinstance(camera, CameraRow) else row_from_mapping(camera, 1)
    if isinstance(map_source, MapData):
        return geocode_camera(row, map_data=map_source)
    catalogue = MapCatalogue.from_source(
        map_source, network=network, cache_folder=cache_folder, overpass_url=overpass_url
    )
    return geocode_camera(row, plan=catalogue)


def _check_source(map_source: object) -> None:
    """A :class:`MapDataError` when ``map_source`` is none of the kinds :data:`MapSource` names."""
    if map_source is None or isinstance(map_source, (str, os.PathLike)):
        return
    from camloc_geo.osm import MapCatalogue, MapData

    if not isinstance(map_source, (MapData, MapCatalogue)):
        raise MapDataError(
            "map_source must be an extract or folder path, a MapCatalogue or a MapData, "
            f"not {type(map_source).__name__}"
        )


def _require_source(map_source: MapSource, network: bool) -> None:
    """Fail at once (before any heavy import) when no map can be had."""
    _check_source(map_source)
    if map_source is None and not network:
        raise MapDataError(
            "no map: the network is off and no extract was given: give --osm EXTRACT "
            "(map_source=...)"
        )


def corners_near(
    *,
    lat: SupportsFloat,
    lon: SupportsFloat,
    radius_m: SupportsFloat = 150.0,
    map_source: MapSource = None,
    network: bool = True,
    streets: str | Sequence[str] | None = None,
    cache_folder: str | os.PathLike[str] | None = None,
    overpass_url: str | None = None,
) -> dict[str, Any]:
    """Intersections with their kerb corners around a point, as GeoJSON (``docs/contract.md``).

    Parameters
    ----------
    lat, lon
        The point, degrees WGS 84 (floats, numpy scalars).
    radius_m
        Only the intersections whose centre lies within this distance, metres.
    map_source, network, cache_folder, overpass_url
        Where the map comes from (:func:`streets_near`, the module's network policy).
    streets
        ``"A & B"`` or ``["A", "B"]``: only the intersection of those streets.

    Returns
    -------
    dict
        A GeoJSON FeatureCollection of intersections and corners (plain JSON types).

    Raises
    ------
    MapDataError
        ``lat``/``lon``/``radius_m`` not numbers or out of range, no map (network off and no
        extract), an unreadable extract, a point outside it, or ``streets`` that do not meet
        within ``radius_m``.
    MapSourceError
        Overpass could not be reached or failed.
    """
    lat, lon = _degrees(lat, "lat"), _degrees(lon, "lon")
    radius_m = check_map_radius_m(radius_m)
    if streets is not None and (
        not isinstance(streets, (str, list, tuple))
        or not all(isinstance(n, str) for n in ([] if isinstance(streets, str) else streets))
    ):
        raise MapDataError(
            f"streets must be 'A & B' or a list of street names, not {type(streets).__name__}"
        )
    m = streets_near(
        lat=lat,
        lon=lon,
        radius_m=radius_m,
        map_source=map_source,
        network=network,
        cache_folder=cache_folder,
        overpass_url=overpass_url,
    )
    from camloc_geo.results import intersections_geojson

    if streets:
        found = m.find_intersection(streets, near=(lat, lon))
        if m.radius_m is None or m.radius_m > radius_m:
            # a map loaded for more than this point: the streets may meet far away; as
            # without ``streets``, only an intersection whose centre lies within radius_m
            from camloc_geo.geodesy import distance_m

            away = float(distance_m(lat1=lat, lon1=lon, lat2=found.lat, lon2=found.lon))
            if away > radius_m:
                raise MapDataError(
                    f"streets {streets!r} do not meet within {radius_m:g} m of "
                    f"lat={lat:.6f}, lon={lon:.6f}: they meet {away:.0f} m away, at "
                    f"lat={found.lat:.6f}, lon={found.lon:.6f} (a larger radius_m reaches it)"
                )
        return intersections_geojson([found])
    inters = list(m.intersections)
    if inters and (m.radius_m is None or m.radius_m > radius_m):
        # a map loaded for more than this point (a whole extract, a catalogue cell, a map
        # passed in): only the intersections whose centre lies within radius_m
        import numpy as np

        from camloc_geo.geodesy import distance_m

        far = distance_m(
            lat1=np.full(len(inters), lat),
            lon1=np.full(len(inters), lon),
            lat2=np.array([x.lat for x in inters]),
            lon2=np.array([x.lon for x in inters]),
        )
        inters = [x for x, d in zip(inters, far, strict=True) if d <= radius_m]
    return intersections_geojson(inters)


def streets_near(
    *,
    lat: SupportsFloat,
    lon: SupportsFloat,
    radius_m: SupportsFloat = 150.0,
    map_source: MapSource = None,
    network: bool = True,
    cache_folder: str | os.PathLike[str] | None = None,
    overpass_url: str | None = None,
) -> MapData:
    """The map around a point (its ``streets`` carry names and bearings).

    Parameters
    ----------
    lat, lon
        The point, degrees WGS 84 (floats, numpy scalars).
    radius_m
        Map radius when loading from an extract or Overpass, metres (a folder or catalogue
        gives its own cell or extract).
    map_source
        Extract, folder of extracts, :class:`~camloc_geo.osm.MapCatalogue` or a loaded map
        (returned as is); None: Overpass when ``network`` allows it.
    network
        May Overpass be queried (only without ``map_source``).
    cache_folder, overpass_url
        Overpass's response cache folder and server (default: osmnx's).

    Returns
    -------
    MapData
        Streets, intersections and buildings (shared through the load cache: read-only).

    Raises
    ------
    MapDataError
        ``lat``/``lon``/``radius_m`` not numbers or out of range, ``map_source`` of an unknown
        kind, no extract and the network off (at once), unreadable extract, no streets there.
    MapSourceError
        Overpass could not be reached (within a few seconds) or failed.
    """
    lat, lon = _degrees(lat, "lat"), _degrees(lon, "lon")
    radius_m = check_map_radius_m(radius_m)
    _require_source(map_source, network)
    catalogue = _catalogue_of(map_source)
    if catalogue is not None:
        return catalogue.map_for_point(lat=lat, lon=lon)
    from camloc_geo.osm import MapData, load_map

    if isinstance(map_source, MapData):
        return map_source
    return load_map(
        map_source,  # type: ignore[arg-type]  # an extract path or None here
        lat,
        lon,
        radius_m,
        cache_folder=cache_folder,
        overpass_url=overpass_url,
    )


def vanishing_points(
    image: str | os.PathLike[str] | Any,
    *,
    focal_px: SupportsFloat | None = None,
    principal_point: tuple[float, float] | None = None,
    ignore_boxes_px: Sequence[Sequence[float]] = (),
    axes_px: Sequence[Sequence[float]] = (),
    estimate_principal_point: bool = False,
    seed: int = 0,
    **options: Any,
) -> AutoVPResult:
    """Three orthogonal vanishing points, focal length, horizon, pitch and roll of a photo.

    Parameters
    ----------
    image
        Path of a photo (JPEG, PNG, TIFF, WebP, BMP, GIF...: a header Pillow reads, decoded
        by OpenCV) or a grey/colour image array: ``uint8``, ``uint16`` (16-bit), floats
        (0..1, or 0..255 when larger than 1), or wider integers holding 0..255.
    focal_px, principal_point
        Known intrinsics, pixels (default: estimated / the image centre).
    ignore_boxes_px
        ``(x0, y0, x1, y1)`` pixel boxes whose segments are ignored (time stamps, logos).
    axes_px
        ``(ox, oy, ex, ey)`` annotated object axes (origin, end); up to 3.
    estimate_principal_point
        Also refine the principal point around the image centre.
    seed
        Seed of the robust sampling (the same seed gives the same answer).
    **options
        Passed to :func:`camloc_geo.autovp.detect_vanishing_points` (``use_exif``,
        ``focal_prior_px``, ``distortion_k1``, ``estimate_distortion``, ...). With
        ``use_exif=True`` and a path, the focal length is read from the photo's EXIF before
        it is loaded (since session 41: the loaded array had none, and the option did
        nothing) and used as the prior, checked against the photo's lines, as
        ``detect_vanishing_points`` does given the path.

    Returns
    -------
    AutoVPResult
        The vanishing points, ``focal_px``, horizon, pitch and roll, with their quality.

    Raises
    ------
    InputError
        Unreadable image, non-positive focal length, a box or axis that is not four finite
        numbers, an unknown option, too little structure
        (:class:`NotEnoughStructureError`).
    """
    import numpy as np

    from camloc_geo._errors import InputError
    from camloc_geo.autovp import detect_vanishing_points, load_image

    if focal_px is not None:
        try:
            focal = _finite_numbers([focal_px], 1, "focal_px must be a positive number of pixels")
        except InputError:  # named as given ('got nan', it said 'got [nan]')
            raise InputError(
                f"focal_px must be a positive number of pixels, got {focal_px!r}"
            ) from None
        if isinstance(focal_px, bool) or not focal[0] > 0:
            raise InputError(f"focal_px must be a positive number of pixels, got {focal_px!r}")
        focal_px = focal[0]
    options, exif_warnings = _exif_prior(image, focal_px, options)
    img = load_image(image)
    if principal_point is not None:
        principal_point = _principal_point_in(principal_point, img.shape[1], img.shape[0])
    mask = None
    if ignore_boxes_px:
        h, w = img.shape[:2]
        mask = np.ones((h, w), dtype=bool)
        for box in ignore_boxes_px:
            box = _finite_numbers(box, 4, "ignore box: give four finite numbers x0 y0 x1 y1")
            xa, xb = sorted((box[0], box[2]))
            ya, yb = sorted((box[1], box[3]))
            mask[
                max(0, int(ya)) : max(0, int(np.ceil(yb))),
                max(0, int(xa)) : max(0, int(np.ceil(xb))),
            ] = False
    axes = [_finite_numbers(a, 4, "axis: give four finite numbers ox oy ex ey") for a in axes_px]
    import inspect

    known = inspect.signature(detect_vanishing_points).parameters
    unknown = sorted(set(options) - set(known))
    if unknown:
        raise InputError(f"unknown vanishing-point option(s): {', '.join(unknown)}")
    result = detect_vanishing_points(
        img,
        focal_px=focal_px,
        principal_point=principal_point,
        seed=seed,
        mask=mask,
        estimate_principal_point=estimate_principal_point,
        axes_hint=[((a[0], a[1]), (a[2], a[3])) for a in axes] or None,
        **options,
    )
    # The EXIF readings' own warnings (a conflict, a phone's telephoto camera, a resize) come
    # first, as detect_vanishing_points puts them when it reads the path itself (stop 42).
    result.warnings[:0] = [w for w in exif_warnings if w not in result.warnings]
    return result


def _principal_point_in(point: object, width: int, height: int) -> tuple[float, float]:
    """``point`` as two finite pixels inside the ``width`` x ``height`` image, or an
    :class:`InputError` naming it.

    A principal point far off the image was taken as given: ``--principal-point 1e9 3`` gave
    a focal length at a stated 0.0 % with confidence 0.94 and no warning (stop 41, qa3).
    """
    px = _finite_numbers(point, 2, "principal_point must be two finite numbers x y")
    x, y = px
    if not (0.0 <= x <= width and 0.0 <= y <= height):
        raise InputError(
            f"principal_point ({x:g}, {y:g}) lies outside the {width}x{height} image; it is "
            f"where the lens axis meets the photo, near its centre ({width / 2:g}, "
            f"{height / 2:g})"
        )
    return x, y


def _exif_prior(
    image: object, focal_px: float | None, options: dict[str, Any]
) -> tuple[dict[str, Any], tuple[str, ...]]:
    """``options`` with ``use_exif`` turned into the EXIF focal-length prior it asks for, and
    the EXIF readings' warnings.

    :func:`vanishing_points` loads the photo into an array before the fit, and an array has
    no EXIF: ``use_exif=True`` passed through did nothing (the fit's own reader only reads a
    path). The tags are read here, from the file, and passed as ``focal_prior_px`` (with its
    sigma and ``focal_source``) and ``check_focal_prior`` (default on, as the fit does for
    its own EXIF prior: a maker's tag can be wrong). A known ``focal_px`` or a given
    ``focal_prior_px`` wins, as in the fit; an array or a photo without the tags leaves the
    options as they were. The readings' warnings (``ExifFocal.warnings``: readings in
    conflict, a phone's other camera, a resized photo) were dropped here until stop 42; they
    are returned for the result.
    """
    if not options.get("use_exif") or focal_px is not None:
        return options, ()
    if options.get("focal_prior_px") is not None or not isinstance(image, (str, os.PathLike)):
        return options, ()
    from camloc_geo.exif import focal_from_exif

    ex = focal_from_exif(image)
    if ex is None:
        return options, ()
    out = dict(options)
    out.update(
        focal_prior_px=ex.focal_px,
        focal_prior_sigma_rel=ex.sigma_rel,
        focal_prior_source=ex.source,
    )
    if out.get("check_focal_prior") is None:
        out["check_focal_prior"] = True
    return out, tuple(ex.warnings)


def _finite_numbers(values: object, count: int, message: str) -> list[float]:
    """``values`` as ``count`` finite floats, or an :class:`InputError` with ``message``."""
    import math

    try:
        out = [float(v) for v in values]  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise InputError(f"{message}, got {values!r}") from None
    if len(out) != count or not all(math.isfinite(v) for v in out):
        raise InputError(f"{message}, got {values!r}")
    return out


def map_around(
    points: Sequence[tuple[float, float]],
    *,
    map_source: MapSource = None,
    network: bool = False,
    margin_m: float = 150.0,
    max_radius_m: float = 2000.0,
) -> MapData | None:
    """The map covering ``(lat, lon)`` points (cameras), or None without points.

    Centred on the points' mean, with a radius reaching the farthest point plus
    ``margin_m`` (at most ``max_radius_m``).

    Parameters
    ----------
    points
        ``(lat, lon)`` pairs, degrees WGS 84.
    map_source, network
        As for :func:`streets_near` (here the network is off by default).
    margin_m, max_radius_m
        Metres added to the farthest point (>= 0), and the largest radius loaded (> 0).

    Returns
    -------
    MapData or None
        The map; None when ``points`` is empty.

    Raises
    ------
    MapDataError
        A point that is not a pair of numbers (named by its index), no map, an unreadable
        extract.
    MapSourceError
        Overpass could not be reached or failed.
    """
    if not points:
        return None
    pts: list[tuple[float, float]] = []
    for k, p in enumerate(points):
        if isinstance(p, (str, bytes)) or not hasattr(p, "__len__") or len(p) != 2:
            raise MapDataError(f"points[{k}] must be a (lat, lon) pair, got {p!r}")
        pts.append((_degrees(p[0], f"points[{k}] lat"), _degrees(p[1], f"points[{k}] lon")))
    points = pts
    margin_m = _metres(margin_m, "margin_m") if margin_m != 0 else 0.0
    max_radius_m = _metres(max_radius_m, "max_radius_m")
    _require_source(map_source, network)
    from camloc_geo.geodesy import distance_m
    from camloc_geo.osm import MapData, load_map

    if isinstance(map_source, MapData):
        return map_source
    lat = sum(p[0] for p in points) / len(points)
    lon = sum(p[1] for p in points) / len(points)
    catalogue = _catalogue_of(map_source)
    if catalogue is not None:
        return catalogue.map_for_point(lat=lat, lon=lon)
    radius = max(distance_m(lat1=lat, lon1=lon, lat2=q[0], lon2=q[1]) for q in points)
    radius_m = min(radius + margin_m, max_radius_m)
    return load_map(map_source, lat, lon, radius_m=radius_m)  # type: ignore[arg-type]


def radar_scene(
    scene: SceneLike,
    video: str | os.PathLike[str],
    *,
    fps: float | None = None,
    tracks: str | os.PathLike[str] | dict[int, dict[int, Any]] | None = None,
    min_track_s: float = 0.5,
    max_frames: int | None = None,
    progress: bool = False,
    video_lines: bool = True,
) -> RadarResult:
    """Virtual radar: calibrate the scene, then measure the vehicles' speeds in a video.

    The video must come from the scene's camera, with the same framing and frame size as
    the scene's image. See :func:`camloc_geo.sensors.radar.measure_speeds` for the method's
    options and ``docs/radar.md`` for the method.

    Parameters
    ----------
    scene
        Path, dict or model (:func:`scene_from`).
    video
        The video file's path.
    fps
        Frame rate; default: the one the file states (refused when it states none).
    tracks
        Boxes per frame from any detector: a file or ``{id: {frame: (x1, y1, x2, y2)}}``;
        None: background subtraction finds the vehicles.
    min_track_s
        Shorter tracks are not measured, seconds.
    max_frames
        Read at most this many frames (the video's lines for the calibration: at most the
        first ``min(max_frames, 600)``).
    progress
        Show a tqdm progress bar on stderr.
    video_lines
        Calibrate with the video's own lines as one more witness (the moving vehicles'
        tracks and edges, :func:`calibrate_scene`'s ``video``; default); False: from the
        scene alone (as before session 36). The JSON's ``calibration`` says which
        witnesses were used.

    Returns
    -------
    RadarResult
        Per-vehicle speeds (``to_dict()`` for JSON).

    Raises
    ------
    InputError
        The scene does not calibrate, ``video`` is not a path, the video is unreadable or not
        the scene's size, no frame rate, malformed tracks (each a one-line message).
    """
    from camloc_geo.sensors._video_lines import _MAX_FRAMES as _VIDEO_LINES_FRAMES
    from camloc_geo.sensors.radar import measure_speeds, probe_video, read_tracks

    sc = scene_from(scene)
    if not isinstance(video, (str, os.PathLike)):
        raise InputError(f"video must be a file path, not {type(video).__name__}")
    size = (sc.image.width, sc.image.height)
    if max_frames is not None and (
        isinstance(max_frames, bool) or not isinstance(max_frames, SupportsIndex) or max_frames < 1
    ):  # refused before the calibration (which reads the video's lines) too
        raise InputError(f"max_frames must be a whole number >= 1, not {max_frames!r}")
    probe_video(video, image_size=size)  # a bad video or tracks file fails before calibrating
    if isinstance(tracks, (str, os.PathLike)):
        tracks = read_tracks(tracks)
    calibration = calibrate_scene(
        sc,
        video=video if video_lines else None,
        # the lines from the frames measured, and never more than their default 600
        video_max_frames=None if max_frames is None else min(max_frames, _VIDEO_LINES_FRAMES),
    )
    result = measure_speeds(
        calibration,
        video,
        fps=fps,
        tracks=tracks,
        image_size=size,
        min_track_s=min_track_s,
        max_frames=max_frames,
        progress=progress,
    )
    # the calibration's warnings about the video's lines (none found, a group that
    # disagrees) are the radar's too: calibration.witnesses alone left them unsaid
    result.warnings.extend(w for w in calibration.warnings if w.startswith("video"))
    return result


def guide_scene(
    scene: SceneLike,
    tracks: Any,
    gps: Any,
    *,
    video_start: Any = None,
    fps: float | None = None,
    pose: str = "auto",
    candidates: str | os.PathLike[str] | dict[str, Any] | None = None,
    candidate: int = 1,
    map_source: MapSource = None,
    network: bool = True,
    radius_m: float | None = None,
    cache_folder: str | os.PathLike[str] | None = None,
    overpass_url: str | None = None,
    settings: GuideSettings | None = None,
) -> GuideResult:
    """Virtual guide: match people tracked in the camera's video to GPS traces.

    Parameters
    ----------
    scene
        Path, dict or model; calibrated with :func:`calibrate_scene`.
    tracks
        People's pixel tracks: a ``.json``/``.csv`` path, parsed JSON, or a list of
        :class:`~camloc_geo.sensors.guide.PixelTrack` (format in ``docs/guide.md``).
    gps
        GPS traces: a ``.gpx``/``.csv`` path or a list of
        :class:`~camloc_geo.sensors.guide.GpsTrace`.
    video_start, fps
        Time of the video's first frame (ISO 8601 or UNIX seconds) when the tracks' times are
        seconds since it; frame rate when they give frame numbers.
    pose
        ``"absolute"``: the camera's absolute pose is needed (from ``candidates`` or by
        locating the scene, which must carry references, kerb corners or landmarks);
        ``"relative"``: solve the transform to the GPS frame jointly with the matching;
        ``"auto"`` (default): absolute when ``candidates`` is given or the scene can be
        located (a scene that locate cannot place falls back to relative, with a warning).
    candidates, candidate
        A candidate GeoJSON written by ``camloc locate`` (path or dict) and the rank to use
        (default 1, the best). Without it the scene is located here.
    map_source, network, radius_m, cache_folder, overpass_url
        Where the map comes from when the scene is located (see :func:`locate_scene`).
    settings
        Noise model and knobs (:class:`~camloc_geo.sensors.guide.GuideSettings`).

    Returns
    -------
    GuideResult
        The people matched to GPS traces, the pose used and ``warnings``.

    Raises
    ------
    InputError
        Unreadable tracks or traces, pixels above the horizon, traces with no overlap in time,
        an absolute pose asked for a scene that cannot be located; each in one line.
    """
    from camloc_geo._errors import InputError
    from camloc_geo.sensors.guide import (
        AbsolutePose,
        GpsTrace,
        PixelTrack,
        match_people,
        pose_from_candidates_geojson,
        read_gps,
        read_tracks,
    )

    if pose not in ("auto", "absolute", "relative"):
        raise InputError(f"pose must be auto, absolute or relative, not {pose!r}")
    candidate = _whole(candidate, "candidate rank")
    if candidate < 1:
        raise InputError(f"candidate rank must be at least 1, not {candidate}")
    if candidates is not None and pose == "relative":
        raise InputError("a candidates file gives an absolute pose: do not ask for relative")
    sc = scene_from(scene)
    if isinstance(tracks, list) and all(isinstance(t, PixelTrack) for t in tracks) and tracks:
        pixel_tracks = list(tracks)
    else:
        pixel_tracks = read_tracks(tracks, video_start=video_start, fps=fps)
    if isinstance(gps, list) and all(isinstance(g, GpsTrace) for g in gps) and gps:
        traces = list(gps)
    else:
        traces = read_gps(gps)
    warnings: list[str] = []
    abs_pose: AbsolutePose | None = None
    if candidates is not None:
        calibration = calibrate_scene(sc)
        if isinstance(candidates, dict):
            doc, name = candidates, "candidates"
        else:
            from camloc_geo._io import read_json_file

            doc, name = read_json_file(candidates), Path(candidates).name
        abs_pose = pose_from_candidates_geojson(doc, calibration, rank=candidate, name=name)
    elif pose != "relative" and (sc.references or sc.intersection or sc.landmarks):
        out = locate_scene(
            sc,
            map_source=map_source,
            network=network,
            radius_m=radius_m,
            cache_folder=cache_folder,
            overpass_url=overpass_url,
        )
        calibration = out.calibration
        cands = out.result.candidates
        if len(cands) >= candidate:
            c = cands[candidate - 1]
            abs_pose = AbsolutePose(
                c.enu_from_world,
                out.result.frame,
                f"locate candidate {c.rank} of {len(cands)} (score {c.score:.2f})",
                c.enu_from_world.inverse().camera(c.camera),
            )
            if c.ambiguous_with:
                warnings.append(
                    f"candidate {c.rank} ties with candidates {c.ambiguous_with}: the ground "
                    "tracks may be placed at the wrong one"
                )
        else:
            why = f"locate found {len(cands)} candidate(s), not a rank {candidate}" + (
                f" ({out.result.reason})" if out.result.reason else ""
            )
            if pose == "absolute":
                raise InputError(f"no absolute pose: {why}")
            warnings.append(f"{why}: matched in the relative frame")
    else:
        if pose == "absolute":
            raise InputError(
                "no absolute pose: the scene has no references, intersection corners or "
                "landmarks to locate it; give a candidates file or use the relative pose"
            )
        calibration = calibrate_scene(sc)
    result = match_people(calibration, pixel_tracks, traces, pose=abs_pose, settings=settings)
    result.warnings[:0] = warnings + list(calibration.warnings)
    return result


corners_within = corners_near
"""The service's name for :func:`corners_near`, which keeps only the intersections within
``radius_m`` on a map loaded wider than the radius (a whole extract shared by many requests,
a catalogue cell): one radius rule, in one function."""


def streets_within(
    *,
    lat: SupportsFloat,
    lon: SupportsFloat,
    radius_m: SupportsFloat = 150.0,
    map_source: MapSource = None,
    network: bool = True,
    cache_folder: str | os.PathLike[str] | None = None,
    overpass_url: str | None = None,
) -> dict[str, Any]:
    """The streets within ``radius_m`` of a point with their bearings (JSON).

    ``near`` lists each street's name and bearing there; ``streets`` describes only those
    streets (not every street of the map, which may be a whole extract).

    Parameters
    ----------
    lat, lon, radius_m, map_source, network, cache_folder, overpass_url
        As for :func:`streets_near`.

    Returns
    -------
    dict
        ``{"near": [...], "streets": [...], ...}`` in plain JSON types.

    Raises
    ------
    MapDataError, MapSourceError
        As for :func:`streets_near`.
    """
    from camloc_geo.results import streets_json

    lat, lon = _degrees(lat, "lat"), _degrees(lon, "lon")
    radius_m = check_map_radius_m(radius_m)
    m = streets_near(
        lat=lat,
        lon=lon,
        radius_m=radius_m,
        map_source=map_source,
        network=network,
        cache_folder=cache_folder,
        overpass_url=overpass_url,
    )
    out = streets_json(m, lat, lon, radius_m)
    names = {n["name"] for n in out["near"]}
    out["streets"] = [s for s in out["streets"] if s["name"] in names]
    return out


def crowd_scene(
    scenes: Sequence[SceneLike], *, prior: dict[str, Any] | None = None
) -> dict[str, Any]:
    """One scene from several annotators' scenes of one snapshot, with the task's prior.

    The scenes are merged (:func:`camloc_geo.merge.merge_scenes`); ``prior`` (``{"lat",
    "lon", "radius_m"}``, the point the snapshot was taken near) is used when no annotator
    gave one.

    Parameters
    ----------
    scenes
        A list of scenes (paths, dicts or models), not one scene.
    prior
        ``{"lat", "lon", "radius_m"}``, or None.

    Returns
    -------
    dict
        The merged ``camloc-scene/1`` dict.

    Raises
    ------
    SceneError
        No scene, ``scenes`` not a list (a single path or dict), ``prior`` not a mapping, a
        scene that does not validate, or scenes that conflict.
    """
    from camloc_geo.merge import merge_scenes

    if isinstance(scenes, (str, bytes, os.PathLike, Mapping)) or not hasattr(scenes, "__iter__"):
        raise SceneError(
            f"scenes must be a list of scenes (paths, dicts or Scenes), not {type(scenes).__name__}"
        )
    if prior is not None and not isinstance(prior, Mapping):
        raise SceneError(
            f"prior must be a mapping {{lat, lon, radius_m}}, not {type(prior).__name__}", "prior"
        )
    merged = dict(merge_scenes(list(scenes)))
    if prior is not None and merged.get("prior") is None:
        merged["prior"] = dict(prior)
    return merged
