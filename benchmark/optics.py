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
(one forward rFFT per band, one inverse per channel) — the fast path.
:func:`irradiance` gives the plain per-band irradiance for tests.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.fft as sfft

from benchmark.cameras.spec import OpticsSpec

FFT_WORKERS = 2


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


class _RadialGrid:
    """|ν| on an rFFT grid, for fast per-band OTF evaluation: the OTF depends on
    ν·λ·N only, so it is read from a fine table (error < 1e-4) and only for the
    non-negative vertical frequencies (the grid is symmetric in ν_y)."""

    _TABLE = diffraction_mtf(np.linspace(0.0, 1.0, 16385), 1.0, 1e6).astype(np.float32)

    def __init__(self, shape_px: tuple[int, int], pixel_um: float):
        rows, cols = shape_px
        self.rows = rows
        self.half = rows // 2 + 1
        pixel_mm = pixel_um * 1e-3
        fy = np.abs(sfft.fftfreq(rows, d=pixel_mm)[: self.half, None])
        fx = sfft.rfftfreq(cols, d=pixel_mm)[None, :]
        self.rho = np.hypot(fx, fy).astype(np.float32)
        self.out = np.empty((rows, cols // 2 + 1), dtype=np.float32)

    def mtf(self, wavelength_nm: float, f_number: float) -> np.ndarray:
        n = len(self._TABLE) - 1
        scale = np.float32(wavelength_nm * 1e-6 * f_number * n)
        idx = np.multiply(self.rho, scale)
        np.minimum(idx, n, out=idx)
        np.add(idx, 0.5, out=idx)
        top = self._TABLE.take(idx.astype(np.int32))
        self.out[: self.half] = top
        # rows k and rows - k have the same |ν_y|
        self.out[self.half :] = top[1 : self.rows - self.half + 1][::-1]
        return self.out


def _pad(band: np.ndarray, pad: int, shape: tuple[int, int]) -> np.ndarray:
    rows, cols = band.shape
    out = np.pad(band, ((pad, shape[0] - rows - pad), (pad, shape[1] - cols - pad)), mode="symmetric")
    return out


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
        radiance: (rows, cols, bands) W·sr⁻¹·m⁻²·nm⁻¹, one sample per pixel.
        wavelengths_nm: (bands,) band centres.
        optics: the lens.
        pixel_um: pixel pitch, µm (sampling of ``radiance``).
        responsivity: (channels, bands) signal per unit irradiance per band, e.g.
            electrons·s⁻¹ per W·m⁻²·nm⁻¹ (:func:`benchmark.sensor.channel_responsivity`).
        diffraction: apply the OTF (off: irradiance only, for tests).

    Returns:
        (channels, rows, cols) float32, e.g. electrons·s⁻¹.
    """
    rows, cols, bands = radiance.shape
    resp = np.asarray(responsivity, dtype=np.float64) * irradiance_per_radiance(
        optics.f_number, optics.transmittance
    )
    if not diffraction:
        out = np.einsum("hwb,cb->chw", radiance, resp.astype(np.float32), optimize=True)
    else:
        pad = pad_px(pixel_um, optics.f_number, float(np.max(wavelengths_nm)))
        shape = _padded_shape(rows, cols, pad)
        radial = _RadialGrid(shape, pixel_um)
        acc = np.zeros((resp.shape[0], shape[0], shape[1] // 2 + 1), dtype=np.complex64)
        tmp = np.empty_like(acc[0])
        for b in range(bands):
            if not np.any(resp[:, b]):
                continue
            spec = sfft.rfft2(_pad(radiance[:, :, b], pad, shape), workers=FFT_WORKERS)
            spec *= radial.mtf(float(wavelengths_nm[b]), optics.f_number)
            for c in range(resp.shape[0]):
                np.multiply(spec, np.float32(resp[c, b]), out=tmp)
                acc[c] += tmp
        out = np.empty((resp.shape[0], rows, cols), dtype=np.float32)
        for c in range(resp.shape[0]):
            full = sfft.irfft2(acc[c], s=shape, workers=FFT_WORKERS)
            out[c] = full[pad : pad + rows, pad : pad + cols]
    if optics.cos4_falloff:
        out *= cos4_map(rows, cols, pixel_um, optics.focal_length_mm)[None]
    return out.astype(np.float32, copy=False)


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


def cos4_map(rows: int, cols: int, pixel_um: float, focal_length_mm: float) -> np.ndarray:
    """Relative illumination cos⁴θ of each pixel centre (natural vignetting)."""
    pixel_mm = pixel_um * 1e-3
    y = (np.arange(rows) - (rows - 1) / 2.0) * pixel_mm / focal_length_mm
    x = (np.arange(cols) - (cols - 1) / 2.0) * pixel_mm / focal_length_mm
    tan2 = y[:, None] ** 2 + x[None, :] ** 2
    return (1.0 / (1.0 + tan2) ** 2).astype(np.float32)
