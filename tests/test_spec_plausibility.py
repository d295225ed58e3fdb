"""Camera specs a sensor cannot have are refused in one line that names the field, the value,
the plausible range and the likely unit mistake; values that are possible
but unusual are warned about. Duplicate YAML keys, impossible QE tables and a user spec that
takes a registry camera's name are refused too. Each refusal: exit code
2, one line, nothing created."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from benchmark.camera import list_cameras, load_camera
from benchmark.camera.spec import cy_per_mrad
from benchmark.camera.spec_files import check_qe_table
from benchmark.camera.spec_rules import PLAUSIBLE
from benchmark.cli.main import app
from metricscenes.spectral import SENSOR_DATA_DIR

BASE = "name: mine\noptics: {f_number: 2.0}\n"
runner = CliRunner()


def _snapshot(root: Path) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "dir"
            for p in sorted(root.rglob("*"))}


def _refused_by_run(tmp_path: Path, spec: Path) -> str:
    """`benchmark run --camera SPEC`: exit 2, one line naming the spec, nothing created."""
    before = _snapshot(tmp_path)
    res = runner.invoke(app, ["run", "--camera", str(spec), "--collection", str(tmp_path / "no-collection"),
                              "--out", str(tmp_path / "out")])
    assert res.exit_code == 2, res.output
    lines = [line for line in res.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in res.output, res.output
    assert _snapshot(tmp_path) == before and not (tmp_path / "out").exists()
    return lines[0]


@pytest.mark.parametrize(("sensor", "exposure", "field", "expected"), [
    ("{pixel_um: 1.4}", "{max_exposure_s: 30}", "exposure.max_exposure_s' = 30",
     "an exposure cap of 30 s is above the plausible range 1e-07 to 1 s of real sensors; if it was meant in ms, write 0.03"),
    ("{pixel_um: 1.4}", "{mode: fixed, exposure_s: 16}", "exposure.exposure_s' = 16",
     "above the plausible range 1e-07 to 1 s of real sensors; if it was meant in ms, write 0.016"),
    ("{pixel_um: 1.4, conversion_gain_uv_per_e: 0.00006}", None, "sensor.conversion_gain_uv_per_e' = 6e-05",
     "a conversion gain of 6e-05 uV/e- is below the plausible range 1 to 1000 uV/e- of real sensors; if it was meant "
     "in V/e-, write 60"),
    ("{pixel_um: 1.4, conversion_gain_uv_per_e: 76500}", None, "sensor.conversion_gain_uv_per_e' = 76500",
     "above the plausible range 1 to 1000 uV/e- of real sensors; if it was meant in nV/e-, write 76.5"),
    ("{pixel_um: 1.4, well_capacity_e: 10}", None, "sensor.well_capacity_e' = 10",
     "a full well of 10 e- is below the plausible range 300 to 10000000 e- of real sensors; if it was meant in ke-, "
     "write 10000"),
    ("{pixel_um: 1.4, voltage_swing_v: 459.1}", None, "sensor.voltage_swing_v' = 459.1",
     "if it was meant in mV, write 0.4591"),
    ("{pixel_um: 1.4, prnu_fraction: 0.7}", None, "sensor.prnu_fraction' = 0.7",
     "a PRNU of 0.7 is above the plausible range 0 to 0.1 of real sensors; if it was meant in percent, write 0.007"),
    ("{pixel_um: 1.4, dsnu_v: 0.5}", None, "sensor.dsnu_v' = 0.5", "if it was meant in mV, write 0.0005"),
])
def test_absurd_values_are_refused_with_the_likely_unit_mistake(tmp_path, sensor, exposure, field, expected):
    spec = tmp_path / "absurd.yaml"
    spec.write_text(BASE + f"sensor: {sensor}\n" + (f"exposure: {exposure}\n" if exposure else ""))
    with pytest.raises(ValueError) as info:
        load_camera(spec)
    message = str(info.value)
    assert "\n" not in message and f"field '{field}" in message and expected in message, message
    assert 'docs/camera.md, "Plausible values"' in message and "(allowed:" not in message
    line = _refused_by_run(tmp_path, spec)
    assert expected in " ".join(line.split())


def test_read_noise_above_the_well_is_refused(tmp_path):
    spec = tmp_path / "noisy.yaml"
    spec.write_text(BASE + "sensor: {pixel_um: 1.4, well_capacity_e: 600, read_noise_e: 700}\n")
    line = _refused_by_run(tmp_path, spec)
    assert "read_noise_e 700 e- is not below well_capacity_e 600 e-: no signal could rise above the noise" in line
    assert "was it given in uV or DN, or the well in ke-?" in line


def test_unusual_but_possible_values_are_warned_about_not_refused(tmp_path):
    spec = tmp_path / "unusual.yaml"
    spec.write_text(BASE + "sensor: {pixel_um: 1.4, well_capacity_e: 1500, read_noise_e: 60}\nexposure: {max_exposure_s: 0.3}\n")
    res = runner.invoke(app, ["cameras", "show", str(spec), "--json"])
    assert res.exit_code == 0, res.output
    warnings = json.loads(res.stdout)["warnings"]
    for text in ("exposure.max_exposure_s 0.3 s is unusual (most sensors: 0.0001 to 0.1 s)",
                 "sensor.well_capacity_e 1500 e- is unusual (most sensors: 2000 to 1000000 e-)",
                 "sensor.read_noise_e 60 e- is unusual (most sensors: 0 to 50 e-)"):
        assert any(w.startswith(text) for w in warnings), (text, warnings)


def test_registry_cameras_are_plausible_and_unchanged():
    """The 13 cameras pass every bound and draw no plausibility warning; their sha256 stay."""
    from benchmark.camera.spec_rules import plausibility_warnings

    for cam in list_cameras():
        assert plausibility_warnings(cam) == []
        for field, rule in PLAUSIBLE.items():
            section, name = field.split(".")
            lo, hi = rule.refused
            assert lo <= getattr(getattr(cam, section), name) <= hi
    assert load_camera("cam12").sha256() == "2e6ada0f7487d40cfed75f6677ac5dbc2d7dbc13fa2fdd3955a996ad0e592548"


def test_duplicate_yaml_keys_are_refused(tmp_path):
    spec = tmp_path / "twice.yaml"
    spec.write_text("name: mine\noptics: {f_number: 2.0}\nsensor:\n  pixel_um: 1.4\n  pixel_um: 2.8\n")
    line = _refused_by_run(tmp_path, spec)
    assert f"{spec}: invalid YAML (line 5): duplicate key 'pixel_um'" in line
    spec.write_text("name: mine\nname: other\noptics: {f_number: 2.0}\nsensor: {pixel_um: 1.4}\n")
    with pytest.raises(ValueError, match=r"invalid YAML \(line 2\): duplicate key 'name'"):
        load_camera(spec)


def _qe_rows(change=None) -> list[str]:
    lines = (SENSOR_DATA_DIR / "imx363_qe.csv").read_text().splitlines()
    rows = [lines[0]] + lines[1:]
    if change:
        rows = change(rows)
    return rows


@pytest.mark.parametrize(("change", "expected"), [
    (lambda r: r[:4] + [r[4].replace("0.0190", "-0.0190", 1)] + r[5:], "row 4 qe_g is -0.019: a fraction of the photons, between 0 and 1"),
    (lambda r: [r[0]] + [",".join([x.split(",")[0]] + [f"{float(v) * 100:g}" for v in x.split(",")[1:4]] + x.split(",")[4:])
                         for x in r[1:]], "between 0 and 1; if the table is in percent, divide it by 100"),
    (lambda r: r[:4] + [r[4].replace("0.0190", "nan", 1)] + r[5:], "row 4 qe_g is not a number"),
    (lambda r: r[:4] + [r[4].replace("0.0190", "", 1)] + r[5:], "row 4 qe_g is not a number"),
    (lambda r: [r[0], r[2], r[1]] + r[3:], "wavelength_nm must increase row by row: row 2 (380) follows row 1 (390)"),
    (lambda r: [r[0]] + [",".join([f"{float(x.split(',')[0]) / 1000:g}"] + x.split(",")[1:]) for x in r[1:]],
     "if they are in um, write 380 to"),
    (lambda r: [r[0].replace("qe_b", "qe_blue")] + r[1:], "lacks column(s) qe_b"),
    (lambda r: r[:2], "1 row(s); two or more wavelengths are needed"),
    (lambda r: ["Sony IMX363 quantum efficiency, from its datasheet", "see the curves in figure 3"],  # not a table
     "not a table of wavelength_nm, qe_r, qe_g, qe_b[, qe_c][, ir_cut_transmittance] (line 2 has 1 columns, the header 2)"),
])
def test_impossible_qe_tables_are_refused(tmp_path, change, expected):
    (tmp_path / "qe.csv").write_text("\n".join(_qe_rows(change)) + "\n")
    spec = tmp_path / "cam.yaml"
    spec.write_text(BASE + "sensor: {pixel_um: 1.4, qe: qe.csv}\n")
    line = _refused_by_run(tmp_path, spec)
    assert "QE table qe.csv: " in line and expected in line, line
    with pytest.raises(ValueError, match="QE table qe.csv"):
        check_qe_table(tmp_path / "qe.csv")


@pytest.mark.parametrize("label", ["\x1b[31mred\x1b[0m", "two\nlines", "bell\x07", "zero\u200bwidth", "x" * 201])
def test_a_label_that_would_drive_the_terminal_is_refused(tmp_path, label):
    """`cameras show` prints the label: an ANSI escape, a line break or an invisible character
    in it would reach the terminal as it is."""
    spec = tmp_path / "cam.yaml"
    spec.write_text(BASE + f"label: {json.dumps(label)}\nsensor: {{pixel_um: 1.4}}\n")
    line = _refused_by_run(tmp_path, spec)
    assert "label" in line and "\x1b" not in line, line
    res = runner.invoke(app, ["cameras", "show", str(spec)])
    assert res.exit_code == 2 and "\x1b" not in res.output and len(res.output.strip().splitlines()) == 1, res.output


def test_the_packaged_qe_table_passes():
    wl, qe, ir = check_qe_table(SENSOR_DATA_DIR / "imx363_qe.csv")
    assert wl[0] == 380 and qe.shape == (3, wl.size) and ir is not None and 0 <= qe.min() and qe.max() <= 1


def test_a_user_spec_cannot_take_a_registry_name(tmp_path):
    for name in ("cam12", "CAM12", "Cam05"):
        spec = tmp_path / f"{name}.yaml"
        spec.write_text(f"name: {name}\noptics: {{f_number: 2.0}}\nsensor: {{pixel_um: 1.4}}\n")
        line = _refused_by_run(tmp_path, spec)
        assert f"name {name!r} is the registry camera {name.lower()}'s, and this spec differs from it" in line
        assert "give the camera a name of its own" in line
    copy = tmp_path / "copy" / "cam12.yaml"  # the registry's very spec, copied: it is cam12
    copy.parent.mkdir()
    copy.write_text((Path(load_camera.__code__.co_filename).parent / "data" / "cam12.yaml").read_text())
    assert load_camera(copy).sha256() == load_camera("cam12").sha256()


@pytest.mark.parametrize(("typed", "suggested"), [("CAM12", "cam12"), ("cam1", "cam01"), ("Cam007", "cam07"), ("cma12", "cam12")])
def test_unknown_camera_names_get_a_suggestion_not_a_substitute(tmp_path, typed, suggested):
    line = _refused_by_run(tmp_path, Path(typed))
    assert f"unknown camera {typed!r}" in line and line.endswith(f"did you mean {suggested!r}?")
    res = runner.invoke(app, ["cameras", "show", typed])
    assert res.exit_code == 2 and f"did you mean {suggested!r}?" in res.output


def test_angular_frequency_is_sensor_frequency_times_focal_length():
    assert cy_per_mrad(229.3, 4.38) == pytest.approx(1.0043, abs=1e-4)
    assert cy_per_mrad(168.6, 8.0) == pytest.approx(1.3488, abs=1e-4)
    assert cy_per_mrad(None, 4.38) is None and cy_per_mrad(float("nan"), 4.38) is None
    assert load_camera("cam12").cy_per_mrad(100.0) == pytest.approx(0.438)
