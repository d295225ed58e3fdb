"""Collection manifests: what to render, validated by pydantic.

A manifest is a small YAML file (see ``manifests/``). :func:`load_manifest` reads
and validates it and raises :class:`ManifestError` with a one-line message naming the
offending field, so the CLI can report it without a traceback.

A manifest is validated as a whole before anything is written: UTF-8 YAML without
duplicate keys, strict types (``environments: true`` or ``seed: "5"`` are refused, not
coerced), finite numbers, lists without repeats, condition names that can name a folder
and do not use the ``<base>@<level>lux`` form reserved for the illuminance sweep, and
(:func:`check_memory`, at ``generate``) a render that fits in memory.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
from pathlib import Path
from typing import Annotated, ClassVar, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, Strict, ValidationError, field_validator, model_validator

from metricscenes.files import read_text_capped

LIGHT_GROUPS = ("sky_day", "sky_dusk", "sky_night", "car_lights", "street_lights", "ego_lights", "ego_high_beam")
PLATE_LIGHT_GROUPS = ("sky_day", "sky_dusk", "sky_night", "street_lights", "ego_lights", "ego_high_beam")
"""Groups that can light the background; car lamps only matter where the car is (the inset)."""


MAX_WEIGHT = 1e6
"""Largest light-group weight of a condition (a weight of 1e300 would overflow float32 radiance)."""
CAR_CLEARANCE_M = 20.0
"""Road a car needs ahead of the camera beyond its distance: its own length (at most 5.5 m in the
library) and road seen behind it, so that no car stands at the detailed road's end."""
MAX_MANIFEST_BYTES = 1 << 20
CONDITION_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")
"""A condition name becomes a folder name (``benchmark sweep``): no ``/``, no ``@`` (the
illuminance sweep's ``<base>@<level>lux`` names are reserved), no leading dot, no ``..``."""

# What one render process needs: the interpreter, Mitsuba and the scene (~0.35 GiB,
# measured), plus ~500 bytes per pixel of the largest film (31 float32 bands held about
# four times: Mitsuba's image block, the developed film, the NumPy copy, the zarr write;
# measured 580 B/px at 1920x1080, 500 B/px between 960x540 and 1920x1080).
PROCESS_BASE_BYTES = 400 * 2**20
BYTES_PER_FILM_PIXEL = 512
# A JIT variant (LLVM, CUDA) adds its wavefront's state: ~450 bytes a lane (path; measured with
# llvm_ad_spectral: quick's 18.7 M-lane plate peaked at 7.5 GB), so a metric-300 plate (1920 x
# 1080 x 36: 75 M lanes) traced whole would need about 30 GB. metricscenes.lightgroups traces a
# larger window in bands of whole rows of at most MAX_WAVEFRONT_LANES lanes (metric-300 peaked
# at 7.9 GiB). Fixed, not taken from the machine's memory: the bands' seeds are part of what is
# rendered, so every machine renders the same bytes. ``auto`` may resolve to a JIT variant, so
# it is counted too.
BYTES_PER_WAVEFRONT_LANE = 450
MAX_WAVEFRONT_LANES = 2**24
MEMORY_LIMIT_ENV = "METRICSCENES_MAX_MEMORY_GIB"

# Numbers: ints must be ints (not bools, floats or strings), floats may be ints but not
# bools or strings, and no NaN or infinity anywhere (model_config allow_inf_nan=False).
Int = Annotated[int, Strict()]
Float = Annotated[float, Strict()]


class ManifestError(ValueError):
    """A manifest could not be read or is invalid (message is one line)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


def _unique(values, what: str):
    from collections import Counter

    repeated = sorted(repr(v) for v, n in Counter(values).items() if n > 1)
    if repeated:
        raise ValueError(f"{what} must not repeat: {', '.join(repeated)}")
    return values


class ReferenceGrid(_Strict):
    """Pixel grid of the plates and of the ground-truth boxes, and the field it covers:
    the reference field (34.3° x 19.6°, the paper's 13 cameras) unless ``hfov_deg`` sets
    another horizontal field (the vertical one follows the grid's aspect)."""

    _name: ClassVar[str] = "reference_grid"
    width_px: Int = Field(ge=16, le=8192)
    height_px: Int = Field(ge=9, le=4608)
    hfov_deg: Float | None = Field(
        None, ge=5.0, le=150.0, description="horizontal field of view, degrees (default: the reference field)")

    @model_validator(mode="after")
    def _aspect(self) -> "ReferenceGrid":
        aspect = self.width_px / self.height_px
        if self.hfov_deg is None and abs(aspect - 16 / 9) > 0.01:
            raise ValueError("reference_grid must have the reference field's 16:9 aspect (e.g. 480 x 270) "
                             "unless it sets hfov_deg")
        if not 1.0 <= aspect <= 4.0:
            raise ValueError(f"{self._name} aspect {aspect:.3g} must lie between 1 and 4")
        return self

    @property
    def field(self):
        """The field the grid covers, in tangent coordinates (:class:`~metricscenes.geometry.TanExtent`)."""
        from metricscenes.geometry import field_extent

        return field_extent(self.hfov_deg, self.width_px, self.height_px)


WIDE_KINDS = ("wide_plates", "wide_frames")
"""The store's arrays of a manifest's ``wide_plate``: its plates (``wide_plates/<env>/<group>``)
and the car lamps' frames on its grid (``wide_frames/<scene>/car_lights``)."""


class WidePlate(ReferenceGrid):
    """A second, coarser plate around the reference grid's field, for cameras wider than it
    (docs/scenes.md, "The wide plate"): ``hfov_deg`` horizontally, the vertical field from the
    grid's aspect, rendered once per environment and light group at ``spp`` samples per pixel.
    A camera inside the reference field never reads it; a wider one sees the reference plate
    (and the car's inset) composited over it at its own sampling."""

    _name: ClassVar[str] = "wide_plate"
    hfov_deg: Float = Field(ge=5.0, le=150.0, description="horizontal field of view, degrees")
    spp: Int = Field(ge=1, le=65536, description="samples per pixel")

    @field_validator("spp")
    @classmethod
    def _square(cls, value: int) -> int:
        return RenderSettings._square(value)


AUTO_VARIANT = "auto"
"""``render.variant`` that lets the machine choose (:func:`metricscenes.render.resolve_variant`)."""


class RenderSettings(_Strict):
    plate_spp: Int = Field(ge=1, le=65536, description="samples per pixel of plates")
    inset_spp: Int = Field(ge=1, le=65536, description="samples per pixel of insets")
    inset_pixel_mrad: Float = Field(
        0.114, gt=0.0, le=10.0, description="target angular sampling of insets, mrad per pixel"
    )
    inset_max_px: Int = Field(512, ge=32, le=8192, description="cap on an inset's longer side, pixels")
    max_depth: Int = Field(6, ge=2, le=64, description="path length limit of the path tracer")
    inset_feather: Float | None = Field(
        None, gt=0.0, le=0.1, description="share of an inset's size over which, along its edges, it blends "
        "linearly into the plate; the window grows by it, outside the car's margins (unset: a hard edge); see "
        "metricscenes.radiance.feather_weights and metricscenes.generate.inset_window")
    ground_to_horizon: bool | None = Field(
        None, description="close the gap between the far ground's edge and the camera's horizontal (unset: "
        "open, a black line 0.078 mrad tall); see metricscenes.assets.roads.horizon_edge")
    frame_divisor: Int | None = Field(
        None, ge=2, le=8, description="render the car lamps' whole frame (frames/<scene>/car_lights) on a grid this "
        "many times coarser than the plates' (unset: the plates' grid); the reader interpolates it onto the plate's "
        "grid. The beams' footprint on the road is smooth and the lamps themselves are in the inset; see "
        "docs/performance.md, 'Car-lamp frames'")
    plate_lamp: bool | None = Field(
        None, description="light the car's rear registration plate at UN ECE R4's minimum luminance (2.5 cd/m² on a "
        "white diffuser; a W5W lamp's spectrum) in light group car_lights (unset: an unlit plate); see "
        "metricscenes.assets.lamps.plate_lamp")
    rear_retroreflectors: bool | None = Field(
        None, description="give the car its two red rear retro-reflectors (UN ECE R3 class IA), returning the ego low "
        "beams' light to the camera in light group ego_lights (unset: none); see metricscenes.assets.retroreflection")
    inset_shadow: bool | None = Field(
        None, description="grow each inset's window over the car's shadow on the road, cast by the sun or moon of each "
        "rendered sky that has one above the horizon (the plate has no car, so a shadow outside the window is "
        "lost; unset: the car's box and margins only); see metricscenes.generate.inset_window and docs/scenes.md, "
        "'The car's shadow'")
    road_end_m: Float | None = Field(
        None, ge=395.0, le=5000.0, description="where the detailed road ends ahead of the camera, metres: its "
        "paving, markings, terrain tiles, trees and street lights (unset: 395 m, the least); beyond it the plain "
        "far road and ground; see metricscenes.assets.roads.road_parts. Every distance must leave the car on it "
        "(Manifest.detailed_road_end_m)")
    # "auto": cuda_ad_spectral where a CUDA device is usable, else llvm_ad_spectral where a libLLVM >= 17
    # renders, else scalar_spectral (metricscenes.render.resolve_variant; the variant used is recorded in
    # manifest.resolved.yaml). Not the default: the default is part of every manifest's sha256.
    variant: Literal["scalar_spectral", "llvm_ad_spectral", "cuda_ad_spectral", "auto"] = "scalar_spectral"

    @field_validator("plate_spp", "inset_spp")
    @classmethod
    def _square(cls, value: int) -> int:
        # Mitsuba's stratified sampler rounds any other count up to a square (32 -> 36), so the
        # renders would not have the samples recorded for them.
        root = math.isqrt(value)
        if root**2 != value:
            raise ValueError(f"must be a square (the stratified sampler rounds {value} to {(root + 1) ** 2}): "
                             f"e.g. {root ** 2} or {(root + 1) ** 2}")
        return value


_ILLUMINANCE_CONDITION = re.compile(r"(?P<base>[^@]+)@(?P<lux>[0-9.eE+-]+)lux")


def illuminance_condition(base: str, lux: float) -> str:
    """The name of an illuminance-sweep condition: ``("day", 0.25)`` → ``"day@0.25lux"``."""
    return f"{base}@{lux:g}lux"


def parse_illuminance_condition(condition: str) -> tuple[str, float] | None:
    """Inverse of :func:`illuminance_condition`: ``"day@0.25lux"`` → ``("day", 0.25)``;
    None for any other name."""
    match = _ILLUMINANCE_CONDITION.fullmatch(str(condition))
    return (match["base"], float(match["lux"])) if match else None


class StoreSettings(_Strict):
    """How radiance is stored (``metricscenes.writer.UnitArrays.write_radiance``). Without ``store``
    every value is stored exactly (lossless)."""

    mantissa_bits: Int | None = Field(
        None, ge=1, le=22, description="float32 mantissa bits kept (of 23), rounded to nearest (BitRound): relative "
        "error at most 2^-(mantissa_bits+1); see docs/performance.md, 'Store size', for the width to choose")
    spectral_basis: Int | None = Field(
        None, ge=5, le=31, description="K: each radiance array stored as K coefficients per pixel on K basis "
        "spectra that hold the IMX363's R, G, B channels and CIE Y exactly (metricscenes.spectral_basis); "
        "see docs/performance.md, 'A spectral basis per array'")

    @model_validator(mode="after")
    def _says_something(self):
        if self.mantissa_bits is None and self.spectral_basis is None:
            raise ValueError("set mantissa_bits and/or spectral_basis, or leave store out (lossless, 31 bands)")
        return self


class IlluminanceSweep(_Strict):
    """Conditions ``<base>@<level>lux``: the base condition with its ambient group scaled
    so that the horizontal illuminance at the camera is ``level`` lux (the paper's
    luminance sweep), plus ``lamps_on`` at weight 1 (the vehicles' and the road's own
    lamps, on at every level as they would be in low light)."""

    base: str
    ambient_group: Literal[PLATE_LIGHT_GROUPS]  # type: ignore[valid-type]
    levels_lux: tuple[Float, ...] = Field(min_length=1)
    lamps_on: tuple[Literal[LIGHT_GROUPS], ...] = ()  # type: ignore[valid-type]

    @field_validator("levels_lux")
    @classmethod
    def _positive(cls, v: tuple[float, ...]) -> tuple[float, ...]:
        if any(not (0 < lux < 2e5) for lux in v):
            raise ValueError("every level must lie in (0, 200000) lux")
        # Each level names a condition '<base>@<level:g>lux': 1 and 1.0000001 would be one name.
        _unique([f"{lux:g}" for lux in v], "levels (as condition names)")
        return v

    @field_validator("lamps_on")
    @classmethod
    def _lamps_unique(cls, v: tuple[str, ...]) -> tuple[str, ...]:
        return _unique(v, "light groups")


TARGET_AT = ("reference_lens", "camera")
"""Where a targeted condition meets its target: the image plane of an ideal lens at
``f_number`` (the default), or each camera's own optical image, the f-number and any lens
transmittance taken out as ISETCam's ``oiAdjustIlluminance`` does (the paper's lab)."""
SCALES = ("ambient", "mix")
"""What a targeted condition scales to its target: the ambient group, the lamps at their
fixed weights (the default), or the whole mix, lamps included, its groups' weights fixed
relative to one another (the paper's lab: isetauto ``iaLightsGroup.m``)."""
TARGETED_KEYS = ("ambient", "mix", "scales", "target_at", "same_targets_as", "target_image_plane_lux")


class TargetedCondition(_Strict):
    """A condition set by its mean image-plane illuminance, drawn per environment
    log-uniformly from ``target_image_plane_lux`` (:mod:`metricscenes.targets`). Two knobs:
    ``scales`` (``ambient``: the ambient group scaled under lamps at fixed weights; ``mix``:
    the groups of ``mix`` scaled together) and ``target_at`` (``reference_lens``: an ideal lens
    at ``f_number``; ``camera``: each camera's own optical image)."""

    ambient: Literal[PLATE_LIGHT_GROUPS] | None = None  # type: ignore[valid-type]
    lamps: dict[str, Float] = {}
    target_image_plane_lux: tuple[Float, Float]
    f_number: Float | None = Field(2.4, gt=0.5, lt=64.0)  # the reference lens's (None: target_at: camera)
    # Added after manifests were published: None (the defaults, ``scales: ambient`` and
    # ``target_at: reference_lens``) is left out of the manifest's hash (:func:`manifest_sha256`).
    scales: Literal[SCALES] | None = None  # type: ignore[valid-type]
    mix: dict[str, Float] | None = None
    target_at: Literal[TARGET_AT] | None = None  # type: ignore[valid-type]
    same_targets_as: str | None = None
    """Draw each environment's target as this condition does (the same seed, so the two are
    paired: a comparison between them is not one of target draws)."""

    @field_validator("target_image_plane_lux")
    @classmethod
    def _range(cls, v: tuple[float, float]) -> tuple[float, float]:
        lo, hi = v
        if not (0.0 < lo <= hi < 2e5):
            raise ValueError(f"target_image_plane_lux: [{lo:g}, {hi:g}] must be a range of lux with "
                             "0 < low <= high < 200000")
        return v

    @field_validator("lamps", "mix")
    @classmethod
    def _lamp_weights(cls, v: dict[str, float] | None, info) -> dict[str, float] | None:
        for group, w in (v or {}).items():
            if not (0.0 <= w <= MAX_WEIGHT):
                raise ValueError(f"{info.field_name}.{group}: weight must lie in [0, {MAX_WEIGHT:g}], got {w}")
        return v

    @model_validator(mode="before")
    @classmethod
    def _lens(cls, data):
        # A target at each camera's image plane has no reference lens: f_number is refused, and
        # held as None (so the condition's JSON form reads back as it was written).
        if isinstance(data, dict) and data.get("target_at") == "camera":
            if data.get("f_number") is not None:
                raise ValueError("f_number is the reference lens's: target_at: camera meets the target at each "
                                 "camera's own image plane, through its own f-number and transmittance")
            return {**data, "f_number": None}
        if isinstance(data, dict) and "f_number" in data and data["f_number"] is None:
            return {k: v for k, v in data.items() if k != "f_number"}
        return data

    @model_validator(mode="after")
    def _knobs(self) -> "TargetedCondition":
        # What makes no sense is refused here, before anything is read.
        if self.scales_mix:
            if self.ambient is not None or self.lamps:
                raise ValueError("scales: mix scales every group of mix together: give their fixed weights in mix, "
                                 "not ambient or lamps")
            if not self.mix or not any(self.mix.values()):
                raise ValueError("scales: mix needs mix: {light group: weight, ...} with a weight > 0")
        else:
            if self.mix is not None:
                raise ValueError("mix is the groups scales: mix scales together; scaling the ambient group "
                                 "(scales: ambient) takes ambient and lamps")
            if self.ambient is None:
                raise ValueError("a target needs an ambient group to scale (ambient: <light group>), or "
                                 "scales: mix and a mix to scale whole")
        return self

    @property
    def scales_mix(self) -> bool:
        return self.scales == "mix"

    @property
    def at_camera(self) -> bool:
        return self.target_at == "camera"

    def groups(self) -> tuple[str, ...]:
        return tuple(self.mix) if self.scales_mix else (self.ambient, *self.lamps)

    def parts(self) -> dict[str, dict[str, float]]:
        """The mixes whose image-plane illuminances set the weights, each with its fixed
        weights (groups at weight 0 left out): ``ambient`` (the ambient group at 1) and
        ``lamps``, or ``mix``."""
        if self.scales_mix:
            return {"mix": {g: w for g, w in self.mix.items() if w != 0.0}}
        return {"ambient": {self.ambient: 1.0}, "lamps": {g: w for g, w in self.lamps.items() if w != 0.0}}

    def identity(self) -> dict:
        """What defines the condition, as the hash reads it (the unset knobs left out)."""
        return _without_unset_knobs(self.model_dump(mode="json"))


def _without_unset_knobs(spec: dict) -> dict:
    """A targeted condition's JSON form without the knobs added later where they are unset."""
    return {k: v for k, v in spec.items() if not (k in ADDED_TARGETED_KNOBS and v is None)}


ADDED_TARGETED_KNOBS = ("ambient", "scales", "mix", "target_at", "same_targets_as")


def _targeted(name: str, value, section: str = "conditions"):
    """A condition given as a mapping with a target becomes a :class:`TargetedCondition`;
    its errors name the condition, in one line."""
    if not (isinstance(value, dict) and set(TARGETED_KEYS) & set(value)):
        return value
    if "target_image_plane_lux" not in value:
        given = next(k for k in TARGETED_KEYS if k in value)
        what = "an ambient group" if given == "ambient" else given
        raise ValueError(f"{section}.{name}: {what} needs target_image_plane_lux: [low, high]")
    if value.get("scales") != "mix" and value.get("ambient") is None:
        raise ValueError(f"{section}.{name}.ambient: a target needs an ambient group to scale (ambient: <light "
                         "group>), or scales: mix and a mix to scale whole")
    try:
        return TargetedCondition.model_validate(value)
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(p) for p in first["loc"])
        msg = first["msg"].removeprefix("Value error, ")
        raise ValueError(f"{section}.{name}{'.' + where if where else ''}: {msg}") from None


class Manifest(_Strict):
    """A collection definition (see docs/scenes.md, "The protocol")."""

    name: str = Field(pattern=r"^[A-Za-z0-9_.-]+$")
    protocol: str = Field(pattern=r"^[A-Za-z0-9_.-]+$")
    description: str = ""
    seed: Int = Field(ge=0, le=2**63 - 1)
    environments: Int = Field(ge=1, le=10000)
    distances_m: tuple[Float, ...] = Field(min_length=1)
    reference_grid: ReferenceGrid
    render: RenderSettings
    light_groups: tuple[Literal[LIGHT_GROUPS], ...] = Field(min_length=1)  # type: ignore[valid-type]
    conditions: dict[str, dict[str, Float] | TargetedCondition] = Field(min_length=1)
    illuminance_sweep: IlluminanceSweep | None = None
    store: StoreSettings | None = None
    wide_plate: WidePlate | None = None
    read_time_conditions: dict[str, dict[str, Float] | TargetedCondition] | None = None
    """Conditions outside the manifest's identity: mixed at read time from the stored groups
    like every condition, but left out of its sha256, so that adding one changes no hash that
    collections, results and submissions are keyed by (their definitions enter the cache keys
    of the runs that use them instead: ``benchmark.experiments.keys.capture_key``). Listed
    after the conditions and the illuminance sweep's; the same rules, names not repeated."""

    @field_validator("light_groups")
    @classmethod
    def _groups_unique(cls, v: tuple[str, ...]) -> tuple[str, ...]:
        return _unique(v, "light groups")

    @field_validator("conditions", "read_time_conditions", mode="before")
    @classmethod
    def _targeted_conditions(cls, v, info):
        return ({name: _targeted(name, value, info.field_name) for name, value in v.items()}
                if isinstance(v, dict) else v)

    @field_validator("conditions", "read_time_conditions")
    @classmethod
    def _condition_names(cls, v: dict[str, dict[str, float]] | None) -> dict[str, dict[str, float]] | None:
        for name in v or {}:
            if "@" in name:
                raise ValueError(f"condition name {name!r}: '@' is reserved for the illuminance sweep's "
                                 "conditions (<base>@<level>lux)")
            if not CONDITION_NAME.fullmatch(name) or ".." in name or len(name) > 64:
                raise ValueError(f"condition name {name!r} must be 1-64 letters, digits, '_', '-' or '.' "
                                 "(not first), without '..'")
        return v

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
        read_time = self.read_time_conditions or {}
        both = [n for n in read_time if n in self.conditions]
        if both:
            raise ValueError(f"read_time_conditions.{both[0]}: already a condition")
        every = {**self.conditions, **read_time}
        for section, conditions in (("conditions", self.conditions), ("read_time_conditions", read_time)):
            for name, weights in conditions.items():
                self._check_condition(f"{section}.{name}", name, weights, every)
        sweep = self.illuminance_sweep
        if sweep is not None:
            if sweep.base not in self.conditions:
                raise ValueError(f"illuminance_sweep.base: {sweep.base!r} is not a condition")
            if isinstance(self.conditions[sweep.base], TargetedCondition):
                raise ValueError(f"illuminance_sweep.base: {sweep.base!r} is a targeted condition (give fixed weights)")
            if self.conditions[sweep.base].get(sweep.ambient_group, 0.0) <= 0.0:
                raise ValueError(f"illuminance_sweep.ambient_group: {sweep.ambient_group!r} does not light "
                                 f"condition {sweep.base!r}")
            for group in sweep.lamps_on:
                if group not in self.light_groups or group == sweep.ambient_group:
                    raise ValueError(f"illuminance_sweep.lamps_on: {group!r} is not a rendered lamp group")
        return self

    def _check_condition(self, where: str, name: str, weights, every: dict) -> None:
        if isinstance(weights, TargetedCondition):
            for group in weights.groups():
                if group not in self.light_groups:
                    raise ValueError(f"{where}: light group {group!r} is not rendered "
                                     f"(light_groups: {', '.join(self.light_groups)})")
            if weights.ambient in weights.lamps:
                raise ValueError(f"{where}: {weights.ambient!r} is the ambient group and a lamp")
            paired = weights.same_targets_as
            if paired is not None and (paired == name or not isinstance(every.get(paired), TargetedCondition)):
                raise ValueError(f"{where}.same_targets_as: {paired!r} is not another targeted condition")
            return
        for group, w in weights.items():
            if group not in self.light_groups:
                raise ValueError(f"{where}.{group}: light group is not rendered "
                                 f"(light_groups: {', '.join(self.light_groups)})")
            if not (0.0 <= w <= MAX_WEIGHT):
                raise ValueError(f"{where}.{group}: weight must lie in [0, {MAX_WEIGHT:g}], got {w}")
        if not any(weights.values()):
            raise ValueError(f"{where}: lights nothing (give at least one light group a weight > 0)")

    @model_validator(mode="after")
    def _scene_holds(self) -> "Manifest":
        from metricscenes.geometry import extent_within

        road_end = self.detailed_road_end_m
        farthest = max(self.distances_m)
        if farthest + CAR_CLEARANCE_M > road_end:
            raise ValueError(f"distances_m: a car at {farthest:g} m stands beyond the detailed road, which ends at "
                             f"{road_end:g} m (it needs {CAR_CLEARANCE_M:g} m more): set render.road_end_m to at "
                             f"least {farthest + CAR_CLEARANCE_M:g}")
        wide, grid = self.wide_plate, self.reference_grid
        if wide is not None and not (extent_within(grid.field, wide.field) and wide.field != grid.field):
            from metricscenes.geometry import fov_deg

            (gh, gv), (wh, wv) = fov_deg(grid.field), fov_deg(wide.field)
            raise ValueError(f"wide_plate: its field {wh:.2f}° x {wv:.2f}° must hold the reference grid's "
                             f"{gh:.2f}° x {gv:.2f}° and be wider")
        return self

    @model_validator(mode="after")
    def _frame_grid(self) -> "Manifest":
        divisor = self.render.frame_divisor
        for name, grid in (("reference grid", self.reference_grid), ("wide plate", self.wide_plate)):
            if divisor is not None and grid is not None and (grid.width_px % divisor or grid.height_px % divisor):
                raise ValueError(f"render.frame_divisor: {divisor} must divide the {name} "
                                 f"({grid.width_px} x {grid.height_px} px)")
        return self

    @property
    def condition_names(self) -> list[str]:
        """The conditions, then the illuminance sweep's (``day@0.25lux``, ...), then the
        read-time conditions."""
        sweep = self.illuminance_sweep
        levels = [illuminance_condition(sweep.base, lux) for lux in sweep.levels_lux] if sweep else []
        return list(self.conditions) + levels + list(self.read_time_conditions or {})

    def condition_spec(self, condition: str):
        """A named condition's definition (weights or :class:`TargetedCondition`), from
        ``conditions`` or ``read_time_conditions``; None for a sweep level or no condition."""
        spec = self.conditions.get(condition)
        return spec if spec is not None else (self.read_time_conditions or {}).get(condition)

    def is_read_time(self, condition: str) -> bool:
        """Whether ``condition`` is one of ``read_time_conditions`` (outside the manifest's hash)."""
        return condition in (self.read_time_conditions or {})

    def condition_light_groups(self, condition: str) -> tuple[str, ...]:
        """The light groups ``condition`` mixes, in ``light_groups``' order: those a condition
        weights above 0 (a group at weight 0 adds nothing), a targeted condition's ambient
        group and lamps, an illuminance-sweep level's base groups with its ambient group and
        ``lamps_on``. :class:`ManifestError` for a name that is no condition."""
        if condition not in self.condition_names:
            raise ManifestError(f"unknown condition {condition!r} (manifest {self.name} has: "
                                f"{', '.join(self.condition_names)})")
        sweep = self.illuminance_sweep
        spec = self.condition_spec(condition) or self.conditions[sweep.base]
        if isinstance(spec, TargetedCondition):
            mixed = {g for part in spec.parts().values() for g in part} | ({spec.ambient} - {None})
        else:
            mixed = {g for g, w in spec.items() if w != 0.0}
        if self.condition_spec(condition) is None:  # a sweep level
            mixed |= {sweep.ambient_group, *sweep.lamps_on}
        return tuple(g for g in self.light_groups if g in mixed)

    @property
    def detailed_road_end_m(self) -> float:
        """Where the detailed road ends ahead: ``render.road_end_m``, or the default road's end."""
        from metricscenes.assets.roads import ROAD_X_RANGE_M

        return self.render.road_end_m or ROAD_X_RANGE_M[1]

    def frame_grid_px(self) -> tuple[int, int]:
        """(width, height) of the car lamps' whole frame: the reference grid, or it divided
        by ``render.frame_divisor``."""
        return self._frame_of(self.reference_grid)

    def wide_frame_grid_px(self) -> tuple[int, int]:
        """(width, height) of the car lamps' frame on the wide plate's field: its grid, or it
        divided by ``render.frame_divisor``."""
        return self._frame_of(self.wide_plate)

    def _frame_of(self, grid: ReferenceGrid) -> tuple[int, int]:
        divisor = self.render.frame_divisor or 1
        return grid.width_px // divisor, grid.height_px // divisor

    def sha256(self) -> str:
        """Hash of the canonical JSON form: identifies what a collection was made from."""
        return manifest_sha256(self.model_dump(mode="json"))

    def largest_film_px(self) -> int:
        """Upper bound on the pixels of the largest film a unit renders: a plate (or a
        car-lamp frame) on the reference grid, or an inset: a crop of the reference film
        k times finer (k at most what ``inset_pixel_mrad`` asks for) whose longer side is
        at most ``inset_max_px`` (plus rounding), unless k = 1 (see ``generate.inset_window``)."""
        import math

        w, h = self.reference_grid.width_px, self.reference_grid.height_px
        k_fine = math.ceil(1e3 * self.reference_grid.field.width / w / self.render.inset_pixel_mrad)
        inset = min((self.render.inset_max_px + 2) ** 2, w * h * k_fine**2)
        wide = 0 if self.wide_plate is None else self.wide_plate.width_px * self.wide_plate.height_px
        return max(w * h, inset, wide)

    def memory_estimate_bytes(self) -> int:
        """Upper estimate of one render process's peak memory (see PROCESS_BASE_BYTES), with
        the wavefront of a JIT variant (or of ``auto``) traced in bands of at most
        ``MAX_WAVEFRONT_LANES`` lanes (see BYTES_PER_WAVEFRONT_LANE)."""
        films = PROCESS_BASE_BYTES + BYTES_PER_FILM_PIXEL * self.largest_film_px()
        if self.render.variant == "scalar_spectral":
            return films
        spp = max(self.render.plate_spp, self.render.inset_spp, self.wide_plate.spp if self.wide_plate else 1)
        return films + BYTES_PER_WAVEFRONT_LANE * min(self.largest_film_px() * spp, MAX_WAVEFRONT_LANES)


def memory_limit_bytes() -> tuple[int, str]:
    """(limit, where it comes from): ``METRICSCENES_MAX_MEMORY_GIB`` if set, else 80 % of
    this machine's physical memory."""
    value = os.environ.get(MEMORY_LIMIT_ENV)
    if value is not None:
        try:
            gib = float(value)
        except ValueError:
            gib = float("nan")
        if not (0 < gib < 2**40):
            raise ManifestError(f"{MEMORY_LIMIT_ENV}={value!r}: must be a positive number of GiB")
        return int(gib * 2**30), f"set by {MEMORY_LIMIT_ENV}"
    try:
        return int(0.8 * os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")), "80 % of this machine's memory"
    except (ValueError, OSError, AttributeError):  # not POSIX: no limit known
        return 2**62, "no known limit"


def check_memory(manifest: Manifest, workers: int = 1, source: str = "manifest") -> int:
    """Refuse (:class:`ManifestError`, one line saying how much) a render that would need
    more memory than :func:`memory_limit_bytes`; return the estimate in bytes."""
    per_process = manifest.memory_estimate_bytes()
    need = per_process * max(1, workers)
    limit, where = memory_limit_bytes()
    if need > limit:
        gib = 2**30
        grid = manifest.reference_grid
        each = f"{workers} workers x {per_process / gib:.1f} GiB" if workers > 1 else "one process"
        raise ManifestError(
            f"{source}: rendering would need about {need / gib:.1f} GiB ({each}: films up to "
            f"{manifest.largest_film_px() / 1e6:.1f} Mpx x 31 bands, plates {grid.width_px}x{grid.height_px}, "
            f"insets up to {manifest.render.inset_max_px} px), above the limit of {limit / gib:.1f} GiB "
            f"({where}{'' if MEMORY_LIMIT_ENV in where else f'; set {MEMORY_LIMIT_ENV} to change it'}); "
            "use a smaller reference_grid, render.inset_max_px or --workers")
    return need


def canonical_sha256(data) -> str:
    """sha256 of plain data's canonical JSON form (sorted keys, no spaces): the same value
    for a manifest and for its copy read back from a collection's YAML."""
    canonical = json.dumps(data, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(canonical.encode()).hexdigest()


# Fields added after collections were first published (paths into the manifest's JSON
# form), omitted from the hash while unset so that every earlier manifest keeps its
# sha256 (pinned by protocols and collections).
HASHED_ONLY_WHEN_SET = (("reference_grid", "hfov_deg"), ("store",), ("wide_plate",), ("render", "road_end_m"),
                        ("render", "inset_feather"), ("render", "ground_to_horizon"), ("render", "frame_divisor"), ("store", "mantissa_bits"),
                        ("store", "spectral_basis"), ("render", "plate_lamp"), ("render", "rear_retroreflectors"),
                        ("render", "inset_shadow"))


NEVER_HASHED = ("read_time_conditions",)
"""Top-level fields never part of a manifest's hash (:attr:`Manifest.read_time_conditions`)."""


def _is_targeted_json(spec) -> bool:
    return isinstance(spec, dict) and "target_image_plane_lux" in spec


def manifest_sha256(data: dict) -> str:
    """sha256 of a manifest's JSON form (``Manifest.model_dump(mode="json")``, or the
    copy in a collection's resolved manifest): :func:`canonical_sha256` with the
    :data:`HASHED_ONLY_WHEN_SET` fields left out where they are unset (None or absent)."""
    data = {key: dict(value) if isinstance(value, dict) else value for key, value in data.items()
            if key not in NEVER_HASHED}
    if isinstance(data.get("conditions"), dict):  # the targeted conditions' knobs added later, where unset
        data["conditions"] = {name: _without_unset_knobs(spec) if _is_targeted_json(spec) else spec
                              for name, spec in data["conditions"].items()}
    for *sections, key in HASHED_ONLY_WHEN_SET:
        holder = data
        for section in sections:
            holder = holder.get(section) if isinstance(holder, dict) else None
        if isinstance(holder, dict) and holder.get(key) is None:
            holder.pop(key, None)
    return canonical_sha256(data)


UNION_BRANCH_NAMES = ("dict[str,float]", "dict[str,Annotated[float, Strict]]", "TargetedCondition")


def parse_manifest(data: object, source: str = "manifest") -> Manifest:
    """Validate an already-parsed mapping, raising :class:`ManifestError` on the first problem."""
    if not isinstance(data, dict):
        raise ManifestError(f"{source}: expected a mapping at the top level, got {type(data).__name__}")
    try:
        return Manifest.model_validate(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        # a key with a newline or a NUL must not break the one-line message
        # (a condition is a union of weights and a targeted condition: pydantic names the branch)
        loc = [p for p in err["loc"] if p not in UNION_BRANCH_NAMES]
        where = ".".join(str(p) if str(p).isprintable() else repr(p) for p in loc)
        msg = err["msg"].removeprefix("Value error, ")
        # Cross-field checks already name their fields in the message.
        message = f"{source}: {where}: {msg}" if where else f"{source}: {msg}"
        raise ManifestError(" ".join(message.splitlines())) from None
    except RecursionError:
        raise ManifestError(f"{source}: nested too deeply") from None


class DuplicateKeyError(yaml.constructor.ConstructorError):
    """A YAML mapping names the same key twice (PyYAML would keep the last silently)."""


class UniqueKeyLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses duplicate keys in a mapping."""

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen = set()
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue  # '<<' merges are PyYAML's business (and may override)
                key = self.construct_object(key_node, deep=True)
                try:
                    duplicate = key in seen
                    seen.add(key)
                except TypeError:
                    continue  # an unhashable key: the base class reports it
                if duplicate:
                    raise DuplicateKeyError(None, None, f"duplicate key {key!r}", key_node.start_mark)
        return super().construct_mapping(node, deep=deep)


def load_manifest(path: str | Path) -> Manifest:
    """Read and validate a manifest YAML file (UTF-8, at most 1 MiB, no duplicate keys)."""
    path = Path(path)
    try:
        text = read_text_capped(path, MAX_MANIFEST_BYTES, "manifest")
    except OSError as exc:
        raise ManifestError(f"{path}: cannot read manifest ({exc.strerror or type(exc).__name__})") from None
    except ValueError as exc:
        raise ManifestError(str(exc)) from None
    try:
        data = yaml.load(text, Loader=UniqueKeyLoader)
    except DuplicateKeyError as exc:
        raise ManifestError(f"{path}: {exc.problem} at line {exc.problem_mark.line + 1}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        raise ManifestError(f"{path}: not valid YAML{where}") from None
    except RecursionError:
        raise ManifestError(f"{path}: not valid YAML (nested too deeply)") from None
    return parse_manifest(data, source=str(path))
