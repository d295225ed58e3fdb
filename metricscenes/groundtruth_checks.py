"""verify's check of a collection's ground truth: ``groundtruth.json`` against its recorded
sha256, the plan, and the one box each scene's mask gives on the reference grid.

Read side (with :mod:`metricscenes.store`, whose :class:`~metricscenes.store.Collection`
and ``verify_collection`` call it): it reads masks through ``store.read_checked`` and
writes nothing.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from metricscenes.geometry import TanExtent, field_extent
from metricscenes.records import ResolvedManifest


def mask_box_xywh(mask: np.ndarray, extent: TanExtent, width_px: int, height_px: int,
                  field: TanExtent) -> list[float] | None:
    """The COCO box a mask gives on the reference grid (covering ``field``), exactly as
    ``generate`` computes it."""
    from metricscenes.groundtruth import box_tan_to_xywh, mask_box_tan

    box = mask_box_tan(np.asarray(mask, dtype=bool), extent)
    return None if box is None else box_tan_to_xywh(box, width_px, height_px, field)


def grid_field(manifest: dict | None) -> TanExtent:
    """The field a manifest's reference grid covers, from its JSON form (verify checks
    collections whose manifest no longer parses); the reference field where the manifest
    is absent or predates ``hfov_deg``."""
    grid = (manifest or {}).get("reference_grid") or {}
    return field_extent(grid.get("hfov_deg"), grid.get("width_px", 16), grid.get("height_px", 9))


def box_problem(img: dict, boxes: list, mask: np.ndarray, extent: TanExtent, field: TanExtent) -> str | None:
    """Is ``boxes`` (the scene's ground truth) exactly the one box its mask gives on the
    reference grid covering ``field``? None: yes."""
    from metricscenes.checked_read import GROUNDTRUTH_FILE

    scene_id = img["scene_id"]
    expected = mask_box_xywh(mask, extent, img["width"], img["height"], field) if mask.dtype == bool else None
    if expected is None:
        return f"scene {scene_id}: masks/{scene_id} is empty or not boolean"
    if len(boxes) != 1:
        return f"scene {scene_id}: {GROUNDTRUTH_FILE} has {len(boxes)} boxes for it, not 1"
    if not np.allclose(boxes[0], expected, rtol=0.0, atol=1e-6):
        return f"scene {scene_id}: its {GROUNDTRUTH_FILE} box {boxes[0]} is not the box of its mask {expected}"
    return None


def groundtruth_problems(root: Path, group, groundtruth: dict, groundtruth_sha256: str,
                         resolved: ResolvedManifest | None) -> list[str]:
    """The ground truth against its recorded sha256. Where that is absent (collections
    written before it, or an unusable resolved manifest) or differs, every scene is
    checked against the plan and its box recomputed from its mask, so that each problem
    names its scene."""
    from metricscenes.checked_read import GROUNDTRUTH_FILE, CollectionError, _extent, read_checked

    recorded = resolved.groundtruth_sha256 if resolved is not None else None
    if recorded is not None and recorded == groundtruth_sha256:
        return []
    arrays = resolved.arrays if resolved is not None else {}
    images = {img["scene_id"]: img for img in groundtruth["images"]}
    boxes: dict[int, list] = {}
    for ann in groundtruth["annotations"]:
        boxes.setdefault(ann["image_id"], []).append(ann["bbox"])
    problems = []
    field = grid_field(resolved.manifest_json if resolved is not None else None)
    if resolved is not None:
        grid = resolved.manifest_json.get("reference_grid", {})
        plan = {s.get("scene_id"): s for s in resolved.plan if isinstance(s, dict)}
        problems += [f"scene {s}: missing from {GROUNDTRUTH_FILE}" for s in plan if s not in images]
        problems += [f"scene {s}: in {GROUNDTRUTH_FILE} but not in the plan" for s in images if s not in plan]
        for scene_id, img in images.items():
            planned = {**plan.get(scene_id, {}), "width": grid.get("width_px"), "height": grid.get("height_px")}
            changed = [k for k in ("image_id", "environment_id", "distance_m", "width", "height")
                       if scene_id in plan and img.get("id" if k == "image_id" else k) != planned.get(k)]
            if changed:
                problems.append(f"scene {scene_id}: {GROUNDTRUTH_FILE} differs from the plan in {', '.join(changed)}")
    for scene_id, img in images.items():
        path = f"masks/{scene_id}"
        try:
            data, attrs = read_checked(root, group, path, arrays.get(path), f"scene {scene_id}")
            problem = box_problem(img, boxes.get(img["id"], []), data, _extent(attrs, f"scene {scene_id}", path),
                                   field)
        except (CollectionError, KeyError, TypeError) as exc:
            problem = str(exc) if isinstance(exc, CollectionError) else f"scene {scene_id}: {GROUNDTRUTH_FILE} entry is malformed"
        if problem:
            problems.append(problem)
    if recorded is not None and not problems:
        problems.append(f"{GROUNDTRUTH_FILE} does not match its sha256 (edited or damaged)")
    return problems
