"""Is the car found? Per-distance detection rates at a working threshold, and what
the detector mistakes the car for (DESIGN §4; docs/scenes.md, "Detectability").

Unlike AP, which sweeps every threshold, this answers the practical question at one
operating point: is there a ``car`` detection with score ≥ ``score_threshold`` whose
box overlaps the ground truth with IoU ≥ ``iou_threshold``? When there is not, the
best-scoring detection of another class at that IoU says what the car was taken for
(``truck``, ``bus``, ...).
"""

from __future__ import annotations

from collections import Counter, defaultdict

import numpy as np

from benchmark.coco import COCO80_NAMES, box_iou, coco80_class_id

CAR_CATEGORY_ID = 3


def _xyxy(bbox_xywh) -> list[float]:
    x, y, w, h = bbox_xywh
    return [x, y, x + w, y + h]


def detection_rates(groundtruth: dict, detections: list[dict], *, score_threshold: float = 0.25,
                    iou_threshold: float = 0.5) -> list[dict]:
    """One row per distance: ``distance_m``, ``n_images``, ``detected`` (count),
    ``rate`` (fraction), ``mistaken_for`` ({class name: count} among the missed cars),
    ``missed_scenes`` (scene ids)."""
    by_image: dict[int, list[dict]] = defaultdict(list)
    for d in detections:
        if d["score"] >= score_threshold:
            by_image[d["image_id"]].append(d)
    car_box = {a["image_id"]: _xyxy(a["bbox"]) for a in groundtruth["annotations"]
               if a["category_id"] == CAR_CATEGORY_ID}
    rows: dict[float, dict] = {}
    for image in groundtruth["images"]:
        row = rows.setdefault(float(image["distance_m"]), {
            "distance_m": float(image["distance_m"]), "n_images": 0, "detected": 0,
            "mistaken_for": Counter(), "missed_scenes": []})
        row["n_images"] += 1
        found = by_image.get(image["id"], [])
        if not found or image["id"] not in car_box:
            row["missed_scenes"].append(image.get("scene_id", image["id"]))
            continue
        ious = box_iou(np.array([_xyxy(d["bbox"]) for d in found]), np.array([car_box[image["id"]]]))[:, 0]
        overlapping = [d for d, iou in zip(found, ious) if iou >= iou_threshold]
        if any(d["category_id"] == CAR_CATEGORY_ID for d in overlapping):
            row["detected"] += 1
            continue
        row["missed_scenes"].append(image.get("scene_id", image["id"]))
        if overlapping:
            best = max(overlapping, key=lambda d: d["score"])
            row["mistaken_for"][COCO80_NAMES[coco80_class_id(best["category_id"])]] += 1
    out = []
    for distance in sorted(rows):
        row = rows[distance]
        out.append({**row, "rate": row["detected"] / row["n_images"], "mistaken_for": dict(row["mistaken_for"])})
    return out
