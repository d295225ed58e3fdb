"""COCO ground truth: one ``car`` box per scene in the reference pixel grid.

The box is the tight box of the car's visible pixels in a rendered instance mask (at
the inset's sampling, at least twice finer than the finest camera pixel for all but
the nearest cars), cross-checked against the box of the car's projected mesh
vertices. Boxes are floats in reference-grid pixels. A camera that sees the whole
field scales them to its own grid by its size ratio; one that sees a window of the
field (another focal length or active area) maps them through tangent coordinates onto
that window, exactly as its pixels sample the radiance (:func:`scale_groundtruth`).
"""

from __future__ import annotations

import numpy as np

from metricscenes.geometry import REFERENCE_EXTENT, TanExtent, extent_border, grid_to_tan, tan_to_grid, world_to_tan

CAR_CATEGORY = {"id": 3, "name": "car", "supercategory": "vehicle"}


def car_box_tan(vertices_world_m: np.ndarray) -> tuple[float, float, float, float]:
    """Tight box (x0, y0, x1, y1) of the projected vertices in tangent coordinates."""
    t = world_to_tan(vertices_world_m)
    return (float(t[:, 0].min()), float(t[:, 1].min()), float(t[:, 0].max()), float(t[:, 1].max()))


def mask_box_tan(mask: np.ndarray, extent) -> tuple[float, float, float, float] | None:
    """Tight box (x0, y0, x1, y1), tangent coordinates, of the True pixels of a mask
    sampled uniformly over ``extent`` (pixel edges, not centres). None if empty."""
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    if rows.size == 0:
        return None
    n_rows, n_cols = mask.shape
    px, py = extent.width / n_cols, extent.height / n_rows
    return (extent.x0 + cols[0] * px, extent.y0 + rows[0] * py,
            extent.x0 + (cols[-1] + 1) * px, extent.y0 + (rows[-1] + 1) * py)


def box_iou(a, b) -> float:
    """IoU of two (x0, y0, x1, y1) boxes."""
    iw = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    ih = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = iw * ih
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return inter / union if union > 0 else 0.0


def box_tan_to_xywh(box_tan, width_px: int, height_px: int, field: TanExtent = REFERENCE_EXTENT) -> list[float]:
    """Convert a tangent-coordinate box to a COCO ``[x, y, w, h]`` box in a pixel grid
    covering ``field`` (default the reference field of view), clipped to the grid."""
    corners = tan_to_grid(np.array([[box_tan[0], box_tan[1]], [box_tan[2], box_tan[3]]]), field, width_px, height_px)
    x0, y0 = np.clip(corners[0], 0, [width_px, height_px])
    x1, y1 = np.clip(corners[1], 0, [width_px, height_px])
    return [round(float(x0), 4), round(float(y0), 4), round(float(x1 - x0), 4), round(float(y1 - y0), 4)]


def coco_groundtruth(images: list[dict], boxes_xywh: list[list[float]], info: dict) -> dict:
    """Assemble the COCO dict. ``images`` carry id, file_name, width, height and the
    scene facts (scene_id, environment_id, distance_m, ...)."""
    annotations = [
        {
            "id": i + 1,
            "image_id": image["id"],
            "category_id": CAR_CATEGORY["id"],
            "bbox": box,
            "area": round(box[2] * box[3], 4),
            "iscrowd": 0,
        }
        for i, (image, box) in enumerate(zip(images, boxes_xywh, strict=True))
    ]
    return {"info": info, "images": images, "annotations": annotations, "categories": [CAR_CATEGORY]}


def scale_groundtruth(groundtruth: dict, width_px: int, height_px: int, *,
                      field: TanExtent | None = None, window: TanExtent | None = None,
                      to_sensor=None) -> dict:
    """The same ground truth on a camera's ``width_px`` × ``height_px`` grid.

    ``field``: the field the ground-truth grid covers (the collection's; default the
    reference field); ``window``: the part of it the camera's grid covers (default the
    whole field: the boxes are scaled by the size ratio, as ever). With a smaller window
    each box goes through tangent coordinates onto the window (the mapping of
    ``SpectralScene.resample(width_px, height_px, window)``), is clipped to the grid,
    and is dropped where nothing of it is left in the camera's view.

    ``to_sensor``: a lens's map from scene to sensor tangent coordinates (N, 2) → (N, 2)
    (radial distortion), with ``window`` then in sensor coordinates: each box becomes
    the bounds of its mapped border (a monotonic radial map sends the border of a box
    onto the border of its image, so the car stays inside).
    """
    field = REFERENCE_EXTENT if field is None else field
    if to_sensor is not None or (window is not None and window != field):
        return _groundtruth_in_window(groundtruth, width_px, height_px, field, window or field, to_sensor)
    out = {**groundtruth, "images": [], "annotations": []}
    scale = {}
    for image in groundtruth["images"]:
        sx, sy = width_px / image["width"], height_px / image["height"]
        scale[image["id"]] = (sx, sy)
        out["images"].append({**image, "width": width_px, "height": height_px})
    for ann in groundtruth["annotations"]:
        sx, sy = scale[ann["image_id"]]
        x, y, w, h = ann["bbox"]
        box = [x * sx, y * sy, w * sx, h * sy]
        out["annotations"].append({**ann, "bbox": box, "area": box[2] * box[3]})
    return out


def _groundtruth_in_window(groundtruth: dict, width_px: int, height_px: int, field: TanExtent,
                           window: TanExtent, to_sensor=None) -> dict:
    out = {**groundtruth, "images": [], "annotations": []}
    grids = {}
    for image in groundtruth["images"]:
        grids[image["id"]] = (image["width"], image["height"])
        out["images"].append({**image, "width": width_px, "height": height_px})
    for ann in groundtruth["annotations"]:
        w_ref, h_ref = grids[ann["image_id"]]
        x, y, w, h = ann["bbox"]
        tan = grid_to_tan(np.array([[x, y], [x + w, y + h]], float), field, w_ref, h_ref)
        if to_sensor is not None:
            seen = to_sensor(extent_border(TanExtent(*tan[0], *tan[1])))
            tan = np.array([seen.min(axis=0), seen.max(axis=0)])
        (x0, y0), (x1, y1) = np.clip(tan_to_grid(tan, window, width_px, height_px), 0.0, [width_px, height_px])
        if x1 <= x0 or y1 <= y0:
            continue  # the car lies outside the camera's field
        box = [float(x0), float(y0), float(x1 - x0), float(y1 - y0)]
        out["annotations"].append({**ann, "bbox": box, "area": box[2] * box[3]})
    return out

