"""Checked reading of a collection's arrays (:mod:`metricscenes.store`'s layout and integrity):
every array against its recorded sha256 when first read in a process (per file version),
its attributes against the sha256 of their canonical JSON each time they are read, and
:class:`CollectionError`, the one-line error of a missing, incomplete or corrupted collection."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

from metricscenes.geometry import TanExtent
from metricscenes.manifest import canonical_sha256
from metricscenes.spectral_basis import decode

RADIANCE_STORE = "radiance.zarr"
GROUNDTRUTH_FILE = "groundtruth.json"
RESOLVED_MANIFEST_FILE = "manifest.resolved.yaml"
PROGRESS_DIR = "progress"
DIMENSIONS = ("y", "x", "wavelength")
REPAIR_HINT = "rerun `metricscenes generate` with its manifest to repair it"


class CollectionError(ValueError):
    """A collection folder is missing, incomplete or corrupted (one-line message)."""


# Arrays that matched their sha256 in this process, by file version (see _fingerprint):
# reading a plate shared by six scenes, or a scene under several conditions, hashes it once.
_CHECKED: set[tuple] = set()


def array_sha256(array: np.ndarray) -> str:
    """sha256 over dtype, shape and the C-order little-endian bytes of an array."""
    a = np.ascontiguousarray(array, dtype=np.dtype(array.dtype).newbyteorder("<"))
    h = hashlib.sha256(f"{a.dtype.str}{a.shape}".encode())
    h.update(a.reshape(-1).view(np.uint8))  # the bytes in place: a copy of a plate is 257 MB
    return h.hexdigest()


def attributes_sha256(attributes: dict) -> str:
    """sha256 of an array's attributes as its ``zarr.json`` holds them (canonical JSON:
    sorted keys, no spaces), the same for the dict written and the one read back."""
    return canonical_sha256(attributes)


def check_attributes(attributes: dict, expected: str | None, label: str, path: str) -> None:
    """Raise :class:`CollectionError` if ``attributes`` are not the ones whose sha256 is
    ``expected`` (None: not recorded, in collections written before it was)."""
    if expected is not None and attributes_sha256(attributes) != expected:
        raise CollectionError(f"{label}: {path} attributes do not match their sha256 (its zarr.json was edited "
                              "or damaged)")


def _fingerprint(root: Path, path: str) -> tuple:
    """What identifies one version of an array's files: names, inodes, sizes, mtimes."""
    folder = root / RADIANCE_STORE / path
    files = []
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            st = p.stat()
            files.append((str(p.relative_to(folder)), st.st_ino, st.st_size, st.st_mtime_ns))
    return (str(folder.resolve()), *files)


def read_checked(root: Path, group, path: str, expected: str | None, label: str,
                 expected_attributes: str | None = None) -> tuple[np.ndarray, dict]:
    """Read one array of a collection and its attributes; check it against ``expected``
    (its recorded sha256; None for masks of older collections, which have none) and its
    attributes against ``expected_attributes`` (:func:`attributes_sha256`; None for
    collections written before it was recorded).

    Raises :class:`CollectionError` ``"<label>: <path> <what is wrong>"`` if the array is
    missing, unreadable, or not the bytes that were written (a deleted chunk reads as
    fill values, so it fails the hash too), or if its attributes were changed.
    """
    import zarr

    try:
        node = group[path]
    except KeyError:
        raise CollectionError(f"{label}: {path} is missing") from None
    except Exception as exc:  # its zarr.json is damaged
        raise CollectionError(f"{label}: {path} is unreadable ({type(exc).__name__})") from None
    if not isinstance(node, zarr.Array):
        raise CollectionError(f"{label}: {path} is missing (a group is in its place)")
    fingerprint = _fingerprint(root, path) + (expected,)
    try:
        data = np.asarray(node[...])
        attrs = dict(node.attrs)
    except Exception as exc:  # zstd, numcodecs and zarr raise many types for a damaged chunk
        raise CollectionError(f"{label}: {path} is unreadable ({type(exc).__name__})") from None
    basis = None
    if "spectral_basis" in attrs:  # K coefficients per pixel: the radiance is decoded (store.spectral_basis)
        try:
            basis = np.asarray(attrs["spectral_basis"], dtype=np.float64)
        except (TypeError, ValueError):
            basis = None
        bands = len(attrs.get("wavelengths_nm") or ())
        if basis is None or basis.ndim != 2 or data.ndim != 3 or basis.shape != (data.shape[-1], bands):
            raise CollectionError(f"{label}: {path} is unreadable (its spectral_basis does not fit its coefficients)")
    check_attributes(attrs, expected_attributes, label, path)  # (after the basis' shape: the more telling error)
    if basis is not None:
        data = decode(data, basis.T)
    if expected is not None and fingerprint not in _CHECKED:
        if array_sha256(data) != expected:
            has_chunk = any(name != "zarr.json" for name, *_ in fingerprint[1:-1])
            raise CollectionError(f"{label}: {path} does not match its sha256"
                                  + ("" if has_chunk else " (its chunk is missing)"))
        _CHECKED.add(fingerprint)
    return data, attrs


def _radiance_shape(arr) -> tuple[int, int, int]:
    """(rows, cols, bands) of a radiance array as a reader gets it, from its metadata (an array
    stored through a spectral basis holds K coefficients per pixel, not its bands)."""
    return (*arr.shape[:2], len(arr.attrs.get("wavelengths_nm", ())) or arr.shape[2])


def _extent(attrs: dict, label: str, path: str) -> TanExtent:
    try:
        return TanExtent(*(float(v) for v in attrs["extent_tan"]))
    except (KeyError, TypeError, ValueError):
        raise CollectionError(f"{label}: {path} has no valid extent_tan attribute") from None
