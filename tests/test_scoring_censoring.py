"""Censored OD50: AP that does not cross 0.5 inside the measured distances is reported as a
bound ("> 200 m", "< 25 m") in tables, the report, figures and the leaderboard ranking."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from benchmark.leaderboard.protocols import condition_label
from benchmark.scoring import BOOTSTRAP_RESAMPLES, format_od50, od50, od50_censoring

D = [25, 50, 75, 100, 150, 200]
REPO = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("ap, expected", [
    ([0.9, 0.85, 0.8, 0.7, 0.6, 0.55], (">", 200.0)),   # extrapolated beyond the far end
    ([0.9, 0.9, 0.9, 0.9, 0.9, 0.9], (">", 200.0)),     # od50 = inf
    ([0.4, 0.3, 0.2, 0.1, 0.0, 0.0], ("<", 25.0)),      # extrapolated below the near end
    ([0.1, 0.1, 0.1, 0.1, 0.1, 0.1], ("<", 25.0)),      # od50 = 0
    ([0.9, 0.8, 0.6, 0.4, 0.2, 0.1], ("", None)),       # measured crossing
    ([0.3, 0.6, 0.7, 0.4, 0.2, 0.1], ("", None)),       # upward then downward crossing
    ([0.7, 0.4, 0.6, 0.7, 0.8, 0.9], ("", None)),       # first downward crossing counts
    ([0.3, 0.6, 0.7, 0.8, 0.8, 0.9], (">", 200.0)),     # only an upward crossing
    ([0.9, math.nan, 0.8, 0.7, 0.6, math.nan], (">", 150.0)),  # NaN points dropped: the farthest measured
])  # fmt: skip
def test_censoring_rule(ap, expected):
    assert od50_censoring(D, ap) == expected
    censored, _ = expected
    value = od50(D, ap)
    if censored == ">":
        assert value >= 150.0
    elif censored == "<":
        assert value <= 25.0
    else:
        assert 25.0 <= value <= 200.0


def test_format_shows_the_bound_not_the_number():
    assert format_od50(1625.6, ">", 200.0, 4150.9) == "> 200 m"
    assert format_od50(0.0, "<", 25.0, 0.0) == "< 25 m"
    assert format_od50(123.456, "", None, 5.67) == "123.5 ± 5.7 m"
    assert format_od50(math.inf) == "∞" and format_od50(None) == "–"


def test_one_bootstrap_default():
    import inspect

    from benchmark.experiments import sweep
    from benchmark.leaderboard import submission
    from benchmark.scoring import bootstrap_od50

    assert BOOTSTRAP_RESAMPLES == 1000
    assert inspect.signature(bootstrap_od50).parameters["n_resamples"].default == BOOTSTRAP_RESAMPLES
    assert inspect.signature(sweep.sweep).parameters["n_resamples"].default == BOOTSTRAP_RESAMPLES
    assert submission.N_RESAMPLES == BOOTSTRAP_RESAMPLES
    assert "n_resamples=200" not in (REPO / "benchmark" / "experiments" / "report.py").read_text()


def test_bootstrap_reports_censoring():
    from benchmark.scoring import bootstrap_od50
    from synthetic_scoring import synthetic_collection

    gt, dets = synthetic_collection(6, seed=1, half_range_m=1000.0)  # AP stays high: beyond the far end
    out = bootstrap_od50(gt, dets, n_resamples=20)
    assert out.censored == ">" and out.bound_m == 200.0 and out.n_resamples == 20


def test_with_censoring_and_summary_table():
    from benchmark.experiments.report import summary_table
    from benchmark.experiments.sweep import od50_cell, with_censoring

    rows = []
    for cam, ap in (("far", [0.9, 0.8, 0.8, 0.7, 0.6, 0.6]), ("mid", [0.9, 0.8, 0.6, 0.4, 0.2, 0.1]),
                    ("none", [0.3, 0.2, 0.1, 0.0, 0.0, 0.0])):
        rows += [{"camera": cam, "condition": "day", "distance_m": d, "ap": a} for d, a in zip(D, ap)]
    table = pd.DataFrame(rows)
    od = pd.DataFrame({"camera": ["far", "mid", "none"], "condition": ["day"] * 3, "mtf50_cy_per_mm": [100.0] * 3,
                       "od50_m": [1626.0, 87.5, 0.0], "sd_m": [6081.0, 5.0, 0.0],
                       "ci95_lo_m": [150.0, 80.0, 0.0], "ci95_hi_m": [np.inf, 95.0, 0.0]})
    od = with_censoring(od, table)
    assert list(od["censored"]) == [">", "", "<"]
    assert [od50_cell(r) for _, r in od.iterrows()] == ["> 200", "87.5 ± 5.0", "< 25"]
    summary = summary_table(table.assign(ap50=1.0, n_images=1), od)
    assert list(summary["OD50 ± SD (m)"]) == ["> 200", "87.5 ± 5.0", "< 25"]
    assert list(summary["95 % interval (m)"])[0] == "–"
    assert "1626" not in summary.to_string()


def test_figure_labels_bounds(tmp_path):
    from benchmark.experiments import spm

    od = pd.DataFrame({"condition": ["day"] * 4, "mtf50_cy_per_mm": [80.0, 100.0, 120.0, 200.0],
                       "od50_m": [90.0, 110.0, 130.0, 1626.0], "sd_m": [5.0] * 4,
                       "censored": ["", "", "", ">"], "bound_m": [np.nan, np.nan, np.nan, 200.0]})
    fig = spm.od50_vs_mtf50(od, tmp_path / "f", measured_range_m=(25.0, 200.0))
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels == [condition_label("day") + ": slope 1.00 m per cy/mm (1 OD50 > 200 m (▲, lower bound): hollow, not fitted)"]
    assert max(np.max(line.get_ydata()) for line in fig.axes[0].get_lines() if len(line.get_ydata())) <= 200.0


def test_sweep_od50_csv_has_censored_column(tmp_path, monkeypatch):
    from benchmark.experiments import sweep as sweep_module
    from test_sweep_cache import make_fake_sweep

    make_fake_sweep(tmp_path / "sw", monkeypatch)
    raw = pd.read_csv(tmp_path / "sw" / "od50.csv", keep_default_na=False)
    assert list(raw.columns) == sweep_module.OD50_COLUMNS  # (columns added later go last: older readers keep theirs)
    assert list(raw.columns)[-5:] == ["censored", "ap_range_m", "ap_range_sd_m", "ap_range_ci95_lo_m", "ap_range_ci95_hi_m"]
    assert set(raw["censored"]) <= {"", ">", "<"}
    assert "od50_m" in raw.columns  # kept for backwards compatibility
    table, od = sweep_module.load_sweep(tmp_path / "sw")
    assert list(od["censored"]) == list(raw["censored"])


def _sub(name, per_distance_ap, od50_m, night=None):
    cond = {"od50_m": od50_m, "od50_sd_m": 1.0, "per_distance": [{"distance_m": float(d), "ap": a} for d, a in zip(D, per_distance_ap)]}
    conds = {"day": cond}
    if night is not None:
        conds["night"] = night
    return {"name": name, "conditions": conds}


def test_leaderboard_rank_rule():
    """Censored OD50s rank in their tier (above or below every measured one) by the AP range, the
    area under AP vs distance: never by AP at one distance, never by the extrapolated number."""
    from benchmark.leaderboard.render import _fmt_ap_range, _fmt_od50, od50_sort_value, ranked

    far_hi = _sub("far-hi", [0.9, 0.9, 0.9, 0.9, 0.8, 0.7], 500.0)     # > 200, AP range 170 m
    far_lo = _sub("far-lo", [0.9, 0.9, 0.9, 0.9, 0.7, 0.55], 1626.0)   # > 200, 161.25 m, bigger extrapolation
    far_inf = _sub("far-inf", [0.6, 0.6, 0.6, 0.6, 0.6, 0.6], None)    # > 200 (null: never falls), 120 m; AP(200) 0.6 > 0.55
    measured = _sub("measured", [0.9, 0.9, 0.9, 0.8, 0.6, 0.4], 187.5)
    near_hi = _sub("near-hi", [0.45, 0.3, 0.1, 0.0, 0.0, 0.0], 0.0)    # < 25, 26.875 m
    near_lo = _sub("near-lo", [0.1, 0.45, 0.45, 0.1, 0.0, 0.0], 0.0)   # < 25, 30 m: AP(25) lower, more AP beyond
    order = [s["name"] for s in ranked([near_lo, measured, far_lo, near_hi, far_inf, far_hi])]
    assert order == ["far-hi", "far-lo", "far-inf", "measured", "near-lo", "near-hi"]
    assert _fmt_od50(far_lo["conditions"]["day"]) == (repr(200 + 161.25 / 361.25), "> 200")
    assert _fmt_od50(near_hi["conditions"]["day"]) == (repr(25 * 26.875 / 51.875), "< 25")
    assert _fmt_od50(measured["conditions"]["day"]) == (repr(187.5), "187.5 ± 1.0")
    assert _fmt_ap_range(far_hi["conditions"]["day"]) == (repr(170.0), "170.0")
    assert od50_sort_value(None) is None


def test_leaderboard_breaks_no_tie_by_one_distance():
    """Two "> 200" curves with the same AP range but different AP at 200 m tie on the rank value
    (the night OD50 then decides); the AP at the farthest distance alone never orders them."""
    from benchmark.leaderboard.render import od50_sort_value, ranked

    first = _sub("a-first", [0.875, 0.875, 0.875, 0.875, 0.875, 0.5], None)  # AP range 165.625 m, AP(200) 0.5
    second = _sub("b-second", [0.875, 0.875, 0.875, 0.875, 0.8125, 0.625], None)  # 165.625 m, AP(200) 0.625
    assert od50_sort_value(first["conditions"]["day"]) == od50_sort_value(second["conditions"]["day"])
    assert [s["name"] for s in ranked([second, first])] == ["a-first", "b-second"]  # tie: by name
    night = {"od50_m": 60.0, "od50_sd_m": 1.0, "per_distance": [{"distance_m": float(d), "ap": a}
                                                               for d, a in zip(D, [0.9, 0.6, 0.4, 0.1, 0.0, 0.0])]}
    second["conditions"]["night"] = night
    assert [s["name"] for s in ranked([first, second])] == ["b-second", "a-first"]  # the night OD50 decides


def test_committed_leaderboard_shows_no_extrapolated_number():
    from benchmark.leaderboard import load_protocols, load_submissions, render_markdown

    lb = REPO / "leaderboard"
    subs = load_submissions(lb, load_protocols(lb))
    assert len(subs) == 3 * 13  # every committed submission still validates: 13 cameras on quick, adas and metric-300
    assert {s["collection"]["protocol"] for s in subs} == {"quick", "adas", "metric-300"}
    text = render_markdown(subs, load_protocols(lb))
    assert "1625.6" not in text and "281.3" not in text and "\\> 200" in text and "(1000 resamples)" in text
    assert text == (lb / "README.md").read_text()  # regenerated with `benchmark leaderboard`


def test_run_and_score_print_a_bound_not_an_extrapolation():
    from benchmark.cli.main import od50_text

    distances = (25.0, 50.0, 100.0, 200.0)
    assert od50_text(distances, (0.9, 0.85, 0.8, 0.7)) == "OD50 > 200 m"  # extrapolation would say ~480 m
    assert od50_text(distances, (0.4, 0.3, 0.2, 0.1)) == "OD50 < 25 m"
    assert od50_text(distances, (0.9, 0.7, 0.3, 0.1)) == "OD50 75.0 m"


def test_leaderboard_marks_figures_from_too_few_environments_and_shows_ap_range():
    from benchmark.leaderboard.protocols import load_protocols
    from benchmark.leaderboard.render import _fmt_ap_range, _fmt_od50, _few, columns
    from benchmark.scoring import MIN_ENVIRONMENTS

    measured = _sub("measured", [0.9, 0.9, 0.9, 0.8, 0.6, 0.4], 187.5)["conditions"]["day"]
    censored = _sub("far", [0.6] * 6, None)["conditions"]["day"]
    for cond, od50_text, range_text in ((measured, "187.5 ± 1.0", "148.8"), (censored, "> 200", "120.0")):
        cond["n_environments"] = MIN_ENVIRONMENTS
        assert (_fmt_od50(cond)[1], _fmt_ap_range(cond)[1]) == (od50_text, range_text)
        cond["n_environments"] = MIN_ENVIRONMENTS - 1
        assert (_fmt_od50(cond)[1], _fmt_ap_range(cond)[1]) == (od50_text + "†", range_text + "†")
    assert _few([{"conditions": {"day": measured}}]) and _fmt_ap_range(None) == ("", "–")
    keys = [c.key for c in columns(load_protocols()["metric-300"])]
    assert keys[3:9] == ["day_od50", "dusk_od50", "night_od50", "night_regulation_od50", "day_ap_range", "night_ap_range"]
