"""The same collection rendered by two backends (a CUDA GPU's and a CPU's), scored by the same
sweep: does either give other scores than the other, beyond their bootstrap SD?
(docs/data/backend-scores.csv; ``benchmark publish backend-scores``.)

Both collections hold the same scenes (the same manifest and seeds), so each camera's two runs
are paired scene by scene: ``benchmark compare`` resamples the environments for both at once
(each camera against itself). Beside the paired ΔOD50 the table gives each run's own bootstrap
OD50 SD, the scale a reader of one collection sees. Where only some of a sweep's runs finished
on one side, the cameras both hold are compared. The markdown is docs/performance.md's "On a GPU".
"""

from __future__ import annotations

from pathlib import Path

from benchmark.publish.paired import called_distances, delta_od50_columns, delta_od50_text, od50_text

HEADER = ("| condition | camera | OD50 GPU (m) | OD50 CPU (m) | own SD GPU / CPU (m) | ΔOD50 GPU − CPU ± SD [95 %] (m) | "
          "largest \\|ΔAP\\| | ΔAP called at (m) |\n|---|---|---|---|---|---|---|---|")


def finished_cameras(sweep: Path, condition: str) -> set[str]:
    """Cameras whose run under ``condition`` finished in ``sweep`` (its results.json written last)."""
    suffix = f"-{condition}"
    return {p.parent.name[: -len(suffix)] for p in (sweep / "runs").glob(f"*{suffix}/results.json")}


def compare_backends(gpu: Path, cpu: Path, condition: str, n_resamples: int, seed: int) -> tuple[list[dict], list[str]]:
    """(table rows, markdown rows) for every camera whose run finished on both sides."""
    from benchmark.experiments.compare import compare_paths
    from benchmark.experiments.sweep import run_od50

    rows, lines = [], []
    for camera in sorted(finished_cameras(cpu, condition) & finished_cameras(gpu, condition)):
        result = compare_paths(gpu, cpu, cameras=[camera], condition=condition, n_resamples=n_resamples, seed=seed)
        own = [run_od50(folder / "runs" / f"{camera}-{condition}", n_resamples=n_resamples, seed=seed).sd_m
               for folder in (gpu, cpu)]  # each run's own bootstrap (cached in its od50.json)
        largest, called = max(abs(r["delta_ap"]) for r in result["per_distance"]), called_distances(result)
        rows.append({"condition": condition, "camera": camera, "od50_gpu_m": result["a"]["od50_m"],
                     "od50_cpu_m": result["b"]["od50_m"], "od50_sd_gpu_m": own[0], "od50_sd_cpu_m": own[1],
                     **delta_od50_columns(result),
                     "largest_abs_delta_ap": largest, "resolved": called,
                     "n_environments": result["n_environments"], "n_resamples": result["n_resamples"]})
        lines.append(f"| {condition} | {camera} | {od50_text(result['a'])} | {od50_text(result['b'])} | "
                     f"{own[0]:.0f} / {own[1]:.0f} | {delta_od50_text(result)} | {largest:.3f} | "
                     f"{called or 'none'} |")
    return rows, lines
