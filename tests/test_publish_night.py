"""`benchmark publish night-exposure` and `night-factors` on the smoke collection: what a camera
collects from the car at night, and the paper's night against ours one factor at a time, each
variant at the same image-plane illuminance."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from benchmark.publish import night_exposure, night_factors


def test_green_sites_are_the_green_pixels_of_the_window():
    mosaic = np.arange(48, dtype=float).reshape(6, 8)
    got = night_exposure.green_sites(mosaic, slice(1, 4), slice(2, 6))
    # RGGB: green where row + column is odd; rows 1-3, columns 2-5
    assert sorted(got) == sorted(mosaic[r, c] for r in range(1, 4) for c in range(2, 6) if (r + c) % 2)


def test_variant_camera_changes_one_part():
    from benchmark.camera import load_camera

    base = load_camera("cam12")
    by_name = {v.name: v for v in night_factors.VARIANTS}
    capped = night_factors.variant_camera(base, by_name["cap 16 ms -> 33 ms (30 fps frame period)"])
    assert capped.exposure.max_exposure_s == pytest.approx(1 / 30) and capped.sensor == base.sensor
    brighter = night_factors.variant_camera(base, by_name["linear image x4 before sRGB"])
    assert brighter.isp.output == "linear" and base.isp.output != "linear"
    shot_only = night_factors.variant_camera(base, by_name["shot noise only (read noise, PRNU, DSNU off)"])
    assert shot_only.sensor.read_noise_e == 0.0 and shot_only.sensor.prnu_fraction == 0.0
    assert shot_only.exposure == base.exposure


@pytest.mark.slow
def test_every_scene_variant_has_the_paper_nights_illuminance(smoke_collection):
    """The daylight sky (with or without every lamp) scaled per scene to the mean luminance the
    paper's night has there: the factors differ in spectrum and lamps, not in light."""
    from metricscenes.store import Collection

    collection = Collection.open(smoke_collection)
    weights = night_factors.SceneWeights(collection)
    for scene in collection.scenes():
        night = weights.luminance(scene.scene_id, weights.weights(scene.scene_id, "night"))
        day = weights.weights(scene.scene_id, "day_matched")
        assert set(day) == {"sky_day"}
        assert weights.luminance(scene.scene_id, day) == pytest.approx(night, rel=1e-9)
        lamps = weights.weights(scene.scene_id, "day_lamps_matched")
        assert all(lamps[g] == 1.0 for g in night_factors.LAMPS)
        if lamps["sky_day"] > 0:  # (lamps alone brighter than the night: no sky, and more light)
            assert weights.luminance(scene.scene_id, lamps) == pytest.approx(night, rel=1e-9)


@pytest.mark.slow
def test_night_exposure_rows_and_histograms(smoke_collection, tmp_path):
    from benchmark.camera import load_camera
    from benchmark.camera.exposure import central_region
    from benchmark.camera.pipeline import simulate
    from benchmark.cli.main import app
    from metricscenes.store import Collection, scale_groundtruth

    out, png = tmp_path / "night-exposure.csv", tmp_path / "histograms.png"
    result = CliRunner().invoke(app, ["publish", "night-exposure", "--collection", str(smoke_collection), "--cameras",
                                      "cam01", "--out", str(out), "--histograms", str(png), "--scenes", "env000-d025m"])
    assert result.exit_code == 0, result.output
    rows = pd.read_csv(out)
    collection = Collection.open(smoke_collection)
    assert list(rows["scene_id"]) == [s.scene_id for s in collection.scenes()]
    assert set(rows["exposure_mode"]) == {"auto_peak"} and set(rows["condition"]) == {"night"}
    assert png.stat().st_size > 10_000
    # one scene again, by hand: the noise-free capture's green pixels in the car's box
    camera = load_camera("cam01")
    scene = collection.scenes()[0]
    capture = simulate(collection.radiance(scene.scene_id, "night"), camera, seed=0, noise=False)
    gt = scale_groundtruth(collection.groundtruth(), camera.width_px, camera.height_px)
    x, y, w, h = next(a["bbox"] for a in gt["annotations"] if a["image_id"] == scene.image_id)
    car = night_exposure.green_sites(capture.electrons, slice(int(y), int(np.ceil(y + h))), slice(int(x), int(np.ceil(x + w))))
    row = rows.iloc[0]
    assert row["car_median_e"] == pytest.approx(np.median(car), abs=0.005)
    assert row["exposure_ms"] == pytest.approx(1e3 * capture.exposure_s, abs=1e-4)
    region = capture.electrons[central_region(capture.electrons.shape, camera.exposure.region_fraction)]
    assert row["region_p999_e"] == pytest.approx(np.percentile(region, 99.9), abs=0.05)
    # a policy replacing the camera's own
    fixed = night_exposure.night_exposure(collection, ["cam01"], "night", "fixed:0.004", say=lambda line: None)
    assert {r["exposure_ms"] for r in fixed} == {4.0} and {r["exposure_mode"] for r in fixed} == {"fixed"}


@pytest.mark.slow
def test_night_factors_scores_each_variant_like_a_run(smoke_collection, tmp_path):
    from benchmark.detectors import load_detector
    from conftest import require_model
    from metricscenes.store import Collection

    require_model("yolov5n-dynamic.onnx")
    by_name = {v.name: v for v in night_factors.VARIANTS}
    variants = [by_name["paper's night as quick makes it (night sky + every lamp, 0.1-1 lux)"],
                by_name["daylight sky at the same image-plane lux"], by_name["no noise at all (bound)"]]
    said = []
    rows = night_factors.night_factors(Collection.open(smoke_collection), ["cam01"], load_detector("yolov5n-dynamic"),
                                       distances="25,200", variants=variants, say=said.append)
    assert [r["variant"] for r in rows] == [v.name for v in variants] and len(said) == 3
    night, day, noiseless = rows
    assert day["image_plane_lux"] == pytest.approx(night["image_plane_lux"], abs=0.002)
    assert noiseless["exposure_ms"] == night["exposure_ms"]  # same scene, same policy
    assert all(set(r) >= {"ap_25m", "ap_200m", "car_median_e"} and 0 <= r["ap_25m"] <= 1 for r in rows)
    night_exposure.write_rows(rows, tmp_path / "night-factors.csv")
    assert list(pd.read_csv(tmp_path / "night-factors.csv")["variant"]) == [v.name for v in variants]
