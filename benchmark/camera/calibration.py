"""The camera's calibration: what the ISP needs to know about its sensor, computed once
from the spec (ISETCam keeps it in the image processor's 'sensor conversion').

:func:`calibrate` fits, from the sensor's spectral responsivity alone:

- the colour matrix from white-balanced camera RGB to linear sRGB, by least squares on
  the 24 spectral reflectances of the ColorChecker (colour-science's ``ColorChecker N
  Ohta``) under CIE D65 against their CIE 1931 2° colorimetry, each row summing to 1 so
  that a white-balanced neutral stays neutral;
- ISETCam's 'MCC optimized' matrix from camera RGB to CIE XYZ (:func:`iset_mcc_matrix`);
- the white-balance gains of a known illuminant (:func:`illuminant_gains`).

The matrices depend on the spectral data only (QE and IR cut, not pixel size), so they
are cached by QE file. The ISP (:mod:`benchmark.camera.isp`) receives a :class:`Calibration`
and never reads the sensor's spectra itself.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import colour
import numpy as np

from benchmark.camera.spec_isp import ISPSpec
from benchmark.camera.spec_sensor import SensorSpec
from benchmark.camera.sensor import channel_responsivity
from metricscenes.photometry import cie_1931_cmfs
from metricscenes.spectral import WAVELENGTHS_NM, resample_spectrum

_CHECKER = "ColorChecker N Ohta"


@dataclass(frozen=True)
class Calibration:
    """A sensor's colour calibration (float64 arrays, read-only by convention).

    Attributes:
        color_matrix: (3, channels) white-balanced camera channels → linear sRGB (rows sum to 1).
        iset_mcc_matrix: (3, channels) camera channels (not white-balanced) → CIE XYZ.
        illuminant_gains: (channels,) white-balance gains of the ISP's known illuminant (G or C gain 1).
    """

    color_matrix: np.ndarray
    iset_mcc_matrix: np.ndarray
    illuminant_gains: np.ndarray


def calibrate(sensor: SensorSpec, isp: ISPSpec | None = None) -> Calibration:
    """The :class:`Calibration` of ``sensor`` for the ISP settings ``isp`` (its
    ``illuminant``; default D65)."""
    illuminant = isp.illuminant if isp is not None else "D65"
    return Calibration(color_matrix(sensor), iset_mcc_matrix(sensor), illuminant_gains(sensor, illuminant))


def illuminant_spectrum(name: str, wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """Relative spectral power of a CIE illuminant (colour-science name) at the bands."""
    try:
        sd = colour.SDS_ILLUMINANTS[name]
    except KeyError:
        raise ValueError(f"isp.illuminant: unknown illuminant {name!r} (e.g. D65, A, D50, F2)") from None
    return resample_spectrum(sd.wavelengths, sd.values, wavelengths_nm, hold_ends=True)


def illuminant_gains(sensor: SensorSpec, illuminant: str = "D65") -> np.ndarray:
    """Gains (channels,) that make a perfect white under ``illuminant`` neutral (G or C gain 1)."""
    response = channel_responsivity(sensor) @ illuminant_spectrum(illuminant)
    return response[1] / response


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
    """White-balanced camera channels (24, channels) of the ColorChecker under D65 (white = 1)."""
    _, refl = checker_reflectances(wavelengths_nm)
    resp = channel_responsivity(sensor, wavelengths_nm)
    d65 = illuminant_spectrum("D65", wavelengths_nm)
    return (refl * d65) @ resp.T / (d65 @ resp.T)


def _qe_sensor(qe_path: str, cfa: str = "RGGB") -> SensorSpec:
    """A sensor that reads the QE file ``qe_path`` behind the tile ``cfa`` (the matrices
    depend on the spectral data only)."""
    sensor = SensorSpec(pixel_um=1.0, cfa=cfa)
    sensor._qe_path = qe_path
    return sensor


@functools.lru_cache(maxsize=32)
def _color_matrix_cached(qe_path: str, cfa: str = "RGGB") -> np.ndarray:
    sensor = _qe_sensor(qe_path, cfa)
    cam = checker_camera_rgb(sensor)
    target = checker_targets_linear_srgb()
    # Row sums fixed to 1: m_n = 1 − m_1 − … − m_(n−1), so t − c_n = Σ_k (c_k − c_n) m_k.
    last = cam.shape[1] - 1
    a = cam[:, :last] - cam[:, last:]
    m = np.empty((3, last + 1))
    for r in range(3):
        sol, *_ = np.linalg.lstsq(a, target[:, r] - cam[:, last], rcond=None)
        m[r] = [*sol, 1.0 - sol.sum()]
    return m


def color_matrix(sensor: SensorSpec) -> np.ndarray:
    """Matrix (3, channels) from white-balanced camera channels to linear sRGB, rows summing
    to 1 (a white-balanced neutral stays neutral): 3×3 for RGGB and RCCB, 3×2 for RCCC.

    For RCCB the fit is the colour reconstruction: green is no channel of the sensor, and the
    least-squares matrix forms it from C, R and B (its G row weighs C against R and B: about
    C − R − B in the sensor's units) as the ColorChecker under D65 asks. For RCCC (red and
    clear only) it is the best monochrome-plus-red rendering the fit allows: each output
    channel a mix of R and C, so reds come out red and everything else in greys of the clear
    channel (docs/camera.md, "Clear-pixel colour filters")."""
    return _color_matrix_cached(str(sensor.qe_path.resolve()), sensor.cfa).copy()


def checker_delta_e2000(sensor: SensorSpec) -> np.ndarray:
    """CIEDE2000 (24,) between the ColorChecker through this sensor + matrix and its
    reference colorimetry (both under D65, noise-free, no clipping)."""
    est = checker_camera_rgb(sensor) @ color_matrix(sensor).T
    ref = checker_targets_linear_srgb()
    lab = [colour.XYZ_to_Lab(colour.RGB_to_XYZ(x, colour.RGB_COLOURSPACES["sRGB"], apply_cctf_decoding=False),
                             colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]) for x in (est, ref)]
    return colour.delta_E(lab[0], lab[1], method="CIE 2000")


@functools.lru_cache(maxsize=32)
def _iset_mcc_matrix_cached(qe_path: str, cfa: str = "RGGB") -> np.ndarray:
    sensor = _qe_sensor(qe_path, cfa)
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
    return _iset_mcc_matrix_cached(str(sensor.qe_path.resolve()), sensor.cfa).copy()
