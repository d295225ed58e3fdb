"""YOLOX (Megvii) output convention, grid decode and candidate selection.

Output [b, N, 85], N = grid cells over strides 8, 16, 32 (stride 8 first; within a
stride y outer, x inner); row = tx, ty, tw, th **raw**, objectness (sigmoid), 80 class
probabilities (sigmoid). Decode (``yolox/models/yolo_head.py: decode_outputs``):
cx = (tx + gx)·s, cy = (ty + gy)·s, w = exp(tw)·s, h = exp(th)·s. Selection as
``yolox/utils/boxes.py: postprocess``: score = objectness × best class probability
>= conf, then class-wise ``batched_nms``.
Input: **BGR, raw 0-255**, resized by r = min(H/h, W/w) (truncated size) and placed at
the top-left of a 114 canvas (``yolox/data/data_augment.py: preproc``).
"""

from __future__ import annotations

import numpy as np

from benchmark.detectors.family import STRIDES, Decoded, Family, select_classes, xywh_to_xyxy


def grid(canvas_hw: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """(gx, gy) cell indices and strides of every output row, in output order."""
    cells, strides = [], []
    for s in STRIDES:
        gy, gx = np.mgrid[0 : canvas_hw[0] // s, 0 : canvas_hw[1] // s]
        cells.append(np.stack([gx.ravel(), gy.ravel()], axis=1))
        strides.append(np.full(gx.size, s, dtype=np.float64))
    return np.concatenate(cells).astype(np.float64), np.concatenate(strides)


def decode(out: np.ndarray, canvas_hw: tuple[int, int], conf_threshold: float, multi_label: bool) -> Decoded:
    """Candidates of one image from its raw [N, 85] output (canvas pixels)."""
    cells, strides = grid(canvas_hw)
    if len(cells) != len(out):
        raise ValueError(f"YOLOX output has {len(out)} rows, the {canvas_hw} grid has {len(cells)}")
    cls = out[:, 5:].astype(np.float64) * out[:, 4:5]
    # Only rows that can pass the threshold need the (exp) decode.
    rows = np.nonzero(cls.max(axis=1) >= conf_threshold)[0]
    o = out[rows].astype(np.float64)
    xywh = np.empty((len(rows), 4))
    xywh[:, :2] = (o[:, :2] + cells[rows]) * strides[rows, None]
    xywh[:, 2:] = np.exp(o[:, 2:4]) * strides[rows, None]
    return select_classes(xywh_to_xyxy(xywh), cls[rows], conf_threshold, multi_label, inclusive=True)


FAMILY = Family(
    name="yolox",
    placement="topleft",
    bgr=True,
    pixel_scale=1.0,
    channels_last_output=True,
    anchors_per_cell=1,
    decode=decode,
)
