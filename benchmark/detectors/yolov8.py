"""YOLOv8 (Ultralytics) output convention and candidate selection.

Output [b, 84, N], N = grid cells (anchor-free, one prediction per cell); column =
cx, cy, w, h (decoded, canvas pixels), 80 class scores (sigmoid), no objectness.
Selection as ``ultralytics/utils/ops.py: non_max_suppression``: score = best class score
> conf (or every class above conf with ``multi_label``), at most 30000 into NMS.
Input: RGB, 0-1, letterbox centred with grey 114 (``LetterBox(auto=False)``).
"""

from __future__ import annotations

import numpy as np

from benchmark.detectors.family import Decoded, Family, select_classes, xywh_to_xyxy

MAX_NMS = 30000


def decode(out: np.ndarray, canvas_hw: tuple[int, int], conf_threshold: float, multi_label: bool) -> Decoded:
    """Candidates of one image from its [84, N] output (canvas pixels)."""
    x = out.T
    cls = x[:, 4:].astype(np.float64)
    keep = cls.max(axis=1) > conf_threshold if len(cls) else np.zeros(0, dtype=bool)
    return select_classes(xywh_to_xyxy(x[keep, :4]), cls[keep], conf_threshold, multi_label)


FAMILY = Family(
    name="yolov8",
    placement="centre",
    bgr=False,
    pixel_scale=1.0 / 255.0,
    channels_last_output=False,
    anchors_per_cell=1,
    decode=decode,
    max_candidates=MAX_NMS,
)
