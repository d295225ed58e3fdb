"""A camera on the smoke collection: real render, real sensor, real ONNX detector, real COCO AP."""

import json

import pytest

from conftest import require_model

pytestmark = pytest.mark.slow


def test_benchmark_run_scores_every_distance(smoke_collection, tmp_path):
    from typer.testing import CliRunner

    from benchmark.cli.main import app

    require_model("yolov5n-dynamic.onnx")
    out = tmp_path / "results"
    result = CliRunner().invoke(app, ["run", "--camera", "cam09", "--collection", str(smoke_collection),
                                      "--out", str(out)])
    assert result.exit_code == 0, result.output
    results = json.loads((out / "results.json").read_text())
    rows = results["per_distance"]
    assert [r["distance_m"] for r in rows] == [25, 50, 75, 100, 150, 200]
    for r in rows:
        assert 0.0 <= r["ap"] <= 1.0 and 0.0 <= r["ap50"] <= 1.0 and r["n_images"] == 2
    assert results["camera"]["name"] == "cam09" and len(results["detector"]["sha256"]) == 64
    detections = json.loads((out / "detections.json").read_text())
    assert detections and {"image_id", "category_id", "bbox", "score"} <= set(detections[0])
    assert len(list((out / "images").glob("*.png"))) == 12
    gt = json.loads((out / "groundtruth.json").read_text())
    assert gt["images"][0]["width"] == results["camera"]["width_px"]
