"""The scene file (``camloc-scene/1``) as a validated pydantic model.

See ``docs/contract.md`` for the contract. Every violation becomes a
:class:`~camloc_geo.SceneError` whose message starts with the dotted path of the field
(``annotations[1].vp_lines.width[0]: ...``). Unknown fields are kept (the format may be
extended by other tools) and logged at debug level.

Extensions beyond the contract (all optional):

- ``object.preset``: a name from :data:`camloc_geo.objects.PRESETS` instead of, or as the
  base for, explicit sizes.
- ``references[].weight``: relative confidence of a reference pixel.
"""

from __future__ import annotations

import json
import logging
import math
from pathlib import Path
from typing import Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from camloc_geo._errors import SceneError
from camloc_geo.objects import DEFAULT_PRESET, ObjectSize, object_preset

__all__ = [
    "SCENE_FORMAT",
    "Annotation",
    "Scene",
    "load_scene",
    "parse_scene",
    "scene_json_schema",
]

log = logging.getLogger(__name__)

SCENE_FORMAT = "camloc-scene/1"

Pixel = tuple[float, float]
Segment = tuple[float, float, float, float]


class _Model(BaseModel):
    model_config = ConfigDict(extra="allow", frozen=True, populate_by_name=True)


class ImageInfo(_Model):
    """The snapshot: its size in pixels and, optionally, its file."""

    width: int = Field(gt=0, le=100_000)
    height: int = Field(gt=0, le=100_000)
    path: str | None = None


class Prior(_Model):
    """The coarse location a camera list gives."""

    lat: float = Field(ge=-90, le=90)
    lon: float = Field(ge=-180, le=180)
    radius_m: float = Field(default=150.0, gt=0, le=50_000)


class ObjectSpec(_Model):
    """The reference object's size; missing numbers come from ``preset`` (default sedan)."""

    preset: str | None = None
    length_m: float | None = Field(default=None, gt=0, lt=1e4)
    width_m: float | None = Field(default=None, gt=0, lt=1e4)
    height_m: float | None = Field(default=None, gt=0, lt=1e4)

    @field_validator("preset")
    @classmethod
    def _known_preset(cls, value: str | None) -> str | None:
        if value is not None:
            object_preset(value)  # SceneError naming object.preset and the known names
        return value

    def size(self) -> ObjectSize:
        """The resolved :class:`ObjectSize`."""
        base = object_preset(self.preset or DEFAULT_PRESET)
        return ObjectSize(
            self.length_m if self.length_m is not None else base.length_m,
            self.width_m if self.width_m is not None else base.width_m,
            self.height_m if self.height_m is not None else base.height_m,
        )


class CameraHints(_Model):
    """Known intrinsics, each optional."""

    focal_px: float | None = Field(default=None, gt=0, lt=1e6)
    principal_point: Pixel | None = None


class Axes(_Model):
    """Pixels of the object's ground corner and of the ends of its three edges."""

    origin: Pixel
    length: Pixel
    width: Pixel
    height: Pixel


class VPLines(_Model):
    """Segments parallel in the world to each object axis."""

    length: list[Segment] = Field(default_factory=list)
    width: list[Segment] = Field(default_factory=list)
    height: list[Segment] = Field(default_factory=list)


class Annotation(_Model):
    """One annotator's work."""

    annotator: str = "anonymous"
    axes: Axes
    vp_lines: VPLines = Field(default_factory=VPLines)


class Reference(_Model):
    """A ground pixel whose geographic position is known."""

    pixel: Pixel
    lat: float = Field(ge=-90, le=90)
    lon: float = Field(ge=-180, le=180)
    weight: float = Field(default=1.0, gt=0)


class IntersectionHint(_Model):
    """The visible kerb corners of the nearest intersection, clockwise on screen."""

    corners: list[Pixel] = Field(min_length=1)
    lat: float | None = Field(default=None, ge=-90, le=90)
    lon: float | None = Field(default=None, ge=-180, le=180)
    streets: list[str] | None = None

    @model_validator(mode="after")
    def _lat_lon_together(self) -> IntersectionHint:
        if (self.lat is None) != (self.lon is None):
            raise ValueError("give both lat and lon, or neither")
        return self


class Landmark(_Model):
    """A visible building corner or face midpoint."""

    pixel: Pixel
    kind: Literal["building_corner", "face_midpoint"]
    name: str | None = None
    lat: float | None = Field(default=None, ge=-90, le=90)
    lon: float | None = Field(default=None, ge=-180, le=180)

    @model_validator(mode="after")
    def _identified(self) -> Landmark:
        if (self.lat is None) != (self.lon is None):
            raise ValueError("give both lat and lon, or neither")
        if self.name is None and self.lat is None:
            raise ValueError("a landmark needs a name or lat/lon")
        return self


class Scene(_Model):
    """A ``camloc-scene/1`` scene."""

    format: str
    id: str = "scene"
    image: ImageInfo
    prior: Prior | None = None
    object: ObjectSpec = Field(default_factory=ObjectSpec)
    camera: CameraHints = Field(default_factory=CameraHints)
    annotations: list[Annotation] = Field(default_factory=list)
    references: list[Reference] = Field(default_factory=list)
    intersection: IntersectionHint | None = None
    landmarks: list[Landmark] = Field(default_factory=list)
    street_bearing_deg: float | None = None

    # Set by load_scene: the folder that image.path is relative to.
    base_dir: str | None = Field(default=None, exclude=True)

    @field_validator("format")
    @classmethod
    def _known_format(cls, value: str) -> str:
        if value != SCENE_FORMAT:
            raise ValueError(f"unknown format version {value!r}; this reads {SCENE_FORMAT!r}")
        return value

    @field_validator("street_bearing_deg")
    @classmethod
    def _finite_bearing(cls, value: float | None) -> float | None:
        if value is not None and not math.isfinite(value):
            raise ValueError("must be a finite number of degrees")
        return value

    @model_validator(mode="after")
    def _pixels_in_image(self) -> Scene:
        for path, pixel in self.iter_pixels():
            _check_pixel(pixel, self.image.width, self.image.height, path)
        return self

    def iter_pixels(self) -> list[tuple[str, tuple[float, ...]]]:
        """Every pixel-valued field with its dotted path (segments give two pixels)."""
        out: list[tuple[str, tuple[float, ...]]] = []
        for i, ann in enumerate(self.annotations):
            for name in ("origin", "length", "width", "height"):
                out.append((f"annotations[{i}].axes.{name}", getattr(ann.axes, name)))
            for axis in ("length", "width", "height"):
                for j, seg in enumerate(getattr(ann.vp_lines, axis)):
                    out.append((f"annotations[{i}].vp_lines.{axis}[{j}]", seg))
        for i, ref in enumerate(self.references):
            out.append((f"references[{i}].pixel", ref.pixel))
        if self.intersection is not None:
            for i, c in enumerate(self.intersection.corners):
                out.append((f"intersection.corners[{i}]", c))
        for i, lm in enumerate(self.landmarks):
            out.append((f"landmarks[{i}].pixel", lm.pixel))
        return out

    @property
    def object_size(self) -> ObjectSize:
        """The reference object's resolved size."""
        return self.object.size()

    @property
    def image_size(self) -> tuple[int, int]:
        """``(width, height)`` in pixels."""
        return self.image.width, self.image.height

    def image_file(self) -> Path | None:
        """Absolute path of the snapshot, if the scene names one."""
        if not self.image.path:
            return None
        p = Path(self.image.path)
        if not p.is_absolute() and self.base_dir:
            p = Path(self.base_dir) / p
        return p


def _check_pixel(values: tuple[float, ...], width: int, height: int, path: str) -> None:
    for k in range(0, len(values), 2):
        x, y = values[k], values[k + 1]
        if not (math.isfinite(x) and math.isfinite(y)):
            raise SceneError(f"pixel [{x}, {y}] is not finite", path)
        if not (0.0 <= x <= width and 0.0 <= y <= height):
            raise SceneError(f"pixel [{x:g}, {y:g}] is outside the {width}x{height} image", path)


def _loc_to_path(loc: tuple[int | str, ...]) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def parse_scene(data: Any, *, base_dir: str | Path | None = None) -> Scene:
    """Validate a scene given as a dict (parsed JSON).

    Raises
    ------
    SceneError
        Naming the first offending field.
    """
    if not isinstance(data, dict):
        raise SceneError(f"a scene is a JSON object, got {type(data).__name__}")
    if "format" not in data:
        raise SceneError(f"missing; expected {SCENE_FORMAT!r}", "format")
    known = set(Scene.model_fields)
    for key in data:
        if key not in known:
            log.debug("scene field %r is not part of %s; kept as is", key, SCENE_FORMAT)
    try:
        scene = Scene.model_validate(
            {**data, "base_dir": str(base_dir) if base_dir is not None else None}
        )
    except ValidationError as exc:
        err = exc.errors()[0]
        cause = err.get("ctx", {}).get("error")
        if isinstance(cause, SceneError) and exc.error_count() == 1:
            raise cause from None  # raised by a validator of ours: it knows its field
        # Drop pydantic's union/type tags from the location.
        loc = tuple(p for p in err["loc"] if not (isinstance(p, str) and "[" in p))
        msg = err["msg"]
        if msg.startswith("Value error, "):
            msg = msg[len("Value error, ") :]
        if err.get("type") == "missing":
            msg = "required field is missing"
        if "input" in err and err.get("type") not in ("missing",):
            shown = json.dumps(err["input"], default=str)
            if len(shown) <= 60:
                msg = f"{msg} (got {shown})"
        extra = f" (+{exc.error_count() - 1} more problems)" if exc.error_count() > 1 else ""
        raise SceneError(msg + extra, _loc_to_path(loc) or None) from None
    return scene


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file.

    Raises
    ------
    SceneError
        Unreadable file, malformed JSON (with line and column), or a field breaking the
        contract.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SceneError(f"scene file not found: {p}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"cannot read scene file {p}: {exc}") from None
    try:
        data = json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise SceneError(
            f"malformed JSON in {p.name} at line {exc.lineno}, column {exc.colno}: {exc.msg}"
        ) from None
    except ValueError as exc:
        raise SceneError(f"malformed JSON in {p.name}: {exc}") from None
    return parse_scene(data, base_dir=p.resolve().parent)


def _reject_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number JSON allows")


def scene_json_schema() -> dict[str, Any]:
    """JSON Schema of the scene format (draft 2020-12, from the pydantic model)."""
    schema = Scene.model_json_schema()
    schema["properties"].pop("base_dir", None)
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = SCENE_FORMAT
    return schema
