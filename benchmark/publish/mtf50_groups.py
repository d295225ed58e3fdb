"""Cameras of one MTF50 group: do they detect alike? (docs/data/mtf50-groups.csv; ``benchmark
publish mtf50-groups``.) Liu et al., EI 2023: "the object detection scores differed by as much as
three standard deviations when the MTF50 was equal".

The paper's 13 cameras fall into four published MTF50 groups (55, 75, 100 and 150 cy/mm;
``mtf50_group_cy_per_mm`` in their specs). For every pair in a group and every condition, the
paired bootstrap of ``benchmark compare`` (the same environments resampled for both): ΔOD50
± SD and its 95 % interval, |ΔOD50| / SD, and the distances where a difference in AP is
called. ΔOD50 is not measured where either OD50 is censored (outside the measured distances).
The markdown is docs/results.md's "Cameras of one MTF50 group".
"""

from __future__ import annotations

import itertools
from pathlib import Path

import pandas as pd

from benchmark.publish.paired import called_distances, delta_od50_columns, delta_od50_text, od50_text

COLUMNS = ["condition", "group_cy_per_mm", "camera_a", "camera_b", "od50_a_m", "od50_b_m", "delta_od50_m",
           "delta_od50_sd_m", "delta_od50_ci95_lo_m", "delta_od50_ci95_hi_m", "delta_over_sd", "resolved",
           "n_resamples"]


def group_pairs(cameras: list[str]) -> list[tuple[float, str, str]]:
    """(group, camera a, camera b) for every pair of cameras of one published MTF50 group."""
    from benchmark.camera import load_camera

    groups: dict[float, list[str]] = {}
    for name in cameras:
        group = load_camera(name).mtf50_group_cy_per_mm
        if group is not None:
            groups.setdefault(float(group), []).append(name)
    return [(g, a, b) for g in sorted(groups) for a, b in itertools.combinations(groups[g], 2)]


def compare_groups(sweep: Path, conditions: list[str], n_resamples: int, seed: int) -> tuple[pd.DataFrame, list[str]]:
    """(table of :data:`COLUMNS`, markdown rows) for every pair of the sweep's cameras in one group."""
    from benchmark.experiments.compare import compare_paths
    from benchmark.result_files import read_sweep_record

    cameras = read_sweep_record(sweep / "sweep.json").cameras
    rows, lines = [], []
    for condition in conditions:
        for group, a, b in group_pairs(cameras):
            result = compare_paths(sweep, sweep, cameras=[a, b], condition=condition, n_resamples=n_resamples, seed=seed)
            od, resolved = result["delta_od50"], called_distances(result)
            ratio = abs(od["delta_m"]) / od["sd_m"] if od["delta_m"] is not None and od["sd_m"] else None
            rows.append({"condition": condition, "group_cy_per_mm": group, "camera_a": a, "camera_b": b,
                         "od50_a_m": result["a"]["od50_m"], "od50_b_m": result["b"]["od50_m"],
                         **delta_od50_columns(result),
                         "delta_over_sd": ratio, "resolved": resolved, "n_resamples": result["n_resamples"]})
            lines.append(f"| {condition} | {group:g} | {a} – {b} | {od50_text(result['a'])} | {od50_text(result['b'])} | "
                         f"{delta_od50_text(result)} | "
                         f"{'–' if ratio is None else f'{ratio:.1f}'} | {resolved or 'none'} |")
    return pd.DataFrame(rows, columns=COLUMNS), lines


def report(table: pd.DataFrame, lines: list[str]) -> str:
    """The markdown table, then per condition how many measured pairs differ by more than 2 SD."""
    out = ["| condition | MTF50 group (cy/mm) | cameras A – B | OD50 A (m) | OD50 B (m) | ΔOD50 ± SD [95 %] (m) | "
           "\\|Δ\\| / SD | ΔAP called at (m) |",
           "|---|---|---|---|---|---|---|---|",
           *lines]
    measured = table.dropna(subset=["delta_over_sd"])
    for condition, part in measured.groupby("condition", sort=False):
        big = part[part["delta_over_sd"] > 2]
        out.append(f"- {condition}: {len(part)} pairs with both OD50s measured, {len(big)} differ by more than 2 SD"
                   + (f" (largest {part['delta_over_sd'].max():.1f} SD)" if len(part) else ""))
    return "\n".join(out)
