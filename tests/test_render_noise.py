"""benchmarks/render_noise.py's statistics on synthetic captures: noise of known size must
come out as that size, whatever the signal's texture."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture(scope="module")
def render_noise(load_benchmark):
    return load_benchmark("render_noise")


def textured_mean(shape=(256, 384), seed=0) -> np.ndarray:
    """Mean electrons from 30 to 900 with edges and a gradient (texture is not noise)."""
    rows, cols = np.indices(shape)
    mean = 30.0 + 870.0 * cols / shape[1]
    mean[(rows // 40 + cols // 40) % 2 == 0] *= 0.5
    return mean


def test_two_poisson_draws_have_ratio_one(render_noise):
    # Two independent Poisson draws of the same mean: each differs from the mean by exactly
    # shot noise, so "render noise" over shot noise is 1, overall and in every window.
    rng = np.random.default_rng(1)
    mean = textured_mean()
    a, b = rng.poisson(mean).astype(np.float32), rng.poisson(mean).astype(np.float32)
    stats = render_noise.pooled_ratio(a, b, np.ones(mean.shape, bool), window=32)
    assert stats["overall"] == pytest.approx(1.0, abs=0.01)
    assert stats["median"] == pytest.approx(1.0, abs=0.03)
    assert stats["windows"] == (256 // 32) * (384 // 32)
    assert stats["used"] == 1.0


def test_noise_of_known_fraction_of_shot_noise(render_noise):
    # Renders whose noise is k times the shot noise of their mean, left-out pixels ignored.
    rng = np.random.default_rng(2)
    mean = textured_mean()
    k = 0.25
    a, b = (mean + k * np.sqrt(mean) * rng.standard_normal(mean.shape) for _ in range(2))
    used = np.ones(mean.shape, bool)
    used[:, :50] = False
    a[:, :50] += 1e4  # huge differences where not used: must not count
    stats = render_noise.pooled_ratio(a, b, used, window=16)
    assert stats["overall"] == pytest.approx(k, rel=0.02)
    assert stats["median"] == pytest.approx(k, rel=0.05)
    assert stats["above"] == 0.0  # 0.25 < 1/3 in every window
    assert stats["used"] == pytest.approx(1 - 50 / 384)
    # 1/sqrt(spp): at k = 1/3 the spp is the spp rendered; at k/2, a quarter of it.
    assert render_noise.spp_needed(16, 1 / 3) == pytest.approx(16)
    assert render_noise.spp_needed(64, 1 / 6) == pytest.approx(16)


def test_fitted_convergence(render_noise):
    alpha, spp = render_noise.fitted_spp([(16, 0.5), (64, 0.25)])
    assert alpha == pytest.approx(0.5)
    assert spp == pytest.approx(36)  # 0.5 at 16 spp, falling as 1/sqrt(spp): 1/3 at 36
    alpha, spp = render_noise.fitted_spp([(16, 0.4), (64, 0.4 / 4**0.75)])
    assert alpha == pytest.approx(0.75)
    assert spp == pytest.approx(16 * (0.4 * 3) ** (1 / 0.75))


def test_collection_check_compares_render_a_as_the_store_writes_it(render_noise, tmp_path):
    """On a lossy store (quick: BitRound 8, an 8-spectra basis) render A is the collection's
    array once written as its store writes it (the manifest rendered has no store); another
    render is not; other render settings are n/a."""
    from types import SimpleNamespace

    from conftest import REPO
    from store_codecs import Renders

    from metricscenes.geometry import TanExtent
    from metricscenes.manifest import load_manifest
    from metricscenes.writer import UnitArrays

    quick = load_manifest(REPO / "manifests" / "quick.yaml")
    rng = np.random.default_rng(0)
    cube = rng.gamma(2.0, 0.01, size=(24, 32, 31)).astype(np.float32)
    extent = TanExtent(-0.1, -0.05, 0.1, 0.05)
    arrays = UnitArrays(tmp_path, "env000", quick.store.mantissa_bits, quick.store.spectral_basis)
    arrays.write_radiance("plates", "sky_day", cube, extent)
    collection = SimpleNamespace(manifest=quick, resolved=SimpleNamespace(arrays=arrays.sha256))
    layers = {"plate": {path: Renders(cube, cube, extent) for path in arrays.sha256}}
    rendered = quick.model_copy(update={"store": None})
    assert render_noise.collection_check(collection, rendered, layers) == "yes"

    other = cube.copy()
    other[0, 0, 0] *= 1.5
    assert render_noise.collection_check(collection, rendered, {"plate": {p: Renders(other, cube, extent)
                                                                          for p in arrays.sha256}}) == "NO"
    finer = rendered.model_copy(update={"render": rendered.render.model_copy(update={"plate_spp": 64})})
    assert render_noise.collection_check(collection, finer, layers) == "n/a"
