"""How often a detector calls our cars something else than COCO `car` (chiefly `truck`), and
what AP would be if `truck` counted as the car.

    PYTHONPATH=. python benchmarks/studies/vehicle_classes.py results/smoke-cam12-yolov5s results/smoke-cam12-yolov5n

Per run folder (results.json, detections.json, groundtruth.json of `benchmark run`) and distance:
the cars whose best overlapping detection (score >= 0.25, IoU >= 0.5; single-label: the box's top
class) is `car`, `truck` or another class, or none; the AP of the run (COCO `car` only, the
reference protocol) and the AP with `truck` detections counted as `car` (each box keeps the
better of its two scores, as one detection). Nothing is tuned: it reads what the runs wrote.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from benchmark.coco import COCO80_NAMES, box_iou, coco80_class_id  # noqa: E402
from benchmark.scoring import ap_by_distance  # noqa: E402

CAR, TRUCK = 3, 8  # COCO category ids


def _xyxy(b):
    return [b[0], b[1], b[0] + b[2], b[1] + b[3]]


def first_classes(groundtruth: dict, detections: list[dict], score: float = 0.25, iou: float = 0.5) -> dict:
    """{distance: Counter of the top class of each car's best overlapping detection ('none': no such detection)}."""
    boxes = {a["image_id"]: _xyxy(a["bbox"]) for a in groundtruth["annotations"]}
    by_image: dict[int, list[dict]] = {}
    for d in detections:
        if d["score"] >= score:
            by_image.setdefault(d["image_id"], []).append(d)
    out: dict[float, Counter] = {}
    for image in groundtruth["images"]:
        row = out.setdefault(float(image["distance_m"]), Counter())
        found = by_image.get(image["id"], [])
        ious = (box_iou(np.array([_xyxy(d["bbox"]) for d in found]), np.array([boxes[image["id"]]]))[:, 0]
                if found else [])
        overlapping = [d for d, v in zip(found, ious) if v >= iou]
        if not overlapping:
            row["none"] += 1
            continue
        best = max(overlapping, key=lambda d: d["score"])
        row[COCO80_NAMES[coco80_class_id(best["category_id"])]] += 1
    return out


def vehicle_detections(detections: list[dict]) -> list[dict]:
    """`truck` counted as `car`: each box (image, bbox) keeps its better car-or-truck score, once."""
    best: dict[tuple, dict] = {}
    for d in detections:
        if d["category_id"] not in (CAR, TRUCK):
            continue
        key = (d["image_id"], tuple(d["bbox"]))
        if key not in best or d["score"] > best[key]["score"]:
            best[key] = {**d, "category_id": CAR}
    return list(best.values())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path, help="run folders of `benchmark run`")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    report = []
    for run in args.runs:
        results = json.loads((run / "results.json").read_text())
        groundtruth = json.loads((run / "groundtruth.json").read_text())
        detections = json.loads((run / "detections.json").read_text())
        firsts = first_classes(groundtruth, detections)
        vehicle = {r["distance_m"]: r["ap"] for r in ap_by_distance(groundtruth, vehicle_detections(detections))}
        rows = []
        for r in results["per_distance"]:
            d = float(r["distance_m"])
            rows.append({"distance_m": d, "n": sum(firsts[d].values()), **dict(firsts[d]),
                         "ap_car": r["ap"], "ap_car_or_truck": round(float(vehicle[d]), 3)})
        total = sum((firsts[d] for d in firsts), Counter())
        report.append({"run": str(run), "detector": results["detector"]["name"], "camera": results["camera"]["name"],
                       "condition": results["condition"], "rows": rows, "total": dict(total)})
    if args.json:
        print(json.dumps(report, indent=1))
        return
    for entry in report:
        total = entry["total"]
        n = sum(total.values())
        print(f"{entry['run']} ({entry['camera']}, {entry['condition']}, {entry['detector']}): of {n} cars, "
              + ", ".join(f"{k} {v}" for k, v in sorted(total.items(), key=lambda kv: -kv[1])))
        print("  distance  n  car truck other none  AP(car)  AP(car|truck)")
        for r in entry["rows"]:
            other = r["n"] - sum(r.get(k, 0) for k in ("car", "truck", "none"))
            print(f"  {r['distance_m']:6g} {r['n']:3d} {r.get('car', 0):4d} {r.get('truck', 0):5d} {other:5d} "
                  f"{r.get('none', 0):4d}  {r['ap_car']:.3f}    {r['ap_car_or_truck']:.3f}")


if __name__ == "__main__":
    main()
