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

from benchmark.scoring.od50 import finite_points


def ap_range(distances_m, ap) -> float:
    """Area under AP vs distance in metres (see the module docstring); one finite point or more."""
    d, a = finite_points(distances_m, ap, at_least=1, what="ap_range")
    if d[0] < 0:
        raise ValueError(f"distances_m must be >= 0, got {d[0]:g}")
    # 0 to d_min at the nearest AP (a car nearer than measured is found at least as well), then trapezoids
    return float(a[0] * d[0] + np.sum(0.5 * (a[1:] + a[:-1]) * np.diff(d)))
