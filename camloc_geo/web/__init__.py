"""The annotation page: a snapshot becomes a ``camloc-scene/1`` file in a browser.

One page for two uses:

- ``mode="file"`` (``camloc annotate``): a self-contained offline HTML file; **Save**
  downloads the scene file.
- ``mode="crowd"`` (the service): the same page with a **Submit** button that POSTs the
  scene JSON to ``submit_url``.

The page is plain HTML, CSS and JavaScript kept in this package (``annotate.html``,
``annotate.css``, ``annotate.js``); the snapshot is embedded as a base64 data URI, the
optional map uses the Leaflet copy the review maps inline (:mod:`camloc_geo.maps`). Nothing
on the page makes a network request, except the crowd mode's submit.

Pixel convention (as in :mod:`camloc_geo.camera`): continuous coordinates with the origin at
the image's top-left corner; the centre of the top-left pixel is ``(0.5, 0.5)``. The page's
vanishing-point and focal-length code mirrors :mod:`camloc_geo.vanishing`.
"""

from __future__ import annotations

import base64
import html
import io
import json
import os
import stat
import warnings
from importlib import resources
from pathlib import Path
from typing import Any, Literal

from camloc_geo._errors import InputError, SceneError
from camloc_geo._io import (
    HEIF_HINT,
    MIN_IMAGE_SIDE_PX,
    displayed_size,
    heif_kind,
    heif_photo,
    image_data_complete,
    magic_format,
)

__all__ = [
    "MAX_IMAGE_BYTES",
    "MAX_IMAGE_PIXELS",
    "SUPPORTED_FORMATS",
    "ImageInfo",
    "annotation_page_html",
    "read_image",
]

MAX_IMAGE_BYTES = 40 * 1024 * 1024
"""Largest snapshot file the page embeds (bytes)."""

MAX_IMAGE_PIXELS = 40_000_000
"""Largest snapshot the page accepts (width × height)."""

SUPPORTED_FORMATS = {"JPEG": "image/jpeg", "PNG": "image/png", "WEBP": "image/webp"}
"""Image formats every browser shows, with their MIME types."""

_SUPPORTED_WORDS = "JPEG, PNG or WebP"


class ImageInfo:
    """A checked snapshot: its bytes, MIME type, size and file name."""

    def __init__(self, data: bytes, mime: str, width: int, height: int, name: str) -> None:
        self.data = data
        self.mime = mime
        self.width = width
        self.height = height
        self.name = name

    def data_uri(self) -> str:
        """The image as a ``data:`` URI."""
        return f"data:{self.mime};base64," + base64.b64encode(self.data).decode("ascii")


def read_image(image: bytes | str | os.PathLike[str], *, name: str | None = None) -> ImageInfo:
    """Read and check a snapshot without decoding its pixels.

    Parameters
    ----------
    image
        The file's bytes, or its path.
    name
        File name to record in the scene's ``image.path`` (default: the path's name).

    Raises
    ------
    InputError
        Unreadable file, a format browsers cannot show, or an image larger than
        :data:`MAX_IMAGE_PIXELS` / :data:`MAX_IMAGE_BYTES`; the message says what is supported.
    """
    from PIL import Image, UnidentifiedImageError

    if isinstance(image, (bytes, bytearray)):
        data = bytes(image)
        name = name or "snapshot"
        label = "the image"
    else:
        path = Path(image)
        label = str(path)
        try:
            st = path.stat()
        except FileNotFoundError:
            raise InputError(f"image not found: {path}") from None
        except OSError as exc:
            raise InputError(f"cannot read image {path}: {exc.strerror or exc}") from None
        if not stat.S_ISREG(st.st_mode):  # a FIFO would block the read forever
            raise InputError(f"image {path} is not a regular file")
        size = st.st_size
        if size > MAX_IMAGE_BYTES:
            raise InputError(
                f"{path.name}: {size / 1e6:.0f} MB is too large; the page takes "
                f"{_SUPPORTED_WORDS} files up to {MAX_IMAGE_BYTES // 2**20} MB"
            )
        try:
            data = path.read_bytes()
        except OSError as exc:
            raise InputError(f"cannot read image {path}: {exc.strerror or exc}") from None
        name = name or path.name
    if len(data) > MAX_IMAGE_BYTES:
        raise InputError(
            f"{label}: {len(data) / 1e6:.0f} MB is too large; the page takes "
            f"{_SUPPORTED_WORDS} files up to {MAX_IMAGE_BYTES // 2**20} MB"
        )
    if not data:
        raise InputError(f"{label} is empty; the page takes {_SUPPORTED_WORDS} images")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(io.BytesIO(data)) as im:
                fmt = (im.format or "").upper()
                width, height = displayed_size(im)  # as the browser shows it
    except Image.DecompressionBombError:
        raise InputError(
            f"{label} has too many pixels; the page takes images up to "
            f"{MAX_IMAGE_PIXELS / 1e6:.0f} megapixels (scale it down first)"
        ) from None
    except (UnidentifiedImageError, OSError, ValueError):
        cut = magic_format(data[:16])
        if cut in SUPPORTED_FORMATS:  # cut off inside its header: it is one, broken
            raise InputError(f"{label} is a truncated or corrupt {cut} file") from None
        heif = heif_kind(data[:16])
        if heif is not None:  # an iPhone's photo: say so, and how to get a JPEG
            raise InputError(
                f"{label} is {heif_photo(heif)}, which the page cannot show; give a "
                f"{_SUPPORTED_WORDS} file: {HEIF_HINT}"
            ) from None
        raise InputError(
            f"{label} is not an image this page can show; give a {_SUPPORTED_WORDS} file"
        ) from None
    if fmt not in SUPPORTED_FORMATS:
        raise InputError(
            f"{label} is a {fmt or 'unknown'} image; the page takes {_SUPPORTED_WORDS} "
            "(convert it first, for example with an image editor or ImageMagick)"
        )
    if width * height > MAX_IMAGE_PIXELS:
        raise InputError(
            f"{label} is {width}x{height} pixels; the page takes images up to "
            f"{MAX_IMAGE_PIXELS / 1e6:.0f} megapixels (scale it down first)"
        )
    if min(width, height) < MIN_IMAGE_SIDE_PX:
        raise InputError(
            f"{label} is {width}x{height} pixels: too small to annotate (at least "
            f"{MIN_IMAGE_SIDE_PX} a side)"
        )
    if not image_data_complete(data, fmt):
        raise InputError(f"{label} is a truncated or corrupt {fmt} file")
    return ImageInfo(data, SUPPORTED_FORMATS[fmt], int(width), int(height), name)


def _asset(name: str) -> str:
    return resources.files(__name__).joinpath(name).read_text(encoding="utf-8")


def _json_for_script(data: Any) -> str:
    # Safe inside <script type="application/json">: no "</" can close the element.
    text = json.dumps(data, allow_nan=False, separators=(",", ":"))
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def _scene_dict(scene: Any) -> dict[str, Any]:
    from camloc_geo.scene import Scene, load_scene, parse_scene

    if isinstance(scene, Scene):
        return scene.model_dump(mode="json", exclude_none=True)
    if isinstance(scene, dict):
        parse_scene(scene)
        return json.loads(json.dumps(scene))
    if isinstance(scene, (str, os.PathLike)):
        load_scene(Path(scene))  # validates with a message naming the file and field
        data: dict[str, Any] = json.loads(Path(scene).read_text(encoding="utf-8"))
        return data
    raise SceneError(f"a scene must be a path, a dict or a Scene, not {type(scene).__name__}")


def annotation_page_html(
    image: bytes | str | os.PathLike[str],
    *,
    scene: Any = None,
    mode: Literal["file", "crowd"] = "file",
    submit_url: str | None = None,
    corners_geojson: dict[str, Any] | None = None,
    image_name: str | None = None,
    prior: tuple[float, float] | None = None,
    title: str | None = None,
    closed: str | None = None,
) -> str:
    """The annotation page as one HTML string.

    Parameters
    ----------
    image
        The snapshot (bytes or a path): JPEG, PNG or WebP, at most :data:`MAX_IMAGE_PIXELS`.
    scene
        An existing scene (path, dict or :class:`~camloc_geo.scene.Scene`) to review or
        correct. It must be for an image of the same size.
    mode
        ``"file"``: Save downloads the scene file. ``"crowd"``: Submit POSTs it (JSON) to
        ``submit_url``.
    submit_url
        Where the crowd mode posts (required with ``mode="crowd"``).
    corners_geojson
        Intersections and kerb corners (GeoJSON of :func:`camloc_geo.api.corners_near`,
        optionally with ``kind: "street"`` LineStrings): shown numbered on a small map.
    image_name
        File name recorded as ``image.path`` (default: the image path's name).
    prior
        ``(lat, lon)`` of the camera's coarse location, written as the scene's ``prior``.
    title
        Page title (default: the image name).
    closed
        Crowd mode: the task takes no more work. This line is shown over the photo from the
        start and Submit is off (an annotator used to learn it only at Submit, the work
        done).

    Returns
    -------
    The page: self-contained HTML, no remote resources.

    Raises
    ------
    InputError
        Bad image (see :func:`read_image`), a scene that does not validate or is for another
        image size, or a crowd page without ``submit_url``.
    """
    if mode not in ("file", "crowd"):
        raise InputError(f"mode must be 'file' or 'crowd', not {mode!r}")
    if mode == "crowd" and not submit_url:
        raise InputError("the crowd page needs submit_url")
    info = read_image(image, name=image_name)
    scene_data = _scene_dict(scene) if scene is not None else None
    if scene_data is not None:
        w, h = scene_data["image"]["width"], scene_data["image"]["height"]
        if (w, h) != (info.width, info.height):
            raise SceneError(
                f"the scene is for a {w}x{h} image but {info.name} is "
                f"{info.width}x{info.height}; give the snapshot the scene was made on",
                "image",
            )
    config: dict[str, Any] = {
        "mode": mode,
        "submitUrl": submit_url,
        "image": {"name": info.name, "width": info.width, "height": info.height},
        "scene": scene_data,
        "corners": corners_geojson,
        "prior": {"lat": prior[0], "lon": prior[1]} if prior else None,
        "closed": closed if mode == "crowd" else None,
    }
    has_map = bool(corners_geojson and corners_geojson.get("features"))
    leaflet = ""
    if has_map:
        from camloc_geo.maps import leaflet_assets

        assets = leaflet_assets()
        leaflet = (
            "<style>"
            + assets["leaflet_css"]
            + "</style>\n<script>"
            + assets["leaflet_js"]
            # "</script" cannot occur: maps.leaflet_assets checked it.
            + "</script>"
        )
    page = _asset("annotate.html")
    connect = "'none'"
    if mode == "crowd" and submit_url:
        from urllib.parse import urlsplit

        parts = urlsplit(submit_url)
        connect = "'self'" + (f" {parts.scheme}://{parts.netloc}" if parts.netloc else "")
    page = page.replace("CAMLOC_CONNECT_SRC", connect, 1)
    replacements = {
        "<!--camloc:title-->": html.escape(title or f"Annotate {info.name}"),
        "<!--camloc:css-->": "<style>" + _asset("annotate.css") + "</style>",
        "<!--camloc:leaflet-->": leaflet,
        "<!--camloc:config-->": (
            '<script id="camloc-config" type="application/json">'
            + _json_for_script(config)
            + "</script>"
        ),
        "<!--camloc:image-->": (
            '<script id="camloc-image" type="text/plain">' + info.data_uri() + "</script>"
        ),
        "<!--camloc:js-->": "<script>" + _asset("annotate.js") + "</script>",
        "<!--camloc:ground-corner-->": _asset("ground-corner.svg"),
    }
    for key, value in replacements.items():
        page = page.replace(key, value, 1)
    return page
