"""benchmark.measure.render_noise's statistics on synthetic captures: noise of known size must
come out as that size, whatever the signal's texture."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.measure import render_noise


def textured_mean(shape=(256, 384), seed=0) -> np.ndarray:
    """Mean electrons from 30 to 900 with edges and a gradient (texture is not noise)."""
    rows, cols = np.indices(shape)
    mean = 30.0 + 870.0 * cols / shape[1]
    mean[(rows // 40 + cols // 40) % 2 == 0] *= 0.5
    return mean


def test_two_poisson_draws_have_ratio_one():
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


def test_noise_of_known_fraction_of_shot_noise():
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


def test_fitted_convergence():
    alpha, spp = render_noise.fitted_spp([(16, 0.5), (64, 0.25)])
    assert alpha == pytest.approx(0.5)
    assert spp == pytest.approx(36)  # 0.5 at 16 spp, falling as 1/sqrt(spp): 1/3 at 36
    alpha, spp = render_noise.fitted_spp([(16, 0.4), (64, 0.4 / 4**0.75)])
    assert alpha == pytest.approx(0.75)
    assert spp == pytest.approx(16 * (0.4 * 3) ** (1 / 0.75))



def test_used_pixels_leave_out_saturated_and_dark():
    e_a = np.array([[10.0, 500.0, 2000.0, 3.0]])
    e_b = np.array([[12.0, 480.0, 900.0, 40.0]])
    used, left_out = render_noise.used_pixels(e_a, e_b, saturation_e=1000.0, dark_e=25.0)
    assert used.tolist() == [[False, True, False, False]]  # dark (11 e-), used, saturated in A, dark on average
    assert left_out == {"saturated": 0.25, "dark": 0.5}


def _small_camera():
    """cam12 with 4x its pixel pitch (480 x 270): quick to simulate."""
    import yaml

    from benchmark.camera.registry import DATA_DIR, camera_from_dict

    data = yaml.safe_load((DATA_DIR / "cam12.yaml").read_text())
    data["sensor"].update(pixel_um=5.6)
    data.update(name="cam12-5.6um", mtf50_group_cy_per_mm=None)
    return camera_from_dict(data)


def test_capture_pair_captures_b_at_as_exposure():
    from metricscenes.geometry import REFERENCE_EXTENT
    from metricscenes.radiance import RadianceLayer, SpectralScene

    camera = _small_camera()
    rng = np.random.default_rng(4)
    radiance = rng.uniform(0.002, 0.02, (54, 96, 31)).astype(np.float32)
    scene_a, brighter = (SpectralScene(layers=(RadianceLayer(r, REFERENCE_EXTENT),)) for r in (radiance, 2 * radiance))
    e_a, e_b, exposure_s, own_b = render_noise.capture_pair(scene_a, scene_a, camera)
    np.testing.assert_array_equal(e_a, e_b)
    assert own_b == pytest.approx(exposure_s, rel=1e-6) and 0 < exposure_s <= camera.exposure.max_exposure_s
    e_a, e_b, exposure_s, own_b = render_noise.capture_pair(scene_a, brighter, camera)
    np.testing.assert_allclose(e_b, 2 * e_a, rtol=1e-4, atol=1e-3)  # same exposure: twice the light, twice the signal
    assert own_b < exposure_s  # its own policy would have exposed it shorter
    hdr = camera.model_copy(update={"exposure": camera.exposure.model_copy(update={"mode": "hdr"})})
    with pytest.raises(ValueError, match="hdr policy takes two exposures"):
        render_noise.capture_pair(scene_a, scene_a, hdr)
