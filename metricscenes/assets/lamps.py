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
- ``illuminant_a``: CIE standard illuminant A (Planckian radiator at 2856 K; CIE 015:2018),
  the CIE's tungsten-filament light: a W5W registration-plate lamp (UN ECE R37 filament
  lamp category W5W, 5 W).

Luminous intensity ranges (per lamp):
- Rear position (tail) lamp, UN ECE R7: 4-17 cd in the axis (R1 min 4, R2 max 17).
- Stop (brake) lamp, UN ECE R7 (S1): 60-260 cd.
- Front position lamp, UN ECE R7: 4-140 cd; daytime running lamp, UN ECE R87: 400-1200 cd.
- Head lamps (low and high beam) and road luminaires are goniometric: their luminous
  intensity distributions, and the regulations and luminaire classes they follow, are in
  :mod:`metricscenes.assets.beams`; this module gives their spectra.
- Street lights (EN 13201 M4-M6 rural roads, 8-10 m poles): LED roadway luminaires of
  4000-15 000 lm (IES RP-8-18 typical outputs for 30-120 W LED luminaires at ~130 lm/W).
- Rear registration plate lamp, UN ECE R4 (Revision 3): at least 2.5 cd/m² at every
  measuring point of the plate (§9, photometric characteristics), measured on a diffuse
  colourless surface in the plate's place and corrected to a diffuse reflection factor of
  1.0 (§8, measuring procedure). :func:`plate_lamp` gives the plate lit to exactly that
  minimum, uniformly (so §9's gradient limit holds trivially).
- Rear retro-reflectors, UN ECE R3 class IA, red: their coefficient of luminous intensity
  and the light they return to a camera beside the head lamps are in
  :mod:`metricscenes.assets.retroreflection`; this module gives the returned light's
  spectrum, :func:`retroreflected_red` (the lamp's spectrum through a red filter).
"""

from __future__ import annotations

import colour
import numpy as np

from metricscenes.assets.parts import spectrum
from metricscenes.photometry import luminous_trapezoid
from metricscenes.spectral import resample_spectrum

LAMP_NM: np.ndarray = np.arange(380.0, 781.0, 5.0)
"""Wavelength grid (nm) of every lamp spectrum in this module."""

SPD_KINDS = ("led_4000k", "led_5700k", "halogen", "hps", "red_led", "amber_led", "illuminant_a")

# (low, typical, high) luminous intensity in cd, per lamp, along the lamp axis.
INTENSITY_RANGES_CD: dict[str, tuple[float, float, float]] = {
    "tail": (4.0, 8.0, 17.0),  # ECE R7 rear position lamp
    "brake": (60.0, 120.0, 260.0),  # ECE R7 stop lamp S1
    "front_position": (4.0, 20.0, 140.0),  # ECE R7
    "drl": (400.0, 800.0, 1200.0),  # ECE R87
}
STREET_LIGHT_FLUX_LM = (4000.0, 9000.0, 15000.0)
"""(low, typical, high) rated flux of a rural road luminaire, lm."""


def relative_spd(kind: str) -> np.ndarray:
    """Relative spectral power distribution (max 1) of a lamp kind on :data:`LAMP_NM`."""
    if kind == "led_4000k":
        sd = colour.SDS_ILLUMINANTS["LED-B3"]
    elif kind == "led_5700k":
        sd = colour.SDS_ILLUMINANTS["LED-B4"]
    elif kind == "hps":
        sd = colour.SDS_ILLUMINANTS["HP1"]
    elif kind == "illuminant_a":
        sd = colour.SDS_ILLUMINANTS["A"]
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
        values = resample_spectrum(sd.wavelengths, sd.values, LAMP_NM)
    values = np.asarray(values, float)
    return values / values.max()


def scaled_to_luminous(kind: str, luminous_value: float) -> tuple[np.ndarray, np.ndarray]:
    """Spectrum of ``kind`` scaled so that K_m ∫ X V dλ equals ``luminous_value``.

    Give cd for a spectral intensity (W·sr⁻¹·nm⁻¹) or cd/m² for a spectral radiance.
    """
    return _scaled(relative_spd(kind), luminous_value)


def _scaled(spd: np.ndarray, luminous_value: float) -> tuple[np.ndarray, np.ndarray]:
    """A relative spectrum on :data:`LAMP_NM` scaled to ``luminous_value`` (cd or cd/m²)."""
    if not np.isfinite(luminous_value) or luminous_value < 0:
        raise ValueError(f"luminous_value must be finite and >= 0, got {luminous_value}")
    return LAMP_NM.copy(), spd * (luminous_value / luminous_trapezoid(LAMP_NM, spd))


def _radiance(kind: str, intensity_cd: float, area_m2: float) -> tuple[np.ndarray, np.ndarray]:
    if area_m2 <= 0:
        raise ValueError(f"lens area_m2 must be > 0, got {area_m2}")
    # A Lambertian emitter of area A and luminance L has axial intensity I = L A.
    return scaled_to_luminous(kind, intensity_cd / area_m2)


def headlamp_spd(kind: str = "led") -> str:
    """Spectrum kind of a head lamp: 'led' (5100 K, CIE LED-B4) or 'halogen' (3200 K)."""
    spd = {"led": "led_5700k", "halogen": "halogen"}.get(kind)
    if spd is None:
        raise ValueError(f"headlamp kind must be 'led' or 'halogen', got {kind!r}")
    return spd


HEADLAMP_LENS_CD = 120.0
"""Axial intensity of a head lamp's Lambertian lens: the most that keeps lens + beam under
J1383's 125 cd limit above 10U (:mod:`metricscenes.assets.beams`: the beam carries the rest)."""


def headlamp(kind: str = "led", lens_area_m2: float = 0.02, intensity_cd: float = HEADLAMP_LENS_CD):
    """Head-lamp lens: (wavelengths_nm, spectral radiance W·sr⁻¹·m⁻²·nm⁻¹) of an area
    emitter whose axial intensity is the lens's share of the beam (:mod:`beams`)."""
    return _radiance(headlamp_spd(kind), intensity_cd, lens_area_m2)


def tail_lamp(brake: bool = False, lens_area_m2: float = 0.02, intensity_cd: float | None = None):
    """Red rear lamp lens (tail, or stop when ``brake``): (wavelengths_nm, spectral radiance)."""
    cd = INTENSITY_RANGES_CD["brake" if brake else "tail"][1] if intensity_cd is None else intensity_cd
    return _radiance("red_led", cd, lens_area_m2)


def street_light_spd(kind: str = "led_4000k") -> str:
    """Spectrum kind of a street light: 'led_4000k' (CIE LED-B3) or 'hps' (CIE HP1)."""
    if kind not in ("led_4000k", "hps"):
        raise ValueError(f"street light kind must be 'led_4000k' or 'hps', got {kind!r}")
    return kind


PLATE_LAMP_SPD = "illuminant_a"
"""A W5W filament lamp (UN ECE R37), as CIE illuminant A (2856 K)."""
PLATE_LAMP_LUMINANCE_CD_M2 = 2.5
"""UN ECE R4 §9: the least luminance at each measuring point of the rear plate, for a
diffuse surface of reflection factor 1.0 in the plate's place (R4 §8)."""


def plate_lamp(plate_reflectance: np.ndarray, luminance_cd_m2: float = PLATE_LAMP_LUMINANCE_CD_M2):
    """The rear registration plate lit by its lamp (UN ECE R4): (wavelengths_nm, spectral
    radiance W·sr⁻¹·m⁻²·nm⁻¹) of the plate seen from behind, L(λ) = ρ(λ) L₁(λ), where
    ``plate_reflectance`` ρ is given on :data:`LAMP_NM` and L₁ is the lamp's light on a perfect
    diffuser (reflection factor 1.0), the spectrum of :data:`PLATE_LAMP_SPD` at
    ``luminance_cd_m2`` (R4's minimum by default): the plate shows ρ_v × 2.5 cd/m², ρ_v being
    its luminous reflectance for illuminant A (0.78 for ``plate_white``)."""
    rho = np.asarray(plate_reflectance, float)
    if rho.shape != LAMP_NM.shape or np.any((rho < 0) | (rho > 1)):
        raise ValueError(f"plate_reflectance must be {LAMP_NM.size} values in [0, 1] on LAMP_NM")
    wl, white = scaled_to_luminous(PLATE_LAMP_SPD, luminance_cd_m2)
    return wl, rho * white


RED_REFLECTOR_CUT_ON_NM = 600.0
RED_REFLECTOR_EDGE_NM = 6.0
"""The red retro-reflector's transmission: a long-pass edge (logistic, 50 % at
:data:`RED_REFLECTOR_CUT_ON_NM`, 10-90 % over 4.4 x :data:`RED_REFLECTOR_EDGE_NM` = 26 nm), the
shape of red PMMA lens material. Its luminous transmittance for illuminant A is 0.26, about
UN ECE R3's red colour factor (0.25), and the light it returns lies inside the ECE red
boundaries (y <= 0.335, z <= 0.008) for illuminant A and for the LED head lamps (tested).
It sets the returned light's colour only; its luminous value is R3's
(:mod:`metricscenes.assets.retroreflection`)."""


def red_reflector_transmission(wavelengths_nm: np.ndarray) -> np.ndarray:
    """Relative spectral transmission (max 1) of a red retro-reflector's lens material."""
    wl = np.asarray(wavelengths_nm, float)
    return 1.0 / (1.0 + np.exp(-(wl - RED_REFLECTOR_CUT_ON_NM) / RED_REFLECTOR_EDGE_NM))


def retroreflected_red(source_kind: str, luminous_value: float) -> tuple[np.ndarray, np.ndarray]:
    """The light a red retro-reflector returns of a lamp of spectrum ``source_kind``: the
    lamp's spectrum times :func:`red_reflector_transmission`, scaled to ``luminous_value``
    (cd, or cd/m² for an area emitter's radiance). Its luminous value comes from UN ECE R3's
    coefficient of luminous intensity (:mod:`metricscenes.assets.retroreflection`)."""
    return _scaled(relative_spd(source_kind) * red_reflector_transmission(LAMP_NM), luminous_value)


def area_emitter(wavelengths_nm: np.ndarray, radiance: np.ndarray, sampled: bool = True) -> dict:
    """Mitsuba ``area`` emitter dict with an irregular spectral radiance.

    ``sampled=False`` gives it a ``sampling_weight`` of 0: next-event estimation never
    chooses it, so a faint emitter that matters only where it is seen (a lit plate, a
    retro-reflector) takes no samples from the lamps of its group; its light on other
    surfaces is still counted, without bias, by the paths that hit it."""
    emitter = {"type": "area", "radiance": spectrum(wavelengths_nm, radiance)}
    if not sampled:
        emitter["sampling_weight"] = 0.0
    return emitter
