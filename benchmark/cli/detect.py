"""``benchmark detect``: run a COCO detector on image files and print its detections.

Mounted by the lead's ``benchmark/cli/main.py`` through :func:`register`.
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
from benchmark.detectors.policy import DEFAULT_INPUT_SIZE
from metricscenes.cli_support import fail


def _read_rgb(path: Path) -> np.ndarray:
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as im:
            return np.asarray(im.convert("RGB"))
    except (FileNotFoundError, UnidentifiedImageError, OSError) as exc:
        raise ValueError(f"cannot read image {path}: {type(exc).__name__}") from None


def _save_targets(save: Path, images: list[Path]) -> list[Path]:
    """Where --save writes each image: the file itself for one image (PNG, JPEG, ... by its
    suffix), else ``save/<stem>.png`` (``<stem>-<n>.png`` for a repeated stem)."""
    from PIL import Image

    if len(images) == 1 and save.suffix:
        if save.suffix.lower() not in Image.registered_extensions():
            raise ValueError(f"--save {save}: unknown image format {save.suffix!r} (use .png or .jpg)")
        if save.is_dir():
            raise ValueError(f"--save {save} is a folder; name a file such as boxes.png")
        return [save]
    if save.exists() and not save.is_dir():
        raise ValueError(f"--save {save}: with {len(images)} images --save names a folder, and this is a file")
    targets: list[Path] = []
    for i, path in enumerate(images):
        target = save / f"{path.stem}.png"
        targets.append(save / f"{path.stem}-{i}.png" if target in targets else target)
    return targets


def _checked_targets(save: Path, images: list[Path]) -> list[Path]:
    """:func:`_save_targets`, none of them inside a collection, run, sweep or leaderboard
    (:func:`metricscenes.outputs.check_output`: a drawn image never replaces a run's)."""
    from metricscenes.outputs import check_output

    targets = _save_targets(save, images)
    for target in targets:
        check_output(target, "--save")
    return targets


def detect(
    images: list[Path] = typer.Argument(..., help="Image files (PNG, JPEG, ...)."),
    model: str = typer.Option("yolov5n-dynamic", help="Registry name (found in --model-dir / $METRICSCENES_MODEL_DIR) or path to an ONNX file."),
    input_size: str = typer.Option(DEFAULT_INPUT_SIZE, help="'multiscale' (native + 640, the reference and `benchmark run`'s default), 'native' or a multiple of 32 such as 640."),
    conf: float = typer.Option(0.25, help="Confidence threshold."),
    iou: float = typer.Option(0.45, help="IoU threshold of the class-wise NMS."),
    json_out: bool = typer.Option(False, "--json", help="Print JSON: [{image, detections: [...]}, ...]."),
    model_dir: Optional[Path] = typer.Option(None, help="Folder holding the registry's model files."),
    threads: Optional[int] = typer.Option(None, help="onnxruntime intra-op threads."),
    class_map: Optional[str] = typer.Option(None, help="For a detector whose classes are not COCO's 80: the COCO class of each model class, in order ('car' for a single-class car detector, 'person,-,car'; '-' drops one)."),
    save: Optional[Path] = typer.Option(None, help="Write the image with its boxes, class and score drawn: a file (one image) or a folder (several: <stem>.png each)."),
) -> None:
    """Detect objects in images with a YOLOv5/YOLOv8/YOLOX ONNX model."""
    err = Console(stderr=True)
    try:
        targets = _checked_targets(save, images) if save is not None else []
        detector = load_detector(model, input_size=input_size, threads=threads, model_dir=model_dir, class_map=class_map)
        arrays = [_read_rgb(p) for p in images]
        results = detector.detect(arrays, conf_threshold=conf, iou_threshold=iou)
        for target, rgb, dets in zip(targets, arrays, results):
            from benchmark.detectors.draw import draw_detections

            target.parent.mkdir(parents=True, exist_ok=True)
            draw_detections(rgb, dets).save(target)
    except (DetectorError, ValueError, OSError) as exc:
        fail(str(exc))
    for target in targets:
        err.print(f"wrote {target}", markup=False, highlight=False, soft_wrap=True)
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
