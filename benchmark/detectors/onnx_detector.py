"""The shared ONNX pipeline: placement, batched onnxruntime inference, decode, NMS, un-placement.

Family conventions live in ``yolov5``, ``yolov8``, ``yolox``; input-size policies in
``policy``. Same-size canvases are stacked into one batch when the model's batch axis is
dynamic (at most ``MAX_BATCH_PX`` pixels per run, to bound memory).
"""

from __future__ import annotations

from collections import defaultdict
from functools import lru_cache
from pathlib import Path
from typing import Sequence

import numpy as np
import onnxruntime as ort

from benchmark.detectors import yolov5, yolov8, yolox
from benchmark.coco import COCO80_NAMES
from benchmark.detectors.base import Detection, DetectorError
from benchmark.detectors.family import N_CLASSES, Family, grid_cells
from benchmark.detectors.letterbox import Placement, letterbox, pad_to_stride
from benchmark.detectors.nms import batched_nms
from benchmark.detectors.policy import Pass, parse_input_size, plan_passes
from metricscenes.files import sha256_file

FAMILIES: dict[str, Family] = {f.name: f for f in (yolov5.FAMILY, yolov8.FAMILY, yolox.FAMILY)}
MAX_BATCH_PX = 4_000_000
_PROBE_HW = (64, 64)  # a dynamic model is probed at this size to learn its output layout


def open_session(path: Path, threads: int | None) -> ort.InferenceSession:
    """onnxruntime CPU session; ``threads`` sets intra-op threads (None = onnxruntime default)."""
    opts = ort.SessionOptions()
    opts.log_severity_level = 3
    if threads is not None:
        opts.intra_op_num_threads = int(threads)
        opts.inter_op_num_threads = 1
    try:
        return ort.InferenceSession(str(path), sess_options=opts, providers=["CPUExecutionProvider"])
    except Exception as exc:  # onnxruntime raises several types for unreadable files
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise DetectorError(f"not a usable ONNX model: {path} ({first[:160]})") from None


def _static_hw(session: ort.InferenceSession) -> tuple[int, int] | None:
    shape = session.get_inputs()[0].shape
    if len(shape) != 4 or shape[1] not in (3, "3"):
        raise DetectorError(f"expected an image input [batch, 3, H, W], got {shape}")
    h, w = shape[2], shape[3]
    return (h, w) if isinstance(h, int) and isinstance(w, int) else None


def _output_layout(session: ort.InferenceSession, path: Path) -> tuple[tuple[int, int], tuple[int, ...]]:
    """(canvas_hw, output shape) at the model's static size, or at a probe size for a dynamic model."""
    hw = _static_hw(session)
    out_shape = session.get_outputs()[0].shape
    if hw is not None and all(isinstance(d, int) for d in out_shape):
        return hw, tuple(out_shape)
    hw = hw or _PROBE_HW
    x = np.zeros((1, 3, *hw), dtype=np.float32)
    try:
        out = session.run(None, {session.get_inputs()[0].name: x})[0]
    except Exception as exc:
        raise DetectorError(f"{path}: model failed on a {hw[0]}x{hw[1]} probe input ({str(exc).splitlines()[0][:120]})") from None
    check_finite(out, path, f"a {hw[0]}x{hw[1]} probe input")
    return hw, tuple(out.shape)


def check_finite(output: np.ndarray, path: Path, what: str) -> None:
    """A model whose outputs hold NaN or infinity is broken: NaN scores pass no threshold,
    so it would silently find nothing. Refuse it with a one-line :class:`DetectorError`."""
    output = np.asarray(output)
    if output.dtype.kind == "f" and not np.isfinite(output).all():
        bad = int(np.count_nonzero(~np.isfinite(output)))
        share = "all" if bad == output.size else f"{bad} of {output.size}"
        raise DetectorError(f"{path}: the model's outputs are not finite on {what} ({share} values are NaN or "
                            "infinite); the model file is broken")


def infer_family(session: ort.InferenceSession, path: Path, n_classes: int = N_CLASSES) -> str:
    """Family from the output shape: [., 84, N] YOLOv8; [., N, 85] YOLOv5 (N = 3·cells) or YOLOX (N = cells)
    (4 + ``n_classes`` and 5 + ``n_classes`` for a model with a class map)."""
    hw, shape = _output_layout(session, path)
    cells = grid_cells(*hw)
    if len(shape) == 3 and shape[1] == 4 + n_classes and shape[2] == cells:
        return "yolov8"
    if len(shape) == 3 and shape[2] == 5 + n_classes:
        if shape[1] == 3 * cells:
            return "yolov5"
        if shape[1] == cells:
            return "yolox"
    raise DetectorError(
        f"wrong output shape {list(shape)} for a {hw[0]}x{hw[1]} input in {path}: expected "
        f"[b,{3 * cells},{5 + n_classes}] (YOLOv5), [b,{cells},{5 + n_classes}] (YOLOX) or [b,{4 + n_classes},{cells}] "
        f"(YOLOv8), {n_classes} classes" + (" (a model with other classes needs a class map: --class-map car, "
                                              "docs/detection.md)" if n_classes == N_CLASSES else " (the class map's)")
    )


def check_family(session: ort.InferenceSession, path: Path, family: Family, n_classes: int = N_CLASSES) -> None:
    hw, shape = _output_layout(session, path)
    rows = family.expected_rows(hw)
    want = (rows, 5 + n_classes) if family.channels_last_output else (4 + n_classes, rows)
    if len(shape) != 3 or tuple(shape[1:]) != want:
        raise DetectorError(f"wrong output shape {list(shape)} for a {family.name} model in {path}: expected [b,{want[0]},{want[1]}]")


class OnnxDetector:
    """A YOLO-family ONNX model with an input-size policy (see :func:`load_detector`)."""

    def __init__(self, session: ort.InferenceSession, *, path: Path, name: str, family: str, sha256: str, input_size: str | int,
                 class_map: tuple[int, ...] | None = None, threads: int | None = None):
        self.session = session
        self.threads = threads  # the session's intra-op threads (None: onnxruntime's default)
        self.class_map = class_map  # COCO-80 index per model class (-1: dropped); None: an 80-class COCO model
        self._class_lut = None if class_map is None else np.asarray(class_map, dtype=np.int64)
        self.path = Path(path)
        self.name = name
        self.family = family
        self.sha256 = sha256
        self.input_size = parse_input_size(input_size)
        self._family = FAMILIES[family]
        self._input_name = session.get_inputs()[0].name
        self._static_hw = _static_hw(session)
        self._dynamic_batch = not isinstance(session.get_inputs()[0].shape[0], int)
        self.passes: list[Pass] = plan_passes(self.input_size, self._static_hw, name)

    def __reduce__(self):
        """Pickled as what builds it, never as a session: another process (a sweep's worker)
        opens the same model file again, its sha256 checked (:func:`reopen_detector`)."""
        return reopen_detector, (self.path.absolute(), self.name, self.family, self.sha256, self.input_size,
                                 self.class_map, self.threads)

    def __repr__(self) -> str:
        return f"OnnxDetector(name={self.name!r}, family={self.family!r}, input_size={self.input_size!r}, passes={[p.label for p in self.passes]})"

    def _place(self, image: np.ndarray, p: Pass) -> tuple[np.ndarray, Placement]:
        if p.size_px is None:
            return pad_to_stride(image, self._family.placement)
        return letterbox(image, (p.size_px, p.size_px), self._family.placement)

    def _run(self, canvases: list[np.ndarray]) -> list[np.ndarray]:
        """Raw outputs, one per canvas (all canvases the same shape)."""
        fam = self._family
        h, w = canvases[0].shape[:2]
        per_run = max(1, MAX_BATCH_PX // (h * w)) if self._dynamic_batch else 1
        outs: list[np.ndarray] = []
        for start in range(0, len(canvases), per_run):
            x = np.stack([fam.to_input(c) for c in canvases[start : start + per_run]])
            y = self.session.run(None, {self._input_name: x})[0]
            check_finite(y, self.path, f"a {h}x{w} input")
            outs.extend(list(y))
        return outs

    def _pass(self, images: Sequence[np.ndarray], p: Pass, conf: float, iou: float, max_det: int, multi_label: bool):
        placed = [self._place(im, p) for im in images]
        groups: dict[tuple[int, int], list[int]] = defaultdict(list)
        for i, (canvas, _) in enumerate(placed):
            groups[canvas.shape[:2]].append(i)
        results: list = [None] * len(images)
        for hw, idx in groups.items():
            for i, out in zip(idx, self._run([placed[i][0] for i in idx])):
                boxes, scores, cls = self._family.decode(out, hw, conf, multi_label)
                if self._class_lut is not None:  # model classes -> COCO classes, dropped ones removed
                    cls = self._class_lut[cls]
                    boxes, scores, cls = boxes[cls >= 0], scores[cls >= 0], cls[cls >= 0]
                if self._family.max_candidates and len(scores) > self._family.max_candidates:
                    top = np.argsort(-scores, kind="stable")[: self._family.max_candidates]
                    boxes, scores, cls = boxes[top], scores[top], cls[top]
                keep = batched_nms(boxes, scores, cls, iou, max_det)
                results[i] = (placed[i][1].to_image(boxes[keep]), scores[keep], cls[keep])
        return results

    def with_input_size(self, input_size: str | int) -> "OnnxDetector":
        """The same model under another input-size policy, sharing this one's session."""
        return OnnxDetector(self.session, path=self.path, name=self.name, family=self.family, sha256=self.sha256,
                            input_size=input_size, class_map=self.class_map, threads=self.threads)

    def pass_policies(self) -> list[str | int]:
        """The single-pass policies whose passes this detector runs besides its own policy
        ('native' and 640 for multiscale; none for a single pass): their detections come
        with this detector's (:meth:`detect_policies`), with no inference of their own."""
        if len(self.passes) < 2:
            return []
        return ["native" if p.size_px is None else p.size_px for p in self.passes]

    def detect(
        self,
        images: Sequence[np.ndarray],
        *,
        conf_threshold: float = 0.001,
        iou_threshold: float = 0.45,
        max_det: int = 300,
        multi_label: bool = False,
    ) -> list[list[Detection]]:
        """Detections per RGB uint8 (H, W, 3) image, best score first, boxes in image pixels.

        ``multi_label`` keeps every class above ``conf_threshold`` for a box (YOLOv5
        ``val.py``); the default keeps the best class only (``detect.py``).
        """
        return self.detect_policies(images, conf_threshold=conf_threshold, iou_threshold=iou_threshold,
                                    max_det=max_det, multi_label=multi_label)[self.input_size]

    def detect_policies(
        self,
        images: Sequence[np.ndarray],
        also: Sequence[str | int] = (),
        *,
        conf_threshold: float = 0.001,
        iou_threshold: float = 0.45,
        max_det: int = 300,
        multi_label: bool = False,
    ) -> dict[str | int, list[list[Detection]]]:
        """:meth:`detect` under this detector's policy and under each policy of ``also``
        (from :meth:`pass_policies`): {policy: detections per image}. A pass's own
        detections are what that policy's detector finds (the same pass, unmerged), so a
        multiscale run gives its native and 640 runs for nothing."""
        for k, im in enumerate(images):
            if not (isinstance(im, np.ndarray) and im.ndim == 3 and im.shape[2] == 3 and im.dtype == np.uint8):
                raise ValueError(f"images[{k}] must be an RGB uint8 array (H, W, 3), got {getattr(im, 'dtype', type(im))} {getattr(im, 'shape', '')}")
        labels, also = self.pass_policies(), [parse_input_size(policy) for policy in also]
        for policy in also:
            if policy not in labels:
                raise ValueError(f"input size {policy} is not one of this detector's passes "
                                 f"({', '.join(map(str, labels)) or 'it runs one'})")
        per_pass = [self._pass(images, p, conf_threshold, iou_threshold, max_det, multi_label) for p in self.passes]
        out = {self.input_size: [self._merged([r[i] for r in per_pass], iou_threshold, max_det)
                                 for i in range(len(images))]}
        for policy in also:
            found = per_pass[labels.index(policy)]
            out[policy] = [self._merged([found[i]], iou_threshold, max_det) for i in range(len(images))]
        return out

    @staticmethod
    def _merged(passes: list, iou_threshold: float, max_det: int) -> list[Detection]:
        """One image's detections from its (boxes, scores, classes) per pass: several passes
        merged by class-wise NMS (multiscale), one taken as it is."""
        boxes = np.concatenate([r[0] for r in passes])
        scores = np.concatenate([r[1] for r in passes])
        cls = np.concatenate([r[2] for r in passes])
        if len(passes) > 1:  # multiscale: merge the passes by class-wise NMS
            keep = batched_nms(boxes, scores, cls, iou_threshold, max_det)
            boxes, scores, cls = boxes[keep], scores[keep], cls[keep]
        return [Detection(int(c), COCO80_NAMES[int(c)], float(s), tuple(float(v) for v in b))
                for b, s, c in zip(boxes, scores, cls)]


@lru_cache(maxsize=4)
def reopen_detector(path: Path, name: str, family: str, sha256: str, input_size: str | int,
                    class_map: tuple[int, ...] | None, threads: int | None) -> OnnxDetector:
    """A detector that another process loaded (what :meth:`OnnxDetector.__reduce__` pickles),
    loaded again here, once per process: the same file (:class:`DetectorError` if its sha256
    is no longer the one recorded) and the same settings."""
    digest = sha256_file(path)
    if digest != sha256:
        raise DetectorError(f"{path}: the model file changed (sha256 {digest}, the detector was loaded with {sha256})")
    return OnnxDetector(open_session(path, threads), path=path, name=name, family=family, sha256=sha256,
                        input_size=input_size, class_map=class_map, threads=threads)
