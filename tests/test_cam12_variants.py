"""The two variants of cam12 for the lens comparison (docs/camera.md, "Two variants of
cam12 for the lens comparison"): cameras/cam12-aberrated.yaml (a quarter-wave defocus and
spherical aberration at cam12's f/1.9) and cameras/cam12-flare.yaml (veiling glare on). Each is
cam12 but for its lens; the aberrated lens resolves less, and the glare moves light without
making or losing any but what it scatters past the frame's edge."""

import math
from pathlib import Path

import numpy as np
import pytest

from benchmark.camera import lens, load_camera
from benchmark.camera.pipeline import electron_rate
from benchmark.measure.mtf import camera_mtf50
from metricscenes.geometry import REFERENCE_EXTENT
from metricscenes.radiance import RadianceLayer, SpectralScene

CAMERAS = Path(__file__).resolve().parents[1] / "cameras"
VARIANTS = {  # file stem: the optics fields it changes from cam12's, and to what
    "cam12-aberrated": {"zernike_waves": {4: 0.0722, 12: 0.0745}},
    "cam12-flare": {"veiling_glare_fraction": 0.102},
}


@pytest.mark.parametrize("stem", sorted(VARIANTS))
def test_a_variant_is_cam12_but_for_its_lens(stem):
    cam12, variant = load_camera("cam12"), load_camera(CAMERAS / f"{stem}.yaml")
    for section in ("sensor", "exposure", "isp"):
        assert getattr(variant, section).model_dump() == getattr(cam12, section).model_dump(), section
    ours, theirs = variant.optics.model_dump(), cam12.optics.model_dump()
    changed = {field for field in ours.keys() | theirs.keys() if ours.get(field) != theirs.get(field)}
    assert changed == set(VARIANTS[stem])
    assert {field: ours[field] for field in changed} == VARIANTS[stem]
    # the same lens geometry and light: focal length, f-number (hence irradiance), transmittance
    assert (variant.optics.focal_length_mm, variant.f_number, variant.optics.transmittance) == (4.38, 1.9, 1.0)
    # the paper's MTF50 group is a measurement of cam12's ideal lens, not of this one
    assert variant.mtf50_group_cy_per_mm is None


def test_the_variants_have_names_and_hashes_of_their_own():
    cams = [load_camera("cam12")] + [load_camera(CAMERAS / f"{stem}.yaml") for stem in sorted(VARIANTS)]
    assert [c.name for c in cams[1:]] == sorted(VARIANTS)  # each named after its file
    assert len({c.name for c in cams}) == len({c.label for c in cams}) == len({c.sha256() for c in cams}) == 3


def test_the_flare_fraction_is_the_stated_vgi_through_the_documented_relation():
    """g = VGI·√(θ₀² + a²)/θ₀ (docs/camera.md, "Veiling glare"): VGI 2 % (assumed) with a black
    spot of 1° diameter (a = 0.5°) and the default θ₀ = 0.1°."""
    optics = load_camera(CAMERAS / "cam12-flare.yaml").optics
    theta0, a, vgi = optics.glare_angle_deg, 0.5, 0.02
    assert theta0 == 0.1
    assert optics.veiling_glare_fraction == pytest.approx(vgi * math.hypot(theta0, a) / theta0, abs=5e-4)


def test_the_aberrated_lens_has_cam12s_f_number_and_a_lower_mtf50():
    cam12, aberrated = load_camera("cam12"), load_camera(CAMERAS / "cam12-aberrated.yaml")
    assert aberrated.f_number == cam12.f_number
    assert lens.otf_is_radial(aberrated.optics)  # defocus and spherical only: the cached real-OTF path
    (analytic12, _), (analytic, _) = camera_mtf50(cam12, "analytic"), camera_mtf50(aberrated, "analytic")
    (measured12, src12), (measured, src) = camera_mtf50(cam12), camera_mtf50(aberrated)
    assert src12 == src == "measured"
    # docs/camera.md: 269.9 -> 179.3 c/mm analytic, 229.3 -> 179.6 c/mm through the whole chain
    assert analytic == pytest.approx(179.3, rel=0.01) and analytic < 0.7 * analytic12
    assert measured == pytest.approx(179.6, rel=0.02) and measured < 0.85 * measured12


def test_the_flare_camera_keeps_a_uniform_fields_light():
    """A uniform field through cam12 and cam12-flare (the whole frame, noise-free): the glare's
    kernel has unit energy, so a pixel loses only the part of its kernel that falls outside the
    frame (bounded by the kernel's encircled energy, 1 − r₀/√(r₀² + R²), at the nearest edge
    and the farthest corner) and the frame's mean only the light scattered past its edges."""
    scene = SpectralScene(layers=(RadianceLayer(np.full((4, 4, 31), 0.01, np.float32), REFERENCE_EXTENT),))
    cam12, flare = load_camera("cam12"), load_camera(CAMERAS / "cam12-flare.yaml")
    plain, glared = electron_rate(scene, cam12), electron_rate(scene, flare)
    np.testing.assert_allclose(plain, np.broadcast_to(plain[:, :1, :1], plain.shape), rtol=1e-5)  # still uniform
    ratio = glared / plain
    g, rows, cols = flare.optics.veiling_glare_fraction, flare.height_px, flare.width_px
    r0_px = lens.glare_scale_mm(flare.optics.focal_length_mm, flare.optics.glare_angle_deg) * 1e3 / flare.pixel_um
    outside = [g * r0_px / math.hypot(r0_px, radius) for radius in (math.hypot(rows, cols) / 2, min(rows, cols) / 2)]
    centre = ratio[:, rows // 2, cols // 2]
    assert np.all(centre >= 1 - outside[1] - 1e-4) and np.all(centre <= 1 - outside[0] + 1e-4)
    # the mean: no light made, and the loss at the edges is a small part of g
    mean = ratio.mean(axis=(1, 2))
    assert np.all(mean < 1) and np.all(mean > 1 - 0.05 * g)
    # a corner keeps its direct light, 1 − g, and about a quadrant of its glare
    assert 1 - 0.8 * g < ratio.min() < 1 - 0.6 * g


def test_the_hdr_variant_is_the_imx490_like_sensor_on_cam12s_grid_and_field():
    """cam12-hdr: auto-imx490-like's sensor, exposure and ISP read out in cam12's 1920 x 1080,
    behind cam12's f-number and field of view (the lens scaled to the 3.0 um pixel): the same
    angular sampling as cam12, so the comparison is the sensor's."""
    cam12, hdr, imx490 = load_camera("cam12"), load_camera(CAMERAS / "cam12-hdr.yaml"), load_camera("auto-imx490-like")
    assert (hdr.width_px, hdr.height_px) == (cam12.width_px, cam12.height_px)
    assert hdr.f_number == cam12.f_number
    assert hdr.hfov_deg == pytest.approx(cam12.hfov_deg, rel=1e-4) and hdr.hfov_deg <= cam12.hfov_deg
    assert hdr.vfov_deg == pytest.approx(cam12.vfov_deg, rel=1e-4) and hdr.vfov_deg <= cam12.vfov_deg
    window = {"active_width_mm", "active_height_mm", "width_px", "height_px"}  # (the last two derived)
    ours, theirs = hdr.sensor.model_dump(), imx490.sensor.model_dump()
    assert {k for k in ours if ours[k] != theirs[k]} == window
    assert (hdr.exposure, hdr.isp) == (imx490.exposure, imx490.isp)
    assert hdr.sensor.dcg is not None and hdr.name == "cam12-hdr"
