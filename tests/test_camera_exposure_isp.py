"""Exposure policies and the ISP's neutrality."""

import colour
import numpy as np
import pytest

from benchmark.camera import calibration, exposure
from benchmark.camera.pipeline import simulate
from benchmark.camera import CameraSpec, load_camera
from benchmark.camera.sensor import signal_volts_per_electron
from metricscenes.geometry import REFERENCE_EXTENT
from metricscenes.radiance import RadianceLayer, SpectralScene

D65 = calibration.illuminant_spectrum("D65")


def _with(cam: CameraSpec, **sections) -> CameraSpec:
    data = cam.model_dump(exclude={"sensor": {"width_px", "height_px"}})
    for key, value in sections.items():
        data[key] = {**data[key], **value}
    return CameraSpec.model_validate(data)


def _textured_scene(scale):
    rng = np.random.default_rng(11)
    cube = rng.random((90, 160, 1), dtype=np.float32) * (D65 * scale).astype(np.float32)
    return SpectralScene(layers=(RadianceLayer(cube.astype(np.float32), REFERENCE_EXTENT),))


@pytest.mark.parametrize("name", ["cam01", "cam06", "cam12"])
def test_auto_exposure_puts_the_central_peak_at_90_percent(name):
    cam = load_camera(name)
    cap = simulate(_textured_scene(1e-2), cam, seed=0, noise=False)
    assert cap.exposure_s < 0.016  # not at the cap: the policy itself is tested
    rows, cols = exposure.central_region(cap.electrons.shape, cam.exposure.region_fraction)
    pct = cam.exposure.peak_percentile
    peak_v = np.percentile(cap.electrons[rows, cols], pct) * signal_volts_per_electron(cam.sensor)
    assert abs(peak_v / cam.sensor.voltage_swing_v - 0.90) < 0.02
    peak_dn = np.percentile(cap.raw_dn[rows, cols], pct)
    assert abs(peak_dn - (64 + 0.9 * 1023)) < 0.02 * 1023
    # Only the brightest (100 - pct) % of the region may clip.
    assert (cap.raw_dn[rows, cols] >= 1023).mean() <= (100 - pct) / 100 + 1e-3


def test_strict_peak_policy_and_glint_rejection():
    cam = load_camera("cam06")  # 1280 x 720: one scene pixel per sensor pixel below
    rng = np.random.default_rng(3)
    texture = rng.random((720, 1280, 1), dtype=np.float32) * (D65 * 1e-2).astype(np.float32)
    scene = SpectralScene(layers=(RadianceLayer(texture, REFERENCE_EXTENT),))
    glint = texture.copy()
    glint[360, 640] *= 300  # one sun glint in the centre
    glinted = SpectralScene(layers=(RadianceLayer(glint, REFERENCE_EXTENT),))
    robust = simulate(glinted, cam, seed=0, noise=False)
    plain = simulate(scene, cam, seed=0, noise=False)
    assert robust.exposure_s == pytest.approx(plain.exposure_s, rel=0.02)
    strict_cam = _with(cam, exposure={"peak_percentile": 100.0})
    strict = simulate(glinted, strict_cam, seed=0, noise=False)
    rows, cols = exposure.central_region(strict.electrons.shape, 0.5)
    assert strict.exposure_s < plain.exposure_s / 10  # the glint alone sets the exposure
    peak_v = strict.electrons[rows, cols].max() * signal_volts_per_electron(cam.sensor)
    assert abs(peak_v / 0.4591 - 0.90) < 0.02


def test_auto_exposure_never_exceeds_16_ms():
    cam = load_camera("cam04")  # f/10.9: the dimmest optics
    dark = simulate(_textured_scene(1e-8), cam, seed=0, noise=False)
    black = simulate(SpectralScene.uniform(np.zeros(31)), cam, seed=0)
    assert dark.exposure_s == black.exposure_s == 0.016


def test_fixed_and_mean_level_policies():
    cam = load_camera("cam01")
    fixed = simulate(_textured_scene(1e-4), _with(cam, exposure={"mode": "fixed", "exposure_s": 0.002}), seed=0)
    assert fixed.exposure_s == 0.002
    mean_cam = _with(cam, exposure={"mode": "mean_level", "level": 0.25})
    cap = simulate(_textured_scene(1e-4), mean_cam, seed=0, noise=False)
    rows, cols = exposure.central_region(cap.electrons.shape, 0.5)
    mean_v = cap.electrons[rows, cols].mean() * signal_volts_per_electron(cam.sensor)
    assert abs(mean_v / 0.4591 - 0.25) < 0.005


def _lab(rgb8):
    lin = colour.models.eotf_sRGB(np.asarray(rgb8, float) / 255.0)
    xyz = colour.RGB_to_XYZ(lin, colour.RGB_COLOURSPACES["sRGB"], apply_cctf_decoding=False)
    return colour.XYZ_to_Lab(xyz, colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"])


@pytest.mark.parametrize("white_balance", ["grey_world", "known_illuminant"])
@pytest.mark.parametrize("demosaic", ["malvar2004", "bilinear"])
def test_grey_patch_is_neutral(white_balance, demosaic):
    cam = _with(load_camera("cam02"), isp={"white_balance": white_balance, "demosaic": demosaic})
    cap = simulate(SpectralScene.uniform(0.18 * D65 * 1e-3), cam, seed=3)
    lab = _lab(cap.rgb8[100:300, 200:500].reshape(-1, 3).mean(axis=0))
    assert abs(lab[1]) < 2 and abs(lab[2]) < 2
    assert 70 < lab[0] < 100  # peak at 90 % of the swing: a bright grey


def test_colorchecker_neutrals_are_neutral_and_colours_close():
    names, refl = calibration.checker_reflectances()
    patches = (refl * D65 * 2e-3).astype(np.float32).reshape(4, 6, 31)
    cube = np.repeat(np.repeat(patches, 30, axis=0), 30, axis=1)
    scene = SpectralScene(layers=(RadianceLayer(cube, REFERENCE_EXTENT),))
    cam = _with(load_camera("cam01"), isp={"white_balance": "known_illuminant"},
                exposure={"region_fraction": 1.0})
    cap = simulate(scene, cam, seed=0, noise=False)
    h, w = cap.height_px // 4, cap.width_px // 6
    centres = np.array([cap.rgb8[r * h + h // 3 : r * h + 2 * h // 3, c * w + w // 3 : c * w + 2 * w // 3]
                        .reshape(-1, 3).mean(0) for r in range(4) for c in range(6)])
    lab = _lab(centres)
    for i in range(19, 23):  # neutral 8 ... neutral 3.5 (white 9.5 may clip)
        assert abs(lab[i, 1]) < 2 and abs(lab[i, 2]) < 2, names[i]
    assert calibration.checker_delta_e2000(cam.sensor).mean() < 4
    assert np.all(np.abs(calibration.color_matrix(cam.sensor).sum(axis=1) - 1) < 1e-9)
