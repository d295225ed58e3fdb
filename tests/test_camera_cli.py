"""``benchmark cameras`` commands."""

import json

from typer.testing import CliRunner

from benchmark.cli_cameras import app

runner = CliRunner()


def test_list_json():
    result = runner.invoke(app, ["list", "--json"])
    assert result.exit_code == 0
    rows = json.loads(result.stdout)
    assert [r["name"] for r in rows][:2] == ["cam01", "cam02"] and len(rows) == 13
    assert {"name", "pixel_um", "f_number", "label", "width_px", "height_px", "mtf50_group"} <= set(rows[0])


def test_show_and_errors():
    result = runner.invoke(app, ["show", "12", "--json"])
    assert result.exit_code == 0 and json.loads(result.stdout)["optics"]["f_number"] == 1.9
    assert runner.invoke(app, ["list"]).exit_code == 0
    bad = runner.invoke(app, ["show", "cam99"])
    assert bad.exit_code == 2 and "valid names" in bad.output and "Traceback" not in bad.output


def test_mtf_json_and_plot(tmp_path):
    result = runner.invoke(app, ["mtf", "cam13", "--json", "--plot", str(tmp_path / "mtf.png")])
    assert result.exit_code == 0, result.output
    (row,) = json.loads(result.stdout)
    assert row["name"] == "cam13" and 150 < row["mtf50_cy_per_mm"] < 300
    assert 190 < row["mtf50_analytic_cy_per_mm"] < 215
    assert (tmp_path / "mtf.png").stat().st_size > 1000
