"""cam12 against cameras that are cam12 but for one part: what each part does to detection.

Issue 27's comparison: the paired bootstrap of ``benchmark compare`` (same environments
resampled for both cameras) between a variant's run and cam12's, per condition, as one table:
OD50 of each, ΔOD50 ± SD with its 95 % interval (None where either OD50 is censored), AP at
25 m of each, ΔAP(25 m) ± SD with its interval, the distances where ``compare`` calls a
difference in AP (+: the variant's higher), and the verdict line.

    PYTHONPATH=. python benchmarks/camera_variants.py --reference results/quick \\
        --variants results/quick-lens --cameras cam12-aberrated,cam12-flare,cam12-hdr \\
        --conditions day,night --out docs/data/camera-variants.csv

``--reference`` and ``--variants`` are sweep folders on the same collection; the reference
camera is cam12 (``--against``). Prints the markdown table of docs/results.md
("cam12 and its variants").
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

COLUMNS = ["condition", "camera", "against", "od50_m", "od50_against_m", "delta_od50_m", "delta_od50_sd_m",
           "delta_od50_ci95_lo_m", "delta_od50_ci95_hi_m", "ap25", "ap25_against", "delta_ap25", "delta_ap25_sd",
           "delta_ap25_ci95_lo", "delta_ap25_ci95_hi", "resolved", "n_resamples", "verdict"]


def od50_text(side: dict) -> str:
    """One side of a ``compare`` result's OD50 in whole metres, or its bound when censored."""
    if side["censored"]:
        return f"{side['censored']} {side['bound_m']:g}"
    return "–" if side["od50_m"] is None else f"{side['od50_m']:.0f}"


def delta_od50_text(result: dict) -> str:
    """ΔOD50 ± SD [95 %] of a ``compare`` result, or "censored" where it is not measured."""
    od = result["delta_od50"]
    if od["delta_m"] is None:
        return "censored"
    return f"{od['delta_m']:+.0f} ± {od['sd_m']:.0f} [{od['ci95_m'][0]:+.0f}, {od['ci95_m'][1]:+.0f}]"


def delta_od50_columns(result: dict) -> dict:
    """A ``compare`` result's ΔOD50, its SD and 95 % interval as the tables' four columns
    (None where either OD50 is censored)."""
    od = result["delta_od50"]
    return {"delta_od50_m": od["delta_m"], "delta_od50_sd_m": od["sd_m"],
            "delta_od50_ci95_lo_m": od["ci95_m"][0], "delta_od50_ci95_hi_m": od["ci95_m"][1]}


def called_distances(result: dict) -> str:
    """The distances where ``compare`` calls a difference in AP (interval excludes 0, backed
    by found cars), each with the sign of A − B: "75− 100−"."""
    return " ".join(f"{r['distance_m']:g}{'+' if r['delta_ap'] > 0 else '−'}"
                    for r in result["per_distance"] if r["resolved"])


def compare_variants(reference: Path, variants: Path, cameras: list[str], conditions: list[str], against: str,
                     n_resamples: int, seed: int) -> tuple[pd.DataFrame, list[str]]:
    """(table of :data:`COLUMNS`, markdown rows) for every camera × condition."""
    from benchmark.experiments.compare import compare_paths

    rows, lines = [], []
    for condition in conditions:
        for camera in cameras:
            result = compare_paths(variants, reference, cameras=[camera, against], condition=condition,
                                   n_resamples=n_resamples, seed=seed)
            at25 = next(r for r in result["per_distance"] if r["distance_m"] == 25.0)
            resolved = called_distances(result)
            rows.append({
                "condition": condition, "camera": camera, "against": against,
                "od50_m": result["a"]["od50_m"], "od50_against_m": result["b"]["od50_m"],
                **delta_od50_columns(result),
                "ap25": at25["ap_a"], "ap25_against": at25["ap_b"], "delta_ap25": at25["delta_ap"],
                "delta_ap25_sd": at25["sd"], "delta_ap25_ci95_lo": at25["ci95"][0], "delta_ap25_ci95_hi": at25["ci95"][1],
                "resolved": resolved,
                "n_resamples": result["n_resamples"], "verdict": result["verdict"],
            })
            lines.append(f"| {condition} | {camera} | {od50_text(result['a'])} | {od50_text(result['b'])} | "
                         f"{delta_od50_text(result)} | "
                         f"{at25['ap_a']:.2f} | {at25['ap_b']:.2f} | {at25['delta_ap']:+.2f} ± {at25['sd']:.2f} "
                         f"[{at25['ci95'][0]:+.2f}, {at25['ci95'][1]:+.2f}] | {resolved or 'none'} |")
    return pd.DataFrame(rows, columns=COLUMNS), lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", required=True, type=Path, help="sweep folder holding the reference camera's runs")
    parser.add_argument("--variants", required=True, type=Path, help="sweep folder holding the variants' runs")
    parser.add_argument("--cameras", required=True, help="comma list of the variants' camera names")
    parser.add_argument("--conditions", default="day,night")
    parser.add_argument("--against", default="cam12")
    parser.add_argument("--resamples", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, help="CSV of the table")
    args = parser.parse_args()
    table, lines = compare_variants(args.reference, args.variants, args.cameras.split(","), args.conditions.split(","),
                                    args.against, args.resamples, args.seed)
    if args.out:
        table.to_csv(args.out, index=False, float_format="%.4f")
    print(f"| condition | camera | OD50 (m) | {args.against} OD50 (m) | ΔOD50 ± SD [95 %] (m) | AP 25 m | "
          f"{args.against} AP 25 m | ΔAP 25 m ± SD [95 %] | ΔAP called at (m) |")
    print("|---|---|---|---|---|---|---|---|---|")
    print("\n".join(lines))
    for row in table.itertuples():
        print(f"- {row.condition}, {row.camera}: {row.verdict}")


if __name__ == "__main__":
    main()
