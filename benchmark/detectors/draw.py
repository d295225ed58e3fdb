"""Boxes drawn on an image: what ``benchmark detect --save`` writes.

>>> from benchmark.detectors.draw import draw_detections     # doctest: +SKIP
>>> draw_detections(rgb_uint8, dets[0]).save("boxes.png")    # doctest: +SKIP

Each box is outlined in its class's colour (cars always in the same orange) and labelled
``class score`` (e.g. ``car 0.87``) on a filled tag above the box, or inside it where the
box touches the top of the image. The line width and the label's size follow the image size.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from benchmark.detectors.base import Detection

CAR_CLASS_ID = 2
# Distinct, readable colours; the car's is fixed so that figures of different runs agree.
PALETTE = ((230, 159, 0), (86, 180, 233), (0, 158, 115), (240, 228, 66), (0, 114, 178), (213, 94, 0), (204, 121, 167))


def class_colour(class_id: int) -> tuple[int, int, int]:
    """The outline colour of a class: orange for cars, another palette colour for the rest."""
    if int(class_id) == CAR_CLASS_ID:
        return PALETTE[0]
    return PALETTE[1 + int(class_id) % (len(PALETTE) - 1)]


def draw_detections(rgb: np.ndarray, detections: Sequence[Detection]):
    """A PIL RGB image of ``rgb`` (uint8 H×W×3) with every detection's box, class and score."""
    from PIL import Image, ImageDraw, ImageFont

    image = Image.fromarray(np.ascontiguousarray(rgb[..., :3]).astype(np.uint8, copy=False), "RGB")
    draw = ImageDraw.Draw(image)
    short = min(image.size)
    width = max(2, round(short / 250))
    font = ImageFont.load_default(size=max(10, round(short / 40)))
    for d in sorted(detections, key=lambda d: d.score):  # the best drawn last, on top
        colour = class_colour(d.class_id)
        x1, y1, x2, y2 = (float(v) for v in d.box_xyxy)
        draw.rectangle([x1, y1, x2, y2], outline=colour, width=width)
        label = f"{d.class_name} {d.score:.2f}"
        left, top, right, bottom = draw.textbbox((0, 0), label, font=font)
        tw, th = right - left + 2 * width, bottom - top + 2 * width
        ty = y1 - th if y1 - th >= 0 else y1  # above the box, else inside its top edge
        draw.rectangle([x1, ty, x1 + tw, ty + th], fill=colour)
        draw.text((x1 + width - left, ty + width - top), label, fill=(0, 0, 0), font=font)
    return image
