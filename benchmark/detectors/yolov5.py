"""YOLOv5 (Ultralytics) output convention and candidate selection.

Output [b, N, 85], N = 3 anchors × grid cells; row = cx, cy, w, h (decoded, canvas
pixels), objectness (sigmoid), 80 class probabilities (sigmoid). Candidate selection is
that of YOLOv5 v7.0 ``utils/general.py: non_max_suppression``: objectness > conf, score =
objectness × class probability, best class (or all classes with ``multi_label``, as
``val.py``) with score > conf, at most 30000 candidates (highest scores) into NMS.
Input: RGB, 0-1, letterbox centred with grey 114 (``utils/augmentations.py: letterbox``).
"""

from __future__ import annotations

import numpy as np

from benchmark.detectors.family import Decoded, Family, select_classes, xywh_to_xyxy

MAX_NMS = 30000


def decode(out: np.ndarray, canvas_hw: tuple[int, int], conf_threshold: float, multi_label: bool) -> Decoded:
    """Candidates of one image from its [N, 85] output (canvas pixels)."""
    x = out[out[:, 4] > conf_threshold]
    cls = x[:, 5:].astype(np.float64) * x[:, 4:5]
    return select_classes(xywh_to_xyxy(x[:, :4]), cls, conf_threshold, multi_label)


FAMILY = Family(
    name="yolov5",
    placement="centre",
    bgr=False,
    pixel_scale=1.0 / 255.0,
    channels_last_output=True,
    anchors_per_cell=3,
    decode=decode,
    max_candidates=MAX_NMS,
)
