"""A spectral basis per radiance array that holds a camera's channels exactly
(``store: {spectral_basis: K}``).

An array's spectra (rows, cols, 31) are stored as K coefficients per pixel on K orthonormal
basis spectra, kept with the array: K/31 of the values (ISETCam's hypercube basis,
``hcBasis``). What a projection loses must not be what a camera sees, so the basis's span
holds :func:`held_spectra` exactly: the R, G and B responsivities of the Sony IMX363 (its
colour-filter QE x IR cut, per photon: x lambda; every camera of the benchmark has it) and
CIE 1931 y-bar. A pixel's signal in each of those channels, and its luminance, are then the
rendered ones (to the store's rounding), and so is their render noise, which Mitsuba's
stratified wavelengths make smaller than the sum of its bands' (a basis of principal spectra
alone undoes that). The other K - 4 spectra are the leading principal directions of the
array's 8 x 8-pixel means, each spectrum scaled to unit length, once the held span is taken
out: the spectral shapes the scene has beyond what the channels see, which the lens's blur
per band can still tell apart.

Measured (benchmarks/studies/spectral_basis.py ``--held``; docs/performance.md, "A spectral basis per
array"): with K = 8, noise-free captures of a scene stored through the basis differ from the
render's by 1-8 % of the render's own noise for cam12, cam01 and cam08, day and night, and
the array takes about 0.3 of the bytes. A sensor with other channels is not held: with
CIE x-bar, y-bar, z-bar held instead, the same cameras see up to about 40 % of the render
noise.
"""

from __future__ import annotations

import numpy as np

from metricscenes.spectral import SENSOR_DATA_DIR, WAVELENGTHS_NM, resample_spectrum

HELD_SENSOR = "imx363_qe.csv"
"""The sensor whose R, G, B channels a basis holds (in :data:`~metricscenes.spectral.SENSOR_DATA_DIR`)."""
BLOCK_PX = 8
"""Principal spectra are learnt from the means of BLOCK_PX x BLOCK_PX pixels: the render's
noise averaged down by BLOCK_PX, the scene's spectra kept."""
DIMENSION = "basis"
"""The third dimension's name of an array stored through a basis (``y, x, basis``)."""


def held_spectra(wavelengths_nm: np.ndarray = WAVELENGTHS_NM) -> np.ndarray:
    """(bands, 4): the IMX363's R, G, B responsivities per unit spectral irradiance (QE x IR
    cut x lambda, photons per joule up to a constant) and CIE 1931 2-degree y-bar."""
    import colour

    table = np.genfromtxt(SENSOR_DATA_DIR / HELD_SENSOR, delimiter=",", names=True)
    ir_cut = table["ir_cut_transmittance"] if "ir_cut_transmittance" in table.dtype.names else 1.0
    channels = [resample_spectrum(table["wavelength_nm"], table[f"qe_{c}"] * ir_cut, wavelengths_nm) * wavelengths_nm
                for c in "rgb"]
    ybar = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].signals["y_bar"]
    return np.column_stack([*channels, ybar[np.asarray(wavelengths_nm, float)]])


def basis_for(cube: np.ndarray, rank: int, held: np.ndarray | None = None) -> np.ndarray:
    """(bands, rank) orthonormal spectra for ``cube`` (rows, cols, bands) whose span holds
    ``held`` (default :func:`held_spectra`), completed by the cube's principal spectra."""
    held = held_spectra() if held is None else held
    q, _ = np.linalg.qr(np.asarray(held, np.float64))
    if not q.shape[1] < rank <= cube.shape[-1]:
        raise ValueError(f"store.spectral_basis: {rank} must exceed the {q.shape[1]} held spectra "
                         f"and be at most the {cube.shape[-1]} bands")
    if min(cube.shape[:2]) >= BLOCK_PX:  # block means (an array smaller than a block: its pixels)
        rows, cols = (n // BLOCK_PX for n in cube.shape[:2])
        cube = cube[: rows * BLOCK_PX, : cols * BLOCK_PX].astype(np.float64)
        cube = cube.reshape(rows, BLOCK_PX, cols, BLOCK_PX, -1).mean(axis=(1, 3))
    x = cube.reshape(-1, cube.shape[-1]).astype(np.float64)
    length = np.linalg.norm(x, axis=1)
    lit = length > 1e-6 * length.max() if length.size and length.max() > 0 else np.zeros(len(x), bool)
    shapes = x[lit] / length[lit, None]
    rest = shapes - (shapes @ q) @ q.T
    _, vectors = np.linalg.eigh(rest.T @ rest)
    completion = vectors[:, ::-1][:, : rank - q.shape[1]]
    completion -= q @ (q.T @ completion)  # exactly outside the held span (eigh's round-off)
    return np.linalg.qr(np.hstack([q, completion]))[0]


def encode(cube: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """float32 coefficients (rows, cols, K) of ``cube`` on the orthonormal ``basis`` (bands, K)."""
    return np.ascontiguousarray(np.asarray(cube, np.float64) @ basis, dtype=np.float32)


def decode(coefficients: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """The float32 radiance (rows, cols, bands) a reader gets back from coefficients and basis."""
    return np.ascontiguousarray(np.asarray(coefficients, np.float64) @ np.asarray(basis, np.float64).T,
                                dtype=np.float32)
