"""The camera specification: optics, sensor, exposure policy and ISP options.

A :class:`CameraSpec` is a frozen pydantic model; every field has a unit in its name
and a validated range. The defaults describe the paper's camera (Liu et al., EI 2023):
4.38 mm diffraction-limited lens over a 2.688 x 1.512 mm Sony IMX363-like sensor, with
the figures of ISETCam's ``sensorIMX363`` (see ``docs/camera.md``). Only the pixel
pitch and the f-number differ between the 13 registry cameras.

Geometry: the pixel array is ``width_px`` × ``height_px`` square pixels of ``pixel_um``,
``width_px = round(active_width_mm / pixel_um)`` (likewise the height): the active area
is rounded to whole pixels, and the field of view is the pixel array's,
``2·atan(width_px · pixel_um / 2f)`` × ``2·atan(height_px · pixel_um / 2f)``, so pixels
are square in angle by construction (docs/camera.md, "Field of view and geometry").

A spec is validated as a whole (docs/camera.md, "Refused specs"): black level below the
ADC white level, a ``qe`` file that is packaged or lies beside the spec file and holds a
physically possible table (:func:`check_qe_table`), lens tables (``optics.psf_table``,
``optics.mtf_table``) beside the spec file that :mod:`benchmark.camera.lens` can read and
that sample the pixel grid finely enough, Zernike indices it knows, a known illuminant, a
pixel array of at least 16 × 16 and at most :data:`MAX_CAPTURE_GIB` of memory for one
capture. Values no sensor has are refused with the unit mistake they most likely are, and
unusual but possible ones are warned about (:data:`PLAUSIBLE`, docs/camera.md, "Plausible
values").

A sensor may have clear pixels (``cfa: RCCB`` or ``RCCC``) and an HDR pixel read in one exposure
(``dcg``: :mod:`benchmark.camera.spec_readout`); a lens table's content is recorded beside its
name (``psf_table_sha256``, ``mtf_table_sha256``), so the camera's sha256 covers it.

Specs that can grow: a field added after the registry and its leaderboard is declared with
:func:`added_later`, and one rule (:class:`SpecModel`) leaves it out of the serialisation —
hence out of :meth:`CameraSpec.sha256` — wherever it is at its default, so every earlier
spec keeps its bytes (docs/camera.md, "Adding a camera feature").
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
from pathlib import Path, PurePosixPath, PureWindowsPath
from typing import Literal

import numpy as np

from pydantic import (
    Field,
    PrivateAttr,
    ValidationInfo,
    computed_field,
    field_serializer,
    field_validator,
    model_validator,
)

from benchmark.camera import lens as _lens
from benchmark.camera.distortion import check_monotonic, undistorted_bounds
from benchmark.camera.spec_readout import DualGainSpec, SmallPhotodiodeSpec, check_dual_gain  # noqa: F401
from benchmark.camera.spec_rules import (  # noqa: F401  (re-exported: the rules' old home)
    ADDED_LATER,
    PLAUSIBLE,
    Plausible,
    SpecModel,
    _number,
    _unit,
    added_later,
    check_plausible,
)
from benchmark.camera.tables import TABLE_WAVELENGTH_RANGE_NM, check_wavelengths_nm, read_numeric_csv
from metricscenes.geometry import (
    REFERENCE_ACTIVE_HEIGHT_MM,
    REFERENCE_ACTIVE_WIDTH_MM,
    REFERENCE_FOCAL_LENGTH_MM,
    TanExtent,
)
from metricscenes.spectral import SENSOR_DATA_DIR, WAVELENGTHS_NM


IMX363_ISO_SPEED = 270.0
"""ISO speed of ISETCam's ``sensorIMX363`` (its default, used by the paper)."""
IMX363_ISO_UNITY_GAIN = 55.0
"""ISO at which the IMX363's analog gain is 1 (ISETCam: "for Pixel 4: ISO55")."""

PACKAGE_DATA_DIR = Path(__file__).parent / "data"
"""Where the packaged camera specs live (``registry.DATA_DIR``); packaged QE files are
metricscenes' (``metricscenes.spectral.SENSOR_DATA_DIR``: the store's spectral basis holds
the IMX363's channels)."""

MAX_CAPTURE_GIB = 4.0
"""A spec whose one capture needs more memory than this (estimate) is refused."""
CAPTURE_BYTES_PER_PIXEL = 256
"""Peak memory of one capture per pixel, bytes: the 31-band float32 radiance on the
pixel grid (124 B), the padded per-band FFTs and channel spectra, the float64 noise
chain, the raw and the ISP's float32 planes. Measured: 226 B/px (1920 × 1080) and
239 B/px (2688 × 1512) of peak RSS above the baseline for ``simulate``."""
MIN_SIZE_PX = 16
"""Fewest pixels per side (the demosaic and the exposure's central region need some)."""
SPEC_DIR_CONTEXT = "spec_dir"
"""Validation context key: the folder of the spec file (``qe`` user files resolve there)."""


def _check_relative_csv(value: str, columns: str, packaged: str = "") -> str:
    """A user table's path must be a relative POSIX path of a ``.csv`` inside its folder: no
    absolute path or drive, no ``..``, no backslash, NUL or line break."""
    bad = next((c for c in ("\\", "\0", "\n", "\r") if c in value), None)
    if bad is not None:
        raise ValueError(f"a relative path with '/' separators is expected, without {bad!r}")
    if PurePosixPath(value).is_absolute() or PureWindowsPath(value).drive or value.startswith("~"):
        raise ValueError(f"an absolute path is refused: name {packaged}a file beside the spec file")
    if ".." in PurePosixPath(value).parts:
        raise ValueError("'..' is refused: the file must lie in the spec file's folder or below it")
    if PurePosixPath(value).suffix.lower() != ".csv":
        raise ValueError(f"a .csv file is expected (columns {columns})")
    return value


def file_sha256(path: str | Path) -> str:
    """sha256 (hex) of a file's bytes; cached while the file's size and modification time stay."""
    stat = Path(path).stat()
    return _file_sha256(str(Path(path).resolve()), stat.st_size, stat.st_mtime_ns)


@functools.lru_cache(maxsize=32)
def _file_sha256(path: str, size: int, mtime_ns: int) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _check_qe_syntax(value: str) -> str:
    return _check_relative_csv(value, "wavelength_nm, qe_r, qe_g, qe_b", packaged="a packaged file (imx363_qe.csv) or ")


def plausibility_warnings(camera: "CameraSpec") -> list[str]:
    """One line per field whose value is possible but unusual (outside ``usual``)."""
    out = []
    for field, rule in PLAUSIBLE.items():
        section, name = field.split(".")
        value = getattr(getattr(camera, section), name)
        lo, hi = rule.usual
        if not lo <= value <= hi:
            out.append(f"{field} {_number(value)}{_unit(rule.unit)} is unusual (most sensors: {_number(lo)} to "
                       f"{_number(hi)}{_unit(rule.unit)}): check its unit")
    return out


QE_WAVELENGTH_RANGE_NM = TABLE_WAVELENGTH_RANGE_NM
"""Where a silicon sensor's QE table may lie, nm (wavelengths in µm are refused with that hint)."""


def check_qe_table(path: str | Path) -> tuple:
    """(wavelengths nm, QE (3, n), IR-cut (n) or None) of a QE CSV file if it is physically
    possible (:func:`read_qe_table`). Else a one-line ValueError naming the file, the row and
    the column."""
    wl, qe, ir_cut = read_qe_table(path)
    return wl, np.stack([qe[c] for c in "rgb"]), ir_cut


def read_qe_table(path: str | Path) -> tuple:
    """(wavelengths nm, {"r", "g", "b"[, "c"]: QE (n)}, IR-cut (n) or None) of a QE CSV file if
    it is physically possible: columns ``wavelength_nm, qe_r, qe_g, qe_b[, qe_c][,
    ir_cut_transmittance]`` (``qe_c``: a measured clear-pixel curve), two or more rows, every
    value a finite number, wavelengths strictly increasing within
    :data:`QE_WAVELENGTH_RANGE_NM`, QE and transmittance between 0 and 1 (a fraction of the
    photons). Else a one-line ValueError naming the file, the row and the column."""
    name = Path(path).name
    columns = ("wavelength_nm", "qe_r", "qe_g", "qe_b")
    table = read_numeric_csv(path, "QE table", columns, optional=("qe_c", "ir_cut_transmittance"),
                             expected="wavelength_nm, qe_r, qe_g, qe_b[, qe_c][, ir_cut_transmittance]")
    rows = table["wavelength_nm"].size
    if rows < 2:
        raise ValueError(f"QE table {name}: {rows} row(s); two or more wavelengths are needed")
    wl = table["wavelength_nm"]
    step = np.nonzero(np.diff(wl) <= 0)[0]
    if step.size:
        i = step[0]
        raise ValueError(f"QE table {name}: wavelength_nm must increase row by row: row {i + 2} ({wl[i + 1]:g}) "
                         f"follows row {i + 1} ({wl[i]:g})")
    check_wavelengths_nm(wl, "QE table", name)
    for column in list(table)[1:]:
        values = table[column]
        outside = np.nonzero((values < 0) | (values > 1))[0]
        if outside.size:
            i = outside[0]
            hint = "; if the table is in percent, divide it by 100" if 0 <= values.min() and values.max() <= 100 else ""
            raise ValueError(f"QE table {name}: row {i + 1} {column} is {values[i]:g}: a fraction of the photons, "
                             f"between 0 and 1{hint}")
    qe = {c: table[f"qe_{c}"] for c in "rgbc" if f"qe_{c}" in table}
    return wl, qe, table.get("ir_cut_transmittance")


def packaged_qe(name: str) -> Path | None:
    """The packaged QE file called ``name`` (a bare file name), or None."""
    if "/" in name:
        return None
    path = SENSOR_DATA_DIR / name
    return path if path.is_file() else None


PSF_TABLE_COLUMNS = ", ".join(_lens.PSF_COLUMNS)
MTF_TABLE_COLUMNS = ", ".join(_lens.MTF_COLUMNS)


class OpticsSpec(SpecModel):
    """The lens: focal length, f-number, transmittance, relative illumination, distortion,
    and what forms its image (:mod:`benchmark.camera.lens`): a diffraction-limited
    circular pupil (the default), the same pupil with Zernike aberrations, or a measured
    PSF or MTF table; optionally veiling glare."""

    focal_length_mm: float = Field(REFERENCE_FOCAL_LENGTH_MM, gt=0.5, le=100.0)
    f_number: float = Field(..., ge=0.5, le=64.0)
    transmittance: float = Field(1.0, gt=0.0, le=1.0)
    cos4_falloff: bool = False
    distortion_k1: float = added_later(0.0, ge=-1.0, le=1.0)
    """Brown–Conrady radial distortion, r² term (normalised image coordinates x/f;
    negative: barrel), :mod:`benchmark.camera.distortion`."""
    distortion_k2: float = added_later(0.0, ge=-1.0, le=1.0)
    """Brown–Conrady radial distortion, r⁴ term."""
    zernike_waves: tuple[tuple[int, float], ...] = added_later(())
    """Wavefront aberration: a mapping OSA/ANSI index j → coefficient in waves (RMS, unit-RMS
    polynomials) at ``zernike_wavelength_nm``, e.g. ``{4: 0.25}`` (defocus), 12 primary
    spherical, 3/5 astigmatism, 7/8 coma (:func:`benchmark.camera.lens.zernike`). Held as
    sorted (j, c) pairs without zeros: all-zero coefficients are the ideal lens, bit for bit."""
    zernike_wavelength_nm: float = added_later(550.0, ge=300.0, le=1100.0)
    """The wavelength at which ``zernike_waves`` are given (the wavefront, an optical path
    difference, is the same at every wavelength: fewer waves at longer ones)."""
    psf_table: str | None = added_later(None, min_length=1, max_length=255)
    """A measured PSF per wavelength: a CSV beside the spec file (relative path), columns
    ``wavelength_nm, x_um, y_um, psf`` (:func:`benchmark.camera.lens.read_psf_table`)."""
    mtf_table: str | None = added_later(None, min_length=1, max_length=255)
    """A measured MTF per wavelength: a CSV beside the spec file, columns
    ``wavelength_nm, frequency_cy_per_mm, mtf`` (:func:`benchmark.camera.lens.read_mtf_table`)."""
    veiling_glare_fraction: float = added_later(0.0, ge=0.0, le=0.5)
    """Fraction of the light that veiling glare spreads over the image (0: none); the veiling
    glare index of ISO 9358:1994 measures it (docs/camera.md, "The lens")."""
    glare_angle_deg: float = added_later(0.1, gt=0.0, le=10.0)
    """Scale angle θ₀ of the glare spread function (1 + (θ/θ₀)²)^(-3/2): 0.1°, the scale
    angle of the wide-angle terms of the CIE 146:2002 general disability glare equation."""

    psf_table_sha256: str | None = added_later(None, pattern=r"^[0-9a-f]{64}$")
    """sha256 of the ``psf_table`` file's content: filled when the spec is loaded from its file,
    so the camera's sha256 covers the table and not only its name; kept from a spec that comes
    from no file (results.json), and checked against the file wherever it is read."""
    mtf_table_sha256: str | None = added_later(None, pattern=r"^[0-9a-f]{64}$")
    """sha256 of the ``mtf_table`` file's content (as ``psf_table_sha256``)."""

    _table_path: str | None = PrivateAttr(None)
    """The resolved PSF or MTF table (a spec loaded from a file); None: unresolved."""

    @model_validator(mode="before")
    @classmethod
    def _table_content_is_recorded(cls, data, info: ValidationInfo):
        # Before the fields: the digest of a table beside the spec file becomes a field, so it is
        # serialised (hence hashed) with the name. A path the field check refuses is left to it.
        spec_dir = (info.context or {}).get(SPEC_DIR_CONTEXT)
        if not isinstance(data, dict) or spec_dir is None:
            return data
        out = dict(data)
        for name in ("psf_table", "mtf_table"):
            value = data.get(name)
            try:
                path = Path(spec_dir) / _check_relative_csv(value, "") if isinstance(value, str) else None
            except ValueError:
                continue
            if path is None or not path.is_file():
                continue
            digest, given = file_sha256(path), data.get(f"{name}_sha256")
            if given is not None and given != digest:
                raise ValueError(f"optics.{name}_sha256: the file {value!r} (sha256 {digest[:12]}...) is not the "
                                 f"table this spec recorded ({str(given)[:12]}...)")
            out[f"{name}_sha256"] = digest
        return out

    @field_validator("zernike_waves", mode="before")
    @classmethod
    def _zernike_mapping(cls, value):
        items = value.items() if isinstance(value, dict) else value
        try:
            pairs = [(key, coefficient) for key, coefficient in items]
        except (TypeError, ValueError):
            raise ValueError("a mapping of OSA/ANSI index j to waves is expected, e.g. {4: 0.25}") from None
        out = {}
        for key, coefficient in pairs:
            text = str(key).strip()
            if isinstance(key, bool) or not text.lstrip("+-").isdigit():
                raise ValueError(f"index {key!r} is not an OSA/ANSI Zernike index (an integer j; 4 defocus, "
                                 "3 and 5 astigmatism, 7 and 8 coma, 12 primary spherical)")
            j = int(text)
            if not 1 <= j <= _lens.MAX_ZERNIKE_INDEX:
                why = " (j = 0 is piston, which changes no image)" if j == 0 else ""
                raise ValueError(f"index {j} is outside the OSA/ANSI indices 1 to {_lens.MAX_ZERNIKE_INDEX} "
                                 f"(radial orders 1 to {_lens.MAX_ZERNIKE_ORDER}){why}; Noll indices start at 1 "
                                 "too but order the terms differently: convert them to OSA/ANSI")
            if isinstance(coefficient, bool) or not isinstance(coefficient, (int, float)) \
                    or not math.isfinite(coefficient):
                raise ValueError(f"index {j}: coefficient {coefficient!r} is not a finite number of waves")
            if abs(coefficient) > 5.0:
                raise ValueError(f"index {j}: {coefficient:g} waves is above the 5 waves modelled here (is it in "
                                 "micrometres or nanometres? coefficients are in waves at zernike_wavelength_nm); "
                                 "describe so blurred a lens by a PSF table")
            if j in out:
                raise ValueError(f"index {j} is given twice")
            out[j] = float(coefficient)
        return tuple(sorted((j, c) for j, c in out.items() if c != 0.0))

    @field_serializer("zernike_waves")
    def _zernike_as_mapping(self, value):
        return {j: c for j, c in value}

    @field_validator("psf_table", "mtf_table")
    @classmethod
    def _table_is_readable(cls, value: str | None, info: ValidationInfo):
        if value is None:
            return value
        columns = PSF_TABLE_COLUMNS if info.field_name == "psf_table" else MTF_TABLE_COLUMNS
        _check_relative_csv(value, columns)
        spec_dir = (info.context or {}).get(SPEC_DIR_CONTEXT)
        if spec_dir is not None:
            path = Path(spec_dir) / value
            if not path.is_file():
                raise ValueError(f"no file {path} (a CSV beside the spec file, columns {columns})")
            read = _lens.read_psf_table if info.field_name == "psf_table" else _lens.read_mtf_table
            read(str(path.resolve()))  # a table the lens can use, or refused before anything runs
        return value

    @model_validator(mode="after")
    def _one_description_of_the_lens(self, info: ValidationInfo) -> "OpticsSpec":
        given = [name for name in ("zernike_waves", "psf_table", "mtf_table") if getattr(self, name)]
        if len(given) > 1:
            raise ValueError(f"{' and '.join('optics.' + g for g in given)} each describe the whole lens: give one "
                             "(a measured table already holds the lens's aberrations)")
        if self.zernike_waves:
            slope = _lens.wavefront_slope(self.zernike_waves) * self.zernike_wavelength_nm / float(WAVELENGTHS_NM.min())
            limit = _lens.PUPIL_MAX_SAMPLES / _lens.PUPIL_SAMPLES_PER_SLOPE
            if slope > limit:
                raise ValueError(f"optics.zernike_waves: the wavefront's steepest slope, {slope:.3g} waves per pupil "
                                 f"radius at {WAVELENGTHS_NM.min():g} nm, is above the {limit:g} the pupil sampling "
                                 "holds: describe so blurred a lens by a PSF table")
        for name in ("psf_table", "mtf_table"):
            if getattr(self, f"{name}_sha256") is not None and getattr(self, name) is None:
                raise ValueError(f"optics.{name}_sha256 is the digest of optics.{name}, which is not given")
        table = self.psf_table or self.mtf_table
        spec_dir = (info.context or {}).get(SPEC_DIR_CONTEXT) if info is not None else None
        if table is not None and spec_dir is not None:
            self._table_path = str((Path(spec_dir) / table).resolve())
        return self

    @property
    def distortion(self) -> tuple[float, float] | None:
        """(k1, k2), or None for a distortion-free lens."""
        return None if self.distortion_k1 == 0.0 and self.distortion_k2 == 0.0 else (
            self.distortion_k1, self.distortion_k2)

    def _table(self, name: str) -> Path:
        value = getattr(self, name)
        if value is None:
            raise ValueError(f"optics.{name}: this lens has none")
        path = Path(self._table_path) if self._table_path is not None else Path(value)
        if not path.is_file():
            raise ValueError(f"optics.{name}: file {value!r} not found (a CSV beside the spec file)")
        recorded = getattr(self, f"{name}_sha256")
        if recorded is not None and file_sha256(path) != recorded:
            raise ValueError(f"optics.{name}: file {value!r} has changed since this spec recorded it "
                             f"(optics.{name}_sha256 {recorded[:12]}...)")
        return path

    @property
    def psf_table_path(self) -> Path:
        """The PSF table this lens reads: resolved beside the spec file it was loaded from,
        else ``psf_table`` from the working folder. ValueError if it does not exist."""
        return self._table("psf_table")

    @property
    def mtf_table_path(self) -> Path:
        """The MTF table this lens reads (as :attr:`psf_table_path`)."""
        return self._table("mtf_table")


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
        return _check_qe_syntax(value)

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


HDR_DEFAULT_RATIO = 16.0
"""The ``hdr`` policy's long / short exposure ratio where none is given (``--exposure hdr``)."""


class ExposureSpec(SpecModel):
    """Exposure policy (docs/camera.md, "Acquisition policies"). ``auto_peak``: the
    paper's (noise-free peak voltage in the central region at ``level`` of the swing);
    ``mean_level``: the mean voltage of the central region at ``level`` of the swing;
    ``percentile``: the ``percentile``-th percentile of the central region at ``level``
    of the swing; ``hdr``: a long and a short exposure ``hdr_ratio`` apart, merged
    before the ISP (:func:`benchmark.camera.acquisition.acquire_two_frames`); ``fixed``:
    ``exposure_s``. All but ``fixed`` are capped at ``max_exposure_s``."""

    mode: Literal["auto_peak", "fixed", "mean_level", "percentile", "hdr"] = "auto_peak"
    level: float = Field(0.90, gt=0.0, le=1.0)
    region_fraction: float = Field(0.5, gt=0.0, le=1.0)
    """Side of the central region as a fraction of the frame's width and height."""
    peak_percentile: float = Field(99.9, ge=90.0, le=100.0)
    """``auto_peak`` reads the region's peak as this percentile of its noise-free signal.
    100 is ISETCam's strict maximum; the default ignores the brightest 0.1 % (sun
    glints on paint and glass, lamp cores), which a strict maximum lets set the
    exposure of the whole frame (see docs/camera.md)."""
    max_exposure_s: float = Field(0.016, gt=0.0, le=60.0)
    exposure_s: float = Field(1.0 / 60.0, gt=0.0, le=60.0)
    percentile: float | None = added_later(None, gt=0.0, le=100.0)
    """``percentile`` mode (required there, refused elsewhere): the percentile of the
    central region's noise-free signal put at ``level`` × swing (100: the maximum)."""
    hdr_ratio: float | None = added_later(None, gt=1.0, le=1024.0)
    """``hdr`` mode (refused elsewhere): long / short exposure time, fixed, as in the
    two-frame HDR of automotive sensors; :data:`HDR_DEFAULT_RATIO` where the mode is
    ``hdr`` and none is given (so an ``hdr`` spec always records its ratio)."""

    @model_validator(mode="before")
    @classmethod
    def _hdr_has_a_ratio(cls, data):
        if isinstance(data, dict) and data.get("mode") == "hdr" and data.get("hdr_ratio") is None:
            data = {**data, "hdr_ratio": HDR_DEFAULT_RATIO}
        return data

    @field_validator("max_exposure_s", "exposure_s", mode="before")
    @classmethod
    def _plausible(cls, value, info: ValidationInfo):
        return check_plausible(f"exposure.{info.field_name}", value)

    @model_validator(mode="after")
    def _parameters_belong_to_their_mode(self) -> "ExposureSpec":
        if self.mode == "percentile" and self.percentile is None:
            raise ValueError("mode 'percentile' needs 'percentile' (0 < percentile <= 100)")
        if self.mode != "percentile" and self.percentile is not None:
            raise ValueError(f"'percentile' applies to mode 'percentile' only, not {self.mode!r}")
        if self.mode != "hdr" and "hdr_ratio" in self.model_fields_set:
            raise ValueError(f"'hdr_ratio' applies to mode 'hdr' only, not {self.mode!r}")
        return self


class ISPSpec(SpecModel):
    """Image processing: demosaic, white balance, colour transform, output encoding.

    :func:`isp_preset` names complete settings: ``default`` (this model's defaults) and
    ``iset-parity`` (ISETCam's default image processor, docs/camera.md)."""

    demosaic: Literal["malvar2004", "bilinear"] = "malvar2004"
    white_balance: Literal["grey_world", "known_illuminant", "none"] = "grey_world"
    """``none``: no gains, as ISETCam's default illuminant correction ('None')."""
    illuminant: str = "D65"
    """Illuminant for ``known_illuminant`` white balance (a colour-science name)."""

    @field_validator("illuminant")
    @classmethod
    def _known_illuminant(cls, value: str) -> str:
        if value == "D65":  # the default: no need to import colour-science
            return value
        import colour

        try:
            colour.SDS_ILLUMINANTS[value]
        except (KeyError, TypeError, ValueError):
            raise ValueError(f"unknown illuminant {value!r} (colour-science names, e.g. D65, A, D50, F2)") from None
        return value
    output: Literal["srgb8", "linear"] = "srgb8"
    color_transform: Literal["checker_srgb", "iset_mcc"] = added_later("checker_srgb")
    """``checker_srgb``: the ColorChecker-fitted matrix from white-balanced camera RGB to
    linear sRGB (rows sum to 1; 1.0 = the ADC white). ``iset_mcc``: ISETCam's 'MCC
    optimized' sensor conversion to XYZ, then display rendering scaled to the image's
    maximum (:func:`benchmark.camera.isp.iset_render`)."""


class CameraSpec(SpecModel):
    """One camera of the benchmark."""

    name: str = Field(..., pattern=r"^[A-Za-z0-9_.-]+$", max_length=64)
    label: str = Field("", max_length=200)
    """Free text for people (`cameras show` and `list` print it): one line of printable characters."""
    mtf50_group_cy_per_mm: float | None = Field(None, gt=0.0, le=2000.0)
    """The MTF50 group the paper published for this camera (None for user cameras)."""
    optics: OpticsSpec
    sensor: SensorSpec
    exposure: ExposureSpec = ExposureSpec()
    isp: ISPSpec = ISPSpec()

    @property
    def width_px(self) -> int:
        return self.sensor.width_px

    @property
    def height_px(self) -> int:
        return self.sensor.height_px

    @property
    def pixel_um(self) -> float:
        return self.sensor.pixel_um

    @property
    def f_number(self) -> float:
        return self.optics.f_number

    @field_validator("label")
    @classmethod
    def _label_is_printable(cls, value: str) -> str:
        # an ANSI escape, a line break or an invisible character would reach the terminal as it is
        bad = next((ch for ch in value if not ch.isprintable()), None)
        if bad is not None:
            raise ValueError(f"holds the character U+{ord(bad):04X}, which prints as nothing or drives the terminal "
                             "(the label is one line of printable characters)")
        return value

    @model_validator(mode="after")
    def _one_acquisition(self) -> "CameraSpec":
        if self.sensor.dcg is not None and self.exposure.mode == "hdr":
            raise ValueError("exposure.mode 'hdr' (two frames) with sensor.dcg (an HDR pixel read in one exposure): "
                             "give one of them")
        return self

    @model_validator(mode="after")
    def _lens_does_not_fold(self) -> "CameraSpec":
        if self.optics.distortion is not None:
            check_monotonic(*self.optics.distortion, math.hypot(self.tan_half_width, self.tan_half_height))
        return self

    @model_validator(mode="after")
    def _lens_table_covers_the_pixel_grid(self) -> "CameraSpec":
        # A measured lens is read on this sensor's frequency grid: the PSF must be sampled
        # at least as finely as the pixels (else its Fourier sum aliases below Nyquist), and
        # the MTF must reach the grid's highest frequency, √2 × Nyquist, or fall to nothing first.
        optics, pixel_um = self.optics, self.sensor.pixel_um
        if optics._table_path is None:  # a spec from no file: its table is checked when first read
            return self
        if optics.psf_table is not None:
            spacing = _lens.read_psf_table(optics._table_path).spacing_um
            if spacing > pixel_um:
                raise ValueError(f"optics.psf_table {optics.psf_table!r} is sampled every {spacing:g} um, coarser than "
                                 f"the {pixel_um:g} um pixels: sample the PSF at least as finely as the pixel pitch")
        if optics.mtf_table is not None:
            table = _lens.read_mtf_table(optics._table_path)
            reach = math.sqrt(2.0) * self.nyquist_cy_per_mm
            for wl, freq, mtf in zip(table.wavelengths_nm, table.frequency_cy_per_mm, table.mtf):
                if freq[-1] < reach and mtf[-1] > 0.01:
                    raise ValueError(f"optics.mtf_table {optics.mtf_table!r}: wavelength {wl:g} nm ends at "
                                     f"{freq[-1]:g} cy/mm with mtf {mtf[-1]:g}; the {pixel_um:g} um pixel grid reaches "
                                     f"{reach:.1f} cy/mm (sqrt(2) x Nyquist): extend the table, or end it where the "
                                     "MTF has fallen to 0.01")
        return self

    @property
    def tan_half_width(self) -> float:
        """tan of half the horizontal field: half the pixel array's width over the focal
        length (the sensor's half-width in distorted coordinates, :mod:`benchmark.camera.distortion`)."""
        return self.sensor.array_width_mm / 2.0 / self.optics.focal_length_mm

    @property
    def tan_half_height(self) -> float:
        return self.sensor.array_height_mm / 2.0 / self.optics.focal_length_mm

    @property
    def hfov_deg(self) -> float:
        """Horizontal field of view, degrees: 2·atan(width_px · pixel / 2f) (with distortion:
        of the undistorted directions the sensor's border sees)."""
        return math.degrees(2.0 * math.atan(self.seen_tan_half_extent[0]))

    @property
    def vfov_deg(self) -> float:
        """Vertical field of view, degrees: 2·atan(height_px · pixel / 2f) (idem)."""
        return math.degrees(2.0 * math.atan(self.seen_tan_half_extent[1]))

    @property
    def seen_tan_half_extent(self) -> tuple[float, float]:
        """Half-width and half-height (tangent units) of the scene window the camera sees:
        the pixel array's over the focal length, enlarged by barrel (shrunk by
        pincushion) distortion to the undistorted image of the sensor's border."""
        if self.optics.distortion is None:
            return self.tan_half_width, self.tan_half_height
        hw, hh = self.tan_half_width, self.tan_half_height
        seen = undistorted_bounds(TanExtent(-hw, -hh, hw, hh), *self.optics.distortion)
        return seen.x1, seen.y1

    @property
    def ifov_mrad(self) -> float:
        """Instantaneous field of view of one pixel on the axis, mrad: pixel / f."""
        return self.pixel_um / self.optics.focal_length_mm

    @property
    def nyquist_cy_per_mm(self) -> float:
        """Sampling Nyquist frequency on the sensor, cycles/mm: 1 / (2 · pixel)."""
        return 500.0 / self.pixel_um

    def cy_per_mrad(self, cy_per_mm: float | None) -> float | None:
        """A sensor-plane frequency of this camera as an angular one, cycles/mrad in object
        space (:func:`cy_per_mrad` with its focal length)."""
        return cy_per_mrad(cy_per_mm, self.optics.focal_length_mm)

    def canonical_json(self) -> str:
        """The resolved spec (defaults filled in) as sorted, compact JSON."""
        return json.dumps(self.model_dump(mode="json"), sort_keys=True, separators=(",", ":"))

    def sha256(self) -> str:
        """sha256 (hex) of :meth:`canonical_json`: identifies the camera in results."""
        return hashlib.sha256(self.canonical_json().encode("utf-8")).hexdigest()


def cy_per_mrad(cy_per_mm: float | None, focal_length_mm: float | None) -> float | None:
    """A frequency on the sensor (cycles/mm) as an angular frequency in object space
    (cycles/mrad): × focal length / 1000, since one mrad of the scene spans f µm of the
    sensor on the axis. The resolution that compares cameras of different focal lengths:
    an 8 mm lens with 168.6 cy/mm resolves 1.35 cy/mrad, finer than cam12's 229.3 cy/mm
    behind 4.38 mm (1.00 cy/mrad). None (or NaN) in, None out."""
    if cy_per_mm is None or focal_length_mm is None or not math.isfinite(cy_per_mm * focal_length_mm):
        return None
    return float(cy_per_mm) * float(focal_length_mm) / 1000.0


ISP_PRESETS = ("default", "iset-parity")
"""Names accepted by :func:`isp_preset` (and ``benchmark cameras mtf --isp``)."""


def isp_preset(name: str) -> ISPSpec:
    """A named ISP setting.

    ``default``: this project's ISP (:class:`ISPSpec` defaults: white balance on the
    mosaic, Malvar-He-Cutler demosaic, ColorChecker matrix to linear sRGB, sRGB 8 bit).

    ``iset-parity``: ISETCam's default image processor, ``ip = ipCreate`` (ISET/isetcam
    ``imgproc/ipCreate.m``: 'transform method' adaptive, 'demosaic method' Bilinear,
    'illuminant correction method' None, 'internal CS' XYZ, 'conversion method sensor'
    MCC optimized) as ``ipCompute`` runs it (``imgproc/ipCompute.m``): zero level
    subtracted, bilinear demosaic (``imgproc/demosaic/ieBilinear.m``) into 'sensor
    space', the least-squares MCC-under-D65 transform to XYZ
    (``imgproc/imageSensorTransform.m``), no white balance, XYZ to linear display RGB
    scaled to the image's maximum (``displays/displayRender.m``). ISETCam's MTF
    (``metrics/ISO/ieISO12233.m``) reads the demosaicked 'sensor space', before the
    colour transform: see :func:`benchmark.measure.mtf.measure_mtf50` and docs/camera.md.
    """
    if name == "default":
        return ISPSpec()
    if name == "iset-parity":
        return ISPSpec(demosaic="bilinear", white_balance="none", color_transform="iset_mcc")
    raise ValueError(f"unknown ISP preset {name!r} (allowed: {', '.join(ISP_PRESETS)})")
