"""What differs between detector families: input layout, placement, output decoding.

A family turns one image's raw output into candidate boxes (canvas pixels, x1 y1 x2 y2),
scores and contiguous class ids, *before* NMS; the shared pipeline (``onnx_detector``)
does placement, batching, class-wise NMS and the mapping back to image pixels.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

STRIDES = (8, 16, 32)
N_CLASSES = 80

Decoded = tuple[np.ndarray, np.ndarray, np.ndarray]  # boxes_xyxy (n,4), scores (n,), class_ids (n,)


def grid_cells(height_px: int, width_px: int) -> int:
    """Number of grid cells over the three strides (8, 16, 32) of a canvas."""
    return sum((height_px // s) * (width_px // s) for s in STRIDES)


def xywh_to_xyxy(xywh: np.ndarray) -> np.ndarray:
    out = np.empty_like(xywh, dtype=np.float64)
    out[:, :2] = xywh[:, :2] - xywh[:, 2:4] / 2
    out[:, 2:] = xywh[:, :2] + xywh[:, 2:4] / 2
    return out


def select_classes(boxes: np.ndarray, cls_scores: np.ndarray, conf_threshold: float, multi_label: bool, inclusive: bool = False) -> Decoded:
    """Best class per box (or every class above threshold when ``multi_label``), as YOLOv5/YOLOv8 NMS."""
    above = (lambda s: s >= conf_threshold) if inclusive else (lambda s: s > conf_threshold)
    if multi_label:
        i, j = np.nonzero(above(cls_scores))
        return boxes[i], cls_scores[i, j].astype(np.float64), j.astype(np.int64)
    j = cls_scores.argmax(axis=1) if len(cls_scores) else np.zeros(0, dtype=np.int64)
    conf = cls_scores[np.arange(len(j)), j].astype(np.float64)
    keep = above(conf)
    return boxes[keep], conf[keep], j[keep].astype(np.int64)


@dataclass(frozen=True)
class Family:
    """Conventions of one detector family (see docs/detection.md)."""

    name: str
    placement: str  # 'centre' (letterbox) or 'topleft'
    bgr: bool  # channel order of the network input
    pixel_scale: float  # network input = pixel value * pixel_scale
    channels_last_output: bool  # output [b, N, C] (True) or [b, C, N] (False)
    anchors_per_cell: int
    decode: Callable[[np.ndarray, tuple[int, int], float, bool], Decoded]
    max_candidates: int | None = None  # YOLOv5/YOLOv8 max_nms

    def expected_rows(self, canvas_hw: tuple[int, int]) -> int:
        return self.anchors_per_cell * grid_cells(*canvas_hw)

    def to_input(self, canvas_rgb: np.ndarray) -> np.ndarray:
        """(H, W, 3) uint8 RGB canvas -> (3, H, W) float32 network input."""
        chw = canvas_rgb[..., ::-1] if self.bgr else canvas_rgb
        return np.ascontiguousarray(chw.transpose(2, 0, 1), dtype=np.float32) * np.float32(self.pixel_scale)
