"""The image sensor: irradiance to electrons to volts to digital numbers (DN).

Spectral integration (ISETCam ``sensorCompute``): a pixel of channel c collects

    e⁻/s = A · FF · Σ_λ E(λ) · QE_c(λ) · IRcut(λ) · λ / (h c) · Δλ

(A pixel area, FF fill factor, Δλ band width). The capture then follows ISETCam's
noise order: signal (+ dark) electrons → Poisson shot noise → clip at the well →
Gaussian read noise → volts (conversion gain) → PRNU (gain) and DSNU (offset) →
analog gain and the offset that gives the black level → clip to [0, swing] →
quantise (``adc_bits``).

The colour filter tile (``sensor.cfa``) is Bayer RGGB, or RCCB / RCCC with clear pixels, whose
QE is the sum of the R, G and B curves unless the table gives its own (:func:`cfa_channels`,
:func:`effective_qe`). A sensor may read its pixel more than once (an HDR pixel:
:mod:`benchmark.camera.dual_gain`): :func:`collect_electrons` and :func:`read_out_volts` are the
two halves of one readout for that.

Every noise source can be switched off (:class:`NoiseOptions`); temporal noise comes
from ``np.random.default_rng(seed)`` (same seed, same raw); the fixed-pattern maps come
from the sensor's own ``fpn_seed`` (the same sensor unit in every capture).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from benchmark.camera.spec_files import read_qe_table
from benchmark.camera.spec_sensor import SensorSpec
from metricscenes.spectral import BAND_WIDTH_NM, WAVELENGTHS_NM, photon_energy_j, resample_spectrum

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
def _read_qe_table(path: str) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """(wavelengths nm, {"r", "g", "b", "c": QE × IR-cut}) of a QE file, refused in one line
    unless it is physically possible (:func:`benchmark.camera.spec_files.read_qe_table`). The clear
    pixel's QE is the table's ``qe_c`` where it has one, else the sum of its R, G and B curves
    (at most 1): the photodiode without a colour filter collects what the three filters pass
    between them (docs/camera.md, "Clear-pixel colour filters")."""
    wl, qe, ir_cut = read_qe_table(path)
    if "c" not in qe:
        qe = {**qe, "c": np.minimum(qe["r"] + qe["g"] + qe["b"], 1.0)}
    if ir_cut is not None:
        qe = {c: q * ir_cut for c, q in qe.items()}
    return wl, qe


def cfa_channels(cfa: str = "RGGB") -> str:
    """The channels a colour filter tile samples, one letter each in the order of the
    channel images (:func:`channel_responsivity`, :func:`mosaic`, the demosaicked image):
    ``RGB`` for a Bayer tile, ``RCB`` for RCCB (clear in green's place), ``RC`` for RCCC."""
    return "".join(c for c in "RGCB" if c in cfa)


def effective_qe(sensor: SensorSpec, wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """Colour-filter QE × IR-cut transmittance of each channel (:func:`cfa_channels`),
    (channels, bands), interpolated to the bands."""
    wl, qe = _read_qe_table(str(sensor.qe_path.resolve()))
    return np.stack([resample_spectrum(wl, qe[c.lower()], wavelengths_nm) for c in cfa_channels(sensor.cfa)])


def channel_responsivity(sensor: SensorSpec, wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """Electrons·s⁻¹ per pixel per W·m⁻²·nm⁻¹ of irradiance in each band, (channels, bands):
    QE · IRcut · λ/(hc) · Δλ · pixel area · fill factor."""
    photons_per_j = 1.0 / photon_energy_j(wavelengths_nm)
    area = sensor.pixel_area_m2 * sensor.fill_factor
    return effective_qe(sensor, wavelengths_nm) * photons_per_j[None, :] * BAND_WIDTH_NM * area


def electron_rate(optical_image, sensor: SensorSpec) -> np.ndarray:
    """Noise-free signal per channel (channels, rows, cols), electrons·s⁻¹, of an optical image
    (:class:`benchmark.camera.optics.OpticalImage`): the sensor integrates its own QE,
    Σ_λ r_c(λ)·E(λ) with :func:`channel_responsivity`, asking the optical image for those
    weighted sums of its bands (:meth:`~benchmark.camera.optics.OpticalImage.weighted_sum`,
    the fast path; :func:`signal_from_irradiance` is the plain one it is held equal to)."""
    return optical_image.weighted_sum(channel_responsivity(sensor, np.asarray(optical_image.wavelengths_nm, float)))


def signal_from_irradiance(irradiance: np.ndarray, wavelengths_nm: np.ndarray, sensor: SensorSpec) -> np.ndarray:
    """Noise-free signal per channel (channels, rows, cols), electrons·s⁻¹, of a spectral
    irradiance (rows, cols, bands) in W·m⁻²·nm⁻¹ (an optical image's): Σ_λ r_c(λ)·E(λ)
    with :func:`channel_responsivity`. The plain path; :func:`electron_rate` (the
    camera's fast path) is held equal to it."""
    resp = channel_responsivity(sensor, np.asarray(wavelengths_nm, float))
    return np.einsum("hwb,cb->chw", np.asarray(irradiance, np.float64), resp).astype(np.float32)


def bayer_sites(cfa: str = "RGGB") -> list[tuple[int, int, int]]:
    """The four sites of the 2×2 colour filter tile ``cfa`` (read row by row), in that order:
    (row offset, column offset, channel index in :func:`cfa_channels`: R 0, G or C 1, B 2).
    A site's pixels are ``mosaic[dy::2, dx::2]``."""
    channels = cfa_channels(cfa)
    return [(dy, dx, channels.index(colour)) for (dy, dx), colour in zip(((0, 0), (0, 1), (1, 0), (1, 1)), cfa)]


def cfa_index(rows: int, cols: int, cfa: str = "RGGB") -> np.ndarray:
    """Channel index (:func:`bayer_sites`) of every pixel of a mosaic, (rows, cols) uint8."""
    tile = np.zeros((2, 2), dtype=np.uint8)
    for dy, dx, channel in bayer_sites(cfa):
        tile[dy, dx] = channel
    return np.tile(tile, ((rows + 1) // 2, (cols + 1) // 2))[:rows, :cols]


def mosaic(channels: np.ndarray, cfa: str = "RGGB") -> np.ndarray:
    """Sample (channels, rows, cols) channel images on the colour filter tile: (rows, cols)."""
    _, rows, cols = channels.shape
    out = np.empty((rows, cols), dtype=channels.dtype)
    for dy, dx, channel in bayer_sites(cfa):
        out[dy::2, dx::2] = channels[channel, dy::2, dx::2]
    return out


def fixed_pattern(sensor: SensorSpec, shape: tuple[int, int], photodiode: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """PRNU gain map (mean 1) and DSNU offset map (V) of this sensor unit (``fpn_seed``);
    float32, read-only (cached: every capture of the unit has the same maps). ``photodiode``
    1: the small photodiode of a split pixel, whose non-uniformity is its own (0: the pixel's
    photodiode, read at any gain)."""
    return _fixed_pattern(sensor.fpn_seed, sensor.prnu_fraction, sensor.dsnu_v, tuple(int(n) for n in shape),
                          int(photodiode))


@functools.lru_cache(maxsize=16)  # (a sweep's cameras, scene by scene)
def _fixed_pattern(fpn_seed: int, prnu_fraction: float, dsnu_v: float, shape: tuple[int, int], photodiode: int = 0):
    rng = np.random.default_rng([fpn_seed, 0x5E45] + ([photodiode] if photodiode else []))
    gain = 1.0 + prnu_fraction * rng.standard_normal(shape, dtype=np.float32)
    offset = dsnu_v * rng.standard_normal(shape, dtype=np.float32)
    gain.setflags(write=False)
    offset.setflags(write=False)
    return gain, offset


def collect_electrons(
    electron_rate: np.ndarray,
    exposure_s: float,
    sensor: SensorSpec,
    rng: np.random.Generator | None,
    noise: NoiseOptions = NoiseOptions(),
    *,
    well_capacity_e: float | None = None,
) -> np.ndarray:
    """Electrons a photodiode holds at the end of the exposure, (rows, cols) float64: signal
    (+ dark) electrons, Poisson shot noise, clipped at its well (``well_capacity_e``, default
    the sensor's).

    Args:
        electron_rate: (rows, cols) noise-free signal, electrons·s⁻¹ (the mosaic).
        exposure_s: integration time, s.
        rng: temporal-noise generator (needed when shot noise is on).
    """
    well = sensor.well_capacity_e if well_capacity_e is None else well_capacity_e
    # float64 throughout, in place: the same values (and random draws) as the plain
    # expressions, without a temporary per step.
    electrons = np.multiply(electron_rate, exposure_s, dtype=np.float64)
    if noise.dark and sensor.dark_current_e_per_s > 0:
        electrons += sensor.dark_current_e_per_s * exposure_s
    if noise.shot:
        np.maximum(electrons, 0.0, out=electrons)
        # Poisson counts, then the photodiode's well
        np.minimum(rng.poisson(electrons), well, out=electrons, casting="unsafe")
    else:
        np.minimum(electrons, well, out=electrons)  # the photodiode's well
    return electrons


def read_out_volts(
    electrons: np.ndarray,
    sensor: SensorSpec,
    rng: np.random.Generator | None,
    noise: NoiseOptions = NoiseOptions(),
    *,
    conversion_gain_uv_per_e: float | None = None,
    read_noise_e: float | None = None,
    photodiode: int = 0,
) -> np.ndarray:
    """One readout of collected ``electrons`` (float64, overwritten): Gaussian read noise,
    volts at the conversion gain, PRNU and DSNU, analog gain and the black-level offset,
    clipped to the swing. ``conversion_gain_uv_per_e`` and ``read_noise_e`` default to the
    sensor's (another gain of a dual-gain pixel gives its own); ``photodiode`` picks the
    fixed-pattern maps (:func:`fixed_pattern`)."""
    read_noise = sensor.read_noise_e if read_noise_e is None else read_noise_e
    gain_uv = sensor.conversion_gain_uv_per_e if conversion_gain_uv_per_e is None else conversion_gain_uv_per_e
    if noise.read and read_noise > 0:
        read = rng.standard_normal(electrons.shape)
        read *= read_noise
        electrons += read
    volts = electrons
    volts *= gain_uv * 1e-6
    if (noise.prnu and sensor.prnu_fraction > 0) or (noise.dsnu and sensor.dsnu_v > 0):
        gain, offset = fixed_pattern(sensor, volts.shape, photodiode)
        if noise.prnu:
            volts *= gain
        if noise.dsnu:
            volts += offset
    volts *= sensor.analog_gain
    volts += sensor.black_level_dn * sensor.lsb_v
    return np.clip(volts, 0.0, sensor.voltage_swing_v, out=volts)


def capture_volts(
    electron_rate: np.ndarray,
    exposure_s: float,
    sensor: SensorSpec,
    rng: np.random.Generator | None,
    noise: NoiseOptions = NoiseOptions(),
) -> np.ndarray:
    """Pixel voltage after analog gain and black-level offset, clipped to the swing: the
    sensor's one readout (:func:`read_out_volts`) of what its photodiode collects
    (:func:`collect_electrons`).

    Args:
        electron_rate: (rows, cols) noise-free signal, electrons·s⁻¹ (the mosaic).
        exposure_s: integration time, s.
        rng: temporal-noise generator (needed when shot or read noise is on).
    """
    return read_out_volts(collect_electrons(electron_rate, exposure_s, sensor, rng, noise), sensor, rng, noise)


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
