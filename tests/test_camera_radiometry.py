"""Radiometric round trip: uniform radiance → optics → sensor electrons, against a
hand calculation from E = πL/(1+4N²), QE × IR-cut, pixel area and exposure time."""

from pathlib import Path

import numpy as np
import pytest

from benchmark.camera import optics, sensor
from benchmark.camera.pipeline import electron_rate, simulate
from benchmark.camera import camera_from_dict, load_camera
from metricscenes.radiance import SpectralScene
from metricscenes.spectral import WAVELENGTHS_NM

H_J_S, C_M_S = 6.62607015e-34, 299792458.0
QE_CSV = Path(__file__).resolve().parents[1] / "metricscenes" / "data" / "imx363_qe.csv"


def _hand_electrons(radiance, f_number, pixel_um, exposure_s, transmittance=1.0):
    """Electrons per channel (R, G, B) for a uniform field, written out from scratch."""
    table = np.loadtxt(QE_CSV, delimiter=",", skiprows=1)
    wl = WAVELENGTHS_NM
    ir = np.interp(wl, table[:, 0], table[:, 4])
    e_w_m2_nm = np.pi * transmittance * radiance / (1.0 + 4.0 * f_number**2)
    photons = e_w_m2_nm * (wl * 1e-9) / (H_J_S * C_M_S)  # photons s-1 m-2 nm-1
    area = (pixel_um * 1e-6) ** 2
    return np.array(
        [np.sum(photons * np.interp(wl, table[:, 0], table[:, k]) * ir) * 10.0 * area * exposure_s for k in (1, 2, 3)]
    )


def _fixed(name, exposure_s, **optics):
    spec = load_camera(name).model_dump(mode="json")
    spec["exposure"] = {"mode": "fixed", "exposure_s": exposure_s}
    spec["optics"].update(optics)
    for k in ("width_px", "height_px"):
        spec["sensor"].pop(k)
    return camera_from_dict(spec)


def _site_means(mosaic):
    return np.array([mosaic[0::2, 0::2].mean(), mosaic[0::2, 1::2].mean(), mosaic[1::2, 1::2].mean()])


@pytest.mark.parametrize("name", ["cam01", "cam04", "cam12"])
def test_uniform_field_electrons_match_hand_calculation(name):
    radiance = np.full(31, 0.01) * np.linspace(0.8, 1.2, 31)
    base = load_camera(name)
    per_s = _hand_electrons(radiance, base.f_number, base.pixel_um, 1.0, transmittance=0.9)
    exposure_s = 0.5 * sensor.saturation_electrons(base.sensor) / per_s[1]  # half the ceiling in G: no clipping
    cam = _fixed(name, exposure_s, transmittance=0.9)
    cap = simulate(SpectralScene.uniform(radiance), cam, seed=0, noise=False)
    expected = per_s * exposure_s
    got = _site_means(cap.electrons)
    np.testing.assert_allclose(got, expected, rtol=0.01)
    # uniform in, uniform out: the OTF (DC gain 1) and the padding keep the borders exact
    assert np.ptp(cap.electrons[0::2, 0::2]) <= 1e-3 * expected[0]
    # DN = black level + electrons × conversion gain × analog gain (ISO 270 / 55) / LSB
    dn = 64 + expected * 76.5e-6 * (270 / 55) / (0.4591 / 1023)
    np.testing.assert_allclose(_site_means(cap.raw_dn.astype(float)), dn, atol=0.51)


def test_d65_field_of_known_luminance():
    import colour

    d65 = colour.SDS_ILLUMINANTS["D65"]
    ybar = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    spd = np.interp(WAVELENGTHS_NM, d65.wavelengths, d65.values)
    y = np.interp(WAVELENGTHS_NM, ybar.wavelengths, ybar.values[:, 1])
    luminance_cd_m2 = 100.0
    radiance = spd * luminance_cd_m2 / (683.0 * np.sum(spd * y) * 10.0)  # W sr-1 m-2 nm-1
    cam = _fixed("cam10", 0.010)
    rate = electron_rate(SpectralScene.uniform(radiance), cam)
    expected = _hand_electrons(radiance, cam.f_number, cam.pixel_um, 1.0)
    np.testing.assert_allclose(rate.mean(axis=(1, 2)), expected, rtol=0.01)
    # order of magnitude sanity: 100 cd/m2 at f/5.4, 1.4 um, 10 ms is a few hundred electrons
    assert 100 < expected[1] * 0.010 < 2000


def test_plain_irradiance_is_pi_l_over_1_plus_4n2():
    cam = load_camera("cam05")
    radiance = np.full((40, 60, 31), 0.02, dtype=np.float32)
    e = optics.irradiance(radiance, WAVELENGTHS_NM, cam.optics, cam.pixel_um)
    np.testing.assert_allclose(e, np.pi * 0.02 / (1 + 4 * 3.8**2), rtol=1e-4)


def test_fast_path_equals_per_band_irradiance_integration():
    """Σ_λ r(λ)·E(λ) in the frequency domain equals integrating the plain irradiance."""
    cam = load_camera("cam09")
    rng = np.random.default_rng(3)
    radiance = rng.random((48, 64, 31), dtype=np.float32) * 0.05
    resp = sensor.channel_responsivity(cam.sensor)
    fast = optics.channel_signal(radiance, WAVELENGTHS_NM, cam.optics, cam.pixel_um, resp)
    e = optics.irradiance(radiance, WAVELENGTHS_NM, cam.optics, cam.pixel_um)
    slow = np.einsum("hwb,cb->chw", e.astype(float), resp)
    np.testing.assert_allclose(fast, slow, rtol=2e-3, atol=1e-3 * slow.max())
