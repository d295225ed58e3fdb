"""`metricscenes generate` on each backend: 1 worker, N worker processes, a dask LocalCluster.

Renders a manifest (default smoke) into fresh folders, once per backend and repeat, each in
its own `metricscenes generate --json` process (so every backend pays its own imports and
worker start-up), checks that every run wrote the same manifest.resolved.yaml and
groundtruth.json bytes as the 1-worker baseline, and prints wall-clock seconds and the
ratio to that baseline (measured in the same run, since these machines are noisy).

    python benchmarks/timing/bench_backends.py [manifests/smoke.yaml] [--workers 2] [--repeat 1]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def timed_generate(manifest: str, out: Path, options: list[str]) -> tuple[float, float, float]:
    """Seconds of one run: the process's wall clock, what `generate` reports (its render,
    worker start-up included) and the sum of its units' own times (``progress/*.json``)."""
    started = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "metricscenes.cli", "generate", "--manifest", manifest,
                           "--out", str(out), "--json", *options], capture_output=True, text=True)
    wall = time.perf_counter() - started
    if proc.returncode != 0:
        sys.exit(f"generate {' '.join(options)} failed: {proc.stderr.strip().splitlines()[-1:]}")
    units = sum(json.loads(p.read_text())["seconds"] for p in (out / "progress").glob("*.json"))
    return wall, json.loads(proc.stdout.strip().splitlines()[-1])["seconds"], units


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("manifest", nargs="?", default="manifests/smoke.yaml")
    parser.add_argument("--workers", type=int, default=2, help="processes of the pool and of the LocalCluster")
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    backends = {
        "1 worker": ["--workers", "1"],
        f"{args.workers} workers (process pool)": ["--workers", str(args.workers)],
        f"--scheduler local, {args.workers} workers": ["--scheduler", "local", "--workers", str(args.workers)],
    }
    print(f"manifest {args.manifest}, {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f} at the start")
    times: dict[str, list[tuple[float, float, float]]] = {name: [] for name in backends}
    with tempfile.TemporaryDirectory(prefix="bench-backends-") as tmp:
        reference = None
        for i in range(args.repeat):
            for j, (name, options) in enumerate(backends.items()):  # interleaved: load drifts hit all alike
                out = Path(tmp) / f"r{i}-b{j}"
                times[name].append(timed_generate(args.manifest, out, options))
                outputs = [(out / f).read_bytes() for f in ("manifest.resolved.yaml", "groundtruth.json")]
                reference = reference or outputs
                if outputs != reference:
                    sys.exit(f"{name}: manifest.resolved.yaml or groundtruth.json differ from the 1-worker run's")
    print(f"load {os.getloadavg()[0]:.1f} at the end; every backend wrote the same bytes")
    baseline = statistics.median(run[0] for run in times["1 worker"])
    print(f"{'backend':<36} {'wall s':>7} {'render s':>9} {'units s':>8} {'baseline / wall':>16}")
    for name, runs in times.items():
        wall, render, units = (statistics.median(column) for column in zip(*runs))
        print(f"{name:<36} {wall:7.1f} {render:9.1f} {units:8.1f} {baseline / wall:15.2f}x")


if __name__ == "__main__":
    main()
