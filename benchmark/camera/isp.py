"""Image signal processing: an acquisition's linear mosaic (DN) to an sRGB image.

Order (as dcraw and most camera ISPs): black-level subtraction and normalisation →
white-balance gains on the mosaic → demosaic (Malvar, He & Cutler 2004, ICASSP, by
default, in float32 by :mod:`benchmark.camera.demosaic`; bilinear option, colour-demosaicing)
→ colour matrix to linear sRGB (3×3 for RGGB and RCCB, 3×2 for RCCC) → for an HDR
capture, the tone curve → sRGB transfer curve (IEC 61966-2-1) → 8 bit (:func:`render`).

The ISP knows its sensor through a :class:`benchmark.camera.calibration.Calibration` (colour
matrices, white-balance gains), fitted once from the sensor's spectra and handed in:
it never reads spectra itself.
"""

from __future__ import annotations

import functools
from importlib import resources
from typing import TYPE_CHECKING

import colour
import colour_demosaicing
import numpy as np

from benchmark.camera.calibration import Calibration
from benchmark.camera.spec_isp import ISPSpec
from benchmark.camera.spec_sensor import SensorSpec
from benchmark.camera.demosaic import malvar2004
from benchmark.camera.sensor import bayer_sites, cfa_channels

if TYPE_CHECKING:
    from benchmark.camera.acquisition import RawCapture


def raw_to_linear(raw_dn: np.ndarray, sensor: SensorSpec) -> np.ndarray:
    """Black-level-subtracted mosaic scaled so the ADC white level is 1 (float32)."""
    span = float(sensor.white_level_dn - sensor.black_level_dn)
    return (raw_dn.astype(np.float32) - np.float32(sensor.black_level_dn)) / np.float32(span)


def grey_world_gains(mosaic: np.ndarray, cfa: str = "RGGB") -> np.ndarray:
    """Gains (channels,) making the channel means of the mosaic equal (G, or C, gain 1)."""
    n = len(cfa_channels(cfa))
    sums, counts = np.zeros(n), np.zeros(n)
    for dy, dx, channel in bayer_sites(cfa):
        site = mosaic[dy::2, dx::2]
        sums[channel] += site.sum(dtype=np.float64)
        counts[channel] += site.size
    means = sums / np.maximum(counts, 1)
    if np.any(means <= 0):
        return np.ones(n)
    return means[1] / means


def apply_gains(mosaic: np.ndarray, gains: np.ndarray, cfa: str = "RGGB") -> np.ndarray:
    out = mosaic.copy()
    for dy, dx, channel in bayer_sites(cfa):
        out[dy::2, dx::2] *= np.float32(gains[channel])
    return out


CLEAR_CFAS = ("RCCB", "RCCC")
"""Tiles with clear (unfiltered) pixels in green's place."""


def demosaic(mosaic: np.ndarray, method: str = "malvar2004", cfa: str = "RGGB") -> np.ndarray:
    """(rows, cols) mosaic → (rows, cols, channels) float32 camera channels (:func:`cfa_channels`;
    ``malvar2004``: the float32 implementation in :mod:`benchmark.camera.demosaic`;
    ``bilinear``: colour-demosaicing).

    Clear-pixel tiles are demosaicked as the Bayer tile they replace, clear in green's place:
    RCCB's R, C, B sit where RGGB's R, G, B do, so the Bayer kernels give R, C, B (the clear
    channel, like green, is sampled twice per tile and correlates with the others). RCCC
    gives R and C: the same kernels on the tile read as RGGB interpolate R everywhere and C
    at the R pixels; the pixels in blue's place are clear and keep their own value."""
    bayer = "RGGB" if cfa in CLEAR_CFAS else cfa
    if method == "malvar2004":
        out = malvar2004(mosaic, bayer)
    elif method == "bilinear":
        out = np.asarray(colour_demosaicing.demosaicing_CFA_Bayer_bilinear(mosaic, bayer), dtype=np.float32)
    else:
        raise ValueError(f"isp.demosaic: unknown method {method!r} (allowed: malvar2004, bilinear)")
    if cfa == "RCCC":
        out = np.ascontiguousarray(out[..., :2])
        out[1::2, 1::2, 1] = np.asarray(mosaic, dtype=np.float32)[1::2, 1::2]
    return out


_BUCKET_SHIFT = 12  # float32 bit patterns >> 12: never two decision levels in one bucket (checked below)


@functools.lru_cache(maxsize=1)
def srgb8_thresholds() -> np.ndarray:
    """(255,) float32: the smallest linear value that encodes to each 8-bit code 1..255
    (package data ``data/srgb8_thresholds.csv``)."""
    text = resources.files("benchmark.camera").joinpath("data/srgb8_thresholds.csv").read_text()
    rows = [line.split(",") for line in text.splitlines() if line and line[0].isdigit()]
    return np.array([float.fromhex(value) for _, value in rows], dtype=np.float32)


@functools.lru_cache(maxsize=1)
def _srgb8_buckets() -> tuple[np.ndarray, np.ndarray]:
    """Per bucket of float32 bit patterns in [0, 1]: the code at its start and the next
    decision level (a table lookup and one comparison instead of a binary search)."""
    levels = srgb8_thresholds()
    top = int(np.float32(1.0).view(np.uint32)) >> _BUCKET_SHIFT
    starts = (np.arange(top + 1, dtype=np.uint32) << _BUCKET_SHIFT).view(np.float32)
    base = np.searchsorted(levels, starts, side="right")
    bucket_of_level = levels.view(np.uint32) >> _BUCKET_SHIFT
    if np.any(np.diff(bucket_of_level) == 0):
        raise AssertionError("two sRGB decision levels share a bucket: lower _BUCKET_SHIFT")
    following = np.append(levels, np.float32(np.inf))[base]
    return base.astype(np.uint8), following


def encode_srgb8(rgb_linear: np.ndarray) -> np.ndarray:
    """Linear sRGB (clipped to [0, 1]) → 8-bit sRGB (IEC 61966-2-1 transfer curve).

    The curve is applied as a search among its 255 decision levels, not through
    ``np.power``: numpy's SIMD ``power`` differs in the last bit between instruction sets
    (AVX-512 machines take other kernels), which moved a code by one here and there. The
    levels are those of the float32 formula, so the codes equal it wherever it agrees with
    itself (docs/performance.md, "Bytes across machines").
    """
    # fmax/fmin: NaN → 0 (black); adding +0.0 turns -0.0 into +0.0 (bit patterns index the table)
    x = np.fmin(np.fmax(np.asarray(rgb_linear, dtype=np.float32), np.float32(0.0)), np.float32(1.0)) + np.float32(0.0)
    base, following = _srgb8_buckets()
    bucket = x.view(np.uint32) >> _BUCKET_SHIFT
    return base[bucket] + (x >= following[bucket])


def render(raw: "RawCapture", sensor: SensorSpec, isp: ISPSpec,
           calibration: Calibration) -> tuple[np.ndarray, np.ndarray]:
    """An acquisition's linear signal (:class:`benchmark.camera.acquisition.RawCapture`) → (linear
    sRGB (rows, cols, 3) float32, 8-bit sRGB). An HDR capture is scaled so that 1 is its
    reference exposure's white and tone-mapped (:func:`tone_curve_reinhard` with its merged
    white) before the encoding; its linear sRGB is the scaled image before the tone curve."""
    rgb_linear = process(raw.linear_dn, sensor, isp, calibration)
    if raw.reference_scale is None:
        return rgb_linear, encode_srgb8(rgb_linear)
    rgb_linear = rgb_linear * np.float32(raw.reference_scale)
    return rgb_linear, encode_srgb8(tone_curve_reinhard(rgb_linear, white=raw.white))


def process(raw_dn: np.ndarray, sensor: SensorSpec, isp: ISPSpec, calibration: Calibration) -> np.ndarray:
    """Raw mosaic DN (rows, cols) → linear sRGB (rows, cols, 3) float32 (not clipped)."""
    rgb = white_balanced_rgb(raw_dn, sensor, isp, calibration)
    if isp.color_transform == "iset_mcc":
        return iset_render(rgb, calibration.iset_mcc_matrix)
    m = calibration.color_matrix.astype(np.float32)
    return np.matmul(rgb, m.T)


def white_balanced_rgb(raw_dn: np.ndarray, sensor: SensorSpec, isp: ISPSpec, calibration: Calibration) -> np.ndarray:
    """Raw DN → black-subtracted, white-balanced, demosaicked camera channels (float32,
    (rows, cols, channels): R, G, B, or R, C, B and R, C for clear-pixel tiles)."""
    lin = raw_to_linear(raw_dn, sensor)
    if isp.white_balance == "grey_world":
        gains = grey_world_gains(lin, sensor.cfa)
    elif isp.white_balance == "none":
        gains = np.ones(len(cfa_channels(sensor.cfa)))
    else:
        gains = calibration.illuminant_gains
    return demosaic(apply_gains(lin, gains, sensor.cfa), isp.demosaic, sensor.cfa)


def tone_curve_reinhard(rgb_linear: np.ndarray, white: float) -> np.ndarray:
    """Global tone curve of the ``hdr`` exposure policy, applied before :func:`encode_srgb8`.

    Reinhard, Stark, Shirley & Ferwerda (2002), "Photographic tone reproduction for
    digital images", SIGGRAPH, eq. 4 (the global operator with a white point), on each
    linear channel: T(x) = x (1 + x / w²) / (1 + x), so T(0) = 0, T(w) = 1, and for w = 1
    T is the identity. The input is scaled so that 1 is the white of the reference
    (``auto_peak``) exposure — the auto exposure plays the role of Reinhard's key — and
    w is the merged white in those units (t_ref / t_short ≥ 1): a merge that holds no
    more than the reference's range is left as it is, a wider one is compressed into it.
    """
    x = np.maximum(np.asarray(rgb_linear, dtype=np.float32), np.float32(0.0))
    w2 = np.float32(float(white) ** 2)
    return x * (1.0 + x / w2) / (1.0 + x)


# --- ISETCam's default image processor (isp_preset("iset-parity")) -------------------


def iset_render(rgb_sensor: np.ndarray, mcc_matrix: np.ndarray) -> np.ndarray:
    """ISETCam's default rendering of demosaicked sensor RGB (its 'sensor space') to
    linear display RGB in [0, 1] (float32), as ``ipCompute`` with the default ``ip``:

    1. XYZ = sensor RGB × ``mcc_matrix`` (:func:`benchmark.camera.calibration.iset_mcc_matrix`), clipped at 0
       (``imgproc/imageSensorCorrection.m``);
    2. illuminant correction 'None': nothing (``imgproc/imageIlluminantCorrection.m``);
    3. XYZ to linear display RGB, clipped at 0, divided by the image's maximum
       (``displays/displayRender.m``, the quantised-sensor branch: "img/max(img(:))").

    ISETCam's default display is ``lcdExample.mat``; we use the sRGB primaries, which it
    approximates. The image-dependent scale is ISETCam's: the brightest pixel becomes 1.
    """
    rgb = np.asarray(rgb_sensor, dtype=np.float32)
    xyz = np.maximum(np.matmul(rgb, np.asarray(mcc_matrix).astype(np.float32).T), np.float32(0.0))
    to_rgb = np.asarray(colour.RGB_COLOURSPACES["sRGB"].matrix_XYZ_to_RGB, dtype=np.float32)
    lin = np.maximum(np.matmul(xyz, to_rgb.T), np.float32(0.0))
    peak = float(lin.max()) if lin.size else 0.0
    return lin / np.float32(peak) if peak > 0 else lin
