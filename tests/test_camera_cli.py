"""``benchmark cameras`` commands."""

import json
import math

import pytest

from typer.testing import CliRunner

from benchmark.cli.cameras import app

runner = CliRunner()


def test_list_json():
    result = runner.invoke(app, ["list", "--json"])
    assert result.exit_code == 0
    rows = json.loads(result.stdout)
    assert [r["name"] for r in rows][:2] == ["cam01", "cam02"] and len([r for r in rows if not r["extra"]]) == 13
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


def test_show_json_says_what_the_spec_implies():
    result = runner.invoke(app, ["show", "cam12", "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    d = data["derived"]
    assert d["fov_deg"] == {"horizontal": pytest.approx(34.117, abs=1e-3), "vertical": pytest.approx(19.586, abs=1e-3)}
    assert d["ifov_mrad"] == pytest.approx(1.4 / 4.38, rel=1e-5)
    assert d["nyquist_cy_per_mm"] == pytest.approx(357.14, abs=0.01)
    assert d["saturation_e"] == pytest.approx(1146, abs=1) and d["saturation_limited_by"] == "adc"
    assert d["dynamic_range_db"] == pytest.approx(20 * math.log10(1146.1 / 5.012), abs=0.05)
    snr = d["snr_reference"]
    assert snr["exposure_s"] == 0.016 and 50 < snr["signal_e"] < 110 and snr["snr"] == pytest.approx(
        snr["signal_e"] / math.sqrt(snr["signal_e"] + (0.007 * snr["signal_e"]) ** 2 + d["noise_floor_e"] ** 2), rel=1e-3)
    assert any("6000 e- well" in w and "1146 e-" in w for w in data["warnings"])
    assert data["sha256"] == data["sha256"] and data["optics"]["f_number"] == 1.9  # the spec is still there


def test_show_warns_when_the_gain_makes_the_well_unreachable(tmp_path):
    spec = tmp_path / "big_well.yaml"
    spec.write_text("name: bigwell\noptics: {f_number: 2.0}\nsensor: {pixel_um: 2.8, well_capacity_e: 20000}\n")
    result = runner.invoke(app, ["show", str(spec)])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "field of view" in text and "34.12° x 19.59°" in text and "Nyquist" in text and "dynamic range" in text
    assert "warning:" in text and "before the 20000 e- well fills" in text and "94% of the well is unreachable" in text
    low = tmp_path / "low_gain.yaml"  # ADC range 11252 e-: the 6000 e- well fills first
    low.write_text("name: lowgain\noptics: {f_number: 2.0}\nsensor: {pixel_um: 2.8, analog_gain: 0.5}\n")
    data = json.loads(runner.invoke(app, ["show", str(low), "--json"]).stdout)
    assert data["derived"]["saturation_limited_by"] == "well" and data["derived"]["saturation_e"] == 6000
    assert not any("unreachable" in w for w in data["warnings"])
    assert any("well fills at 575 DN" in w and "47% of the codes above black are never used" in w
               for w in data["warnings"])


def test_show_warns_about_a_field_wider_than_the_reference_and_refuses_bad_specs(tmp_path):
    spec = tmp_path / "wide.yaml"
    spec.write_text("name: wide\noptics: {f_number: 2.0}\nsensor: {pixel_um: 1.4, active_height_mm: 1.792}\n")
    data = json.loads(runner.invoke(app, ["show", str(spec), "--json"]).stdout)
    assert data["derived"]["fov_deg"]["vertical"] == pytest.approx(23.12, abs=0.01)
    assert any("exceeds the reference collection field" in w for w in data["warnings"])
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\noptics: {f_number: 2.0}\nsensor: {pixel_um: 1, adc_bits: 8, black_level_dn: 4096}\n")
    result = runner.invoke(app, ["show", str(bad)])
    assert result.exit_code == 2 and "black_level_dn 4096" in result.output and "Traceback" not in result.output
