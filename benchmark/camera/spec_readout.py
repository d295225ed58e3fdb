"""The spec of an HDR pixel read in one exposure: dual conversion gain (DCG), optionally
with a small photodiode beside the large one (split pixel), merged on the sensor into one
linear word and companded to the output's bits (``sensor.dcg`` in a camera's YAML).

The sensor's own fields describe the high-gain readout of the large photodiode (HCG:
``conversion_gain_uv_per_e``, ``well_capacity_e`` the charge it can read, ``read_noise_e``);
:class:`DualGainSpec` adds the same charge read again at low gain (LCG: the photodiode with
its overflow capacitor), :class:`SmallPhotodiodeSpec` the small photodiode, and the merge
and companding. The physics and its sources are in :mod:`benchmark.camera.dual_gain` and
docs/camera.md ("Acquisition").

A spec is refused in one line naming the field where the readouts contradict each other
(:func:`check_dual_gain`): a low gain not below the high gain, a readout that holds no more
than the one it takes over from, a transition above the saturation of the readout it leaves,
a merged word too short for the range, companding knees that do not make an invertible,
concave curve from 0 to the word's top.
"""

from __future__ import annotations

import math

from pydantic import Field, ValidationInfo, field_validator

from benchmark.camera.spec_rules import SpecModel, check_plausible


class SmallPhotodiodeSpec(SpecModel):
    """The small photodiode of a split pixel (read at one gain): it collects
    ``sensitivity_ratio`` of the large photodiode's electrons for the same light, so it
    saturates ``1 / sensitivity_ratio`` times later."""

    sensitivity_ratio: float = Field(..., gt=0.0, lt=1.0)
    """Electrons of the small photodiode per electron of the large one under the same light
    (area × microlens × QE ratio), e.g. 1/40."""
    conversion_gain_uv_per_e: float = Field(..., gt=0.0, le=1e4)
    well_capacity_e: float = Field(..., gt=0.0, le=1e7)
    read_noise_e: float = Field(..., ge=0.0, le=1000.0)
    lcg_to_spd_e: float = Field(..., gt=0.0, le=1e9)
    """Where the small photodiode takes over from the LCG readout, in electrons of the large
    photodiode (at most the LCG saturation)."""

    @field_validator("conversion_gain_uv_per_e", "well_capacity_e", "read_noise_e", mode="before")
    @classmethod
    def _plausible(cls, value, info: ValidationInfo):
        return check_plausible(f"sensor.{info.field_name}", value)


class DualGainSpec(SpecModel):
    """The low-gain readout of the large photodiode, the optional small photodiode, the
    merge's transitions and the companding of the merged word (docs/camera.md, "Acquisition")."""

    lcg_conversion_gain_uv_per_e: float = Field(..., gt=0.0, le=1e4)
    """Conversion gain of the low-gain readout (below the sensor's high gain)."""
    lcg_well_capacity_e: float = Field(..., gt=0.0, le=1e7)
    """Charge the large photodiode and its overflow capacitor hold, read at low gain."""
    lcg_read_noise_e: float = Field(..., ge=0.0, le=1000.0)
    hcg_to_lcg_e: float = Field(..., gt=0.0, le=1e9)
    """Where the LCG readout takes over from the HCG one, electrons (at most the HCG saturation)."""
    small_photodiode: SmallPhotodiodeSpec | None = None
    merged_bits: int = Field(..., ge=12, le=32)
    """Bits of the merged linear word (DN of the HCG readout, black level included)."""
    companded_bits: int = Field(..., ge=8, le=16)
    """Bits of the companded output word."""
    companding_knees: tuple[tuple[int, int], ...] = Field(..., min_length=2)
    """Piecewise-linear companding: (merged code, output code) knee points from (0, 0) to
    (2^merged_bits − 1, at most 2^companded_bits − 1), linear between them."""

    @field_validator("lcg_conversion_gain_uv_per_e", "lcg_well_capacity_e", "lcg_read_noise_e", mode="before")
    @classmethod
    def _plausible(cls, value, info: ValidationInfo):
        return check_plausible(f"sensor.{info.field_name.removeprefix('lcg_')}", value)

    @field_validator("companding_knees")
    @classmethod
    def _knees_make_an_invertible_curve(cls, knees, info: ValidationInfo):
        bits = info.data.get("merged_bits"), info.data.get("companded_bits")
        check_companding_knees(knees, *bits) if None not in bits else None
        return knees


def check_companding_knees(knees, merged_bits: int, companded_bits: int) -> None:
    """One-line ValueError unless ``knees`` (merged code, output code) run from (0, 0) to
    (2^merged_bits − 1, ≤ 2^companded_bits − 1), strictly increasing in both, with slopes at
    most 1 that never rise (a concave curve: finer steps where the signal, hence its shot
    noise, is small), so that every output code decodes to one merged value."""
    top_in, top_out = 2**merged_bits - 1, 2**companded_bits - 1
    if tuple(knees[0]) != (0, 0):
        raise ValueError(f"the first knee is {tuple(knees[0])}, not (0, 0)")
    if knees[-1][0] != top_in or knees[-1][1] > top_out:
        raise ValueError(f"the last knee is {tuple(knees[-1])}: it must be at merged code {top_in} (2^merged_bits - 1) "
                         f"and output code at most {top_out} (2^companded_bits - 1)")
    slopes = []
    for (x0, y0), (x1, y1) in zip(knees[:-1], knees[1:]):
        if not (x1 > x0 and y1 > y0):
            raise ValueError(f"knee {(x1, y1)} does not follow {(x0, y0)} upwards in both codes")
        slopes.append((y1 - y0) / (x1 - x0))
    if slopes[0] > 1.0:
        raise ValueError(f"the first segment's slope {slopes[0]:.4g} is above 1: companding never expands")
    rise = next((i for i in range(1, len(slopes)) if slopes[i] > slopes[i - 1]), None)
    if rise is not None:
        raise ValueError(f"the slope rises after knee {tuple(knees[rise])} ({slopes[rise - 1]:.4g} to "
                         f"{slopes[rise]:.4g}): companding knees give slopes that never rise")


def readout_saturation_e(sensor, conversion_gain_uv_per_e: float, well_capacity_e: float) -> float:
    """Electrons at which one readout saturates: its well, or the ADC white level less the
    black level at this conversion gain (× the sensor's analog gain), whichever comes first
    (:func:`benchmark.camera.sensor.saturation_electrons` for the sensor's own readout)."""
    adc_e = (sensor.white_level_dn - sensor.black_level_dn) * sensor.lsb_v / (
        conversion_gain_uv_per_e * 1e-6 * sensor.analog_gain)
    return float(min(well_capacity_e, adc_e))


def check_dual_gain(sensor) -> None:
    """One-line ValueError, naming the field, where ``sensor.dcg`` contradicts the sensor's
    own (high-gain) readout or itself."""
    dcg = sensor.dcg
    high = sensor.conversion_gain_uv_per_e
    if dcg.lcg_conversion_gain_uv_per_e >= high:
        raise ValueError(f"sensor.dcg.lcg_conversion_gain_uv_per_e {dcg.lcg_conversion_gain_uv_per_e:g} uV/e- is not "
                         f"below the high gain sensor.conversion_gain_uv_per_e {high:g} uV/e-: the low-gain readout "
                         "is the one with the smaller conversion gain")
    hcg_sat = readout_saturation_e(sensor, high, sensor.well_capacity_e)
    lcg_sat = readout_saturation_e(sensor, dcg.lcg_conversion_gain_uv_per_e, dcg.lcg_well_capacity_e)
    if lcg_sat <= hcg_sat:
        raise ValueError(f"sensor.dcg.lcg_well_capacity_e: the low-gain readout saturates at {lcg_sat:.0f} e-, no "
                         f"later than the high-gain one ({hcg_sat:.0f} e-): it would extend nothing")
    if dcg.hcg_to_lcg_e > hcg_sat:
        raise ValueError(f"sensor.dcg.hcg_to_lcg_e {dcg.hcg_to_lcg_e:g} e- is above the high-gain readout's "
                         f"saturation {hcg_sat:.0f} e- (min of sensor.well_capacity_e and its ADC range)")
    top_e, top_name = lcg_sat, "sensor.dcg.lcg_well_capacity_e"
    spd = dcg.small_photodiode
    if spd is not None:
        spd_sat = readout_saturation_e(sensor, spd.conversion_gain_uv_per_e, spd.well_capacity_e)
        spd_top = spd_sat / spd.sensitivity_ratio
        if spd_top <= lcg_sat:
            raise ValueError(f"sensor.dcg.small_photodiode: it saturates at {spd_top:.0f} e- of the large photodiode, "
                             f"no later than the low-gain readout ({lcg_sat:.0f} e-): it would extend nothing")
        if not dcg.hcg_to_lcg_e < spd.lcg_to_spd_e <= lcg_sat:
            raise ValueError(f"sensor.dcg.small_photodiode.lcg_to_spd_e {spd.lcg_to_spd_e:g} e- must lie above "
                             f"sensor.dcg.hcg_to_lcg_e ({dcg.hcg_to_lcg_e:g} e-) and at most at the low-gain "
                             f"saturation {lcg_sat:.0f} e-")
        top_e, top_name = spd_top, "sensor.dcg.small_photodiode"
    dn_per_e = high * 1e-6 * sensor.analog_gain / sensor.lsb_v
    top_dn = sensor.black_level_dn + top_e * dn_per_e
    if top_dn > 2**dcg.merged_bits - 1:
        raise ValueError(f"sensor.dcg.merged_bits {dcg.merged_bits} holds codes up to {2**dcg.merged_bits - 1}; the "
                         f"merged range ({top_name}) reaches {top_dn:.0f} DN of the high-gain readout: give "
                         f"{math.ceil(math.log2(top_dn + 1))} bits or more")
