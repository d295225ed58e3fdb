"""A targeted condition's light-group luminances (the paper's night: the weights that meet a
scene's photometric target) measured once per scene for a whole sweep, shared with its units."""

import pytest

from conftest import require_model


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
    from test_backends import _sweep_files, sweep_serial_and_pooled

    _, serial, pooled = sweep_serial_and_pooled(smoke_collection, "night", tmp_path)
    assert serial.equals(pooled)
    assert _sweep_files(tmp_path / "pooled") == _sweep_files(tmp_path / "serial")
