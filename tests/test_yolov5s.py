"""YOLOv5s, the paper's detector, in the registry: its file is checked by sha256 as YOLOv5n's
is, and it behaves as shared/models/README.md says (a pickup read as a truck)."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from benchmark.detectors import DetectorError, load_detector
from benchmark.detectors.registry import registry
from conftest import model_dir, require_model
from test_detectors_errors import write_onnx

SHA256 = "d74a8043556c58ce1631db6fb43d1df48ac3c4cdc665c8c14cc96dfd139254c6"  # shared/models/README.md, SHA256SUMS


def test_the_registry_names_yolov5s_with_its_sha256_licence_and_source():
    entry = registry()["yolov5s-dynamic"]
    assert (entry.family, entry.file, entry.input_size, entry.sha256) == ("yolov5", "yolov5s-dynamic.onnx", "dynamic",
                                                                         SHA256)
    assert entry.licence == "GPL-3.0" and entry.url.endswith("/v6.0/yolov5s.pt")
    assert registry()["yolov5n-dynamic"].sha256 != SHA256  # the reference detector is unchanged


def test_the_shared_file_is_the_registrys():
    path = require_model("yolov5s-dynamic.onnx")
    assert hashlib.sha256(path.read_bytes()).hexdigest() == SHA256
    det = load_detector("yolov5s-dynamic", input_size="native", model_dir=model_dir())
    assert (det.sha256, det.family) == (SHA256, "yolov5")


def test_another_file_under_its_name_is_refused_in_one_line(tmp_path):
    fake = write_onnx(tmp_path / "yolov5s-dynamic.onnx", [1, 3, 64, 64], [1, 3, 64, 64])
    with pytest.raises(DetectorError) as err:
        load_detector(fake)
    text = str(err.value)
    assert "sha256 mismatch" in text and "yolov5s-dynamic" in text and SHA256 in text and "\n" not in text


def test_yolov5s_reads_the_dog_photos_pickup_as_a_truck_first():
    """As the models README lists it: truck 0.68 and car 0.47 on the same box at 640
    (YOLOv5n: car 0.70)."""
    require_model("yolov5s-dynamic.onnx")
    from PIL import Image

    dog = np.asarray(Image.open(model_dir() / "samples" / "dog.jpg").convert("RGB"))
    det = load_detector("yolov5s-dynamic", input_size=640, model_dir=model_dir(), threads=1)
    (found,) = det.detect([dog], conf_threshold=0.25)
    scores = {d.class_name: round(d.score, 2) for d in found}
    assert scores["dog"] == 0.93 and scores["truck"] == 0.68 and scores["car"] == pytest.approx(0.47, abs=0.015)


def test_every_run_states_what_counts_as_the_car(tmp_path, monkeypatch):
    """COCO's `car` only (docs/detection.md, "What counts as the car"), written in results.json."""
    import json

    import benchmark.camera.pipeline
    from benchmark.camera import load_camera
    from benchmark.coco import COCO80_NAMES, coco_category_id
    from benchmark.experiments.run import run_camera
    from benchmark.scoring.ap import CAR_CLASSES
    from test_sweep_cache import BlankCapture, BlankCollection, BlindDetector

    assert CAR_CLASSES == ("car",) and [coco_category_id(COCO80_NAMES.index(c)) for c in CAR_CLASSES] == [3]
    monkeypatch.setattr(benchmark.camera.pipeline, "simulate", lambda radiance, camera, seed: BlankCapture())
    run_camera(BlankCollection(tmp_path), load_camera("cam01"), "day", BlindDetector(), tmp_path / "run",
               save_images=False)
    assert json.loads((tmp_path / "run" / "results.json").read_text())["car_classes"] == ["car"]
