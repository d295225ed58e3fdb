"""Two-exposure HDR: a long and a short raw of the same scene merged into one linear raw.

The automotive "two-frame" HDR (fixed exposure ratio r = t_long / t_short, e.g. 16): each
pixel of the Bayer mosaic keeps its long-exposure value where that is below saturation,
and takes the short-exposure value × r elsewhere — the two-exposure case of the
radiance-map merge of Mann & Picard (1995, "On being 'undigital' with digital cameras",
IS&T) and Debevec & Malik (1997, "Recovering high dynamic range radiance maps from
photographs", SIGGRAPH), with the response known to be linear and a hard switch as
the weighting. The merged mosaic stays on the long exposure's scale and in DN (black
level included, float32, up to r × the white level), so it goes through the ISP's
colour path like a single raw; :func:`benchmark.camera.isp.tone_curve_reinhard` brings it to
the 8-bit range (docs/camera.md, "Acquisition policies").
"""

from __future__ import annotations

import numpy as np

from benchmark.camera.spec import SensorSpec
from benchmark.camera.sensor import saturation_electrons, signal_volts_per_electron

SWITCH_FRACTION = 0.95
"""The long exposure is used below this fraction of the raw's saturation: a margin so
that the shot and read noise of a pixel sitting at the clip never pick a clipped value."""


def saturation_dn(sensor: SensorSpec) -> float:
    """Signal DN above the black level at which a raw saturates (the ADC or the well)."""
    return saturation_electrons(sensor) * signal_volts_per_electron(sensor) / sensor.lsb_v


def merge_two_exposures_dn(raw_long_dn: np.ndarray, raw_short_dn: np.ndarray, ratio: float,
                           sensor: SensorSpec, *, switch_fraction: float = SWITCH_FRACTION) -> np.ndarray:
    """Merged raw (rows, cols) float32 DN on the long exposure's scale, black level included.

    Rule, per pixel: s_long = raw_long − black; if s_long < ``switch_fraction`` ×
    saturation, merged = raw_long, else merged = black + ``ratio`` × (raw_short − black).

    Args:
        raw_long_dn, raw_short_dn: uint16 Bayer mosaics of the same scene, DN.
        ratio: t_long / t_short.
    """
    black = np.float32(sensor.black_level_dn)
    signal_long = raw_long_dn.astype(np.float32) - black
    signal_short = (raw_short_dn.astype(np.float32) - black) * np.float32(ratio)
    use_short = signal_long >= np.float32(switch_fraction * saturation_dn(sensor))
    return np.where(use_short, signal_short, signal_long) + black
