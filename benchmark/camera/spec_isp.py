"""The image processor's spec (:class:`ISPSpec`: demosaic, white balance, colour transform,
output encoding) and its named settings (:func:`isp_preset`); the processing is
:mod:`benchmark.camera.isp`'s.
"""

from __future__ import annotations

from typing import Literal

from pydantic import field_validator

from benchmark.camera.spec_rules import SpecModel, added_later


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
