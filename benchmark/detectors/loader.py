"""``load_detector``: registry name or path -> a ready :class:`OnnxDetector`."""

from __future__ import annotations

from pathlib import Path

from benchmark.detectors.base import DetectorError
from benchmark.detectors.classmap import parse_class_map
from benchmark.detectors.family import N_CLASSES
from benchmark.detectors.onnx_detector import FAMILIES, OnnxDetector, check_family, infer_family, open_session
from benchmark.detectors.policy import DEFAULT_INPUT_SIZE, parse_input_size
from benchmark.detectors.registry import resolve_model, verify_sha256


def load_detector(
    model: str | Path,
    *,
    family: str | None = None,
    input_size: str | int = DEFAULT_INPUT_SIZE,
    threads: int | None = None,
    model_dir: Path | None = None,
    class_map: str | list[str] | None = None,
) -> OnnxDetector:
    """Load a YOLOv5/YOLOv8/YOLOX ONNX detector.

    ``model`` is a registry name (file looked up in ``model_dir``, default env
    ``METRICSCENES_MODEL_DIR``) or a path. ``family`` is inspected from the output shape
    when None. ``input_size``: 'multiscale' (the default, as ``benchmark run`` and ``detect``),
    'native' or a multiple of 32 (see ``policy``).
    ``threads`` sets onnxruntime's intra-op threads. Raises :class:`DetectorError` (one
    line) for a missing file, a non-ONNX file, a wrong output shape or a sha256 mismatch.
    ``class_map``: for a model whose classes are not COCO's 80, the COCO class of each of
    its classes ('car' for a single-class car detector; see ``classmap``).
    """
    input_size = parse_input_size(input_size)
    lut = parse_class_map(class_map)
    n_classes = N_CLASSES if lut is None else len(lut)
    if family is not None and family not in FAMILIES:
        raise ValueError(f"family must be one of {sorted(FAMILIES)}, got {family!r}")
    path, entry = resolve_model(model, Path(model_dir) if model_dir is not None else None)
    digest = verify_sha256(path, entry)
    session = open_session(path, threads)
    if family is None:
        family = entry.family if entry is not None else infer_family(session, path, n_classes)
    check_family(session, path, FAMILIES[family], n_classes)
    name = entry.name if entry is not None else path.stem
    return OnnxDetector(session, path=path, name=name, family=family, sha256=digest, input_size=input_size,
                        class_map=lut, threads=threads)


__all__ = ["load_detector", "DetectorError"]
