"""A camera's own field of view: focal length and pixel array set the field,
the camera samples its window of the collection's field, ground truth follows the same
mapping, a camera wider than the collection is refused, and the 13 registry cameras are
unchanged. Synthetic scenes of one band (550 nm), no renders."""

import math

import numpy as np
import pytest

from benchmark.camera import optics as _optics
from benchmark.camera import sensor as _sensor
from benchmark.camera.pipeline import FieldOfViewError, camera_extent, camera_window, electron_rate
from benchmark.camera import camera_from_dict, list_cameras, load_camera
from benchmark.experiments.collection_view import camera_geometry, collection_field
from benchmark.experiments.run import run_camera
from metricscenes.geometry import (
    HORIZONTAL_FOV_DEG,
    REFERENCE_EXTENT,
    VERTICAL_FOV_DEG,
    TanExtent,
    fov_deg,
    tan_to_grid,
)
from metricscenes.groundtruth import box_tan_to_xywh, scale_groundtruth
from metricscenes.radiance import RadianceLayer, SpectralScene

REPO_CAMERA = "cameras/lux-sweep-1.4um-f2.4.yaml"
WL = np.array([550.0])


def _camera(name, pixel_um, width_mm, height_mm, focal_mm=4.38):
    return camera_from_dict({"name": name, "optics": {"f_number": 2.0, "focal_length_mm": focal_mm},
                             "sensor": {"pixel_um": pixel_um, "active_width_mm": width_mm,
                                        "active_height_mm": height_mm}})


CAM_3_2 = ("r3x2", 2.8, 2.016, 1.344)   # 720 x 480 px, 25.92° x 17.45°
CAM_4_3 = ("r4x3", 2.8, 1.792, 1.344)   # 640 x 480 px, 23.12° x 17.45°


def _scene(inset: np.ndarray, extent: TanExtent) -> SpectralScene:
    """A black plate over the reference field and a bright inset (one band, 550 nm)."""
    plate = RadianceLayer(np.zeros((27, 48, 1), np.float32), REFERENCE_EXTENT)
    return SpectralScene(layers=(plate, RadianceLayer(inset[..., None].astype(np.float32), extent)),
                         wavelengths_nm=WL.copy())


def _disc_scene(radius_tan: float, n: int = 400, supersample: int = 4) -> SpectralScene:
    half = 1.25 * radius_tan
    s = (np.arange(n * supersample) + 0.5) / (n * supersample) * 2 * half - half
    inside = (s[None, :] ** 2 + s[:, None] ** 2 <= radius_tan**2).astype(np.float32)
    cover = inside.reshape(n, supersample, n, supersample).mean(axis=(1, 3))
    return _scene(cover, TanExtent(-half, -half, half, half))


def _square_scene(x0, y0, x1, y1) -> SpectralScene:
    return _scene(np.ones((50, 50), np.float32), TanExtent(x0, y0, x1, y1))


def _image(scene, cam, **kw) -> np.ndarray:
    """Green-channel signal normalised to 1 where the bright target fills a pixel."""
    g = electron_rate(scene, cam, diffraction=False, **kw)[1].astype(np.float64)
    return g / g.max()


def _moments_aspect(img: np.ndarray) -> float:
    rows, cols = np.indices(img.shape)
    w = img / img.sum()
    cx, cy = (w * cols).sum(), (w * rows).sum()
    return math.sqrt((w * (cols - cx) ** 2).sum() / (w * (rows - cy) ** 2).sum())


# --- the registry's 13 cameras are unchanged ------------------------------------------

def test_registry_cameras_see_exactly_the_reference_field():
    cams = list_cameras() + [load_camera(REPO_CAMERA)]
    copy = TanExtent(*REFERENCE_EXTENT.as_tuple())  # a field read back from a store's attributes
    for cam in cams:
        assert camera_window(cam) is REFERENCE_EXTENT, cam.name
        assert camera_window(cam, copy) is copy
        assert cam.hfov_deg == pytest.approx(HORIZONTAL_FOV_DEG, rel=1e-12)
        assert cam.vfov_deg == pytest.approx(VERTICAL_FOV_DEG, rel=1e-12)
        assert camera_geometry(_StubCollection(), cam) is None  # results.json and cache keys keep their bytes


def test_registry_capture_is_byte_identical_to_the_full_field_path():
    cam = load_camera("cam01")
    rng = np.random.default_rng(3)
    e = REFERENCE_EXTENT
    inset_ext = TanExtent(-0.05, -0.02, 0.04, 0.03)
    scene = SpectralScene(layers=(RadianceLayer(rng.random((54, 96, 31), dtype=np.float32) * 0.01, e),
                                  RadianceLayer(rng.random((120, 200, 31), dtype=np.float32) * 0.02, inset_ext)))
    new = electron_rate(scene, cam)
    # the code path before cameras had their own field: the whole field, resampled to the grid
    resp = _sensor.channel_responsivity(cam.sensor, np.asarray(scene.wavelengths_nm, float))
    old = _optics.channel_signal(scene.resample(cam.width_px, cam.height_px), scene.wavelengths_nm, cam.optics,
                                 cam.pixel_um, resp)
    assert new.dtype == old.dtype and np.array_equal(new, old)


def test_registry_groundtruth_is_unchanged():
    gt = {"info": {}, "categories": [], "images": [{"id": 1, "width": 1920, "height": 1080}],
          "annotations": [{"id": 1, "image_id": 1, "bbox": [900.25, 500.5, 40.125, 20.0], "area": 802.5}]}
    cam = load_camera("cam07")
    assert scale_groundtruth(gt, cam.width_px, cam.height_px, field=REFERENCE_EXTENT,
                             window=camera_window(cam)) == scale_groundtruth(gt, cam.width_px, cam.height_px)


# --- own field of view -----------------------------------------------------------------

@pytest.mark.parametrize("spec", [CAM_3_2, CAM_4_3], ids=lambda s: s[0])
def test_a_circle_is_imaged_as_a_circle(spec):
    cam = _camera(*spec)
    radius = 0.02
    scene = _disc_scene(radius)
    img = _image(scene, cam)
    assert _moments_aspect(img) == pytest.approx(1.0, abs=0.005)
    # its diameter in pixels is the angular diameter over the pixel's angle
    ifov_tan = cam.pixel_um * 1e-3 / cam.optics.focal_length_mm
    assert math.sqrt(img.sum() * 4 / math.pi) == pytest.approx(2 * radius / ifov_tan, rel=0.005)
    # the defect this replaces: the whole 16:9 field stretched onto the 3:2 / 4:3 grid
    stretched = _image(scene, cam, extent=REFERENCE_EXTENT)
    assert abs(_moments_aspect(stretched) - 1.0) > 0.1


@pytest.mark.parametrize("spec", [CAM_3_2, CAM_4_3, ("tele", 4.2, 2.688, 1.512, 8.76), ("ref", 4.2, 2.688, 1.512)],
                         ids=lambda s: s[0])
def test_a_square_subtends_its_angle_over_the_ifov(spec):
    cam = _camera(*spec)
    half = 0.01  # a 20 mrad (tangent) square on the axis
    img = _image(_square_scene(-half, -half, half, half), cam)
    expected_px = 2 * half / (cam.pixel_um * 1e-3 / cam.optics.focal_length_mm)
    assert math.sqrt(img.sum()) == pytest.approx(expected_px, rel=1e-4)
    assert img.sum(axis=1).max() == pytest.approx(expected_px, rel=1e-4)  # width
    assert img.sum(axis=0).max() == pytest.approx(expected_px, rel=1e-4)  # height


def test_pixels_are_square_in_angle_and_the_pixel_array_sets_the_field():
    cam = _camera("odd", 1.4, 2.5, 1.2)  # 1785.7 x 857.1 pixels written: 1786 x 857
    assert (cam.width_px, cam.height_px) == (1786, 857)
    w = camera_extent(cam)
    assert w.width / cam.width_px == pytest.approx(w.height / cam.height_px, rel=1e-12)
    assert w.width / cam.width_px == pytest.approx(1.4e-3 / 4.38, rel=1e-12)
    assert cam.hfov_deg == pytest.approx(math.degrees(2 * math.atan(1786 * 1.4e-3 / 2 / 4.38)), rel=1e-12)
    assert fov_deg(w) == pytest.approx((cam.hfov_deg, cam.vfov_deg), rel=1e-12)


def test_groundtruth_follows_the_pixels_of_the_window():
    cam = _camera(*CAM_3_2)
    box_tan = (0.031, 0.012, 0.052, 0.0265)  # off the axis: the offset of the window matters
    img = _image(_square_scene(*box_tan), cam)
    # ground truth as the generator writes it (reference grid over the reference field)
    gt = {"info": {}, "categories": [], "images": [{"id": 1, "width": 1920, "height": 1080}],
          "annotations": [{"id": 1, "image_id": 1, "bbox": box_tan_to_xywh(box_tan, 1920, 1080), "area": 0}]}
    (ann,) = scale_groundtruth(gt, cam.width_px, cam.height_px, field=REFERENCE_EXTENT,
                               window=camera_window(cam))["annotations"]
    cols, rows = img.max(axis=0), img.max(axis=1)
    c, r = np.flatnonzero(cols > 1e-9), np.flatnonzero(rows > 1e-9)
    measured = [c[0] + 1 - cols[c[0]], r[0] + 1 - rows[r[0]], c[-1] + cols[c[-1]], r[-1] + rows[r[-1]]]
    x, y, w, h = ann["bbox"]
    np.testing.assert_allclose([x, y, x + w, y + h], measured, atol=2e-3)
    np.testing.assert_allclose([x, y, x + w, y + h], tan_to_grid(np.array(box_tan).reshape(2, 2), camera_window(cam),
                                                                 cam.width_px, cam.height_px).ravel(), atol=1e-3)


def test_groundtruth_is_clipped_to_the_window_and_dropped_outside_it():
    cam = _camera("tele", 4.2, 2.688, 1.512, 8.76)  # half the reference field: 640 x 360 over the middle
    gt = {"info": {}, "categories": [], "images": [{"id": 1, "width": 1920, "height": 1080},
                                                   {"id": 2, "width": 1920, "height": 1080}],
          "annotations": [{"id": 1, "image_id": 1, "bbox": [1400.0, 500.0, 200.0, 100.0], "area": 0},   # half in
                          {"id": 2, "image_id": 2, "bbox": [1700.0, 500.0, 100.0, 100.0], "area": 0}]}  # outside
    out = scale_groundtruth(gt, cam.width_px, cam.height_px, field=REFERENCE_EXTENT, window=camera_window(cam))
    assert [a["id"] for a in out["annotations"]] == [1]
    x, y, w, h = out["annotations"][0]["bbox"]
    # the window spans reference columns 480..1440 at 960/640 = 1.5 reference px per camera px
    assert (x, x + w) == pytest.approx(((1400 - 480) / 1.5, 640.0))
    assert (y, h) == pytest.approx(((500 - 270) / 1.5, 100 / 1.5))
    assert {im["width"] for im in out["images"]} == {640}


# --- refusals ----------------------------------------------------------------------------

def test_a_camera_wider_than_the_collection_is_refused_naming_both_fields():
    cam = _camera("wide32", 1.4, 2.688, 1.792)  # 1920 x 1280 at 4.38 mm: 34.1° x 23.1°
    with pytest.raises(FieldOfViewError) as info:
        camera_window(cam)
    msg = str(info.value)
    assert "\n" not in msg and "34.12° x 23.12°" in msg and "34.12° x 19.59°" in msg
    with pytest.raises(FieldOfViewError):
        electron_rate(_square_scene(-0.01, -0.01, 0.01, 0.01), cam, diffraction=False)
    narrow = TanExtent(-0.1, -0.05, 0.1, 0.05)
    with pytest.raises(FieldOfViewError, match=r"more than the collection's field 11\.42° x 5\.72°"):
        camera_window(load_camera("cam01"), narrow)


class _StubCollection:
    """Enough of a collection for the checks made before anything is written."""

    def scenes(self):
        return []


def test_run_refuses_a_wide_camera_before_writing_anything(tmp_path):
    cam = _camera("wide32", 1.4, 2.688, 1.792)
    out = tmp_path / "run"
    with pytest.raises(FieldOfViewError):
        run_camera(_StubCollection(), cam, "day", None, out)
    assert not out.exists()
    assert collection_field(_StubCollection()) is REFERENCE_EXTENT
    geometry = camera_geometry(_StubCollection(), _camera(*CAM_3_2))
    assert geometry["hfov_deg"] == pytest.approx(25.92, abs=0.01) and len(geometry["window_tan"]) == 4
