"""e-SFR MTF50 against analytic oracles (diffraction × square pixel)."""

import math

import numpy as np
import pytest

from benchmark.camera import load_camera
from benchmark.measure.mtf import esf_mtf, measure_mtf50, mtf50, mtf50_analytic_cy_per_mm
from benchmark.camera.optics import diffraction_mtf
from benchmark.measure.targets import square_coverage, synthetic_edge_image


@pytest.mark.parametrize("pixel_um", [1.4, 2.8])
@pytest.mark.parametrize("f_number", [2.0, 4.0, 8.0])
def test_esfr_recovers_known_mtf50(pixel_um, f_number):
    pixel_mm = pixel_um * 1e-3
    ca, sa = math.cos(math.radians(5)), math.sin(math.radians(5))

    def system_mtf(f_cy_per_px):  # diffraction at 550 nm × the square pixel seen along the edge normal
        return diffraction_mtf(f_cy_per_px / pixel_mm, 550.0, f_number) * np.sinc(f_cy_per_px * ca) * np.sinc(f_cy_per_px * sa)

    image = synthetic_edge_image((96, 192), system_mtf, pixel_mm / (550e-6 * f_number))
    freq, mtf = esf_mtf(image)
    measured = mtf50(freq, mtf) / pixel_mm
    expected = mtf50_analytic_cy_per_mm(pixel_um, f_number, wavelength_nm=550.0)
    assert abs(measured / expected - 1) < 0.03


def test_analytic_oracle_limits():
    # diffraction alone: MTF50 = 0.404 / (λN); pixel alone: 0.603 cycles/pixel
    assert abs(mtf50_analytic_cy_per_mm(0.01, 4.0, 550.0) / (0.404 / (550e-6 * 4.0)) - 1) < 0.005
    assert abs(mtf50_analytic_cy_per_mm(2.0, 0.001, 550.0) * 2e-3 / 0.603 - 1) < 0.01


def test_square_coverage_is_exact_area():
    rng = np.random.default_rng(0)
    d = rng.uniform(-1, 1, 50)
    u, v = rng.uniform(-0.5, 0.5, (2, 200000))
    a = math.radians(5)
    mc = [np.mean(u * math.cos(a) - v * math.sin(a) > -di) for di in d[:5]]
    np.testing.assert_allclose(square_coverage(d[:5], 5.0), mc, atol=0.005)


def test_measured_camera_mtf50_follows_the_optics():
    """Through optics + sensor + demosaic the measured MTF50 stays near the analytic
    diffraction × pixel value (the demosaic moves it by tens of percent at most)."""
    for name in ("cam04", "cam10"):
        cam = load_camera(name)
        measured = measure_mtf50(cam)["mtf50_cy_per_mm"]
        analytic = mtf50_analytic_cy_per_mm(cam.pixel_um, cam.f_number)
        assert 0.85 < measured / analytic < 1.15, (name, measured, analytic)
    slow, fast = (measure_mtf50(load_camera(n))["mtf50_cy_per_mm"] for n in ("cam04", "cam13"))
    assert fast > 2.5 * slow
