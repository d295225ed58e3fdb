"""The write side of a collection; :class:`metricscenes.store.Collection` is the read side.

:class:`CollectionWriter` makes every file of a collection folder (its layout:
:mod:`metricscenes.store`): the stamps under ``progress/`` and the store's groups
(:meth:`~CollectionWriter.prepare`), each unit's arrays (:class:`UnitArrays`), the
progress records (:class:`~metricscenes.records.UnitRecord`), then ``groundtruth.json``
and ``manifest.resolved.yaml`` (:meth:`~CollectionWriter.finish`). ``generate`` decides
what to render; this module is how it lands on disk.

One writer per file: a unit's arrays are written by the process that renders it (perhaps a
worker on another machine) and by nothing else; the stamps, records, ground truth and
resolved manifest only by the process that holds the collection's lock
(:meth:`~CollectionWriter.locked`, :mod:`metricscenes.lock`). Every array is one zarr
chunk; text files are written atomically (:func:`metricscenes.files.write_atomic`), a
unit's record after its arrays and the resolved manifest last, so a run killed at any point
leaves no half-written file and no record of a unit whose arrays are not all there.

Codecs: radiance chunks are encoded as bytes (little-endian) + Blosc (zstd level 1, byte
shuffle, the chunk as one block): codecs of the zarr v3 core specification, lossless, so
the values and their sha256 are the ones rendered (:data:`RADIANCE_COMPRESSORS`).
Collections written before with zarr's default (bytes + zstd level 0) read the same:
zarr takes each array's chain from its ``zarr.json``. A manifest's ``store:
{mantissa_bits: N}`` rounds radiance to N of float32's 23 mantissa bits before the write
(BitRound, :func:`round_mantissa`): at most 2^-(N+1) relative error per value (RMS about
2^-N / sqrt(12)); the sha256 recorded is the rounded values', and such arrays carry a
``mantissa_bits`` attribute. Sizes, times and the error against the render's own noise:
docs/performance.md, "Store size".
"""

from __future__ import annotations

import hashlib
import json
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import numpy as np

from metricscenes.files import write_atomic
from metricscenes.geometry import TanExtent
from metricscenes.manifest import AUTO_VARIANT, WIDE_KINDS, Manifest
from metricscenes.plan import ScenePlan
from metricscenes.records import PLATE, ResolvedManifest, UnitRecord, resolved_content_sha256
from metricscenes.spectral import RADIANCE_UNITS, WAVELENGTHS_NM
from metricscenes.store import (
    DIMENSIONS, GROUNDTRUTH_FILE, PROGRESS_DIR, RADIANCE_STORE, RESOLVED_MANIFEST_FILE, CollectionError, array_sha256,
    attributes_sha256,
)

MANIFEST_STAMP = "manifest_sha256"
"""File under ``progress/`` naming the manifest the records were made from."""
VARIANT_STAMP = "render_variant"
"""File under ``progress/`` naming the Mitsuba variant that renders the collection."""
# Arrays are always written with their chunk, even an all-zero one, so that a missing
# chunk file is damage (zarr would otherwise read it as fill-value zeros).
WRITE_CONFIG = {"write_empty_chunks": True}
# Radiance chunks: bytes (little-endian), then Blosc: byte shuffle and zstd level 1 over the
# whole chunk as one block; all codecs of the zarr v3 core specification (any v3 reader
# decodes them). Monte Carlo noise fills the low mantissa bytes, which no lossless coder
# shrinks; the shuffle puts the sign-exponent bytes of all values together, where they
# compress well. Against zarr's default (bytes + zstd level 0, what collections were written
# with before: they still read) 6 % smaller, written 3x faster, read as fast (measured by
# benchmarks/studies/store_codecs.py: docs/performance.md, "Store size").
RADIANCE_COMPRESSORS = ({"name": "blosc", "configuration": {"cname": "zstd", "clevel": 1, "shuffle": "shuffle",
                                                             "typesize": 4, "blocksize": 2**30}},)
# c-blosc 1 refuses buffers of 2 GiB or more: such a chunk (a film the manifest's bounds allow
# only on a very large machine) is written with zarr's default zstd instead.
BLOSC_MAX_BYTES = 2**31 - 64
ZARR_DEFAULT_COMPRESSORS = ({"name": "zstd", "configuration": {"level": 0, "checksum": False}},)


def round_mantissa(values: np.ndarray, mantissa_bits: int) -> np.ndarray:
    """float32 values rounded to nearest (ties to even) with ``mantissa_bits`` of their 23
    explicit mantissa bits kept: numcodecs' BitRound (Klöwer et al. 2021, "Compressing
    atmospheric data into its real information content", Nat. Comput. Sci. 1, 713-724).

    The relative error of a normal value is at most 2^-(mantissa_bits + 1) (its RMS over
    many values about 2^-mantissa_bits / sqrt(12)); zeros stay zero and the sign is kept.
    The zeroed low bits are what makes the chunk compress."""
    from numcodecs import BitRound

    a = np.ascontiguousarray(values, dtype=np.float32)
    return np.asarray(BitRound(keepbits=mantissa_bits).encode(a)).view(np.float32)


def stored_form(cube: np.ndarray, mantissa_bits: int | None, spectral_basis_k: int | None
                ) -> tuple[np.ndarray, np.ndarray | None]:
    """What :meth:`UnitArrays.write_radiance` stores of ``cube`` with these store settings
    (the manifest's ``store``; None: lossless, 31 bands): the values (K coefficients per pixel
    on the cube's basis, or the 31 bands), rounded, and the basis (None for 31 bands)."""
    from metricscenes import spectral_basis

    cube = np.ascontiguousarray(cube, dtype=np.float32)
    basis = None if spectral_basis_k is None else spectral_basis.basis_for(cube, spectral_basis_k)
    stored = cube if basis is None else spectral_basis.encode(cube, basis)
    if mantissa_bits is not None:
        stored = round_mantissa(stored, mantissa_bits)
    return stored, basis


def radiance_attributes(light_group: str, extent: TanExtent, mantissa_bits: int | None,
                        basis_attribute: list | None, extra_attrs: dict | None = None) -> dict:
    """The attributes of a radiance array (``basis_attribute``: its ``spectral_basis``, K
    lists of 31, or None for 31 bands): what :meth:`UnitArrays.write_radiance` writes, and
    what ``generate`` expects of arrays written before their attributes had a sha256."""
    return {
        "units": RADIANCE_UNITS,
        "wavelengths_nm": [float(w) for w in WAVELENGTHS_NM],
        "extent_tan": list(extent.as_tuple()),
        "light_group": light_group,
        **({} if mantissa_bits is None else {"mantissa_bits": mantissa_bits}),
        **({} if basis_attribute is None else {"spectral_basis": basis_attribute}),
        **(extra_attrs or {}),
    }


def mask_attributes(extent: TanExtent) -> dict:
    """The attributes of an inset's mask (see :func:`radiance_attributes`)."""
    return {"extent_tan": list(extent.as_tuple()), "meaning": "car instance mask"}


def _stored_attributes_sha256(root: Path, path: str) -> str:
    """sha256 of an array's attributes as its ``zarr.json`` now holds them (read back, so the
    hash is of what every reader will see)."""
    import zarr

    return attributes_sha256(dict(zarr.open_array(store=str(root / RADIANCE_STORE), path=path, mode="r").attrs))


def read_back(stored: np.ndarray, basis: np.ndarray | None) -> np.ndarray:
    """The 31 bands a reader gets back of :func:`stored_form`'s values (what an array's
    sha256 is of)."""
    from metricscenes import spectral_basis

    return stored if basis is None else spectral_basis.decode(stored, basis)


class UnitArrays:
    """The arrays of one unit of work, written by the process that renders it: its radiance
    per light group (``<kind>/<unit>/<light_group>``) and, for an inset, the car's mask
    (``masks/<unit>``). :attr:`sha256` collects what was written and :attr:`attributes_sha256`
    its attributes' hashes, for the unit's record."""

    def __init__(self, root: str | Path, unit: str, mantissa_bits: int | None = None,
                 spectral_basis: int | None = None):
        self.root = Path(root)
        self.unit = unit
        self.mantissa_bits = mantissa_bits  # the manifest's store.mantissa_bits; None: lossless
        self.spectral_basis = spectral_basis  # store.spectral_basis: K basis spectra per array; None: 31 bands
        self.sha256: dict[str, str] = {}
        self.attributes_sha256: dict[str, str] = {}

    def write_radiance(self, kind: str, light_group: str, cube: np.ndarray, extent: TanExtent,
                       extra_attrs: dict | None = None) -> str:
        """Write one radiance cube as a single-chunk zarr array (:data:`RADIANCE_COMPRESSORS`);
        return the sha256 of the values stored.

        With ``spectral_basis`` K the cube is stored as K coefficients per pixel
        (:mod:`metricscenes.spectral_basis`), its basis spectra in the array's
        ``spectral_basis`` attribute (K lists of 31). With ``mantissa_bits`` the stored values
        are rounded (:func:`round_mantissa`) and the ``mantissa_bits`` attribute records the
        width. The sha256 is that of the values a reader gets back (rounded, decoded)."""
        import zarr

        from metricscenes import spectral_basis

        stored, basis = stored_form(cube, self.mantissa_bits, self.spectral_basis)
        attrs = radiance_attributes(light_group, extent, self.mantissa_bits,
                                    None if basis is None else basis.T.tolist(), extra_attrs)
        path = f"{kind}/{self.unit}/{light_group}"
        self._check_own_folder(path)
        arr = zarr.create_array(
            store=str(self.root / RADIANCE_STORE), name=path, shape=stored.shape, dtype="float32", chunks=stored.shape,
            dimension_names=DIMENSIONS if basis is None else (*DIMENSIONS[:2], spectral_basis.DIMENSION),
            attributes=attrs,
            compressors=RADIANCE_COMPRESSORS if stored.nbytes <= BLOSC_MAX_BYTES else ZARR_DEFAULT_COMPRESSORS,
            overwrite=True, config=WRITE_CONFIG,
        )
        arr[...] = stored
        self.sha256[path] = array_sha256(read_back(stored, basis))
        self.attributes_sha256[path] = _stored_attributes_sha256(self.root, path)
        return self.sha256[path]

    def _check_own_folder(self, path: str) -> None:
        """Refuse (:class:`CollectionError`, naming it) an array folder that is a symbolic link:
        zarr replaces an array by removing its folder, which it cannot do through a link
        ("Cannot call rmtree on a symbolic link", no path)."""
        folder = self.root / RADIANCE_STORE / path
        if folder.is_symlink():
            raise CollectionError(f"{self.root}: {RADIANCE_STORE}/{path} is a symbolic link (to {folder.readlink()}), "
                                  "and generate writes an array only in its own folder: remove the link (the array is "
                                  "rendered again) or put the folder it points to in its place")

    def write_mask(self, mask: np.ndarray, extent: TanExtent) -> str:
        """Write the car's instance mask (True = car) over the inset window; return its sha256."""
        import zarr

        mask = np.ascontiguousarray(mask, dtype=bool)
        path = f"masks/{self.unit}"
        self._check_own_folder(path)
        arr = zarr.create_array(
            store=str(self.root / RADIANCE_STORE), name=path, shape=mask.shape, dtype="bool",
            chunks=mask.shape, dimension_names=("y", "x"), overwrite=True, config=WRITE_CONFIG,
            attributes=mask_attributes(extent),
        )
        arr[...] = mask
        self.sha256[path] = array_sha256(mask)
        self.attributes_sha256[path] = _stored_attributes_sha256(self.root, path)
        return self.sha256[path]


class CollectionWriter:
    """Everything that writes a collection folder ``root`` (nothing is touched until a
    method is called, so a worker may make one to write its unit's arrays)."""

    def __init__(self, root: str | Path):
        self.root = Path(root)

    @contextmanager
    def locked(self, notice=None):
        """Create ``root`` and hold its ``generate.lock`` for the block: one writer at a
        time, released on errors too (:class:`~metricscenes.lock.LockError` if another
        holds it; ``notice`` gets one line when a stale lock is taken over)."""
        from metricscenes.lock import collection_lock

        self.root.mkdir(parents=True, exist_ok=True)
        with collection_lock(self.root, notice=notice):
            yield self

    def unit_arrays(self, unit: str, mantissa_bits: int | None = None, spectral_basis: int | None = None) -> UnitArrays:
        """The writer of unit ``unit``'s arrays (``mantissa_bits``, ``spectral_basis``: the
        manifest's ``store`` settings; None: lossless, 31 bands)."""
        return UnitArrays(self.root, unit, mantissa_bits, spectral_basis)

    # --- stamps ------------------------------------------------------------------------
    def prepare(self, manifest: Manifest, variant: str) -> None:
        """Stamp ``root`` with the manifest's sha256 and the Mitsuba ``variant`` and create
        the store, refusing (:class:`CollectionError`) a folder whose finished units came
        from another manifest or another variant."""
        import zarr

        progress = self.root / PROGRESS_DIR
        progress.mkdir(exist_ok=True)
        stamp = progress / MANIFEST_STAMP
        finished = self._has_finished_work()  # (a run that finished no unit, e.g. a render error, left nothing to keep)
        if finished and stamp.exists() and stamp.read_text().strip() != manifest.sha256():
            raise CollectionError(f"{self.root}: holds a collection of another manifest; "
                                  "choose another --out or delete it")
        recorded = self._recorded_variant(manifest)
        if finished and recorded != variant:
            # The same manifest with render.variant: auto, resumed on a machine that resolves it otherwise.
            raise CollectionError(
                f"{self.root}: rendered with Mitsuba variant {recorded or '(unknown)'}, this run would render with "
                f"{variant} (render.variant: {manifest.render.variant}); finish it where it was started or choose "
                "another --out")
        write_atomic(stamp, manifest.sha256() + "\n")
        write_atomic(progress / VARIANT_STAMP, variant + "\n")
        zroot = zarr.open_group(str(self.root / RADIANCE_STORE), mode="a")
        zroot.attrs.update({"units": "W sr-1 m-2 nm-1", "manifest_sha256": manifest.sha256(),
                            "dimension_names": ["y", "x", "wavelength"]})
        for name in ("plates", "insets", "frames", "masks", *(WIDE_KINDS if manifest.wide_plate else ())):
            zroot.require_group(name)

    def _has_finished_work(self) -> bool:
        return any((self.root / PROGRESS_DIR).glob("*.json")) or (self.root / RESOLVED_MANIFEST_FILE).exists()

    def _recorded_variant(self, manifest: Manifest) -> str | None:
        """The variant that rendered the units already in ``root`` (None: unknown)."""
        try:
            return (self.root / PROGRESS_DIR / VARIANT_STAMP).read_text().strip()
        except OSError:  # collections made before the stamp could only use the variant their manifest names
            return None if manifest.render.variant == AUTO_VARIANT else manifest.render.variant

    # --- progress records --------------------------------------------------------------
    def _record_path(self, unit: str) -> Path:
        return self.root / PROGRESS_DIR / f"{unit}.json"

    def read_record(self, unit: str) -> UnitRecord | None:
        """The record of a finished unit; None where there is none to read (absent, torn, or
        another unit's), :class:`~metricscenes.records.RecordError` where one is incomplete."""
        try:
            data = json.loads(self._record_path(unit).read_text())
        except (OSError, ValueError):  # (json's and UTF-8's decode errors are ValueErrors)
            return None  # absent or torn: redo the unit
        if not isinstance(data, dict) or data.get("unit") != unit:
            return None
        return UnitRecord.from_dict(data)

    def write_record(self, record: UnitRecord) -> None:
        """Record a finished unit (after all its arrays are written: the record is the claim)."""
        write_atomic(self._record_path(record.unit), record.to_json())

    # --- the collection's own files, last ----------------------------------------------
    def finish(self, manifest: Manifest, scenes: list[ScenePlan], records: dict[str, UnitRecord],
               variant: str, light_groups: tuple[str, ...] | None = None) -> None:
        """Write ``groundtruth.json`` and then ``manifest.resolved.yaml`` from the records of
        all units (every one finished, each holding ``light_groups``; None: all of the
        manifest's): the collection is complete when the latter lands."""
        from metricscenes import __version__
        from metricscenes.groundtruth import coco_groundtruth

        ref_w, ref_h = manifest.reference_grid.width_px, manifest.reference_grid.height_px
        images, boxes = [], []
        for s in scenes:
            inset = records[s.scene_id].inset
            env = s.environment
            images.append({
                "id": s.image_id, "file_name": f"{s.scene_id}.png", "width": ref_w, "height": ref_h,
                "scene_id": s.scene_id, "environment_id": env.environment_id, "distance_m": s.distance_m,
                "car_id": env.car_id, "road_id": env.road_id, "heading": env.heading,
                "mask_vs_projection_iou": inset.mask_iou,
            })
            boxes.append(list(inset.bbox_xywh))
        info = {"description": f"metricscenes collection {manifest.name}", "version": __version__,
                "protocol": manifest.protocol, "manifest_sha256": manifest.sha256()}
        gt_text = json.dumps(coco_groundtruth(images, boxes, info), indent=1)
        resolved = ResolvedManifest(
            package_version=__version__,
            manifest_sha256=manifest.sha256(),
            manifest_json=manifest.model_dump(mode="json"),
            render_variant=variant,
            light_groups=None if light_groups is None else list(light_groups),
            arrays={path: sha for key in sorted(records) for path, sha in sorted(records[key].arrays.items())},
            # (None if a record predates them: generate records them first, so this is for callers of old records)
            attributes_sha256=None if any(r.attributes is None for r in records.values()) else {
                path: sha for key in sorted(records) for path, sha in sorted(records[key].attributes.items())},
            # (sorted: a record read back from progress/ has sorted keys, one just rendered has not)
            illuminance_lux={key: dict(sorted((records[key].illuminance_lux or {}).items()))
                             for key in sorted(records) if records[key].kind == PLATE},
            plan=[s.summary() for s in scenes],
            groundtruth_sha256=hashlib.sha256(gt_text.encode()).hexdigest(),
        )
        # Last, over all of the above: an edited illuminance or hash is caught on open.
        content = resolved_content_sha256(resolved.as_dict())
        write_atomic(self.root / GROUNDTRUTH_FILE, gt_text)
        write_atomic(self.root / RESOLVED_MANIFEST_FILE,
                     replace(resolved, content_sha256=content).to_yaml())
