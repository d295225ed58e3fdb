"""Photometry of spectral radiance: CIE 1931 XYZ, luminance, image-plane illuminance."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from metricscenes.spectral import BAND_WIDTH_NM, WAVELENGTHS_NM

MAX_LUMINOUS_EFFICACY_LM_W = 683.0
"""K_m, lm/W (CIE photopic)."""


@lru_cache(maxsize=1)
def _cmfs() -> np.ndarray:
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    return np.stack([np.interp(WAVELENGTHS_NM, cmfs.wavelengths, cmfs.values[:, i]) for i in range(3)], axis=1)


def radiance_to_xyz(radiance: np.ndarray) -> np.ndarray:
    """Spectral radiance (..., 31) W·sr⁻¹·m⁻²·nm⁻¹ → XYZ (..., 3) with Y in cd/m².

    The same sum turns spectral irradiance (W·m⁻²·nm⁻¹) into Y in lux.
    """
    return MAX_LUMINOUS_EFFICACY_LM_W * BAND_WIDTH_NM * (np.asarray(radiance, dtype=np.float64) @ _cmfs())


def image_plane_illuminance_lux(mean_luminance_cd_m2: float, f_number: float) -> float:
    """Illuminance on the sensor of an ideal lens (T = 1) at f/N: E = π L / (1 + 4 N²)."""
    return float(np.pi * mean_luminance_cd_m2 / (1.0 + 4.0 * f_number**2))
