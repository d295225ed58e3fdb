"""`benchmark paper-factors`: our night to the paper's, one documented change at a time and
cumulatively (benchmark.experiments.paper_factors), checked on smoke with two small cameras."""

from __future__ import annotations

import json

import pytest

from benchmark.experiments.paper_factors import (
    FACTOR_KEYS, factor_rows, row_camera, row_condition, run_factors,
)
from conftest import REPO, model_dir, require_model
from metricscenes.manifest import TargetedCondition, load_manifest


def test_the_rows_start_from_the_physical_night_and_add_each_factor():
    both, alone, cumulative = factor_rows("both"), factor_rows("alone"), factor_rows("cumulative")
    assert both[0].factors == () and both[0].kind == "baseline"
    assert [r.factors for r in cumulative[1:]] == [FACTOR_KEYS[: i + 1] for i in range(len(FACTOR_KEYS))]
    assert [r.factors for r in alone[1:]] == [(k,) for k in FACTOR_KEYS]
    assert len(both) == 1 + 2 * len(FACTOR_KEYS) - 1  # the first factor alone is the first cumulative row
    assert len({r.name for r in both}) == len(both) == len({r.factors for r in both})
    with pytest.raises(ValueError, match="--rows"):
        factor_rows("some")


def test_the_scene_factors_together_make_quicks_night_lab():
    manifest = load_manifest(REPO / "manifests" / "quick.yaml")
    night = manifest.conditions["night"].identity()
    made = row_condition(night, "night", ("image_plane", "whole_mix", "no_ego"))
    assert TargetedCondition.model_validate(made).identity() == manifest.read_time_conditions["night_lab"].identity()
    assert row_condition(night, "night", ("yolov5s", "strict_max")) is None  # no scene factor: night itself
    only_plane = TargetedCondition.model_validate(row_condition(night, "night", ("image_plane",)))
    assert only_plane.at_camera and not only_plane.scales_mix and only_plane.lamps == night["lamps"]
    mix = TargetedCondition.model_validate(row_condition(night, "night", ("whole_mix",)))
    assert not mix.at_camera and mix.f_number == 2.4  # the mix scaled at the reference lens
    assert mix.mix == {"sky_night": 10.0, "car_lights": 1.0, "street_lights": 0.5, "ego_lights": 1.0}


def test_the_camera_factors_change_only_what_they_name():
    from benchmark.camera import load_camera

    cam12 = load_camera("cam12")
    same, noise = row_camera(cam12, ("image_plane", "yolov5s"))
    assert same.sha256() == cam12.sha256() and noise
    changed, noise = row_camera(cam12, ("strict_max", "centre_20", "read_noise_1e", "noise_free"))
    assert (changed.exposure.peak_percentile, changed.exposure.region_fraction, changed.sensor.read_noise_e) == (
        100.0, 0.2, 1.0)
    assert not noise and changed.exposure.level == cam12.exposure.level


def test_a_base_that_is_no_physical_night_is_refused_in_one_line(smoke_collection, tmp_path):
    from benchmark.camera import load_camera
    from metricscenes.store import Collection

    collection = Collection.open(smoke_collection)
    for base in ("day", "night_lab", "night_regulation"):
        with pytest.raises(ValueError) as err:
            run_factors(collection, [load_camera("cam12")], tmp_path / base, base_name=base)
        assert "starts from a physical night" in str(err.value) and "\n" not in str(err.value)


@pytest.mark.slow
def test_on_smoke_the_first_row_is_the_runs_night_and_a_second_run_resumes(smoke_collection, tmp_path):
    require_model("yolov5n-dynamic.onnx")
    require_model("yolov5s-dynamic.onnx")
    from benchmark.camera import load_camera
    from benchmark.detectors import load_detector
    from benchmark.experiments.run import run_camera
    from benchmark.experiments.subset import subset_collection
    from metricscenes.store import Collection

    specs = []
    for name, f_number, pixel in (("small", 2.0, 11.2), ("small-f4", 4.0, 8.4)):
        path = tmp_path / f"{name}.yaml"
        path.write_text(f"name: {name}\noptics: {{f_number: {f_number}}}\nsensor: {{pixel_um: {pixel}}}\n")
        specs.append(load_camera(path))
    collection = Collection.open(smoke_collection)
    out = tmp_path / "factors"
    table = run_factors(collection, specs, out, which="cumulative", distances="25,50", mtf_source="analytic",
                        model_dir=model_dir())
    assert [r["factors"] for r in table["rows"]][-1] == list(FACTOR_KEYS)
    assert table["fast"] == ["small"] and table["slow"] == ["small-f4"]
    # The physical night's row is what `benchmark run --condition night` scores, camera by camera.
    detector = load_detector("yolov5n-dynamic", model_dir=model_dir())
    for camera in specs:
        run = run_camera(subset_collection(collection, distances="25,50"), camera, "night", detector,
                         tmp_path / f"run-{camera.name}", save_images=False)
        assert table["rows"][0]["ap"][camera.name] == {f"{r.distance_m:g}": round(r.ap, 3) for r in run.per_distance}
    # Every row at each camera's image plane records that camera's weights, per scene.
    units = json.loads((out / "units" / "small-f4-env000.json").read_text())
    lab = units["rows"][-1]["condition_weights"]
    assert set(lab) == {"env000-d025m", "env000-d050m"}
    assert all(w["target_at"]["camera"] == "small-f4" and w["scales"] == "mix" for w in lab.values())
    # A second run finds every unit done (same key) and writes the same table.
    before = (out / "factors.json").read_bytes()
    seen = []
    run_factors(collection, specs, out, which="cumulative", distances="25,50", mtf_source="analytic",
                model_dir=model_dir(), progress=lambda done, total: seen.append((done, total)))
    assert seen == [(4, 4)] and (out / "factors.json").read_bytes() == before
