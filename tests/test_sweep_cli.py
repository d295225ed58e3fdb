"""``benchmark sweep`` and ``benchmark report`` commands: output, one-line errors (fake runs)."""

from __future__ import annotations

import pandas as pd
import pytest
from typer.testing import CliRunner

from benchmark.cli.main import app
from test_sweep_cache import FakeCollection, FakeDetector, fake_run_camera, patch_runs


@pytest.fixture
def fakes(monkeypatch, tmp_path):
    import benchmark.detectors
    import metricscenes.store

    patch_runs(monkeypatch, fake_run_camera)
    monkeypatch.setattr(metricscenes.store.Collection, "open", classmethod(lambda cls, path: FakeCollection(tmp_path)))
    monkeypatch.setattr(benchmark.detectors, "load_detector", lambda model, **kw: FakeDetector(name=model))
    return tmp_path


def test_sweep_then_report(fakes):
    out = fakes / "sw"
    args = ["sweep", "--collection", str(fakes), "--cameras", "cam01,12", "--conditions", "day,night",
            "--out", str(out), "--resamples", "20", "--mtf-source", "published_group"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "OD50 ± SD" in result.output and "cam12" in result.output and "150.0 (published_group)" in result.output
    od50 = pd.read_csv(out / "od50.csv")
    row = od50.query("camera == 'cam01' and condition == 'night'").iloc[0]
    assert f"{row.od50_m:.1f} ± {row.sd_m:.1f}†" in result.output  # 4 environments: marked, and the mark explained
    assert f"{row.ap_range_m:.1f} ± {row.ap_range_sd_m:.1f}†" in result.output and "† from fewer than" in result.output
    again = CliRunner().invoke(app, args)  # cached: same table
    assert again.exit_code == 0 and f"{row.od50_m:.1f} ± {row.sd_m:.1f}" in again.output
    page = CliRunner().invoke(app, ["report", str(out)])
    assert page.exit_code == 0, page.output
    assert (out / "report.html").is_file() and "report.html" in page.output


@pytest.mark.parametrize("extra, message", [
    (["--cameras", "cam99"], "unknown camera 'cam99'"),
    (["--conditions", "dawn"], "unknown condition 'dawn'"),
    (["--mtf-source", "guess"], "--mtf-source must be one of"),
    (["--also-input-size", "640"], "expected SIZE=FOLDER"),
    (["--also-input-size", "big=elsewhere"], "input_size must be"),
    (["--also-input-size", "640=a", "--also-input-size", "640=b"], "input size 640 given twice"),
])
def test_sweep_errors_are_one_line(fakes, extra, message):
    args = ["sweep", "--collection", str(fakes), "--cameras", "cam01", "--out", str(fakes / "sw"), *extra]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2
    assert message in result.output and "Traceback" not in result.output
    assert len([line for line in result.output.splitlines() if line.strip()]) == 1


def test_report_errors_are_one_line(tmp_path):
    for target in (tmp_path / "missing", tmp_path):
        result = CliRunner().invoke(app, ["report", str(target)])
        assert result.exit_code == 2 and "Traceback" not in result.output
        assert "not found" in result.output or "neither a sweep folder" in result.output
