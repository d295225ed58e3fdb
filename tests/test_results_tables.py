"""docs/results.md's tables are the ones benchmarks/results_tables.py makes from docs/data,
and `publish` lays the sweep folders out as docs/data."""

from pathlib import Path

import pandas as pd

REPO = Path(__file__).resolve().parents[1]
DATA = REPO / "docs" / "data"


def test_every_table_row_of_the_results_page_comes_from_docs_data(load_benchmark):
    tables = load_benchmark("results_tables").markdown(DATA)
    page = (REPO / "docs" / "results.md").read_text().splitlines()
    rows = [line for line in tables.splitlines() if line.startswith("| ")]
    assert len(rows) > 13 * 3
    missing = [row for row in rows if row not in page]
    assert not missing, f"docs/results.md lacks (or has other numbers in) {missing[:3]}"


def test_publish_lays_sweep_folders_out_as_docs_data(load_benchmark, tmp_path):
    results_tables = load_benchmark("results_tables")
    results = tmp_path / "results"
    for suffix, folder in results_tables.SWEEPS.items():
        if not (DATA / f"sweep{suffix}.csv").exists():  # a sweep not yet published
            continue
        (results / folder).mkdir(parents=True)
        for name in ("sweep", "od50"):
            (results / folder / f"{name}.csv").write_bytes((DATA / f"{name}{suffix}.csv").read_bytes())
    policies = pd.read_csv(DATA / "sweep-policies.csv"), pd.read_csv(DATA / "od50-policies.csv")
    for policy, folder in results_tables.POLICIES.items():
        (results / folder).mkdir()
        for name, table in zip(("sweep", "od50"), policies):
            table[table["exposure"] == policy].drop(columns="exposure").to_csv(results / folder / f"{name}.csv", index=False)

    results_tables.publish(results, tmp_path / "data")

    for name in ("sweep", "od50"):
        assert (tmp_path / "data" / f"{name}.csv").read_bytes() == (DATA / f"{name}.csv").read_bytes()
    made = pd.read_csv(tmp_path / "data" / "sweep-policies.csv")
    reference = made[made["exposure"] == results_tables.REFERENCE_POLICY]
    assert set(reference["condition"]) == {"dusk", "night"} and reference["camera"].nunique() == 4
    assert len(made) == len(policies[0])
    key = ["camera", "condition", "distance_m", "exposure"]
    # the policies' rows as their sweeps wrote them, the reference's from the reference sweep (sweep.csv)
    expected_policies = policies[0][policies[0]["exposure"] != results_tables.REFERENCE_POLICY]
    sweep = pd.read_csv(DATA / "sweep.csv")
    expected_reference = sweep[sweep["camera"].isin(set(reference["camera"]))
                               & sweep["condition"].isin(results_tables.POLICY_CONDITIONS)].assign(
        exposure=results_tables.REFERENCE_POLICY)
    expected = pd.concat([expected_reference, expected_policies], ignore_index=True)
    pd.testing.assert_frame_equal(made.sort_values(key).reset_index(drop=True)[list(policies[0].columns)],
                                  expected.sort_values(key).reset_index(drop=True)[list(policies[0].columns)],
                                  check_exact=False)
