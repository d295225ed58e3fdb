"""Acceptance checks of a sweep against the paper's qualitative findings.

Liu et al., EI 2023 report, for the 13 cameras:

1. AP falls with distance (Fig. 5): here, in daylight, Spearman's rho of AP against
   distance is <= -0.8 for every camera;
2. night is harder than day (Fig. 5, right): night AP below day AP at every distance
   for every camera. Where both are 0 the camera sees nothing in either light; such
   pairs cannot be "below" and do not count against the finding (they are counted in
   ``night_day_ties_at_zero``);
3. OD50 rises with MTF50 in daylight (Fig. 7A): Spearman's rho of OD50 against MTF50
   across cameras >= 0.6 (infinite OD50s rank above every finite one).

:func:`paper_findings` returns each verdict (bool) with the statistic behind it (float);
:func:`night_findings` does the same for night and dusk criteria on the unlit regulation road
(``night_regulation``), :func:`paper_night_findings` for the paper's own night, and
:func:`od50_sd_shrinks` compares two collections' bootstrap SDs.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

AP_DISTANCE_RHO_MAX = -0.8
OD50_MTF50_RHO_MIN = 0.6


def _spearman(x, y) -> float:
    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = ~(np.isnan(x) | np.isnan(y))
    if ok.sum() < 3 or np.unique(x[ok]).size < 2 or np.unique(y[ok]).size < 2:
        return float("nan")  # undefined: a constant series or too few points
    return float(stats.spearmanr(x[ok], y[ok]).statistic)


def _ap_by_camera(table: pd.DataFrame, condition: str) -> pd.DataFrame:
    """AP of one condition, camera × distance (ValueError, one line, if the table has none)."""
    rows = table[table["condition"] == condition]
    if rows.empty:
        raise ValueError(f"table has no {condition!r} rows (conditions: {sorted(set(table['condition']))})")
    return rows.pivot_table(index="camera", columns="distance_m", values="ap")


def ap_distance_rho(table: pd.DataFrame, condition: str = "day") -> pd.Series:
    """Spearman's rho of AP against distance, per camera, under ``condition`` (NaN where
    AP is constant or fewer than three distances have AP)."""
    rows = table[table["condition"] == condition]
    return rows.groupby("camera").apply(lambda part: _spearman(part["distance_m"], part["ap"]), include_groups=False)


def paper_findings(table: pd.DataFrame, od50: pd.DataFrame, *, day: str = "day", night: str = "night") -> dict[str, bool | float]:
    """Check the three findings on a sweep's tables (``sweep.csv``, ``od50.csv``).

    Returns:
        ``ap_falls_with_distance`` (bool) and ``ap_distance_rho_worst`` (the largest
        per-camera rho in daylight; NaN rho counts as failing), ``night_below_day`` (bool),
        ``night_minus_day_ap_max`` (largest night - day AP over cameras × distances where
        not both are 0) and ``night_day_ties_at_zero`` (count), ``od50_rises_with_mtf50``
        (bool) and ``od50_mtf50_rho`` (daylight, across cameras).
    """
    for name, frame, cols in (("table", table, ("camera", "condition", "distance_m", "ap")),
                              ("od50", od50, ("camera", "condition", "mtf50_cy_per_mm", "od50_m"))):
        missing = [c for c in cols if c not in frame.columns]
        if missing:
            raise ValueError(f"{name} lacks column(s) {missing}")
    for condition in (day, night):
        if condition not in set(table["condition"]):
            raise ValueError(f"table has no {condition!r} rows (conditions: {sorted(set(table['condition']))})")

    day_rows = table[table["condition"] == day]
    rhos = ap_distance_rho(table, day).to_numpy()
    worst = float(np.max(rhos)) if not np.any(np.isnan(rhos)) else float("nan")

    paired = day_rows.merge(table[table["condition"] == night], on=["camera", "distance_m"], suffixes=("_day", "_night"))
    if paired.empty:
        raise ValueError(f"no camera × distance has both {day!r} and {night!r} AP")
    both_zero = (paired["ap_day"] == 0) & (paired["ap_night"] == 0)
    diff = (paired["ap_night"] - paired["ap_day"])[~both_zero]
    diff_max = float(diff.max()) if len(diff) else float("nan")

    od_day = od50[od50["condition"] == day]
    rho_od = _spearman(od_day["mtf50_cy_per_mm"], od_day["od50_m"].astype(float).replace(np.inf, 1e12))
    return {
        "ap_falls_with_distance": bool(worst <= AP_DISTANCE_RHO_MAX),
        "ap_distance_rho_worst": worst,
        "night_below_day": bool(len(diff) > 0 and diff_max < 0),
        "night_minus_day_ap_max": diff_max,
        "night_day_ties_at_zero": int(both_zero.sum()),
        "od50_rises_with_mtf50": bool(rho_od >= OD50_MTF50_RHO_MIN),
        "od50_mtf50_rho": rho_od,
    }


NIGHT_AP_25M_MIN = 0.2
NIGHT_OD50_INSIDE_MIN_CAMERAS = 10


def night_findings(table: pd.DataFrame, od50: pd.DataFrame, *, day: str = "day", dusk: str = "dusk",
                   night: str = "night", near_m: float = 25.0,
                   measured_range_m: tuple[float, float] = (25.0, 200.0)) -> dict[str, bool | float | int]:
    """Night and dusk criteria on a sweep's tables (every camera of the table):

    - ``night_ap_near_useful``: night AP at ``near_m`` >= 0.2 for every camera
      (``night_ap_near_min``: the smallest);
    - ``night_below_day_everywhere``: night AP < day AP at every distance, every camera
      (ties at zero count against it here: a blind camera is not "below");
    - ``night_ap_falls_with_distance``: Spearman rho of night AP vs distance <= -0.8 for
      every camera (``night_rho_worst``; a constant AP gives NaN and fails);
    - ``night_od50_inside``: night OD50 inside ``measured_range_m`` for >= 10 cameras
      (``night_od50_inside_cameras``: how many);
    - ``dusk_between_at_near``: night < dusk <= day AP at ``near_m`` for every camera
      (dusk may match day; ``dusk_between_cameras``: how many).
    """
    ap_day, ap_dusk, ap_night = (_ap_by_camera(table, c) for c in (day, dusk, night))
    rhos = ap_distance_rho(table, night).to_numpy()
    worst = float(np.max(rhos)) if not np.any(np.isnan(rhos)) else float("nan")
    od_night = od50[od50["condition"] == night]["od50_m"].astype(float)
    inside = int(((od_night >= measured_range_m[0]) & (od_night <= measured_range_m[1])).sum())
    near_night, near_dusk, near_day = ap_night[near_m], ap_dusk[near_m], ap_day[near_m]
    between = (near_night < near_dusk) & (near_dusk <= near_day)
    return {
        "night_ap_near_useful": bool((near_night >= NIGHT_AP_25M_MIN).all()),
        "night_ap_near_min": float(near_night.min()),
        "night_below_day_everywhere": bool((ap_night < ap_day).to_numpy().all()),
        "night_ap_falls_with_distance": bool(worst <= AP_DISTANCE_RHO_MAX),
        "night_rho_worst": worst,
        "night_od50_inside": inside >= NIGHT_OD50_INSIDE_MIN_CAMERAS,
        "night_od50_inside_cameras": inside,
        "dusk_between_at_near": bool(between.all()),
        "dusk_between_cameras": int(between.sum()),
    }


PAPER_NIGHT_AP_25M_MIN = 0.15
PAPER_NIGHT_USEFUL_MIN_CAMERAS = 10


def paper_night_findings(table: pd.DataFrame, od50: pd.DataFrame, *, day: str = "day", night: str = "night",
                         near_m: float = 25.0, seen_ap: float = 0.1) -> dict[str, bool | float | int]:
    """The paper's night (Liu et al. 2023: 0.1-1 lux mean image-plane illuminance, every lamp
    on), judged on every camera of the table:

    - ``night_ap_near_useful``: night AP at ``near_m`` >= 0.15 for at least 10 cameras
      (``night_ap_near_useful_cameras``: how many);
    - ``night_below_day_everywhere``: night AP < day AP at every distance, every camera
      (a tie at zero counts against it);
    - ``night_below_day_where_seen``: the same, over the cells (camera × distance) where day or
      night AP reaches ``seen_ap`` (``night_day_seen_cells``: how many), so that a few low
      boxes on a far car both lights barely see do not decide it;
    - ``night_od50_reported``: every night OD50 inside the measured distances or censored
      (a bound, "> 200" or "< 25"), none infinite or extrapolated;
    - ``night_od50_rises_with_mtf50``: Spearman rho of night OD50 against MTF50 > 0
      (``night_od50_mtf50_rho``; a censored OD50 ranks at its bound).
    """
    from benchmark.experiments.sweep import with_censoring

    ap_day, ap_night = _ap_by_camera(table, day), _ap_by_camera(table, night)
    rows = table[table["condition"] == night]
    od_night = with_censoring(od50[od50["condition"] == night], rows)
    lo, hi = float(rows["distance_m"].min()), float(rows["distance_m"].max())
    values = od_night["od50_m"].astype(float)
    censored = od_night["censored"].astype(str).isin([">", "<"])
    reported = censored | ((values >= lo) & (values <= hi))
    ranked = np.where(censored, od_night["bound_m"].astype(float), values)
    useful = int((ap_night[near_m] >= PAPER_NIGHT_AP_25M_MIN).sum())
    below = (ap_night < ap_day).to_numpy()
    seen = ((ap_day >= seen_ap) | (ap_night >= seen_ap)).to_numpy()
    rho = _spearman(od_night["mtf50_cy_per_mm"], pd.Series(ranked).replace(np.inf, 1e12))
    return {
        "night_ap_near_useful": useful >= PAPER_NIGHT_USEFUL_MIN_CAMERAS,
        "night_ap_near_useful_cameras": useful,
        "night_below_day_everywhere": bool(below.all()),
        "night_below_day_where_seen": bool(below[seen].all()),
        "night_day_seen_cells": int(seen.sum()),
        "night_od50_reported": bool(reported.all()),
        "night_od50_rises_with_mtf50": bool(rho > 0),
        "night_od50_mtf50_rho": rho,
    }


def od50_sd_shrinks(od50: pd.DataFrame, smaller_collection_od50: pd.DataFrame, *, condition: str = "day") -> dict:
    """A larger collection's bootstrap OD50 SDs against a smaller one's (metric-300's day SDs
    below quick's for at least 11 of 13 cameras: tests/test_metric300_findings.py), camera by
    camera under ``condition``.
    Cameras whose OD50 is censored on either side (its SD measures the edge of the distances,
    not the spread) are counted apart, not compared.

    Returns ``smaller`` (cameras whose SD is below the smaller collection's), ``compared``
    and ``censored`` (counts), and ``ratio_median`` (median SD ratio, large / small, NaN when
    none is compared)."""
    def sds(table):
        part = table[table["condition"] == condition].set_index("camera")
        if part.empty:
            raise ValueError(f"od50 table has no {condition!r} rows")
        censored = part["censored"].fillna("").astype(str).str.len() > 0 if "censored" in part else pd.Series(False, part.index)
        return part["sd_m"].where(~censored & np.isfinite(part["od50_m"]))

    large, small = sds(od50), sds(smaller_collection_od50)
    cameras = large.index.intersection(small.index)
    both = large[cameras].notna() & small[cameras].notna()
    ratio = (large[cameras] / small[cameras])[both]
    return {"smaller": int((ratio < 1).sum()), "compared": int(both.sum()), "censored": int((~both).sum()),
            "ratio_median": float(ratio.median()) if both.any() else float("nan")}
