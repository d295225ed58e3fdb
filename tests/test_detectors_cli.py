"""The `detect` command: JSON output shape, table output, one-line errors with exit code 2."""

import json
import os
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from benchmark.cli.detect import register

REPO = Path(__file__).resolve().parents[1]
MODEL_DIR = Path(os.environ.get("METRICSCENES_MODEL_DIR", REPO.parent / "shared" / "models"))
DOG = MODEL_DIR / "samples" / "dog.jpg"


@pytest.fixture()
def app():
    app = typer.Typer()
    register(app)

    @app.callback()  # keep 'detect' a subcommand, as in the lead's CLI
    def main():
        pass

    return app


def test_detect_json(app):
    if not (MODEL_DIR / "yolov5n-dynamic.onnx").is_file() or not DOG.is_file():
        pytest.skip(f"models not in {MODEL_DIR}")
    res = CliRunner().invoke(app, ["detect", str(DOG), str(DOG), "--model", "yolov5n-dynamic", "--model-dir", str(MODEL_DIR), "--input-size", "640", "--json"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert len(out) == 2 and out[0]["image"] == str(DOG)
    dets = out[0]["detections"]
    assert set(dets[0]) == {"class_id", "class_name", "score", "box_xyxy"} and len(dets[0]["box_xyxy"]) == 4
    assert [d["class_name"] for d in dets] == ["dog", "car", "bicycle", "bicycle"]
    res = CliRunner().invoke(app, ["detect", str(DOG), "--model", str(MODEL_DIR / "yolov5n-dynamic.onnx")])
    assert res.exit_code == 0 and "car" in res.stdout


def test_missing_model_exits_2_with_one_line(app, tmp_path):
    img = tmp_path / "x.png"
    img.write_bytes(b"")
    res = CliRunner().invoke(app, ["detect", str(img), "--model", str(tmp_path / "missing.onnx")])
    assert res.exit_code == 2
    assert "Traceback" not in res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: model file not found")


def test_not_onnx_exits_2(app, tmp_path):
    bad = tmp_path / "bad.onnx"
    bad.write_text("nope")
    res = CliRunner().invoke(app, ["detect", str(tmp_path / "x.png"), "--model", str(bad)])
    assert res.exit_code == 2 and "not a usable ONNX model" in res.output and "Traceback" not in res.output
