"""A synthetic sweep folder (runs/<camera>-<condition>/ and sweep.json), for tests of what reads
sweeps: each run from :func:`synthetic_leaderboard.write_synthetic_run`, on one manifest, so any two
runs pair scene by scene as ``benchmark compare`` needs."""

from __future__ import annotations

from pathlib import Path


def write_synthetic_sweep(out: str | Path, cameras: list[tuple], conditions=("day",), *, manifest,
                          n_environments: int = 6, seed: int = 0) -> Path:
    """``cameras``: (CameraSpec, half range in metres: AP ≈ 0.5 there) pairs; each camera × condition
    gets its own detections (seeded by its position), the same scenes for all."""
    from benchmark.result_files import (SWEEP_FORMAT, CollectionRecord, DetectorRecord, SweepRecord, SweepRun,
                                        write_sweep_record)
    from synthetic_leaderboard import write_synthetic_run

    out = Path(out)
    runs = []
    for k, (camera, half_range_m) in enumerate(cameras):
        for j, condition in enumerate(conditions):
            path = f"runs/{camera.name}-{condition}"
            results = write_synthetic_run(out / path, camera, condition, manifest=manifest, n_environments=n_environments,
                                          half_range_m=half_range_m, seed=seed + 100 * k + j)
            runs.append(SweepRun(camera=camera.name, condition=condition, path=path, reused=False))
    detector = results["detector"]
    record = SweepRecord(format=SWEEP_FORMAT,
                         collection=CollectionRecord(name=manifest.name, manifest_sha256=manifest.sha256()),
                         detector=DetectorRecord(name=detector["name"], sha256=detector["sha256"], input_size="multiscale"),
                         seed=seed, n_resamples=20, mtf_source="analytic", scoring_backend="faster-coco-eval",
                         cameras=[camera.name for camera, _ in cameras], conditions=list(conditions), runs=runs,
                         table=[], od50=[])
    write_sweep_record(out / "sweep.json", record)
    return out
