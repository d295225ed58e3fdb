"""``benchmark detect``: run a COCO detector on image files and print its detections.

Mounted by the lead's ``benchmark/cli.py`` through :func:`register`.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Optional

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from benchmark.detectors import DetectorError, load_detector


def _read_rgb(path: Path) -> np.ndarray:
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as im:
            return np.asarray(im.convert("RGB"))
    except (FileNotFoundError, UnidentifiedImageError, OSError) as exc:
        raise ValueError(f"cannot read image {path}: {type(exc).__name__}") from None


def detect(
    images: list[Path] = typer.Argument(..., help="Image files (PNG, JPEG, ...)."),
    model: str = typer.Option("yolov5n-dynamic", help="Registry name (found in --model-dir / $METRICSCENES_MODEL_DIR) or path to an ONNX file."),
    input_size: str = typer.Option("native", help="'native', 'multiscale' or a multiple of 32 such as 640."),
    conf: float = typer.Option(0.25, help="Confidence threshold."),
    iou: float = typer.Option(0.45, help="IoU threshold of the class-wise NMS."),
    json_out: bool = typer.Option(False, "--json", help="Print JSON: [{image, detections: [...]}, ...]."),
    model_dir: Optional[Path] = typer.Option(None, help="Folder holding the registry's model files."),
    threads: Optional[int] = typer.Option(None, help="onnxruntime intra-op threads."),
) -> None:
    """Detect objects in images with a YOLOv5/YOLOv8/YOLOX ONNX model."""
    err = Console(stderr=True)
    try:
        detector = load_detector(model, input_size=input_size, threads=threads, model_dir=model_dir)
        arrays = [_read_rgb(p) for p in images]
        results = detector.detect(arrays, conf_threshold=conf, iou_threshold=iou)
    except (DetectorError, ValueError) as exc:
        err.print(f"error: {exc}", markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(code=2) from None
    if json_out:
        payload = [{"image": str(p), "detections": [d.to_dict() for d in dets]} for p, dets in zip(images, results)]
        typer.echo(json.dumps(payload, indent=2))
        return
    console = Console()
    for path, dets in zip(images, results):
        table = Table(title=f"{path} — {detector.name} ({detector.family}, {input_size})")
        for col in ("class_id", "class_name", "score", "box_xyxy"):
            table.add_column(col, justify="right" if col in ("class_id", "score") else "left")
        for d in dets:
            table.add_row(str(d.class_id), d.class_name, f"{d.score:.3f}", "[" + ", ".join(f"{v:.1f}" for v in d.box_xyxy) + "]")
        console.print(table)


def register(app: typer.Typer) -> None:
    """Add the ``detect`` command to a Typer app."""
    app.command("detect")(detect)
