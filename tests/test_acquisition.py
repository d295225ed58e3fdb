"""Acquisition as a value: one function per strategy returning a RawCapture — one
exposure, two-frame HDR, an HDR pixel (dual conversion gain + split pixel) merged on the
sensor and companded; RCCB / RCCC colour filters and their ISP; the automotive cameras and
their datasheet figures (photon transfer); lens tables hashed by content; the paper's
cameras byte for byte as before."""

from __future__ import annotations

import hashlib
import math

import colour
import numpy as np
import pytest
import yaml

from benchmark.camera import acquisition, camera_from_dict, camera_names, dual_gain, extra_camera_names, load_camera
from benchmark.camera import sensor as _sensor
from benchmark.camera.calibration import checker_delta_e2000, checker_reflectances, checker_targets_linear_srgb
from benchmark.camera.calibration import illuminant_spectrum
from benchmark.camera.exposure import parse_exposure, with_exposure
from benchmark.camera.pipeline import simulate
from benchmark.camera.registry import DATA_DIR
from benchmark.camera.spec_files import file_sha256
from benchmark.camera.spec_sensor import SensorSpec
from benchmark.measure.mtf import measure_mtf50
from benchmark.measure.photon_transfer import datasheet_figures, photon_transfer
from metricscenes.geometry import REFERENCE_EXTENT, TanExtent
from metricscenes.radiance import RadianceLayer, SpectralScene
from metricscenes.spectral import WAVELENGTHS_NM

AUTO = "auto-imx490-like"
D65 = illuminant_spectrum("D65")


def _sha(array: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(array).tobytes()).hexdigest()


# ── the paper's cameras, byte for byte as before ────────────────────────────────────────

def _basis() -> np.ndarray:
    return np.stack([np.exp(-0.5 * ((WAVELENGTHS_NM - c) / 40.0) ** 2) for c in (450, 550, 630)]).astype(np.float32)


def _reference_scene() -> SpectralScene:
    """tests/test_lens.py's: a plate over the reference field and a brighter inset, seed 27."""
    rng = np.random.default_rng(27)
    plate = (rng.random((54, 96, 3), dtype=np.float32) @ _basis() * np.float32(0.02)).astype(np.float32)
    inset = (rng.random((60, 80, 3), dtype=np.float32) @ _basis() * np.float32(0.05)).astype(np.float32)
    return SpectralScene(layers=(RadianceLayer(plate, REFERENCE_EXTENT),
                                 RadianceLayer(inset, TanExtent(-0.03, -0.02, 0.03, 0.025))))


def _lamp_scene() -> SpectralScene:
    """A dim plate with two bright lamps in an inset (the lamps set the exposure)."""
    rng = np.random.default_rng(5)
    plate = (rng.random((54, 96, 3), dtype=np.float32) @ _basis() * np.float32(2e-6)).astype(np.float32)
    lamp = np.zeros((20, 40, 3), np.float32)
    lamp[5:15, 5:15] = 1.0
    lamp[5:15, 25:35] = 0.3
    inset = (lamp @ _basis() * np.float32(0.02)).astype(np.float32)
    return SpectralScene(layers=(RadianceLayer(plate, REFERENCE_EXTENT),
                                 RadianceLayer(inset, TanExtent(-0.04, -0.02, 0.04, 0.02))))


# Recorded with the code before this work (commit 3358ea4), seed 7: raw, rgb8, exposure;
# for hdr:16 also the short raw, the merged raw and the short exposure.
BEFORE = {
    ("cam12", "hdr:16", "reference"): {
        "raw": "1f1c39942f9175f631f96383806fb6e7eb160b2fa1bf374ca405716b99f43218",
        "raw_short": "8230b7ca6e5223e64675819093aa145c6d5866bc371cafb1e2dc39201fad4d75",
        "merged": "afbeb295b9a2289b15885cd586b30b21f149ae847b4f0990f72411aa7d3f2e8e",
        "rgb8": "452d732dec82406f1b446344458e88fd1e5d13cc9c979a3c3f77723489695bdc",
        "exposure_s": 0.007549807172387684, "exposure_short_s": 0.0004718629482742303},
    ("cam08", "hdr:16", "reference"): {
        "raw": "805fc7ce114a32ce0fd010eff1a424884520d778018bbdad74eb9b5c2aee942c",
        "raw_short": "ec3a10aa710936fd5986ebb6dac3d707cd93c7c37145576d7ca14049729b1f1c",
        "merged": "ae25c9d007e021e2bda6243d6434d1f31e7b08581f126d2227317c48594e0e44",
        "rgb8": "4d359233cf3550fbab9e685c13d9471d2a24f071e0899619750ba0c5f0c7fd24",
        "exposure_s": 0.016, "exposure_short_s": 0.001},
    ("cam12", "hdr:16", "lamps"): {
        "raw": "9877773b9a45217233eb5d585b0e291ed781d814b51bb7325a2d7cbd20d76f8f",
        "raw_short": "6c1fb791c8c0251b74d5efcb91b529eb3b3725310d7b1b25308fb37f0dc9c362",
        "merged": "b38426e4bc02204b55abe1de426aaf03555aeed23e41177f0ee3f7d41f7b5ebf",
        "rgb8": "db6e02df77105cd22a179b528b552ad805d3957000f22d215467431546f1e45d",
        "exposure_s": 0.013382780111824847, "exposure_short_s": 0.0008364237569890529},
    ("cam12", None, "lamps"): {
        "raw": "dba511d895c228f2613520d68921d96283a7e9e951b46025bbe950d874f47c6a",
        "rgb8": "0ca704079182f2bfbf361a5b843cd486ff343f1a93db73b6938e477b739f787b",
        "exposure_s": 0.0008364237569890529},
}


@pytest.mark.parametrize("key", sorted(BEFORE, key=str))
def test_single_and_two_frame_captures_are_byte_identical_to_before(key):
    name, policy, scene = key
    camera = load_camera(name) if policy is None else with_exposure(load_camera(name), parse_exposure(policy))
    cap = simulate(_reference_scene() if scene == "reference" else _lamp_scene(), camera, seed=7)
    want = BEFORE[key]
    assert (_sha(cap.raw_dn), _sha(cap.rgb8), cap.exposure_s) == (want["raw"], want["rgb8"], want["exposure_s"])
    if policy is None:
        assert cap.raw.strategy == "single" and cap.merged_dn is None and cap.exposure_short_s is None
        assert cap.raw.linear_dn is cap.raw_dn  # the ISP processes the raw itself
        return
    assert (_sha(cap.raw_short_dn), _sha(cap.merged_dn), cap.exposure_short_s) == \
        (want["raw_short"], want["merged"], want["exposure_short_s"])
    # the Capture's HDR fields are the RawCapture's
    raw = cap.raw
    assert raw.strategy == "two_frame_hdr" and [f.name for f in raw.frames] == ["long", "short"]
    assert raw.frame("short").raw_dn is cap.raw_short_dn and raw.linear_dn is cap.merged_dn
    assert raw.white == pytest.approx(raw.reference_scale * 16.0)


def test_the_mtf_bench_runs_the_cameras_acquisition_and_isp_as_before():
    """Recorded before this work: cam12's MTF50 and curve (project ISP, ISO e-SFR) and
    cam01's with ISETCam's ISP and e-SFR."""
    cam12 = measure_mtf50(load_camera("cam12"))
    assert cam12["mtf50_cy_per_mm"] == 229.34639770214133
    assert _sha(cam12["mtf"]) == "44351f65719baab7a47282c7882c213a1f4a30ac796757009219139952819adc"
    from benchmark.camera.spec_isp import isp_preset
    cam01 = measure_mtf50(load_camera("cam01").model_copy(update={"isp": isp_preset("iset-parity")}), esfr="isetcam")
    assert cam01["mtf50_cy_per_mm"] == 56.6
    assert _sha(cam01["mtf"]) == "4aea341670bdaac06eb0ca67496373067bd31420ffd361829080c22db20afe80"


# ── the HDR pixel: photon transfer, dynamic range, transitions ──────────────────────────

@pytest.fixture(scope="module")
def auto_ptc():
    camera = load_camera(AUTO)
    return camera, photon_transfer(camera, exposure_s=0.016)


def test_the_hdr_pixels_photon_transfer_shows_each_gain_and_its_transitions(auto_ptc):
    camera, ptc = auto_ptc
    sensor = camera.sensor
    hcg, lcg, spd = dual_gain.readouts(sensor)
    # Each raw frame's variance against its mean (EMVA 1288: the slope is the system gain K,
    # DN per electron of its photodiode) below its saturation: 300 and 40 uV/e- at 1/4095 V per DN.
    for r in (hcg, lcg, spd):
        mean, var = ptc.frames[r.name]
        k = dual_gain.dn_per_electron(sensor, r)
        charge = ptc.electrons * r.sensitivity
        shot = (charge > 30 * r.read_noise_e**2 + 50) & (charge < 0.8 * r.saturation_e)
        slope = np.polyfit(mean[shot], var[shot], 1)[0]
        assert slope == pytest.approx(k, rel=0.04), r.name
    assert dual_gain.dn_per_electron(sensor, hcg) / dual_gain.dn_per_electron(sensor, lcg) == pytest.approx(7.5)
    # The merged signal (electrons of the large photodiode): shot-noise slope 1 on the large
    # photodiode, 1 / sensitivity_ratio (40) once the small one takes over.
    e, var = ptc.electrons, ptc.temporal_var_e2
    large = (e > 200) & (e < 0.8 * 18000)
    small = (e > 40000) & (e < 0.8 * 800000)
    assert np.polyfit(e[large], var[large], 1)[0] == pytest.approx(1.0, rel=0.05)
    assert np.polyfit(e[small], var[small], 1)[0] == pytest.approx(40.0, rel=0.05)
    # Transitions where the spec puts them (half the pixels of a level moved on), within 3 %.
    sheet = datasheet_figures(camera, ptc)
    found = {(t["from"], t["to"]): t["electrons"] for t in sheet["transitions"]}
    assert found[("hcg", "lcg")] == pytest.approx(sensor.dcg.hcg_to_lcg_e, rel=0.03)
    assert found[("lcg", "spd")] == pytest.approx(sensor.dcg.small_photodiode.lcg_to_spd_e, rel=0.03)
    # the SNR dip after the small photodiode takes over: its 450 e- and 3 e- read noise (about 26.5 dB)
    dip = next(t for t in sheet["transitions"] if t["to"] == "spd")["snr_db_after"]
    assert 25.0 < dip < 28.5


def test_the_hdr_pixels_measured_dynamic_range_is_the_spec_s(auto_ptc):
    camera, ptc = auto_ptc
    sheet = datasheet_figures(camera, ptc)
    sensor = camera.sensor
    floor = dual_gain.noise_floor_e(sensor, dual_gain.readouts(sensor)[0])
    spec_db = 20 * math.log10(dual_gain.merged_saturation_e(sensor) / floor)
    assert sheet["dynamic_range_db"] == pytest.approx(spec_db, abs=1.0)
    assert sheet["dynamic_range_db"] == pytest.approx(121.0, abs=1.0)  # Iida et al., IEDM 2018
    assert sheet["saturation_e"] == pytest.approx(800000, rel=0.01)
    assert sheet["dark_noise_e"] == pytest.approx(floor, rel=0.1)  # 0.68 e- read noise and the HCG's LSB
    assert sheet["snr10_lux"] > 0 and sheet["snr1_lux"] < sheet["snr10_lux"]


def test_a_single_gain_sensors_photon_transfer_is_its_own():
    camera = load_camera("cam12")
    sheet = datasheet_figures(camera)
    assert sheet["saturation_e"] == pytest.approx(1146.1, rel=0.002) and sheet["transitions"] == []
    assert 20 * math.log10(1146.1 / 5.012) == pytest.approx(sheet["dynamic_range_db"], abs=0.5)


def test_the_hdr_pixels_noise_free_capture_is_the_linear_scene():
    """A small camera with the automotive sensor on a ramp of light over 5 decades: the
    decompanded linear signal is the noise-free signal within the companding and ADC steps."""
    camera = _small_auto_camera()
    rate = np.geomspace(1e2, 5e7, camera.height_px)[:, None] * np.ones((1, camera.width_px))
    fixed = with_exposure(camera, parse_exposure("fixed:0.01"))
    raw = acquisition.acquire(rate, fixed, seed=0, noise=False)
    assert raw.strategy == "dual_gain" and [f.name for f in raw.frames] == ["hcg", "lcg", "spd"]
    sensor = camera.sensor
    steps = dual_gain.readouts(sensor)
    k = dual_gain.dn_per_electron(sensor, steps[0])
    truth = np.minimum(rate * 0.01, 800000.0) * k
    got = raw.linear_dn.astype(np.float64) - sensor.black_level_dn
    # each readout's ADC step on the merged scale, the merged word's and half a companding step
    adc_step = np.array([k / (dual_gain.dn_per_electron(sensor, r) * r.sensitivity) for r in steps])
    choice = dual_gain.readout_choice({f.name: f.raw_dn for f in raw.frames}, sensor)
    step = np.interp(raw.merged_dn.astype(np.float64), *zip(*_segment_steps(sensor.dcg.companding_knees)))
    assert np.all(np.abs(got - truth) <= 0.5 * adc_step[choice] + 0.5 + 0.5 * step + 1e-6)
    assert set(np.unique(choice)) == {0, 1, 2}  # the ramp crosses both transitions
    assert raw.exposure_s == 0.01 and raw.reference_scale == 1.0 and raw.white == pytest.approx(256.004, rel=1e-5)
    # the same seed, the same bytes; another seed, other noise
    a, b = (acquisition.acquire(rate, fixed, seed=s) for s in (3, 3))
    assert np.array_equal(a.output_dn, b.output_dn)
    assert not np.array_equal(a.output_dn, acquisition.acquire(rate, fixed, seed=4).output_dn)


def _segment_steps(knees):
    """(merged code, merged codes per output code) at each knee, for np.interp."""
    out = []
    for (x0, y0), (x1, y1) in zip(knees[:-1], knees[1:]):
        out.append((x0, (x1 - x0) / (y1 - y0)))
    out.append((knees[-1][0], out[-1][1]))
    return out


def test_companding_is_monotonic_and_invertible_within_one_code():
    knees = load_camera(AUTO).sensor.dcg.companding_knees
    codes = np.arange(4096)
    assert np.array_equal(dual_gain.compand(dual_gain.decompand(codes, knees), knees), codes)
    x = np.unique(np.concatenate([np.arange(0, 70000), np.random.default_rng(1).integers(0, 2**24, 200000),
                                  [k[0] for k in knees]]))
    y = dual_gain.compand(x, knees)
    assert np.all(np.diff(y.astype(int)) >= 0) and y[0] == 0 and y.max() <= 4095
    back = dual_gain.decompand(y, knees)
    one_code = np.interp(x, *zip(*_segment_steps(knees)))
    assert np.all(np.abs(back - x) <= one_code)
    assert np.all(np.abs(back - x) <= 0.5 * one_code + 1e-6)  # half a step: rounded to the nearest code


def test_the_companding_steps_stay_below_the_temporal_noise():
    """The knees' design rule (docs/camera.md): each segment the merged range reaches has a
    step, at its start, below the merged signal's temporal noise there, so companding adds at
    most step²/12 to the noise variance."""
    camera = load_camera(AUTO)
    sensor = camera.sensor
    k = dual_gain.dn_per_electron(sensor, dual_gain.readouts(sensor)[0])
    top = sensor.black_level_dn + dual_gain.merged_saturation_e(sensor) * k
    for x, step in _segment_steps(sensor.dcg.companding_knees)[1:-1]:
        if x > top:  # codes the merged range never reaches
            continue
        signal_e = (x - sensor.black_level_dn) / k
        noise_dn = math.sqrt(dual_gain.temporal_variance_e2(sensor, signal_e)) * k
        assert step <= noise_dn, (x, step, noise_dn)


# ── clear-pixel colour filters ──────────────────────────────────────────────────────────

def test_the_clear_channel_is_the_sum_of_r_g_b_or_a_given_curve(tmp_path):
    rggb, rccb, rccc = (SensorSpec(pixel_um=1.4, cfa=c) for c in ("RGGB", "RCCB", "RCCC"))
    assert _sensor.cfa_channels("RCCB") == "RCB" and _sensor.cfa_channels("RCCC") == "RC"
    qe = _sensor.effective_qe(rggb)
    np.testing.assert_allclose(_sensor.effective_qe(rccb)[1], np.minimum(qe.sum(0), 1.0), rtol=1e-12)
    assert _sensor.effective_qe(rccc).shape == (2, WAVELENGTHS_NM.size)
    table = tmp_path / "qe.csv"
    table.write_text("wavelength_nm,qe_r,qe_g,qe_b,qe_c\n400,0.1,0.1,0.3,0.5\n700,0.4,0.1,0.05,0.45\n")
    measured = camera_from_dict({"name": "c", "optics": {"f_number": 2}, "sensor": {"pixel_um": 1.4, "cfa": "RCCB",
                                 "qe": "qe.csv"}}, spec_dir=tmp_path)
    assert _sensor.effective_qe(measured.sensor)[1][0] == pytest.approx(0.5)
    assert np.array_equal(_sensor.cfa_index(2, 2, "RCCC"), [[0, 1], [1, 1]])


def _checker_camera(cfa: str):
    data = yaml.safe_load((DATA_DIR / "cam01.yaml").read_text())
    data["name"] = f"checker-{cfa.lower()}"
    data["sensor"]["cfa"] = cfa
    data["isp"].update(white_balance="known_illuminant", output="linear")
    data["exposure"].update(region_fraction=1.0, peak_percentile=100.0)  # the brightest patch at 90 %: none clips
    return camera_from_dict(data)


def _checker_patches_linear_srgb(camera) -> np.ndarray:
    """The 24 ColorChecker patches under D65 as a 4 × 6 plate over the field, noise off,
    through the whole pipeline: the linear sRGB mean of each patch's inner half."""
    _, refl = checker_reflectances()
    cube = np.repeat(np.repeat((refl * D65 * 0.01).reshape(4, 6, -1), 40, axis=0), 40, axis=1).astype(np.float32)
    cap = simulate(SpectralScene(layers=(RadianceLayer(cube, REFERENCE_EXTENT),)), camera, seed=0, noise=False)
    h, w = cap.height_px / 4, cap.width_px / 6
    return np.array([cap.rgb_linear[int((i + 0.25) * h): int((i + 0.75) * h), int((j + 0.25) * w): int((j + 0.75) * w)]
                     .reshape(-1, 3).mean(0) for i in range(4) for j in range(6)])


def _delta_e(est: np.ndarray, ref: np.ndarray) -> np.ndarray:
    srgb = colour.RGB_COLOURSPACES["sRGB"]
    white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    lab = [colour.XYZ_to_Lab(colour.RGB_to_XYZ(x, srgb, apply_cctf_decoding=False), white) for x in (est, ref)]
    return colour.delta_E(lab[0], lab[1], method="CIE 2000")


def test_rccb_reproduces_the_colour_checker_within_the_stated_delta_e():
    """RCCB: green reconstructed from C, R and B by the calibrated least-squares matrix.
    With C = R + G + B the fit recovers green exactly: the ColorChecker's mean ΔE2000 is
    RGGB's, 2.1 (docs/camera.md). Through the whole pipeline (demosaic, 10-bit ADC, noise
    off) it stays below 2.5 on average (RGGB: 2.1) and within 1 of RGGB's patch by patch."""
    assert checker_delta_e2000(SensorSpec(pixel_um=1.4, cfa="RCCB")).mean() == pytest.approx(
        checker_delta_e2000(SensorSpec(pixel_um=1.4)).mean(), abs=0.01)
    ref = checker_targets_linear_srgb()
    results = {}
    for cfa in ("RGGB", "RCCB"):
        est = _checker_patches_linear_srgb(_checker_camera(cfa))
        est = est * (ref[18, 1] / est[18, 1])  # the white patch sets the scale (the exposure's choice)
        results[cfa] = _delta_e(est, ref)
    rccb, rggb = results["RCCB"], results["RGGB"]
    assert rggb.mean() < 2.2 and rccb.mean() < 2.5
    # Neutrals: within 1.5, but black (3 % reflectance), whose 10-bit steps, undithered
    # without noise, the reconstruction amplifies (G = 3.4 C - 1.2 R - 1.2 B): within 3.5.
    assert rccb[18:23].max() < 1.5 and rccb[23] < 3.5
    assert np.abs(rccb - rggb)[:23].max() < 1.0  # patch by patch, RGGB's colour


def test_rccc_renders_monochrome_plus_red():
    camera = _checker_camera("RCCC")
    est = _checker_patches_linear_srgb(camera)
    ref = checker_targets_linear_srgb()
    est = est * (ref[18, 1] / est[18, 1])
    assert _delta_e(est, ref)[18:].max() < 2.0  # greys stay grey
    red = est[14]  # ColorChecker "red"
    assert red[0] > 1.5 * red[1] and red[0] > 1.5 * red[2]  # red comes out red
    # Two channels: every colour lies in one plane of linear sRGB (monochrome plus red), so
    # the checker's 24 patches span two dimensions, not three.
    singular = np.linalg.svd(est, compute_uv=False)
    assert singular[2] < 0.01 * singular[0]


def test_rccc_demosaic_keeps_every_clear_sample():
    from benchmark.camera.isp import demosaic

    mosaic = np.random.default_rng(0).random((16, 20)).astype(np.float32)
    clear = _sensor.cfa_index(16, 20, "RCCC") == 1
    for method in ("malvar2004", "bilinear"):
        out = demosaic(mosaic, method, "RCCC")
        assert out.shape == (16, 20, 2)
        # colour-demosaicing's bilinear counts an edge sample twice (its 'reflect' border): inside only
        inner = np.s_[:, :] if method == "malvar2004" else np.s_[1:-1, 1:-1]
        np.testing.assert_array_equal(out[..., 1][inner][clear[inner]], mosaic[inner][clear[inner]])
        red = ~clear
        np.testing.assert_array_equal(out[..., 0][inner][red[inner]], mosaic[inner][red[inner]])
    # the clear pixels in blue's place keep their value even on the border
    np.testing.assert_array_equal(demosaic(mosaic, "bilinear", "RCCC")[1::2, 1::2, 1], mosaic[1::2, 1::2])


def test_an_rccb_hdr_camera_runs_end_to_end():
    camera = _small_auto_camera(cfa="RCCB")
    cap = simulate(_reference_scene(), camera, seed=1)
    assert cap.rgb8.shape == (camera.height_px, camera.width_px, 3) and cap.raw.strategy == "dual_gain"
    assert cap.raw_dn.dtype == np.uint16 and cap.raw_dn.max() <= 4095 and cap.exposure_short_s is None
    assert 20 < cap.rgb8.mean() < 235


# ── the automotive cameras in the registry ──────────────────────────────────────────────

def _small_auto_camera(cfa: str = "RGGB"):
    """auto-imx490-like's sensor on a 640 × 360 window (a lens scaled to the reference field)."""
    data = yaml.safe_load((DATA_DIR / f"{AUTO}.yaml").read_text())
    data["name"] = "small-auto"
    data["optics"]["focal_length_mm"] = 3.13
    data["sensor"].update(active_width_mm=1.92, active_height_mm=1.08, cfa=cfa)
    return camera_from_dict(data)


def test_the_automotive_cameras_are_extras_beside_the_paper_s_13():
    assert camera_names() == [f"cam{i:02d}" for i in range(1, 14)]
    assert extra_camera_names() == ["auto-imx490-like", "auto-imx490-rccb-like"]
    for name in extra_camera_names():
        camera = load_camera(name)
        assert camera.name == name and camera.sensor.dcg is not None
        assert camera.hfov_deg <= 34.12 and camera.vfov_deg <= 19.59  # it runs on the collections
    assert load_camera("auto-imx490-rccb-like").sensor.cfa == "RCCB"
    with pytest.raises(ValueError, match=r"extra cameras: auto-imx490-like.*did you mean 'auto-imx490-like'"):
        load_camera("auto-imx490")
    # a user file may not take an extra camera's name with another spec
    data = yaml.safe_load((DATA_DIR / f"{AUTO}.yaml").read_text())
    data["optics"]["f_number"] = 2.4
    with pytest.raises(ValueError, match="registry camera auto-imx490-like's"):
        from benchmark.camera.registry import check_not_a_registry_name
        check_not_a_registry_name(camera_from_dict(data))


def test_the_cli_shows_the_datasheet_figures():
    import json

    from typer.testing import CliRunner

    from benchmark.cli.cameras import app

    result = CliRunner().invoke(app, ["show", AUTO, "--json"])
    assert result.exit_code == 0, result.output
    derived = json.loads(result.stdout)["derived"]
    sheet = derived["datasheet"]
    assert sheet["dynamic_range_db"] == pytest.approx(121.0, abs=1.0)
    assert [(t["from"], t["to"]) for t in sheet["transitions"]] == [("hcg", "lcg"), ("lcg", "spd")]
    assert derived["saturation_e"] == 800000.0 and derived["mtf50"]["source"] == "measured"
    assert [r["name"] for r in derived["hdr_readouts"]] == ["hcg", "lcg", "spd"]
    text = CliRunner().invoke(app, ["show", AUTO]).output
    assert "SNR10" in text and "HDR lcg -> spd" in text and "measured through the whole" in text


# ── refused specs ───────────────────────────────────────────────────────────────────────

def _auto_with(change) -> dict:
    data = yaml.safe_load((DATA_DIR / f"{AUTO}.yaml").read_text())
    data["name"] = "mine"
    change(data)
    return data


@pytest.mark.parametrize("change, pattern", [
    (lambda d: d["sensor"].update(cfa="RGBW"), r"field 'sensor\.cfa' = 'RGBW'.*'RGGB', 'RCCB' or 'RCCC'"),
    (lambda d: d["sensor"]["dcg"].update(lcg_conversion_gain_uv_per_e=400.0),
     r"sensor\.dcg\.lcg_conversion_gain_uv_per_e 400 uV/e- is not below the high gain"),
    (lambda d: d["sensor"]["dcg"].update(hcg_to_lcg_e=5000.0),
     r"sensor\.dcg\.hcg_to_lcg_e 5000 e- is above the high-gain readout's saturation 3125 e-"),
    (lambda d: d["sensor"]["dcg"].update(lcg_well_capacity_e=2500.0),
     r"sensor\.dcg\.lcg_well_capacity_e: the low-gain readout saturates at 2500 e-, no later than the high-gain"),
    (lambda d: d["sensor"]["dcg"]["small_photodiode"].update(lcg_to_spd_e=25000.0),
     r"sensor\.dcg\.small_photodiode\.lcg_to_spd_e 25000 e- must lie above"),
    (lambda d: d["sensor"]["dcg"]["small_photodiode"].update(sensitivity_ratio=1.5),
     r"field 'sensor\.dcg\.small_photodiode\.sensitivity_ratio' = 1\.5"),
    (lambda d: d["sensor"]["dcg"].update(merged_bits=16, companding_knees=[[0, 0], [1024, 1024], [65535, 4095]]),
     r"sensor\.dcg\.merged_bits 16 holds codes up to 65535; the merged range .* reaches 983056 DN"),
    (lambda d: d["sensor"]["dcg"].update(merged_bits=20),
     r"field 'sensor\.dcg\.companding_knees'.*the last knee is \(16777215, 4095\): it must be at merged code 1048575"),
    (lambda d: d["sensor"]["dcg"].update(companding_knees=[[0, 0], [1024, 1024], [900, 1500], [16777215, 4095]]),
     r"field 'sensor\.dcg\.companding_knees'.*\(900, 1500\) does not follow \(1024, 1024\)"),
    (lambda d: d["sensor"]["dcg"].update(companding_knees=[[0, 0], [1024, 512], [4096, 4095], [16777215, 4095]]),
     r"field 'sensor\.dcg\.companding_knees'"),
    (lambda d: d["sensor"]["dcg"].update(lcg_read_noise_e=3000.0), r"field 'sensor\.dcg\.lcg_read_noise_e' = 3000"),
    (lambda d: d.update(exposure={"mode": "hdr", "hdr_ratio": 16}),
     r"exposure\.mode 'hdr' \(two frames\) with sensor\.dcg"),
])
def test_bad_hdr_and_cfa_specs_are_refused_in_one_line_naming_the_field(change, pattern):
    with pytest.raises(ValueError, match=pattern) as info:
        camera_from_dict(_auto_with(change), source="mine.yaml")
    assert "\n" not in str(info.value)


def test_a_two_frame_policy_on_an_hdr_pixel_is_refused_at_capture_too():
    camera = with_exposure(_small_auto_camera(), parse_exposure("hdr:16"))  # model_copy: not validated
    with pytest.raises(ValueError, match="exposure.mode 'hdr'.*sensor.dcg"):
        acquisition.acquire(np.ones((8, 8)), camera, seed=0)


# ── lens tables hashed by their content ─────────────────────────────────────────────────

def test_a_lens_tables_content_is_in_the_cameras_sha256(tmp_path):
    def table(centre_um: float) -> None:
        rows = ["wavelength_nm,x_um,y_um,psf"] + [
            f"{wl},{x},{y},{1.0 if (x, y) == (centre_um, 0.0) else 0.0}"
            for wl in (450.0, 650.0) for y in (-0.5, 0.0, 0.5) for x in (-0.5, 0.0, 0.5)]
        (tmp_path / "psf.csv").write_text("\n".join(rows) + "\n")

    spec = {"name": "tabled", "optics": {"f_number": 2.0, "psf_table": "psf.csv"},
            "sensor": {"pixel_um": 1.4, "active_width_mm": 0.1344, "active_height_mm": 0.0896}}
    table(0.0)
    first = camera_from_dict(spec, spec_dir=tmp_path)
    assert first.optics.psf_table_sha256 == file_sha256(tmp_path / "psf.csv")
    assert f'"psf_table_sha256":"{first.optics.psf_table_sha256}"' in first.canonical_json()
    dump = first.model_dump(mode="json")
    dump["sensor"] = {k: v for k, v in dump["sensor"].items() if k not in ("width_px", "height_px")}
    assert camera_from_dict(dump).sha256() == first.sha256()  # results.json's spec keeps the digest
    table(0.5)  # another lens under the same name
    second = camera_from_dict(spec, spec_dir=tmp_path)
    assert second.sha256() != first.sha256()
    with pytest.raises(ValueError, match=r"optics\.psf_table: file 'psf\.csv' has changed since this spec recorded it"):
        first.optics.psf_table_path
    with pytest.raises(ValueError, match=r"optics\.psf_table_sha256: the file 'psf\.csv' .* is not the table"):
        camera_from_dict(dump, spec_dir=tmp_path)
    # the digest belongs to its table
    with pytest.raises(ValueError, match=r"optics\.mtf_table_sha256 is the digest of optics\.mtf_table"):
        camera_from_dict({**spec, "optics": {"f_number": 2.0, "mtf_table_sha256": "0" * 64}})
    # cameras without tables keep their hashes (tests/test_lens.py pins the registry's)
    assert "table_sha256" not in load_camera("cam12").canonical_json()
