"""A synthetic run folder (results.json, detections.json, groundtruth.json), for tests and examples.

Ground truth and detections come from :func:`synthetic_scoring.synthetic_collection`
(seeded; AP falls with distance), scored with :func:`benchmark.scoring.ap_by_distance`, and
written in :mod:`benchmark.experiments.run`'s results format, as if ``camera`` had run on ``manifest``.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path


def write_synthetic_run(
    out_dir: str | Path,
    camera,
    condition: str = "day",
    *,
    manifest,
    n_environments: int = 4,
    half_range_m: float = 90.0,
    seed: int = 0,
    detector_name: str = "yolov5n-dynamic",
    distances_m=None,
) -> dict:
    """Write a run folder for ``camera`` (a CameraSpec) on ``manifest`` (a Manifest); returns results."""
    from benchmark.experiments.run import RESULTS_FORMAT, _finite_or_none
    from benchmark.detectors import registry
    from benchmark.scoring import AP_SCORE_THRESHOLD, ap_by_distance, od50
    from synthetic_scoring import synthetic_collection
    from metricscenes import __version__

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    gt, dets = synthetic_collection(n_environments, distances_m or manifest.distances_m, seed=seed, half_range_m=half_range_m)
    gt["info"] = {"description": f"synthetic {manifest.name}", "protocol": manifest.protocol, "manifest_sha256": manifest.sha256()}
    for im in gt["images"]:
        im["width"], im["height"] = camera.width_px, camera.height_px
    rows = ap_by_distance(gt, dets)
    det_bytes = json.dumps(dets, separators=(",", ":")).encode()
    entry = registry()[detector_name]
    results = {
        "format": RESULTS_FORMAT,
        "package_version": __version__,
        "camera": {"name": camera.name, "pixel_um": camera.pixel_um, "f_number": camera.f_number,
                   "width_px": camera.width_px, "height_px": camera.height_px, "spec_sha256": camera.sha256(),
                   "spec": camera.model_dump(mode="json")},
        "condition": condition,
        "detector": {"name": entry.name, "family": entry.family, "sha256": entry.sha256, "input_size": "multiscale",
                     "score_threshold": AP_SCORE_THRESHOLD, "multi_label": True},
        "collection": {"name": manifest.name, "protocol": manifest.protocol, "manifest_sha256": manifest.sha256(), "path": "synthetic"},
        "seed": seed,
        "scoring_backend": "faster-coco-eval",
        "per_distance": rows,
        "od50_m": _finite_or_none(od50([r["distance_m"] for r in rows], [r["ap"] for r in rows])),
        "detections_file": "detections.json",
        "detections_sha256": hashlib.sha256(det_bytes).hexdigest(),
    }  # fmt: skip
    (out / "detections.json").write_bytes(det_bytes)
    (out / "groundtruth.json").write_text(json.dumps(gt))
    (out / "results.json").write_text(json.dumps(results, indent=1))
    return results
