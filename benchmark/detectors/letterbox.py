"""Image placement on the network canvas and its exact inverse for boxes.

Two placements exist in the families:

- ``centre`` — YOLOv5/YOLOv8 ``letterbox`` (``auto=False``): resize keeping the aspect
  ratio, r = min(H_in/h, W_in/w), new size = round(w·r) × round(h·r), pad evenly on both
  sides with grey 114 (top = round(dh/2 - 0.1), bottom = round(dh/2 + 0.1)).
- ``topleft`` — YOLOX ``preproc``: r as above, new size = int(w·r) × int(h·r) (truncated),
  image at the top-left of a canvas filled with 114.

Resizing is OpenCV ``INTER_LINEAR`` semantics (half-pixel centres, no antialiasing, edge
clamp) written in numpy, so no OpenCV dependency; values agree with ``cv2.resize`` to within
1 DN (OpenCV uses 11-bit fixed-point weights).

Boxes are mapped back with the per-axis scale actually applied (new_w/w, new_h/h) and the
integer padding actually used. YOLOv5 ``scale_boxes`` instead divides by r and subtracts
the *fractional* half-padding, which is off by 0.5 px when the padding is odd; ours is exact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PAD_VALUE = 114  # grey used by YOLOv5, YOLOv8 and YOLOX


@dataclass(frozen=True)
class Placement:
    """Where an image lies on the network canvas: x_canvas = x_image·scale_x + left."""

    scale_x: float
    scale_y: float
    left_px: int
    top_px: int
    image_wh: tuple[int, int]

    def to_image(self, boxes_xyxy: np.ndarray) -> np.ndarray:
        """Canvas boxes -> original-image boxes, clipped to the image."""
        b = np.asarray(boxes_xyxy, dtype=np.float64).reshape(-1, 4).copy()
        b[:, [0, 2]] = (b[:, [0, 2]] - self.left_px) / self.scale_x
        b[:, [1, 3]] = (b[:, [1, 3]] - self.top_px) / self.scale_y
        w, h = self.image_wh
        b[:, [0, 2]] = b[:, [0, 2]].clip(0.0, w)
        b[:, [1, 3]] = b[:, [1, 3]].clip(0.0, h)
        return b


def _linear_taps(n_in: int, n_out: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Source indices and weights of OpenCV INTER_LINEAR along one axis."""
    scale = n_in / n_out
    f = (np.arange(n_out) + 0.5) * scale - 0.5
    i0 = np.floor(f).astype(np.int64)
    frac = f - i0
    frac = np.where(i0 < 0, 0.0, frac)
    i0 = np.clip(i0, 0, n_in - 1)
    frac = np.where(i0 >= n_in - 1, 0.0, frac)
    i1 = np.minimum(i0 + 1, n_in - 1)
    return i0, i1, frac


def resize_linear(image: np.ndarray, width: int, height: int) -> np.ndarray:
    """Bilinear resize of a uint8 (H, W, C) image to (height, width), OpenCV INTER_LINEAR style."""
    h, w = image.shape[:2]
    if (w, h) == (width, height):
        return image
    y0, y1, fy = _linear_taps(h, height)
    x0, x1, fx = _linear_taps(w, width)
    img = image.astype(np.float32)
    rows = img[y0] * (1.0 - fy)[:, None, None].astype(np.float32) + img[y1] * fy[:, None, None].astype(np.float32)
    out = rows[:, x0] * (1.0 - fx)[None, :, None].astype(np.float32) + rows[:, x1] * fx[None, :, None].astype(np.float32)
    return np.clip(np.rint(out), 0, 255).astype(np.uint8)


def _canvas(image: np.ndarray, canvas_hw: tuple[int, int], top: int, left: int) -> np.ndarray:
    out = np.full((canvas_hw[0], canvas_hw[1], image.shape[2]), PAD_VALUE, dtype=np.uint8)
    out[top : top + image.shape[0], left : left + image.shape[1]] = image
    return out


def letterbox(image: np.ndarray, canvas_hw: tuple[int, int], placement: str) -> tuple[np.ndarray, Placement]:
    """Resize (aspect kept) and place ``image`` on a ``canvas_hw`` canvas; ``placement`` = centre | topleft."""
    h, w = image.shape[:2]
    r = min(canvas_hw[0] / h, canvas_hw[1] / w)
    if placement == "centre":
        new_w, new_h = int(round(w * r)), int(round(h * r))
        dw, dh = (canvas_hw[1] - new_w) / 2, (canvas_hw[0] - new_h) / 2
        top, left = int(round(dh - 0.1)), int(round(dw - 0.1))
    elif placement == "topleft":
        new_w, new_h = int(w * r), int(h * r)
        top, left = 0, 0
    else:
        raise ValueError(f"placement must be 'centre' or 'topleft', got {placement!r}")
    resized = resize_linear(image, new_w, new_h)
    return _canvas(resized, canvas_hw, top, left), Placement(new_w / w, new_h / h, left, top, (w, h))


def pad_to_stride(image: np.ndarray, placement: str, stride: int = 32) -> tuple[np.ndarray, Placement]:
    """No resize: pad with grey 114 up to the next multiple of ``stride`` (centred or bottom/right)."""
    h, w = image.shape[:2]
    ch, cw = -(-h // stride) * stride, -(-w // stride) * stride
    if placement == "centre":  # YOLOv5 letterbox(auto=True) at the native long side: r = 1
        top, left = int(round((ch - h) / 2 - 0.1)), int(round((cw - w) / 2 - 0.1))
    elif placement == "topleft":
        top, left = 0, 0
    else:
        raise ValueError(f"placement must be 'centre' or 'topleft', got {placement!r}")
    return _canvas(image, (ch, cw), top, left), Placement(1.0, 1.0, left, top, (w, h))
