"""The camera registry: names, derived sizes, hashing and one-line errors."""

import pytest

from benchmark.camera import CameraSpec, camera_names, list_cameras, load_camera

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


# --- specs validated as a whole ----------------------------------------------------------

_BASE = "name: x\noptics: {f_number: 2}\n"


@pytest.mark.parametrize(
    "sensor, pattern",
    [
        ("{pixel_um: 1, adc_bits: 8, black_level_dn: 4096}", r"black_level_dn 4096 must be below the ADC white level 255"),
        ("{pixel_um: 1, adc_bits: 8, black_level_dn: 255}", r"black_level_dn 255 must be below the ADC white level 255"),
        ("{pixel_um: 1, qe: /etc/passwd}", r"sensor\.qe' = '/etc/passwd': an absolute path is refused"),
        ("{pixel_um: 1, qe: ../x.csv}", r"sensor\.qe' = '\.\./x\.csv': '\.\.' is refused"),
        ("{pixel_um: 1, qe: data/../../x.csv}", r"'\.\.' is refused"),
        ("{pixel_um: 1, qe: 'C:\\x.csv'}", r"sensor\.qe.*a relative path with '/' separators is expected"),
        ("{pixel_um: 1, qe: missing.csv}", r"qe 'missing\.csv': no packaged file of that name and no file .*missing\.csv"),
        ("{pixel_um: 1, qe: notes.txt}", r"a \.csv file is expected"),
        ("{pixel_um: 0.2}", r"13440 x 7560 px \(101\.6 Mpx.*about 24\.2 GiB, above the 4 GiB limit"),
        ("{pixel_um: 0.2, active_width_mm: 50, active_height_mm: 50}", r"250000 x 250000 px.*GiB, above the 4 GiB"),
        ("{pixel_um: 1.4, active_width_mm: 50, active_height_mm: 50}", r"35714 x 35714 px.*about 304\.1 GiB"),
        ("{pixel_um: 10, active_width_mm: 0.1}", r"10 x 151 px .*at least 16 px per side"),
    ],
)
def test_bad_sensor_as_a_whole_is_refused_in_one_line(tmp_path, sensor, pattern):
    path = tmp_path / "bad.yaml"
    path.write_text(_BASE + f"sensor: {sensor}\n")
    with pytest.raises(ValueError, match=pattern) as info:
        load_camera(path)
    assert "\n" not in str(info.value) and str(path) in str(info.value)


def test_unknown_illuminant_is_refused_and_known_ones_pass(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(_BASE + "sensor: {pixel_um: 1}\nisp: {white_balance: known_illuminant, illuminant: D66}\n")
    with pytest.raises(ValueError, match=r"isp\.illuminant' = 'D66': unknown illuminant 'D66'") as info:
        load_camera(path)
    assert "\n" not in str(info.value)
    path.write_text(_BASE + "sensor: {pixel_um: 1}\nisp: {white_balance: known_illuminant, illuminant: A}\n")
    assert load_camera(path).isp.illuminant == "A"


def test_qe_user_file_is_read_beside_the_spec_file(tmp_path, monkeypatch):
    import numpy as np

    from benchmark.camera.calibration import color_matrix
    from benchmark.camera.sensor import effective_qe

    folder = tmp_path / "mycam"
    (folder / "data").mkdir(parents=True)
    from metricscenes.spectral import SENSOR_DATA_DIR

    lines = (SENSOR_DATA_DIR / "imx363_qe.csv").read_text().splitlines()
    halved = [lines[0]] + [",".join([row.split(",")[0]] + [f"{float(v) / 2:.6g}" for v in row.split(",")[1:4]]
                                    + row.split(",")[4:]) for row in lines[1:]]
    (folder / "data" / "half_qe.csv").write_text("\n".join(halved) + "\n")
    (folder / "cam.yaml").write_text(_BASE + "sensor: {pixel_um: 1.4, qe: data/half_qe.csv}\n")
    monkeypatch.chdir(tmp_path)  # not the spec's folder: the file is found beside the spec anyway
    cam = load_camera("mycam/cam.yaml")
    assert cam.sensor.qe == "data/half_qe.csv"  # the spec (and its sha256) keep the relative name
    assert cam.sensor.qe_path == (folder / "data" / "half_qe.csv").resolve()
    reference = load_camera("cam10").sensor
    np.testing.assert_allclose(effective_qe(cam.sensor), effective_qe(reference) / 2, rtol=1e-5, atol=1e-9)
    np.testing.assert_allclose(color_matrix(cam.sensor), color_matrix(reference), atol=1e-4)  # scale-free fit
    assert load_camera(folder / "cam.yaml") == cam


def test_registry_specs_pass_the_whole_spec_checks_unchanged():
    for cam in list_cameras():
        assert cam.sensor.qe == "imx363_qe.csv" and cam.sensor._qe_path is None
        assert cam.sensor.capture_memory_bytes < 1.0 * 2**30
