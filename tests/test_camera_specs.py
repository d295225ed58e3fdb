"""The camera registry: names, derived sizes, hashing and one-line errors."""

import pytest

from benchmark.cameras import CameraSpec, camera_names, list_cameras, load_camera

PAPER = [(4.2, 3.1, 55), (3.5, 6.4, 55), (2.8, 9.1, 55), (2.1, 10.9, 55), (2.8, 3.8, 75), (2.1, 6.4, 75),
         (1.4, 3.3, 75), (1.0, 8.9, 75), (2.1, 2.7, 100), (1.4, 5.4, 100), (1.0, 6.1, 100), (1.4, 1.9, 150),
         (1.0, 3.3, 150)]
SIZES = {1.0: (2688, 1512), 1.4: (1920, 1080), 2.1: (1280, 720), 2.8: (960, 540), 3.5: (768, 432), 4.2: (640, 360)}


def test_registry_matches_the_paper():
    cams = list_cameras()
    assert [c.name for c in cams] == [f"cam{i:02d}" for i in range(1, 14)] == camera_names()
    for cam, (pixel_um, f_number, group) in zip(cams, PAPER):
        assert (cam.pixel_um, cam.f_number, cam.mtf50_group_cy_per_mm) == (pixel_um, f_number, group)
        assert (cam.width_px, cam.height_px) == SIZES[pixel_um]
        s = cam.sensor
        assert (s.well_capacity_e, s.conversion_gain_uv_per_e, s.voltage_swing_v, s.read_noise_e) == (6000, 76.5, 0.4591, 5)
        assert (s.adc_bits, s.black_level_dn, s.prnu_fraction, s.cfa) == (10, 64, 0.007, "RGGB")
        assert cam.exposure.mode == "auto_peak" and cam.exposure.max_exposure_s == 0.016


def test_load_by_number_name_and_path(tmp_path):
    assert load_camera(12) == load_camera("12") == load_camera("cam12") == load_camera(" cam12 ")
    path = tmp_path / "mine.yaml"
    path.write_text("name: mine\noptics: {f_number: 2.4}\nsensor: {pixel_um: 1.4}\n")
    cam = load_camera(path)
    assert (cam.width_px, cam.height_px, cam.sensor.well_capacity_e) == (1920, 1080, 6000)


def test_sha256_is_stable_and_sensitive():
    a, b = load_camera("cam07"), load_camera("cam07")
    assert a.sha256() == b.sha256() and len(a.sha256()) == 64
    changed = CameraSpec.model_validate({**a.model_dump(exclude={"sensor"}),
                                         "sensor": {"pixel_um": 1.4, "read_noise_e": 4.0}})
    assert changed.sha256() != a.sha256()


def test_unknown_name_lists_valid_names():
    with pytest.raises(ValueError, match=r"unknown camera 'cam99'.*cam01, cam02"):
        load_camera("cam99")


@pytest.mark.parametrize(
    "text, pattern",
    [
        ("name: x\noptics: {f_number: 2}\nsensor: {pixel_um: 0}\n", r"sensor\.pixel_um.*0\.2 <= pixel_um <= 20"),
        ("name: x\noptics: {f_number: 200}\nsensor: {pixel_um: 1}\n", r"optics\.f_number.*<= 64"),
        ("name: x\noptics: {f_number: 2}\nsensor: {pixel_um: 1, adc_bits: 4}\n", r"sensor\.adc_bits.*8 <= adc_bits <= 16"),
        ("name: x\noptics: {f_number: 2}\nsensor: {pixel_um: 1, cfa: BGGR}\n", r"sensor\.cfa.*RGGB"),
        ("name: x\noptics: {f_number: 2}\nsensor: {pixel_um: 1}\nisp: {demosaic: vng}\n", r"isp\.demosaic.*malvar2004, bilinear"),
        ("name: x\noptics: {f_nmber: 2}\nsensor: {pixel_um: 1}\n", r"optics\.f_n"),
        ("name: x\noptics: {f_number: 2\n", r"invalid YAML"),
        ("- just\n- a list\n", r"expected a mapping"),
    ],
)
def test_bad_yaml_gives_one_line_value_error(tmp_path, text, pattern):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ValueError, match=pattern) as info:
        load_camera(path)
    assert "\n" not in str(info.value)
