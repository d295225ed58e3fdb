"""Intervals that hold together for the differences one comparison can call, and one figure's
interval widened for few environments.

``benchmark compare`` calls a difference where *any* of its intervals excludes 0: ΔAP at each
distance, and the headline (ΔOD50, or the ΔAP range where OD50 is censored). Seven 95 %
percentile intervals read one by one called a difference between a camera and itself,
reseeded, in 39 of 66 pairs on quick (docs/scoring.md, "Verdicts under a reseed"). Two
things made them too narrow:

1. **Many intervals.** Each holds its value 95 % of the time; all seven at once, far less.
   Each member's level is raised to 1 − α/m (Bonferroni, m members), which holds the family
   at 1 − α whatever the members' correlation.
2. **Few environments.** A bootstrap over n environments underestimates the variance of a
   mean by (n − 1)/n, and a normal quantile ignores that the SD is itself estimated from n
   values: the quantile is Student's t with n − 1 degrees of freedom and the SD is scaled
   by √(n/(n − 1)).

So each half-width is ``t_{n−1}(1 − α/(2m)) · √(n/(n − 1)) · s`` with ``s`` the member's
bootstrap SD (:func:`family_multiplier`: 3.65 for seven members on 10 environments, 2.84 on
50, against 1.96 for one normal interval). Nothing in it is tuned: it follows from n, m and
the level. A sup-t band from the bootstrap's own maximum (narrower where members correlate)
held seven normal members of correlation 0.5 in 350 of 400 trials (88 %) on 10 environments,
in the simulation of tests/test_scoring_simultaneous.py, where Bonferroni's t holds 94–97 %.

ΔOD50 takes the headline's place (``point ± multiplier · s``) where every resample is finite;
where AP never falls to 0.5 in some resample (ΔOD50 infinite there) it keeps its percentile
interval, stretched about its point by ``multiplier / z(1 − α/2)``
(:meth:`FamilyIntervals.stretch`): an infinite end stays infinite.

One run's OD50 and AP range (:func:`benchmark.scoring.bootstrap_od50`) are a family of one:
their percentile intervals are stretched by :func:`few_environments_scale`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats


def family_multiplier(n_environments: int, members: int, confidence_level: float = 0.95) -> float:
    """t_{n−1}(1 − α/(2m)) · √(n/(n − 1)): what a member's bootstrap SD is multiplied by for
    ``members`` intervals over ``n_environments`` to hold together at ``confidence_level``
    (inf below two environments)."""
    n, m = int(n_environments), int(members)
    if m < 1:
        raise ValueError(f"a family needs one or more members, got {m}")
    if n < 2:
        return math.inf
    alpha = 1.0 - confidence_level
    return float(stats.t.ppf(1.0 - alpha / (2 * m), n - 1)) * math.sqrt(n / (n - 1))


def few_environments_scale(n_environments: int, confidence_level: float = 0.95) -> float:
    """How much wider than its percentile interval one figure's interval is on ``n_environments``
    (a family of one): t_{n−1}(q) · √(n/(n − 1)) / z(q), 1.22 on 10 environments, 1.04 on 50."""
    return family_multiplier(n_environments, 1, confidence_level) / float(stats.norm.ppf(0.5 * (1.0 + confidence_level)))


def stretch(point: float, lo: float, hi: float, scale: float, floor: float = -math.inf) -> tuple[float, float]:
    """[lo, hi], which holds ``point``, widened about it by ``scale``, its lower end no lower than
    ``floor`` (a distance's 0; an infinite end stays infinite, NaN stays NaN)."""
    low = point - (point - lo) * scale
    return float(max(low, floor) if low == low else low), float(point + (hi - point) * scale)


@dataclass(frozen=True)
class FamilyIntervals:
    """Half-widths of a family's intervals (``point ± half_width``), held together at the level."""

    half_widths: np.ndarray  # (members,) ≥ 0; 0 where a member's resamples do not vary, NaN without two finite
    sd: np.ndarray  # (members,) bootstrap SD (ddof 1) of each member's finite resamples
    multiplier: float  # family_multiplier(n_environments, members, level)
    normal_quantile: float  # z(1 − α/2): what the multiplier replaces in a single normal interval

    def interval(self, j: int, point: float) -> tuple[float, float]:
        return float(point - self.half_widths[j]), float(point + self.half_widths[j])

    def stretch(self, point: float, lo: float, hi: float) -> tuple[float, float]:
        """A percentile interval [lo, hi] that holds ``point``, widened about it as the family
        widens a normal interval (an infinite end stays infinite)."""
        return stretch(point, lo, hi, self.multiplier / self.normal_quantile)


def family_intervals(points: np.ndarray, resampled: np.ndarray, n_environments: int,
                     confidence_level: float = 0.95) -> FamilyIntervals:
    """Intervals of ``points`` (members,) from their bootstrap ``resampled`` (resamples,
    members) that hold together. A member's SD is over its finite resamples (an AP is NaN in a
    resample without a counted car); with fewer than two its SD and half-width are NaN, and its
    interval [NaN, NaN] excludes nothing."""
    points = np.asarray(points, dtype=np.float64)
    resampled = np.asarray(resampled, dtype=np.float64)
    if resampled.ndim != 2 or resampled.shape[1] != points.size:
        raise ValueError(f"resampled must be (resamples, {points.size}), got {resampled.shape}")
    sd = np.full(points.size, np.nan)
    for j in range(points.size):
        column = resampled[:, j][np.isfinite(resampled[:, j])]
        if column.size > 1:
            sd[j] = np.std(column, ddof=1)
    multiplier = family_multiplier(n_environments, points.size, confidence_level)
    return FamilyIntervals(half_widths=multiplier * sd, sd=sd, multiplier=multiplier,
                           normal_quantile=float(stats.norm.ppf(0.5 * (1.0 + confidence_level))))
