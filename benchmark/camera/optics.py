"""Diffraction-limited optics: scene radiance to sensor-plane irradiance.

Image-plane irradiance of a lens of f-number N and transmittance T from scene radiance
L (camera equation, magnification ≈ 0 at road distances; ISETCam ``oiCalculateIrradiance``):

    E(λ) = π · T · L(λ) / (1 + 4 N²)          W·m⁻²·nm⁻¹ from W·sr⁻¹·m⁻²·nm⁻¹

blurred by the OTF of a circular pupil (Goodman, *Introduction to Fourier Optics*, 3rd
ed., eq. 6-32), per wavelength, with cutoff ν_c = 1 / (λ N):

    H(ν) = (2/π) [acos(ν/ν_c) − (ν/ν_c) √(1 − (ν/ν_c)²)],  ν < ν_c;  0 otherwise.

The radiance is first box-resampled onto the sensor's pixel grid
(:meth:`SpectralScene.resample`), which *is* the pixel-aperture integral (fill factor 1);
the OTF is then applied on that grid in the frequency domain. Below the Nyquist
frequency this is exact (MTF = OTF × pixel sinc); above it, aliased scene detail is
filtered at its alias frequency (see ``docs/camera.md``). The image is padded by
symmetric reflection (``pad_px``, a few Airy radii) so the FFT does not wrap around.

Sensor integration is linear in irradiance, so a colour channel's signal is
``Σ_λ r_c(λ) · E(λ)``: :func:`channel_signal` sums spectra in the frequency domain
(one float32 forward rFFT per band, one inverse per channel) — the fast path. Its
per-band OTFs are exact (no table), computed once per (grid, pixel, f-number, bands)
and cached; bands are read as contiguous planes (:meth:`SpectralScene.resample` stores
them so) and padded in place. :func:`irradiance` gives the plain per-band irradiance,
the reference the fast path is tested against.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft

from benchmark.camera.spec import OpticsSpec

FFT_WORKERS = 2
_BATCH = 8  # spectra summed per matrix product (memory: 8 × the padded image, complex64)


def irradiance_per_radiance(f_number: float, transmittance: float = 1.0) -> float:
    """E / L = π T / (1 + 4 N²), in sr (W·m⁻²·nm⁻¹ per W·sr⁻¹·m⁻²·nm⁻¹)."""
    return math.pi * transmittance / (1.0 + 4.0 * f_number**2)


def diffraction_mtf(freq_cy_per_mm: np.ndarray, wavelength_nm: float, f_number: float) -> np.ndarray:
    """OTF (real, non-negative) of an aberration-free circular pupil at radial spatial
    frequency ``freq_cy_per_mm`` on the image plane (Goodman eq. 6-32)."""
    cutoff_cy_per_mm = 1.0 / (wavelength_nm * 1e-6 * f_number)
    s = np.clip(np.abs(np.asarray(freq_cy_per_mm, dtype=float)) / cutoff_cy_per_mm, 0.0, 1.0)
    return (2.0 / np.pi) * (np.arccos(s) - s * np.sqrt(1.0 - s * s))


def pad_px(pixel_um: float, f_number: float, wavelength_nm: float = 700.0) -> int:
    """Reflection padding, pixels: 8 Airy radii (1.22 λ N) of the reddest band, ≥ 8 px.
    The PSF's energy beyond 8 Airy radii is < 1 %, and reflected content (not zeros)
    is what it then blurs in, so the border of a uniform field stays exact."""
    airy_um = 1.22 * wavelength_nm * 1e-3 * f_number
    return max(8, int(math.ceil(8.0 * airy_um / pixel_um)))


def _padded_shape(rows: int, cols: int, pad: int) -> tuple[int, int]:
    return sfft.next_fast_len(rows + 2 * pad, real=True), sfft.next_fast_len(cols + 2 * pad, real=True)


def otf_grid(shape_px: tuple[int, int], pixel_um: float, wavelength_nm: float, f_number: float) -> np.ndarray:
    """Diffraction OTF sampled on the rFFT grid of a (rows, cols) image, float32
    (rows, cols // 2 + 1)."""
    rows, cols = shape_px
    pixel_mm = pixel_um * 1e-3
    fy = sfft.fftfreq(rows, d=pixel_mm)[:, None]
    fx = sfft.rfftfreq(cols, d=pixel_mm)[None, :]
    return diffraction_mtf(np.hypot(fx, fy), wavelength_nm, f_number).astype(np.float32)


@functools.lru_cache(maxsize=3)
def _half_otfs(
    shape_px: tuple[int, int], pixel_um: float, wavelengths_nm: tuple[float, ...], f_number: float
) -> np.ndarray:
    """Exact diffraction OTFs (bands, rows // 2 + 1, cols // 2 + 1), float32, on the
    non-negative vertical frequencies of an rFFT grid (rows k and rows − k have the
    same |ν_y|). Cached: a camera's every capture has the same grid and bands; a
    sweep runs one camera at a time."""
    rows, cols = shape_px
    pixel_mm = pixel_um * 1e-3
    fy = np.abs(sfft.fftfreq(rows, d=pixel_mm)[: rows // 2 + 1, None])
    rho = np.hypot(sfft.rfftfreq(cols, d=pixel_mm)[None, :], fy)
    out = np.stack([diffraction_mtf(rho, wl, f_number).astype(np.float32) for wl in wavelengths_nm])
    out.setflags(write=False)
    return out


def _apply_otf(spec: np.ndarray, half_otf: np.ndarray, out: np.ndarray) -> None:
    """``out = spec × OTF`` on the full rFFT grid from the half-grid OTF."""
    half = half_otf.shape[0]
    rows = spec.shape[0]
    np.multiply(spec[:half], half_otf, out=out[:half])
    np.multiply(spec[half:], half_otf[1 : rows - half + 1][::-1], out=out[half:])


def _pad_into(buf: np.ndarray, band: np.ndarray, pad: int) -> None:
    """Write ``band`` into ``buf`` at (pad, pad) and fill the margins by symmetric
    reflection: the same array as ``np.pad(band, ..., mode="symmetric")``, without
    allocating one."""
    rows, cols = band.shape
    bottom, right = buf.shape[0] - rows - pad, buf.shape[1] - cols - pad
    if max(pad, bottom) > rows or max(pad, right) > cols:  # margins wider than the image
        buf[...] = np.pad(band, ((pad, bottom), (pad, right)), mode="symmetric")
        return
    inner = slice(pad, pad + cols)
    buf[pad : pad + rows, inner] = band
    buf[:pad, inner] = band[:pad][::-1]
    buf[pad + rows :, inner] = band[rows - bottom :][::-1]
    buf[:, :pad] = buf[:, pad : 2 * pad][:, ::-1]
    buf[:, pad + cols :] = buf[:, pad + cols - right : pad + cols][:, ::-1]


def _pad(band: np.ndarray, pad: int, shape: tuple[int, int]) -> np.ndarray:
    rows, cols = band.shape
    out = np.pad(band, ((pad, shape[0] - rows - pad), (pad, shape[1] - cols - pad)), mode="symmetric")
    return out


def band_planes(radiance: np.ndarray) -> np.ndarray:
    """(rows, cols, bands) radiance as (bands, rows, cols) C-contiguous planes: a view
    when the cube is stored band by band (as :meth:`SpectralScene.resample` returns
    it), else one copy."""
    return np.ascontiguousarray(np.moveaxis(np.asarray(radiance, dtype=np.float32), 2, 0))


def channel_signal(
    radiance: np.ndarray,
    wavelengths_nm: np.ndarray,
    optics: OpticsSpec,
    pixel_um: float,
    responsivity: np.ndarray,
    *,
    diffraction: bool = True,
) -> np.ndarray:
    """Per-channel signal images from a radiance grid on the sensor's pixel grid.

    Args:
        radiance: (rows, cols, bands) W·sr⁻¹·m⁻²·nm⁻¹, one sample per pixel (fastest
            when stored band by band, as :meth:`SpectralScene.resample` returns it).
        wavelengths_nm: (bands,) band centres.
        optics: the lens.
        pixel_um: pixel pitch, µm (sampling of ``radiance``).
        responsivity: (channels, bands) signal per unit irradiance per band, e.g.
            electrons·s⁻¹ per W·m⁻²·nm⁻¹ (:func:`benchmark.camera.sensor.channel_responsivity`).
        diffraction: apply the OTF (off: irradiance only, for tests).

    Returns:
        (channels, rows, cols) float32, e.g. electrons·s⁻¹.
    """
    rows, cols, bands = radiance.shape
    planes = band_planes(radiance)
    resp = np.asarray(responsivity, dtype=np.float64) * irradiance_per_radiance(
        optics.f_number, optics.transmittance
    )
    channels = resp.shape[0]
    if not diffraction:
        out = np.matmul(resp.astype(np.float32), planes.reshape(bands, -1)).reshape(channels, rows, cols)
    else:
        out = _diffracted_channels(planes, np.asarray(wavelengths_nm, float), optics.f_number, pixel_um, resp)
    if optics.cos4_falloff:
        out *= cos4_map(rows, cols, pixel_um, optics.focal_length_mm)[None]
    return out


def _diffracted_channels(
    planes: np.ndarray, wavelengths_nm: np.ndarray, f_number: float, pixel_um: float, resp: np.ndarray
) -> np.ndarray:
    """Σ_b resp[c, b] · OTF_b · FFT(band b), one inverse FFT per channel.

    Bands go through the FFT one at a time into a batch of OTF-weighted spectra; each
    full batch is added to the channel spectra by one matrix product (channels × batch)
    over the spectra viewed as float32 (the weights are real).
    """
    bands, rows, cols = planes.shape
    channels = resp.shape[0]
    pad = pad_px(pixel_um, f_number, float(np.max(wavelengths_nm)))
    shape = _padded_shape(rows, cols, pad)
    otfs = _half_otfs(shape, float(pixel_um), tuple(float(w) for w in wavelengths_nm), float(f_number))
    used = [b for b in range(bands) if np.any(resp[:, b])]
    spec_shape = (shape[0], shape[1] // 2 + 1)
    batch = np.empty((min(_BATCH, max(len(used), 1)),) + spec_shape, dtype=np.complex64)
    acc = np.zeros((channels,) + spec_shape, dtype=np.complex64)
    acc_f = acc.view(np.float32).reshape(channels, -1)
    batch_f = batch.view(np.float32).reshape(batch.shape[0], -1)
    padded = np.empty(shape, dtype=np.float32)
    for start in range(0, len(used), batch.shape[0]):
        chunk = used[start : start + batch.shape[0]]
        for k, b in enumerate(chunk):
            _pad_into(padded, planes[b], pad)
            _apply_otf(sfft.rfft2(padded, workers=FFT_WORKERS), otfs[b], batch[k])
        weights = resp[:, chunk].astype(np.float32)
        acc_f += weights @ batch_f[: len(chunk)]
    out = np.empty((channels, rows, cols), dtype=np.float32)
    for c in range(channels):
        out[c] = sfft.irfft2(acc[c], s=shape, workers=FFT_WORKERS)[pad : pad + rows, pad : pad + cols]
    return out


@dataclass(frozen=True)
class OpticalImage:
    """Spectral irradiance on the sensor plane (ISETCam's optical image).

    Attributes:
        irradiance: (rows, cols, bands) float32, W·m⁻²·nm⁻¹, one sample per pixel.
        wavelengths_nm: (bands,) band centres.
        pixel_um: the sampling pitch on the sensor, µm.
    """

    irradiance: np.ndarray
    wavelengths_nm: np.ndarray
    pixel_um: float


def optical_image(radiance: np.ndarray, wavelengths_nm: np.ndarray, optics: OpticsSpec, pixel_um: float, *,
                  diffraction: bool = True) -> OpticalImage:
    """Radiance on the pixel grid → the :class:`OpticalImage` (per band: :func:`irradiance`)."""
    return OpticalImage(irradiance(radiance, wavelengths_nm, optics, pixel_um, diffraction=diffraction),
                        np.asarray(wavelengths_nm, float), float(pixel_um))


def irradiance(
    radiance: np.ndarray, wavelengths_nm: np.ndarray, optics: OpticsSpec, pixel_um: float, *, diffraction: bool = True
) -> np.ndarray:
    """Sensor-plane spectral irradiance (rows, cols, bands), W·m⁻²·nm⁻¹ (plain, per band)."""
    out = np.empty(radiance.shape, dtype=np.float32)
    for b in range(radiance.shape[2]):
        out[:, :, b] = _one_band(radiance[:, :, b], float(wavelengths_nm[b]), optics, pixel_um, diffraction)
    return out


def _one_band(band: np.ndarray, wavelength_nm: float, optics: OpticsSpec, pixel_um: float, diffraction: bool) -> np.ndarray:
    scale = np.float32(irradiance_per_radiance(optics.f_number, optics.transmittance))
    rows, cols = band.shape
    if diffraction:
        pad = pad_px(pixel_um, optics.f_number, wavelength_nm)
        shape = _padded_shape(rows, cols, pad)
        spec = sfft.rfft2(_pad(band, pad, shape), workers=FFT_WORKERS)
        spec *= otf_grid(shape, pixel_um, wavelength_nm, optics.f_number)
        band = sfft.irfft2(spec, s=shape, workers=FFT_WORKERS)[pad : pad + rows, pad : pad + cols]
    out = band * scale
    if optics.cos4_falloff:
        out = out * cos4_map(rows, cols, pixel_um, optics.focal_length_mm)
    return out


@functools.lru_cache(maxsize=4)
def cos4_map(rows: int, cols: int, pixel_um: float, focal_length_mm: float) -> np.ndarray:
    """Relative illumination cos⁴θ of each pixel centre (natural vignetting); cached,
    read-only."""
    pixel_mm = pixel_um * 1e-3
    y = (np.arange(rows) - (rows - 1) / 2.0) * pixel_mm / focal_length_mm
    x = (np.arange(cols) - (cols - 1) / 2.0) * pixel_mm / focal_length_mm
    tan2 = y[:, None] ** 2 + x[None, :] ** 2
    out = (1.0 / (1.0 + tan2) ** 2).astype(np.float32)
    out.setflags(write=False)
    return out
