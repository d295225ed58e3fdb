"""benchmark.experiments.acceptance.paper_findings on synthetic tables: each finding met and violated."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from benchmark.experiments.acceptance import ap_distance_rho, night_findings, paper_findings, paper_night_findings

DISTANCES = (25.0, 50.0, 75.0, 100.0, 150.0, 200.0)
MTF50 = {"cam01": 60.0, "cam02": 80.0, "cam03": 110.0, "cam04": 150.0}


def tables(day_ap=None, night_factor=0.5):
    """A sweep that satisfies all three findings; ``day_ap(camera, d)`` overrides daylight AP."""
    rows, od = [], []
    for cam, m in MTF50.items():
        reach = m + 20  # OD50 grows with MTF50
        for condition in ("day", "night"):
            for d in DISTANCES:
                ap = 0.95 / (1 + np.exp((d - reach) / 25))
                if condition == "day" and day_ap is not None:
                    ap = day_ap(cam, d)
                rows.append({"camera": cam, "condition": condition, "distance_m": d,
                             "ap": ap * (night_factor if condition == "night" else 1.0)})
            od.append({"camera": cam, "condition": condition, "mtf50_cy_per_mm": m,
                       "od50_m": reach * (1.0 if condition == "day" else 0.5), "sd_m": 5.0})
    return pd.DataFrame(rows), pd.DataFrame(od)


def test_all_findings_hold():
    res = paper_findings(*tables())
    assert res["ap_falls_with_distance"] and res["ap_distance_rho_worst"] == pytest.approx(-1.0)
    assert res["night_below_day"] and res["night_minus_day_ap_max"] < 0
    assert res["od50_rises_with_mtf50"] and res["od50_mtf50_rho"] == pytest.approx(1.0)


def test_ap_not_falling_with_distance_fails():
    # one camera's daylight AP rises after 75 m: rho = 1 - 6·50/(6·35) = -3/7 > -0.8
    bumpy = lambda cam, d: {25: 0.9, 50: 0.8, 75: 0.3, 100: 0.5, 150: 0.6, 200: 0.7}[int(d)] if cam == "cam02" else 1 - d / 250
    res = paper_findings(*tables(day_ap=bumpy))
    assert not res["ap_falls_with_distance"]
    assert res["ap_distance_rho_worst"] == pytest.approx(-3 / 7)
    rho = ap_distance_rho(tables(day_ap=bumpy)[0])
    assert rho["cam02"] == pytest.approx(-3 / 7) and np.allclose(rho.drop("cam02"), -1.0)
    flat = paper_findings(*tables(day_ap=lambda cam, d: 0.9))  # constant AP: rho undefined, fails
    assert not flat["ap_falls_with_distance"] and np.isnan(flat["ap_distance_rho_worst"])


def test_night_not_below_day_fails():
    table, od = tables()
    i = table.index[(table.camera == "cam03") & (table.condition == "night") & (table.distance_m == 50)][0]
    day = table[(table.camera == "cam03") & (table.condition == "day") & (table.distance_m == 50)].ap.iloc[0]
    table.loc[i, "ap"] = day + 0.05
    res = paper_findings(table, od)
    assert not res["night_below_day"] and res["night_minus_day_ap_max"] == pytest.approx(0.05)
    table.loc[i, "ap"] = day  # equal is not below
    assert not paper_findings(table, od)["night_below_day"]


def test_both_zero_is_a_tie_not_a_violation():
    table, od = tables()
    far = table.distance_m == 200
    table.loc[far, "ap"] = 0.0
    res = paper_findings(table, od)
    assert res["night_below_day"] and res["night_day_ties_at_zero"] == len(MTF50)


def test_od50_not_rising_with_mtf50_fails():
    table, od = tables()
    day = od.condition == "day"
    od.loc[day, "od50_m"] = od.loc[day, "od50_m"].to_numpy()[::-1]  # falls with MTF50
    res = paper_findings(table, od)
    assert not res["od50_rises_with_mtf50"] and res["od50_mtf50_rho"] == pytest.approx(-1.0)
    od.loc[day, "od50_m"] = [80.0, 120.0, 90.0, np.inf]  # inf ranks highest: rho = 0.8
    res = paper_findings(table, od)
    assert res["od50_rises_with_mtf50"] and res["od50_mtf50_rho"] == pytest.approx(0.8)


def test_bad_input():
    table, od = tables()
    with pytest.raises(ValueError, match="lacks column"):
        paper_findings(table.drop(columns="ap"), od)
    with pytest.raises(ValueError, match="no 'night' rows"):
        paper_findings(table[table.condition == "day"], od)


# --- night and dusk criteria --------------------------------------------------------------

def night_tables(night_ap, dusk_factor=0.75):
    """Day AP falls from 0.9; dusk is ``dusk_factor`` of day; night AP is ``night_ap(cam, d)``;
    night OD50 is where the night AP crosses 0.5 (inside 25-200 m when it does)."""
    rows, od = [], []
    for cam, m in MTF50.items():
        for d in DISTANCES:
            day = 0.9 * np.exp(-d / 400)
            for condition, ap in (("day", day), ("dusk", dusk_factor * day), ("night", night_ap(cam, d))):
                rows.append({"camera": cam, "condition": condition, "distance_m": d, "ap": ap})
        night = [night_ap(cam, d) for d in DISTANCES]
        cross = next((d for d, a in zip(DISTANCES, night) if a < 0.5), 0.0) if night[0] >= 0.5 else 0.0
        od.append({"camera": cam, "condition": "night", "mtf50_cy_per_mm": m, "od50_m": cross})
    return pd.DataFrame(rows), pd.DataFrame(od)


def test_night_findings_all_hold():
    res = night_findings(*night_tables(lambda cam, d: 0.9 * np.exp(-d / 120), dusk_factor=0.9), near_m=25.0)
    assert res["night_ap_near_useful"] and res["night_ap_near_min"] == pytest.approx(0.9 * np.exp(-25 / 120))
    assert res["night_below_day_everywhere"] and res["night_ap_falls_with_distance"]
    assert res["dusk_between_at_near"] and res["dusk_between_cameras"] == len(MTF50)
    assert res["night_od50_inside_cameras"] == len(MTF50)  # 4 cameras: the >= 10 rule cannot hold
    assert not res["night_od50_inside"]


def test_night_findings_blind_night_fails_every_criterion():
    res = night_findings(*night_tables(lambda cam, d: 0.0, dusk_factor=0.0))
    assert not res["night_ap_near_useful"] and res["night_ap_near_min"] == 0.0
    assert res["night_below_day_everywhere"]  # blind at night, not by day: below, trivially
    assert not res["night_ap_falls_with_distance"] and np.isnan(res["night_rho_worst"])
    assert res["night_od50_inside_cameras"] == 0
    assert not res["dusk_between_at_near"]


def test_night_findings_need_dusk_rows():
    table, od = night_tables(lambda cam, d: 0.1)
    with pytest.raises(ValueError, match="dusk"):
        night_findings(table[table["condition"] != "dusk"], od)


# --- the paper's night below day, where either light sees the car -------------------------

def test_paper_night_below_day_where_seen_ignores_cells_neither_light_sees():
    table, od = night_tables(lambda cam, d: 0.4 * np.exp(-d / 120))
    far = (table["camera"] == "cam01") & (table["distance_m"] == 200.0)
    table.loc[far & (table["condition"] == "day"), "ap"] = 0.01  # a far car both lights barely see
    table.loc[far & (table["condition"] == "night"), "ap"] = 0.03
    res = paper_night_findings(table, od)
    assert not res["night_below_day_everywhere"]
    assert res["night_below_day_where_seen"] and res["night_day_seen_cells"] == len(MTF50) * len(DISTANCES) - 1

    near = (table["camera"] == "cam02") & (table["distance_m"] == 25.0) & (table["condition"] == "night")
    table.loc[near, "ap"] = 0.95  # night above a seen day: the finding fails
    assert not paper_night_findings(table, od)["night_below_day_where_seen"]
