"""The files a camera spec names, and their checks: a user table's relative CSV path
(:func:`check_relative_csv`), a file's content digest (:func:`file_sha256`, which puts a lens
table's content in the camera's sha256), and the sensor's QE table (:func:`read_qe_table`,
:func:`check_qe_table`: a physically possible table, or a one-line refusal naming the file,
the row and the column; :func:`packaged_qe`: the packaged files by name).

A spec loaded from a file is validated with the file's folder in the validation context
(:data:`SPEC_DIR_CONTEXT`): the files it names resolve there (docs/camera.md, "Refused specs").
"""

from __future__ import annotations

import functools
import hashlib
from pathlib import Path, PurePosixPath, PureWindowsPath

import numpy as np

from benchmark.camera.tables import TABLE_WAVELENGTH_RANGE_NM, check_wavelengths_nm, read_numeric_csv
from metricscenes.spectral import SENSOR_DATA_DIR


SPEC_DIR_CONTEXT = "spec_dir"
"""Validation context key: the folder of the spec file (``qe`` user files resolve there)."""


def check_relative_csv(value: str, columns: str, packaged: str = "") -> str:
    """A user table's path must be a relative POSIX path of a ``.csv`` inside its folder: no
    absolute path or drive, no ``..``, no backslash, NUL or line break."""
    bad = next((c for c in ("\\", "\0", "\n", "\r") if c in value), None)
    if bad is not None:
        raise ValueError(f"a relative path with '/' separators is expected, without {bad!r}")
    if PurePosixPath(value).is_absolute() or PureWindowsPath(value).drive or value.startswith("~"):
        raise ValueError(f"an absolute path is refused: name {packaged}a file beside the spec file")
    if ".." in PurePosixPath(value).parts:
        raise ValueError("'..' is refused: the file must lie in the spec file's folder or below it")
    if PurePosixPath(value).suffix.lower() != ".csv":
        raise ValueError(f"a .csv file is expected (columns {columns})")
    return value


def file_sha256(path: str | Path) -> str:
    """sha256 (hex) of a file's bytes; cached while the file's size and modification time stay."""
    stat = Path(path).stat()
    return _file_sha256(str(Path(path).resolve()), stat.st_size, stat.st_mtime_ns)


@functools.lru_cache(maxsize=32)
def _file_sha256(path: str, size: int, mtime_ns: int) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def check_qe_name(value: str) -> str:
    """``sensor.qe`` if it can name a QE file: a packaged name, or a relative CSV path
    (:func:`check_relative_csv`)."""
    return check_relative_csv(value, "wavelength_nm, qe_r, qe_g, qe_b", packaged="a packaged file (imx363_qe.csv) or ")


QE_WAVELENGTH_RANGE_NM = TABLE_WAVELENGTH_RANGE_NM
"""Where a silicon sensor's QE table may lie, nm (wavelengths in µm are refused with that hint)."""


def check_qe_table(path: str | Path) -> tuple:
    """(wavelengths nm, QE (3, n), IR-cut (n) or None) of a QE CSV file if it is physically
    possible (:func:`read_qe_table`). Else a one-line ValueError naming the file, the row and
    the column."""
    wl, qe, ir_cut = read_qe_table(path)
    return wl, np.stack([qe[c] for c in "rgb"]), ir_cut


def read_qe_table(path: str | Path) -> tuple:
    """(wavelengths nm, {"r", "g", "b"[, "c"]: QE (n)}, IR-cut (n) or None) of a QE CSV file if
    it is physically possible: columns ``wavelength_nm, qe_r, qe_g, qe_b[, qe_c][,
    ir_cut_transmittance]`` (``qe_c``: a measured clear-pixel curve), two or more rows, every
    value a finite number, wavelengths strictly increasing within
    :data:`QE_WAVELENGTH_RANGE_NM`, QE and transmittance between 0 and 1 (a fraction of the
    photons). Else a one-line ValueError naming the file, the row and the column."""
    name = Path(path).name
    columns = ("wavelength_nm", "qe_r", "qe_g", "qe_b")
    table = read_numeric_csv(path, "QE table", columns, optional=("qe_c", "ir_cut_transmittance"),
                             expected="wavelength_nm, qe_r, qe_g, qe_b[, qe_c][, ir_cut_transmittance]")
    rows = table["wavelength_nm"].size
    if rows < 2:
        raise ValueError(f"QE table {name}: {rows} row(s); two or more wavelengths are needed")
    wl = table["wavelength_nm"]
    step = np.nonzero(np.diff(wl) <= 0)[0]
    if step.size:
        i = step[0]
        raise ValueError(f"QE table {name}: wavelength_nm must increase row by row: row {i + 2} ({wl[i + 1]:g}) "
                         f"follows row {i + 1} ({wl[i]:g})")
    check_wavelengths_nm(wl, "QE table", name)
    for column in list(table)[1:]:
        values = table[column]
        outside = np.nonzero((values < 0) | (values > 1))[0]
        if outside.size:
            i = outside[0]
            hint = "; if the table is in percent, divide it by 100" if 0 <= values.min() and values.max() <= 100 else ""
            raise ValueError(f"QE table {name}: row {i + 1} {column} is {values[i]:g}: a fraction of the photons, "
                             f"between 0 and 1{hint}")
    qe = {c: table[f"qe_{c}"] for c in "rgbc" if f"qe_{c}" in table}
    return wl, qe, table.get("ir_cut_transmittance")


def packaged_qe(name: str) -> Path | None:
    """The packaged QE file called ``name`` (a bare file name), or None."""
    if "/" in name:
        return None
    path = SENSOR_DATA_DIR / name
    return path if path.is_file() else None
