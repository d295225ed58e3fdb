"""Export one scene's composited spectral radiance for other tools (ISETCam first).

The plate and the car's inset are composited onto one uniform grid over the whole
reference field of view (:meth:`SpectralScene.resample`: area averaging where a
layer is finer than the grid, linear interpolation where it is coarser) and written
to HDF5 with everything an ISETCam ``scene`` needs [1]_:

========================  =========================================================
``/photons``              (rows, cols, 31) float32, photons·s⁻¹·sr⁻¹·m⁻²·nm⁻¹,
                          q = L λ / (h c) per band (ISETCam ``scene.data.photons``)
``/radiance``             (rows, cols, 31) float32, W·sr⁻¹·m⁻²·nm⁻¹ (energy)
``/wave``                 (31,) float64, band centres in nm
``/x_tan``, ``/y_tan``    pixel-centre tangent coordinates (x right, y down)
``/groundtruth``          ``bbox_xywh`` (4,) COCO box on the exported grid
root attributes           ``hfov_deg``, ``vfov_deg``, ``distance_m``, ``mrad_per_px``,
                          ``extent_tan``, ``dimension_order``, scene facts, the
                          source layers' sampling (``layers_json``), provenance
========================  =========================================================

Arrays are stored in C order as (y, x, wavelength), like the collection store. MATLAB
reads HDF5 with the dimensions reversed, so ``h5read`` returns wave × cols × rows and
``permute(photons, [3 2 1])`` gives ISETCam's rows × cols × wave (``docs/scenes.md``).

Default grid: the finest uniform grid that keeps the inset's angular sampling over
the whole field, capped at :data:`MAX_DEFAULT_WIDTH_PX` (2688 px, the finest
camera's grid, 1.0 µm pixels) and never coarser than the reference grid.

.. [1] ISETCam, ``sceneCreate``/``sceneSet`` (scene.data.photons in
   photons/s/sr/m²/nm, ``fov`` = horizontal field of view in degrees,
   ``distance`` in m). https://github.com/ISET/isetcam
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from metricscenes import __version__
from metricscenes.geometry import TanExtent, fov_deg
from metricscenes.radiance import SpectralScene
from metricscenes.spectral import RADIANCE_UNITS, photon_energy_j
from metricscenes.store import Collection

EXPORT_FORMATS = ("hdf5",)
PHOTON_UNITS = "photons s-1 sr-1 m-2 nm-1"
MAX_DEFAULT_WIDTH_PX = 2688
MAX_WIDTH_PX = 8192
FORMAT_VERSION = 1
DIMENSION_ORDER = ("C order (y, x, wavelength) = (rows, cols, wave); MATLAB h5read returns "
                   "wave x cols x rows: use permute(data, [3 2 1])")
_BANDS_PER_PASS = 8  # composite a few bands at a time: a 2688-px grid of 31 bands is 0.5 GB


class ExportError(ValueError):
    """Bad export request (one-line message)."""


def default_width_px(scene: SpectralScene, reference_width_px: int) -> int:
    """The finest grid width that keeps every layer's sampling over the whole field,
    capped at :data:`MAX_DEFAULT_WIDTH_PX`, at least the reference width."""
    finest_tan = min(layer.pixel_tan[0] for layer in scene.layers)
    width = math.ceil(scene.extent.width / finest_tan - 1e-6)
    return int(max(reference_width_px, min(MAX_DEFAULT_WIDTH_PX, width)))


def grid_for_width(width_px: int, reference_grid: tuple[int, int]) -> tuple[int, int]:
    """(cols, rows) of an export grid ``width_px`` wide with square pixels."""
    if int(width_px) != width_px or not 16 <= width_px <= MAX_WIDTH_PX:
        raise ExportError(f"--width-px must be an integer in 16..{MAX_WIDTH_PX}, got {width_px!r}")
    ref_w, ref_h = reference_grid
    return int(width_px), max(1, round(width_px * ref_h / ref_w))


def composite(scene: SpectralScene, cols: int, rows: int) -> np.ndarray:
    """(rows, cols, bands) float32 energy radiance of all layers on one grid, a few bands per pass."""
    bands = scene.layers[0].radiance.shape[2]
    out = np.empty((rows, cols, bands), dtype=np.float32)
    for b0 in range(0, bands, _BANDS_PER_PASS):
        sl = slice(b0, min(bands, b0 + _BANDS_PER_PASS))
        part = SpectralScene(layers=tuple(replace(layer, radiance=layer.radiance[..., sl]) for layer in scene.layers))
        out[..., sl] = part.resample(cols, rows)
    return out


def radiance_to_photons(radiance_w: np.ndarray, wavelengths_nm: np.ndarray) -> np.ndarray:
    """Spectral radiance W·sr⁻¹·m⁻²·nm⁻¹ → photons·s⁻¹·sr⁻¹·m⁻²·nm⁻¹, q = L λ / (h c) (float32)."""
    per_joule = (1.0 / photon_energy_j(wavelengths_nm)).astype(np.float64)
    out = np.empty(radiance_w.shape, dtype=np.float32)
    for b, k in enumerate(per_joule):  # per band: no float64 copy of the whole cube
        np.multiply(radiance_w[..., b], k, out=out[..., b], casting="unsafe")
    return out


def export_hdf5(collection: Collection, scene_id: str, condition: str, out: str | Path, *,
                width_px: int | None = None, gzip: bool = False) -> Path:
    """Write one scene under one condition to an HDF5 file for ISETCam (see module doc).

    ``width_px``: export grid width (height follows the 16:9 field with square pixels);
    default :func:`default_width_px`. ``gzip``: compress the cubes (level 1 + shuffle,
    readable by MATLAB; renders are noisy, so it saves only ~25 % and takes ~4x longer). Raises :class:`ExportError` or
    :class:`~metricscenes.store.CollectionError` with one-line messages.
    """
    import h5py

    scene = collection.radiance(scene_id, condition)  # unknown scene/condition → CollectionError
    ref_grid = collection.reference_grid
    cols, rows = grid_for_width(width_px if width_px is not None else default_width_px(scene, ref_grid[0]),
                                ref_grid)
    extent: TanExtent = scene.extent
    hfov, vfov = fov_deg(extent)
    energy = composite(scene, cols, rows)
    photons = radiance_to_photons(energy, scene.wavelengths_nm)
    coco = collection.groundtruth()
    image = next(img for img in coco["images"] if img["scene_id"] == scene_id)
    ann = next(a for a in coco["annotations"] if a["image_id"] == image["id"])
    sx, sy = cols / image["width"], rows / image["height"]
    x, y, w, h = ann["bbox"]
    bbox = [x * sx, y * sy, w * sx, h * sy]

    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    opts = {}
    if gzip:  # higher levels save ~3 % more on noisy renders and take twice as long
        opts = {"chunks": (min(rows, 128), min(cols, 128), energy.shape[2]), "compression": "gzip",
                "compression_opts": 1, "shuffle": True}
    tmp = out.with_name(f".{out.name}.tmp")
    with h5py.File(tmp, "w") as f:
        f.attrs.update({
            "format": "metricscenes-isetcam", "format_version": FORMAT_VERSION,
            "package_version": __version__, "collection": collection.name,
            "manifest_sha256": collection.manifest_sha256, "scene_id": scene_id, "condition": condition,
            "environment_id": int(image["environment_id"]), "car_id": int(image.get("car_id", -1)),
            "heading": str(image.get("heading", "")), "distance_m": float(image["distance_m"]),
            "hfov_deg": hfov, "vfov_deg": vfov,
            "extent_tan": np.array(extent.as_tuple()), "width_px": cols, "height_px": rows,
            "mrad_per_px": np.array([1e3 * extent.width / cols, 1e3 * extent.height / rows]),
            "dimension_order": DIMENSION_ORDER,
            "layers_json": json.dumps([
                {"layer": name, "extent_tan": list(layer.extent.as_tuple()),
                 "mrad_per_px": [1e3 * layer.pixel_tan[0], 1e3 * layer.pixel_tan[1]],
                 "shape": list(layer.radiance.shape)}
                for name, layer in zip(("plate", "inset"), scene.layers)]),
        })
        wave = f.create_dataset("wave", data=scene.wavelengths_nm.astype(np.float64))
        wave.attrs["units"] = "nm"
        centres_x = extent.x0 + (np.arange(cols) + 0.5) * extent.width / cols
        centres_y = extent.y0 + (np.arange(rows) + 0.5) * extent.height / rows
        xs = f.create_dataset("x_tan", data=centres_x)
        ys = f.create_dataset("y_tan", data=centres_y)
        xs.attrs["units"] = ys.attrs["units"] = "tangent of the angle from the optical axis (x right, y down)"
        for scale in (ys, xs, wave):
            scale.make_scale(scale.name.lstrip("/"))
        for name, data, units in (("photons", photons, PHOTON_UNITS), ("radiance", energy, RADIANCE_UNITS)):
            ds = f.create_dataset(name, data=data, **opts)
            ds.attrs.update({"units": units, "dimension_order": DIMENSION_ORDER})
            for axis, scale in enumerate((ys, xs, wave)):
                ds.dims[axis].attach_scale(scale)
        gt = f.create_group("groundtruth")
        box = gt.create_dataset("bbox_xywh", data=np.array(bbox, dtype=np.float64))
        box.attrs.update({"units": "pixels of the exported grid, COCO [x, y, w, h], origin at the "
                                   "top-left corner of the top-left pixel",
                          "category": "car", "category_id": int(ann["category_id"])})
        gt.attrs["coco_image_json"] = json.dumps(image)
        gt.attrs["coco_annotation_json"] = json.dumps(ann)
    tmp.replace(out)
    return out


def export_scene(collection_dir: str | Path, scene_id: str, condition: str, fmt: str, out: str | Path,
                 width_px: int | None = None, gzip: bool = False) -> Path:
    """Open a collection and export one scene in format ``fmt`` (only 'hdf5' so far)."""
    if fmt not in EXPORT_FORMATS:
        raise ExportError(f"unknown export format {fmt!r} (supported: {', '.join(EXPORT_FORMATS)})")
    if width_px is not None:
        grid_for_width(width_px, (16, 9))  # validate before reading any radiance
    return export_hdf5(Collection.open(collection_dir), scene_id, condition, out, width_px=width_px,
                       gzip=gzip)
