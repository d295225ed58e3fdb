"""Does the reference plate's border show in a wide camera's image? `plate_seam_check`
(benchmark.measure.seam) over some scenes of a collection with a wide plate: per camera and scene,
the largest relative luminance step and L* step the seam adds across the plate's four edges
(docs/scenes.md, "The wide plate").

    PYTHONPATH=. python benchmarks/studies/plate_seam.py collections/adas-quick day \
        cameras/front-2.3mp-37deg.yaml cameras/adas-2.6mp-60deg.yaml --scenes env000-d100m env003-d100m env006-d100m
"""

from __future__ import annotations

import argparse

from benchmark.camera import load_camera
from benchmark.measure.seam import plate_seam_check
from metricscenes.store import Collection


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("collection")
    parser.add_argument("condition")
    parser.add_argument("cameras", nargs="+")
    parser.add_argument("--scenes", nargs="+", required=True)
    args = parser.parse_args()
    collection = Collection.open(args.collection)
    for name in args.cameras:
        camera = load_camera(name)
        for scene in args.scenes:
            r = plate_seam_check(collection, scene, args.condition, camera)
            edges = " ".join(f"{edge} {100 * v:+.2f} %" for edge, v in r["step_luminance"].items())
            print(f"{camera.name} {scene}: luminance step at most {100 * r['step_luminance_max']:.2f} % ({edges}); "
                  f"L* step at most {r['step_l_max']:.2f}; ΔE*ab inside {r['inside_de']:.2f}")


if __name__ == "__main__":
    main()
