"""Do a camera run's bytes depend on the instruction set the numeric libraries use?

    PYTHONPATH=. python benchmarks/studies/bytes_across_isa.py --collection collections/smoke [--camera cam12]

Runs ``benchmark run`` (day) once per setting, each in a fresh process, and compares every
camera image and ``detections.json`` by sha256 with the first setting's, and AP per distance:

- ``pinned``: as the commands run (metricscenes.numeric_pins: OpenBLAS's Haswell kernels,
  numpy without its AVX-512 kernels);
- ``numpy-sse``: numpy also without its AVX2/FMA kernels (``NPY_DISABLE_CPU_FEATURES``
  += ``X86_V3``), i.e. another numpy instruction set;
- ``blas-sandybridge``, ``blas-prescott``: OpenBLAS's AVX (no FMA) and SSE3 kernels forced
  (``OPENBLAS_CORETYPE``): what the pin protects against — the kernels an AVX-512 machine's
  OpenBLAS would take instead of Haswell's cannot be produced on an AVX2 machine, these can.

The renderer (Embree) and onnxruntime pick their kernels themselves, so the settings here
reach the camera stage only; the collection is the same for all.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import tempfile
from pathlib import Path

SETTINGS = {
    "pinned": {},
    "numpy-sse": {"NPY_DISABLE_CPU_FEATURES": "X86_V3 X86_V4 AVX512_ICL AVX512_SPR"},
    "blas-sandybridge": {"OPENBLAS_CORETYPE": "Sandybridge"},
    "blas-prescott": {"OPENBLAS_CORETYPE": "Prescott"},
}


def run(collection: Path, camera: str, out: Path, extra_env: dict[str, str]) -> dict:
    env = dict(os.environ, **extra_env)
    subprocess.run(["benchmark", "run", "--camera", camera, "--collection", str(collection), "--out", str(out)],
                   env=env, check=True, stdout=subprocess.DEVNULL)
    files = sorted(p for p in out.rglob("*") if p.suffix == ".png") + [out / "detections.json"]
    results = json.loads((out / "results.json").read_text())
    return {"sha256": {str(p.relative_to(out)): hashlib.sha256(p.read_bytes()).hexdigest() for p in files},
            "ap": [round(r["ap"], 4) for r in results["per_distance"]],
            "blas": results.get("numerics", {}).get("openblas_coretype")}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--collection", type=Path, required=True)
    parser.add_argument("--camera", default="cam12")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        runs = {name: run(args.collection, args.camera, Path(tmp) / name, env) for name, env in SETTINGS.items()}
    base = runs["pinned"]
    print(f"{'setting':18s} {'OpenBLAS':12s} {'files differing':>16s}  detections  AP per distance")
    for name, r in runs.items():
        differ = sum(r["sha256"][k] != v for k, v in base["sha256"].items())
        same_det = r["sha256"]["detections.json"] == base["sha256"]["detections.json"]
        print(f"{name:18s} {','.join(r['blas'] or []):12s} {differ:>10d} of {len(base['sha256']):<3d}  "
              f"{'same' if same_det else 'DIFFER':10s}  {r['ap']}")


if __name__ == "__main__":
    main()
