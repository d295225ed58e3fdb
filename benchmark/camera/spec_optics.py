"""The lens's spec (:class:`OpticsSpec`): focal length, f-number, transmittance, relative
illumination, distortion, and what forms its image (:mod:`benchmark.camera.lens`): the
diffraction-limited pupil, Zernike aberrations, or a measured PSF or MTF table beside the spec
file, whose content is recorded beside its name (``psf_table_sha256``, ``mtf_table_sha256``)
so the camera's sha256 covers it; optionally veiling glare.

A table is refused before anything runs unless :mod:`benchmark.camera.lens` can read it; that
it samples the sensor's pixel grid finely enough is the whole camera's check
(:class:`benchmark.camera.spec.CameraSpec`).
"""

from __future__ import annotations

import math
from pathlib import Path

from pydantic import Field, PrivateAttr, ValidationInfo, field_serializer, field_validator, model_validator

from benchmark.camera import lens as _lens
from benchmark.camera.spec_files import SPEC_DIR_CONTEXT, check_relative_csv, file_sha256
from benchmark.camera.spec_rules import SpecModel, added_later
from metricscenes.geometry import REFERENCE_FOCAL_LENGTH_MM
from metricscenes.spectral import WAVELENGTHS_NM


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
                path = Path(spec_dir) / check_relative_csv(value, "") if isinstance(value, str) else None
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
        check_relative_csv(value, columns)
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
