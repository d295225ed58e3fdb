"""Bad model files give one-line DetectorErrors; a synthetic YOLOv8 model checks decode + un-letterbox.

Tiny ONNX files are written by hand (protobuf wire format), so no `onnx` package is needed.
"""

import os
from pathlib import Path

import numpy as np
import pytest

from benchmark.detectors import DetectorError, load_detector
from benchmark.detectors.onnx_detector import infer_family, open_session

REPO = Path(__file__).resolve().parents[1]
MODEL_DIR = Path(os.environ.get("METRICSCENES_MODEL_DIR", REPO.parent / "shared" / "models"))


# --- a minimal protobuf / ONNX writer -------------------------------------------------
def _varint(n: int) -> bytes:
    out = b""
    while True:
        b, n = n & 0x7F, n >> 7
        out += bytes([b | (0x80 if n else 0)])
        if not n:
            return out


def _f(num: int, value) -> bytes:
    if isinstance(value, int):
        return _varint(num << 3) + _varint(value)
    data = value.encode() if isinstance(value, str) else value
    return _varint(num << 3 | 2) + _varint(len(data)) + data


def _value_info(name: str, shape) -> bytes:
    dims = b"".join(_f(1, _f(1, d) if isinstance(d, int) else _f(2, d)) for d in shape)
    return _f(1, name) + _f(2, _f(1, _f(1, 1) + _f(2, dims)))  # elem_type FLOAT


def _tensor(array: np.ndarray) -> bytes:
    dims = b"".join(_f(1, int(d)) for d in array.shape)
    return dims + _f(2, 1) + _f(9, np.ascontiguousarray(array, dtype="<f4").tobytes())


def write_onnx(path: Path, input_shape, output_shape, constant: np.ndarray | None = None) -> Path:
    """Identity model (output = input) or, with ``constant``, a model that returns it."""
    if constant is None:
        node = _f(1, "images") + _f(2, "output0") + _f(4, "Identity")
    else:
        attr = _f(1, "value") + _f(5, _tensor(constant)) + _f(20, 4)
        node = _f(2, "output0") + _f(4, "Constant") + _f(5, attr)
    graph = _f(1, node) + _f(2, "g") + _f(11, _value_info("images", input_shape)) + _f(12, _value_info("output0", output_shape))
    model = _f(1, 7) + _f(2, "metricscenes-test") + _f(7, graph) + _f(8, _f(1, "") + _f(2, 13))
    path.write_bytes(model)
    return path


def _yolov8_constant() -> np.ndarray:
    """[1, 84, 84] output for a 64x64 input: car 0.9, a weaker car duplicate, a truck on the same spot."""
    out = np.zeros((1, 84, 84), dtype=np.float32)
    for col, (cx, cy, w, h, cls, score) in enumerate([(32, 32, 20, 10, 2, 0.9), (33, 32, 20, 10, 2, 0.5), (32, 32, 20, 10, 7, 0.6)]):
        out[0, :4, col] = (cx, cy, w, h)
        out[0, 4 + cls, col] = score
    return out


def _assert_one_line(exc: pytest.ExceptionInfo, *words: str) -> None:
    msg = str(exc.value)
    assert "\n" not in msg and msg
    for w in words:
        assert w in msg


# --- errors ---------------------------------------------------------------------------
def test_missing_file(tmp_path):
    with pytest.raises(DetectorError) as e:
        load_detector(tmp_path / "nope.onnx")
    _assert_one_line(e, "not found", "nope.onnx")


def test_registry_name_without_model_dir(monkeypatch):
    monkeypatch.delenv("METRICSCENES_MODEL_DIR", raising=False)
    with pytest.raises(DetectorError) as e:
        load_detector("yolov5n")
    _assert_one_line(e, "METRICSCENES_MODEL_DIR")


def test_not_onnx(tmp_path):
    bad = tmp_path / "model.onnx"
    bad.write_text("this is not a model\nat all\n")
    with pytest.raises(DetectorError) as e:
        load_detector(bad)
    _assert_one_line(e, "not a usable ONNX model", "model.onnx")


def test_sha256_mismatch(tmp_path):
    fake = write_onnx(tmp_path / "yolov5n.onnx", [1, 3, 640, 640], [1, 3, 640, 640])  # registry file name
    with pytest.raises(DetectorError) as e:
        load_detector(fake)
    _assert_one_line(e, "sha256 mismatch", "yolov5n")


@pytest.mark.parametrize(
    "input_shape, output_shape, constant",
    [
        ([1, 3, 64, 64], [1, 3, 64, 64], None),  # image out
        ([1, 3, 64, 64], [1, 100, 85], np.zeros((1, 100, 85), np.float32)),  # N fits no grid
        ([1, 3, 64, 64], [1, 84, 83], np.zeros((1, 84, 83), np.float32)),  # YOLOv8-like, wrong N
    ],
)
def test_wrong_output_shape(tmp_path, input_shape, output_shape, constant):
    model = write_onnx(tmp_path / "odd.onnx", input_shape, output_shape, constant)
    with pytest.raises(DetectorError) as e:
        load_detector(model)
    _assert_one_line(e, "wrong output shape", "odd.onnx")


def test_explicit_family_checked(tmp_path):
    model = write_onnx(tmp_path / "v8.onnx", [1, 3, 64, 64], [1, 84, 84], _yolov8_constant())
    with pytest.raises(DetectorError) as e:
        load_detector(model, family="yolov5", input_size=64)
    _assert_one_line(e, "wrong output shape")
    with pytest.raises(ValueError, match="family"):
        load_detector(model, family="detr")


def test_bad_input_size_and_images(tmp_path):
    model = write_onnx(tmp_path / "v8.onnx", [1, 3, 64, 64], [1, 84, 84], _yolov8_constant())
    with pytest.raises(ValueError, match="multiple of 32"):
        load_detector(model, input_size=100)
    with pytest.raises(DetectorError, match="static 64x64"):
        load_detector(model, input_size=640)
    det = load_detector(model, input_size=64)
    with pytest.raises(ValueError, match="RGB uint8"):
        det.detect([np.zeros((10, 10), np.uint8)])


# --- a synthetic YOLOv8 model: decode, class-wise NMS, un-letterbox ---------------------
def test_yolov8_pipeline_oracle(tmp_path):
    model = write_onnx(tmp_path / "v8.onnx", [1, 3, 64, 64], [1, 84, 84], _yolov8_constant())
    assert infer_family(open_session(model, 1), model) == "yolov8"
    det = load_detector(model, input_size=64)
    assert det.family == "yolov8" and det.name == "v8" and len(det.sha256) == 64
    # 128x64 image -> r = 0.5, resized 64x32, centred: 16 px grey above. Canvas box
    # (22, 27, 42, 37) -> image ((22-0)/0.5, (27-16)/0.5, ...) = (44, 22, 84, 42).
    (dets,) = det.detect([np.zeros((64, 128, 3), np.uint8)], conf_threshold=0.25)
    assert [(d.class_name, round(d.score, 6)) for d in dets] == [("car", 0.9), ("truck", 0.6)]  # duplicate car suppressed
    for d in dets:
        assert d.box_xyxy == pytest.approx((44.0, 22.0, 84.0, 42.0))
    # with the IoU threshold above the duplicates' IoU (0.905), both cars stay
    (dets,) = det.detect([np.zeros((64, 128, 3), np.uint8)], conf_threshold=0.25, iou_threshold=0.95)
    assert [d.class_name for d in dets] == ["car", "truck", "car"]
    (dets,) = det.detect([np.zeros((64, 128, 3), np.uint8)], conf_threshold=0.7)
    assert [d.class_name for d in dets] == ["car"]


def test_static_model_native_warns(tmp_path):
    model = write_onnx(tmp_path / "v8.onnx", [1, 3, 64, 64], [1, 84, 84], _yolov8_constant())
    with pytest.warns(UserWarning, match="falls back to 64"):
        det = load_detector(model, input_size="native")
    assert [p.size_px for p in det.passes] == [64]


def test_a_detector_reopened_in_another_process_checks_its_file(tmp_path):
    """What a sweep worker does with a pickled detector: the same file loads again with the
    same settings; a file changed since the first load is refused in one line."""
    import shutil

    from benchmark.detectors.onnx_detector import reopen_detector

    model = tmp_path / "yolov5n.onnx"
    shutil.copyfile(MODEL_DIR / "yolov5n.onnx", model)
    first = load_detector(model, threads=1)
    again = reopen_detector(model, first.name, first.family, first.sha256, first.input_size, None, 1)
    assert (again.name, again.family, again.sha256) == (first.name, first.family, first.sha256)
    with model.open("ab") as f:
        f.write(b"\0")
    reopen_detector.cache_clear()
    with pytest.raises(DetectorError, match="the model file changed"):
        reopen_detector(model, first.name, first.family, first.sha256, first.input_size, None, 1)
