"""COCO's vocabulary, shared by the detectors (which speak it) and the scoring (which reads it).

Class ids are the contiguous COCO-80 indices used by YOLOv5, YOLOv8 and YOLOX output
columns (0 = person, 2 = car); :func:`coco_category_id` maps them to the original COCO
category ids 1..90 used by ground truth and COCO result files (car = 3). Boxes here are
(x1, y1, x2, y2) in pixels.
"""

from __future__ import annotations

from importlib import resources

import numpy as np


def _load_names() -> tuple[str, ...]:
    text = resources.files("benchmark").joinpath("data/coco80.txt").read_text()
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


def box_iou(a_xyxy: np.ndarray, b_xyxy: np.ndarray) -> np.ndarray:
    """IoU matrix (len(a), len(b)) of boxes given as (x1, y1, x2, y2)."""
    a = np.asarray(a_xyxy, dtype=np.float64).reshape(-1, 4)
    b = np.asarray(b_xyxy, dtype=np.float64).reshape(-1, 4)
    lt = np.maximum(a[:, None, :2], b[None, :, :2])
    rb = np.minimum(a[:, None, 2:], b[None, :, 2:])
    inter = np.prod(np.clip(rb - lt, 0.0, None), axis=2)
    area_a = np.prod(a[:, 2:] - a[:, :2], axis=1)
    area_b = np.prod(b[:, 2:] - b[:, :2], axis=1)
    union = area_a[:, None] + area_b[None, :] - inter
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(union > 0, inter / union, 0.0)
