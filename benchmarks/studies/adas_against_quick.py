"""The paper's six distances on `adas-quick` against `quick`: the same environments, cars, poses
and road up to 395 m (the adas road is the default road and more: docs/scenes.md, "Distances
beyond 200 m"), so a narrow camera's AP at 25-200 m should differ between the two only as much as
a rerender of the same scenes does. The camera's noise is drawn per image id, and the ids differ
(eleven distances per environment against six), so each scene is also a reseed of quick's. Prints,
per condition, each camera's largest |ΔAP| over the six distances and the mean ΔAP (adas − quick);
then, for reseeded runs of one camera on quick (folders of ``benchmarks/studies/reseed_spread.py``:
one run per noise seed), the largest |ΔAP| of every pair of seeds: what a reseed alone moves.

    PYTHONPATH=. python benchmarks/studies/adas_against_quick.py QUICK_SWEEP/sweep.csv docs/data/adas-quick/sweep.csv \
        [RESEED_FOLDER ...]
"""

from __future__ import annotations

import itertools
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

PAPER_DISTANCES_M = (25.0, 50.0, 75.0, 100.0, 150.0, 200.0)


def compare(quick: pd.DataFrame, adas: pd.DataFrame) -> pd.DataFrame:
    """Per condition and camera: max |ΔAP| and mean ΔAP over the paper's distances (adas − quick)."""
    keys = ["camera", "condition", "distance_m"]
    both = quick[keys + ["ap"]].merge(adas[keys + ["ap"]], on=keys, suffixes=("_quick", "_adas"))
    both = both[both["distance_m"].isin(PAPER_DISTANCES_M)]
    both["delta"] = both["ap_adas"] - both["ap_quick"]
    return both.groupby(["condition", "camera"]).agg(max_abs_delta=("delta", lambda d: float(np.abs(d).max())),
                                                     mean_delta=("delta", "mean"), distances=("delta", "size"))


def main(argv: list[str]) -> int:
    quick, adas = (pd.read_csv(path) for path in argv[:2])
    table = compare(quick, adas)
    for condition, rows in table.groupby(level="condition"):
        worst = rows["max_abs_delta"].idxmax()[1]
        print(f"{condition}: {len(rows)} cameras; |ΔAP| at most {rows['max_abs_delta'].max():.3f} ({worst}), "
              f"median of the cameras' largest {rows['max_abs_delta'].median():.3f}; mean ΔAP "
              f"{rows['mean_delta'].mean():+.3f} (cameras from {rows['mean_delta'].min():+.3f} to "
              f"{rows['mean_delta'].max():+.3f})")
    for folder in argv[2:]:
        runs = [json.loads(p.read_text())["per_distance"] for p in sorted(Path(folder).glob("*/results.json"))]
        aps = [{r["distance_m"]: r["ap"] for r in run} for run in runs]
        largest = [max(abs(a[d] - b[d]) for d in a) for a, b in itertools.combinations(aps, 2)]
        print(f"{folder}: {len(runs)} seeds, {len(largest)} pairs; largest |ΔAP| of a pair: median "
              f"{np.median(largest):.3f}, at most {max(largest):.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
