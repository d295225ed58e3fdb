"""A synthetic, seeded COCO ground truth and detection set, for tests and examples.

One car per image (category 3) on a 1920×1080 grid, whose size falls as 1/distance; the
detector's recall, localisation and score degrade with distance, and each environment has
its own difficulty, so AP falls with distance and varies between environments. Detections
include hits, misses, duplicates (a second, worse box on the same car), false positives,
other categories and optionally a distance with no detections at all.

``noise_seed`` separates the capture noise from the scenes: the environments' difficulties and
the cars' boxes come from ``seed`` alone, and whether and how the detector finds each car from
``noise_seed`` — a camera run again with another sensor-noise seed (``benchmark run --seed``).
"""

from __future__ import annotations

import numpy as np

DISTANCES_M = (25.0, 50.0, 75.0, 100.0, 150.0, 200.0)


def synthetic_collection(
    n_environments: int = 10,
    distances_m=DISTANCES_M,
    *,
    seed: int = 0,
    half_range_m: float = 90.0,
    empty_distance_m: float | None = None,
    noise_seed: int | None = None,
) -> tuple[dict, list[dict]]:
    """(groundtruth COCO dict, COCO results list); AP ≈ 0.5 near ``half_range_m``. Without
    ``noise_seed`` one stream draws everything (the sets the tests were written against)."""
    rng = np.random.default_rng(seed)
    noise = rng if noise_seed is None else np.random.default_rng([seed, noise_seed])
    images, annotations, results = [], [], []
    for env in range(n_environments):
        difficulty = rng.normal(1.0, 0.25)  # per-environment factor on the effective distance
        for d in distances_m:
            image_id = len(images) + 1
            images.append({
                "id": image_id, "width": 1920, "height": 1080, "file_name": f"env{env:03d}_{int(d):03d}m.png",
                "distance_m": float(d), "environment_id": env, "scene_id": f"env{env:03d}-{int(d):03d}m",
            })  # fmt: skip
            w, h = 4.5 * 1000 / d, 1.5 * 1000 / d
            x, y = rng.uniform(0, 1920 - w), rng.uniform(500, 1080 - h)
            annotations.append({"id": image_id, "image_id": image_id, "category_id": 3, "bbox": [x, y, w, h], "area": w * h, "iscrowd": 0})
            if empty_distance_m is not None and d == empty_distance_m:
                continue
            hardness = d * max(difficulty, 0.2) / half_range_m  # 1 at the half range
            if noise.uniform() < 1.0 / (1.0 + hardness**4):  # hit
                for dup in range(1 + (noise.uniform() < 0.3)):  # sometimes a duplicate
                    jitter = noise.normal(0.0, 0.04 * hardness * (1 + dup), 4)
                    results.append({
                        "image_id": image_id, "category_id": 3,
                        "bbox": [x + jitter[0] * w, y + jitter[1] * h, w * np.exp(jitter[2]), h * np.exp(jitter[3])],
                        "score": float(noise.uniform(0.3, 1.0) / (1 + hardness) / (1 + dup)),
                    })  # fmt: skip
            for _ in range(noise.poisson(2)):  # false positives, some of another category
                fw, fh = noise.uniform(5, 80, 2)
                results.append({
                    "image_id": image_id, "category_id": int(noise.choice([3, 3, 8])),
                    "bbox": [noise.uniform(0, 1800), noise.uniform(0, 1000), fw, fh], "score": float(noise.uniform(0.001, 0.4)),
                })  # fmt: skip
    return {"images": images, "annotations": annotations, "categories": [{"id": 3, "name": "car"}, {"id": 8, "name": "truck"}]}, results
