from benchmark.scoring import detection_rates


def _gt():
    images = [{"id": i, "scene_id": f"s{i}", "distance_m": d, "environment_id": i % 2, "width": 100, "height": 100}
              for i, d in enumerate([25, 25, 50, 50], start=1)]
    anns = [{"id": i, "image_id": i, "category_id": 3, "bbox": [10, 10, 20, 10], "area": 200, "iscrowd": 0}
            for i in range(1, 5)]
    return {"images": images, "annotations": anns, "categories": [{"id": 3, "name": "car"}]}


def test_rates_threshold_iou_and_confusions():
    dets = [
        {"image_id": 1, "category_id": 3, "bbox": [10, 10, 20, 10], "score": 0.9},   # found
        {"image_id": 2, "category_id": 3, "bbox": [10, 10, 20, 10], "score": 0.2},   # below threshold
        {"image_id": 2, "category_id": 8, "bbox": [11, 10, 20, 10], "score": 0.6},   # taken for a truck
        {"image_id": 3, "category_id": 3, "bbox": [40, 40, 20, 10], "score": 0.9},   # wrong place
        {"image_id": 4, "category_id": 6, "bbox": [10, 10, 20, 11], "score": 0.7},   # a bus...
        {"image_id": 4, "category_id": 3, "bbox": [10, 10, 19, 10], "score": 0.3},   # ...and a car: found
    ]
    near, far = detection_rates(_gt(), dets)
    assert (near["distance_m"], near["detected"], near["rate"]) == (25.0, 1, 0.5)
    assert near["mistaken_for"] == {"truck": 1} and near["missed_scenes"] == ["s2"]
    assert (far["detected"], far["mistaken_for"], far["missed_scenes"]) == (1, {}, ["s3"])
    assert detection_rates(_gt(), dets, score_threshold=0.1)[0]["rate"] == 1.0
    assert all(r["rate"] == 0 for r in detection_rates(_gt(), []))
