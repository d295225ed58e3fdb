"""A scene's layers as band planes: numpy's copy of the transposed view against the blocked copy.

Every resample reads its layers band by band (:func:`metricscenes.radiance.band_planes`):
the stored (rows, cols, bands) cube becomes (bands, rows, cols) planes once per scene. This
script makes those planes for the layers of a few scenes both ways in one run, alternating,
best of ``--repeat``, checks that they are identical, and prints the times and their ratio.

    PYTHONPATH=. python benchmarks/timing/bench_band_planes.py --collection /work/collections/metric-300-first2

Results: docs/performance.md, "A camera run and the 13-camera sweep".
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def whole_view_copy(cube: np.ndarray) -> np.ndarray:
    """band_planes before the blocked copy: numpy's copy of the whole transposed view."""
    return np.ascontiguousarray(np.moveaxis(np.asarray(cube, dtype=np.float32), 2, 0))


def best_of(repeat: int, make, cube: np.ndarray) -> tuple[float, np.ndarray]:
    best, out = np.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = make(cube)
        best = min(best, time.perf_counter() - t)
    return best, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--collection", required=True)
    parser.add_argument("--condition", default="dusk")
    parser.add_argument("--scenes", default="env000-d025m,env001-d100m")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    from benchmark.experiments.collection_view import COMPOSITE
    from metricscenes.radiance import band_planes
    from metricscenes.store import Collection

    collection = Collection.open(args.collection)
    totals = {"before": 0.0, "now": 0.0}
    for scene_id in args.scenes.split(","):
        scene = collection.radiance(scene_id, args.condition, inset_resolution=COMPOSITE)
        for k, layer in enumerate(scene.layers):
            cube = layer.radiance
            before, reference = best_of(args.repeat, whole_view_copy, cube)
            now, planes = best_of(args.repeat, band_planes, cube)
            if not np.array_equal(reference, planes):
                raise SystemExit(f"{scene_id} layer {k}: the band planes differ")
            totals["before"] += before
            totals["now"] += now
            print(f"{scene_id} layer {k} {'x'.join(map(str, cube.shape))}: {before:.3f} s before, {now:.3f} s now "
                  f"({before / now:.2f}x), identical")
    print(f"all layers: {totals['before']:.2f} s -> {totals['now']:.2f} s, {totals['before'] / totals['now']:.2f}x")


if __name__ == "__main__":
    main()
