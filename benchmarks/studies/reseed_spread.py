"""Does the printed uncertainty cover the sensor's noise? One camera run again and again with
only the sensor-noise seed changed, scored as `benchmark compare` scores two cameras.

    PYTHONPATH=. python benchmarks/studies/reseed_spread.py --collection collections/quick \
        --camera cam12 --condition day --seeds 20 --work results/reseed [--subsets 40]

1. ``benchmark run --seed s`` for s in 0..seeds-1 (a finished run is kept: rerun to resume).
2. Each run's OD50 and its bootstrap SD over environments: the spread of OD50 across seeds
   against the SD a single run prints.
3. Every pair of seeds through :func:`benchmark.experiments.compare.compare_runs`: the fraction
   of pairs where a difference is called (ΔOD50's interval excludes 0, or AP differs at a
   distance) — every call is false, the camera is the same.
4. The same on subsets of k environments (the same k for both sides of a pair), k = 2 … all:
   how the false-call rate grows as the sample shrinks, from which the minimum is read.
Prints JSON (also written to WORK/summary.json).
"""

from __future__ import annotations

import argparse
import itertools
import json
import subprocess
import sys
from pathlib import Path

import metricscenes  # noqa: F401  (pins the numeric kernels before numpy)
import numpy as np

from benchmark.experiments import compare
from benchmark.experiments.compare import Side, compare_runs, load_side
from benchmark.scoring import bootstrap_od50


def run_seeds(collection: Path, camera: str, condition: str, seeds: int, work: Path) -> list[Path]:
    folders = []
    for seed in range(seeds):
        out = work / f"{camera}-{condition}-seed{seed:02d}"
        if not (out / "results.json").is_file():
            subprocess.run(["benchmark", "run", "--camera", camera, "--collection", str(collection),
                            "--condition", condition, "--seed", str(seed), "--out", str(out)],
                           check=True, stdout=subprocess.DEVNULL)
        folders.append(out)
    return folders


def restricted(side: Side, environments: set) -> Side:
    """``side`` with only the scenes of ``environments`` (ground truth and detections)."""
    images = [im for im in side.groundtruth["images"] if im["environment_id"] in environments]
    ids = {im["id"] for im in images}
    gt = {**side.groundtruth, "images": images,
          "annotations": [a for a in side.groundtruth["annotations"] if a["image_id"] in ids]}
    return Side(side.folder, side.results, gt, [d for d in side.detections if d["image_id"] in ids])


def calls(result: dict) -> dict[str, bool]:
    """What compare calls here, by its intervals and found-car rule alone (the minimum sample
    is switched off in :func:`main`: this measures what it has to stop): the headline (ΔOD50,
    or the ΔAP range where OD50 is censored), any distance, and either."""
    od = result["delta_od50"]
    if od["delta_m"] is not None:
        headline = bool(od["ci95_m"][0] > 0 or od["ci95_m"][1] < 0)
    else:
        headline = bool(result.get("delta_ap_range") and result["delta_ap_range"]["resolved"])
    distance = any(r["resolved"] for r in result["per_distance"])
    return {"headline": headline, "distance": distance, "any": headline or distance}


def od50_coverage(boots) -> dict:
    """How often one run's OD50 95 % interval holds another reseed's OD50 (pairs of runs whose
    OD50s are both measured), and the same for the AP range."""
    held = {"od50": [], "ap_range": []}
    for i, j in itertools.permutations(range(len(boots)), 2):
        a, b = boots[i], boots[j]
        if not a.censored and not b.censored:
            held["od50"].append(a.ci95_m[0] <= b.od50_m <= a.ci95_m[1])
        held["ap_range"].append(a.ap_range_ci95_m[0] <= b.ap_range_m <= a.ap_range_ci95_m[1])
    return {k: {"pairs": len(v), "held": int(sum(v))} for k, v in held.items()}


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--collection", type=Path, required=True)
    p.add_argument("--camera", default="cam12")
    p.add_argument("--condition", default="day")
    p.add_argument("--seeds", type=int, default=20)
    p.add_argument("--subsets", type=int, default=40, help="random (pair, environment subset) draws per k")
    p.add_argument("--resamples", type=int, default=1000)
    p.add_argument("--work", type=Path, required=True)
    args = p.parse_args(argv)
    compare.too_few = lambda n: False  # measure the intervals themselves, below the minimum too

    sides = [load_side(f) for f in run_seeds(args.collection, args.camera, args.condition, args.seeds, args.work)]
    boots = [bootstrap_od50(s.groundtruth, s.detections, n_resamples=args.resamples) for s in sides]
    od50s = np.array([b.od50_m for b in boots])
    finite = od50s[np.isfinite(od50s)]
    pairs = list(itertools.combinations(range(len(sides)), 2))
    full = [compare_runs(sides[i], sides[j], n_resamples=args.resamples) for i, j in pairs]
    full_calls = [calls(r) for r in full]
    parts = {k: int(sum(c[k] for c in full_calls)) for k in ("headline", "distance", "any")}
    deltas = np.array([r["delta_od50"]["delta_m"] for r in full if r["delta_od50"]["delta_m"] is not None])
    printed = np.array([r["delta_od50"]["sd_m"] for r in full if r["delta_od50"]["sd_m"] is not None])
    envs = sorted(sides[0].environments, key=str)
    rng = np.random.default_rng(0)
    by_k = {}
    for k in range(2, len(envs)):
        made = []
        for _ in range(args.subsets):
            i, j = pairs[rng.integers(len(pairs))]
            subset = set(rng.choice(np.array(envs, dtype=object), size=k, replace=False).tolist())
            made.append(calls(compare_runs(restricted(sides[i], subset), restricted(sides[j], subset),
                                           n_resamples=args.resamples))["any"])
        by_k[k] = {"draws": len(made), "false_calls": int(sum(made)), "rate": float(np.mean(made))}
        print(f"k={k}: {by_k[k]}", file=sys.stderr, flush=True)
    by_k[len(envs)] = {"draws": len(pairs), "false_calls": parts["any"], "rate": parts["any"] / len(pairs)}
    summary = {
        "collection": str(args.collection), "camera": args.camera, "condition": args.condition,
        "seeds": args.seeds, "environments": len(envs), "resamples": args.resamples,
        "od50_m": od50s.tolist(), "censored": [b.censored for b in boots],
        "od50_sd_across_seeds_m": float(np.std(finite, ddof=1)) if finite.size > 1 else None,
        "ap_range_m": [b.ap_range_m for b in boots],
        "ap_range_sd_across_seeds_m": float(np.std([b.ap_range_m for b in boots], ddof=1)),
        "ap_range_bootstrap_sd_median_m": float(np.median([b.ap_range_sd_m for b in boots])),
        "interval_holds_a_reseed": od50_coverage(boots),
        "false_calls_all_environments": {**parts, "pairs": len(pairs)},
        "bootstrap_sd_m": {"median": float(np.nanmedian([b.sd_m for b in boots])),
                           "min": float(np.nanmin([b.sd_m for b in boots])),
                           "max": float(np.nanmax([b.sd_m for b in boots]))},
        "delta_od50_m": {"pairs": int(deltas.size), "rms": float(np.sqrt(np.mean(deltas ** 2))) if deltas.size else None,
                         "printed_sd_median": float(np.median(printed)) if printed.size else None},
        "false_call_rate_by_environments": by_k,
    }
    args.work.mkdir(parents=True, exist_ok=True)
    (args.work / "summary.json").write_text(json.dumps(summary, indent=1))
    print(json.dumps(summary, indent=1))
    return summary


if __name__ == "__main__":
    main()
