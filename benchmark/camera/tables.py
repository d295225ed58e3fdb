"""Numeric CSV tables of user data — a sensor's QE (:func:`benchmark.camera.spec_files.check_qe_table`),
a lens's PSF or MTF (:mod:`benchmark.camera.lens`) — read with one-line refusals that name
the file, the row and the column."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np


def read_numeric_csv(path: str | Path, what: str, columns: tuple[str, ...], *, optional: tuple[str, ...] = (),
                     expected: str) -> dict[str, np.ndarray]:
    """The named columns of a CSV file with a header row, as float arrays (optional columns
    where present). ``what`` names the table in messages (``"QE table"``), ``expected`` its
    columns. One-line ValueError where the file is unreadable, lacks a column or holds a
    value that is not a finite number."""
    name = Path(path).name
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # an empty or short file: refused below, one line
            table = np.genfromtxt(path, delimiter=",", names=True, ndmin=1)
    except (OSError, ValueError) as exc:
        # numpy's "Some errors were detected !" heads the lines that say what: the first of them
        lines = [line.strip() for line in str(exc).splitlines() if line.strip()] or [type(exc).__name__]
        if len(lines) > 1 and lines[0].startswith("Some errors were detected"):
            first = re.sub(r"Line #(\d+) \(got (\d+) columns instead of (\d+)\)", r"line \1 has \2 columns, the header \3",
                           lines[1])
            more = f", and {len(lines) - 2} more such line(s)" if len(lines) > 2 else ""
            raise ValueError(f"{what} {name}: not a table of {expected} ({first}{more})") from None
        raise ValueError(f"{what} {name}: unreadable ({lines[0]})") from None
    names = table.dtype.names or ()
    missing = [c for c in columns if c not in names]
    if missing:
        raise ValueError(f"{what} {name}: lacks column(s) {', '.join(missing)} (expected {expected})")
    out = {}
    for column in (*columns, *(c for c in optional if c in names)):
        values = np.atleast_1d(np.asarray(table[column], float))
        bad = np.nonzero(~np.isfinite(values))[0]
        if bad.size:
            raise ValueError(f"{what} {name}: row {bad[0] + 1} {column} is not a number")
        out[column] = values
    return out


def wavelength_groups(wavelengths_nm: np.ndarray, what: str, name: str) -> list[slice]:
    """The row ranges of a long-format table, one per wavelength: rows must be grouped by
    wavelength in increasing order (one-line ValueError naming the row otherwise)."""
    wl = np.asarray(wavelengths_nm, float)
    step = np.nonzero(np.diff(wl) < 0)[0]
    if step.size:
        i = step[0]
        raise ValueError(f"{what} {name}: rows must be grouped by wavelength_nm in increasing order: row {i + 2} "
                         f"({wl[i + 1]:g}) follows row {i + 1} ({wl[i]:g})")
    starts = np.concatenate([[0], np.nonzero(np.diff(wl) > 0)[0] + 1, [wl.size]])
    return [slice(int(a), int(b)) for a, b in zip(starts[:-1], starts[1:])]


TABLE_WAVELENGTH_RANGE_NM = (200.0, 1200.0)
"""Where a table's wavelengths may lie, nm (silicon's response; wavelengths in µm are refused with that hint)."""


def check_wavelengths_nm(wavelengths_nm: np.ndarray, what: str, name: str) -> None:
    """One-line ValueError where a table's wavelengths leave :data:`TABLE_WAVELENGTH_RANGE_NM`."""
    wl = np.asarray(wavelengths_nm, float)
    lo, hi = TABLE_WAVELENGTH_RANGE_NM
    first, last = float(wl.min()), float(wl.max())
    if first < lo or last > hi:
        hint = f"; if they are in um, write {first * 1000:g} to {last * 1000:g}" if last < 10 else ""
        raise ValueError(f"{what} {name}: wavelengths {first:g} to {last:g} nm lie outside {lo:g} to {hi:g} nm{hint}")
