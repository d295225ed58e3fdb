"""A submission says what decided its bytes (versions, the CPU's kernel class), and
``submit --check`` warns where this machine differs, and passes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from benchmark.cli.main import app
from benchmark.leaderboard.submission import software_differences
from benchmark.leaderboard.validate import canonical_sha256, validate_submission
from metricscenes import numeric_pins
from metricscenes.numeric_pins import isa_class, package_versions

REPO = Path(__file__).resolve().parents[1]
REFERENCE = REPO / "leaderboard" / "submissions" / "ref-cam12-yolov5n-metric-300.json"
PROTOCOLS = REPO / "benchmark" / "leaderboard" / "data" / "protocols.yaml"


def _with_software(versions: dict, isa: str) -> dict:
    sub = json.loads(REFERENCE.read_text())
    sub["software"] = {"versions": versions, "isa_class": isa}
    return sub


def test_the_same_software_is_no_difference_and_validates():
    sub = _with_software(package_versions(), isa_class())
    assert validate_submission(sub, source="s") is sub and software_differences(sub) == []


@pytest.mark.parametrize("here", ["avx2", "avx512", "other"])
def test_a_reference_submission_is_checked_the_same_on_every_kind_of_machine(here, monkeypatch, tmp_path):
    """The committed references were made on an AVX2 machine: elsewhere the check names the
    machine as the one difference, warns and accepts; it never fails for the host's CPU."""
    monkeypatch.setattr(numeric_pins, "isa_class", lambda flags=None: here)
    reference = json.loads(REFERENCE.read_text())
    made_on = reference["software"]["isa_class"]
    expected = [] if here == made_on else [f"made on an x86-64 {made_on} machine (here {here})"]
    assert software_differences(reference) == expected
    assert validate_submission(reference, source="s") is reference
    res = CliRunner().invoke(app, ["submit", "--check", str(REFERENCE), "--leaderboard", str(REPO / "leaderboard")])
    assert res.exit_code == 0, res.output
    assert ("made on an x86-64" in res.output) == bool(expected)


@pytest.mark.parametrize(("versions", "expected"), [
    ({}, "software.versions is empty"),
    ({"numpy": None}, "software.versions.numpy is None, not a version"),
    ({"numpy": "two"}, "software.versions.numpy is 'two', not a version"),
    ({"x" * 5000: "1.0"}, "software.versions names 'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx'..., not a package that decides"),
])
def test_software_that_no_run_records_is_refused(tmp_path, versions, expected):
    """A run records every byte-deciding package's version (each is a dependency): none of these
    comes from one, and a package name is printed back at most 40 characters long."""
    path = tmp_path / "ref-cam12-yolov5n-metric-300.json"
    path.write_text(json.dumps(_with_software(versions, isa_class())))
    res = CliRunner().invoke(app, ["submit", "--check", str(path), "--leaderboard", str(tmp_path / "lb")])
    assert res.exit_code == 2 and expected in res.output and len(res.output) < 400, res.output


def _pinned_leaderboard(folder: Path, sub: dict) -> Path:
    """A leaderboard whose protocols.yaml pins ``sub`` as made before detections shipped, as the
    committed references are, so that only the software check speaks."""
    protocols = yaml.safe_load(PROTOCOLS.read_text())
    protocols["protocols"]["metric-300"]["made_before_detections"] = {sub["name"]: canonical_sha256(sub)}
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "protocols.yaml").write_text(yaml.safe_dump(protocols, allow_unicode=True))
    return folder


def test_check_warns_about_other_versions_and_another_kernel_class(tmp_path):
    other_isa = "avx512" if isa_class() != "avx512" else "avx2"
    sub = _with_software({**package_versions(), "numpy": "1.0.0"}, other_isa)
    assert software_differences(sub) == [f"made with numpy 1.0.0 (here {package_versions()['numpy']})",
                                         f"made on an x86-64 {other_isa} machine (here {isa_class()})"]
    path = tmp_path / "ref-cam12-yolov5n-metric-300.json"
    path.write_text(json.dumps(sub))
    lb = _pinned_leaderboard(tmp_path / "lb", sub)
    res = CliRunner().invoke(app, ["submit", "--check", str(path), "--leaderboard", str(lb)])
    assert res.exit_code == 0, res.output
    assert "warning: ref-cam12-yolov5n-metric-300.json was made with numpy 1.0.0" in res.output
    assert f"(here {package_versions()['numpy']}) and made on an x86-64 {other_isa} machine" in res.output
    sub["software"] = {"versions": package_versions(), "isa_class": other_isa}  # the machine alone: no "made with made on"
    path.write_text(json.dumps(sub))
    lb = _pinned_leaderboard(tmp_path / "lb2", sub)
    res = CliRunner().invoke(app, ["submit", "--check", str(path), "--leaderboard", str(lb)])
    assert res.exit_code == 0 and f"metric-300.json was made on an x86-64 {other_isa} machine" in res.output, res.output