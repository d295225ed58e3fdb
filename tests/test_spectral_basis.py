"""benchmarks/spectral_basis.py's estimates on synthetic spectra of known rank and noise:
a basis that spans the signal loses nothing, one that is too small loses what is left out,
and the estimate separates that loss from the noise the projection removes."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture(scope="module")
def spectral_basis(load_benchmark):
    return load_benchmark("spectral_basis")


def rank3_pair(noise: float, seed: int = 0, shape=(64, 96)):
    """Two renders of one scene whose spectra span three smooth spectra, with independent
    white noise of relative size ``noise`` per band (shape: multiples of 16)."""
    rng = np.random.default_rng(seed)
    wavelengths = np.linspace(0.0, 1.0, 31)
    spectra = np.stack([np.ones(31), wavelengths, np.sin(3 * wavelengths)])  # (3, 31)
    # Constant over 16 x 16-pixel tiles, as surfaces are (the blocks-norm basis learns from 8 x 8 means).
    tiles = rng.uniform(0.5, 2.0, (shape[0] // 16, shape[1] // 16, 3)) * np.array([1.0, 0.6, 0.4])
    weights = tiles.repeat(16, axis=0).repeat(16, axis=1)
    truth = (weights @ spectra).astype(np.float32)
    return tuple((truth * (1 + noise * rng.standard_normal(truth.shape))).astype(np.float32) for _ in range(2))


def test_basis_is_orthonormal(spectral_basis):
    a, _ = rank3_pair(0.2)
    for weighting in ("norm", "energy", "blocks-norm"):
        v = spectral_basis.basis(a, 5, weighting)
        assert v.shape == (31, 5)
        np.testing.assert_allclose(v.T @ v, np.eye(5), atol=1e-10)


def test_a_basis_that_spans_the_signal_loses_nothing_and_a_small_one_does(spectral_basis):
    a, b = rank3_pair(0.2)
    losses = {k: spectral_basis.basis_loss(a, b, k, "blocks-norm") for k in (1, 2, 3)}
    bias, nearer, kept = losses[3]
    assert bias < 0.1  # none lost (the estimate is a difference of noisy sums)
    # White noise: the projection drops 28 of 31 directions of it, so P A is nearer the
    # truth than A, and Y keeps less noise.
    assert nearer < 0.95 and kept < 0.95
    assert losses[1][0] > losses[2][0] > 0.3  # one or two of the three spectra left out


def test_the_held_spectra_to_compare(spectral_basis):
    from metricscenes import spectral_basis as store_basis
    from metricscenes.spectral import WAVELENGTHS_NM

    w = np.asarray(WAVELENGTHS_NM, float)
    np.testing.assert_array_equal(spectral_basis.held_spectra(w, "imx363+y"), store_basis.held_spectra(w))
    xyz = spectral_basis.held_spectra(w, "xyz")
    assert xyz.shape == (31, 3) and np.argmax(xyz[:, 1]) == list(w).index(560.0)  # y-bar peaks at 555 nm
    assert spectral_basis.held_spectra(w, "none").shape == (31, 0)
    a, _ = rank3_pair(0.2)
    v = store_basis.basis_for(a, 3, spectral_basis.held_spectra(w, "none"))  # principal spectra alone
    np.testing.assert_allclose(v.T @ v, np.eye(3), atol=1e-10)


def test_the_held_basis_completes_with_the_data_and_stores_fewer_bytes(spectral_basis):
    from metricscenes.spectral import WAVELENGTHS_NM
    from metricscenes.spectral_basis import basis_for

    held = spectral_basis.held_spectra(np.asarray(WAVELENGTHS_NM, float))
    a, _ = rank3_pair(0.0)
    v = basis_for(a, 7, held)  # 4 held + 3: the data's span is then inside
    back, coefficient_bytes, band_bytes = spectral_basis.stored_projection(a, v, None)
    np.testing.assert_allclose(back, a, rtol=1e-5, atol=1e-6 * a.max())
    noisy, _ = rank3_pair(0.2)  # incompressible mantissas: bytes in proportion to the values kept
    _, coefficient_bytes, band_bytes = spectral_basis.stored_projection(noisy, v, None)
    assert 0.8 * 7 / 31 < coefficient_bytes / band_bytes < 1.2 * 7 / 31
    rounded, _, _ = spectral_basis.stored_projection(a, v, 8)
    assert 0 < np.abs(rounded - a).max() < 2**-6 * np.abs(a).max()
