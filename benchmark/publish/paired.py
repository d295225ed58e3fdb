"""A ``benchmark compare`` result (:func:`benchmark.experiments.compare.compare_paths`) as the
cells and columns of the paired tables: MTF50 groups, camera variants, backends."""

from __future__ import annotations


def od50_text(side: dict) -> str:
    """One side of a ``compare`` result's OD50 in whole metres, or its bound when censored."""
    if side["censored"]:
        return f"{side['censored']} {side['bound_m']:g}"
    return "–" if side["od50_m"] is None else f"{side['od50_m']:.0f}"


def delta_od50_text(result: dict) -> str:
    """ΔOD50 ± SD [95 %] of a ``compare`` result, or "censored" where it is not measured."""
    od = result["delta_od50"]
    if od["delta_m"] is None:
        return "censored"
    return f"{od['delta_m']:+.0f} ± {od['sd_m']:.0f} [{od['ci95_m'][0]:+.0f}, {od['ci95_m'][1]:+.0f}]"


def delta_od50_columns(result: dict) -> dict:
    """A ``compare`` result's ΔOD50, its SD and 95 % interval as the tables' four columns
    (None where either OD50 is censored)."""
    od = result["delta_od50"]
    return {"delta_od50_m": od["delta_m"], "delta_od50_sd_m": od["sd_m"],
            "delta_od50_ci95_lo_m": od["ci95_m"][0], "delta_od50_ci95_hi_m": od["ci95_m"][1]}


def called_distances(result: dict) -> str:
    """The distances where ``compare`` calls a difference in AP (interval excludes 0, backed
    by found cars), each with the sign of A − B: "75− 100−"."""
    return " ".join(f"{r['distance_m']:g}{'+' if r['delta_ap'] > 0 else '−'}"
                    for r in result["per_distance"] if r["resolved"])
