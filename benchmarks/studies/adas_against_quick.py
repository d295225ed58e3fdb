"""The paper's six distances on `adas-quick` against `quick`: the same environments, cars, poses
and road up to 395 m (the adas road is the default road and more: docs/scenes.md, "Distances
beyond 200 m"), so a narrow camera's AP at 25-200 m should differ between the two only as much as
a rerender of the same scenes does (on another machine kind: within about 0.015 per distance,
docs/performance.md). Prints, per condition, each camera's largest |ΔAP| over the six distances
and the mean ΔAP (adas − quick).

    PYTHONPATH=. python benchmarks/studies/adas_against_quick.py docs/data/sweep.csv docs/data/adas-quick/sweep.csv
"""

from __future__ import annotations

import sys

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
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
