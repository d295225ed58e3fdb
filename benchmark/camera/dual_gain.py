"""An HDR pixel read in one exposure: dual conversion gain (DCG), optionally a split pixel,
merged on the sensor into one linear word and companded to the output's bits
(``sensor.dcg``, :class:`benchmark.camera.spec_readout.DualGainSpec`).

**The pixel.** A large photodiode integrates its charge Q once; it is read twice, at high
conversion gain (HCG: a small sense node, the lowest read noise, saturating first) and at
low conversion gain (LCG: the photodiode with its overflow capacitor, up to
``lcg_well_capacity_e``). A split pixel adds a small photodiode beside it, which collects
``sensitivity_ratio`` of the large one's electrons for the same light and is read once
(its own gain, well and read noise). The HCG/LCG readout of one charge is the DCG pixel of
onsemi's automotive sensors (AR0820AT, AR0233AT: "DCG"; Solhusvik et al., "A comparison of
high dynamic range CIS technologies for automotive applications", IISW 2019); large and
small photodiodes each read at two gains are Sony's sub-pixel architecture of the IMX490
(Iida et al., "A 0.68e-rms random-noise 121dB dynamic-range sub-pixel architecture CMOS
image sensor with LED flicker mitigation", IEDM 2018; LUCID Vision Labs, "Sony IMX490 CMOS
sensor: on-sensor HDR for 24-bit imaging", tech brief): here the small photodiode is read
at one gain (its HCG readout, which bridges a gap the merge does not need, is left out).

**The readouts** follow the sensor's one-readout noise order (:mod:`benchmark.camera.sensor`):
Poisson shot noise on Q, clipped at the large photodiode's capacity (the LCG well); the HCG
readout sees min(Q, ``well_capacity_e``); each readout adds its own Gaussian read noise,
converts at its own gain, shares the analog gain, black level and ADC (``adc_bits``). The
two gains of one photodiode share its PRNU map; the small photodiode has its own.

**The merge** (:func:`merge_dn`), per pixel of the mosaic, in DN of the HCG readout (the
signal of the large photodiode, black level included): each readout's signal above black
is scaled by the ratio of the gains (K_HCG / K_readout, K in DN per electron) and, for the
small photodiode, by 1 / sensitivity_ratio; the HCG value is kept where it is below the
transition ``hcg_to_lcg_e`` (× K_HCG), else the LCG value where that is below
``lcg_to_spd_e``, else the small photodiode's: the hard switch of the two-frame merge
(:func:`benchmark.camera.acquisition.merge_two_exposures_dn`), each readout deciding for
itself. The result is rounded to the ``merged_bits`` linear word, as on the sensor.

**Companding** (:func:`compand`, :func:`decompand`): the merged word is mapped to
``companded_bits`` by the piecewise-linear curve through ``companding_knees`` (merged
code, output code), rounded to the nearest code; the host inverts the curve exactly at each
code. Slopes at most 1 that never rise (checked by the spec) make the curve monotonic and
invertible: decompanding a code and companding it again gives the code, and a merged value
comes back within half a step of its segment (1 / (2·slope) merged codes). Sensors
publish such knee tables for their output (onsemi AR0330CM datasheet, "Compression":
A-law from 12 to 10 bits, segments of halving slope; automotive HDR sensors compand their
20–24-bit merged word to 12–16 bits the same way). A segment whose step stays below the
temporal noise where it starts adds no visible error: quantisation adds step²/12 to the
noise variance (docs/camera.md, "Acquisition").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from benchmark.camera import sensor as _sensor
from benchmark.camera.spec_sensor import SensorSpec
from benchmark.camera.spec_readout import readout_saturation_e


@dataclass(frozen=True)
class Readout:
    """One readout of an HDR pixel, as the merge sees it.

    Attributes:
        name: ``hcg``, ``lcg`` or ``spd`` (the small photodiode).
        photodiode: 0 the large photodiode, 1 the small one (its own shot noise and PRNU).
        sensitivity: electrons of its photodiode per electron of the large one.
        conversion_gain_uv_per_e, read_noise_e: of this readout.
        well_capacity_e: the charge it reads at most (its photodiode's electrons).
        saturation_e: where its raw saturates, in its photodiode's electrons (well or ADC).
        takes_over_e: where the merge switches to it, in electrons of the large photodiode
            (None for the first).
    """

    name: str
    photodiode: int
    sensitivity: float
    conversion_gain_uv_per_e: float
    read_noise_e: float
    well_capacity_e: float
    saturation_e: float
    takes_over_e: float | None


def readouts(sensor: SensorSpec) -> tuple[Readout, ...]:
    """The readouts of ``sensor``, most sensitive first: its own (``hcg``), then the DCG
    block's ``lcg`` and, for a split pixel, ``spd``; a sensor without ``dcg``: its one readout."""
    first = Readout("hcg", 0, 1.0, sensor.conversion_gain_uv_per_e, sensor.read_noise_e, sensor.well_capacity_e,
                    readout_saturation_e(sensor, sensor.conversion_gain_uv_per_e, sensor.well_capacity_e), None)
    dcg = sensor.dcg
    if dcg is None:
        return (first,)
    out = [first, Readout("lcg", 0, 1.0, dcg.lcg_conversion_gain_uv_per_e, dcg.lcg_read_noise_e,
                          dcg.lcg_well_capacity_e,
                          readout_saturation_e(sensor, dcg.lcg_conversion_gain_uv_per_e, dcg.lcg_well_capacity_e),
                          dcg.hcg_to_lcg_e)]
    spd = dcg.small_photodiode
    if spd is not None:
        out.append(Readout("spd", 1, spd.sensitivity_ratio, spd.conversion_gain_uv_per_e, spd.read_noise_e,
                           spd.well_capacity_e,
                           readout_saturation_e(sensor, spd.conversion_gain_uv_per_e, spd.well_capacity_e),
                           spd.lcg_to_spd_e))
    return tuple(out)


def dn_per_electron(sensor: SensorSpec, readout: Readout) -> float:
    """DN of ``readout`` per electron of its photodiode: gain × analog gain / LSB."""
    return readout.conversion_gain_uv_per_e * 1e-6 * sensor.analog_gain / sensor.lsb_v


def merged_saturation_e(sensor: SensorSpec) -> float:
    """Top of the merged range, electrons of the large photodiode: the last readout's
    saturation over its sensitivity (the sensor's own saturation without ``dcg``)."""
    last = readouts(sensor)[-1]
    return last.saturation_e / last.sensitivity


def merged_range_ratio(sensor: SensorSpec) -> float:
    """The merged range over the HCG readout's ADC range above black (1 = the HCG white in
    the ISP's linear units): how much more signal the HDR pixel holds than its HCG raw."""
    first = readouts(sensor)[0]
    hcg_range_dn = sensor.white_level_dn - sensor.black_level_dn
    return merged_saturation_e(sensor) * dn_per_electron(sensor, first) / hcg_range_dn


def read_out(electron_rate: np.ndarray, exposure_s: float, sensor: SensorSpec, rng: np.random.Generator | None,
             noise: _sensor.NoiseOptions) -> dict[str, np.ndarray]:
    """The raw mosaics (uint16, black level included) of every readout of one exposure, by
    readout name. Random draws in a fixed order: the large photodiode's shot noise, the HCG
    and LCG read noise, the small photodiode's shot and read noise."""
    steps = readouts(sensor)
    # The large photodiode holds up to its LCG well (photodiode and overflow capacitor).
    large = _sensor.collect_electrons(electron_rate, exposure_s, sensor, rng, noise,
                                      well_capacity_e=sensor.dcg.lcg_well_capacity_e)
    raws = {}
    for r in steps:
        if r.photodiode == 0:
            charge = np.minimum(large, r.well_capacity_e) if r.name == "hcg" else large
        else:
            charge = _sensor.collect_electrons(np.multiply(electron_rate, r.sensitivity), exposure_s, sensor, rng,
                                               noise, well_capacity_e=r.well_capacity_e)
        volts = _sensor.read_out_volts(charge, sensor, rng, noise, conversion_gain_uv_per_e=r.conversion_gain_uv_per_e,
                                       read_noise_e=r.read_noise_e, photodiode=r.photodiode)
        raws[r.name] = _sensor.quantize(volts, sensor)
    return raws


def readout_choice(raws: dict[str, np.ndarray], sensor: SensorSpec) -> np.ndarray:
    """Index (in :func:`readouts`) of the readout the merge takes at each pixel, (rows, cols) uint8."""
    steps = readouts(sensor)
    black = float(sensor.black_level_dn)
    choice = np.zeros(next(iter(raws.values())).shape, dtype=np.uint8)
    # Each readout decides for itself: the next one takes over where this one reaches the transition.
    moves_on = np.ones(choice.shape, dtype=bool)
    for i in range(1, len(steps)):
        before = steps[i - 1]
        per_e = dn_per_electron(sensor, before) * before.sensitivity
        signal_before = (raws[before.name].astype(np.float64) - black) / per_e
        moves_on &= signal_before >= steps[i].takes_over_e
        choice[moves_on] = i
    return choice


def merge_dn(raws: dict[str, np.ndarray], sensor: SensorSpec) -> np.ndarray:
    """The merged linear signal (rows, cols) float64, DN of the HCG readout, black level
    included, before rounding to the merged word: each pixel from the readout
    :func:`readout_choice` takes, scaled to the HCG readout's DN of large-photodiode electrons."""
    steps = readouts(sensor)
    black = float(sensor.black_level_dn)
    k_first = dn_per_electron(sensor, steps[0])
    choice = readout_choice(raws, sensor)
    merged = np.empty(choice.shape, dtype=np.float64)
    for i, r in enumerate(steps):
        at = choice == i
        scale = k_first / (dn_per_electron(sensor, r) * r.sensitivity)
        merged[at] = (raws[r.name][at].astype(np.float64) - black) * scale
    return merged + black


def merged_word(merged_dn: np.ndarray, sensor: SensorSpec) -> np.ndarray:
    """The merged signal rounded to the sensor's ``merged_bits`` linear word (uint32)."""
    top = 2**sensor.dcg.merged_bits - 1
    return np.clip(np.rint(merged_dn), 0, top).astype(np.uint32)


def compand(word: np.ndarray, knees) -> np.ndarray:
    """Merged linear codes → output codes (uint16): the piecewise-linear curve through
    ``knees`` (merged code, output code), rounded to the nearest code."""
    x, y = (np.asarray(k, dtype=np.float64) for k in zip(*knees))
    return np.rint(np.interp(np.asarray(word, dtype=np.float64), x, y)).astype(np.uint16)


def decompand(codes: np.ndarray, knees) -> np.ndarray:
    """Output codes → merged linear values (float64): the curve inverted at each code (the
    host's table). compand(decompand(c)) == c for every code."""
    x, y = (np.asarray(k, dtype=np.float64) for k in zip(*knees))
    return np.interp(np.asarray(codes, dtype=np.float64), y, x)


def noise_floor_e(sensor: SensorSpec, readout: Readout) -> float:
    """A readout's noise floor in electrons of the large photodiode: its read noise, the
    DSNU and the ADC's LSB/√12 at its gain, in quadrature, over its sensitivity."""
    per_e = dn_per_electron(sensor, readout)
    dsnu_e = sensor.dsnu_v / (readout.conversion_gain_uv_per_e * 1e-6)
    return float(np.sqrt(readout.read_noise_e**2 + dsnu_e**2 + 1.0 / per_e**2 / 12.0)) / readout.sensitivity


def temporal_variance_e2(sensor: SensorSpec, signal_e: float) -> float:
    """Temporal variance, e⁻² of the large photodiode, of the merged signal at a noise-free
    ``signal_e``: the shot noise of the photodiode the merge reads there (signal /
    sensitivity: the small photodiode counts fewer electrons) and that readout's floor
    (:func:`noise_floor_e`); the readout is the last whose transition lies at or below the signal."""
    steps = readouts(sensor)
    chosen = [r for r in steps if r.takes_over_e is None or r.takes_over_e <= signal_e][-1]
    return signal_e / chosen.sensitivity + noise_floor_e(sensor, chosen) ** 2
