"""The collection store: how a rendered collection is laid out, and its read side
(:class:`Collection`, :func:`verify_collection`); :mod:`metricscenes.writer` is its write
side (``CollectionWriter``), and nothing else writes a collection.

Layout of a collection folder::

    radiance.zarr/                      zarr v3
      plates/<env>/<light_group>        (y, x, wavelength) float32, whole field of view
      insets/<scene>/<light_group>      (y, x, wavelength) float32, a window around the car
      frames/<scene>/car_lights         (y, x, wavelength) float32, the car's lamps over the whole view
                                        (the plates' grid, or render.frame_divisor times coarser: read
                                        onto the plate's grid, radiance.on_grid_of)
      masks/<scene>                     (y, x) bool, the car's visible pixels over the inset window
      wide_plates/<env>/<light_group>   with a manifest's wide_plate: a coarser plate over a wider field
      wide_frames/<scene>/car_lights    and the car's lamps on its grid (read by wider cameras only)
    groundtruth.json                    COCO, one car box per scene (reference grid)
    manifest.resolved.yaml              manifest as run, package version, the Mitsuba variant that
                                        rendered it, the light groups it holds where fewer than the
                                        manifest's, sha256 of every array (masks too) and of its
                                        attributes, of groundtruth.json and of its own content
    progress/<unit>.json                one record per finished unit of work (resume)
    progress/manifest_sha256            what the records were made from (a resume of another
    progress/render_variant             manifest, or with another variant, is refused)

Every array is one chunk written by one unit of work, so workers never share a file.
The resolved manifest and the progress records are typed in :mod:`metricscenes.records`.
Array attributes carry ``units``, ``wavelengths_nm``, ``extent_tan`` (x0, y0, x1, y1)
and ``light_group``. A light group that puts no light in a unit (e.g. street lights
on a road without any) has no array: it reads as zero. Which arrays a unit has is
what ``manifest.resolved.yaml`` records, never what the folder happens to hold. A
collection may hold some of its manifest's light groups only (``generate --conditions``;
:attr:`Collection.light_groups`): a condition that mixes another is refused, in one line
that says how to add it (:meth:`Collection.check_condition`), never read as zero.

Codecs (:mod:`metricscenes.writer`): radiance is stored losslessly with zarr v3 core
codecs unless the manifest asks for ``store: {mantissa_bits: N}``; zarr reads each array's
chain from its ``zarr.json``, so collections written with older chains read the same. With
``store: {spectral_basis: K}`` a radiance array holds K coefficients per pixel and its
``spectral_basis`` attribute the K basis spectra; :func:`read_checked` hands back the
decoded 31 bands (:mod:`metricscenes.spectral_basis`), so no reader sees the difference.

Integrity: every array is checked against its recorded sha256 when it is first read
(once per process and file version, :func:`read_checked`), so a damaged, truncated or
deleted chunk is an error, never wrong numbers or fill-value zeros; its attributes (the
extent, units, wavelengths, spectral basis: everything a reader takes from its
``zarr.json``) against the sha256 of their canonical JSON (:func:`attributes_sha256`) each
time they are read, so a moved ``extent_tan`` is an error too. Collections written before
masks and ground truth had a sha256 are still read: their ground-truth boxes are recomputed
from the masks instead; those written before attributes had one are read unchecked, and
``verify`` says how to record them (:func:`upgrade_notes`).
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from metricscenes.checked_read import (  # noqa: F401 (the store's API)
    _CHECKED, DIMENSIONS, GROUNDTRUTH_FILE, PROGRESS_DIR, RADIANCE_STORE, REPAIR_HINT, RESOLVED_MANIFEST_FILE,
    CollectionError, _extent, _fingerprint, _radiance_shape, array_sha256, attributes_sha256, check_attributes,
    read_checked,
)
from metricscenes.collection_files import (  # noqa: F401 (the store's API)
    ATTRIBUTES_UPGRADE_NOTE, _load_groundtruth, _load_resolved, _parse_manifest, _progress_arrays,
    collection_containing, file_in_the_way, unfinished_generation, upgrade_notes, verify_collection,
)
from metricscenes.geometry import TanExtent
from metricscenes.groundtruth import scale_groundtruth  # noqa: F401 -- store API: ground truth on a camera's grid
from metricscenes.groundtruth_checks import box_problem, groundtruth_problems, mask_box_xywh  # noqa: F401 -- verify's
from metricscenes.manifest import (
    Manifest, ManifestError, TargetedCondition, load_manifest, parse_illuminance_condition, parse_manifest,
)
from metricscenes.radiance import LazyLayer, RadianceLayer, SpectralScene, car_sharpness, on_grid_of
from metricscenes.records import ResolvedManifest
from metricscenes.photometry import image_plane_illuminance_lux
from metricscenes.targets import TargetedWeights, ambient_weight, draw_target_lux, solve_at_image_plane

_GROUP_LUMINANCE: dict[tuple, float] = {}  # mean luminance of a scene's light group, per version of its files


def _lamps_on(spec: TargetedCondition) -> dict[str, float]:
    """A targeted condition's lamp groups that it lights (weight > 0), with their weights."""
    return {g: w for g, w in spec.lamps.items() if w != 0.0}


def remember_group_luminances(values: dict[tuple, float]) -> None:
    """Keep in this process the group luminances another process measured
    (:meth:`Collection.group_luminances`): the same keys (a file's version included), so a
    changed file is measured again, and the same floats, so the same weights and bytes."""
    _GROUP_LUMINANCE.update(values)


@dataclass(frozen=True)
class SceneRecord:
    """What the store knows of one scene without reading its radiance."""

    scene_id: str
    image_id: int
    environment_id: int
    distance_m: float


class Collection:
    """A rendered collection, opened read-only. Use :meth:`open`.

    ``manifest`` is the manifest it was rendered from, parsed; ``resolved`` what its making
    recorded beside it (array hashes, illuminances, the Mitsuba variant: ``manifest.resolved.yaml``)."""

    def __init__(self, root: Path, resolved: ResolvedManifest, manifest: Manifest, groundtruth: dict,
                 groundtruth_sha256: str | None = None):
        self.root = root
        self.resolved = resolved
        self.manifest = manifest
        self._groundtruth = groundtruth
        self._groundtruth_sha256 = groundtruth_sha256
        self._images = {img["scene_id"]: img for img in groundtruth["images"]}
        self._boxes: dict[int, list] = {}
        for ann in groundtruth["annotations"]:
            self._boxes.setdefault(ann["image_id"], []).append(ann["bbox"])
        self._zarr = None
        self._plate_mix: dict[str, tuple[tuple, RadianceLayer]] = {}  # per kind of plate, the last mixed and its key
        # The light groups of each plate, inset and frame, as recorded (sorted: float sums
        # are not associative); a recorded array that is absent is an error, not a zero.
        self._recorded: dict[str, list[str]] = {}
        for path in sorted(resolved.arrays):
            parts = path.split("/")
            if len(parts) == 3:
                self._recorded.setdefault(f"{parts[0]}/{parts[1]}", []).append(parts[2])

    @classmethod
    def open(cls, path: str | Path) -> "Collection":
        root = Path(path)
        if not root.is_dir():
            raise CollectionError(f"{root}: no such collection folder")
        unfinished = unfinished_generation(root)
        if unfinished:
            raise CollectionError(f"{root}: not a complete collection: {unfinished}")
        for name in (RESOLVED_MANIFEST_FILE, GROUNDTRUTH_FILE, RADIANCE_STORE):
            if not (root / name).exists():
                raise CollectionError(
                    f"{root}: not a complete collection ({name} is missing; rerun `metricscenes generate` to finish it)"
                )
        resolved = _load_resolved(root)
        collection = cls(root, resolved, _parse_manifest(root, resolved), *_load_groundtruth(root))
        problems = collection._groundtruth_problems()
        if problems:
            more = f" (and {len(problems) - 1} more: run `metricscenes verify {root}`)" if len(problems) > 1 else ""
            raise CollectionError(f"{root}: {problems[0]}{more}; {REPAIR_HINT}")
        return collection

    # --- facts -------------------------------------------------------------------------
    @property
    def name(self) -> str:
        return self.manifest.name

    @property
    def protocol(self) -> str:
        return self.manifest.protocol

    @property
    def manifest_sha256(self) -> str:
        """As recorded (a manifest parsed from an older collection may gain defaults that
        would change its hash)."""
        return self.resolved.manifest_sha256

    @property
    def render_variant(self) -> str:
        """The Mitsuba variant that rendered the arrays (collections made before
        ``render.variant: auto`` record none: their manifest's variant rendered them)."""
        return self.resolved.render_variant or self.manifest.render.variant

    @property
    def conditions(self) -> dict[str, dict[str, float]]:
        """The manifest's conditions and its read-time conditions, by name."""
        return {**self.manifest.conditions, **(self.manifest.read_time_conditions or {})}

    @property
    def reference_grid(self) -> tuple[int, int]:
        """(width_px, height_px) of the plates and ground-truth boxes."""
        g = self.manifest.reference_grid
        return (g.width_px, g.height_px)

    @property
    def field(self) -> TanExtent:
        """The field of view the plates and the ground-truth grid cover (tangent extent;
        the reference field unless the manifest set ``reference_grid.hfov_deg``)."""
        return self.manifest.reference_grid.field

    @property
    def widest_field(self) -> TanExtent | None:
        """The wide plate's field (``wide_plate``: what a camera wider than :attr:`field` may
        see), or None for a collection without one."""
        wide = self.manifest.wide_plate
        return None if wide is None else wide.field

    def scenes(self) -> list[SceneRecord]:
        return [
            SceneRecord(img["scene_id"], img["id"], img["environment_id"], float(img["distance_m"]))
            for img in self._groundtruth["images"]
        ]

    def groundtruth(self) -> dict:
        """The COCO ground truth (a deep copy: callers may modify it)."""
        return json.loads(json.dumps(self._groundtruth))

    # --- radiance ----------------------------------------------------------------------
    def _group(self):
        import zarr

        if self._zarr is None:
            try:
                self._zarr = zarr.open_group(str(self.root / RADIANCE_STORE), mode="r")
            except Exception as exc:  # its zarr.json is missing or damaged
                raise CollectionError(f"{self.root}: {RADIANCE_STORE} is missing or unreadable ({type(exc).__name__}); "
                                      f"{REPAIR_HINT}") from None
        return self._zarr

    @property
    def condition_names(self) -> list[str]:
        """The manifest's conditions, then the illuminance sweep's (``day@0.25lux``, ...)."""
        return self.manifest.condition_names

    @property
    def light_groups(self) -> tuple[str, ...]:
        """The light groups the collection holds: all of its manifest's, or those that
        ``generate --conditions`` rendered (collections made before it hold all)."""
        held = self.resolved.light_groups
        return self.manifest.light_groups if held is None else tuple(g for g in self.manifest.light_groups if g in held)

    @property
    def held_condition_names(self) -> list[str]:
        """The conditions (:attr:`condition_names`) whose light groups the collection holds."""
        return [c for c in self.condition_names if not self._missing_light_groups(c)]

    def _missing_light_groups(self, condition: str | dict[str, float]) -> list[str]:
        if isinstance(condition, str):
            needed = self.manifest.condition_light_groups(condition)
        else:  # (a group the manifest does not render reads as zero, as it always did)
            needed = [g for g, w in condition.items() if w != 0.0 and g in self.manifest.light_groups]
        return [g for g in needed if g not in self.light_groups]

    def check_condition(self, condition: str | dict[str, float]) -> None:
        """Refuse (:class:`CollectionError`, one line) a condition that cannot be mixed here:
        an unknown name, or one that mixes light groups the collection does not hold (the
        line names them and the command that renders them)."""
        if isinstance(condition, str) and condition not in self.condition_names:
            raise CollectionError(
                f"unknown condition {condition!r} (this collection has: {', '.join(self.condition_names)})"
            )
        missing = self._missing_light_groups(condition)
        if missing:
            add = f"--conditions {condition}" if isinstance(condition, str) else f"--light-groups {','.join(missing)}"
            raise CollectionError(
                f"{self.root} holds no {', '.join(missing)} (rendered: {', '.join(self.light_groups)}); add "
                f"{'it' if len(missing) == 1 else 'them'} with: {self.generate_command()} {add}")

    def generate_command(self) -> str:
        """The ``metricscenes generate`` command that renders into this collection: with the
        manifest file in ``manifests/`` of the working directory that holds its manifest (the
        presets), else with a placeholder for it (the collection keeps the manifest, not its path)."""
        preset = Path("manifests") / f"{self.name}.yaml"
        try:
            manifest = str(preset) if load_manifest(preset).sha256() == self.manifest_sha256 else "<its manifest>"
        except ManifestError:
            manifest = "<its manifest>"
        return f"metricscenes generate --manifest {manifest} --out {self.root}"

    def _weights(self, condition: str | dict[str, float], scene_id: str) -> dict[str, float]:
        """Light-group weights of a condition in one scene (a targeted condition's depend on
        the scene: :meth:`targeted_weights`); :meth:`check_condition` refuses one it cannot mix."""
        self.check_condition(condition)
        if not isinstance(condition, str):
            return dict(condition)
        if self.is_targeted(condition):
            if self.targets_camera(condition):
                raise CollectionError(f"condition {condition} meets its target at each camera's own image plane: its "
                                      "radiance needs a camera (benchmark run), its weights a camera or a lens "
                                      "(info --photometry --f-number N)")
            return self.targeted_weights(scene_id, condition).weights
        if condition in self.conditions:
            return dict(self.conditions[condition])
        environment_id = self._image(scene_id)["environment_id"]
        sweep = self.manifest.illuminance_sweep
        _, level = parse_illuminance_condition(condition)
        weights = dict(self.conditions[sweep.base])
        group = sweep.ambient_group
        measured = self.resolved.illuminance_lux[f"env{environment_id:03d}"].get(group, 0.0)
        if measured <= 0.0:
            raise CollectionError(f"{self.root}: no {group} illuminance recorded for env{environment_id:03d}")
        weights[group] = level / measured
        for lamp_group in sweep.lamps_on:
            weights[lamp_group] = 1.0
        return weights

    def illuminance_lux(self, scene_id: str, condition: str | dict[str, float]) -> float:
        """Horizontal illuminance at the camera (lux) under a condition: the light groups'
        measured values, weighted (car lamps not included: they face the road)."""
        return self._illuminance_under(scene_id, self._weights(condition, scene_id))

    def _illuminance_under(self, scene_id: str, weights: dict[str, float]) -> float:
        """:meth:`illuminance_lux` for weights already resolved."""
        env = self._image(scene_id)["environment_id"]
        measured = self.resolved.illuminance_lux[f"env{env:03d}"]
        return float(sum(w * measured.get(g, 0.0) for g, w in weights.items()))

    def mean_luminance(self, scene_id: str, condition: str | dict[str, float]) -> float:
        """Mean luminance (cd/m²) of a scene under a condition over the field of view, on the
        reference grid (what a lens images: plate, frame and inset composited)."""
        from metricscenes.photometry import radiance_to_xyz

        cols, rows = self.reference_grid
        return float(radiance_to_xyz(self.radiance(scene_id, condition).resample(cols, rows))[..., 1].mean())

    def group_luminance(self, scene_id: str, group: str) -> float:
        """:meth:`mean_luminance` of one light group at weight 1, kept per version of its files."""
        return self._group_luminance_entry(scene_id, group)[1]

    def _group_luminance_entry(self, scene_id: str, group: str) -> tuple[tuple, float]:
        """(the key this process keeps it under, :meth:`group_luminance`)."""
        units = (f"plates/env{self._image(scene_id)['environment_id']:03d}", f"frames/{scene_id}", f"insets/{scene_id}")
        key = (str(self.root), scene_id, group,
               tuple(_fingerprint(self.root, f"{unit}/{group}") for unit in units if group in self._recorded.get(unit, [])))
        if key not in _GROUP_LUMINANCE:
            _GROUP_LUMINANCE[key] = self.mean_luminance(scene_id, {group: 1.0})
        return key, _GROUP_LUMINANCE[key]

    def is_targeted(self, condition: str) -> bool:
        """Whether ``condition`` is set by a photometric target (its weights depend on the scene)."""
        return isinstance(self.conditions.get(condition), TargetedCondition)

    def with_read_time_conditions(self, extra: dict) -> "Collection":
        """This collection with more read-time conditions, given at read time (a program's own
        variants of a condition: ``benchmark paper-factors``), validated as a manifest's own
        and refused in one line; the same arrays, hash and caches."""
        data = self.manifest.model_dump(mode="json")
        data["read_time_conditions"] = {**(data.get("read_time_conditions") or {}), **extra}
        try:
            manifest = parse_manifest(data, source="read-time conditions")
        except ManifestError as exc:
            raise CollectionError(str(exc)) from None
        return Collection(self.root, self.resolved, manifest, self._groundtruth, self._groundtruth_sha256)

    def read_time_condition(self, condition: str) -> dict | None:
        """The definition of one of the manifest's ``read_time_conditions`` (its JSON form, the
        unset knobs left out), which the manifest's sha256 does not hold: what a run's cache key
        and results.json add for it. None for any other condition."""
        if not isinstance(condition, str) or not self.manifest.is_read_time(condition):
            return None
        spec = self.conditions[condition]
        return spec.identity() if isinstance(spec, TargetedCondition) else dict(spec)

    def targets_camera(self, condition: str) -> bool:
        """Whether ``condition`` meets its target at each camera's own image plane (``target_at:
        camera``): its weights depend on the camera too (:meth:`camera_weights`)."""
        spec = self.conditions.get(condition)
        return isinstance(spec, TargetedCondition) and spec.at_camera

    def condition_parts(self, condition: str) -> dict[str, dict[str, float]]:
        """The mixes (light-group weights) whose image-plane illuminances set a targeted
        condition's weights (``TargetedCondition.parts``), those that light nothing left out:
        a camera measures each through its lens (``benchmark.camera.image_plane``)."""
        self.check_condition(condition)
        return {name: part for name, part in self.conditions[condition].parts().items() if part}

    def camera_weights(self, scene_id: str, condition: str, part_lux: dict[str, float],
                       at: dict | None = None) -> TargetedWeights:
        """A ``target_at: camera`` condition's weights in one scene for one camera, from what the
        camera measured of each of :meth:`condition_parts` at its image plane (``part_lux``,
        lux); ``at`` (the camera, its lens) is recorded with them."""
        self.check_condition(condition)
        spec = self.conditions[condition]
        try:
            return solve_at_image_plane(spec, self._target_lux(scene_id, condition), part_lux, at)
        except ValueError as exc:
            raise CollectionError(f"{self.root}: scene {scene_id}, condition {condition}: {exc}") from None

    def _target_lux(self, scene_id: str, condition: str) -> float:
        """The environment's target of a targeted condition (drawn as ``same_targets_as``'s where it names one)."""
        spec = self.conditions[condition]
        env = self._image(scene_id)["environment_id"]
        return draw_target_lux(self.manifest.seed, env, spec.same_targets_as or condition, spec.target_image_plane_lux)

    def group_luminances(self, scene_ids: Iterable[str], condition: str) -> dict[tuple, float]:
        """The :meth:`group_luminance` of every light group a targeted ``condition`` weighs, in
        these scenes (computed where this process has not yet), keyed as this process keeps
        them: :func:`remember_group_luminances` in another process spares it the reading
        (each is a whole scene read and resampled onto the reference grid: 0.7 core-s on metric-300)."""
        self.check_condition(condition)
        spec = self.conditions[condition]
        if spec.at_camera:  # each camera measures its own image plane: no group luminance is needed
            return {}
        groups = [g for part in spec.parts().values() for g in part]
        return dict(self._group_luminance_entry(scene_id, group) for scene_id in scene_ids for group in groups)

    def targeted_weights(self, scene_id: str, condition: str, f_number: float | None = None) -> TargetedWeights:
        """A targeted condition's weights in one scene: its environment's target drawn from
        the condition's range, the ambient weight (or the whole mix's scale) that meets it
        (:mod:`metricscenes.targets`). A ``target_at: camera`` condition's depend on the camera:
        here, those of an ideal camera at f/``f_number`` that sees the collection's field (the
        registry's cameras: T = 1, no falloff), from the groups' mean luminance over it; a
        run records its own camera's (:meth:`camera_weights`)."""
        self.check_condition(condition)  # (before its groups are read one by one: the line names the condition)
        spec = self.conditions[condition]
        target = self._target_lux(scene_id, condition)
        if spec.at_camera and f_number is None:
            raise CollectionError(f"condition {condition} meets its target at each camera's own image plane: its "
                                  "weights need a camera (benchmark run) or a lens (info --photometry --f-number N)")
        lens = spec.f_number if f_number is None else f_number
        try:
            if spec.at_camera or spec.scales_mix:
                part_lux = {name: image_plane_illuminance_lux(
                    sum(w * self.group_luminance(scene_id, g) for g, w in part.items()), lens)
                    for name, part in self.condition_parts(condition).items()}
                at = {"camera": f"ideal lens f/{lens:g} over the collection's field", "f_number": lens,
                      "part_image_plane_lux": part_lux} if spec.at_camera else None
                return solve_at_image_plane(spec, target, part_lux, at)
            lamps = _lamps_on(spec)  # (the first targeted conditions' arithmetic, kept: their weights keep their bits)
            return ambient_weight(target, spec.f_number, self.group_luminance(scene_id, spec.ambient),
                                  {g: self.group_luminance(scene_id, g) for g in lamps}, lamps, spec.ambient)
        except ValueError as exc:
            raise CollectionError(f"{self.root}: scene {scene_id}, condition {condition}: {exc}") from None

    def condition_record(self, scene_id: str, condition: str) -> dict | None:
        """What a targeted condition did in a scene (target, weights, over target), else None
        (and None for a ``target_at: camera`` condition, whose weights each camera records)."""
        if isinstance(condition, str) and self.is_targeted(condition) and not self.targets_camera(condition):
            return self.targeted_weights(scene_id, condition).record()
        return None

    def photometry(self, scene_id: str, condition: str | dict[str, float], f_number: float = 2.4) -> dict:
        """Horizontal illuminance at the camera, mean scene luminance over the field of
        view, and the mean image-plane illuminance of an ideal f/N lens.

        The luminance is the weighted sum of the light groups' (:meth:`group_luminance`, kept
        per scene): mixing, compositing, resampling and the mean are linear, so it is the mix's
        own (:meth:`mean_luminance`) to the rounding, and a scene's groups are read once for
        all its conditions (a targeted condition's weights need them anyway)."""
        targeted = (self.targeted_weights(scene_id, condition, f_number if self.targets_camera(condition) else None)
                    if isinstance(condition, str) and self.is_targeted(condition) else None)
        weights = targeted.weights if targeted is not None else self._weights(condition, scene_id)
        luminance = float(sum(w * self.group_luminance(scene_id, g) for g, w in weights.items() if w != 0.0))
        out = {
            "scene_id": scene_id, "condition": condition if isinstance(condition, str) else dict(condition),
            "illuminance_at_camera_lux": self._illuminance_under(scene_id, weights),
            "mean_luminance_cd_m2": luminance,
            "f_number": f_number,
            "image_plane_illuminance_lux": image_plane_illuminance_lux(luminance, f_number),
        }
        if targeted is not None:
            out["targeted"] = targeted.record()
        return out

    def _image(self, scene_id: str) -> dict:
        if scene_id not in self._images:
            raise CollectionError(f"unknown scene {scene_id!r}")
        return self._images[scene_id]

    def _expected_attributes(self, path: str) -> str | None:
        """The recorded sha256 of an array's attributes (None: the collection predates them;
        "": it records them, but not this array's, which then fails the check)."""
        recorded = self.resolved.attributes_sha256
        return None if recorded is None else recorded.get(path, "")

    def _read(self, path: str, scene_id: str) -> tuple[np.ndarray, dict]:
        """One array, checked against its recorded sha256 and its attributes against theirs
        (a one-line error naming the scene)."""
        try:
            return read_checked(self.root, self._group(), path, self.resolved.arrays.get(path), f"scene {scene_id}",
                                self._expected_attributes(path))
        except CollectionError as exc:
            raise CollectionError(f"{self.root}: {exc}; {REPAIR_HINT}") from None

    def _mix(self, kind: str, unit: str, weights: dict[str, float], scene_id: str,
             required: bool = True) -> RadianceLayer | None:
        groups = self._recorded.get(f"{kind}/{unit}", [])
        if not groups:
            if not required:
                return None
            raise CollectionError(f"{self.root}: scene {scene_id}: {kind}/{unit} has no arrays in {RESOLVED_MANIFEST_FILE}")
        lit = [g for g in groups if weights.get(g, 0.0) != 0.0]
        if not lit and not required:  # a frame whose lamps are off adds nothing
            return None
        key = None
        if kind in ("plates", "wide_plates"):  # one plate serves its environment's scenes, read in turn: mixed once
            key = (unit, tuple((g, weights[g]) for g in lit),
                   tuple(_fingerprint(self.root, f"{kind}/{unit}/{g}") for g in lit))  # a changed file is read again
            if kind in self._plate_mix and self._plate_mix[kind][0] == key:
                return self._plate_mix[kind][1]
        total, extent = None, None
        for light_group in lit:
            w = weights[light_group]
            path = f"{kind}/{unit}/{light_group}"
            data, attrs = self._read(path, scene_id)
            extent = _extent(attrs, f"{self.root}: scene {scene_id}", path)
            cube = np.asarray(data, dtype=np.float32) * np.float32(w)
            total = cube if total is None else total + cube
        if total is None:  # no group of this unit is lit: zeros on its grid (metadata only)
            path = f"{kind}/{unit}/{groups[0]}"
            arr = self._node(path, scene_id)
            extent = _extent(dict(arr.attrs), f"{self.root}: scene {scene_id}", path)
            total = np.zeros(_radiance_shape(arr), dtype=np.float32)
        layer = RadianceLayer(total, extent)
        if key is not None:
            total.flags.writeable = False  # shared by the scenes that reuse it
            self._plate_mix[kind] = (key, layer)
        return layer

    def _node(self, path: str, scene_id: str):
        """An array's metadata (shape, attributes) without reading its data; its attributes
        checked against their recorded sha256."""
        try:
            node = self._group()[path]
            attrs = dict(node.attrs)
        except Exception:
            raise CollectionError(f"{self.root}: scene {scene_id}: {path} is missing or unreadable; {REPAIR_HINT}") from None
        try:
            check_attributes(attrs, self._expected_attributes(path), f"scene {scene_id}", path)
        except CollectionError as exc:
            raise CollectionError(f"{self.root}: {exc}; {REPAIR_HINT}") from None
        return node

    def mask(self, scene_id: str) -> tuple[np.ndarray, TanExtent]:
        """The car's instance mask over its inset window and that window's extent, checked
        against its sha256 (where recorded) and against the scene's ground-truth box."""
        img = self._image(scene_id)
        path = f"masks/{scene_id}"
        data, attrs = self._read(path, scene_id)
        extent = _extent(attrs, f"{self.root}: scene {scene_id}", path)
        problem = box_problem(img, self._boxes.get(img["id"], []), data, extent, self.field)
        if problem:
            raise CollectionError(f"{self.root}: {problem}; {REPAIR_HINT}")
        return data.astype(bool, copy=False), extent

    def _groundtruth_problems(self) -> list[str]:
        return groundtruth_problems(self.root, self._group(), self._groundtruth, self._groundtruth_sha256, self.resolved)

    def radiance(self, scene_id: str, condition: str | dict[str, float], *,
                 inset_resolution: str = "car") -> SpectralScene:
        """The scene's spectral radiance under a condition (a name from the manifest, or
        light-group weights): the plate and the car's inset, each the weighted sum of its
        light groups' renders. ``inset_resolution``: where a grid is finer than the plate,
        ``"car"`` keeps the inset's own resolution on the car and shows the rest of its
        window at the plate's, so the window leaves no seam (:func:`metricscenes.radiance.car_sharpness`);
        ``"window"`` keeps it over the whole window (the composite before; docs/scenes.md,
        "The inset seam")."""
        if inset_resolution not in ("car", "window"):
            raise ValueError(f"inset_resolution must be 'car' or 'window', not {inset_resolution!r}")
        img = self._image(scene_id)
        weights = self._weights(condition, scene_id)
        mask, _ = self.mask(scene_id)  # a scene is read whole or not at all: its mask and box too
        plate = self._plate_with_frame("plates", "frames", img["environment_id"], weights, scene_id)
        inset = replace(self._mix("insets", scene_id, weights, scene_id),
                        feather=self.manifest.render.inset_feather or 0.0)
        if inset_resolution == "car" and mask.shape == inset.radiance.shape[:2]:
            inset = replace(inset, sharp=car_sharpness(mask, inset.extent, plate.pixel_tan))
        layers = tuple(layer for layer in (plate, inset) if layer is not None)
        surround = None
        if self.manifest.wide_plate is not None:  # read only by a camera wider than the plate
            surround = LazyLayer(self.manifest.wide_plate.field, lambda: self._plate_with_frame(
                "wide_plates", "wide_frames", img["environment_id"], weights, scene_id))
        return SpectralScene(
            layers=layers, surround=surround,
            metadata={"scene_id": scene_id, "condition": condition, "distance_m": img["distance_m"],
                      "environment_id": img["environment_id"]},
        )

    def _plate_with_frame(self, plate_kind: str, frame_kind: str, environment_id: int, weights: dict[str, float],
                          scene_id: str) -> RadianceLayer:
        """The scene's plate (``plates`` or ``wide_plates``) under ``weights``, with the car lamps'
        light of its frame (``frames`` or ``wide_frames``) on its grid."""
        plate = self._mix(plate_kind, f"env{environment_id:03d}", weights, scene_id)
        frame = self._mix(frame_kind, scene_id, weights, scene_id, required=False)
        return plate if frame is None else RadianceLayer(plate.radiance + on_grid_of(frame, plate), plate.extent)

    def angular_sampling(self, scene_id: str) -> list[dict]:
        """Per layer (plate, inset): its extent in tangent coordinates and its sampling in mrad per pixel."""
        env = self._image(scene_id)["environment_id"]
        out = []
        for name, unit in (("plate", f"plates/env{env:03d}"), ("inset", f"insets/{scene_id}")):
            groups = self._recorded.get(unit)
            if not groups:
                raise CollectionError(f"{self.root}: scene {scene_id}: {unit} has no arrays in {RESOLVED_MANIFEST_FILE}")
            path = f"{unit}/{groups[0]}"  # every light group of a unit shares its grid
            arr = self._node(path, scene_id)
            extent = _extent(dict(arr.attrs), f"{self.root}: scene {scene_id}", path)
            rows, cols = arr.shape[:2]
            out.append({"layer": name, "extent_tan": extent.as_tuple(), "shape": _radiance_shape(arr),
                        "mrad_per_px": (1e3 * extent.width / cols, 1e3 * extent.height / rows)})
        return out

    def verify(self) -> list[str]:
        """Every problem of the collection, one line each naming its scene (or plate)."""
        return verify_collection(self.root)
