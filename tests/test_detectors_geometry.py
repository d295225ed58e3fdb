"""Letterbox, padding, resize and NMS against analytic oracles; class-id mapping."""

import numpy as np
import pytest

from benchmark.coco import COCO80_NAMES, coco80_class_id, coco_category_id
from benchmark.detectors import Detection
from benchmark.detectors.letterbox import letterbox, pad_to_stride, resize_linear
from benchmark.detectors.nms import batched_nms, nms
from benchmark.detectors.policy import parse_input_size, plan_passes


def test_class_id_mapping():
    assert COCO80_NAMES[2] == "car" and len(COCO80_NAMES) == 80
    assert coco_category_id(2) == 3 and coco_category_id(0) == 1
    assert coco_category_id(11) == 13  # stop sign: COCO id 12 is unused
    assert coco_category_id(79) == 90
    assert [coco80_class_id(coco_category_id(k)) for k in range(80)] == list(range(80))
    with pytest.raises(ValueError, match="class_id"):
        coco_category_id(80)
    with pytest.raises(ValueError, match="category_id 12"):
        coco80_class_id(12)
    d = Detection(2, "car", 0.5, (10.0, 20.0, 40.0, 30.0))
    assert d.to_coco(7) == {"image_id": 7, "category_id": 3, "bbox": [10.0, 20.0, 30.0, 10.0], "score": 0.5}


def test_resize_linear_halving_is_pair_average():
    ramp = np.tile(np.arange(0, 200, 2, dtype=np.uint8), (4, 1))[..., None].repeat(3, axis=2)  # 4x100
    half = resize_linear(ramp, 50, 2)
    # INTER_LINEAR at exactly 1/2: source x = 2·x + 0.5 -> mean of pixels 2x and 2x+1 (= 4x + 1)
    np.testing.assert_array_equal(half[0, :, 0], np.arange(50) * 4 + 1)


def test_letterbox_centre_matches_yolov5_and_maps_back():
    img = np.zeros((576, 768, 3), np.uint8)
    canvas, pl = letterbox(img, (640, 640), "centre")
    assert canvas.shape == (640, 640, 3) and (pl.left_px, pl.top_px) == (0, 80)
    assert canvas[0, 0, 0] == 114 and canvas[80, 0, 0] == 0
    box = np.array([[100.0, 200.0, 300.0, 400.0]])
    on_canvas = box * [pl.scale_x, pl.scale_y, pl.scale_x, pl.scale_y] + [pl.left_px, pl.top_px, pl.left_px, pl.top_px]
    np.testing.assert_allclose(pl.to_image(on_canvas), box)
    # odd padding: 1000x333 at 640 -> 640x213, dh = 427 -> top round(213.5 - 0.1) = 213, bottom 214
    canvas, pl = letterbox(np.zeros((333, 1000, 3), np.uint8), (640, 640), "centre")
    assert pl.top_px == 213 and canvas[213 + 213, 0, 0] == 114 and canvas[213 + 212, 0, 0] == 0


def test_letterbox_topleft_matches_yolox():
    canvas, pl = letterbox(np.zeros((576, 768, 3), np.uint8), (416, 416), "topleft")
    # r = 416/768; new size int(768 r) x int(576 r) = 416 x 312 at the top-left
    assert (pl.left_px, pl.top_px) == (0, 0) and pl.scale_y == pytest.approx(312 / 576)
    assert canvas[311, 0, 0] == 0 and canvas[312, 0, 0] == 114


@pytest.mark.parametrize("placement, top", [("centre", 4), ("topleft", 0)])
def test_native_padding_no_resize(placement, top):
    img = np.full((1080, 1920, 3), 7, np.uint8)
    canvas, pl = pad_to_stride(img, placement)
    assert canvas.shape == (1088, 1920, 3) and pl.top_px == top and pl.scale_x == pl.scale_y == 1.0
    np.testing.assert_array_equal(canvas[top : top + 1080], img)
    np.testing.assert_allclose(pl.to_image([[10, 10 + top, 50, 60 + top]]), [[10, 10, 50, 60]])


def test_nms_oracle():
    boxes = np.array([[0, 0, 10, 10], [1, 0, 11, 10], [0, 0, 10, 5], [20, 20, 30, 30]], float)
    scores = np.array([0.9, 0.8, 0.7, 0.6])
    # IoU(0,1) = 90/110 = 0.818, IoU(0,2) = 0.5 exactly: kept at threshold 0.5 (strictly greater suppresses)
    assert nms(boxes, scores, 0.5).tolist() == [0, 2, 3]
    assert nms(boxes, scores, 0.45).tolist() == [0, 3]
    assert batched_nms(boxes, scores, np.array([2, 7, 2, 2]), 0.45).tolist() == [0, 1, 3]  # other class survives
    assert batched_nms(boxes, scores, np.array([2, 7, 2, 2]), 0.45, max_det=2).tolist() == [0, 1]
    assert batched_nms(np.zeros((0, 4)), np.zeros(0), np.zeros(0), 0.45).tolist() == []


def test_policies():
    assert parse_input_size("640") == 640 and parse_input_size("Native") == "native"
    for bad in ("600", "big", 0, -32, True):
        with pytest.raises(ValueError, match="input_size"):
            parse_input_size(bad)
    assert [p.size_px for p in plan_passes("multiscale", None, "m")] == [None, 640]
    assert [p.size_px for p in plan_passes(1280, None, "m")] == [1280]
    with pytest.warns(UserWarning, match="static"):
        assert [p.size_px for p in plan_passes("multiscale", (416, 416), "m")] == [416]
