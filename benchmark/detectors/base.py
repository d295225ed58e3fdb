"""Typed values shared by every detector family: detections, the detector protocol, errors.

Class ids are the contiguous COCO-80 indices (:mod:`benchmark.coco`) of the YOLO output columns.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, Sequence, runtime_checkable

import numpy as np

from benchmark.coco import coco_category_id


class DetectorError(ValueError):
    """A model file that cannot be used (missing, not ONNX, wrong output shape, sha256 mismatch).

    The message is one line and names the file, so a CLI can print it as is.
    """


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
