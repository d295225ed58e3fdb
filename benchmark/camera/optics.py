"""Optics: scene radiance on the pixel grid to sensor-plane irradiance, through the lens.

Image-plane irradiance of a lens of f-number N and transmittance T from scene radiance
L (camera equation, magnification ≈ 0 at road distances; ISETCam ``oiCalculateIrradiance``):

    E(λ) = π · T · L(λ) / (1 + 4 N²)          W·m⁻²·nm⁻¹ from W·sr⁻¹·m⁻²·nm⁻¹

blurred by the lens's OTF, per wavelength: :func:`benchmark.camera.lens.lens_otf` (by
default the diffraction-limited circular pupil, Goodman eq. 6-32; aberrations, measured
tables and veiling glare there).

The radiance is first box-resampled onto the sensor's pixel grid
(:meth:`SpectralScene.resample`), which *is* the pixel-aperture integral (fill factor 1);
the OTF is then applied on that grid in the frequency domain. Below the Nyquist
frequency this is exact (MTF = OTF × pixel sinc); above it, aliased scene detail is
filtered at its alias frequency (see ``docs/camera.md``). The image is padded by
symmetric reflection (:func:`lens_pad_px`: the lens's PSF radius) so the FFT does not wrap
around; veiling glare, whose tail spans the frame, is applied on a zero-padded grid twice
the frame's size (:func:`veiling_glare`).

:class:`OpticalImage` is the value between the lens and the sensor (ISETCam's optical
image), held lazily: the radiance on the pixel grid and the lens. Its :attr:`irradiance`
is the plain per-band image; its :meth:`~OpticalImage.weighted_sum` is the fast path the
sensor uses to integrate its own QE: sensor integration is linear, so a colour channel's
signal Σ_λ r_c(λ) · E(λ) is summed in the frequency domain (one float32 forward rFFT per
band, one inverse per channel). Rotationally symmetric lenses use exact per-band OTFs
computed once per (grid, pixel, lens, bands) and cached on half the rFFT grid; bands are
read as contiguous planes (:meth:`SpectralScene.resample` stores them so) and padded in
place.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft

from benchmark.camera import lens as _lens
from benchmark.camera.spec_optics import OpticsSpec
from metricscenes.radiance import band_planes

FFT_WORKERS = 2
_BATCH = 8  # spectra summed per matrix product (memory: 8 × the padded image, complex64)


def irradiance_per_radiance(f_number: float, transmittance: float = 1.0) -> float:
    """E / L = π T / (1 + 4 N²), in sr (W·m⁻²·nm⁻¹ per W·sr⁻¹·m⁻²·nm⁻¹)."""
    return math.pi * transmittance / (1.0 + 4.0 * f_number**2)


diffraction_mtf = _lens.diffraction_otf
"""The ideal lens's OTF (Goodman eq. 6-32): :func:`benchmark.camera.lens.diffraction_otf`."""


def padding_px(radius_um: float, pixel_um: float) -> int:
    """Reflection padding, pixels, for a PSF of ``radius_um``: at least 8 px. Reflected
    content (not zeros) is what the PSF's tail blurs in, so the border of a uniform field
    stays exact."""
    return max(8, int(math.ceil(radius_um / pixel_um)))


def pad_px(pixel_um: float, f_number: float, wavelength_nm: float = 700.0) -> int:
    """Reflection padding of the ideal lens, pixels: 8 Airy radii (1.22 λ N) of the reddest
    band, ≥ 8 px (the PSF's energy beyond 8 Airy radii is < 1 %)."""
    return padding_px(_lens.diffraction_psf_radius_um(wavelength_nm, f_number), pixel_um)


def lens_pad_px(optics: OpticsSpec, pixel_um: float, wavelengths_nm) -> int:
    """Reflection padding, pixels, that holds the lens's PSF at these wavelengths
    (:func:`benchmark.camera.lens.psf_radius_um`); the ideal lens's is :func:`pad_px`."""
    return padding_px(_lens.psf_radius_um(optics, wavelengths_nm), pixel_um)


def _padded_shape(rows: int, cols: int, pad: int) -> tuple[int, int]:
    return sfft.next_fast_len(rows + 2 * pad, real=True), sfft.next_fast_len(cols + 2 * pad, real=True)


def _as_optics(lens: OpticsSpec | float) -> OpticsSpec:
    """An :class:`OpticsSpec`, or a bare f-number standing for the ideal lens at it."""
    return lens if isinstance(lens, OpticsSpec) else OpticsSpec(f_number=float(lens))


def _table_key(optics: OpticsSpec) -> str | None:
    """The resolved table a lens reads (part of the OTF cache's key with the spec, whose
    hash holds the relative path only)."""
    if optics.psf_table is not None:
        return str(optics.psf_table_path.resolve())
    if optics.mtf_table is not None:
        return str(optics.mtf_table_path.resolve())
    return None


def otf_grid(shape_px: tuple[int, int], pixel_um: float, wavelength_nm: float, lens: OpticsSpec | float) -> np.ndarray:
    """The lens's OTF (veiling glare aside) on the rFFT grid of a (rows, cols) image:
    (rows, cols // 2 + 1), float32 for a rotationally symmetric lens, else complex64.
    ``lens``: an :class:`OpticsSpec` or an f-number (the ideal lens)."""
    rows, cols = shape_px
    pixel_mm = pixel_um * 1e-3
    otf = _lens.lens_otf(_as_optics(lens), wavelength_nm, sfft.rfftfreq(cols, d=pixel_mm),
                         sfft.fftfreq(rows, d=pixel_mm), glare=False)
    return otf.astype(np.float32 if np.isrealobj(otf) else np.complex64)


def _half_otfs(shape_px: tuple[int, int], pixel_um: float, wavelengths_nm: tuple[float, ...],
               lens: OpticsSpec | float) -> np.ndarray:
    """Exact OTFs (bands, rows // 2 + 1, cols // 2 + 1), float32, of a rotationally
    symmetric lens (veiling glare aside) on the non-negative vertical frequencies of an
    rFFT grid (rows k and rows − k have the same |ν_y|). ``lens``: an :class:`OpticsSpec`
    or an f-number (the ideal lens)."""
    optics = _as_optics(lens)
    return _cached_half_otfs(shape_px, pixel_um, wavelengths_nm, optics, _table_key(optics))


@functools.lru_cache(maxsize=16)
def _cached_half_otfs(shape_px, pixel_um, wavelengths_nm, optics, table_key) -> np.ndarray:
    # Cached: a camera's every capture has the same grid and bands; a sweep takes a group of
    # cameras scene by scene (the paper's 13 and extras fit: ≤ 140 MB each, at 2688 x 1512).
    rows, cols = shape_px
    pixel_mm = pixel_um * 1e-3
    fy = np.abs(sfft.fftfreq(rows, d=pixel_mm)[: rows // 2 + 1])
    fx = sfft.rfftfreq(cols, d=pixel_mm)
    out = np.stack([_lens.lens_otf(optics, wl, fx, fy, glare=False).astype(np.float32) for wl in wavelengths_nm])
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


def veiling_glare(images: np.ndarray, optics: OpticsSpec, pixel_um: float) -> np.ndarray:
    """Images (..., rows, cols) on the sensor with the lens's veiling glare: a fraction g
    (``optics.veiling_glare_fraction``) of each image's light spread by the glare spread
    function (:func:`benchmark.camera.lens.glare_spread_function`), i.e. the spectrum
    multiplied by (1 − g) + g · exp(−2π r₀ ν), float32.

    The tail spans the frame, so each image is zero-padded to at least twice its size
    (no light beyond the camera's field, where the scene is unknown): light a source
    scatters past the frame's edge is lost, as on a sensor, and the total over the
    padded plane is kept exactly (the factor is 1 at ν = 0). The part of the tail beyond
    the padded plane (a fraction ≈ r₀ / (padded size) of g) wraps around.
    """
    rows, cols = images.shape[-2:]
    shape = (sfft.next_fast_len(2 * rows, real=True), sfft.next_fast_len(2 * cols, real=True))
    pixel_mm = pixel_um * 1e-3
    rho = np.hypot(sfft.rfftfreq(shape[1], d=pixel_mm)[None, :], sfft.fftfreq(shape[0], d=pixel_mm)[:, None])
    factor = _lens.glare_factor(optics, rho).astype(np.float32)
    out = np.empty(images.shape, dtype=np.float32)
    for index in np.ndindex(images.shape[:-2]):
        spectrum = sfft.rfft2(np.asarray(images[index], np.float32), s=shape, workers=FFT_WORKERS)
        spectrum *= factor
        out[index] = sfft.irfft2(spectrum, s=shape, workers=FFT_WORKERS)[:rows, :cols]
    return out


@dataclass(frozen=True, eq=False)
class OpticalImage:
    """The scene through the lens, on the sensor's pixel grid (ISETCam's optical image),
    held lazily: the radiance resampled to the pixel grid and the lens that images it.
    A later stage asks it for what it needs — the per-band :attr:`irradiance`, or the
    weighted sums of its bands the sensor integrates (:meth:`weighted_sum`, the fast
    path) — and never reaches back into the scene.

    Attributes:
        radiance: (rows, cols, bands) W·sr⁻¹·m⁻²·nm⁻¹, one sample per pixel (fastest
            stored band by band, as :meth:`SpectralScene.resample` returns it).
        wavelengths_nm: (bands,) band centres.
        pixel_um: the sampling pitch on the sensor, µm.
        optics: the lens.
        blur: apply the lens's OTF and glare (off: irradiance only, for uniform fields
            and tests).
    """

    radiance: np.ndarray
    wavelengths_nm: np.ndarray
    pixel_um: float
    optics: OpticsSpec
    blur: bool = True

    @functools.cached_property
    def irradiance(self) -> np.ndarray:
        """Sensor-plane spectral irradiance (rows, cols, bands), float32, W·m⁻²·nm⁻¹: the
        plain path, band by band, each padded for its own wavelength."""
        optics, pixel_um = self.optics, self.pixel_um
        rows, cols, bands = self.radiance.shape
        scale = np.float32(irradiance_per_radiance(optics.f_number, optics.transmittance))
        out = np.empty(self.radiance.shape, dtype=np.float32)
        for b in range(bands):
            band = self.radiance[:, :, b]
            wl = float(self.wavelengths_nm[b])
            if self.blur:
                pad = lens_pad_px(optics, pixel_um, [wl])
                shape = _padded_shape(rows, cols, pad)
                spec = sfft.rfft2(_pad(band, pad, shape), workers=FFT_WORKERS)
                spec *= otf_grid(shape, pixel_um, wl, optics)
                band = sfft.irfft2(spec, s=shape, workers=FFT_WORKERS)[pad : pad + rows, pad : pad + cols]
            out[:, :, b] = self._after_the_otf(band * scale)
        return out

    def weighted_sum(self, weights: np.ndarray) -> np.ndarray:
        """Σ_b weights[c, b] · E_b: weighted sums of the irradiance bands, (channels, rows,
        cols) float32 — the fast path, equal to summing :attr:`irradiance` (tested).

        Args:
            weights: (channels, bands) per unit irradiance of each band, e.g. the sensor's
                electrons·s⁻¹ per W·m⁻²·nm⁻¹
                (:func:`benchmark.camera.sensor.channel_responsivity`).
        """
        rows, cols, bands = self.radiance.shape
        planes = band_planes(self.radiance)
        resp = np.asarray(weights, dtype=np.float64) * irradiance_per_radiance(
            self.optics.f_number, self.optics.transmittance
        )
        channels = resp.shape[0]
        if not self.blur:
            out = np.matmul(resp.astype(np.float32), planes.reshape(bands, -1)).reshape(channels, rows, cols)
        else:
            out = _blurred_channels(planes, np.asarray(self.wavelengths_nm, float), self.optics, self.pixel_um, resp)
        return self._after_the_otf(out)

    def _after_the_otf(self, images: np.ndarray) -> np.ndarray:
        """Relative illumination (cos⁴), then veiling glare: the glare spreads the light
        that reaches the sensor. Both are the same for every band, so the fast path applies
        them once per channel."""
        rows, cols = images.shape[-2:]
        if self.optics.cos4_falloff:
            images *= cos4_map(rows, cols, self.pixel_um, self.optics.focal_length_mm)
        if self.blur and self.optics.veiling_glare_fraction > 0.0:
            images = veiling_glare(images, self.optics, self.pixel_um)
        return images


def channel_signal(
    radiance: np.ndarray,
    wavelengths_nm: np.ndarray,
    optics: OpticsSpec,
    pixel_um: float,
    responsivity: np.ndarray,
    *,
    diffraction: bool = True,
) -> np.ndarray:
    """Per-channel signal images (channels, rows, cols) float32 from a radiance grid on the
    sensor's pixel grid: :meth:`OpticalImage.weighted_sum` of the optical image with the
    channel responsivities (e.g. electrons·s⁻¹ per W·m⁻²·nm⁻¹). ``diffraction`` off: no
    lens blur (irradiance only, for tests)."""
    return OpticalImage(radiance, wavelengths_nm, pixel_um, optics, blur=diffraction).weighted_sum(responsivity)


def _blurred_channels(
    planes: np.ndarray, wavelengths_nm: np.ndarray, optics: OpticsSpec, pixel_um: float, resp: np.ndarray
) -> np.ndarray:
    """Σ_b resp[c, b] · OTF_b · FFT(band b), one inverse FFT per channel.

    Bands go through the FFT one at a time into a batch of OTF-weighted spectra; each
    full batch is added to the channel spectra by one matrix product (channels × batch)
    over the spectra viewed as float32 (the weights are real). A rotationally symmetric
    lens multiplies by its cached half-grid OTFs; any other by its full-grid complex OTF,
    computed band by band (not cached: 31 of them would hold hundreds of MB).
    """
    bands, rows, cols = planes.shape
    channels = resp.shape[0]
    pad = lens_pad_px(optics, pixel_um, wavelengths_nm)
    shape = _padded_shape(rows, cols, pad)
    radial = _lens.otf_is_radial(optics)
    if radial:
        otfs = _half_otfs(shape, float(pixel_um), tuple(float(w) for w in wavelengths_nm), optics)
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
            if radial:
                _apply_otf(sfft.rfft2(padded, workers=FFT_WORKERS), otfs[b], batch[k])
            else:
                np.multiply(sfft.rfft2(padded, workers=FFT_WORKERS),
                            otf_grid(shape, pixel_um, float(wavelengths_nm[b]), optics), out=batch[k])
        weights = resp[:, chunk].astype(np.float32)
        acc_f += weights @ batch_f[: len(chunk)]
    out = np.empty((channels, rows, cols), dtype=np.float32)
    for c in range(channels):
        out[c] = sfft.irfft2(acc[c], s=shape, workers=FFT_WORKERS)[pad : pad + rows, pad : pad + cols]
    return out


def optical_image(radiance: np.ndarray, wavelengths_nm: np.ndarray, optics: OpticsSpec, pixel_um: float, *,
                  diffraction: bool = True) -> OpticalImage:
    """Radiance on the pixel grid → the (lazy) :class:`OpticalImage` through ``optics``."""
    return OpticalImage(radiance, np.asarray(wavelengths_nm, float), float(pixel_um), optics, blur=diffraction)


def irradiance(
    radiance: np.ndarray, wavelengths_nm: np.ndarray, optics: OpticsSpec, pixel_um: float, *, diffraction: bool = True
) -> np.ndarray:
    """Sensor-plane spectral irradiance (rows, cols, bands), W·m⁻²·nm⁻¹ (plain, per band):
    :attr:`OpticalImage.irradiance`."""
    return optical_image(radiance, wavelengths_nm, optics, pixel_um, diffraction=diffraction).irradiance


@functools.lru_cache(maxsize=16)  # (a sweep's cameras, scene by scene)
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
