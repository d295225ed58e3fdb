"""The paper's findings on metric-300 (50 environments x 6 distances), checked on the published
tables in docs/data/metric-300 (written by the metric-300 chain's `benchmark publish` steps; the
commands are in docs/results.md, "Regenerate metric-300"). The thresholds were written
before the tables existed; until they are published every test here is skipped with that reason."""

from pathlib import Path

import pandas as pd
import pytest

from benchmark.experiments.acceptance import od50_sd_shrinks, paper_findings, paper_night_findings

DOCS_DATA = Path(__file__).resolve().parents[1] / "docs" / "data"
DATA = DOCS_DATA / "metric-300"
CONDITIONS = {"day", "dusk", "night", "night_regulation"}

pytestmark = pytest.mark.skipif(not (DATA / "sweep.csv").is_file(),
                                reason="docs/data/metric-300 is not published yet (benchmarks/metric-300/chain.sh)")


def _load(suffix: str) -> tuple[pd.DataFrame, pd.DataFrame]:
    return (pd.read_csv(DATA / f"sweep{suffix}.csv"),
            pd.read_csv(DATA / f"od50{suffix}.csv", keep_default_na=False, na_values=[""]))


@pytest.fixture(scope="module")
def reference():
    return _load("")


@pytest.fixture(scope="module")
def paper_parity():
    return _load("-640")


@pytest.mark.parametrize("suffix", ["", "-640"], ids=["reference", "paper-parity"])
def test_the_tables_cover_13_cameras_four_conditions_and_50_environments(suffix):
    table, od50 = _load(suffix)
    assert table["camera"].nunique() == 13 and set(table["condition"]) == CONDITIONS
    assert len(table) == 13 * len(CONDITIONS) * 6 and (table["n_images"] == 50).all()
    assert len(od50) == 13 * len(CONDITIONS) and (od50["n_environments"] == 50).all()


def test_ap_falls_with_distance_by_day_for_every_camera_at_paper_parity(paper_parity):
    findings = paper_findings(*paper_parity)
    assert findings["ap_falls_with_distance"] and findings["ap_distance_rho_worst"] <= -0.8


NIGHT_AT_200_M = (
    "Measured on metric-300's runs before the tables were published, as on quick: on "
    "the paper's night the two coarsest cameras score a few low boxes on a car 200 m away, AP 0.034 "
    "and 0.038 against 0.003 and 0.030 by day (cam01, cam02); every other camera and distance is "
    "below day (docs/results.md, \"The nights and dusk on metric-300\")")


@pytest.mark.xfail(strict=True, reason=NIGHT_AT_200_M)
def test_the_papers_night_is_below_day_at_every_distance(reference):
    assert paper_night_findings(*reference)["night_below_day_everywhere"]


def test_the_papers_night_is_below_day_wherever_either_sees_the_car(reference):
    """Night below day at every camera and distance where day or night AP reaches 0.1."""
    findings = paper_night_findings(*reference)
    assert findings["night_day_seen_cells"] > 13 * 4 and findings["night_below_day_where_seen"]


def test_day_od50_rises_with_mtf50(reference):
    findings = paper_findings(*reference)
    assert findings["od50_rises_with_mtf50"] and findings["od50_mtf50_rho"] >= 0.6


def test_day_od50_bootstrap_sds_are_smaller_than_quicks_for_11_of_13_cameras(paper_parity):
    """At paper parity, where every camera's day OD50 lies inside the measured distances on
    quick: with the reference input five of quick's 13 are censored ("> 200 m"), their SD the
    edge of the distances rather than a spread, so 11 of 13 could not be compared there."""
    quick = pd.read_csv(DOCS_DATA / "od50-640.csv", keep_default_na=False, na_values=[""])
    found = od50_sd_shrinks(paper_parity[1], quick)
    assert found["smaller"] >= 11, found  # (counted among the compared cameras only)
