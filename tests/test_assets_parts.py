import numpy as np
import pytest

from metricscenes.assets.parts import spectrum


def _table(d):
    return (np.array(d["wavelengths"].split(","), float), np.array(d["values"].split(","), float))


def test_spectrum_is_held_out_to_the_end_bands():
    wl, val = _table(spectrum([400, 550, 700], [0.2, 0.5, 0.8]))
    # The 400 and 700 nm bands integrate 395-405 and 695-705 nm: the table must reach past them.
    assert wl[0] <= 395 and wl[-1] >= 705
    assert np.interp(397, wl, val) == pytest.approx(0.2) and np.interp(703, wl, val) == pytest.approx(0.8)
    wide_wl, _ = _table(spectrum([350, 800], [1, 1]))
    np.testing.assert_array_equal(wide_wl, [350, 800])
    band_wl, _ = _table(spectrum([395, 405], [0.1, 0.1], hold_ends=False))  # a film band stays a band
    np.testing.assert_array_equal(band_wl, [395, 405])


def test_end_band_radiance_is_not_halved():
    from metricscenes.render import Film, render_radiance, sensor_dict, use_variant

    mi = use_variant()
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": 2},
             "sensor": sensor_dict(Film(8, 8), spp=256, seed=0),
             "sky": {"type": "constant", "radiance": {"type": "uniform", "value": 1.0}},
             "wall": {"type": "rectangle", "to_world": mi.ScalarTransform4f().look_at([5, 0, 1.5], [0, 0, 1.5], [0, 0, 1]).scale(50),
                      "bsdf": {"type": "diffuse", "reflectance": spectrum([400, 700], [0.5, 0.5])}}}
    cube = render_radiance(scene, 256)
    # A furnace: L = rho * 1 in every band, the end bands included (they were halved).
    np.testing.assert_allclose(cube.mean(axis=(0, 1)), 0.5, rtol=0.05)
