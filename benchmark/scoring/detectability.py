"""Is the car found? Per-distance detection rates at a working threshold, and what
the detector mistakes the car for (DESIGN §4; docs/scenes.md, "Detectability").

Unlike AP, which sweeps every threshold, this answers the practical question at one
operating point: is there a ``car`` detection with score ≥ ``score_threshold`` whose
box overlaps the ground truth with IoU ≥ ``iou_threshold``? When there is not, the
best-scoring detection of another class at that IoU says what the car was taken for
(``truck``, ``bus``, ...).

The working threshold, :data:`FOUND_SCORE` and :data:`FOUND_IOU`, is the one operating point of
``benchmark score``, the miss rate and false positives per image in ``results.json``, and
``compare``'s found-cars rule (docs/scoring.md, "The working threshold"). At it, per distance:
``miss_rate`` = 1 − found cars / images; ``false_positives_per_image`` = car detections at or above
the score that do not find the car (off the car, or a second box on it), per image.
"""

from __future__ import annotations

from collections import Counter, defaultdict

import numpy as np

from benchmark.coco import COCO80_NAMES, box_iou, coco80_class_id

CAR_CATEGORY_ID = 3
FOUND_SCORE = 0.25
"""A car is found by a car detection of at least this score (YOLO's own default confidence) ..."""
FOUND_IOU = 0.5
"""... overlapping its ground-truth box at least this much (COCO's AP50 match)."""


def _xyxy(bbox_xywh) -> list[float]:
    x, y, w, h = bbox_xywh
    return [x, y, x + w, y + h]


def detection_rates(groundtruth: dict, detections: list[dict], *, score_threshold: float = FOUND_SCORE,
                    iou_threshold: float = FOUND_IOU) -> list[dict]:
    """One row per distance: ``distance_m``, ``n_images``, ``detected`` (count),
    ``rate`` (fraction), ``miss_rate`` (1 − rate), ``false_positives`` (car detections at or above
    the threshold that do not find the car) and ``false_positives_per_image``, ``mistaken_for``
    ({class name: count} among the missed cars), ``missed_scenes`` (scene ids)."""
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
            "false_positives": 0, "mistaken_for": Counter(), "missed_scenes": []})
        row["n_images"] += 1
        found = by_image.get(image["id"], [])
        n_cars = sum(d["category_id"] == CAR_CATEGORY_ID for d in found)
        if not found or image["id"] not in car_box:
            row["false_positives"] += n_cars
            row["missed_scenes"].append(image.get("scene_id", image["id"]))
            continue
        ious = box_iou(np.array([_xyxy(d["bbox"]) for d in found]), np.array([car_box[image["id"]]]))[:, 0]
        overlapping = [d for d, iou in zip(found, ious) if iou >= iou_threshold]
        if any(d["category_id"] == CAR_CATEGORY_ID for d in overlapping):
            row["detected"] += 1
            row["false_positives"] += n_cars - 1  # one car box finds the car; any other is a false positive
            continue
        row["false_positives"] += n_cars
        row["missed_scenes"].append(image.get("scene_id", image["id"]))
        if overlapping:
            best = max(overlapping, key=lambda d: d["score"])
            row["mistaken_for"][COCO80_NAMES[coco80_class_id(best["category_id"])]] += 1
    out = []
    for distance in sorted(rows):
        row = rows[distance]
        rate = row["detected"] / row["n_images"]
        out.append({**row, "rate": rate, "miss_rate": 1.0 - rate,
                    "false_positives_per_image": row["false_positives"] / row["n_images"],
                    "mistaken_for": dict(row["mistaken_for"])})
    return out


def working_point(groundtruth: dict, detections: list[dict]) -> dict[float, dict]:
    """Per distance, ``{"miss_rate", "false_positives_per_image"}`` at the working threshold
    (:data:`FOUND_SCORE`, :data:`FOUND_IOU`): what ``results.json`` records beside AP."""
    return {r["distance_m"]: {"miss_rate": r["miss_rate"], "false_positives_per_image": r["false_positives_per_image"]}
            for r in detection_rates(groundtruth, detections)}
