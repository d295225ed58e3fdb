"""Angular resolution beside sensor-plane MTF50: cycles/mrad in object space
(MTF50 × focal length / 1000) with focal length and field of view in `cameras list/show/mtf`,
results.json, sweep tables, the report and the leaderboard; the SPM and OD50-vs-MTF50 figures use
the angular axis when the compared cameras' focal lengths differ, and say which axis they use.
Also the OD50 axis that censored points cannot stretch."""

from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from benchmark.camera import load_camera
from benchmark.cli.main import app
from benchmark.experiments import report as report_module
from benchmark.experiments import spm
from test_sweep_cache import make_fake_sweep  # the fake runs (tests/ is on sys.path)

runner = CliRunner()
TELE = ("name: tele-8mm\nlabel: 8 mm f/2.0 behind 2.1 um pixels\noptics: {focal_length_mm: 8.0, f_number: 2.0}\n"
        "sensor: {pixel_um: 2.1, active_width_mm: 4.032, active_height_mm: 2.268}\n")


def test_cameras_commands_show_both_units_focal_length_and_field(tmp_path):
    shown = json.loads(runner.invoke(app, ["cameras", "show", "cam12", "--json"]).stdout)["derived"]
    assert shown["mtf50"]["source"] == "measured" and shown["mtf50"]["cy_per_mm"] == pytest.approx(229.3, abs=0.1)
    assert shown["mtf50"]["cy_per_mrad"] == pytest.approx(shown["mtf50"]["cy_per_mm"] * 4.38 / 1000, abs=1e-4)
    assert shown["nyquist_cy_per_mrad"] == pytest.approx(357.1429 * 4.38 / 1000, abs=1e-4)
    text = " ".join(runner.invoke(app, ["cameras", "show", "cam12"]).output.split())
    assert "229.3 cy/mm on the sensor," in text and "1.004 cy/mrad in object" in text  # (a table cell: wrapped)
    (tmp_path / "tele.yaml").write_text(TELE)
    res = runner.invoke(app, ["cameras", "mtf", "cam12", str(tmp_path / "tele.yaml"), "--json"])
    assert res.exit_code == 0, res.output
    cam12, tele = json.loads(res.stdout)
    assert (cam12["focal_length_mm"], tele["focal_length_mm"]) == (4.38, 8.0)
    assert tele["fov_deg"] == [28.29, 16.14]  # 2·atan(1920 · 2.1 µm / 16 mm), 2·atan(1080 · 2.1 µm / 16 mm)
    # the longer lens: coarser on the sensor, finer in object space
    assert tele["mtf50_cy_per_mm"] < cam12["mtf50_cy_per_mm"] and tele["mtf50_cy_per_mrad"] > cam12["mtf50_cy_per_mrad"]
    assert tele["mtf50_cy_per_mrad"] == pytest.approx(tele["mtf50_cy_per_mm"] * 8.0 / 1000, abs=1e-4)
    listed = json.loads(runner.invoke(app, ["cameras", "list", "--json"]).stdout)
    assert listed[11]["focal_length_mm"] == 4.38 and listed[11]["mtf50_group_cy_per_mrad"] == pytest.approx(0.657)


def test_results_json_records_the_camera_geometry_and_both_mtf50s():
    from benchmark.experiments.run import camera_record

    record = camera_record(load_camera("cam12")).model_dump(exclude_none=True)
    assert record["focal_length_mm"] == 4.38 and record["fov_deg"] == [34.1172, 19.5858]
    assert record["mtf50_source"] == "measured" and record["mtf50_cy_per_mm"] == pytest.approx(229.35, abs=0.01)
    assert record["mtf50_cy_per_mrad"] == pytest.approx(record["mtf50_cy_per_mm"] * 4.38 / 1000, abs=1e-4)
    assert record["spec_sha256"] == load_camera("cam12").sha256()


def test_mtf50_axis_is_angular_only_where_focal_lengths_differ():
    same = pd.DataFrame({"camera": ["cam01", "cam12"], "focal_length_mm": [4.38, 4.38],
                         "mtf50_cy_per_mm": [80.0, 229.0], "mtf50_cy_per_mrad": [0.35, 1.0]})
    assert spm.mtf50_axis(same) == "sensor"
    assert spm.mtf50_axis_text(same, "sensor") == "MTF50 in cycles/mm on the sensor: every camera has the same 4.38 mm focal length"
    differ = same.assign(focal_length_mm=[4.38, 8.0])
    assert spm.mtf50_axis(differ) == "angular"
    assert "the cameras' focal lengths differ (4.38, 8 mm)" in spm.mtf50_axis_text(differ, "angular")
    assert spm.mtf50_axis(same.drop(columns="focal_length_mm")) == "sensor"  # an old sweep, nothing to convert with


@pytest.fixture(scope="module")
def tele_sweep(tmp_path_factory):
    monkeypatch = pytest.MonkeyPatch()
    root = tmp_path_factory.mktemp("angular")
    (root / "tele.yaml").write_text(TELE)
    try:
        make_fake_sweep(root / "sweep", monkeypatch, cameras=("cam12", str(root / "tele.yaml")), n_resamples=20)
    finally:
        monkeypatch.undo()
    return root / "sweep"


def test_sweep_tables_hold_focal_length_and_angular_mtf50(tele_sweep):
    for name in ("sweep.csv", "od50.csv"):
        table = pd.read_csv(tele_sweep / name)
        focal = table.groupby("camera")["focal_length_mm"].first()
        assert focal.to_dict() == {"cam12": 4.38, "tele-8mm": 8.0}
        np.testing.assert_allclose(table["mtf50_cy_per_mrad"], table["mtf50_cy_per_mm"] * table["focal_length_mm"] / 1000)
    assert list(pd.read_csv(tele_sweep / "od50.csv").columns)[-5] == "censored"  # then the AP range's four


def test_report_uses_the_angular_axis_and_says_so(tele_sweep, tmp_path):
    page = report_module.report(tele_sweep, tmp_path / "page" / "report.html").read_text(encoding="utf-8")
    assert page.count("MTF50 in cycles/mrad in object space (MTF50 × focal length / 1000): the cameras&#x27; focal "
                      "lengths differ (4.38, 8 mm)") >= 2
    table = pd.read_csv(tmp_path / "page" / "report_table.csv")
    assert list(table.columns[2:6]) == ["MTF50 (cy/mm)", "MTF50 (cy/mrad)", "focal length (mm)", "FOV (°)"]
    assert set(table["focal length (mm)"]) == {4.38, 8.0}
    table, od50, runs, _ = report_module.load_many([tele_sweep])
    fig = spm.od50_vs_mtf50(od50, axis="angular", measured_range_m=(25.0, 200.0))
    assert fig.axes[0].get_xlabel() == "MTF50 (cycles/mrad in object space)"
    fig = spm.spm_mtf50(table, axis="angular")
    assert fig.axes[0].get_ylabel() == "MTF50 (cycles/mrad in object space)"


def test_report_of_the_paper_cameras_keeps_the_sensor_axis(tmp_path, monkeypatch):
    make_fake_sweep(tmp_path / "sweep", monkeypatch, n_resamples=20)  # cam01, cam12: one focal length
    page = report_module.report(tmp_path / "sweep").read_text(encoding="utf-8")
    assert "MTF50 in cycles/mm on the sensor: every camera has the same 4.38 mm focal length" in page
    assert "cycles/mrad in object space (MTF50 ×" not in page


def test_od50_axis_is_set_by_what_is_drawn_not_by_extrapolations():
    """Every OD50 a bound at 25 or 200 m, the numbers behind them up to 1300 m: the axis ends
    just above the farthest bound."""
    od = pd.DataFrame({"condition": ["night"] * 3 + ["day"] * 2, "mtf50_cy_per_mm": [80.0, 120.0, 200.0, 80.0, 200.0],
                       "od50_m": [3.0, 0.0, 12.0, 1300.0, 900.0], "sd_m": [1.0] * 5,
                       "censored": ["<", "<", "<", ">", ">"], "bound_m": [25.0, 25.0, 25.0, 200.0, 200.0]})
    fig = spm.od50_vs_mtf50(od, measured_range_m=(25.0, 200.0))
    assert fig.axes[0].get_ylim() == pytest.approx((0.0, 230.0))
    only_near = od[od["condition"] == "night"]  # nothing measured, every OD50 below 25 m
    assert spm.od50_vs_mtf50(only_near, measured_range_m=(25.0, 200.0)).axes[0].get_ylim()[1] == pytest.approx(220.0)
    measured = od.assign(censored="", bound_m=np.nan, od50_m=[60.0, 80.0, 100.0, 150.0, 180.0])
    assert spm.od50_vs_mtf50(measured, measured_range_m=(25.0, 200.0)).axes[0].get_ylim()[1] == pytest.approx(1.6 * 180.0)


def test_leaderboard_rows_show_angular_mtf50_focal_length_and_field():
    from benchmark.leaderboard.render import row_cells
    from benchmark.leaderboard.protocols import load_protocols
    from benchmark.leaderboard.validate import read_submission_file

    from conftest import REPO

    protocol = load_protocols(REPO / "leaderboard")["quick"]
    sub = read_submission_file(REPO / "leaderboard" / "submissions" / "ref-cam12-yolov5n-quick.json")
    cells = row_cells(2, sub, protocol)
    assert cells["mtf50"][1] == "229" and cells["mtf50_mrad"][1] == "1.00" and cells["focal_mm"][1] == "4.38"
    assert cells["fov"][1] == "34.1 × 19.6" and float(cells["fov"][0]) == pytest.approx(34.117, abs=1e-3)
    readme = (REPO / "leaderboard" / "README.md").read_text()
    assert re.search(r"\| MTF50 \(cy/mm\) \| MTF50 \(cy/mrad\) \| Focal \(mm\) \| FOV \(°\) \|", readme)
