"""The lens as one seam (benchmark.camera.lens): one OTF function for the pipeline, the
analytic MTF50 and the benchmarks; Zernike aberrations, measured PSF/MTF tables, veiling
glare; the registry's bytes and hashes pinned; lens specs refused in one line."""

from __future__ import annotations

import hashlib
import math

import numpy as np
import pytest
import scipy.integrate
import yaml
from scipy.special import j0, j1

from benchmark.camera import camera_from_dict, camera_names, lens, load_camera, optics, sensor
from benchmark.camera.pipeline import electron_rate, optical_image, simulate
from benchmark.camera.spec_exposure import ExposureSpec
from benchmark.camera.spec_optics import OpticsSpec
from benchmark.measure.mtf import mtf50_analytic_cy_per_mm
from metricscenes.geometry import REFERENCE_EXTENT, TanExtent
from metricscenes.radiance import RadianceLayer, SpectralScene
from metricscenes.spectral import WAVELENGTHS_NM

# ── the registry does not move ───────────────────────────────────────────────────────────

REGISTRY_SHA256 = {  # computed before the lens seam (3358ea4), with the specs as they were
    "cam01": "0241ed23fed235fa85b70a2ce4c99a975e5d090ca637f567a11ddcfca3d6d288",
    "cam02": "a792c983cc38e55b5e505b3476a3ec6e947874a779eb9a8c0fee891f33126c48",
    "cam03": "06aeda10727fcf9b4ef6ee4f6c9d0ae420c79d4d19956897fb3539b3b05a5792",
    "cam04": "b775aadadb3831f4e4df34634ee4e658029672987f143cbfa4d4f4da60f43d92",
    "cam05": "d7396c7aa8881bb7c595a393b464294b067f75550752bc6e17c4b609bb6b17b5",
    "cam06": "22f783ec0cfa13ff228f49bb4ef8f06ecd13d5c5a45d74ce33fb15773de9afcd",
    "cam07": "76cee266f2a5f3c4efe14d9bfa2de271f0e0d40aadb462d1629b4af15b46995a",
    "cam08": "2ec0331d504ec8489295176598769cf8542cafdb6672dde3edc69fc95c3bbe4f",
    "cam09": "c18237ec8caf8d0067de4d3ee9686f0edde3d406f9f0ce4f23cffa81cad19456",
    "cam10": "04d7fe4f9c724510b9fc495a0268f96ed1b044da04edb28991d35d16d9a21e92",
    "cam11": "927277baf6b2727d3d239ea0adc26d044d5ba92835339a722938a8ee343d984e",
    "cam12": "2e6ada0f7487d40cfed75f6677ac5dbc2d7dbc13fa2fdd3955a996ad0e592548",
    "cam13": "f929591dc477349157aa991422f3af6faebe7308bc835984857666b4a6c5139f",
}

CAPTURE_SHA256 = {  # (raw_dn, rgb8) of _reference_scene(), seed 7, before the lens work
    "cam12": ("61aae5be0a529f634a8832af33c904a73cd870d7ec976df10b4a7ea0dfd81cf6",
              "c99dcd8f71a75175e910e6484fb77bd18d26bc1a93bd9644d89b62425ba8638a"),
    "cam08": ("805fc7ce114a32ce0fd010eff1a424884520d778018bbdad74eb9b5c2aee942c",
              "a8bb3a5640683e481b86f4c64d760d0a4c7d20758fb3b9f486b7f273dbc026a1"),
}


def _sha(array: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(array).tobytes()).hexdigest()


def _reference_scene() -> SpectralScene:
    """A plate over the reference field and a brighter inset, smooth spectra, seed 27."""
    rng = np.random.default_rng(27)
    basis = np.stack([np.exp(-0.5 * ((WAVELENGTHS_NM - c) / 40.0) ** 2) for c in (450, 550, 630)]).astype(np.float32)
    plate = (rng.random((54, 96, 3), dtype=np.float32) @ basis * np.float32(0.02)).astype(np.float32)
    inset = (rng.random((60, 80, 3), dtype=np.float32) @ basis * np.float32(0.05)).astype(np.float32)
    return SpectralScene(layers=(RadianceLayer(plate, REFERENCE_EXTENT),
                                 RadianceLayer(inset, TanExtent(-0.03, -0.02, 0.03, 0.025))))


def test_registry_sha256_are_pinned():
    assert camera_names() == sorted(REGISTRY_SHA256)
    assert {name: load_camera(name).sha256() for name in camera_names()} == REGISTRY_SHA256


@pytest.mark.parametrize("name", sorted(CAPTURE_SHA256))
def test_ideal_lens_captures_are_byte_identical_to_before(name):
    capture = simulate(_reference_scene(), load_camera(name), seed=7)
    assert (_sha(capture.raw_dn), _sha(capture.rgb8)) == CAPTURE_SHA256[name]


# ── one rule for fields added later ──────────────────────────────────────────────────────

def test_a_later_field_at_its_default_is_left_out_and_otherwise_written():
    cam = load_camera("cam12")
    text = cam.canonical_json()
    for field in ("distortion_k1", "zernike_waves", "zernike_wavelength_nm", "psf_table", "mtf_table",
                  "veiling_glare_fraction", "glare_angle_deg", "color_transform", "percentile", "hdr_ratio"):
        assert f'"{field}"' not in text
    aberrated = cam.model_copy(update={"name": "aberrated",
                                       "optics": OpticsSpec(f_number=1.9, zernike_waves={4: 0.25})})
    dump = aberrated.model_dump(mode="json")
    assert dump["optics"]["zernike_waves"] == {"4": 0.25}
    dump["sensor"] = {k: v for k, v in dump["sensor"].items() if k not in ("width_px", "height_px")}
    assert camera_from_dict(dump) == aberrated  # results.json's spec reads back to the same camera
    # all-zero coefficients are no aberration at all: the ideal lens, the same hash
    zero = camera_from_dict({**dump, "name": "cam12", "optics": {**dump["optics"], "zernike_waves": {4: 0.0, 12: 0}}})
    assert zero.optics.zernike_waves == () and zero.sha256() == cam.sha256()
    # an hdr spec always records its ratio (as before the rule), other modes never
    assert ExposureSpec(mode="hdr").hdr_ratio == 16.0 and ExposureSpec(mode="hdr").model_dump()["hdr_ratio"] == 16.0
    assert "hdr_ratio" not in ExposureSpec().model_dump()


# ── the ideal lens and the aberrated pupil ──────────────────────────────────────────────

def test_zero_zernike_coefficients_give_todays_diffraction_otf_exactly():
    ideal, zero = OpticsSpec(f_number=2.2), OpticsSpec(f_number=2.2, zernike_waves={4: 0.0, 7: 0.0})
    assert zero == ideal
    pixel_mm, shape = 1.4e-3, (70, 96)
    fx, fy = np.fft.rfftfreq(shape[1], d=pixel_mm), np.abs(np.fft.fftfreq(shape[0], d=pixel_mm))
    for wl in (400.0, 550.0, 700.0):
        todays = lens.diffraction_otf(np.hypot(fx[None, :], fy[:, None]), wl, 2.2)
        assert np.array_equal(lens.lens_otf(zero, wl, fx, fy), todays)
        assert np.array_equal(optics.otf_grid(shape, 1.4, wl, zero), optics.otf_grid(shape, 1.4, wl, 2.2))


def test_the_pupil_path_reproduces_goodman_without_aberration():
    """The FFT autocorrelation of the sampled pupil, interpolated off its nodes, against
    Goodman eq. 6-32 (a 10⁻⁹-wave term forces the pupil path)."""
    nearly = OpticsSpec(f_number=2.0, zernike_waves={12: 1e-9})
    cutoff = 1.0 / (550e-6 * 2.0)
    fx, fy = np.linspace(0.0, 1.05 * cutoff, 401), np.linspace(-cutoff, cutoff, 77)
    otf = lens.lens_otf(nearly, 550.0, fx, fy)
    assert otf.dtype == np.float64  # a rotationally symmetric pupil: a real OTF
    np.testing.assert_allclose(otf, lens.diffraction_otf(np.hypot(fx[None, :], fy[:, None]), 550.0, 2.0), atol=2e-3)


def hopkins_defocus_otf(s: np.ndarray, w020_waves: float) -> np.ndarray:
    """Exact OTF of a defocused circular pupil (Hopkins, Proc. R. Soc. A 231, 1955): the
    overlap integral of two unit pupils shifted by s pupil radii (0 ≤ s ≤ 2), whose phase
    difference is 2k·W020·s·x: (1/π) ∫∫ cos(4π W020 s x) dx dy over the overlap."""
    out = []
    for shift in np.atleast_1d(s):
        half = 1.0 - shift / 2.0
        if half <= 0:
            out.append(0.0)
            continue
        integrand = lambda x: math.cos(4 * math.pi * w020_waves * shift * x) * 2 * math.sqrt(  # noqa: E731
            max(0.0, 1.0 - (abs(x) + shift / 2.0) ** 2))
        out.append(scipy.integrate.quad(integrand, -half, half, limit=200)[0] / math.pi)
    return np.array(out)


def stokseth_defocus_otf(s: np.ndarray, w020_waves: float) -> np.ndarray:
    """Stokseth's approximation (JOSA 59, 1314, 1969) of the defocused OTF, s in 0–2:
    (1 − 0.69 s + 0.0076 s² + 0.043 s³) · 2 J1(a)/a, a = 4π W020 s (1 − s/2)."""
    a = 4.0 * np.pi * w020_waves * s * (1.0 - s / 2.0)
    jinc = np.where(a == 0, 1.0, 2.0 * j1(a) / np.where(a == 0, 1.0, a))
    return (1.0 - 0.69 * s + 0.0076 * s**2 + 0.043 * s**3) * jinc


@pytest.mark.parametrize("wavelength_nm", [550.0, 700.0])
def test_pure_defocus_gives_the_analytic_defocus_mtf(wavelength_nm):
    c4 = 0.3  # waves RMS at 550 nm; Z4 = √3 (2ρ² − 1), so W020 = 2√3 c4 waves at 550 nm
    defocused = OpticsSpec(f_number=2.8, zernike_waves={4: c4})
    w020 = 2.0 * math.sqrt(3.0) * c4 * 550.0 / wavelength_nm  # the same path difference, fewer waves
    cutoff = 1.0 / (wavelength_nm * 1e-6 * 2.8)
    freq = np.linspace(0.0, 0.995 * cutoff, 173)  # off the table's nodes
    otf = lens.lens_otf(defocused, wavelength_nm, freq, [0.0])[0]
    s = 2.0 * freq / cutoff
    np.testing.assert_allclose(otf, hopkins_defocus_otf(s, w020), atol=3e-3)
    np.testing.assert_allclose(otf, stokseth_defocus_otf(s, w020), atol=0.02)
    first = lambda y: s[np.nonzero(y < 0.5)[0][0]]  # noqa: E731
    assert first(otf) == pytest.approx(first(stokseth_defocus_otf(s, w020)), rel=0.02)


def test_tilt_shifts_the_image_along_x_and_y():
    """OSA j = 2 (2ρ cos θ) moves the image along +x (the columns), j = 1 along +y (the
    rows): by 4 N λ_ref c, the transverse ray aberration of the tilted wavefront."""
    c, f_number = 0.5, 2.0
    shift_mm = 4.0 * f_number * 550e-6 * c
    freq = np.linspace(0.0, 200.0, 9)
    expected = np.exp(-2j * np.pi * freq * shift_mm) * lens.diffraction_otf(freq, 550.0, f_number)
    along_x = lens.lens_otf(OpticsSpec(f_number=f_number, zernike_waves={2: c}), 550.0, freq, [0.0])[0]
    along_y = lens.lens_otf(OpticsSpec(f_number=f_number, zernike_waves={1: c}), 550.0, [0.0], freq)[:, 0]
    np.testing.assert_allclose(along_x, expected, atol=2e-3)
    np.testing.assert_allclose(along_y, expected, atol=2e-3)


def test_aberrations_lower_the_analytic_mtf50():
    ideal = mtf50_analytic_cy_per_mm(1.4, 2.8)
    assert ideal == pytest.approx(mtf50_analytic_cy_per_mm(1.4, 2.8, optics=OpticsSpec(f_number=2.8)), rel=1e-12)
    for coefficients in ({4: 0.15}, {12: 0.1}, {5: 0.15}, {8: 0.15}):
        aberrated = mtf50_analytic_cy_per_mm(1.4, 2.8, optics=OpticsSpec(f_number=2.8, zernike_waves=coefficients))
        assert aberrated < 0.97 * ideal, coefficients


def _small_camera(**optics_fields):
    return camera_from_dict({"name": "lens-test", "optics": {"f_number": 2.2, "focal_length_mm": 5.0, **optics_fields},
                             "sensor": {"pixel_um": 2.8, "active_width_mm": 0.224, "active_height_mm": 0.168}})


def _random_scene(seed: int = 5) -> SpectralScene:
    cube = np.random.default_rng(seed).random((120, 200, 31), dtype=np.float32) * 0.05
    return SpectralScene(layers=(RadianceLayer(cube, REFERENCE_EXTENT),))


@pytest.mark.parametrize("optics_fields", [{"zernike_waves": {5: 0.3, 8: 0.2}}, {"veiling_glare_fraction": 0.05},
                                           {"zernike_waves": {4: 0.2}, "veiling_glare_fraction": 0.02}])
def test_the_sensor_integrates_the_optical_image_on_the_fast_path(optics_fields):
    """Fast path (complex, full-grid OTFs for astigmatism and coma; glare once per channel)
    against the plain per-band irradiance through the sensor."""
    cam = _small_camera(**optics_fields)
    scene = _random_scene()
    oi = optical_image(scene, cam)
    plain = sensor.signal_from_irradiance(oi.irradiance, oi.wavelengths_nm, cam.sensor)
    fused = electron_rate(scene, cam)
    inner = (slice(None), slice(16, -16), slice(16, -16))  # the two paths pad the PSF differently
    np.testing.assert_allclose(fused[inner], plain[inner], rtol=0, atol=3e-4 * plain.max())
    assert not np.allclose(fused, electron_rate(scene, _small_camera()), rtol=1e-3)


# ── measured lenses ──────────────────────────────────────────────────────────────────────

def _write_camera(tmp_path, optics_fields: dict, pixel_um: float = 1.4):
    spec = {"name": "measured", "optics": {"f_number": 2.0, **optics_fields},
            "sensor": {"pixel_um": pixel_um, "active_width_mm": 0.1344, "active_height_mm": 0.0896}}
    path = tmp_path / "measured.yaml"
    path.write_text(yaml.safe_dump(spec))
    return path


def _psf_csv(path, wavelengths=(450.0, 650.0), spacing_um=0.5, centre=(0.0, 0.0)):
    rows = ["wavelength_nm,x_um,y_um,psf"]
    for wl in wavelengths:
        for y in (-spacing_um, 0.0, spacing_um):
            for x in (-spacing_um, 0.0, spacing_um):
                rows.append(f"{wl},{x + centre[0]},{y + centre[1]},{1.0 if (x, y) == (0.0, 0.0) else 0.0}")
    path.write_text("\n".join(rows) + "\n")


def test_a_delta_psf_table_gives_the_pixel_only_mtf(tmp_path):
    _psf_csv(tmp_path / "delta.csv")
    cam = load_camera(_write_camera(tmp_path, {"psf_table": "delta.csv"}))
    freq = np.linspace(0.0, 800.0, 50)
    assert np.array_equal(lens.lens_otf(cam.optics, 550.0, freq, freq), np.ones((50, 50), complex))
    # the camera's MTF is the pixel aperture's alone: sinc(f p) = 0.5 at 0.6034 / p
    pixel_only = 0.60335 / (cam.pixel_um * 1e-3)
    assert mtf50_analytic_cy_per_mm(cam.pixel_um, 2.0, optics=cam.optics) == pytest.approx(pixel_only, rel=1e-4)
    scene = _random_scene()
    np.testing.assert_allclose(electron_rate(scene, cam), electron_rate(scene, cam, diffraction=False),
                               rtol=1e-5, atol=1e-6 * electron_rate(scene, cam).max())
    # the table is read beside the spec file, and its name (not its folder) is in the hash
    assert cam.optics.psf_table_path == (tmp_path / "delta.csv").resolve()
    assert '"psf_table":"delta.csv"' in cam.canonical_json()


def test_a_psf_table_off_the_image_point_shifts_the_image(tmp_path):
    _psf_csv(tmp_path / "shifted.csv", centre=(1.5, -0.5))  # a lateral offset, as lateral colour has
    cam = load_camera(_write_camera(tmp_path, {"psf_table": "shifted.csv"}))
    freq = np.linspace(0.0, 300.0, 7)
    otf = lens.lens_otf(cam.optics, 550.0, freq, freq)
    expected = np.exp(-2j * np.pi * (freq[None, :] * 1.5e-3 + freq[:, None] * -0.5e-3))
    np.testing.assert_allclose(otf, expected, atol=1e-12)


def test_an_mtf_table_of_the_diffraction_curve_is_the_ideal_lens(tmp_path):
    rows = ["wavelength_nm,frequency_cy_per_mm,mtf"]
    for wl in (400.0, 550.0, 700.0):
        for f in np.linspace(0.0, 1.0 / (wl * 1e-6 * 2.0), 400):
            rows.append(f"{wl},{f!r},{float(lens.diffraction_otf(f, wl, 2.0))!r}")
    (tmp_path / "ideal_mtf.csv").write_text("\n".join(rows) + "\n")
    cam = load_camera(_write_camera(tmp_path, {"mtf_table": "ideal_mtf.csv"}))
    freq = np.linspace(0.0, 900.0, 301)
    np.testing.assert_allclose(lens.lens_otf(cam.optics, 550.0, freq, [0.0])[0], lens.diffraction_otf(freq, 550.0, 2.0),
                               atol=1e-5)
    ideal = mtf50_analytic_cy_per_mm(cam.pixel_um, 2.0, sensor_spec=cam.sensor)
    assert mtf50_analytic_cy_per_mm(cam.pixel_um, 2.0, sensor_spec=cam.sensor, optics=cam.optics) == \
        pytest.approx(ideal, rel=2e-3)


# ── veiling glare ────────────────────────────────────────────────────────────────────────

def test_the_glare_spread_function_has_unit_energy_and_its_stated_otf():
    r0 = 0.0076  # mm: 0.1° behind a 4.38 mm lens
    energy = scipy.integrate.quad(lambda r: lens.glare_spread_function(r, r0) * 2 * math.pi * r, 0, np.inf)[0]
    assert energy == pytest.approx(1.0, abs=1e-6)
    for nu in (5.0, 20.0, 60.0):
        ring = lambda r: lens.glare_spread_function(r, r0) * j0(2 * math.pi * nu * r) * 2 * math.pi * r  # noqa: E731
        hankel = scipy.integrate.quad(ring, 0, 200 * r0, limit=2000)[0]
        assert hankel == pytest.approx(float(lens.glare_otf(nu, r0)), abs=2e-3)


def test_veiling_glare_conserves_energy():
    """A point source in the middle of a 512 × 512 frame: the glare moves a fraction g of its
    light into a long tail; all of it stays in the frame but the tail beyond it, which for
    this kernel is a fraction r₀ / √(r₀² + R²) of g beyond a radius R."""
    g, pixel_um = 0.05, 1.4
    cam_optics = OpticsSpec(f_number=2.0, veiling_glare_fraction=g, glare_angle_deg=0.05)
    r0_px = lens.glare_scale_mm(cam_optics.focal_length_mm, 0.05) * 1e3 / pixel_um
    image = np.zeros((512, 512), np.float32)
    image[256, 256] = 1.0
    glared = optics.veiling_glare(image, cam_optics, pixel_um)
    assert glared.sum(dtype=np.float64) == pytest.approx(1.0, abs=1e-3)
    outside = [g * r0_px / math.hypot(r0_px, radius) for radius in (256.0 * math.sqrt(2), 256.0)]
    assert 1 - outside[1] - 1e-4 <= glared.sum(dtype=np.float64) <= 1 - outside[0] + 1e-4
    assert glared[256, 256] == pytest.approx(1 - g + g * lens.glare_spread_function(0.0, r0_px), rel=0.05)
    # a glare-free lens leaves the image alone, and the switch is per camera
    assert _small_camera().optics.veiling_glare_fraction == 0.0


# ── refused specs ────────────────────────────────────────────────────────────────────────

@pytest.mark.parametrize("optics_fields, files, pattern", [
    ({"zernike_waves": {0: 0.1}}, {}, r"field 'optics\.zernike_waves'.*index 0 .*piston"),
    ({"zernike_waves": {66: 0.1}}, {},
     r"field 'optics\.zernike_waves'.*index 66 is outside the OSA/ANSI indices 1 to 65"),
    ({"zernike_waves": {"defocus": 0.1}}, {}, r"field 'optics\.zernike_waves'.*'defocus' is not an OSA/ANSI"),
    ({"zernike_waves": {4: 0.1}, "zernike_wavelength_nm": 0.55}, {}, r"field 'optics\.zernike_wavelength_nm'"),
    ({"zernike_waves": {4: 250.0}}, {}, r"field 'optics\.zernike_waves'.*250 waves is above"),
    ({"psf_table": "missing.csv"}, {}, r"field 'optics\.psf_table' = 'missing\.csv': no file .*missing\.csv"),
    ({"psf_table": "../psf.csv"}, {}, r"field 'optics\.psf_table'.*'\.\.' is refused"),
    ({"psf_table": "bad.csv"}, {"bad.csv": "wavelength_nm,x_um,y_um,value\n550,0,0,1\n"},
     r"field 'optics\.psf_table' = 'bad\.csv': PSF table bad\.csv: lacks column\(s\) psf"),
    ({"psf_table": "bad.csv"}, {"bad.csv": "wavelength_nm,x_um,y_um,psf\n550,0,0,1\n550,1,0,x\n"},
     r"field 'optics\.psf_table'.*row 2 psf is not a number"),
    ({"psf_table": "bad.csv"}, {"bad.csv": "wavelength_nm,x_um,y_um,psf\n550,0,0,1\n550,1,0,1\n550,0,1,1\n"},
     r"field 'optics\.psf_table'.*do not form a full grid"),
    ({"mtf_table": "bad.csv"}, {"bad.csv": "wavelength_nm,frequency_cy_per_mm,mtf\n550,0,0.8\n550,100,0.1\n"},
     r"field 'optics\.mtf_table'.*mtf at frequency 0 is 0\.8, not 1"),
    ({"mtf_table": "bad.csv"}, {"bad.csv": "wavelength_nm,frequency_cy_per_mm,mtf\n550,0,1\n550,100,1.4\n"},
     r"field 'optics\.mtf_table'.*row 2 mtf is 1\.4: an MTF lies between 0 and 1"),
    ({"mtf_table": "short.csv"}, {"short.csv": "wavelength_nm,frequency_cy_per_mm,mtf\n550,0,1\n550,100,0.5\n"},
     r"optics\.mtf_table 'short\.csv': wavelength 550 nm ends at 100 cy/mm with mtf 0\.5"),
    ({"psf_table": "coarse.csv"}, {"coarse.csv": None},
     r"optics\.psf_table 'coarse\.csv' is sampled every 2 um, coarser"),
    ({"psf_table": "coarse.csv", "zernike_waves": {4: 0.1}}, {"coarse.csv": None},
     r"optics\.zernike_waves and optics\.psf_table each describe the whole lens"),
    ({"veiling_glare_fraction": 0.9}, {},
     r"field 'optics\.veiling_glare_fraction' = 0\.9.*veiling_glare_fraction <= 0\.5"),
])
def test_bad_lens_specs_are_refused_in_one_line_naming_the_field(tmp_path, optics_fields, files, pattern):
    for name, text in files.items():
        if text is None:
            _psf_csv(tmp_path / name, spacing_um=2.0)
        else:
            (tmp_path / name).write_text(text)
    path = _write_camera(tmp_path, optics_fields)
    with pytest.raises(ValueError, match=pattern) as info:
        load_camera(path)
    assert "\n" not in str(info.value)
