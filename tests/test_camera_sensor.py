"""The sensor model: photon transfer (EMVA 1288 style) and seeded noise."""

import numpy as np

from benchmark.camera import sensor as S
from benchmark.camera.pipeline import simulate
from benchmark.camera import load_camera
from metricscenes.radiance import SpectralScene

SPEC = load_camera("cam10").sensor
K_SPEC = S.signal_volts_per_electron(SPEC) / SPEC.lsb_v  # DN per electron: 0.1705 × analog gain 4.91
SATURATION_E = S.saturation_electrons(SPEC)


def _pair(mean_e, seed, shape=(200, 200)):
    rate = np.full(shape, mean_e, dtype=np.float32)  # e-/s, exposed for 1 s
    a = S.capture_dn(rate, 1.0, SPEC, np.random.default_rng([seed, 0])).astype(float)
    b = S.capture_dn(rate, 1.0, SPEC, np.random.default_rng([seed, 1])).astype(float)
    return a, b


def test_photon_transfer_recovers_gain_read_noise_and_full_well():
    levels_e = SATURATION_E * np.concatenate([np.linspace(0, 0.8, 16), np.linspace(0.84, 1.16, 12)])  # 28 levels
    mean_dn, var_dn = [], []
    for i, level in enumerate(levels_e):
        a, b = _pair(level, i)
        mean_dn.append(0.5 * (a.mean() + b.mean()))
        var_dn.append(np.var(a - b) / 2.0)  # frame difference: fixed pattern (PRNU) cancels
    mean_dn, var_dn = np.array(mean_dn), np.array(var_dn)
    dark_mean, dark_var = mean_dn[0], var_dn[0]
    # EMVA 1288: K from the slope of var vs mean in the linear range (below 70 % of saturation)
    linear = (mean_dn - dark_mean) < 0.7 * (mean_dn.max() - dark_mean)
    k_dn_per_e = np.polyfit(mean_dn[linear] - dark_mean, var_dn[linear] - dark_var, 1)[0]
    read_noise_e = np.sqrt(dark_var - 1.0 / 12.0) / k_dn_per_e  # less quantisation noise
    # full well: the ceiling of the mean signal (all pixels clipped), in electrons
    full_well_e = (mean_dn.max() - dark_mean) / k_dn_per_e
    # EMVA saturation capacity (variance peak) sits a few shot-noise σ below the ceiling
    saturation_e = (mean_dn[np.argmax(var_dn)] - dark_mean) / k_dn_per_e
    assert abs(k_dn_per_e / K_SPEC - 1) < 0.03
    assert abs(read_noise_e / SPEC.read_noise_e - 1) < 0.03
    assert abs(full_well_e / S.saturation_electrons(SPEC) - 1) < 0.03
    assert 0 < S.saturation_electrons(SPEC) - saturation_e < 4 * np.sqrt(S.saturation_electrons(SPEC))
    assert abs(dark_mean - SPEC.black_level_dn) < 0.05


def test_saturation_is_the_well_less_the_black_level_headroom():
    assert abs(SATURATION_E - (1023 - 64) / K_SPEC) < 1e-6
    assert abs(SATURATION_E - 1146.0) < 1.0  # ISO 270: the ADC, not the 6000 e⁻ well, sets the ceiling
    assert S.capture_dn(np.full((4, 4), 1e9, np.float32), 1.0, SPEC, np.random.default_rng(0)).max() == 1023


def test_prnu_is_a_fixed_pattern_of_the_sensor():
    rate = np.full((300, 300), 0.5 * SATURATION_E, dtype=np.float32)
    off = S.NoiseOptions(shot=False, read=False)
    a = S.capture_volts(rate, 1.0, SPEC, None, off)
    b = S.capture_volts(rate, 1.0, SPEC, None, off)
    np.testing.assert_array_equal(a, b)
    signal = a - SPEC.black_level_dn * SPEC.lsb_v
    assert abs(signal.std() / signal.mean() - SPEC.prnu_fraction) < 0.001


def test_seeded_noise():
    cam = load_camera("cam01")
    scene = SpectralScene.uniform(np.full(31, 0.01))
    a = simulate(scene, cam, seed=7)
    b = simulate(scene, cam, seed=7)
    c = simulate(scene, cam, seed=8)
    assert a.raw_dn.dtype == np.uint16 and a.raw_dn.shape == (360, 640)
    np.testing.assert_array_equal(a.raw_dn, b.raw_dn)
    np.testing.assert_array_equal(a.rgb8, b.rgb8)
    assert np.mean(a.raw_dn != c.raw_dn) > 0.5
    quiet = simulate(scene, cam, seed=7, noise=False)
    assert np.ptp(quiet.raw_dn[0::2, 0::2]) == 0  # noise off: a flat field stays flat


def test_every_noise_source_switches():
    rate = np.full((100, 100), 0.4 * SATURATION_E, dtype=np.float32)
    base = S.capture_volts(rate, 1.0, SPEC, np.random.default_rng(1), S.NoiseOptions.off())
    assert np.ptp(base) == 0
    for field in ("shot", "read", "prnu"):
        opts = S.NoiseOptions(**{f: f == field for f in ("shot", "read", "dark", "prnu", "dsnu")})
        assert np.ptp(S.capture_volts(rate, 1.0, SPEC, np.random.default_rng(1), opts)) > 0, field
