"""A scene onto the paper's six pixel grids: what keeping its grid-free parts saves.

A sweep resamples each scene once per pixel grid (six for the paper's 13 cameras). What does
not depend on the grid — the plate and each inset band by band, the inset pasted onto the
plate's cells — is now made once per scene (``SpectralScene._once``). This script resamples
the same scenes onto the six grids both ways in one run (the baseline empties the scene's
store before each grid, which is what every grid did before), alternating, best of
``--repeat``, checks that the composites are identical, and prints the times and their ratio.

    PYTHONPATH=. python benchmarks/timing/bench_resample.py --collection collections/quick --condition night

Results: docs/performance.md, "A camera run and the 13-camera sweep".
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--collection", required=True)
    parser.add_argument("--condition", default="night")
    parser.add_argument("--scenes", default="env000-d025m,env000-d100m,env003-d050m")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    from benchmark.camera import camera_names, load_camera
    from benchmark.camera.pipeline import camera_window, sensor_extent
    from benchmark.experiments.keys import grid_key
    from benchmark.experiments.collection_view import COMPOSITE
    from metricscenes.store import Collection

    collection = Collection.open(args.collection)
    grids = {}
    for camera in (load_camera(name) for name in camera_names()):
        grids.setdefault(grid_key(camera), camera)
    before_total = now_total = 0.0
    for scene_id in args.scenes.split(","):
        scene = collection.radiance(scene_id, args.condition, inset_resolution=COMPOSITE)
        best = {"before": np.inf, "now": np.inf}
        for _ in range(args.repeat):
            for way in ("before", "now"):
                scene._grid_free.clear()
                outs = []
                t = time.perf_counter()
                for camera in grids.values():
                    if way == "before":
                        scene._grid_free.clear()
                    scene._last_resample.clear()
                    camera_window(camera, scene.extent)
                    outs.append(scene.resample(camera.width_px, camera.height_px, sensor_extent(camera, scene.extent)))
                best[way] = min(best[way], time.perf_counter() - t)
                if way == "before":
                    reference = outs
                elif not all(np.array_equal(a, b) for a, b in zip(reference, outs)):
                    raise SystemExit(f"{scene_id}: the composites differ")
        before_total += best["before"]
        now_total += best["now"]
        print(f"{scene_id} {args.condition}: six grids {best['before']:.2f} s before, {best['now']:.2f} s now "
              f"({best['before'] / best['now']:.2f}x), composites identical")
    print(f"all: {before_total:.2f} s -> {now_total:.2f} s, {before_total / now_total:.2f}x")


if __name__ == "__main__":
    main()
