"""A real sweep on the smoke collection (render, camera, YOLOv5n): cache and report."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from conftest import require_model


@pytest.mark.slow
def test_smoke_sweep_is_cached_and_reported(smoke_collection, tmp_path, monkeypatch):
    require_model("yolov5n-dynamic.onnx")
    from benchmark.experiments import report, sweep
    from benchmark.camera import load_camera
    from benchmark.detectors import load_detector
    from conftest import model_dir

    detector = load_detector("yolov5n-dynamic", input_size="multiscale", model_dir=model_dir())
    out = tmp_path / "sweep"
    table = sweep.sweep(smoke_collection, [load_camera("cam01")], ["day", "night"], detector, out, n_resamples=20)
    assert len(table) == 2 * 6 and table["mtf50_source"].eq("measured").all()
    results = json.loads((out / "runs" / "cam01-day" / "results.json").read_text())
    assert [r["ap"] for r in results["per_distance"]] == table.query("condition == 'day'")["ap"].tolist()

    def no_run(*args, **kwargs):
        raise AssertionError("a cached run was recomputed")

    monkeypatch.setattr("benchmark.experiments.run.run_camera", no_run)
    monkeypatch.setattr("benchmark.experiments.run.run_cameras", no_run)
    again = sweep.sweep(smoke_collection, [load_camera("cam01")], ["day", "night"], detector, out, n_resamples=20)
    pd.testing.assert_frame_equal(again, table)

    page = report.report(out).read_text(encoding="utf-8")
    assert "http://" not in page and "https://" not in page and page.count("data:image/png;base64,") == 1 + 2 * 6
    single = report.report(out / "runs" / "cam01-night").read_text(encoding="utf-8")
    assert "cam01" in single and single.count("data:image/png;base64,") == 1 + 6
