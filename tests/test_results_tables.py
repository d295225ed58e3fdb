"""docs/results.md's tables are the ones `benchmark publish markdown` makes from docs/data,
and `benchmark publish sweeps` lays the sweep folders out as docs/data."""

from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

from benchmark.cli.main import app
from benchmark.publish import results_page, sweep_tables

REPO = Path(__file__).resolve().parents[1]
DATA = REPO / "docs" / "data"


def _markdown(args: list[str]) -> str:
    result = CliRunner().invoke(app, ["publish", "markdown", *args])
    assert result.exit_code == 0, result.output
    return result.output


def _rows_missing_from_the_page(tables: dict[str, str]) -> tuple[list[str], list[str]]:
    """The table rows of ``tables``, and those docs/results.md lacks (or has with other numbers)."""
    page = (REPO / "docs" / "results.md").read_text().splitlines()
    rows = [line for text in tables.values() for line in text.splitlines() if line.startswith("| ")]
    return rows, [row for row in rows if row not in page]


def test_every_table_row_of_the_results_page_comes_from_docs_data():
    rows, missing = _rows_missing_from_the_page(results_page.tables(DATA))
    assert len(rows) > 13 * 3
    assert not missing, f"docs/results.md lacks (or has other numbers in) {missing[:3]}"


# metric-300's tables the page leaves out: every OD50 in them is "< 25 m", which the nights side by side say
METRIC_300_LEFT_OUT = {"night_regulation", "night: metric-300 against quick", "night_regulation: metric-300 against quick"}


def test_every_metric_300_table_row_of_the_results_page_comes_from_its_tables():
    tables = results_page.tables(DATA / "metric-300", against=DATA)
    assert METRIC_300_LEFT_OUT < set(tables) and len(tables) > 6
    _, missing = _rows_missing_from_the_page({k: v for k, v in tables.items() if k not in METRIC_300_LEFT_OUT})
    assert not missing, f"docs/results.md lacks (or has other numbers in) {missing[:3]}"


def test_every_adas_quick_table_row_of_the_results_page_comes_from_its_tables():
    tables = results_page.tables(DATA / "adas-quick", against=DATA, names=("quick", "adas-quick"))
    assert "day" in tables and "OD50 against MTF50" in tables and "day: adas-quick against quick" in tables
    _, missing = _rows_missing_from_the_page(tables)
    assert not missing, f"docs/results.md lacks (or has other numbers in) {missing[:3]}"


def test_every_adas_camera_table_row_of_the_results_page_comes_from_its_tables():
    tables = results_page.tables(DATA / "adas-quick-cameras")
    assert set(tables) == {"day", "OD50 against MTF50"}
    _, missing = _rows_missing_from_the_page(tables)
    assert not missing, f"docs/results.md lacks (or has other numbers in) {missing[:3]}"


@pytest.mark.parametrize("collection", ["quick", "metric-300"])
def test_publish_lays_sweep_folders_out_as_docs_data(tmp_path, collection):
    results = tmp_path / "results"
    for suffix, folder_suffix in sweep_tables.SWEEPS.items():
        if not (DATA / f"sweep{suffix}.csv").exists():  # a sweep not yet published
            continue
        (results / (collection + folder_suffix)).mkdir(parents=True)
        for name in ("sweep", "od50"):
            (results / (collection + folder_suffix) / f"{name}.csv").write_bytes((DATA / f"{name}{suffix}.csv").read_bytes())
    (results / "other-640").mkdir()  # another collection's sweep is not taken
    (results / "other-640" / "sweep.csv").write_text("camera\n")
    policies = pd.read_csv(DATA / "sweep-policies.csv"), pd.read_csv(DATA / "od50-policies.csv")
    for policy, folder_suffix in sweep_tables.POLICIES.items():
        (results / (collection + folder_suffix)).mkdir()
        for name, table in zip(("sweep", "od50"), policies):
            table[table["exposure"] == policy].drop(columns="exposure").to_csv(
                results / (collection + folder_suffix) / f"{name}.csv", index=False)

    publish = CliRunner().invoke(app, ["publish", "sweeps", "--results", str(results), "--collection", collection,
                                       "--out", str(tmp_path / "data")])
    assert publish.exit_code == 0, publish.output
    assert (tmp_path / "data" / "sweep-640.csv").read_bytes() == (DATA / "sweep-640.csv").read_bytes()

    for name in ("sweep", "od50"):
        assert (tmp_path / "data" / f"{name}.csv").read_bytes() == (DATA / f"{name}.csv").read_bytes()
    made = pd.read_csv(tmp_path / "data" / "sweep-policies.csv")
    reference = made[made["exposure"] == sweep_tables.REFERENCE_POLICY]
    assert set(reference["condition"]) == {"dusk", "night"} and reference["camera"].nunique() == 4
    assert len(made) == len(policies[0])
    key = ["camera", "condition", "distance_m", "exposure"]
    # the policies' rows as their sweeps wrote them, the reference's from the reference sweep (sweep.csv)
    expected_policies = policies[0][policies[0]["exposure"] != sweep_tables.REFERENCE_POLICY]
    sweep = pd.read_csv(DATA / "sweep.csv")
    expected_reference = sweep[sweep["camera"].isin(set(reference["camera"]))
                               & sweep["condition"].isin(sweep_tables.POLICY_CONDITIONS)].assign(
        exposure=sweep_tables.REFERENCE_POLICY)
    expected = pd.concat([expected_reference, expected_policies], ignore_index=True)
    pd.testing.assert_frame_equal(made.sort_values(key).reset_index(drop=True)[list(policies[0].columns)],
                                  expected.sort_values(key).reset_index(drop=True)[list(policies[0].columns)],
                                  check_exact=False)


def test_markdown_of_a_folder_without_native_or_policy_sweeps(tmp_path):
    """A collection's folder without the native and policy sweeps (metric-300's has no policy
    sweeps): their sections are left out, the others written."""
    for suffix in ("", "-640", "-illuminance"):
        for name in ("sweep", "od50"):
            (tmp_path / f"{name}{suffix}.csv").write_bytes((DATA / f"{name}{suffix}.csv").read_bytes())
    page = results_page.markdown(tmp_path)
    assert "### day" in page and "### illuminance" in page
    assert "### policies" not in page and "### input size" not in page


def test_one_collection_against_another_camera_by_camera(tmp_path):
    """metric-300 against quick (here quick against an edited copy of itself): OD50s, SD ratio,
    difference in combined SDs and ranks among the cameras both hold, and the orders' ρ."""
    sweep, od50 = (pd.read_csv(DATA / f"{name}.csv") for name in ("sweep", "od50"))
    od50.loc[(od50["condition"] == "day") & (od50["camera"] == "cam05"), "sd_m"] *= 2
    od50[od50["camera"] != "cam13"].to_csv(tmp_path / "od50.csv", index=False)
    sweep[sweep["camera"] != "cam13"].to_csv(tmp_path / "sweep.csv", index=False)
    page = _markdown(["--data", str(tmp_path), "--against", str(DATA), "--names", "quick,other"])
    day = page.split("### day: other against quick")[1].split("###")[0]
    rows = {cells[0]: cells for cells in ([c.strip() for c in line.strip("|").split("|")]
                                          for line in day.splitlines() if line.startswith("| cam")) if cells[0] != "camera"}
    assert len(rows) == 12 and "cam13" not in rows
    assert rows["cam05"][4:6] == ["2.00", "0.0"] and rows["cam01"][4:6] == ["1.00", "0.0"]
    assert rows["cam12"][4:6] == ["—", "—"]  # > 200 m by day: censored, not compared
    assert all(len(set(cells[6].split(" → "))) == 1 for cells in rows.values())  # the same order
    assert "Spearman's ρ of the two orders (12 cameras): 1.00" in day
    assert "### night: other against quick" in page and "### night_regulation: other against quick" in page


def test_markdown_command_prints_the_pages_tables():
    assert _markdown(["--data", str(DATA)]) == results_page.markdown(DATA) + "\n"


def test_publish_leaves_the_tables_of_absent_sweeps_as_they_are(tmp_path):
    """A sweep not there (or still under way: no sweep.csv yet) leaves its docs/data tables as they
    were, and says so; the sweeps there are copied."""
    (tmp_path / "results" / "quick").mkdir(parents=True)
    for name in ("sweep", "od50"):
        (tmp_path / "results" / "quick" / f"{name}.csv").write_bytes((DATA / f"{name}.csv").read_bytes())
    (tmp_path / "results" / "quick-640").mkdir()  # under way
    out = tmp_path / "data"
    out.mkdir()
    (out / "sweep-640.csv").write_text("kept\n")
    said = []
    sweep_tables.publish(tmp_path / "results", out, "quick", say=said.append)
    assert (out / "sweep.csv").read_bytes() == (DATA / "sweep.csv").read_bytes()
    assert (out / "sweep-640.csv").read_text() == "kept\n" and not (out / "sweep-policies.csv").exists()
    assert said[0] == f"no {tmp_path / 'results' / 'quick-640'}/sweep.csv: {out}/sweep-640.csv and od50-640.csv left as they are"
    assert said[-1].startswith("no policy sweeps under") and len(said) == len(sweep_tables.SWEEPS)
