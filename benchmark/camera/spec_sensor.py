"""The sensor's spec (:class:`SensorSpec`): geometry, colour filters and QE, noise and the
readout, with the figures of ISETCam's ``sensorIMX363`` as defaults (docs/camera.md).

Geometry: the pixel array is ``width_px`` × ``height_px`` square pixels of ``pixel_um``,
``width_px = round(active_width_mm / pixel_um)`` (likewise the height): the active area is
rounded to whole pixels (docs/camera.md, "Field of view and geometry").

Refused as a whole: read noise not below the well, DSNU not below the swing, black level not
below the ADC white level, a pixel array under :data:`MIN_SIZE_PX` per side or above
:data:`MAX_CAPTURE_GIB` of memory for one capture, a ``qe`` file that is neither packaged nor
a physically possible table beside the spec file (:func:`benchmark.camera.spec_files.check_qe_table`).
A sensor may have clear pixels (``cfa: RCCB`` or ``RCCC``) and an HDR pixel read in one
exposure (``dcg``: :mod:`benchmark.camera.spec_readout`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field, PrivateAttr, ValidationInfo, computed_field, field_validator, model_validator

from benchmark.camera.spec_files import SPEC_DIR_CONTEXT, check_qe_name, check_qe_table, packaged_qe
from benchmark.camera.spec_readout import DualGainSpec, check_dual_gain
from benchmark.camera.spec_rules import SpecModel, added_later, check_plausible
from metricscenes.geometry import REFERENCE_ACTIVE_HEIGHT_MM, REFERENCE_ACTIVE_WIDTH_MM


IMX363_ISO_SPEED = 270.0
"""ISO speed of ISETCam's ``sensorIMX363`` (its default, used by the paper)."""
IMX363_ISO_UNITY_GAIN = 55.0
"""ISO at which the IMX363's analog gain is 1 (ISETCam: "for Pixel 4: ISO55")."""

MAX_CAPTURE_GIB = 4.0
"""A spec whose one capture needs more memory than this (estimate) is refused."""
CAPTURE_BYTES_PER_PIXEL = 256
"""Peak memory of one capture per pixel, bytes: the 31-band float32 radiance on the
pixel grid (124 B), the padded per-band FFTs and channel spectra, the float64 noise
chain, the raw and the ISP's float32 planes. Measured: 226 B/px (1920 × 1080) and
239 B/px (2688 × 1512) of peak RSS above the baseline for ``simulate``."""
MIN_SIZE_PX = 16
"""Fewest pixels per side (the demosaic and the exposure's central region need some)."""


class SensorSpec(SpecModel):
    """Sensor geometry, spectral response and noise (IMX363-like defaults, ISETCam)."""

    pixel_um: float = Field(..., ge=0.2, le=20.0)
    active_width_mm: float = Field(REFERENCE_ACTIVE_WIDTH_MM, gt=0.0, le=50.0)
    active_height_mm: float = Field(REFERENCE_ACTIVE_HEIGHT_MM, gt=0.0, le=50.0)
    cfa: Literal["RGGB", "RCCB", "RCCC"] = "RGGB"
    """The 2×2 colour filter tile, row by row: Bayer ``RGGB``, or ``RCCB`` / ``RCCC`` with clear
    (unfiltered) pixels, whose QE is the table's ``qe_c`` column or, without one, the sum of
    its R, G and B curves (docs/camera.md, "Clear-pixel colour filters")."""
    qe: str = Field("imx363_qe.csv", min_length=1, max_length=255)
    """Packaged CSV name (``metricscenes/data``), else a relative path from the spec
    file's folder (no absolute path, no ``..``); columns
    ``wavelength_nm, qe_r, qe_g, qe_b[, ir_cut_transmittance]``."""
    fill_factor: float = Field(1.0, gt=0.0, le=1.0)
    well_capacity_e: float = Field(6000.0, gt=0.0, le=1e7)
    conversion_gain_uv_per_e: float = Field(76.5, gt=0.0, le=1e4)
    voltage_swing_v: float = Field(0.4591, gt=0.0, le=10.0)
    read_noise_e: float = Field(5.0, ge=0.0, le=1000.0)
    dark_current_e_per_s: float = Field(0.0, ge=0.0, le=1e6)
    dsnu_v: float = Field(0.0, ge=0.0, le=1.0)
    prnu_fraction: float = Field(0.007, ge=0.0, le=0.5)
    adc_bits: int = Field(10, ge=8, le=16)
    black_level_dn: int = Field(64, ge=0, le=4096)
    analog_gain: float = Field(IMX363_ISO_SPEED / IMX363_ISO_UNITY_GAIN, gt=0.0, le=64.0)
    """Multiplies the pixel voltage: ISO speed / unity-gain ISO. ISETCam's sensorIMX363
    runs at ISO 270 with unity gain at ISO 55, so 4.91 (usable well ≈ 1150 e⁻)."""
    fpn_seed: int = Field(0, ge=0)
    """Seed of the fixed-pattern noise maps (PRNU, DSNU): a property of the sensor
    unit, the same in every capture, independent of the capture seed."""
    dcg: DualGainSpec | None = added_later(None)
    """An HDR pixel read in one exposure (:class:`benchmark.camera.spec_readout.DualGainSpec`):
    the charge read again at low gain, optionally a small photodiode, merged on the sensor and
    companded. The fields above then describe the high-gain readout. None: one readout."""

    _qe_path: str | None = PrivateAttr(None)
    """Resolved user QE file (a spec loaded from a file); None: packaged or unresolved."""

    @field_validator("qe")
    @classmethod
    def _qe_is_a_relative_csv(cls, value: str) -> str:
        return check_qe_name(value)

    @field_validator("well_capacity_e", "conversion_gain_uv_per_e", "voltage_swing_v", "read_noise_e",
                     "dark_current_e_per_s", "dsnu_v", "prnu_fraction", mode="before")
    @classmethod
    def _plausible(cls, value, info: ValidationInfo):
        return check_plausible(f"sensor.{info.field_name}", value)

    @model_validator(mode="after")
    def _whole_sensor(self, info: ValidationInfo) -> "SensorSpec":
        if self.read_noise_e >= self.well_capacity_e:
            raise ValueError(f"read_noise_e {self.read_noise_e:g} e- is not below well_capacity_e "
                             f"{self.well_capacity_e:g} e-: no signal could rise above the noise (read noise is in "
                             "electrons, a few e- on CMOS sensors; was it given in uV or DN, or the well in ke-?)")
        if self.dsnu_v >= self.voltage_swing_v:
            raise ValueError(f"dsnu_v {self.dsnu_v:g} V is not below voltage_swing_v {self.voltage_swing_v:g} V: "
                             "the offsets alone would fill the swing (DSNU is in volts; was it meant in mV?)")
        if self.black_level_dn >= self.white_level_dn:
            raise ValueError(f"black_level_dn {self.black_level_dn} must be below the ADC white level "
                             f"{self.white_level_dn} (2^adc_bits - 1 for adc_bits {self.adc_bits})")
        if self.dcg is not None:
            check_dual_gain(self)
        if min(self.width_px, self.height_px) < MIN_SIZE_PX:
            raise ValueError(f"the pixel array is {self.width_px} x {self.height_px} px (active area "
                             f"{self.active_width_mm:g} x {self.active_height_mm:g} mm at {self.pixel_um:g} um); "
                             f"at least {MIN_SIZE_PX} px per side")
        gib = self.capture_memory_bytes / 2**30
        if gib > MAX_CAPTURE_GIB:
            raise ValueError(f"the pixel array is {self.width_px} x {self.height_px} px "
                             f"({self.width_px * self.height_px / 1e6:.1f} Mpx: {self.active_width_mm:g} x "
                             f"{self.active_height_mm:g} mm at {self.pixel_um:g} um); one capture needs about "
                             f"{gib:.1f} GiB, above the {MAX_CAPTURE_GIB:g} GiB limit: use larger pixels or a "
                             "smaller active area")
        spec_dir = (info.context or {}).get(SPEC_DIR_CONTEXT) if info is not None else None
        if spec_dir is not None and packaged_qe(self.qe) is None:
            path = Path(spec_dir) / self.qe
            if not path.is_file():
                raise ValueError(f"qe {self.qe!r}: no packaged file of that name and no file {path}")
            check_qe_table(path)  # a user table: physically possible, or refused before anything runs
            self._qe_path = str(path.resolve())
        return self

    @computed_field
    @property
    def width_px(self) -> int:
        return int(round(self.active_width_mm * 1000.0 / self.pixel_um))

    @computed_field
    @property
    def height_px(self) -> int:
        return int(round(self.active_height_mm * 1000.0 / self.pixel_um))

    @property
    def pixel_area_m2(self) -> float:
        return (self.pixel_um * 1e-6) ** 2

    @property
    def lsb_v(self) -> float:
        """Volts per DN: the swing spans the full ADC range (ISETCam)."""
        return self.voltage_swing_v / (2**self.adc_bits - 1)

    @property
    def white_level_dn(self) -> int:
        return 2**self.adc_bits - 1

    @property
    def array_width_mm(self) -> float:
        """Width of the pixel array, mm: ``width_px`` × ``pixel_um`` (the active area
        rounded to whole pixels); it sets the horizontal field of view."""
        return self.width_px * self.pixel_um * 1e-3

    @property
    def array_height_mm(self) -> float:
        return self.height_px * self.pixel_um * 1e-3

    @property
    def capture_memory_bytes(self) -> int:
        """Estimated peak memory of one capture (:data:`CAPTURE_BYTES_PER_PIXEL` per pixel)."""
        return self.width_px * self.height_px * CAPTURE_BYTES_PER_PIXEL

    @property
    def qe_path(self) -> Path:
        """The QE file this sensor reads: the resolved user file of a spec loaded from a
        file, else the packaged file of that name, else ``qe`` from the working folder
        (a spec validated without a file). ValueError if it does not exist."""
        if self._qe_path is not None:
            return Path(self._qe_path)
        path = packaged_qe(self.qe) or Path(self.qe)
        if not path.is_file():
            raise ValueError(f"sensor.qe: QE file {self.qe!r} not found (packaged name or a file beside the spec)")
        return path
