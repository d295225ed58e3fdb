"""COCO AP of one category, per distance (DESIGN §4).

AP = COCO AP@[.50:.05:.95] (101-point interpolated precision, mean over the 10 IoU
thresholds), ``ap50`` at IoU 0.5, maxDets 100, area range 'all' only (objects are not
split into small/medium/large: distance is the factor of interest). Computed separately
for each distance over that distance's images. ``faster-coco-eval`` by default,
``pycocotools`` as the reference; both give the same numbers (tests/test_scoring_ap.py).

Rules: an image set with ground truth and no detections has AP 0 (COCO itself returns 0
through its accumulate; ``loadRes`` would crash on an empty list, so it is not called); a
distance with no ground-truth object has AP NaN (COCO's -1 means "undefined").
"""

from __future__ import annotations

import contextlib
import io
from collections import defaultdict

import numpy as np

BACKENDS = ("faster-coco-eval", "pycocotools")
MAX_DETS = (1, 10, 100)
ALL_AREAS = [0.0, 1e10]
# The score a detection needs to be kept for AP: COCO evaluation wants the whole precision-recall
# curve, so runs keep every detection down to it and a submission's detections must say so.
CAR_CLASSES = ("car",)
"""The COCO classes whose detections count as the car in AP: COCO's `car` only, as the paper's
AP did (docs/detection.md, "What counts as the car"). Every results.json records it."""
AP_SCORE_THRESHOLD = 0.001


def _check_backend(backend: str) -> None:
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {BACKENDS}, got {backend!r}")


def _quiet():
    """Silence the libraries' prints (pycocotools prints to stdout)."""
    return contextlib.redirect_stdout(io.StringIO())


def make_coco_eval(groundtruth: dict, detections: list[dict], backend: str = "faster-coco-eval", evaluate: bool = True):
    """A COCOeval (bbox) of the chosen backend, params set to area 'all' and maxDets (1, 10, 100).

    ``detections`` must be non-empty (COCO ``loadRes`` cannot take an empty list).
    """
    _check_backend(backend)
    with _quiet():
        if backend == "pycocotools":
            from pycocotools.coco import COCO
            from pycocotools.cocoeval import COCOeval

            gt = COCO()
            gt.dataset = groundtruth
            gt.createIndex()
            ev = COCOeval(gt, gt.loadRes(list(detections)), iouType="bbox")
        else:
            from faster_coco_eval import COCO, COCOeval_faster

            gt = COCO(groundtruth, print_function=lambda *a, **k: None)
            dt = gt.loadRes(list(detections))
            ev = COCOeval_faster(gt, dt, iouType="bbox", print_function=lambda *a, **k: None)
        ev.params.areaRng = [ALL_AREAS]
        ev.params.areaRngLbl = ["all"]
        ev.params.maxDets = list(MAX_DETS)
    return ev


def _ap_from_eval(ev, image_ids: list[int], category_id: int) -> tuple[float, float]:
    ev.params.imgIds = sorted(image_ids)
    ev.params.catIds = [category_id]
    with _quiet():
        ev.evaluate()
        ev.accumulate()
    # precision[T, R, K, A, M]; K = the one category, A = 'all', M = maxDets 100 (as summarize()).
    p = np.asarray(ev.eval["precision"])[:, :, 0, 0, -1]
    if np.all(p < 0):  # no ground truth in this image set
        return float("nan"), float("nan")
    return float(np.mean(p[p > -1])), float(np.mean(p[0][p[0] > -1]))


def images_by_distance(groundtruth: dict) -> dict[float, list[int]]:
    """Image ids of the ground truth grouped by ``distance_m`` (sorted by distance)."""
    groups: dict[float, list[int]] = defaultdict(list)
    for im in groundtruth["images"]:
        if "distance_m" not in im:
            raise ValueError(f"ground-truth image {im.get('id')} has no 'distance_m'")
        groups[float(im["distance_m"])].append(int(im["id"]))
    return dict(sorted(groups.items()))


def check_detections(detections: list[dict]) -> None:
    """One-line ValueError naming the first detection whose ``bbox`` is not four finite
    numbers with a width and height of 0 or more, or whose ``score`` is not a finite number:
    COCO scores NaN and infinite boxes without a word (a NaN box matches nothing)."""
    try:  # all at once; one by one only to name the first bad one
        boxes = np.asarray([d["bbox"] for d in detections], dtype=np.float64).reshape(len(detections), 4)
        scores = np.asarray([d["score"] for d in detections], dtype=np.float64)
        if np.all(np.isfinite(boxes)) and np.all(boxes[:, 2:] >= 0) and np.all(np.isfinite(scores)):
            return
    except (TypeError, ValueError, KeyError):
        pass
    for k, d in enumerate(detections):
        box, score = (d.get("bbox"), d.get("score")) if isinstance(d, dict) else (None, None)
        try:
            values = np.asarray(box, dtype=np.float64)
            ok = values.shape == (4,) and bool(np.all(np.isfinite(values))) and values[2] >= 0 and values[3] >= 0
            ok = ok and bool(np.isfinite(float(score)))
        except (TypeError, ValueError):
            ok = False
        if not ok:
            where = f" (image {d.get('image_id')})" if isinstance(d, dict) else ""
            raise ValueError(f"detection {k}{where}: bbox {str(box)[:80]} and score {str(score)[:24]} must be four "
                             "finite numbers [x, y, width >= 0, height >= 0] and a finite number")


def ap_by_distance(
    groundtruth: dict,
    detections: list[dict],
    *,
    backend: str = "faster-coco-eval",
    category_id: int = 3,
) -> list[dict]:
    """COCO AP per distance: ``[{distance_m, ap, ap50, n_images}, ...]`` sorted by distance.

    ``groundtruth`` is a COCO dict whose images carry ``distance_m``; ``detections`` a COCO
    results list ``{image_id, category_id, bbox [x, y, w, h], score}``. Detections of other
    categories are ignored.
    """
    _check_backend(backend)
    check_detections(detections)
    known = {int(im["id"]) for im in groundtruth["images"]}
    unknown = sorted({int(d["image_id"]) for d in detections} - known)
    if unknown:
        raise ValueError(f"detections refer to image ids not in the ground truth: {unknown[:5]}")
    dets = [d for d in detections if int(d["category_id"]) == category_id]
    has_gt = {int(a["image_id"]) for a in groundtruth["annotations"] if int(a["category_id"]) == category_id}
    det_images = {int(d["image_id"]) for d in dets}
    ev = make_coco_eval(groundtruth, dets, backend) if dets else None
    rows = []
    for distance_m, ids in images_by_distance(groundtruth).items():
        if not has_gt.intersection(ids):
            ap, ap50 = float("nan"), float("nan")
        elif ev is None or not det_images.intersection(ids):
            ap, ap50 = 0.0, 0.0
        else:
            ap, ap50 = _ap_from_eval(ev, ids, category_id)
        rows.append({"distance_m": distance_m, "ap": ap, "ap50": ap50, "n_images": len(ids)})
    return rows
