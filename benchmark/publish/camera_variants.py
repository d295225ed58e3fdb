"""cam12 against cameras that are cam12 but for one part: what each part does to detection
(docs/data/camera-variants.csv; ``benchmark publish camera-variants``).

The paired bootstrap of ``benchmark compare`` (same environments resampled for both cameras)
between a variant's run and the reference camera's, per condition, as one table: OD50 of each,
ΔOD50 ± SD with its 95 % interval (None where either OD50 is censored), AP at 25 m of each,
ΔAP(25 m) ± SD with its interval, the distances where ``compare`` calls a difference in AP (+:
the variant's higher), and the verdict line. The markdown is docs/results.md's "cam12 and its
variants".
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from benchmark.publish.paired import called_distances, delta_od50_columns, delta_od50_text, od50_text

COLUMNS = ["condition", "camera", "against", "od50_m", "od50_against_m", "delta_od50_m", "delta_od50_sd_m",
           "delta_od50_ci95_lo_m", "delta_od50_ci95_hi_m", "ap25", "ap25_against", "delta_ap25", "delta_ap25_sd",
           "delta_ap25_ci95_lo", "delta_ap25_ci95_hi", "resolved", "n_resamples", "verdict"]


def compare_variants(reference: Path, variants: Path, cameras: list[str], conditions: list[str], against: str,
                     n_resamples: int, seed: int) -> tuple[pd.DataFrame, list[str]]:
    """(table of :data:`COLUMNS`, markdown rows) for every camera × condition; ``reference`` and
    ``variants`` are sweep folders on the same collection, ``against`` the reference camera."""
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


def report(table: pd.DataFrame, lines: list[str], against: str) -> str:
    """The markdown table, then each row's verdict."""
    return "\n".join([
        f"| condition | camera | OD50 (m) | {against} OD50 (m) | ΔOD50 ± SD [95 %] (m) | AP 25 m | "
        f"{against} AP 25 m | ΔAP 25 m ± SD [95 %] | ΔAP called at (m) |",
        "|---|---|---|---|---|---|---|---|---|",
        *lines,
        *(f"- {row.condition}, {row.camera}: {row.verdict}" for row in table.itertuples()),
    ])
