"""Class maps: a single-class car detector (output [1, N, 6]) and custom-class models,
read as COCO classes; refused without a map, with a one-line hint."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.detectors import DetectorError, load_detector
from benchmark.detectors.classmap import class_map_names, parse_class_map
from test_detectors_errors import write_onnx

CELLS_64 = 8 * 8 + 4 * 4 + 2 * 2  # grid cells of a 64x64 canvas over strides 8, 16, 32


def _yolov5_model(tmp_path, n_classes: int, rows: list[tuple]):
    """A static 64x64 YOLOv5-layout model, [1, 3·cells, 5 + n_classes], returning ``rows``
    (cx, cy, w, h, objectness, class, class probability)."""
    out = np.zeros((1, 3 * CELLS_64, 5 + n_classes), np.float32)
    for i, (cx, cy, w, h, obj, cls, p) in enumerate(rows):
        out[0, i, :5] = (cx, cy, w, h, obj)
        out[0, i, 5 + cls] = p
    return write_onnx(tmp_path / f"custom{n_classes}.onnx", [1, 3, 64, 64], list(out.shape), out)


def test_parse_class_map():
    assert parse_class_map(None) is None
    assert parse_class_map("car") == (2,)
    assert parse_class_map("person, -, car") == (0, -1, 2)
    assert parse_class_map(["traffic_light", "truck"]) == (9, 7)
    assert class_map_names((0, -1, 2)) == ["person", "-", "car"]
    with pytest.raises(ValueError, match="'sedan' is not a COCO class name"):
        parse_class_map("car,sedan")
    with pytest.raises(ValueError, match="every class is dropped"):
        parse_class_map("-,-")


def test_single_class_car_detector(tmp_path):
    model = _yolov5_model(tmp_path, 1, [(32, 32, 20, 10, 0.9, 0, 1.0), (10, 10, 8, 8, 0.2, 0, 1.0)])
    with pytest.raises(DetectorError) as info:  # an [1, N, 6] output without a map: refused, with the hint
        load_detector(model, input_size=64)
    assert "\n" not in str(info.value) and "--class-map car" in str(info.value)
    det = load_detector(model, input_size=64, class_map="car")
    assert det.family == "yolov5" and det.class_map == (2,)
    (dets,) = det.detect([np.zeros((64, 64, 3), np.uint8)], conf_threshold=0.25)
    assert [(d.class_name, d.class_id, round(d.score, 3)) for d in dets] == [("car", 2, 0.9)]
    assert dets[0].to_coco(1)["category_id"] == 3  # scored as a COCO car
    assert dets[0].box_xyxy == pytest.approx((22.0, 27.0, 42.0, 37.0))
    with pytest.raises(DetectorError, match="wrong output shape"):  # a map of the wrong length
        load_detector(model, input_size=64, class_map="car,truck")


def test_custom_classes_dropped_and_merged(tmp_path):
    model = _yolov5_model(tmp_path, 3, [(32, 32, 20, 10, 0.9, 0, 0.8), (12, 12, 6, 6, 0.9, 1, 0.9),
                                        (50, 50, 6, 6, 0.9, 2, 0.7)])
    det = load_detector(model, input_size=64, class_map="person,-,truck")
    (dets,) = det.detect([np.zeros((64, 64, 3), np.uint8)], conf_threshold=0.25)
    assert sorted(d.class_name for d in dets) == ["person", "truck"]  # the dropped class is gone


def test_run_records_the_class_map_and_sweep_keys_it(tmp_path):
    from benchmark.camera import load_camera
    from benchmark.experiments.keys import results_key, run_key
    from benchmark.result_files import RunResults
    from test_sweep_cache import FakeCollection, FakeDetector

    class Mapped(FakeDetector):
        class_map = (2,)

    col, cam = FakeCollection(tmp_path), load_camera("cam01")
    plain, mapped = run_key(cam, "day", FakeDetector(), col, 0), run_key(cam, "day", Mapped(), col, 0)
    assert "class_map" not in plain and mapped["class_map"] == ["car"]
    results = {"camera": {"name": "cam01", "spec_sha256": cam.sha256()}, "condition": "day",
               "detector": {"name": "fake", "sha256": "d" * 64, "input_size": "multiscale", "class_map": ["car"]},
               "collection": {"manifest_sha256": "f" * 64}, "seed": 0, "composite": "car"}
    assert results_key(RunResults.model_validate(results)) == mapped != plain


def test_cli_class_map_errors_are_one_line(tmp_path):
    from typer.testing import CliRunner

    from benchmark.cli.main import app

    model = _yolov5_model(tmp_path, 1, [(32, 32, 20, 10, 0.9, 0, 1.0)])
    image = tmp_path / "x.png"
    from PIL import Image

    Image.fromarray(np.zeros((64, 64, 3), np.uint8)).save(image)
    ok = CliRunner().invoke(app, ["detect", str(image), "--model", str(model), "--input-size", "64", "--class-map", "car"])
    assert ok.exit_code == 0, ok.output
    assert "car" in ok.output
    for extra, message in ((["--class-map", "sedan"], "not a COCO class name"), ([], "--class-map car")):
        res = CliRunner().invoke(app, ["detect", str(image), "--model", str(model), "--input-size", "64", *extra])
        assert res.exit_code == 2 and message in res.output
        assert len([line for line in res.output.splitlines() if line.strip()]) == 1


def test_run_camera_writes_the_class_map(tmp_path, monkeypatch):
    import benchmark.camera.pipeline
    from benchmark.camera import load_camera
    from benchmark.experiments.run import run_camera
    from test_sweep_cache import FakeCollection

    class Capture:
        rgb8 = np.zeros((8, 8, 3), np.uint8)
        exposure_s, exposure_short_s = 1e-3, None

    class Detector:
        name, family, sha256, input_size, class_map = "mine", "yolov5", "0" * 64, 64, (2,)

        def detect(self, images, **kw):
            return [[] for _ in images]

    class Collection(FakeCollection):
        def scenes(self):
            return super().scenes()[:2]

        def radiance(self, scene_id, condition, inset_resolution="car"):
            return None

    monkeypatch.setattr(benchmark.camera.pipeline, "simulate", lambda radiance, camera, seed: Capture())
    results = run_camera(Collection(tmp_path), load_camera("cam01"), "day", Detector(), tmp_path / "run", save_images=False)
    assert results.detector.class_map == ["car"]
