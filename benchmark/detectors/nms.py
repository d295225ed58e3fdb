"""Non-maximum suppression in numpy, as the YOLO families define it.

``nms`` is ``torchvision.ops.nms``: boxes sorted by score (descending), a box is dropped
when its IoU with an already kept box is strictly greater than the threshold; areas are
(x2 - x1)·(y2 - y1) with no "+1". ``batched_nms`` is class-wise NMS by the coordinate
offset trick of YOLOv5 ``non_max_suppression`` / ``torchvision.ops.batched_nms``: each
class is shifted by ``class_id · offset`` so that boxes of different classes never overlap.
"""

from __future__ import annotations

import numpy as np

YOLOV5_MAX_WH = 7680.0
"""YOLOv5's class offset (``max_wh``); raised automatically when boxes are larger."""


def nms(boxes_xyxy: np.ndarray, scores: np.ndarray, iou_threshold: float, max_keep: int | None = None) -> np.ndarray:
    """Indices of the kept boxes, best score first (``torchvision.ops.nms``); with
    ``max_keep``, the first ``max_keep`` of them (greedy suppression never revisits a kept
    box, so stopping there changes none of them: the same as cutting the full list)."""
    boxes = np.asarray(boxes_xyxy, dtype=np.float64).reshape(-1, 4)
    order = np.argsort(-np.asarray(scores, dtype=np.float64), kind="stable")
    x1, y1, x2, y2 = boxes.T
    areas = (x2 - x1) * (y2 - y1)
    keep: list[int] = []
    while order.size and (max_keep is None or len(keep) < max_keep):
        i = order[0]
        keep.append(int(i))
        rest = order[1:]
        w = np.clip(np.minimum(x2[i], x2[rest]) - np.maximum(x1[i], x1[rest]), 0.0, None)
        h = np.clip(np.minimum(y2[i], y2[rest]) - np.maximum(y1[i], y1[rest]), 0.0, None)
        inter = w * h
        union = areas[i] + areas[rest] - inter
        with np.errstate(invalid="ignore", divide="ignore"):
            iou = np.where(union > 0, inter / union, 0.0)
        order = rest[iou <= iou_threshold]
    return np.asarray(keep, dtype=np.int64)


def batched_nms(
    boxes_xyxy: np.ndarray,
    scores: np.ndarray,
    class_ids: np.ndarray,
    iou_threshold: float,
    max_det: int | None = None,
) -> np.ndarray:
    """Class-wise NMS (YOLOv5 offset trick); indices of kept boxes, best first, at most ``max_det``."""
    boxes = np.asarray(boxes_xyxy, dtype=np.float64).reshape(-1, 4)
    if boxes.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    # YOLOv5 uses max_wh = 7680; a larger offset is needed only if boxes reach that far.
    offset = max(YOLOV5_MAX_WH, float(np.abs(boxes).max()) * 2.0 + 1.0)
    shifted = boxes + np.asarray(class_ids, dtype=np.float64)[:, None] * offset
    return nms(shifted, scores, iou_threshold, max_keep=max_det)
