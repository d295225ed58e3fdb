"""Typed values shared by every detector family: detections, the detector protocol, errors.

Class ids are the contiguous COCO-80 indices used by YOLOv5, YOLOv8 and YOLOX output
columns (0 = person, 2 = car); :func:`coco_category_id` maps them to the original COCO
category ids 1..90 used by ground truth and COCO result files (car = 3).
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Protocol, Sequence, runtime_checkable

import numpy as np


class DetectorError(ValueError):
    """A model file that cannot be used (missing, not ONNX, wrong output shape, sha256 mismatch).

    The message is one line and names the file, so a CLI can print it as is.
    """


def _load_names() -> tuple[str, ...]:
    text = resources.files("benchmark.detectors").joinpath("data/coco80.txt").read_text()
    return tuple(line.strip() for line in text.splitlines() if line.strip())


COCO80_NAMES: tuple[str, ...] = _load_names()
"""The 80 COCO class names in output-column order (ultralytics/yolov5 ``data/coco.yaml``)."""

# Contiguous 0..79 -> COCO category id 1..90 (the 11 unused ids of the 91-id list skipped);
# the same table as YOLOv5 ``utils/general.py: coco80_to_coco91_class``.
COCO80_TO_COCO91: tuple[int, ...] = (
    1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 27,
    28, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44, 46, 47, 48, 49, 50, 51, 52, 53,
    54, 55, 56, 57, 58, 59, 60, 61, 62, 63, 64, 65, 67, 70, 72, 73, 74, 75, 76, 77, 78, 79, 80,
    81, 82, 84, 85, 86, 87, 88, 89, 90,
)  # fmt: skip


def coco_category_id(class_id: int) -> int:
    """COCO category id (1..90) of a contiguous COCO-80 class index (0..79); car: 2 -> 3."""
    if not 0 <= int(class_id) < 80:
        raise ValueError(f"class_id must be in 0..79, got {class_id}")
    return COCO80_TO_COCO91[int(class_id)]


def coco80_class_id(category_id: int) -> int:
    """Inverse of :func:`coco_category_id`: COCO category id (1..90) -> 0..79; car: 3 -> 2."""
    try:
        return COCO80_TO_COCO91.index(int(category_id))
    except ValueError:
        raise ValueError(f"category_id {category_id} is not one of the 80 COCO detection categories") from None


@dataclass(frozen=True)
class Detection:
    """One detected object; ``box_xyxy`` = (x1, y1, x2, y2) in original-image pixels.

    Pixel coordinates are continuous: the top-left corner of the image is (0, 0) and the
    bottom-right corner is (width, height), as in COCO and YOLO.
    """

    class_id: int
    class_name: str
    score: float
    box_xyxy: tuple[float, float, float, float]

    def to_coco(self, image_id: int) -> dict:
        """COCO results entry: ``{image_id, category_id, bbox [x, y, w, h], score}``."""
        x1, y1, x2, y2 = self.box_xyxy
        return {
            "image_id": image_id,
            "category_id": coco_category_id(self.class_id),
            "bbox": [x1, y1, x2 - x1, y2 - y1],
            "score": self.score,
        }

    def to_dict(self) -> dict:
        return {
            "class_id": self.class_id,
            "class_name": self.class_name,
            "score": self.score,
            "box_xyxy": list(self.box_xyxy),
        }


@runtime_checkable
class Detector(Protocol):
    """What ``load_detector`` returns: a loaded model and its input-size policy."""

    name: str
    family: str
    sha256: str
    input_size: str | int
    path: Path

    def detect(
        self,
        images: Sequence[np.ndarray],
        *,
        conf_threshold: float = 0.001,
        iou_threshold: float = 0.45,
        max_det: int = 300,
    ) -> list[list[Detection]]:
        """Detect objects in RGB uint8 (H, W, 3) images; one list per image, best score first."""
        ...
