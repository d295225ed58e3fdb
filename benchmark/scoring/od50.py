"""OD50: the distance (m) at which AP falls to 0.5 (Liu et al. 2023, "object detection distance").

Rules, applied to the points sorted by distance (NaN AP points dropped; at least two needed):

1. **Crossing.** The first *downward* crossing from the near end — the first pair of
   neighbours with AP(d_i) >= 0.5 > AP(d_{i+1}) — is interpolated linearly. A curve
   that crosses 0.5 more than once (e.g. 0.7, 0.4, 0.6, 0.3) counts its first downward
   crossing: OD50 is the range up to which detection is reliable, and a later recovery
   (noise, or a policy that favours mid distances) does not make the nearer gap reliable.
   An upward crossing (AP below 0.5 at the near end, above further out) is not a fall
   to 0.5 and is skipped.
2. **Ends above 0.5** (no downward crossing, last point >= 0.5): linear extrapolation
   beyond the far end from the last two points. If that line does not fall
   (flat or rising), AP never reaches 0.5 on it: OD50 = +inf.
3. **All below 0.5**: linear extrapolation below the near end from the first two points,
   clipped at 0 m. If that line does not fall (flat or rising), OD50 = 0 m: the camera
   does not reach AP 0.5 at any distance.

Rule 1 with rules 2-3 (plain linear extrapolation from the nearest two points)
reproduces the paper's values; the flat/rising cases are our additions so that OD50 is
always defined (inf or a number >= 0, never NaN) for bootstrapping.

**Censoring.** Rules 2 and 3 are extrapolations, kept only so that the bootstrap has a
number; they are not reported. :func:`od50_censoring` tells them apart, and tables, reports,
figures and the leaderboard show the bound instead: "> 200 m" (AP has not fallen to 0.5 at
the farthest measured distance: a lower bound) or "< 25 m" (AP is below 0.5 already at the
nearest: an upper bound). See :func:`format_od50`.
"""

from __future__ import annotations

import math

import numpy as np

AP_LEVEL = 0.5


def _line_at(d0: float, a0: float, d1: float, a1: float, level: float) -> float:
    return d0 + (level - a0) * (d1 - d0) / (a1 - a0)


def finite_points(distances_m, ap, *, at_least: int = 2, what: str = "od50") -> tuple[np.ndarray, np.ndarray]:
    """The (distance, AP) points with finite values, sorted by distance: ``at_least`` of them, distinct."""
    d = np.asarray(distances_m, dtype=np.float64).ravel()
    a = np.asarray(ap, dtype=np.float64).ravel()
    if d.shape != a.shape:
        raise ValueError(f"distances_m and ap must have the same length, got {d.size} and {a.size}")
    ok = np.isfinite(a) & np.isfinite(d)
    d, a = d[ok], a[ok]
    if d.size < at_least:
        count = {1: "one", 2: "two"}.get(at_least, str(at_least))
        raise ValueError(f"{what} needs AP at {count} or more distances, got {d.size} finite points")
    order = np.argsort(d, kind="stable")
    d, a = d[order], a[order]
    if np.any(np.diff(d) == 0):
        raise ValueError(f"distances_m must be distinct, got {d.tolist()}")
    return d, a


def od50(distances_m, ap, *, level: float = AP_LEVEL) -> float:
    """Distance in metres where AP crosses ``level`` (0.5); see the module docstring for the rules."""
    d, a = finite_points(distances_m, ap)
    down = np.nonzero((a[:-1] >= level) & (a[1:] < level))[0]
    if down.size:
        i = int(down[0])
        return float(_line_at(d[i], a[i], d[i + 1], a[i + 1], level))
    if a[-1] >= level:  # never falls below the level within the range: extrapolate beyond it
        if a[-1] >= a[-2]:
            return float("inf")
        return float(_line_at(d[-2], a[-2], d[-1], a[-1], level))
    # all points below the level: extrapolate below the near end
    if a[1] >= a[0]:
        return 0.0
    return float(max(0.0, _line_at(d[0], a[0], d[1], a[1], level)))


# --- censoring: OD50 outside the measured distances is a bound, not a number -------------------

CENSORED_ABOVE, CENSORED_BELOW, NOT_CENSORED = ">", "<", ""


def od50_censoring(distances_m, ap, *, level: float = AP_LEVEL) -> tuple[str, float | None]:
    """(``censored``, ``bound_m``) of the OD50 of these points (NaN AP points dropped).

    ``">"``, farthest distance: AP has not fallen to ``level`` within the measured distances
    (no downward crossing and the farthest point is at or above it; rule 2 above); the OD50 is
    a lower bound, reported as "> 200 m", never as the extrapolated number.
    ``"<"``, nearest distance: AP is below ``level`` at every measured distance (rule 3): an
    upper bound, "< 25 m". ``""`` and None: a crossing was measured (rule 1).
    """
    d, a = finite_points(distances_m, ap)
    if np.any((a[:-1] >= level) & (a[1:] < level)):
        return NOT_CENSORED, None
    if a[-1] >= level:
        return CENSORED_ABOVE, float(d[-1])
    return CENSORED_BELOW, float(d[0])


def od50_rank_value(od50_m, censored: str = "", bound_m: float | None = None, ap_at_bound: float | None = None, *,
                    ap_range_m: float | None = None) -> float:
    """The number an OD50 is ranked by, higher better (docs/leaderboard.md, "Censored OD50 and the rank rule").

    A measured OD50 ranks by its value. ``">"`` ranks above every measured one (a measured OD50
    is below the farthest distance) and ``"<"`` below every measured one (a measured OD50 is at
    least the nearest); within each, by the AP range ``ap_range_m`` (area under AP vs distance,
    :func:`benchmark.scoring.ap_range.ap_range`), squashed by s = x / (x + bound) into [0, 1) so it
    stays in its tier: ``bound_m + s`` for ">" (infinite with no bound), ``bound_m × s`` for "<".
    An extrapolated OD50 is never the key.

    ``ap_at_bound`` (AP at the bound, the rule before the AP range) is used only where
    ``ap_range_m`` is not given, for callers that still pass it; it breaks ties by one distance's AP.
    """
    if censored not in (CENSORED_ABOVE, CENSORED_BELOW):
        return float(od50_m)
    if censored == CENSORED_ABOVE and bound_m is None:
        return math.inf
    bound = float(bound_m)
    if ap_range_m is None:  # the older rule, AP at the bound
        return bound + float(ap_at_bound) if censored == CENSORED_ABOVE else bound * float(ap_at_bound)
    x = max(0.0, float(ap_range_m))
    squashed = x / (x + bound) if x + bound > 0 else 0.0
    return bound + squashed if censored == CENSORED_ABOVE else bound * squashed


def format_od50(od50_m, censored: str = "", bound_m: float | None = None, sd_m=None, *, unit: str = " m") -> str:
    """OD50 for people: "123.4 ± 5.6 m", or the bound when censored ("> 200 m", "< 25 m", no ±)."""
    if censored in (CENSORED_ABOVE, CENSORED_BELOW) and bound_m is not None and np.isfinite(bound_m):
        return f"{censored} {bound_m:g}{unit}"
    if od50_m is None or not np.isfinite(float(od50_m)):
        return "–" if od50_m is None or np.isnan(float(od50_m)) else "∞"
    text = f"{float(od50_m):.1f}"
    if sd_m is not None and np.isfinite(float(sd_m)):
        text += f" ± {float(sd_m):.1f}"
    return text + unit
