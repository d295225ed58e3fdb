"""Collection manifests: what to render, validated by pydantic.

A manifest is a small YAML file (see ``manifests/``). :func:`load_manifest` reads
and validates it and raises :class:`ManifestError` with a one-line message naming the
offending field, so the CLI can report it without a traceback.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

LIGHT_GROUPS = ("sky_day", "sky_dusk", "sky_night", "car_lights", "street_lights", "ego_lights", "ego_high_beam")
PLATE_LIGHT_GROUPS = ("sky_day", "sky_dusk", "sky_night", "street_lights", "ego_lights", "ego_high_beam")
"""Groups that can light the background; car lamps only matter where the car is (the inset)."""


class ManifestError(ValueError):
    """A manifest could not be read or is invalid (message is one line)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class ReferenceGrid(_Strict):
    """Pixel grid of the plates and of the ground-truth boxes (covers the cameras' field of view)."""

    width_px: int = Field(ge=16, le=8192)
    height_px: int = Field(ge=9, le=4608)

    @model_validator(mode="after")
    def _aspect(self) -> "ReferenceGrid":
        if abs(self.width_px / self.height_px - 16 / 9) > 0.01:
            raise ValueError("reference_grid must have the cameras' 16:9 aspect (e.g. 480 x 270)")
        return self


class RenderSettings(_Strict):
    plate_spp: int = Field(ge=1, le=65536, description="samples per pixel of plates")
    inset_spp: int = Field(ge=1, le=65536, description="samples per pixel of insets")
    inset_pixel_mrad: float = Field(
        0.114, gt=0.0, le=10.0, description="target angular sampling of insets, mrad per pixel"
    )
    inset_max_px: int = Field(512, ge=32, le=8192, description="cap on an inset's longer side, pixels")
    max_depth: int = Field(6, ge=2, le=64, description="path length limit of the path tracer")
    variant: Literal["scalar_spectral", "llvm_ad_spectral", "cuda_ad_spectral"] = "scalar_spectral"


class IlluminanceSweep(_Strict):
    """Conditions ``<base>@<level>lux``: the base condition with its ambient group scaled
    so that the horizontal illuminance at the camera is ``level`` lux (the paper's
    luminance sweep), plus ``lamps_on`` at weight 1 (the vehicles' and the road's own
    lamps, on at every level as they would be in low light)."""

    base: str
    ambient_group: Literal[PLATE_LIGHT_GROUPS]  # type: ignore[valid-type]
    levels_lux: tuple[float, ...] = Field(min_length=1)
    lamps_on: tuple[Literal[LIGHT_GROUPS], ...] = ()  # type: ignore[valid-type]

    @field_validator("levels_lux")
    @classmethod
    def _positive(cls, v: tuple[float, ...]) -> tuple[float, ...]:
        if any(not (0 < lux < 2e5) for lux in v):
            raise ValueError("every level must lie in (0, 200000) lux")
        return v


class Manifest(_Strict):
    """A collection definition (see docs/collections.md)."""

    name: str = Field(pattern=r"^[A-Za-z0-9_.-]+$")
    protocol: str = Field(pattern=r"^[A-Za-z0-9_.-]+$")
    description: str = ""
    seed: int = Field(ge=0, le=2**63 - 1)
    environments: int = Field(ge=1, le=10000)
    distances_m: tuple[float, ...] = Field(min_length=1)
    reference_grid: ReferenceGrid
    render: RenderSettings
    light_groups: tuple[Literal[LIGHT_GROUPS], ...] = Field(min_length=1)  # type: ignore[valid-type]
    conditions: dict[str, dict[str, float]] = Field(min_length=1)
    illuminance_sweep: IlluminanceSweep | None = None

    @field_validator("distances_m")
    @classmethod
    def _distances(cls, v: tuple[float, ...]) -> tuple[float, ...]:
        if any(d < 5.0 or d > 1000.0 for d in v):
            raise ValueError("every distance must lie in [5, 1000] m")
        if list(v) != sorted(set(v)):
            raise ValueError("distances must be strictly increasing")
        return v

    @model_validator(mode="after")
    def _conditions(self) -> "Manifest":
        for name, weights in self.conditions.items():
            for group, w in weights.items():
                if group not in self.light_groups:
                    raise ValueError(
                        f"conditions.{name}.{group}: light group is not rendered "
                        f"(light_groups: {', '.join(self.light_groups)})"
                    )
                if not (w >= 0.0):
                    raise ValueError(f"conditions.{name}.{group}: weight must be >= 0, got {w}")
        sweep = self.illuminance_sweep
        if sweep is not None:
            if sweep.base not in self.conditions:
                raise ValueError(f"illuminance_sweep.base: {sweep.base!r} is not a condition")
            if self.conditions[sweep.base].get(sweep.ambient_group, 0.0) <= 0.0:
                raise ValueError(f"illuminance_sweep.ambient_group: {sweep.ambient_group!r} does not light "
                                 f"condition {sweep.base!r}")
            for group in sweep.lamps_on:
                if group not in self.light_groups or group == sweep.ambient_group:
                    raise ValueError(f"illuminance_sweep.lamps_on: {group!r} is not a rendered lamp group")
        return self

    def sha256(self) -> str:
        """Hash of the canonical JSON form: identifies what a collection was made from."""
        return canonical_sha256(self.model_dump(mode="json"))


def canonical_sha256(data) -> str:
    """sha256 of plain data's canonical JSON form (sorted keys, no spaces): the same value
    for a manifest and for its copy read back from a collection's YAML."""
    canonical = json.dumps(data, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(canonical.encode()).hexdigest()


def parse_manifest(data: object, source: str = "manifest") -> Manifest:
    """Validate an already-parsed mapping, raising :class:`ManifestError` on the first problem."""
    if not isinstance(data, dict):
        raise ManifestError(f"{source}: expected a mapping at the top level, got {type(data).__name__}")
    try:
        return Manifest.model_validate(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        where = ".".join(str(p) for p in err["loc"])
        msg = err["msg"].removeprefix("Value error, ")
        # Cross-field checks already name their fields in the message.
        raise ManifestError(f"{source}: {where}: {msg}" if where else f"{source}: {msg}") from None


def load_manifest(path: str | Path) -> Manifest:
    """Read and validate a manifest YAML file."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise ManifestError(f"{path}: cannot read manifest ({exc.strerror})") from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        raise ManifestError(f"{path}: not valid YAML{where}") from None
    return parse_manifest(data, source=str(path))
