"""The spectral sampling shared by every stage (ISET convention).

31 bands, 400-700 nm in 10 nm steps. A band value is the radiance averaged over
[centre - 5 nm, centre + 5 nm], in W·sr⁻¹·m⁻²·nm⁻¹.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

WAVELENGTHS_NM: np.ndarray = np.arange(400.0, 701.0, 10.0)
"""Band centres in nm, shape (31,)."""

SENSOR_DATA_DIR = Path(__file__).parent / "data"
"""Packaged sensor spectra (``imx363_qe.csv``: the IMX363's colour-filter QE x IR cut), read by
the store's spectral basis (:mod:`metricscenes.spectral_basis`) and the benchmark's cameras."""

BAND_WIDTH_NM: float = 10.0
RADIANCE_UNITS = "W sr-1 m-2 nm-1"

PLANCK_J_S = 6.62607015e-34
SPEED_OF_LIGHT_M_S = 299792458.0


def photon_energy_j(wavelengths_nm: np.ndarray) -> np.ndarray:
    """Energy of one photon, J, at each wavelength in nm (E = h c / λ)."""
    return PLANCK_J_S * SPEED_OF_LIGHT_M_S / (np.asarray(wavelengths_nm, dtype=float) * 1e-9)


def resample_spectrum(
    wavelengths_nm: np.ndarray, values: np.ndarray, target_nm: np.ndarray = WAVELENGTHS_NM, *,
    hold_ends: bool = False,
) -> np.ndarray:
    """Linearly interpolate a tabulated spectrum onto ``target_nm``: zero outside the table
    (a filter, a lamp: no light where nothing was measured), or with ``hold_ends`` its end
    values held (a reflectance, an illuminant, a colour-matching table)."""
    if hold_ends:
        return np.interp(target_nm, wavelengths_nm, values)
    return np.interp(target_nm, wavelengths_nm, values, left=0.0, right=0.0)
