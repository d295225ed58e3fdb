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


def test_miss_rate_and_false_positives_per_image_at_the_working_threshold():
    from benchmark.scoring import FOUND_IOU, FOUND_SCORE, working_point

    dets = [
        {"image_id": 1, "category_id": 3, "bbox": [10, 10, 20, 10], "score": 0.9},   # finds the car
        {"image_id": 1, "category_id": 3, "bbox": [11, 10, 20, 10], "score": 0.5},   # a second box on it: false positive
        {"image_id": 1, "category_id": 3, "bbox": [60, 60, 20, 10], "score": 0.24},  # below the threshold: not counted
        {"image_id": 2, "category_id": 8, "bbox": [10, 10, 20, 10], "score": 0.8},   # a truck on the car: missed, not a car FP
        {"image_id": 3, "category_id": 3, "bbox": [40, 40, 20, 10], "score": 0.3},   # off the car: missed and a false positive
        {"image_id": 3, "category_id": 3, "bbox": [70, 70, 20, 10], "score": 0.6},   # another false positive
        {"image_id": 4, "category_id": 3, "bbox": [10, 10, 20, 10], "score": 0.25},  # at the threshold: found
    ]
    near, far = detection_rates(_gt(), dets)
    assert (FOUND_SCORE, FOUND_IOU) == (0.25, 0.5)
    assert (near["miss_rate"], near["false_positives"], near["false_positives_per_image"]) == (0.5, 1, 0.5)
    assert (far["miss_rate"], far["false_positives"], far["false_positives_per_image"]) == (0.5, 2, 1.0)
    assert working_point(_gt(), dets) == {25.0: {"miss_rate": 0.5, "false_positives_per_image": 0.5},
                                          50.0: {"miss_rate": 0.5, "false_positives_per_image": 1.0}}
    assert working_point(_gt(), []) == {25.0: {"miss_rate": 1.0, "false_positives_per_image": 0.0},
                                        50.0: {"miss_rate": 1.0, "false_positives_per_image": 0.0}}
