"""Spectral reflectances and Mitsuba BSDFs of road-scene materials and car paints.

All reflectances are tabulated in nm and handed to Mitsuba as ``irregular`` spectra, so
``scalar_spectral`` renders them physically (never RGB: Mitsuba would upsample it).

Sources
-------
- Natural and built materials (asphalt, concrete, soil, grass, leaves, bark): smooth
  approximations of the visible part (400-700 nm) of library spectra of the USGS Spectral
  Library v7 (Kokaly et al. 2017, doi:10.3133/ds1035) and the ECOSTRESS spectral library
  (Meerdink et al. 2019, doi:10.1016/j.rse.2019.05.015): aged asphalt 0.06-0.10 rising
  slowly with wavelength; concrete 0.2-0.35; green vegetation with the 550 nm peak, the
  chlorophyll trough near 670 nm and the start of the red edge at 700 nm; dry soil rising
  monotonically. Road-paint values follow typical white (TiO2) and yellow (lead-free azo or
  chromate) traffic paints, luminance factor about 0.7 and 0.5 (EN 1436 class minima 0.3/0.2).
- Car paints: the Jakob & Hanika (2019) sigmoid-polynomial reflectance model
  ("A low-dimensional function space for efficient spectral upsampling", Computer Graphics
  Forum 38(2)), with coefficients fitted by ``colour.recovery.find_coefficients_Jakob2019``
  (colour-science) to representative linear-sRGB albedos of common car colours under D65.
  Smooth, bounded in [0, 1] and metamerically faithful to the intended colour.
- Conductors use Mitsuba's built-in measured spectral ``eta``/``k`` tables (``Cr``, ``Al``).
"""

from __future__ import annotations

import numpy as np

from metricscenes.assets.parts import spectrum
from metricscenes.spectral import WAVELENGTHS_NM, resample_spectrum

_TABLE_NM = np.array([400, 425, 450, 475, 500, 525, 550, 575, 600, 625, 650, 675, 700], dtype=float)

# Diffuse reflectance tables on _TABLE_NM (see module docstring for sources).
_REFLECTANCE = {
    "asphalt": [0.065, 0.068, 0.071, 0.074, 0.077, 0.080, 0.083, 0.086, 0.089, 0.092, 0.095, 0.098, 0.100],
    "lane_white": [0.45, 0.60, 0.66, 0.68, 0.69, 0.70, 0.70, 0.70, 0.70, 0.70, 0.70, 0.70, 0.70],
    "lane_yellow": [0.07, 0.07, 0.07, 0.08, 0.12, 0.30, 0.50, 0.58, 0.60, 0.61, 0.61, 0.61, 0.61],
    "grass": [0.035, 0.040, 0.042, 0.045, 0.055, 0.090, 0.120, 0.100, 0.075, 0.065, 0.055, 0.060, 0.150],
    "dirt": [0.080, 0.090, 0.100, 0.115, 0.130, 0.150, 0.170, 0.195, 0.220, 0.240, 0.255, 0.265, 0.275],
    "bark": [0.050, 0.055, 0.060, 0.065, 0.070, 0.080, 0.090, 0.100, 0.115, 0.130, 0.140, 0.150, 0.160],
    "leaves": [0.030, 0.035, 0.037, 0.040, 0.048, 0.080, 0.105, 0.085, 0.060, 0.050, 0.040, 0.045, 0.130],
    "concrete": [0.22, 0.25, 0.27, 0.29, 0.30, 0.31, 0.32, 0.325, 0.33, 0.335, 0.34, 0.345, 0.35],
    "rubber": [0.030, 0.030, 0.030, 0.030, 0.031, 0.031, 0.032, 0.032, 0.033, 0.033, 0.034, 0.034, 0.035],
    # Car details: plate sheeting, black trim plastic, cabin interior, unlit lamp lenses.
    "plate_white": [0.55, 0.68, 0.74, 0.76, 0.77, 0.78, 0.78, 0.78, 0.78, 0.78, 0.78, 0.78, 0.78],
    "plate_yellow": [0.06, 0.06, 0.07, 0.08, 0.15, 0.40, 0.62, 0.70, 0.72, 0.72, 0.72, 0.72, 0.72],
    "trim_black": [0.040, 0.040, 0.040, 0.040, 0.040, 0.040, 0.040, 0.040, 0.040, 0.040, 0.040, 0.040, 0.040],
    "interior": [0.030, 0.030, 0.031, 0.032, 0.033, 0.034, 0.035, 0.036, 0.037, 0.038, 0.039, 0.040, 0.040],
    "lens_red": [0.03, 0.03, 0.03, 0.03, 0.03, 0.03, 0.035, 0.05, 0.15, 0.35, 0.45, 0.48, 0.50],
    "lens_amber": [0.03, 0.03, 0.03, 0.03, 0.04, 0.08, 0.20, 0.40, 0.50, 0.52, 0.52, 0.52, 0.52],
    "lens_clear": [0.55, 0.58, 0.60, 0.61, 0.62, 0.62, 0.62, 0.62, 0.62, 0.62, 0.62, 0.62, 0.62],
}

# Jakob & Hanika (2019) coefficients (c0, c1, c2) for R(λ) = S(c0 λ² + c1 λ + c2), λ in nm,
# S(x) = 1/2 + x / (2 sqrt(1 + x²)); fitted to the linear-sRGB albedo in the comment.
_PAINT_COEFFS = {
    "white": (-2.192523e-06, 2.546286e-03, 1.203419e-02),  # (0.80, 0.80, 0.79)
    "black": (1.022698e-05, -1.190348e-02, 4.107171e-01),  # (0.025, 0.025, 0.028)
    "silver": (-3.566765e-08, -1.602907e-04, 1.182390e-01),  # (0.50, 0.51, 0.52)
    "grey": (-1.428650e-07, -2.147113e-04, -5.536772e-01),  # (0.20, 0.21, 0.22)
    "red": (1.369746e-04, -1.313627e-01, 2.873034e01),  # (0.50, 0.025, 0.025)
    "dark_red": (1.258220e-04, -1.218642e-01, 2.614116e01),  # (0.22, 0.015, 0.02)
    "blue": (8.353750e-06, -1.753424e-02, 6.250207e00),  # (0.06, 0.18, 0.55)
    "dark_blue": (1.768333e-05, -2.889813e-02, 8.242972e00),  # (0.025, 0.04, 0.13)
    "green": (-1.342261e-04, 1.427592e-01, -3.876021e01),  # (0.04, 0.18, 0.07)
    "beige": (-6.904269e-06, 9.827327e-03, -3.382574e00),  # (0.55, 0.46, 0.32)
    "gold": (-3.009455e-05, 3.746548e-02, -1.182996e01),  # (0.45, 0.33, 0.12)
    "yellow": (-1.045606e-04, 1.246396e-01, -3.659635e01),  # (0.80, 0.60, 0.03)
    "orange": (-9.104862e-06, 2.455112e-02, -1.133359e01),  # (0.78, 0.22, 0.02)
    "brown": (-3.969131e-06, 1.162355e-02, -6.814515e00),  # (0.14, 0.07, 0.035)
}

PAINT_LINEAR_SRGB: dict[str, tuple[float, float, float]] = {
    "white": (0.80, 0.80, 0.79),
    "black": (0.025, 0.025, 0.028),
    "silver": (0.50, 0.51, 0.52),
    "grey": (0.20, 0.21, 0.22),
    "red": (0.50, 0.025, 0.025),
    "dark_red": (0.22, 0.015, 0.02),
    "blue": (0.06, 0.18, 0.55),
    "dark_blue": (0.025, 0.04, 0.13),
    "green": (0.04, 0.18, 0.07),
    "beige": (0.55, 0.46, 0.32),
    "gold": (0.45, 0.33, 0.12),
    "yellow": (0.80, 0.60, 0.03),
    "orange": (0.78, 0.22, 0.02),
    "brown": (0.14, 0.07, 0.035),
}
"""Target linear-sRGB albedo (D65) each paint spectrum was fitted to."""

PAINTS: tuple[str, ...] = tuple(_PAINT_COEFFS)
"""Car paint names, in palette order."""

MATERIALS: tuple[str, ...] = tuple(_REFLECTANCE) + ("chrome", "aluminium", "glass", "car_glass")
"""Names accepted by :func:`bsdf`."""


def reflectance(name: str, wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """Diffuse reflectance (0-1) of a named material at ``wavelengths_nm``."""
    if name not in _REFLECTANCE:
        raise ValueError(f"unknown material {name!r}; known: {sorted(_REFLECTANCE)}")
    return resample_spectrum(_TABLE_NM, _REFLECTANCE[name], wavelengths_nm, hold_ends=True)


def paint_reflectance(paint: str, wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """Body-colour reflectance (0-1) of a car paint (Jakob & Hanika 2019 model)."""
    if paint not in _PAINT_COEFFS:
        raise ValueError(f"unknown paint {paint!r}; known: {list(PAINTS)}")
    c0, c1, c2 = _PAINT_COEFFS[paint]
    wl = np.asarray(wavelengths_nm, float)
    u = c0 * wl**2 + c1 * wl + c2
    return 0.5 + u / (2.0 * np.sqrt(1.0 + u**2))


def _spec(values: np.ndarray, wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> dict:
    return spectrum(wavelengths_nm, values)


def car_paint_bsdf(paint: str, roughness: float = 0.08) -> dict:
    """Clear-coat-like automotive paint: ``roughplastic`` (IOR 1.5 coat) over the body colour."""
    return {
        "type": "roughplastic",
        "distribution": "ggx",
        "alpha": float(roughness),
        "int_ior": 1.5,
        "diffuse_reflectance": _spec(paint_reflectance(paint)),
        "nonlinear": False,
    }


def bsdf(name: str) -> dict:
    """Mitsuba BSDF dict of a named material (see :data:`MATERIALS`).

    Rough dielectric-coated materials (``rubber``, trim, lenses) use ``roughplastic``; the
    ground materials are Lambertian ``diffuse``; ``chrome``/``aluminium`` are rough
    conductors with Mitsuba's measured spectral optical constants; ``glass`` is a thin
    clear pane; ``car_glass`` is tinted glass in front of a dark cabin seen from outside
    (a dark gloss: specular coat over 3 % diffuse).
    """
    if name == "chrome":
        return {"type": "roughconductor", "material": "Cr", "alpha": 0.05, "distribution": "ggx"}
    if name == "aluminium":
        return {"type": "roughconductor", "material": "Al", "alpha": 0.25, "distribution": "ggx"}
    if name == "glass":
        return {"type": "thindielectric", "int_ior": 1.52, "ext_ior": 1.0}
    if name == "car_glass":
        return {"type": "plastic", "int_ior": 1.52, "diffuse_reflectance": _spec(reflectance("interior") * 0.8)}
    if name in ("rubber", "trim_black", "lens_red", "lens_amber", "lens_clear", "plate_white", "plate_yellow"):
        alpha = {"rubber": 0.5, "trim_black": 0.3, "plate_white": 0.3, "plate_yellow": 0.3}.get(name, 0.05)
        return {
            "type": "roughplastic",
            "distribution": "ggx",
            "alpha": alpha,
            "int_ior": 1.5,
            "diffuse_reflectance": _spec(reflectance(name)),
        }
    return {"type": "diffuse", "reflectance": _spec(reflectance(name))}
