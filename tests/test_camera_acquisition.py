"""Acquisition policies: auto_peak (the reference), mean_level, percentile, two-frame HDR,
their spec fields, the --exposure syntax, and the sweep's run folders per policy."""

from __future__ import annotations

import json

import numpy as np
import pytest
from pydantic import ValidationError
from typer.testing import CliRunner

from benchmark.camera import calibration, hdr, isp, sensor
from benchmark.camera.pipeline import electron_rate, simulate
from benchmark.camera import ExposureSpec, SensorSpec, list_cameras, load_camera
from benchmark.cli.main import app
from benchmark.camera.exposure import (
    exposure_tag,
    exposure_time_s,
    format_exposure,
    hdr_exposures_s,
    parse_exposure,
    with_exposure,
)
from metricscenes.geometry import REFERENCE_EXTENT
from metricscenes.radiance import RadianceLayer, SpectralScene
from test_sweep_cli import fakes  # noqa: F401  (fixture)

D65 = calibration.illuminant_spectrum("D65")
SENSOR = SensorSpec(pixel_um=1.4)  # IMX363 defaults
VOLTS_PER_E = 76.5e-6 * 270.0 / 55.0  # conversion gain × analog gain (ISO 270 / ISO 55)
SWING_V = 0.4591
OLD_EXPOSURE_KEYS = ["mode", "level", "region_fraction", "peak_percentile", "max_exposure_s", "exposure_s"]


def _rate_mosaic(scale: float = 1.0) -> np.ndarray:
    """8 × 8 e⁻/s: the central 4 × 4 (region_fraction 0.5) holds 1 … 16 × 1e6 × scale,
    the border is 1000 × brighter (it must not count)."""
    rate = np.full((8, 8), 1e12 * scale)
    rate[2:6, 2:6] = np.arange(1.0, 17.0).reshape(4, 4)[::-1] * 1e6 * scale
    return rate


def _t(level: float, rate_e_per_s: float) -> float:
    return level * SWING_V / (rate_e_per_s * VOLTS_PER_E)


# ── exposure times against hand-computed values ──────────────────────────────────

@pytest.mark.parametrize("policy, rate_e_per_s, level", [
    # np.percentile interpolates linearly between order statistics: the p-th of 1..16
    # sits at rank p/100 × 15, so 99.9 → 15.985, 95 → 15.25, 50 → 8.5 (× 1e6).
    (ExposureSpec(), 15.985e6, 0.9),
    (ExposureSpec(peak_percentile=100.0), 16e6, 0.9),
    (ExposureSpec(mode="mean_level", level=0.25), 8.5e6, 0.25),
    (ExposureSpec(mode="percentile", percentile=95.0), 15.25e6, 0.9),
    (ExposureSpec(mode="percentile", percentile=50.0, level=0.3), 8.5e6, 0.3),
    (ExposureSpec(mode="percentile", percentile=100.0), 16e6, 0.9),
])
def test_policy_exposure_times(policy, rate_e_per_s, level):
    assert exposure_time_s(_rate_mosaic(), SENSOR, policy) == pytest.approx(_t(level, rate_e_per_s), rel=1e-12)


def test_percentile_999_at_090_is_the_reference():
    rate = np.random.default_rng(0).gamma(2.0, 1e6, (60, 80))
    assert exposure_time_s(rate, SENSOR, ExposureSpec(mode="percentile", percentile=99.9)) == \
        exposure_time_s(rate, SENSOR, ExposureSpec())


def test_caps_fixed_and_black():
    dim = _rate_mosaic(1e-3)  # 1..16 × 1e3 e⁻/s: every policy wants more than 16 ms
    for policy in (ExposureSpec(), ExposureSpec(mode="mean_level"), ExposureSpec(mode="percentile", percentile=95)):
        assert exposure_time_s(dim, SENSOR, policy) == 0.016
        assert exposure_time_s(np.zeros((8, 8)), SENSOR, policy) == 0.016
    assert exposure_time_s(dim, SENSOR, ExposureSpec(mode="fixed", exposure_s=0.004)) == 0.004


def test_hdr_exposure_times():
    bright = hdr_exposures_s(_rate_mosaic(), SENSOR, ExposureSpec(mode="hdr"))
    t_ref = _t(0.9, 15.985e6)  # 69 µs: long = 16 t_ref is under the cap
    assert bright.reference_s == pytest.approx(t_ref, rel=1e-12)
    assert bright.long_s == pytest.approx(16 * t_ref, rel=1e-12)
    assert bright.short_s == pytest.approx(t_ref, rel=1e-12)  # daylight: the short frame is the reference
    assert exposure_time_s(_rate_mosaic(), SENSOR, ExposureSpec(mode="hdr")) == bright.long_s
    dim = hdr_exposures_s(_rate_mosaic(1e-3), SENSOR, ExposureSpec(mode="hdr", hdr_ratio=8))
    assert (dim.reference_s, dim.long_s, dim.short_s) == (0.016, 0.016, 0.002)  # at the cap: the long frame is
    mid = hdr_exposures_s(_rate_mosaic(0.05), SENSOR, ExposureSpec(mode="hdr"))
    assert mid.long_s == 0.016 and mid.short_s == 0.001 and mid.short_s < mid.reference_s < mid.long_s


# ── the spec: validation, and the canonical JSON of existing specs ───────────────

@pytest.mark.parametrize("fields", [
    {"mode": "percentile"},  # the percentile is required
    {"mode": "percentile", "percentile": 0},
    {"mode": "percentile", "percentile": -5},
    {"mode": "percentile", "percentile": 100.5},
    {"mode": "percentile", "percentile": "high"},
    {"percentile": 95},  # a parameter of another mode
    {"mode": "mean_level", "percentile": 95},
    {"mode": "hdr", "hdr_ratio": 1.0},
    {"mode": "hdr", "hdr_ratio": 2000},
    {"hdr_ratio": 8},
    {"mode": "median"},
])
def test_bad_policy_fields_are_refused(fields):
    with pytest.raises(ValidationError):
        ExposureSpec(**fields)


def test_bad_percentile_in_a_camera_yaml_is_one_line(tmp_path):
    path = tmp_path / "cam.yaml"
    path.write_text("name: x\noptics: {f_number: 2}\nsensor: {pixel_um: 1.4}\n"
                    "exposure: {mode: percentile, percentile: 120}\n")
    with pytest.raises(ValueError, match=r"exposure\.percentile.*0\.0 < percentile <= 100") as info:
        load_camera(path)
    assert "\n" not in str(info.value)


def test_default_specs_keep_their_canonical_json():
    """The new fields are written only for the mode that reads them: the registry's
    hashes (and the leaderboard's submissions) do not move."""
    assert list(ExposureSpec().model_dump()) == OLD_EXPOSURE_KEYS
    for cam in list_cameras():
        assert list(cam.model_dump()["exposure"]) == OLD_EXPOSURE_KEYS
        assert '"percentile":' not in cam.canonical_json() and "hdr_ratio" not in cam.canonical_json()
    assert load_camera("cam01").sha256() == "0241ed23fed235fa85b70a2ce4c99a975e5d090ca637f567a11ddcfca3d6d288"
    assert load_camera("cam12").sha256() == with_exposure(load_camera("cam12"), ExposureSpec()).sha256()


@pytest.mark.parametrize("text, key, value", [("percentile:95", "percentile", 95.0), ("hdr:16", "hdr_ratio", 16.0)])
def test_policy_parameters_are_recorded(text, key, value):
    from benchmark.camera import camera_from_dict

    cam = with_exposure(load_camera("cam12"), parse_exposure(text))
    dump = cam.model_dump(mode="json")
    assert dump["exposure"][key] == value and cam.sha256() != load_camera("cam12").sha256()
    dump["sensor"] = {k: v for k, v in dump["sensor"].items() if k not in ("width_px", "height_px")}
    assert camera_from_dict(dump) == cam  # results.json's spec reads back to the same camera


# ── the --exposure syntax ────────────────────────────────────────────────────────

@pytest.mark.parametrize("text, expected, tag", [
    ("auto_peak", ExposureSpec(), "auto_peak"),
    ("mean_level", ExposureSpec(mode="mean_level"), "mean_level"),
    ("mean_level@0.18", ExposureSpec(mode="mean_level", level=0.18), "mean_level-level0.18"),
    ("percentile:95", ExposureSpec(mode="percentile", percentile=95), "percentile-95"),
    (" Percentile:50@0.3 ", ExposureSpec(mode="percentile", percentile=50, level=0.3), "percentile-50-level0.3"),
    ("hdr", ExposureSpec(mode="hdr"), "hdr-16"),
    ("hdr:8", ExposureSpec(mode="hdr", hdr_ratio=8), "hdr-8"),
    ("fixed:0.004", ExposureSpec(mode="fixed", exposure_s=0.004), "fixed-0.004"),
])
def test_parse_and_format(text, expected, tag):
    spec = parse_exposure(text)
    assert spec == expected and exposure_tag(spec) == tag
    assert parse_exposure(format_exposure(spec)) == spec


def test_specs_the_syntax_cannot_say_get_a_hashed_tag():
    spec = ExposureSpec(mode="hdr", max_exposure_s=0.033)
    assert format_exposure(spec) is None
    assert exposure_tag(spec).startswith("hdr-") and exposure_tag(spec) != exposure_tag(ExposureSpec(mode="hdr"))


@pytest.mark.parametrize("text, message", [
    ("percentile", "needs its parameter"),
    ("percentile:150", "less than or equal to 100"),
    ("percentile:abc", "not a number"),
    ("hdr:1", "greater than 1"),
    ("fixed:0.01@0.5", "no @LEVEL"),
    ("auto_peak:3", "takes no ':' parameter"),
    ("median", "unknown policy"),
    ("mean_level@2", "level"),
])
def test_parse_errors(text, message):
    with pytest.raises(ValueError, match=message) as info:
        parse_exposure(text)
    assert "\n" not in str(info.value) and "expected auto_peak" in str(info.value)


# ── two-frame HDR: merge, determinism, tone curve ────────────────────────────────

def _lamp_and_shadow_rate() -> np.ndarray:
    """e⁻/s: a 5e6 lamp (rows 0-7), a 2e5 mid-tone (rows 8-15), a 2e3 shadow (rows 16-23)."""
    rate = np.empty((24, 32))
    rate[:8], rate[8:16], rate[16:] = 5e6, 2e5, 2e3
    rate *= 1.0 + 0.5 * np.random.default_rng(5).random(rate.shape)  # texture
    return rate


def test_hdr_merge_recovers_the_linear_scene_where_one_exposure_fails():
    rate = _lamp_and_shadow_rate()
    t_long, ratio = 0.002, 16.0
    off = sensor.NoiseOptions.off()
    raw_long = sensor.capture_dn(rate, t_long, SENSOR, None, off)
    raw_short = sensor.capture_dn(rate, t_long / ratio, SENSOR, None, off)
    lamp, shadow = np.s_[:8], np.s_[16:]
    assert np.all(raw_long[lamp] == SENSOR.white_level_dn)  # the long frame saturates on the lamp
    assert np.all(raw_short[shadow] - SENSOR.black_level_dn <= 2)  # the short one has ~1 DN in the shadow
    merged = hdr.merge_two_exposures_dn(raw_long, raw_short, ratio, SENSOR)
    truth_dn = rate * t_long * VOLTS_PER_E / SENSOR.lsb_v  # linear scene, DN of the long exposure
    error = merged - SENSOR.black_level_dn - truth_dn
    assert np.abs(error[shadow]).max() <= 0.5 + 1e-3  # long-frame quantisation
    assert np.abs(error[lamp]).max() <= 0.5 * ratio + 1e-3  # short-frame quantisation × ratio
    assert np.abs(error[lamp] / truth_dn[lamp]).max() < 0.001
    assert truth_dn[lamp].min() > 5 * SENSOR.white_level_dn  # far beyond a single exposure at t_long
    # The rule: long below 95 % of saturation, short × ratio above.
    use_long = (raw_long - 64.0) < 0.95 * hdr.saturation_dn(SENSOR)
    assert np.array_equal(merged[use_long], raw_long[use_long].astype(np.float32))


def _scene(cube: np.ndarray) -> SpectralScene:
    return SpectralScene(layers=(RadianceLayer(cube.astype(np.float32), REFERENCE_EXTENT),))


def _lamp_scene(radiance_scale: float) -> SpectralScene:
    rng = np.random.default_rng(2)
    cube = (0.2 + 0.8 * rng.random((90, 160, 1))) * D65 * radiance_scale
    cube[40:50, 70:90] *= 300.0  # a lamp in the central region: it sets the reference exposure
    cube[:, :40] *= 0.002  # a deep shadow
    return _scene(cube)


def test_hdr_capture_noise_free_matches_the_electrons():
    cam = with_exposure(load_camera("cam01"), parse_exposure("hdr:16"))
    cap = simulate(_lamp_scene(1e-3), cam, seed=0, noise=False)
    assert cap.exposure_s == pytest.approx(16 * cap.exposure_short_s)
    truth_dn = cap.electrons * VOLTS_PER_E / SENSOR.lsb_v
    error = np.abs(cap.merged_dn - 64.0 - truth_dn)
    assert error[truth_dn < 0.9 * 959].max() <= 0.5 + 1e-3  # from the long frame
    # From the short frame, × 16, except the brightest lamp pixels: the short frame is the
    # reference exposure (daylight), which lets the top 0.1 % of the central region clip.
    unclipped = cap.raw_short_dn < 1023
    assert error[unclipped].max() <= 0.5 * 16 + 1e-3 and unclipped.mean() > 0.999
    assert cap.merged_dn.max() - 64.0 > 5 * (1023 - 64)  # the lamp, beyond the long frame's white


def test_hdr_is_deterministic_for_a_seed_with_independent_frames():
    cam = with_exposure(load_camera("cam01"), parse_exposure("hdr:16"))
    scene = _lamp_scene(1e-3)
    a, b = simulate(scene, cam, seed=7), simulate(scene, cam, seed=7)
    for field in ("raw_dn", "raw_short_dn", "merged_dn", "rgb8"):
        assert np.array_equal(getattr(a, field), getattr(b, field)), field
    c = simulate(scene, cam, seed=8)
    assert not np.array_equal(a.raw_dn, c.raw_dn) and not np.array_equal(a.raw_short_dn, c.raw_short_dn)
    # The long frame draws what a single capture would; the short one the seed's first child stream.
    single = simulate(scene, with_exposure(cam, ExposureSpec(mode="fixed", exposure_s=a.exposure_s)), seed=7)
    assert np.array_equal(single.raw_dn, a.raw_dn)
    rate = sensor.mosaic(electron_rate(scene, cam), "RGGB")
    child = np.random.default_rng(np.random.SeedSequence(7).spawn(1)[0])
    assert np.array_equal(sensor.capture_dn(rate, a.exposure_short_s, cam.sensor, child), a.raw_short_dn)
    reused = sensor.capture_dn(rate, a.exposure_short_s, cam.sensor, np.random.default_rng(7))
    assert not np.array_equal(reused, a.raw_short_dn)


def test_tone_curve():
    x = np.linspace(0.0, 16.0, 1001, dtype=np.float32)
    assert np.allclose(isp.tone_curve_reinhard(x, 1.0), x, rtol=1e-6)  # w = 1: identity
    t = isp.tone_curve_reinhard(x, 16.0)
    assert t[0] == 0 and t[-1] == pytest.approx(1.0, rel=1e-6) and np.all(np.diff(t) > 0)
    assert isp.tone_curve_reinhard(np.float32(0.5), 16.0) == pytest.approx(0.5 * (1 + 0.5 / 256) / 1.5, rel=1e-6)


def test_hdr_in_daylight_is_the_reference_image_with_cleaner_shadows():
    cam = load_camera("cam01")
    hdr_cam = with_exposure(cam, parse_exposure("hdr:16"))
    scene = _lamp_scene(1e-3)
    ref_clean = simulate(scene, cam, seed=0, noise=False).rgb8.astype(int)
    hdr_clean = simulate(scene, hdr_cam, seed=0, noise=False).rgb8.astype(int)
    lit = ref_clean > 40  # where the reference's 10 bits are not the limit, the images agree
    assert np.abs(hdr_clean - ref_clean)[lit].max() <= 1
    ref, both = simulate(scene, cam, seed=1), simulate(scene, hdr_cam, seed=1)
    assert both.exposure_short_s == pytest.approx(ref.exposure_s)  # daylight: short = reference
    dark = np.s_[:, cam.width_px // 4 :]  # the textured surround, 1/300 of the lamp that sets the exposure
    err_ref = np.abs(ref.rgb8[dark] - hdr_clean[dark]).mean()
    err_hdr = np.abs(both.rgb8[dark] - hdr_clean[dark]).mean()
    assert err_hdr < err_ref / 3  # 16 × the light: about 4 × the SNR


def test_hdr_at_night_keeps_the_lamp_unclipped():
    cam = load_camera("cam01")  # 640 × 360: one scene pixel per sensor pixel below
    rng = np.random.default_rng(4)
    cube = (0.2 + 0.8 * rng.random((360, 640, 1))) * D65 * 4e-7  # about 10 % of white at 16 ms
    lamp = np.s_[179:182, 319:322]  # 9 px: under the 0.1 % of the central region the reference ignores
    brightness = 50.0 + 50.0 * rng.random((3, 3))
    cube[lamp] = brightness[..., None] * D65 * 4e-7  # 5-10 × white at 16 ms
    scene = _scene(cube)
    ref = simulate(scene, cam, seed=0, noise=False)
    both = simulate(scene, with_exposure(cam, parse_exposure("hdr:16")), seed=0, noise=False)
    assert ref.exposure_s == both.exposure_s == 0.016 and both.exposure_short_s == 0.001  # the cap: long = reference
    assert np.all(ref.raw_dn[lamp] == 1023)  # the reference clips the lamp flat
    truth_dn = both.electrons[lamp] * VOLTS_PER_E / SENSOR.lsb_v
    assert np.allclose(both.merged_dn[lamp] - 64.0, truth_dn, rtol=0.02)
    toned = both.rgb8[lamp].astype(float).mean(axis=-1)
    assert both.rgb8[lamp].max() < 255 and np.corrcoef(toned.ravel(), brightness.ravel())[0, 1] > 0.9  # compressed, kept
    background = np.s_[40:120, 40:200]  # dim (≈ 0.07 linear): the tone curve (w = 16) takes ≈ 7 % off
    diff = both.rgb8[background].astype(int) - ref.rgb8[background]
    assert -5 < diff.mean() <= 0


# ── CLI and sweep ────────────────────────────────────────────────────────────────

@pytest.mark.parametrize("command", ["run", "sweep"])
@pytest.mark.parametrize("value", ["percentile:150", "hdr:0", "median", "fixed"])
def test_cli_exposure_errors_are_one_line(fakes, command, value):  # noqa: F811
    args = [command, "--collection", str(fakes), "--out", str(fakes / "o"), "--exposure", value]
    args += ["--camera", "cam01"] if command == "run" else ["--cameras", "cam01"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "--exposure" in lines[0] and "Traceback" not in result.output


def test_cli_run_overrides_the_camera_exposure(fakes, monkeypatch):  # noqa: F811
    seen = []

    def run_camera(collection, camera, condition, detector, out_dir, **kw):
        seen.append(camera)
        from test_sweep_cache import fake_run_camera

        return fake_run_camera(collection, camera, condition, detector, out_dir, **kw)

    from test_sweep_cache import patch_runs

    patch_runs(monkeypatch, run_camera)
    result = CliRunner().invoke(app, ["run", "--camera", "cam05", "--collection", str(fakes), "--out",
                                      str(fakes / "r"), "--exposure", "percentile:95@0.5"])
    assert result.exit_code == 0, result.output
    assert seen[0].exposure == ExposureSpec(mode="percentile", percentile=95, level=0.5)
    assert "exposure percentile:95@0.5" in " ".join(result.output.split())  # the table title, maybe wrapped


def test_sweep_policies_do_not_collide(fakes):  # noqa: F811
    out = fakes / "sw"
    base = ["sweep", "--collection", str(fakes), "--cameras", "cam01", "--conditions", "day", "--out", str(out),
            "--resamples", "10", "--mtf-source", "published_group", "--no-save-images"]
    assert CliRunner().invoke(app, base).exit_code == 0
    assert CliRunner().invoke(app, [*base, "--exposure", "hdr:16"]).exit_code == 0
    runs = out / "runs"
    assert sorted(p.name for p in runs.iterdir()) == ["cam01-day", "cam01-day+hdr-16"]
    plain = json.loads((runs / "cam01-day" / "results.json").read_text())["camera"]["spec_sha256"]
    tagged = json.loads((runs / "cam01-day+hdr-16" / "results.json").read_text())["camera"]["spec_sha256"]
    assert plain == load_camera("cam01").sha256() != tagged
    meta = json.loads((out / "sweep.json").read_text())
    assert meta["exposure"]["policy"] == "hdr:16" and meta["runs"][0]["path"] == "runs/cam01-day+hdr-16"
    from benchmark.experiments.report import load_results

    assert load_results(out)[2][("cam01", "day")] == runs / "cam01-day+hdr-16"
    # The reference policy, spelt out, is the cameras' own: the untagged runs are reused.
    again = CliRunner().invoke(app, [*base, "--exposure", "auto_peak"])
    assert again.exit_code == 0 and json.loads((out / "sweep.json").read_text())["runs"][0]["reused"]
    assert sorted(p.name for p in runs.iterdir()) == ["cam01-day", "cam01-day+hdr-16"]


def test_run_records_the_hdr_short_exposures(tmp_path):
    from benchmark.experiments.run import run_camera
    from test_sweep_cache import FakeCollection

    class Collection(FakeCollection):
        def scenes(self):
            return super().scenes()[:2]

        def radiance(self, scene_id, condition, inset_resolution="car"):
            return _lamp_scene(1e-3)

    class Detector:
        name, family, sha256, input_size = "none", "none", "0" * 64, "native"

        def detect(self, images, **kw):
            return [[] for _ in images]

    cam = with_exposure(load_camera("cam01"), parse_exposure("hdr:16"))
    results = run_camera(Collection(tmp_path), cam, "day", Detector(), tmp_path / "run", save_images=False)
    assert results.camera.spec["exposure"]["mode"] == "hdr"
    assert set(results.exposure_short_s) == set(results.exposure_s) and len(results.exposure_s) == 2
    for scene_id, long_s in results.exposure_s.items():
        assert long_s == pytest.approx(16 * results.exposure_short_s[scene_id])
    plain = run_camera(Collection(tmp_path), load_camera("cam01"), "day", Detector(), tmp_path / "plain", save_images=False)
    assert plain.exposure_short_s is None and "exposure_short_s" not in (tmp_path / "plain" / "results.json").read_text()
