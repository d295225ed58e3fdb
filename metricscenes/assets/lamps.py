"""Lamp spectra and photometry: car head/tail lamps and street lights, in Mitsuba units.

Photometric targets (luminous intensity I_v in cd, luminance L_v in cd/m²) are converted to
spectral intensity (W·sr⁻¹·nm⁻¹, for ``spot``/``point`` emitters) or spectral radiance
(W·sr⁻¹·m⁻²·nm⁻¹, for ``area`` emitters) with the CIE 1924 photopic luminous efficiency
V(λ) and K_m = 683 lm/W:  X_v = K_m ∫ X_e(λ) V(λ) dλ  (CIE 015:2018; ISO 23539:2005).

Spectral power distributions (relative, 380-780 nm, 5 nm; colour-science datasets):
- ``led_4000k``: CIE illuminant LED-B3 (phosphor-converted white LED, 4103 K; CIE 015:2018).
- ``led_5700k``: CIE illuminant LED-B4 (5109 K) — typical of LED headlamps (5000-6000 K).
- ``halogen``: Planckian radiator at 3200 K (tungsten-halogen H4/H7 filament).
- ``hps``: CIE illuminant HP1 (standard high-pressure sodium, 1959 K; CIE 015:2018).
- ``red_led``/``amber_led``: AlInGaP LED, Gaussian of 18 nm FWHM at 630/592 nm
  (Schubert, "Light-Emitting Diodes", 2nd ed., ch. 12).

Luminous intensity ranges (per lamp):
- Rear position (tail) lamp, UN ECE R7: 4-17 cd in the axis (R1 min 4, R2 max 17).
- Stop (brake) lamp, UN ECE R7 (S1): 60-260 cd.
- Front position lamp, UN ECE R7: 4-140 cd; daytime running lamp, UN ECE R87: 400-1200 cd.
- Dipped (low) beam, UN ECE R112/R149: >= 5100 cd at 50V, hot spot up to 44 100 cd; towards
  an oncoming driver (above the cut-off, point B50L) <= 350-625 cd. Seen from a camera 1.5 m
  high in the other lane (above the cut-off) a low-beam lens therefore shows a few hundred to
  about two thousand cd of glare (a Lambertian area emitter cannot carry the beam shape, so
  the lens carries the glare intensity and a ``spot`` carries the beam onto the road).
- Street lights (EN 13201 roads, 8-12 m poles): LED luminaire 4000-20 000 lm, HPS 100-250 W
  9000-33 000 lm; peak intensities about 2000-12 000 cd (luminaire photometry files).
"""

from __future__ import annotations

import colour
import numpy as np

from metricscenes.assets.parts import spectrum
from metricscenes.photometry import MAX_LUMINOUS_EFFICACY_LM_W

K_M_LM_W = MAX_LUMINOUS_EFFICACY_LM_W
"""Maximum luminous efficacy of radiation for photopic vision, lm/W (CIE)."""

LAMP_NM: np.ndarray = np.arange(380.0, 781.0, 5.0)
"""Wavelength grid (nm) of every lamp spectrum in this module."""

SPD_KINDS = ("led_4000k", "led_5700k", "halogen", "hps", "red_led", "amber_led")

# (low, typical, high) luminous intensity in cd, per lamp, along the lamp axis.
INTENSITY_RANGES_CD: dict[str, tuple[float, float, float]] = {
    "tail": (4.0, 8.0, 17.0),  # ECE R7 rear position lamp
    "brake": (60.0, 120.0, 260.0),  # ECE R7 stop lamp S1
    "front_position": (4.0, 20.0, 140.0),  # ECE R7
    "drl": (400.0, 800.0, 1200.0),  # ECE R87
    "headlamp_glare": (200.0, 700.0, 2000.0),  # low beam seen from an oncoming driver's eye/camera
    "low_beam": (5100.0, 15000.0, 44100.0),  # ECE R112 50V minimum .. Emax
    "street_led": (2000.0, 5000.0, 12000.0),
    "street_hps": (2000.0, 6000.0, 12000.0),
}


def photopic_v(wavelengths_nm: np.ndarray = LAMP_NM) -> np.ndarray:
    """CIE 1924 photopic luminous efficiency V(λ) at ``wavelengths_nm`` (0 outside 360-830)."""
    lef = colour.colorimetry.SDS_LEFS_PHOTOPIC["CIE 1924 Photopic Standard Observer"]
    return np.interp(np.asarray(wavelengths_nm, float), lef.wavelengths, lef.values, left=0.0, right=0.0)


def luminous(wavelengths_nm: np.ndarray, spectral_values: np.ndarray) -> float:
    """Photometric value of a spectral quantity: K_m ∫ X(λ) V(λ) dλ (trapezoid).

    W·sr⁻¹·nm⁻¹ gives cd; W·sr⁻¹·m⁻²·nm⁻¹ gives cd/m²; W·m⁻²·nm⁻¹ gives lux.
    """
    wl = np.asarray(wavelengths_nm, float)
    return float(K_M_LM_W * np.trapezoid(np.asarray(spectral_values, float) * photopic_v(wl), wl))


def relative_spd(kind: str) -> np.ndarray:
    """Relative spectral power distribution (max 1) of a lamp kind on :data:`LAMP_NM`."""
    if kind == "led_4000k":
        sd = colour.SDS_ILLUMINANTS["LED-B3"]
    elif kind == "led_5700k":
        sd = colour.SDS_ILLUMINANTS["LED-B4"]
    elif kind == "hps":
        sd = colour.SDS_ILLUMINANTS["HP1"]
    elif kind == "halogen":
        sd = None
        values = colour.colorimetry.planck_law(LAMP_NM * 1e-9, 3200.0)
    elif kind in ("red_led", "amber_led"):
        sd = None
        peak = 630.0 if kind == "red_led" else 592.0
        sigma = 18.0 / (2.0 * np.sqrt(2.0 * np.log(2.0)))
        values = np.exp(-0.5 * ((LAMP_NM - peak) / sigma) ** 2)
    else:
        raise ValueError(f"unknown lamp spectrum kind {kind!r}; known: {SPD_KINDS}")
    if sd is not None:
        values = np.interp(LAMP_NM, sd.wavelengths, sd.values, left=0.0, right=0.0)
    values = np.asarray(values, float)
    return values / values.max()


def scaled_to_luminous(kind: str, luminous_value: float) -> tuple[np.ndarray, np.ndarray]:
    """Spectrum of ``kind`` scaled so that K_m ∫ X V dλ equals ``luminous_value``.

    Give cd for a spectral intensity (W·sr⁻¹·nm⁻¹) or cd/m² for a spectral radiance.
    """
    if not np.isfinite(luminous_value) or luminous_value < 0:
        raise ValueError(f"luminous_value must be finite and >= 0, got {luminous_value}")
    spd = relative_spd(kind)
    return LAMP_NM.copy(), spd * (luminous_value / luminous(LAMP_NM, spd))


def _radiance(kind: str, intensity_cd: float, area_m2: float) -> tuple[np.ndarray, np.ndarray]:
    if area_m2 <= 0:
        raise ValueError(f"lens area_m2 must be > 0, got {area_m2}")
    # A Lambertian emitter of area A and luminance L has axial intensity I = L A.
    return scaled_to_luminous(kind, intensity_cd / area_m2)


def headlamp(kind: str = "led", lens_area_m2: float = 0.02, intensity_cd: float | None = None):
    """Head-lamp lens: (wavelengths_nm, spectral radiance W·sr⁻¹·m⁻²·nm⁻¹) of an area emitter.

    ``kind`` 'led' (5100 K) or 'halogen' (3200 K); the axial intensity defaults to the typical
    low-beam glare towards an oncoming camera (:data:`INTENSITY_RANGES_CD` 'headlamp_glare').
    """
    spd = {"led": "led_5700k", "halogen": "halogen"}.get(kind)
    if spd is None:
        raise ValueError(f"headlamp kind must be 'led' or 'halogen', got {kind!r}")
    cd = INTENSITY_RANGES_CD["headlamp_glare"][1] if intensity_cd is None else intensity_cd
    return _radiance(spd, cd, lens_area_m2)


def headlamp_beam(kind: str = "led", intensity_cd: float | None = None):
    """Low-beam hot spot for a ``spot`` emitter: (wavelengths_nm, W·sr⁻¹·nm⁻¹)."""
    spd = {"led": "led_5700k", "halogen": "halogen"}.get(kind)
    if spd is None:
        raise ValueError(f"headlamp kind must be 'led' or 'halogen', got {kind!r}")
    cd = INTENSITY_RANGES_CD["low_beam"][1] if intensity_cd is None else intensity_cd
    return scaled_to_luminous(spd, cd)


def tail_lamp(brake: bool = False, lens_area_m2: float = 0.02, intensity_cd: float | None = None):
    """Red rear lamp lens (tail, or stop when ``brake``): (wavelengths_nm, spectral radiance)."""
    cd = INTENSITY_RANGES_CD["brake" if brake else "tail"][1] if intensity_cd is None else intensity_cd
    return _radiance("red_led", cd, lens_area_m2)


def street_light(kind: str = "led_4000k", intensity_cd: float | None = None):
    """Street-light luminaire peak: (wavelengths_nm, spectral intensity W·sr⁻¹·nm⁻¹).

    ``kind`` 'led_4000k' or 'hps'. For an area emitter of area A use radiance = intensity / A
    (see :func:`street_light_radiance`).
    """
    key = {"led_4000k": "street_led", "hps": "street_hps"}.get(kind)
    if key is None:
        raise ValueError(f"street light kind must be 'led_4000k' or 'hps', got {kind!r}")
    cd = INTENSITY_RANGES_CD[key][1] if intensity_cd is None else intensity_cd
    return scaled_to_luminous(kind, cd)


def street_light_radiance(kind: str = "led_4000k", area_m2: float = 0.15, intensity_cd: float | None = None):
    """Street-light luminaire face as a Lambertian area emitter: (wavelengths_nm, radiance)."""
    if area_m2 <= 0:
        raise ValueError(f"area_m2 must be > 0, got {area_m2}")
    wl, intensity = street_light(kind, intensity_cd)
    return wl, intensity / area_m2


def area_emitter(wavelengths_nm: np.ndarray, radiance: np.ndarray) -> dict:
    """Mitsuba ``area`` emitter dict with an irregular spectral radiance."""
    return {"type": "area", "radiance": spectrum(wavelengths_nm, radiance)}


def spot_emitter(
    wavelengths_nm: np.ndarray,
    intensity: np.ndarray,
    origin_m,
    target_m,
    cutoff_deg: float = 30.0,
    beam_width_deg: float = 12.0,
) -> dict:
    """Mitsuba ``spot`` emitter dict (intensity W·sr⁻¹·nm⁻¹ at the beam centre)."""
    import mitsuba as mi

    return {
        "type": "spot",
        "intensity": spectrum(wavelengths_nm, intensity),
        "cutoff_angle": float(cutoff_deg),
        "beam_width": float(beam_width_deg),
        "to_world": mi.ScalarTransform4f().look_at(
            origin=[float(c) for c in origin_m], target=[float(c) for c in target_m], up=[0.0, 0.0, 1.0]
        ),
    }
