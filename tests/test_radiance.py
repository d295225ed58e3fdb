import numpy as np
import pytest

from metricscenes import radiance
from metricscenes.geometry import REFERENCE_EXTENT, TanExtent, pixels_to_tan, tan_to_pixels, world_to_tan
from metricscenes.radiance import RadianceLayer, SpectralScene, feather_weights


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


def _feathered_pair(feather: float, fine_value: float = 3.0):
    """A plate of ones and an inset (40 x 64 px, 4x finer than a 160 x 90 grid, on its pixel edges)."""
    e = REFERENCE_EXTENT
    ext = TanExtent(e.x0 + 40 * e.width / 160, e.y0 + 20 * e.height / 90, e.x0 + 56 * e.width / 160, e.y0 + 30 * e.height / 90)
    plate = RadianceLayer(np.ones((9, 16, 2), np.float32), REFERENCE_EXTENT)
    return plate, RadianceLayer(np.full((40, 64, 2), fine_value, np.float32), ext, feather=feather)


def test_feathered_inset_blends_by_its_weight_area_averaged():
    plate, inset = _feathered_pair(0.1)
    wy, wx = feather_weights(inset, REFERENCE_EXTENT)
    # Linear ramps over 10 % of each side (4 of 40 rows, 6.4 of 64 columns), 1 inside, symmetric.
    np.testing.assert_allclose(wy[:5], [0.125, 0.375, 0.625, 0.875, 1.0])
    np.testing.assert_allclose(wx[:7], np.minimum((np.arange(7) + 0.5) / 6.4, 1.0))
    np.testing.assert_allclose(wx, wx[::-1])
    out = SpectralScene(layers=(plate, inset), wavelengths_nm=np.array([500.0, 510.0])).resample(160, 90)
    # Each output pixel averages 4 x 4 inset pixels: plate + (inset - plate) x their mean weight.
    weight = np.outer(wy, wx).reshape(10, 4, 16, 4).mean(axis=(1, 3))
    np.testing.assert_allclose(out[20:30, 40:56, 0], 1.0 + 2.0 * weight, rtol=1e-5)
    np.testing.assert_allclose(out[25, 48, :], 3.0, rtol=1e-6)  # the middle keeps the inset alone
    assert np.all(out[:20] == 1.0) and np.all(out[:, :40] == 1.0)  # nothing outside the window


def test_feathering_keeps_equal_layers_equal_and_is_off_by_default():
    plate, inset = _feathered_pair(0.08, fine_value=1.0)
    out = SpectralScene(layers=(plate, inset), wavelengths_nm=np.array([500.0, 510.0])).resample(123, 77)
    np.testing.assert_allclose(out, 1.0, rtol=1e-6)  # a blend of two equal estimates changes nothing
    hard = RadianceLayer(inset.radiance, inset.extent)
    assert hard.feather == 0.0 and all(np.all(w == 1.0) for w in feather_weights(hard, REFERENCE_EXTENT))


def test_feather_leaves_edges_on_the_plate_border_hard():
    e = REFERENCE_EXTENT
    inset = RadianceLayer(np.ones((20, 40, 1), np.float32), TanExtent(e.x0, 0.0, 0.0, e.y1), feather=0.1)
    wy, wx = feather_weights(inset, REFERENCE_EXTENT)
    assert wx[0] == 1.0 and wx[-1] == pytest.approx(0.125)  # left edge on the border; right inside (4 px ramp)
    assert wy[0] == pytest.approx(0.25) and wy[-1] == 1.0  # top inside (2 px ramp); bottom on the border


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_band_planes_are_the_transposed_cube_in_blocks_of_rows(dtype, monkeypatch):
    """The blocked copy gives numpy's whole-view copy's values, whatever the block (one row,
    a block that does not divide the rows, all of them), and a band-major cube is not copied."""
    cube = np.random.default_rng(1).random((37, 23, 31)).astype(dtype)
    want = np.ascontiguousarray(np.moveaxis(cube.astype(np.float32), 2, 0))
    for block_bytes in (1, 23 * 31 * np.dtype(dtype).itemsize * 5, 1 << 30):
        monkeypatch.setattr(radiance, "BAND_PLANES_BLOCK_BYTES", block_bytes)
        planes = radiance.band_planes(cube)
        assert planes.dtype == np.float32 and planes.flags.c_contiguous and np.array_equal(planes, want)
    stored = np.moveaxis(want, 0, 2)  # (rows, cols, bands), stored band by band
    assert np.shares_memory(radiance.band_planes(stored), want)
