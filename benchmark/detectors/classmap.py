"""Class maps: a detector whose classes are not COCO's 80 (a single-class car detector,
output ``[1, N, 6]`` for YOLOv5/YOLOX or ``[1, 5, N]`` for YOLOv8; or any custom list).

A class map names, for each of the model's output classes in order, the COCO class it
stands for, or ``-`` to drop it: ``"car"`` (one class, a car), ``"person,-,car"`` (three
classes, the second ignored). Several model classes may map to one COCO class (``"car,car"``
for sedan and SUV); the class-wise NMS then merges them. Detections carry the COCO class,
so scoring (car = COCO category 3) is unchanged. ``load_detector(..., class_map="car")``,
``--class-map car`` on ``benchmark detect``, ``run`` and ``sweep``; a run records it in
``results.json`` (``detector.class_map``) and the sweep cache key.
"""

from __future__ import annotations

from typing import Sequence

from benchmark.coco import COCO80_NAMES

DROP = "-"


def parse_class_map(value: str | Sequence[str] | None) -> tuple[int, ...] | None:
    """COCO-80 index (-1: dropped) per model output class, or None (an 80-class COCO model).
    A one-line ValueError for an empty entry, a name that is not a COCO class, or a map
    that drops every class."""
    if value is None:
        return None
    names = value.split(",") if isinstance(value, str) else list(value)
    out = []
    for raw in names:
        name = str(raw).strip().lower().replace("_", " ")
        if name == DROP:
            out.append(-1)
        elif name in COCO80_NAMES:
            out.append(COCO80_NAMES.index(name))
        else:
            raise ValueError(f"class map: {str(raw).strip()!r} is not a COCO class name (one per model class, in order, "
                             f"e.g. 'car' or 'person,-,car'; '-' drops a class)")
    if all(i < 0 for i in out):
        raise ValueError("class map: every class is dropped; name at least one COCO class (e.g. 'car')")
    return tuple(out)


def class_map_names(class_map: Sequence[int]) -> list[str]:
    """The map as recorded in results.json: a COCO name or '-' per model class."""
    return [DROP if i < 0 else COCO80_NAMES[i] for i in class_map]
