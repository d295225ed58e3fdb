"""The fast paths of the camera pipeline against their plain references: float32
Malvar vs colour-demosaicing, in-place padding vs np.pad, cached exact OTFs vs the
direct formula, band-planar resampling vs a dense oracle, the fast channel signal vs
per-band irradiance, and the in-place sensor vs the written-out noise chain."""

import colour_demosaicing
import numpy as np
import pytest

from benchmark.camera import optics, sensor
from benchmark.camera import load_camera
from benchmark.camera.demosaic import malvar2004
from metricscenes.geometry import REFERENCE_EXTENT, TanExtent
from metricscenes.radiance import RadianceLayer, SpectralScene, _axis_matrix
from metricscenes.spectral import WAVELENGTHS_NM


@pytest.mark.parametrize("cfa", ["RGGB", "BGGR", "GRBG", "GBRG"])
@pytest.mark.parametrize("shape", [(64, 97), (7, 9), (6, 5)])
def test_float32_malvar_matches_colour_demosaicing(cfa, shape):
    mosaic = np.random.default_rng(sum(shape)).random(shape, dtype=np.float32)
    ours = malvar2004(mosaic, cfa)
    ref = colour_demosaicing.demosaicing_CFA_Bayer_Malvar2004(mosaic, cfa)
    assert ours.dtype == np.float32 and ours.shape == shape + (3,)
    np.testing.assert_allclose(ours, ref, rtol=0, atol=2e-6)


def test_malvar_rejects_non_bayer_patterns():
    with pytest.raises(ValueError, match="cfa"):
        malvar2004(np.zeros((8, 8)), "RGBG")


@pytest.mark.parametrize("band_shape, pad, shape", [((40, 60), 9, (60, 80)), ((10, 12), 9, (30, 40)), ((20, 30), 4, (30, 45))])
def test_in_place_padding_equals_np_pad(band_shape, pad, shape):
    band = np.random.default_rng(0).random(band_shape, dtype=np.float32)
    buf = np.full(shape, np.nan, dtype=np.float32)
    optics._pad_into(buf, band, pad)
    np.testing.assert_array_equal(buf, optics._pad(band, pad, shape))


@pytest.mark.parametrize("shape", [(48, 64), (49, 63)])
def test_cached_half_otfs_equal_the_full_grid(shape):
    spec = np.random.default_rng(1).random((shape[0], shape[1] // 2 + 1)).astype(np.complex64)
    otfs = optics._half_otfs(shape, 1.4, (450.0, 650.0), 5.4)
    assert not otfs.flags.writeable
    for k, wl in enumerate((450.0, 650.0)):
        out = np.empty_like(spec)
        optics._apply_otf(spec, otfs[k], out)
        np.testing.assert_allclose(out, spec * optics.otf_grid(shape, 1.4, wl, 5.4), rtol=1e-6)


def test_resample_is_band_planar_and_equals_a_dense_oracle():
    rng = np.random.default_rng(2)
    plate = rng.random((9, 16, 31), dtype=np.float32)
    e = REFERENCE_EXTENT
    ext = TanExtent(e.x0 + 0.31 * e.width, e.y0 + 0.4 * e.height, e.x0 + 0.47 * e.width, e.y0 + 0.55 * e.height)
    inset = rng.random((30, 40, 31), dtype=np.float32)
    out = SpectralScene(layers=(RadianceLayer(plate, e), RadianceLayer(inset, ext))).resample(50, 30)
    assert out.shape == (30, 50, 31) and out.dtype == np.float32
    assert np.moveaxis(out, 2, 0).flags.c_contiguous  # each band one contiguous image

    def dense(cube, ex):
        wy = _axis_matrix(ex.y0, ex.y1, cube.shape[0], e.y0, e.y1, 30).toarray()
        wx = _axis_matrix(ex.x0, ex.x1, cube.shape[1], e.x0, e.x1, 50).toarray()
        return np.einsum("ir,jc,rcb->ijb", wy, wx, cube.astype(float))

    # coverage of each output pixel by the inset, from the pixel edges (written out)
    xs, ys = np.linspace(e.x0, e.x1, 51), np.linspace(e.y0, e.y1, 31)
    cx = np.clip(np.minimum(xs[1:], ext.x1) - np.maximum(xs[:-1], ext.x0), 0, None) / np.diff(xs)
    cy = np.clip(np.minimum(ys[1:], ext.y1) - np.maximum(ys[:-1], ext.y0), 0, None) / np.diff(ys)
    cov = np.outer(cy, cx)[..., None]
    expected = dense(plate, e) * (1 - cov) + dense(inset, ext) * cov
    np.testing.assert_allclose(out, expected, rtol=1e-5, atol=1e-6)


@pytest.mark.parametrize("name", ["cam08", "cam12"])
def test_fast_channel_signal_on_band_planar_input_equals_per_band_irradiance(name):
    cam = load_camera(name)
    planes = np.random.default_rng(3).random((31, 40, 56), dtype=np.float32) * 0.05
    radiance = planes.transpose(1, 2, 0)  # as SpectralScene.resample stores it
    resp = sensor.channel_responsivity(cam.sensor)
    fast = optics.channel_signal(radiance, WAVELENGTHS_NM, cam.optics, cam.pixel_um, resp)
    slow = np.einsum("hwb,cb->chw", optics.irradiance(radiance, WAVELENGTHS_NM, cam.optics, cam.pixel_um).astype(float), resp)
    # The reference pads each band for its own wavelength, the fast path for the reddest:
    # the wrapped-around PSF tails differ a little near the border only.
    np.testing.assert_allclose(fast, slow, rtol=2e-3, atol=1e-3 * slow.max())
    inner = (slice(None), slice(12, -12), slice(12, -12))
    np.testing.assert_allclose(fast[inner], slow[inner], rtol=0, atol=3e-4 * slow.max())
    # the same cube stored band-last gives the same answer
    np.testing.assert_array_equal(
        optics.channel_signal(np.ascontiguousarray(radiance), WAVELENGTHS_NM, cam.optics, cam.pixel_um, resp), fast
    )


@pytest.mark.parametrize("distortion", [None, (-0.1, 0.02)])
def test_electron_rate_is_the_optical_image_through_the_sensor(distortion):
    """The camera's fused path equals the plain one through the values between stages:
    scene → optical image (irradiance on the pixel grid) → sensor signal."""
    from benchmark.camera.pipeline import electron_rate, optical_image
    from benchmark.camera import camera_from_dict
    from metricscenes.radiance import RadianceLayer, SpectralScene

    optics_spec = {"f_number": 2.2, "focal_length_mm": 5.0}
    if distortion:
        optics_spec.update(distortion_k1=distortion[0], distortion_k2=distortion[1])
    cam = camera_from_dict({"name": "values", "optics": optics_spec,
                            "sensor": {"pixel_um": 2.8, "active_width_mm": 0.224, "active_height_mm": 0.168}})
    cube = np.random.default_rng(5).random((120, 200, 31), dtype=np.float32) * 0.05
    scene = SpectralScene(layers=(RadianceLayer(cube, REFERENCE_EXTENT),))
    oi = optical_image(scene, cam)
    assert oi.irradiance.shape == (cam.height_px, cam.width_px, 31) and oi.pixel_um == cam.pixel_um
    plain = sensor.signal_from_irradiance(oi.irradiance, oi.wavelengths_nm, cam.sensor)
    fused = electron_rate(scene, cam)
    inner = (slice(None), slice(12, -12), slice(12, -12))  # the two paths pad the PSF differently
    np.testing.assert_allclose(fused[inner], plain[inner], rtol=0, atol=3e-4 * plain.max())


def test_in_place_sensor_equals_the_written_out_noise_chain():
    spec = load_camera("cam10").sensor
    rate = np.random.default_rng(4).random((32, 48), dtype=np.float32) * 4e5
    exposure_s = 0.01
    got = sensor.capture_volts(rate, exposure_s, spec, np.random.default_rng(9))
    rng = np.random.default_rng(9)
    e = rate.astype(np.float64) * exposure_s + spec.dark_current_e_per_s * exposure_s
    e = np.minimum(rng.poisson(np.maximum(e, 0.0)).astype(np.float64), spec.well_capacity_e)
    e = e + spec.read_noise_e * rng.standard_normal(e.shape)
    g = np.random.default_rng([spec.fpn_seed, 0x5E45])
    gain = 1.0 + spec.prnu_fraction * g.standard_normal(e.shape, dtype=np.float32)
    offset = spec.dsnu_v * g.standard_normal(e.shape, dtype=np.float32)
    v = (e * (spec.conversion_gain_uv_per_e * 1e-6)) * gain + offset
    v = np.clip(v * spec.analog_gain + spec.black_level_dn * spec.lsb_v, 0.0, spec.voltage_swing_v)
    np.testing.assert_array_equal(got, v)
    assert not sensor.fixed_pattern(spec, (32, 48))[0].flags.writeable
