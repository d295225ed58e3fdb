"""What a collection records of its own making, typed, and the exact bytes it is stored as.

- :class:`UnitRecord` is ``progress/<unit>.json``: one per finished unit of work (a plate
  or an inset), the sha256 of every array it wrote (and of each array's attributes) and
  what the ground truth and the resolved manifest take from it. The writer writes it (:mod:`metricscenes.writer`);
  a rerun of ``generate`` reads it back to resume.
- :class:`ResolvedManifest` is ``manifest.resolved.yaml``: the manifest as run and what
  its making recorded (array hashes, illuminances, the plan, the variant, its own hashes).
  The writer writes it; :class:`metricscenes.store.Collection` reads it.

Both were dicts before they were types, and their bytes are still the dicts' (the same
keys, order and number formats), so collections made before resume and verify unchanged:
:meth:`UnitRecord.to_json` and :meth:`ResolvedManifest.to_yaml` are the only places those
bytes are made. Values read back are kept as JSON gave them (no int becomes a float), since
they are written again into ``groundtruth.json``.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass

import yaml

from metricscenes.manifest import canonical_sha256

PLATE, INSET = "plate", "inset"


class RecordError(ValueError):
    """A progress record that parses but lacks a field or holds one of the wrong type."""


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _box(data: dict, name: str) -> tuple:
    value = data.get(name)
    if not (isinstance(value, list) and len(value) == 4 and all(map(_is_number, value))):
        raise RecordError(name)
    return tuple(value)


def _names(data: dict, name: str) -> tuple[str, ...]:
    value = data.get(name)
    if not (isinstance(value, list) and all(isinstance(v, str) for v in value)):
        raise RecordError(name)
    return tuple(value)


def _mapping(data: dict, name: str, values) -> dict:
    value = data.get(name)
    if not (isinstance(value, dict) and all(isinstance(k, str) and values(v) for k, v in value.items())):
        raise RecordError(name)
    return value


@dataclass(frozen=True)
class InsetTruth:
    """Where an inset's car stands, and the ground truth its instance mask gives."""

    pose: dict[str, float]  # the car's CarPose: x_m, y_m, yaw_rad
    projected_box_tan: tuple[float, ...]  # the box of its projected mesh vertices (x0, y0, x1, y1)
    inset_scale: int  # the inset is a crop of a film this many times finer than the reference grid
    box_tan: tuple[float, ...]  # the tight box of its mask (x0, y0, x1, y1): the ground truth
    mask_iou: float  # IoU of box_tan and projected_box_tan, 4 decimals (a cross-check)
    bbox_xywh: tuple[float, ...]  # box_tan on the reference grid: its COCO box


@dataclass(frozen=True)
class UnitRecord:
    """One finished unit of work, as ``progress/<unit>.json`` holds it."""

    unit: str  # a plate's environment (env000) or an inset's scene (env000-d025m)
    kind: str  # PLATE or INSET
    arrays: dict[str, str]  # every array the unit wrote (its mask too) -> sha256 of its values
    seconds: float  # how long the unit took: the one field that differs between two runs
    # Plates: horizontal illuminance at the camera per light group (None: no group lit the plate).
    illuminance_lux: dict[str, float] | None = None
    inset: InsetTruth | None = None  # insets (stored flat, beside the fields above)
    # Every array -> sha256 of its attributes (store.attributes_sha256); None in records
    # written before they were recorded.
    attributes: dict[str, str] | None = None
    # The light groups the unit has rendered, where fewer than its manifest's (`generate
    # --conditions`); None: all of them (and every record written before a unit could hold fewer).
    light_groups: tuple[str, ...] | None = None

    def to_json(self) -> str:
        data = {"unit": self.unit, "kind": self.kind, "arrays": self.arrays, "seconds": self.seconds}
        if self.attributes is not None:
            data["attributes"] = self.attributes
        if self.light_groups is not None:
            data["light_groups"] = list(self.light_groups)
        if self.illuminance_lux is not None:
            data["illuminance_lux"] = self.illuminance_lux
        if self.inset is not None:
            data.update(asdict(self.inset))
        return json.dumps(data, indent=1, sort_keys=True)

    @classmethod
    def from_dict(cls, data: dict) -> "UnitRecord":
        """A record from its parsed JSON; :class:`RecordError` naming the first field missing
        or of the wrong type (a plate's ``illuminance_lux`` may be absent)."""
        unit, kind, seconds = data.get("unit"), data.get("kind"), data.get("seconds")
        if not isinstance(unit, str) or kind not in (PLATE, INSET) or not _is_number(seconds):
            raise RecordError("unit, kind or seconds")
        arrays = _mapping(data, "arrays", lambda v: isinstance(v, str))
        attributes = None if "attributes" not in data else _mapping(data, "attributes", lambda v: isinstance(v, str))
        groups = None if "light_groups" not in data else _names(data, "light_groups")
        if kind == PLATE:
            illuminance = None if "illuminance_lux" not in data else _mapping(data, "illuminance_lux", _is_number)
            return cls(unit, kind, arrays, seconds, illuminance_lux=illuminance, attributes=attributes,
                       light_groups=groups)
        scale, iou = data.get("inset_scale"), data.get("mask_iou")
        if not (isinstance(scale, int) and not isinstance(scale, bool) and _is_number(iou)):
            raise RecordError("inset_scale or mask_iou")
        inset = InsetTruth(pose=_mapping(data, "pose", _is_number), projected_box_tan=_box(data, "projected_box_tan"),
                           inset_scale=scale, box_tan=_box(data, "box_tan"), mask_iou=iou,
                           bbox_xywh=_box(data, "bbox_xywh"))
        return cls(unit, kind, arrays, seconds, inset=inset, attributes=attributes, light_groups=groups)


def resolved_content_sha256(resolved: dict) -> str:
    """sha256 of a resolved manifest's content, its own ``content_sha256`` left out."""
    return canonical_sha256({k: v for k, v in resolved.items() if k != "content_sha256"})


@dataclass(frozen=True)
class ResolvedManifest:
    """``manifest.resolved.yaml``: the manifest as run and what its making recorded.

    The four fields after ``plan`` are absent (None) in collections made before they were
    recorded; ``light_groups`` is absent where the collection holds every light group of its
    manifest."""

    package_version: str | None  # of metricscenes, when it was written
    manifest_sha256: str
    manifest_json: dict  # the manifest as run, its JSON form (the file's ``manifest``)
    arrays: dict[str, str]  # every array of the collection (masks too) -> sha256 of its values
    # Horizontal illuminance at the camera (0, 0, 1.5 m) per plate (env000, ...) and light group.
    illuminance_lux: dict[str, dict[str, float]]
    plan: list[dict]  # the planned scenes (ScenePlan.summary())
    render_variant: str | None = None  # the Mitsuba variant that rendered the arrays (render.variant: auto resolved)
    groundtruth_sha256: str | None = None  # of groundtruth.json's bytes
    content_sha256: str | None = None  # over all of the above (resolved_content_sha256)
    # Every array (masks too) -> sha256 of its attributes (store.attributes_sha256).
    attributes_sha256: dict[str, str] | None = None
    # The light groups rendered, where fewer than the manifest's (`generate --conditions`).
    light_groups: list[str] | None = None

    def as_dict(self) -> dict:
        """The file's mapping, in the file's order; fields that are None are left out."""
        data = {"package_version": self.package_version, "manifest_sha256": self.manifest_sha256,
                "manifest": self.manifest_json, "render_variant": self.render_variant,
                "light_groups": self.light_groups, "arrays": self.arrays,
                "attributes_sha256": self.attributes_sha256, "illuminance_lux": self.illuminance_lux,
                "plan": self.plan, "groundtruth_sha256": self.groundtruth_sha256, "content_sha256": self.content_sha256}
        optional = ("package_version", "render_variant", "light_groups", "attributes_sha256", "groundtruth_sha256",
                    "content_sha256")
        return {k: v for k, v in data.items() if v is not None or k not in optional}

    def to_yaml(self) -> str:
        return yaml.safe_dump(self.as_dict(), sort_keys=False)

    @classmethod
    def from_dict(cls, data: dict) -> "ResolvedManifest":
        """From the file's mapping, already checked to hold ``manifest`` and ``arrays``
        (mappings) and ``manifest_sha256`` (``metricscenes.store``)."""
        return cls(package_version=data.get("package_version"), manifest_sha256=data["manifest_sha256"],
                   manifest_json=data["manifest"], arrays=data["arrays"],
                   illuminance_lux=data.get("illuminance_lux", {}), plan=data.get("plan", []),
                   render_variant=data.get("render_variant"), groundtruth_sha256=data.get("groundtruth_sha256"),
                   content_sha256=data.get("content_sha256"), attributes_sha256=data.get("attributes_sha256"),
                   light_groups=data.get("light_groups"))
