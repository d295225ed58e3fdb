"""Image signal processing: raw Bayer DN to an sRGB image.

Order (as dcraw and most camera ISPs): black-level subtraction and normalisation →
white-balance gains on the mosaic → demosaic (Malvar, He & Cutler 2004, ICASSP, by
default, in float32 by :mod:`benchmark.demosaic`; bilinear option, colour-demosaicing)
→ 3×3 colour matrix to linear sRGB → sRGB transfer curve (IEC 61966-2-1) → 8 bit.

The colour matrix is fitted for each sensor by least squares on the 24 spectral
reflectances of the ColorChecker (colour-science's ``ColorChecker N Ohta``) under
CIE D65, against their CIE 1931 2° colorimetry converted to linear sRGB, with each
row summing to 1 so that a white-balanced neutral stays neutral.
"""

from __future__ import annotations

import functools

import colour
import colour_demosaicing
import numpy as np

from benchmark.cameras.spec import ISPSpec, SensorSpec
from benchmark.demosaic import malvar2004
from benchmark.sensor import bayer_sites, channel_responsivity
from metricscenes.photometry import cie_1931_cmfs
from metricscenes.spectral import WAVELENGTHS_NM, resample_spectrum

_CHECKER = "ColorChecker N Ohta"


def raw_to_linear(raw_dn: np.ndarray, sensor: SensorSpec) -> np.ndarray:
    """Black-level-subtracted mosaic scaled so the ADC white level is 1 (float32)."""
    span = float(sensor.white_level_dn - sensor.black_level_dn)
    return (raw_dn.astype(np.float32) - np.float32(sensor.black_level_dn)) / np.float32(span)


def grey_world_gains(mosaic: np.ndarray, cfa: str = "RGGB") -> np.ndarray:
    """Gains (3,) making the R, G, B means of the mosaic equal (G gain 1)."""
    sums, counts = np.zeros(3), np.zeros(3)
    for dy, dx, channel in bayer_sites(cfa):
        site = mosaic[dy::2, dx::2]
        sums[channel] += site.sum(dtype=np.float64)
        counts[channel] += site.size
    means = sums / np.maximum(counts, 1)
    if np.any(means <= 0):
        return np.ones(3)
    return means[1] / means


def illuminant_spectrum(name: str, wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """Relative spectral power of a CIE illuminant (colour-science name) at the bands."""
    try:
        sd = colour.SDS_ILLUMINANTS[name]
    except KeyError:
        raise ValueError(f"isp.illuminant: unknown illuminant {name!r} (e.g. D65, A, D50, F2)") from None
    return resample_spectrum(sd.wavelengths, sd.values, wavelengths_nm, hold_ends=True)


def illuminant_gains(sensor: SensorSpec, illuminant: str = "D65") -> np.ndarray:
    """Gains (3,) that make a perfect white under ``illuminant`` neutral (G gain 1)."""
    response = channel_responsivity(sensor) @ illuminant_spectrum(illuminant)
    return response[1] / response


def apply_gains(mosaic: np.ndarray, gains: np.ndarray, cfa: str = "RGGB") -> np.ndarray:
    out = mosaic.copy()
    for dy, dx, channel in bayer_sites(cfa):
        out[dy::2, dx::2] *= np.float32(gains[channel])
    return out


def demosaic(mosaic: np.ndarray, method: str = "malvar2004", cfa: str = "RGGB") -> np.ndarray:
    """(rows, cols) mosaic → (rows, cols, 3) float32 RGB (``malvar2004``: the float32
    implementation in :mod:`benchmark.demosaic`; ``bilinear``: colour-demosaicing)."""
    if method == "malvar2004":
        return malvar2004(mosaic, cfa)
    elif method == "bilinear":
        rgb = colour_demosaicing.demosaicing_CFA_Bayer_bilinear(mosaic, cfa)
    else:
        raise ValueError(f"isp.demosaic: unknown method {method!r} (allowed: malvar2004, bilinear)")
    return np.asarray(rgb, dtype=np.float32)


def checker_reflectances(wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> tuple[list[str], np.ndarray]:
    """Names and spectral reflectances (24, bands) of the ColorChecker patches."""
    sds = colour.SDS_COLOURCHECKERS[_CHECKER]
    names = list(sds)
    refl = np.stack([resample_spectrum(sds[n].wavelengths, sds[n].values, wavelengths_nm, hold_ends=True) for n in names])
    return names, refl


def checker_targets_linear_srgb(wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """Linear sRGB (24, 3) of the ColorChecker under D65, perfect white Y = 1."""
    _, refl = checker_reflectances(wavelengths_nm)
    xyz_bar = cie_1931_cmfs(wavelengths_nm)
    d65 = illuminant_spectrum("D65", wavelengths_nm)
    xyz = (refl * d65) @ xyz_bar / (d65 @ xyz_bar[:, 1])
    return colour.XYZ_to_RGB(xyz, colour.RGB_COLOURSPACES["sRGB"], apply_cctf_encoding=False)


def checker_camera_rgb(sensor: SensorSpec, wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """White-balanced camera RGB (24, 3) of the ColorChecker under D65 (white = 1)."""
    _, refl = checker_reflectances(wavelengths_nm)
    resp = channel_responsivity(sensor, wavelengths_nm)
    d65 = illuminant_spectrum("D65", wavelengths_nm)
    return (refl * d65) @ resp.T / (d65 @ resp.T)


def _qe_sensor(qe_path: str) -> SensorSpec:
    """A sensor that reads the QE file ``qe_path`` (the matrices depend on the spectral data only)."""
    sensor = SensorSpec(pixel_um=1.0)
    sensor._qe_path = qe_path
    return sensor


@functools.lru_cache(maxsize=32)
def _color_matrix_cached(qe_path: str) -> np.ndarray:
    sensor = _qe_sensor(qe_path)
    cam = checker_camera_rgb(sensor)
    target = checker_targets_linear_srgb()
    # Row sums fixed to 1: m3 = 1 − m1 − m2, so t − c3 = (c1 − c3) m1 + (c2 − c3) m2.
    a = cam[:, :2] - cam[:, 2:3]
    m = np.empty((3, 3))
    for r in range(3):
        sol, *_ = np.linalg.lstsq(a, target[:, r] - cam[:, 2], rcond=None)
        m[r] = [sol[0], sol[1], 1.0 - sol.sum()]
    return m


def color_matrix(sensor: SensorSpec) -> np.ndarray:
    """3×3 matrix from white-balanced camera RGB to linear sRGB (rows sum to 1)."""
    return _color_matrix_cached(str(sensor.qe_path.resolve())).copy()


def checker_delta_e2000(sensor: SensorSpec) -> np.ndarray:
    """CIEDE2000 (24,) between the ColorChecker through this sensor + matrix and its
    reference colorimetry (both under D65, noise-free, no clipping)."""
    est = checker_camera_rgb(sensor) @ color_matrix(sensor).T
    ref = checker_targets_linear_srgb()
    lab = [colour.XYZ_to_Lab(colour.RGB_to_XYZ(x, colour.RGB_COLOURSPACES["sRGB"], apply_cctf_decoding=False),
                             colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]) for x in (est, ref)]
    return colour.delta_E(lab[0], lab[1], method="CIE 2000")


def encode_srgb8(rgb_linear: np.ndarray) -> np.ndarray:
    """Linear sRGB (clipped to [0, 1]) → 8-bit sRGB (IEC 61966-2-1 transfer curve)."""
    x = np.clip(rgb_linear, 0.0, 1.0).astype(np.float32)
    v = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4, dtype=np.float32) - 0.055)
    return np.rint(v * 255.0).astype(np.uint8)


def process(raw_dn: np.ndarray, sensor: SensorSpec, isp: ISPSpec) -> np.ndarray:
    """Raw Bayer DN (rows, cols) → linear sRGB (rows, cols, 3) float32 (not clipped)."""
    rgb = white_balanced_rgb(raw_dn, sensor, isp)
    if isp.color_transform == "iset_mcc":
        return iset_render(rgb, sensor)
    m = color_matrix(sensor).astype(np.float32)
    return np.matmul(rgb, m.T)


def white_balanced_rgb(raw_dn: np.ndarray, sensor: SensorSpec, isp: ISPSpec) -> np.ndarray:
    """Raw DN → black-subtracted, white-balanced, demosaicked camera RGB (float32)."""
    lin = raw_to_linear(raw_dn, sensor)
    if isp.white_balance == "grey_world":
        gains = grey_world_gains(lin, sensor.cfa)
    elif isp.white_balance == "none":
        gains = np.ones(3)
    else:
        gains = illuminant_gains(sensor, isp.illuminant)
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


@functools.lru_cache(maxsize=32)
def _iset_mcc_matrix_cached(qe_path: str) -> np.ndarray:
    sensor = _qe_sensor(qe_path)
    _, refl = checker_reflectances()
    resp = channel_responsivity(sensor)
    d65 = illuminant_spectrum("D65")
    cam = (refl * d65) @ resp.T / (d65 @ resp[1])  # not white-balanced: G of white = 1
    xyz_bar = cie_1931_cmfs(WAVELENGTHS_NM)
    xyz = (refl * d65) @ xyz_bar / (d65 @ xyz_bar[:, 1])
    t, *_ = np.linalg.lstsq(cam, xyz, rcond=None)  # xyz ≈ cam @ t, unconstrained
    return t.T


def iset_mcc_matrix(sensor: SensorSpec) -> np.ndarray:
    """3×3 matrix from camera RGB (not white-balanced) to CIE XYZ: ISETCam's 'MCC
    optimized' sensor conversion (ISET/isetcam ``imgproc/imageSensorCorrection.m`` →
    ``ieColorTransform(sensor,'XYZ','D65','mcc')`` → ``imageSensorTransform.m``:
    ``T = sensorResponse \\ targetResponse``), the unconstrained least-squares fit of the
    sensor's responses to the 24 ColorChecker patches under D65 to their XYZ. Our camera
    RGB counts photo-electrons, so it pairs with ordinary XYZ as ISETCam's quanta
    responses pair with ``xyzQuanta``. Rows need not sum to anything: ISETCam fixes the
    scale at the end (:func:`iset_render`)."""
    return _iset_mcc_matrix_cached(str(sensor.qe_path.resolve())).copy()


def iset_render(rgb_sensor: np.ndarray, sensor: SensorSpec) -> np.ndarray:
    """ISETCam's default rendering of demosaicked sensor RGB (its 'sensor space') to
    linear display RGB in [0, 1] (float32), as ``ipCompute`` with the default ``ip``:

    1. XYZ = sensor RGB × :func:`iset_mcc_matrix`, clipped at 0
       (``imgproc/imageSensorCorrection.m``);
    2. illuminant correction 'None': nothing (``imgproc/imageIlluminantCorrection.m``);
    3. XYZ to linear display RGB, clipped at 0, divided by the image's maximum
       (``displays/displayRender.m``, the quantised-sensor branch: "img/max(img(:))").

    ISETCam's default display is ``lcdExample.mat``; we use the sRGB primaries, which it
    approximates. The image-dependent scale is ISETCam's: the brightest pixel becomes 1.
    """
    rgb = np.asarray(rgb_sensor, dtype=np.float32)
    xyz = np.maximum(np.matmul(rgb, iset_mcc_matrix(sensor).astype(np.float32).T), np.float32(0.0))
    to_rgb = np.asarray(colour.RGB_COLOURSPACES["sRGB"].matrix_XYZ_to_RGB, dtype=np.float32)
    lin = np.maximum(np.matmul(xyz, to_rgb.T), np.float32(0.0))
    peak = float(lin.max()) if lin.size else 0.0
    return lin / np.float32(peak) if peak > 0 else lin
