"""`benchmark publish mtf50-groups`, `camera-variants` and `backend-scores` on synthetic sweeps:
each row is the paired bootstrap `benchmark compare` gives for that pair, only the pairs the
table is about are made, and the CSV and markdown say the same."""

from __future__ import annotations

import pandas as pd
import pytest
from typer.testing import CliRunner

from synthetic_sweep import write_synthetic_sweep

RESAMPLES = 50


@pytest.fixture(scope="module")
def sweeps(tmp_path_factory, smoke_manifest):
    """quick: cam01, cam02, cam03 (MTF50 group 55), cam05 (75) and cam12 (150, alone in the
    sweep), day and night; lens: two cam12 variants; gpu: cam01 and cam02 again, cam02's run
    the CPU's own (same detections), cam05's unfinished."""
    from benchmark.camera import load_camera

    root = tmp_path_factory.mktemp("sweeps")
    cam = {name: load_camera(name) for name in ("cam01", "cam02", "cam03", "cam05", "cam12")}
    quick = write_synthetic_sweep(root / "quick", [(cam["cam01"], 60.0), (cam["cam02"], 90.0), (cam["cam03"], 150.0),
                                                   (cam["cam05"], 80.0), (cam["cam12"], 300.0)],
                                  ("day", "night"), manifest=smoke_manifest, n_environments=8)
    variants = [(cam["cam12"].model_copy(update={"name": name}), half) for name, half in (("cam12-a", 70.0), ("cam12-b", 120.0))]
    lens = write_synthetic_sweep(root / "quick-lens", variants, ("day", "night"), manifest=smoke_manifest, n_environments=8)
    gpu = write_synthetic_sweep(root / "gpu", [(cam["cam01"], 65.0), (cam["cam02"], 90.0)], manifest=smoke_manifest,
                                n_environments=8)
    (gpu / "runs" / "cam05-day").mkdir()  # started, results.json not written: not compared
    return quick, lens, gpu


def _invoke(args: list[str]):
    from benchmark.cli.main import app

    result = CliRunner().invoke(app, ["publish", *args, "--resamples", str(RESAMPLES)])
    assert result.exit_code == 0, result.output
    return result.output


def _compare(a, b, cameras, condition):
    from benchmark.experiments.compare import compare_paths

    return compare_paths(a, b, cameras=cameras, condition=condition, n_resamples=RESAMPLES, seed=0)


def test_mtf50_groups_pairs_cameras_of_one_group_only(sweeps, tmp_path):
    quick, _, _ = sweeps
    out = tmp_path / "mtf50-groups.csv"
    text = _invoke(["mtf50-groups", "--sweep", str(quick), "--conditions", "day,night", "--out", str(out)])
    table = pd.read_csv(out, keep_default_na=False, na_values=[""])
    pairs = [("cam01", "cam02"), ("cam01", "cam03"), ("cam02", "cam03")]  # cam05 and cam12 have no partner
    assert list(zip(table["camera_a"], table["camera_b"])) == pairs * 2
    assert list(table["condition"]) == ["day"] * 3 + ["night"] * 3 and set(table["group_cy_per_mm"]) == {55.0}
    far = table[(table["condition"] == "day") & (table["camera_b"] == "cam03") & (table["camera_a"] == "cam01")].iloc[0]
    result = _compare(quick, quick, ["cam01", "cam03"], "day")
    assert far["od50_a_m"] == pytest.approx(result["a"]["od50_m"], abs=1e-4)
    assert far["delta_od50_m"] == pytest.approx(result["delta_od50"]["delta_m"], abs=1e-4) and far["delta_od50_m"] < 0
    assert far["delta_over_sd"] == pytest.approx(abs(far["delta_od50_m"]) / far["delta_od50_sd_m"], rel=1e-3)
    assert (table["n_resamples"] == RESAMPLES).all()
    rows = [line for line in text.splitlines() if line.startswith("| day | 55 | cam01 – cam03 |")]
    assert len(rows) == 1 and f"| {far['delta_over_sd']:.1f} |" in rows[0]
    measured = table.dropna(subset=["delta_over_sd"])
    day = measured[measured["condition"] == "day"]
    assert f"- day: {len(day)} pairs with both OD50s measured, {int((day['delta_over_sd'] > 2).sum())} differ" in text


def test_camera_variants_against_the_reference_camera(sweeps, tmp_path):
    quick, lens, _ = sweeps
    out = tmp_path / "camera-variants.csv"
    text = _invoke(["camera-variants", "--reference", str(quick), "--variants", str(lens), "--cameras", "cam12-a,cam12-b",
                    "--conditions", "day,night", "--out", str(out)])
    table = pd.read_csv(out, keep_default_na=False, na_values=[""])
    assert list(zip(table["condition"], table["camera"])) == [("day", "cam12-a"), ("day", "cam12-b"),
                                                              ("night", "cam12-a"), ("night", "cam12-b")]
    assert set(table["against"]) == {"cam12"}
    result = _compare(lens, quick, ["cam12-a", "cam12"], "night")
    row = table[(table["condition"] == "night") & (table["camera"] == "cam12-a")].iloc[0]
    at25 = next(r for r in result["per_distance"] if r["distance_m"] == 25.0)
    assert row["delta_ap25"] == pytest.approx(at25["delta_ap"], abs=1e-4) and row["delta_ap25"] < 0
    assert row["verdict"] == result["verdict"]
    assert f"- night, cam12-a: {result['verdict']}" in text
    assert sum(line.startswith("| day | cam12-") for line in text.splitlines()) == 2


def test_backend_scores_compares_the_cameras_both_backends_finished(sweeps, tmp_path):
    quick, _, gpu = sweeps
    out = tmp_path / "backend-scores.csv"
    text = _invoke(["backend-scores", "--cpu", str(quick), "--gpu", str(gpu), "--conditions", "day", "--out", str(out)])
    table = pd.read_csv(out, keep_default_na=False, na_values=[""])
    assert list(table["camera"]) == ["cam01", "cam02"]  # cam03, cam12: CPU only; cam05: unfinished on the GPU
    same = table.set_index("camera").loc["cam02"]  # the same detections on both sides
    assert same["delta_od50_m"] == 0 and same["largest_abs_delta_ap"] == 0 and same["od50_sd_gpu_m"] == same["od50_sd_cpu_m"]
    assert same["od50_sd_cpu_m"] > 0 and same["n_environments"] == 8
    other = table.set_index("camera").loc["cam01"]
    assert other["largest_abs_delta_ap"] > 0
    assert "| day | cam02 | " in text and "| 0.000 | none |" in text
