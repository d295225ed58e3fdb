"""AP range: the area under AP vs distance, in metres — a detection range defined for every camera.

OD50 is censored where AP does not cross 0.5 inside the measured distances ("> 200 m",
"< 25 m"); the AP range is not. It is

    ∫₀^{d_max} AP(d) dd,

AP held at its nearest measured value from 0 to the nearest distance d_min and linear
(trapezoid) between measured distances, up to the farthest d_max. A camera that finds every
car (AP 1) up to D and none beyond scores about D (within the spacing of the distances), so it
reads like OD50 and is bounded by d_max; a camera that sees nothing scores 0. NaN AP points
(distances without ground truth) are dropped, as for OD50. docs/scoring.md, "AP range".
"""

from __future__ import annotations

import numpy as np


def ap_range(distances_m, ap) -> float:
    """Area under AP vs distance in metres (see the module docstring); one finite point or more."""
    d = np.asarray(distances_m, dtype=np.float64).ravel()
    a = np.asarray(ap, dtype=np.float64).ravel()
    if d.shape != a.shape:
        raise ValueError(f"distances_m and ap must have the same length, got {d.size} and {a.size}")
    ok = np.isfinite(a) & np.isfinite(d)
    d, a = d[ok], a[ok]
    if d.size == 0:
        raise ValueError("ap_range needs AP at one distance or more, got none finite")
    if np.any(d < 0):
        raise ValueError(f"distances_m must be >= 0, got {d.min():g}")
    order = np.argsort(d, kind="stable")
    d, a = d[order], a[order]
    if np.any(np.diff(d) == 0):
        raise ValueError(f"distances_m must be distinct, got {d.tolist()}")
    # 0 to d_min at the nearest AP (a car nearer than measured is found at least as well), then trapezoids
    return float(a[0] * d[0] + np.sum(0.5 * (a[1:] + a[:-1]) * np.diff(d)))
