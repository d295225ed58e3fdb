"""COCO-pretrained YOLO detectors (YOLOv5, YOLOv8, YOLOX) in ONNX through onnxruntime.

>>> det = load_detector("yolov5n-dynamic", input_size="multiscale")  # doctest: +SKIP
>>> det.detect([rgb_uint8])[0][0]                                     # doctest: +SKIP
Detection(class_id=2, class_name='car', score=0.70, box_xyxy=(468.0, 80.0, 690.0, 169.0))

See docs/detection.md for the families' conventions and the input-size policies.
"""

from benchmark.detectors.base import Detection, Detector, DetectorError
from benchmark.detectors.loader import load_detector
from benchmark.detectors.onnx_detector import OnnxDetector
from benchmark.detectors.registry import ModelEntry, registry

__all__ = [
    "Detection",
    "Detector",
    "DetectorError",
    "ModelEntry",
    "OnnxDetector",
    "load_detector",
    "registry",
]
