"""Radial lens distortion (Brown–Conrady k1, k2): the inverse is exact, a
point target lands where the model puts it, ground truth follows the lens, a lens that
folds is refused, and a zero distortion changes nothing (specs, hashes, images)."""

import numpy as np
import pytest

from benchmark.camera.pipeline import FieldOfViewError, camera_window, electron_rate, lens_mapping
from benchmark.camera import camera_from_dict
from benchmark.camera.distortion import distort, undistort
from metricscenes.geometry import REFERENCE_EXTENT, TanExtent, tan_to_grid
from metricscenes.groundtruth import scale_groundtruth
from metricscenes.radiance import RadianceLayer, SpectralScene

WL = np.array([550.0])
BARREL = (-0.25, 0.05)


def _camera(k1=None, k2=None, focal_mm=5.0):
    optics = {"f_number": 2.0, "focal_length_mm": focal_mm}
    optics.update({k: v for k, v in (("distortion_k1", k1), ("distortion_k2", k2)) if v is not None})
    return camera_from_dict({"name": "lens", "optics": optics,
                             "sensor": {"pixel_um": 2.8, "active_width_mm": 1.792, "active_height_mm": 1.008}})


def _spot_scene(x_tan: float, y_tan: float, radius_tan: float = 0.004) -> SpectralScene:
    """A black reference field with one small bright disc at (x_tan, y_tan)."""
    n, half = 64, 2 * radius_tan
    s = (np.arange(n) + 0.5) / n * 2 * half - half
    disc = (s[None, :] ** 2 + s[:, None] ** 2 <= radius_tan**2).astype(np.float32)
    plate = RadianceLayer(np.zeros((27, 48, 1), np.float32), REFERENCE_EXTENT)
    spot = RadianceLayer(disc[..., None], TanExtent(x_tan - half, y_tan - half, x_tan + half, y_tan + half))
    return SpectralScene(layers=(plate, spot), wavelengths_nm=WL.copy())


def test_undistort_inverts_distort():
    rng = np.random.default_rng(1)
    xy = rng.uniform(-0.35, 0.35, (1000, 2))
    for k1, k2 in (BARREL, (0.2, 0.1), (-0.1, 0.0)):
        np.testing.assert_allclose(undistort(distort(xy, k1, k2), k1, k2), xy, atol=1e-12)


def test_zero_distortion_changes_nothing():
    plain, zero = _camera(), _camera(0.0, 0.0)
    assert plain.sha256() == zero.sha256() and plain.optics.distortion is None
    assert "distortion_k1" not in plain.canonical_json()
    scene = _spot_scene(0.05, 0.02)
    np.testing.assert_array_equal(electron_rate(scene, plain, diffraction=False),
                                  electron_rate(scene, zero, diffraction=False))


@pytest.mark.parametrize("k1, k2", [BARREL, (0.3, 0.0)])
def test_a_point_lands_where_the_model_puts_it(k1, k2):
    cam = _camera(k1, k2)
    x_u, y_u = 0.16, -0.08  # a direction well off the axis
    image = electron_rate(_spot_scene(x_u, y_u), cam, diffraction=False)[1].astype(float)
    rows, cols = np.indices(image.shape)
    w = image / image.sum()
    found = np.array([(w * cols).sum() + 0.5, (w * rows).sum() + 0.5])  # pixel-centre convention
    window, _ = lens_mapping(cam, REFERENCE_EXTENT)
    expected = tan_to_grid(distort(np.array([x_u, y_u]), k1, k2), window, cam.width_px, cam.height_px)
    undistorted = tan_to_grid(np.array([x_u, y_u]), window, cam.width_px, cam.height_px)
    assert np.abs(found - expected).max() < 0.1  # pixels
    assert np.abs(undistorted - expected).max() > 1.5  # the lens moved it, visibly


def test_groundtruth_follows_the_lens():
    cam = _camera(*BARREL)
    window, to_sensor = lens_mapping(cam, REFERENCE_EXTENT)
    box_tan = np.array([[0.10, -0.08], [0.16, -0.04]])
    ref_w, ref_h = 1920, 1080
    x0, y0 = tan_to_grid(box_tan[0], REFERENCE_EXTENT, ref_w, ref_h)
    x1, y1 = tan_to_grid(box_tan[1], REFERENCE_EXTENT, ref_w, ref_h)
    gt = {"images": [{"id": 1, "width": ref_w, "height": ref_h}],
          "annotations": [{"id": 1, "image_id": 1, "bbox": [x0, y0, x1 - x0, y1 - y0], "area": 0}]}
    (ann,) = scale_groundtruth(gt, cam.width_px, cam.height_px, field=REFERENCE_EXTENT, window=window,
                               to_sensor=to_sensor)["annotations"]
    corners = tan_to_grid(distort(np.array([[0.10, -0.08], [0.16, -0.04], [0.10, -0.04], [0.16, -0.08]]), *BARREL),
                          window, cam.width_px, cam.height_px)
    # barrel: the corner farthest from the axis bounds x1 and y0; the nearest, x0 and y1
    np.testing.assert_allclose(ann["bbox"][0], corners[:, 0].min(), atol=1e-6)
    np.testing.assert_allclose(ann["bbox"][0] + ann["bbox"][2], corners[:, 0].max(), atol=1e-6)
    plain = scale_groundtruth(gt, cam.width_px, cam.height_px, field=REFERENCE_EXTENT,
                              window=camera_window(_camera(), REFERENCE_EXTENT))["annotations"][0]
    assert ann["bbox"][2] < plain["bbox"][2]  # barrel shrinks what lies off the axis


def test_barrel_sees_wider_and_is_checked_against_the_field():
    plain, barrel = _camera(focal_mm=3.0), _camera(*BARREL, focal_mm=3.0)
    assert barrel.hfov_deg > plain.hfov_deg + 0.5
    wide = _camera(-0.4, 0.0, focal_mm=3.0)  # 35.0° seen: more than the reference field's 34.3°
    camera_window(plain, REFERENCE_EXTENT)  # 33.3° without the distortion: inside
    with pytest.raises(FieldOfViewError, match="collection's field"):
        camera_window(wide, REFERENCE_EXTENT)


def test_a_lens_that_folds_is_refused():
    with pytest.raises(ValueError, match="the spec as a whole: distortion k1 -1, k2 0 folds the image"):
        _camera(-1.0, 0.0, focal_mm=1.0)
