"""The camera specification: :class:`CameraSpec`, a lens (:class:`OpticsSpec`,
:mod:`benchmark.camera.spec_optics`), a sensor (:class:`SensorSpec`,
:mod:`benchmark.camera.spec_sensor`), an exposure policy (:class:`ExposureSpec`,
:mod:`benchmark.camera.spec_exposure`) and the ISP's options (:class:`ISPSpec`,
:mod:`benchmark.camera.spec_isp`); the files a spec names are checked in
:mod:`benchmark.camera.spec_files`, and every part follows the rules of
:mod:`benchmark.camera.spec_rules`. Loading a spec from its file or the registry is
:mod:`benchmark.camera.registry`'s.

A :class:`CameraSpec` is a frozen pydantic model; every field has a unit in its name
and a validated range. The defaults describe the paper's camera (Liu et al., EI 2023):
4.38 mm diffraction-limited lens over a 2.688 x 1.512 mm Sony IMX363-like sensor, with
the figures of ISETCam's ``sensorIMX363`` (see ``docs/camera.md``). Only the pixel
pitch and the f-number differ between the 13 registry cameras.

Geometry: the field of view is the pixel array's, ``2·atan(width_px · pixel_um / 2f)`` ×
``2·atan(height_px · pixel_um / 2f)``, so pixels are square in angle by construction
(docs/camera.md, "Field of view and geometry").

A spec is validated as a whole (docs/camera.md, "Refused specs"): each part checks its own
fields, and the camera what needs two of them: one acquisition (two-frame ``hdr`` or the
sensor's ``dcg``, not both), a distortion that does not fold the sensor's field, and lens
tables that sample this sensor's pixel grid finely enough. Values no sensor has are refused
with the unit mistake they most likely are, and unusual but possible ones are warned about
(:data:`benchmark.camera.spec_rules.PLAUSIBLE`, docs/camera.md, "Plausible values").

Specs that can grow: a field added after the registry and its leaderboard is declared with
:func:`~benchmark.camera.spec_rules.added_later`, and one rule
(:class:`~benchmark.camera.spec_rules.SpecModel`) leaves it out of the serialisation —
hence out of :meth:`CameraSpec.sha256` — wherever it is at its default, so every earlier
spec keeps its bytes (docs/camera.md, "Adding a camera feature").
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

from pydantic import Field, field_validator, model_validator

from benchmark.camera import lens as _lens
from benchmark.camera.distortion import check_monotonic, undistorted_bounds
from benchmark.camera.spec_exposure import ExposureSpec
from benchmark.camera.spec_isp import ISPSpec
from benchmark.camera.spec_optics import OpticsSpec
from benchmark.camera.spec_rules import SpecModel
from benchmark.camera.spec_sensor import SensorSpec
from metricscenes.geometry import TanExtent


PACKAGE_DATA_DIR = Path(__file__).parent / "data"
"""Where the packaged camera specs live (``registry.DATA_DIR``); packaged QE files are
metricscenes' (``metricscenes.spectral.SENSOR_DATA_DIR``: the store's spectral basis holds
the IMX363's channels)."""


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
