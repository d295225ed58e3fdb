"""``--exposure hdr:...`` (two frames) on an HDR pixel (``sensor.dcg``) is refused in one line,
before anything runs or is written."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from benchmark.camera import extra_camera_names, load_camera
from benchmark.camera.exposure import check_exposure_override, parse_exposure
from benchmark.cli.main import app
from test_sweep_cli import fakes  # noqa: F401  (fixture)

runner = CliRunner()


@pytest.mark.parametrize("name", ["auto-imx490-like", "auto-imx490-rccb-like"])
@pytest.mark.parametrize("text", ["hdr", "hdr:16", "hdr:4@0.5"])
def test_a_two_frame_policy_on_an_hdr_pixel_is_refused_in_one_line(name, text):
    camera = load_camera(name)
    assert camera.sensor.dcg is not None
    with pytest.raises(ValueError) as info:
        check_exposure_override(camera, parse_exposure(text))
    message = str(info.value)
    assert "\n" not in message and f"camera {name!r}" in message
    assert f"--exposure {text if ':' in text else 'hdr:'}" in message  # the policy as given (hdr: its default ratio)
    assert "sensor.dcg" in message and "the camera's own exposure policy" in message


@pytest.mark.parametrize("text", ["auto_peak", "mean_level", "percentile:95", "fixed:0.004"])
def test_one_frame_policies_apply_to_an_hdr_pixel(text):
    check_exposure_override(load_camera("auto-imx490-like"), parse_exposure(text))


def test_no_override_and_a_bayer_camera_pass():
    check_exposure_override(load_camera("auto-imx490-like"), None)
    check_exposure_override(load_camera("cam01"), parse_exposure("hdr:16"))  # two frames of a plain sensor: modelled


def _refused_in_one_line(result, name: str) -> None:
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in result.output, result.output
    assert lines[0].startswith("error: ") and f"camera {name!r}" in lines[0] and "sensor.dcg" in lines[0]


def test_run_refuses_hdr_on_an_hdr_pixel_before_writing_anything(fakes, monkeypatch):  # noqa: F811
    def run_camera(*args, **kw):
        raise AssertionError("the run began")

    monkeypatch.setattr("benchmark.experiments.run.run_camera", run_camera)
    out = fakes / "run-out"
    result = runner.invoke(app, ["run", "--camera", "auto-imx490-like", "--collection", str(fakes), "--out", str(out),
                                 "--exposure", "hdr:16"])
    _refused_in_one_line(result, "auto-imx490-like")
    assert not out.exists()


def test_sweep_refuses_hdr_on_an_hdr_pixel_before_writing_anything(fakes, monkeypatch):  # noqa: F811
    def runs(*args, **kw):
        raise AssertionError("a run began")

    monkeypatch.setattr("benchmark.experiments.run.run_cameras", runs)  # sweep() refuses it before its runs
    out = fakes / "sweep-out"
    result = runner.invoke(app, ["sweep", "--collection", str(fakes), "--out", str(out), "--conditions", "day",
                                 "--cameras", f"cam01,{extra_camera_names()[0]}", "--exposure", "hdr:16"])
    _refused_in_one_line(result, extra_camera_names()[0])
    assert not out.exists()


def test_run_takes_a_one_frame_policy_on_an_hdr_pixel(fakes):  # noqa: F811
    out = fakes / "run-out"
    result = runner.invoke(app, ["run", "--camera", "auto-imx490-like", "--collection", str(fakes), "--out", str(out),
                                 "--exposure", "fixed:0.004", "--no-save-images"])
    assert result.exit_code == 0, result.output
    assert (out / "results.json").is_file()
