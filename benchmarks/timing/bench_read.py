"""Reading a collection's scenes as a camera run does: each environment's plate mixed once
for its scenes (``Collection`` keeps the last plate it mixed) against a fresh ``Collection``
per scene (every scene mixes its plate anew: the baseline).

    PYTHONPATH=. python benchmarks/timing/bench_read.py --collection collections/quick --scenes 12 --conditions day night

Every array is read and checked once before the timings (the sha256 checks are cached per
process either way), so both sides time reading, decoding and mixing. Prints seconds per
scene and the ratio, per condition, with the load average.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path


def main() -> None:
    from metricscenes.store import Collection

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--collection", type=Path, required=True)
    parser.add_argument("--scenes", type=int, default=12, help="the first N scenes (environments in turn)")
    parser.add_argument("--conditions", nargs="+", default=["day", "night"])
    args = parser.parse_args()

    collection = Collection.open(args.collection)
    scenes = [s.scene_id for s in collection.scenes()][: args.scenes]
    for condition in args.conditions:  # warm: every array checked once in this process
        for scene in scenes:
            Collection.open(args.collection).radiance(scene, condition)
    print(f"{args.collection}: {len(scenes)} scenes; load {os.getloadavg()[0]:.1f}")
    print("| condition | plate mixed once per environment, s per scene | fresh per scene (baseline) | ratio |")
    print("|---|---|---|---|")
    for condition in args.conditions:
        started = time.perf_counter()
        reused = Collection.open(args.collection)
        for scene in scenes:
            reused.radiance(scene, condition)
        once = (time.perf_counter() - started) / len(scenes)
        started = time.perf_counter()
        for scene in scenes:
            Collection.open(args.collection).radiance(scene, condition)
        fresh = (time.perf_counter() - started) / len(scenes)
        print(f"| {condition} | {once:.2f} | {fresh:.2f} | {fresh / once:.2f}x |", flush=True)


if __name__ == "__main__":
    main()
