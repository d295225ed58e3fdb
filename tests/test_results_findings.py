"""The paper's qualitative findings, checked on the tables the quick sweeps produced
(written by the commands in docs/results.md): the reference sweep (multiscale detector
input, docs/data/sweep.csv and od50.csv) and the paper-parity sweep (YOLOv5's default
640 input, docs/data/sweep-640.csv and od50-640.csv). ``night`` is the paper's night
(0.1-1 lux image-plane, every lamp on), ``night_regulation`` the unlit regulation road."""

from pathlib import Path

import pandas as pd
import pytest

from benchmark.experiments.acceptance import night_findings, paper_findings, paper_night_findings

DATA = Path(__file__).resolve().parents[1] / "docs" / "data"


def _load(suffix: str) -> tuple[pd.DataFrame, pd.DataFrame]:
    return pd.read_csv(DATA / f"sweep{suffix}.csv"), pd.read_csv(DATA / f"od50{suffix}.csv")


@pytest.fixture(scope="module")
def tables():
    return _load("")


@pytest.fixture(scope="module")
def paper_parity():
    return _load("-640")


CONDITIONS = {"day", "dusk", "night", "night_regulation"}


@pytest.mark.parametrize("suffix, conditions", [("", CONDITIONS), ("-640", CONDITIONS)], ids=["reference", "paper-parity"])
def test_the_table_covers_13_cameras_and_its_conditions(suffix, conditions):
    table, od50 = _load(suffix)
    assert table["camera"].nunique() == 13 and set(table["condition"]) == conditions
    assert len(table) == 13 * len(conditions) * 6 and (table["n_images"] == 10).all()
    assert len(od50) == 13 * len(conditions)


NIGHT_AT_200_M = (
    "On the paper's night the two coarsest cameras score a few low boxes on a car 200 m away: "
    "AP 0.03-0.07 (640: 0.04-0.07) against 0.00-0.01 by day (cam01, cam02); every other camera and "
    "distance is below day (docs/results.md, \"The three nights side by side\")")


@pytest.mark.xfail(strict=True, reason=NIGHT_AT_200_M)
def test_night_ap_is_below_day_ap_at_every_distance(tables):
    assert paper_findings(*tables)["night_below_day"]


def test_night_is_below_day_wherever_either_sees_the_car(tables):
    """Night below day at every camera and distance where day or night AP reaches 0.1."""
    findings = paper_night_findings(*tables)
    assert findings["night_day_seen_cells"] > 13 * 4 and findings["night_below_day_where_seen"]


def test_od50_rises_with_mtf50_in_daylight(tables):
    findings = paper_findings(*tables)
    assert findings["od50_rises_with_mtf50"] and findings["od50_mtf50_rho"] >= 0.6


def test_far_cars_score_lower_than_near_cars_for_every_camera(tables):
    day = tables[0][tables[0]["condition"] == "day"]
    for camera, rows in day.groupby("camera"):
        ap = rows.set_index("distance_m")["ap"]
        assert ap[200.0] < ap[25.0], camera


@pytest.mark.xfail(strict=True, reason=(
    "With the reference multiscale input (native + 640) the finely sampled cameras keep AP of about "
    "0.8-0.9 out to 100-150 m (the native pass sees a 100 m car at 40-80 px), so 8 of 13 have a "
    "Spearman rho of AP vs distance between -0.77 and -0.09; the paper-parity (640) sweep meets the "
    "criterion (docs/results.md, \"Acceptance checks\")"))
def test_ap_falls_with_distance_for_every_camera(tables):
    assert paper_findings(*tables)["ap_falls_with_distance"]


def test_paper_parity_sweep_shows_the_daylight_findings(paper_parity):
    findings = paper_findings(*paper_parity)
    assert findings["ap_falls_with_distance"] and findings["ap_distance_rho_worst"] <= -0.8
    assert findings["od50_rises_with_mtf50"] and findings["od50_mtf50_rho"] >= 0.6


@pytest.mark.xfail(strict=True, reason=NIGHT_AT_200_M)
def test_paper_parity_night_is_below_day_everywhere(paper_parity):
    assert paper_findings(*paper_parity)["night_below_day"]


# --- the paper's night (0.1-1 lux image-plane, every lamp on; reference sweep) -------------

PAPER_NIGHT_IS_READ_NOISE_BOUND = (
    "At the paper's night's own image-plane lux our camera is read-noise bound (6.8 e- on the car "
    "against 5 e- read noise at ISO 270) and an oncoming car's lamps at 25 m take the exposure: "
    "night AP at 25 m >= 0.15 for 7 of 13 cameras, not 10; measured factor by factor in "
    "docs/results.md, \"The paper's night, factor by factor\" (docs/data/night-factors.csv)")


def test_paper_night_od50_lies_inside_the_distances_or_is_censored(tables):
    assert paper_night_findings(*tables)["night_od50_reported"]


def test_paper_night_od50_rises_with_mtf50(tables):
    findings = paper_night_findings(*tables)
    assert findings["night_od50_rises_with_mtf50"] and findings["night_od50_mtf50_rho"] > 0


def test_paper_night_sees_the_car_near_the_camera_for_some_cameras(tables):
    """Unlike the regulation road, the paper's night is not blind: the best cameras reach
    AP >= 0.5 at 50 m and an OD50 inside the measured distances."""
    findings = paper_night_findings(*tables)
    table, od50 = tables
    night = table[table["condition"] == "night"]
    assert findings["night_ap_near_useful_cameras"] >= 5 and night["ap"].max() >= 0.5
    assert (od50[od50["condition"] == "night"]["od50_m"] >= 25.0).sum() >= 2


@pytest.mark.xfail(strict=True, reason=PAPER_NIGHT_IS_READ_NOISE_BOUND)
def test_paper_night_ap_at_25_m_is_useful_for_ten_cameras(tables):
    assert paper_night_findings(*tables)["night_ap_near_useful"]


# --- dusk and the regulation road (night_regulation; reference sweep) ---------------------

NIGHT_IS_BLIND = (
    "On the regulation road (ego low beams to SAE J1383 / ECE R112, R7 tail lamps, R3 reflectors, "
    "an R4 plate lamp, IES road luminaires) the car body ahead collects ~2 e- per pixel at 25 m "
    "(cam12, 16 ms, ISO 270): night_regulation AP <= 0.07 at every distance for every camera; "
    "measured and explained in docs/results.md")


def test_dusk_lies_between_night_and_day_at_25_m(tables):
    findings = night_findings(*tables, night="night_regulation")
    assert findings["dusk_between_at_near"], findings["dusk_between_cameras"]


def test_night_is_below_day_at_every_distance(tables):
    assert night_findings(*tables, night="night_regulation")["night_below_day_everywhere"]


@pytest.mark.xfail(strict=True, reason=NIGHT_IS_BLIND)
def test_night_ap_at_25_m_is_useful_for_every_camera(tables):
    assert night_findings(*tables, night="night_regulation")["night_ap_near_useful"]


@pytest.mark.xfail(strict=True, reason=NIGHT_IS_BLIND)
def test_night_ap_falls_with_distance_for_every_camera(tables):
    assert night_findings(*tables, night="night_regulation")["night_ap_falls_with_distance"]


@pytest.mark.xfail(strict=True, reason=NIGHT_IS_BLIND)
def test_night_od50_lies_inside_the_measured_range_for_ten_cameras(tables):
    assert night_findings(*tables, night="night_regulation")["night_od50_inside"]


def test_cameras_of_one_published_mtf50_group_differ_by_several_sds_by_day():
    """The paper: scores "differed by as much as three standard deviations when the MTF50 was
    equal". docs/data/mtf50-groups.csv (`benchmark publish mtf50-groups` on the reference sweep):
    pairs of one published group, paired bootstrap; by day some pair differs by more than 2 SD,
    and the table's OD50s are the reference sweep's."""
    groups = pd.read_csv(DATA / "mtf50-groups.csv")
    day = groups[groups["condition"] == "day"].dropna(subset=["delta_over_sd"])
    assert len(day) >= 5 and (day["delta_over_sd"] > 2).any()
    od50 = pd.read_csv(DATA / "od50.csv").set_index(["camera", "condition"])["od50_m"]
    for row in day.itertuples():
        assert row.od50_a_m == pytest.approx(od50[row.camera_a, "day"], abs=0.01)
        assert row.od50_b_m == pytest.approx(od50[row.camera_b, "day"], abs=0.01)
        assert row.delta_od50_m == pytest.approx(row.od50_a_m - row.od50_b_m, abs=0.01)


def test_the_gpus_collection_scores_as_the_cpus():
    """metric-300's first 8 environments rendered by cuda_ad_spectral (an H100) and by
    llvm_ad_spectral (this CPU), swept alike and compared camera by camera (paired bootstrap):
    docs/data/backend-scores.csv (`benchmark publish backend-scores`; docs/performance.md, "On a GPU").
    Each ΔOD50 lies within either collection's own OD50 SD, no AP differs by 0.1, and the AP
    differences called are about as many as a 95 % interval calls by chance."""
    table = pd.read_csv(DATA / "backend-scores.csv", keep_default_na=False, na_values=[""])
    assert len(table) >= 10 and (table["n_environments"] == 8).all()
    measured = table.dropna(subset=["delta_od50_m"])
    assert len(measured) >= 5
    assert (measured["delta_od50_m"].abs() <= measured[["od50_sd_gpu_m", "od50_sd_cpu_m"]].min(axis=1)).all()
    assert (table["largest_abs_delta_ap"] < 0.1).all()
    called = table["resolved"].fillna("").str.split().str.len().sum()
    assert called <= 0.1 * 6 * len(table)


def test_od50_sd_shrinks_counts_cameras_and_leaves_censored_ones_apart():
    from benchmark.experiments.acceptance import od50_sd_shrinks

    quick = pd.read_csv(DATA / "od50.csv", keep_default_na=False, na_values=[""])
    day = quick[quick["condition"] == "day"]
    larger = quick.copy()
    measured = day[day["censored"].fillna("") == ""]["camera"].tolist()
    halved = measured[:-1]  # all but one measured camera's SD halved
    rows = (larger["condition"] == "day") & larger["camera"].isin(halved)
    larger.loc[rows, "sd_m"] /= 2
    found = od50_sd_shrinks(larger, quick)
    assert found["compared"] == len(measured) and found["smaller"] == len(halved)
    assert found["censored"] == day["camera"].nunique() - len(measured)
    with pytest.raises(ValueError, match="no 'dawn' rows"):
        od50_sd_shrinks(larger, quick, condition="dawn")
