"""`benchmark detect`: the same default input size as `benchmark run`; --save draws the boxes."""

from __future__ import annotations

import inspect

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from benchmark.detectors import Detection
from benchmark.detectors.draw import class_colour, draw_detections
from benchmark.detectors.policy import DEFAULT_INPUT_SIZE

CAR = Detection(class_id=2, class_name="car", score=0.87, box_xyxy=(40.0, 30.0, 120.0, 70.0))
TRUCK = Detection(class_id=7, class_name="truck", score=0.31, box_xyxy=(130.0, 2.0, 190.0, 60.0))


def _default(command, name):
    param = inspect.signature(command).parameters[name].default
    return getattr(param, "default", param)  # typer.Option(...) or an Annotated default


def test_detect_run_and_sweep_share_one_default_input_size():
    from benchmark.cli import main as cli, detect as cli_detect

    assert DEFAULT_INPUT_SIZE == "multiscale"  # the reference policy
    assert _default(cli_detect.detect, "input_size") == _default(cli.run, "input_size") \
        == _default(cli.sweep, "input_size") == DEFAULT_INPUT_SIZE


def test_draw_detections_outlines_and_labels():
    rgb = np.full((100, 200, 3), 60, np.uint8)
    out = np.asarray(draw_detections(rgb, [CAR, TRUCK]))
    assert out.shape == rgb.shape
    assert tuple(out[50, 40]) == class_colour(2) and tuple(out[50, 120]) == class_colour(2)  # left/right edges
    assert tuple(out[50, 80]) == (60, 60, 60)  # the inside is untouched
    assert tuple(out[50, 190]) == class_colour(7) != class_colour(2)
    tag = out[:30, 40:120]  # the car's label tag above its box: colour and dark text
    assert (tag == class_colour(2)).all(axis=-1).sum() > 50 and (tag.astype(int).sum(axis=-1) < 150).sum() > 10
    truck_tag = out[2:20, 131:190]  # a box at the top edge: the tag goes inside it
    assert (truck_tag == class_colour(7)).all(axis=-1).any()
    assert (rgb == 60).all()  # the input is not modified


class FakeDetector:
    name, family, sha256, input_size = "fake", "yolov5", "0" * 64, "multiscale"

    def detect(self, images, **kw):
        return [[CAR, TRUCK] for _ in images]


@pytest.fixture
def app(monkeypatch):
    from benchmark.cli import detect as cli_detect
    from benchmark.cli.main import app

    seen = {}

    def load(model, **kw):
        seen.update(kw)
        return FakeDetector()

    monkeypatch.setattr(cli_detect, "load_detector", load)
    app.seen = seen
    return app


def test_detect_save_writes_the_boxes(app, tmp_path):
    image = tmp_path / "frame.png"
    Image.fromarray(np.full((100, 200, 3), 60, np.uint8)).save(image)
    out = tmp_path / "figs" / "boxes.png"
    res = CliRunner().invoke(app, ["detect", str(image), "--save", str(out)])
    assert res.exit_code == 0, res.output
    assert app.seen["input_size"] == "multiscale"
    saved = np.asarray(Image.open(out).convert("RGB"))
    assert saved.shape == (100, 200, 3) and tuple(saved[50, 40]) == class_colour(2)
    assert "car" in res.output and f"wrote {out}" in res.output
    folder = tmp_path / "many"  # several images: a folder, one file each (a repeated stem numbered)
    res = CliRunner().invoke(app, ["detect", str(image), str(image), "--save", str(folder)])
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in folder.iterdir()) == ["frame-1.png", "frame.png"]


@pytest.mark.parametrize("target, message", [("boxes.xyz", "unknown image format '.xyz'"),
                                             ("file.txt/", None)])
def test_detect_save_errors_are_one_line(app, tmp_path, target, message):
    image = tmp_path / "frame.png"
    Image.fromarray(np.zeros((20, 20, 3), np.uint8)).save(image)
    if message is None:  # several images and --save names an existing file
        (tmp_path / "file.txt").write_text("x")
        args, message = [str(image), str(image), "--save", str(tmp_path / "file.txt")], "names a folder"
    else:
        args = [str(image), "--save", str(tmp_path / target)]
    res = CliRunner().invoke(app, ["detect", *args])
    assert res.exit_code == 2 and message in res.output
    assert len([line for line in res.output.splitlines() if line.strip()]) == 1
