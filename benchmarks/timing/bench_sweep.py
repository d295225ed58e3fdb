"""Scene by scene against camera by camera: what a sweep gains when its cameras share each scene.

``benchmark sweep`` runs each condition's cameras together (:func:`benchmark.experiments.run.run_cameras`):
a scene's radiance is read once for all of them and resampled once per pixel grid (the
paper's 13 cameras have six grids). This script runs the same cameras both ways on a
collection subset, in this process, and prints the wall time of each, their ratio (both
measured in the same run: these machines are noisy), the time per capture and per stage, and
whether every run's detections and images are byte-identical.

    PYTHONPATH=. python benchmarks/timing/bench_sweep.py --collection collections/quick \\
        --cameras cam07,cam10,cam12,cam08 --condition night --environments 0

Results: docs/performance.md, "A camera run and the 13-camera sweep".
"""

from __future__ import annotations

import argparse
import hashlib
import tempfile
import time
from pathlib import Path


def _files(folder: Path) -> dict[str, str]:
    """sha256 of a run folder's detections and images."""
    paths = [folder / "detections.json", *sorted((folder / "images").glob("*.png"))]
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in paths}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--collection", required=True)
    parser.add_argument("--cameras", default="cam07,cam10,cam12,cam08")
    parser.add_argument("--condition", default="night")
    parser.add_argument("--environments", default="0")
    parser.add_argument("--threads", type=int, default=None, help="detector threads")
    args = parser.parse_args()

    from benchmark.camera import load_camera
    from benchmark.detectors import load_detector
    from benchmark.experiments.run import run_camera, run_cameras
    from benchmark.experiments.subset import subset_collection
    from metricscenes.store import Collection

    collection = subset_collection(Collection.open(args.collection), args.environments, None)
    cameras = [load_camera(name) for name in args.cameras.split(",")]
    detector = load_detector("yolov5n-dynamic", threads=args.threads)
    n_captures = len(cameras) * len(collection.scenes())
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        t = time.perf_counter()
        alone = [run_camera(collection, c, args.condition, detector, tmp / "alone" / c.name) for c in cameras]
        t_alone = time.perf_counter() - t
        t = time.perf_counter()
        together = run_cameras(collection, cameras, args.condition, detector, [tmp / "together" / c.name for c in cameras])
        t_together = time.perf_counter() - t
        same = all(_files(tmp / "alone" / c.name) == _files(tmp / "together" / c.name) for c in cameras)
    print(f"{len(cameras)} cameras x {len(collection.scenes())} scenes, {args.condition}: "
          f"camera by camera {t_alone:.1f} s ({t_alone / n_captures:.2f} s a capture), "
          f"scene by scene {t_together:.1f} s ({t_together / n_captures:.2f} s a capture): "
          f"ratio {t_alone / t_together:.2f}; detections and images identical: {same}")
    for label, runs in (("camera by camera", alone), ("scene by scene", together)):
        stages: dict[str, float] = {}
        for r in runs:
            for stage, seconds in r.timing_s.items():
                stages[stage] = stages.get(stage, 0.0) + seconds
        if label == "scene by scene":
            stages["read_radiance"] /= len(runs)  # (each run records the shared read)
        print(f"  {label}: " + ", ".join(f"{k} {v / n_captures:.2f} s" for k, v in stages.items()) + " a capture")


if __name__ == "__main__":
    main()
