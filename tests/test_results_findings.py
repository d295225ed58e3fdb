"""The paper's qualitative findings, checked on the tables the quick sweeps produced
(written by the commands in docs/results.md): the reference sweep (multiscale detector
input, docs/data/sweep.csv and od50.csv) and the paper-parity sweep (YOLOv5's default
640 input, docs/data/sweep-640.csv and od50-640.csv)."""

from pathlib import Path

import pandas as pd
import pytest

from benchmark.experiments.acceptance import night_findings, paper_findings

DATA = Path(__file__).resolve().parents[1] / "docs" / "data"


def _load(suffix: str) -> tuple[pd.DataFrame, pd.DataFrame]:
    return pd.read_csv(DATA / f"sweep{suffix}.csv"), pd.read_csv(DATA / f"od50{suffix}.csv")


@pytest.fixture(scope="module")
def tables():
    return _load("")


@pytest.fixture(scope="module")
def paper_parity():
    return _load("-640")


@pytest.mark.parametrize("suffix, conditions", [("", {"day", "dusk", "night"}), ("-640", {"day", "dusk", "night"})],
                         ids=["reference", "paper-parity"])
def test_the_table_covers_13_cameras_and_its_conditions(suffix, conditions):
    table, od50 = _load(suffix)
    assert table["camera"].nunique() == 13 and set(table["condition"]) == conditions
    assert len(table) == 13 * len(conditions) * 6 and (table["n_images"] == 10).all()
    assert len(od50) == 13 * len(conditions)


def test_night_ap_is_below_day_ap_at_every_distance(tables):
    assert paper_findings(*tables)["night_below_day"]


def test_od50_rises_with_mtf50_in_daylight(tables):
    findings = paper_findings(*tables)
    assert findings["od50_rises_with_mtf50"] and findings["od50_mtf50_rho"] >= 0.6


def test_far_cars_score_lower_than_near_cars_for_every_camera(tables):
    day = tables[0][tables[0]["condition"] == "day"]
    for camera, rows in day.groupby("camera"):
        ap = rows.set_index("distance_m")["ap"]
        assert ap[200.0] < ap[25.0], camera


@pytest.mark.xfail(strict=True, reason=(
    "With the reference multiscale input (native + 640) three finely sampled cameras keep AP ≈ 0.82–0.89 "
    "out to 150 m (the native pass sees a 100 m car at 40–80 px), so their Spearman rho of AP vs "
    "distance is only -0.14 to -0.43; the paper-parity (640) sweep meets the criterion (docs/results.md)"))
def test_ap_falls_with_distance_for_every_camera(tables):
    assert paper_findings(*tables)["ap_falls_with_distance"]


def test_paper_parity_sweep_shows_all_three_findings(paper_parity):
    findings = paper_findings(*paper_parity)
    assert findings["ap_falls_with_distance"] and findings["ap_distance_rho_worst"] <= -0.8
    assert findings["night_below_day"]
    assert findings["od50_rises_with_mtf50"] and findings["od50_mtf50_rho"] >= 0.6


# --- issue 10: night and dusk with the lamps of a real road (reference sweep) ---------------

NIGHT_IS_BLIND = (
    "With cited photometry (ego low beams to SAE J1383 / ECE R112, R7 tail lamps, IES road "
    "luminaires) the car body ahead collects ~2 e- per pixel at 25 m (cam12, 16 ms, ISO 270) and "
    "YOLOv5n finds no car under any acquisition policy; measured and explained in docs/results.md")


def test_dusk_lies_between_night_and_day_at_25_m(tables):
    findings = night_findings(*tables)
    assert findings["dusk_between_at_near"], findings["dusk_between_cameras"]


def test_night_is_below_day_at_every_distance(tables):
    assert night_findings(*tables)["night_below_day_everywhere"]


@pytest.mark.xfail(strict=True, reason=NIGHT_IS_BLIND)
def test_night_ap_at_25_m_is_useful_for_every_camera(tables):
    assert night_findings(*tables)["night_ap_near_useful"]


@pytest.mark.xfail(strict=True, reason=NIGHT_IS_BLIND)
def test_night_ap_falls_with_distance_for_every_camera(tables):
    assert night_findings(*tables)["night_ap_falls_with_distance"]


@pytest.mark.xfail(strict=True, reason=NIGHT_IS_BLIND)
def test_night_od50_lies_inside_the_measured_range_for_ten_cameras(tables):
    assert night_findings(*tables)["night_od50_inside"]
