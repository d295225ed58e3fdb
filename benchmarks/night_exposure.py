"""What a camera collects from the car at night: exposure time, electrons on the car body,
and what sets the exposure (the central region's brightest pixels).

    PYTHONPATH=. python benchmarks/night_exposure.py --collection collections/quick \\
        --cameras cam12 cam08 --condition night [--exposure percentile:50] --out docs/data/night-exposure.csv

For every scene the camera simulation runs without temporal noise; per scene it writes
the exposure time (s), the median signal electrons of the green pixels inside the car's
ground-truth box, the same in the central region (the exposure policy's window), the
central region's 99.9th percentile and its ratio to the region's median, and which
fraction of the region is within a factor 2 of that peak (lamps, glare). A histogram of
log10 electrons in the central region is drawn for the first scene at each distance
(``--histograms``).
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np

from benchmark.camera import simulate
from benchmark.cameras import load_camera
from benchmark.exposure import central_region, parse_exposure, with_exposure
from metricscenes.groundtruth import scale_groundtruth
from metricscenes.store import Collection


def green_sites(electrons: np.ndarray, rows: slice, cols: slice) -> np.ndarray:
    """Green pixels (RGGB: (0, 1) and (1, 0) sites) of a window of a mosaic."""
    win = np.zeros(electrons.shape, bool)
    win[rows, cols] = True
    green = np.zeros(electrons.shape, bool)
    green[0::2, 1::2] = True
    green[1::2, 0::2] = True
    return electrons[win & green]


def scene_rows(collection: Collection, camera, condition: str) -> list[dict]:
    gt = scale_groundtruth(collection.groundtruth(), camera.width_px, camera.height_px)
    boxes = {a["image_id"]: a["bbox"] for a in gt["annotations"]}
    out = []
    for scene in collection.scenes():
        capture = simulate(collection.radiance(scene.scene_id, condition), camera, seed=0, noise=False)
        e = capture.electrons
        x, y, w, h = boxes[scene.image_id]
        car = green_sites(e, slice(int(y), int(np.ceil(y + h))), slice(int(x), int(np.ceil(x + w))))
        region = e[central_region(e.shape, camera.exposure.region_fraction)]
        peak = float(np.percentile(region, 99.9))
        out.append({
            "camera": camera.name, "condition": condition, "exposure_mode": camera.exposure.mode,
            "scene_id": scene.scene_id, "distance_m": scene.distance_m,
            "exposure_ms": round(1e3 * capture.exposure_s, 4),
            "car_median_e": round(float(np.median(car)), 2),
            "region_median_e": round(float(np.median(region)), 3),
            "region_p999_e": round(peak, 1),
            "peak_over_median": round(peak / max(float(np.median(region)), 1e-9), 1),
            "fraction_near_peak": float(f"{np.mean(region >= 0.5 * peak):.2e}"),
        })
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--collection", required=True)
    parser.add_argument("--cameras", nargs="+", default=["cam12"])
    parser.add_argument("--condition", default="night")
    parser.add_argument("--exposure", default=None, help="an acquisition policy, as `benchmark run --exposure`")
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()
    collection = Collection.open(args.collection)
    rows = []
    for name in args.cameras:
        camera = load_camera(name)
        if args.exposure:
            camera = with_exposure(camera, parse_exposure(args.exposure))
        rows += scene_rows(collection, camera, args.condition)
        by_d: dict[float, list[dict]] = {}
        for r in rows:
            if r["camera"] == name:
                by_d.setdefault(r["distance_m"], []).append(r)
        for d, rs in sorted(by_d.items()):
            print(f"{name} {args.condition} {d:5.0f} m: exposure {np.median([r['exposure_ms'] for r in rs]):7.3f} ms, "
                  f"car {np.median([r['car_median_e'] for r in rs]):8.2f} e-, "
                  f"peak/median {np.median([r['peak_over_median'] for r in rs]):8.1f}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
