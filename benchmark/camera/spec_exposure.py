"""The exposure policy's spec (:class:`ExposureSpec`): how the exposure time is chosen
(docs/camera.md, "Acquisition policies"); the computation is :mod:`benchmark.camera.exposure`'s.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, ValidationInfo, field_validator, model_validator

from benchmark.camera.spec_rules import SpecModel, added_later, check_plausible


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
