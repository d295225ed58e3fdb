"""COCO AP per distance: backends agree, edge cases, and a hand-computed oracle."""

import numpy as np
import pytest

from benchmark.scoring import ap_by_distance
from synthetic_scoring import synthetic_collection


def _gt(boxes_by_distance):
    images, anns = [], []
    for d, boxes in boxes_by_distance.items():
        for b in boxes:
            i = len(images) + 1
            images.append({"id": i, "width": 640, "height": 480, "file_name": f"{i}.png", "distance_m": d, "environment_id": i, "scene_id": i})
            anns.append({"id": i, "image_id": i, "category_id": 3, "bbox": list(b), "area": b[2] * b[3], "iscrowd": 0})
    return {"images": images, "annotations": anns, "categories": [{"id": 3, "name": "car"}]}


def test_backends_agree_on_hits_misses_duplicates_and_empty_distance():
    gt, dets = synthetic_collection(12, seed=3, empty_distance_m=150.0)
    assert any(d["category_id"] != 3 for d in dets)
    fast = ap_by_distance(gt, dets)
    ref = ap_by_distance(gt, dets, backend="pycocotools")
    assert [r["distance_m"] for r in fast] == [25.0, 50.0, 75.0, 100.0, 150.0, 200.0]
    for f, r in zip(fast, ref):
        assert f["n_images"] == r["n_images"] == 12
        assert f["ap"] == pytest.approx(r["ap"], abs=1e-12)
        assert f["ap50"] == pytest.approx(r["ap50"], abs=1e-12)
    by_d = {r["distance_m"]: r for r in fast}
    assert by_d[150.0]["ap"] == 0.0 and by_d[150.0]["ap50"] == 0.0  # empty distance -> 0, not -1
    assert by_d[25.0]["ap"] > by_d[200.0]["ap"]  # the generator degrades with distance
    assert 0.0 < by_d[25.0]["ap"] < by_d[25.0]["ap50"] <= 1.0


@pytest.mark.parametrize("backend", ["faster-coco-eval", "pycocotools"])
def test_oracle_values(backend):
    # distance 10: two images; a perfect hit (IoU 1) on image 1, a box of IoU 0.62 on image 2.
    # At IoU thresholds 0.50, 0.55, 0.60 both are found (AP 1); at 0.65..0.95 only image 1 is:
    # 101-point precision 1 up to recall 0.5, 0 beyond = 51/101. AP = (3·1 + 7·51/101) / 10.
    # distance 20: no detections -> AP 0.
    gt = _gt({10.0: [(100, 100, 100, 100), (100, 100, 100, 100)], 20.0: [(10, 10, 20, 20)]})
    dets = [
        {"image_id": 1, "category_id": 3, "bbox": [100, 100, 100, 100], "score": 0.9},
        {"image_id": 2, "category_id": 3, "bbox": [100, 100, 100, 62], "score": 0.8},  # IoU 0.62
    ]
    rows = ap_by_distance(gt, dets, backend=backend)
    assert rows[0]["ap50"] == pytest.approx(1.0)
    assert rows[0]["ap"] == pytest.approx((3 * 1.0 + 7 * 51 / 101) / 10)
    assert rows[1] == {"distance_m": 20.0, "ap": 0.0, "ap50": 0.0, "n_images": 1}


@pytest.mark.parametrize("backend", ["faster-coco-eval", "pycocotools"])
def test_no_detections_at_all_gives_zero(backend, capsys):
    gt, _ = synthetic_collection(2, seed=0)
    rows = ap_by_distance(gt, [], backend=backend)
    assert all(r["ap"] == 0.0 and r["ap50"] == 0.0 for r in rows)
    assert capsys.readouterr().out == ""


def test_libraries_are_silent(capsys):
    gt, dets = synthetic_collection(3, seed=1)
    ap_by_distance(gt, dets, backend="pycocotools")
    ap_by_distance(gt, dets)
    assert capsys.readouterr().out == ""


def test_bad_input():
    gt, dets = synthetic_collection(2, seed=0)
    with pytest.raises(ValueError, match="backend"):
        ap_by_distance(gt, dets, backend="detectron")
    with pytest.raises(ValueError, match="image ids not in the ground truth"):
        ap_by_distance(gt, dets + [{"image_id": 9999, "category_id": 3, "bbox": [0, 0, 1, 1], "score": 0.5}])
    gt["images"][0].pop("distance_m")
    with pytest.raises(ValueError, match="distance_m"):
        ap_by_distance(gt, dets)


def test_distance_without_ground_truth_is_nan():
    gt = _gt({10.0: [(0, 0, 10, 10)]})
    gt["images"].append({"id": 99, "width": 640, "height": 480, "file_name": "x.png", "distance_m": 30.0, "environment_id": 0})
    rows = ap_by_distance(gt, [{"image_id": 1, "category_id": 3, "bbox": [0, 0, 10, 10], "score": 0.5}])
    assert rows[0]["ap"] == pytest.approx(1.0)
    assert np.isnan(rows[1]["ap"])
