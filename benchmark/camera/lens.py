"""The lens's optical transfer function (OTF): one function, :func:`lens_otf`, gives it to
every stage that needs it — the camera's optics (:mod:`benchmark.camera.optics`), the
analytic MTF50 (:func:`benchmark.measure.mtf.mtf50_analytic_cy_per_mm`) and the benchmarks.

A lens (an :class:`~benchmark.camera.spec_optics.OpticsSpec`) forms its image through one of

* **a clear circular pupil** (the default, the paper's diffraction-limited lenses) at
  f-number N: Goodman, *Introduction to Fourier Optics*, 3rd ed., eq. 6-32, with cutoff
  ν_c = 1 / (λ N),

      H(ν) = (2/π) [acos(ν/ν_c) − (ν/ν_c) √(1 − (ν/ν_c)²)],  ν < ν_c;  0 otherwise;

* **an aberrated pupil**: Zernike coefficients c_j (OSA/ANSI single index j, ISO 24157;
  RMS-normalised polynomials; c_j in waves at the reference wavelength λ_ref) give the
  wavefront W = λ_ref Σ c_j Z_j(ρ, θ), an optical path difference that does not change
  with wavelength. The pupil function is P = circ(ρ) · exp(2πi W / λ) and the OTF its
  normalised autocorrelation (Goodman eq. 6-28 and §6.4), computed by FFT
  (:func:`pupil_otf_table`) as ISETCam's wavefront code builds the PSF from the same
  pupil function (ISET/isetcam ``wvfComputePupilFunction``, ``wvfComputePSF``);
* **a measured lens**: a PSF or an MTF table per wavelength (CSV files, docs/camera.md:
  :func:`read_psf_table`, :func:`read_mtf_table`);

and, where the lens has veiling glare, a fraction g of the light leaves that image and is
spread by a glare spread function of the long-tailed form of the CIE 146:2002 glare
equations, which multiplies the OTF by (1 − g) + g · exp(−2π r₀ ν) (:func:`glare_otf`).

Frequencies are cycles/mm on the sensor; ``fx`` runs along the image's columns, ``fy``
along its rows (downwards). The OTF is real for a rotationally symmetric lens
(:func:`otf_is_radial`), complex otherwise.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.fft as sfft
import scipy.sparse

from benchmark.camera.tables import check_wavelengths_nm, read_numeric_csv, wavelength_groups

# ── diffraction ─────────────────────────────────────────────────────────────────────────


def diffraction_otf(freq_cy_per_mm: np.ndarray, wavelength_nm: float, f_number: float) -> np.ndarray:
    """OTF (real, non-negative) of an aberration-free circular pupil at radial spatial
    frequency ``freq_cy_per_mm`` on the image plane (Goodman eq. 6-32)."""
    cutoff_cy_per_mm = 1.0 / (wavelength_nm * 1e-6 * f_number)
    s = np.clip(np.abs(np.asarray(freq_cy_per_mm, dtype=float)) / cutoff_cy_per_mm, 0.0, 1.0)
    return (2.0 / np.pi) * (np.arccos(s) - s * np.sqrt(1.0 - s * s))


def diffraction_psf_radius_um(wavelength_nm: float, f_number: float) -> float:
    """8 Airy radii (1.22 λ N each), µm: the Airy pattern's energy beyond is < 1 %."""
    return 8.0 * (1.22 * wavelength_nm * 1e-3 * f_number)


# ── Zernike polynomials (OSA/ANSI) ──────────────────────────────────────────────────────

MAX_ZERNIKE_ORDER = 10
MAX_ZERNIKE_INDEX = (MAX_ZERNIKE_ORDER * (MAX_ZERNIKE_ORDER + 2) + MAX_ZERNIKE_ORDER) // 2
"""65: the highest OSA/ANSI index accepted (radial order 10)."""


def zernike_order(j: int) -> tuple[int, int]:
    """(radial order n, azimuthal frequency m) of OSA/ANSI index j = (n (n + 2) + m) / 2."""
    n = int(math.ceil((-3.0 + math.sqrt(9.0 + 8.0 * j)) / 2.0))
    return n, 2 * j - n * (n + 2)


def zernike(j: int, rho: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """OSA/ANSI Zernike polynomial Z_j at pupil radius ``rho`` (0–1) and angle ``theta``
    (radians, from +x towards +y), normalised to unit RMS over the unit disk:
    N R_n^|m|(ρ) cos(mθ) for m ≥ 0, N R_n^|m|(ρ) sin(|m|θ) for m < 0,
    N = √(2 (n + 1) / (1 + δ_m0)) (ANSI Z80.28; Thibos et al., JOSA A 19, 2002)."""
    n, m = zernike_order(j)
    a = abs(m)
    radial = sum((-1) ** k * math.factorial(n - k)
                 / (math.factorial(k) * math.factorial((n + a) // 2 - k) * math.factorial((n - a) // 2 - k))
                 * rho ** (n - 2 * k) for k in range((n - a) // 2 + 1))
    norm = math.sqrt(2.0 * (n + 1) / (2.0 if m == 0 else 1.0))
    return norm * radial * (np.cos(m * theta) if m >= 0 else np.sin(a * theta))


def wavefront_waves(coefficients: tuple[tuple[int, float], ...], rho: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """W / λ_ref = Σ c_j Z_j(ρ, θ): the wavefront in waves at the reference wavelength."""
    out = np.zeros(np.broadcast(rho, theta).shape)
    for j, c in coefficients:
        out += c * zernike(j, rho, theta)
    return out


@functools.lru_cache(maxsize=64)
def wavefront_slope(coefficients: tuple[tuple[int, float], ...]) -> float:
    """The wavefront's steepest slope over the pupil, waves (at the reference) per pupil
    radius: it sets the pupil sampling (:func:`pupil_samples`) and the geometric blur
    (:func:`psf_radius_um`)."""
    x = np.linspace(-1.0, 1.0, 257)
    rho, theta = np.hypot(x[None, :], x[:, None]), np.arctan2(x[:, None], x[None, :])
    gy, gx = np.gradient(wavefront_waves(coefficients, rho, theta), x, x)
    return float(np.max(np.hypot(gx, gy)[rho <= 1.0]))


PUPIL_MIN_SAMPLES = 128
PUPIL_MAX_SAMPLES = 512
PUPIL_SAMPLES_PER_SLOPE = 32
"""Pupil samples across the diameter per wave-per-radius of wavefront slope: the phase
moves by at most 1/16 wave between neighbouring samples, and the OTF table's step
(ν_c / samples) stays fine against the PSF's extent, so its cubic interpolation holds to
about 10⁻³. With no aberration 128 samples reproduce Goodman's OTF within 10⁻³."""


def pupil_samples(coefficients: tuple[tuple[int, float], ...], reference_nm: float, wavelength_nm: float) -> int:
    """Pupil samples across the diameter for these aberrations at ``wavelength_nm`` (even)."""
    slope = wavefront_slope(coefficients) * reference_nm / wavelength_nm
    return max(PUPIL_MIN_SAMPLES, 2 * math.ceil(PUPIL_SAMPLES_PER_SLOPE * slope / 2.0))


@functools.lru_cache(maxsize=128)  # 31 bands of a few cameras (a sweep goes scene by scene); ≤ 9 MB each
def pupil_otf_table(coefficients: tuple[tuple[int, float], ...], reference_nm: float,
                    wavelength_nm: float) -> tuple[np.ndarray, int]:
    """(OTF table, pupil samples n) of an aberrated circular pupil at ``wavelength_nm``.

    The pupil P = circ(ρ) exp(2πi W λ_ref / λ) is sampled at n points across its
    diameter; its autocorrelation (Goodman eq. 6-28), by FFT on an M ≥ 2n + 1 grid (no
    wrap-around), is normalised to 1 at zero lag. Table entry [M//2 + ky, M//2 + kx]
    holds the OTF at ν = (kx, ky) · ν_c / n, ν_c = 1 / (λ N): lags of whole pupil
    samples, up to ν_c at n. With PSF(u) = |F{P}|² and the FFT's e^{−2πi…} convention the
    OTF at shift s is Σ P(ξ) P*(ξ + s), the conjugate of numpy's autocorrelation.
    Read-only, complex64; cached (a camera's every capture needs the same bands).
    """
    n = pupil_samples(coefficients, reference_nm, wavelength_nm)
    x = (np.arange(n) + 0.5 - n / 2.0) * (2.0 / n)
    rho, theta = np.hypot(x[None, :], x[:, None]), np.arctan2(x[:, None], x[None, :])
    phase = (2.0 * np.pi * reference_nm / wavelength_nm) * wavefront_waves(coefficients, rho, theta)
    pupil = np.where(rho <= 1.0, np.exp(1j * phase), 0.0)
    size = sfft.next_fast_len(2 * n + 1)
    autocorrelation = np.conj(sfft.ifft2(np.abs(sfft.fft2(pupil, s=(size, size))) ** 2))
    table = sfft.fftshift(autocorrelation / autocorrelation[0, 0]).astype(np.complex64)
    table.setflags(write=False)
    return table, n


def _cubic_interpolation_matrix(position: np.ndarray, size: int) -> scipy.sparse.csr_matrix:
    """(len(position), size) sparse weights of Keys's cubic convolution (a = −1/2; Keys,
    IEEE Trans. ASSP 29, 1981) at fractional indices ``position``; taps outside the
    table are dropped (the OTF is zero there)."""
    p = np.asarray(position, float)
    i = np.floor(p).astype(np.int64)
    t = p - i
    t2, t3 = t * t, t * t * t
    taps = ((-1, (-t3 + 2 * t2 - t) / 2), (0, (3 * t3 - 5 * t2 + 2) / 2), (1, (-3 * t3 + 4 * t2 + t) / 2),
            (2, (t3 - t2) / 2))
    rows, cols, data = [], [], []
    for offset, weight in taps:
        col = i + offset
        ok = (col >= 0) & (col < size)
        rows.append(np.nonzero(ok)[0])
        cols.append(col[ok])
        data.append(weight[ok])
    return scipy.sparse.csr_matrix((np.concatenate(data), (np.concatenate(rows), np.concatenate(cols))),
                                   shape=(p.size, size))


def _pupil_otf(optics, wavelength_nm: float, fx: np.ndarray, fy: np.ndarray) -> np.ndarray:
    """The aberrated pupil's OTF on the grid fy × fx: its table, interpolated (separably)."""
    table, n = pupil_otf_table(optics.zernike_waves, float(optics.zernike_wavelength_nm), float(wavelength_nm))
    step = 1.0 / (wavelength_nm * 1e-6 * optics.f_number) / n  # cycles/mm per table entry
    centre = table.shape[0] // 2
    wy = _cubic_interpolation_matrix(fy / step + centre, table.shape[0])
    wx = _cubic_interpolation_matrix(fx / step + centre, table.shape[1])
    return np.ascontiguousarray((wx @ (wy @ table).T).T)


# ── measured lenses: PSF and MTF tables ─────────────────────────────────────────────────

PSF_COLUMNS = ("wavelength_nm", "x_um", "y_um", "psf")
MTF_COLUMNS = ("wavelength_nm", "frequency_cy_per_mm", "mtf")


@dataclass(frozen=True)
class PSFTable:
    """A measured PSF per wavelength: ``psf[k]`` (len(y_um[k]), len(x_um[k])) sums to 1, on
    the sample positions ``x_um[k]`` (along the columns) and ``y_um[k]`` (along the rows,
    downwards), relative to the ideal image point."""

    wavelengths_nm: np.ndarray
    x_um: tuple[np.ndarray, ...]
    y_um: tuple[np.ndarray, ...]
    psf: tuple[np.ndarray, ...]

    @property
    def spacing_um(self) -> float:
        """The coarsest sample spacing of any wavelength's grid, µm (0 for single points)."""
        steps = [float(np.max(np.diff(a))) for a in (*self.x_um, *self.y_um) if a.size > 1]
        return max(steps, default=0.0)

    @property
    def radius_um(self) -> float:
        """The farthest sample from the ideal image point, plus half a spacing, µm."""
        far = max(max(abs(float(x[0])), abs(float(x[-1])), abs(float(y[0])), abs(float(y[-1])))
                  for x, y in zip(self.x_um, self.y_um))
        return far + self.spacing_um / 2.0


@dataclass(frozen=True)
class MTFTable:
    """A measured MTF per wavelength (rotationally symmetric lens, zero phase): ``mtf[k]``
    at ``frequency_cy_per_mm[k]``, from frequency 0 (MTF 1); zero beyond the last."""

    wavelengths_nm: np.ndarray
    frequency_cy_per_mm: tuple[np.ndarray, ...]
    mtf: tuple[np.ndarray, ...]

    def first_frequency_below(self, level: float) -> float:
        """The lowest frequency, over wavelengths, where the MTF first falls to ``level``
        (a curve that does not: its last frequency), cycles/mm."""
        out = []
        for f, m in zip(self.frequency_cy_per_mm, self.mtf):
            below = np.nonzero(m <= level)[0]
            out.append(float(f[below[0]]) if below.size else float(f[-1]))
        return min(out)


@functools.lru_cache(maxsize=8)
def read_psf_table(path: str) -> PSFTable:
    """A PSF table (columns ``wavelength_nm, x_um, y_um, psf``: one row per sample, rows
    grouped by wavelength in increasing order; each wavelength's samples a full, evenly
    spaced grid, any row order within it; psf ≥ 0, normalised here to sum 1), refused in one
    line naming the file, the row or wavelength and the column where it is not. Cached."""
    what, name = "PSF table", Path(path).name
    cols = read_numeric_csv(path, what, PSF_COLUMNS, expected=", ".join(PSF_COLUMNS))
    wl = cols["wavelength_nm"]
    if wl.size < 1:
        raise ValueError(f"{what} {name}: no rows")
    check_wavelengths_nm(wl, what, name)
    negative = np.nonzero(cols["psf"] < 0)[0]
    if negative.size:
        raise ValueError(f"{what} {name}: row {negative[0] + 1} psf is {cols['psf'][negative[0]]:g}: "
                         "a PSF is not negative")
    waves, xs, ys, psfs = [], [], [], []
    for rows in wavelength_groups(wl, what, name):
        at = f"{what} {name}: wavelength {wl[rows.start]:g} nm"
        x, y, value = cols["x_um"][rows], cols["y_um"][rows], cols["psf"][rows]
        ux, ix = np.unique(x, return_inverse=True)
        uy, iy = np.unique(y, return_inverse=True)
        flat = iy * ux.size + ix
        if value.size != ux.size * uy.size or np.unique(flat).size != value.size:
            raise ValueError(f"{at}: x_um, y_um do not form a full grid ({value.size} rows for {ux.size} x "
                             f"{uy.size} positions, each once)")
        for axis, u in (("x_um", ux), ("y_um", uy)):
            steps = np.diff(u)
            if steps.size and np.ptp(steps) > 1e-4 * steps.max():
                raise ValueError(f"{at}: {axis} is not evenly spaced (steps {steps.min():g} to {steps.max():g} um)")
        grid = np.zeros((uy.size, ux.size))
        grid.ravel()[flat] = value
        if grid.sum() <= 0:
            raise ValueError(f"{at}: the PSF sums to 0")
        waves.append(float(wl[rows.start]))
        xs.append(ux)
        ys.append(uy)
        psfs.append(grid / grid.sum())
    return PSFTable(np.array(waves), tuple(xs), tuple(ys), tuple(psfs))


@functools.lru_cache(maxsize=8)
def read_mtf_table(path: str) -> MTFTable:
    """An MTF table (columns ``wavelength_nm, frequency_cy_per_mm, mtf``: rows grouped by
    wavelength in increasing order; within a wavelength two or more rows, frequency
    increasing from 0, where mtf is 1; 0 ≤ mtf ≤ 1), refused in one line naming the file,
    the row and the column where it is not. Cached."""
    what, name = "MTF table", Path(path).name
    cols = read_numeric_csv(path, what, MTF_COLUMNS, expected=", ".join(MTF_COLUMNS))
    wl, freq, mtf = cols["wavelength_nm"], cols["frequency_cy_per_mm"], cols["mtf"]
    if wl.size < 2:
        raise ValueError(f"{what} {name}: {wl.size} row(s); two or more frequencies per wavelength are needed")
    check_wavelengths_nm(wl, what, name)
    outside = np.nonzero((mtf < 0) | (mtf > 1))[0]
    if outside.size:
        i = outside[0]
        raise ValueError(f"{what} {name}: row {i + 1} mtf is {mtf[i]:g}: an MTF lies between 0 and 1")
    waves, freqs, mtfs = [], [], []
    for rows in wavelength_groups(wl, what, name):
        at = f"{what} {name}: wavelength {wl[rows.start]:g} nm"
        f, m = freq[rows], mtf[rows]
        if f.size < 2:
            raise ValueError(f"{at}: {f.size} row(s); two or more frequencies are needed")
        if f[0] != 0.0:
            raise ValueError(f"{at}: starts at {f[0]:g} cy/mm; each wavelength starts at frequency 0 (mtf 1)")
        if abs(m[0] - 1.0) > 1e-3:
            raise ValueError(f"{at}: mtf at frequency 0 is {m[0]:g}, not 1 (an MTF is normalised at zero frequency)")
        step = np.nonzero(np.diff(f) <= 0)[0]
        if step.size:
            i = rows.start + step[0]
            raise ValueError(f"{what} {name}: frequency_cy_per_mm must increase within a wavelength: row {i + 2} "
                             f"({freq[i + 1]:g}) follows row {i + 1} ({freq[i]:g})")
        waves.append(float(wl[rows.start]))
        freqs.append(f)
        mtfs.append(m)
    return MTFTable(np.array(waves), tuple(freqs), tuple(mtfs))


def _wavelength_weights(table_nm: np.ndarray, wavelength_nm: float) -> list[tuple[int, float]]:
    """(table index, weight) pairs that interpolate a table linearly in wavelength; held
    at its first and last wavelength beyond them."""
    k = int(np.searchsorted(table_nm, wavelength_nm))
    if k == 0:
        return [(0, 1.0)]
    if k == table_nm.size:
        return [(table_nm.size - 1, 1.0)]
    t = (wavelength_nm - table_nm[k - 1]) / (table_nm[k] - table_nm[k - 1])
    return [(k - 1, 1.0 - t), (k, t)]


def _psf_table_otf(table: PSFTable, wavelength_nm: float, fx: np.ndarray, fy: np.ndarray) -> np.ndarray:
    """OTF of a PSF table on the grid fy × fx: the exact Fourier sum of each tabulated PSF,
    Σ psf(x, y) e^{−2πi (fx x + fy y)} (separable), interpolated linearly in wavelength."""
    out = np.zeros((fy.size, fx.size), complex)
    for k, weight in _wavelength_weights(table.wavelengths_nm, wavelength_nm):
        ex = np.exp(-2j * np.pi * np.outer(table.x_um[k] * 1e-3, fx))
        ey = np.exp(-2j * np.pi * np.outer(fy, table.y_um[k] * 1e-3))
        out += weight * (ey @ (table.psf[k] @ ex))
    return out


def _mtf_table_otf(table: MTFTable, wavelength_nm: float, rho: np.ndarray) -> np.ndarray:
    """OTF of an MTF table at radial frequencies ``rho``: each curve interpolated linearly
    (zero beyond its last frequency), then linearly in wavelength."""
    return sum(weight * np.interp(rho, table.frequency_cy_per_mm[k], table.mtf[k], right=0.0)
               for k, weight in _wavelength_weights(table.wavelengths_nm, wavelength_nm))


# ── veiling glare ───────────────────────────────────────────────────────────────────────


def glare_scale_mm(focal_length_mm: float, glare_angle_deg: float) -> float:
    """r₀ = f · tan θ₀: the glare spread function's scale on the sensor, mm."""
    return focal_length_mm * math.tan(math.radians(glare_angle_deg))


def glare_spread_function(r_mm: np.ndarray, scale_mm: float) -> np.ndarray:
    """G(r) = (1 / 2π r₀²) (1 + r² / r₀²)^(−3/2), per mm²: unit energy over the plane, a
    1/r³ tail. The form of the terms of the CIE 146:2002 general disability glare
    equation (``a / (1 + (θ/θ₀)²)^1.5``, θ the angle from the source), as a camera's
    glare spread function (docs/camera.md, "The lens")."""
    return (1.0 / (2.0 * np.pi * scale_mm**2)) * (1.0 + (np.asarray(r_mm, float) / scale_mm) ** 2) ** -1.5


def glare_otf(freq_cy_per_mm: np.ndarray, scale_mm: float) -> np.ndarray:
    """The 2-D Fourier transform of :func:`glare_spread_function`, exp(−2π r₀ ν): the
    Poisson kernel's (Stein & Weiss, *Introduction to Fourier Analysis on Euclidean
    Spaces*, 1971, ch. I). 1 at ν = 0: the glare moves light, it neither adds
    nor removes any."""
    return np.exp(-2.0 * np.pi * scale_mm * np.abs(np.asarray(freq_cy_per_mm, float)))


def glare_factor(optics, freq_cy_per_mm: np.ndarray) -> np.ndarray:
    """(1 − g) + g · exp(−2π r₀ ν): what veiling glare (fraction g) multiplies the OTF by."""
    g = optics.veiling_glare_fraction
    return (1.0 - g) + g * glare_otf(freq_cy_per_mm, glare_scale_mm(optics.focal_length_mm, optics.glare_angle_deg))


# ── the one function ────────────────────────────────────────────────────────────────────


def otf_is_radial(optics) -> bool:
    """Whether the lens's OTF is real and rotationally symmetric: no PSF table, and every
    Zernike term rotationally symmetric (m = 0: defocus, spherical …). Then the OTF at
    (fx, fy) equals that at (fx, −fy), which the fast path uses."""
    return optics.psf_table is None and all(zernike_order(j)[1] == 0 for j, _ in optics.zernike_waves)


def lens_otf(optics, wavelength_nm: float, fx_cy_per_mm: np.ndarray, fy_cy_per_mm: np.ndarray, *,
             glare: bool = True) -> np.ndarray:
    """The lens's OTF at ``wavelength_nm`` on the frequency grid fy × fx (cycles/mm on the
    sensor; 1-D ``fx`` along the columns, ``fy`` along the rows): (len(fy), len(fx)),
    float64 where :func:`otf_is_radial`, else complex128.

    The pupil's or measured table's OTF (module docstring), times the veiling glare's
    factor where the lens has glare and ``glare`` is on (the camera's fast path applies
    the glare once per channel instead: it does not depend on the wavelength).
    """
    fx = np.asarray(fx_cy_per_mm, float).reshape(-1)
    fy = np.asarray(fy_cy_per_mm, float).reshape(-1)
    rho = np.hypot(fx[None, :], fy[:, None])
    if optics.psf_table is not None:
        otf = _psf_table_otf(read_psf_table(str(optics.psf_table_path)), wavelength_nm, fx, fy)
    elif optics.mtf_table is not None:
        otf = _mtf_table_otf(read_mtf_table(str(optics.mtf_table_path)), wavelength_nm, rho)
    elif optics.zernike_waves:
        otf = _pupil_otf(optics, wavelength_nm, fx, fy)
        if otf_is_radial(optics):
            otf = otf.real
    else:
        otf = diffraction_otf(rho, wavelength_nm, optics.f_number)
    if glare and optics.veiling_glare_fraction > 0.0:
        otf = otf * glare_factor(optics, rho)
    return otf


def psf_radius_um(optics, wavelengths_nm) -> float:
    """The radius, µm, that holds the lens's PSF (veiling glare aside) at these
    wavelengths: what the image is padded by before its FFT.

    Ideal pupil: 8 Airy radii of the longest wavelength. Aberrated pupil: that plus the
    geometric blur, the largest transverse ray aberration 2 N λ_ref · max|∇W| (W in
    waves per pupil radius; the ray leaves the pupil edge at 1 / 2N). PSF table: its
    extent. MTF table: 8 / ν₁₀, ν₁₀ the first frequency where the MTF falls to 0.1
    (8 Airy radii for a diffraction-limited curve, whose ν₁₀ is 0.82 ν_c)."""
    longest = float(np.max(wavelengths_nm))
    if optics.psf_table is not None:
        return read_psf_table(str(optics.psf_table_path)).radius_um
    if optics.mtf_table is not None:
        return 8.0 / read_mtf_table(str(optics.mtf_table_path)).first_frequency_below(0.1) * 1e3
    radius = diffraction_psf_radius_um(longest, optics.f_number)
    if optics.zernike_waves:
        radius += 2.0 * optics.f_number * optics.zernike_wavelength_nm * 1e-3 * wavefront_slope(optics.zernike_waves)
    return radius
