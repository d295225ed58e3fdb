"""The collection store: the only way to read (and write) a rendered collection.

Layout of a collection folder::

    radiance.zarr/                      zarr v3
      plates/<env>/<light_group>        (y, x, wavelength) float32, whole field of view
      insets/<scene>/<light_group>      (y, x, wavelength) float32, a window around the car
      frames/<scene>/car_lights         (y, x, wavelength) float32, the car's lamps over the whole view
      masks/<scene>                     (y, x) bool, the car's visible pixels over the inset window
    groundtruth.json                    COCO, one car box per scene (reference grid)
    manifest.resolved.yaml              manifest as run, package version, sha256 of every array
    progress/<unit>.json                one record per finished unit of work (resume)

Every array is one chunk written by one unit of work, so workers never share a file.
Array attributes carry ``units``, ``wavelengths_nm``, ``extent_tan`` (x0, y0, x1, y1)
and ``light_group``. A light group that puts no light in a unit (e.g. street lights
on a road without any) has no array: it reads as zero.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from metricscenes.geometry import TanExtent
from metricscenes.radiance import RadianceLayer, SpectralScene
from metricscenes.spectral import RADIANCE_UNITS, WAVELENGTHS_NM

RADIANCE_STORE = "radiance.zarr"
GROUNDTRUTH_FILE = "groundtruth.json"
RESOLVED_MANIFEST_FILE = "manifest.resolved.yaml"
PROGRESS_DIR = "progress"
DIMENSIONS = ("y", "x", "wavelength")


class CollectionError(ValueError):
    """A collection folder is missing, incomplete or corrupted (one-line message)."""


def array_sha256(array: np.ndarray) -> str:
    """sha256 over dtype, shape and the C-order little-endian bytes of an array."""
    a = np.ascontiguousarray(array, dtype=np.dtype(array.dtype).newbyteorder("<"))
    h = hashlib.sha256(f"{a.dtype.str}{a.shape}".encode())
    h.update(a.tobytes())
    return h.hexdigest()


def write_atomic(path: Path, text: str) -> None:
    """Write a text file through a temporary file and a rename, so readers never see half of it."""
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    tmp.write_text(text)
    os.replace(tmp, path)


def write_radiance(root: Path, kind: str, unit: str, light_group: str, cube: np.ndarray,
                   extent: TanExtent, extra_attrs: dict | None = None) -> str:
    """Write one radiance cube as a single-chunk zarr array; return its sha256."""
    import zarr

    cube = np.ascontiguousarray(cube, dtype=np.float32)
    attrs = {
        "units": RADIANCE_UNITS,
        "wavelengths_nm": [float(w) for w in WAVELENGTHS_NM],
        "extent_tan": list(extent.as_tuple()),
        "light_group": light_group,
        **(extra_attrs or {}),
    }
    arr = zarr.create_array(
        store=str(root / RADIANCE_STORE), name=f"{kind}/{unit}/{light_group}", shape=cube.shape,
        dtype="float32", chunks=cube.shape, dimension_names=DIMENSIONS, attributes=attrs,
        overwrite=True,
    )
    arr[...] = cube
    return array_sha256(cube)


def write_mask(root: Path, unit: str, mask: np.ndarray, extent: TanExtent) -> None:
    """Write a scene's instance mask (True = car) over its inset window."""
    import zarr

    arr = zarr.create_array(
        store=str(root / RADIANCE_STORE), name=f"masks/{unit}", shape=mask.shape, dtype="bool",
        chunks=mask.shape, dimension_names=("y", "x"), overwrite=True,
        attributes={"extent_tan": list(extent.as_tuple()), "meaning": "car instance mask"},
    )
    arr[...] = mask


@dataclass(frozen=True)
class SceneRecord:
    """What the store knows of one scene without reading its radiance."""

    scene_id: str
    image_id: int
    environment_id: int
    distance_m: float


class Collection:
    """A rendered collection, opened read-only. Use :meth:`open`."""

    def __init__(self, root: Path, resolved: dict, groundtruth: dict):
        self.root = root
        self.resolved = resolved
        self._groundtruth = groundtruth
        self._images = {img["scene_id"]: img for img in groundtruth["images"]}
        self._zarr = None

    @classmethod
    def open(cls, path: str | Path) -> "Collection":
        root = Path(path)
        if not root.is_dir():
            raise CollectionError(f"{root}: no such collection folder")
        for name in (RESOLVED_MANIFEST_FILE, GROUNDTRUTH_FILE, RADIANCE_STORE):
            if not (root / name).exists():
                raise CollectionError(
                    f"{root}: not a complete collection ({name} is missing; rerun `metricscenes generate` to finish it)"
                )
        try:
            resolved = yaml.safe_load((root / RESOLVED_MANIFEST_FILE).read_text())
            groundtruth = json.loads((root / GROUNDTRUTH_FILE).read_text())
        except (yaml.YAMLError, json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise CollectionError(f"{root}: corrupted metadata ({type(exc).__name__})") from None
        if not isinstance(resolved, dict) or "manifest" not in resolved or "arrays" not in resolved:
            raise CollectionError(f"{root}: {RESOLVED_MANIFEST_FILE} lacks 'manifest' or 'arrays'")
        return cls(root, resolved, groundtruth)

    # --- facts -------------------------------------------------------------------------
    @property
    def manifest(self) -> dict:
        return self.resolved["manifest"]

    @property
    def name(self) -> str:
        return self.manifest["name"]

    @property
    def protocol(self) -> str:
        return self.manifest["protocol"]

    @property
    def manifest_sha256(self) -> str:
        return self.resolved["manifest_sha256"]

    @property
    def conditions(self) -> dict[str, dict[str, float]]:
        return self.manifest["conditions"]

    @property
    def reference_grid(self) -> tuple[int, int]:
        """(width_px, height_px) of the plates and ground-truth boxes."""
        g = self.manifest["reference_grid"]
        return (g["width_px"], g["height_px"])

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
            self._zarr = zarr.open_group(str(self.root / RADIANCE_STORE), mode="r")
        return self._zarr

    @property
    def condition_names(self) -> list[str]:
        """The manifest's conditions, then the illuminance sweep's (``day@0.25lux``, ...)."""
        sweep = self.manifest.get("illuminance_sweep")
        levels = [f"{sweep['base']}@{lux:g}lux" for lux in sweep["levels_lux"]] if sweep else []
        return list(self.conditions) + levels

    def _weights(self, condition: str | dict[str, float], environment_id: int) -> dict[str, float]:
        if not isinstance(condition, str):
            return dict(condition)
        if condition not in self.condition_names:
            raise CollectionError(
                f"unknown condition {condition!r} (this collection has: {', '.join(self.condition_names)})"
            )
        if condition in self.conditions:
            return dict(self.conditions[condition])
        sweep = self.manifest["illuminance_sweep"]
        level = float(condition.split("@")[1].removesuffix("lux"))
        weights = dict(self.conditions[sweep["base"]])
        group = sweep["ambient_group"]
        measured = self.resolved["illuminance_lux"][f"env{environment_id:03d}"].get(group, 0.0)
        if measured <= 0.0:
            raise CollectionError(f"{self.root}: no {group} illuminance recorded for env{environment_id:03d}")
        weights[group] = level / measured
        for lamp_group in sweep.get("lamps_on", ()):
            weights[lamp_group] = 1.0
        return weights

    def illuminance_lux(self, scene_id: str, condition: str | dict[str, float]) -> float:
        """Horizontal illuminance at the camera (lux) under a condition: the light groups'
        measured values, weighted (car lamps not included: they face the road)."""
        env = self._image(scene_id)["environment_id"]
        measured = self.resolved["illuminance_lux"][f"env{env:03d}"]
        return float(sum(w * measured.get(g, 0.0) for g, w in self._weights(condition, env).items()))

    def photometry(self, scene_id: str, condition: str | dict[str, float], f_number: float = 2.4) -> dict:
        """Horizontal illuminance at the camera, mean scene luminance over the field of
        view, and the mean image-plane illuminance of an ideal f/N lens."""
        from metricscenes.photometry import image_plane_illuminance_lux, radiance_to_xyz

        cols, rows = self.reference_grid
        luminance = float(radiance_to_xyz(self.radiance(scene_id, condition).resample(cols, rows))[..., 1].mean())
        return {
            "scene_id": scene_id, "condition": condition if isinstance(condition, str) else dict(condition),
            "illuminance_at_camera_lux": self.illuminance_lux(scene_id, condition),
            "mean_luminance_cd_m2": luminance,
            "f_number": f_number,
            "image_plane_illuminance_lux": image_plane_illuminance_lux(luminance, f_number),
        }

    def _image(self, scene_id: str) -> dict:
        if scene_id not in self._images:
            raise CollectionError(f"unknown scene {scene_id!r}")
        return self._images[scene_id]

    def _mix(self, kind: str, unit: str, weights: dict[str, float], required: bool = True) -> RadianceLayer | None:
        group = self._group()
        path = f"{kind}/{unit}"
        if path not in group:
            if not required:
                return None
            raise CollectionError(f"{self.root}: {path} is missing from {RADIANCE_STORE}")
        node = group[path]
        total, extent = None, None
        for light_group in sorted(node.array_keys()):  # a fixed order: float sums are not associative
            arr = node[light_group]
            extent = TanExtent(*arr.attrs["extent_tan"])
            w = weights.get(light_group, 0.0)
            if w == 0.0:
                continue
            cube = np.asarray(arr[...], dtype=np.float32) * np.float32(w)
            total = cube if total is None else total + cube
        if extent is None:
            return None
        if total is None:
            arr = node[min(node.array_keys())]
            total = np.zeros(arr.shape, dtype=np.float32)
        return RadianceLayer(total, extent)

    def radiance(self, scene_id: str, condition: str | dict[str, float]) -> SpectralScene:
        """The scene's spectral radiance under a condition (a name from the manifest, or
        light-group weights): the plate and the car's inset, each the weighted sum of its
        light groups' renders."""
        img = self._image(scene_id)
        weights = self._weights(condition, img["environment_id"])
        plate = self._mix("plates", f"env{img['environment_id']:03d}", weights)
        if plate is None:
            raise CollectionError(f"{self.root}: scene {scene_id} has no plate")
        frame = self._mix("frames", scene_id, weights, required=False)
        if frame is not None:
            plate = RadianceLayer(plate.radiance + frame.radiance, plate.extent)
        inset = self._mix("insets", scene_id, weights)
        layers = tuple(layer for layer in (plate, inset) if layer is not None)
        return SpectralScene(
            layers=layers,
            metadata={"scene_id": scene_id, "condition": condition, "distance_m": img["distance_m"],
                      "environment_id": img["environment_id"]},
        )

    def angular_sampling(self, scene_id: str) -> list[dict]:
        """Per layer (plate, inset): its extent in tangent coordinates and its sampling in mrad per pixel."""
        env = self._image(scene_id)["environment_id"]
        out = []
        for name, path in (("plate", f"plates/env{env:03d}"), ("inset", f"insets/{scene_id}")):
            node = self._group()[path]
            arr = node[min(node.array_keys())]  # every light group of a unit shares its grid
            extent = TanExtent(*arr.attrs["extent_tan"])
            rows, cols = arr.shape[:2]
            out.append({"layer": name, "extent_tan": extent.as_tuple(), "shape": arr.shape,
                        "mrad_per_px": (1e3 * extent.width / cols, 1e3 * extent.height / rows)})
        return out

    def verify(self) -> list[str]:
        """Recompute every array's sha256; return the paths whose content does not match."""
        bad = []
        group = self._group()
        for path, expected in sorted(self.resolved["arrays"].items()):
            try:
                actual = array_sha256(np.asarray(group[path][...]))
            except Exception:  # missing or unreadable chunk
                actual = None
            if actual != expected:
                bad.append(path)
        return bad
