import numpy as np
import pytest

from metricscenes.geometry import REFERENCE_EXTENT, TanExtent, pixels_to_tan, tan_to_pixels, world_to_tan
from metricscenes.radiance import RadianceLayer, SpectralScene


def _area(e: TanExtent) -> float:
    return e.width * e.height


@pytest.mark.parametrize("cols, rows", [(37, 23), (64, 36), (160, 90)])
def test_downsampling_conserves_flux(cols, rows):
    plate = RadianceLayer(np.random.default_rng(0).random((270, 480, 31), dtype=np.float32), REFERENCE_EXTENT)
    out = SpectralScene(layers=(plate,)).resample(cols, rows)
    assert out.shape == (rows, cols, 31) and out.dtype == np.float32
    np.testing.assert_allclose(out.mean(axis=(0, 1), dtype=np.float64), plate.radiance.mean(axis=(0, 1), dtype=np.float64), rtol=1e-5)


def test_inset_on_output_pixel_edges_is_pasted_exactly():
    rng = np.random.default_rng(1)
    plate = RadianceLayer(rng.random((9, 16, 31), dtype=np.float32), REFERENCE_EXTENT)
    e = REFERENCE_EXTENT
    # An inset covering output pixels [40, 56) x [20, 30) of a 160 x 90 grid, sampled 4x finer.
    ext = TanExtent(e.x0 + 40 * e.width / 160, e.y0 + 20 * e.height / 90, e.x0 + 56 * e.width / 160, e.y0 + 30 * e.height / 90)
    fine = rng.random((40, 64, 31), dtype=np.float32)
    out = SpectralScene(layers=(plate, RadianceLayer(fine, ext))).resample(160, 90)
    expected_block = fine.reshape(10, 4, 16, 4, 31).mean(axis=(1, 3))
    np.testing.assert_allclose(out[20:30, 40:56], expected_block, rtol=1e-5)
    base = SpectralScene(layers=(plate,)).resample(160, 90)
    mask = np.ones((90, 160), bool)
    mask[20:30, 40:56] = False
    np.testing.assert_allclose(out[mask], base[mask], rtol=1e-6)


def test_inset_partly_covering_pixels_blends_by_area():
    plate = RadianceLayer(np.full((9, 16, 31), 1.0, np.float32), REFERENCE_EXTENT)
    e = REFERENCE_EXTENT
    # Covers half of output pixel column 10 (and all of 11) of a 32-column grid.
    ext = TanExtent(e.x0 + 10.5 * e.width / 32, e.y0, e.x0 + 12 * e.width / 32, e.y1)
    out = SpectralScene(layers=(plate, RadianceLayer(np.full((18, 3, 31), 3.0, np.float32), ext))).resample(32, 18)
    np.testing.assert_allclose(out[:, 10, 0], 2.0, rtol=1e-6)
    np.testing.assert_allclose(out[:, 11, 0], 3.0, rtol=1e-6)
    np.testing.assert_allclose(out[:, 12, 0], 1.0, rtol=1e-6)


def test_upsampling_interpolates_linearly_between_centres():
    ramp = np.tile(np.arange(16, dtype=np.float32)[None, :, None], (9, 1, 31))
    out = SpectralScene(layers=(RadianceLayer(ramp, REFERENCE_EXTENT),)).resample(64, 36)
    # Target centres (j + 0.5) / 4 - 0.5 source pixels, clamped at the ends.
    expected = np.clip((np.arange(64) + 0.5) / 4 - 0.5, 0, 15)
    np.testing.assert_allclose(out[5, :, 3], expected, atol=1e-5)
    np.testing.assert_allclose(out[0], out[35])


def test_uniform_field_stays_uniform():
    spectrum = np.linspace(0.01, 0.02, 31)
    out = SpectralScene.uniform(spectrum, rows=9, cols=16).resample(333, 187)
    np.testing.assert_allclose(out, np.broadcast_to(spectrum, out.shape), rtol=1e-5)


def test_tangent_and_pixel_coordinates_round_trip():
    # A point 100 m ahead on the camera axis lands in the image centre.
    centre = tan_to_pixels(world_to_tan(np.array([[100.0, 0.0, 1.5]])), 1920, 1080)
    np.testing.assert_allclose(centre, [[960.0, 540.0]])
    # Left (+y) goes to smaller columns, down (-z) to larger rows.
    p = tan_to_pixels(world_to_tan(np.array([[10.0, 1.0, 0.5]])), 1920, 1080)[0]
    assert p[0] < 960 and p[1] > 540
    px = np.array([[12.5, 99.0], [1919.0, 0.5]])
    np.testing.assert_allclose(tan_to_pixels(pixels_to_tan(px, 1920, 1080), 1920, 1080), px)
