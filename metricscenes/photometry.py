"""Photometry of spectra: CIE 1931 XYZ, luminance, illuminance, luminous intensity.

Every photometric value in the project is computed here. Three sums, kept apart because
results depend on each to the last bit: :func:`radiance_to_xyz` (the 31 bands, CIE 1931
ȳ), :func:`luminous_trapezoid` (a tabulated spectrum, V(λ), trapezoid rule: the lamps) and
:func:`luminous_band_sum` (band values, V(λ), one band per sample: the skies).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from metricscenes.spectral import BAND_WIDTH_NM, WAVELENGTHS_NM, resample_spectrum

MAX_LUMINOUS_EFFICACY_LM_W = 683.0
"""K_m, lm/W (CIE photopic)."""


def cie_1931_cmfs(wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """CIE 1931 2° colour-matching functions x̄, ȳ, z̄ at ``wavelengths_nm``, (bands, 3)."""
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    return np.stack([resample_spectrum(cmfs.wavelengths, cmfs.values[:, i], wavelengths_nm, hold_ends=True)
                     for i in range(3)], axis=1)


@lru_cache(maxsize=1)
def _cmfs() -> np.ndarray:
    return cie_1931_cmfs(WAVELENGTHS_NM)


def radiance_to_xyz(radiance: np.ndarray) -> np.ndarray:
    """Spectral radiance (..., 31) W·sr⁻¹·m⁻²·nm⁻¹ → XYZ (..., 3) with Y in cd/m².

    The same sum turns spectral irradiance (W·m⁻²·nm⁻¹) into Y in lux.
    """
    return MAX_LUMINOUS_EFFICACY_LM_W * BAND_WIDTH_NM * (np.asarray(radiance, dtype=np.float64) @ _cmfs())


def photopic_v(wavelengths_nm: np.ndarray) -> np.ndarray:
    """CIE 1924 photopic luminous efficiency V(λ) at ``wavelengths_nm`` (0 outside 360-830)."""
    import colour

    lef = colour.colorimetry.SDS_LEFS_PHOTOPIC["CIE 1924 Photopic Standard Observer"]
    return resample_spectrum(lef.wavelengths, lef.values, wavelengths_nm)


def luminous_trapezoid(wavelengths_nm: np.ndarray, spectral_values: np.ndarray) -> float:
    """Photometric value of a tabulated spectrum: K_m ∫ X(λ) V(λ) dλ (trapezoid rule).

    W·sr⁻¹·nm⁻¹ gives cd; W·sr⁻¹·m⁻²·nm⁻¹ gives cd/m²; W·m⁻²·nm⁻¹ gives lux.
    """
    wl = np.asarray(wavelengths_nm, float)
    return float(MAX_LUMINOUS_EFFICACY_LM_W * np.trapezoid(np.asarray(spectral_values, float) * photopic_v(wl), wl))


def luminous_band_sum(spectral_values: np.ndarray, wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> float:
    """Photometric value (lm, lux or cd/m²) of band values: K_m Σ X V Δλ, each sample
    standing for a band as wide as the (even) sampling step."""
    wl = np.asarray(wavelengths_nm, dtype=float)
    step = float(np.mean(np.diff(wl)))
    return float(MAX_LUMINOUS_EFFICACY_LM_W * np.sum(np.asarray(spectral_values) * photopic_v(wl)) * step)


def image_plane_illuminance_lux(mean_luminance_cd_m2: float, f_number: float) -> float:
    """Illuminance on the sensor of an ideal lens (T = 1) at f/N: E = π L / (1 + 4 N²)."""
    return float(np.pi * mean_luminance_cd_m2 / (1.0 + 4.0 * f_number**2))
