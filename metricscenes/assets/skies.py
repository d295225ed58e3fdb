"""Thirty seeded skies: 10 day, 10 dusk (civil twilight) and 10 night (DESIGN.md §2).

Every sky is a set of Mitsuba emitter dicts in physical units (W·sr⁻¹·m⁻²·nm⁻¹ for
radiance, W·m⁻²·nm⁻¹ for irradiance), given as ``irregular`` spectra so that
``scalar_spectral`` does not upsample them (mitsuba-notes.md). World frame: x forward,
y left, z up; azimuths are measured from +x towards +y.

- **day** (ids 0-9): Hosek-Wilkie ``sunsky`` [Hosek & Wilkie 2012], sun elevation 15-70°,
  turbidity 2-6, physical scale (sun and sky).
- **dusk** (ids 10-19): civil twilight, sun 0-4.5° *below* the horizon. ``sunsky`` is zero
  then, so the sky keeps the Hosek-Wilkie angular and spectral shape of a sun at +0.5°
  (the model's lowest valid elevation) without the sun disk (``sun_scale = 0``), and
  ``sky_scale`` brings its horizontal illuminance to the clear-sky twilight value for the
  solar depression: log-linear between 500 lux at 0°, 2.8 lux at -6° and 0.008 lux at
  -12° (AMS Glossary of Meteorology, "civil twilight", "nautical twilight": 585-410 lux
  falling to 3.5-2 lux during civil twilight; 0.008 lux at -12°).
- **night** (ids 20-29): a uniform ``constant`` sky. Moonless (ids 20-24): natural sky
  (zenith 22 mag/arcsec² ≈ 1.7e-4 cd/m² at a dark site, Leinert et al. 1998; more with
  distant sky glow), spectrum a 4000 K continuum (integrated starlight,
  zodiacal light, airglow continuum) plus the 557.7 nm [OI] airglow line. A uniform sky
  of L gives πL lux: 3.2-12 × 10⁻⁴ cd/m² gives the 1-4 millilux usually quoted for starlight,
  the real sky being brighter towards the horizon than at the zenith (van Rhijn effect). Moonlit
  (ids 25-29): a ``directional`` moon with a lunar spectrum (5778 K sun × the lunar
  reflectance, which rises ~1.7× from 400 to 700 nm; Lane & Irvine 1973, ROLO) giving
  0.03-0.27 lux at normal incidence (quarter to full moon, Krisciunas & Schaefer 1991),
  and a sky of scattered moonlight (Rayleigh λ⁻⁴ tint, diffuse/direct ratio 0.15 as for a
  clear day) on top of the natural background.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from metricscenes.assets.parts import spectrum
from metricscenes.photometry import luminous_band_sum
from metricscenes.spectral import WAVELENGTHS_NM, resample_spectrum

SKY_KINDS = ("day", "dusk", "night")
SKIES_PER_KIND = 10
N_SKIES = SKIES_PER_KIND * len(SKY_KINDS)
SKY_LIGHT_GROUPS = {"day": "sky_day", "dusk": "sky_dusk", "night": "sky_night"}

# Spectra are tabulated a little beyond 400-700 nm so every 10 nm band is fully covered.
_GRID_NM = np.arange(380.0, 721.0, 5.0)
_DUSK_MODEL_ELEVATION_DEG = 0.5
_TWILIGHT_TABLE = ((-12.0, np.log10(0.008)), (-6.0, np.log10(2.8)), (0.0, np.log10(500.0)))
# Horizontal illuminance (lux) of sunsky(sun at +0.5°, sun_scale=0, sky_scale=1, albedo
# 0.15) per turbidity, measured by rendering a 0.18 grey plane (tests re-measure it).
_DUSK_UNIT_SKY_LUX = {2: 2815.0, 3: 2772.0, 4: 2686.0, 5: 2585.0}
_MOONLIT_DIFFUSE_RATIO = 0.15
_SALT = 0x5C1E5


@dataclass(frozen=True)
class SkySpec:
    """Parameters of one sky. Angles in degrees; azimuth from +x (forward) towards +y (left).

    ``sun_elevation_deg`` is the true solar elevation (negative at dusk and night).
    ``moon_normal_illuminance_lux`` is 0 for a moonless night.
    """

    sky_id: int
    kind: str
    sun_elevation_deg: float
    sun_azimuth_deg: float
    turbidity: float
    ground_albedo: float = 0.15
    background_luminance_cd_m2: float = 0.0
    moon_elevation_deg: float = 0.0
    moon_azimuth_deg: float = 0.0
    moon_normal_illuminance_lux: float = 0.0

    @property
    def light_group(self) -> str:
        return SKY_LIGHT_GROUPS[self.kind]


def _planck(wavelengths_nm: np.ndarray, temperature_k: float) -> np.ndarray:
    """Relative blackbody spectral radiance (Planck's law; arbitrary scale).

    Not ``colour.colorimetry.planck_law`` (the lamps' halogen uses it): with its rounded
    c2 = 0.014388 m·K the moon and night-sky spectra move by 3-5e-5, and even given this
    c2 its c1/π scale and order of operations change their last bits; the rendered
    collections depend on these spectra to the last bit.
    """
    lam = np.asarray(wavelengths_nm, dtype=float) * 1e-9
    return 1.0 / (lam**5 * np.expm1(1.4387769e-2 / (lam * temperature_k)))


def _normalised(values: np.ndarray, photometric: float) -> np.ndarray:
    """Scale a spectrum on ``_GRID_NM`` so that its photometric value equals ``photometric``."""
    return values * (photometric / luminous_band_sum(values, _GRID_NM))


def lunar_spectrum_w_m2_nm(normal_illuminance_lux: float) -> np.ndarray:
    """Moonlight irradiance on ``_GRID_NM`` (sun-like 5778 K × lunar reflectance slope)."""
    rel = _planck(_GRID_NM, 5778.0) * (1.0 + 0.0017 * (_GRID_NM - 550.0))
    return _normalised(rel, normal_illuminance_lux)


def night_background_radiance(luminance_cd_m2: float) -> np.ndarray:
    """Moonless night-sky radiance on ``_GRID_NM``: 4000 K continuum + 557.7 nm airglow line."""
    rel = _planck(_GRID_NM, 4000.0)
    rel = rel / np.max(rel)
    line = np.exp(-0.5 * ((_GRID_NM - 557.7) / 2.5) ** 2) * 0.6  # ~10 % of the luminance
    return _normalised(rel + line, luminance_cd_m2)


def twilight_illuminance_lux(sun_elevation_deg: float) -> float:
    """Clear-sky horizontal illuminance (lux) for a sun 0-12° below the horizon (AMS glossary)."""
    h, logs = zip(*_TWILIGHT_TABLE)
    if not -12.0 <= sun_elevation_deg <= 0.0:
        raise ValueError(f"sun_elevation_deg must be in [-12, 0] for twilight, got {sun_elevation_deg}")
    return float(10 ** np.interp(sun_elevation_deg, h, logs))


def _direction(elevation_deg: float, azimuth_deg: float) -> list[float]:
    el, az = np.radians(elevation_deg), np.radians(azimuth_deg)
    return [float(np.cos(el) * np.cos(az)), float(np.cos(el) * np.sin(az)), float(np.sin(el))]


def sky_spec(sky_id: int) -> SkySpec:
    """The sky ``sky_id`` (0-9 day, 10-19 dusk, 20-29 night), deterministic."""
    if not isinstance(sky_id, (int, np.integer)) or not 0 <= sky_id < N_SKIES:
        raise ValueError(f"sky_id must be an integer in [0, {N_SKIES}), got {sky_id!r}")
    sky_id = int(sky_id)
    kind = SKY_KINDS[sky_id // SKIES_PER_KIND]
    i = sky_id % SKIES_PER_KIND
    rng = np.random.default_rng([_SALT, sky_id])
    u = float(rng.uniform())  # stratified draw within the kind's range
    azimuth = float(rng.uniform(-180.0, 180.0))
    if kind == "day":
        return SkySpec(sky_id, kind, sun_elevation_deg=round(15.0 + 55.0 * (i + u) / 10, 2),
                       sun_azimuth_deg=round(azimuth, 1), turbidity=round(float(rng.uniform(2.0, 6.0)), 2))
    if kind == "dusk":
        return SkySpec(sky_id, kind, sun_elevation_deg=round(-4.5 * (i + u) / 10, 2),
                       sun_azimuth_deg=round(azimuth, 1), turbidity=float(rng.integers(2, 6)))
    moonlit = i >= SKIES_PER_KIND // 2
    background = round(float(10 ** rng.uniform(np.log10(3.2e-4), np.log10(1.2e-3))), 6)
    if not moonlit:
        return SkySpec(sky_id, kind, sun_elevation_deg=-30.0, sun_azimuth_deg=round(azimuth, 1),
                       turbidity=3.0, background_luminance_cd_m2=background)
    k = i - SKIES_PER_KIND // 2
    return SkySpec(sky_id, kind, sun_elevation_deg=-30.0, sun_azimuth_deg=round(azimuth, 1), turbidity=3.0,
                   background_luminance_cd_m2=background,
                   moon_elevation_deg=round(15.0 + 45.0 * (k + u) / 5, 2),
                   moon_azimuth_deg=round(float(rng.uniform(-180.0, 180.0)), 1),
                   moon_normal_illuminance_lux=round(float(10 ** rng.uniform(np.log10(0.03), np.log10(0.27))), 4))


def sky_library() -> list[SkySpec]:
    """All 30 skies, ordered by ``sky_id``."""
    return [sky_spec(i) for i in range(N_SKIES)]


def skies_for(kind: str) -> list[int]:
    """The ``sky_id`` values of one kind ('day', 'dusk' or 'night')."""
    if kind not in SKY_KINDS:
        raise ValueError(f"kind must be one of {SKY_KINDS}, got {kind!r}")
    start = SKY_KINDS.index(kind) * SKIES_PER_KIND
    return list(range(start, start + SKIES_PER_KIND))


def night_sky_radiance(spec: SkySpec) -> np.ndarray:
    """Uniform night-sky radiance on ``_GRID_NM`` (background + scattered moonlight)."""
    radiance = night_background_radiance(spec.background_luminance_cd_m2)
    if spec.moon_normal_illuminance_lux > 0:
        horizontal_lux = spec.moon_normal_illuminance_lux * np.sin(np.radians(spec.moon_elevation_deg))
        scattered_cd_m2 = _MOONLIT_DIFFUSE_RATIO * horizontal_lux / np.pi
        tint = lunar_spectrum_w_m2_nm(1.0) * (_GRID_NM / 550.0) ** -4
        radiance = radiance + _normalised(tint, scattered_cd_m2)
    return radiance


def sky_emitters(spec: SkySpec) -> dict[str, dict]:
    """Mitsuba emitter dicts of a sky: key 'sky' (the environment) and 'moon' when moonlit."""
    if spec.kind == "day":
        return {"sky": {"type": "sunsky", "sun_direction": _direction(spec.sun_elevation_deg, spec.sun_azimuth_deg),
                        "turbidity": spec.turbidity, "albedo": spec.ground_albedo}}
    if spec.kind == "dusk":
        unit_lux = _DUSK_UNIT_SKY_LUX[int(spec.turbidity)]
        scale = twilight_illuminance_lux(spec.sun_elevation_deg) / unit_lux
        return {"sky": {"type": "sunsky", "turbidity": spec.turbidity, "albedo": spec.ground_albedo,
                        "sun_direction": _direction(_DUSK_MODEL_ELEVATION_DEG, spec.sun_azimuth_deg),
                        "sun_scale": 0.0, "sky_scale": float(scale)}}
    emitters = {"sky": {"type": "constant", "radiance": spectrum(_GRID_NM, night_sky_radiance(spec))}}
    if spec.moon_normal_illuminance_lux > 0:
        d = _direction(spec.moon_elevation_deg, spec.moon_azimuth_deg)
        emitters["moon"] = {"type": "directional", "direction": [-c for c in d],
                            "irradiance": spectrum(_GRID_NM, lunar_spectrum_w_m2_nm(spec.moon_normal_illuminance_lux))}
    return emitters


def expected_illuminance_lux(spec: SkySpec) -> float:
    """Horizontal illuminance (lux) the sky is built to give (night and dusk exact by design).

    Day skies are physical, not calibrated: use :func:`horizontal_illuminance_lux` (rendered).
    """
    if spec.kind == "dusk":
        return twilight_illuminance_lux(spec.sun_elevation_deg)
    if spec.kind == "night":
        moon = spec.moon_normal_illuminance_lux * np.sin(np.radians(spec.moon_elevation_deg))
        return float(np.pi * luminous_band_sum(resample_spectrum(_GRID_NM, night_sky_radiance(spec), hold_ends=True)) + moon)
    raise ValueError(f"expected_illuminance_lux is defined for dusk and night skies, got kind {spec.kind!r}")


def measure_illuminance_lux(emitters: dict[str, dict], albedo: float = 0.18, size_px: int = 8,
                            spp: int = 16, seed: int = 0) -> float:
    """Horizontal illuminance (lux) of ``emitters``, rendered on a grey Lambertian plane.

    A camera 1 m above a ``albedo`` plane looks straight down; E = π L / ρ per band and
    lux = 683 Σ E V(λ) Δλ. Needs a spectral Mitsuba variant already set.
    """
    import mitsuba as mi

    from metricscenes.render import Film, spectral_film_dict

    if "spectral" not in (mi.variant() or ""):
        raise ValueError(f"measure_illuminance_lux needs a spectral Mitsuba variant, got {mi.variant()!r}")
    T = mi.ScalarTransform4f
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": 2},
             "ground": {"type": "rectangle", "to_world": T().scale([1e5, 1e5, 1.0]),
                        "bsdf": {"type": "diffuse", "reflectance": {"type": "uniform", "value": albedo}}},
             "sensor": {"type": "perspective", "fov": 10.0,
                        "to_world": T().look_at(origin=[0, 0, 1], target=[0, 0, 0], up=[1, 0, 0]),
                        "film": spectral_film_dict(Film(size_px, size_px)),
                        "sampler": {"type": "stratified", "sample_count": spp, "seed": seed}},
             **emitters}
    image = np.asarray(mi.render(mi.load_dict(scene), spp=spp))
    radiance = image.reshape(-1, image.shape[-1]).mean(axis=0)
    return luminous_band_sum(np.pi * radiance / albedo)


def horizontal_illuminance_lux(spec: SkySpec, spp: int = 64) -> float:
    """Rendered horizontal illuminance (lux) of a sky at the ground (see measure_illuminance_lux)."""
    return measure_illuminance_lux(sky_emitters(spec), size_px=8, spp=spp)


def sky_luminance_cd_m2(spec: SkySpec, elevation_deg: float = 90.0, azimuth_deg: float = 0.0) -> float:
    """Luminance (cd/m²) of the sky in one direction (default the zenith), from the emitter itself.

    Evaluates the 'sky' emitter (not the moon or the sun disk unless looked at); needs a
    spectral Mitsuba variant.
    """
    import mitsuba as mi

    emitter = mi.load_dict(sky_emitters(spec)["sky"])
    si = mi.SurfaceInteraction3f()
    si.wi = -mi.Vector3f(*_direction(elevation_deg, azimuth_deg))
    values = []
    for chunk in _chunks(WAVELENGTHS_NM, 4):  # a spectral Spectrum holds 4 wavelengths
        si.wavelengths = mi.Spectrum(list(chunk))
        values.extend(list(np.asarray(emitter.eval(si)).ravel()))
    values = values[: len(WAVELENGTHS_NM)]
    return luminous_band_sum(np.array(values))


def _chunks(values: np.ndarray, n: int) -> list[np.ndarray]:
    padded = np.concatenate([values, np.repeat(values[-1], (-len(values)) % n)])
    return [padded[i : i + n] for i in range(0, len(values), n)][: int(np.ceil(len(values) / n))]
