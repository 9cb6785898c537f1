"""Service settings, read from ``CAMLOC_*`` environment variables (pydantic-settings)."""

from __future__ import annotations

from pathlib import Path

from pydantic import Field, SecretStr, field_validator
from pydantic_settings import BaseSettings, SettingsConfigDict

__all__ = ["Settings", "default_data_dir"]


def default_data_dir() -> Path:
    """The user's data folder for the service (``~/.local/share/camloc/service`` on Linux)."""
    from platformdirs import user_data_path

    return user_data_path("camloc", appauthor=False) / "service"


class Settings(BaseSettings):
    """The service's configuration; each field is ``CAMLOC_<NAME>`` in the environment.

    Map data comes from here only: a folder of extracts (``CAMLOC_MAP_DIR``) and, when
    ``CAMLOC_NETWORK`` is true, Overpass with an HTTP cache. Clients never name server files.
    """

    model_config = SettingsConfigDict(env_prefix="CAMLOC_", extra="ignore")

    map_dir: Path | None = Field(
        default=None, description="folder of OSM extracts (.osm, .osm.gz, .osm.bz2, .osm.pbf)"
    )
    network: bool = Field(
        default=False, description="query Overpass where no extract covers a point"
    )
    cache_folder: Path | None = Field(
        default=None, description="osmnx HTTP cache folder for Overpass"
    )
    overpass_url: str | None = Field(default=None, description="Overpass API endpoint")
    api_key: SecretStr | None = Field(
        default=None,
        description="when set, write endpoints need the header X-API-Key with this value",
    )
    data_dir: Path = Field(
        default_factory=default_data_dir,
        description=(
            "folder for the job and task database (SQLite) and uploaded snapshots (default: "
            "the user's data folder, e.g. ~/.local/share/camloc/service)"
        ),
    )
    verdict_dir: Path | None = Field(
        default=None,
        description=(
            "folder of the reviewers' shared verdicts (camloc-verdicts.sqlite; default: "
            "data_dir); camloc serve --verdict-dir sets it"
        ),
    )
    max_verdicts: int = Field(
        default=1_000_000, ge=1, description="most verdicts kept over all review pages"
    )
    max_request_bytes: int = Field(
        default=2_000_000, ge=1_000, description="largest JSON body accepted"
    )
    max_upload_bytes: int = Field(
        default=12_000_000, ge=1_000, description="largest snapshot upload accepted (bytes)"
    )
    max_upload_pixels: int = Field(
        default=40_000_000, ge=1, description="largest snapshot accepted (width × height)"
    )
    max_annotations: int = Field(default=50, ge=1, description="most annotators in one scene")
    max_lines_per_axis: int = Field(
        default=100, ge=2, description="most vp_lines per axis per annotator"
    )
    max_references: int = Field(default=50, ge=1, description="most references in one scene")
    max_cameras_per_job: int = Field(default=10_000, ge=1, description="most cameras in one job")
    workers: int = Field(
        default=0,
        ge=0,
        le=256,
        description=(
            "worker processes for the CPU work, each with its own maps (0: threads of the "
            "serving process); camloc serve --workers sets it"
        ),
    )
    request_timeout_s: float = Field(
        default=20.0, gt=0, description="processing time limit of one request (seconds)"
    )
    annotations_per_task: int = Field(
        default=3, ge=1, le=50, description="default annotations collected before a task is located"
    )
    max_radius_m: float = Field(default=2_000.0, gt=0, description="largest corners/streets radius")
    tile_url: str | None = Field(
        default=None,
        description=(
            "basemap tile URL template (https://.../{z}/{x}/{y}.png) under a job's summary "
            "page; none (default): no basemap, the page makes no request of its own"
        ),
    )
    tile_attribution: str | None = Field(
        default=None,
        max_length=300,
        description="the basemap's attribution, plain text (default: 'basemap: <host>')",
    )

    cors_origins: str | None = Field(
        default=None,
        description=(
            "origins (comma-separated: https://review.example.org, http://localhost:8080, "
            "null for pages opened from files) whose pages may read and change verdicts "
            "(/v1/verdicts) from another origin; none (default): no CORS"
        ),
    )

    @property
    def cors_origin_list(self) -> list[str]:
        """``cors_origins`` as a list (empty: no CORS)."""
        return [o.strip() for o in (self.cors_origins or "").split(",") if o.strip()]

    @field_validator("cors_origins")
    @classmethod
    def _origins(cls, value: str | None) -> str | None:
        import re

        if value is None:
            return None
        origins = [o.strip() for o in value.split(",") if o.strip()]
        for origin in origins:
            if origin == "*":
                raise ValueError(
                    "CAMLOC_CORS_ORIGINS: name the origins, '*' is not taken "
                    "(e.g. https://review.example.org)"
                )
            if origin != "null" and not re.fullmatch(
                r"https?://[A-Za-z0-9.\-]+(:[0-9]{1,5})?|https?://\[[0-9A-Fa-f:.]+\](:[0-9]{1,5})?",
                origin,
            ):
                raise ValueError(
                    f"CAMLOC_CORS_ORIGINS: {origin!r} is not an origin (scheme://host[:port], "
                    "no path, no trailing slash; or null for pages opened from files)"
                )
        return ",".join(origins) or None

    @field_validator("tile_url")
    @classmethod
    def _tile_template(cls, value: str | None) -> str | None:
        if value is None or not value.strip():
            return None
        value = value.strip()
        if not value.startswith(("https://", "http://")):
            raise ValueError(f"CAMLOC_TILE_URL must start with https:// or http:// (got {value!r})")
        missing = [p for p in ("{z}", "{x}", "{y}") if p not in value]
        if missing:
            raise ValueError(
                f"CAMLOC_TILE_URL needs the placeholders {{z}}, {{x}} and {{y}} "
                f"(missing {', '.join(missing)} in {value!r})"
            )
        if len(value) > 2000 or any(c in value for c in "\"'<>` \\"):
            raise ValueError(f"CAMLOC_TILE_URL is not a URL template: {value!r}")
        return value
