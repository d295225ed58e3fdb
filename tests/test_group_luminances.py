"""A targeted condition's light-group luminances (the paper's night: the weights that meet a
scene's photometric target) measured once per scene for a whole sweep, shared with its units."""

import pytest

from conftest import model_dir, require_model


@pytest.fixture(autouse=True)
def forget_measured(monkeypatch):
    """Each test starts with this process knowing no group luminance."""
    from metricscenes import store

    monkeypatch.setattr(store, "_GROUP_LUMINANCE", {})


def test_remembered_luminances_give_the_same_weights_without_measuring(smoke_collection, monkeypatch):
    from benchmark.experiments.sweep import shared_group_luminances
    from metricscenes import store
    from metricscenes.store import Collection, remember_group_luminances

    collection = Collection.open(smoke_collection)
    scenes = [s.scene_id for s in collection.scenes()]
    direct = {s: collection.targeted_weights(s, "night") for s in scenes}
    monkeypatch.setattr(store, "_GROUP_LUMINANCE", {})
    shared = shared_group_luminances(collection, ["day", "night", "night_regulation"], workers=2, scheduler=None)
    assert set(shared) == {"night"}  # the only condition set by a target
    assert len(shared["night"]) == len(scenes) * 3  # sky_night, car_lights, ego_lights in each scene

    monkeypatch.setattr(store, "_GROUP_LUMINANCE", {})
    remember_group_luminances(shared["night"])

    def measuring(*args, **kwargs):
        raise AssertionError("measured a group luminance it was given")

    monkeypatch.setattr(Collection, "mean_luminance", measuring)
    assert {s: collection.targeted_weights(s, "night") for s in scenes} == direct


def test_no_target_no_measuring(smoke_collection, monkeypatch):
    from benchmark.experiments.sweep import shared_group_luminances
    from metricscenes.store import Collection

    monkeypatch.setattr(Collection, "mean_luminance", lambda *a, **k: pytest.fail("measured"))
    assert shared_group_luminances(Collection.open(smoke_collection), ["day", "day@100lux"], workers=2,
                                   scheduler=None) == {}


@pytest.mark.slow
def test_a_targeted_sweeps_bytes_do_not_depend_on_the_workers(smoke_collection, tmp_path):
    require_model("yolov5n-dynamic.onnx")
    from benchmark.camera import load_camera
    from benchmark.detectors import load_detector
    from benchmark.experiments.sweep import sweep
    from test_backends import _sweep_files

    spec = tmp_path / "small.yaml"
    spec.write_text("name: small\noptics: {f_number: 2.0}\nsensor: {pixel_um: 11.2}\n")
    twin = tmp_path / "small-f4.yaml"
    twin.write_text("name: small-f4\noptics: {f_number: 4.0}\nsensor: {pixel_um: 8.4}\n")
    cameras = [load_camera(spec), load_camera(twin)]
    detector = load_detector("yolov5n-dynamic", input_size="native", model_dir=model_dir())
    options = dict(n_resamples=20, mtf_source="analytic")
    serial = sweep(smoke_collection, cameras, ["night"], detector, tmp_path / "serial", **options)
    pooled = sweep(smoke_collection, cameras, ["night"], detector, tmp_path / "pooled", workers=2, **options)
    assert serial.equals(pooled)
    assert _sweep_files(tmp_path / "pooled") == _sweep_files(tmp_path / "serial")
