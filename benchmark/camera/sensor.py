"""The image sensor: irradiance to electrons to volts to digital numbers (DN).

Spectral integration (ISETCam ``sensorCompute``): a pixel of channel c collects

    e⁻/s = A · FF · Σ_λ E(λ) · QE_c(λ) · IRcut(λ) · λ / (h c) · Δλ

(A pixel area, FF fill factor, Δλ band width). The capture then follows ISETCam's
noise order: signal (+ dark) electrons → Poisson shot noise → clip at the well →
Gaussian read noise → volts (conversion gain) → PRNU (gain) and DSNU (offset) →
analog gain and the offset that gives the black level → clip to [0, swing] →
quantise (``adc_bits``).

Every noise source can be switched off (:class:`NoiseOptions`); temporal noise comes
from ``np.random.default_rng(seed)`` (same seed, same raw); the fixed-pattern maps come
from the sensor's own ``fpn_seed`` (the same sensor unit in every capture).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from benchmark.camera.spec import SensorSpec, check_qe_table
from metricscenes.spectral import BAND_WIDTH_NM, WAVELENGTHS_NM, photon_energy_j, resample_spectrum

CHANNELS = ("r", "g", "b")


@dataclass(frozen=True)
class NoiseOptions:
    """Which noise sources a capture draws (all on by default)."""

    shot: bool = True
    read: bool = True
    dark: bool = True
    prnu: bool = True
    dsnu: bool = True

    @classmethod
    def off(cls) -> "NoiseOptions":
        return cls(shot=False, read=False, dark=False, prnu=False, dsnu=False)


@functools.lru_cache(maxsize=16)
def _read_qe_table(path: str) -> tuple[np.ndarray, np.ndarray]:
    """(wavelengths nm, QE × IR-cut (3, n)) of a QE file, refused in one line unless it is
    physically possible (:func:`benchmark.camera.spec.check_qe_table`)."""
    wl, qe, ir_cut = check_qe_table(path)
    if ir_cut is not None:
        qe = qe * ir_cut[None, :]
    return wl, qe


def effective_qe(sensor: SensorSpec, wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """Colour-filter QE × IR-cut transmittance, (3, bands), interpolated to the bands."""
    wl, qe = _read_qe_table(str(sensor.qe_path.resolve()))
    return np.stack([resample_spectrum(wl, q, wavelengths_nm) for q in qe])


def channel_responsivity(sensor: SensorSpec, wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """Electrons·s⁻¹ per pixel per W·m⁻²·nm⁻¹ of irradiance in each band, (3, bands):
    QE · IRcut · λ/(hc) · Δλ · pixel area · fill factor."""
    photons_per_j = 1.0 / photon_energy_j(wavelengths_nm)
    area = sensor.pixel_area_m2 * sensor.fill_factor
    return effective_qe(sensor, wavelengths_nm) * photons_per_j[None, :] * BAND_WIDTH_NM * area


def electron_rate(optical_image, sensor: SensorSpec) -> np.ndarray:
    """Noise-free signal per channel (3, rows, cols), electrons·s⁻¹, of an optical image
    (:class:`benchmark.camera.optics.OpticalImage`): the sensor integrates its own QE,
    Σ_λ r_c(λ)·E(λ) with :func:`channel_responsivity`, asking the optical image for those
    weighted sums of its bands (:meth:`~benchmark.camera.optics.OpticalImage.weighted_sum`,
    the fast path; :func:`signal_from_irradiance` is the plain one it is held equal to)."""
    return optical_image.weighted_sum(channel_responsivity(sensor, np.asarray(optical_image.wavelengths_nm, float)))


def signal_from_irradiance(irradiance: np.ndarray, wavelengths_nm: np.ndarray, sensor: SensorSpec) -> np.ndarray:
    """Noise-free signal per channel (3, rows, cols), electrons·s⁻¹, of a spectral
    irradiance (rows, cols, bands) in W·m⁻²·nm⁻¹ (an optical image's): Σ_λ r_c(λ)·E(λ)
    with :func:`channel_responsivity`. The plain path; :func:`electron_rate` (the
    camera's fast path) is held equal to it."""
    resp = channel_responsivity(sensor, np.asarray(wavelengths_nm, float))
    return np.einsum("hwb,cb->chw", np.asarray(irradiance, np.float64), resp).astype(np.float32)


def bayer_sites(cfa: str = "RGGB") -> list[tuple[int, int, int]]:
    """The four sites of the 2×2 Bayer tile ``cfa`` (read row by row), in that order:
    (row offset, column offset, channel index 0 R 1 G 2 B). A site's pixels are
    ``mosaic[dy::2, dx::2]``."""
    return [(dy, dx, "RGB".index(colour)) for (dy, dx), colour in zip(((0, 0), (0, 1), (1, 0), (1, 1)), cfa)]


def cfa_index(rows: int, cols: int, cfa: str = "RGGB") -> np.ndarray:
    """Channel index (0 R, 1 G, 2 B) of every pixel of a Bayer mosaic, (rows, cols) uint8."""
    lut = {"R": 0, "G": 1, "B": 2}
    tile = np.array([[lut[cfa[0]], lut[cfa[1]]], [lut[cfa[2]], lut[cfa[3]]]], dtype=np.uint8)
    return np.tile(tile, ((rows + 1) // 2, (cols + 1) // 2))[:rows, :cols]


def mosaic(channels: np.ndarray, cfa: str = "RGGB") -> np.ndarray:
    """Sample (3, rows, cols) channel images on the Bayer pattern: (rows, cols)."""
    _, rows, cols = channels.shape
    out = np.empty((rows, cols), dtype=channels.dtype)
    for dy, dx, channel in bayer_sites(cfa):
        out[dy::2, dx::2] = channels[channel, dy::2, dx::2]
    return out


def fixed_pattern(sensor: SensorSpec, shape: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """PRNU gain map (mean 1) and DSNU offset map (V) of this sensor unit (``fpn_seed``);
    float32, read-only (cached: every capture of the unit has the same maps)."""
    return _fixed_pattern(sensor.fpn_seed, sensor.prnu_fraction, sensor.dsnu_v, tuple(int(n) for n in shape))


@functools.lru_cache(maxsize=4)
def _fixed_pattern(fpn_seed: int, prnu_fraction: float, dsnu_v: float, shape: tuple[int, int]):
    rng = np.random.default_rng([fpn_seed, 0x5E45])
    gain = 1.0 + prnu_fraction * rng.standard_normal(shape, dtype=np.float32)
    offset = dsnu_v * rng.standard_normal(shape, dtype=np.float32)
    gain.setflags(write=False)
    offset.setflags(write=False)
    return gain, offset


def capture_volts(
    electron_rate: np.ndarray,
    exposure_s: float,
    sensor: SensorSpec,
    rng: np.random.Generator | None,
    noise: NoiseOptions = NoiseOptions(),
) -> np.ndarray:
    """Pixel voltage after analog gain and black-level offset, clipped to the swing.

    Args:
        electron_rate: (rows, cols) noise-free signal, electrons·s⁻¹ (the mosaic).
        exposure_s: integration time, s.
        rng: temporal-noise generator (needed when shot or read noise is on).
    """
    # float64 throughout, in place: the same values (and random draws) as the plain
    # expressions, without a temporary per step.
    electrons = np.multiply(electron_rate, exposure_s, dtype=np.float64)
    if noise.dark and sensor.dark_current_e_per_s > 0:
        electrons += sensor.dark_current_e_per_s * exposure_s
    if noise.shot:
        np.maximum(electrons, 0.0, out=electrons)
        # Poisson counts, then the photodiode's well
        np.minimum(rng.poisson(electrons), sensor.well_capacity_e, out=electrons, casting="unsafe")
    else:
        np.minimum(electrons, sensor.well_capacity_e, out=electrons)  # the photodiode's well
    if noise.read and sensor.read_noise_e > 0:
        read = rng.standard_normal(electrons.shape)
        read *= sensor.read_noise_e
        electrons += read
    volts = electrons
    volts *= sensor.conversion_gain_uv_per_e * 1e-6
    if (noise.prnu and sensor.prnu_fraction > 0) or (noise.dsnu and sensor.dsnu_v > 0):
        gain, offset = fixed_pattern(sensor, volts.shape)
        if noise.prnu:
            volts *= gain
        if noise.dsnu:
            volts += offset
    volts *= sensor.analog_gain
    volts += sensor.black_level_dn * sensor.lsb_v
    return np.clip(volts, 0.0, sensor.voltage_swing_v, out=volts)


def quantize(volts: np.ndarray, sensor: SensorSpec) -> np.ndarray:
    """Linear ADC: DN = round(V / LSB), uint16 in [0, 2^bits − 1]."""
    dn = np.divide(volts, sensor.lsb_v)
    np.rint(dn, out=dn)
    np.clip(dn, 0, sensor.white_level_dn, out=dn)
    return dn.astype(np.uint16)


def capture_dn(
    electron_rate: np.ndarray,
    exposure_s: float,
    sensor: SensorSpec,
    rng: np.random.Generator | None,
    noise: NoiseOptions = NoiseOptions(),
) -> np.ndarray:
    """Raw Bayer DN (rows, cols) uint16 of one exposure: :func:`capture_volts` then
    :func:`quantize`."""
    return quantize(capture_volts(electron_rate, exposure_s, sensor, rng, noise), sensor)


def signal_volts_per_electron(sensor: SensorSpec) -> float:
    """Volts at the ADC per signal electron (conversion gain × analog gain)."""
    return sensor.conversion_gain_uv_per_e * 1e-6 * sensor.analog_gain


def saturation_electrons(sensor: SensorSpec) -> float:
    """Signal electrons at which the raw data saturates: the well, or the ADC white level
    less the black-level offset (the offset uses part of the swing, as in ISETCam),
    whichever comes first. IMX363 defaults (ISO 270): min(6000, 959 DN / 0.837 DN/e⁻) = 1146 e⁻."""
    adc_e = (sensor.white_level_dn - sensor.black_level_dn) * sensor.lsb_v / signal_volts_per_electron(sensor)
    return float(min(sensor.well_capacity_e, adc_e))
