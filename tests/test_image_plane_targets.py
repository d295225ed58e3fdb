"""A targeted condition's two knobs (metricscenes.manifest.TargetedCondition): ``target_at:
camera`` meets the target at each camera's own optical image (ISETCam's oiAdjustIlluminance,
as the paper's lab did), ``scales: mix`` scales the whole mix, lamps included, at fixed
relative weights (isetauto's iaLightsGroup.m); and the read-time conditions that carry the
lab's night and day without touching any manifest's hash."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from conftest import REPO, model_dir, require_model
from metricscenes.manifest import ManifestError, load_manifest, parse_manifest

CAMERAS = ("cam12", "cam02", "cam04")  # f/1.9, f/6.4, f/10.9
SCENES = ("env000-d025m", "env001-d100m")
PUBLISHED = {  # the published manifests' sha256 (tests/test_store.py pins them too)
    "smoke": "2b496a1a26819de6db01186453bfb52231475da05b2c558a5d153342fd8ee687",
    "quick": "6ce3394e3129c2704092906ed6ae4d447610c48f19399a571be4319123edaf00",
    "metric-300": "fd9342ff7e065f1d172afca80942cb14e08ddd056981ee56f914a44a77d14db5",
}


# The lab's night and day with the groups smoke renders (no street lights): as quick's
# read_time_conditions, added to a copy of smoke (smoke.yaml keeps its bytes: other tests trim its groups).
SMOKE_LAB = {
    "night_lab": {"scales": "mix", "mix": {"sky_night": 10.0, "car_lights": 1.0}, "target_at": "camera",
                  "target_image_plane_lux": [0.1, 1.0], "same_targets_as": "night"},
    "day_lab": {"scales": "mix", "mix": {"sky_day": 10.0, "car_lights": 1.0}, "target_at": "camera",
                "target_image_plane_lux": [10.0, 200.0]},
}


def _smoke(**read_time) -> dict:
    data = load_manifest(REPO / "manifests" / "smoke.yaml").model_dump(mode="json")
    data["read_time_conditions"] = {**SMOKE_LAB, **read_time}
    return data


@pytest.fixture(scope="module")
def lab_smoke(smoke_collection, tmp_path_factory):
    """A copy of smoke that records the lab's conditions: `generate` run again with them
    renders nothing (the same hash) and rewrites the resolved manifest."""
    import shutil

    from metricscenes.generate import generate

    copy = tmp_path_factory.mktemp("lab") / "smoke"
    shutil.copytree(smoke_collection, copy)
    generate(parse_manifest(_smoke()), copy)
    return copy


def _lux_of_optical_image(radiance, wavelengths, camera) -> float:
    """Mean illuminance of the camera's optical image as the camera makes it (lens blur,
    relative illumination and glare included): what the target is checked against."""
    from benchmark.camera import optics
    from benchmark.camera.image_plane import _lux_per_irradiance

    oi = optics.optical_image(radiance, wavelengths, camera.optics, camera.pixel_um)
    return float(np.mean(oi.weighted_sum(_lux_per_irradiance(tuple(float(w) for w in wavelengths))), dtype=np.float64))


def _weighted(parts, weights, grids):
    total = None
    for name, k in weights.part_coefficients().items():
        if name in grids:
            term = np.float32(k) * grids[name]
            total = term if total is None else total + term
    return total


# --- the manifests ------------------------------------------------------------------------

def test_read_time_conditions_leave_the_hash_as_it_was():
    assert load_manifest(REPO / "manifests" / "smoke.yaml").sha256() == PUBLISHED["smoke"]
    assert parse_manifest(_smoke()).sha256() == PUBLISHED["smoke"]
    other = _smoke(night_lab={**SMOKE_LAB["night_lab"], "target_image_plane_lux": [1.0, 10.0]})
    assert parse_manifest(other).sha256() == PUBLISHED["smoke"]


def test_a_knob_on_a_hashed_condition_is_part_of_the_hash():
    data = load_manifest(REPO / "manifests" / "smoke.yaml").model_dump(mode="json")
    data["conditions"]["night"] = {**data["conditions"]["night"], "target_at": "camera", "f_number": None}
    assert parse_manifest(data).sha256() != PUBLISHED["smoke"]


@pytest.mark.parametrize("spec, message", [
    ({"scales": "mix", "mix": {"sky_night": 1.0}, "ambient": "sky_night", "target_image_plane_lux": [0.1, 1]},
     "give their fixed weights in mix, not ambient or lamps"),
    ({"scales": "mix", "target_image_plane_lux": [0.1, 1]}, "needs mix:"),
    ({"scales": "mix", "mix": {"sky_night": 0.0}, "target_image_plane_lux": [0.1, 1]}, "with a weight > 0"),
    ({"ambient": "sky_night", "mix": {"sky_night": 1.0}, "target_image_plane_lux": [0.1, 1]},
     "takes ambient and lamps"),
    ({"ambient": "sky_night", "target_at": "camera", "f_number": 2.4, "target_image_plane_lux": [0.1, 1]},
     "f_number is the reference lens's"),
    ({"scales": "mix", "mix": {"street_lights": 1.0}, "target_image_plane_lux": [0.1, 1]},
     "light group 'street_lights' is not rendered"),
    ({"ambient": "sky_night", "target_at": "sensor", "target_image_plane_lux": [0.1, 1]}, "target_at"),
    ({"ambient": "sky_night", "scales": "everything", "target_image_plane_lux": [0.1, 1]}, "scales"),
    ({"ambient": "sky_night", "same_targets_as": "fog", "target_image_plane_lux": [0.1, 1]},
     "'fog' is not another targeted condition"),
    ({"ambient": "sky_night", "same_targets_as": "day", "target_image_plane_lux": [0.1, 1]},
     "'day' is not another targeted condition"),
    ({"scales": "mix", "mix": {"sky_night": 1.0}}, "needs target_image_plane_lux"),
])
def test_what_makes_no_sense_is_refused_in_one_line(spec, message):
    with pytest.raises(ManifestError) as err:
        parse_manifest(_smoke(odd=spec), "smoke.yaml")
    text = str(err.value)
    assert message in text and "read_time_conditions.odd" in text and "\n" not in text, text


def test_a_read_time_condition_may_not_take_a_conditions_name():
    with pytest.raises(ManifestError, match="read_time_conditions.night: already a condition"):
        parse_manifest(_smoke(night={"sky_night": 1.0}))


def test_a_bad_read_time_condition_is_refused_before_anything_is_written(tmp_path):
    path = tmp_path / "m.json"
    path.write_text(json.dumps(_smoke(odd={"target_at": "camera", "f_number": 4.0, "ambient": "sky_night",
                                           "target_image_plane_lux": [0.1, 1.0]})))
    proc = subprocess.run([sys.executable, "-m", "metricscenes.cli", "generate", "--manifest", str(path),
                           "--out", str(tmp_path / "c")], capture_output=True, text=True)
    lines = [line for line in proc.stderr.splitlines() + proc.stdout.splitlines() if line.strip()]
    assert proc.returncode != 0 and len(lines) == 1 and "f_number is the reference lens's" in lines[0], proc.stderr
    assert not (tmp_path / "c").exists()


# --- on smoke: each camera's own image plane ----------------------------------------------

@pytest.fixture(scope="module")
def smoke(lab_smoke):
    from metricscenes.store import Collection

    return Collection.open(lab_smoke)


def _cameras():
    from benchmark.camera import load_camera

    cams = [load_camera(name) for name in CAMERAS]
    # A lens that loses light two more ways: transmittance and cos^4 falloff, both taken out.
    dim = cams[0].model_copy(update={"name": "cam12-dim", "optics": cams[0].optics.model_copy(
        update={"transmittance": 0.8, "cos4_falloff": True})})
    return cams + [dim, load_camera(REPO / "cameras" / "cam12-flare.yaml")]


def test_the_target_is_met_at_each_cameras_own_image_plane(smoke):
    from benchmark.experiments.run import read_scene

    for scene_id in SCENES:
        parts = read_scene(smoke, scene_id, "night_lab")
        got = {}
        for camera in _cameras():
            weights, grids = parts.weights(camera)
            lux = _lux_of_optical_image(_weighted(parts, weights, grids), parts.parts["mix"].wavelengths_nm, camera)
            assert lux == pytest.approx(weights.target_lux, rel=0.01), (scene_id, camera.name)
            assert 0.1 <= weights.target_lux <= 1.0
            got[camera.name] = weights
        # f/1.9 to f/10.9: the same image-plane illuminance, so the scale goes as 1 + 4 N^2.
        ratio = got["cam04"].mix_scale / got["cam12"].mix_scale
        assert ratio == pytest.approx((1 + 4 * 10.9**2) / (1 + 4 * 1.9**2), rel=0.01)
        assert got["cam12-dim"].mix_scale > got["cam12"].mix_scale / 0.8  # transmittance and falloff taken out
        for w in got.values():  # the lab's ratio: sky x 10, car lamps x 1 (smoke renders no street lights)
            assert w.weights["sky_night"] == pytest.approx(10.0 * w.weights["car_lights"], rel=1e-12)


def test_the_reference_lens_gives_a_slow_camera_less(smoke):
    """Today's physical conditions (an ideal f/2.4 lens): a camera at f/N gets about
    (1 + 4 * 2.4^2) / (1 + 4 N^2) of the target. The knob is what changes it."""
    from benchmark.camera import load_camera
    from benchmark.camera.pipeline import sensor_radiance

    camera = load_camera("cam04")
    checked = 0
    for scene_id in SCENES:
        record = smoke.targeted_weights(scene_id, "night")
        if record.over_target:  # (the lamps alone exceed the target there)
            continue
        scene = smoke.radiance(scene_id, "night")
        lux = _lux_of_optical_image(sensor_radiance(scene, camera), np.asarray(scene.wavelengths_nm), camera)
        assert lux == pytest.approx(record.target_lux * (1 + 4 * 2.4**2) / (1 + 4 * 10.9**2), rel=0.01)
        checked += 1
    assert checked


def test_the_lab_night_is_paired_with_the_physical_night(smoke):
    for scene in smoke.scenes():
        night = smoke.targeted_weights(scene.scene_id, "night")
        lab = smoke.targeted_weights(scene.scene_id, "night_lab", f_number=1.9)
        assert lab.target_lux == night.target_lux  # same_targets_as: night


def test_a_camera_plane_condition_without_a_camera_is_refused_in_one_line(smoke, lab_smoke, tmp_path):
    from metricscenes.store import CollectionError

    with pytest.raises(CollectionError, match="each camera's own image plane") as err:
        smoke.radiance(SCENES[0], "night_lab")
    assert "\n" not in str(err.value)
    with pytest.raises(CollectionError, match="info --photometry --f-number"):
        smoke.targeted_weights(SCENES[0], "night_lab")
    proc = subprocess.run([sys.executable, "-m", "metricscenes.cli", "preview", str(lab_smoke), "--condition",
                           "night_lab", "--out", str(tmp_path / "p.png")], capture_output=True, text=True)
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode != 0 and len(lines) == 1 and "each camera's own image plane" in lines[0], proc.stderr


def test_info_photometry_shows_an_ideal_cameras_weights(lab_smoke):
    proc = subprocess.run([sys.executable, "-m", "metricscenes.cli", "info", str(lab_smoke), "--photometry",
                           "--f-number", "6.4", "--json"], capture_output=True, text=True, check=True)
    rows = [r for r in json.loads(proc.stdout)["photometry"] if r["condition"] == "night_lab"]
    assert len(rows) == 12
    for row in rows:
        record = row["targeted"]
        assert record["target_at"]["f_number"] == 6.4 and record["scales"] == "mix"
        assert row["image_plane_illuminance_lux"] == pytest.approx(record["target_image_plane_lux"], rel=1e-3)


def test_an_ideal_cameras_weights_are_a_registry_cameras_within_a_percent(smoke):
    """The registry's cameras are ideal lenses over the collection's field: ``info
    --photometry --f-number N`` (the reference grid) and the run (the camera's own grid) agree."""
    from benchmark.camera import load_camera
    from benchmark.experiments.run import read_scene

    for name in ("cam12", "cam04"):
        camera = load_camera(name)
        for scene_id in SCENES:
            measured, _ = read_scene(smoke, scene_id, "night_lab").weights(camera)
            ideal = smoke.targeted_weights(scene_id, "night_lab", f_number=camera.optics.f_number)
            assert ideal.mix_scale == pytest.approx(measured.mix_scale, rel=0.01)


def test_weights_are_the_same_in_another_process(smoke, lab_smoke):
    from benchmark.camera import load_camera
    from benchmark.experiments.run import read_scene

    here = read_scene(smoke, SCENES[1], "night_lab").weights(load_camera("cam02"))[0].record()
    code = ("import json, sys; from metricscenes.store import Collection; from benchmark.camera import load_camera; "
            "from benchmark.experiments.run import read_scene; c = Collection.open(sys.argv[1]); "
            f"print(json.dumps(read_scene(c, {SCENES[1]!r}, 'night_lab').weights(load_camera('cam02'))[0].record()))")
    there = subprocess.run([sys.executable, "-c", code, str(lab_smoke)], check=True, capture_output=True,
                           text=True).stdout
    assert json.loads(there) == json.loads(json.dumps(here))


# --- runs: recorded per scene and camera, in the cache key, the same with any workers -----------

def test_capture_key_holds_a_read_time_conditions_definition_and_nothing_new_for_the_others(smoke):
    from benchmark.camera import load_camera
    from benchmark.experiments.keys import capture_key

    camera = load_camera("cam12")
    night = capture_key(camera, "night", smoke, 0)
    assert set(night) == {"camera_spec_sha256", "condition", "manifest_sha256", "seed", "composite"}
    lab = capture_key(camera, "night_lab", smoke, 0)
    assert lab["condition_spec"]["mix"] == {"sky_night": 10.0, "car_lights": 1.0}
    assert lab["manifest_sha256"] == night["manifest_sha256"] == PUBLISHED["smoke"]


@pytest.mark.slow
def test_a_sweep_records_each_cameras_weights_the_same_with_any_workers(lab_smoke, tmp_path):
    """Two small cameras of different f-numbers (fast), one and two workers: the same files."""
    require_model("yolov5n-dynamic.onnx")
    from test_backends import _sweep_files, sweep_serial_and_pooled

    from benchmark.experiments.keys import capture_key, results_capture_key
    from benchmark.result_files import read_results
    from metricscenes.store import Collection

    cameras, _, _ = sweep_serial_and_pooled(lab_smoke, "night_lab", tmp_path)  # each sweep opens it afresh
    assert _sweep_files(tmp_path / "pooled") == _sweep_files(tmp_path / "serial")
    collection = Collection.open(lab_smoke)
    small, fast = (read_results(tmp_path / "serial" / "runs" / f"{c.name}-night_lab" / "results.json")
                   for c in cameras)
    assert set(small.condition_weights) == {s.scene_id for s in collection.scenes()}
    for scene_id, record in small.condition_weights.items():
        other = fast.condition_weights[scene_id]
        assert record["target_at"]["camera"] == "small" and other["target_at"]["camera"] == "small-f4"
        assert other["mix_scale"] / record["mix_scale"] == pytest.approx((1 + 4 * 4.0**2) / (1 + 4 * 2.0**2), rel=0.02)
    assert small.condition_spec == collection.read_time_condition("night_lab")
    assert results_capture_key(small) == capture_key(cameras[0], "night_lab", collection, 0)


@pytest.mark.slow
def test_a_stopped_run_resumes_with_each_scenes_own_weights(lab_smoke, tmp_path):
    """A run stopped after two scenes takes them up from its stage, weights included, and ends
    with the files of a run never stopped; a run on its captures records the same weights."""
    require_model("yolov5n-dynamic.onnx")
    from test_backends import _sweep_files

    from benchmark.camera import load_camera
    from benchmark.detectors import load_detector
    from benchmark.experiments import run as run_module
    from benchmark.experiments.subset import subset_collection
    from metricscenes.store import Collection

    spec = tmp_path / "small.yaml"
    spec.write_text("name: small\noptics: {f_number: 4.0}\nsensor: {pixel_um: 11.2}\n")
    camera = load_camera(spec)
    collection = subset_collection(Collection.open(lab_smoke), distances="25,50")
    detector = load_detector("yolov5n-dynamic", input_size="native", model_dir=model_dir())
    whole = run_module.run_camera(collection, camera, "night_lab", detector, tmp_path / "whole")

    class Interrupted:  # stopped by Ctrl-C at its third scene
        calls = 0

        def __getattr__(self, name):
            return getattr(detector, name)

        def detect(self, images, **kwargs):
            Interrupted.calls += 1
            if Interrupted.calls == 3:
                raise KeyboardInterrupt
            return detector.detect(images, **kwargs)

    out = tmp_path / "stopped"
    with pytest.raises(KeyboardInterrupt):
        run_module.run_camera(collection, camera, "night_lab", Interrupted(), out)
    staged = [json.loads(line) for line in (out / run_module.RESUMABLE_STAGE / run_module.CHECKPOINT).open()]
    assert len(staged) == 2 and all(entry["condition_weights"]["target_at"]["camera"] == "small" for entry in staged)
    resumed = run_module.run_camera(collection, camera, "night_lab", detector, out)
    assert resumed.condition_weights == whole.condition_weights and len(whole.condition_weights) == 4
    assert _sweep_files(out) == _sweep_files(tmp_path / "whole")
    again = run_module.run_camera(collection, camera, "night_lab", detector, tmp_path / "again", captures=out)
    assert again.condition_weights == whole.condition_weights
